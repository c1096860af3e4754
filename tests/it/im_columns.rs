//! Intensity measures as columns (issue 48, part 4): every run writes its scaled record's PGV,
//! Arias intensity and CAV (`pgv_m_s`, `arias_m_s`, `cav_m_s`) and each building's `Sa(T1)` at
//! 5 % (`sa_t1_g`, `sa_t2_g` of a pair; `bK_sa_t1_g` of a row), whatever the record was scaled
//! to. Closed forms first, on hand-written records linear between samples (a constant, a
//! triangle and a saw whose every step crosses zero), whole and windowed, under a free tail;
//! then a sweep scaled to `Sa(T1)` has it in its column, and a fragility or IDA on the column is
//! the one on the target; `pound columns`, `--aggregate`, `--columns` and Parquet name them.

use crate::support::{ok, pound, rel, sweep_cpu, table, tempdir};
use pounding::record::G;
use std::collections::HashMap;
use std::path::Path;

/// The records' step, s.
const DT: f64 = 0.01;
/// The constant record's acceleration, m/s^2, over 3 s (301 samples).
const A: f64 = 1.5;
/// The triangle's peak, m/s^2: 0 at 0 s, P at 1 s, 0 at 2 s.
const P: f64 = 2.0;
/// The saw's amplitude, m/s^2: B, -B, B, ... over 2 s, every step crossing zero at its middle.
const B: f64 = 0.8;

/// `pi / (2 g)`: Arias intensity per `integral ag^2 dt`.
fn arias_per_square() -> f64 {
    std::f64::consts::PI / (2.0 * G)
}

/// The first overshoot of a step `A` (physics.md section 9), for `xi = 5 %`.
fn step_sa(a: f64) -> f64 {
    let xi: f64 = 0.05;
    a * (1.0 + (-xi * std::f64::consts::PI / (1.0 - xi * xi).sqrt()).exp())
}

/// PGV, Arias intensity and CAV (m/s) of each unscaled record, in closed form, by its name in
/// the CSV.
fn closed_forms() -> HashMap<&'static str, [f64; 3]> {
    let k = arias_per_square();
    HashMap::from([
        // A constant A over D: v = A t, integral a^2 = A^2 D, integral |a| = A D.
        ("const", [3.0 * A, k * A * A * 3.0, 3.0 * A]),
        // Its window [0.5, 1.5] s: one second of it (the run is driven by the window alone).
        ("const-window", [A, k * A * A, A]),
        // Two ramps of 1 s: v rises to P (the area), integral a^2 = 2 P^2 / 3, |a| = a.
        ("tri", [P, k * 2.0 * P * P / 3.0, P]),
        // Each step of h from B to -B: v peaks at its zero, B h / 4, and returns to 0;
        // integral a^2 = h B^2 / 3; integral |a| = h B / 2 (two triangles), where the trapezoid
        // of |a| would give h B.
        (
            "saw",
            [
                B * DT / 4.0,
                k * 200.0 * DT * B * B / 3.0,
                200.0 * DT * B / 2.0,
            ],
        ),
    ])
}

/// The records as value files (m/s^2) in `dir`, and their `[[record]]` entries.
fn records(dir: &Path) -> String {
    let write = |name: &str, values: Vec<f64>| {
        let text: Vec<String> = values.iter().map(|v| format!("{v:e}")).collect();
        std::fs::write(dir.join(name), text.join("\n")).unwrap();
    };
    write("const.txt", vec![A; 301]);
    write(
        "tri.txt",
        (0..=200)
            .map(|i| P * (if i <= 100 { i } else { 200 - i }) as f64 / 100.0)
            .collect(),
    );
    write(
        "saw.txt",
        (0..=200).map(|i| if i % 2 == 0 { B } else { -B }).collect(),
    );
    let entry = |path: &str, extra: &str| {
        format!("[[record]]\npath = \"{path}\"\nformat = \"values\"\ndt_s = {DT}\nunits = \"m/s2\"\n{extra}\n")
    };
    [
        entry("const.txt", ""),
        entry(
            "const.txt",
            "name = \"const-window\"\nwindow_s = [0.5, 1.5]",
        ),
        entry("tri.txt", ""),
        entry("saw.txt", ""),
    ]
    .concat()
}

const PAIR: &str = r#"
[run]
tail_s = 1.0

