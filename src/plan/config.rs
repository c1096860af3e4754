//! TOML sweep configs: raw serde structs (stage 1), turned into a validated [`PairPlan`] (stage 2).
//! Every error names the file and the key; unknown keys are errors.
//!
//! An axis is a number, a list of numbers, or a range table
//! `{ from = .., to = .., n = .. }` (add `log = true` for log spacing) or `{ from, to, step }`.

use crate::physics::contact::LawKind;
use crate::physics::restitution::Formula;
use crate::physics::solver::{FastOptions, ReferenceOptions, Scheme};
use crate::plan::intensity::{PeriodRef, SpectralIm};
use crate::plan::sample::{draw, Dist, Method};
use crate::plan::{
    BuildingAxes, ContactPlan, ContactSpec, Intensity, PairPlan, Plan, PlanError, PlanSpec,
    SampledAxis, Samples,
};
use crate::record::{
    read_record, synthetic, Format, ReadOptions, Record, RecordError, SyntheticSpec, Units,
};
use serde::de::{self, Deserializer, MapAccess, SeqAccess, Visitor};
use serde::Deserialize;
use std::fmt;
use std::path::{Path, PathBuf};
use std::sync::Arc;

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
fn missing_record(name: &str, looked: &Path) -> String {
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

/// A sweep axis as written.
#[derive(Debug, Clone, PartialEq)]
pub enum Axis {
    List(Vec<f64>),
    Range(RangeSpec),
}

#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RangeSpec {
    pub from: f64,
    pub to: f64,
    pub n: Option<usize>,
    pub step: Option<f64>,
    #[serde(default)]
    pub log: bool,
}

impl<'de> Deserialize<'de> for Axis {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Axis, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = Axis;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a number, a list of numbers, or a range table { from, to, n } / { from, to, step }")
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<Axis, E> {
                Ok(Axis::List(vec![v]))
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<Axis, E> {
                Ok(Axis::List(vec![v as f64]))
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<Axis, E> {
                Ok(Axis::List(vec![v as f64]))
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Axis, A::Error> {
                let mut v = Vec::new();
                while let Some(x) = seq.next_element::<f64>()? {
                    v.push(x);
                }
                Ok(Axis::List(v))
            }
            fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<Axis, A::Error> {
                RangeSpec::deserialize(de::value::MapAccessDeserializer::new(map)).map(Axis::Range)
            }
        }
        d.deserialize_any(V)
    }
}

/// Parse `start:stop:step` (the CLI's range syntax) into values, stop included.
pub fn parse_colon_range(s: &str) -> Option<Vec<f64>> {
    let p: Vec<f64> = s
        .split(':')
        .map(|x| x.trim().parse().ok())
        .collect::<Option<_>>()?;
    match p[..] {
        [v] => Some(vec![v]),
        [a, b, st] => Axis::Range(RangeSpec {
            from: a,
            to: b,
            n: None,
            step: Some(st),
            log: false,
        })
        .values()
        .ok(),
        _ => None,
    }
}

/// Round to 12 significant digits, so generated ranges read as typed (0.35, not
/// 0.35000000000000003) in outputs.
fn tidy(v: f64) -> f64 {
    format!("{v:.11e}").parse().unwrap_or(v)
}

/// The first number `values` holds twice (a list a user typed: each value once).
pub fn number_given_twice(values: &[f64]) -> Option<f64> {
    let mut sorted = values.to_vec();
    sorted.sort_by(f64::total_cmp);
    sorted.windows(2).find(|w| w[0] == w[1]).map(|w| w[0])
}

/// The first name `names` holds twice.
pub fn name_given_twice<S: AsRef<str>>(names: &[S]) -> Option<&str> {
    let mut seen = std::collections::HashSet::new();
    names.iter().map(AsRef::as_ref).find(|n| !seen.insert(*n))
}

impl Axis {
    pub fn values(&self) -> Result<Vec<f64>, String> {
        match self {
            Axis::List(v) => match number_given_twice(v) {
                // A value listed twice runs its runs twice, weighting them double in a fit.
                Some(x) => Err(format!(
                    "{} is given twice: give each value once (a repeated value repeats its runs)",
                    crate::plan::limits::show(x)
                )),
                None => Ok(v.clone()),
            },
            Axis::Range(r) => {
                let v: Vec<f64> = Self::range_values(r)?.into_iter().map(tidy).collect();
                // Points closer than the 12 digits they are written to would be runs repeated
                // (a range is monotonic: a repeat is next to its twin, found without a sort).
                match v.windows(2).find(|w| w[0] == w[1]).map(|w| w[0]) {
                    Some(x) => Err(format!(
                        "gives {} twice (its points are closer than 12 significant digits): a repeated value repeats its runs; give fewer points",
                        crate::plan::limits::show(x)
                    )),
                    None => Ok(v),
                }
            }
        }
    }

    /// The number of values, without computing them (so a sweep too large to run is refused
    /// before gigabytes of axes are built).
    pub fn count(&self) -> Result<usize, String> {
        match self {
            Axis::List(v) => Ok(v.len()),
            Axis::Range(r) => Self::range_count(r),
        }
    }

