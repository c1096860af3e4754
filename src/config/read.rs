//! Reading a config file: its text, its kind (a pair or a row, told here once), its TOML into
//! the raw sections, and where its records are looked up.

use crate::config::error::{toml_error, ConfigError};
use crate::config::pair::RawConfig;
use crate::config::row::RawRowConfig;
use crate::config::sections::RawRecord;
use crate::record::set::{read_set, results_path, COMPONENTS};
use std::path::{Path, PathBuf};

/// Default directory of real records when `POUND_RECORDS_DIR` is unset (relative to the working
/// directory, i.e. the repository root beside `shared/`).
pub const DEFAULT_RECORDS_DIR: &str = "../shared/records";

/// Where `file = ...` records are looked up from the working directory: `POUND_RECORDS_DIR`,
/// else [`DEFAULT_RECORDS_DIR`].
pub fn records_dir() -> PathBuf {
    std::env::var_os("POUND_RECORDS_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(DEFAULT_RECORDS_DIR))
}

/// Where `file = ...` records of a config in folder `base` are looked up: `POUND_RECORDS_DIR`
/// if set; else [`DEFAULT_RECORDS_DIR`] from the working directory where that folder exists;
/// else the first `shared/records` beside the config's folder or a folder above it (so a
/// command run from elsewhere finds the records of a config in a checkout beside `shared/`).
pub fn records_dir_for(base: &Path) -> PathBuf {
    let default = records_dir();
    if std::env::var_os("POUND_RECORDS_DIR").is_some() || default.is_dir() {
        return default;
    }
    let from = std::fs::canonicalize(if base.as_os_str().is_empty() {
        Path::new(".")
    } else {
        base
    });
    from.ok()
        .and_then(|b| {
            b.ancestors()
                .map(|a| a.join("shared").join("records"))
                .find(|d| d.is_dir())
        })
        .unwrap_or(default)
}

/// Why a `file = ` record is not found: where it was looked for and how to point elsewhere.
pub fn missing_record(name: &str, looked: &Path) -> String {
    let how = match std::env::var_os("POUND_RECORDS_DIR") {
        Some(_) => "POUND_RECORDS_DIR is set to that folder".to_string(),
        None => format!(
            "POUND_RECORDS_DIR is unset, so {DEFAULT_RECORDS_DIR} from the working directory and shared/records beside the config's folders were tried"
        ),
    };
    format!(
        "file = \"{name}\": no such record in {} ({how}); set POUND_RECORDS_DIR to the folder that holds it, or give path = \"...\" (relative to the config) instead",
        looked.display()
    )
}

/// The text of a config file, read once (it may be a pipe: `pound sweep <(make-config)`).
pub fn read_text(path: &Path) -> Result<String, ConfigError> {
    let text = std::fs::read_to_string(path).map_err(|error| ConfigError::Io {
        path: path.into(),
        error,
    })?;
    // A UTF-8 byte-order mark (Windows editors write one) is not TOML.
    Ok(match text.strip_prefix('\u{feff}') {
        Some(rest) => rest.to_string(),
        None => text,
    })
}

/// Does config `text` describe a row (`[[building]]` entries)? Text that is not TOML is not.
/// The one place a config's kind is told: every other layer asks the plan.
fn is_row_config(text: &str) -> bool {
    text.parse::<toml::Table>()
        .is_ok_and(|t| t.contains_key("building"))
}

/// Yielding storeys need a storey height and belong to `[[building]]`: a pair's `[building1]`
/// or `[building2]` that gives one is told how to write it.
fn refuse_yielding_pair(text: &str, path: &Path) -> Result<(), ConfigError> {
    let Ok(table) = text.parse::<toml::Table>() else {
        return Ok(());
    };
    for b in ["building1", "building2"] {
        let Some(keys) = table.get(b).and_then(|v| v.as_table()) else {
            continue;
        };
        if let Some(k) = keys
            .keys()
            .find(|k| k.starts_with("yield_") || *k == "post_yield_ratio")
        {
            return Err(ConfigError::Invalid {
                path: path.into(),
                key: format!("{b}.{k}"),
                message: "yielding storeys are given per [[building]]: write the pair as a row of two one-storey buildings ([[building]] with storeys = 1 and storey_height_m; configs/inelastic-pair.toml)".into(),
            });
        }
    }
    Ok(())
}

/// The record files config `text` (read from `path`) reads, `file =` and `path =` records
/// resolved, so a command can refuse to write over one of them. Text that does not parse lists
/// none (loading it reports the error).
pub fn input_files(text: &str, path: &Path) -> Vec<PathBuf> {
    let raw_records = match toml::from_str::<RawConfig>(text) {
        Ok(raw) => raw.records,
        Err(_) => match toml::from_str::<RawRowConfig>(text) {
            Ok(raw) => raw.records,
            Err(_) => return Vec::new(),
        },
    };
    let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
    // A set's search results, and its records' files.
    let results: Vec<PathBuf> = (raw_records.iter())
        .filter_map(|r| r.set.as_ref())
        .map(|dir| results_path(&base.join(dir)))
        .collect();
    let Ok(raw_records) = expand_sets(raw_records, path) else {
        return results;
    };
    let records = records_dir_for(&base);
    raw_records
        .iter()
        .filter_map(|r| r.file_path(&base, &records))
        .chain(results)
        .collect()
}

/// A config as written, of either kind.
#[derive(Debug, Clone)]
pub enum Config {
    /// `[building1]` and `[building2]`.
    Pair(Box<RawConfig>),
    /// `[[building]]` entries.
    Row(Box<RawRowConfig>),
}

/// Config `text` read from `path` (named in errors) into its raw sections, its kind told by
/// whether it has `[[building]]` entries. A pair that gives yielding storeys is told how to
/// write it as a row.
pub fn from_text(text: &str, path: &Path) -> Result<Config, ConfigError> {
    Ok(if is_row_config(text) {
        Config::Row(Box::new(row_from_text(text, path)?))
    } else {
        refuse_yielding_pair(text, path)?;
        Config::Pair(Box::new(pair_from_text(text, path)?))
    })
}

/// Config `text` read as a pair's (`[building1]` and `[building2]`).
pub fn pair_from_text(text: &str, path: &Path) -> Result<RawConfig, ConfigError> {
    let mut raw: RawConfig = toml::from_str(text).map_err(|e| toml_error(path, e))?;
    raw.records = expand_sets(std::mem::take(&mut raw.records), path)?;
    Ok(raw)
}

/// Config `text` read as a row's (`[[building]]` entries).
pub fn row_from_text(text: &str, path: &Path) -> Result<RawRowConfig, ConfigError> {
    let mut raw: RawRowConfig = toml::from_str(text).map_err(|e| toml_error(path, e))?;
    raw.records = expand_sets(std::mem::take(&mut raw.records), path)?;
    Ok(raw)
}

/// Each `[[record]] set = "DIR"` of a config at `path` as the records its search lists, one
/// per record and component (`path =` its file, labelled `RSN6_H1`, scaled by the search's
/// factor where `search_scale`); the other records as written.
fn expand_sets(records: Vec<RawRecord>, path: &Path) -> Result<Vec<RawRecord>, ConfigError> {
    let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let invalid = |key: String, message: String| ConfigError::Invalid {
        path: path.into(),
        key,
        message,
    };
    let mut out = Vec::with_capacity(records.len());
    for (i, r) in records.into_iter().enumerate() {
        let Some(dir) = r.set.clone() else {
            if let Some(k) = [
                ("components", r.components.is_some()),
                ("search_scale", r.search_scale.is_some()),
            ]
            .iter()
            .find(|(_, given)| *given)
            {
                return Err(invalid(
                    format!("record[{i}].{}", k.0),
                    "applies to a record set (set = \"DIR\"), not to one record".into(),
                ));
            }
            out.push(RawRecord {
                written_at: Some(i),
                ..r
            });
            continue;
        };
        if r.file.is_some() || r.path.is_some() || r.synthetic.is_some() {
            return Err(invalid(
                format!("record[{i}]"),
                "give exactly one of file, path, synthetic or set".into(),
            ));
        }
        if r.name.is_some() {
            return Err(invalid(
                format!("record[{i}].name"),
                "a set's records are labelled by RSN and component (RSN6_H1): leave name out"
                    .into(),
            ));
        }
        let bad_components = |m: String| invalid(format!("record[{i}].components"), m);
        let expected = "expected any of \"H1\", \"H2\", \"V\"";
        let components: Vec<usize> = match &r.components {
            None => vec![0, 1],
            Some(list) if list.is_empty() => {
                return Err(bad_components(format!("is empty: {expected}")))
            }
            Some(list) => {
                let mut picked = Vec::new();
                for c in list {
                    let at = COMPONENTS
                        .iter()
                        .position(|k| k.eq_ignore_ascii_case(c.trim()));
                    match at {
                        Some(at) if !picked.contains(&at) => picked.push(at),
                        Some(_) => return Err(bad_components(format!("`{c}` is given twice"))),
                        None => return Err(bad_components(format!("`{c}`: {expected}"))),
                    }
                }
                picked
            }
        };
        if dir.trim().is_empty() {
            return Err(invalid(
                format!("record[{i}].set"),
                "is empty: give the folder of a PEER NGA-West2 search (its records and _SearchResults.csv), relative to the config".into(),
            ));
        }
        let set = read_set(&base.join(&dir)).map_err(|error| ConfigError::Record {
            path: path.into(),
            key: format!("record[{i}].set"),
            error,
        })?;
        for rec in &set.records {
            for &c in &components {
                let Some(file) = &rec.files[c] else {
                    return Err(invalid(
                        format!("record[{i}].components"),
                        format!(
                            "RSN {} has no {} file in {} (line {}): leave {} out of components",
                            rec.rsn,
                            COMPONENTS[c],
                            set.results.display(),
                            rec.line,
                            COMPONENTS[c]
                        ),
                    ));
                };
                let factor = match (r.search_scale.unwrap_or(false), rec.scale_factor) {
                    (false, _) => None,
                    (true, Some(f)) if f > 0.0 => Some(f),
                    (true, f) => {
                        return Err(invalid(
                            format!("record[{i}].search_scale"),
                            format!(
                                "RSN {} has {} in {} (line {}): expected a scale factor > 0",
                                rec.rsn,
                                f.map_or("no Scale Factor".into(), |f| format!(
                                    "a Scale Factor of {f}"
                                )),
                                set.results.display(),
                                rec.line
                            ),
                        ))
                    }
                };
                out.push(RawRecord {
                    path: Some(file.to_string_lossy().into_owned()),
                    name: Some(rec.label(c)),
                    set: None,
                    components: None,
                    search_scale: None,
                    factor,
                    meta: Some(rec.meta(c)),
                    written_at: Some(i),
                    ..r.clone()
                });
            }
        }
    }
    Ok(out)
}