[building1]
mass_kg = 1.0e5
period_s = [0.3, 0.7]
damping_ratio = 0.05

[building2]
mass_kg = 1.0e5
period_s = 1.1
damping_ratio = 0.02

[contact]
law = "kelvin_voigt"
formula = "exact"
e = 0.65
k_n_per_m = 2.0e8
gap_m = 0.02
"#;

const ROW: &str = r#"
[run]
tail_s = 1.0

[[building]]
storeys = 3
storey_height_m = 3.0
mass_kg = 2.0e5
period_s = [0.4, 0.9]
damping_ratio = 0.05

[[building]]
storeys = 2
storey_height_m = 3.0
mass_kg = 2.0e5
period_s = 0.25
damping_ratio = 0.03

[contact]
law = "kelvin_voigt"
formula = "exact"
e = 0.65
k_n_per_m = 2.0e8
gap_m = 0.02
"#;

fn num(row: &HashMap<String, String>, column: &str) -> f64 {
    row[column]
        .parse()
        .unwrap_or_else(|_| panic!("{column} = `{}`", row[column]))
}

/// A sweep of `scene` with `extra` (records, intensity) in `dir`, as its rows by column name.
fn sweep(dir: &Path, name: &str, text: String) -> Vec<HashMap<String, String>> {
    let cfg = dir.join(format!("{name}.toml"));
    std::fs::write(&cfg, text).unwrap();
    let out = dir.join(format!("{name}.csv"));
    ok(&sweep_cpu(&cfg, &out, &[]));
    table(&out)
}

/// Check a run's PGV, Arias and CAV against the closed forms of its record, scaled by its
/// factor (the PGA against the record's own, which is the target's).
fn check_record_columns(r: &HashMap<String, String>) -> f64 {
    let forms = closed_forms();
    let name = r["record"].as_str();
    let [pgv, arias, cav] = forms[name];
    let s = num(r, "scale_factor");
    let run = &r["run"];
    assert!(
        rel(num(r, "pgv_m_s"), s * pgv) < 1e-12,
        "run {run} {name}: PGV"
    );
    assert!(
        rel(num(r, "arias_m_s"), s * s * arias) < 1e-12,
        "run {run} {name}: Arias {} vs {}",
        num(r, "arias_m_s"),
        s * s * arias
    );
    assert!(
        rel(num(r, "cav_m_s"), s * cav) < 1e-12,
        "run {run} {name}: CAV {} vs {}",
        num(r, "cav_m_s"),
        s * cav
    );
    s
}

/// `Sa(T, 5 %)` in g of record `name` (unscaled) at `period`: the step's overshoot for the
/// constant records, the library's for the others.
fn sa_g(dir: &Path, name: &str, period: f64) -> f64 {
    match name {
        "const" | "const-window" => step_sa(A) / G,
        _ => {
            let opts = pounding::record::ReadOptions {
                format: pounding::record::Format::Values,
                units: Some(pounding::record::Units::MPerS2),
                dt: Some(DT),
                skip_lines: 0,
            };
            let rec =
                pounding::record::read_record(&dir.join(format!("{name}.txt")), &opts).unwrap();
            pounding::record::intensity::sa(&rec, period, 0.05) / G
        }
    }
}

/// A pair's runs on each record, at factors 1 and 2: the closed forms of PGV, Arias and CAV
/// times the factor (Arias its square), whole record or window, under a free tail that adds
/// nothing; each building's `Sa(T1)` at its own period; and a factor of 2 has 4x the Arias of
/// the unscaled run, 2x the rest.
#[test]
fn a_pairs_columns_are_the_closed_forms_of_its_scaled_records() {
    let dir = tempdir();
    let d = dir.path();
    let rows = sweep(
        d,
        "pair",
        format!("{PAIR}\n{}\n[intensity]\nscale = [1.0, 2.0]\n", records(d)),
    );
    assert_eq!(rows.len(), 4 * 2 * 2);
    let mut unscaled: HashMap<(String, String), &HashMap<String, String>> = HashMap::new();
    for r in &rows {
        assert_eq!(r["status"], "ok");
        let s = check_record_columns(r);
        for (sa, t) in [("sa_t1_g", "t1_s"), ("sa_t2_g", "t2_s")] {
            let want = s * sa_g(d, &r["record"], num(r, t));
            // The step's overshoot falls between samples: found to 1e-10 (Newton on the exact
            // solution, as `record::intensity`'s own test).
            assert!(
                rel(num(r, sa), want) < 1e-10,
                "run {} {}: {sa} {} vs {want}",
                r["run"],
                r["record"],
                num(r, sa)
            );
        }
        if s == 1.0 {
            unscaled.insert((r["record"].clone(), r["t1_s"].clone()), r);
        }
    }
    let mut doubled = 0;
    for r in rows.iter().filter(|r| r["scale_factor"] == "2") {
        let one = unscaled[&(r["record"].clone(), r["t1_s"].clone())];
        assert!(rel(num(r, "arias_m_s"), 4.0 * num(one, "arias_m_s")) < 1e-14);
        for c in ["pga_g", "pgv_m_s", "cav_m_s", "sa_t1_g", "sa_t2_g"] {
            assert!(rel(num(r, c), 2.0 * num(one, c)) < 1e-14, "{c}");
        }
        doubled += 1;
    }
    assert_eq!(doubled, 8);
}

