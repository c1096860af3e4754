//! `pound gap`: the required gap against what `pound sweep` says at gaps around it, for pairs
//! and for a row of multi-storey buildings; identical buildings; the runs it covers; bad input.

use crate::support::cli::s;
use crate::support::run::{ok, pound};
use crate::support::{table, tempdir};
use std::collections::HashMap;
use std::path::Path;

/// `pound sweep CFG -o OUT` on the CPU, read back.
fn sweep_table(cfg: &Path, out: &Path) -> Vec<HashMap<String, String>> {
    ok(&pound(&["sweep", s(cfg), "-o", s(out), "--backend", "cpu"]));
    table(out)
}

fn num(row: &HashMap<String, String>, col: &str) -> f64 {
    row.get(col)
        .unwrap_or_else(|| panic!("no column {col}"))
        .parse()
        .unwrap_or_else(|_| panic!("{col} = `{}`", row[col]))
}

/// The sweep's gaps: every millimetre from 0 to just past the largest required gap.
fn grid_past(largest: f64) -> Vec<f64> {
    (0..=((largest * 1e3).ceil() as usize + 2))
        .map(|i| i as f64 * 1e-3)
        .collect()
}

/// For every run of `sweep` (keyed by `key` to a run of the gap study): impacts exactly where
/// the gap is below the required one. Returns the runs checked.
fn check_against_sweep(
    gaps: &[HashMap<String, String>],
    sweep: &[HashMap<String, String>],
    key: &dyn Fn(&HashMap<String, String>) -> String,
    required_col: &str,
    gap_col: &str,
) -> usize {
    let required: HashMap<String, f64> = gaps
        .iter()
        .map(|r| (key(r), num(r, required_col)))
        .collect();
    let mut checked = 0;
    for r in sweep {
        let need = required[&key(r)];
        let gap = num(r, gap_col);
        assert_eq!(r["status"], "ok");
        // Grid points within a hair of the required gap could go either way.
        if (gap - need).abs() <= 1e-7 * need.max(1e-3) {
            continue;
        }
        let impacts = num(r, "impacts");
        assert_eq!(
            impacts > 0.0,
            gap < need,
            "gap {gap} m against a required {need} m: {impacts} impacts ({})",
            key(r)
        );
        checked += 1;
    }
    checked
}

const PAIRS: &str = r#"
[building1]
mass_kg = 1.0e5
period_s = [0.3, 0.75]
damping_ratio = 0.05

[building2]
mass_kg = 2.0e5
period_s = [0.45, 1.2]
damping_ratio = [0.02, 0.05]

[contact]
law = "nonlinear_viscoelastic"
formula = "ebrahimi"
e = 0.65
beta_n_per_m1_5 = 2.75e9
gap_m = GAPS

[[record]]
synthetic = { seed = 3, duration_s = 8.0, dt_s = 0.01, pga_g = 0.3 }

[[record]]
synthetic = { seed = 7, duration_s = 8.0, dt_s = 0.02, pga_g = 0.3 }

[intensity]
pga_g = [0.2, 0.4]
"#;

