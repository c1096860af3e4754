//! What the studies of a table and `pound accuracy` do with runs that collapse (issue 64).
//!
//! `pound plot`: collapsed runs are left out (or drawn apart with `--collapsed mark`), and the
//! figure itself says how many per x value and series; an x value where every run collapsed
//! stays on the axis, marked. A building's column reads that building's `bK_collapsed`, so a
//! run where only its neighbour collapsed is a result for it.
//!
//! `pound accuracy`: a collapse is compared with the reference's (the same building and
//! storey, the time's error relative to the reference's collapse time); one on one side only is
//! named and fails `--target-error`; a point where no run could be compared is refused, with
//! why, and writes nothing. The scene: `configs/accuracy-collapse.toml` (Tabas 1978 at Sa(T1)
//! 0.6, 0.8, 1.0 and 1.25 g: the last two collapse).

use crate::support::{ok, pound, table, tempdir};
use std::path::{Path, PathBuf};

fn shipped(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("configs")
        .join(name)
}

/// A hand-written table: 12 runs at PGA 0.5, 1.0 and 1.5 g, 4 each (records a and b).
/// At 0.5 g nothing collapses. At 1.0 g: run 4 stands; building 1 collapses in runs 5 and 7;
/// in run 6 only building 2 collapses (building 1's drift, 0.05, is a result for it). At
/// 1.5 g building 1 collapses in every run (building 2 stands).
const TABLE: &str = "\
run,record,pga_g,status,peak_force_n,b1_peak_drift_ratio,b1_collapsed,b2_peak_drift_ratio,b2_collapsed
0,a,0.5,ok,1000,0.010,0,0.004,0
1,b,0.5,ok,1100,0.012,0,0.005,0
2,a,0.5,ok,1200,0.011,0,0.006,0
3,b,0.5,ok,1300,0.013,0,0.007,0
4,a,1.0,ok,2000,0.030,0,0.010,0
5,b,1.0,collapsed,2100,0.100,1,0.020,0
6,a,1.0,collapsed,2200,0.050,0,0.100,1
7,b,1.0,collapsed,2300,0.100,1,0.030,0
8,a,1.5,collapsed,3000,0.100,1,0.030,0
9,b,1.5,collapsed,3100,0.100,1,0.031,0
10,a,1.5,collapsed,3200,0.100,1,0.032,0
11,b,1.5,collapsed,3300,0.100,1,0.033,0
";

/// The text of an SVG's `<text>` elements, one after the other (wrapped lines joined by a
/// space), unescaped.
fn svg_text(svg: &str) -> String {
    let mut out = Vec::new();
    for part in svg.split("<text").skip(1) {
        let body = &part[part.find('>').unwrap() + 1..part.find("</text>").unwrap()];
        let body = body
            .trim()
            .replace("&apos;", "'")
            .replace("&quot;", "\"")
            .replace("&lt;", "<")
            .replace("&gt;", ">")
            .replace("&amp;", "&");
        out.push(body);
    }
    out.join(" ")
}

/// The collapse markers of an SVG (`studies::plot`'s crossed square: its sides and both
/// diagonals, each a segment of its own), as their centres.
fn crossed_squares(svg: &str) -> Vec<(i64, i64)> {
    let mut segments = Vec::new();
    for part in svg.split("<polyline").skip(1) {
        let Some(at) = part.find("points=\"") else {
            continue;
        };
        let rest = &part[at + 8..];
        let p: Vec<(i64, i64)> = rest[..rest.find('"').unwrap()]
            .split_whitespace()
            .map(|xy| {
                let (x, y) = xy.split_once(',').unwrap();
                (x.parse().unwrap(), y.parse().unwrap())
            })
            .collect();
        if let [a, b] = p[..] {
            segments.push((a, b));
        }
    }
    let has = |a: (i64, i64), b: (i64, i64)| segments.contains(&(a, b));
    // A side may run on past the corners (by half the stroke's width).
    let side = |y: i64, x0: i64, x1: i64| {
        segments
            .iter()
            .any(|&(a, b)| a.1 == y && b.1 == y && a.0 <= x0 && b.0 >= x1 && x0 - a.0 <= 2)
    };
    segments
        .iter()
        .filter(|&&((x0, y0), (x1, y1))| {
            x1 - x0 == y1 - y0
                && x1 > x0
                && has((x0, y1), (x1, y0))
                && side(y0, x0, x1)
                && side(y1, x0, x1)
                && has((x0, y0), (x0, y1))
                && has((x1, y0), (x1, y1))
        })
        .map(|&((x0, y0), (x1, y1))| ((x0 + x1) / 2, (y0 + y1) / 2))
        .collect()
}

