//! `pound plot`: an output of a results CSV against a swept parameter.

use super::{check_study_outputs, Holds};
use anyhow::{bail, Result};
use clap::ValueEnum;
use pounding::io::table::{Filter, Table};
use pounding::studies::sensitivity::{panel_with, Aggregate, Collapsed, PlotSpec};
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
    #[arg(long, value_name = "COLUMN")]
    series: Option<String>,
    /// The old spelling of --series.
    #[arg(long, hide = true, conflicts_with = "series")]
    by: Option<String>,
    /// Keep only rows with COLUMN=VALUE (also !=, <, <=, >, >=); repeat to combine.
    #[arg(long = "where", value_name = "FILTER")]
    filters: Vec<String>,
    /// How rows that share x (and series) are combined: the other swept parameters are
    /// aggregated. `none` draws every row as a point.
    #[arg(long, value_enum, default_value = "max")]
    agg: AggArg,
    /// Runs that collapsed (`status` collapsed; for a building's column, `bK_...`, that
    /// building's `bK_collapsed` where the CSV has it): `omit` leaves them out, `mark` draws
    /// their peaks before the collapse apart, as crossed squares. Either way the figure's
    /// caption counts them per x value (and series), and an x value where every run collapsed
    /// stays on the axis, marked.
    #[arg(long, value_enum, default_value = "omit")]
    collapsed: CollapsedArg,
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
enum CollapsedArg {
    Omit,
    Mark,
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
        by: super::renamed(a.series, a.by, "--by", "--series"),
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
    let collapsed = match a.collapsed {
        CollapsedArg::Omit => Collapsed::Omit,
        CollapsedArg::Mark => Collapsed::Mark,
    };
    let (mut p, left_out) = panel_with(&table, &spec, collapsed)?;
    a.figure.apply(std::slice::from_mut(&mut p))?;
    for line in left_out.lines() {
        note!("{}: {line}", a.results.display());
    }
    for line in &p.notes.caption {
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
    let marked = |i: usize| p.notes.collapsed.iter().any(|(k, q)| *k == i && !off(q));
    let kept: Vec<bool> = (p.series.iter().enumerate())
        .map(|(i, s)| {
            let drawn = s.points.iter().any(|q| !off(q)) || marked(i);
            if !drawn {
                note!(
                    "{}: no series drawn for {}: every one of its points is <= 0 on a log axis",
                    a.results.display(),
                    s.name
                );
            }
            drawn
        })
        .collect();
    // The collapsed runs' marks follow their series to its place among those kept.
    let place: Vec<Option<usize>> = kept
        .iter()
        .scan(0, |n, &k| {
            *n += usize::from(k);
            Some(k.then(|| *n - 1))
        })
        .collect();
    let mut k = 0;
    p.series.retain(|_| {
        k += 1;
        kept[k - 1]
    });
    p.notes.collapsed = std::mem::take(&mut p.notes.collapsed)
        .into_iter()
        .filter_map(|(i, q)| Some((place[i]?, q)))
        .collect();
    let points: usize = p.series.iter().map(|s| s.points.len()).sum::<usize>()
        - p.series
            .iter()
            .flat_map(|s| &s.points)
            .filter(|q| off(q))
            .count();
    let marks = p.notes.collapsed.iter().filter(|(_, q)| !off(q)).count();
    if points + marks == 0 && p.notes.x_marks.is_empty() {
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
    let apart = if marks > 0 {
        format!(", {marks} collapsed marked")
    } else {
        String::new()
    };
    note!(
        "{} series, {points} points{apart} -> {}",
        p.series.len(),
        output.display()
    );
    Ok(())
}
