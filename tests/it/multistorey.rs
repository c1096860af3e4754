//! Rows of multi-storey shear buildings: analytic oracles first (modal closed form, an
//! independent physical-coordinate integration), then cross-checks between the schemes and
//! against the pair of oscillators, the energy balance and hard cases.

use crate::scenes::models::{building, forcing, record, single_storey_scenes};
use crate::scenes::ROW_CONFIG;
use crate::support::{floats, rel};
use pounding::physics::contact::LawKind;
use pounding::physics::model::{Forcing, Initial, Status};
use pounding::physics::row::{Row, RowOutput};
use pounding::physics::shear::{Damping, ShearBuilding};
use pounding::physics::solver::row::{simulate_row, RowModel, RowScheme};
use pounding::physics::solver::{simulate, FastOptions, ReferenceOptions, Scheme};
use std::f64::consts::PI;

fn schemes() -> [RowScheme; 2] {
    [
        RowScheme::Fast(FastOptions {
            energy: true,
            ..crate::support::precise_fast()
        }),
        RowScheme::Reference(ReferenceOptions::default()),
    ]
}

/// A row far apart: no level can touch.
fn alone(b: ShearBuilding) -> Row {
    let other = building(1, 0.3, Damping::Modal(0.05));
    Row::new(vec![b, other], vec![1e3], LawKind::Linear, 1e9, 0.0)
}

/// Free vibration of a 4-storey building with a soft first storey from initial floor
/// displacements and velocities: peak roof displacement and peak drift against the modal
/// closed form `q_i = e^(-xi w t) (q0 cos wd t + (q0' + xi w q0) / wd sin wd t)`, sampled
/// finely; the modes here come from the same decomposition, which the unit tests check against
/// the uniform building's closed form and `Phi^T K Phi`.
#[test]
fn free_vibration_peaks_match_the_modal_closed_form() {
    let b = ShearBuilding::from_period(
        vec![2e5, 2e5, 1.8e5, 1.5e5],
        &[0.4, 1.0, 0.9, 0.8],
        vec![4.5, 3.0, 3.0, 3.0],
        0.6,
        Damping::Rayleigh(0.05),
    );
    let md = b.modes();
    let u0 = vec![0.01, 0.03, 0.04, 0.05];
    let v0 = vec![-0.05, 0.02, 0.1, -0.2];
    let q0 = md.to_modes(&b.masses, &u0);
    let qd0 = md.to_modes(&b.masses, &v0);
    let floors_at = |t: f64| -> Vec<f64> {
        let q: Vec<f64> = (0..4)
            .map(|i| {
                let (w, xi) = (md.omega[i], md.xi[i]);
                let wd = w * (1.0 - xi * xi).sqrt();
                (-xi * w * t).exp()
                    * (q0[i] * (wd * t).cos() + (qd0[i] + xi * w * q0[i]) / wd * (wd * t).sin())
            })
            .collect();
        md.to_floors(&q)
    };
    let (mut roof, mut drift): (f64, f64) = (0.0, 0.0);
    for k in 0..=400_000 {
        let u = floors_at(k as f64 * 1e-5);
        roof = roof.max(u[3].abs());
        for j in 0..4 {
            let below = if j == 0 { 0.0 } else { u[j - 1] };
            drift = drift.max((u[j] - below).abs() / b.heights[j]);
        }
    }
    let row = alone(b.clone());
    let m = RowModel::new(&row);
    let zeros = vec![0.0; 401];
    let z0 = m.state_of_floors(&[u0.clone(), vec![0.0]], &[v0.clone(), vec![0.0]]);
    for scheme in schemes() {
        let out = simulate_row(&m, &forcing(&zeros), z0.clone(), &scheme);
        assert_eq!(out.status, Status::Ok);
        assert_eq!(out.impacts, 0);
        // The energy balance of free vibration: what was held at the start is held or damped.
        assert_peaks(
            &format!("{scheme:?}"),
            &out,
            [roof, drift, 0.0],
            [1e-7, 1e-7, 0.0],
        );
    }
}