    fn range_count(r: &RangeSpec) -> Result<usize, String> {
        let max = crate::plan::limits::MAX_AXIS_POINTS;
        if !(r.from.is_finite() && r.to.is_finite()) {
            return Err("range ends must be finite".into());
        }
        match (r.n, r.step) {
            (Some(n), None) => {
                if n == 0 || n > max {
                    return Err(format!("n = {n}: expected 1 to 1e7 points"));
                }
                if n == 1 && r.to != r.from {
                    return Err(format!(
                        "n = 1 gives the single value from = {}, and to = {} would be ignored: give one value, or n >= 2",
                        r.from, r.to
                    ));
                }
                Ok(n)
            }
            (None, Some(step)) if !r.log => {
                if !(step.is_finite() && step != 0.0) || (r.to - r.from) * step < 0.0 {
                    return Err(format!(
                        "step = {step:?} does not lead from {:?} to {:?}",
                        r.from, r.to
                    ));
                }
                let count = ((r.to - r.from) / step + 1e-9).floor() + 1.0;
                if count.is_nan() || count > max as f64 {
                    return Err(format!(
                        "step = {step:?} gives {count:.3e} points from {:?} to {:?}: expected at most 1e7",
                        r.from, r.to
                    ));
                }
                Ok(count as usize)
            }
            _ => Err("give exactly one of n or step (log ranges take n)".into()),
        }
    }

    fn range_values(r: &RangeSpec) -> Result<Vec<f64>, String> {
        let count = Self::range_count(r)?;
        match (r.n, r.step) {
            (Some(n), None) => {
                if n == 1 {
                    return Ok(vec![r.from]);
                }
                if r.log {
                    if !(r.from > 0.0 && r.to > 0.0) {
                        return Err("a log range needs from > 0 and to > 0".into());
                    }
                    let (a, b) = (r.from.ln(), r.to.ln());
                    Ok((0..n)
                        .map(|i| {
                            if i == n - 1 {
                                r.to
                            } else {
                                (a + (b - a) * i as f64 / (n - 1) as f64).exp()
                            }
                        })
                        .collect())
                } else {
                    Ok((0..n)
                        .map(|i| {
                            if i == n - 1 {
                                r.to
                            } else {
                                r.from + (r.to - r.from) * i as f64 / (n - 1) as f64
                            }
                        })
                        .collect())
                }
            }
            (None, Some(step)) => Ok((0..count).map(|i| r.from + step * i as f64).collect()),
            _ => Err("give exactly one of n or step (log ranges take n)".into()),
        }
    }
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
            .map_or_else(|_| m[i..end].to_string(), crate::plan::limits::show);
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

/// A value of a key that takes several forms, read by a visitor that names them all when the
/// value takes none (serde's untagged enums say only "did not match any variant"): numbers,
/// strings, lists and tables each go to `number`, `text`, `list` or `table`, those not given
/// (`None`) refused with `forms`.
macro_rules! forms {
    ($ty:ty, $forms:expr, {
        number: $num:expr, text: $text:expr, list: $list:expr, table: $table:expr $(,)?
    }) => {
        impl<'de> ::serde::Deserialize<'de> for $ty {
            fn deserialize<D: ::serde::Deserializer<'de>>(d: D) -> Result<$ty, D::Error> {
                struct V;
                impl<'de> ::serde::de::Visitor<'de> for V {
                    type Value = $ty;
                    fn expecting(&self, f: &mut ::std::fmt::Formatter) -> ::std::fmt::Result {
                        f.write_str($forms)
                    }
                    fn visit_f64<E: ::serde::de::Error>(self, v: f64) -> Result<$ty, E> {
                        let number: Option<fn(f64) -> $ty> = $num;
                        number.map(|n| n(v)).ok_or_else(|| {
                            E::invalid_type(::serde::de::Unexpected::Float(v), &self)
                        })
                    }
                    fn visit_i64<E: ::serde::de::Error>(self, v: i64) -> Result<$ty, E> {
                        let number: Option<fn(f64) -> $ty> = $num;
                        number.map(|n| n(v as f64)).ok_or_else(|| {
                            E::invalid_type(::serde::de::Unexpected::Signed(v), &self)
                        })
                    }
                    fn visit_u64<E: ::serde::de::Error>(self, v: u64) -> Result<$ty, E> {
                        self.visit_i64(v.min(i64::MAX as u64) as i64)
                    }
                    fn visit_str<E: ::serde::de::Error>(self, v: &str) -> Result<$ty, E> {
                        let text: Option<fn(String) -> $ty> = $text;
                        text.map(|t| t(v.to_string()))
                            .ok_or_else(|| E::invalid_type(::serde::de::Unexpected::Str(v), &self))
                    }
                    fn visit_seq<A: ::serde::de::SeqAccess<'de>>(
                        self,
                        seq: A,
                    ) -> Result<$ty, A::Error> {
                        let list: Option<fn(A) -> Result<$ty, A::Error>> = $list;
                        match list {
                            Some(l) => l(seq),
                            None => Err(::serde::de::Error::invalid_type(
                                ::serde::de::Unexpected::Seq,
                                &self,
                            )),
                        }
                    }
                    fn visit_map<A: ::serde::de::MapAccess<'de>>(
                        self,
                        map: A,
                    ) -> Result<$ty, A::Error> {
                        let table: Option<fn(A) -> Result<$ty, A::Error>> = $table;
                        match table {
                            Some(t) => t(map),
                            None => Err(::serde::de::Error::invalid_type(
                                ::serde::de::Unexpected::Map,
                                &self,
                            )),
                        }
                    }
                }
                d.deserialize_any(V)
            }
        }
    };
}
pub(crate) use forms;

