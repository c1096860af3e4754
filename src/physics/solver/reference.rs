//! The reference scheme: adaptive Dormand-Prince 5(4) in f64, local extrapolation, error per
//! component against `atol + rtol |z|`. Steps end on every record sample (where `ag` has kinks),
//! every non-smooth contact instant is located inside the step (see [`super`]), a free step that
//! could hide a contact is shortened to the contact time scale, and steps in an impact are capped
//! at `t_c / contact_steps` so the peak force is resolved to about `rtol` (not
//! once the contact is sustained, see [`super::fast::SUSTAINED`]).

use super::events::may_touch;
use super::fast::SUSTAINED;
use super::state::{
    ddelta, finite, impact_step, structural_rel_accel, Mode, Sample, Segment, State,
};
use super::tracker::Integration;
use crate::physics::model::{Forcing, Initial, Pair, RunOutput, Status};

/// Tolerance settings of the reference scheme.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReferenceOptions {
    /// Relative tolerance of the local error ([`ReferenceOptions::with_tol`] derives it from the
    /// stated accuracy).
    pub rtol: f64,
    /// Cap in contact: at least this many steps per estimated contact duration.
    pub contact_steps: f64,
    /// Step budget of one run.
    pub max_steps: u64,
}

impl ReferenceOptions {
    /// Options whose peak force is accurate to about `tol` (relative). Measured global
    /// peak-force errors run to about 36x the local `rtol` (nonlinear viscoelastic contact on a
    /// synthetic record), so `rtol = tol / 100`; the contact cap `0.5 rtol^(-1/3)` keeps the
    /// peak read between steps (the force's cubic Hermite; a parabola through samples before,
    /// whose error fell as the cube of the step, set the cap) below that.
    pub fn with_tol(tol: f64) -> ReferenceOptions {
        let rtol = 0.01 * tol;
        ReferenceOptions {
            rtol,
            contact_steps: (0.5 * rtol.powf(-1.0 / 3.0)).max(20.0),
            max_steps: 500_000_000,
        }
    }
}

/// Default stated accuracy of the reference scheme.
pub const DEFAULT_TOL: f64 = 1e-8;

impl Default for ReferenceOptions {
    fn default() -> Self {
        ReferenceOptions::with_tol(DEFAULT_TOL)
    }
}

const A21: f64 = 1.0 / 5.0;
const A31: f64 = 3.0 / 40.0;
const A32: f64 = 9.0 / 40.0;
const A41: f64 = 44.0 / 45.0;
const A42: f64 = -56.0 / 15.0;
const A43: f64 = 32.0 / 9.0;
const A51: f64 = 19372.0 / 6561.0;
const A52: f64 = -25360.0 / 2187.0;
const A53: f64 = 64448.0 / 6561.0;
const A54: f64 = -212.0 / 729.0;
const A61: f64 = 9017.0 / 3168.0;
const A62: f64 = -355.0 / 33.0;
const A63: f64 = 46732.0 / 5247.0;
const A64: f64 = 49.0 / 176.0;
const A65: f64 = -5103.0 / 18656.0;
const B1: f64 = 35.0 / 384.0;
const B3: f64 = 500.0 / 1113.0;
const B4: f64 = 125.0 / 192.0;
const B5: f64 = -2187.0 / 6784.0;
const B6: f64 = 11.0 / 84.0;
const E1: f64 = 71.0 / 57600.0;
const E3: f64 = -71.0 / 16695.0;
const E4: f64 = 71.0 / 1920.0;
const E5: f64 = -17253.0 / 339200.0;
const E6: f64 = 22.0 / 525.0;
const E7: f64 = -1.0 / 40.0;

/// Scales the error of a step in contact is measured against: the impact's penetration, speed
/// and kinetic energy (the displacements and the accumulated contact work may be far larger, or
/// at the first touch exactly 0).
#[derive(Debug, Clone, Copy)]
pub(crate) struct ContactScales {
    pub delta: f64,
    pub v: f64,
    pub energy: f64,
}

impl ContactScales {
    fn of(p: &Pair, v0: f64) -> ContactScales {
        ContactScales {
            delta: v0 * p.contact.duration_estimate(v0) / 3.0,
            v: v0,
            energy: 0.5 * p.contact.m_eff * v0 * v0,
        }
    }
}

/// The stages of one Dormand-Prince step of `z' = f(t, z)` from `(t, z)` over `h`: the
/// 5th-order solution and its error estimate (5th minus embedded 4th order), for any state
/// held as a slice (the pair's array, a row's vector).
#[inline]
pub(crate) fn dopri_stages<S>(z: &S, t: f64, h: f64, mut f: impl FnMut(f64, &S) -> S) -> (S, S)
where
    S: Clone + AsRef<[f64]> + AsMut<[f64]>,
{
    let lin = |c: &[(f64, &S)]| -> S {
        let mut y = z.clone();
        for (i, yi) in y.as_mut().iter_mut().enumerate() {
            *yi += h * c.iter().map(|(a, k)| a * k.as_ref()[i]).sum::<f64>();
        }
        y
    };
    let k1 = f(t, z);
    let k2 = f(t + 0.2 * h, &lin(&[(A21, &k1)]));
    let k3 = f(t + 0.3 * h, &lin(&[(A31, &k1), (A32, &k2)]));
    let k4 = f(t + 0.8 * h, &lin(&[(A41, &k1), (A42, &k2), (A43, &k3)]));
    let k5 = f(
        t + 8.0 / 9.0 * h,
        &lin(&[(A51, &k1), (A52, &k2), (A53, &k3), (A54, &k4)]),
    );
    let k6 = f(
        t + h,
        &lin(&[(A61, &k1), (A62, &k2), (A63, &k3), (A64, &k4), (A65, &k5)]),
    );
    let y = lin(&[(B1, &k1), (B3, &k3), (B4, &k4), (B5, &k5), (B6, &k6)]);
    let k7 = f(t + h, &y);
    let mut ev = k1.clone();
    for (i, e) in ev.as_mut().iter_mut().enumerate() {
        let k = |s: &S| s.as_ref()[i];
        *e =
            h * (E1 * k(&k1) + E3 * k(&k3) + E4 * k(&k4) + E5 * k(&k5) + E6 * k(&k6) + E7 * k(&k7));
    }
    (y, ev)
}

