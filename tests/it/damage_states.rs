//! The built-in damage-state sets end to end (`pound fragility --damage-states`): the list of
//! them, FEMA P-58's residual drift states fitted on residual drifts (runs that did not settle
//! included), each set read only on its own demand, and the error for a name there is not.

use crate::support::cli::yielding_runs;
use crate::support::{ok, pound, tempdir};
use pounding::plan::sample::{phi_inv, Rng};
use pounding::studies::damage_states::DamageStates;
use std::path::{Path, PathBuf};

/// Residual drifts `ln r = A + B ln IM + SIGMA eps`, so that
/// `P(r > L | IM) = Phi(ln(IM / m) / beta)` with `beta = SIGMA / B` and `ln m = (ln L - A) / B`;
/// the peak drift is 4 r. A run whose residual is below 0.0005 is written with no residual
/// (as a run that did not settle) where `blank`: its peak drift, below 0.002, decides it below
/// every limit of FEMA P-58's set.
const A: f64 = -4.5;
const B: f64 = 1.2;
const SIGMA: f64 = 0.5;

fn draws(dir: &Path, blank: bool) -> (PathBuf, usize) {
    let mut rng = Rng::new(48);
    let mut s =
        String::from("run,record,target_sa_g,status,b1_peak_drift_ratio,b1_residual_drift_ratio\n");
    let (mut run, mut blanks) = (0, 0);
    for im in [0.1, 0.2, 0.3, 0.45, 0.6, 0.8, 1.0, 1.4, 2.0] {
        for r in 0..8 {
            for _ in 0..50 {
                let residual = (A + B * f64::ln(im) + SIGMA * phi_inv(rng.uniform())).exp();
                let cell = if blank && residual < 0.0005 {
                    blanks += 1;
                    String::new()
                } else {
                    residual.to_string()
                };
                s.push_str(&format!("{run},rec{r},{im},ok,{},{cell}\n", 4.0 * residual));
                run += 1;
            }
        }
    }
    let p = dir.join(if blank { "blanks.csv" } else { "all.csv" });
    std::fs::write(&p, s).unwrap();
    (p, blanks)
}

fn s(p: &Path) -> String {
    p.to_str().unwrap().to_string()
}

/// The fitted table's rows: label, then median, beta, se(ln median), se(beta).
fn rows(out: &str) -> Vec<(String, [f64; 4])> {
    out.lines()
        .take_while(|l| !l.contains("have no value of"))
        .filter(|l| l.starts_with("| ") && !l.contains("median"))
        .filter_map(|l| {
            let c: Vec<&str> = l.split('|').map(str::trim).collect();
            let v: Vec<f64> = c[2..6].iter().filter_map(|x| x.parse().ok()).collect();
            (v.len() == 4).then(|| (c[1].to_string(), [v[0], v[1], v[2], v[3]]))
        })
        .collect()
}

/// FEMA P-58's residual drift states on `b1_residual_drift_ratio`: each state's median and beta
/// those of the demand model within 3 standard errors; the runs with no residual, decided by
/// their peak drift, leave the fit as it is with their values written.
#[test]
fn a_residual_drift_set_fits_residual_drifts_end_to_end() {
    let dir = tempdir();
    let d = dir.path();
    let fit = |csv: &Path, out: &str| {
        ok(&pound(&[
            "fragility",
            &s(csv),
            "--im",
            "target_sa_g",
            "--edp",
            "b1_residual_drift_ratio",
            "--damage-states",
            "fema-p58-residual",
            "-o",
            &s(&d.join(out)),
        ]))
    };
    let (all, _) = draws(d, false);
    let (blanks, n) = draws(d, true);
    assert!(n > 50, "{n} runs without a residual");
    let full = fit(&all, "all-f.csv");
    let out = fit(&blanks, "blanks-f.csv");
    assert!(
        out.contains("damage states fema-p58-residual (FEMA P-58-1 (2012), Table 5-3, damage states for residual drift) on b1_residual_drift_ratio"),
        "{out}"
    );
    let r = rows(&out);
    assert_eq!(r.len(), 4, "{out}");
    let beta = SIGMA / B;
    for ((label, v), (state, limit)) in r.iter().zip([
        ("DS1", 0.002f64),
        ("DS2", 0.005),
        ("DS3", 0.01),
        ("DS4", 0.02),
    ]) {
        assert_eq!(label, &format!("{state} ({limit})"));
        let median = ((limit.ln() - A) / B).exp();
        let z_median = (v[0].ln() - median.ln()) / v[2];
        let z_beta = (v[1] - beta) / v[3];
        assert!(
            z_median.abs() < 3.0 && z_beta.abs() < 3.0,
            "{label}: {v:?} against {median}, {beta}"
        );
    }
    // Every blank is decided (below 0.002 at its peak): the same fits as with the values.
    assert_eq!(r, rows(&full));
    assert!(
        out.contains(&format!(
            "{n} runs have no value of b1_residual_drift_ratio"
        )),
        "{out}"
    );
    assert!(out.contains(&format!("| DS1 (0.002) | {n} | 0 |")), "{out}");
    let csv = std::fs::read_to_string(d.join("blanks-f.csv")).unwrap();
    assert!(csv.lines().nth(1).unwrap().contains("DS1"), "{csv}");
}

