//! `pound restitution`: one isolated collision per damped law, formula and e.

use super::{check_outputs, e_values, Holds};
use anyhow::Result;
use pounding::studies::fidelity;
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Args {
    /// Values of e: start:stop:step, a list a,b,c, or one value.
    #[arg(long, default_value = "0.1:1:0.05")]
    e: String,
    /// Every collision as CSV.
    /// (default: restitution.csv, numbered `-2`, `-3`, ... where that file exists)
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Achieved against asked e, one panel per law (SVG).
    #[arg(long)]
    plot: Option<PathBuf>,
    #[command(flatten)]
    figure: super::FigureArgs,
}

pub fn run(a: Args) -> Result<()> {
    let output = super::default_output(a.output.clone(), "restitution.csv");
    check_outputs(
        &[],
        &[
            ("-o", Some(&output), Holds::Csv),
            ("--plot", a.plot.as_deref(), Holds::Plot),
        ],
    )?;
    let rows = fidelity::table(&e_values(&a.e)?)?;
    say!("max |achieved e - asked e| per law and formula (`own`: the law's own chi(e)):\n");
    super::say_text(&fidelity::summary(&rows))?;
    let plot = a.plot.as_deref().map(|p| (p, fidelity::panels(&rows), 4));
    super::write_and_plot(&output, fidelity::csv(&rows).as_bytes(), plot, &a.figure)?;
    note!("{} collisions -> {}", rows.len(), output.display());
    Ok(())
}
