//! The row's tests that run whole rows: yielding storeys ([`super::yielding`]) against their
//! closed forms, the elastic run and the reference scheme, in both schemes.

use super::algebra::dot;
use super::fast::RowFastOptions;
use super::model::RowModel;
use super::rhs::{rhs, Motion};
use super::storey::StoreyMode;
use super::{simulate_row, RowScheme};
use crate::physics::contact::LawKind;
use crate::physics::model::{Forcing, Status};
use crate::physics::row::{Row, RowOutput};
use crate::physics::shear::{Damping, ShearBuilding, Yielding};
use crate::physics::solver::ReferenceOptions;
use std::f64::consts::PI;

/// A one-storey building of mass `m` and period `t` (3 m storey), yielding at drift `d_y`
/// with post-yield ratio `b`.
fn sdof(m: f64, t: f64, xi: f64, d_y: f64, b: f64) -> ShearBuilding {
    let k = m * (2.0 * PI / t).powi(2);
    ShearBuilding {
        masses: vec![m],
        stiffness: vec![k],
        heights: vec![3.0],
        damping: Damping::Modal(xi),
        yielding: Some(Yielding {
            force: vec![k * d_y],
            post_yield: vec![b],
            deterioration: None,
        }),
        geometric: None,
        struck_column_share: None,
    }
}

/// `n` storeys of 3 m and 2.5e5 kg at period `t` (a soft first storey if `soft`), Rayleigh
/// 5 %, yielding at drift ratio `theta` (None: elastic) with post-yield ratio `b`.
fn tower(n: usize, t: f64, soft: bool, theta: Option<f64>, b: f64) -> ShearBuilding {
    let mut profile = vec![1.0; n];
    if soft {
        profile[0] = 0.4;
    }
    let mut s = ShearBuilding::from_period(
        vec![2.5e5; n],
        &profile,
        vec![3.0; n],
        t,
        Damping::Rayleigh(0.05),
    );
    s.yielding = theta
        .map(|th| Yielding::from_drift_ratio(&s.stiffness, &s.heights, &vec![th; n], vec![b; n]));
    s
}

/// The fast scheme at 64 substeps (these tests hold the yielding model to closed forms and
/// to the reference at 1e-7 to 5e-3; the default setting's error is the accuracy suites'
/// business, `configs/accuracy-inelastic.toml`), and the reference.
fn schemes() -> [RowScheme; 2] {
    [
        RowScheme::Fast(RowFastOptions {
            energy: true,
            substeps_per_contact: 64.0,
            ..RowFastOptions::default()
        }),
        RowScheme::Reference(ReferenceOptions {
            rtol: 1e-10,
            ..ReferenceOptions::default()
        }),
    ]
}

/// As the row fast scheme's tests: three frequencies under an envelope, 8 s at 0.01 s,
/// peak about 4.4 m/s^2, times `scale`.
fn ground_motion(scale: f64) -> Vec<f64> {
    (0..800)
        .map(|i| {
            let t = i as f64 * 0.01;
            let envelope = (t / 1.5).min(1.0) * (-(t - 4.0).max(0.0) / 2.0).exp();
            let w = 2.0 * PI;
            scale
                * envelope
                * (2.5 * (w * 1.1 * t).sin()
                    + 1.5 * (w * 2.3 * t + 0.4).sin()
                    + 1.0 * (w * 0.7 * t + 1.3).sin())
        })
        .collect()
}

fn forcing(accel: &[f64]) -> Forcing<'_> {
    Forcing {
        accel,
        dt: 0.01,
        t0: 0.0,
        scale: 1.0,
        tail: 1.0,
    }
}

fn relative(a: f64, b: f64) -> f64 {
    (a - b).abs() / a.abs().max(b.abs()).max(1e-300)
}

