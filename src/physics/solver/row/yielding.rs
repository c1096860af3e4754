//! Yielding storeys in the row schemes (physics.md section 8).
//!
//! Storey `s` (storey `j` of building `b`) is a bilinear spring with kinematic hardening: its
//! force is `f = k (d - p)` with drift `d` and plastic drift `p`. While every storey is inside
//! its band, `p` is constant and the building is linear under the constant load `D^T K p`
//! (`D` the drift operator): free flight is the exact modal propagator about the static
//! response to that load ([`RowModel::static_offsets`]). On a bounding line the storey yields:
//! `p' = (1 - b) d'`, so the force moves with slope `b k`. The band is `|s| <= d_y` in the
//! back drift `s = d - p / (1 - b)` (the kinematic shift of the band), which stays at `+-d_y`
//! while yielding (RK steps keep linear invariants, so it does to rounding); yield onset and
//! unloading (the drift velocity reversing) are located events, like a touch. `p` and each
//! storey's plastic work `int f dp` are state: slots `2 n + nl + 2 + s` and `+ ns` after them.
//!
//! Residual drift: at rest every storey force is zero, so a storey's residual drift is its
//! plastic drift `p` once the motion can no longer yield. After the record that is decided by
//! energy: with no level in contact and every storey in its band, the row's mechanical
//! energy `E` (kinetic plus the springs' stored `f^2 / 2k`) can only fall (damping and contact
//! dissipate), and `|f| <= sqrt(2 k E)`, so `|s| <= sqrt(2 E / k) + b |p| / (1 - b)`; once
//! that is within every storey's band ([`RowModel::settled`]) no storey yields again and `p`
//! is the residual drift exactly. Until then the run goes on in free vibration (zero ground
//! motion), up to [`SETTLE_PERIODS`] of its longest period; a run that does not settle by
//! then reports no residual drift (empty), not a guess.

use super::algebra::dot;
use super::model::RowModel;
use super::run::RowRun;
use super::storey::StoreyMode;
// The band's slack, named here as the storeys' model (the GPU shader reads it by this path).
pub(crate) use super::storey::YIELD_SLACK;
use crate::physics::model::Forcing;
use crate::physics::shear::ImkRule;
use crate::physics::solver::state::Segment;

/// After the record, a run goes on in free vibration for at most this many of its longest
/// fundamental period until no storey can yield again ([`RowModel::settled`]).
pub const SETTLE_PERIODS: f64 = 50.0;

impl RowModel {
    /// Each building's yielding storeys in [`RowModel::storeys`] (None: elastic).
    pub(crate) fn storey_spans(&self) -> Vec<Option<std::ops::Range<usize>>> {
        self.buildings
            .iter()
            .map(|b| b.first_storey.map(|f| f..f + b.n()))
            .collect()
    }

    /// Slot of storey `s`'s plastic drift in the state; its plastic work follows `ns` later.
    #[inline]
    pub(crate) fn plastic_slot(&self, s: usize) -> usize {
        2 * self.n + self.levels.len() + 2 + s
    }

    /// The storeys in the model's coordinates for the buildings `in_floors` (after
    /// [`RowModel::substep_model`] sets them).
    pub(crate) fn storeys_to_coordinates(&mut self) {
        for s in self.storeys.iter_mut() {
            let b = &self.buildings[s.building];
            let j = s.storey;
            (s.off, s.row) = b.drift_row(j, &s.modal_row);
            s.psi = match (b.in_floors, j) {
                (false, _) => s.modal_row.clone(),
                (true, 0) => vec![1.0 / b.masses[0]],
                (true, j) => vec![-1.0 / b.masses[j - 1], 1.0 / b.masses[j]],
            };
        }
    }

    /// The static modal response to the plastic loads of modal state `z`: `q_i = G_i / w_i^2`
    /// with `G = Phi^T D^T K p`, for every mode, into `qs` (zeros with no plastic drift).
    pub(crate) fn static_offsets(&self, z: &[f64], qs: &mut [f64]) {
        qs.fill(0.0);
        for (s, sm) in self.storeys.iter().enumerate() {
            let kp = sm.k * z[self.plastic_slot(s)];
            if kp == 0.0 {
                continue;
            }
            let o = self.buildings[sm.building].off;
            for (i, r) in sm.modal_row.iter().enumerate() {
                qs[o + i] += r * kp / self.w2[o + i];
            }
        }
    }

