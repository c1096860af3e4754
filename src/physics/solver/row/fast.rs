//! The production scheme for rows, the pair's ([`crate::physics::solver::fast`]) on the row's
//! state:
//!
//! 1. While no level is in contact, each record step is taken with the exact propagator of
//!    every mode (no truncation error).
//! 2. The step is kept unless some level may touch inside it (the Hermite cubic of its
//!    penetration within twice its error bound of 0).
//! 3. Such a step, and every step while a level is in contact, is redone with `M` fixed RK4
//!    substeps of the whole row, sized as the pair's from each level that is in contact or may
//!    touch (its impact duration and local rate) and from the fastest mode of the row. Every
//!    level's events are located inside the substeps. Buildings of
//!    `FLOOR_SUBSTEPS_FROM` (4) storeys or more with Rayleigh damping take them in floor
//!    coordinates (`O(N)` per right-hand side; the same motion, `RowModel::substep_model`).
//! 4. Peaks: as the pair's (force samples refined by a parabola; displacements and drifts from
//!    the quintic Hermite over free record steps, the cubic inside contact steps). Floor
//!    accelerations: the cubic Hermite with their rates over free record steps, the samples at
//!    substep ends and events in contact steps, where a contact force's spike makes them
//!    converge with the substep (as the force peak's samples do).

use super::{rhs, LevelModes, RowModel, RowRun};
use crate::physics::model::{Forcing, Oscillator, Status};
use crate::physics::propagator::{EnergyForms, Propagator};
use crate::physics::row::RowOutput;
use crate::physics::solver::fast::{
    FastOptions, LOCATE_ITERATIONS, LOCATE_TOLERANCE, MAX_PIECES_PER_SUBSTEP, SUSTAINED,
};
use crate::physics::solver::{impact_step, Mode, Segment};

/// The fast scheme's settings are the pair's.
pub type RowFastOptions = FastOptions;

/// The stages of an RK4 step, kept between calls.
struct Stages {
    k: [Vec<f64>; 4],
    y: Vec<f64>,
}

/// Classic RK4 over `h` from `(t, z)` in the levels' modes `lv`.
fn rk4(
    m: &RowModel,
    lv: &LevelModes,
    seg: &Segment,
    t: f64,
    z: &[f64],
    h: f64,
    st: &mut Stages,
) -> Vec<f64> {
    let (ag0, agm, ag1) = (seg.at(t), seg.at(t + 0.5 * h), seg.at(t + h));
    let Stages { k, y } = st;
    let [k1, k2, k3, k4] = k;
    rhs(m, lv, ag0, z, k1);
    for ((y, z), k) in y.iter_mut().zip(z).zip(k1.iter()) {
        *y = z + 0.5 * h * k;
    }
    rhs(m, lv, agm, y, k2);
    for ((y, z), k) in y.iter_mut().zip(z).zip(k2.iter()) {
        *y = z + 0.5 * h * k;
    }
    rhs(m, lv, agm, y, k3);
    for ((y, z), k) in y.iter_mut().zip(z).zip(k3.iter()) {
        *y = z + h * k;
    }
    rhs(m, lv, ag1, y, k4);
    (0..z.len())
        .map(|i| z[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]))
        .collect()
}

fn mode_oscillator(m: &RowModel, k: usize) -> Oscillator {
    Oscillator {
        m: 1.0,
        k: m.w2[k],
        c: m.two_xi_w[k],
    }
}

pub(crate) fn run(m: &RowModel, forcing: &Forcing, z0: Vec<f64>, o: &FastOptions) -> RowOutput {
    // Contact substeps run in floor coordinates where the damping allows (O(N) each).
    run_with(m, m.substep_model().as_ref(), forcing, z0, o)
}

