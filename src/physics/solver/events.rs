//! Locating the non-smooth instants inside a step: first touch, the turn, separation, and a
//! touch hidden inside a free step; the mode change each calls for.

use super::hermite::{cubic_max_bound, hermite_range, CUBIC_SLOPE_WEIGHT};
use super::state::{ddelta, delta, Mode, Segment, State};
use crate::physics::model::{Oscillator, Pair};

/// Event location in the fast schemes: the relative tolerance on the step and the most
/// iterations (`LOCATE_TOL` and `LOCATE_ITER` in the shaders).
pub const LOCATE_TOLERANCE: f64 = 1e-9;
pub const LOCATE_ITERATIONS: u32 = 16;

/// Bisections after event location's regula falsi iterations (in every scheme), enough to
/// close any bracket to its tolerance (`LOCATE_BISECT` in the shaders).
pub const LOCATE_BISECTIONS: u32 = 32;

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
/// when the estimate is good and keeps regula falsi from stalling on one side. If `max_iter`
/// such iterations leave the bracket wider than `tol` (a function regula falsi cannot model,
/// e.g. one that is 0 where the step starts), up to [`LOCATE_BISECTIONS`] bisections close it:
/// an event is never taken late by more than `tol`. Returns the length and state on the far
/// side of the event, so the next mode starts with a consistent sign.
#[allow(clippy::too_many_arguments)]
pub(crate) fn locate<S>(
    h: f64,
    f0: f64,
    z1: S,
    f1: f64,
    tol: f64,
    max_iter: u32,
    mut step: impl FnMut(f64) -> S,
    eval: impl Fn(&S) -> f64,
) -> (f64, S) {
    let mut loc = Locator::new(h, f0, f1, tol, max_iter);
    let mut zb = z1;
    while let Some(x) = loc.next() {
        let zx = step(x);
        if loc.take(x, eval(&zx)) {
            zb = zx;
        }
    }
    (loc.end(), zb)
}

/// [`locate`] as a state machine, one probe at a time: the GPU row kernel (`Locator` in
/// `shaders/row.wgsl`) keeps it between units of work, so a unit takes one RK4 step however
/// long the search.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Locator {
    /// The bracket: `f(a) <= 0 < f(b)`.
    a: f64,
    fa: f64,
    b: f64,
    fb: f64,
    tol: f64,
    /// The side the last estimate moved: 1 (b), -1 (a), 0 (none yet).
    last: i8,
    /// Iterations done (an estimate with its guard probe, or a bisection).
    it: u32,
    max_iter: u32,
    /// The guard probe due after the last estimate.
    guard: Option<f64>,
}

impl Locator {
    pub(crate) fn new(h: f64, f0: f64, f1: f64, tol: f64, max_iter: u32) -> Self {
        Locator {
            a: 0.0,
            fa: f0.min(0.0),
            b: h,
            fb: f1,
            tol,
            last: 0,
            it: 0,
            max_iter,
            guard: None,
        }
    }

    /// The length to probe next, or None once the bracket is closed.
    pub(crate) fn next(&self) -> Option<f64> {
        if let Some(g) = self.guard {
            return Some(g);
        }
        let (a, b) = (self.a, self.b);
        if self.it >= self.max_iter + LOCATE_BISECTIONS || b - a <= self.tol {
            return None;
        }
        let mut x = if self.it < self.max_iter && self.fb != self.fa {
            b - self.fb * (b - a) / (self.fb - self.fa)
        } else {
            0.5 * (a + b)
        };
        if !(x > a && x < b) {
            x = 0.5 * (a + b);
        }
        Some(x)
    }

    /// The event value `fx` at the probe `x` [`Self::next`] gave; true where `x` became the
    /// bracket's far end (its state is then the one to keep).
    pub(crate) fn take(&mut self, x: f64, fx: f64) -> bool {
        let fires = fx > 0.0;
        if self.guard.take().is_some() {
            if fires {
                (self.b, self.fb) = (x, fx);
            } else {
                (self.a, self.fa) = (x, fx);
            }
            self.it += 1;
            return fires;
        }
        let g = if fires {
            (self.b, self.fb) = (x, fx);
            if self.last == 1 {
                self.fa *= 0.5;
            }
            self.last = 1;
            x - 0.5 * self.tol
        } else {
            (self.a, self.fa) = (x, fx);
            if self.last == -1 {
                self.fb *= 0.5;
            }
            self.last = -1;
            x + 0.5 * self.tol
        };
        if self.it < self.max_iter && g > self.a && g < self.b {
            self.guard = Some(g);
        } else {
            self.it += 1;
        }
        fires
    }