    /// Storey `s`'s drift at rest as a combination of its building's plastic drifts: `d_s =
    /// sum_j c_j p_(first + j)` (the building's storeys from `first`), the static response
    /// [`RowModel::static_offsets`] gives, as one row. Without P-Delta `d_s = p_s`; with it
    /// gravity leans on every storey's plastic drift (the GPU's readback takes its residual
    /// drifts from it).
    pub(crate) fn residual_row(&self, s: usize) -> (usize, Vec<f64>) {
        let sm = &self.storeys[s];
        let b = &self.buildings[sm.building];
        let first = b.first_storey.expect("a yielding storey's building yields");
        let c = self.storeys[first..first + b.n()]
            .iter()
            .map(|other| {
                (0..b.n())
                    .map(|i| sm.modal_row[i] * other.modal_row[i] * other.k / self.w2[b.off + i])
                    .sum()
            })
            .collect();
        (first, c)
    }

    /// Building `k`'s plastic load and its rate in its current coordinates, added to `acc`
    /// and `jerk` (indexed by its modes or floors from 0): `psi k p` and `psi k p'`, `p'` from
    /// the storeys' `modes`.
    pub(crate) fn add_plastic(
        &self,
        k: usize,
        z: &[f64],
        modes: &[StoreyMode],
        acc: &mut [f64],
        jerk: &mut [f64],
    ) {
        let o = self.buildings[k].off;
        for (s, sm) in self.storeys.iter().enumerate() {
            if sm.building != k {
                continue;
            }
            let kp = sm.k * z[self.plastic_slot(s)];
            let kdp = match modes[s] {
                StoreyMode::Elastic => 0.0,
                mode => sm.k * sm.flow(mode) * sm.drift(z, self.n),
            };
            for (i, p) in sm.psi.iter().enumerate() {
                acc[sm.off - o + i] += p * kp;
                jerk[sm.off - o + i] += p * kdp;
            }
        }
    }

    /// The springs' stored energy less what the modes count as strain (`1/2 q^T W^2 q` is
    /// `sum 1/2 k d^2`; the springs hold `sum 1/2 k (d - p)^2`), in modal state `z`.
    pub(crate) fn plastic_strain_correction(&self, z: &[f64]) -> f64 {
        self.storeys
            .iter()
            .enumerate()
            .map(|(s, sm)| {
                let p = z[self.plastic_slot(s)];
                let d = dot(&sm.modal_row, &z[self.buildings[sm.building].off..]);
                sm.k * p * (0.5 * p - d)
            })
            .sum()
    }

    /// Can no storey yield again in the free motion from modal state `z` (no level in contact,
    /// every storey in its band, `modes` the storeys' states)? See the module's text.
    pub(crate) fn settled(&self, z: &[f64], modes: &[StoreyMode]) -> bool {
        if self.storeys.iter().any(|sm| sm.imk.is_some()) {
            return self.settled_imk(z, modes);
        }
        if self.storeys.iter().any(|sm| sm.geometric != 0.0) {
            return self.settled_p_delta(z);
        }
        let e = (self.mechanical_energy(z)).max(0.0);
        self.storeys.iter().enumerate().all(|(s, sm)| {
            let p = z[self.plastic_slot(s)];
            (2.0 * e / sm.k).sqrt() + sm.b * p.abs() / (1.0 - sm.b) <= sm.d_y * (1.0 + YIELD_SLACK)
        })
    }

    /// [`RowModel::settled`] with P-Delta: about the static response `q_s` to the plastic loads
    /// the drifts are `d_s` (no longer the plastic drifts: gravity leans on them), and the
    /// energy `E` of the motion about it bounds each storey's excursion by
    /// `sqrt(2 E / (k - P/h))` (the stiffness `K0 - K_G` is a sum of storey terms
    /// `k_j - P_j/h_j`, all positive). A storey stays in its band while
    /// `|d_s - p / (1 - b)| + sqrt(2 E / (k - P/h)) <= d_y`.
    fn settled_p_delta(&self, z: &[f64]) -> bool {
        let n = self.n;
        let mut qs = vec![0.0; n];
        self.static_offsets(z, &mut qs);
        let e: f64 = (0..n)
            .map(|i| {
                let x = z[i] - qs[i];
                0.5 * (z[n + i] * z[n + i] + self.w2[i] * x * x)
            })
            .sum();
        self.storeys.iter().enumerate().all(|(s, sm)| {
            let p = z[self.plastic_slot(s)];
            let o = self.buildings[sm.building].off;
            let d_s = dot(&sm.modal_row, &qs[o..]);
            (2.0 * e / (sm.k - sm.geometric)).sqrt() + sm.back_drift(d_s, p).abs()
                <= sm.d_y * (1.0 + YIELD_SLACK)
        })
    }

