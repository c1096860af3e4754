//! A config's errors in its own words: the file, the key, what was expected.

use crate::record::RecordError;
use std::path::{Path, PathBuf};

#[derive(Debug, thiserror::Error)]
pub enum ConfigError {
    #[error("{}: cannot read config: {error}", path.display())]
    Io {
        path: PathBuf,
        error: std::io::Error,
    },
    #[error("{}: {message}", path.display())]
    Toml { path: PathBuf, message: String },
    #[error("{}: {key}: {message}", path.display())]
    Invalid {
        path: PathBuf,
        key: String,
        message: String,
    },
    #[error("{}: {key}: {error}", path.display())]
    Record {
        path: PathBuf,
        key: String,
        error: RecordError,
    },
}

/// What a TOML error says, in the config's words: serde names Rust types (`f64`, `usize`,
/// `struct RawRun`) where the user wrote a number, a whole number or a table. The one place a
/// config's TOML error is made, for pairs and rows alike.
pub(crate) fn toml_error(path: &Path, e: toml::de::Error) -> ConfigError {
    ConfigError::Toml {
        path: path.into(),
        message: in_toml_words(e.to_string()),
    }
}

/// A TOML reader's message in the words of the file it read (a number, a list, a table), not
/// Rust's (`f64`, `sequence`, `map`, `struct RawX`), with a refused float shown short: for
/// configs and every other TOML file a command reads (damage states).
pub fn in_toml_words(message: String) -> String {
    let mut m = message;
    for (rust, words) in [
        ("expected f64", "expected a number"),
        ("expected usize", "expected a whole number >= 0"),
        ("expected u64", "expected a whole number >= 0"),
        ("expected u32", "expected a whole number >= 0"),
        ("expected i64", "expected a whole number"),
        ("expected a sequence", "expected a list"),
        ("invalid type: sequence", "invalid type: a list"),
        ("invalid type: map", "invalid type: a table"),
    ] {
        m = m.replace(rust, words);
    }
    // serde writes a float it refuses in full (`1e300` as 301 digits): as a message shows it.
    let mut from = 0;
    while let Some(i) = m[from..].find("floating point `").map(|i| from + i + 16) {
        let end = m[i..].find('`').map_or(m.len(), |j| i + j);
        let shown = m[i..end]
            .parse::<f64>()
            .map_or_else(|_| m[i..end].to_string(), crate::show);
        m.replace_range(i..end, &shown);
        from = i + shown.len();
    }
    while let Some(i) = m.find("expected struct ") {
        let name = i + "expected struct ".len();
        let end = m[name..]
            .find(|c: char| !c.is_alphanumeric())
            .map_or(m.len(), |j| name + j);
        m.replace_range(i..end, "expected a table");
    }
    m
}