/// The required gap of every pair is where `pound sweep` stops reporting impacts: on a 1 mm
/// grid, every gap below it pounds and every gap above it does not (32 runs, 16 of them
/// sharing a response with another intensity).
#[test]
fn required_gap_is_where_pair_sweeps_stop_pounding() {
    let dir = tempdir();
    let cfg = dir.path().join("pairs.toml");
    std::fs::write(&cfg, PAIRS.replace("GAPS", "0.01")).unwrap();
    let out = dir.path().join("gaps.csv");
    let said = ok(&pound(&["gap", s(&cfg), "-o", s(&out)]));
    assert!(said.contains("32 runs (16 responses"), "{said}");
    let gaps = table(&out);
    assert_eq!(gaps.len(), 32);
    let largest = gaps
        .iter()
        .map(|r| num(r, "required_gap_m"))
        .fold(0.0, f64::max);
    // Responses are linear in the record's scale: 0.4 g needs twice what 0.2 g needs.
    let key = |r: &HashMap<String, String>| {
        format!(
            "{} {} {} {} {}",
            r["record"], r["t1_s"], r["t2_s"], r["xi2"], r["target_pga_g"]
        )
    };
    for r in gaps.iter().filter(|r| r["target_pga_g"] == "0.2") {
        let twin = gaps
            .iter()
            .find(|x| key(x) == key(r).replace(" 0.2", " 0.4"))
            .unwrap();
        let ratio = num(twin, "required_gap_m") / num(r, "required_gap_m");
        assert!((ratio - 2.0).abs() < 1e-12, "{ratio}");
    }
    let grid: Vec<String> = grid_past(largest).iter().map(|g| g.to_string()).collect();
    std::fs::write(
        &cfg,
        PAIRS.replace("GAPS", &format!("[{}]", grid.join(", "))),
    )
    .unwrap();
    let swept = dir.path().join("sweep.csv");
    let sweep = sweep_table(&cfg, &swept);
    let checked = check_against_sweep(&gaps, &sweep, &key, "required_gap_m", "gap_m");
    assert!(checked + 4 >= sweep.len(), "{checked} of {}", sweep.len());
    // The rules' columns: ABS >= SRSS >= DDC, each ratio their gap over the required one.
    for r in &gaps {
        let (a, q, d) = (
            num(r, "abs_gap_m"),
            num(r, "srss_gap_m"),
            num(r, "ddc_gap_m"),
        );
        assert!(a >= q && q >= d, "{r:?}");
        assert!((num(r, "ddc_ratio") - d / num(r, "required_gap_m")).abs() < 1e-12);
        assert!((a - num(r, "peak_left_m") - num(r, "peak_right_m")).abs() < 1e-15);
    }
}

const ROW: &str = r#"
[[building]]
storeys = 3
storey_height_m = 3.0
mass_kg = 3.0e5
period_s = [0.3, 0.5]
damping_ratio = 0.05
gap_right_m = G12

[[building]]
storeys = 5
storey_height_m = 3.0
mass_kg = 3.0e5
period_s = 0.8
damping_ratio = 0.05
gap_right_m = G23

[[building]]
storeys = 2
storey_height_m = 3.0
mass_kg = 2.0e5
period_s = 0.2
damping_ratio = 0.05
damping = "modal"

[contact]
law = "nonlinear_viscoelastic"
formula = "ebrahimi"
e = 0.65
beta_n_per_m1_5 = 2.75e9
gap_m = 1.0

[[record]]
synthetic = { seed = 5, duration_s = 6.0, dt_s = 0.01, pga_g = 0.3 }
"#;

/// In a row, a pair's required gap (the largest over its shared levels) is where the row sweep
/// stops pounding between those two buildings; each level's own required gap is reported.
#[test]
fn required_gaps_of_a_row_are_where_row_sweeps_stop_pounding() {
    let dir = tempdir();
    let cfg = dir.path().join("row.toml");
    std::fs::write(&cfg, ROW.replace("G12", "0.01").replace("G23", "0.01")).unwrap();
    let out = dir.path().join("gaps.csv");
    ok(&pound(&["gap", s(&cfg), "-o", s(&out)]));
    let gaps = table(&out);
    assert_eq!(gaps.len(), 2);
    for r in &gaps {
        // The pair's required gap is its governing level's, the largest of its levels'.
        for (pair, levels) in [("1_2", 3), ("2_3", 2)] {
            let need = num(r, &format!("required_gap_{pair}_m"));
            let level = &r[&format!("governing_level_{pair}")];
            assert_eq!(num(r, &format!("{level}_required_m")), need);
            let (b, c) = (&pair[..1], &pair[2..]);
            let of_pair: Vec<f64> = (1..=levels)
                .map(|f| num(r, &format!("level_b{b}f{f}_b{c}f{f}_required_m")))
                .collect();
            assert_eq!(of_pair.iter().cloned().fold(0.0, f64::max), need);
        }
    }
    let largest = gaps
        .iter()
        .flat_map(|r| [num(r, "required_gap_1_2_m"), num(r, "required_gap_2_3_m")])
        .fold(0.0, f64::max);
    // One gap swept for both pairs at once would make one pair's contact change the other's
    // motion: sweep each pair with the other far apart.
    let grid: Vec<String> = grid_past(largest).iter().map(|g| g.to_string()).collect();
    let grid = format!("[{}]", grid.join(", "));
    for pair in ["1_2", "2_3"] {
        let text = if pair == "1_2" {
            ROW.replace("G12", &grid).replace("G23", "1.0")
        } else {
            ROW.replace("G12", "1.0").replace("G23", &grid)
        };
        std::fs::write(&cfg, &text).unwrap();
        let swept = dir.path().join(format!("sweep-{pair}.csv"));
        let sweep = sweep_table(&cfg, &swept);
        let key = |r: &HashMap<String, String>| r["b1_t1_s"].clone();
        let (b, c) = (&pair[..1], &pair[2..]);
        let checked = check_against_sweep(
            &gaps,
            &sweep,
            &key,
            &format!("required_gap_{pair}_m"),
            &format!("gap_{b}_{c}_m"),
        );
        assert!(checked + 2 >= sweep.len(), "{checked} of {}", sweep.len());
    }
}

