//! Config files: the shipped configs load, bad keys and values give errors that name the key,
//! and plan numbering is a clean mixed-radix decode.

use crate::support::{records_dir, tempdir};
use pounding::physics::contact::LawKind;
use pounding::physics::restitution::Formula;
use pounding::plan::config::{self, ConfigError};
use std::path::Path;

fn parse(text: &str) -> Result<pounding::plan::PairPlan, ConfigError> {
    config::parse(text, Path::new("t.toml"), Path::new("."), &records_dir())
}

const BASE: &str = r#"
[building1]
mass_kg = 1.0e5
period_s = [0.3, 0.5]
damping_ratio = 0.05

[building2]
mass_kg = 2.0e5
period_s = 0.8
damping_ratio = 0.05

[contact]
law = ["hertz", "nonlinear_viscoelastic", "kelvin_voigt"]
formula = ["ebrahimi", "exact"]
e = [0.5, 0.7, 0.9]
k_n_per_m = [1e8, 1e9]
beta_n_per_m1_5 = 2.75e9
gap_m = { from = 0.0, to = 0.02, n = 5 }

[[record]]
synthetic = { seed = 2, duration_s = 5.0 }

[intensity]
pga_g = [0.2, 0.4]
"#;

#[test]
fn shipped_configs_load() {
    let q = config::load_pair(Path::new("configs/quickstart.toml")).unwrap();
    assert_eq!(q.len(), 2700);
    for (name, runs) in [("e", 70), ("period", 100), ("damping", 105), ("gap", 100)] {
        let p = config::load_pair(Path::new(&format!("configs/paper-{name}.toml")))
            .unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(p.len(), runs, "paper-{name}");
        assert_eq!(p.contact.spec.records.len(), 5);
        // Every run is scaled to 0.35 g.
        assert!(
            (0..p.len()).all(|i| (p.run(i).pga_g - 0.35).abs() < 1e-12),
            "paper-{name}"
        );
    }
}

#[test]
fn plan_blocks_follow_the_law() {
    let p = parse(BASE).unwrap();
    // hertz: no formula, no e, beta only: 1*1*1 * 1 record * 2 pga * 2 T1 * 5 gaps = 20
    // nonlinear_viscoelastic: 2 formulas * 3 e * 1 beta * 20 = 120
    // kelvin_voigt: 2 * 3 * 2 k * 20 = 240
    assert_eq!(p.len(), 380);
    let first = p.run(0);
    assert_eq!(
        (first.law, first.formula, first.e, first.damping),
        (LawKind::Hertz, None, None, 0.0)
    );
    let r = p.run(20);
    assert_eq!(
        (r.law, r.formula, r.e),
        (
            LawKind::NonlinearViscoelastic,
            Some(Formula::Ebrahimi),
            Some(0.5)
        )
    );
    assert!((r.damping - Formula::Ebrahimi.zeta(0.5).unwrap().unwrap()).abs() < 1e-15);
    // Gap is the innermost axis, then T1.
    assert_eq!(p.run(21).gap, 0.005);
    assert_eq!((p.run(25).gap, p.run(25).t1), (0.0, 0.5));
    let last = p.run(379);
    assert_eq!(
        (last.law, last.formula, last.e, last.stiffness, last.gap),
        (
            LawKind::KelvinVoigt,
            Some(Formula::Exact),
            Some(0.9),
            1e9,
            0.02
        )
    );
    // Every (law, formula, e, stiffness, record, intensity, buildings, gap) combination once.
    let mut seen = std::collections::HashSet::new();
    for i in 0..p.len() {
        let s = p.run(i);
        assert_eq!(s.index, i);
        assert!(seen.insert(format!(
            "{:?}{:?}{:?}{}{}{:?}{}{}",
            s.law, s.formula, s.e, s.stiffness, s.record, s.intensity, s.t1, s.gap
        )));
    }
}

