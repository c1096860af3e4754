//! One scene, two spellings: two one-storey buildings written as `[building1]`/`[building2]`
//! and as two `[[building]]` entries give the same runs in the same order. Under the reference
//! scheme the pair's and the row's kernels run them: the same impacts, and peaks within 1e-9.
//! Under the fast scheme both spellings run on the pair's kernels (`engine::Kernel::of`): every
//! cell the two outputs share is the same, and the row's floor accelerations (which the pair
//! kernel tracks for it) are within 1e-4 of the reference row kernel's. Each says which kernel
//! ran; only the config reader tells the kinds of config apart.

use crate::support::{ok, pound, tempdir};
use std::collections::HashMap;
use std::path::Path;

const SCENE: &str = r#"
[contact]
law = ["nonlinear_viscoelastic", "kelvin_voigt"]
formula = "exact"
e = 0.65
beta_n_per_m1_5 = 2.75e9
k_n_per_m = 2.0e8
gap_m = [0.0, 0.01]

[[record]]
synthetic = { seed = 1, duration_s = 6.0, dt_s = 0.01 }

[intensity]
pga_g = 0.4
"#;

fn buildings(pair: bool) -> String {
    let b = |storeys: bool, m: f64, t: f64, xi: f64| {
        format!(
            "{}mass_kg = {m:e}\nperiod_s = {t}\ndamping_ratio = {xi}\n",
            if storeys {
                "storeys = 1\nstorey_height_m = 3.0\n"
            } else {
                ""
            }
        )
    };
    if pair {
        format!(
            "[building1]\n{}\n[building2]\n{}",
            b(false, 1e5, 0.3, 0.05),
            b(false, 2e5, 0.9, 0.03)
        )
    } else {
        format!(
            "[[building]]\n{}\n[[building]]\n{}",
            b(true, 1e5, 0.3, 0.05),
            b(true, 2e5, 0.9, 0.03)
        )
    }
}

/// Each run's cells by column name.
fn sweep(
    dir: &Path,
    name: &str,
    run: &str,
    pair: bool,
    kernel: &str,
) -> Vec<HashMap<String, String>> {
    let cfg = dir.join(format!("{name}.toml"));
    std::fs::write(
        &cfg,
        format!("[run]\ntail_s = 1.0\n{run}\n{}\n{SCENE}", buildings(pair)),
    )
    .unwrap();
    let out = dir.join(format!("{name}.csv"));
    let run = pound(&[
        "sweep",
        cfg.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--backend",
        "cpu",
    ]);
    ok(&run);
    // The kernel chosen from the scene is said in the one-line description and the sidecar.
    let said = String::from_utf8_lossy(&run.stderr);
    assert!(
        said.contains(&format!("{kernel} kernel on the CPU")),
        "{said}"
    );
    let sidecar = std::fs::read_to_string(dir.join(format!("{name}.csv.meta.toml"))).unwrap();
    assert!(
        sidecar.contains(&format!("kernel = \"{kernel}\"")),
        "{sidecar}"
    );
    let text = std::fs::read_to_string(&out).unwrap();
    let mut lines = text.lines();
    let head: Vec<&str> = lines.next().unwrap().split(',').collect();
    lines
        .map(|l| {
            head.iter()
                .zip(l.split(','))
                .map(|(h, c)| (h.to_string(), c.to_string()))
                .collect()
        })
        .collect()
}

/// The two spellings' runs side by side: the same parameters and impacts, and the largest
/// relative difference of their peaks.
fn compare(pair: &[HashMap<String, String>], row: &[HashMap<String, String>]) -> f64 {
    assert_eq!(pair.len(), 4);
    assert_eq!(pair.len(), row.len());
    let mut worst = 0.0f64;
    for (p, r) in pair.iter().zip(row) {
        for (a, b) in [
            ("law", "law"),
            ("gap_m", "gap_1_2_m"),
            ("t1_s", "b1_t1_s"),
            ("scale_factor", "scale_factor"),
            ("pgv_m_s", "pgv_m_s"),
            ("arias_m_s", "arias_m_s"),
            ("cav_m_s", "cav_m_s"),
            ("sa_t1_g", "b1_sa_t1_g"),
            ("sa_t2_g", "b2_sa_t1_g"),
            ("impacts", "impacts"),
        ] {
            assert_eq!(p[a], r[b], "run {}: {a}", p["run"]);
        }
        for (a, b) in [
            ("peak_force_n", "peak_force_n"),
            ("peak_penetration_m", "peak_penetration_m"),
            ("peak_u1_m", "b1_peak_roof_m"),
            ("peak_u2_m", "b2_peak_roof_m"),
        ] {
            let (x, y): (f64, f64) = (p[a].parse().unwrap(), r[b].parse().unwrap());
            assert!(x > 0.0, "run {}: {a} = {x}: the runs pound", p["run"]);
            worst = worst.max((x - y).abs() / x);
        }
    }
    worst
}