/// A row's runs scaled to target PGAs: the record's columns as a pair's, and `bK_sa_t1_g` of
/// each building at its fundamental period `bK_t1_s` (a swept one too).
#[test]
fn a_rows_columns_follow_each_buildings_fundamental_period() {
    let dir = tempdir();
    let d = dir.path();
    let rows = sweep(
        d,
        "row",
        format!("{ROW}\n{}\n[intensity]\npga_g = [0.1, 0.3]\n", records(d)),
    );
    assert_eq!(rows.len(), 4 * 2 * 2);
    let mut periods = std::collections::BTreeSet::new();
    for r in &rows {
        assert_eq!(r["status"], "ok");
        let s = check_record_columns(r);
        for k in 1..=2 {
            let t = num(r, &format!("b{k}_t1_s"));
            periods.insert(r[&format!("b{k}_t1_s")].clone());
            let got = num(r, &format!("b{k}_sa_t1_g"));
            let want = s * sa_g(d, &r["record"], t);
            assert!(
                rel(got, want) < 1e-10,
                "run {}: b{k} {got} vs {want}",
                r["run"]
            );
        }
        assert!(rel(num(r, "pga_g"), num(r, "target_pga_g")) < 1e-12);
        assert!(!r.contains_key("sa_t1_g") && !r.contains_key("sa_t2_g"));
    }
    assert_eq!(periods.len(), 3, "{periods:?}");
}

/// Synthetic records of a few seconds.
const SYNTHETIC: &str = "[[record]]\nsynthetic = { seed = 3, duration_s = 5.0, dt_s = 0.01 }\n\n[[record]]\nsynthetic = { seed = 8, duration_s = 5.0, dt_s = 0.02 }\n";

/// A sampled row scaled to `Sa(T1)` of building 1 (its period sampled per run).
fn sampled_row(intensity: &str) -> String {
    format!(
        "{}\n[sample]\nmethod = \"latin_hypercube\"\nn = 8\nseed = 5\n\n[[sample.axis]]\nkey = \"building[0].period_s\"\ndist = \"lognormal\"\nmedian = 0.5\nbeta = 0.2\n\n{SYNTHETIC}\n[intensity]\n{intensity}\n",
        ROW.replace("period_s = [0.4, 0.9]\n", "")
    )
}

/// The EDP's median over `rows`: a threshold that some runs exceed and some do not.
fn median(rows: &[HashMap<String, String>], edp: &str) -> String {
    let mut v: Vec<f64> = rows.iter().map(|r| num(r, edp)).collect();
    v.sort_by(f64::total_cmp);
    format!("{:e}", v[v.len() / 2])
}

/// `pound fragility` and `pound ida` on the CSV `csv` with `--im im`: their stdout and files,
/// with `im`'s name replaced by `IM` (IDA curves named by the columns `by`).
fn studies(dir: &Path, csv: &Path, im: &str, edp: &str, threshold: &str, by: &str) -> Vec<String> {
    let s = |p: &Path| p.to_str().unwrap().to_string();
    let f = dir.join(format!("fragility-{im}.csv"));
    let i = dir.join(format!("ida-{im}.csv"));
    let mut said = ok(&pound(&[
        "fragility",
        &s(csv),
        "--im",
        im,
        "--edp",
        edp,
        "--threshold",
        threshold,
        "-o",
        &s(&f),
    ]));
    said += &ok(&pound(&[
        "ida",
        &s(csv),
        "--im",
        im,
        "--edp",
        edp,
        "--curves",
        by,
        "-o",
        &s(&i),
    ]));
    [
        said,
        std::fs::read_to_string(&f).unwrap(),
        std::fs::read_to_string(&i).unwrap(),
    ]
    .map(|t| t.replace(im, "IM"))
    .to_vec()
}

