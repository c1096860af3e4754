//! The sections every scene's config shares, as written: `[run]`, `[contact]`, `[[record]]`,
//! `[intensity]` and `[sample]`.

use crate::config::axis::Axis;
use crate::config::forms::{elements, forms};
use serde::Deserialize;
use std::path::{Path, PathBuf};

/// One string or a list of strings.
#[derive(Debug, Clone, PartialEq)]
pub enum Names {
    One(String),
    List(Vec<String>),
}

forms!(Names, "a name, or a list of names", {
    number: None,
    text: Some(Names::One),
    list: Some(|s| elements(s).map(Names::List)),
    table: None,
});

impl Names {
    pub fn list(&self) -> Vec<String> {
        match self {
            Names::One(s) => vec![s.clone()],
            Names::List(v) => v.clone(),
        }
    }
}

#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawRun {
    /// "fast" (default) or "reference".
    pub scheme: Option<String>,
    pub substeps_per_contact: Option<f64>,
    /// Stated accuracy of the reference scheme (relative, peak force).
    pub tol: Option<f64>,
    pub tail_s: Option<f64>,
    /// Report each run's energy balance (fast scheme; the reference always does).
    pub energy: Option<bool>,
    /// Rows: a run collapses when any storey's drift ratio reaches this (default
    /// [`crate::plan::limits::COLLAPSE_DRIFT_RATIO`]), or `"none"`.
    pub collapse_drift_ratio: Option<CollapseLimit>,
}

/// `collapse_drift_ratio` as written: a drift ratio, or `"none"` (runs never collapse).
#[derive(Debug, Clone, PartialEq)]
pub enum CollapseLimit {
    Ratio(f64),
    None,
    /// Any other text, refused by name when the plan is read.
    Other(String),
}

forms!(CollapseLimit, "a drift ratio (> 0 and <= 1), or \"none\" (runs never collapse)", {
    number: Some(CollapseLimit::Ratio),
    text: Some(|s| if s == "none" { CollapseLimit::None } else { CollapseLimit::Other(s) }),
    list: None,
    table: None,
});

/// `[sample]`: uncertain parameters drawn jointly, crossed with every grid axis.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawSample {
    /// `latin_hypercube` (default) or `monte_carlo`.
    pub method: Option<String>,
    pub n: usize,
    pub seed: u64,
    #[serde(rename = "axis", default)]
    pub axes: Vec<RawSampledAxis>,
}