/// The elements of a list, each read as `T`.
pub(crate) fn elements<'de, T: Deserialize<'de>, A: SeqAccess<'de>>(
    mut seq: A,
) -> Result<Vec<T>, A::Error> {
    let mut v = Vec::new();
    while let Some(x) = seq.next_element::<T>()? {
        v.push(x);
    }
    Ok(v)
}

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
    fn list(&self) -> Vec<String> {
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

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawBuilding {
    /// Each may be left out when `[[sample.axis]]` samples it.
    pub mass_kg: Option<Axis>,
    pub period_s: Option<Axis>,
    pub damping_ratio: Option<Axis>,
}

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
}

impl RawRecord {
    /// The file this record reads: `file =` in the records directory `records`, `path =`
    /// relative to the config's folder `base`; None for a synthetic record.
    fn file_path(&self, base: &Path, records: &Path) -> Option<PathBuf> {
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

/// The periods `sa_avg_n` may ask for: Eads et al. (2015) use 10.
const MAX_SA_AVG_N: usize = 100;

impl RawIntensity {
    /// The intensity axis, for a scene of `buildings` buildings.
    fn axis(
        &self,
        buildings: usize,
        invalid: &dyn Fn(&str, String) -> ConfigError,
    ) -> Result<Vec<Intensity>, ConfigError> {
        let given: Vec<(&str, &Axis)> = [
            ("pga_g", &self.pga_g),
            ("scale", &self.scale),
            ("sa_g", &self.sa_g),
            ("sa_avg_g", &self.sa_avg_g),
        ]
        .into_iter()
        .filter_map(|(k, a)| a.as_ref().map(|a| (k, a)))
        .collect();
        let spectral = |key: &str| -> Result<(), ConfigError> {
            let owned: [(&str, bool); 4] = [
                ("sa_period_s", self.sa_period_s.is_some()),
                ("sa_avg_periods_s", self.sa_avg_periods_s.is_some()),
                ("sa_avg_n", self.sa_avg_n.is_some()),
                ("sa_damping", self.sa_damping.is_some()),
            ];
            let allowed: &[&str] = match key {
                "sa_g" => &["sa_period_s", "sa_damping"],
                "sa_avg_g" => &["sa_avg_periods_s", "sa_avg_n", "sa_damping"],
                _ => &[],
            };
            match owned.iter().find(|(k, set)| *set && !allowed.contains(k)) {
                Some((k, _)) => Err(invalid(
                    &format!("intensity.{k}"),
                    match key {
                        "sa_g" | "sa_avg_g" => format!("does not apply to {key}"),
                        _ => format!("applies to sa_g or sa_avg_g, not {key}"),
                    },
                )),
                None => Ok(()),
            }
        };
        let (key, a) = match given[..] {
            [] => {
                spectral("scale")?;
                return Ok(vec![Intensity::Scale(1.0)]);
            }
            [one] => one,
            _ => {
                return Err(invalid(
                    "intensity",
                    format!(
                        "gives {}: give one of pga_g, scale, sa_g, sa_avg_g",
                        given.iter().map(|g| g.0).collect::<Vec<_>>().join(" and ")
                    ),
                ))
            }
        };
        spectral(key)?;
        let full = format!("intensity.{key}");
        let values = a.values().map_err(|m| invalid(&full, m))?;
        let period = |k: &str, p: &RawPeriod| -> Result<PeriodRef, ConfigError> {
            let r = match p {
                RawPeriod::Seconds(t) => PeriodRef::Seconds(*t),
                RawPeriod::Named(n) => PeriodRef::parse(n).map_err(|m| invalid(k, m))?,
            };
            if let Some(b) = r.building() {
                if b >= buildings {
                    return Err(invalid(
                        k,
                        format!(
                            "follows building{} (building[{b}]), but the scene has {buildings} buildings",
                            b + 1
                        ),
                    ));
                }
            }
            if let PeriodRef::Seconds(t) = r {
                SpectralIm::check_range([t, t]).map_err(|m| invalid(k, m))?;
            }
            Ok(r)
        };
        let damping = self
            .sa_damping
            .unwrap_or(crate::record::intensity::DEFAULT_DAMPING);
        if !(0.0..1.0).contains(&damping) {
            return Err(invalid(
                "intensity.sa_damping",
                format!(
                    "{} is out of range: expected 0 <= damping ratio < 1",
                    crate::plan::limits::show(damping)
                ),
            ));
        }
        let im = match key {
            "pga_g" => return Ok(values.into_iter().map(Intensity::PgaG).collect()),
            "scale" => return Ok(values.into_iter().map(Intensity::Scale).collect()),
            "sa_g" => {
                let k = "intensity.sa_period_s";
                let p = self.sa_period_s.as_ref().ok_or_else(|| {
                    invalid(
                        k,
                        "is missing: sa_g needs the period of Sa, in s or \"building1\"".into(),
                    )
                })?;
                let t = period(k, p)?;
                SpectralIm {
                    average: false,
                    from: t,
                    to: t,
                    n: 1,
                    damping,
                }
            }
            _ => {
                let k = "intensity.sa_avg_periods_s";
                let p = match self.sa_avg_periods_s.as_ref().map(|p| &p.0[..]) {
                    Some([a, b]) => [period(&format!("{k}[0]"), a)?, period(&format!("{k}[1]"), b)?],
                    Some(v) => {
                        return Err(invalid(
                            k,
                            format!("{} values: expected two, [from, to]", v.len()),
                        ))
                    }
                    None => {
                        return Err(invalid(
                            k,
                            "is missing: sa_avg_g needs the periods [from, to], e.g. [\"0.2*building1\", \"3*building1\"]".into(),
                        ))
                    }
                };
                let n = self.sa_avg_n.unwrap_or(10);
                if !(2..=MAX_SA_AVG_N).contains(&n) {
                    return Err(invalid(
                        "intensity.sa_avg_n",
                        format!("{n}: expected 2 to {MAX_SA_AVG_N} periods"),
                    ));
                }
                if p[0] == p[1] {
                    return Err(invalid(
                        k,
                        "from and to are the same period: give a range (or sa_g for one period)"
                            .into(),
                    ));
                }
                SpectralIm {
                    average: true,
                    from: p[0],
                    to: p[1],
                    n,
                    damping,
                }
            }
        };
        Ok(values
            .into_iter()
            .map(|g| Intensity::Spectral { g, im })
            .collect())
    }
}

/// A config file as written.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawConfig {
    #[serde(default)]
    pub run: RawRun,
    pub building1: RawBuilding,
    pub building2: RawBuilding,
    /// Required by a sweep; a gap study leaves the contact out ([`load_text_for_gaps`]).
    pub contact: Option<RawContact>,
    #[serde(rename = "record", default)]
    pub records: Vec<RawRecord>,
    #[serde(default)]
    pub intensity: RawIntensity,
    pub sample: Option<RawSample>,
}

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
/// The one place a config's kind is told: every other layer asks the [`Plan`].
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

/// Validate config `text` read from `path` (records resolved beside it and in
/// [`records_dir`]): a pair's or a row's plan, as the config describes.
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

/// What a config is read for: a sweep needs its contact and gaps; a gap study does not.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Reading {
    Sweep,
    GapStudy,
}

