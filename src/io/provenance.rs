//! What an output was computed from and what it holds: the plan fingerprint, the sidecar
//! `OUT.meta.toml` written beside every finished output, and the journal `OUT.progress.toml` of
//! an unfinished one. `pound merge`, `--resume` and the studies check them.

pub use crate::io::paths::{meta_path, progress_path};
use crate::plan::shard::Shard;
use crate::plan::PairPlan;
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// [`Fingerprint::differs`]' words for a plan that differs.
const CONFIG: &str = "the config (the validated plan)";

/// What an output was computed from: the validated plan (axes, scheme, settings), the records'
/// content, and the engine version. Two outputs may be combined or continued only when all three
/// match.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Fingerprint {
    pub plan: String,
    pub records: String,
    pub engine: String,
}

fn hex(d: impl AsRef<[u8]>) -> String {
    d.as_ref()
        .iter()
        .take(16)
        .map(|b| format!("{b:02x}"))
        .collect()
}

impl Fingerprint {
    pub fn of(plan: &PairPlan) -> Fingerprint {
        Fingerprint::hashed(
            &plan.contact.spec,
            &plan.building1,
            &plan.building2,
            &plan.gaps,
            &plan.samples,
        )
    }

    /// The hash of the shared axes and a pair's own. Debug prints every f64 exactly (shortest
    /// round-trip), so equal plans hash equally; the text's layout is that of every earlier
    /// version, so their sidecars still match (`--resume`, `pound merge`).
    fn hashed(
        s: &crate::plan::ContactSpec,
        building1: &crate::plan::BuildingAxes,
        building2: &crate::plan::BuildingAxes,
        gaps: &[f64],
        samples: &Option<crate::plan::Samples>,
    ) -> Fingerprint {
        let mut text = format!(
            "{:?}|{:?}|{:?}|{:?}|{:?}|{:?}|{:?}|{:?}|{:?}|{:?}|{:?}|{:?}|{:?}",
            s.laws,
            s.formulas,
            s.e,
            s.k_linear,
            s.beta,
            s.intensities,
            building1,
            building2,
            gaps,
            s.scheme,
            s.tail,
            samples,
            s.records.iter().map(|r| &r.name).collect::<Vec<_>>(),
        );
        // A record set's metadata is written in its runs' rows (sweeps without one hash as
        // before).
        if s.record_meta.iter().any(Option::is_some) {
            text.push_str(&format!("|{:?}", s.record_meta));
        }
        if s.record_factor.iter().any(|&f| f != 1.0) {
            text.push_str(&format!("|{:?}", s.record_factor));
        }
        let mut rec = Sha256::new();
        for r in &s.records {
            rec.update(r.name.as_bytes());
            rec.update(r.dt.to_le_bytes());
            rec.update(r.t0.to_le_bytes());
            rec.update((r.accel.len() as u64).to_le_bytes());
            for a in &r.accel {
                rec.update(a.to_le_bytes());
            }
        }
        Fingerprint {
            plan: hex(Sha256::digest(text.as_bytes())),
            records: hex(rec.finalize()),
            engine: env!("CARGO_PKG_VERSION").to_string(),
        }
    }

    /// The fingerprint of any plan: a pair's ([`Fingerprint::of`]) or a row's
    /// ([`Fingerprint::of_row`]).
    pub fn of_plan(plan: &crate::plan::Plan) -> Fingerprint {
        match plan {
            crate::plan::Plan::Pair(p) => Fingerprint::of(p),
            crate::plan::Plan::Row(r) => Fingerprint::of_row(r),
        }
    }