/// Forced response of a uniform 5-storey building with Rayleigh damping, against an
/// independent integration in floor coordinates: dense `M`, `K` and `C = a0 M + a1 K` with
/// `w1`, `w2` from the uniform building's closed form, classic RK4 at 1e-4 s (1/100 of the
/// record step), peaks over its samples.
#[test]
fn forced_response_matches_an_independent_floor_integration() {
    let n = 5;
    let (mass, k) = (2.5e5, 3e8);
    let b = ShearBuilding {
        masses: vec![mass; n],
        stiffness: vec![k; n],
        heights: vec![3.5; n],
        damping: Damping::Rayleigh(0.05),
        yielding: None,
        geometric: None,
        struck_column_share: None,
    };
    let w = |i: usize| {
        2.0 * (k / mass).sqrt() * ((2 * i + 1) as f64 * PI / (2.0 * (2 * n + 1) as f64)).sin()
    };
    let (w1, w2) = (w(0), w(1));
    let a0 = 2.0 * 0.05 * w1 * w2 / (w1 + w2);
    let a1 = 2.0 * 0.05 / (w1 + w2);
    let mut kk = vec![vec![0.0; n]; n];
    for j in 0..n {
        kk[j][j] = k + if j + 1 < n { k } else { 0.0 };
        if j + 1 < n {
            kk[j][j + 1] = -k;
            kk[j + 1][j] = -k;
        }
    }
    let accel = record(7, 8.0, 0.3);
    let f = forcing(&accel);
    let ag = |t: f64| {
        let x = t / 0.01;
        let i = (x.floor() as usize).min(accel.len() - 2);
        let s = x - i as f64;
        accel[i] * (1.0 - s) + accel[i + 1] * s
    };
    let deriv = |t: f64, y: &[f64]| -> Vec<f64> {
        let mut d = vec![0.0; 2 * n];
        for j in 0..n {
            d[j] = y[n + j];
            let ku: f64 = (0..n).map(|l| kk[j][l] * y[l]).sum();
            let kv: f64 = (0..n).map(|l| kk[j][l] * y[n + l]).sum();
            let cv = a0 * mass * y[n + j] + a1 * kv;
            d[n + j] = (-ku - cv) / mass - ag(t);
        }
        d
    };
    let h = 1e-4;
    let steps = ((accel.len() - 1) as f64 * 0.01 / h).round() as usize;
    let mut y = vec![0.0; 2 * n];
    let (mut roof, mut drift, mut acc): (f64, f64, f64) = (0.0, 0.0, 0.0);
    for s in 0..steps {
        let t = s as f64 * h;
        let k1 = deriv(t, &y);
        let y2: Vec<f64> = (0..2 * n).map(|i| y[i] + 0.5 * h * k1[i]).collect();
        let k2 = deriv(t + 0.5 * h, &y2);
        let y3: Vec<f64> = (0..2 * n).map(|i| y[i] + 0.5 * h * k2[i]).collect();
        let k3 = deriv(t + 0.5 * h, &y3);
        let y4: Vec<f64> = (0..2 * n).map(|i| y[i] + h * k3[i]).collect();
        let k4 = deriv(t + h, &y4);
        for i in 0..2 * n {
            y[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
        }
        let d = deriv(t + h, &y);
        roof = roof.max(y[n - 1].abs());
        for j in 0..n {
            let below = if j == 0 { 0.0 } else { y[j - 1] };
            drift = drift.max((y[j] - below).abs() / 3.5);
            acc = acc.max((d[n + j] + ag(t + h)).abs());
        }
    }
    let row = alone(b);
    let m = RowModel::new(&row);
    for scheme in schemes() {
        let out = simulate_row(&m, &f, m.at_rest(), &scheme);
        assert_eq!(out.impacts, 0);
        assert_peaks(
            &format!("{scheme:?}"),
            &out,
            [roof, drift, acc],
            [1e-6, 1e-6, 1e-5],
        );
    }
}

/// Building 1's peak roof displacement, drift ratio and floor acceleration against `want`
/// within relative `tol` (a tolerance of 0 skips that output), and the energy balance closed.
fn assert_peaks(label: &str, out: &RowOutput, want: [f64; 3], tol: [f64; 3]) {
    let b = &out.buildings[0];
    let got = [b.peak_roof, b.peak_drift_ratio, b.peak_accel];
    for (k, name) in ["roof", "drift", "accel"].iter().enumerate() {
        if tol[k] > 0.0 {
            assert!(
                rel(got[k], want[k]) < tol[k],
                "{label} {name} {} vs {}",
                got[k],
                want[k]
            );
        }
    }
    if let Some(e) = out.energy {
        assert!(e.residual.abs() < 1e-9, "{label} {e:?}");
    }
}

/// A row of two single-storey buildings is the pair of oscillators: both schemes agree with
/// the pair's reference on every output, with pounding (four laws).
#[test]
fn single_storey_rows_are_the_pair() {
    let accel = record(3, 10.0, 0.4);
    let f = forcing(&accel);
    for (p, m) in single_storey_scenes() {
        let law = p.contact.kind;
        let truth = simulate(
            &p,
            &f,
            &Initial::default(),
            &Scheme::Reference(ReferenceOptions::default()),
        );
        assert!(truth.impacts > 0, "{law:?}: the scene must pound");
        for scheme in schemes() {
            let out = simulate_row(&m, &f, m.at_rest(), &scheme);
            let tol = match scheme {
                RowScheme::Fast(_) => 5e-3,
                RowScheme::Reference(_) => 1e-6,
            };
            assert_eq!(out.impacts, truth.impacts, "{law:?} {scheme:?}");
            assert!(
                rel(out.peak_force, truth.peak_force) < tol,
                "{law:?} {scheme:?}: {} vs {}",
                out.peak_force,
                truth.peak_force
            );
            assert!(rel(out.buildings[0].peak_roof, truth.peak_u1) < tol);
            assert!(rel(out.buildings[1].peak_roof, truth.peak_u2) < tol);
            // An elastic law's net contact work is a small difference of large ones: 1 J is its
            // scale there.
            let d = truth.dissipated_energy;
            assert!((out.dissipated_energy - d).abs() < 10.0 * tol * d.abs().max(1.0));
            assert!(
                (out.contact_time - truth.contact_time).abs() < 1e-6 + tol * truth.contact_time
            );
        }
    }
}

/// Identical neighbours at gap 0 move together: no level ever touches.
#[test]
fn identical_neighbours_at_gap_zero_never_pound() {
    let accel = record(11, 6.0, 0.5);
    let b = building(4, 0.5, Damping::Rayleigh(0.05));
    let row = Row::new(vec![b.clone(), b], vec![0.0], LawKind::Hertz, 2.75e9, 0.0);
    assert_eq!(row.levels.len(), 4);
    let m = RowModel::new(&row);
    for scheme in schemes() {
        let out = simulate_row(&m, &forcing(&accel), m.at_rest(), &scheme);
        assert_eq!(out.status, Status::Ok);
        assert_eq!(out.impacts, 0, "{scheme:?}");
        assert!(out.buildings[0].peak_roof > 0.01);
    }
}

fn compare(label: &str, fast: &RowOutput, truth: &RowOutput, tol: f64) {
    assert_eq!(fast.status, Status::Ok, "{label}");
    assert_eq!(truth.status, Status::Ok, "{label}");
    assert!(truth.impacts > 0, "{label}: the scene must pound");
    assert!(
        rel(fast.peak_force, truth.peak_force) < tol,
        "{label}: force {} vs {}",
        fast.peak_force,
        truth.peak_force
    );
    for (k, (a, b)) in fast.buildings.iter().zip(&truth.buildings).enumerate() {
        assert!(
            rel(a.peak_roof, b.peak_roof) < tol,
            "{label} building {k}: roof {} vs {}",
            a.peak_roof,
            b.peak_roof
        );
        assert!(
            rel(a.peak_drift_ratio, b.peak_drift_ratio) < tol,
            "{label} building {k}: drift"
        );
        assert!(
            rel(a.peak_accel, b.peak_accel) < 2.0 * tol,
            "{label} building {k}: accel {} vs {}",
            a.peak_accel,
            b.peak_accel
        );
    }
}

/// The hard scenes: a 3- against a 6-storey pair, 20 storeys beside 2, a soft first storey,
/// very stiff lower storeys, and a row of five. The fast scheme against the reference, and the
/// energy balance of both.
#[test]
fn hard_rows_fast_against_reference() {
    let accel = record(5, 10.0, 0.45);
    let f = forcing(&accel);
    let soft = ShearBuilding::from_period(
        vec![3e5; 5],
        &[0.3, 1.0, 1.0, 1.0, 1.0],
        vec![3.0; 5],
        0.7,
        Damping::Rayleigh(0.05),
    );
    let stiff_base = ShearBuilding::from_period(
        vec![3e5; 6],
        &[50.0, 50.0, 1.0, 1.0, 1.0, 1.0],
        vec![3.0; 6],
        0.5,
        Damping::Modal(0.05),
    );
    let scenes: Vec<(&str, Vec<ShearBuilding>, Vec<f64>)> = vec![
        (
            "3 vs 6",
            vec![
                building(3, 0.35, Damping::Rayleigh(0.05)),
                building(6, 0.8, Damping::Rayleigh(0.05)),
            ],
            vec![0.01],
        ),
        (
            "20 vs 2",
            vec![
                building(20, 2.0, Damping::Rayleigh(0.05)),
                building(2, 0.2, Damping::Rayleigh(0.05)),
            ],
            vec![0.005],
        ),
        (
            "soft storey",
            vec![soft, building(4, 0.4, Damping::Modal(0.05))],
            vec![0.01],
        ),
        (
            "stiff base",
            vec![building(6, 0.9, Damping::Modal(0.02)), stiff_base],
            vec![0.005],
        ),
        (
            "row of five",
            vec![
                building(3, 0.3, Damping::Rayleigh(0.05)),
                building(5, 0.6, Damping::Rayleigh(0.05)),
                building(4, 0.35, Damping::Rayleigh(0.05)),
                building(6, 0.9, Damping::Rayleigh(0.05)),
                building(2, 0.2, Damping::Rayleigh(0.05)),
            ],
            vec![0.01, 0.01, 0.01, 0.01],
        ),
    ];
    for (label, bs, gaps) in scenes {
        let row = Row::new(bs, gaps, LawKind::NonlinearViscoelastic, 2.75e9, 0.35);
        let m = RowModel::new(&row);
        let [fast, reference] = schemes().map(|s| simulate_row(&m, &f, m.at_rest(), &s));
        // Measured: 3e-4 at most on force, roofs and drifts, 6e-4 on floor accelerations.
        compare(label, &fast, &reference, 3e-3);
        for (name, o) in [("fast", &fast), ("reference", &reference)] {
            let e = o.energy.expect("energy");
            // Measured: 1.3e-7 (fast), 6e-11 (reference).
            let bound = if name == "fast" { 2e-6 } else { 1e-9 };
            assert!(e.residual.abs() < bound, "{label} {name}: {e:?}");
        }
    }
}

/// Against OpenSees (`benches/opensees_multistorey.py`, data in
/// `tests/data/opensees_multistorey.toml`): three scenes on three real records, linear
/// compression-only contact at every shared floor level, Rayleigh damping. OpenSees
/// (Newmark average acceleration) at dt and dt / 2 states its own error; the reference must
/// agree with its finer run to a few times that, plus the error its peaks take from sampling
/// only at its steps.
#[test]
fn opensees_cross_check() {
    use pounding::record::{read_record, ReadOptions};
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/opensees_multistorey.toml"
    );
    let data: toml::Table = std::fs::read_to_string(path).unwrap().parse().unwrap();
    let k = data["contact_k_n_per_m"].as_float().unwrap();
    let xi = data["damping_ratio"].as_float().unwrap();
    let dir = crate::support::records_dir();
    for scene in data["scene"].as_array().unwrap() {
        let name = scene["name"].as_str().unwrap();
        let buildings = scene["building"]
            .as_array()
            .unwrap()
            .iter()
            .map(|b| ShearBuilding {
                masses: floats(&b["masses_kg"]),
                stiffness: floats(&b["stiffness_n_per_m"]),
                heights: floats(&b["heights_m"]),
                damping: Damping::Rayleigh(xi),
                yielding: None,
                geometric: None,
                struck_column_share: None,
            })
            .collect();
        let row = Row::new(buildings, floats(&scene["gaps_m"]), LawKind::Linear, k, 0.0);
        let rec = read_record(
            &dir.join(scene["record"].as_str().unwrap()),
            &ReadOptions::default(),
        )
        .unwrap();
        let npts = scene["npts"].as_integer().unwrap() as usize;
        let f = Forcing {
            accel: &rec.accel[..npts],
            dt: rec.dt,
            t0: 0.0,
            scale: scene["scale"].as_float().unwrap(),
            tail: 0.0,
        };
        let m = RowModel::new(&row);
        // Measured: both schemes within 4.5e-6 of the largest value of each kind, where
        // OpenSees' own change from dt to dt / 2 is up to 8.5e-6.
        for (scheme, floor) in [
            (RowScheme::Reference(ReferenceOptions::default()), 2e-5),
            (RowScheme::Fast(FastOptions::default()), 1e-4),
        ] {
            let ours = simulate_row(&m, &f, m.at_rest(), &scheme);
            let check = |what: &str, got: &[f64], key: &str| {
                let fine = floats(&scene[key]);
                let coarse = floats(&scene[&format!("{key}_coarse")]);
                assert_eq!(got.len(), fine.len(), "{name} {what}");
                let scale = fine.iter().cloned().fold(0.0, f64::max);
                for (i, ((g, a), b)) in got.iter().zip(&fine).zip(&coarse).enumerate() {
                    let own = (a - b).abs();
                    assert!(
                        (g - a).abs() <= 4.0 * own + floor * scale,
                        "{name} {scheme:?} {what}[{i}]: pound {g} against OpenSees {a} (its own error {own})"
                    );
                }
            };
            let forces: Vec<f64> = ours.levels.iter().map(|l| l.peak_force).collect();
            check("peak force", &forces, "peak_force_n");
            let roofs: Vec<f64> = ours.buildings.iter().map(|b| b.peak_roof).collect();
            check("roof", &roofs, "peak_roof_m");
            let drifts: Vec<f64> = ours.buildings.iter().map(|b| b.peak_drift_ratio).collect();
            check("drift", &drifts, "peak_drift_ratio");
        }
    }
}