/// [`run`] with the contact substeps in `sub` (None: in modes, as the reference).
fn run_with(
    m: &RowModel,
    sub: Option<&RowModel>,
    forcing: &Forcing,
    z0: Vec<f64>,
    o: &FastOptions,
) -> RowOutput {
    let n = m.n;
    let nl = m.levels.len();
    let dt = forcing.dt;
    let props: Vec<Propagator> = (0..n)
        .map(|k| Propagator::new(&mode_oscillator(m, k), dt))
        .collect();
    let forms: Option<Vec<EnergyForms>> = o.energy.then(|| {
        (0..n)
            .map(|k| EnergyForms::new(&mode_oscillator(m, k), dt))
            .collect()
    });
    let rate = m.structural_rate();
    let mut run = RowRun::start(m, z0, forcing.t0);
    run.energy = o.energy;
    let mut substeps: u32 = 0;
    let len = m.len();
    let mut stages = Stages {
        k: std::array::from_fn(|_| vec![0.0; len]),
        y: vec![0.0; len],
    };
    let mut modes = Vec::with_capacity(nl);
    let mut bounds = Vec::with_capacity(n);
    for i in 0..forcing.intervals() {
        let seg = Segment::of(forcing, i);
        let z = run.z.clone();
        // The substep: the shortest any level asks for, and the structures' own rate.
        let h_rate_of = |d_est: f64, v0: f64, c: &crate::physics::contact::Contact| {
            2.0 * std::f64::consts::PI
                / o.substeps_per_contact
                / c.local_rate(2.0 * d_est, v0).max(rate)
        };
        let mut h = 2.0 * std::f64::consts::PI / o.substeps_per_contact / rate;
        if !run.any_contact() {
            let mut z1 = z.clone();
            for k in 0..n {
                let (a0, a1) = (m.part[k] * seg.a0, m.part[k] * seg.a1);
                (z1[k], z1[n + k]) = props[k].step(z[k], z[n + k], a0, a1);
                if let Some(f) = &forms {
                    let (vv, agv) = f[k].integrals(z[k], z[n + k], a0, a1);
                    z1[2 * n + nl] -= agv;
                    z1[2 * n + nl + 1] += m.two_xi_w[k] * vv;
                }
            }
            let mut touching = false;
            m.fourth_derivative_bounds(&seg, &z, &z1, &mut bounds);
            for (lm, ls) in m.levels.iter().zip(&run.levels) {
                if !lm.may_touch_bounded(n, &bounds, &z, &z1, dt, ls.v0) {
                    continue;
                }
                touching = true;
                let v_est = 1.5 * lm.ddelta(n, &z).abs().max(lm.ddelta(n, &z1).abs());
                let d_est = lm.delta(&z).max(lm.delta(&z1));
                let a_est = lm
                    .structural_rel_accel(m, &z)
                    .abs()
                    .max(lm.structural_rel_accel(m, &z1).abs());
                let c = &lm.contact;
                h = h.min(
                    impact_step(c, v_est, a_est, o.substeps_per_contact)
                        .min(h_rate_of(d_est, ls.v0, c)),
                );
            }
            if !touching {
                run.free_step(&seg, z1);
                if !run.z.iter().all(|x| x.is_finite()) {
                    return run.finish(Status::NonFinite, substeps as u64);
                }
                continue;
            }
        } else {
            for (lm, ls) in m.levels.iter().zip(&run.levels) {
                let c = &lm.contact;
                let (d, r) = (lm.delta(&z), lm.ddelta(n, &z));
                let a = lm.structural_rel_accel(m, &z).abs();
                if ls.mode == Mode::Free {
                    // A free level beside a contact: size for its touch if it could close within
                    // the step at its present rate.
                    if d + 2.0 * r.max(0.0) * dt > 0.0 {
                        h = h.min(impact_step(c, 1.5 * r.abs(), a, o.substeps_per_contact));
                    }
                    continue;
                }
                let h_rate = h_rate_of(d, ls.v0, c);
                let sustained = seg.t0 - ls.t_onset > SUSTAINED * c.duration_estimate(ls.v0);
                h = h.min(if sustained {
                    h_rate
                } else {
                    impact_step(c, ls.v0.max(r.abs()), a, o.substeps_per_contact).min(h_rate)
                });
            }
        }
        let msub = (dt / h).ceil().max(1.0);
        if msub.is_nan() || msub > o.max_substeps_per_step as f64 {
            return run.finish(Status::StepLimit, substeps as u64);
        }
        let msub = msub as u32;
        let h = dt / msub as f64;
        let mut t = seg.t0;
        if let Some(sub) = sub {
            run.enter_substeps(sub);
        }
        let sm = sub.unwrap_or(m);
        for j in 1..=msub {
            let t_target = if j == msub {
                seg.t1()
            } else {
                seg.t0 + j as f64 * h
            };
            let mut pieces = 0;
            while t_target - t > 1e-9 * h {
                substeps += 1;
                pieces += 1;
                if substeps > o.max_substeps || pieces > MAX_PIECES_PER_SUBSTEP {
                    return run.finish(Status::StepLimit, substeps as u64);
                }
                let hs = t_target - t;
                let z0 = run.z.clone();
                run.level_modes(&mut modes);
                let mut step = |x: f64| rk4(sm, &modes, &seg, t, &z0, x, &mut stages);
                let trial = step(hs);
                t += run.accept(
                    &seg,
                    t,
                    hs,
                    trial,
                    LOCATE_TOLERANCE,
                    LOCATE_ITERATIONS,
                    step,
                );
                if !run.z.iter().all(|x| x.is_finite()) {
                    return run.finish(Status::NonFinite, substeps as u64);
                }
            }
            t = t_target;
        }
        run.leave_substeps();
    }
    run.finish(Status::Ok, substeps as u64)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::contact::LawKind;
    use crate::physics::row::Row;
    use crate::physics::shear::{Damping, ShearBuilding};

    /// Two tall buildings (one with a soft first storey) and a low one, `gaps` apart.
    fn row(gaps: Vec<f64>) -> RowModel {
        let building = |n: usize, period: f64, profile: Vec<f64>| {
            ShearBuilding::from_period(
                vec![2.5e5; n],
                &profile,
                vec![3.0; n],
                period,
                Damping::Rayleigh(0.05),
            )
        };
        let mut soft = vec![1.0; 8];
        soft[0] = 0.4;
        RowModel::new(&Row::new(
            vec![
                building(8, 0.7, soft),
                building(6, 0.45, vec![1.0; 6]),
                building(2, 0.2, vec![1.0; 2]),
            ],
            gaps,
            LawKind::NonlinearViscoelastic,
            2.75e9,
            0.35,
        ))
    }

    /// The largest relative difference between the floor-coordinate and modal substeps' runs
    /// of `m` (after checking they take the same substeps and impacts at every level), and the
    /// impacts.
    fn floors_against_modes(m: &RowModel) -> (f64, u32) {
        let sub = m
            .substep_model()
            .expect("two buildings of 4 storeys or more");
        assert_eq!(
            sub.buildings
                .iter()
                .map(|b| b.in_floors)
                .collect::<Vec<_>>(),
            [true, true, false]
        );
        // A ground motion of three frequencies under a rising and decaying envelope, 8 s at
        // 0.01 s, peak about 4.4 m/s^2 (physics knows no records).
        let accel: Vec<f64> = (0..800)
            .map(|i| {
                let t = i as f64 * 0.01;
                let envelope = (t / 1.5).min(1.0) * (-(t - 4.0).max(0.0) / 2.0).exp();
                let w = 2.0 * std::f64::consts::PI;
                envelope
                    * (2.5 * (w * 1.1 * t).sin()
                        + 1.5 * (w * 2.3 * t + 0.4).sin()
                        + 1.0 * (w * 0.7 * t + 1.3).sin())
            })
            .collect();
        let forcing = Forcing {
            accel: &accel,
            dt: 0.01,
            t0: 0.0,
            scale: 1.0,
            tail: 1.0,
        };
        let o = FastOptions {
            energy: true,
            ..FastOptions::default()
        };
        let modal = run_with(m, None, &forcing, m.at_rest(), &o);
        let floors = run_with(m, Some(&sub), &forcing, m.at_rest(), &o);
        assert_eq!(modal.status, Status::Ok);
        assert_eq!(floors.substeps, modal.substeps);
        let mut worst = 0.0f64;
        let mut diff = |a: f64, b: f64| {
            let d = (a - b).abs() / a.abs().max(b.abs()).max(1e-300);
            worst = worst.max(d);
        };
        for (a, b) in floors.levels.iter().zip(&modal.levels) {
            assert_eq!(a.impacts, b.impacts);
            diff(a.peak_force, b.peak_force);
            diff(a.peak_penetration, b.peak_penetration);
            diff(a.dissipated_energy, b.dissipated_energy);
        }
        for (a, b) in floors.buildings.iter().zip(&modal.buildings) {
            diff(a.peak_roof, b.peak_roof);
            diff(a.peak_drift_ratio, b.peak_drift_ratio);
            diff(a.peak_accel, b.peak_accel);
        }
        let (ea, eb) = (floors.energy.unwrap(), modal.energy.unwrap());
        diff(ea.input, eb.input);
        diff(ea.damping, eb.damping);
        assert!(ea.residual.abs() < 1e-6, "residual {}", ea.residual);
        (worst, modal.impacts)
    }

    /// The floor-coordinate right-hand side is the modal one in floor coordinates (every slot,
    /// energy terms included, with every level pressing), and the change of coordinates
    /// round-trips: the two are one ODE.
    #[test]
    fn floor_rhs_is_the_modal_rhs() {
        use crate::physics::solver::Mode;
        // Negative gaps: every level overlaps, so every level's force enters.
        let m = row(vec![-0.0005, -0.0005]);
        let sub = m.substep_model().unwrap();
        let len = m.len();
        let mut z: Vec<f64> = (0..len)
            .map(|i| ((i * 7919 % 113) as f64 / 113.0 - 0.5) * 0.01)
            .collect();
        z[2 * m.n..].fill(0.0);
        let mut y = z.clone();
        sub.modes_to_substeps(&mut y);
        let mut back = y.clone();
        sub.substeps_to_modes(&mut back);
        for (a, b) in z.iter().zip(&back) {
            assert!((a - b).abs() <= 1e-15, "round trip {a} {b}");
        }
        let levels: Vec<(Mode, f64)> = m.levels.iter().map(|_| (Mode::Approach, 0.5)).collect();
        for (lm, ls) in m.levels.iter().zip(&sub.levels) {
            assert!(lm.delta(&z) > 0.0);
            assert!((lm.delta(&z) - ls.delta(&y)).abs() < 1e-15);
        }
        let (mut fz, mut fy) = (vec![0.0; len], vec![0.0; len]);
        super::super::rhs(&m, &levels, 0.7, &z, &mut fz);
        super::super::rhs(&sub, &levels, 0.7, &y, &mut fy);
        sub.modes_to_substeps(&mut fz);
        let scale = fy.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        for (i, (a, b)) in fz.iter().zip(&fy).enumerate() {
            assert!(
                (a - b).abs() <= 1e-12 * scale,
                "slot {i}: {a} (modes) {b} (floors)"
            );
        }
    }

    /// Contact substeps in floor coordinates against the modal substeps over whole runs: the
    /// same substeps and impacts at every level; over one impact, peaks and energy terms to
    /// rounding (within 1e-8, measured 8e-10); over many, within 1e-4 (the fast scheme's p99
    /// peak-force error at 64 substeps is 2.8e-4). They are one ODE (above) and RK4 is
    /// affine-invariant, but an event location that ends at its 16 iterations rather than its
    /// tolerance (a contact force's root is not smooth) lands where rounding moves it by up to
    /// 1e-8 s, and later impacts carry that on: measured 1.8e-5 over 102 impacts.
    #[test]
    fn floor_substeps_are_the_modal_substeps() {
        for (gap, impacts, tol) in [(0.11, 1..=1, 1e-8), (0.01, 50..=1000, 1e-4)] {
            let (worst, n) = floors_against_modes(&row(vec![gap, gap / 2.0]));
            assert!(impacts.contains(&n), "gap {gap}: {n} impacts");
            assert!(worst < tol, "gap {gap}: {worst:e} over {n} impacts");
        }
    }
}
