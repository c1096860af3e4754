//! CPU integration of one run, in f64. Two schemes share the machinery here:
//!
//! - [`fast`] (production): exact linear stepping at the record's `dt` while the buildings are
//!   apart, fixed RK4 substeps sized to the contact duration only in record steps where a contact
//!   may happen.
//! - [`reference`] (truth): adaptive Dormand-Prince 5(4) with error control, steps that never
//!   cross a record sample (where `ag` has kinks), and a cap on the step in contact.
//!
//! Both locate every non-smooth instant inside the step (first touch `delta = 0`, the turn
//! `delta' = 0`, separation at `delta = 0` or `F = 0`) by regula falsi on re-taken partial
//! steps, so each step integrates a smooth right-hand side. The contact work
//! `w' = F delta'` rides along as a fifth state so the dissipated energy is integrated to the
//! scheme's own order.

pub mod fast;
pub mod reference;

pub use fast::FastOptions;
pub use reference::ReferenceOptions;

use crate::contact::Contact;
use crate::model::{EnergyBalance, Forcing, Initial, Oscillator, Pair, RunOutput, Status};

/// `[u1, v1, u2, v2, w, e_in, e_damp]`: displacements and velocities, then the contact work
/// `w' = F delta'`, the input work `e_in' = -ag (m1 v1 + m2 v2)` and the structural damping work
/// `e_damp' = c1 v1^2 + c2 v2^2`. The last two ride along for the energy balance; error control
/// and events look only at the first five.
pub type State = [f64; 7];

/// Contact mode; changes only at located events.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    Free,
    Approach,
    Restitution,
}

/// Which integration scheme a run uses.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Scheme {
    Fast(FastOptions),
    Reference(ReferenceOptions),
}

impl Scheme {
    pub fn key(&self) -> &'static str {
        match self {
            Scheme::Fast(_) => "fast",
            Scheme::Reference(_) => "reference",
        }
    }
}

/// A point handed to an observer after every accepted step and event.
#[derive(Debug, Clone, Copy)]
pub struct Sample {
    pub t: f64,
    pub z: State,
    pub force: f64,
    pub mode: Mode,
}

/// Simulate one run from rest (or from `init`) over the forcing's whole duration.
pub fn simulate(pair: &Pair, forcing: &Forcing, init: &Initial, scheme: &Scheme) -> RunOutput {
    simulate_observed(pair, forcing, init, scheme, None)
}

/// As [`simulate`], calling `observer` after every step.
pub fn simulate_observed(
    pair: &Pair,
    forcing: &Forcing,
    init: &Initial,
    scheme: &Scheme,
    observer: Option<&mut dyn FnMut(&Sample)>,
) -> RunOutput {
    match scheme {
        Scheme::Fast(o) => fast::run(pair, forcing, init, o, observer),
        Scheme::Reference(o) => reference::run(pair, forcing, init, o, observer, None),
    }
}

/// Result of one isolated collision of two free bodies (NaN fields if the solve failed).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Collision {
    /// `-delta'_out / delta'_in`
    pub e: f64,
    pub peak_force: f64,
    pub peak_penetration: f64,
    pub duration: f64,
    pub dissipated: f64,
}

/// Tolerance of the single-collision solves behind the `exact` formula.
pub const EXACT_RTOL: f64 = 1e-11;

/// Two free bodies (masses `2 m_eff` each) meeting at relative speed `v0` with `contact`; solved
/// with the reference scheme at `rtol` until they separate.
pub fn single_collision(contact: &Contact, v0: f64, rtol: f64) -> Collision {
    single_collision_observed(contact, v0, rtol, 20.0, &mut |_| {})
}

