//! `pound ida`: IDA curves and their fractiles from a results CSV.

use super::{check_study_outputs, Holds};
use anyhow::{bail, Result};
use pounding::io::table::{Filter, Table};
use pounding::studies::fragility::default_im;
use pounding::studies::ida::{read, IdaSpec, FRACTILES};
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Args {
    /// A CSV written by `pound sweep`.
    results: PathBuf,
    /// Intensity measure column (e.g. target_sa_g, target_sa_avg_g, pga_g, or an intensity
    /// measure every run writes of its scaled record: pgv_m_s, arias_m_s, cav_m_s, sa_t1_g /
    /// sa_t2_g of a pair, b1_sa_t1_g ... of a row). Default: the spectral target the CSV was
    /// scaled to, else pga_g.
    #[arg(long)]
    im: Option<String>,
    /// Demand column (e.g. b1_peak_drift_ratio, peak_force_n). A collapsed run (status
    /// `collapsed`) is an infinite demand: its curve flatlines at its first collapse.
    #[arg(long)]
    edp: String,
    /// The columns that name a curve, comma-separated (default: record, and sample where the
    /// CSV has samples).
    #[arg(long, value_delimiter = ',')]
    by: Vec<String>,
    /// Keep only rows with COLUMN=VALUE (also !=, <, <=, >, >=); repeat to combine.
    #[arg(long = "where", value_name = "FILTER")]
    filters: Vec<String>,
    /// Per level: the intensity, the curves there, the fractiles, the curves collapsed and their
    /// share, and each curve's demand (CSV; `inf` for a collapse).
    /// (default: ida.csv, numbered `-2`, `-3`, ... where that file exists)
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// The curves and the fractiles (.svg or .png), with a second panel of the share of curves
    /// collapsed per level where any collapsed.
    #[arg(long)]
    plot: Option<PathBuf>,
    #[command(flatten)]
    figure: super::FigureArgs,
}

