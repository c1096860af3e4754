//! A config's plan: the entry points that read a config file ([`crate::config`], its raw
//! sections) and decode it ([`crate::plan::decode`]) into a validated [`Plan`], of a pair or a
//! row as the config describes. Every error names the file and the key.

use crate::config::read::{self, records_dir_for, Config};
use crate::plan::decode::contact::Reading;
use crate::plan::decode::{pair::parse_raw, row::parse_row_as};
use crate::plan::pair::PairPlan;
use crate::plan::row::RowPlan;
use crate::plan::scene::Plan;
use std::path::Path;

/// What the loaders' callers use beside them (a config's text read once, the record files it
/// names, its errors), from the config layer where they live: the call sites stay as they were.
pub use crate::config::{input_files, read_text, records_dir, ConfigError};

/// Read and validate a config file, of any scene.
pub fn load(path: &Path) -> Result<Plan, ConfigError> {
    load_with_text(path).map(|(plan, _)| plan)
}

/// [`load`], also returning the config's text (for [`changed_records`]).
pub fn load_with_text(path: &Path) -> Result<(Plan, String), ConfigError> {
    let text = read_text(path)?;
    let plan = load_text(&text, path)?;
    Ok((plan, text))
}

/// Read and validate the config of a pair (`[building1]` and `[building2]`): for the studies
/// built on the pair's runs alone. A row config is refused, naming its key.
pub fn load_pair(path: &Path) -> Result<PairPlan, ConfigError> {
    match load(path)? {
        Plan::Pair(p) => Ok(p),
        Plan::Row(_) => Err(ConfigError::Invalid {
            path: path.into(),
            key: "building".into(),
            message: "a row of [[building]] entries: expected a pair ([building1] and [building2])"
                .into(),
        }),
    }
}

/// Validate config `text` read from `path` (records resolved beside it and in
/// [`crate::config::records_dir`]): a pair's or a row's plan, as the config describes.
pub fn load_text(text: &str, path: &Path) -> Result<Plan, ConfigError> {
    load_text_as(text, path, Reading::Sweep)
}

/// [`load_text`] for a gap study (`pound gap`), which runs the config without its contact and
/// gap axes: a config may leave out `[contact]` and its gaps (the study computes the gaps each
/// pair needs); where it gives them, they are read as a sweep reads them (a gap axis of two
/// values or more is where the study counts the probability of pounding).
pub fn load_text_for_gaps(text: &str, path: &Path) -> Result<Plan, ConfigError> {
    load_text_as(text, path, Reading::GapStudy)
}

fn load_text_as(text: &str, path: &Path, reading: Reading) -> Result<Plan, ConfigError> {
    let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let records = records_dir_for(&base);
    Ok(match read::from_text(text, path)? {
        Config::Row(raw) => Plan::Row(parse_row_as(&raw, path, &base, &records, reading)?),
        Config::Pair(raw) => Plan::Pair(parse_raw(&raw, path, &base, &records, reading)?),
    })
}

/// The records of `plan` (from the config `text` at `path`) whose files no longer hold what was
/// read, by name; or why they cannot be read again. A sweep reads its records once, so this
/// finds files changed while it ran.
pub fn changed_records(text: &str, path: &Path, plan: &Plan) -> Vec<String> {
    match load_text(text, path) {
        Err(e) => vec![format!("the records can no longer be read ({e})")],
        Ok(now) => plan
            .contact()
            .spec
            .records
            .iter()
            .zip(&now.contact().spec.records)
            .filter(|(a, b)| a != b)
            .map(|(a, _)| format!("record `{}`", a.name))
            .collect(),
    }
}

/// Validate the row config `text` read from `path` ([`crate::plan::row`]).
pub fn load_row_text(text: &str, path: &Path) -> Result<RowPlan, ConfigError> {
    let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
    parse_row(text, path, &base, &records_dir_for(&base))
}

/// The columns a sweep of this config writes, in file order (a pair's or a row's).
pub fn columns_of(text: &str, path: &Path) -> Result<Vec<String>, ConfigError> {
    Ok(load_text(text, path)?.header())
}

/// A plan from config text that names no record file (synthetic records only), `name` standing
/// for its file in messages: built-in sweeps (`pound bench`) and tests.
pub fn parse_builtin(text: &str, name: &str) -> Result<PairPlan, ConfigError> {
    parse(text, Path::new(name), Path::new("."), Path::new("."))
}

/// Parse and validate config text. `path` names the file in errors; `base` resolves `path =`
/// records; `records` resolves `file =` records.
pub fn parse(
    text: &str,
    path: &Path,
    base: &Path,
    records: &Path,
) -> Result<PairPlan, ConfigError> {
    parse_raw(
        &read::pair_from_text(text, path)?,
        path,
        base,
        records,
        Reading::Sweep,
    )
}

/// Validate a row config read from `path` (records resolved beside it, `base`, and in
/// `records`).
pub fn parse_row(
    text: &str,
    path: &Path,
    base: &Path,
    records: &Path,
) -> Result<RowPlan, ConfigError> {
    parse_row_as(
        &read::row_from_text(text, path)?,
        path,
        base,
        records,
        Reading::Sweep,
    )
}
