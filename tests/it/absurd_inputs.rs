//! No silent physics: a very stiff building is solved, failed runs are kept out of plots and
//! summaries, physically absurd inputs are warned about, and what a record's header states cannot
//! be contradicted.

use crate::scenes::{row, Scene, CHEAP_SWEEP, STOREYS2, STOREYS3};
use crate::support::cli::stderr as err;
use crate::support::cli::{fails_with, s, stderr, sweep, warns, write};
use crate::support::{ok, pound, tempdir};
use std::path::Path;

/// Class 7: a very stiff building is solved (not `non_finite`), failed runs are kept out of
/// plots and summaries, and absurd inputs are warned about.
#[test]
fn stiff_structures_failed_runs_and_absurd_inputs() {
    let sc = Scene::new();
    let stiff = sc.path("stiff.toml");
    std::fs::write(
        &stiff,
        CHEAP_SWEEP
            .replace("period_s = [0.3, 0.6]", "period_s = 1e-4")
            .replace("period_s = [0.45, 1.0]", "period_s = 0.5")
            .replace(
                "law = [\"nonlinear_viscoelastic\", \"kelvin_voigt\"]",
                "law = \"nonlinear_viscoelastic\"",
            )
            .replace("e = [0.5, 0.8]", "e = 0.5")
            .replace("gap_m = [0.0, 0.01, 0.03]", "gap_m = 0.0")
            .replace("duration_s = 3.0", "duration_s = 1.0"),
    )
    .unwrap();
    let (fast, refr) = (sc.path("fast.csv"), sc.path("ref.csv"));
    ok(&sweep(&stiff, &fast, &[]));
    ok(&sweep(&stiff, &refr, &["--scheme", "reference"]));
    let read = |p: &Path| -> Vec<(String, f64, f64)> {
        let mut r = csv::Reader::from_path(p).unwrap();
        let h = r.headers().unwrap().clone();
        let c = |n: &str| h.iter().position(|x| x == n).unwrap();
        r.records()
            .map(|x| {
                let x = x.unwrap();
                (
                    x[c("status")].to_string(),
                    x[c("peak_force_n")].parse().unwrap(),
                    x[c("peak_u2_m")].parse().unwrap(),
                )
            })
            .collect()
    };
    let (a, b) = (read(&fast), read(&refr));
    assert_eq!(a.len(), 2);
    for (x, y) in a.iter().zip(&b) {
        assert_eq!(x.0, "ok");
        assert!(x.1 > 0.0, "it pounds");
        assert!(crate::support::rel(x.1, y.1) < 1e-4, "{x:?} vs {y:?}");
        assert!(crate::support::rel(x.2, y.2) < 1e-4, "{x:?} vs {y:?}");
    }
    // Plots leave failed runs out (their values are whatever a diverged run held).
    let mut text = sc.whole.clone();
    let row = text.lines().nth(1).unwrap().to_string();
    let bad_row = row.replacen(",ok,", ",non_finite,", 1);
    let cells: Vec<&str> = bad_row.split(',').collect();
    let force = pounding::plan::columns::header()
        .iter()
        .position(|c| *c == "peak_force_n")
        .unwrap();
    let mut cells: Vec<String> = cells.iter().map(|c| c.to_string()).collect();
    cells[force] = "1e205".into();
    text = text.replacen(&row, &cells.join(","), 1);
    let t = sc.path("t.csv");
    std::fs::write(&t, text).unwrap();
    let table = pounding::io::table::Table::read(&t).unwrap();
    let spec = pounding::studies::sensitivity::PlotSpec {
        x: "gap_m".into(),
        y: "peak_force_n".into(),
        by: None,
        filters: vec![],
        aggregate: pounding::studies::sensitivity::Aggregate::Max,
        log_x: false,
        log_y: false,
    };
    let (panel, left_out) = pounding::studies::sensitivity::panel(&table, &spec).unwrap();
    assert_eq!(left_out.failed, 1);
    let top = panel.series[0]
        .points
        .iter()
        .map(|p| p.1)
        .fold(0.0, f64::max);
    assert!(top < 1e10, "{top}");
    // A group with no ok run has empty statistics, not zeros.
    let plan =
        pounding::plan::config::parse(CHEAP_SWEEP, &sc.cfg, sc.dir.path(), sc.dir.path()).unwrap();
    let mut agg = pounding::engine::aggregate::Aggregator::new(&["gap_m".into()], &[]).unwrap();
    let spec0 = plan.run(0);
    let g = agg.group_of(&plan, &spec0);
    agg.add(
        g,
        &pounding::physics::model::RunOutput {
            status: pounding::physics::model::Status::NonFinite,
            peak_force: 1e205,
            ..Default::default()
        },
    );
    let csv = pounding::io::summary::csv(&agg);
    let row: Vec<&str> = csv.lines().nth(1).unwrap().split(',').collect();
    assert_eq!(&row[..3], &["0", "1", "1"], "{csv}");
    assert!(row[3..].iter().all(|c| c.is_empty()), "{csv}");
    // A record of 1e6 g: a warning on the PGA and on drifts above the buildings' height.
    let g = sc.path("g.toml");
    std::fs::write(
        &g,
        CHEAP_SWEEP.replace("duration_s = 3.0", "duration_s = 3.0, pga_g = 1e6"),
    )
    .unwrap();
    let r = sweep(&g, &sc.path("g.csv"), &[]);
    let err = stderr(&r);
    ok(&r);
    assert!(
        err.contains("warning") && err.contains("PGA of 1000000.000 g"),
        "{err}"
    );
    assert!(
        err.contains("exceeds its height (estimated from its period"),
        "{err}"
    );
    assert!(!stderr(&sweep(&sc.cfg, &sc.path("q.csv"), &[])).contains("warning"));
}

