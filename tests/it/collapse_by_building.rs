//! Collapse building by building in the studies (physics.md section 12): `pound fragility --edp
//! bK_collapsed` fits building K's collapse fragility; a building's demand (`bK_...`) is infinite
//! where that building collapsed (its `bK_collapsed`), not where a neighbour did, in fragility
//! counts and IDA curves alike, while a demand of the run (`peak_force_n`) keeps the run's
//! collapse; tables without the per-building columns keep the run's collapse and say so; a fitted
//! median outside the levels run is flagged as extrapolated. Tables written by hand give the
//! exact counts.

use crate::support::cli::{stderr, write};
use crate::support::{ok, pound, table, tempdir};
use pounding::io::table::Table;
use pounding::plan::sample::phi_inv;
use pounding::studies::fragility::{self, FragilityOptions};
use pounding::studies::ida::{self, IdaOptions};
use std::path::Path;

fn s(p: &Path) -> String {
    p.to_str().unwrap().to_string()
}

/// A row sweep's columns with a collapse limit, cut to what the studies read: the run's collapse
/// columns and each building's.
const HEAD: &str = "run,record,pga_g,status,peak_force_n,collapse_time_s,collapse_building,collapse_storey,b1_peak_drift_ratio,b1_collapsed,b1_collapse_time_s,b1_collapse_storey,b2_peak_drift_ratio,b2_collapsed,b2_collapse_time_s,b2_collapse_storey\n";

/// One run: its record and intensity, each building's peak drift and whether it collapsed
/// (building 1 at 3 s, building 2 at 2 s, each in its first storey), and `failed`.
#[derive(Clone, Copy)]
struct Run {
    record: &'static str,
    pga: f64,
    b1: (f64, bool),
    b2: (f64, bool),
    failed: bool,
}

fn run(record: &'static str, pga: f64, b1: (f64, bool), b2: (f64, bool)) -> Run {
    Run {
        record,
        pga,
        b1,
        b2,
        failed: false,
    }
}

/// The table of `runs` under [`HEAD`]: status `collapsed` where any building collapsed, the run's
/// collapse columns at its first collapse, a peak force of 1e5 N.
fn text(runs: &[Run]) -> String {
    let mut t = String::from(HEAD);
    for (i, r) in runs.iter().enumerate() {
        let status = if r.failed {
            "failed"
        } else if r.b1.1 || r.b2.1 {
            "collapsed"
        } else {
            "ok"
        };
        // The first collapse: building 2's (at 2 s) where both collapsed.
        let first = match (r.b1.1, r.b2.1) {
            (_, true) => "2,2,1",
            (true, false) => "3,1,1",
            _ => ",,",
        };
        let building = |(drift, collapsed): (f64, bool), at: &str| {
            if collapsed {
                format!("{drift},1,{at},1")
            } else {
                format!("{drift},0,,")
            }
        };
        t.push_str(&format!(
            "{i},{},{},{status},100000,{first},{},{}\n",
            r.record,
            r.pga,
            building(r.b1, "3"),
            building(r.b2, "2")
        ));
    }
    t
}

/// `text` with the columns named by `keep` only (as `--columns` or an older sweep writes it).
fn keep_columns(text: &str, keep: &dyn Fn(&str) -> bool) -> String {
    let mut lines = text.lines();
    let head: Vec<&str> = lines.next().unwrap().split(',').collect();
    let kept: Vec<usize> = (0..head.len()).filter(|&k| keep(head[k])).collect();
    let pick = |l: &str| {
        let c: Vec<&str> = l.split(',').collect();
        kept.iter().map(|&k| c[k]).collect::<Vec<_>>().join(",") + "\n"
    };
    std::iter::once(pick(&head.join(",")))
        .chain(lines.map(pick))
        .collect()
}

/// An output from before each building's collapse was written: no `bK_collapse...` columns.
fn older(text: &str) -> String {
    keep_columns(text, &|c| !(c.starts_with('b') && c.contains("_collapse")))
}

