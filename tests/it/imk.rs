//! Deteriorating (IMK) storeys in whole rows (issue 67, physics.md section 13): a push past
//! capping against its closed form, and every run's convergence with the substeps (8 to 512)
//! against the reference, on IMK scenes with and without contact, with and without P-Delta
//! (standing and collapsing), past capping and on the residual plateau, both hysteresis rules;
//! those that stand apart settle (their residual drifts given).

use crate::convergence::{cpu_failures, fast, low_frame, row, soft_frame, truths, Scene};
use crate::scenes::models::{building, record};
use pounding::physics::contact::LawKind;
use pounding::physics::model::{Forcing, Status};
use pounding::physics::row::Row;
use pounding::physics::shear::{Damping, Deterioration, ImkRule, ShearBuilding, Yielding};
use pounding::physics::solver::row::{simulate_row, RowModel, RowScheme};
use pounding::physics::solver::ReferenceOptions;

/// The IMK ratios of a storey: theta_p, theta_pc, kappa, theta_u, gamma.
#[derive(Clone, Copy)]
pub(crate) struct Imk {
    pub theta_p: f64,
    pub theta_pc: f64,
    pub kappa: f64,
    pub theta_u: f64,
    pub gamma: Option<f64>,
}

/// `s` with every storey an IMK spring of `rule`: yield drift ratio `theta`, hardening `b`.
pub(crate) fn imk(
    mut s: ShearBuilding,
    rule: ImkRule,
    theta: f64,
    b: f64,
    r: Imk,
) -> ShearBuilding {
    let n = s.storeys();
    let mut y = Yielding::from_drift_ratio(&s.stiffness, &s.heights, &vec![theta; n], vec![b; n]);
    y.deterioration = Some(Deterioration {
        rule,
        plastic: vec![r.theta_p; n],
        post_capping: vec![r.theta_pc; n],
        residual: vec![r.kappa; n],
        ultimate: vec![r.theta_u; n],
        energy: r.gamma.map(|g| vec![g; n]),
    });
    s.yielding = Some(y);
    s
}

const RC: Imk = Imk {
    theta_p: 0.01,
    theta_pc: 0.05,
    kappa: 0.2,
    theta_u: 0.1,
    gamma: Some(40.0),
};

/// An undamped one-storey IMK building set moving at `v0` from rest goes up its backbone
/// until the kinetic energy is spent: past capping, `1/2 m v0^2 = 1/2 k d_y^2 + (F_y + F_c)
/// u_p / 2 + F_c x - s x^2 / 2` (`x` past the capping drift, `s = F_c / u_pc` the falling
/// slope), a free flight with a negative tangent located to the capping event.
#[test]
fn a_storey_pushed_past_capping_follows_the_closed_form() {
    let (m, t, h, theta) = (1e5, 0.5, 3.0, 0.004);
    for rule in [ImkRule::Bilinear, ImkRule::PeakOriented] {
        let mut b = imk(building(1, t, Damping::Modal(0.0)), rule, theta, 0.05, RC);
        b.masses = vec![m];
        let w = 2.0 * std::f64::consts::PI / t;
        b.stiffness = vec![m * w * w];
        let b = imk(b, rule, theta, 0.05, RC);
        let k = b.stiffness[0];
        let (d_y, u_p, u_pc) = (theta * h, RC.theta_p * h, RC.theta_pc * h);
        let (f_y, f_c) = (k * d_y, k * d_y + 0.05 * k * u_p);
        let s = f_c / u_pc;
        let x_want = 0.3 * u_pc;
        let spare = f_c * x_want - 0.5 * s * x_want * x_want;
        let e0 = 0.5 * k * d_y * d_y + 0.5 * (f_y + f_c) * u_p + spare;
        let v0 = (2.0 * e0 / m).sqrt();
        let row = Row::new(
            vec![b, building(1, 0.3, Damping::Modal(0.05))],
            vec![10.0],
            LawKind::Linear,
            1e9,
            0.0,
        );
        let model = RowModel::new(&row);
        let z0 = model.state_of_floors(&[vec![0.0], vec![0.0]], &[vec![v0], vec![0.0]]);
        let accel = vec![0.0; 201];
        let forcing = Forcing {
            accel: &accel,
            dt: 0.01,
            t0: 0.0,
            scale: 1.0,
            tail: 1.0,
        };
        let schemes = [
            RowScheme::Fast(fast(64.0)),
            RowScheme::Reference(ReferenceOptions::with_tol(1e-10)),
        ];
        for scheme in schemes {
            let out = simulate_row(&model, &forcing, z0.clone(), &scheme);
            assert_eq!(out.status, Status::Ok);
            let peak = out.buildings[0].peak_drift_ratio * h;
            let want = d_y + u_p + x_want;
            assert!(
                (peak - want).abs() < 1e-7 * want,
                "{rule:?}, {}: peak drift {peak} against {want}",
                scheme.key()
            );
        }
    }
}

