//! A way in: `pound init KIND` prints a commented starting config that runs as is (synthetic
//! records, no files needed); `pound columns [CONFIG]` lists the output columns with their units
//! and meanings.

use anyhow::Result;
use clap::ValueEnum;
use pounding::plan::{config, meaning};
use std::io::Write;
use std::path::PathBuf;

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Kind {
    /// Two single-storey buildings: restitution formulas, e, periods and gaps (2,700 runs).
    Pair,
    /// A 3-storey building beside a 6-storey one, pounding floor against floor (180 runs).
    Row,
    /// Uncertain periods, damping and gap over an intensity ladder, for `pound fragility`.
    Fragility,
    /// A period grid for `pound gap`: the separation two buildings need.
    Gap,
    /// A yielding frame that pounds, over records and intensities, for the fragility of its
    /// ductility demand or residual drift (120 runs).
    Inelastic,
}

impl Kind {
    /// The template (a shipped config) and the command that runs it.
    fn template(self) -> (&'static str, &'static str) {
        match self {
            Kind::Pair => (
                include_str!("../../configs/quickstart.toml"),
                "pound sweep my.toml -o results.csv",
            ),
            Kind::Row => (
                include_str!("../../configs/row-3-6.toml"),
                "pound sweep my.toml -o results.csv",
            ),
            Kind::Fragility => (
                include_str!("../../configs/fragility-example.toml"),
                "pound sweep my.toml -o runs.csv && pound fragility runs.csv --edp peak_force_n --threshold 0,1e6",
            ),
            Kind::Gap => (
                include_str!("../../configs/gap-example.toml"),
                "pound gap my.toml -o gaps.csv --plot gaps.svg",
            ),
            Kind::Inelastic => (
                include_str!("../../configs/inelastic-fragility.toml"),
                "pound sweep my.toml -o runs.csv && pound fragility runs.csv --edp b1_peak_ductility --threshold 1,2,4",
            ),
        }
    }
}

#[derive(clap::Args)]
pub struct InitArgs {
    /// What the config studies.
    #[arg(value_enum)]
    kind: Kind,
}

#[derive(clap::Args)]
pub struct ColumnsArgs {
    /// A sweep config: its own columns (a row's name each building and contact level);
    /// without one, a pair's.
    config: Option<PathBuf>,
    /// Every column the config can give: a row's storeys' and floors' too, written only when
    /// `pound sweep --columns` asks for them (`+storeys`, `+floors` or by name).
    #[arg(long)]
    all: bool,
}

pub fn init(a: InitArgs) -> Result<()> {
    let (text, command) = a.kind.template();
    // The template goes to stdout whole (to be redirected into a file); the hint to stderr.
    std::io::stdout().write_all(text.as_bytes())?;
    note!("# then: {command}  (keys: README.md \"A config\"; columns: pound columns my.toml)");
    Ok(())
}

pub fn columns(a: ColumnsArgs) -> Result<()> {
    let plan = match &a.config {
        Some(path) => Some(config::load_text(&config::read_text(path)?, path)?),
        None => None,
    };
    // A row with every group on: its columns written only when asked too (its storeys' and
    // floors'), in the order a sweep writes them.
    let every = match &plan {
        Some(pounding::plan::Plan::Row(row)) => Some(row.with_every_group()),
        _ => None,
    };
    let names = match (&plan, &every) {
        (_, Some(every)) if a.all => every.header(),
        (Some(plan), _) => plan.header(),
        (None, _) => pounding::plan::columns::header()
            .into_iter()
            .map(String::from)
            .collect(),
    };
    std::io::stdout().write_all(meaning::table(&names).as_bytes())?;
    // A row's contact levels, where each is and what meets there, on stderr: standard output
    // holds the one table of columns.
    if let Some(pounding::plan::Plan::Row(row)) = &plan {
        if !row.is_empty() && !row.level_names().is_empty() {
            note!("\ncontact levels:\n{}", row.level_table().trim_end());
        }
        if let (false, Some(every)) = (a.all, &every) {
            let more = every.header().len() - names.len();
            let groups: Vec<String> = (pounding::plan::columns::row::COLUMN_GROUPS.iter())
                .map(|(g, what)| format!("{g}: {what}"))
                .collect();
            note!(
                "\n{more} more columns when asked, by name or by group with `pound sweep --columns` ({}); `pound columns {} --all` lists them",
                groups.join("; "),
                a.config.as_deref().map_or(String::new(), |p| p.display().to_string())
            );
        }
    }
    Ok(())
}