pub fn run(a: Args) -> Result<()> {
    let output = super::default_output(a.output.clone(), "ida.csv");
    check_study_outputs(
        &a.results,
        &[],
        &[
            ("-o", Some(&output), Holds::Csv),
            ("--plot", a.plot.as_deref(), Holds::Plot),
        ],
    )?;
    if let Some(twice) = pounding::plan::config::name_given_twice(&a.by) {
        bail!("--by: `{twice}` is given twice: give each column once");
    }
    let table = Table::read(&a.results)?;
    let by = if a.by.is_empty() {
        let sampled = table
            .col("sample")
            .is_ok_and(|c| table.rows.iter().any(|r| !r[c].is_empty()));
        let mut by = vec!["record".to_string()];
        if sampled {
            by.push("sample".into());
        }
        by
    } else {
        a.by
    };
    let spec = IdaSpec {
        im: a.im.unwrap_or_else(|| default_im(&table)),
        edp: a.edp,
        by,
        filters: Filter::parse_all(&a.filters)?,
    };
    if spec.edp == pounding::studies::fragility::COLLAPSED && table.col(&spec.edp).is_err() {
        bail!("--edp {}: an IDA reads a demand column (e.g. b1_peak_drift_ratio), where a collapsed run is an infinite demand; the collapse fragility P(collapse | IM) is `pound fragility --edp collapsed`", spec.edp);
    }
    let (ida, skipped) = read(&table, &spec)?;
    let collapsed_runs = skipped.collapsed;
    say!(
        "{} curves (by {}) at {} levels of {}{}{}",
        ida.curves.len(),
        spec.by.join(", "),
        ida.ims.len(),
        spec.im,
        if collapsed_runs > 0 {
            format!(", {collapsed_runs} runs collapsed (an infinite demand)")
        } else {
            String::new()
        },
        if skipped.total() > 0 {
            format!(" ({} rows left out: {skipped})", skipped.total())
        } else {
            String::new()
        }
    );
    // Failed runs are left out of the fractiles. Where the table has no collapse criterion a
    // failed run may be a collapse, so the fractiles over the others are collapse-free; where it
    // has one, they are over the runs that did not fail.
    let failed: usize = ida.failed.iter().sum();
    let can_collapse = table.col("collapse_time_s").is_ok();
    let over = match (failed > 0, can_collapse) {
        (false, _) => "",
        (true, false) => " (collapse-free)",
        (true, true) => " (failed runs left out)",
    };
    let head: Vec<String> = FRACTILES
        .iter()
        .map(|f| format!("{} {f} %{over}", spec.edp))
        .collect();
    say!(
        "\n| {} | curves | collapsed | {} |\n|---:|---:|---:|---:|---:|---:|",
        spec.im,
        head.join(" | ")
    );
    let show = |x: f64| {
        if x.is_infinite() {
            "inf (collapse)".to_string()
        } else {
            format!("{x:.4e}")
        }
    };
    for (l, im) in ida.ims.iter().enumerate() {
        let f = ida.fractiles[l];
        if ida.counts[l] == 0 {
            say!("| {im} | 0 | | no run with a value | | |");
            continue;
        }
        say!(
            "| {im} | {} | {} ({:.0} %) | {} | {} | {} |",
            ida.counts[l],
            ida.collapsed[l],
            100.0 * ida.collapsed_fraction(l).unwrap_or(0.0),
            show(f[0]),
            show(f[1]),
            show(f[2])
        );
    }
    // Where curves are missing at a level, say why: no run there, or a run left out.
    let short: Vec<String> = ida
        .ims
        .iter()
        .enumerate()
        .filter(|(l, _)| ida.counts[*l] < ida.curves.len())
        .map(|(l, im)| {
            let (n, f, e) = (ida.counts[l], ida.failed[l], ida.no_value[l]);
            let mut why = Vec::new();
            if f > 0 {
                why.push(format!("{f} failed (status neither ok nor collapsed)"));
            }
            if e > 0 {
                why.push(format!(
                    "{e} with no value of {} (a run that did not settle)",
                    spec.edp
                ));
            }
            let absent = ida.curves.len().saturating_sub(n + f + e);
            if absent > 0 {
                why.push(format!("{absent} with no run"));
            }
            format!(
                "{im}: {n} of {} curves ({})",
                ida.curves.len(),
                why.join(", ")
            )
        })
        .collect();
    if !short.is_empty() {
        note!(
            "notice: not every curve has a value at each level of {}: {}; the fractiles there are over the runs with a value",
            spec.im,
            short.join("; ")
        );
    }
    if failed > 0 {
        if can_collapse {
            note!(
                "notice: {failed} failed runs (status neither ok nor collapsed: a numerical failure) are left out of the fractiles, which are over the runs that did not fail (the collapsed ones among them, as infinite demands)"
            );
        } else {
            note!(
                "notice: {failed} failed runs (status not ok: a collapse or a numerical failure, this table having no collapse criterion) are left out of the fractiles, which are therefore collapse-free: below the fractiles of every run where the failed runs are the most severe"
            );
        }
    }
    if ida.any_collapsed() {
        let flat: Vec<String> = FRACTILES
            .iter()
            .enumerate()
            .filter_map(|(k, f)| {
                let l = (0..ida.ims.len())
                    .find(|&l| ida.counts[l] > 0 && ida.fractiles[l][k].is_infinite())?;
                Some(format!("the {f} % from {}", ida.ims[l]))
            })
            .collect();
        note!(
            "notice: collapsed runs are infinite demands (Vamvatsikos & Cornell 2002): a curve flatlines at its first collapse and is collapsed at every level above it; a fractile is infinite (`inf`) where the collapses reach it{}",
            if flat.is_empty() {
                ": none does here".to_string()
            } else {
                format!(": {}", flat.join(", "))
            }
        );
    }
    if ida.resurrected + ida.filled > 0 {
        let mut what = Vec::new();
        if ida.resurrected > 0 {
            what.push(format!(
                "{} runs that did not collapse (structural resurrection)",
                ida.resurrected
            ));
        }
        if ida.filled > 0 {
            what.push(format!("{} levels with no run", ida.filled));
        }
        note!(
            "notice: above their curve's first collapse, {} are counted as collapsed: the first collapse is the curve's capacity",
            what.join(" and ")
        );
    }
    let plot = a.plot.as_deref().map(|p| {
        let mut panels = vec![ida.panel(&spec)];
        panels.extend(ida.collapse_panel(&spec));
        let cols = panels.len();
        (p, panels, cols)
    });
    super::write_and_plot(&output, ida.csv(&spec).as_bytes(), plot, &a.figure)
}