/// IMK scenes (the GPU takes those of low buildings: `gpu_imk`).
pub(crate) fn scenes() -> Vec<Scene> {
    let synth = |seed, seconds, pga_g| (record(seed, seconds, pga_g), 0.01);
    let mut out = Vec::new();
    let mut push = |name, model, (accel, dt): (Vec<f64>, f64), pounds, collapses| {
        out.push(Scene {
            name,
            model,
            accel,
            dt,
            pounds,
            collapses,
        })
    };
    let bilin = ImkRule::Bilinear;
    let peak = ImkRule::PeakOriented;
    push(
        "IMK bilinear storey past capping in free flight (gap 2 m)",
        row(
            vec![
                imk(
                    building(1, 0.6, Damping::Modal(0.05)),
                    bilin,
                    0.004,
                    0.03,
                    RC,
                ),
                building(1, 0.3, Damping::Modal(0.05)),
            ],
            vec![2.0],
            LawKind::Linear,
        ),
        synth(11, 8.0, 0.9),
        false,
        false,
    );
    push(
        "IMK peak-oriented storeys pounding (gap 1 cm)",
        row(
            vec![
                imk(
                    building(2, 0.5, Damping::Modal(0.05)),
                    peak,
                    0.004,
                    0.03,
                    RC,
                ),
                imk(
                    building(1, 0.3, Damping::Modal(0.05)),
                    bilin,
                    0.003,
                    0.0,
                    RC,
                ),
            ],
            vec![0.01],
            LawKind::NonlinearViscoelastic,
        ),
        synth(5, 8.0, 0.7),
        true,
        false,
    );
    push(
        "IMK soft frame (Rayleigh, floor substeps) beside a low IMK frame at gap 1 mm, no energy rule",
        row(
            vec![
                imk(soft_frame(), peak, 0.005, 0.03, Imk { gamma: None, ..RC }),
                imk(low_frame(), bilin, 0.004, 0.0, Imk { gamma: None, ..RC }),
            ],
            vec![0.001],
            LawKind::NonlinearViscoelastic,
        ),
        synth(3, 8.0, 0.45),
        true,
        false,
    );
    push(
        "IMK peak-oriented storey onto its residual plateau (theta_pc 0.015, kappa 0.3, no ultimate drift)",
        row(
            vec![
                imk(
                    building(1, 0.6, Damping::Modal(0.05)),
                    peak,
                    0.004,
                    0.02,
                    Imk {
                        theta_pc: 0.015,
                        kappa: 0.3,
                        theta_u: f64::INFINITY,
                        ..RC
                    },
                ),
                building(1, 0.3, Damping::Modal(0.05)),
            ],
            vec![2.0],
            LawKind::Linear,
        ),
        synth(8, 8.0, 0.9),
        false,
        false,
    );
    push(
        "IMK P-Delta storey past capping that stands (gravity mass ratio 0.3, energy rule)",
        row(
            vec![
                imk(
                    building(1, 0.6, Damping::Modal(0.05)),
                    peak,
                    0.004,
                    0.03,
                    RC,
                )
                .with_p_delta(0.3),
                building(1, 0.3, Damping::Modal(0.05)),
            ],
            vec![2.0],
            LawKind::Linear,
        ),
        synth(11, 8.0, 0.7),
        false,
        false,
    );
    out.push(Scene {
        name: "IMK P-Delta frame that collapses (gravity mass ratio 3)",
        model: RowModel::new(
            &Row::new(
                vec![
                    imk(
                        building(3, 0.9, Damping::Rayleigh(0.05)),
                        peak,
                        0.004,
                        0.01,
                        RC,
                    )
                    .with_p_delta(3.0),
                    building(2, 0.3, Damping::Modal(0.05)),
                ],
                vec![0.02],
                LawKind::NonlinearViscoelastic,
                2.75e9,
                0.65,
            )
            .with_collapse(0.1),
        ),
        accel: record(9, 8.0, 1.2),
        dt: 0.01,
        pounds: true,
        collapses: true,
    });
    out
}