/// Building 1 collapses in 1 of 4 runs at 0.5 g, 1 of 2 at 1 g and 3 of 4 at 2 g (the fit of
/// `collapse_studies`: median 1 g); building 2 in 1 of 4, 1 of 2 and 2 of 4, mostly in runs
/// where building 1 stood; one run at 2 g failed. Building 1's drift is 0.001 where it
/// collapsed (a collapse counts whatever the cell holds) and, where only building 2 collapsed,
/// 0.005 at 0.5 g, 0.02 at 1 g and 0.008 at 2 g.
fn ladder() -> Vec<Run> {
    let (c, up) = ((0.001, true), |d: f64| (d, false));
    let mut runs = vec![
        run("r", 0.5, c, up(0.001)),
        run("r", 0.5, up(0.005), (0.1, true)),
        run("r", 0.5, up(0.002), up(0.001)),
        run("r", 0.5, up(0.003), up(0.001)),
        run("r", 1.0, c, up(0.001)),
        run("r", 1.0, up(0.02), (0.1, true)),
        run("r", 2.0, c, up(0.001)),
        run("r", 2.0, c, up(0.001)),
        run("r", 2.0, c, (0.1, true)),
        run("r", 2.0, up(0.008), (0.1, true)),
    ];
    runs.push(Run {
        failed: true,
        ..run("r", 2.0, up(0.0), up(0.0))
    });
    runs
}

fn study(path: &Path, edp: &str, thresholds: &[f64]) -> pounding::studies::report::StudyReport {
    fragility::study(
        &Table::read(path).unwrap(),
        &FragilityOptions {
            im: Some("pga_g".into()),
            edp: edp.into(),
            thresholds: thresholds.to_vec(),
            ..FragilityOptions::default()
        },
    )
    .unwrap_or_else(|e| panic!("{edp}: {e}"))
}

/// The fitted median and beta of `label`'s row in a fragility's summary.
fn fitted(said: &str, label: &str) -> (f64, f64) {
    let row = said
        .lines()
        .find(|l| l.starts_with(&format!("| {label} |")) && !l.contains("median"))
        .unwrap_or_else(|| panic!("no row {label}: {said}"));
    let c: Vec<&str> = row.split('|').map(str::trim).collect();
    (c[2].parse().unwrap(), c[3].parse().unwrap())
}

/// `--edp b1_collapsed` counts building 1's collapses alone (the maximum-likelihood curve through
/// its shares: median 1 g), `--edp b2_collapsed` building 2's, `--edp collapsed` the run's (any
/// building); a threshold with a building's collapse is refused as with the run's.
#[test]
fn each_building_has_its_own_collapse_fragility() {
    let dir = tempdir();
    let d = dir.path();
    let results = write(d, "runs.csv", &text(&ladder()));
    let r = study(&results, "b1_collapsed", &[]);
    assert_eq!(
        r.csv,
        "pga_g,runs,collapsed,fraction\n0.5,4,1,0.25\n1,2,1,0.5\n2,4,3,0.75\n"
    );
    assert!(
        r.said.starts_with(
            "10 runs at 3 levels of pga_g, 5 where building 1 collapsed (1 rows left out: 1 failed"
        ),
        "{}",
        r.said
    );
    assert!(
        r.said
            .contains("| P(building 1 collapses) | median pga_g |"),
        "{}",
        r.said
    );
    let (median, beta) = fitted(&r.said, "collapse");
    let want_beta = 4f64.ln() / (2.0 * phi_inv(0.75));
    assert!(
        (median - 1.0).abs() < 1e-4 && (beta - want_beta).abs() < 1e-4,
        "{}",
        r.said
    );
    assert_eq!(r.panels[0].title, "P(building 1 collapses) against PGA");
    assert_eq!(
        study(&results, "b2_collapsed", &[]).csv,
        "pga_g,runs,collapsed,fraction\n0.5,4,1,0.25\n1,2,1,0.5\n2,4,2,0.5\n"
    );
    assert_eq!(
        study(&results, "collapsed", &[]).csv,
        "pga_g,runs,collapsed,fraction\n0.5,4,2,0.5\n1,2,2,1\n2,4,4,1\n"
    );
    // The command: the counts written, a threshold refused.
    let o = d.join("b2.csv");
    ok(&pound(&[
        "fragility",
        &s(&results),
        "--edp",
        "b2_collapsed",
        "-o",
        &s(&o),
    ]));
    assert_eq!(table(&o)[2]["collapsed"], "2");
    let e = stderr(&pound(&[
        "fragility",
        &s(&results),
        "--edp",
        "b1_collapsed",
        "--threshold",
        "0.5",
        "-o",
        &s(&d.join("x.csv")),
    ]));
    assert!(
        e.contains("--threshold makes no sense with --edp b1_collapsed"),
        "{e}"
    );
}

