//! `pound plot`: an output of a results CSV against a swept parameter.

use super::{check_study_outputs, Holds};
use anyhow::{bail, Result};
use clap::ValueEnum;
use pounding::io::table::{Filter, Table};
use pounding::studies::sensitivity::{panel, Aggregate, PlotSpec};
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Args {
    /// A CSV written by `pound sweep` (or any CSV with a header row).
    results: PathBuf,
    /// Column on the x axis (a swept parameter, e.g. gap_m, e, t1_s, pga_g).
    #[arg(long)]
    x: String,
    /// Column on the y axis (an output, e.g. peak_force_n).
    #[arg(long)]
    y: String,
    /// One series per value of this column (e.g. record, law).
    #[arg(long)]
    by: Option<String>,
    /// Keep only rows with COLUMN=VALUE (also !=, <, <=, >, >=); repeat to combine.
    #[arg(long = "where", value_name = "FILTER")]
    filters: Vec<String>,
    /// How rows that share x (and series) are combined: the other swept parameters are
    /// aggregated. `none` draws every row as a point.
    #[arg(long, value_enum, default_value = "max")]
    agg: AggArg,
    #[arg(long)]
    log_x: bool,
    #[arg(long)]
    log_y: bool,
    /// `--title` (default: what is plotted against what, the aggregation and the filters) and
    /// `--size`.
    #[command(flatten)]
    figure: super::FigureArgs,
    /// Output: .svg, or .png (text in a font built into the binary).
    /// (default: plot.svg, numbered `-2`, `-3`, ... where that file exists)
    #[arg(short, long)]
    output: Option<PathBuf>,
}

#[derive(Clone, Copy, ValueEnum)]
enum AggArg {
    Max,
    Mean,
    Median,
    Min,
    None,
}

pub fn run(a: Args) -> Result<()> {
    let output = super::default_output(a.output.clone(), "plot.svg");
    check_study_outputs(&a.results, &[], &[("-o", Some(&output), Holds::Plot)])?;
    let table = Table::read(&a.results)?;
    let spec = PlotSpec {
        x: a.x,
        y: a.y,
        by: a.by,
        filters: Filter::parse_all(&a.filters)?,
        aggregate: match a.agg {
            AggArg::Max => Aggregate::Max,
            AggArg::Mean => Aggregate::Mean,
            AggArg::Median => Aggregate::Median,
            AggArg::Min => Aggregate::Min,
            AggArg::None => Aggregate::None,
        },
        log_x: a.log_x,
        log_y: a.log_y,
    };
    let (mut p, left_out) = panel(&table, &spec)?;
    a.figure.apply(std::slice::from_mut(&mut p))?;
    for line in left_out.lines() {
        note!("{}: {line}", a.results.display());
    }
    // A log axis cannot show a value <= 0: such points are left out, with a count, and a
    // series left with none is named and not drawn (nor listed in the legend).
    let off = |&(x, y): &(f64, f64)| (spec.log_x && x <= 0.0) || (spec.log_y && y <= 0.0);
    let off_log = p
        .series
        .iter()
        .flat_map(|s| &s.points)
        .filter(|q| off(q))
        .count();
    if off_log > 0 {
        note!(
            "{}: {off_log} points left out: a value <= 0 on a log axis (--log-x / --log-y)",
            a.results.display()
        );
    }
    p.series.retain(|s| {
        let drawn = s.points.iter().any(|q| !off(q));
        if !drawn {
            note!(
                "{}: no series drawn for {}: every one of its points is <= 0 on a log axis",
                a.results.display(),
                s.name
            );
        }
        drawn
    });
    let points: usize = p.series.iter().map(|s| s.points.len()).sum::<usize>()
        - p.series
            .iter()
            .flat_map(|s| &s.points)
            .filter(|q| off(q))
            .count();
    if points == 0 {
        let why = if table.rows.is_empty() {
            "the file has a header but no rows".to_string()
        } else if spec.filters.is_empty() {
            "every row was left out, as counted above".to_string()
        } else {
            format!(
                "check --where, and that {} and {} have values",
                spec.x, spec.y
            )
        };
        bail!("{}: no rows left to plot: {why}", a.results.display());
    }
    // The line below says what was written.
    a.figure.save(&output, std::slice::from_ref(&p), 1)?;
    note!(
        "{} series, {points} points -> {}",
        p.series.len(),
        output.display()
    );
    Ok(())
}
