//! The shared free response: runs that differ only in their gap and contact law (same
//! buildings, record and intensity, from rest) move identically until their first contact, and
//! after their last one they move as that same free response plus a free vibration of each
//! building that only decays. [`FreeResponse`] steps the two buildings once, with the same
//! propagator and peak search as a run (so the states and peaks agree to the bit), and keeps
//! what lets a run of the fast scheme
//!
//! - start at its first possible contact: the first step whose contact reach (the smallest gap
//!   `may_touch` could fail to clear, `events::contact_reach`) comes within its gap, found by binary
//!   search in the reach's running maximum; a run that never gets there costs O(log n);
//! - end early with the same output: once free, a run's motion is the shared one plus a free
//!   vibration of energy at most what it has now, so `|u - u_shared| <= R` and
//!   `|v - v_shared| <= omega R` for the rest of the record, where
//!   `R = sqrt(e_u^2 + (e_v / omega)^2)` (damping only takes energy out). When the suffix maxima
//!   of the reach and of the peak bounds, grown by `R`, clear the gap and the run's peaks, no
//!   later step could have touched or raised a peak. A response built
//!   [`FreeResponse::with_accel`] keeps the buildings' peak absolute accelerations and their
//!   bounds too (`|a - a_shared| <= (omega^2 + (c/m) omega) R`, its rate's likewise), for the
//!   runs that report them.
//!
//! Both shortcuts are exact: the output is the one the run would have stepped to, field for
//! field; only the work counters (`free_steps`, `shared_steps`) differ.

pub(crate) use super::events::REACH_SLACK;
use super::events::{contact_reach, contact_reach_growth};
use super::hermite::{cubic_abs_bound, quintic_max_bound, CUBIC_SLOPE_WEIGHT};
use super::state::{Segment, State};
use super::tracker::{free_accel, free_accel_and_jerk, free_accel_peak, free_peak};
use crate::physics::model::{Forcing, Initial, Oscillator, Pair};
use crate::physics::propagator::Propagator;

/// The free response of two buildings under one forcing, with the maxima runs look up.
pub struct FreeResponse<'f> {
    b: [Oscillator; 2],
    forcing: Forcing<'f>,
    /// `[u1, v1, u2, v2]` at each record sample `0..=n`.
    state: Vec<[f64; 4]>,
    /// Peak `|u1|`, `|u2|`, `|a1|`, `|a2|` after `j` free steps, `j = 0..=n`, as a run's
    /// tracker finds them (the accelerations' 0 unless `accel`).
    peaks: Vec<[f64; 4]>,
    /// Contact reach of each step, and its largest value over steps `0..=j`.
    reach: Vec<f64>,
    reach_before: Vec<f64>,
    /// Largest contact reach over steps `j..n` (`-inf` at `n`).
    reach_after: Vec<f64>,
    /// Bound on each building's quintic over each step, with slack, and its largest value over
    /// steps `j..n` (0 at `n`); then, where `accel`, the same of its acceleration's cubic.
    peak_bound: Vec<[f64; 4]>,
    peak_bound_after: Vec<[f64; 4]>,
    omega: [f64; 2],
    /// Growth of the reach and of the peak bounds per metre of `R`, per building (the
    /// displacements', then the accelerations').
    reach_growth: [f64; 2],
    peak_growth: [f64; 4],
    accel: bool,
}

impl<'f> FreeResponse<'f> {
    /// Step `b1` and `b2` from rest through `forcing`.
    pub fn new(b1: &Oscillator, b2: &Oscillator, forcing: &Forcing<'f>) -> Self {
        Self::build(b1, b2, forcing, false)
    }

    /// As [`FreeResponse::new`], keeping the buildings' peak absolute accelerations too (for
    /// [`super::simulate_tracking_accel`]).
    pub fn with_accel(b1: &Oscillator, b2: &Oscillator, forcing: &Forcing<'f>) -> Self {
        Self::build(b1, b2, forcing, true)
    }

    /// Does it keep the peak accelerations?
    pub(crate) fn accel(&self) -> bool {
        self.accel
    }

