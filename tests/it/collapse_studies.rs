//! Fragility and IDA with collapse (issue 48, part 3; physics.md section 10): `pound fragility
//! --edp collapsed` fits P(collapse | IM) to the runs whose status is `collapsed`; threshold and
//! damage-state fits count a collapsed run as exceeding every limit; `pound ida` takes a collapse
//! as an infinite demand (the flatline), in its fractiles and its table. Hand-written tables
//! give the exact counts; one small P-Delta sweep runs them end to end.

use crate::support::cli::stderr;
use crate::support::{ok, pound, table, tempdir};
use pounding::io::table::Table;
use pounding::plan::sample::phi_inv;
use pounding::studies::fragility::{fit, FragilitySpec, Grouped};
use std::path::{Path, PathBuf};

fn s(p: &Path) -> String {
    p.to_str().unwrap().to_string()
}

/// The header of a row sweep that can collapse, cut to what the studies read.
const HEAD: &str = "run,record,pga_g,status,collapse_time_s,collapse_building,collapse_storey,b1_peak_drift_ratio,b1_residual_drift_ratio,b2_peak_drift_ratio\n";

/// A table of `(record, pga, status, b1 peak, b1 residual, b2 peak)` rows under [`HEAD`]; a
/// collapsed run gets its collapse cells (building 1, storey 1), an empty residual and the limit
/// 0.1 as its peak drift, whatever `rows` says.
fn write(dir: &Path, name: &str, rows: &[(&str, f64, &str, f64, &str, f64)]) -> PathBuf {
    let mut text = String::from(HEAD);
    for (i, &(rec, pga, status, peak, residual, b2)) in rows.iter().enumerate() {
        let line = if status == "collapsed" {
            format!("{i},{rec},{pga},collapsed,3.5,1,1,0.1,,{b2}\n")
        } else {
            format!("{i},{rec},{pga},{status},,,,{peak},{residual},{b2}\n")
        };
        text.push_str(&line);
    }
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// The fitted row of `label` in a fragility's stdout: median and beta.
fn fitted(out: &str, label: &str) -> (f64, f64) {
    let row = out
        .lines()
        .find(|l| l.starts_with(&format!("| {label} |")) && !l.contains("median"))
        .unwrap_or_else(|| panic!("no row {label}: {out}"));
    let c: Vec<&str> = row.split('|').map(str::trim).collect();
    (
        c[2].parse().unwrap_or_else(|_| panic!("{row}")),
        c[3].parse().unwrap_or_else(|_| panic!("{row}")),
    )
}

/// Two levels fitted exactly: 1 of 4 runs collapsed at 0.5 g and 3 of 4 at 2 g (a level at the
/// median, 1 of 2 at 1 g, lies on every curve of median 1). The maximum-likelihood lognormal
/// passes through the shares: median sqrt(0.5 x 2) = 1 g and beta = ln 4 / (2 Phi^-1(0.75)).
/// Failed runs (4 at 2 g: counting them as collapses would give 7 of 8) are left out and counted;
/// the `-o` table holds the counts per level; `--threshold` and `--damage-states` are refused with
/// it, and a table that cannot collapse (no status column, no collapse columns, no rows) too.
#[test]
fn collapse_fragility_is_the_mle_of_the_collapse_counts() {
    let dir = tempdir();
    let d = dir.path();
    let mut rows = Vec::new();
    for (pga, collapsed, n) in [(0.5, 1, 4), (1.0, 1, 2), (2.0, 3, 4)] {
        for r in 0..n {
            let status = if r < collapsed { "collapsed" } else { "ok" };
            rows.push(("rec", pga, status, 0.02, "0.001", 0.01));
        }
    }
    for _ in 0..4 {
        rows.push(("rec", 2.0, "failed", 0.0, "", 0.0));
    }
    let results = write(d, "runs.csv", &rows);
    let want_beta = 4f64.ln() / (2.0 * phi_inv(0.75));
    // The library, to the normal distribution's precision (its erfc is good to 1.2e-7).
    let table = Table::read(&results).unwrap();
    let spec = FragilitySpec::collapse("pga_g", Vec::new());
    let (g, left) = Grouped::read(&table, &spec, None).unwrap();
    assert_eq!((left.failed, left.collapsed, g.runs), (4, 5, 10));
    let f = fit(&g.pooled(&[1])[0]).unwrap();
    assert!((f.median - 1.0).abs() < 1e-6, "{f:?}");
    assert!((f.beta - want_beta).abs() < 1e-6, "{f:?} {want_beta}");
    // The command.
    let o = d.join("collapse.csv");
    let out = ok(&pound(&[
        "fragility",
        &s(&results),
        "--edp",
        "collapsed",
        "-o",
        &s(&o),
    ]));
    assert!(
        out.contains(
            "10 runs at 3 levels of pga_g, 5 collapsed (4 rows left out: 4 failed (status neither ok nor collapsed))"
        ),
        "{out}"
    );
    let (median, beta) = fitted(&out, "collapse");
    assert!(
        (median - 1.0).abs() < 1e-4 && (beta - want_beta).abs() < 1e-4,
        "{out}"
    );
    let t = std::fs::read_to_string(&o).unwrap();
    assert_eq!(
        t,
        "pga_g,runs,collapsed,fraction\n0.5,4,1,0.25\n1,2,1,0.5\n2,4,3,0.75\n"
    );
    // Neither a threshold nor damage states with it.
    for (flag, value) in [
        ("--threshold", "0.1"),
        ("--damage-states", "hazus-c1l-high"),
    ] {
        let e = stderr(&pound(&[
            "fragility",
            &s(&results),
            "--edp",
            "collapsed",
            flag,
            value,
            "-o",
            &s(&d.join("x.csv")),
        ]));
        assert!(
            e.contains(&format!("{flag} makes no sense with --edp collapsed")),
            "{e}"
        );
    }
    // Tables that cannot give a collapse fragility, each named why.
    let text = std::fs::read_to_string(&results).unwrap();
    let cut = |name: &str, f: &dyn Fn(&str) -> String| {
        let p = d.join(name);
        std::fs::write(&p, f(&text)).unwrap();
        p
    };
    let drop_column = |text: &str, k: usize| -> String {
        text.lines()
            .map(|l| {
                let mut c: Vec<&str> = l.split(',').collect();
                c.remove(k);
                c.join(",") + "\n"
            })
            .collect()
    };
    for (name, file, words) in [
        (
            "no status",
            cut("nostatus.csv", &|t| drop_column(t, 3)),
            "has no status column",
        ),
        // No collapse column and no run whose status says `collapsed`: nothing shows a collapse
        // limit (a status `collapsed` would: issue 65, tests/it/table_columns.rs).
        (
            "no collapse columns",
            cut("nocollapse.csv", &|t| {
                drop_column(&drop_column(&drop_column(t, 4), 4), 4).replace(",collapsed,", ",ok,")
            }),
            "no collapse columns (collapse_time_s, collapse_building, collapse_storey, bK_collapsed missing",
        ),
        (
            "no rows",
            cut("norows.csv", &|t| {
                t.lines().next().unwrap().to_string() + "\n"
            }),
            "the table has no rows",
        ),
    ] {
        let o = pound(&[
            "fragility",
            &s(&file),
            "--edp",
            "collapsed",
            "-o",
            &s(&d.join("x.csv")),
        ]);
        assert!(!o.status.success(), "{name}: accepted");
        assert!(stderr(&o).contains(words), "{name}: {}", stderr(&o));
    }
    // No collapse at all: no fit, said so (the table and a notice), the counts still written.
    let none = cut("none.csv", &|t| t.replace(",collapsed,3.5,1,1,", ",ok,,,,"));
    let o = d.join("none-out.csv");
    let run = pound(&["fragility", &s(&none), "--edp", "collapsed", "-o", &s(&o)]);
    let out = ok(&run);
    assert!(
        out.contains("| collapse | no fit: no run collapsed |"),
        "{out}"
    );
    assert!(
        stderr(&run).contains("notice: no run collapsed"),
        "{}",
        stderr(&run)
    );
    assert!(std::fs::read_to_string(&o).unwrap().contains("2,4,0,0\n"));
}

/// A collapsed run exceeds every damage state and threshold, of any demand: FEMA P-58's
/// residual drift states, where a collapsed run's residual is empty (it was left out as "status
/// not ok" before, and would be undecided as a run that did not settle), and a threshold no run
/// that did not collapse reaches. The counts per state and level, and the report, say how many
/// collapsed runs were counted so.
#[test]
fn collapsed_runs_exceed_every_state_and_threshold() {
    let dir = tempdir();
    let d = dir.path();
    let mut rows = Vec::new();
    for (pga, runs) in [
        (0.2, vec!["0.001", "0.003", "0.006", "0.012"]),
        (0.4, vec!["0.004", "0.008", "0.015", "c"]),
        (0.8, vec!["0.009", "c", "c", "f"]),
    ] {
        for (r, cell) in runs.into_iter().enumerate() {
            let rec = ["r1", "r2", "r3", "r4"][r];
            rows.push(match cell {
                "c" => (rec, pga, "collapsed", 0.0, "", 0.004),
                "f" => (rec, pga, "failed", 0.0, "", 0.0),
                v => (rec, pga, "ok", 0.05, v, 0.004),
            });
        }
    }
    let results = write(d, "runs.csv", &rows);
    let o = d.join("ds.csv");
    let out = ok(&pound(&[
        "fragility",
        &s(&results),
        "--edp",
        "b1_residual_drift_ratio",
        "--damage-states",
        "fema-p58-residual",
        "-o",
        &s(&o),
    ]));
    assert!(
        out.contains("11 runs at 3 levels of pga_g, 3 collapsed (counted as exceeding every state: an infinite demand) (1 rows left out: 1 failed"),
        "{out}"
    );
    // No run is undecided: the collapsed ones, with no residual, are decided as exceeding.
    assert!(!out.contains("have no value of"), "{out}");
    let rows = table(&o);
    let at = |state: &str, pga: &str| {
        let r = rows
            .iter()
            .find(|r| r["state"] == state && r["pga_g"] == pga)
            .unwrap_or_else(|| panic!("{state} {pga}"));
        (
            r["runs"].clone(),
            r["exceed"].clone(),
            r["collapsed"].clone(),
            r["undecided"].clone(),
        )
    };
    let q = |a: &str, b: &str, c: &str| (a.to_string(), b.to_string(), c.to_string(), "0".into());
    // DS4 (0.02): no run that stood reaches it; the collapsed ones exceed it.
    assert_eq!(at("DS4", "0.2"), q("4", "0", "0"));
    assert_eq!(at("DS4", "0.4"), q("4", "1", "1"));
    assert_eq!(at("DS4", "0.8"), q("3", "2", "2"));
    // DS2 (0.005): 0.006 and 0.012 at 0.2; 0.008, 0.015 and the collapse at 0.4; all 3 at 0.8.
    assert_eq!(at("DS2", "0.2"), q("4", "2", "0"));
    assert_eq!(at("DS2", "0.4"), q("4", "3", "1"));
    assert_eq!(at("DS2", "0.8"), q("3", "3", "2"));
    // A threshold of another building's drift that only the collapses exceed (their own cells
    // hold 0.004, below it).
    let o = d.join("b2.csv");
    let out = ok(&pound(&[
        "fragility",
        &s(&results),
        "--edp",
        "b2_peak_drift_ratio",
        "--threshold",
        "0.01",
        "-o",
        &s(&o),
    ]));
    assert!(
        out.contains("3 collapsed (counted as exceeding every threshold"),
        "{out}"
    );
    let counts: Vec<(String, String)> = table(&o)
        .iter()
        .map(|r| (r["exceed"].clone(), r["collapsed"].clone()))
        .collect();
    let pairs = |v: &[(&str, &str)]| -> Vec<(String, String)> {
        v.iter()
            .map(|(a, b)| (a.to_string(), b.to_string()))
            .collect()
    };
    assert_eq!(counts, pairs(&[("0", "0"), ("1", "1"), ("2", "2")]));
}

/// IDA with collapses: five records, demand r x IM for record r. At 0.2 g record 5 collapsed (20
/// %, above the 16 % that leaves the 84 % fractile finite); at 0.4 g record 4 collapsed and
/// record 5 did not (resurrection: its curve flatlined at 0.2 g, so it counts as collapsed); at
/// 0.8 g record 1 failed (left out) and 3 of the 4 others collapsed. The fractiles are the type-7
/// quantiles with collapses as infinite demands (`inf`), the table has the curves collapsed and
/// their share per level, and each curve's cells are `inf` from its first collapse up.
#[test]
fn ida_fractiles_take_collapses_as_infinite_demands() {
    let dir = tempdir();
    let d = dir.path();
    let mut rows = Vec::new();
    let recs = ["r1", "r2", "r3", "r4", "r5"];
    for pga in [0.1, 0.2, 0.4, 0.8] {
        for (k, rec) in recs.iter().enumerate() {
            let r = (k + 1) as f64;
            let status = match (pga, k + 1) {
                (0.2, 5) | (0.4, 4) | (0.8, 3) | (0.8, 4) | (0.8, 5) => "collapsed",
                (0.8, 1) => "failed",
                _ => "ok",
            };
            rows.push((*rec, pga, status, r * pga, "", 0.0));
        }
    }
    let results = write(d, "runs.csv", &rows);
    let o = d.join("ida.csv");
    let plot = d.join("ida.svg");
    let run = pound(&[
        "ida",
        &s(&results),
        "--edp",
        "b1_peak_drift_ratio",
        "-o",
        &s(&o),
        "--plot",
        &s(&plot),
    ]);
    let out = ok(&run);
    assert!(
        out.contains("5 curves (by record) at 4 levels of pga_g, 5 runs collapsed"),
        "{out}"
    );
    let said = stderr(&run);
    assert!(
        said.contains("1 runs that did not collapse (structural resurrection)"),
        "{said}"
    );
    let text = std::fs::read_to_string(&o).unwrap();
    let mut lines = text.lines();
    assert_eq!(
        lines.next().unwrap(),
        "pga_g,curves,b1_peak_drift_ratio_p16,b1_peak_drift_ratio_p50,b1_peak_drift_ratio_p84,collapsed,collapsed_fraction,r1,r2,r3,r4,r5"
    );
    let cells: Vec<Vec<String>> = lines
        .map(|l| l.split(',').map(String::from).collect())
        .collect();
    let num = |c: &str| -> f64 { c.parse().unwrap_or_else(|_| panic!("`{c}`")) };
    let close = |c: &str, want: f64| (num(c) - want).abs() < 1e-12;
    // 0.1: no collapse, 1..5 x 0.1.
    assert_eq!(cells[0][1], "5");
    assert!(close(&cells[0][2], 0.164) && close(&cells[0][3], 0.3) && close(&cells[0][4], 0.436));
    assert_eq!(cells[0][5..7], ["0", "0"]);
    // 0.2: [0.2, 0.4, 0.6, 0.8, inf]: p16 at 0.64 of the way from 0.2 to 0.4, p50 0.6, p84
    // between 0.8 and a collapse: infinite.
    assert!(
        close(&cells[1][2], 0.328) && close(&cells[1][3], 0.6),
        "{:?}",
        cells[1]
    );
    assert_eq!(cells[1][4], "inf");
    assert_eq!(cells[1][5..7], ["1", "0.2"]);
    assert_eq!(cells[1][11], "inf");
    // 0.4: [0.4, 0.8, 1.2, inf, inf] (record 5 resurrected, counted as collapsed).
    assert!(
        close(&cells[2][2], 0.656) && close(&cells[2][3], 1.2),
        "{:?}",
        cells[2]
    );
    assert_eq!(cells[2][4], "inf");
    assert_eq!(cells[2][5..7], ["2", "0.4"]);
    assert_eq!(cells[2][10..12], ["inf", "inf"]);
    // 0.8: record 1 failed (no cell); [1.6, inf, inf, inf]: every fractile infinite.
    assert_eq!(cells[3][1], "4");
    assert_eq!(cells[3][2..5], ["inf", "inf", "inf"]);
    assert_eq!(cells[3][5..7], ["3", "0.75"]);
    assert_eq!(cells[3][7], "");
    assert!(close(&cells[3][8], 1.6));
    // The figure has the second panel, of the share collapsed.
    let svg = std::fs::read_to_string(&plot).unwrap();
    assert!(
        svg.contains("Share of the curves collapsed"),
        "no share panel"
    );
    // A collapsed curve is its points and its flatline, one legend entry.
    let entries = |name: &str| svg.lines().filter(|l| l.trim() == name).count();
    for name in ["r2", "r4", "r5", "84 % fractile (collapse from 0.2 g)"] {
        assert_eq!(entries(name), 1, "{name}");
    }
}

/// A yielding 3-storey frame with P-Delta (gravity twice its floors' weight) beside an elastic
/// building, three short synthetic records at six PGAs: most runs at the top collapse.
const FRAME: &str = r#"
[run]
tail_s = 1.0

[[building]]
storeys = 3
storey_height_m = 3.5
mass_kg = 3.0e5
period_s = 0.8
damping_ratio = 0.05
yield_drift_ratio = 0.005
post_yield_ratio = 0.02
p_delta = true
gravity_mass_ratio = 2.0
gap_right_m = [0.02]

[[building]]
storeys = 3
storey_height_m = 3.5
mass_kg = 2.5e5
period_s = 0.3
damping_ratio = 0.05

[contact]
law = "linear"
k_n_per_m = 1e9

[[record]]
synthetic = { seed = 3, duration_s = 5.0, dt_s = 0.01, pga_g = 0.4 }

[[record]]
synthetic = { seed = 4, duration_s = 5.0, dt_s = 0.01, pga_g = 0.4 }

[[record]]
synthetic = { seed = 5, duration_s = 5.0, dt_s = 0.01, pga_g = 0.4 }

[intensity]
pga_g = [0.1, 0.3, 0.6, 1.0, 1.5, 2.0]
warn_scale_factor = 10
"#;

/// End to end: `pound sweep` of the P-Delta frame, then `pound fragility --edp collapsed` (its
/// counts those of the sweep's status column, its fitted median inside the levels) and `pound
/// ida` (each curve `inf` from its first collapse, the share collapsed per level from the same
/// column with the flatline convention).
#[test]
fn a_p_delta_sweep_gives_a_collapse_fragility_and_ida() {
    let dir = tempdir();
    let d = dir.path();
    let cfg = d.join("frame.toml");
    std::fs::write(&cfg, FRAME).unwrap();
    let runs = d.join("runs.csv");
    ok(&pound(&["sweep", &s(&cfg), "-o", &s(&runs)]));
    let sweep = table(&runs);
    assert_eq!(sweep.len(), 18);
    let levels = ["0.1", "0.3", "0.6", "1", "1.5", "2"];
    let collapsed_at = |pga: &str| {
        sweep
            .iter()
            .filter(|r| r["pga_g"] == pga && r["status"] == "collapsed")
            .count()
    };
    let total: usize = levels.iter().map(|l| collapsed_at(l)).sum();
    assert!(
        total >= 3 && collapsed_at("0.1") == 0,
        "the frame should collapse at the top levels only: {total}"
    );
    let f = d.join("collapse.csv");
    let out = ok(&pound(&[
        "fragility",
        &s(&runs),
        "--edp",
        "collapsed",
        "-o",
        &s(&f),
        "--plot",
        &s(&d.join("collapse.svg")),
    ]));
    assert!(
        out.contains(&format!("18 runs at 6 levels of pga_g, {total} collapsed")),
        "{out}"
    );
    for r in table(&f) {
        assert_eq!(r["runs"], "3");
        assert_eq!(
            r["collapsed"],
            collapsed_at(&r["pga_g"]).to_string(),
            "{r:?}"
        );
    }
    let (median, beta) = fitted(&out, "collapse");
    assert!(0.1 < median && median < 2.0 && beta > 0.0, "{out}");
    let i = d.join("ida.csv");
    ok(&pound(&[
        "ida",
        &s(&runs),
        "--edp",
        "b1_peak_drift_ratio",
        "-o",
        &s(&i),
        "--plot",
        &s(&d.join("ida.svg")),
    ]));
    let ida = table(&i);
    // Each curve (record): collapsed from its first collapse up.
    let mut first: std::collections::HashMap<String, usize> = Default::default();
    for (l, pga) in levels.iter().enumerate() {
        for r in sweep
            .iter()
            .filter(|r| r["pga_g"] == *pga && r["status"] == "collapsed")
        {
            first.entry(r["record"].clone()).or_insert(l);
        }
    }
    for (l, row) in ida.iter().enumerate() {
        assert_eq!(row["pga_g"], levels[l]);
        let down = first.values().filter(|&&f| f <= l).count();
        assert_eq!(row["collapsed"], down.to_string(), "{row:?}");
        for (rec, &f) in &first {
            assert_eq!(row[rec] == "inf", f <= l, "{rec} at {}: {row:?}", levels[l]);
        }
    }
}