/// A sweep scaled to `Sa(T1)` of building 1 has that Sa in its `sa_t1_g` column (a pair) and
/// `b1_sa_t1_g` (a row, its period sampled per run), to rounding; at a fixed period only the
/// runs whose T1 is that period do. A fragility and an IDA on the column are those on the
/// target, to the digit.
#[test]
fn a_sweep_scaled_to_sa_at_t1_has_it_in_its_column_and_the_same_fragility() {
    let dir = tempdir();
    let d = dir.path();
    let pair = sweep(
        d,
        "pair-sa",
        format!(
            "{PAIR}\n{SYNTHETIC}\n[intensity]\nsa_g = [0.1, 0.25, 0.5, 0.8]\nsa_period_s = \"building1\"\n"
        ),
    );
    let row = sweep(
        d,
        "row-sa",
        sampled_row("sa_g = [0.1, 0.25, 0.5, 0.8]\nsa_period_s = \"building1\""),
    );
    for (rows, sa, t) in [(&pair, "sa_t1_g", "t1_s"), (&row, "b1_sa_t1_g", "b1_t1_s")] {
        let mut periods = std::collections::BTreeSet::new();
        for r in rows.iter() {
            assert!(
                rel(num(r, sa), num(r, "target_sa_g")) < 1e-14,
                "run {}: {sa} {} vs {}",
                r["run"],
                r[sa],
                r["target_sa_g"]
            );
            assert_eq!(r["sa_period_s"], r[t]);
            periods.insert(r[t].clone());
        }
        assert!(periods.len() >= 2, "{periods:?}");
    }
    for (csv, sa, edp, by) in [
        ("pair-sa.csv", "sa_t1_g", "peak_u1_m", "record,t1_s"),
        (
            "row-sa.csv",
            "b1_sa_t1_g",
            "b1_peak_drift_ratio",
            "record,sample",
        ),
    ] {
        let rows = if sa == "sa_t1_g" { &pair } else { &row };
        let threshold = median(rows, edp);
        let csv = d.join(csv);
        let on_target = studies(d, &csv, "target_sa_g", edp, &threshold, by);
        let on_column = studies(d, &csv, sa, edp, &threshold, by);
        assert!(on_target[0].contains("median IM"), "{}", on_target[0]);
        for (a, b) in on_target.iter().zip(&on_column) {
            crate::support::assert_same_text(sa, a, b);
        }
    }
    // At a fixed period, only the runs at that T1 have the target as their Sa(T1).
    let fixed = sweep(
        d,
        "pair-fixed",
        format!("{PAIR}\n{SYNTHETIC}\n[intensity]\nsa_g = 0.4\nsa_period_s = 0.7\n"),
    );
    for r in &fixed {
        let at = r["t1_s"] == "0.7";
        assert_eq!(rel(num(r, "sa_t1_g"), 0.4) < 1e-14, at, "run {}", r["run"]);
        assert!(rel(num(r, "sa_t2_g"), 0.4) > 1e-6);
    }
}