/// The exceedances of a threshold per level, as `-o` writes them: (runs, exceed, collapsed).
fn counts(csv: &str) -> Vec<(String, String, String)> {
    let mut lines = csv.lines();
    let head: Vec<&str> = lines.next().unwrap().split(',').collect();
    let at = |n: &str| head.iter().position(|h| *h == n).unwrap();
    lines
        .map(|l| {
            let c: Vec<&str> = l.split(',').collect();
            (
                c[at("runs")].to_string(),
                c[at("exceed")].to_string(),
                c[at("collapsed")].to_string(),
            )
        })
        .collect()
}

fn triples(v: &[(u32, u32, u32)]) -> Vec<(String, String, String)> {
    v.iter()
        .map(|(a, b, c)| (a.to_string(), b.to_string(), c.to_string()))
        .collect()
}

/// Building 1's drift above 0.01: its own collapses exceed whatever their cells hold (0.001), a
/// run where only building 2 collapsed is building 1's drift as measured (0.005 and 0.008 below,
/// 0.02 above); building 2's drift the other way round; the peak force, a demand of the run,
/// exceeds wherever any building collapsed.
#[test]
fn a_neighbours_collapse_leaves_a_buildings_demand_as_measured() {
    let dir = tempdir();
    let results = write(dir.path(), "runs.csv", &text(&ladder()));
    let r = study(&results, "b1_peak_drift_ratio", &[0.01]);
    assert_eq!(
        counts(&r.csv),
        triples(&[(4, 1, 1), (2, 2, 1), (4, 3, 3)]),
        "{}",
        r.csv
    );
    assert!(
        r.said.starts_with("10 runs at 3 levels of pga_g, 5 where building 1 collapsed (counted as exceeding every threshold"),
        "{}",
        r.said
    );
    assert!(
        r.notices.iter().all(|n| !n.contains("as the run")),
        "{:?}",
        r.notices
    );
    let r = study(&results, "b2_peak_drift_ratio", &[0.01]);
    assert_eq!(counts(&r.csv), triples(&[(4, 1, 1), (2, 1, 1), (4, 2, 2)]));
    let r = study(&results, "peak_force_n", &[1e6]);
    assert_eq!(counts(&r.csv), triples(&[(4, 2, 2), (2, 2, 2), (4, 4, 4)]));
    assert!(
        r.said
            .starts_with("10 runs at 3 levels of pga_g, 8 collapsed (counted"),
        "{}",
        r.said
    );
}

/// A table with no `bK_collapsed` (an older output) keeps the run's collapse for a building's
/// demand, and a notice says so; so does one whose `bK_collapsed` are all 0 in a collapsed run
/// (written unfilled). A demand of the run needs no notice.
#[test]
fn tables_that_do_not_say_which_building_collapsed_keep_the_runs_collapse() {
    let dir = tempdir();
    let d = dir.path();
    let full = text(&ladder());
    let old = write(d, "old.csv", &older(&full));
    let r = study(&old, "b1_peak_drift_ratio", &[0.01]);
    assert_eq!(counts(&r.csv), triples(&[(4, 2, 2), (2, 2, 2), (4, 4, 4)]));
    assert!(
        r.notices.iter().any(|n| n.starts_with(
            "notice: 8 collapsed runs (status `collapsed`) are counted as collapsed for b1_peak_drift_ratio, as the run, not building 1 alone: this table has no column b1_collapsed"
        )),
        "{:?}",
        r.notices
    );
    assert!(study(&old, "peak_force_n", &[1e6]).notices.is_empty());
    // The command tells it on stderr.
    let o = pound(&[
        "fragility",
        &s(&old),
        "--edp",
        "b1_peak_drift_ratio",
        "--threshold",
        "0.01",
        "-o",
        &s(&d.join("x.csv")),
    ]);
    assert!(
        o.status.success() && stderr(&o).contains("no column b1_collapsed"),
        "{}",
        stderr(&o)
    );
    // Unfilled: every building's flag 0 where the status says collapsed.
    let mut unfilled = String::new();
    for (i, l) in full.lines().enumerate() {
        let mut c: Vec<String> = l.split(',').map(String::from).collect();
        if i > 0 {
            for k in [9, 13] {
                c[k] = "0".into();
            }
        }
        unfilled.push_str(&(c.join(",") + "\n"));
    }
    let unfilled = write(d, "unfilled.csv", &unfilled);
    let r = study(&unfilled, "b1_peak_drift_ratio", &[0.01]);
    assert_eq!(counts(&r.csv), triples(&[(4, 2, 2), (2, 2, 2), (4, 4, 4)]));
    assert!(
        r.notices.iter().any(|n| n.contains("8 collapsed runs")
            && n.contains("every bJ_collapsed of this table is 0")),
        "{:?}",
        r.notices
    );
}