/// As [`single_collision`], with at least `contact_steps` steps per estimated contact duration,
/// calling `observer` after every step (body 1 starts at `u1 = 0` touching body 2, so
/// `delta = u1 - u2`).
pub fn single_collision_observed(
    contact: &Contact,
    v0: f64,
    rtol: f64,
    contact_steps: f64,
    observer: &mut dyn FnMut(&Sample),
) -> Collision {
    let m = 2.0 * contact.m_eff;
    let pair = Pair {
        b1: Oscillator::free(m),
        b2: Oscillator::free(m),
        gap: 0.0,
        contact: *contact,
    };
    let tc = contact.duration_estimate(v0);
    let horizon = tc * 200.0 * (1.0 + contact.damping_ratio);
    let zeros = [0.0, 0.0];
    let forcing = Forcing {
        accel: &zeros,
        dt: horizon,
        t0: 0.0,
        scale: 0.0,
        tail: 0.0,
    };
    let init = Initial {
        u1: 0.0,
        v1: 0.5 * v0,
        u2: 0.0,
        v2: -0.5 * v0,
    };
    let opts = ReferenceOptions {
        rtol,
        contact_steps,
        max_steps: 50_000_000,
    };
    let mut last = [0.0; 7];
    let mut separated = false;
    let mut obs = |s: &Sample| {
        last = s.z;
        separated = s.mode == Mode::Free;
        observer(s);
    };
    let out = reference::run(&pair, &forcing, &init, &opts, Some(&mut obs), Some(1));
    if out.status != Status::Ok {
        return Collision {
            e: f64::NAN,
            peak_force: f64::NAN,
            peak_penetration: f64::NAN,
            duration: f64::NAN,
            dissipated: f64::NAN,
        };
    }
    Collision {
        // Overdamped Kelvin-Voigt never lets go: the bodies creep together until the horizon.
        e: if separated {
            -(last[1] - last[3]) / v0
        } else {
            0.0
        },
        peak_force: out.peak_force,
        peak_penetration: out.peak_penetration,
        duration: out.contact_time,
        dissipated: out.dissipated_energy,
    }
}

/// Ground acceleration over one record interval: linear from `a0` at `t0` to `a1` at `t0 + dt`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Segment {
    pub t0: f64,
    pub dt: f64,
    pub a0: f64,
    pub a1: f64,
}

impl Segment {
    pub fn of(forcing: &Forcing, i: usize) -> Segment {
        Segment {
            t0: forcing.t0 + i as f64 * forcing.dt,
            dt: forcing.dt,
            a0: forcing.sample(i),
            a1: forcing.sample(i + 1),
        }
    }
    #[inline]
    pub fn at(&self, t: f64) -> f64 {
        self.a0 + (self.a1 - self.a0) * ((t - self.t0) / self.dt)
    }
    pub fn t1(&self) -> f64 {
        self.t0 + self.dt
    }
}

#[inline]
pub(crate) fn delta(p: &Pair, z: &State) -> f64 {
    z[0] - z[2] - p.gap
}

#[inline]
pub(crate) fn ddelta(z: &State) -> f64 {
    z[1] - z[3]
}

/// Contact force in `mode`.
#[inline]
pub(crate) fn force(p: &Pair, mode: Mode, v0: f64, z: &State) -> f64 {
    match mode {
        Mode::Free => 0.0,
        _ => p
            .contact
            .force(delta(p, z), ddelta(z), v0, mode == Mode::Approach),
    }
}

// Always inlined: with the energy terms it grew past the inliner's threshold, and the call
// cost 25 % of the CPU fast path's runs/s.
#[inline(always)]
pub(crate) fn rhs(p: &Pair, mode: Mode, v0: f64, ag: f64, z: &State) -> State {
    let f = force(p, mode, v0, z);
    let (b1, b2) = (&p.b1, &p.b2);
    [
        z[1],
        (-b1.c * z[1] - b1.k * z[0] - f) / b1.m - ag,
        z[3],
        (-b2.c * z[3] - b2.k * z[2] + f) / b2.m - ag,
        f * ddelta(z),
        -ag * (b1.m * z[1] + b2.m * z[3]),
        b1.c * z[1] * z[1] + b2.c * z[3] * z[3],
    ]
}

/// Relative acceleration `delta''` from the structures alone (the ground motion cancels).
#[inline]
pub(crate) fn structural_rel_accel(p: &Pair, z: &State) -> f64 {
    let (b1, b2) = (&p.b1, &p.b2);
    -(b1.c * z[1] + b1.k * z[0]) / b1.m + (b2.c * z[3] + b2.k * z[2]) / b2.m
}

