//! Records scaled to spectral targets (`[intensity] sa_g`, `sa_avg_g`): each run's record, scaled
//! by its factor, has the target's Sa (or Sa_avg) at the periods the run reports, to 1e-12; a
//! period that follows a swept building gives each run its own factor; the CSV carries the
//! target, the periods and the factor; bad targets are refused by key.

use crate::support::{ok, pound, rel, tempdir};
use pounding::plan::config;
use pounding::record::intensity::{log_periods, sa, sa_avg};
use pounding::record::{Record, G};

const PAIR: &str = r#"
[building1]
mass_kg = 1.0e5
period_s = [0.3, 0.8]
damping_ratio = 0.05

[building2]
mass_kg = 1.0e5
period_s = [0.5, 1.1]
damping_ratio = 0.05

[contact]
law = "kelvin_voigt"
formula = "exact"
e = 0.65
k_n_per_m = 2.0e8
gap_m = 0.01

[[record]]
synthetic = { seed = 3, duration_s = 6.0, dt_s = 0.01 }

[[record]]
synthetic = { seed = 4, duration_s = 6.0, dt_s = 0.02 }
"#;

fn scaled(rec: &Record, s: f64) -> Record {
    Record {
        accel: rec.accel.iter().map(|a| a * s).collect(),
        ..rec.clone()
    }
}

fn write(dir: &std::path::Path, intensity: &str) -> std::path::PathBuf {
    let p = dir.join("sa.toml");
    std::fs::write(&p, format!("{PAIR}\n[intensity]\n{intensity}\n")).unwrap();
    p
}

#[test]
fn sa_targets_at_a_swept_building_period_scale_each_run_exactly() {
    let dir = tempdir();
    let plan = config::load_pair(&write(
        dir.path(),
        "sa_g = [0.2, 0.5]\nsa_period_s = \"building1\"",
    ))
    .unwrap();
    assert_eq!(plan.len(), 2 * 2 * 2 * 2);
    let mut factors = std::collections::HashSet::new();
    for i in 0..plan.len() {
        let r = plan.run(i);
        let target = r.intensity.value();
        assert_eq!(r.im_periods, Some([r.t1, r.t1]));
        let rec = scaled(&plan.contact.spec.records[r.record], r.scale);
        let got = sa(&rec, r.t1, 0.05) / G;
        assert!(
            rel(got, target) < 1e-12,
            "run {i}: Sa {got} g, target {target} g"
        );
        assert!(rel(r.pga_g, rec.pga().value / G) < 1e-14);
        factors.insert(r.scale.to_bits());
    }
    // Two records x two targets x two periods of building 1: eight factors.
    assert_eq!(factors.len(), 8);
}

#[test]
fn sa_avg_targets_over_multiples_of_both_buildings_periods() {
    let dir = tempdir();
    let plan = config::load_pair(&write(
        dir.path(),
        "sa_avg_g = 0.3\nsa_avg_periods_s = [\"0.2*building1\", \"3*building2\"]\nsa_avg_n = 6\nsa_damping = 0.02",
    ))
    .unwrap();
    for i in 0..plan.len() {
        let r = plan.run(i);
        let [from, to] = r.im_periods.unwrap();
        assert_eq!([from, to], [0.2 * r.t1, 3.0 * r.t2]);
        let rec = scaled(&plan.contact.spec.records[r.record], r.scale);
        let periods = log_periods(from, to, 6);
        let got = sa_avg(&rec, &periods, 0.02) / G;
        assert!(rel(got, 0.3) < 1e-12, "run {i}: Sa_avg {got} g");
        // The geometric mean of the Sa it averages.
        let logs: f64 = periods.iter().map(|&t| (sa(&rec, t, 0.02) / G).ln()).sum();
        assert!(rel((logs / 6.0).exp(), got) < 1e-12);
    }
}

#[test]
fn a_fixed_period_target_is_one_factor_per_record_and_level() {
    let dir = tempdir();
    let plan =
        config::load_pair(&write(dir.path(), "sa_g = [0.1, 0.4]\nsa_period_s = 1.0")).unwrap();
    for i in 0..plan.len() {
        let r = plan.run(i);
        let rec = &plan.contact.spec.records[r.record];
        let want = r.intensity.value() * G / sa(rec, 1.0, 0.05);
        assert!(rel(r.scale, want) < 1e-15, "run {i}");
        assert_eq!(r.im_periods, Some([1.0, 1.0]));
    }
}