/// Tables that cannot give a collapse fragility name the columns they lack: one written with
/// `--columns` that left every collapse column out (its status naming the runs that collapsed,
/// or none), one that left out building 1's but kept
/// building 2's, an older one with the run's columns only; a building's column alone is
/// enough for the run's collapse fragility (the status is what it counts).
#[test]
fn missing_collapse_columns_are_named() {
    let dir = tempdir();
    let d = dir.path();
    let full = text(&ladder());
    let refused = |name: &str, text: &str, edp: &str| -> String {
        let p = write(d, name, text);
        let o = pound(&[
            "fragility",
            &s(&p),
            "--edp",
            edp,
            "-o",
            &s(&d.join("x.csv")),
        ]);
        assert!(!o.status.success(), "{name} {edp}: accepted");
        stderr(&o)
    };
    let bare = keep_columns(&full, &|c| !c.contains("collapse"));
    // Its status still says which runs collapsed: the run's collapse fragility is counted from
    // it (issue 65), and building 1's names the column missing, not a sweep without collapses.
    let e = refused("bare.csv", &bare, "b1_collapsed");
    assert!(
        e.contains("rows have status `collapsed`, but this table has no column b1_collapsed (nor any collapse column): it was written with --columns that left them out"),
        "{e}"
    );
    // With no run collapsed either, nothing tells a sweep without a collapse limit from one
    // written with --columns that left the columns out: both are named.
    let never = bare.replace(",collapsed,", ",ok,");
    let e = refused("never.csv", &never, "collapsed");
    assert!(
        e.contains("no collapse columns (collapse_time_s, collapse_building, collapse_storey, bK_collapsed missing")
            && e.contains("--columns that left them out")
            && !e.contains("its runs could not collapse"),
        "{e}"
    );
    let e = refused("never.csv", &never, "b1_collapsed");
    assert!(
        e.contains("no collapse columns (b1_collapsed, collapse_time_s, collapse_building, collapse_storey missing"),
        "{e}"
    );
    let no_b1 = keep_columns(&full, &|c| c != "b1_collapsed");
    let e = refused("nob1.csv", &no_b1, "b1_collapsed");
    assert!(
        e.contains(
            "--edp b1_collapsed: this table has no column b1_collapsed (it has b2_collapsed)"
        ),
        "{e}"
    );
    let e = refused("old.csv", &older(&full), "b2_collapsed");
    assert!(
        e.contains("has the run's collapse columns (collapse_time_s, collapse_building, collapse_storey) but no building's"),
        "{e}"
    );
    // A flag that is neither 0 nor 1 is named with its line; booleans (a table handed to the
    // Python package) read as 0 and 1.
    let flags = |first: &str, second: &str| {
        let mut t = String::from("status,pga_g,b1_peak_drift_ratio,b1_collapsed\n");
        t.push_str(&format!("collapsed,1,0.1,{first}\nok,1,0.001,{second}\n"));
        t
    };
    let e = fragility::study(
        &Table::read(&write(d, "two.csv", &flags("1", "2"))).unwrap(),
        &FragilityOptions {
            im: Some("pga_g".into()),
            edp: "b1_collapsed".into(),
            ..FragilityOptions::default()
        },
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.ends_with("two.csv: line 3, column `b1_collapsed`: `2` is not 0 or 1 (whether the building collapsed)"),
        "{e}"
    );
    let r = study(
        &write(d, "bools.csv", &flags("true", "false")),
        "b1_collapsed",
        &[],
    );
    assert_eq!(r.csv, "pga_g,runs,collapsed,fraction\n1,2,1,0.5\n");
    // The run's collapse fragility from a table with building 1's flag as its only collapse column.
    let only_b1 = keep_columns(&full, &|c| !c.contains("collapse") || c == "b1_collapsed");
    let r = study(&write(d, "onlyb1.csv", &only_b1), "collapsed", &[]);
    assert_eq!(
        r.csv,
        "pga_g,runs,collapsed,fraction\n0.5,4,2,0.5\n1,2,2,1\n2,4,4,1\n"
    );
}