/// Step that resolves an impact at approach speed `v` with `per_contact` steps. The impact
/// lasts the free-collision duration `t_c(v)`, or less when the structures reverse the relative
/// motion first (about `2 v / |a|` for a relative deceleration `a`); the kinematic bound is
/// floored at `t_c / 16` so a grazing touch cannot ask for unbounded steps.
pub(crate) fn impact_step(p: &Pair, v: f64, a: f64, per_contact: f64) -> f64 {
    let tc = p.contact.duration_estimate(v);
    let tk = if a != 0.0 {
        2.0 * v / a.abs()
    } else {
        f64::INFINITY
    };
    let t = tc.min(tk.max(tc / 16.0));
    t / (per_contact * (1.0 + 2.0 * p.contact.damping_ratio))
}

/// Positive once `mode` must end: first touch (Free), the turn `delta' = 0` (Approach),
/// separation (Restitution).
#[inline]
pub(crate) fn event_value(p: &Pair, mode: Mode, v0: f64, z: &State) -> f64 {
    match mode {
        Mode::Free => p.contact.gauge(delta(p, z), ddelta(z), v0),
        Mode::Approach => -ddelta(z),
        Mode::Restitution => -p.contact.gauge(delta(p, z), ddelta(z), v0),
    }
}

/// Regula falsi (Illinois) for the first instant in `(0, h]` where `f > 0`, given
/// `f(0) <= 0 < f(h)`. `step(x)` re-takes the step with length `x`. Each estimate is followed
/// by a guard probe `tol` beyond it (towards the other end), which closes the bracket at once
/// when the estimate is good and keeps regula falsi from stalling on one side. Returns the length
/// and state on the far side of the event, so the next mode starts with a consistent sign.
#[allow(clippy::too_many_arguments)]
pub(crate) fn locate(
    h: f64,
    f0: f64,
    z1: State,
    f1: f64,
    tol: f64,
    max_iter: u32,
    mut step: impl FnMut(f64) -> State,
    eval: impl Fn(&State) -> f64,
) -> (f64, State) {
    let (mut a, mut fa) = (0.0, f0.min(0.0));
    let (mut b, mut fb, mut zb) = (h, f1, z1);
    let mut last = 0i8;
    for _ in 0..max_iter {
        if b - a <= tol {
            break;
        }
        let mut x = if fb != fa {
            b - fb * (b - a) / (fb - fa)
        } else {
            0.5 * (a + b)
        };
        if !(x > a && x < b) {
            x = 0.5 * (a + b);
        }
        let zx = step(x);
        let fx = eval(&zx);
        let g = if fx > 0.0 {
            (b, fb, zb) = (x, fx, zx);
            if last == 1 {
                fa *= 0.5;
            }
            last = 1;
            x - 0.5 * tol
        } else {
            (a, fa) = (x, fx);
            if last == -1 {
                fb *= 0.5;
            }
            last = -1;
            x + 0.5 * tol
        };
        if g > a && g < b {
            let zg = step(g);
            let fg = eval(&zg);
            if fg > 0.0 {
                (b, fb, zb) = (g, fg, zg);
            } else {
                (a, fa) = (g, fg);
            }
        }
    }
    (b, zb)
}

