//! One scene, two spellings: two one-storey buildings written as `[building1]`/`[building2]`
//! (the pair kernels) and as two `[[building]]` entries (the row kernels) give the same runs in
//! the same order: the same impacts, and peaks within 1e-9 under the reference scheme; the two
//! fast kernels discretise contact differently, within 1e-5 of each other (each is about 6e-4
//! from the reference here).

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
    ok(&pound(&[
        "sweep",
        cfg.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--backend",
        "cpu",
    ]));
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