/// Three curves: `a` where building 2 collapsed at 1 and 2 g (building 1 stood), `b` where
/// building 1 collapsed at 1 g and both at 2 g, `c` standing. Building 1's curves flatline at
/// building 1's collapses only (`a` keeps its drifts), building 2's at building 2's (`b` at 1 g is
/// its drift), the peak force's at any; the share collapsed per level follows.
#[test]
fn ida_curves_flatline_at_their_own_buildings_collapse() {
    let dir = tempdir();
    let d = dir.path();
    let (c, up) = ((0.1, true), |x: f64| (x, false));
    let runs = [
        run("a", 0.5, up(0.002), up(0.003)),
        run("a", 1.0, up(0.004), c),
        run("a", 2.0, up(0.006), c),
        run("b", 0.5, up(0.001), up(0.002)),
        run("b", 1.0, c, up(0.005)),
        run("b", 2.0, c, c),
        run("c", 0.5, up(0.001), up(0.001)),
        run("c", 1.0, up(0.002), up(0.002)),
        run("c", 2.0, up(0.003), up(0.003)),
    ];
    let path = write(d, "runs.csv", &text(&runs));
    let t = Table::read(&path).unwrap();
    let read = |edp: &str| {
        let o = IdaOptions {
            im: Some("pga_g".into()),
            ..IdaOptions::new(edp)
        };
        ida::study(&t, &o).unwrap_or_else(|e| panic!("{edp}: {e}"))
    };
    let inf = f64::INFINITY;
    let curves = |csv: &str| -> (Vec<String>, Vec<Vec<f64>>) {
        let mut lines = csv.lines();
        let head: Vec<&str> = lines.next().unwrap().split(',').collect();
        let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
        let col = |n: &str| head.iter().position(|h| *h == n).unwrap();
        let collapsed = rows
            .iter()
            .map(|r| r[col("collapsed")].to_string())
            .collect();
        let per = ["a", "b", "c"]
            .iter()
            .map(|n| rows.iter().map(|r| r[col(n)].parse().unwrap()).collect())
            .collect();
        (collapsed, per)
    };
    let b1 = read("b1_peak_drift_ratio");
    let (collapsed, per) = curves(&b1.csv);
    assert_eq!(per[0], vec![0.002, 0.004, 0.006], "{}", b1.csv);
    assert_eq!(per[1], vec![0.001, inf, inf]);
    assert_eq!(per[2], vec![0.001, 0.002, 0.003]);
    assert_eq!(collapsed, ["0", "1", "1"]);
    assert!(
        b1.said.starts_with(
            "3 curves (by record) at 3 levels of pga_g, 2 runs where building 1 collapsed"
        ),
        "{}",
        b1.said
    );
    assert_eq!(
        b1.panels[1].title,
        "Share of the curves where building 1 collapsed against PGA"
    );
    assert_eq!(
        b1.panels[1].series[0].points,
        vec![(0.5, 0.0), (1.0, 1.0 / 3.0), (2.0, 1.0 / 3.0)]
    );
    let b2 = read("b2_peak_drift_ratio");
    let (collapsed, per) = curves(&b2.csv);
    assert_eq!(per[0], vec![0.003, inf, inf]);
    assert_eq!(per[1], vec![0.002, 0.005, inf]);
    assert_eq!(collapsed, ["0", "1", "2"]);
    let force = read("peak_force_n");
    let (collapsed, per) = curves(&force.csv);
    assert_eq!(per[0], vec![1e5, inf, inf]);
    assert_eq!(per[1], vec![1e5, inf, inf]);
    assert_eq!(collapsed, ["0", "2", "2"]);
    assert_eq!(
        force.panels[1].title,
        "Share of the curves collapsed against PGA"
    );
    // The command writes the same; an older table flatlines at the run's collapse, with a notice.
    let o = d.join("ida.csv");
    ok(&pound(&[
        "ida",
        &s(&path),
        "--im",
        "pga_g",
        "--edp",
        "b1_peak_drift_ratio",
        "-o",
        &s(&o),
    ]));
    assert_eq!(std::fs::read_to_string(&o).unwrap(), b1.csv);
    let old = write(d, "old.csv", &older(&text(&runs)));
    let run = pound(&[
        "ida",
        &s(&old),
        "--im",
        "pga_g",
        "--edp",
        "b1_peak_drift_ratio",
        "-o",
        &s(&d.join("old-ida.csv")),
    ]);
    ok(&run);
    let (collapsed, per) = curves(&std::fs::read_to_string(d.join("old-ida.csv")).unwrap());
    assert_eq!(per[0], vec![0.002, inf, inf]);
    assert_eq!(collapsed, ["0", "2", "2"]);
    assert!(
        stderr(&run).contains("no column b1_collapsed"),
        "{}",
        stderr(&run)
    );
    // A building's collapse flag is no demand of an IDA.
    let e = stderr(&pound(&[
        "ida",
        &s(&path),
        "--edp",
        "b1_collapsed",
        "-o",
        &s(&d.join("x.csv")),
    ]));
    assert!(e.contains("pound fragility --edp b1_collapsed"), "{e}");
}

