//! `pound formulas`: zeta(e) of every formula as CSV on standard output, and Fig. 2.

use super::{check_outputs, e_values, Holds};
use anyhow::Result;
use pounding::physics::restitution::Formula;
use pounding::studies::formulas;
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Args {
    /// Values of e: start:stop:step, a list a,b,c, or one value.
    #[arg(long, default_value = "0.1:1:0.05")]
    e: String,
    /// Also plot zeta against e for every formula (the seed's Fig. 2): .svg or .png.
    #[arg(long)]
    plot: Option<PathBuf>,
    #[command(flatten)]
    figure: super::FigureArgs,
}

pub fn run(a: Args) -> Result<()> {
    let es = e_values(&a.e)?;
    check_outputs(&[], &[("--plot", a.plot.as_deref(), Holds::Plot)])?;
    if let Some(path) = &a.plot {
        // The line below says what was written.
        a.figure.save(path, &formulas::zeta_panels(&es)?, 2)?;
        note!(
            "zeta(e) of {} formulas -> {}",
            Formula::ALL.len(),
            path.display()
        );
    }
    for row in formulas::table(&es)? {
        say!("{}", row.join(","));
    }
    Ok(())
}
