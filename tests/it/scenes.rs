//! One scene, two spellings: two one-storey buildings written as `[building1]`/`[building2]`
//! (the pair kernels) and as two `[[building]]` entries (the row kernels) give the same runs in
//! the same order: the same impacts, and peaks within 1e-9 under the reference scheme; the two
//! fast kernels discretise contact differently, within 1e-5 of each other (each is about 6e-4
//! from the reference here). Each says which kernel ran; only the config reader tells the kinds
//! of config apart.

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
fn sweep(dir: &Path, name: &str, run: &str, pair: bool) -> Vec<HashMap<String, String>> {
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
    let kernel = if pair { "pair" } else { "row" };
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
    let d = compare(
        &sweep(dir.path(), "pair-ref", reference, true),
        &sweep(dir.path(), "row-ref", reference, false),
    );
    assert!(d < 1e-9, "reference: pair and row differ by {d:e}");
    let d = compare(
        &sweep(dir.path(), "pair", "", true),
        &sweep(dir.path(), "row", "", false),
    );
    assert!(d < 1e-5, "fast: pair and row kernels differ by {d:e}");
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
        if rel.starts_with("src/plan/") {
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
