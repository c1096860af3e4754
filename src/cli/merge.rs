//! `pound merge`: shard outputs combined into one, checked.

use anyhow::Result;
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Args {
    /// Shard outputs (CSV files written by `pound sweep --shard`), in any order.
    #[arg(required = true)]
    inputs: Vec<PathBuf>,
    /// (default: results.csv, numbered `-2`, `-3`, ... where that file exists)
    #[arg(short, long)]
    output: Option<PathBuf>,
}

pub fn run(a: Args) -> Result<()> {
    let output = super::default_output(a.output.clone(), "results.csv");
    // Merge writes CSV (its own checks of inputs against the output follow).
    super::check_extension("-o", &output, super::Holds::Csv)?;
    let rows = pounding::io::merge::merge(&output, &a.inputs)?;
    note!(
        "{rows} runs from {} inputs -> {}",
        a.inputs.len(),
        output.display()
    );
    Ok(())
}
