//! The reference scheme for rows: the pair's ([`crate::physics::solver::reference`]) on the
//! row's state. Adaptive Dormand-Prince 5(4), steps that end on every record sample, every
//! level's events located, a free step that could hide a touch shortened to the contact time
//! scale, and steps in an impact capped at `t_c / contact_steps`. The error of each building's
//! modes is measured against that building's largest modal amplitude (a high mode's own tiny
//! amplitude would ask for needless accuracy), and of each level in contact against the
//! impact's scales.

use super::model::RowModel;
use super::rhs::{rhs, LevelModes, Motion};
use super::run::RowRun;
use super::sample::RowObserver;
use super::storey::StoreyMode;
use super::yielding::next_segment;
use crate::physics::model::{Forcing, Status};
use crate::physics::row::RowOutput;
use crate::physics::solver::fast::SUSTAINED;
use crate::physics::solver::reference::{dopri_stages, retry, ReferenceOptions};
use crate::physics::solver::state::{impact_step, Mode, Segment};

/// One Dormand-Prince step; returns the 5th-order solution and the scaled error norm
/// (`<= 1` accepts).
#[allow(clippy::too_many_arguments)]
fn dopri(
    m: &RowModel,
    (lv, storeys, active): (&LevelModes, &[StoreyMode], &[bool]),
    seg: &Segment,
    t: f64,
    z: &[f64],
    h: f64,
    rtol: f64,
) -> (Vec<f64>, f64) {
    // Every building still standing moves in every step of the reference.
    let (y, ev) = dopri_stages(&z.to_vec(), t, h, |tt, y: &Vec<f64>| {
        let mut out = vec![0.0; y.len()];
        let motion = Motion {
            levels: lv,
            active,
            energy: true,
            storeys,
        };
        rhs(m, &motion, seg.at(tt), y, &mut out);
        out
    });
    let n = m.n;
    let mut err: f64 = 0.0;
    for b in &m.buildings {
        let atol = rtol * 1e-6 * b.scale;
        for part in [0, n] {
            let r = part + b.off..part + b.off + b.n();
            let sc = r
                .clone()
                .map(|i| z[i].abs().max(y[i].abs()))
                .fold(0.0, f64::max);
            for i in r {
                err = err.max(ev[i].abs() / (atol + rtol * sc));
            }
        }
    }
    for (l, (lm, &(mode, v0))) in m.levels.iter().zip(lv).enumerate() {
        let i = 2 * n + l;
        let mut sc = z[i].abs().max(y[i].abs());
        if mode == Mode::Free {
            err = err.max(ev[i].abs() / (rtol * 1e-6 + rtol * sc));
            continue;
        }
        let c = &lm.contact;
        sc = sc.max(0.5 * c.m_eff * v0 * v0);
        err = err.max(ev[i].abs() / (rtol * 1e-6 + rtol * sc));
        // Floors: a grazing impact's scales can fall below what f64 resolves in u and v.
        let ua = lm.delta(z) + lm.gap;
        let ds = (v0 * c.duration_estimate(v0) / 3.0).max(1e-4 * ua.abs());
        let vs = v0.max(1e-4 * lm.ddelta(n, z).abs());
        let de = lm.delta(&ev) + lm.gap;
        err = err.max(de.abs() / (rtol * ds));
        err = err.max(lm.ddelta(n, &ev).abs() / (rtol * vs));
    }
    // Plastic drifts against the yield drift, plastic work against its own size.
    let ns = m.storeys.len();
    for (s, sm) in m.storeys.iter().enumerate() {
        let (p, w) = (m.plastic_slot(s), m.plastic_slot(s) + ns);
        err = err.max(ev[p].abs() / (rtol * sm.d_y));
        let sc = z[w].abs().max(y[w].abs());
        err = err.max(ev[w].abs() / (rtol * 1e-6 * sm.k * sm.d_y * sm.d_y + rtol * sc));
    }
    (y, err)
}

/// The reference scheme's run from `z0`, tracking the levels' closings where `closings`
/// ([`RowRun::track_closings`]).
pub(crate) fn run_tracked<'a>(
    m: &'a RowModel,
    forcing: &Forcing,
    z0: Vec<f64>,
    o: &ReferenceOptions,
    closings: bool,
    observer: Option<RowObserver<'a>>,
) -> RowOutput {
    let n = m.n;
    let mut run = RowRun::start(m, z0, forcing.t0);
    run.observer = observer;
    run.watch_all();
    if closings {
        run.track_closings();
    }
    let mut steps: u64 = 0;
    let mut h = forcing.dt / 8.0;
    let mut modes = Vec::with_capacity(m.levels.len());
    let mut storeys = Vec::with_capacity(m.storeys.len());
    let mut active = run.active.clone();
    let mut i = 0;
    while let Some(seg) = next_segment(m, forcing, i, &mut run) {
        i += 1;
        let mut t = seg.t0;
        let t1 = seg.t1();
        while t1 - t > 1e-12 * seg.dt {
            steps += 1;
            if steps > o.max_steps {
                return run.finish(Status::StepLimit, steps);
            }
            let z0 = run.z.clone();
            let mut hs = h.min(t1 - t);
            // The cap resolves each impact's force peak; a sustained contact is left to the
            // error control.
            for (lm, ls) in m.levels.iter().zip(&run.levels) {
                let c = &lm.contact;
                if ls.mode != Mode::Free && t - ls.t_onset <= SUSTAINED * c.duration_estimate(ls.v0)
                {
                    let a = lm.structural_rel_accel(m, &z0);
                    hs = hs.min(impact_step(c, ls.v0, a, o.contact_steps));
                }
            }
            run.level_modes(&mut modes);
            storeys.clone_from(&run.storey_modes);
            let (trial, err) = dopri(m, (&modes, &storeys, &active), &seg, t, &z0, hs, o.rtol);
            if err.is_nan() || err > 1.0 {
                let finite = trial.iter().all(|x| x.is_finite());
                match retry(&seg, t, hs, err, finite) {
                    Ok(shorter) => h = shorter,
                    Err(status) => return run.finish(status, steps),
                }
                continue;
            }
            // A free level that could touch inside a step longer than its contact time scale
            // shortens the step to that scale.
            let mut h_touch = f64::INFINITY;
            for (l, (lm, ls)) in m.levels.iter().zip(&run.levels).enumerate() {
                if ls.mode != Mode::Free || run.level_dead(l) {
                    continue;
                }
                let v_est = 1.5 * lm.ddelta(n, &z0).abs().max(lm.ddelta(n, &trial).abs());
                let a = lm
                    .structural_rel_accel(m, &z0)
                    .abs()
                    .max(lm.structural_rel_accel(m, &trial).abs());
                let hl = impact_step(&lm.contact, v_est, a, 8.0);
                if hs > hl && lm.may_touch(m, &seg, &z0, &trial, hs, ls.v0) {
                    h_touch = h_touch.min(hl);
                }
            }
            if h_touch < hs {
                h = h_touch;
                continue;
            }
            let step = |x: f64| dopri(m, (&modes, &storeys, &active), &seg, t, &z0, x, o.rtol).0;
            t += run.accept(&seg, t, hs, trial, 1e-13, 100, step);
            if run.active != active {
                // A building left the scene: it stands frozen from here on.
                if run.all_gone() {
                    return run.finish(Status::Collapsed, steps);
                }
                active.clone_from(&run.active);
            }
            h = hs * (0.9 * err.max(1e-12).powf(-0.2)).min(5.0);
        }
    }
    run.finish(Status::Ok, steps)
}
