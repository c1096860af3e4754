//! `pound demands`: a sweep's demands of one building in the SimCenter format pelicun reads.

use super::{check_study_outputs, Holds};
use anyhow::Result;
use pounding::io::table::Table;
use pounding::studies::demands::{study, DemandsOptions};
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Args {
    /// A CSV written by `pound sweep --columns +storeys,+floors`.
    results: PathBuf,
    /// The building whose demands are written (from 1, left to right).
    #[arg(long)]
    building: usize,
    /// Keep only rows with COLUMN=VALUE (also !=, <, <=, >, >=); repeat to combine (e.g. one
    /// intensity level: --where target_sa_g=0.5).
    #[arg(long = "where", value_name = "FILTER")]
    filters: Vec<String>,
    /// The demand sample (CSV: a row per run, `1-PID-j-1`, `1-RID-j-1`, `1-PFA-j-1`, the target
    /// Sa as `1-SA_T-0-1` where the runs were scaled to one, and `1-COL-0-1` columns, a units
    /// row).
    /// (default: demands.csv, numbered `-2`, `-3`, ... where that file exists)
    #[arg(short, long)]
    output: Option<PathBuf>,
}

pub fn run(a: Args) -> Result<()> {
    let output = super::default_output(a.output.clone(), "demands.csv");
    check_study_outputs(&a.results, &[], &[("-o", Some(&output), Holds::Csv)])?;
    let table = Table::read(&a.results)?;
    let options = DemandsOptions {
        building: a.building,
        filters: a.filters,
    };
    let report = study(&table, &options)?;
    report.tell(super::say_text, |n| note!("{n}"))?;
    super::write_file(&output, report.csv.as_bytes())
}