/// An elastic-perfectly-plastic, undamped storey set moving at `v0` from rest: elastic up
/// to `d_y`, then at the constant force `F_y` until the kinetic energy left at `d_y` is
/// spent, so `u_max = d_y + (m v0^2 / 2 - k d_y^2 / 2) / F_y`, the plastic drift (and the
/// residual drift) is `u_max - d_y`, the hysteretic energy `F_y (u_max - d_y)`; with
/// kinematic hardening `b`, the force past yield is `F_y + b k (u - d_y)` and the energy
/// balance gives `u_max` from a quadratic, the first excursion's hysteretic energy
/// `int f dp = (1 - b)(F_y x + b k x^2 / 2)`, `x = u_max - d_y`.
#[test]
fn a_storey_pushed_past_yield_follows_the_closed_form() {
    let (m, t, d_y, v0) = (1e5, 0.5, 0.01, 0.3);
    let k = m * (2.0 * PI / t).powi(2);
    let f_y = k * d_y;
    for b in [0.0, 0.1] {
        let row = Row::new(
            vec![sdof(m, t, 0.0, d_y, b), tower(1, 0.3, false, None, 0.0)],
            vec![10.0],
            LawKind::Linear,
            1e9,
            0.0,
        );
        let model = RowModel::new(&row);
        let z0 = model.state_of_floors(&[vec![0.0], vec![0.0]], &[vec![v0], vec![0.0]]);
        // Spent past yield: 1/2 m v0^2 - 1/2 k d_y^2 = F_y x + b k x^2 / 2.
        let spare = 0.5 * m * v0 * v0 - 0.5 * k * d_y * d_y;
        let x = if b == 0.0 {
            spare / f_y
        } else {
            (-f_y + (f_y * f_y + 2.0 * b * k * spare).sqrt()) / (b * k)
        };
        let hysteretic = (1.0 - b) * (f_y * x + 0.5 * b * k * x * x);
        let accel = vec![0.0; 201];
        for scheme in schemes() {
            let out = simulate_row(&model, &forcing(&accel), z0.clone(), &scheme);
            assert_eq!(out.status, Status::Ok);
            let bo = &out.buildings[0];
            let ie = bo.inelastic.expect("a yielding building");
            let what = format!("b {b}, {}", scheme.key());
            assert!(
                relative(bo.peak_drift_ratio * 3.0, d_y + x) < 1e-7,
                "{what}: peak drift {} against {}",
                bo.peak_drift_ratio * 3.0,
                d_y + x
            );
            assert!(
                relative(ie.peak_ductility, (d_y + x) / d_y) < 1e-7,
                "{what}"
            );
            // With hardening the swing back reaches the lower bounding line (the force
            // left, F_y + b k x, exceeds F_y): later excursions dissipate more.
            let first = relative(ie.hysteretic_energy, hysteretic);
            assert!(
                if b == 0.0 {
                    first < 1e-7
                } else {
                    ie.hysteretic_energy > hysteretic
                },
                "{what}: hysteretic {} against {hysteretic}",
                ie.hysteretic_energy
            );
            assert_eq!(ie.yielded_storeys, 1);
            assert!(out.energy.unwrap().residual.abs() < 1e-8, "{what}");
            // Undamped, it swings about its plastic drift for ever: the residual is p if
            // the energy bound closes, else not claimed.
            let r = ie.residual_drift_ratio;
            assert!(
                r.is_nan() || b > 0.0 || relative(r * 3.0, x) < 1e-7,
                "{what}: residual {r}"
            );
        }
    }
}

/// With damping, a yielding storey comes to rest at its plastic drift: the run settles
/// after the record and reports it, the same from both schemes.
#[test]
fn a_damped_storey_settles_at_its_plastic_drift() {
    let row = Row::new(
        vec![
            sdof(1e5, 0.5, 0.05, 0.01, 0.05),
            tower(1, 0.3, false, None, 0.0),
        ],
        vec![10.0],
        LawKind::Linear,
        1e9,
        0.0,
    );
    let model = RowModel::new(&row);
    let accel = ground_motion(1.0);
    let [fast, reference] =
        schemes().map(|s| simulate_row(&model, &forcing(&accel), model.at_rest(), &s));
    let (a, b) = (
        fast.buildings[0].inelastic.unwrap(),
        reference.buildings[0].inelastic.unwrap(),
    );
    assert!(a.yielded_storeys == 1 && b.yielded_storeys == 1);
    assert!(a.residual_drift_ratio > 1e-4, "{a:?}");
    assert!(
        relative(a.residual_drift_ratio, b.residual_drift_ratio) < 1e-5,
        "{a:?} {b:?}"
    );
    assert!(
        relative(a.hysteretic_energy, b.hysteretic_energy) < 1e-5,
        "{a:?} {b:?}"
    );
    assert!(fast.energy.unwrap().residual.abs() < 1e-8);
}