/// Each bad input gives an error naming the key (and index) and what was expected.
#[test]
fn bad_configs_name_the_key() {
    let cases: &[(&str, &str, &str)] = &[
        (
            "damping_ratio = 0.05\n\n[building2]",
            "damping_ratio = 0.05\ncolour = 3\n\n[building2]",
            "unknown field `colour`",
        ),
        (
            "e = [0.5, 0.7, 0.9]",
            "e = [0.5, 1.7, 0.9]",
            "contact.e[1]: 1.7 is out of range: expected a coefficient of restitution 0.01 <= e <= 1",
        ),
        (
            "e = [0.5, 0.7, 0.9]",
            "e = [0.0]",
            "contact.e[0]: 0 is out of range",
        ),
        (
            "gap_m = { from = 0.0, to = 0.02, n = 5 }",
            "gap_m = [0.01, -0.001]",
            "contact.gap_m[1]: -0.001 is out of range: expected a gap >= 0 m",
        ),
        (
            "mass_kg = 2.0e5",
            "mass_kg = 0",
            "building2.mass_kg[0]: 0 is out of range: expected a mass > 0 kg",
        ),
        (
            "period_s = [0.3, 0.5]",
            "period_s = [0.3, 0.0]",
            "building1.period_s[1]: 0 is out of range: expected a period >= 1e-4 s",
        ),
        ("period_s = 0.8", "period_s = 0.8\n", ""),
        (
            "damping_ratio = 0.05\n\n[building2]",
            "damping_ratio = 1.0\n\n[building2]",
            "building1.damping_ratio[0]: 1 is out of range: expected 0 <= damping ratio < 1",
        ),
        (
            "\"kelvin_voigt\"]",
            "\"kelvin_voight\"]",
            "contact.law[2]: unknown law `kelvin_voight`: expected one of linear, kelvin_voigt",
        ),
        (
            "\"exact\"]",
            "\"exakt\"]",
            "contact.formula[1]: unknown formula `exakt`",
        ),
        (
            "gap_m = { from = 0.0, to = 0.02, n = 5 }",
            "gap_m = { from = 0.0, to = 0.02, n = 5, step = 0.1 }",
            "contact.gap_m: give exactly one of n or step",
        ),
        (
            "gap_m = { from = 0.0, to = 0.02, n = 5 }",
            "gap_m = \"wide\"",
            "expected a number, a list of numbers, or a range table",
        ),
        (
            "k_n_per_m = [1e8, 1e9]",
            "k_n_per_m = []",
            "contact.k_n_per_m: is missing or empty",
        ),
        (
            "pga_g = [0.2, 0.4]",
            "pga_g = [0.2, -0.4]",
            "intensity.pga_g[1]: -0.4 is out of range",
        ),
        (
            "pga_g = [0.2, 0.4]",
            "pga_g = 0.2\nscale = 2",
            "intensity: gives pga_g and scale: give one of pga_g, scale, sa_g, sa_avg_g",
        ),
        (
            "synthetic = { seed = 2, duration_s = 5.0 }",
            "file = \"no_such_record.AT2\"",
            "record[0]: ",
        ),
        (
            "synthetic = { seed = 2, duration_s = 5.0 }",
            "file = \"tabas1978_FN_opensees_tabasFN.txt\"",
            "no NPTS/DT header and no time column",
        ),
        (
            "synthetic = { seed = 2, duration_s = 5.0 }",
            "synthetic = { seed = 2 }\nunits = \"g\"",
            "record[0]: format, units, dt_s and skip_lines apply to files",
        ),
        (
            "synthetic = { seed = 2, duration_s = 5.0 }",
            "file = \"x.AT2\"\nsynthetic = { seed = 1 }",
            "record[0]: give exactly one of file, path or synthetic",
        ),
        (
            "synthetic = { seed = 2, duration_s = 5.0 }",
            "file = \"tabas1978_FN_opensees_tabasFN.txt\"\ndt_s = 0.02\nunits = \"furlongs\"",
            "record[0]: units `furlongs`: expected g, m/s2 or cm/s2",
        ),
    ];
    for (from, to, want) in cases {
        assert!(BASE.contains(from), "test case does not apply: {from}");
        let text = BASE.replacen(from, to, 1);
        match parse(&text) {
            Ok(_) => assert!(
                want.is_empty(),
                "accepted, expected error `{want}`:\n{text}"
            ),
            Err(e) => {
                let msg = e.to_string();
                assert!(
                    !want.is_empty() && msg.starts_with("t.toml: ") && msg.contains(want),
                    "got `{msg}`, want `{want}`"
                );
            }
        }
    }
    // A missing record file names the file it looked for.
    let e = parse(&BASE.replacen(
        "synthetic = { seed = 2, duration_s = 5.0 }",
        "file = \"no_such_record.AT2\"",
        1,
    ))
    .unwrap_err();
    assert!(
        e.to_string()
            .contains("file = \"no_such_record.AT2\": no such record in")
            && e.to_string().contains("POUND_RECORDS_DIR"),
        "{e}"
    );
    // TOML syntax errors give the line.
    let e = parse(&BASE.replacen("mass_kg = 2.0e5", "mass_kg = = 2", 1)).unwrap_err();
    assert!(e.to_string().contains("line 8"), "{e}");
}