/// In free mode a step whose end is still apart can hide a brief, grazing touch. If the Hermite
/// cubic of `delta` over the step rises above 0 inside, return the fraction of the step at its
/// maximum (the step is then re-taken to there and checked for the event).
pub(crate) fn hidden_touch(p: &Pair, z0: &State, z1: &State, h: f64) -> Option<f64> {
    let (y0, d0, y1, d1) = (delta(p, z0), ddelta(z0), delta(p, z1), ddelta(z1));
    if y1 > 0.0 || d0 <= 0.0 && d1 >= 0.0 {
        return None;
    }
    let (m0, m1) = (h * d0, h * d1);
    let b = 3.0 * (y1 - y0) - 2.0 * m0 - m1;
    let c = 2.0 * (y0 - y1) + m0 + m1;
    let (qa, qb, qc) = (3.0 * c, 2.0 * b, m0);
    let mut best: Option<(f64, f64)> = None;
    let disc = qb * qb - 4.0 * qa * qc;
    if qa.abs() > 1e-300 && disc >= 0.0 {
        let r = disc.sqrt();
        for s in [(-qb + r) / (2.0 * qa), (-qb - r) / (2.0 * qa)] {
            if s > 0.0 && s < 1.0 {
                let v = y0 + s * (m0 + s * (b + s * c));
                if v > 0.0 && best.is_none_or(|(bv, _)| v > bv) {
                    best = Some((v, s));
                }
            }
        }
    }
    best.map(|(_, s)| s)
}

/// Min and max over `[0, h]` of the cubic Hermite through `(y0, y0')` and `(y1, y1')`.
#[inline]
pub(crate) fn hermite_range(y0: f64, d0: f64, y1: f64, d1: f64, h: f64) -> (f64, f64) {
    let (m0, m1) = (h * d0, h * d1);
    let b = 3.0 * (y1 - y0) - 2.0 * m0 - m1;
    let c = 2.0 * (y0 - y1) + m0 + m1;
    let p = |s: f64| y0 + s * (m0 + s * (b + s * c));
    let (mut lo, mut hi) = (y0.min(y1), y0.max(y1));
    for s in hermite_extrema(m0, b, c) {
        if s > 0.0 && s < 1.0 {
            let v = p(s);
            lo = lo.min(v);
            hi = hi.max(v);
        }
    }
    (lo, hi)
}

/// Where the cubic Hermite `y0 + s (m0 + s (b + s c))` may have extrema: the roots of
/// `p'(s) = m0 + 2 b s + 3 c s^2` by the stable formula, -1 where there is none. Callers keep
/// those in `(0, 1)`.
#[inline]
pub(crate) fn hermite_extrema(m0: f64, b: f64, c: f64) -> [f64; 2] {
    let (qa, qb, qc) = (3.0 * c, 2.0 * b, m0);
    if qa.abs() < 1e-300 {
        if qb != 0.0 {
            return [-qc / qb, -1.0];
        }
    } else {
        let disc = qb * qb - 4.0 * qa * qc;
        if disc >= 0.0 {
            let q = -0.5 * (qb + qb.signum() * disc.sqrt());
            if q != 0.0 {
                return [q / qa, qc / q];
            }
        }
    }
    [-1.0, -1.0]
}

/// Largest `|y|` over `[0, h]` of the quintic Hermite through `(y, y', y'')` at both ends.
/// Used for peak displacements over free record steps, where the cubic's error,
/// `(omega h)^4 / 384`, reaches 5e-3 at `omega h` = 1.3; the quintic's is about
/// `(omega h)^6 / 46080`. Its extrema lie near the cubic's: each cubic extremum inside the step
/// is refined by three Newton steps on the quintic's derivative.
pub(crate) fn quintic_peak_abs(y: [f64; 2], d: [f64; 2], a: [f64; 2], h: f64) -> f64 {
    let (m0, m1, q0, q1) = (h * d[0], h * d[1], h * h * a[0], h * h * a[1]);
    let dy = y[1] - y[0];
    let c2 = 0.5 * q0;
    let c3 = 10.0 * dy - 6.0 * m0 - 4.0 * m1 - 1.5 * q0 + 0.5 * q1;
    let c4 = -15.0 * dy + 8.0 * m0 + 7.0 * m1 + 1.5 * q0 - q1;
    let c5 = 6.0 * dy - 3.0 * m0 - 3.0 * m1 - 0.5 * q0 + 0.5 * q1;
    let mut peak = y[0].abs().max(y[1].abs());
    let b = 3.0 * dy - 2.0 * m0 - m1;
    let c = -2.0 * dy + m0 + m1;
    for s0 in hermite_extrema(m0, b, c) {
        if !(s0 > 0.0 && s0 < 1.0) {
            continue;
        }
        let mut s = s0;
        for _ in 0..3 {
            let d1 = m0 + s * (2.0 * c2 + s * (3.0 * c3 + s * (4.0 * c4 + s * 5.0 * c5)));
            let d2 = 2.0 * c2 + s * (6.0 * c3 + s * (12.0 * c4 + s * 20.0 * c5));
            if d2 != 0.0 {
                s = (s - d1 / d2).clamp(0.0, 1.0);
            }
        }
        let v = y[0] + s * (m0 + s * (c2 + s * (c3 + s * (c4 + s * c5))));
        peak = peak.max(v.abs());
    }
    peak
}

