//! Named scenes the tests share: configs (or builders of them) that several features are tested
//! on, so a scene is written once and a test says only what it changes.

pub mod models;

use crate::support::cli::{interrupt, sweep};
use crate::support::{ok, pound, tempdir};
use std::path::{Path, PathBuf};

/// 96 cheap runs: a synthetic record and a record file (so `-o` can name an input record).
pub const CHEAP_SWEEP: &str = r#"
[run]
tail_s = 0.5

[building1]
mass_kg = 1.0e5
period_s = [0.3, 0.6]
damping_ratio = 0.05

[building2]
mass_kg = 1.0e5
period_s = [0.45, 1.0]
damping_ratio = 0.05

[contact]
law = ["nonlinear_viscoelastic", "kelvin_voigt"]
formula = "exact"
e = [0.5, 0.8]
k_n_per_m = 1e9
beta_n_per_m1_5 = 2.75e9
gap_m = [0.0, 0.01, 0.03]

[[record]]
synthetic = { seed = 1, duration_s = 3.0 }

[[record]]
path = "rec.txt"
format = "values"
dt_s = 0.01
units = "g"
"#;

/// A row of two buildings; `left` and `right` are the `[[building]]` bodies.
pub fn row(left: &str, right: &str, extra: &str) -> String {
    format!(
        r#"[run]
tail_s = 0.5

[[building]]
{left}

[[building]]
{right}

[contact]
law = "nonlinear_viscoelastic"
formula = "ebrahimi"
e = 0.65
beta_n_per_m1_5 = 2.75e9
gap_m = [0.0, 0.01]

[[record]]
synthetic = {{ seed = 1, duration_s = 2.0, dt_s = 0.01, pga_g = 0.35 }}
{extra}"#
    )
}

/// The keys of a 3-storey (and below, a 2-storey) building of 300 t floors, for [`row`].
pub const STOREYS3: &str =
    "storeys = 3\nstorey_height_m = 3.0\nmass_kg = 3.0e5\nperiod_s = 0.4\ndamping_ratio = 0.05";

pub const STOREYS2: &str =
    "storeys = 2\nstorey_height_m = 3.0\nmass_kg = 3.0e5\nperiod_s = 0.3\ndamping_ratio = 0.05";

/// `base` (TOML lines) with `extra`'s lines after it, less the base's lines whose key `extra`
/// gives or drops (a line `-key`).
pub fn with(base: &[&str], extra: &str) -> String {
    let key = |line: &str| line.split('=').next().unwrap_or("").trim().to_string();
    let given = |line: &str| {
        extra
            .lines()
            .any(|l| key(l) == key(line) || l.strip_prefix('-') == Some(key(line).as_str()))
    };
    let mut lines: Vec<&str> = base.iter().copied().filter(|l| !given(l)).collect();
    lines.extend(extra.lines().filter(|l| !l.starts_with('-')));
    lines.join("\n")
}

/// A row of two 2-storey buildings with `b0`, `b1` added to (or replacing keys of) each
/// building's keys, `contact` to the contact's, and `tail` at the end.
pub fn row_config(b0: &str, b1: &str, contact: &str, tail: &str) -> String {
    let building = |period: &'static str| {
        [
            "storeys = 2",
            "storey_height_m = 3.0",
            "mass_kg = 3.0e5",
            period,
            "damping_ratio = 0.05",
        ]
    };
    format!(
        "[[building]]\n{}\n\n[[building]]\n{}\n\n[contact]\n{}\n\n[[record]]\nsynthetic = {{ seed = 1, duration_s = 1.0, dt_s = 0.01, pga_g = 0.3 }}\n{tail}\n",
        with(&building("period_s = 0.4"), b0),
        with(&building("period_s = 0.3"), b1),
        with(&["law = \"linear\"", "k_n_per_m = 1e9", "gap_m = 0.01"], contact),
    )
}