/// A built-in set names its demand: FEMA P-58's residual drift states on a peak drift, HAZUS's
/// peak drift states on a residual drift, and the residual states on a storey's signed residual
/// are refused, both named, nothing written; a file's set (no demand named) reads on any column
/// of its unit, as before.
#[test]
fn a_set_is_read_only_on_its_own_demand() {
    let dir = tempdir();
    let d = dir.path();
    let (csv, _) = draws(d, false);
    let run = |edp: &str, set: &str, out: &str| {
        pound(&[
            "fragility",
            &s(&csv),
            "--im",
            "target_sa_g",
            "--edp",
            edp,
            "--damage-states",
            set,
            "-o",
            &s(&d.join(out)),
        ])
    };
    for (edp, set, needles) in [
        (
            "b1_peak_drift_ratio",
            "fema-p58-residual",
            vec![
                "--damage-states fema-p58-residual: its limits are of the residual interstorey drift ratio",
                "--edp b1_peak_drift_ratio is the peak drift ratio, building 1",
                "give --edp b1_residual_drift_ratio",
            ],
        ),
        (
            "b1_residual_drift_ratio",
            "hazus-c1l-moderate",
            vec![
                "--damage-states hazus-c1l-moderate: its limits are of the peak interstorey drift ratio",
                "--edp b1_residual_drift_ratio is the residual drift ratio, building 1",
                "give --edp b1_peak_drift_ratio",
                "such as fema-p58-residual",
            ],
        ),
        (
            "b1_s1_residual_drift_ratio",
            "fema-p58-residual",
            vec!["signed", "give --edp b1_residual_drift_ratio"],
        ),
        (
            "peak_force_n",
            "fema-p58-residual",
            vec!["in m/m", "peak_force_n is in N", "such as b1_residual_drift_ratio"],
        ),
    ] {
        let o = run(edp, set, "refused.csv");
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{edp} with {set}: rc 0");
        for n in needles {
            assert!(err.contains(n), "expected `{n}` in: {err}");
        }
    }
    assert!(!d.join("refused.csv").exists());
    ok(&run(
        "b1_residual_drift_ratio",
        "fema-p58-residual",
        "a.csv",
    ));
    ok(&run("b1_peak_drift_ratio", "hazus-s1m-moderate", "b.csv"));
    let file = d.join("drift.toml");
    std::fs::write(
        &file,
        "unit = \"m/m\"\n[[state]]\nname = \"small\"\nlimit = 0.002\n[[state]]\nname = \"large\"\nlimit = 0.01\n",
    )
    .unwrap();
    ok(&run("b1_residual_drift_ratio", &s(&file), "c.csv"));
    ok(&run("b1_peak_drift_ratio", &s(&file), "d.csv"));
}