/// One Dormand-Prince step; returns the 5th-order solution and the scaled error norm
/// (`<= 1` accepts).
#[allow(clippy::too_many_arguments)]
pub(crate) fn dopri(
    p: &Pair,
    mode: Mode,
    v0: f64,
    seg: &Segment,
    t: f64,
    z: &State,
    h: f64,
    rtol: f64,
    cs: &ContactScales,
) -> (State, f64) {
    let inv_m = [1.0 / p.b1.m, 1.0 / p.b2.m];
    let (y, ev) = dopri_stages(z, t, h, |tt, y| {
        super::state::rhs(p, mode, v0, seg.at(tt), inv_m, y)
    });
    let atol = rtol * 1e-6;
    let mut err: f64 = 0.0;
    // The energy integrals (z[5], z[6]) follow from the others; they are not error-controlled.
    for i in 0..5 {
        let mut sc = z[i].abs().max(y[i].abs());
        if i == 4 && mode != Mode::Free {
            sc = sc.max(cs.energy);
        }
        err = err.max(ev[i].abs() / (atol + rtol * sc));
    }
    if mode != Mode::Free {
        // Floors: a grazing impact's scales can fall below what f64 resolves in u and v.
        let ds = cs.delta.max(1e-4 * z[0].abs().max(z[2].abs()));
        let vs = cs.v.max(1e-4 * z[1].abs().max(z[3].abs()));
        err = err.max((ev[0] - ev[2]).abs() / (rtol * ds));
        err = err.max((ev[1] - ev[3]).abs() / (rtol * vs));
    }
    (y, err)
}

/// The step to retry after a step of length `hs` at `t` was rejected with error norm `err`
/// (NaN where non-finite), or how the run ends when no shorter step is left. Only
/// floating-point resolution bounds the step: the delta^(1/4) damping of the nonlinear
/// viscoelastic law needs very short steps just after first touch.
pub(crate) fn retry(seg: &Segment, t: f64, hs: f64, err: f64, finite: bool) -> Result<f64, Status> {
    let hmin = 1e-20 * seg.dt + 4.0 * f64::EPSILON * t.abs();
    if hs <= hmin {
        return Err(if finite {
            Status::StepLimit
        } else {
            Status::NonFinite
        });
    }
    Ok(if err.is_finite() {
        hs * (0.9 * err.powf(-0.2)).max(0.1)
    } else {
        hs * 0.1
    })
}

pub(crate) fn run(
    pair: &Pair,
    forcing: &Forcing,
    init: &Initial,
    o: &ReferenceOptions,
    observer: Option<&mut dyn FnMut(&Sample)>,
    stop_after_impacts: Option<u32>,
    accel: bool,
) -> RunOutput {
    let mut run = Integration::start(pair, init, forcing.t0, observer);
    run.tr.accel = accel;
    let mut steps: u64 = 0;
    let mut h = forcing.dt / 8.0;
    for i in 0..forcing.intervals() {
        let seg = Segment::of(forcing, i);
        let mut t = seg.t0;
        let t1 = seg.t1();
        while t1 - t > 1e-12 * seg.dt {
            steps += 1;
            if steps > o.max_steps {
                return run.finish(Status::StepLimit, steps);
            }
            let (z0, mode, v0) = (run.z, run.mode, run.tr.v0);
            let mut hs = h.min(t1 - t);
            // The cap resolves an impact's force peak; a sustained contact (as in the fast
            // scheme) is left to the error control.
            let sustained =
                t - run.tr.onset_time() > SUSTAINED * pair.contact.duration_estimate(v0);
            if mode != Mode::Free && !sustained {
                let a = structural_rel_accel(pair, &z0);
                hs = hs.min(impact_step(&pair.contact, v0, a, o.contact_steps));
            }
            let cs = ContactScales::of(pair, v0);
            let (trial, err) = dopri(pair, mode, v0, &seg, t, &z0, hs, o.rtol, &cs);
            if err.is_nan() || err > 1.0 {
                match retry(&seg, t, hs, err, finite(&trial)) {
                    Ok(shorter) => h = shorter,
                    Err(status) => return run.finish(status, steps),
                }
                continue;
            }
            if mode == Mode::Free {
                let v_est = 1.5 * ddelta(&z0).abs().max(ddelta(&trial).abs());
                let a = structural_rel_accel(pair, &z0).abs();
                let a = a.max(structural_rel_accel(pair, &trial).abs());
                let h_touch = impact_step(&pair.contact, v_est, a, 8.0);
                if hs > h_touch && may_touch(pair, &seg, &z0, &trial, hs, v0) {
                    h = h_touch;
                    continue;
                }
            }
            let step = |x: f64| dopri(pair, mode, v0, &seg, t, &z0, x, o.rtol, &cs).0;
            t += run.accept(&seg, t, hs, trial, 1e-13, 100, step);
            if stop_after_impacts.is_some_and(|n| run.tr.impacts_ended() >= n) {
                return run.finish(Status::Ok, steps);
            }
            h = hs * (0.9 * err.max(1e-12).powf(-0.2)).min(5.0);
        }
    }
    run.finish(Status::Ok, steps)
}
