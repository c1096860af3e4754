//! One contact level: its penetration and rate in a state, its force, its event value and the
//! bounds that say whether a free step may touch; and each level's and yielding storey's record
//! in a run.

use super::algebra::dot;
use super::model::{LevelModel, RowModel};
use crate::physics::row::LevelOutput;
use crate::physics::solver::events::error_margin;
use crate::physics::solver::hermite::{cubic_max_bound, hermite_range};
use crate::physics::solver::state::{Mode, Segment};

impl LevelModel {
    /// Penetration `u_left - u_right - gap`.
    #[inline]
    pub(crate) fn delta(&self, z: &[f64]) -> f64 {
        let (a, b) = (self.a, self.b);
        dot(&self.phi_a, &z[a.0..a.0 + a.1]) - dot(&self.phi_b, &z[b.0..b.0 + b.1]) - self.gap
    }

    /// Penetration rate; `n` is the model's mode count (velocities follow the displacements).
    #[inline]
    pub(crate) fn ddelta(&self, n: usize, z: &[f64]) -> f64 {
        let (a, b) = (self.a, self.b);
        dot(&self.phi_a, &z[n + a.0..n + a.0 + a.1]) - dot(&self.phi_b, &z[n + b.0..n + b.0 + b.1])
    }

    /// The left floor's displacement (`n = 0`) or velocity (`n` the mode count).
    #[inline]
    pub(crate) fn left(&self, z: &[f64], n: usize) -> f64 {
        dot(&self.phi_a, &z[n + self.a.0..n + self.a.0 + self.a.1])
    }

    /// The right floor's displacement (`n = 0`) or velocity (`n` the mode count).
    #[inline]
    pub(crate) fn right(&self, z: &[f64], n: usize) -> f64 {
        dot(&self.phi_b, &z[n + self.b.0..n + self.b.0 + self.b.1])
    }

    /// `delta''` from the structures alone (no contact force; the ground motion cancels).
    pub(crate) fn structural_rel_accel(&self, m: &RowModel, z: &[f64]) -> f64 {
        let n = m.n;
        let acc = |phi: &[f64], (o, len): (usize, usize)| -> f64 {
            (0..len)
                .map(|i| phi[i] * (-m.two_xi_w[o + i] * z[n + o + i] - m.w2[o + i] * z[o + i]))
                .sum()
        };
        let coupled = |k: usize, phi: &[f64], (o, len): (usize, usize)| -> f64 {
            match &m.buildings[k].modes.coupling {
                Some(e) if len == e.len() => (0..len)
                    .map(|i| phi[i] * dot(&e[i], &z[n + o..n + o + len]))
                    .sum(),
                _ => 0.0,
            }
        };
        acc(&self.phi_a, self.a)
            - acc(&self.phi_b, self.b)
            - coupled(self.buildings.0, &self.phi_a, self.a)
            + coupled(self.buildings.1, &self.phi_b, self.b)
    }

    /// Contact force in `mode`.
    #[inline]
    pub(crate) fn force(&self, n: usize, mode: Mode, v0: f64, z: &[f64]) -> f64 {
        match mode {
            Mode::Free => 0.0,
            _ => self
                .contact
                .force(self.delta(z), self.ddelta(n, z), v0, mode == Mode::Approach),
        }
    }

    /// Positive once `mode` must end: first touch (free), the turn `delta' = 0` (approach),
    /// and in restitution separation (as the pair's `event_value`) or, where the law's force
    /// depends on the phase, the floors closing again, `delta' > 0`. That one is located too:
    /// in a sustained contact (floors pressed together, a gap of 0) such a law's force changes
    /// with the phase, and a re-approach noticed only at a piece's end is late by up to the
    /// piece, an error of order 2 in the substep where the scheme's is of order 4. (Where the
    /// phase changes nothing, it is switched at a piece's end: [`Self::reapproaches`].)
    #[inline]
    pub(crate) fn event_value(&self, n: usize, mode: Mode, v0: f64, z: &[f64]) -> f64 {
        let r = self.ddelta(n, z);
        let g = self.contact.gauge(self.delta(z), r, v0);
        match mode {
            Mode::Free => g,
            Mode::Approach => -r,
            Mode::Restitution if self.contact.kind.force_depends_on_phase() => (-g).max(r),
            Mode::Restitution => -g,
        }
    }

    /// Does the level, in `mode`, close again in state `z` (restitution with `delta' > 0`)?
    #[inline]
    pub(crate) fn reapproaches(&self, n: usize, mode: Mode, z: &[f64]) -> bool {
        mode == Mode::Restitution && self.ddelta(n, z) > 0.0
    }

