//! `pound trace`: one run of a sweep, whole: its time history and its row.

use super::Holds;
use anyhow::Result;
use pounding::plan::config;
use pounding::studies::trace;
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Args {
    /// The sweep config (a pair, [building1] and [building2], or a row of [[building]]).
    config: PathBuf,
    /// The run's number, as in the sweep's `run` column.
    #[arg(long)]
    run: u64,
    /// The time history at every record step and located event. A pair: displacements,
    /// velocities, absolute floor accelerations, penetration, contact force, contact mode. A
    /// row: every floor's displacement, each level's penetration, force and mode, and each
    /// yielding storey's drift and plastic drift ratios, shear and hysteretic energy; an IMK
    /// storey's drift (m), the force its law gives (N) and its branch too.
    /// (default: trace.csv, numbered `-2`, `-3`, ... where that file exists)
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Displacements (a row's roofs) and contact force (per level) against time, force against
    /// penetration; where storeys yield, each yielding building's hysteresis loop and
    /// hysteretic energy (.svg or .png).
    #[arg(long)]
    plot: Option<PathBuf>,
    #[command(flatten)]
    figure: super::FigureArgs,
}

pub fn run(a: Args) -> Result<()> {
    let output = super::default_output(a.output.clone(), "trace.csv");
    let text = super::config_checked(
        &a.config,
        &[
            ("-o", Some(&output), Holds::Csv),
            ("--plot", a.plot.as_deref(), Holds::Plot),
        ],
    )?;
    let plan = config::load_text(&text, &a.config)?;
    let t = trace::trace(&plan, a.run)?;
    // The run's row, as the sweep writes it: the trace's peaks are the sweep's.
    say!("{}", t.header.join(","));
    say!("{}", t.row.join(","));
    let plot = a.plot.as_deref().map(|p| (p, t.panels(), 3));
    super::write_and_plot(&output, t.csv().as_bytes(), plot, &a.figure)?;
    note!(
        "run {} of {}: {} samples (record steps and located events) -> {}",
        a.run,
        a.config.display(),
        t.len(),
        output.display()
    );
    Ok(())
}
