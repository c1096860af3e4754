//! The struck column as a column (issue 68, physics.md section 11): `struck_column_share`
//! puts the struck columns' local stiffness `k_loc = alpha k_j / (4 xi^3 (1 - xi)^3)` in series
//! with the contact. Checked against a fixed-fixed beam under a point load (two Euler-Bernoulli
//! elements), against the linear law's `k_eff` in closed form with its continuity at the storey's
//! ends, and against OpenSees with explicit fixed-fixed columns split at the impact point
//! (`benches/opensees_struck_column.py`, `tests/data/opensees_struck_column.toml`).

use crate::support::{floats, ok, pound, records_dir, sweep_cpu, table, tempdir};
use pounding::physics::contact::LawKind;
use pounding::physics::row::{local_stiffness, struck_side, LevelRule, Row};
use pounding::physics::shear::{Damping, ShearBuilding};

/// The lateral stiffness at `a` along a member of length `l`, fixed (no displacement, no
/// rotation) at both ends, of bending stiffness `ei`: two Euler-Bernoulli elements meeting
/// there, their 2x2 stiffness at the free point's displacement and rotation, the rotation
/// condensed out.
fn beam_point_stiffness(ei: f64, l: f64, a: f64) -> f64 {
    // An element of length `h`, its end at the point: [[12, 6h], [6h, 4h^2]] EI / h^3 for
    // the near end's (v, theta), the sign of the coupling by which end it is.
    let part = |h: f64, sign: f64| {
        let c = ei / (h * h * h);
        [12.0 * c, sign * 6.0 * h * c, 4.0 * h * h * c]
    };
    let (left, right) = (part(a, -1.0), part(l - a, 1.0));
    let (kvv, kvt, ktt) = (left[0] + right[0], left[1] + right[1], left[2] + right[2]);
    kvv - kvt * kvt / ktt
}

/// `local_stiffness` is the fixed-fixed member's stiffness under a point load (its lateral
/// stiffness `12 EI / h^3` shared as the key says), at points up the whole storey.
#[test]
fn the_local_stiffness_is_a_fixed_fixed_beams() {
    let (ei, h) = (3.2e8, 3.5);
    let k_col = 12.0 * ei / (h * h * h);
    for xi in [0.02, 1.0 / 6.0, 0.25, 1.0 / 3.0, 0.5, 0.6, 0.8, 0.97] {
        let ours = local_stiffness(k_col, xi);
        let beam = beam_point_stiffness(ei, h, xi * h);
        assert!(
            (ours - beam).abs() <= 1e-9 * beam,
            "xi {xi}: {ours} against the beam's {beam}"
        );
    }
    // 16 k_col at mid-height, 93.3 at a sixth (physics.md section 11).
    assert!((local_stiffness(k_col, 0.5) / k_col - 16.0).abs() < 1e-12);
    let sixth = local_stiffness(k_col, 1.0 / 6.0) / k_col;
    assert!((sixth - 93.312).abs() < 1e-9, "{sixth}");
}

/// Two buildings of unequal storeys (floors striking columns), building 2 with `alpha`.
fn row(alpha: Option<f64>, law: LawKind) -> Row {
    let b = |n: usize, h: f64, m: f64, t: f64| {
        ShearBuilding::from_period(
            vec![m; n],
            &vec![1.0; n],
            vec![h; n],
            t,
            Damping::Rayleigh(0.05),
        )
    };
    let struck = ShearBuilding {
        struck_column_share: alpha,
        ..b(4, 3.0, 3e5, 0.6)
    };
    Row::with_levels(
        vec![b(3, 3.5, 2e5, 0.45), struck],
        vec![0.01],
        law,
        1e9,
        0.0,
        LevelRule::default(),
    )
}

/// The linear law's contact stiffness at a level where a floor strikes a column of the
/// building with the key is `k k_loc / (k + k_loc)`; elsewhere (floor against floor, the other
/// building's columns, another law, no key) it is `k` to the bit.
#[test]
fn the_linear_law_takes_the_series_stiffness() {
    let rigid = row(None, LawKind::Linear);
    for alpha in [1.0, 0.25] {
        let r = row(Some(alpha), LawKind::Linear);
        let mut struck = 0;
        for (l, (a, b)) in r.levels.iter().zip(&rigid.levels).enumerate() {
            let k = b.contact.stiffness;
            match struck_side(&a.sides) {
                Some(side) if a.left + side == 1 => {
                    let storey = a.sides[side].floor - 1;
                    let k_j = r.buildings[1].stiffness[storey];
                    let k_loc = local_stiffness(alpha * k_j, a.sides[side].xi);
                    let k_eff = k * k_loc / (k + k_loc);
                    let got = a.contact.stiffness;
                    assert!(
                        (got - k_eff).abs() <= 1e-12 * k,
                        "level {l}: {got} vs {k_eff}"
                    );
                    assert!(got < k, "level {l}");
                    struck += 1;
                }
                _ => assert_eq!(a.contact, b.contact, "level {l}"),
            }
        }
        assert!(struck >= 2, "{struck} levels strike building 2's columns");
    }
    // Another law is left alone by the physics (the plan refuses the key with it).
    let hertz = row(Some(0.5), LawKind::Hertz);
    let hertz_rigid = row(None, LawKind::Hertz);
    assert_eq!(hertz.levels, hertz_rigid.levels);
}