fn load_text_as(text: &str, path: &Path, reading: Reading) -> Result<Plan, ConfigError> {
    let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let records = records_dir_for(&base);
    Ok(if is_row_config(text) {
        Plan::Row(crate::plan::row::parse_row_as(
            text, path, &base, &records, reading,
        )?)
    } else {
        refuse_yielding_pair(text, path)?;
        let raw: RawConfig = toml::from_str(text).map_err(|e| toml_error(path, e))?;
        Plan::Pair(parse_raw(&raw, path, &base, &records, reading)?)
    })
}

/// The contact of a scene that has none to run (a building alone, or a gap study without
/// `[contact]`): a linear law that no run uses.
pub(crate) fn unused_contact() -> RawContact {
    RawContact {
        law: Names::One("linear".into()),
        formula: None,
        e: None,
        gap_m: None,
        k_n_per_m: Some(Axis::List(vec![1e9])),
        beta_n_per_m1_5: None,
    }
}

/// The gap a gap study takes for a pair whose gap the config leaves out: one value, so no run
/// is repeated and no gap is counted at it (a gap study counts at a config's gap axis of two
/// values or more only).
pub(crate) const UNUSED_GAP_M: f64 = 0.0;

/// The record files config `text` (read from `path`) reads, `file =` and `path =` records
/// resolved, so a command can refuse to write over one of them. Text that does not parse lists
/// none (loading it reports the error).
pub fn input_files(text: &str, path: &Path) -> Vec<PathBuf> {
    let raw_records = match toml::from_str::<RawConfig>(text) {
        Ok(raw) => raw.records,
        Err(_) => match toml::from_str::<crate::plan::row::RawRowConfig>(text) {
            Ok(raw) => raw.records,
            Err(_) => return Vec::new(),
        },
    };
    let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let records = records_dir_for(&base);
    raw_records
        .iter()
        .filter_map(|r| r.file_path(&base, &records))
        .collect()
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
pub fn load_row_text(text: &str, path: &Path) -> Result<crate::plan::row::RowPlan, ConfigError> {
    let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
    crate::plan::row::parse_row(text, path, &base, &records_dir_for(&base))
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
    let raw: RawConfig = toml::from_str(text).map_err(|e| toml_error(path, e))?;
    parse_raw(&raw, path, base, records, Reading::Sweep)
}

/// [`parse`] of a config already read into its raw form.
fn parse_raw(
    raw: &RawConfig,
    path: &Path,
    base: &Path,
    records: &Path,
    reading: Reading,
) -> Result<PairPlan, ConfigError> {
    let invalid = |key: &str, message: String| ConfigError::Invalid {
        path: path.into(),
        key: key.into(),
        message,
    };
    let mut rc = match (&raw.contact, reading) {
        (Some(c), _) => c.clone(),
        (None, Reading::GapStudy) => unused_contact(),
        (None, Reading::Sweep) => {
            return Err(invalid(
                "contact",
                "missing: a pair of buildings that may touch needs [contact] (law, its stiffness and gap_m)".into(),
            ))
        }
    };
    let gap_sampled =
        (raw.sample.iter()).any(|s| s.axes.iter().any(|a| a.key == SampledAxis::Gap.key()));
    if reading == Reading::GapStudy && rc.gap_m.is_none() && !gap_sampled {
        rc.gap_m = Some(Axis::List(vec![UNUSED_GAP_M]));
    }
    let rc = &rc;
    let axis = |key: &str, a: &Axis| a.values().map_err(|m| invalid(key, m));
    if raw.run.collapse_drift_ratio.is_some() {
        return Err(invalid(
            "run.collapse_drift_ratio",
            "a collapse is a storey's drift ratio, and [building1]/[building2] have no storey height: write the buildings as [[building]] entries with storey_height_m".into(),
        ));
    }
    let scheme = parse_scheme(&raw.run, &invalid)?;
    let (laws, formulas) = parse_laws(rc, &invalid)?;
    let count = |key: &str, a: &Option<Axis>| -> Result<usize, ConfigError> {
        a.as_ref()
            .map_or(Ok(1), |a| a.count().map_err(|m| invalid(key, m)))
    };
    let b = |name: &str, r: &RawBuilding| -> Result<[usize; 3], ConfigError> {
        Ok([
            count(&format!("{name}.mass_kg"), &r.mass_kg)?,
            count(&format!("{name}.period_s"), &r.period_s)?,
            count(&format!("{name}.damping_ratio"), &r.damping_ratio)?,
        ])
    };
    let scene = SceneCounts {
        samples: raw.sample.as_ref().map_or(1, |s| s.n.max(1)),
        building1: b("building1", &raw.building1)?,
        building2: b("building2", &raw.building2)?,
        gaps: count("contact.gap_m", &rc.gap_m)?,
    };
    check_size(
        rc,
        raw.records.len(),
        &raw.intensity,
        &laws,
        scene,
        &invalid,
    )?;
    let samples = raw
        .sample
        .as_ref()
        .map(|s| samples(s, &invalid))
        .transpose()?;
    let sampled = |key: &str| {
        samples
            .as_ref()
            .is_some_and(|s| s.axes.iter().any(|a| a.key() == key))
    };
    let grid = |key: &str, a: &Option<Axis>| -> Result<Vec<f64>, ConfigError> {
        match grid_or_sampled(a.as_ref(), sampled(key)).map_err(|m| invalid(key, m))? {
            Some(a) => axis(key, &a),
            None => Err(invalid(key, MISSING.into())),
        }
    };
    let building = |name: &str, b: &RawBuilding| -> Result<BuildingAxes, ConfigError> {
        Ok(BuildingAxes {
            mass: grid(&format!("{name}.mass_kg"), &b.mass_kg)?,
            period: grid(&format!("{name}.period_s"), &b.period_s)?,
            damping: grid(&format!("{name}.damping_ratio"), &b.damping_ratio)?,
        })
    };
    let contact = contact_spec(
        ContactSections {
            scheme,
            laws,
            formulas,
            contact: rc,
            k_linear: rc.k_n_per_m.as_ref(),
            beta: rc.beta_n_per_m1_5.as_ref(),
            records: &raw.records,
            intensity: &raw.intensity,
            buildings: 2,
            tail: raw.run.tail_s.unwrap_or(0.0),
        },
        base,
        records,
        path,
    )?;
    let spec = PlanSpec {
        contact,
        building1: building("building1", &raw.building1)?,
        building2: building("building2", &raw.building2)?,
        gaps: grid("contact.gap_m", &rc.gap_m)?,
        samples,
    };
    let plan = PairPlan::new(spec).map_err(|PlanError { key, message }| invalid(&key, message))?;
    // A gap study runs no contact axis: none can repeat its runs.
    if reading == Reading::Sweep {
        plan.refuse_unused()
            .map_err(|PlanError { key, message }| invalid(&key, message))?;
    }
    Ok(plan)
}

/// The `[run]` section's scheme.
fn parse_scheme(
    run: &RawRun,
    invalid: &dyn Fn(&str, String) -> ConfigError,
) -> Result<Scheme, ConfigError> {
    Ok(match run.scheme.as_deref().unwrap_or("fast") {
        "fast" => {
            let mut o = FastOptions::default();
            if let Some(n) = run.substeps_per_contact {
                if !(n.is_finite()
                    && (1.0..=crate::plan::limits::MAX_SUBSTEPS_PER_CONTACT).contains(&n))
                {
                    return Err(invalid(
                        "run.substeps_per_contact",
                        format!(
                            "{}: expected 1 to {} ({})",
                            crate::plan::limits::show(n),
                            crate::plan::limits::MAX_SUBSTEPS_PER_CONTACT,
                            crate::plan::limits::WHY_SUBSTEPS
                        ),
                    ));
                }
                o.substeps_per_contact = n;
            }
            o.energy = run.energy.unwrap_or(false);
            Scheme::Fast(o)
        }
        "reference" => {
            let tol = run
                .tol
                .unwrap_or(crate::physics::solver::reference::DEFAULT_TOL);
            let tol = crate::plan::limits::check_tol(tol).map_err(|m| invalid("run.tol", m))?;
            Scheme::Reference(ReferenceOptions::with_tol(tol))
        }
        other => {
            return Err(invalid(
                "run.scheme",
                format!("`{other}`: expected fast or reference"),
            ))
        }
    })
}

/// The `[contact]` section's laws and formulas.
fn parse_laws(
    contact: &RawContact,
    invalid: &dyn Fn(&str, String) -> ConfigError,
) -> Result<(Vec<LawKind>, Vec<Formula>), ConfigError> {
    let mut laws = Vec::new();
    for (i, k) in contact.law.list().iter().enumerate() {
        let law = LawKind::from_key(k).ok_or_else(|| {
            invalid(
                &format!("contact.law[{i}]"),
                format!("unknown law `{k}`: expected one of {}", LawKind::keys()),
            )
        })?;
        // Twice would write two runs of one label for every other value.
        if let Some(j) = laws.iter().position(|l| *l == law) {
            return Err(invalid(
                &format!("contact.law[{i}]"),
                format!("`{k}` is given twice (also contact.law[{j}])"),
            ));
        }
        laws.push(law);
    }
    let mut formulas = Vec::new();
    for (i, k) in contact
        .formula
        .as_ref()
        .map(Names::list)
        .unwrap_or_default()
        .iter()
        .enumerate()
    {
        let formula = Formula::from_key(k).ok_or_else(|| {
            invalid(
                &format!("contact.formula[{i}]"),
                format!("unknown formula `{k}`: expected one of {}", Formula::keys()),
            )
        })?;
        if let Some(j) = formulas.iter().position(|f| *f == formula) {
            return Err(invalid(
                &format!("contact.formula[{i}]"),
                format!("`{k}` is given twice (also contact.formula[{j}])"),
            ));
        }
        formulas.push(formula);
    }
    Ok((laws, formulas))
}

/// The sections every scene shares, as a scene's reader settled them.
pub(crate) struct ContactSections<'a> {
    pub scheme: Scheme,
    pub laws: Vec<LawKind>,
    pub formulas: Vec<Formula>,
    pub contact: &'a RawContact,
    /// `k` and `beta` as the scene gives them (a sampled one holds a placeholder value).
    pub k_linear: Option<&'a Axis>,
    pub beta: Option<&'a Axis>,
    pub records: &'a [RawRecord],
    pub intensity: &'a RawIntensity,
    /// The scene's buildings, for the intensity's references to their periods.
    pub buildings: usize,
    /// `run.tail_s`
    pub tail: f64,
}