/// `pound plot CSV ARGS -o OUT.svg`: the SVG and stderr.
fn plot(csv: &Path, out: &Path, args: &[&str]) -> (String, String) {
    let mut all = vec!["plot", csv.to_str().unwrap()];
    all.extend_from_slice(args);
    all.extend_from_slice(&["-o", out.to_str().unwrap()]);
    let o = pound(&all);
    let err = String::from_utf8_lossy(&o.stderr).to_string();
    assert!(o.status.success(), "{err}");
    (std::fs::read_to_string(out).unwrap(), err)
}

/// The caption counts the runs left out per x value, for a building's column by that
/// building's own collapse (run 6, where only the neighbour collapsed, is a point of building
/// 1's curve), for any other column by the run's status; the x value where every run
/// collapsed stays on the axis, marked "all 4 collapsed". Before: the stderr line only, and
/// 1.5 g gone from the axis.
#[test]
fn plot_says_how_many_runs_collapsed_at_each_x() {
    let d = tempdir();
    let csv = d.path().join("t.csv");
    std::fs::write(&csv, TABLE).unwrap();
    let svg = d.path().join("p.svg");

    let (drawn, err) = plot(&csv, &svg, &["--x", "pga_g", "--y", "b1_peak_drift_ratio"]);
    let text = svg_text(&drawn);
    for said in [
        "Runs in which building 1 collapsed left out",
        "1 g, 2 of 4; 1.5 g, all 4.",
        "all 4 collapsed",
        "collapsed runs left out",
    ] {
        assert!(text.contains(said), "`{said}` not in the figure: {text}");
    }
    assert!(!text.contains("0.5 g,"), "{text}");
    assert!(
        err.contains("6 rows left out: runs that collapsed"),
        "{err}"
    );
    assert!(crossed_squares(&drawn).is_empty());

    // Building 1's curve: at 1 g the run where only building 2 collapsed is a point (0.05, the
    // max of 0.03 and 0.05); its collapsed runs (0.10) are not; at 1.5 g there is no point.
    let t = pounding::io::table::Table::read(&csv).unwrap();
    let spec = |y: &str, by: Option<&str>| pounding::studies::sensitivity::PlotSpec {
        x: "pga_g".into(),
        y: y.into(),
        by: by.map(String::from),
        filters: vec![],
        aggregate: pounding::studies::sensitivity::Aggregate::Max,
        log_x: false,
        log_y: false,
    };
    let (p, _) =
        pounding::studies::sensitivity::panel(&t, &spec("b1_peak_drift_ratio", None)).unwrap();
    assert_eq!(p.series[0].points, [(0.5, 0.013), (1.0, 0.05)]);

    // Building 2 collapsed in run 6 only: its curve keeps 1.5 g, and nothing is marked.
    let (drawn, _) = plot(&csv, &svg, &["--x", "pga_g", "--y", "b2_peak_drift_ratio"]);
    let text = svg_text(&drawn);
    assert!(
        text.contains("Runs in which building 2 collapsed left out")
            && text.contains("1 g, 1 of 4."),
        "{text}"
    );
    assert!(!text.contains("all 4 collapsed"), "{text}");

    // A run's own column: the status (runs 5, 6, 7 at 1 g).
    let (drawn, _) = plot(&csv, &svg, &["--x", "pga_g", "--y", "peak_force_n"]);
    let text = svg_text(&drawn);
    assert!(
        text.contains("Runs that collapsed left out")
            && text.contains("1 g, 3 of 4; 1.5 g, all 4.")
            && text.contains("all 4 collapsed"),
        "{text}"
    );

    // Per series: each record's counts.
    let (drawn, _) = plot(
        &csv,
        &svg,
        &[
            "--x",
            "pga_g",
            "--y",
            "b1_peak_drift_ratio",
            "--series",
            "record",
        ],
    );
    let text = svg_text(&drawn);
    for said in [
        "of each series' runs at each PGA:",
        "record = a: 1.5 g, all 2.",
        "record = b: 1 g, all 2; 1.5 g, all 2.",
        "all 4 collapsed",
    ] {
        assert!(text.contains(said), "`{said}` not in the figure: {text}");
    }
}

/// A table written before each building's collapse had its columns filled (every
/// `bK_collapsed` 0, the run `collapsed`): a building's column falls back on the run's status.
#[test]
fn plot_reads_the_status_where_no_building_is_marked_collapsed() {
    let d = tempdir();
    let csv = d.path().join("t.csv");
    let unfilled: String = TABLE
        .lines()
        .map(|l| {
            let mut c: Vec<&str> = l.split(',').collect();
            if c[0] != "run" {
                c[6] = "0";
                c[8] = "0";
            }
            c.join(",") + "\n"
        })
        .collect();
    std::fs::write(&csv, unfilled).unwrap();
    let (drawn, _) = plot(
        &csv,
        &d.path().join("p.svg"),
        &["--x", "pga_g", "--y", "b1_peak_drift_ratio"],
    );
    let text = svg_text(&drawn);
    assert!(
        text.contains("Runs that collapsed left out")
            && text.contains("1 g, 3 of 4; 1.5 g, all 4.")
            && text.contains("all 4 collapsed"),
        "{text}"
    );
}