    fn build(b1: &Oscillator, b2: &Oscillator, forcing: &Forcing<'f>, accel: bool) -> Self {
        let n = forcing.intervals();
        let dt = forcing.dt;
        let (p1, p2) = (Propagator::new(b1, dt), Propagator::new(b2, dt));
        let mut state = Vec::with_capacity(n + 1);
        let mut peaks = Vec::with_capacity(n + 1);
        let mut reach = Vec::with_capacity(n);
        let mut peak_bound = Vec::with_capacity(n);
        let (mut s, mut pk) = ([0.0; 4], [0.0; 4]);
        state.push(s);
        peaks.push(pk);
        for i in 0..n {
            let seg = Segment::of(forcing, i);
            let (u1, v1) = p1.step(s[0], s[1], seg.a0, seg.a1);
            let (u2, v2) = p2.step(s[2], s[3], seg.a0, seg.a1);
            let s1 = [u1, v1, u2, v2];
            let (z0, z1) = (full(&s), full(&s1));
            reach.push(contact_reach(b1, b2, &seg, &z0, &z1, dt));
            pk[0] = free_peak(b1, pk[0], &seg, [s[0], s[1]], [u1, v1]);
            pk[1] = free_peak(b2, pk[1], &seg, [s[2], s[3]], [u2, v2]);
            if accel {
                pk[2] = free_accel_peak(b1, pk[2], &seg, [s[0], s[1]], [u1, v1]);
                pk[3] = free_accel_peak(b2, pk[3], &seg, [s[2], s[3]], [u2, v2]);
            }
            let bound = |o: &Oscillator, k: usize| {
                let a = [
                    free_accel(o, s[k], s[k + 1], seg.a0),
                    free_accel(o, s1[k], s1[k + 1], seg.a1),
                ];
                let y = [s[k], s1[k]];
                let b = quintic_max_bound(y, [s[k + 1], s1[k + 1]], a, dt);
                b * (1.0 + REACH_SLACK)
            };
            let accel_bound = |o: &Oscillator, k: usize| {
                if !accel {
                    return 0.0;
                }
                let (a0, j0) = free_accel_and_jerk(o, s[k], s[k + 1], seg.a0);
                let (a1, j1) = free_accel_and_jerk(o, s1[k], s1[k + 1], seg.a1);
                cubic_abs_bound(a0, j0, a1, j1, dt) * (1.0 + REACH_SLACK)
            };
            peak_bound.push([
                bound(b1, 0),
                bound(b2, 2),
                accel_bound(b1, 0),
                accel_bound(b2, 2),
            ]);
            s = s1;
            state.push(s);
            peaks.push(pk);
        }
        let reach_before: Vec<f64> = reach
            .iter()
            .scan(f64::NEG_INFINITY, |m, &r| {
                *m = m.max(r);
                Some(*m)
            })
            .collect();
        let mut reach_after = vec![f64::NEG_INFINITY; n + 1];
        let mut peak_bound_after = vec![[0.0f64; 4]; n + 1];
        for j in (0..n).rev() {
            reach_after[j] = reach_after[j + 1].max(reach[j]);
            let (a, b) = (peak_bound_after[j + 1], peak_bound[j]);
            peak_bound_after[j] = std::array::from_fn(|q| a[q].max(b[q]));
        }
        let growth = |o: &Oscillator| {
            let (w2, cm) = (o.k / o.m, o.c / o.m);
            let w = w2.sqrt();
            // The quintic bound is affine in |u|, |v|, |a|; per metre of R they grow by 1,
            // omega and (c/m) omega + omega^2 at both ends.
            let g = quintic_max_bound([1.0; 2], [w; 2], [cm * w + w2; 2], dt);
            // The acceleration `-(c v + k u) / m` by `(c/m) omega + omega^2`, its rate
            // `-(c a + k v) / m` by `(c/m)` that plus `omega^3`; the cubic's bound is affine
            // in both.
            let ga = cm * w + w2;
            let gj = cm * ga + w2 * w;
            let g_accel = ga + CUBIC_SLOPE_WEIGHT * dt * 2.0 * gj;
            (
                w,
                contact_reach_growth(o, dt),
                g * (1.0 + 2.0 * REACH_SLACK),
                g_accel * (1.0 + 2.0 * REACH_SLACK),
            )
        };
        let (g1, g2) = (growth(b1), growth(b2));
        FreeResponse {
            b: [*b1, *b2],
            forcing: *forcing,
            state,
            peaks,
            reach,
            reach_before,
            peak_bound,
            reach_after,
            peak_bound_after,
            omega: [g1.0, g2.0],
            reach_growth: [g1.1, g2.1],
            peak_growth: [g1.2, g2.2, g1.3, g2.3],
            accel,
        }
    }

    /// Is this the free response of `pair`'s buildings under `forcing` from `init`?
    pub fn serves(&self, pair: &Pair, forcing: &Forcing, init: &Initial) -> bool {
        let f = &self.forcing;
        self.b == [pair.b1, pair.b2]
            && std::ptr::eq(f.accel, forcing.accel)
            && (f.dt, f.t0, f.scale, f.tail)
                == (forcing.dt, forcing.t0, forcing.scale, forcing.tail)
            && *init == Initial::default()
    }