/// The axes every scene shares, validated but for the buildings' periods a spectral target
/// reads (the scene checks those): records read (`path =` beside `base`, `file =` in
/// `records`), intensities, `e`, `k` and `beta`.
fn contact_spec(
    c: ContactSections,
    base: &Path,
    records: &Path,
    path: &Path,
) -> Result<ContactSpec, ConfigError> {
    let invalid = |key: &str, message: String| ConfigError::Invalid {
        path: path.into(),
        key: key.into(),
        message,
    };
    let axis = |key: &str, a: &Axis| a.values().map_err(|m| invalid(key, m));
    let opt_axis = |key: &str, a: Option<&Axis>| a.map_or(Ok(Vec::new()), |a| axis(key, a));
    let intensities = c.intensity.axis(c.buildings, &invalid)?;
    let warn_scale = c
        .intensity
        .warn_scale_factor
        .unwrap_or(crate::plan::limits::WARN_SCALE_FACTOR);
    if !(warn_scale.is_finite() && warn_scale >= 1.0) {
        return Err(invalid(
            "intensity.warn_scale_factor",
            format!(
                "{} is out of range: expected a scale factor >= 1 (default {})",
                crate::plan::limits::show(warn_scale),
                crate::plan::limits::WARN_SCALE_FACTOR
            ),
        ));
    }
    let mut recs = Vec::new();
    for (i, r) in c.records.iter().enumerate() {
        let key = format!("record[{i}]");
        let rec = load_record(r, base, records).map_err(|e| match e {
            LoadError::Invalid(m) => invalid(&key, m),
            LoadError::Record(error) => ConfigError::Record {
                path: path.into(),
                key: key.clone(),
                error,
            },
        })?;
        // A label names a record's runs in every output: two records of one label could not be
        // told apart (a name given twice, two windows of one file, one seed twice).
        if let Some(j) = recs.iter().position(|r: &Arc<Record>| r.name == rec.name) {
            return Err(invalid(
                &key,
                format!(
                    "is labelled `{}`, as record[{j}] is: give each a distinct name = \"...\"",
                    rec.name
                ),
            ));
        }
        // The same motion under another label would repeat every run of the first.
        if let Some(j) = recs
            .iter()
            .position(|r| r.dt == rec.dt && r.t0 == rec.t0 && r.accel == rec.accel)
        {
            return Err(invalid(
                &key,
                format!(
                    "`{}` holds the same accelerations (same dt and start) as record[{j}] `{}`: its runs would repeat record[{j}]'s with the same physics; remove one",
                    rec.name, recs[j].name
                ),
            ));
        }
        recs.push(Arc::new(rec));
    }
    Ok(ContactSpec {
        laws: c.laws,
        formulas: c.formulas,
        e: opt_axis("contact.e", c.contact.e.as_ref())?,
        k_linear: opt_axis("contact.k_n_per_m", c.k_linear)?,
        beta: opt_axis("contact.beta_n_per_m1_5", c.beta)?,
        records: recs,
        intensities,
        scheme: c.scheme,
        tail: c.tail,
        warn_scale,
    })
}