/// `--damage-states list` (no results CSV needed) prints every built-in set once, in the
/// library's order, with the limits `--damage-states NAME` then uses; a set from the list fits
/// with those limits.
#[test]
fn the_built_in_sets_are_listed_with_their_limits() {
    let out = ok(&pound(&["fragility", "--damage-states", "list"]));
    let listed_rows: Vec<Vec<String>> = out
        .lines()
        .filter(|l| l.starts_with("| ") && !l.starts_with("| set |"))
        .map(|l| l.split('|').map(|c| c.trim().to_string()).collect())
        .collect();
    let names = DamageStates::built_in_names();
    assert_eq!(listed_rows.len(), names.len(), "{out}");
    assert_eq!(listed_rows.len(), 129);
    for (row, name) in listed_rows.iter().zip(&names) {
        assert_eq!(&row[1], name);
        let listed: Vec<f64> = row[5]
            .split(", ")
            .map(|p| p.rsplit_once(' ').unwrap().1.parse().unwrap())
            .collect();
        assert!(listed.windows(2).all(|w| w[0] < w[1]), "{name}: {listed:?}");
        assert_eq!(listed, DamageStates::get(name).unwrap().limits(), "{name}");
    }
    let row = listed_rows
        .iter()
        .find(|r| r[1] == "hazus-s1m-moderate")
        .unwrap();
    assert_eq!(row[2], "S1M: steel moment frame, mid-rise, moderate code");
    assert_eq!(row[3], "bK_peak_drift_ratio");
    assert_eq!(
        row[4],
        "HAZUS-MH MR5 Technical Manual (FEMA 2010), Table 5.9b, S1M"
    );
    assert_eq!(
        row[5],
        "slight 0.004, moderate 0.0069, extensive 0.0157, complete 0.04"
    );
    // The types a code level lacks are not listed at it.
    assert!(!names.iter().any(|n| n == "hazus-urml-high"));
    assert!(names.iter().any(|n| n == "hazus-urml-low"));

    let dir = tempdir();
    let (csv, _) = draws(dir.path(), false);
    let out = ok(&pound(&[
        "fragility",
        &s(&csv),
        "--im",
        "target_sa_g",
        "--edp",
        "b1_peak_drift_ratio",
        "--damage-states",
        "hazus-s1m-moderate",
        "-o",
        &s(&dir.path().join("f.csv")),
    ]));
    let labels: Vec<String> = rows(&out).into_iter().map(|r| r.0).collect();
    assert!(out.contains("Table 5.9b, S1M"), "{out}");
    for want in ["slight (0.004)", "moderate (0.0069)", "extensive (0.0157)"] {
        assert!(labels.iter().any(|l| l == want), "{want} in {labels:?}");
    }
    assert!(out.contains("| complete (0.04) |"), "{out}");
}

/// A name that is no set: the error groups the built-in names (not 129 of them) and points to
/// `--damage-states list`; a HAZUS type at a code level its table lacks is told the levels it
/// has; without a results CSV, only `list` runs.
#[test]
fn an_unknown_set_is_refused_with_the_names_grouped() {
    let dir = tempdir();
    let (csv, _) = draws(dir.path(), false);
    let refused = |set: &str| {
        let o = pound(&["fragility", &s(&csv), "--damage-states", set]);
        assert!(!o.status.success(), "{set}: rc 0");
        String::from_utf8_lossy(&o.stderr).to_string()
    };
    let e = refused("hazus-c1x-high");
    for n in [
        "not a built-in set or a file",
        "hazus-TYPE-LEVEL (e.g. hazus-c1l-high)",
        "s5l, s5m, s5h, c3l, c3m, c3h, urml, urmm at low and pre code only",
        "fema-p58-residual",
        "`pound fragility --damage-states list`",
    ] {
        assert!(e.contains(n), "expected `{n}` in: {e}");
    }
    assert!(!e.contains("hazus-rm2h-pre"), "{e}");
    let e = refused("hazus-urmm-high");
    assert!(
        e.contains(
            "HAZUS Table 5.9a (high code) has no URMM: it has hazus-urmm-low, hazus-urmm-pre"
        ),
        "{e}"
    );
    let o = pound(&["fragility", "--damage-states", "hazus-c1l-high"]);
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("give the results CSV"));
}

/// Class 3, units ignored: damage-state limits in one unit are refused on a column in another,
/// both named (`--edp peak_force_n --damage-states hazus-c1l-high` read drift-ratio limits as
/// newtons, rc 0, four identical curves); a file may give its limits' unit, and then reads on
/// a column in that unit.
#[test]
fn limits_and_columns_agree_on_units() {
    let dir = tempdir();
    let d = dir.path();
    let runs = yielding_runs(d);
    let forces = d.join("forces.toml");
    std::fs::write(
        &forces,
        "unit = \"N\"\n[[state]]\nname = \"light\"\nlimit = 1e6\n[[state]]\nname = \"heavy\"\nlimit = 3e6\n",
    )
    .unwrap();
    let s = |p: &Path| p.to_str().unwrap().to_string();
    let run = |edp: &str, states: &str, out: &str| {
        pound(&[
            "fragility",
            &s(&runs),
            "--edp",
            edp,
            "--damage-states",
            states,
            "-o",
            &s(&d.join(out)),
        ])
    };
    for (o, needles) in [
        (
            run("peak_force_n", "hazus-c1l-high", "a.csv"),
            ["in m/m", "peak_force_n is in N"],
        ),
        (
            run("b1_peak_drift_ratio", &s(&forces), "b.csv"),
            ["in N", "b1_peak_drift_ratio is in m/m"],
        ),
    ] {
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "rc 0: {err}");
        for n in needles {
            assert!(err.contains(n), "expected `{n}` in: {err}");
        }
    }
    assert!(!d.join("a.csv").exists() && !d.join("b.csv").exists());
    ok(&run("peak_force_n", &s(&forces), "c.csv"));
    ok(&run("b1_peak_drift_ratio", "hazus-c1l-high", "d.csv"));
}