    /// The fingerprint of a row sweep: the shared axes' hash, with the buildings' and gaps'
    /// axes. The shared axes are hashed in a pair's layout with the one-value building and gap
    /// axes that earlier versions' row plans carried, so their sidecars still match.
    pub fn of_row(plan: &crate::plan::row::RowPlan) -> Fingerprint {
        let one = |x: f64| vec![x];
        let unit = crate::plan::BuildingAxes {
            mass: one(1.0),
            period: one(1.0),
            damping: one(0.05),
        };
        let base = Fingerprint::hashed(&plan.contact.spec, &unit, &unit, &one(0.0), &None);
        let mut text = format!(
            "{}|{:?}|{:?}|{:?}",
            base.plan, plan.buildings, plan.gaps, plan.samples
        );
        // Elastic rows hash as they did before storeys could yield.
        if plan.yielding.iter().any(Option::is_some) {
            text.push_str(&format!("|{:?}", plan.yielding));
        }
        // Rows at the default contact levels hash as they did before `[levels]`.
        if plan.level_rule != crate::physics::row::LevelRule::default() {
            text.push_str(&format!("|{:?}", plan.level_rule));
        }
        // Rows at the default collapse limit hash as they did before the limit was hashed
        // (sidecars of sweeps at it stay resumable); any other limit, `none` included, changes
        // the runs (their status, their end, the collapse columns) and so the hash.
        if plan.collapse_drift_ratio.to_bits()
            != crate::plan::limits::COLLAPSE_DRIFT_RATIO.to_bits()
        {
            text.push_str(&format!("|collapse {:?}", plan.collapse_drift_ratio));
        }
        // Equal gap values taken in two layouts are two sets of runs: `contact.gap_m` one axis
        // that its pairs share, or each pair its own. Rows whose pairs each read their own axis
        // hash as before the shared axis (they have the runs they had then).
        let (shared, axis) = plan.gap_layout();
        if axis.iter().enumerate().any(|(a, &x)| x != a) {
            text.push_str(&format!("|gap axes {axis:?}"));
        }
        // A sampled `contact.gap_m` sets the pairs it gives; which, where some pair has its own
        // `gap_right_m` (the grid's placeholder gap may equal that one's value).
        let sampled_gap = plan
            .samples
            .as_ref()
            .is_some_and(|s| s.axes.contains(&crate::plan::row::RowSampled::SharedGap));
        if sampled_gap && shared.contains(&false) {
            text.push_str(&format!("|sampled gap on {shared:?}"));
        }
        Fingerprint {
            plan: hex(Sha256::digest(text.as_bytes())),
            ..base
        }
    }

    /// The first part that differs from `other`, in words; None if they match.
    pub fn differs(&self, other: &Fingerprint) -> Option<&'static str> {
        if self.engine != other.engine {
            Some("the engine version")
        } else if self.records != other.records {
            Some("the records (their content)")
        } else if self.plan != other.plan {
            Some(CONFIG)
        } else {
            None
        }
    }
}

/// The plan by the config's keys, recorded in a sidecar so that a refusal to join two outputs
/// names what differs: each `[run]` key in effect with its value, and each other part of the
/// plan (a section, or the gaps) as a digest of its validated values. The fingerprint decides;
/// these only name.
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Settings {
    /// `[run]` keys in effect (the scheme's own, the tail, a row's collapse limit) and their
    /// values as a config gives them, with what flags set (`--scheme`, `--energy`, the
    /// substeps `--target-error` chose).
    #[serde(default)]
    pub run: BTreeMap<String, String>,
    /// Every other part, by its section (`[contact]`, `[levels]`, ...): a digest.
    #[serde(default)]
    pub parts: BTreeMap<String, String>,
}