/// A yield force above any demand gives the elastic run, bit for bit.
#[test]
fn storeys_that_never_yield_give_the_elastic_run() {
    let accel = ground_motion(1.0);
    let scene = |theta: Option<f64>| {
        Row::new(
            vec![
                tower(8, 0.7, true, theta, 0.0),
                tower(6, 0.45, false, theta, 0.1),
                tower(2, 0.2, false, None, 0.0),
            ],
            vec![0.01, 0.005],
            LawKind::NonlinearViscoelastic,
            2.75e9,
            0.35,
        )
    };
    let strip = |mut o: RowOutput| {
        for b in o.buildings.iter_mut() {
            if let Some(ie) = b.inelastic.take() {
                assert_eq!(ie.yielded_storeys, 0);
            }
        }
        for st in std::mem::take(&mut o.storeys) {
            assert_eq!((st.residual_drift_ratio, st.hysteretic_energy), (0.0, 0.0));
        }
        o
    };
    for scheme in schemes() {
        let elastic = RowModel::new(&scene(None));
        let strong = RowModel::new(&scene(Some(10.0)));
        let a = simulate_row(&elastic, &forcing(&accel), elastic.at_rest(), &scheme);
        let b = simulate_row(&strong, &forcing(&accel), strong.at_rest(), &scheme);
        assert!(a.impacts > 0);
        assert_eq!(strip(b), a, "{}", scheme.key());
    }
}

/// Yielding storeys that pound (a soft first storey, b = 0, beside a stiff elastic
/// neighbour, and a third building): the fast scheme against the reference, and the energy
/// balance closing with the hysteretic work.
#[test]
fn yielding_while_pounding_matches_the_reference() {
    let accel = ground_motion(1.5);
    let row = Row::new(
        vec![
            tower(8, 0.7, true, Some(0.004), 0.0),
            tower(3, 0.2, false, None, 0.0),
            tower(6, 0.5, false, Some(0.005), 0.05),
        ],
        vec![0.01, 0.01],
        LawKind::NonlinearViscoelastic,
        2.75e9,
        0.35,
    );
    let model = RowModel::new(&row);
    let [fast, reference] =
        schemes().map(|s| simulate_row(&model, &forcing(&accel), model.at_rest(), &s));
    assert_eq!(fast.status, Status::Ok);
    assert_eq!(reference.status, Status::Ok);
    assert!(fast.impacts > 0);
    let mut worst: f64 = 0.0;
    for (a, b) in fast.buildings.iter().zip(&reference.buildings) {
        worst = worst.max(relative(a.peak_drift_ratio, b.peak_drift_ratio));
        if let (Some(x), Some(y)) = (a.inelastic, b.inelastic) {
            assert!(x.yielded_storeys > 0);
            assert_eq!(x.yielded_storeys, y.yielded_storeys);
            worst = worst.max(relative(x.residual_drift_ratio, y.residual_drift_ratio));
            worst = worst.max(relative(x.hysteretic_energy, y.hysteretic_energy));
            worst = worst.max(relative(x.peak_ductility, y.peak_ductility));
        }
    }
    worst = worst.max(relative(fast.peak_force, reference.peak_force));
    eprintln!("worst {worst:e}, impacts {}", fast.impacts);
    assert!(worst < 2e-3, "worst {worst}");
    assert!(fast.energy.unwrap().residual.abs() < 1e-6);
    assert!(reference.energy.unwrap().residual.abs() < 1e-6);
}

/// The largest relative difference of the yielding outputs, drifts and peak force between
/// two runs of one row.
fn worst_difference(a: &RowOutput, b: &RowOutput) -> f64 {
    let mut worst: f64 = relative(a.peak_force, b.peak_force);
    for (x, y) in a.buildings.iter().zip(&b.buildings) {
        worst = worst.max(relative(x.peak_drift_ratio, y.peak_drift_ratio));
        if let (Some(p), Some(q)) = (x.inelastic, y.inelastic) {
            assert_eq!(p.yielded_storeys, q.yielded_storeys);
            for (u, v) in [
                (p.residual_drift_ratio, q.residual_drift_ratio),
                (p.peak_ductility, q.peak_ductility),
                (p.hysteretic_energy, q.hysteretic_energy),
            ] {
                // A residual of a storey that barely yielded is measured against the
                // building's peak drift.
                let scale = u.abs().max(v.abs()).max(1e-3 * x.peak_drift_ratio);
                worst = worst.max((u - v).abs() / scale);
            }
        }
    }
    worst
}