/// `--collapsed mark` draws the collapsed runs' peaks apart, one crossed square per x value
/// where building 1 collapsed (the max of their peaks there: 0.10) and one in the legend, with
/// its entry; a bad value is refused naming the choices.
#[test]
fn plot_marks_collapsed_runs_apart_and_refuses_a_bad_choice() {
    let d = tempdir();
    let csv = d.path().join("t.csv");
    std::fs::write(&csv, TABLE).unwrap();
    let svg = d.path().join("p.svg");
    let args = [
        "--x",
        "pga_g",
        "--y",
        "b1_peak_drift_ratio",
        "--collapsed",
        "mark",
    ];
    let (drawn, err) = plot(&csv, &svg, &args);
    let text = svg_text(&drawn);
    for said in [
        "collapsed: peak before the collapse",
        "Runs in which building 1 collapsed drawn apart",
        "1 g, 2 of 4; 1.5 g, all 4.",
        "all 4 collapsed",
        "collapsed runs marked",
    ] {
        assert!(text.contains(said), "`{said}` not in the figure: {text}");
    }
    let marks = crossed_squares(&drawn);
    assert_eq!(marks.len(), 3, "{marks:?}");
    // The two in the plot stand at one height (both 0.10), the legend's apart.
    let mut ys: Vec<i64> = marks.iter().map(|m| m.1).collect();
    ys.sort();
    assert!(ys[0] == ys[1] || ys[1] == ys[2], "{marks:?}");
    assert!(err.contains("2 collapsed marked"), "{err}");

    let bad = pound(&[
        "plot",
        csv.to_str().unwrap(),
        "--x",
        "pga_g",
        "--y",
        "b1_peak_drift_ratio",
        "--collapsed",
        "hide",
        "-o",
        d.path().join("bad.svg").to_str().unwrap(),
    ]);
    assert!(!bad.status.success());
    let err = String::from_utf8_lossy(&bad.stderr);
    assert!(
        err.contains("'hide'") && err.contains("--collapsed") && err.contains("omit, mark"),
        "{err}"
    );
    assert!(!d.path().join("bad.svg").exists());
}

/// A sweep of the collapse scene, plotted: the two runs that collapse (1.0 and 1.25 g) are
/// counted and their intensities kept on the axis.
#[test]
fn plot_of_a_sweep_keeps_the_intensities_where_it_collapsed() {
    let d = tempdir();
    let csv = d.path().join("s.csv");
    ok(&crate::support::sweep_cpu(
        &shipped("accuracy-collapse.toml"),
        &csv,
        &[],
    ));
    let rows = table(&csv);
    let fell: Vec<&str> = rows
        .iter()
        .filter(|r| r["status"] == "collapsed")
        .map(|r| r["target_sa_g"].as_str())
        .collect();
    assert_eq!(fell, ["1", "1.25"]);
    let (drawn, _) = plot(
        &csv,
        &d.path().join("p.svg"),
        &["--x", "target_sa_g", "--y", "b1_peak_drift_ratio"],
    );
    let text = svg_text(&drawn);
    assert!(text.contains("1 g, all 1; 1.25 g, all 1."), "{text}");
    assert_eq!(text.matches("all 1 collapsed").count(), 2, "{text}");
}

/// `pound accuracy ARGS`: its output (stdout, stderr) and whether it succeeded.
fn accuracy(args: &[&str]) -> (String, String, bool) {
    let mut all = vec!["accuracy"];
    all.extend_from_slice(args);
    all.extend_from_slice(&["--backend", "cpu"]);
    let o = pound(&all);
    (
        String::from_utf8_lossy(&o.stdout).to_string(),
        String::from_utf8_lossy(&o.stderr).to_string(),
        o.status.success(),
    )
}