/// Bound on `|u''''|` of a free oscillator over a step (inside a step `ag'' = 0`), for the
/// Hermite error margin of the near-contact test.
fn fourth_derivative_bound(o: &Oscillator, u: f64, v: f64, seg: &Segment) -> f64 {
    let w2 = o.k / o.m;
    let cm = o.c / o.m;
    let a2 = w2 * u + cm * v + seg.a0.abs().max(seg.a1.abs());
    let a3 = w2 * v + cm * a2 + ((seg.a1 - seg.a0) / seg.dt).abs();
    w2 * a2 + cm * a3
}

/// Could the bodies touch inside a free step from `z0` to `z1` (length `h`)? Uses the Hermite
/// cubic of `delta` plus twice its interpolation-error bound `h^4/384 max|delta''''|`.
pub(crate) fn may_touch(p: &Pair, seg: &Segment, z0: &State, z1: &State, h: f64, v0: f64) -> bool {
    let (d0, d1) = (delta(p, z0), delta(p, z1));
    if p.contact.gauge(d0, ddelta(z0), v0) > 0.0 || p.contact.gauge(d1, ddelta(z1), v0) > 0.0 {
        return true;
    }
    let (_, hi) = hermite_range(d0, ddelta(z0), d1, ddelta(z1), h);
    let (u1, v1) = (z0[0].abs().max(z1[0].abs()), z0[1].abs().max(z1[1].abs()));
    let (u2, v2) = (z0[2].abs().max(z1[2].abs()), z0[3].abs().max(z1[3].abs()));
    let bound =
        fourth_derivative_bound(&p.b1, u1, v1, seg) + fourth_derivative_bound(&p.b2, u2, v2, seg);
    let h2 = h * h;
    hi > -2.0 * h2 * h2 / 384.0 * bound
}

/// Peaks and impact bookkeeping shared by both schemes.
pub(crate) struct Tracker {
    pub out: RunOutput,
    /// Approach speed of the current impact.
    pub v0: f64,
    imp_peak: f64,
    /// Kinetic plus strain energy at the start, and the largest `initial + input` so far (the
    /// energy balance's scale).
    e_initial: f64,
    e_peak: f64,
    /// Onset time of the current impact; force-sample times are kept relative to it, as the
    /// shader does (so f32 times keep their resolution late in a record).
    t_onset: f64,
    hist: [(f64, f64); 2],
    nhist: usize,
    impacts_ended: u32,
}

impl Tracker {
    pub fn new() -> Tracker {
        Tracker {
            out: RunOutput::default(),
            v0: 0.0,
            imp_peak: 0.0,
            e_initial: 0.0,
            e_peak: 0.0,
            t_onset: 0.0,
            hist: [(0.0, 0.0); 2],
            nhist: 0,
            impacts_ended: 0,
        }
    }

    /// Onset time of the current (or last) impact.
    pub fn onset_time(&self) -> f64 {
        self.t_onset
    }

    pub fn impacts_ended(&self) -> u32 {
        self.impacts_ended
    }