/// The contact plan of a row config ([`crate::plan::row`]): its `[run]`, `[contact]`,
/// `[[record]]` and `[intensity]` sections, with `k` and `beta` as the row settled them, for a
/// row of `buildings` buildings.
#[allow(clippy::too_many_arguments)]
pub(crate) fn parse_contact(
    run: &RawRun,
    contact: &RawContact,
    k_linear: Option<&Axis>,
    beta: Option<&Axis>,
    raw_records: &[RawRecord],
    intensity: &RawIntensity,
    buildings: usize,
    (path, base, records): (&Path, &Path, &Path),
) -> Result<ContactPlan, ConfigError> {
    let invalid = |key: &str, message: String| ConfigError::Invalid {
        path: path.into(),
        key: key.into(),
        message,
    };
    let scheme = parse_scheme(run, &invalid)?;
    let (laws, formulas) = parse_laws(contact, &invalid)?;
    // The row checks its whole count once its buildings are read; here the contact runs'.
    check_size(
        contact,
        raw_records.len(),
        intensity,
        &laws,
        SceneCounts::ONE,
        &invalid,
    )?;
    let spec = contact_spec(
        ContactSections {
            scheme,
            laws,
            formulas,
            contact,
            k_linear,
            beta,
            records: raw_records,
            intensity,
            buildings,
            tail: run.tail_s.unwrap_or(0.0),
        },
        base,
        records,
        path,
    )?;
    ContactPlan::new(spec).map_err(|PlanError { key, message }| invalid(&key, message))
}