/// `pound sweep` of a `[[building]]` config: every run's row is the library's simulation of
/// the run its number decodes to (parameters and outputs, cell for cell), the header names each
/// building's and level's columns, and the sidecar vouches for the file.
#[test]
fn row_config_sweeps_to_csv_matching_the_library() {
    use pounding::physics::solver::row::simulate_row;
    let dir = crate::support::tempdir();
    let cfg = dir.path().join("row.toml");
    std::fs::write(&cfg, ROW_CONFIG).unwrap();
    let out = dir.path().join("row.csv");
    crate::support::ok(&crate::support::pound(&[
        "sweep",
        cfg.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--threads",
        "2",
    ]));
    let plan = pounding::plan::config::load_row_text(ROW_CONFIG, &cfg).unwrap();
    // 2 laws x 2 masses x 2 gaps x 2 periods (Hertz takes no formula or e).
    assert_eq!(plan.len(), 16);
    let mut rd = csv::Reader::from_path(&out).unwrap();
    let header: Vec<String> = rd.headers().unwrap().iter().map(String::from).collect();
    assert_eq!(header, plan.header());
    // Levels: building 1's floors 1, 2 meet building 2's (3 m, 6 m); building 2's floors at 3
    // and 6 m meet building 3's floors 1 and 2, building 3's roof (9 m) strikes building 2's
    // third storey's columns (6 to 9.5 m), and building 2's 9.5 m and 13 m floors, above
    // building 3's roof, meet nothing.
    for name in [
        "level_b1f1_b2f1_peak_force_n",
        "level_b1f2_b2f2_peak_force_n",
        "level_b2f1_b3f1_peak_force_n",
        "level_b2f2_b3f2_peak_force_n",
        "level_b2c3_b3f3_peak_force_n",
        "level_b2c3_b3f3_column_shear_n",
        "b2_peak_drift_ratio",
        "gap_2_3_m",
    ] {
        assert!(header.iter().any(|h| h == name), "{name} missing");
    }
    assert_eq!(
        header
            .iter()
            .filter(|h| h.starts_with("level_") && h.ends_with("_peak_force_n"))
            .count(),
        5
    );
    let rows: Vec<Vec<String>> = rd
        .records()
        .map(|r| r.unwrap().iter().map(String::from).collect())
        .collect();
    assert_eq!(rows.len(), 16);
    let scheme = plan.scheme();
    let mut pounded = 0;
    for (i, row) in rows.iter().enumerate() {
        let spec = plan.run(i as u64);
        let m = RowModel::new(&plan.row(&spec));
        let o = simulate_row(&m, &plan.forcing(&spec), m.at_rest(), &scheme);
        pounded += (o.impacts > 0) as usize;
        assert_eq!(row, &plan.cells(&spec, &o), "run {i}");
    }
    assert!(pounded > 0, "the sweep must pound");
    assert!(pounding::io::provenance::meta_path(&out).is_file());
    // The studies read the new columns.
    let svg = dir.path().join("drift.svg");
    crate::support::ok(&crate::support::pound(&[
        "plot",
        out.to_str().unwrap(),
        "--x",
        "gap_1_2_m",
        "--y",
        "b2_peak_drift_ratio",
        "--series",
        "law",
        "-o",
        svg.to_str().unwrap(),
    ]));
    assert!(svg.is_file());
}