#[test]
fn a_pair_and_the_same_row_of_two_give_the_same_runs() {
    let dir = tempdir();
    let reference = "scheme = \"reference\"\ntol = 1e-10";
    let row_ref = sweep(dir.path(), "row-ref", reference, false, "row");
    let d = compare(
        &sweep(dir.path(), "pair-ref", reference, true, "pair"),
        &row_ref,
    );
    assert!(d < 1e-9, "reference: pair and row differ by {d:e}");
    let (pair, row) = (
        sweep(dir.path(), "pair", "", true, "pair"),
        sweep(dir.path(), "row", "", false, "pair"),
    );
    assert_eq!(
        compare(&pair, &row),
        0.0,
        "fast: one kernel, the same peaks"
    );
    let names: HashMap<&str, &str> = [
        ("gap_m", "gap_1_2_m"),
        ("sa_t1_g", "b1_sa_t1_g"),
        ("sa_t2_g", "b2_sa_t1_g"),
        ("peak_u1_m", "b1_peak_roof_m"),
        ("peak_u2_m", "b2_peak_roof_m"),
        ("m1_kg", "b1_mass_kg"),
        ("m2_kg", "b2_mass_kg"),
        ("t1_s", "b1_t1_s"),
        ("t2_s", "b2_t1_s"),
        ("xi1", "b1_xi"),
        ("xi2", "b2_xi"),
    ]
    .into();
    for (p, r) in pair.iter().zip(&row) {
        for (a, x) in p {
            let b = names.get(a.as_str()).copied().unwrap_or(a);
            assert_eq!(Some(x), r.get(b), "run {}: {a} against {b}", p["run"]);
        }
    }
    // The accelerations the pair kernel tracks for the row, against the row reference's.
    let mut worst = 0.0f64;
    for (r, t) in row.iter().zip(&row_ref) {
        for c in ["b1_peak_accel_m_s2", "b2_peak_accel_m_s2"] {
            let (x, y): (f64, f64) = (r[c].parse().unwrap(), t[c].parse().unwrap());
            assert!(y > 0.0, "run {}: {c}", r["run"]);
            worst = worst.max((x - y).abs() / y);
        }
        for c in [
            "b1_accel_floor",
            "b2_accel_floor",
            "b1_drift_storey",
            "b2_drift_storey",
        ] {
            assert_eq!(r[c], "1", "run {}: {c}", r["run"]);
        }
    }
    eprintln!("fast accelerations against the reference: {worst:.1e}");
    assert!(worst < 1e-4, "fast accelerations differ by {worst:e}");
}

/// The Rust files under `dir`, recursively.
fn sources(dir: &Path) -> Vec<std::path::PathBuf> {
    let mut files = Vec::new();
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            files.extend(sources(&p));
        } else if p.extension().is_some_and(|x| x == "rs") {
            files.push(p);
        }
    }
    files
}

/// One path for every scene: only the config reader tells a pair's config from a row's (no
/// module outside `src/plan/` reads a config's keys to pick a world), and `pound sweep`'s `run`
/// is the short sequence the layout describes.
#[test]
fn only_the_config_reader_tells_the_kinds_of_config_apart() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let files = sources(&root.join("src"));
    assert!(files.len() > 50, "{} sources", files.len());
    for f in &files {
        let text = std::fs::read_to_string(f).unwrap();
        let rel = f
            .strip_prefix(root)
            .unwrap()
            .to_string_lossy()
            .replace('\\', "/");
        if rel.starts_with("src/plan/") || rel.starts_with("src/config/") {
            continue;
        }
        for telltale in [
            "is_row_config",
            "contains_key(\"building\")",
            "RawRowConfig",
        ] {
            assert!(!text.contains(telltale), "{rel} holds `{telltale}`");
        }
    }
    let sweep = std::fs::read_to_string(root.join("src/cli/sweep.rs")).unwrap();
    let body: Vec<&str> = sweep
        .lines()
        .skip_while(|l| !l.starts_with("pub fn run("))
        .take_while(|l| *l != "}")
        .collect();
    assert!(
        !body.is_empty() && body.len() < 80,
        "cli/sweep.rs::run is {} lines",
        body.len()
    );
}
