//! `pound ida`: IDA curves and their fractiles from a results CSV.

use super::{check_study_outputs, Holds};
use anyhow::Result;
use pounding::io::table::Table;
use pounding::studies::ida::{study, IdaOptions};
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
    /// Demand column (e.g. b1_peak_drift_ratio, peak_force_n). A collapse is an infinite demand:
    /// a curve flatlines at its first collapse, of a building's column (bK_...) building K's own
    /// (bK_collapsed), of a column of the run any building's (status `collapsed`).
    #[arg(long)]
    edp: String,
    /// The columns that name a curve, comma-separated (default: record, and sample where the
    /// CSV has samples).
    #[arg(long, value_delimiter = ',', value_name = "COLUMNS")]
    curves: Vec<String>,
    /// The old spelling of --curves.
    #[arg(long, value_delimiter = ',', hide = true, conflicts_with = "curves")]
    by: Vec<String>,
    /// Keep only rows with COLUMN=VALUE (also !=, <, <=, >, >=); repeat to combine.
    #[arg(long = "where", value_name = "FILTER")]
    filters: Vec<String>,
    /// Per level: the intensity, the curves there, the fractiles, the curves collapsed and their
    /// share, and each curve's demand (CSV; `inf` for a collapse).
    /// (default: ida.csv, numbered `-2`, `-3`, ... where that file exists)
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// The curves in long form (CSV): a row per curve and level, its --curves cells joined by `/`, the
    /// intensity, the demand (`inf` from its first collapse) and whether it has collapsed (1/0).
    #[arg(long, value_name = "FILE")]
    long: Option<PathBuf>,
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
            ("--long", a.long.as_deref(), Holds::Csv),
            ("--plot", a.plot.as_deref(), Holds::Plot),
        ],
    )?;
    let options = IdaOptions {
        im: a.im,
        edp: a.edp,
        by: super::renamed(
            Some(a.curves).filter(|c| !c.is_empty()),
            Some(a.by).filter(|c| !c.is_empty()),
            "--by",
            "--curves",
        )
        .unwrap_or_default(),
        filters: a.filters,
    };
    // The settings are checked before the results are read.
    options.check()?;
    let table = Table::read(&a.results)?;
    let report = study(&table, &options)?;
    report.tell(super::say_text, |n| note!("{n}"))?;
    let plot = a.plot.as_deref().map(|p| {
        let cols = report.panels.len();
        (p, report.panels, cols)
    });
    super::write_and_plot(&output, report.csv.as_bytes(), plot, &a.figure)?;
    super::write_tables(&report.tables, &[("long", a.long.as_deref())])
}