/// Bad row configs: each error names the file, the key and what was expected; flags that
/// rows do not support are refused by name before anything runs.
#[test]
fn row_config_errors_name_the_key() {
    let dir = crate::support::tempdir();
    let cases: [(&str, &str, &str); 7] = [
        (
            "floor_masses_kg = [3e5, 3e5, 2.5e5, 2e5]",
            "floor_masses_kg = [3e5, 3e5]",
            "building[1].floor_masses_kg",
        ),
        (
            "mass_kg = 2e5\nperiod_s = 0.3",
            "period_s = 0.3",
            "building[2].mass_kg",
        ),
        ("storeys = 3", "storeys = 0", "building[2].storeys"),
        (
            "damping = \"modal\"",
            "damping = \"viscous\"",
            "building[1].damping",
        ),
        (
            "damping_ratio = 0.03",
            "damping_ratio = 0.03\ngap_right_m = 0.01",
            "building[2].gap_right_m",
        ),
        (
            "period_s = [0.5, 0.7]",
            "period_s = [0.5, -0.7]",
            "building[1].period_s[1]",
        ),
        (
            "stiffness_profile = [0.5, 1.0, 1.0, 0.8]",
            "stiffness_profile = [0.5, 1.0, 1.0]",
            "building[1].stiffness_profile",
        ),
    ];
    for (from, to, key) in cases {
        assert!(ROW_CONFIG.contains(from), "{from}");
        let cfg = dir.path().join("bad.toml");
        std::fs::write(&cfg, ROW_CONFIG.replacen(from, to, 1)).unwrap();
        let out = crate::support::pound(&["sweep", cfg.to_str().unwrap(), "-o", "-"]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{key}");
        assert!(
            err.contains("bad.toml") && err.contains(key),
            "{key}: {err}"
        );
    }
    let cfg = dir.path().join("row.toml");
    std::fs::write(&cfg, ROW_CONFIG).unwrap();
    let out = dir.path().join("row.csv");
    for flag in [
        // The row kernel runs the fast scheme without the energy balance.
        &["--backend", "gpu", "--energy"][..],
        &["--backend", "gpu", "--scheme", "reference"],
    ] {
        let mut args = vec!["sweep", cfg.to_str().unwrap(), "-o", out.to_str().unwrap()];
        args.extend_from_slice(flag);
        let o = crate::support::pound(&args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(
            !o.status.success() && err.contains(flag[0]),
            "{flag:?}: {err}"
        );
        assert!(!out.exists(), "{flag:?} wrote an output");
    }
}

/// The example configs load as rows, with the levels their comments describe.
#[test]
fn example_row_configs_load() {
    for (file, runs, levels) in [
        ("configs/row-3-6.toml", 180, 3),
        ("configs/row-of-three.toml", 128, 7),
    ] {
        let path = std::path::Path::new(file);
        let text = std::fs::read_to_string(path).unwrap();
        let pounding::plan::Plan::Row(plan) =
            pounding::plan::config::load_text(&text, path).unwrap()
        else {
            panic!("{file} loads as a pair");
        };
        assert_eq!(plan.len(), runs, "{file}");
        assert_eq!(plan.row(&plan.run(0)).levels.len(), levels, "{file}");
    }
}

/// `pound bench --storeys`: one line per storey count with every run of its sweep counted, on
/// the CPU and on the GPU adapter found (lavapipe in CI) with the share of its lanes busy; a
/// row the adapter cannot run is named and left out; a storey count out of range refused.
#[test]
fn bench_storeys_suite_times_each_storey_count() {
    let out = crate::support::pound(&["bench", "--storeys", "1,4", "--storey-runs", "20"]);
    let table = crate::support::ok(&out);
    let stderr = String::from_utf8_lossy(&out.stderr);
    let head: Vec<&str> = table
        .lines()
        .find(|l| l.starts_with("| storeys per building"))
        .expect("the table's header")
        .split('|')
        .map(str::trim)
        .collect();
    let col = |name: &str| head.iter().position(|c| *c == name).expect(name);
    let lines: Vec<&str> = table.lines().filter(|l| l.contains("cpu (")).collect();
    assert_eq!(lines.len(), 2, "{table}");
    for (line, n) in lines.iter().zip(["1", "4"]) {
        let cells: Vec<&str> = line.split('|').map(str::trim).collect();
        assert_eq!((cells[1], cells[2]), (n, "20"), "{line}");
        assert!(cells[col("runs/s")].parse::<f64>().unwrap() > 0.0, "{line}");
        for c in ["lanes busy", "pack s", "kernel s"] {
            assert_eq!(cells[col(c)], "-", "no {c} on the CPU: {line}");
        }
    }
    if crate::support::gpu::ctx().is_some() {
        let gpu: Vec<&str> = table.lines().filter(|l| l.contains("| gpu ")).collect();
        let one = gpu
            .iter()
            .find(|l| l.starts_with("| 1 |"))
            .expect("1-storey rows on the GPU");
        let cells: Vec<&str> = one.split('|').map(str::trim).collect();
        assert_eq!(cells[2], "20", "{one}");
        let busy: f64 = cells[col("lanes busy")]
            .trim_end_matches(" %")
            .parse()
            .unwrap();
        assert!(busy > 0.0 && busy <= 100.0, "{one}");
        let total: f64 = cells[col("total s")].parse().unwrap();
        let kernel: f64 = cells[col("kernel s")].parse().unwrap();
        assert!(kernel > 0.0 && kernel <= total, "{one}");
        assert!(
            gpu.iter().any(|l| l.starts_with("| 4 |")) || stderr.contains("4-storey rows on"),
            "the 4-storey rows are run or named: {table}\n{stderr}"
        );
    }
    let bad = crate::support::pound(&["bench", "--storeys", "0"]);
    assert!(!bad.status.success());
    assert!(String::from_utf8_lossy(&bad.stderr).contains("--storeys: 0"));
}

/// `pound accuracy` on a row config: the reference, then the fast scheme at each setting, as a
/// table and CSV; the fast scheme's errors fall with the setting and stay within what the
/// hard-case test measures at 64.
#[test]
fn accuracy_of_a_row_config() {
    let dir = crate::support::tempdir();
    let cfg = dir.path().join("row.toml");
    let text = ROW_CONFIG
        .replace("mass_kg = [2e5, 3e5]", "mass_kg = 2e5")
        .replace("duration_s = 5.0", "duration_s = 3.0");
    std::fs::write(&cfg, text).unwrap();
    let out = dir.path().join("acc.csv");
    let svg = dir.path().join("acc.svg");
    let table = crate::support::ok(&crate::support::pound(&[
        "accuracy",
        cfg.to_str().unwrap(),
        "--settings",
        "8,64",
        "-o",
        out.to_str().unwrap(),
        "--plot",
        svg.to_str().unwrap(),
    ]));
    // The work-precision plot: a series per quantity in each panel, and each setting marked
    // and named.
    let drawn = std::fs::read_to_string(&svg).unwrap();
    for name in [
        "peak force",
        "drift ratio",
        "floor acceleration",
        "99th percentile error",
        "\n8 substeps per contact\n",
        "\n64 substeps per contact\n",
    ] {
        assert!(drawn.contains(name), "{name} missing from the plot");
    }
    // The reference is not a setting of the fast scheme.
    assert!(!drawn.contains("\n0 substeps per contact\n"));
    let rows: Vec<Vec<String>> = csv::Reader::from_path(&out)
        .unwrap()
        .records()
        .map(|r| r.unwrap().iter().map(String::from).collect())
        .collect();
    assert_eq!(rows.len(), 3, "{table}");
    assert_eq!(rows[0][0], "reference");
    // Runs whose impact count differs are reported by their largest count difference and
    // peak-force error (none for the reference against itself).
    assert_eq!(&rows[0][15..17], ["0", "0"]);
    for r in &rows[1..] {
        let gap: u32 = r[15].parse().unwrap();
        let force: f64 = r[16].parse().unwrap();
        assert_eq!(gap == 0, force == 0.0 && r[11] == "0", "{table}");
    }
    // The runs whose error rose with the setting (issue 46): none at the first setting, which
    // has none before it; every row counts them.
    let header = csv::Reader::from_path(&out)
        .unwrap()
        .headers()
        .unwrap()
        .clone();
    assert_eq!(&header[17], "not_converging");
    assert_eq!(&rows[0][17], "0");
    assert_eq!(&rows[1][17], "0");
    let rose: usize = rows[2][17].parse().unwrap();
    assert_eq!(
        rose,
        table
            .lines()
            .filter(|l| l.starts_with("not converging: run"))
            .count(),
        "{table}"
    );
    let p99 = |r: &[String], col: usize| r[col].parse::<f64>().unwrap();
    // Columns: force p99 (4), roof p99 (6), drift p99 (8).
    for col in [4, 6, 8] {
        assert!(
            p99(&rows[2], col) <= p99(&rows[1], col),
            "column {col}: {table}"
        );
        assert!(p99(&rows[2], col) < 3e-3, "column {col}: {table}");
    }
    assert_eq!(
        table
            .lines()
            .filter(|l| l.starts_with("| cpu-fast-f64"))
            .count(),
        2
    );
    // `--target-error` runs the setting the rows' calibration chooses and fails exactly when
    // the error it measures is above the target.
    let o = crate::support::pound(&[
        "accuracy",
        cfg.to_str().unwrap(),
        "--target-error",
        "1e-3",
        "-o",
        out.to_str().unwrap(),
    ]);
    let said = String::from_utf8_lossy(&o.stdout);
    let chosen = pounding::physics::solver::calibration::for_target_in(
        pounding::physics::solver::calibration::Suite::Rows,
        1e-3,
    )
    .unwrap();
    let line = said
        .lines()
        .find(|l| {
            l.starts_with(&format!(
                "--target-error 1e-3: {} substeps per contact, cpu-fast-f64",
                chosen.substeps_per_contact
            ))
        })
        .unwrap_or_else(|| panic!("{said}"));
    let measured: f64 = line
        .split("p99 peak-force error ")
        .nth(1)
        .and_then(|t| t.split(' ').next())
        .unwrap()
        .parse()
        .unwrap();
    assert_eq!(o.status.success(), measured <= 1e-3, "{said}");
    assert_eq!(line.ends_with("(met)"), o.status.success(), "{line}");
}

/// `rows` (single-storey) against the pair's fast scheme on `accel`: the same impacts and
/// substeps, and peaks, contact time and dissipated energy within `tol`.
pub fn assert_rows_are_the_pair_fast(
    label: &str,
    scenes: &[(pounding::physics::model::Pair, RowModel)],
    rows: &[RowOutput],
    accel: &[f64],
    tol: f64,
) {
    let f = forcing(accel);
    for ((p, _), r) in scenes.iter().zip(rows) {
        let pf = simulate(
            p,
            &f,
            &Initial::default(),
            &Scheme::Fast(FastOptions::default()),
        );
        let law = p.contact.kind;
        assert_eq!(
            (r.impacts, r.substeps),
            (pf.impacts, pf.substeps),
            "{label} {law:?}"
        );
        for (name, a, b) in [
            ("peak force", r.peak_force, pf.peak_force),
            ("u1", r.buildings[0].peak_roof, pf.peak_u1),
            ("u2", r.buildings[1].peak_roof, pf.peak_u2),
            ("contact time", r.contact_time, pf.contact_time),
            ("dissipated", r.dissipated_energy, pf.dissipated_energy),
            ("impact velocity", r.impact_velocity, pf.impact_velocity),
        ] {
            // The net contact work of an elastic law is a small difference of large ones: 1 J
            // is its scale there.
            let scale = if name == "dissipated" {
                b.abs().max(1.0)
            } else {
                a.abs().max(b.abs())
            };
            assert!(
                (a - b).abs() <= tol * scale,
                "{label} {law:?} {name}: {a} vs {b}"
            );
        }
    }
}

/// N = 1 to rounding: the row fast scheme on single-storey rows takes the pair fast scheme's
/// steps (the same impacts and substeps) and reports its peaks to rounding. Measured: 2e-15
/// (linear) to 1.6e-9 (nonlinear viscoelastic: modal and physical coordinates round apart,
/// and the gap grows through 14 impacts).
#[test]
fn single_storey_rows_are_the_pair_fast_scheme_to_rounding() {
    let accel = record(3, 10.0, 0.4);
    let f = forcing(&accel);
    let scenes = single_storey_scenes();
    let rows: Vec<RowOutput> = scenes
        .iter()
        .map(|(_, m)| simulate_row(m, &f, m.at_rest(), &RowScheme::Fast(FastOptions::default())))
        .collect();
    assert_rows_are_the_pair_fast("cpu", &scenes, &rows, &accel, 1e-8);
}

/// `--columns` on a row sweep writes the chosen columns (`run` first, in the order given) with
/// the full sweep's values; a name that is not one of the row's columns is refused with the list.
#[test]
fn row_sweep_writes_the_chosen_columns() {
    let dir = crate::support::tempdir();
    let cfg = dir.path().join("row.toml");
    std::fs::write(&cfg, ROW_CONFIG).unwrap();
    let sweep = |name: &str, extra: &[&str]| -> Vec<Vec<String>> {
        let out = dir.path().join(name);
        let mut args = vec!["sweep", cfg.to_str().unwrap(), "-o", out.to_str().unwrap()];
        args.extend_from_slice(extra);
        crate::support::run::ok(&crate::support::pound(&args));
        std::fs::read_to_string(&out)
            .unwrap()
            .lines()
            .map(|l| l.split(',').map(String::from).collect())
            .collect()
    };
    let full = sweep("full.csv", &[]);
    let level = full[0]
        .iter()
        .rev()
        .find(|c| c.starts_with("level_"))
        .unwrap()
        .clone();
    let chosen = ["b2_peak_drift_ratio", "impacts", level.as_str()];
    let sub = sweep("sub.csv", &["--columns", &chosen.join(",")]);
    let want: Vec<&str> = ["run"].into_iter().chain(chosen).collect();
    assert_eq!(sub[0], want);
    assert_eq!(sub.len(), full.len());
    for (s, f) in sub[1..].iter().zip(&full[1..]) {
        for (k, name) in want.iter().enumerate() {
            let at = full[0].iter().position(|c| c == name).unwrap();
            assert_eq!(s[k], f[at], "{name}");
        }
    }
    let out = dir.path().join("bad.csv");
    let o = crate::support::pound(&[
        "sweep",
        cfg.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--columns",
        "peak_u1_m",
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success());
    assert!(
        err.contains("`peak_u1_m` is not a column of this sweep (a row of 3 buildings")
            && err.contains("b1_peak_roof_m")
            && err.contains("`pound columns CONFIG --all`"),
        "{err}"
    );
    assert!(!out.exists());
}