    /// Account for a free record step over `seg`, from `z0` to `z1`: peak displacements from
    /// the quintic Hermite (both ends' accelerations are known in free flight).
    pub fn free_step(&mut self, p: &Pair, seg: &Segment, z0: &State, z1: &State) {
        let acc =
            |o: &crate::model::Oscillator, u: f64, v: f64, ag: f64| (-o.c * v - o.k * u) / o.m - ag;
        let o = &mut self.out;
        let a1 = [
            acc(&p.b1, z0[0], z0[1], seg.a0),
            acc(&p.b1, z1[0], z1[1], seg.a1),
        ];
        let pk = quintic_peak_abs([z0[0], z1[0]], [z0[1], z1[1]], a1, seg.dt);
        o.peak_u1 = o.peak_u1.max(pk);
        let a2 = [
            acc(&p.b2, z0[2], z0[3], seg.a0),
            acc(&p.b2, z1[2], z1[3], seg.a1),
        ];
        let pk = quintic_peak_abs([z0[2], z1[2]], [z0[3], z1[3]], a2, seg.dt);
        o.peak_u2 = o.peak_u2.max(pk);
        self.e_peak = self.e_peak.max(self.e_initial + z1[5]);
    }

    /// Account for a step `t0 -> t0 + h` spent in `mode`, from `z0` to `z1`.
    pub fn step(&mut self, p: &Pair, mode: Mode, t0: f64, h: f64, z0: &State, z1: &State) {
        let o = &mut self.out;
        let (lo, hi) = hermite_range(z0[0], z0[1], z1[0], z1[1], h);
        o.peak_u1 = o.peak_u1.max(hi.abs()).max(lo.abs());
        let (lo, hi) = hermite_range(z0[2], z0[3], z1[2], z1[3], h);
        o.peak_u2 = o.peak_u2.max(hi.abs()).max(lo.abs());
        self.e_peak = self.e_peak.max(self.e_initial + z1[5]);
        if mode != Mode::Free {
            o.contact_time += h;
            let (_, dmax) = hermite_range(delta(p, z0), ddelta(z0), delta(p, z1), ddelta(z1), h);
            o.peak_penetration = o.peak_penetration.max(dmax);
            o.dissipated_energy = z1[4];
            let f = force(p, mode, self.v0, z1);
            self.force_sample(t0 + h - self.t_onset, f);
        }
    }

    /// A force sample `t` after the onset of the current impact; a local maximum of three samples is refined by
    /// the vertex of their parabola.
    fn force_sample(&mut self, t: f64, f: f64) {
        self.imp_peak = self.imp_peak.max(f);
        if self.nhist == 2 {
            let [(x0, y0), (x1, y1)] = self.hist;
            if y1 >= y0 && y1 >= f && x1 > x0 && t > x1 {
                let d1 = (y1 - y0) / (x1 - x0);
                let d2 = (f - y1) / (t - x1);
                let a = (d2 - d1) / (t - x0);
                if a < 0.0 {
                    // Newton form around x0, x1: y(x) = y0 + d1 (x - x0) + a (x - x0)(x - x1).
                    let xv = (0.5 * (x0 + x1) - 0.5 * d1 / a).clamp(x0, t);
                    let yv = y0 + d1 * (xv - x0) + a * (xv - x0) * (xv - x1);
                    self.imp_peak = self.imp_peak.max(yv);
                }
            }
            self.hist = [self.hist[1], (t, f)];
        } else {
            self.hist[self.nhist] = (t, f);
            self.nhist += 1;
        }
    }

    pub fn onset(&mut self, t: f64, v0: f64, f: f64) {
        self.out.impacts += 1;
        if self.out.first_impact.is_none() {
            self.out.first_impact = Some(t);
        }
        self.v0 = v0;
        self.imp_peak = 0.0;
        self.t_onset = t;
        self.nhist = 0;
        self.force_sample(0.0, f);
    }

    pub fn end_impact(&mut self) {
        if self.imp_peak > self.out.peak_force {
            self.out.peak_force = self.imp_peak;
            self.out.impact_velocity = self.v0;
        }
        self.impacts_ended += 1;
    }

    pub fn finish(mut self, mode: Mode, status: Status) -> RunOutput {
        if mode != Mode::Free {
            self.end_impact();
        }
        self.out.status = status;
        self.out
    }