/// The collapse scene's collapses are compared with the reference's (both runs, the same
/// building and storey, the time within 1e-3 of the reference's), and `--target-error 1e-2`
/// passes: before, the collapsed runs counted as failed and no target could.
#[test]
fn accuracy_compares_collapses_and_a_target_can_pass() {
    let d = tempdir();
    let csv = d.path().join("a.csv");
    let cfg = shipped("accuracy-collapse.toml");
    let (out, err, passed) = accuracy(&[
        cfg.to_str().unwrap(),
        "--target-error",
        "1e-2",
        "-o",
        csv.to_str().unwrap(),
    ]);
    assert!(passed, "{out}\n{err}");
    assert!(
        out.contains("collapses at 8 substeps per contact, cpu-fast-f64: 2 compared with the reference's (both sides, the same building and storey), collapse time error median")
            && out.contains("(relative to the reference's collapse time); 0 differ"),
        "{out}"
    );
    let line = out
        .lines()
        .find(|l| l.starts_with("--target-error 1e-2: 8 substeps per contact, cpu-fast-f64"))
        .unwrap_or_else(|| panic!("{out}"));
    assert!(
        line.contains("and the collapse time")
            && line.contains("2 collapse(s) compared")
            && line.contains("over 4 runs compared, 0 failed (met)"),
        "{line}"
    );
    assert!(!out.contains("NaN"), "{out}");
    let rows = table(&csv);
    let fast = rows.iter().find(|r| r["path"] == "cpu-fast-f64").unwrap();
    assert_eq!(fast["collapses_compared"], "2");
    assert_eq!(fast["collapses_differ"], "0");
    let time: f64 = fast["collapse_time_p99"].parse().unwrap();
    assert!(time > 0.0 && time < 1e-3, "{time}");
    assert_eq!(fast["failed"], "0");
}

/// A collapse on one side only is named (run, record, intensity, building, which side) and
/// fails the target; where no run could be compared, `pound accuracy` says why and writes
/// nothing. The limit is put between the reference's and the fast scheme's peak drift of the
/// 0.8 g run (they differ by about 2e-3 at 8 substeps per contact), so one side reaches it and
/// the other does not.
#[test]
fn a_collapse_on_one_side_only_is_named_and_fails_the_target() {
    let d = tempdir();
    let base = std::fs::read_to_string(shipped("accuracy-collapse.toml")).unwrap();
    let peak = |run: &str, name: &str| -> f64 {
        let cfg = d.path().join(format!("{name}.toml"));
        let text = base
            .replace("sa_g = [0.6, 0.8, 1.0, 1.25]", "sa_g = [0.8]")
            .replace(
                "collapse_drift_ratio = 0.10",
                &format!("collapse_drift_ratio = 0.10\n{run}"),
            );
        std::fs::write(&cfg, text).unwrap();
        let csv = d.path().join(format!("{name}.csv"));
        ok(&crate::support::sweep_cpu(&cfg, &csv, &[]));
        let rows = table(&csv);
        assert_eq!(rows[0]["status"], "ok");
        rows[0]["b1_peak_drift_ratio"].parse().unwrap()
    };
    let truth = peak("scheme = \"reference\"\ntol = 1e-8", "reference");
    let fast = peak("substeps_per_contact = 8", "fast");
    assert!(
        (fast - truth).abs() > 1e-3 * truth,
        "the two peaks, {truth} and {fast}, are too close to put a limit between"
    );
    let limit = 0.5 * (truth + fast);
    let side = if fast > truth {
        "collapsed on cpu-fast-f64 only"
    } else {
        "collapsed in the reference only"
    };
    let scene = |levels: &str| {
        let cfg = d.path().join(format!("mid-{}.toml", levels.len()));
        let text = base
            .replace("sa_g = [0.6, 0.8, 1.0, 1.25]", &format!("sa_g = {levels}"))
            .replace(
                "collapse_drift_ratio = 0.10",
                &format!("collapse_drift_ratio = {limit:e}"),
            );
        std::fs::write(&cfg, text).unwrap();
        cfg
    };
    let csv = d.path().join("a.csv");
    let (out, err, passed) = accuracy(&[
        scene("[0.6, 0.8]").to_str().unwrap(),
        "--target-error",
        "1e-2",
        "-o",
        csv.to_str().unwrap(),
    ]);
    assert!(!passed, "{out}");
    assert!(
        out.contains(&format!(
            "collapse differs at 8 substeps per contact: run 1 (record tabas_1978, Sa(T) 0.8 g), building 1: {side} (storey "
        )),
        "{out}"
    );
    assert!(
        out.contains("NOT met: 1 of 2 runs collapsed otherwise than in the reference"),
        "{out}"
    );
    assert!(err.contains("--target-error not met"), "{err}");
    assert_eq!(table(&csv)[1]["collapses_differ"], "1");

    // The 0.8 g run alone: nothing to compare, refused with why, nothing written.
    let none = d.path().join("none.csv");
    let (out, err, passed) = accuracy(&[
        scene("[0.8]").to_str().unwrap(),
        "--settings",
        "8",
        "-o",
        none.to_str().unwrap(),
    ]);
    assert!(!passed, "{out}");
    assert!(
        err.contains("no run could be compared with the reference")
            && err.contains("8 substeps per contact, cpu-fast-f64: of 1 runs, 0 failed")
            && err.contains("1 collapsed otherwise than in the reference"),
        "{err}"
    );
    assert!(!err.contains("NaN") && !out.contains("NaN"), "{out}\n{err}");
    assert!(!none.exists());
}