/// As the struck point nears the storey's ends its local stiffness grows without bound and
/// the series stiffness returns to the contact's own: the point becomes the floor.
#[test]
fn the_series_stiffness_is_continuous_at_the_storeys_ends() {
    let (k, k_col) = (1e9, 2.7e8);
    let mut last = 0.0;
    for xi in [0.2, 0.1, 0.05, 0.02, 0.01, 0.001] {
        let k_loc = local_stiffness(k_col, xi);
        let k_eff = k * k_loc / (k + k_loc);
        assert!(k_eff > last, "xi {xi}: {k_eff} after {last}");
        last = k_eff;
        // The same from the top of the storey.
        let top = local_stiffness(k_col, 1.0 - xi);
        assert!(
            (top - k_loc).abs() <= 1e-6 * k_loc,
            "xi {xi}: {top} vs {k_loc}"
        );
    }
    assert!((k - last) / k < 1e-6, "{last}");
}

/// `pound sweep` with the key against OpenSees with explicit fixed-fixed columns split at the
/// impact point (model C of `benches/opensees_struck_column.py`, the linear law, massless
/// columns; the script's step error is 4.5e-4 at most), and without it against OpenSees with
/// pound's rigid point (model R): every level's peak force and impacts, each building's peak
/// drift ratio.
#[test]
fn linear_law_against_opensees_with_explicit_columns() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/opensees_struck_column.toml"
    );
    let data: toml::Table = std::fs::read_to_string(path).unwrap().parse().unwrap();
    let records = records_dir();
    let tmp = tempdir();
    let mut compared = 0;
    for scene in data["scene"].as_array().unwrap() {
        if scene["law"].as_str() != Some("linear") {
            continue;
        }
        let name = scene["name"].as_str().unwrap();
        let record = data["record"].as_str().unwrap();
        let base = scene["pound_config"].as_str().unwrap().replace(
            &format!("file = \"{record}\""),
            &format!("file = {:?}", records.join(record).to_str().unwrap()),
        );
        let levels: Vec<&str> = (scene["levels"].as_array().unwrap().iter())
            .map(|l| l.as_str().unwrap())
            .collect();
        for model in scene["model"].as_array().unwrap() {
            let (kind, alpha) = (
                model["model"].as_str().unwrap(),
                model["alpha"].as_float().unwrap(),
            );
            let text = match kind {
                "R" => base.clone(),
                "C" => {
                    // The key on the second building.
                    let at = base.rfind("[[building]]").unwrap() + "[[building]]".len();
                    format!(
                        "{}\nstruck_column_share = {alpha}{}",
                        &base[..at],
                        &base[at..]
                    )
                }
                _ => continue,
            };
            let cfg = tmp.path().join(format!("{name}-{kind}-{alpha}.toml"));
            std::fs::write(&cfg, &text).unwrap();
            let out = tmp.path().join(format!("{name}-{kind}-{alpha}.csv"));
            ok(&sweep_cpu(&cfg, &out, &[]));
            let rows = table(&out);
            let r = &rows[0];
            let value = |c: &str| -> f64 {
                r.get(c)
                    .unwrap_or_else(|| panic!("{c} not in the table"))
                    .parse()
                    .unwrap()
            };
            let forces = floats(&model["peak_force_n"]);
            let impacts: Vec<f64> = (model["impacts"].as_array().unwrap().iter())
                .map(|x| x.as_integer().unwrap() as f64)
                .collect();
            let mut worst: f64 = 0.0;
            for (l, level) in levels.iter().enumerate() {
                let f = value(&format!("{level}_peak_force_n"));
                worst = worst.max((f - forces[l]).abs() / forces[l]);
                assert_eq!(
                    value(&format!("{level}_impacts")),
                    impacts[l],
                    "{name} {kind} alpha {alpha}: {level} impacts"
                );
            }
            // The struck columns' shear: `alpha V` plus the contact's share on the key's
            // building, the storey's `V` on the other's (one floor strikes each storey here).
            let mut shear: f64 = 0.0;
            for (l, level) in levels.iter().enumerate() {
                let ours = value(&format!("{level}_column_shear_n"));
                let theirs = floats(&model["column_shear_n"])[l];
                shear = shear.max((ours - theirs).abs() / theirs);
            }
            for (k, d) in floats(&model["peak_drift_ratio"]).iter().enumerate() {
                let ours = value(&format!("b{}_peak_drift_ratio", k + 1));
                worst = worst.max((ours - d).abs() / d);
            }
            eprintln!("{name} {kind} alpha {alpha}: {worst:.1e}, column shear {shear:.1e}");
            assert!(
                worst <= 1e-4,
                "{name} {kind} alpha {alpha}: {worst:e} from OpenSees"
            );
            // OpenSees' column shear moves by up to 3.4e-4 between its two time steps (a
            // shallow contact's): its own step error.
            assert!(
                shear <= 1e-3,
                "{name} {kind} alpha {alpha}: column shear {shear:e} from OpenSees"
            );
            compared += 1;
        }
    }
    // R once, C at alpha 1 and 0.25.
    assert_eq!(compared, 3, "{compared} models compared");
}