/// Hard cases, fast against reference: an elastic-perfectly-plastic soft storey, yield at
/// the first record step (a ground step), yielding neighbours pounding from gap 0, a very
/// stiff elastic neighbour, and a 20-storey yielding frame beside a 10-storey one. Each
/// yields, ends well, settles, and agrees with the reference.
#[test]
fn hard_yielding_scenes_match_the_reference() {
    let step: Vec<f64> = (0..300).map(|i| if i < 50 { 3.0 } else { 0.0 }).collect();
    let quake = ground_motion(1.5);
    let scenes: Vec<(&str, Row, &[f64])> = vec![
        (
            "soft storey, b = 0",
            Row::new(
                vec![
                    tower(8, 0.7, true, Some(0.002), 0.0),
                    tower(2, 0.2, false, None, 0.0),
                ],
                vec![0.03],
                LawKind::NonlinearViscoelastic,
                2.75e9,
                0.35,
            ),
            &quake,
        ),
        (
            "yield at the first step",
            Row::new(
                vec![
                    tower(3, 0.4, false, Some(0.001), 0.0),
                    tower(3, 0.3, false, Some(0.001), 0.02),
                ],
                vec![0.002],
                LawKind::NonlinearViscoelastic,
                2.75e9,
                0.35,
            ),
            &step,
        ),
        (
            "yielding at gap 0",
            Row::new(
                vec![
                    tower(4, 0.5, false, Some(0.003), 0.02),
                    tower(4, 0.35, true, Some(0.003), 0.0),
                ],
                vec![0.0],
                LawKind::Hertz,
                2.75e9,
                0.0,
            ),
            &quake,
        ),
        (
            "very stiff elastic neighbour",
            Row::new(
                vec![
                    tower(6, 0.6, false, Some(0.003), 0.03),
                    tower(3, 0.05, false, None, 0.0),
                ],
                vec![0.005],
                LawKind::KelvinVoigt,
                1e9,
                0.3,
            ),
            &quake,
        ),
        (
            "20 storeys beside 10",
            Row::new(
                vec![
                    tower(20, 1.8, true, Some(0.003), 0.02),
                    tower(10, 1.0, false, Some(0.004), 0.02),
                ],
                vec![0.02],
                LawKind::NonlinearViscoelastic,
                2.75e9,
                0.35,
            ),
            &quake,
        ),
    ];
    for (name, row, accel) in scenes {
        let model = RowModel::new(&row);
        let [fast, reference] =
            schemes().map(|s| simulate_row(&model, &forcing(accel), model.at_rest(), &s));
        assert_eq!(fast.status, Status::Ok, "{name}");
        assert_eq!(reference.status, Status::Ok, "{name}");
        let yielded: u32 = fast
            .buildings
            .iter()
            .filter_map(|b| b.inelastic)
            .map(|i| i.yielded_storeys)
            .sum();
        assert!(yielded > 0, "{name}: nothing yielded");
        for b in fast.buildings.iter().filter_map(|b| b.inelastic) {
            assert!(b.residual_drift_ratio.is_finite(), "{name}: not settled");
        }
        let worst = worst_difference(&fast, &reference);
        let mu = fast
            .buildings
            .iter()
            .filter_map(|b| b.inelastic)
            .map(|i| i.peak_ductility)
            .fold(0.0, f64::max);
        eprintln!(
            "{name}: worst {worst:.1e}, {} impacts, {yielded} storeys yielded (ductility up to {mu:.1}), energy residual {:.1e}",
            fast.impacts,
            fast.energy.unwrap().residual
        );
        assert!(worst < 5e-3, "{name}: {worst}");
        assert!(fast.energy.unwrap().residual.abs() < 1e-6, "{name}");
    }
}