/// Yielding storeys (the shipped yielding pair, the right one's yield drift an axis): each run
/// is its own response (not linear in the scale), its strength has its column, and its
/// required gap is where `pound sweep` stops pounding on a 1 mm grid; the error bound is
/// left empty (none is known where storeys yield).
#[test]
fn yielding_required_gap_is_where_sweeps_stop_pounding() {
    let dir = tempdir();
    let base = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("configs/inelastic-pair.toml"),
    )
    .unwrap()
    .replace(
        "yield_drift_ratio = 0.004",
        "yield_drift_ratio = { from = 0.003, to = 0.006, n = 2 }",
    );
    let cfg = dir.path().join("pair.toml");
    std::fs::write(&cfg, &base).unwrap();
    let out = dir.path().join("gaps.csv");
    let said = ok(&pound(&["gap", s(&cfg), "-o", s(&out)]));
    assert!(
        said.contains("6 runs (yielding storeys: one response per run"),
        "{said}"
    );
    let gaps = table(&out);
    assert_eq!(gaps.len(), 6);
    let key = |r: &HashMap<String, String>| {
        format!("{} {}", r["target_pga_g"], r["b2_yield_drift_ratio"])
    };
    let mut keys: Vec<String> = gaps.iter().map(key).collect();
    keys.dedup();
    assert_eq!(keys.len(), 6, "{keys:?}");
    for r in &gaps {
        assert_eq!(r["error_bound_m"], "");
        assert!(num(r, "required_gap_m") > 0.0);
    }
    // Not linear in the scale: 0.5 g does not need 2.5 times what 0.2 g needs.
    let of = |k: &str| num(gaps.iter().find(|r| key(r) == k).unwrap(), "required_gap_m");
    let ratio = of("0.5 0.003") / of("0.2 0.003");
    assert!((ratio - 2.5).abs() > 1e-3, "{ratio}");
    let largest = gaps
        .iter()
        .map(|r| num(r, "required_gap_m"))
        .fold(0.0, f64::max);
    let grid: Vec<String> = grid_past(largest).iter().map(|g| g.to_string()).collect();
    std::fs::write(
        &cfg,
        base.replace(
            "gap_right_m = [0.01, 0.02]",
            &format!("gap_right_m = [{}]", grid.join(", ")),
        ),
    )
    .unwrap();
    let swept = dir.path().join("sweep.csv");
    let sweep = sweep_table(&cfg, &swept);
    let checked = check_against_sweep(&gaps, &sweep, &key, "required_gap_m", "gap_1_2_m");
    assert!(checked + 2 >= sweep.len(), "{checked} of {}", sweep.len());
}