/// The key's bounds, a law that cannot take it yet and a building no floor strikes at a
/// column are refused with the key named.
#[test]
fn the_key_is_refused_where_it_cannot_apply() {
    let text = |alpha: &str, law: &str, second: (usize, f64)| {
        format!(
            r#"
[[building]]
storeys = 3
storey_height_m = 3.5
mass_kg = 2e5
period_s = 0.45
damping_ratio = 0.05

[[building]]
storeys = {}
storey_height_m = {}
mass_kg = 3e5
period_s = 0.6
damping_ratio = 0.05
struck_column_share = {alpha}

[contact]
law = "{law}"
k_n_per_m = 1e9
beta_n_per_m1_5 = 2.75e9
e = 0.65
formula = "jankowski"
gap_m = 0.01

[[record]]
synthetic = {{ seed = 3, duration_s = 2.0, dt_s = 0.01, pga_g = 0.3 }}
"#,
            second.0, second.1
        )
    };
    let tmp = tempdir();
    let fails = |name: &str, t: String, expect: &[&str]| {
        let cfg = tmp.path().join(format!("{name}.toml"));
        std::fs::write(&cfg, t).unwrap();
        let out = pound(&["sweep", cfg.to_str().unwrap(), "-o", "/dev/null"]);
        assert!(!out.status.success(), "{name}");
        let err = String::from_utf8_lossy(&out.stderr);
        for e in expect {
            assert!(err.contains(e), "{name}: {e:?} not in {err}");
        }
    };
    fails(
        "zero",
        text("0", "linear", (4, 3.0)),
        &["struck_column_share", "expected a share > 0 and <= 1"],
    );
    fails(
        "above one",
        text("1.5", "linear", (4, 3.0)),
        &["struck_column_share", "out of range"],
    );
    fails(
        "hertzian",
        text("0.25", "nonlinear_viscoelastic", (4, 3.0)),
        &[
            "struck_column_share",
            "nonlinear_viscoelastic",
            "internal coordinate",
        ],
    );
    // Equal storeys: every level is floor against floor.
    fails(
        "no column struck",
        text("0.25", "linear", (3, 3.5)),
        &["struck_column_share", "no neighbour's floor strikes"],
    );
    // And with a linear law and columns struck, it runs.
    let cfg = tmp.path().join("good.toml");
    std::fs::write(&cfg, text("0.25", "linear", (4, 3.0))).unwrap();
    ok(&pound(&["sweep", cfg.to_str().unwrap(), "-o", "/dev/null"]));
}

/// With the key on a yielding struck building, the GPU row kernel in f64 gives the CPU's
/// level forces, column shears and column shear ratios (against `alpha F_y`), to 1e-9.
#[test]
fn the_gpu_takes_the_key_as_the_cpu() {
    if crate::support::gpu::ctx().is_none() {
        return;
    }
    let text = r#"
[[building]]
storeys = 3
storey_height_m = 3.5
mass_kg = 2e5
period_s = 0.45
damping_ratio = 0.05

[[building]]
storeys = 4
storey_height_m = 3.0
mass_kg = 3e5
period_s = 0.6
damping_ratio = 0.05
yield_drift_ratio = 0.003
post_yield_ratio = 0.02
struck_column_share = 0.25

[contact]
law = "linear"
k_n_per_m = 1e9
gap_m = 0.01

[[record]]
synthetic = { seed = 5, duration_s = 3.0, dt_s = 0.01, pga_g = 0.4 }
"#;
    let tmp = tempdir();
    let cfg = tmp.path().join("key.toml");
    std::fs::write(&cfg, text).unwrap();
    let run = |backend: &[&str], name: &str| {
        let out = tmp.path().join(name);
        let mut args = vec!["sweep", cfg.to_str().unwrap(), "-o", out.to_str().unwrap()];
        args.extend(backend);
        ok(&pound(&args));
        table(&out).remove(0)
    };
    let cpu = run(&["--backend", "cpu"], "cpu.csv");
    let gpu = run(&["--backend", "gpu", "--precision", "f64"], "gpu.csv");
    let mut compared = 0;
    for (k, v) in &cpu {
        let wanted = k.ends_with("_peak_force_n")
            || k.ends_with("_column_shear_n")
            || k.ends_with("_column_shear_ratio");
        if !(wanted && k.starts_with("level_")) {
            continue;
        }
        let (x, y): (f64, f64) = (v.parse().unwrap(), gpu[k].parse().unwrap());
        assert!(
            (x - y).abs() <= 1e-9 * x.abs().max(y.abs()),
            "{k}: cpu {x}, gpu {y}"
        );
        compared += 1;
    }
    assert!(compared >= 12, "{compared} columns compared");
}