/// Every IMK run on both CPU paths converges, run by run, as the yielding scenes do
/// (`convergence`'s rule).
#[test]
fn every_imk_run_converges_on_the_cpu_paths() {
    let all = scenes();
    let scenes: Vec<&Scene> = all.iter().collect();
    let truth = truths(&scenes);
    // What each scene is for: every IMK scene passes a capping point; those with the energy
    // rule lose strength.
    for (sc, t) in scenes.iter().zip(&truth) {
        assert!(t.storeys.iter().any(|s| s.capped), "{}: capped", sc.name);
        // A run that stands apart settles, on either rule: its residual drift is given (where
        // the buildings pound they may end leaning on each other, in contact: not settled).
        if !sc.collapses && !sc.pounds {
            let settled = (t.buildings.iter())
                .filter_map(|b| b.inelastic)
                .all(|y| y.residual_drift_ratio.is_finite());
            assert!(settled, "{}: residual drifts", sc.name);
        }
        let energy_rule = !sc.name.contains("no energy rule");
        let lost = t.storeys.iter().any(|s| s.strength_ratio < 1.0);
        assert_eq!(lost, energy_rule, "{}: strength lost", sc.name);
    }
    let bad = cpu_failures(&scenes, &truth);
    assert!(bad.is_empty(), "{}", bad.join("\n"));
}

/// The CPU scheme takes a building whose IMK storeys stand on pieces off their initial
/// stiffness in exact steps of its tangent stiffness, where the GPU kernel's twin
/// (`simulate_whole_row`) takes substeps: on every scene it takes no more substeps, on those
/// that stand apart far fewer, and the two give the same run to their truncation error (each converges to the reference, `every_imk_run_converges_on_the_cpu_paths`).
#[test]
fn pieces_off_the_initial_stiffness_take_exact_steps() {
    use pounding::physics::solver::row::fast::simulate_whole_row;
    let mut apart = 0;
    for sc in scenes() {
        let scheme = RowScheme::Fast(fast(64.0));
        let a = simulate_row(&sc.model, &sc.forcing(), sc.model.at_rest(), &scheme);
        let b = simulate_whole_row(&sc.model, &sc.forcing(), sc.model.at_rest(), &fast(64.0));
        assert_eq!(a.status, b.status, "{}", sc.name);
        assert!(
            a.substeps <= b.substeps,
            "{}: {} > {}",
            sc.name,
            a.substeps,
            b.substeps
        );
        let mut worst: f64 = 0.0;
        for (x, y) in a.buildings.iter().zip(&b.buildings) {
            for (u, v) in [
                (x.peak_roof, y.peak_roof),
                (x.peak_drift_ratio, y.peak_drift_ratio),
            ] {
                worst = worst.max((u - v).abs() / u.abs().max(v.abs()));
            }
        }
        for (x, y) in a.storeys.iter().zip(&b.storeys) {
            let (u, v) = (x.hysteretic_energy, y.hysteretic_energy);
            worst = worst.max((u - v).abs() / u.abs().max(v.abs()).max(1.0));
        }
        eprintln!(
            "{}: substeps {} (twin {}), apart {worst:.1e}",
            sc.name, a.substeps, b.substeps
        );
        assert!(worst <= 1e-5, "{}: {worst:e} apart", sc.name);
        // Apart and standing, the storeys' deteriorated pieces are most of the run (measured:
        // 6 to 35 times fewer substeps).
        if !sc.pounds && !sc.collapses {
            assert!(
                3 * a.substeps < b.substeps,
                "{}: {} substeps against the twin's {}",
                sc.name,
                a.substeps,
                b.substeps
            );
            apart += 1;
        }
    }
    assert!(apart >= 2, "{apart} scenes apart");
}