/// One `[[sample.axis]]`: `key` names the parameter as in the grid (`building1.period_s`).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawSampledAxis {
    pub key: String,
    /// `uniform` (min, max), `normal` (mean, sd; min, max optional) or `lognormal` (median,
    /// beta = the log standard deviation; min, max optional).
    pub dist: String,
    pub min: Option<f64>,
    pub max: Option<f64>,
    pub mean: Option<f64>,
    pub sd: Option<f64>,
    pub median: Option<f64>,
    pub beta: Option<f64>,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawContact {
    pub law: Names,
    pub formula: Option<Names>,
    pub e: Option<Axis>,
    /// May be left out when sampled.
    pub gap_m: Option<Axis>,
    pub k_n_per_m: Option<Axis>,
    pub beta_n_per_m1_5: Option<Axis>,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawSynthetic {
    pub seed: u64,
    pub duration_s: Option<f64>,
    pub dt_s: Option<f64>,
    pub pga_g: Option<f64>,
    pub fg_hz: Option<f64>,
    pub zeta_g: Option<f64>,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawRecord {
    /// A file in the records directory (`POUND_RECORDS_DIR`, default `../shared/records`).
    pub file: Option<String>,
    /// A file path, relative to the config file.
    pub path: Option<String>,
    pub synthetic: Option<RawSynthetic>,
    /// Label in outputs (default: file stem, or `synthetic-sSEED`).
    pub name: Option<String>,
    pub format: Option<String>,
    pub units: Option<String>,
    pub dt_s: Option<f64>,
    pub skip_lines: Option<usize>,
    /// `[start, end]`, s: simulate only this part of the record.
    pub window_s: Option<[f64; 2]>,
    /// A folder of PEER NGA-West2 records with the search's `_SearchResults.csv`, relative to
    /// the config's folder: one record per listed record and component, labelled `RSN6_H1`
    /// (expanded when the config is read, [`crate::config::read`]).
    pub set: Option<String>,
    /// A set's components: any of "H1", "H2", "V" (default both horizontals).
    pub components: Option<Vec<String>>,
    /// Scale a set's records by the search's scale factors (default false: as recorded).
    pub search_scale: Option<bool>,
    /// The factor a set's record is scaled by as read (the search's), set by the expansion.
    #[serde(skip)]
    pub factor: Option<f64>,
    /// A set's record's metadata, set by the expansion (its runs' `record_...` columns).
    #[serde(skip)]
    pub meta: Option<crate::record::set::RecordMeta>,
    /// Its `[[record]]`'s index as written, set by the expansion (a set is one entry and
    /// several records).
    #[serde(skip)]
    pub written_at: Option<usize>,
}

impl RawRecord {
    /// The key its messages name: `record[i]` as written, with a set's record's label
    /// (`record[0] (RSN6_H2)`); `i` its index among the records read where it was not expanded.
    pub fn key(&self, i: usize) -> String {
        let at = self.written_at.unwrap_or(i);
        match &self.meta {
            Some(_) => format!(
                "record[{at}] ({})",
                self.name.as_deref().unwrap_or_default()
            ),
            None => format!("record[{at}]"),
        }
    }

    /// The file this record reads: `file =` in the records directory `records`, `path =`
    /// relative to the config's folder `base`; None for a synthetic record.
    pub fn file_path(&self, base: &Path, records: &Path) -> Option<PathBuf> {
        match (&self.file, &self.path) {
            (Some(f), _) => Some(records.join(f)),
            (_, Some(p)) => Some(base.join(p)),
            _ => None,
        }
    }
}

#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawIntensity {
    pub pga_g: Option<Axis>,
    pub scale: Option<Axis>,
    /// Targets of `Sa(T)` (g) at `sa_period_s`.
    pub sa_g: Option<Axis>,
    pub sa_period_s: Option<RawPeriod>,
    /// Targets of `Sa_avg` (g) over `sa_avg_periods_s` (from, to), `sa_avg_n` periods.
    pub sa_avg_g: Option<Axis>,
    pub sa_avg_periods_s: Option<RawPeriods>,
    pub sa_avg_n: Option<usize>,
    /// Damping ratio of the spectral targets' oscillator (default 5 %).
    pub sa_damping: Option<f64>,
    /// A record scaled by more than this is named before the first run (default
    /// [`crate::plan::limits::WARN_SCALE_FACTOR`]).
    pub warn_scale_factor: Option<f64>,
}

/// A period as written: seconds, or `"building1"`, `"0.2*building1"`, `"building[0]"`.
#[derive(Debug, Clone)]
pub enum RawPeriod {
    Seconds(f64),
    Named(String),
}

/// The forms of a period, for [`RawPeriod`]'s messages and `sa_avg_periods_s`'s.
const PERIOD_FORMS: &str =
    "a period in s, or a building's: \"building1\", \"building[0]\" or a multiple, \"0.2*building1\"";

forms!(RawPeriod, PERIOD_FORMS, {
    number: Some(RawPeriod::Seconds),
    text: Some(RawPeriod::Named),
    list: None,
    table: None,
});

/// `sa_avg_periods_s`: a list of periods (two, from and to: [`RawIntensity`] counts them).
#[derive(Debug, Clone)]
pub struct RawPeriods(pub Vec<RawPeriod>);

forms!(RawPeriods, "a list of two periods [from, to], each in s or a building's (\"0.2*building1\")", {
    number: None,
    text: None,
    list: Some(|s| elements(s).map(RawPeriods)),
    table: None,
});