/// Buildings of equal period and damping move as one: no gap is needed, DDC says so too
/// (rho = 1), the ratios are left empty and no rule counts as unconservative; the five records
/// of the seed paper are read by path.
#[test]
fn identical_buildings_need_no_gap() {
    let records = crate::support::records_dir();
    let dir = tempdir();
    let cfg = dir.path().join("same.toml");
    let paper = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("configs/paper-gap.toml"),
    )
    .unwrap();
    let text = paper
        .replace("period_s = 0.3", "period_s = [0.5, 0.3]")
        .replace(
            "mass_kg = 10.0\nperiod_s = 0.5",
            "mass_kg = 40.0\nperiod_s = 0.5",
        );
    std::fs::write(&cfg, text).unwrap();
    let out = dir.path().join("gaps.csv");
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_pound"))
        .args(["gap", s(&cfg), "-o", s(&out)])
        .env("POUND_RECORDS_DIR", &records)
        .output()
        .unwrap();
    let said = ok(&o);
    let gaps = table(&out);
    assert_eq!(gaps.len(), 10);
    for r in &gaps {
        let need = num(r, "required_gap_m");
        if r["t2_s"] == "0.5" {
            assert!(need <= 1e-12 * num(r, "peak_left_m"), "{r:?}");
            assert_eq!(num(r, "rho"), 1.0);
            assert!(num(r, "ddc_gap_m") <= 1e-6 * num(r, "peak_left_m"), "{r:?}");
            assert_eq!(r["ddc_ratio"], "");
        } else {
            assert!(need > 0.0 && num(r, "rho") < 1.0, "{r:?}");
            assert!(num(r, "abs_ratio") >= 1.0);
        }
    }
    // 5 runs of different periods close; none of the equal ones counts against a rule.
    assert!(said.contains("| 1-2 | ABS | 10 | "), "{said}");
}

/// The study covers each motion of the sweep once: every distinct (record, intensity,
/// buildings, sample) of the full plan, with no contact or gap axis.
#[test]
fn motions_are_the_distinct_motions_of_the_plan() {
    use pounding::plan::config;
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let cfg = root.join("configs/quickstart.toml");
    let plan = config::load_pair(&cfg).unwrap();
    let key = |r: &pounding::plan::RunSpec| {
        format!(
            "{} {} {} {} {} {} {} {}",
            r.record, r.scale, r.m1, r.t1, r.xi1, r.m2, r.t2, r.xi2
        )
    };
    let all: std::collections::BTreeSet<String> =
        (0..plan.len()).map(|i| key(&plan.run(i))).collect();
    let m = plan.motions();
    let motions: Vec<String> = (0..m.len()).map(|i| key(&plan.motion_run(i))).collect();
    assert_eq!(motions.len(), all.len());
    assert_eq!(
        motions
            .iter()
            .cloned()
            .collect::<std::collections::BTreeSet<_>>(),
        all
    );
    // Rows, with samples that set a period (so each sample is a motion).
    let text = crate::row_sweeps::sampled_config();
    let row = config::load_row_text(&text, &root.join("x.toml")).unwrap();
    let rkey = |r: &pounding::plan::row::RowRunSpec| {
        format!(
            "{} {} {:?} {:?} {:?} {:?}",
            r.contact.record, r.contact.scale, r.mass, r.period, r.damping, r.sample
        )
    };
    let all: std::collections::BTreeSet<String> =
        (0..row.len()).map(|i| rkey(&row.run(i))).collect();
    let m = row.motions();
    let motions: Vec<String> = (0..m.len()).map(|i| rkey(&row.motion_run(i))).collect();
    assert_eq!(motions.len(), all.len());
    assert_eq!(
        motions
            .into_iter()
            .collect::<std::collections::BTreeSet<_>>(),
        all
    );
}