/// The sizes of a pair's own axes, for [`check_size`].
#[derive(Clone, Copy)]
struct SceneCounts {
    samples: usize,
    building1: [usize; 3],
    building2: [usize; 3],
    gaps: usize,
}

impl SceneCounts {
    /// One scene value per contact run: the contact runs alone.
    const ONE: SceneCounts = SceneCounts {
        samples: 1,
        building1: [1; 3],
        building2: [1; 3],
        gaps: 1,
    };
}

/// Refuse a sweep of more than [`crate::plan::limits::MAX_RUNS`] runs from the axes' sizes alone,
/// before any axis is built or sample drawn.
fn check_size(
    contact: &RawContact,
    records: usize,
    intensity: &RawIntensity,
    laws: &[LawKind],
    scene: SceneCounts,
    invalid: &dyn Fn(&str, String) -> ConfigError,
) -> Result<(), ConfigError> {
    let count = |key: &str, a: &Option<Axis>| -> Result<usize, ConfigError> {
        a.as_ref()
            .map_or(Ok(1), |a| a.count().map_err(|m| invalid(key, m)))
    };
    let counts = crate::plan::AxisCounts {
        formulas: contact.formula.as_ref().map_or(0, |f| f.list().len()),
        e: count("contact.e", &contact.e)?,
        k_linear: count("contact.k_n_per_m", &contact.k_n_per_m)?,
        beta: count("contact.beta_n_per_m1_5", &contact.beta_n_per_m1_5)?,
        records,
        intensities: count("intensity.pga_g", &intensity.pga_g)?
            * count("intensity.scale", &intensity.scale)?
            * count("intensity.sa_g", &intensity.sa_g)?
            * count("intensity.sa_avg_g", &intensity.sa_avg_g)?,
        samples: scene.samples,
        building1: scene.building1,
        building2: scene.building2,
        gaps: scene.gaps,
    };
    crate::plan::check_run_count(laws, &counts)
        .map(|_| ())
        .map_err(|e| invalid(&e.key, e.message))
}

/// A grid axis or a sampled one, not both: a sampled parameter's grid axis holds one placeholder
/// (0.5: valid for every axis, never used). `Err` says why `given` cannot stand; `Ok(None)`: a
/// parameter neither given nor sampled ([`MISSING`] where it is required). Shared by the pair's
/// config and the row's ([`crate::plan::row`]).
pub(crate) fn grid_or_sampled(given: Option<&Axis>, sampled: bool) -> Result<Option<Axis>, String> {
    match (given, sampled) {
        (Some(_), true) => Err("is sampled under [sample]: remove it from the grid".into()),
        (None, true) => Ok(Some(Axis::List(vec![0.5]))),
        (given, false) => Ok(given.cloned()),
    }
}

/// The error of a required parameter that is neither given nor sampled.
pub(crate) const MISSING: &str = "missing: give values or sample it";

/// Stage 2 of `[sample]`: distributions checked, points drawn.
fn samples(
    s: &RawSample,
    invalid: &dyn Fn(&str, String) -> ConfigError,
) -> Result<Samples, ConfigError> {
    let keys = SampledAxis::ALL.map(|x| x.key()).join(", ");
    let (axes, points) = draw_sampled(s, invalid, &SampledAxis::from_key, &keys)?;
    Ok(Samples { axes, points })
}