impl Settings {
    /// The settings of any plan, as its runs take them.
    pub fn of_plan(plan: &crate::plan::Plan) -> Settings {
        use crate::physics::solver::Scheme;
        use crate::plan::Plan;
        let spec = &plan.contact().spec;
        let mut run = BTreeMap::new();
        let mut put = |k: &str, v: String| run.insert(k.to_string(), v);
        put("scheme", spec.scheme.key().into());
        match spec.scheme {
            Scheme::Fast(o) => {
                put("substeps_per_contact", crate::show(o.substeps_per_contact));
                put("energy", o.energy.to_string());
            }
            Scheme::Reference(o) => {
                // The stated accuracy the options were made from (`rtol = tol / 100`), read
                // back to 12 digits: a rounding of the product is not a setting.
                let tol: f64 = format!("{:.11e}", o.rtol * 100.0)
                    .parse()
                    .unwrap_or(f64::NAN);
                put("tol", crate::show(tol));
            }
        }
        put("tail_s", crate::show(spec.tail));
        let digest = |x: &dyn std::fmt::Debug| hex(Sha256::digest(format!("{x:?}").as_bytes()));
        let mut parts = BTreeMap::new();
        let mut part = |k: &str, x: &dyn std::fmt::Debug| parts.insert(k.to_string(), digest(x));
        part(
            "[contact]",
            &(
                &spec.laws,
                &spec.formulas,
                &spec.e,
                &spec.k_linear,
                &spec.beta,
            ),
        );
        part("[intensity]", &spec.intensities);
        part(
            "[[record]] (their labels)",
            &spec.records.iter().map(|r| &r.name).collect::<Vec<_>>(),
        );
        match plan {
            Plan::Pair(p) => {
                part("[contact] gap_m", &p.gaps);
                part("[building1]", &p.building1);
                part("[building2]", &p.building2);
                part("[sample]", &p.samples);
            }
            Plan::Row(r) => {
                let cdr = r.collapse_drift_ratio;
                put(
                    "collapse_drift_ratio",
                    if cdr.is_finite() {
                        crate::show(cdr)
                    } else {
                        "\"none\"".into()
                    },
                );
                part("[[building]]", &(&r.buildings, &r.yielding));
                part(
                    "the gaps ([contact] gap_m, [[building]] gap_right_m)",
                    &(&r.gaps, r.gap_layout()),
                );
                part("[levels]", &r.level_rule);
                part("[sample]", &r.samples);
            }
        }
        Settings { run, parts }
    }

    /// The keys whose values differ from `theirs`', in words (`there` names where theirs are
    /// recorded): `[run] collapse_drift_ratio: 0.05 here, 0.1 in OUT.meta.toml`. Empty where
    /// none does.
    pub fn differing(&self, theirs: &Settings, there: &str) -> Vec<String> {
        let mut said = Vec::new();
        let keys = |a: &BTreeMap<String, String>, b: &BTreeMap<String, String>| {
            let mut k: Vec<String> = a.keys().chain(b.keys()).cloned().collect();
            k.sort();
            k.dedup();
            k
        };
        let none = "not set".to_string();
        for k in keys(&self.run, &theirs.run) {
            let (here, them) = (self.run.get(&k), theirs.run.get(&k));
            if here != them {
                said.push(format!(
                    "[run] {k}: {} here, {} in {there}",
                    here.unwrap_or(&none),
                    them.unwrap_or(&none)
                ));
            }
        }
        for k in keys(&self.parts, &theirs.parts) {
            if self.parts.get(&k) != theirs.parts.get(&k) {
                said.push(k);
            }
        }
        said
    }
}

/// What differs between two outputs' plans: the engine, the records or the config, the config's
/// keys named where both sidecars record them.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Difference {
    /// The part of the fingerprint ([`Fingerprint::differs`]).
    pub what: &'static str,
    /// The config's keys that differ, in words (empty where not known: an older sidecar).
    pub keys: Vec<String>,
}

impl Difference {
    /// `{what} differs from {whose}`, with the keys that differ in parentheses.
    pub fn differs_from(&self, whose: &str) -> String {
        if self.keys.is_empty() {
            format!("{} differs from {whose}", self.what)
        } else {
            format!(
                "{} differs from {whose} ({})",
                self.what,
                self.keys.join("; ")
            )
        }
    }
}

