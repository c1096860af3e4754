//! `pound restitution`: one isolated collision per damped law, formula and e.

use super::{check_outputs, e_values, write_file};
use anyhow::{Context, Result};
use pounding::studies::fidelity;
use std::io::Write as _;
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Args {
    /// Values of e: start:stop:step, a list a,b,c, or one value.
    #[arg(long, default_value = "0.1:1:0.05")]
    e: String,
    /// Every collision as CSV.
    #[arg(short, long, default_value = "restitution.csv")]
    output: PathBuf,
    /// Achieved against asked e, one panel per law (SVG).
    #[arg(long)]
    plot: Option<PathBuf>,
}

pub fn run(a: Args) -> Result<()> {
    check_outputs(
        &[],
        &[("-o", Some(&a.output)), ("--plot", a.plot.as_deref())],
    )?;
    let rows = fidelity::table(&e_values(&a.e)?)?;
    write_file(&a.output, fidelity::csv(&rows).as_bytes())?;
    say!("max |achieved e - asked e| per law and formula (`own`: the law's own chi(e)):\n");
    write!(std::io::stdout(), "{}", fidelity::summary(&rows))
        .context("writing to standard output")?;
    if let Some(p) = &a.plot {
        pounding::studies::plot::svg(p, &fidelity::panels(&rows), 4)?;
    }
    note!("{} collisions -> {}", rows.len(), a.output.display());
    Ok(())
}