    /// Could the level touch inside a free step from `z0` to `z1` (length `h`)? As the pair's
    /// `may_touch`: the Hermite cubic of `delta` plus twice its interpolation-error bound,
    /// `|delta''''|` bounded mode by mode.
    pub(crate) fn may_touch(
        &self,
        m: &RowModel,
        seg: &Segment,
        z0: &[f64],
        z1: &[f64],
        h: f64,
        v0: f64,
    ) -> bool {
        let mut bounds = Vec::new();
        m.fourth_derivative_bounds(seg, (z0, z1), &mut bounds, None);
        self.may_touch_bounded(m.n, &bounds, z0, z1, h, v0)
    }

    /// [`LevelModel::may_touch`] with each mode's `|q''''|` bound over the step already
    /// computed ([`RowModel::fourth_derivative_bounds`]): a free step checks every level
    /// against the same bounds, so they are computed once per step, not once per level.
    pub(crate) fn may_touch_bounded(
        &self,
        n: usize,
        bounds: &[f64],
        z0: &[f64],
        z1: &[f64],
        h: f64,
        v0: f64,
    ) -> bool {
        let ends = [
            self.delta(z0),
            self.ddelta(n, z0),
            self.delta(z1),
            self.ddelta(n, z1),
        ];
        self.may_touch_within(ends, self.fourth_derivative_bound(bounds), h, v0)
    }

    /// The bound on `|delta''''|` over a free step from each mode's bound on `|q''''|`.
    pub(crate) fn fourth_derivative_bound(&self, bounds: &[f64]) -> f64 {
        self.side_fourth_derivative_bound(true, bounds)
            + self.side_fourth_derivative_bound(false, bounds)
    }

    /// The bound on the left (or right) floor's `|u''''|`: `sum_i |phi_i| bound_i`.
    pub(crate) fn side_fourth_derivative_bound(&self, left: bool, bounds: &[f64]) -> f64 {
        let (phi, (o, len)) = if left {
            (&self.phi_a, self.a)
        } else {
            (&self.phi_b, self.b)
        };
        (0..len).map(|i| phi[i].abs() * bounds[o + i]).sum()
    }

    /// [`LevelModel::may_touch`] from the penetration and its rate at the step's ends,
    /// `[delta0, delta0', delta1, delta1']`, and a bound on `|delta''''|` over it. A larger bound
    /// only answers yes more often, so a "no" under a coarse bound is a "no" under the exact
    /// one.
    pub(crate) fn may_touch_within(&self, ends: [f64; 4], bound: f64, h: f64, v0: f64) -> bool {
        let [d0, r0, d1, r1] = ends;
        let margin = -error_margin(bound, h);
        if cubic_max_bound(d0, r0, d1, r1, h) <= margin {
            return false;
        }
        if self.contact.gauge(d0, r0, v0) > 0.0 || self.contact.gauge(d1, r1, v0) > 0.0 {
            return true;
        }
        hermite_range(d0, r0, d1, r1, h).1 > margin
    }
}

/// One yielding storey's record (its spring state is in [`RowRun::storey_modes`], and an IMK
/// storey's history here).
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct StoreyState {
    /// It has yielded at least once.
    pub yielded: bool,
    /// Its largest `|d| / h`.
    pub peak_drift_ratio: f64,
    /// An IMK storey's spring state (None: bilinear).
    pub imk: Option<crate::physics::imk::ImkState>,
}

/// The contact state of one level and its impact bookkeeping.
#[derive(Debug, Clone, Default)]
pub(crate) struct LevelState {
    pub mode: Mode,
    /// Approach speed of the current impact.
    pub v0: f64,
    pub t_onset: f64,
    pub(super) imp_peak: f64,
    /// On a struck column, the contact force and its rate at the tracked piece's two ends
    /// (`[F0, F0', F1, F1']`), a bound on `|F|` over it, and whether the piece begins at the
    /// touch or ends at the separation: the storey's column shear sums every level's.
    pub(super) column_load: ([f64; 4], f64, bool),
    pub out: LevelOutput,
}

impl LevelState {
    pub(super) fn onset(&mut self, t: f64, v0: f64, f: f64) {
        self.out.impacts += 1;
        if self.out.first_impact.is_none() {
            self.out.first_impact = Some(t);
        }
        self.v0 = v0;
        self.t_onset = t;
        self.imp_peak = f.max(0.0);
    }

    pub(super) fn end_impact(&mut self) {
        if self.imp_peak > self.out.peak_force {
            self.out.peak_force = self.imp_peak;
            self.out.impact_velocity = self.v0;
        }
    }
}