/// The plastic loads enter the floor-coordinate right-hand side as they enter the modal
/// one: every slot equal after the change of coordinates, with some storeys yielding.
#[test]
fn plastic_loads_are_the_same_in_floors_and_modes() {
    let row = Row::new(
        vec![
            tower(8, 0.7, true, Some(0.004), 0.1),
            tower(6, 0.45, false, Some(0.005), 0.0),
        ],
        vec![1.0],
        LawKind::Linear,
        1e9,
        0.0,
    );
    let m = RowModel::new(&row);
    let sub = m.substep_model().expect("tall Rayleigh buildings");
    let len = m.len();
    let mut z: Vec<f64> = (0..len)
        .map(|i| ((i * 7919 % 113) as f64 / 113.0 - 0.5) * 0.01)
        .collect();
    z[2 * m.n..m.plastic_slot(0)].fill(0.0);
    let modes: Vec<StoreyMode> = (0..m.storeys.len())
        .map(|s| match s % 3 {
            0 => StoreyMode::Elastic,
            1 => StoreyMode::Yielding(1.0),
            _ => StoreyMode::Yielding(-1.0),
        })
        .collect();
    let mut y = z.clone();
    sub.modes_to_substeps(&mut y);
    let motion = Motion {
        levels: &[],
        active: &[true; 2],
        energy: true,
        storeys: &modes,
    };
    let (mut fz, mut fy) = (vec![0.0; len], vec![0.0; len]);
    rhs(&m, &motion, 0.7, &z, &mut fz);
    rhs(&sub, &motion, 0.7, &y, &mut fy);
    sub.modes_to_substeps(&mut fz);
    for (i, (a, b)) in fz.iter().zip(&fy).enumerate() {
        assert!(
            (a - b).abs() <= 1e-9 * a.abs().max(1e-6),
            "slot {i}: {a} against {b}"
        );
    }
    for s in 0..m.storeys.len() {
        assert!(fz[m.plastic_slot(s)] != 0.0 || modes[s] == StoreyMode::Elastic);
    }
}