    /// The first record step a run with this gap could touch in (`n`: none).
    pub fn first_possible_contact(&self, gap: f64) -> usize {
        let clear = gap * (1.0 - REACH_SLACK);
        self.reach_before.partition_point(|&r| r < clear)
    }

    /// The state at sample `i` and the peaks after `i` steps (`[u1, u2, a1, a2]`).
    pub(crate) fn at(&self, i: usize) -> (State, [f64; 4]) {
        (full(&self.state[i]), self.peaks[i])
    }

    /// Record steps the response covers (samples `0..=intervals()`).
    pub(crate) fn intervals(&self) -> usize {
        self.reach.len()
    }

    /// The largest contact reach and each building's largest peak bound over steps `i..` (what
    /// [`Self::can_end`] grows by `R`).
    pub(crate) fn maxima_after(&self, i: usize) -> (f64, [f64; 2]) {
        let b = self.peak_bound_after[i];
        (self.reach_after[i], [b[0], b[1]])
    }

    /// Each building's largest acceleration bound over steps `i..` (0 unless `accel`).
    pub(crate) fn accel_bounds_after(&self, i: usize) -> [f64; 2] {
        let b = self.peak_bound_after[i];
        [b[2], b[3]]
    }

    /// Per building, the growth of its acceleration bound per metre of `R`.
    pub(crate) fn accel_growth(&self) -> [f64; 2] {
        [self.peak_growth[2], self.peak_growth[3]]
    }

    /// Per building: `omega`, and the growth of the reach and of the peak bound per metre of
    /// `R` (what [`Self::distance`], [`Self::clears`] and [`Self::can_end`] use).
    pub(crate) fn rates(&self) -> [[f64; 2]; 3] {
        let g = self.peak_growth;
        [self.omega, self.reach_growth, [g[0], g[1]]]
    }

    /// `R` of each building for a free run at state `z` at sample `i`: its motion differs from
    /// the shared one by a free vibration with `|u - u_shared| <= R` and
    /// `|v - v_shared| <= omega R` from here on, as long as it steps free.
    #[inline]
    pub(crate) fn distance(&self, i: usize, z: &State) -> [f64; 2] {
        let s = &self.state[i];
        let r = |k: usize, b: usize| {
            let (eu, ev) = (z[k] - s[k], (z[k + 1] - s[k + 1]) / self.omega[b]);
            (eu * eu + ev * ev).sqrt() * (1.0 + REACH_SLACK)
        };
        [r(0, 0), r(2, 1)]
    }

    #[inline]
    fn clear_of(&self, reach: f64, r: [f64; 2], gap: f64) -> bool {
        reach + self.reach_growth[0] * r[0] + self.reach_growth[1] * r[1]
            < gap * (1.0 - REACH_SLACK)
    }

    /// Does record step `j` stay clear of contact for a free run at distance `r` from the
    /// shared motion? (Then `may_touch` would say no.)
    #[inline]
    pub(crate) fn clears(&self, j: usize, r: [f64; 2], gap: f64) -> bool {
        self.clear_of(self.reach[j], r, gap)
    }

    /// For each peak (`[u1, u2, a1, a2]`), can record step `j` not raise it for a free run at
    /// distance `r`? (The accelerations' are settled where the response does not keep them:
    /// such a run does not track them.)
    #[inline]
    pub(crate) fn peaks_settled(&self, j: usize, r: [f64; 2], peaks: [f64; 4]) -> [bool; 4] {
        let pb = &self.peak_bound[j];
        let settled = |q: usize| pb[q] + self.peak_growth[q] * r[q % 2] < peaks[q];
        [
            settled(0),
            settled(1),
            !self.accel || settled(2),
            !self.accel || settled(3),
        ]
    }

    /// Can a free run at distance `r` at sample `i`, with this gap and these peaks, end here
    /// with the output it would step to? (See the module's notes.)
    #[inline]
    pub(crate) fn can_end(&self, i: usize, r: [f64; 2], gap: f64, peaks: [f64; 4]) -> bool {
        let pb = self.peak_bound_after[i];
        let below = |q: usize| pb[q] + self.peak_growth[q] * r[q % 2] < peaks[q];
        self.clear_of(self.reach_after[i], r, gap)
            && below(0)
            && below(1)
            && (!self.accel || (below(2) && below(3)))
    }
}

fn full(s: &[f64; 4]) -> State {
    [s[0], s[1], s[2], s[3], 0.0, 0.0, 0.0]
}