/// The sidecar of a finished output (`OUT.meta.toml`): what it was computed from and which runs
/// it holds.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Meta {
    pub fingerprint: Fingerprint,
    /// Runs in the whole plan.
    pub plan_runs: u64,
    pub first_run: u64,
    pub end_run: u64,
    pub shard: Option<Shard>,
    /// Where the runs were integrated: `cpu`, `gpu-f32` or `gpu-f64` (a resumed sweep must keep
    /// it; merged shards may mix them).
    pub backend: String,
    /// The kernels the runs took, chosen from the scene: `pair` or `row` (absent in sidecars
    /// written before it was recorded).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub kernel: Option<String>,
    /// The columns written, when `--columns` chose them (all otherwise).
    #[serde(default)]
    pub columns: Option<Vec<String>>,
    /// What the file holds (rows and hashes): `pound merge` and the studies check it.
    #[serde(default)]
    pub content: Option<crate::io::journal::Content>,
    /// `--target-error`: the error asked for and the setting it chose.
    #[serde(default)]
    pub target_error: Option<TargetError>,
    /// The plan by the config's keys, to name what differs (absent in sidecars written before
    /// it was recorded: their refusals name the config as a whole).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub settings: Option<Settings>,
}

impl Meta {
    /// The key-value metadata of a typed output (a Parquet file's, the Python package's Arrow
    /// tables'): the fingerprint's parts, the runs held and the backend.
    pub fn key_values(&self) -> Vec<(String, String)> {
        let f = &self.fingerprint;
        vec![
            ("pound.fingerprint.plan".into(), f.plan.clone()),
            ("pound.fingerprint.records".into(), f.records.clone()),
            ("pound.fingerprint.engine".into(), f.engine.clone()),
            (
                "pound.runs".into(),
                format!("{}..{} of {}", self.first_run, self.end_run, self.plan_runs),
            ),
            ("pound.backend".into(), self.backend.clone()),
        ]
    }

    /// What differs between the plan of this output and `theirs` (recorded in `there`), or
    /// None where their fingerprints match.
    pub fn differs(&self, theirs: &Meta, there: &str) -> Option<Difference> {
        let what = self.fingerprint.differs(&theirs.fingerprint)?;
        // Keys are named only where the config is what differs first (another engine may read
        // the same config otherwise), and where both sides record them.
        let keys = match (&self.settings, &theirs.settings) {
            (Some(a), Some(b)) if what == CONFIG => a.differing(b, there),
            _ => Vec::new(),
        };
        Some(Difference { what, keys })
    }
}

/// The accuracy a sweep was asked for (`--target-error`) and what it chose: the fast scheme's
/// RK4 substeps per contact and their calibrated p99 relative peak-force error.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TargetError {
    pub target: f64,
    pub substeps_per_contact: f64,
    pub calibrated_p99: f64,
}

impl TargetError {
    /// The sidecar's record of a setting chosen for a target.
    pub fn of(c: crate::physics::solver::calibration::Choice) -> TargetError {
        TargetError {
            target: c.target,
            substeps_per_contact: c.substeps_per_contact,
            calibrated_p99: c.calibrated_p99,
        }
    }
}

/// Progress of an unfinished output (`OUT.progress.toml`), rewritten atomically after each
/// chunk's rows are on disk: the first `done` runs of the range are in the first `bytes` bytes of
/// `OUT.partial`, whose SHA-256 is `sha256`; anything after that is a half-written chunk. A hint,
/// never the truth: `--resume` re-reads and checks those bytes before it continues.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Progress {
    pub meta: Meta,
    pub done: u64,
    pub bytes: u64,
    #[serde(default)]
    pub sha256: String,
}

