//! `pound gap` where a building collapses (issue 64, item 2): every run is reported, a
//! collapsed one with each pair's gaps up to the collapse (a lower bound, censored) and a run
//! that ended early for another reason left out with its status; a study whose every run failed
//! is an error; a study where nothing collapses writes what it wrote before, to the bit.

use crate::support::cli::s;
use crate::support::{ok, pound, table, tempdir};
use sha2::{Digest, Sha256};
use std::collections::HashMap;

fn num(row: &HashMap<String, String>, col: &str) -> f64 {
    row[col]
        .parse()
        .unwrap_or_else(|_| panic!("{col} = `{}`", row[col]))
}

fn sha256(bytes: &[u8]) -> String {
    Sha256::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

/// The shipped IDA ladder to collapse (a P-Delta frame beside a stiff neighbour, 50 runs)
/// runs to the end. The frame collapses uncoupled exactly where it collapses alone
/// (`configs/collapse-ida-alone.toml`, the same frame, records and ladder): the same runs,
/// at the same times within 1 ms, are censored by building 1; the others are not. The summary
/// counts them with their record and intensity and leaves them out of the rule table; the
/// curve counts a censored run as pounding below its bound and nowhere above it.
#[test]
fn a_collapse_censors_the_pair_and_the_study_goes_on() {
    let dir = tempdir();
    let (gaps, curve, plot) = (
        dir.path().join("g.csv"),
        dir.path().join("curve.csv"),
        dir.path().join("g.svg"),
    );
    let stdout = ok(&pound(&[
        "gap",
        "configs/collapse-ida.toml",
        "-o",
        s(&gaps),
        "--curve",
        s(&curve),
        "--plot",
        s(&plot),
    ]));
    let alone = dir.path().join("alone.csv");
    ok(&pound(&[
        "sweep",
        "configs/collapse-ida-alone.toml",
        "-o",
        s(&alone),
        "--backend",
        "cpu",
    ]));
    let (rows, alone) = (table(&gaps), table(&alone));
    assert_eq!(rows.len(), 50);
    assert_eq!(alone.len(), 50);
    let mut collapsed = Vec::new();
    for (g, a) in rows.iter().zip(&alone) {
        assert_eq!(
            (&g["record"], &g["target_sa_g"]),
            (&a["record"], &a["target_sa_g"])
        );
        let required = num(g, "required_gap_m");
        assert!(required.is_finite() && required > 0.0, "{g:?}");
        if a["status"] == "collapsed" {
            collapsed.push(g);
            assert_eq!(g["status"], "collapsed", "run {}", g["run"]);
            assert_eq!(g["censored_by"], "1", "run {}", g["run"]);
            let (t, want) = (num(g, "censored_at_s"), num(a, "collapse_time_s"));
            assert!(
                (t - want).abs() < 1e-3,
                "run {}: {t} against {want}",
                g["run"]
            );
            // The closing is over the time before the collapse.
            assert!(num(g, "required_at_s") <= t, "{g:?}");
        } else {
            assert_eq!(a["status"], "ok");
            assert_eq!(g["status"], "ok", "run {}", g["run"]);
            assert_eq!(
                (g["censored_by"].as_str(), g["censored_at_s"].as_str()),
                ("", "")
            );
        }
    }
    let n = collapsed.len();
    assert!(n >= 10, "the ladder reaches collapse: {n} runs");
    let first = collapsed[0];
    let head = format!(
        "{n} of 50 runs collapsed (a building's storey reached [run] collapse_drift_ratio)"
    );
    assert!(stdout.contains(&head), "{stdout}");
    let named = format!(
        "run {} ({}, Sa {} g): building 1 at {:.2} s",
        first["run"],
        first["record"],
        first["target_sa_g"],
        num(first, "censored_at_s")
    );
    assert!(stdout.contains(&named), "{named} not in {stdout}");
    // The rule table counts the runs with no collapse only, and says so.
    let abs_row = format!("| 1-2 | ABS | {} |", 50 - n);
    assert!(stdout.contains(&abs_row), "{stdout}");
    assert!(stdout.contains(&format!("Pair 1-2: {n} runs censored by a collapse")));
    // The curve: at each gap, the runs whose outcome there is known (exact ones, and
    // censored ones whose bound is above it) and of those the ones that pound.
    let curve = table(&curve);
    assert!(!curve.is_empty());
    for c in &curve {
        let g = num(c, "gap_m");
        let at: Vec<_> = rows
            .iter()
            .filter(|r| format!("Sa {} g", r["target_sa_g"]) == c["intensity"])
            .collect();
        assert_eq!(at.len(), 5, "{}", c["intensity"]);
        let (exact, bounds): (Vec<_>, Vec<_>) =
            at.iter().partition(|r| r["censored_by"].is_empty());
        let above = |v: &[&&HashMap<String, String>]| {
            v.iter().filter(|r| num(r, "required_gap_m") > g).count()
        };
        let known = exact.len() + above(&bounds);
        let pound = above(&exact) + above(&bounds);
        assert_eq!(
            (c["runs"].as_str(), c["pounding"].as_str()),
            (known.to_string().as_str(), pound.to_string().as_str()),
            "{c:?}"
        );
        if known == 0 {
            assert_eq!(c["share"], "", "no share over zero runs: {c:?}");
        }
    }
    let svg = std::fs::read_to_string(&plot).unwrap();
    assert!(
        svg.contains("lower bound"),
        "the censored runs are drawn apart"
    );
}

/// The same ladder with no collapse limit: the frames that collapse run away (a floor travels
/// the uncoupled levels' 1e6 m gap) or overflow. Each such run is reported with its status and
/// its record and intensity, its gaps left empty and out of every statistic; the others are
/// the runs of the study with the limit that did not collapse, to the bit.
#[test]
fn runs_that_end_early_are_named_and_left_out() {
    let dir = tempdir();
    let text = std::fs::read_to_string("configs/collapse-ida.toml").unwrap();
    let none = text.replace(
        "collapse_drift_ratio = 0.10",
        "collapse_drift_ratio = \"none\"",
    );
    assert_ne!(none, text);
    let cfg = dir.path().join("ida-none.toml");
    std::fs::write(&cfg, &none).unwrap();
    let (gaps, limited) = (dir.path().join("g.csv"), dir.path().join("limited.csv"));
    let stdout = ok(&pound(&["gap", s(&cfg), "-o", s(&gaps)]));
    ok(&pound(&[
        "gap",
        "configs/collapse-ida.toml",
        "-o",
        s(&limited),
    ]));
    let (rows, limited) = (table(&gaps), table(&limited));
    assert_eq!(rows.len(), 50);
    // No limit: no censoring columns.
    assert!(!rows[0].contains_key("censored_by"));
    let failed: Vec<_> = rows.iter().filter(|r| r["status"] != "ok").collect();
    assert!(!failed.is_empty());
    for r in &failed {
        assert!(
            ["non_finite", "step_limit", "runaway"].contains(&r["status"].as_str()),
            "{r:?}"
        );
        assert_eq!(r["required_gap_m"], "", "{r:?}");
        assert_eq!(r["abs_gap_m"], "", "{r:?}");
        // Only a frame that collapses under the limit fails without one.
        let l = &limited[num(r, "run") as usize];
        assert_eq!(l["status"], "collapsed", "run {}", r["run"]);
    }
    for (r, l) in rows.iter().zip(&limited) {
        if l["status"] == "ok" {
            assert_eq!(r["status"], "ok");
            assert_eq!(r["required_gap_m"], l["required_gap_m"], "run {}", r["run"]);
            assert_eq!(r["ddc_gap_m"], l["ddc_gap_m"], "run {}", r["run"]);
        }
    }
    let head = format!(
        "{} of 50 runs ended early and are left out of every statistic (status in the CSV): run {} ({}, Sa {} g): {}",
        failed.len(),
        failed[0]["run"],
        failed[0]["record"],
        failed[0]["target_sa_g"],
        failed[0]["status"]
    );
    assert!(stdout.contains(&head), "{head} not in {stdout}");
    let ok_runs = rows.len() - failed.len();
    assert!(
        stdout.contains(&format!("| 1-2 | DDC | {ok_runs} |")),
        "{stdout}"
    );
}

/// A study whose every run ends early has no gap to give: an error naming the runs, and no
/// file written (statistics over zero runs are not zeros).
#[test]
fn a_study_whose_every_run_failed_is_an_error() {
    let dir = tempdir();
    let text = std::fs::read_to_string("configs/collapse-ida.toml").unwrap();
    let top = text
        .replace(
            "collapse_drift_ratio = 0.10",
            "collapse_drift_ratio = \"none\"",
        )
        .replace(
            "sa_g = [0.1, 0.2, 0.3, 0.45, 0.6, 0.8, 1.0, 1.25, 1.5, 2.0]",
            "sa_g = [2.0]",
        );
    let cfg = dir.path().join("top.toml");
    std::fs::write(&cfg, &top).unwrap();
    let gaps = dir.path().join("g.csv");
    let out = pound(&["gap", s(&cfg), "-o", s(&gaps)]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("every run ended early, so there is no gap to give: run 0 (loma_prieta_1989_corralitos, Sa 2 g): "),
        "{err}"
    );
    assert!(!gaps.exists());
}

/// Where nothing can collapse (a pair config: the 2,000 runs of `configs/gap-study.toml`), the
/// CSV, the curve and the tables are those of the code before collapses were handled
/// (SHA-256 of its output, generated on this machine before the change; the first line, the
/// timing, left out). A yielding row with a collapse limit where nothing collapses
/// (`configs/inelastic-fragility.toml`) gains the columns `status`, `censored_by` and
/// `censored_at_s`; every other column is as before, to the bit.
#[test]
fn where_nothing_collapses_the_output_is_unchanged() {
    let dir = tempdir();
    let (gaps, curve) = (dir.path().join("g.csv"), dir.path().join("c.csv"));
    let stdout = ok(&pound(&[
        "gap",
        "configs/gap-study.toml",
        "-o",
        s(&gaps),
        "--curve",
        s(&curve),
    ]));
    assert_eq!(
        sha256(&std::fs::read(&gaps).unwrap()),
        "6e0692730d59e96895243747753345cca10cee7f9c7572fac4f6e60799883677"
    );
    assert_eq!(
        sha256(&std::fs::read(&curve).unwrap()),
        "ba25d5822c0675de39aa661273b2c64bc7c5aea44f51c5e79cbebf2fabc3cf26"
    );
    let tables = stdout.split_once('\n').unwrap().1;
    assert_eq!(
        sha256(tables.as_bytes()),
        "9e18ff531d416e1f12e8c0b4bae7692c678c927b31f79899a460e9a625370870"
    );

    let yielding = dir.path().join("y.csv");
    ok(&pound(&[
        "gap",
        "configs/inelastic-fragility.toml",
        "-o",
        s(&yielding),
    ]));
    let text = std::fs::read_to_string(&yielding).unwrap();
    let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
    let new = ["status", "censored_by", "censored_at_s"];
    let at: Vec<usize> = new
        .iter()
        .map(|c| header.iter().position(|h| h == c).expect(c))
        .collect();
    let mut before = String::new();
    for (i, line) in text.lines().enumerate() {
        let cells: Vec<&str> = line.split(',').collect();
        if i > 0 {
            assert_eq!(
                at.iter().map(|&k| cells[k]).collect::<Vec<_>>(),
                ["ok", "", ""],
                "{line}"
            );
        }
        let kept: Vec<&str> = (cells.iter().enumerate())
            .filter(|(k, _)| !at.contains(k))
            .map(|(_, c)| *c)
            .collect();
        before.push_str(&kept.join(","));
        before.push('\n');
    }
    assert_eq!(
        sha256(before.as_bytes()),
        "b496c2352536e48ea11f8eb7b69d619b743cdd1ba95f472ec360a558b50e10a8"
    );
}