/// Class 3: what a file's header states cannot be contradicted; rows get the pair's absurd-
/// input warnings with their real height; a pair with no shared floor level is said before
/// any run; NaN is never "not exceeding"; a BOM or a typo never shortens a record silently.
#[test]
fn no_silent_physics() {
    let d = tempdir();
    // An AT2 whose header says g, read with units = cm/s2: refused, as a contradicting dt is.
    let values: Vec<String> = (0..200)
        .map(|i| format!("{:.6}", 0.3 * (i as f64 * 0.2).sin()))
        .collect();
    let at2 = format!(
        "PEER NGA STRONG MOTION DATABASE RECORD\nTest\nACCELERATION TIME SERIES IN UNITS OF G\nNPTS=  200, DT= .0100 SEC\n{}\n",
        values.join("\n")
    );
    write(d.path(), "rec.AT2", &at2);
    let pair = |units: &str| {
        format!(
            "[building1]\nmass_kg = 1e5\nperiod_s = 0.5\ndamping_ratio = 0.05\n[building2]\nmass_kg = 1e5\nperiod_s = 0.3\ndamping_ratio = 0.05\n[contact]\nlaw = \"linear\"\nk_n_per_m = 1e9\ngap_m = 0.01\n[[record]]\npath = \"rec.AT2\"\n{units}\n"
        )
    };
    let bad = write(d.path(), "units.toml", &pair("units = \"cm/s2\""));
    let o = d.path().join("o.csv");
    fails_with(
        &sweep(&bad, &o, &[]),
        "header says its values are in g but units = cm/s2 was given",
    );
    ok(&sweep(
        &write(d.path(), "g.toml", &pair("units = \"g\"")),
        &o,
        &[],
    ));
    // Rows: PGA above 5 g, and displacements above the building's real height.
    let hot = write(
        d.path(),
        "hot.toml",
        &row(STOREYS3, STOREYS3, "").replace("pga_g = 0.35", "pga_g = 6.0"),
    );
    warns(&sweep(&hot, &d.path().join("hot.csv"), &[]), "above 5 g");
    // Without a collapse limit (with one, each building collapses at 10 % of its 3 nm and
    // stands there: its peaks end at the limit).
    let flat = write(
        d.path(),
        "flat.toml",
        &row(
            &STOREYS3.replace("storey_height_m = 3.0", "storey_height_m = 1e-9"),
            &STOREYS3.replace("storey_height_m = 3.0", "storey_height_m = 1e-9"),
            "",
        )
        .replace(
            "tail_s = 0.5",
            "tail_s = 0.5\ncollapse_drift_ratio = \"none\"",
        ),
    );
    warns(
        &sweep(&flat, &d.path().join("flat.csv"), &[]),
        "exceeds its height",
    );
    // Neighbours that share no floor level pound floor against column (issue 50); with that
    // turned off they never touch: said before any run, refused by the gap study.
    let offset = STOREYS2.replace("storey_height_m = 3.0", "storey_height_m = 3.2");
    let struck = write(d.path(), "struck.toml", &row(STOREYS3, &offset, ""));
    let o = sweep(&struck, &d.path().join("struck.csv"), &[]);
    assert!(o.status.success() && !err(&o).contains("share no floor level"));
    let header = std::fs::read_to_string(d.path().join("struck.csv")).unwrap();
    assert!(
        header.contains("level_b1c2_b2f1_column_shear_n"),
        "{header}"
    );
    let apart = write(
        d.path(),
        "apart.toml",
        // One gap: a list would repeat each run (refused, `idle_axes`).
        &row(STOREYS3, &offset, "[levels]\nfloor_column = false\n")
            .replace("gap_m = [0.0, 0.01]", "gap_m = 0.0"),
    );
    warns(
        &sweep(&apart, &d.path().join("apart.csv"), &[]),
        "buildings 1 and 2 share no floor level (floors at 3, 6, 9 m against 3.2, 6.4 m",
    );
    let gaps = d.path().join("apart-gaps.csv");
    fails_with(
        &pound(&["gap", s(&apart), "-o", s(&gaps)]),
        "buildings 1 and 2 share no floor level",
    );
    assert!(!gaps.exists());
    // Fragility: NaN EDPs are left out with a count (the median is that of the finite rows);
    // a non-finite threshold is refused wherever one is typed.
    let mut clean = String::from("run,pga_g,status,peak_force_n\n");
    let mut nan = clean.clone();
    for (i, im) in [0.1, 0.2, 0.3, 0.4, 0.5, 0.6].iter().enumerate() {
        for k in 0..10 {
            let f = if (k as f64) < 10.0 * im { 2e6 } else { 0.0 };
            clean.push_str(&format!("{},{im},ok,{f}\n", i * 10 + k));
            nan.push_str(&format!("{},{im},ok,{f}\n", i * 10 + k));
            nan.push_str(&format!("{},{im},ok,NaN\n", 1000 + i * 10 + k));
        }
    }
    let fit = |name: &str, text: &str| {
        let r = write(d.path(), name, text);
        let o = pound(&[
            "fragility",
            s(&r),
            "--threshold",
            "1e6",
            "-o",
            s(&d.path().join(format!("{name}.frag.csv"))),
        ]);
        (ok(&o), err(&o))
    };
    let (a, _) = fit("clean.csv", &clean);
    let (b, _) = fit("nan.csv", &nan);
    assert!(b.contains("60 rows left out: 60 a value not finite"), "{b}");
    let median = |t: &str| {
        t.lines()
            .find(|l| l.starts_with("| 1000000 |"))
            .unwrap()
            .split('|')
            .nth(2)
            .unwrap()
            .trim()
            .to_string()
    };
    assert_eq!(median(&a), median(&b));
    let r = d.path().join("nan.csv");
    fails_with(
        &pound(&[
            "fragility",
            s(&r),
            "--threshold",
            "nan",
            "-o",
            s(&d.path().join("t.csv")),
        ]),
        "--threshold NaN: expected a finite number",
    );
    fails_with(
        &pound(&[
            "plot",
            s(&r),
            "--x",
            "pga_g",
            "--y",
            "peak_force_n",
            "--where",
            "pga_g>inf",
            "-o",
            s(&d.path().join("t.svg")),
        ]),
        "finite number",
    );
    let cfg = write(d.path(), "row.toml", &row(STOREYS3, STOREYS2, ""));
    fails_with(
        &sweep(
            &cfg,
            &d.path().join("agg.csv"),
            &["--aggregate", "gap_1_2_m", "--exceed", "b1_peak_roof_m=nan"],
        ),
        "must be a finite number",
    );
    // Two-column records: a BOM is not part of the first line, a typo is an error.
    let rows: Vec<String> = (0..200)
        .map(|i| {
            format!(
                "{:.2} {:.4}",
                i as f64 * 0.01,
                if i == 0 { 0.9 } else { 0.1 }
            )
        })
        .collect();
    let bom = write(
        d.path(),
        "bom.txt",
        &format!("\u{feff}{}\n", rows.join("\n")),
    );
    let info = ok(&pound(&[
        "record",
        "info",
        s(&bom),
        "--format",
        "two_column",
    ]));
    assert!(
        info.contains("npts      200") && info.contains("pga       0.9000 g"),
        "{info}"
    );
    let typo = write(
        d.path(),
        "typo.txt",
        &format!("{}\n", rows.join("\n").replacen("0.9000", "0.9O00", 1)),
    );
    fails_with(
        &pound(&["record", "info", s(&typo), "--format", "two_column"]),
        "typo.txt:1:",
    );
    // A cm/s2 file read as g: record info says so.
    let cms: Vec<String> = (0..100)
        .map(|i| format!("{:.2}", 300.0 * (i as f64 * 0.3).sin()))
        .collect();
    let cms = write(d.path(), "cms.txt", &cms.join("\n"));
    warns(
        &pound(&["record", "info", s(&cms), "--dt", "0.01"]),
        "above 5 g",
    );
}