    /// [`RowModel::settled`] with IMK storeys. Each yielding storey is on a linear piece
    /// `f = a + K d` (`K` its slope; a bilinear storey in its band: `k (d - p)`), and at rest
    /// a shear building's every storey carries no net shear, so each comes to rest on its own
    /// where its spring force is gravity's P-Delta shear `g d` (`g = P/h`, 0 without P-Delta):
    /// `d* = -a / (K - g)`. The motion's energy, half the modal velocities squared plus each
    /// storey's `(K - g)(d - d*)^2 / 2` (the elastic buildings' modes as in
    /// [`RowModel::mechanical_energy`]), can only fall while the pieces hold (damping and
    /// contact dissipate), so a storey's drift stays within `sqrt(2 E / (K - g))` of `d*`: it
    /// stays on its piece while that reach is inside the piece's rest thresholds (a bilinear
    /// storey: in its band). A storey with `K <= g` may run away: not settled. A peak-oriented
    /// storey may come to rest on a reloading line, once its reach is below
    /// [`crate::physics::imk::ImkSpring::rest_reach`]; an `IMKBilin` one's lines that flow one
    /// way are its backbone's.
    fn settled_imk(&self, z: &[f64], modes: &[StoreyMode]) -> bool {
        let n = self.n;
        let mut e: f64 = (0..n).map(|i| 0.5 * z[n + i] * z[n + i]).sum();
        for b in self.buildings.iter().filter(|b| b.first_storey.is_none()) {
            e += (b.off..b.off + b.n())
                .map(|i| 0.5 * self.w2[i] * z[i] * z[i])
                .sum::<f64>();
        }
        let mut rests = Vec::with_capacity(self.storeys.len());
        for (s, (sm, mode)) in self.storeys.iter().zip(modes).enumerate() {
            let o = self.buildings[sm.building].off;
            let d = dot(&sm.modal_row, &z[o..]);
            let (a, slope) = match mode {
                StoreyMode::Imk(piece) => {
                    let loops =
                        (sm.imk.as_ref()).is_some_and(|sp| sp.rule == ImkRule::PeakOriented);
                    if piece.heading != 0.0 && !loops {
                        return false;
                    }
                    (piece.f0 - piece.slope * piece.d0, piece.slope)
                }
                StoreyMode::Elastic => (-sm.k * z[self.plastic_slot(s)], sm.k),
                StoreyMode::Yielding(_) => return false,
            };
            let stiffness = slope - sm.geometric;
            if stiffness <= 0.0 {
                return false;
            }
            let rest = -a / stiffness;
            e += 0.5 * stiffness * (d - rest) * (d - rest);
            rests.push((rest, stiffness));
        }
        (self.storeys.iter().zip(modes).zip(rests).enumerate()).all(
            |(s, ((sm, mode), (rest, stiffness)))| {
                let reach = (2.0 * e / stiffness).sqrt();
                match mode {
                    StoreyMode::Imk(piece) => {
                        let sp = sm.imk.as_ref().expect("an IMK mode has its spring");
                        let slack = sp.slack();
                        reach <= sp.rest_reach()
                            && rest - reach >= piece.rest_lo - slack
                            && rest + reach <= piece.rest_hi + slack
                    }
                    _ => {
                        let p = z[self.plastic_slot(s)];
                        sm.back_drift(rest, p).abs() + reach <= sm.d_y * (1.0 + YIELD_SLACK)
                    }
                }
            },
        )
    }

