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
//!    level's events are located inside the substeps.
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
            for (lm, ls) in m.levels.iter().zip(&run.levels) {
                if !lm.may_touch(m, &seg, &z, &z1, dt, ls.v0) {
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
                let mut step = |x: f64| rk4(m, &modes, &seg, t, &z0, x, &mut stages);
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
    }
    run.finish(Status::Ok, substeps as u64)
}