/// [`CHEAP_SWEEP`] written out in a folder of its own beside its record file `rec.txt`, and the
/// CSV of its uninterrupted sweep.
pub struct Scene {
    pub dir: tempfile::TempDir,
    pub cfg: PathBuf,
    pub record: PathBuf,
    /// The uninterrupted sweep's CSV.
    pub whole: String,
}

impl Scene {
    /// Writes the scene and sweeps it whole (CPU).
    pub(crate) fn new() -> Scene {
        let dir = tempdir();
        let record = dir.path().join("rec.txt");
        let v: Vec<String> = (0..400)
            .map(|i| format!("{}", 0.3 * (i as f64 * 0.07).sin()))
            .collect();
        std::fs::write(&record, v.join("\n")).unwrap();
        let cfg = dir.path().join("sweep.toml");
        std::fs::write(&cfg, CHEAP_SWEEP).unwrap();
        let out = dir.path().join("whole.csv");
        ok(&sweep(&cfg, &out, &[]));
        let whole = std::fs::read_to_string(&out).unwrap();
        Scene {
            dir,
            cfg,
            record,
            whole,
        }
    }

    /// `name` in the scene's folder.
    pub fn path(&self, name: &str) -> PathBuf {
        self.dir.path().join(name)
    }

    /// See [`interrupt`].
    pub fn interrupted(&self, out: &Path, fraction: f64) {
        interrupt(&self.cfg, self.whole.len(), out, fraction);
    }
}

/// A row of three buildings (2, 4 and 3 storeys: masses, gaps, periods and laws swept; a modal
/// damping, a soft-storey profile) on one synthetic record.
pub const ROW_CONFIG: &str = r#"
[[building]]
storeys = 2
storey_height_m = 3.0
mass_kg = [2e5, 3e5]
period_s = 0.25
damping_ratio = 0.05
gap_right_m = [0.005, 0.01]

[[building]]
storeys = 4
storey_height_m = [3.0, 3.0, 3.5, 3.5]
floor_masses_kg = [3e5, 3e5, 2.5e5, 2e5]
stiffness_profile = [0.5, 1.0, 1.0, 0.8]
period_s = [0.5, 0.7]
damping_ratio = 0.05
damping = "modal"

[[building]]
storeys = 3
storey_height_m = 3.0
mass_kg = 2e5
period_s = 0.3
damping_ratio = 0.03

[contact]
law = ["hertz", "nonlinear_viscoelastic"]
formula = "ebrahimi"
e = 0.6
beta_n_per_m1_5 = 2.75e9
gap_m = 0.008

[[record]]
synthetic = { seed = 4, duration_s = 5.0, dt_s = 0.01, pga_g = 0.4 }
"#;

/// A small sweep with a sampled gap and period and an intensity ladder, on a synthetic record.
pub const SAMPLED: &str = r#"
[run]
tail_s = 1.0

[building1]
mass_kg = 1.0e5
damping_ratio = 0.05

[building2]
mass_kg = 1.0e5
period_s = [0.3, 0.9]
damping_ratio = 0.05

[contact]
law = ["nonlinear_viscoelastic", "hertz"]
formula = "exact"
e = 0.65
beta_n_per_m1_5 = 2.75e9

[sample]
n = 12
seed = 5

[[sample.axis]]
key = "building1.period_s"
dist = "lognormal"
median = 0.5
beta = 0.3
min = 0.2
max = 1.0

[[sample.axis]]
key = "contact.gap_m"
dist = "uniform"
min = 0.0
max = 0.04

[[record]]
synthetic = { seed = 2, duration_s = 6.0 }

[intensity]
pga_g = [0.1, 0.3, 0.6]
"#;

/// [`SAMPLED`] swept (CPU) into `dir`/runs.csv.
pub fn sampled_runs(dir: &Path) -> std::path::PathBuf {
    let cfg = dir.join("sampled.toml");
    std::fs::write(&cfg, SAMPLED).unwrap();
    let out = dir.join("runs.csv");
    ok(&pound(&[
        "sweep",
        cfg.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--backend",
        "cpu",
    ]));
    out
}