#[test]
fn path_records_resolve_against_the_config() {
    let d = tempdir();
    std::fs::write(
        d.path().join("r.csv"),
        "0.0,0.1\n0.01,-0.2\n0.02,0.3\n0.03,0.0\n",
    )
    .unwrap();
    let text = BASE.replacen(
        "synthetic = { seed = 2, duration_s = 5.0 }",
        "path = \"r.csv\"\nname = \"mine\"",
        1,
    );
    let cfg = d.path().join("c.toml");
    std::fs::write(&cfg, text).unwrap();
    let p = config::load_pair(&cfg).unwrap();
    assert_eq!(p.contact.spec.records[0].name, "mine");
    assert_eq!(p.contact.spec.records[0].npts(), 4);
}

#[test]
fn ranges_expand() {
    assert_eq!(
        pounding::config::parse_colon_range("0.1:1:0.3").unwrap(),
        vec![0.1, 0.4, 0.7, 1.0]
    );
    assert_eq!(
        pounding::config::parse_colon_range("0.5").unwrap(),
        vec![0.5]
    );
    assert!(pounding::config::parse_colon_range("1:0:0.1").is_none());
    let p = parse(&BASE.replacen(
        "pga_g = [0.2, 0.4]",
        "pga_g = { from = 0.1, to = 1.0, n = 3, log = true }",
        1,
    ))
    .unwrap();
    let got: Vec<f64> = p
        .contact
        .spec
        .intensities
        .iter()
        .map(|i| match i {
            pounding::plan::Intensity::PgaG(g) => *g,
            _ => 0.0,
        })
        .collect();
    assert!(
        (got[1] - 0.1f64.sqrt()).abs() < 1e-12 && got[2] == 1.0 && got[0] == 0.1,
        "{got:?}"
    );
}

/// `window_s` keeps the samples inside the window on the record's own clock, and a window with
/// fewer than two samples is an error naming the record and the record's span.
#[test]
fn record_windows_cut_the_record() {
    let text = BASE.replacen(
        "synthetic = { seed = 2, duration_s = 5.0 }",
        "synthetic = { seed = 2, duration_s = 5.0, dt_s = 0.01 }\nwindow_s = [1.0, 2.5]",
        1,
    );
    let full = parse(
        BASE.replacen("duration_s = 5.0 }", "duration_s = 5.0, dt_s = 0.01 }", 1)
            .as_str(),
    )
    .unwrap();
    let cut = parse(&text).unwrap();
    let (f, c) = (&full.contact.spec.records[0], &cut.contact.spec.records[0]);
    assert_eq!(c.npts(), 151);
    assert!((c.t0 - 1.0).abs() < 1e-12, "t0 {}", c.t0);
    assert_eq!(c.accel[..], f.accel[100..=250]);
    let bad = BASE.replacen(
        "synthetic = { seed = 2, duration_s = 5.0 }",
        "synthetic = { seed = 2, duration_s = 5.0 }\nwindow_s = [4.0, 3.0]",
        1,
    );
    let e = parse(&bad).unwrap_err().to_string();
    assert!(
        e.contains("record[0]: window_s = [4, 3]: expected start < end"),
        "{e}"
    );
}
