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
//!   later step could have touched or raised a peak.
//!
//! Both shortcuts are exact: the output is the one the run would have stepped to, field for
//! field; only the work counters (`free_steps`, `shared_steps`) differ.

pub(crate) use super::events::REACH_SLACK;
use super::events::{contact_reach, contact_reach_growth};
use super::hermite::quintic_max_bound;
use super::tracker::{free_accel, free_peak};
use super::{Segment, State};
use crate::physics::model::{Forcing, Initial, Oscillator, Pair};
use crate::physics::propagator::Propagator;

/// The free response of two buildings under one forcing, with the maxima runs look up.
pub struct FreeResponse<'f> {
    b: [Oscillator; 2],
    forcing: Forcing<'f>,
    /// `[u1, v1, u2, v2]` at each record sample `0..=n`.
    state: Vec<[f64; 4]>,
    /// Peak `|u1|`, `|u2|` after `j` free steps, `j = 0..=n`, as a run's tracker finds them.
    peaks: Vec<[f64; 2]>,
    /// Contact reach of each step, and its largest value over steps `0..=j`.
    reach: Vec<f64>,
    reach_before: Vec<f64>,
    /// Largest contact reach over steps `j..n` (`-inf` at `n`).
    reach_after: Vec<f64>,
    /// Bound on each building's quintic over each step, with slack, and its largest value over
    /// steps `j..n` (0 at `n`).
    peak_bound: Vec<[f64; 2]>,
    peak_bound_after: Vec<[f64; 2]>,
    omega: [f64; 2],
    /// Growth of the reach and of the peak bounds per metre of `R`, per building.
    reach_growth: [f64; 2],
    peak_growth: [f64; 2],
}

impl<'f> FreeResponse<'f> {
    /// Step `b1` and `b2` from rest through `forcing`.
    pub fn new(b1: &Oscillator, b2: &Oscillator, forcing: &Forcing<'f>) -> Self {
        let n = forcing.intervals();
        let dt = forcing.dt;
        let (p1, p2) = (Propagator::new(b1, dt), Propagator::new(b2, dt));
        let mut state = Vec::with_capacity(n + 1);
        let mut peaks = Vec::with_capacity(n + 1);
        let mut reach = Vec::with_capacity(n);
        let mut peak_bound = Vec::with_capacity(n);
        let (mut s, mut pk) = ([0.0; 4], [0.0; 2]);
        state.push(s);
        peaks.push(pk);
        for i in 0..n {
            let seg = Segment::of(forcing, i);
            let (u1, v1) = p1.step(s[0], s[1], seg.a0, seg.a1);
            let (u2, v2) = p2.step(s[2], s[3], seg.a0, seg.a1);
            let s1 = [u1, v1, u2, v2];
            let (z0, z1) = (full(&s), full(&s1));
            reach.push(contact_reach(b1, b2, &seg, &z0, &z1, dt));
            pk = [
                free_peak(b1, pk[0], &seg, [s[0], s[1]], [u1, v1]),
                free_peak(b2, pk[1], &seg, [s[2], s[3]], [u2, v2]),
            ];
            let bound = |o: &Oscillator, k: usize| {
                let a = [
                    free_accel(o, s[k], s[k + 1], seg.a0),
                    free_accel(o, s1[k], s1[k + 1], seg.a1),
                ];
                let y = [s[k], s1[k]];
                let b = quintic_max_bound(y, [s[k + 1], s1[k + 1]], a, dt);
                b * (1.0 + REACH_SLACK)
            };
            peak_bound.push([bound(b1, 0), bound(b2, 2)]);
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
        let mut peak_bound_after = vec![[0.0f64; 2]; n + 1];
        for j in (0..n).rev() {
            reach_after[j] = reach_after[j + 1].max(reach[j]);
            let (a, b) = (peak_bound_after[j + 1], peak_bound[j]);
            peak_bound_after[j] = [a[0].max(b[0]), a[1].max(b[1])];
        }
        let growth = |o: &Oscillator| {
            let (w2, cm) = (o.k / o.m, o.c / o.m);
            let w = w2.sqrt();
            // The quintic bound is affine in |u|, |v|, |a|; per metre of R they grow by 1,
            // omega and (c/m) omega + omega^2 at both ends.
            let g = quintic_max_bound([1.0; 2], [w; 2], [cm * w + w2; 2], dt);
            (
                w,
                contact_reach_growth(o, dt),
                g * (1.0 + 2.0 * REACH_SLACK),
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
            peak_growth: [g1.2, g2.2],
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

    /// The state at sample `i` and the peaks after `i` steps.
    pub(crate) fn at(&self, i: usize) -> (State, [f64; 2]) {
        (full(&self.state[i]), self.peaks[i])
    }

    /// Record steps the response covers (samples `0..=intervals()`).
    pub(crate) fn intervals(&self) -> usize {
        self.reach.len()
    }

    /// The largest contact reach and each building's largest peak bound over steps `i..` (what
    /// [`Self::can_end`] grows by `R`).
    pub(crate) fn maxima_after(&self, i: usize) -> (f64, [f64; 2]) {
        (self.reach_after[i], self.peak_bound_after[i])
    }

    /// Per building: `omega`, and the growth of the reach and of the peak bound per metre of
    /// `R` (what [`Self::distance`], [`Self::clears`] and [`Self::can_end`] use).
    pub(crate) fn rates(&self) -> [[f64; 2]; 3] {
        [self.omega, self.reach_growth, self.peak_growth]
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

    /// For each building, can record step `j` not raise `peaks` for a free run at distance `r`?
    #[inline]
    pub(crate) fn peaks_settled(&self, j: usize, r: [f64; 2], peaks: [f64; 2]) -> [bool; 2] {
        let pb = &self.peak_bound[j];
        [0, 1].map(|b| pb[b] + self.peak_growth[b] * r[b] < peaks[b])
    }

    /// Can a free run at distance `r` at sample `i`, with this gap and these peaks, end here
    /// with the output it would step to? (See the module's notes.)
    #[inline]
    pub(crate) fn can_end(&self, i: usize, r: [f64; 2], gap: f64, peaks: [f64; 2]) -> bool {
        let pb = self.peak_bound_after[i];
        self.clear_of(self.reach_after[i], r, gap)
            && pb[0] + self.peak_growth[0] * r[0] < peaks[0]
            && pb[1] + self.peak_growth[1] * r[1] < peaks[1]
    }
}

fn full(s: &[f64; 4]) -> State {
    [s[0], s[1], s[2], s[3], 0.0, 0.0, 0.0]
}