    /// The energy balance at state `z`.
    pub fn energy(&self, p: &Pair, z: &State) -> EnergyBalance {
        let held = mechanical_energy(p, z);
        EnergyBalance::close(self.e_initial, z[5], z[6], z[4], held, self.e_peak)
    }
}

/// Kinetic plus strain energy of both buildings, J.
pub(crate) fn mechanical_energy(p: &Pair, z: &State) -> f64 {
    p.b1.energy(z[0], z[1]) + p.b2.energy(z[2], z[3])
}

/// The state of one run being integrated, shared by both schemes: they decide step lengths and
/// take trial steps; [`Integration::accept`] does the rest.
pub(crate) struct Integration<'a, 'o> {
    pub pair: &'a Pair,
    pub z: State,
    pub mode: Mode,
    pub tr: Tracker,
    /// Report the energy balance (its integrals are complete).
    pub energy: bool,
    observer: Option<&'o mut dyn FnMut(&Sample)>,
}

impl<'a, 'o> Integration<'a, 'o> {
    /// Start at `t0` from `init` (already in contact if the bodies overlap).
    pub fn start(
        pair: &'a Pair,
        init: &Initial,
        t0: f64,
        observer: Option<&'o mut dyn FnMut(&Sample)>,
    ) -> Self {
        let z = [init.u1, init.v1, init.u2, init.v2, 0.0, 0.0, 0.0];
        let mut run = Integration {
            pair,
            z,
            mode: Mode::Free,
            tr: Tracker::new(),
            energy: true,
            observer,
        };
        run.tr.e_initial = mechanical_energy(pair, &z);
        if event_value(pair, run.mode, 0.0, &z) > 0.0 {
            run.mode = transition(pair, run.mode, t0, &z, &z, &mut run.tr);
        }
        run.emit(t0);
        run
    }

    pub fn emit(&mut self, t: f64) {
        if let Some(obs) = self.observer.as_mut() {
            let force = force(self.pair, self.mode, self.tr.v0, &self.z);
            obs(&Sample {
                t,
                z: self.z,
                force,
                mode: self.mode,
            });
        }
    }

    /// The free record step over `seg` to `z1`, with no possible contact (already checked by the
    /// caller).
    pub fn free_step(&mut self, seg: &Segment, z1: State) {
        self.tr.free_step(self.pair, seg, &self.z, &z1);
        self.z = z1;
        self.emit(seg.t1());
    }

    /// Accept `trial`, the step `t -> t + h` in the current mode; `step(x)` re-takes it with
    /// length `x`. A touch hidden inside a free step and any event inside the step are located
    /// (to `tol_rel * h`, at most `max_iter` iterations); the step then ends there. Updates peaks
    /// and mode and returns the length advanced.
    pub fn accept(
        &mut self,
        t: f64,
        h: f64,
        trial: State,
        tol_rel: f64,
        max_iter: u32,
        mut step: impl FnMut(f64) -> State,
    ) -> f64 {
        let (p, mode, v0, z0) = (self.pair, self.mode, self.tr.v0, self.z);
        let (mut trial, mut h) = (trial, h);
        let mut f1 = event_value(p, mode, v0, &trial);
        if mode == Mode::Free && f1 <= 0.0 {
            if let Some(s) = hidden_touch(p, &z0, &trial, h) {
                let zs = step(s * h);
                let fs = event_value(p, mode, v0, &zs);
                if fs > 0.0 {
                    (trial, f1, h) = (zs, fs, s * h);
                }
            }
        }
        let advanced = if f1 > 0.0 {
            let f0 = event_value(p, mode, v0, &z0);
            let tol = (tol_rel * h).max(4.0 * f64::EPSILON * t.abs());
            let eval = |s: &State| event_value(p, mode, v0, s);
            let (x, zb) = locate(h, f0, trial, f1, tol, max_iter, &mut step, eval);
            self.tr.step(p, mode, t, x, &z0, &zb);
            self.mode = transition(p, mode, t + x, &zb, &z0, &mut self.tr);
            self.z = zb;
            x
        } else {
            self.tr.step(p, mode, t, h, &z0, &trial);
            self.z = trial;
            self.mode = reapproach(mode, &self.z);
            h
        };
        self.emit(t + advanced);
        advanced
    }

