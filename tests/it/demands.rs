//! Demands storey by storey and floor by floor (issue 69): `--columns +storeys,+floors` adds
//! every building's per-storey peak and residual drift ratios and per-floor peak absolute
//! accelerations (floor 0 the ground), and changes no other cell.
//!
//! Checks: on an elastic row, a yielding row, a row whose buildings collapse and a row that
//! runs on the pair's kernels, every cell of the default table is the same with the groups on;
//! each building's largest storey drift and floor acceleration are its `bK_peak_drift_ratio`
//! and `bK_peak_accel_m_s2` to the bit, floor 0 is the scaled record's PGA, an elastic storey's
//! residual is 0, a yielding building's largest `|residual|` is its `bK_residual_drift_ratio`,
//! a collapsed storey's peak drift is the limit; the groups are refused where they cannot be
//! written, naming why.

use crate::support::cli::refusal as refused;
use crate::support::{ok, pound, table, tempdir};
use std::collections::HashMap;

type Row = HashMap<String, String>;

fn sweep(config: &str, out: &std::path::Path, extra: &[&str]) -> Vec<Row> {
    let mut args = vec![
        "sweep",
        config,
        "-o",
        out.to_str().unwrap(),
        "--backend",
        "cpu",
    ];
    args.extend_from_slice(extra);
    ok(&pound(&args));
    table(out)
}

fn num(r: &Row, c: &str) -> f64 {
    r.get(c)
        .unwrap_or_else(|| panic!("no column {c}"))
        .parse()
        .unwrap_or_else(|_| panic!("{c}: {:?}", r[c]))
}

#[test]
fn storeys_and_floors_are_the_buildings_peaks_one_by_one() {
    let d = tempdir();
    let mut checked = (0, 0, 0);
    for config in [
        "configs/row-3-6.toml",
        "configs/inelastic-row.toml",
        "configs/collapse-fragility.toml",
        "configs/row-of-two.toml",
    ] {
        let plain = sweep(config, &d.path().join("plain.csv"), &[]);
        let rows = sweep(
            config,
            &d.path().join("demands.csv"),
            &["--columns", "+storeys,+floors"],
        );
        assert_eq!(plain.len(), rows.len(), "{config}");
        // `pound columns --all` names every column the groups write, in the sweep's order, each
        // with a unit and a meaning.
        let listed = ok(&pound(&["columns", config, "--all"]));
        let names: Vec<&str> = (listed.lines().skip(2))
            .map(|l| {
                let cells: Vec<&str> = l.split('|').map(str::trim).collect();
                assert!(!cells[2].is_empty() && cells[3].len() > 3, "{l}");
                cells[1].trim_matches('`')
            })
            .collect();
        let header = std::fs::read_to_string(d.path().join("demands.csv")).unwrap();
        let written: Vec<&str> = header.lines().next().unwrap().split(',').collect();
        assert_eq!(names, written, "{config}");
        let limit = rows[0].get("collapse_time_s").map(|_| 0.10);
        for (p, r) in plain.iter().zip(&rows) {
            for (c, v) in p {
                assert_eq!(&r[c], v, "{config} run {}: {c}", p["run"]);
            }
            let mut b = 1;
            while r.contains_key(&format!("b{b}_peak_drift_ratio")) {
                let storeys =
                    (1..).take_while(|j| r.contains_key(&format!("b{b}_s{j}_peak_drift_ratio")));
                let n = storeys.count();
                assert!(n >= 1, "{config}: building {b} has storey columns");
                let drift = |j: usize| num(r, &format!("b{b}_s{j}_peak_drift_ratio"));
                let accel = |j: usize| num(r, &format!("b{b}_f{j}_peak_accel_m_s2"));
                let top = (1..=n).map(drift).fold(0.0, f64::max);
                assert_eq!(
                    top,
                    num(r, &format!("b{b}_peak_drift_ratio")),
                    "{config} b{b}"
                );
                let top = (1..=n).map(accel).fold(0.0, f64::max);
                assert_eq!(
                    top,
                    num(r, &format!("b{b}_peak_accel_m_s2")),
                    "{config} b{b}"
                );
                let ground = accel(0) / pounding::record::G;
                assert!(
                    (ground - num(r, "pga_g")).abs() <= 1e-12 * ground,
                    "{config}"
                );
                let collapsed = r.get(&format!("b{b}_collapsed")).is_some_and(|x| x == "1");
                let residuals: Vec<&String> = (1..=n)
                    .map(|j| &r[&format!("b{b}_s{j}_residual_drift_ratio")])
                    .collect();
                if collapsed {
                    let j: usize = r[&format!("b{b}_collapse_storey")].parse().unwrap();
                    assert_eq!(drift(j), limit.unwrap(), "{config} b{b}");
                    assert!(residuals.iter().all(|x| x.is_empty()));
                    checked.2 += 1;
                } else if r.contains_key(&format!("b{b}_residual_drift_ratio")) {
                    let said = &r[&format!("b{b}_residual_drift_ratio")];
                    if said.is_empty() {
                        // A run that did not settle has no residual drift, storey by storey.
                        assert!(residuals.iter().all(|x| x.is_empty()), "{config} b{b}");
                    } else {
                        let largest = (residuals.iter())
                            .map(|x| x.parse::<f64>().unwrap().abs())
                            .fold(0.0, f64::max);
                        assert_eq!(largest, said.parse::<f64>().unwrap(), "{config} b{b}");
                        checked.1 += 1;
                    }
                } else if r["status"] == "ok" {
                    assert!(residuals.iter().all(|x| *x == "0"), "{config} b{b}");
                    checked.0 += 1;
                }
                b += 1;
            }
        }
    }
    assert!(
        checked.0 > 0 && checked.1 > 0 && checked.2 > 0,
        "{checked:?}"
    );
}