#[test]
fn a_row_target_follows_its_own_buildings_fundamental_period() {
    let dir = tempdir();
    let cfg = dir.path().join("row.toml");
    let text = r#"
[[building]]
storeys = 3
storey_height_m = 3.0
mass_kg = 2.0e5
period_s = [0.3, 0.4]
damping_ratio = 0.05
gap_right_m = 0.02

[[building]]
storeys = 5
storey_height_m = 3.0
mass_kg = 2.0e5
period_s = 0.6
damping_ratio = 0.05
gap_right_m = 0.02

[[building]]
storeys = 2
storey_height_m = 3.0
mass_kg = 2.0e5
period_s = [0.2, 0.25]
damping_ratio = 0.05

[contact]
law = "kelvin_voigt"
formula = "exact"
e = 0.65
k_n_per_m = 2.0e8

[[record]]
synthetic = { seed = 5, duration_s = 5.0 }

[intensity]
sa_g = [0.3, 0.6]
sa_period_s = "building[2]"
"#;
    std::fs::write(&cfg, text).unwrap();
    let plan = config::load_row_text(text, &cfg).unwrap();
    assert_eq!(plan.len(), 2 * 2 * 2);
    for i in 0..plan.len() {
        let r = plan.run(i);
        let t = r.period[2];
        assert_eq!(r.contact.im_periods, Some([t, t]));
        let rec = scaled(&plan.contact.spec.records[0], r.contact.scale);
        assert!(rel(sa(&rec, t, 0.05) / G, r.contact.intensity.value()) < 1e-12);
    }
    // A warning of an absurd PGA reads the row's own period, not a placeholder's.
    let loud =
        config::load_row_text(&text.replace("sa_g = [0.3, 0.6]", "sa_g = 40.0"), &cfg).unwrap();
    let pga = loud.run(0).contact.pga_g;
    assert!(pga > 5.0);
    let w = loud.warnings().join("\n");
    assert!(w.contains(&format!("a PGA of {pga:.3} g")), "{pga}: {w}");
    // The CSV carries the target, the period and the factor.
    let csv = dir.path().join("row.csv");
    ok(&pound(&[
        "sweep",
        cfg.to_str().unwrap(),
        "-o",
        csv.to_str().unwrap(),
    ]));
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut lines = text.lines();
    let h: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |c: &str| h.iter().position(|x| *x == c).unwrap();
    for (i, line) in lines.enumerate() {
        let c: Vec<&str> = line.split(',').collect();
        let r = plan.run(i as u64);
        assert_eq!(
            c[col("target_sa_g")].parse::<f64>().unwrap(),
            r.contact.intensity.value()
        );
        assert_eq!(c[col("sa_period_s")], c[col("b3_t1_s")]);
        assert_eq!(
            c[col("scale_factor")].parse::<f64>().unwrap(),
            r.contact.scale
        );
        assert_eq!(c[col("target_pga_g")], "");
        assert_eq!(c[col("target_sa_avg_g")], "");
    }
}

#[test]
fn bad_spectral_targets_are_refused_by_key() {
    let dir = tempdir();
    for (intensity, key, says) in [
        ("sa_g = 0.3", "intensity.sa_period_s", "is missing"),
        (
            "sa_g = 0.3\nsa_period_s = \"building3\"",
            "intensity.sa_period_s",
            "the scene has 2 buildings",
        ),
        (
            "sa_g = 0.3\nsa_period_s = \"storey1\"",
            "intensity.sa_period_s",
            "expected a period in s",
        ),
        (
            "sa_g = 0.3\nsa_period_s = 500.0",
            "intensity.sa_period_s",
            "expected periods from",
        ),
        (
            "sa_g = 0.3\nsa_period_s = \"0.0001*building1\"",
            "intensity.sa_period_s",
            "expected periods from",
        ),
        (
            "sa_g = 0.3\npga_g = 0.3",
            "intensity",
            "give one of pga_g, scale, sa_g, sa_avg_g",
        ),
        (
            "sa_g = -0.3\nsa_period_s = 1.0",
            "intensity.sa_g[0]",
            "expected an Sa > 0 g",
        ),
        (
            "sa_g = 0.3\nsa_period_s = 1.0\nsa_avg_n = 5",
            "intensity.sa_avg_n",
            "does not apply to sa_g",
        ),
        (
            "pga_g = 0.3\nsa_period_s = 1.0",
            "intensity.sa_period_s",
            "applies to sa_g or sa_avg_g",
        ),
        (
            "sa_avg_g = 0.3\nsa_avg_periods_s = [0.5]",
            "intensity.sa_avg_periods_s",
            "expected two",
        ),
        (
            "sa_avg_g = 0.3\nsa_avg_periods_s = [0.5, 0.5]",
            "intensity.sa_avg_periods_s",
            "the same period",
        ),
        (
            "sa_avg_g = 0.3\nsa_avg_periods_s = [0.1, 2.0]\nsa_avg_n = 1",
            "intensity.sa_avg_n",
            "expected 2 to",
        ),
        (
            "sa_g = 0.3\nsa_period_s = 1.0\nsa_damping = 1.0",
            "intensity.sa_damping",
            "out of range",
        ),
    ] {
        let err = config::load_pair(&write(dir.path(), intensity))
            .unwrap_err()
            .to_string();
        assert!(
            err.contains(key) && err.contains(says),
            "{intensity}: {err}"
        );
    }
}