/// An elastic-perfectly-plastic storey with P-Delta (`theta = P / (k h) = 0.1`) set moving
/// outwards from its yield drift, with no ground motion: on its plateau the storey force is
/// `F_y - (P/h) d` (the softening slope `-P/h`), so `m d'' + c d' - (P/h) d = -F_y`, whose
/// solution runs away from `d_p = F_y h / P` exponentially; the run collapses when
/// `d = L h` (`L` the collapse drift ratio), at the time the closed form gives, with the
/// peak drift ratio `L`, no residual drift, and the same from both schemes.
#[test]
fn a_leaning_storey_past_yield_runs_away_and_collapses_as_the_closed_form() {
    let (m, t, d_y, v0, theta, limit) = (1e5, 0.5, 0.01, 0.6, 0.1, 0.1);
    let h = 3.0;
    for damping in [Damping::Modal(0.05), Damping::Rayleigh(0.05)] {
        let mut b = sdof(m, t, 0.05, d_y, 0.0);
        b.damping = damping;
        let k = b.stiffness[0];
        let g = theta * k;
        b.geometric = Some(vec![g]);
        // c: the elastic building's (Rayleigh on one storey: 2 xi m w0), or the ratio on
        // the P-Delta mode (modal).
        let w0 = (k / m).sqrt();
        let c = match damping {
            Damping::Rayleigh(x) => 2.0 * x * m * w0,
            Damping::Modal(x) => 2.0 * x * m * ((k - g) / m).sqrt(),
        };
        let row = Row::new(
            vec![b, tower(1, 0.3, false, None, 0.0)],
            vec![10.0],
            LawKind::Linear,
            1e9,
            0.0,
        )
        .with_collapse(limit);
        let model = RowModel::new(&row);
        let z0 = model.state_of_floors(&[vec![d_y], vec![0.0]], &[vec![v0], vec![0.0]]);
        // x = d - d_p: m x'' + c x' - g x = 0.
        let d_p = k * d_y / g;
        let disc = (c * c + 4.0 * m * g).sqrt();
        let (l1, l2) = ((-c + disc) / (2.0 * m), (-c - disc) / (2.0 * m));
        let x0 = d_y - d_p;
        let a = (v0 - l2 * x0) / (l1 - l2);
        assert!(a > 0.0, "the storey runs away");
        let x = |t: f64| a * (l1 * t).exp() + (x0 - a) * (l2 * t).exp();
        // x rises monotonically: bisect x(t) = L h - d_p.
        let target = limit * h - d_p;
        let (mut lo, mut hi) = (0.0, 10.0);
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if x(mid) < target {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let t_c = 0.5 * (lo + hi);
        assert!(t_c > 0.1 && t_c < 2.5, "{t_c}");
        let accel = vec![0.0; 301];
        for scheme in schemes() {
            let out = simulate_row(&model, &forcing(&accel), z0.clone(), &scheme);
            let what = format!("{damping:?}, {}", scheme.key());
            assert_eq!(out.status, Status::Collapsed, "{what}");
            let cl = out.collapse.expect("where it collapsed");
            assert_eq!((cl.building, cl.storey), (1, 1), "{what}");
            assert!(
                relative(cl.time, t_c) < 1e-6,
                "{what}: {} against {t_c}",
                cl.time
            );
            let bo = &out.buildings[0];
            assert!(
                relative(bo.peak_drift_ratio, limit) < 1e-9,
                "{what}: {}",
                bo.peak_drift_ratio
            );
            let ie = bo.inelastic.unwrap();
            assert!(
                ie.residual_drift_ratio.is_nan(),
                "{what}: no residual drift"
            );
            // The plateau's plastic work, F_y (d - d_y) at the collapse.
            assert!(
                relative(ie.hysteretic_energy, k * d_y * (limit * h - d_y)) < 1e-6,
                "{what}"
            );
        }
    }
}

/// Without a collapse limit the same storey runs on past it (a building that stands in
/// the model where a real one fell), as it did before collapse existed.
#[test]
fn without_a_collapse_limit_the_run_goes_on() {
    let mut b = sdof(1e5, 0.5, 0.05, 0.01, 0.0);
    b.geometric = Some(vec![0.1 * b.stiffness[0]]);
    let row = Row::new(
        vec![b, tower(1, 0.3, false, None, 0.0)],
        vec![10.0],
        LawKind::Linear,
        1e9,
        0.0,
    );
    let model = RowModel::new(&row);
    let z0 = model.state_of_floors(&[vec![0.01], vec![0.0]], &[vec![0.6], vec![0.0]]);
    let accel = vec![0.0; 101];
    let out = simulate_row(&model, &forcing(&accel), z0, &schemes()[0]);
    assert_ne!(out.status, Status::Collapsed);
    assert!(out.collapse.is_none());
    assert!(out.buildings[0].peak_drift_ratio > 0.1);
}
/// A storey's drift at rest from its building's plastic drifts: each plastic drift itself
/// without gravity (`D K^-1 D^T diag(k) = I` for a shear building), and with P-Delta the
/// static response to the plastic loads, `p / (1 - theta)` in one storey.
#[test]
fn residual_rows_give_the_static_drifts_gravity_leans_on() {
    let plain = tower(4, 0.6, true, Some(0.01), 0.03);
    let leaning = plain.clone().with_p_delta(3.0);
    for (b, lean) in [(plain, false), (leaning, true)] {
        let row = Row::new(
            vec![b, tower(1, 0.3, false, None, 0.0)],
            vec![1.0],
            LawKind::Linear,
            1e9,
            0.0,
        );
        let model = RowModel::new(&row);
        let mut z = model.at_rest();
        let p = [0.004, -0.002, 0.001, 0.003];
        for (s, &x) in p.iter().enumerate() {
            z[model.plastic_slot(s)] = x;
        }
        let mut qs = vec![0.0; model.n];
        model.static_offsets(&z, &mut qs);
        for s in 0..4 {
            let (first, c) = model.residual_row(s);
            assert_eq!(first, 0);
            let d: f64 = c.iter().zip(&p).map(|(c, p)| c * p).sum();
            let d_s = dot(&model.storeys[s].modal_row, &qs);
            assert!(
                (d - d_s).abs() < 1e-12 * p[0].abs(),
                "storey {s}: {d} {d_s}"
            );
            if !lean {
                assert!((d - p[s]).abs() < 1e-12, "storey {s}: {d} against {}", p[s]);
            } else {
                assert!(
                    (d - p[s]).abs() > 1e-6 * p[s].abs(),
                    "gravity leans on storey {s}"
                );
            }
        }
    }
    let mut one = sdof(1e5, 0.5, 0.05, 0.01, 0.0);
    let k = one.stiffness[0];
    one.geometric = Some(vec![0.2 * k]);
    let row = Row::new(
        vec![one, tower(1, 0.3, false, None, 0.0)],
        vec![1.0],
        LawKind::Linear,
        1e9,
        0.0,
    );
    let (_, c) = RowModel::new(&row).residual_row(0);
    assert!((c[0] - 1.0 / 0.8).abs() < 1e-12, "{}", c[0]);
}
