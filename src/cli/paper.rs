//! `pound paper`: the seed paper's cheap checks, as markdown on standard output.

use anyhow::{Context, Result};
use std::io::Write as _;

pub fn run() -> Result<()> {
    write!(std::io::stdout(), "{}", pounding::studies::paper::report()?)
        .context("writing to standard output")
}