    /// End the run with `status`, after `substeps` steps of integration work.
    pub fn finish(self, status: Status, substeps: u64) -> RunOutput {
        let energy = self.energy.then(|| self.tr.energy(self.pair, &self.z));
        let mut out = self.tr.finish(self.mode, status);
        out.substeps = substeps;
        out.energy = energy;
        out
    }
}

/// Apply the mode change an event at state `z` (time `t`) calls for; `before` is the state at
/// the start of the step in which the event was located.
pub(crate) fn transition(
    p: &Pair,
    mode: Mode,
    t: f64,
    z: &State,
    before: &State,
    tr: &mut Tracker,
) -> Mode {
    match mode {
        Mode::Free => {
            let v = ddelta(z);
            // A first touch takes v0 = delta' at delta = 0. A clamped law that re-engages while
            // still overlapping (force back above 0) continues the previous impact's v0.
            let v0 = if delta(p, before) <= 0.0 || tr.v0 <= 0.0 {
                v.abs()
            } else {
                tr.v0
            };
            let v0 = v0.max(1e-12);
            let next = if v > 0.0 {
                Mode::Approach
            } else {
                Mode::Restitution
            };
            tr.onset(t, v0, force(p, next, v0, z));
            next
        }
        Mode::Approach => Mode::Restitution,
        Mode::Restitution => {
            tr.end_impact();
            Mode::Free
        }
    }
}

/// After a step without a located event: a restituting contact that starts to close again goes
/// back to the approach phase.
#[inline]
pub(crate) fn reapproach(mode: Mode, z: &State) -> Mode {
    if mode == Mode::Restitution && ddelta(z) > 0.0 {
        Mode::Approach
    } else {
        mode
    }
}

pub(crate) fn finite(z: &State) -> bool {
    z.iter().all(|x| x.is_finite())
}

#[cfg(test)]
mod tests {
    use super::quintic_peak_abs;

    /// Exact for a quintic, and within its error bound `(omega h)^6 / 46080` for a sine whose
    /// crest lies inside the step (where the cubic Hermite is off by up to `(omega h)^4 / 384`).
    #[test]
    fn quintic_peak_is_exact_for_quintics_and_tight_for_sines() {
        let p = |t: f64| 0.3 + t * (1.0 + t * (-2.0 + t * (0.5 + t * (0.2 - 0.1 * t))));
        let dp = |t: f64| 1.0 + t * (-4.0 + t * (1.5 + t * (0.8 - 0.5 * t)));
        let ddp = |t: f64| -4.0 + t * (3.0 + t * (2.4 - 2.0 * t));
        let h = 1.0;
        let exact = (0..=100_000)
            .map(|i| p(i as f64 * 1e-5).abs())
            .fold(0.0, f64::max);
        let got = quintic_peak_abs([p(0.0), p(h)], [dp(0.0), dp(h)], [ddp(0.0), ddp(h)], h);
        assert!((got - exact).abs() < 1e-9, "{got} vs {exact}");
        for wh in [0.3f64, 0.8, 1.3] {
            // Step [1.2, 2.2]: the crest pi / (2 w) lies inside for w = 0.8 and 1.3, not 0.3.
            let (w, t0) = (wh, 1.2);
            let t1 = t0 + 1.0;
            let y = |t: f64| (w * t).sin();
            let got = quintic_peak_abs(
                [y(t0), y(t1)],
                [w * (w * t0).cos(), w * (w * t1).cos()],
                [-w * w * y(t0), -w * w * y(t1)],
                1.0,
            );
            let truth = if (t0..t1).contains(&(std::f64::consts::FRAC_PI_2 / w)) {
                1.0
            } else {
                y(t0).abs().max(y(t1).abs())
            };
            assert!(
                (got - truth).abs() <= wh.powi(6) / 46080.0 * 2.0 + 1e-15,
                "omega h = {wh}: {got} vs {truth}"
            );
        }
    }
}