/// `pound columns` lists the new columns with their units and meanings (the record linear
/// between samples said), a pair's and a row's, in one well-formed table.
#[test]
fn pound_columns_lists_the_intensity_measures() {
    let dir = tempdir();
    let d = dir.path();
    let row = d.join("row.toml");
    std::fs::write(
        &row,
        format!("{ROW}\n{SYNTHETIC}\n[intensity]\npga_g = 0.3\n"),
    )
    .unwrap();
    let pair = ok(&pound(&["columns"]));
    let row = ok(&pound(&["columns", row.to_str().unwrap()]));
    for (text, columns) in [
        (
            &pair,
            &["pgv_m_s", "arias_m_s", "cav_m_s", "sa_t1_g", "sa_t2_g"][..],
        ),
        (
            &row,
            &[
                "pgv_m_s",
                "arias_m_s",
                "cav_m_s",
                "b1_sa_t1_g",
                "b2_sa_t1_g",
            ][..],
        ),
    ] {
        for line in text.lines() {
            assert_eq!(line.matches('|').count(), 5, "{line}");
        }
        let names: Vec<&str> = text
            .lines()
            .filter_map(|l| l.strip_prefix("| `")?.split('`').next())
            .collect();
        let pga = names.iter().position(|c| *c == "pga_g").unwrap();
        assert_eq!(
            names[pga + 1..pga + 6],
            *columns,
            "in file order after pga_g"
        );
        for c in columns {
            let line = text
                .lines()
                .find(|l| l.starts_with(&format!("| `{c}` |")))
                .unwrap();
            let unit = if c.ends_with("_g") {
                "| g |"
            } else {
                "| m/s |"
            };
            assert!(line.contains(unit), "{line}");
            assert!(
                line.contains("linear between samples") && line.contains("not the free tail"),
                "{line}"
            );
        }
    }
    assert!(pair.contains("split at its zero"));
    assert!(row.contains("building 2's fundamental period b2_t1_s"));
}

/// The columns are parameters: `--aggregate` groups by them (a pair's by its typed keys, a
/// row's by its cells), `--exceed` refuses them, `--columns` and Parquet write them.
#[test]
fn the_columns_group_summaries_and_travel_to_parquet() {
    use parquet::file::reader::{FileReader, SerializedFileReader};
    let dir = tempdir();
    let d = dir.path();
    let s = |p: &Path| p.to_str().unwrap().to_string();
    let pair_cfg = d.join("pair.toml");
    std::fs::write(
        &pair_cfg,
        format!("{PAIR}\n{}\n[intensity]\nscale = [1.0, 2.0]\n", records(d)),
    )
    .unwrap();
    let row_cfg = d.join("row.toml");
    std::fs::write(
        &row_cfg,
        sampled_row("sa_g = [0.2, 0.4]\nsa_period_s = \"building1\""),
    )
    .unwrap();
    for (cfg, by) in [(&pair_cfg, "pgv_m_s"), (&row_cfg, "b1_sa_t1_g")] {
        let full = d.join("full.csv");
        ok(&sweep_cpu(cfg, &full, &[]));
        let rows = table(&full);
        let summary = d.join("summary.csv");
        ok(&sweep_cpu(cfg, &summary, &["--aggregate", by]));
        let groups = table(&summary);
        let mut want: Vec<&String> = rows.iter().map(|r| &r[by]).collect();
        want.sort();
        want.dedup();
        let mut got: Vec<&String> = groups.iter().map(|g| &g[by]).collect();
        got.sort();
        assert_eq!(got, want, "{by}");
        for g in &groups {
            let n = rows.iter().filter(|r| r[by] == g[by]).count();
            assert_eq!(g["runs"], n.to_string());
        }
        let refused = sweep_cpu(
            cfg,
            &d.join("bad.csv"),
            &["--aggregate", "record", "--exceed", &format!("{by}=1")],
        );
        assert!(!refused.status.success());
        // Parquet: the chosen columns as doubles, the CSV's values.
        let pq = d.join("ims.parquet");
        let picked = if by == "pgv_m_s" {
            "pgv_m_s,arias_m_s,cav_m_s,sa_t1_g,sa_t2_g"
        } else {
            "pgv_m_s,arias_m_s,cav_m_s,b1_sa_t1_g,b2_sa_t1_g"
        };
        ok(&sweep_cpu(
            cfg,
            &pq,
            &["--format", "parquet", "--columns", picked],
        ));
        let reader = SerializedFileReader::new(std::fs::File::open(&pq).unwrap()).unwrap();
        let mut seen = 0;
        for (row, r) in reader.get_row_iter(None).unwrap().zip(&rows) {
            for (name, field) in row.unwrap().get_column_iter() {
                match field {
                    parquet::record::Field::Double(v) => {
                        assert_eq!(*v, num(r, name), "{name}");
                        seen += 1;
                    }
                    parquet::record::Field::Long(v) => assert_eq!(name, "run", "{v}"),
                    other => panic!("{name}: {other:?}"),
                }
            }
        }
        assert_eq!(seen, 5 * rows.len(), "{}", s(&pq));
    }
}