/// The `[[sample.axis]]` entries of `s` resolved by `resolve` (`keys` lists the keys it
/// knows, for the error), their distributions checked, and `s.n` points drawn: `points[s][j]`
/// is axis `j`'s value in sample `s`.
pub(crate) fn draw_sampled<A: PartialEq>(
    s: &RawSample,
    invalid: &dyn Fn(&str, String) -> ConfigError,
    resolve: &dyn Fn(&str) -> Option<A>,
    keys: &str,
) -> Result<(Vec<A>, Vec<Vec<f64>>), ConfigError> {
    let method = match s.method.as_deref().unwrap_or("latin_hypercube") {
        "latin_hypercube" => Method::LatinHypercube,
        "monte_carlo" => Method::MonteCarlo,
        other => {
            return Err(invalid(
                "sample.method",
                format!("`{other}`: expected latin_hypercube or monte_carlo"),
            ))
        }
    };
    if s.n == 0 {
        return Err(invalid(
            "sample.n",
            "is 0: expected at least one sample".into(),
        ));
    }
    if s.n > crate::plan::limits::MAX_SAMPLES {
        return Err(invalid(
            "sample.n",
            format!(
                "{}: expected at most {} ({})",
                s.n,
                crate::plan::limits::MAX_SAMPLES,
                crate::plan::limits::WHY_SAMPLES
            ),
        ));
    }
    if s.axes.is_empty() {
        return Err(invalid(
            "sample.axis",
            "is empty: add [[sample.axis]] entries (key, dist, ...)".into(),
        ));
    }
    let mut axes = Vec::new();
    let mut dists = Vec::new();
    for (i, a) in s.axes.iter().enumerate() {
        let key = format!("sample.axis[{i}]");
        let axis = resolve(&a.key).ok_or_else(|| {
            invalid(
                &format!("{key}.key"),
                format!("`{}`: expected one of {keys}", a.key),
            )
        })?;
        if axes.contains(&axis) {
            return Err(invalid(
                &format!("{key}.key"),
                format!("`{}` is sampled twice", a.key),
            ));
        }
        let need = |name: &str, v: Option<f64>| {
            v.filter(|x| x.is_finite()).ok_or_else(|| {
                invalid(
                    &format!("{key}.{name}"),
                    format!("a {} distribution needs a finite `{name}`", a.dist),
                )
            })
        };
        let (lo, hi) = (
            a.min.unwrap_or(f64::NEG_INFINITY),
            a.max.unwrap_or(f64::INFINITY),
        );
        let allowed: &[&str] = match a.dist.as_str() {
            "uniform" => &["min", "max"],
            "normal" => &["mean", "sd", "min", "max"],
            "lognormal" => &["median", "beta", "min", "max"],
            _ => &[],
        };
        for (name, given) in [
            ("min", a.min),
            ("max", a.max),
            ("mean", a.mean),
            ("sd", a.sd),
            ("median", a.median),
            ("beta", a.beta),
        ] {
            if given.is_some() && !allowed.is_empty() && !allowed.contains(&name) {
                return Err(invalid(
                    &format!("{key}.{name}"),
                    format!(
                        "does not apply to a {} distribution (it takes {})",
                        a.dist,
                        allowed.join(", ")
                    ),
                ));
            }
        }
        let d = match a.dist.as_str() {
            "uniform" => Dist::Uniform {
                min: need("min", a.min)?,
                max: need("max", a.max)?,
            },
            "normal" => Dist::Normal {
                mean: need("mean", a.mean)?,
                sd: need("sd", a.sd)?,
                min: lo,
                max: hi,
            },
            "lognormal" => Dist::LogNormal {
                median: need("median", a.median)?,
                beta: need("beta", a.beta)?,
                min: lo,
                max: hi,
            },
            other => {
                return Err(invalid(
                    &format!("{key}.dist"),
                    format!("`{other}`: expected uniform, normal or lognormal"),
                ))
            }
        };
        let bad = match d {
            Dist::Uniform { min, max } => (min >= max).then_some("expected min < max"),
            Dist::Normal { sd, .. } if sd <= 0.0 => Some("expected sd > 0"),
            Dist::LogNormal { median, beta, .. } if median <= 0.0 || beta <= 0.0 => {
                Some("expected median > 0 and beta > 0")
            }
            _ => (lo >= hi).then_some("expected min < max"),
        };
        if let Some(m) = bad {
            return Err(invalid(&key, m.into()));
        }
        axes.push(axis);
        dists.push(d);
    }
    Ok((axes, draw(method, s.n, &dists, s.seed)))
}

enum LoadError {
    Invalid(String),
    Record(RecordError),
}

fn load_record(r: &RawRecord, base: &Path, records: &Path) -> Result<Record, LoadError> {
    let sources = [r.file.is_some(), r.path.is_some(), r.synthetic.is_some()]
        .iter()
        .filter(|x| **x)
        .count();
    if sources != 1 {
        return Err(LoadError::Invalid(
            "give exactly one of file, path or synthetic".into(),
        ));
    }
    let mut rec = if let Some(s) = &r.synthetic {
        if r.format.is_some() || r.units.is_some() || r.dt_s.is_some() || r.skip_lines.is_some() {
            return Err(LoadError::Invalid("format, units, dt_s and skip_lines apply to files, not synthetic records (use synthetic.dt_s)".into()));
        }
        let d = SyntheticSpec::default();
        let spec = SyntheticSpec {
            seed: s.seed,
            duration: s.duration_s.unwrap_or(d.duration),
            dt: s.dt_s.unwrap_or(d.dt),
            pga_g: s.pga_g.unwrap_or(d.pga_g),
            fg_hz: s.fg_hz.unwrap_or(d.fg_hz),
            zeta_g: s.zeta_g.unwrap_or(d.zeta_g),
        };
        synthetic(&spec).map_err(LoadError::Record)?
    } else {
        let file = r
            .file_path(base, records)
            .expect("one source checked above");
        if let Some(name) = &r.file {
            if !file.exists() {
                return Err(LoadError::Invalid(missing_record(name, records)));
            }
        }
        let format = match &r.format {
            Some(f) => Format::parse(f).ok_or_else(|| {
                LoadError::Invalid(format!("format `{f}`: expected {}", Format::KEYS))
            })?,
            None => Format::Auto,
        };
        let units = match &r.units {
            Some(u) => Some(Units::parse(u).ok_or_else(|| {
                LoadError::Invalid(format!("units `{u}`: expected {}", Units::KEYS))
            })?),
            None => None,
        };
        let opts = ReadOptions {
            format,
            units,
            dt: r.dt_s,
            skip_lines: r.skip_lines.unwrap_or(0),
        };
        read_record(&file, &opts).map_err(LoadError::Record)?
    };
    if let Some(w) = r.window_s {
        rec = rec.windowed(w).map_err(|m| {
            LoadError::Invalid(format!(
                "window_s = [{}, {}]: {m}",
                crate::plan::limits::show(w[0]),
                crate::plan::limits::show(w[1])
            ))
        })?;
    }
    if let Some(n) = &r.name {
        rec.name = n.clone();
    }
    Ok(rec)
}
