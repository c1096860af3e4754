//! `pound merge`: shard outputs combined into one, checked.

use anyhow::Result;
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Args {
    /// Shard outputs (CSV files written by `pound sweep --shard`), in any order.
    #[arg(required = true)]
    inputs: Vec<PathBuf>,
    #[arg(short, long, default_value = "results.csv")]
    output: PathBuf,
}

pub fn run(a: Args) -> Result<()> {
    let rows = pounding::io::merge::merge(&a.output, &a.inputs)?;
    note!(
        "{rows} runs from {} inputs -> {}",
        a.inputs.len(),
        a.output.display()
    );
    Ok(())
}