/// Bad input is refused before any work, naming what was wrong; the config is never replaced.
#[test]
fn gap_refuses_bad_input() {
    let dir = tempdir();
    let cfg = dir.path().join("pairs.toml");
    std::fs::write(&cfg, PAIRS.replace("GAPS", "0.01")).unwrap();
    let before = std::fs::read(&cfg).unwrap();
    let err = |args: &[&str]| {
        let o = pound(args);
        assert!(!o.status.success(), "{args:?} succeeded");
        String::from_utf8_lossy(&o.stderr).into_owned()
    };
    let out = dir.path().join("g.csv");
    let e = err(&["gap", s(&cfg), "-o", s(&cfg)]);
    assert!(e.contains("the config"), "{e}");
    let e = err(&["gap", s(&cfg), "-o", s(&out), "--gaps", "0.01,-0.02"]);
    assert!(e.contains("--gaps") && e.contains("-0.02"), "{e}");
    let e = err(&["gap", s(&cfg), "-o", s(&out), "--gaps", "a:b"]);
    assert!(e.contains("--gaps `a:b`"), "{e}");
    let e = err(&["gap", s(&cfg), "-o", s(&out), "--threads", "0"]);
    assert!(e.contains("--threads 0"), "{e}");
    assert_eq!(std::fs::read(&cfg).unwrap(), before);
    assert!(!out.exists());
    // The probability of pounding at the gaps asked for, with the plot and the curve.
    let (plot, curve) = (dir.path().join("g.svg"), dir.path().join("c.csv"));
    let said = ok(&pound(&[
        "gap",
        s(&cfg),
        "-o",
        s(&out),
        "--gaps",
        "0:0.2:0.005",
        "--plot",
        s(&plot),
        "--curve",
        s(&curve),
    ]));
    assert!(said.contains("| 1-2 | PGA 0.2 g |"), "{said}");
    let c = table(&curve);
    assert_eq!(c.len(), 2 * 41);
    let gaps = table(&out);
    for p in &c {
        let (g, n, k) = (num(p, "gap_m"), num(p, "runs"), num(p, "pounding"));
        let pga = p["intensity"]
            .trim_start_matches("PGA ")
            .trim_end_matches(" g");
        let expect = gaps
            .iter()
            .filter(|r| r["target_pga_g"] == pga && num(r, "required_gap_m") > g)
            .count();
        assert_eq!((n, k), (16.0, expect as f64), "{p:?}");
    }
    assert!(std::fs::read_to_string(&plot)
        .unwrap()
        .contains("Probability of pounding"));
}

/// Class 12, a fit the grid biases: `pound gap` fits the probability of pounding to the runs'
/// required gaps themselves, so the gaps it is counted at (the default, a coarse and a fine
/// grid) do not move the fit, and the median is the maximum-likelihood lognormal's of the
/// required gaps the CSV holds (the runs whose floors never close counted apart). It fitted
/// counts at the grid's gaps: the median moved with the grid.
#[test]
fn a_gap_fit_does_not_depend_on_the_grid() {
    let dir = tempdir();
    let config = concat!(env!("CARGO_MANIFEST_DIR"), "/configs/gap-example.toml");
    let fitted_line = |grid: Option<&str>| {
        let out = dir.path().join("gaps.csv");
        let mut args = vec!["gap", config, "-o", out.to_str().unwrap()];
        if let Some(g) = grid {
            args.extend(["--gaps", g]);
        }
        let text = ok(&pound(&args));
        let line = text
            .lines()
            .find(|l| l.starts_with("| 1-2 | PGA 0.35 g |"))
            .unwrap_or_else(|| panic!("no fitted line in:\n{text}"))
            .to_string();
        (line, table(&out))
    };
    let (default, rows) = fitted_line(None);
    for grid in ["0:0.5:0.1", "0:0.5:0.001", "0.03,0.2"] {
        assert_eq!(fitted_line(Some(grid)).0, default, "--gaps {grid}");
    }
    // The maximum-likelihood lognormal of the required gaps above 0.
    let required: Vec<f64> = rows
        .iter()
        .map(|r| r["required_gap_m"].parse().unwrap())
        .collect();
    let logs: Vec<f64> = required
        .iter()
        .filter(|&&r| r > 0.0)
        .map(|r| r.ln())
        .collect();
    let mean = logs.iter().sum::<f64>() / logs.len() as f64;
    let beta = (logs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / logs.len() as f64).sqrt();
    assert!(
        logs.len() > 2 && logs.len() < required.len(),
        "some runs never close"
    );
    let cells: Vec<&str> = default.split('|').map(str::trim).collect();
    assert_eq!(cells[3], required.len().to_string(), "{default}");
    assert_eq!(cells[4], logs.len().to_string(), "{default}");
    assert_eq!(cells[5], format!("{:.2} mm", mean.exp() * 1e3), "{default}");
    assert_eq!(cells[6], format!("{beta:.3}"), "{default}");
}