#[derive(Debug, thiserror::Error)]
pub enum SidecarError {
    #[error("{}: {message}", path.display())]
    Io { path: PathBuf, message: String },
    #[error(transparent)]
    Verify(#[from] crate::io::journal::VerifyError),
    #[error(transparent)]
    Target(#[from] crate::io::target::TargetError),
}

/// Read a TOML sidecar.
pub fn read_toml<T: for<'de> Deserialize<'de>>(path: &Path) -> Result<T, SidecarError> {
    let text = std::fs::read_to_string(path).map_err(|e| SidecarError::Io {
        path: path.into(),
        message: e.to_string(),
    })?;
    toml::from_str(&text).map_err(|e| SidecarError::Io {
        path: path.into(),
        message: format!("not a valid sidecar: {e}"),
    })
}

/// Write a TOML sidecar atomically.
pub fn write_toml<T: Serialize>(path: &Path, v: &T) -> Result<(), SidecarError> {
    let text = toml::to_string(v).map_err(|e| SidecarError::Io {
        path: path.into(),
        message: e.to_string(),
    })?;
    crate::io::atomic::write_atomic(path, text.as_bytes()).map_err(|e| SidecarError::Io {
        path: path.into(),
        message: e.to_string(),
    })
}

/// Why a results file handed to a study may not be what `pound sweep` wrote (no sidecar, an
/// unfinished sweep, edited since); None when its sidecar vouches for it. For warnings.
pub fn provenance_warning(path: &Path) -> Option<String> {
    let meta = meta_path(path);
    let progress = progress_path(path);
    if progress.exists() {
        return Some(format!(
            "{} belongs to an unfinished sweep ({} exists)",
            path.display(),
            progress.display()
        ));
    }
    let m: Meta = match read_toml(&meta) {
        Ok(m) => m,
        Err(_) if !meta.exists() => {
            return Some(format!(
                "{} has no sidecar {}: its rows are not vouched for by `pound sweep` (not its output, or the sidecar was removed)",
                path.display(),
                meta.display()
            ))
        }
        Err(e) => return Some(format!("{e}")),
    };
    let Some(content) = m.content else {
        return Some(format!(
            "{} carries no content hash: its rows cannot be checked",
            meta.display()
        ));
    };
    match crate::io::journal::file_sha256(path) {
        Ok(sha) if sha == content.sha256 => None,
        Ok(_) => Some(format!(
            "{} differs from what `pound sweep` wrote (content hash in {}): it was edited since",
            path.display(),
            meta.display()
        )),
        Err(e) => Some(format!("{}: {e}", path.display())),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn differs_names_the_first_part_that_differs() {
        let a = Fingerprint {
            plan: "p".into(),
            records: "r".into(),
            engine: "e".into(),
        };
        let with = |f: fn(&mut Fingerprint)| {
            let mut b = a.clone();
            f(&mut b);
            b
        };
        assert_eq!(a.differs(&a.clone()), None);
        assert_eq!(
            a.differs(&with(|b| b.plan = "q".into())),
            Some("the config (the validated plan)")
        );
        assert_eq!(
            a.differs(&with(|b| b.records = "s".into())),
            Some("the records (their content)")
        );
        // The engine version is named first: a new pound may read the same config otherwise.
        assert_eq!(
            a.differs(&with(|b| {
                b.engine = "f".into();
                b.plan = "q".into();
            })),
            Some("the engine version")
        );
    }

    /// A refusal names the `[run]` keys that differ, with both values, where both sidecars
    /// record them (they survive TOML); against a sidecar written before they were recorded it
    /// names the config as a whole; where the engine differs, only that.
    #[test]
    fn sidecars_name_the_keys_that_differ() {
        let meta = |limit: &str| {
            let text = format!(
                "[[building]]\nstoreys = 2\nstorey_height_m = 3.0\nmass_kg = 2e5\nperiod_s = 0.3\ndamping_ratio = 0.05\n\
                 [[building]]\nstoreys = 1\nstorey_height_m = 3.0\nmass_kg = 2e5\nperiod_s = 0.2\ndamping_ratio = 0.05\n\
                 [contact]\nlaw = \"linear\"\nk_n_per_m = 1e9\ngap_m = 0.01\n\
                 [[record]]\nsynthetic = {{ seed = 1, duration_s = 1.0 }}\n[run]\ncollapse_drift_ratio = {limit}\n"
            );
            let plan = crate::plan::config::load_text(&text, Path::new("row.toml")).unwrap();
            Meta {
                fingerprint: Fingerprint::of_plan(&plan),
                plan_runs: plan.len(),
                first_run: 0,
                end_run: plan.len(),
                shard: None,
                backend: "cpu".into(),
                kernel: None,
                columns: None,
                content: None,
                target_error: None,
                settings: Some(Settings::of_plan(&plan)),
            }
        };
        let round_trip =
            |m: &Meta| -> Meta { toml::from_str(&toml::to_string(m).unwrap()).unwrap() };
        let (here, there) = (meta("0.05"), round_trip(&meta("0.1")));
        assert_eq!(there, meta("0.1"));
        let d = here.differs(&there, "OUT.meta.toml").unwrap();
        assert_eq!(
            d.differs_from("the sweep that wrote it"),
            "the config (the validated plan) differs from the sweep that wrote it ([run] collapse_drift_ratio: 0.05 here, 0.1 in OUT.meta.toml)"
        );
        assert_eq!(
            meta("\"none\"").differs(&there, "X").unwrap().keys,
            ["[run] collapse_drift_ratio: \"none\" here, 0.1 in X"]
        );
        assert_eq!(here.differs(&meta("0.05"), "X"), None);
        // An older sidecar: no settings in its text.
        let older = {
            let text = toml::to_string(&Meta {
                settings: None,
                ..there.clone()
            })
            .unwrap();
            assert!(!text.contains("settings"), "{text}");
            toml::from_str::<Meta>(&text).unwrap()
        };
        assert_eq!(
            here.differs(&older, "X").unwrap().differs_from("its sweep"),
            "the config (the validated plan) differs from its sweep"
        );
        let other_engine = Meta {
            fingerprint: Fingerprint {
                engine: "0.0.0".into(),
                ..there.fingerprint.clone()
            },
            ..there.clone()
        };
        assert_eq!(
            here.differs(&other_engine, "X")
                .unwrap()
                .differs_from("its sweep"),
            "the engine version differs from its sweep"
        );
    }

    /// The fingerprint covers the axes, the scheme and the records' content, and nothing that
    /// does not change the runs (the config's file name, or its text's spelling).
    #[test]
    fn fingerprint_follows_what_changes_the_runs() {
        let base = "[building1]\nmass_kg = 1.0e5\nperiod_s = [0.3, 0.5]\ndamping_ratio = 0.05\n[building2]\nmass_kg = 1.0e5\nperiod_s = 0.9\ndamping_ratio = 0.05\n[contact]\nlaw = \"linear\"\nk_n_per_m = 1e9\ngap_m = 0.0\n";
        let fp = |text: &str, name: &str| {
            let plan = crate::plan::config::parse_builtin(text, name).unwrap();
            Fingerprint::of(&plan)
        };
        let rec =
            |seed: u32| format!("[[record]]\nsynthetic = {{ seed = {seed}, duration_s = 1.0 }}\n");
        let a = fp(&format!("{base}{}", rec(1)), "a.toml");
        assert_eq!(a, fp(&format!("{base}{}", rec(1)), "elsewhere/b.toml"));
        assert_eq!(
            a,
            fp(
                &format!("{}{}", base.replace("1.0e5", "100000.0"), rec(1)),
                "a.toml"
            )
        );
        let other_axis = fp(
            &format!("{}{}", base.replace("[0.3, 0.5]", "[0.3, 0.6]"), rec(1)),
            "a.toml",
        );
        assert_eq!(
            a.differs(&other_axis),
            Some("the config (the validated plan)")
        );
        let other_record = fp(&format!("{base}{}", rec(2)), "a.toml");
        assert_eq!(
            a.differs(&other_record),
            Some("the records (their content)")
        );
    }
}