    /// Each building with a storey that yields now or may reach a bounding line over the
    /// exact free step `z -> z1` of length `h` (modal states, each mode's `|q''''|` bound in
    /// `bounds`), into `out`; whether any. A building that `tangent` marks takes the exact
    /// step of its tangent stiffness, so its storeys' pieces hold it back only at their edges.
    pub(crate) fn yield_watch(
        &self,
        (modes, tangent): (&[StoreyMode], Option<&[bool]>),
        (z, z1): (&[f64], &[f64]),
        bounds: &[f64],
        h: f64,
        out: &mut [bool],
    ) -> bool {
        out.fill(false);
        for (s, (sm, mode)) in self.storeys.iter().zip(modes).enumerate() {
            if out[sm.building] {
                continue;
            }
            let (ends, bound) = self.drift_over_step(sm.building, &sm.modal_row, (z, z1), bounds);
            // A building on its tangent stiffness steps every piece it stands on exactly.
            let free = sm.free(*mode) || tangent.is_some_and(|on| on[sm.building]);
            out[sm.building] =
                !free || sm.may_yield(*mode, ends, z[self.plastic_slot(s)], bound, h);
        }
        out.iter().any(|&x| x)
    }

    /// A drift `d = row . q` of building `k`'s modes (`row` its modal row) over the exact free
    /// step `z -> z1` (modal states): `[d0, d0', d1, d1']` at its ends, and the bound on
    /// `|d''''|` over it from each mode's in `bounds` (for `may_yield` and the collapse watch).
    pub(crate) fn drift_over_step(
        &self,
        k: usize,
        row: &[f64],
        (z, z1): (&[f64], &[f64]),
        bounds: &[f64],
    ) -> ([f64; 4], f64) {
        let n = self.n;
        let o = self.buildings[k].off;
        let nb = self.buildings[k].n();
        let at = |z: &[f64], part: usize| dot(row, &z[part + o..part + o + nb]);
        let bound: f64 = row
            .iter()
            .zip(&bounds[o..o + nb])
            .map(|(r, q)| r.abs() * q)
            .sum();
        ([at(z, 0), at(z, n), at(z1, 0), at(z1, n)], bound)
    }

    /// The run's last settling time after a record that ends at `t_end`: `SETTLE_PERIODS` of
    /// its longest mode's period.
    pub(crate) fn settle_until(&self, t_end: f64) -> f64 {
        let w_min = self.w2.iter().cloned().fold(f64::INFINITY, f64::min).sqrt();
        t_end + SETTLE_PERIODS * 2.0 * std::f64::consts::PI / w_min
    }
}

/// Record step `i` of a run of `m` (`intervals` of them in `forcing`), or after the record,
/// a step of free vibration while the run has yielding storeys that may still yield (until
/// [`RowModel::settle_until`]); None once the run ends. Marks the run settled when it is. Call
/// in modal coordinates.
pub(crate) fn next_segment(
    m: &RowModel,
    forcing: &Forcing,
    i: usize,
    run: &mut RowRun,
) -> Option<Segment> {
    let intervals = forcing.intervals();
    if i < intervals {
        return Some(Segment::of(forcing, i));
    }
    if m.storeys.is_empty() {
        return None;
    }
    let settled = || match run.standing_state(&run.z) {
        Some(standing) => m.settled(&standing, &run.standing_modes()),
        None => m.settled(&run.z, &run.storey_modes),
    };
    if !run.any_contact() && !run.any_yielding() && settled() {
        run.settled = true;
        return None;
    }
    (i < settle_intervals(m, forcing)).then_some(Segment {
        t0: forcing.t0 + i as f64 * forcing.dt,
        dt: forcing.dt,
        a0: 0.0,
        a1: 0.0,
    })
}

/// The end of a run that has not settled, in record steps: the steps `i` after the record
/// with `t0 + i dt` before [`RowModel::settle_until`] are its settling tail.
pub(crate) fn settle_intervals(m: &RowModel, forcing: &Forcing) -> usize {
    let intervals = forcing.intervals();
    let t = |i: usize| forcing.t0 + i as f64 * forcing.dt;
    let until = m.settle_until(t(intervals));
    let guess = ((until - forcing.t0) / forcing.dt).ceil();
    let mut i = if guess.is_finite() {
        (guess.max(0.0) as usize).max(intervals)
    } else {
        intervals
    };
    while i > intervals && t(i - 1) >= until {
        i -= 1;
    }
    while t(i) < until {
        i += 1;
    }
    i
}