#[test]
fn the_groups_are_refused_where_they_cannot_be_written() {
    let d = tempdir();
    let out = d.path().join("x.csv");
    let o = out.to_str().unwrap();
    let e = refused(&[
        "sweep",
        "configs/row-3-6.toml",
        "-o",
        o,
        "--columns",
        "+nope",
    ]);
    assert!(
        e.contains("`+nope` is no column group") && e.contains("+storeys"),
        "{e}"
    );
    let e = refused(&[
        "sweep",
        "configs/quickstart.toml",
        "-o",
        o,
        "--columns",
        "+floors",
    ]);
    assert!(e.contains("a pair's buildings have one storey each"), "{e}");
    let e = refused(&[
        "sweep",
        "configs/row-3-6.toml",
        "-o",
        o,
        "--columns",
        "+storeys",
        "--backend",
        "gpu",
    ]);
    assert!(e.contains("tracked on the CPU only"), "{e}");
    // A yielding storey's own column is written from what every run reports: no demand is
    // tracked, so the GPU takes the sweep.
    ok(&pound(&[
        "sweep",
        "configs/inelastic-row.toml",
        "-o",
        o,
        "--columns",
        "run,b1_s1_peak_ductility",
        "--backend",
        "gpu",
        "--precision",
        "f64",
    ]));
    // A group beside named columns adds its own to them.
    let rows = sweep(
        "configs/row-3-6.toml",
        &out,
        &["--columns", "run,status,+floors"],
    );
    let mut names: Vec<&String> = rows[0].keys().collect();
    names.sort();
    let floors = names.iter().filter(|c| c.contains("_f")).count();
    assert_eq!(names.len(), 2 + floors, "{names:?}");
    assert_eq!(floors, 4 + 7);
}

/// `pound demands` writes a row per run that did not fail, its columns from the storeys' and
/// floors' and the units row pelicun reads; it refuses a table without them (naming the flag
/// that writes them) and a building the table does not have.
#[test]
fn pound_demands_writes_the_simcenter_form_or_says_what_is_missing() {
    let d = tempdir();
    let runs = d.path().join("runs.csv");
    let rows = sweep(
        "configs/row-3-6.toml",
        &runs,
        &["--columns", "+storeys,+floors"],
    );
    let out = d.path().join("demands.csv");
    let (r, o) = (runs.to_str().unwrap(), out.to_str().unwrap());
    ok(&pound(&["demands", r, "--building", "2", "-o", o]));
    let text = std::fs::read_to_string(&out).unwrap();
    let mut lines = text.lines();
    let head: Vec<&str> = lines.next().unwrap().split(',').collect();
    let units: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!((head[0], units[0]), ("", "Units"));
    assert_eq!(head.len(), 1 + 2 * 6 + 7 + 1, "{head:?}");
    for (h, u) in head.iter().zip(&units).skip(1) {
        let unit = match h.split('-').nth(1).unwrap() {
            "PID" | "RID" => "rad",
            "PFA" => "mps2",
            "COL" => "unitless",
            other => panic!("{other}"),
        };
        assert_eq!(*u, unit, "{h}");
    }
    let body: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(body.len(), rows.len());
    for (cells, r) in body.iter().zip(&rows) {
        assert_eq!(cells[0], r["run"]);
        for (h, c) in head.iter().zip(cells).skip(1) {
            let parts: Vec<&str> = h.split('-').collect();
            let column = match parts[1] {
                "PID" => format!("b2_s{}_peak_drift_ratio", parts[2]),
                "RID" => format!("b2_s{}_residual_drift_ratio", parts[2]),
                "PFA" => format!("b2_f{}_peak_accel_m_s2", parts[2]),
                _ => {
                    assert_eq!(*c, "0", "an elastic row never collapses");
                    continue;
                }
            };
            assert_eq!(c.parse::<f64>().unwrap(), num(r, &column), "{h}");
        }
    }
    let plain = d.path().join("plain.csv");
    sweep("configs/row-3-6.toml", &plain, &[]);
    let p = plain.to_str().unwrap();
    let e = refused(&["demands", p, "--building", "1", "-o", o]);
    assert!(e.contains("--columns +storeys,+floors"), "{e}");
    // A table that left out the building's collapse column cannot tell its collapsed runs.
    let partial = d.path().join("partial.csv");
    sweep(
        "configs/collapse-fragility.toml",
        &partial,
        &["--columns", "status,target_sa_g,+storeys,+floors"],
    );
    let e = refused(&[
        "demands",
        partial.to_str().unwrap(),
        "--building",
        "1",
        "-o",
        o,
    ]);
    assert!(e.contains("no b1_collapsed column"), "{e}");
    // A demand that is not a number is refused, naming its line and column.
    let text = std::fs::read_to_string(&runs).unwrap();
    let head: Vec<&str> = text.lines().next().unwrap().split(',').collect();
    let at = head
        .iter()
        .position(|h| *h == "b2_s2_peak_drift_ratio")
        .unwrap();
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    let mut cells: Vec<String> = lines[1].split(',').map(String::from).collect();
    cells[at] = "NaN".into();
    lines[1] = cells.join(",");
    let nan = d.path().join("nan.csv");
    std::fs::write(&nan, lines.join("\n") + "\n").unwrap();
    let e = refused(&["demands", nan.to_str().unwrap(), "--building", "2", "-o", o]);
    assert!(
        e.contains("line 2: `b2_s2_peak_drift_ratio` is NaN: a demand is a finite number"),
        "{e}"
    );
    let e = refused(&["demands", r, "--building", "3", "-o", o]);
    assert!(
        e.contains("no building 3 (the table's columns name buildings 1 to 2)"),
        "{e}"
    );
}
