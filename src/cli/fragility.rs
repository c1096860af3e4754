//! `pound fragility`: exceedance counts and fitted lognormal curves from a results CSV.

use super::{check_study_outputs, write_file, Holds};
use anyhow::{bail, Result};
use pounding::io::table::{Filter, Table};
use pounding::studies::fragility::{csv, fit, levels, panel, FragilitySpec};
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Args {
    /// A CSV written by `pound sweep`.
    results: PathBuf,
    /// Intensity measure column (e.g. pga_g, scale_factor).
    #[arg(long, default_value = "pga_g")]
    im: String,
    /// Demand column (e.g. peak_force_n; `impacts` with threshold 0 for "pounds at all").
    #[arg(long, default_value = "peak_force_n")]
    edp: String,
    /// Exceedance thresholds (EDP > threshold), comma-separated.
    #[arg(long, value_delimiter = ',', required = true)]
    threshold: Vec<f64>,
    /// Keep only rows with COLUMN=VALUE (also !=, <, <=, >, >=); repeat to combine.
    #[arg(long = "where", value_name = "FILTER")]
    filters: Vec<String>,
    /// Counts per threshold and level (CSV).
    /// (default: fragility.csv, numbered `-2`, `-3`, ... where that file exists)
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Observed fractions and fitted curves (.svg or .png).
    #[arg(long)]
    plot: Option<PathBuf>,
}

pub fn run(a: Args) -> Result<()> {
    let output = super::default_output(a.output.clone(), "fragility.csv");
    check_study_outputs(
        &a.results,
        &[
            ("-o", Some(&output), Holds::Csv),
            ("--plot", a.plot.as_deref(), Holds::Plot),
        ],
    )?;
    let table = Table::read(&a.results)?;
    let spec = FragilitySpec {
        im: a.im,
        edp: a.edp,
        thresholds: a.threshold,
        filters: Filter::parse_all(&a.filters)?,
    };
    let (lv, skipped) = levels(&table, &spec)?;
    let runs: u64 = lv.first().map_or(0, |l| l.iter().map(|x| x.n).sum());
    if runs == 0 {
        bail!(
            "{}: no runs left to count (check --where)",
            a.results.display()
        );
    }
    let fits: Vec<_> = lv.iter().map(|l| fit(l)).collect();
    say!(
        "{runs} runs at {} levels of {}{}",
        lv[0].len(),
        spec.im,
        if skipped.total() > 0 {
            format!(" ({} rows left out: {skipped})", skipped.total())
        } else {
            String::new()
        }
    );
    say!("\n| {} > | median {} | beta | se(ln median) | se(beta) | log-likelihood | deviance (dof) | p (fit) |\n|---:|---:|---:|---:|---:|---:|---:|---:|", spec.edp, spec.im);
    let mut poor = Vec::new();
    for (t, f) in spec.thresholds.iter().zip(&fits) {
        match f {
            Ok(f) => {
                say!(
                    "| {t} | {:.4} | {:.4} | {:.4} | {:.4} | {:.2} | {:.2} ({}) | {} |",
                    f.median,
                    f.beta,
                    f.se_ln_median,
                    f.se_beta,
                    f.log_likelihood,
                    f.deviance,
                    f.dof,
                    f.p_fit.map_or("-".into(), |p| format!("{p:.3}"))
                );
                if f.p_fit.is_some_and(|p| p < 0.05) {
                    poor.push(t.to_string());
                }
            }
            Err(e) => say!("| {t} | no fit: {e} | | | | | | |"),
        }
    }
    if !poor.is_empty() {
        note!(
            "notice: the shares above {} do not follow a lognormal curve (goodness of fit p < 0.05): the deviance against each level's own share is larger than chance allows; read the fitted median and beta with care",
            poor.join(", ")
        );
    }
    write_file(&output, csv(&spec, &lv).as_bytes())?;
    if let Some(p) = &a.plot {
        super::save_plot(p, &[panel(&spec, &lv, &fits)], 1)?;
    }
    Ok(())
}