    /// The far side of the event: where the search ends.
    pub(crate) fn end(&self) -> f64 {
        self.b
    }
}

/// In free mode a step whose end is still apart can hide a brief, grazing touch. If the Hermite
/// cubic of `delta` over the step rises above 0 inside, return the fraction of the step at its
/// maximum (the step is then re-taken to there and checked for the event).
#[inline]
pub(crate) fn hidden_touch(p: &Pair, z0: &State, z1: &State, h: f64) -> Option<f64> {
    hidden_rise(delta(p, z0), ddelta(z0), delta(p, z1), ddelta(z1), h)
}

/// [`hidden_touch`] for a penetration `y` with rate `d` at both ends of a step of length `h`.
#[inline]
pub(crate) fn hidden_rise(y0: f64, d0: f64, y1: f64, d1: f64, h: f64) -> Option<f64> {
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

/// Bound on `|u''''|` of a free oscillator over a step (inside a step `ag'' = 0`), for the
/// Hermite error margin of the near-contact test.
#[inline]
pub(crate) fn fourth_derivative_bound(o: &Oscillator, u: f64, v: f64, seg: &Segment) -> f64 {
    let w2 = o.k / o.m;
    let cm = o.c / o.m;
    let a2 = w2 * u + cm * v + seg.a0.abs().max(seg.a1.abs());
    let a3 = w2 * v + cm * a2 + ((seg.a1 - seg.a0) / seg.dt).abs();
    w2 * a2 + cm * a3
}

/// Twice the cubic Hermite's interpolation-error bound, `2 h^4/384 max|delta''''|`, for a
/// bound on `|delta''''|`.
#[inline]
pub(crate) fn error_margin(bound: f64, h: f64) -> f64 {
    let h2 = h * h;
    2.0 * h2 * h2 / 384.0 * bound
}

/// [`error_margin`] over the free step from `z0` to `z1` (length `h`), and the larger `|u1|` plus
/// the larger `|u2|` at its ends.
#[inline]
fn free_step_margin(
    b1: &Oscillator,
    b2: &Oscillator,
    seg: &Segment,
    z0: &State,
    z1: &State,
    h: f64,
) -> (f64, f64) {
    let (u1, v1) = (z0[0].abs().max(z1[0].abs()), z0[1].abs().max(z1[1].abs()));
    let (u2, v2) = (z0[2].abs().max(z1[2].abs()), z0[3].abs().max(z1[3].abs()));
    let bound = fourth_derivative_bound(b1, u1, v1, seg) + fourth_derivative_bound(b2, u2, v2, seg);
    (error_margin(bound, h), u1 + u2)
}

/// Could the bodies touch inside a free step from `z0` to `z1` (length `h`)? Uses the Hermite
/// cubic of `delta` plus twice its interpolation-error bound `h^4/384 max|delta''''|`.
#[inline]
pub(crate) fn may_touch(p: &Pair, seg: &Segment, z0: &State, z1: &State, h: f64, v0: f64) -> bool {
    let (d0, d1) = (delta(p, z0), delta(p, z1));
    let margin = -free_step_margin(&p.b1, &p.b2, seg, z0, z1, h).0;
    // Most free steps are far from the gap: the cubic's bound settles them without its
    // extrema. Below 0 it also settles the gauges, which are positive only where delta is.
    if cubic_max_bound(d0, ddelta(z0), d1, ddelta(z1), h) <= margin {
        return false;
    }
    if p.contact.gauge(d0, ddelta(z0), v0) > 0.0 || p.contact.gauge(d1, ddelta(z1), v0) > 0.0 {
        return true;
    }
    let (_, hi) = hermite_range(d0, ddelta(z0), d1, ddelta(z1), h);
    hi > margin
}

/// Relative slack of [`contact_reach`]: far above the rounding of the free steps (about
/// 1e-12 of the state over a long record) and of `may_touch`'s own bound.
pub(crate) const REACH_SLACK: f64 = 1e-6;

/// The smallest gap that the first test of [`may_touch`] could fail to clear over the free
/// step from `z0` to `z1` (only the buildings' motion, not the gap or the contact, enters):
/// a run with `gap * (1 - REACH_SLACK) > contact_reach` takes this step free for certain.
/// It is `may_touch`'s `cubic_max_bound(...) - margin` with the gap left out, plus slack.
#[inline]
pub(crate) fn contact_reach(
    b1: &Oscillator,
    b2: &Oscillator,
    seg: &Segment,
    z0: &State,
    z1: &State,
    h: f64,
) -> f64 {
    let (margin, u) = free_step_margin(b1, b2, seg, z0, z1, h);
    let slope = CUBIC_SLOPE_WEIGHT * h * (ddelta(z0).abs() + ddelta(z1).abs());
    let reach = (z0[0] - z0[2]).max(z1[0] - z1[2]) + slope + margin;
    reach + REACH_SLACK * (u + slope + margin)
}

/// How much [`contact_reach`] can grow per metre of `R`, where a run's motion differs from the
/// one it was computed on by a free (homogeneous) response of `o` with `|u| <= R` and
/// `|v| <= omega R` throughout: the reach's terms are affine in `|u|`, `|v|` and `u1 - u2`.
pub(crate) fn contact_reach_growth(o: &Oscillator, h: f64) -> f64 {
    let w = (o.k / o.m).sqrt();
    // fourth_derivative_bound's linear part at (|u|, |v|) = (1, omega): no ground motion.
    let still = Segment {
        t0: 0.0,
        dt: h,
        a0: 0.0,
        a1: 0.0,
    };
    let margin = error_margin(fourth_derivative_bound(o, 1.0, w, &still), h);
    let slope = CUBIC_SLOPE_WEIGHT * h * 2.0 * w;
    (1.0 + slope + margin) * (1.0 + 2.0 * REACH_SLACK)
}

/// The impact speed and contact mode of a touch located at penetration rate `v`, where the
/// step began at penetration `delta_before` and the last impact had speed `last_v0`. A first
/// touch takes `v0 = delta'` at `delta = 0`; a clamped law that re-engages while still
/// overlapping (force back above 0) continues the previous impact's `v0`.
#[inline]
pub(crate) fn touch(delta_before: f64, v: f64, last_v0: f64) -> (f64, Mode) {
    let v0 = if delta_before <= 0.0 || last_v0 <= 0.0 {
        v.abs()
    } else {
        last_v0
    };
    let next = if v > 0.0 {
        Mode::Approach
    } else {
        Mode::Restitution
    };
    (v0.max(1e-12), next)
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The search ends on the far side of the root, within its tolerance, for a function regula
    /// falsi models well (a line), one it stalls on (a steep exponential-like rise) and one that
    /// is 0 where the step starts (bisections close it).
    #[test]
    fn locate_ends_just_past_the_first_positive_instant() {
        type Case = (f64, fn(f64) -> f64);
        let cases: [Case; 3] = [
            (0.3, |x| x - 0.3),
            (0.7, |x| (x - 0.7) * (1.0 + 1e6 * (x - 0.7).max(0.0))),
            (0.25, |x| if x <= 0.25 { 0.0 } else { x - 0.25 }),
        ];
        for (root, f) in cases {
            let tol = 1e-9;
            let (x, zx) = locate(
                1.0,
                f(0.0),
                1.0,
                f(1.0),
                tol,
                LOCATE_ITERATIONS,
                |x| x,
                |&x| f(x),
            );
            assert_eq!(x, zx);
            assert!(f(x) > 0.0, "{root}: ends at {x}, f = {}", f(x));
            assert!(x > root && x - root <= tol, "{root}: ends at {x}");
        }
    }

    /// Driven one probe at a time, as the GPU kernel drives it between units of work, the
    /// search probes exactly where `locate` does and ends at the same length.
    #[test]
    fn the_locator_one_probe_at_a_time_is_locate() {
        let f = |x: f64| (x - 0.41) * (2.0 + x);
        let mut probes = Vec::new();
        let (x, _) = locate(
            0.9,
            f(0.0),
            0.9,
            f(0.9),
            1e-10,
            LOCATE_ITERATIONS,
            |x| {
                probes.push(x);
                x
            },
            |&x| f(x),
        );
        let mut loc = Locator::new(0.9, f(0.0), f(0.9), 1e-10, LOCATE_ITERATIONS);
        let mut resumed = Vec::new();
        while let Some(p) = loc.next() {
            // A copy, as the kernel stores and reloads it between dispatches.
            let mut kept = loc;
            kept.take(p, f(p));
            loc = kept;
            resumed.push(p);
        }
        assert!(!probes.is_empty());
        assert_eq!(probes, resumed);
        assert_eq!(loc.end(), x);
    }
}