/// Building 1's collapses in `counts` of 100 runs at each of `levels`.
fn shares(levels: &[f64], counts: &[usize]) -> String {
    let mut runs = Vec::new();
    for (&pga, &k) in levels.iter().zip(counts) {
        for i in 0..100 {
            runs.push(run("r", pga, (0.001, i < k), (0.001, false)));
        }
    }
    text(&runs)
}

/// A fitted median above the highest level run (shares of a median-4 g curve on a ladder that
/// ends at 3 g) or below the lowest is flagged as extrapolated, in the study's notices and on
/// stderr, for a collapse fragility and a threshold's alike; one inside the levels is not.
#[test]
fn a_median_beyond_the_levels_is_flagged_as_extrapolated() {
    let dir = tempdir();
    let d = dir.path();
    let high = write(d, "high.csv", &shares(&[1.0, 2.0, 3.0], &[0, 8, 28]));
    let r = study(&high, "b1_collapsed", &[]);
    let (median, _) = fitted(&r.said, "collapse");
    assert!(median > 3.0, "{}", r.said);
    let q = pounding::io::table::quantity("pga_g", median);
    let want = format!(
        "notice: the fitted median of P(building 1 collapses) is {q} from a ladder of pga_g that ends at 3 g: extrapolated"
    );
    assert!(
        r.notices.iter().any(|n| n.starts_with(&want)),
        "{want}\n{:?}",
        r.notices
    );
    let o = pound(&[
        "fragility",
        &s(&high),
        "--edp",
        "b1_collapsed",
        "-o",
        &s(&d.join("x.csv")),
    ]);
    assert!(stderr(&o).contains(&want), "{}", stderr(&o));
    // A threshold's fit: the same runs exceed 0.01 of building 1's drift (their collapses).
    let r = study(&high, "b1_peak_drift_ratio", &[0.01]);
    assert!(
        r.notices.iter().any(|n| n
            .starts_with("notice: the fitted median of b1_peak_drift_ratio > 0.01 is ")
            && n.contains("ends at 3 g: extrapolated")),
        "{:?}",
        r.notices
    );
    let low = write(d, "low.csv", &shares(&[1.0, 2.0, 3.0], &[60, 85, 95]));
    let r = study(&low, "b1_collapsed", &[]);
    assert!(fitted(&r.said, "collapse").0 < 1.0, "{}", r.said);
    assert!(
        r.notices
            .iter()
            .any(|n| n.contains("from a ladder of pga_g that starts at 1 g: extrapolated")),
        "{:?}",
        r.notices
    );
    let inside = write(d, "inside.csv", &text(&ladder()));
    let r = study(&inside, "b1_collapsed", &[]);
    assert!(
        r.notices.iter().all(|n| !n.contains("extrapolated")),
        "{:?}",
        r.notices
    );
}
