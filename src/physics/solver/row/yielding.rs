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

use super::{dot, RowModel, RowRun};
use crate::physics::model::Forcing;
use crate::physics::solver::events::error_margin;
use crate::physics::solver::hermite::{cubic_max_bound, hermite_range};
use crate::physics::solver::state::Segment;

/// A storey yields once its back drift passes its band by this fraction: the band edge an
/// unloading storey leaves from is then inside its band, not on it, to rounding.
pub(crate) const YIELD_SLACK: f64 = 1e-9;

/// After the record, a run goes on in free vibration for at most this many of its longest
/// fundamental period until no storey can yield again ([`RowModel::settled`]).
pub const SETTLE_PERIODS: f64 = 50.0;

/// The state of one storey's spring.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(crate) enum StoreyMode {
    /// Inside its band: force slope `k`, plastic drift constant.
    #[default]
    Elastic,
    /// On its upper (`+1`) or lower (`-1`) bounding line: force slope `b k`.
    Yielding(f64),
}

/// One yielding storey, as the integrators see it.
#[derive(Debug, Clone)]
pub(crate) struct StoreyModel {
    pub building: usize,
    /// Storey of the building, from 0 (storey 0 joins the ground and floor 0).
    pub storey: usize,
    /// Initial stiffness, N/m; yield drift `F_y / k`, m; post-yield ratio; storey height, m.
    pub k: f64,
    pub d_y: f64,
    pub b: f64,
    pub height: f64,
    /// Geometric stiffness `P / h` of P-Delta, N/m (0 without).
    pub geometric: f64,
    /// The drift in the building's modes: `d = modal_row . q`.
    pub modal_row: Vec<f64>,
    /// The drift in the model's coordinates: `d = row . z[off..off + row.len()]` (the modes, or
    /// the two floors where the building is in floor coordinates).
    pub off: usize,
    pub row: Vec<f64>,
    /// How the storey's plastic load `k p` enters the accelerations `z'[n + off + i]`: the
    /// modal row again (`Phi^T D^T`), or `+-1 / m` of the two floors.
    pub psi: Vec<f64>,
}

impl StoreyModel {
    /// Drift (`n = 0`) or drift rate (`n` the mode count) in state `z`.
    #[inline]
    pub fn drift(&self, z: &[f64], n: usize) -> f64 {
        dot(&self.row, &z[n + self.off..n + self.off + self.row.len()])
    }

    /// Back drift `d - p / (1 - b)`: the band is `|s| <= d_y`.
    #[inline]
    pub fn back_drift(&self, d: f64, p: f64) -> f64 {
        d - p / (1.0 - self.b)
    }

    /// Positive once `mode` must end: the back drift past the band (elastic), the drift
    /// velocity reversed (yielding).
    #[inline]
    pub fn event_value(&self, mode: StoreyMode, d: f64, rate: f64, p: f64) -> f64 {
        match mode {
            StoreyMode::Elastic => self.back_drift(d, p).abs() - self.d_y * (1.0 + YIELD_SLACK),
            StoreyMode::Yielding(sign) => -sign * rate,
        }
    }

    /// Could the elastic storey reach a bounding line inside a free step of length `h` with
    /// drift and rate `[d0, d0', d1, d1']` at its ends and plastic drift `p`, when `bound`
    /// bounds `|d''''|` over it? As a level's `may_touch`: the Hermite cubic of each edge
    /// function within twice its error bound of 0.
    pub fn may_yield(&self, [d0, r0, d1, r1]: [f64; 4], p: f64, bound: f64, h: f64) -> bool {
        may_reach(self.edges(d0, r0, p), self.edges(d1, r1, p), bound, h)
    }

    /// The band's two edges as functions that reach 0 on them: `[s - d_y, -s - d_y]` with
    /// their rates, for the hidden-yield checks of a step.
    #[inline]
    pub fn edges(&self, d: f64, rate: f64, p: f64) -> [(f64, f64); 2] {
        band_edges(self.back_drift(d, p), rate, self.d_y * (1.0 + YIELD_SLACK))
    }
}

/// The edges of the band `|x| <= half` as functions that reach 0 on them, `[x - half, -x -
/// half]`, with their rates from `x`'s `rate`: a yielding storey's band in its back drift, a
/// drift's collapse limit.
#[inline]
pub(crate) fn band_edges(x: f64, rate: f64, half: f64) -> [(f64, f64); 2] {
    [(x - half, rate), (-x - half, -rate)]
}

/// Could an edge function (value and rate at both ends of a free step of length `h`, `bound`
/// bounding its fourth derivative) reach 0 inside the step? As a level's `may_touch`: the
/// Hermite cubic of each within twice its error bound of 0.
pub(crate) fn may_reach(e0: [(f64, f64); 2], e1: [(f64, f64); 2], bound: f64, h: f64) -> bool {
    let margin = -error_margin(bound, h);
    e0.iter().zip(&e1).any(|(a, b)| {
        cubic_max_bound(a.0, a.1, b.0, b.1, h) > margin
            && (a.0 > 0.0 || b.0 > 0.0 || hermite_range(a.0, a.1, b.0, b.1, h).1 > margin)
    })
}

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
                StoreyMode::Yielding(_) => sm.k * (1.0 - sm.b) * sm.drift(z, self.n),
                StoreyMode::Elastic => 0.0,
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
    /// every storey in its band)? See the module's text.
    pub(crate) fn settled(&self, z: &[f64]) -> bool {
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

    /// Each building with a storey that yields now or may reach a bounding line over the
    /// exact free step `z -> z1` of length `h` (modal states, each mode's `|q''''|` bound in
    /// `bounds`), into `out`; whether any.
    pub(crate) fn yield_watch(
        &self,
        modes: &[StoreyMode],
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
            out[sm.building] = *mode != StoreyMode::Elastic
                || sm.may_yield(ends, z[self.plastic_slot(s)], bound, h);
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
        Some(standing) => m.settled(&standing),
        None => m.settled(&run.z),
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::contact::LawKind;
    use crate::physics::model::Status;
    use crate::physics::row::{Row, RowOutput};
    use crate::physics::shear::{Damping, ShearBuilding, Yielding};
    use crate::physics::solver::row::{rhs, simulate_row, Motion, RowFastOptions, RowScheme};
    use crate::physics::solver::ReferenceOptions;
    use std::f64::consts::PI;

    /// A one-storey building of mass `m` and period `t` (3 m storey), yielding at drift `d_y`
    /// with post-yield ratio `b`.
    fn sdof(m: f64, t: f64, xi: f64, d_y: f64, b: f64) -> ShearBuilding {
        let k = m * (2.0 * PI / t).powi(2);
        ShearBuilding {
            masses: vec![m],
            stiffness: vec![k],
            heights: vec![3.0],
            damping: Damping::Modal(xi),
            yielding: Some(Yielding {
                force: vec![k * d_y],
                post_yield: vec![b],
            }),
            geometric: None,
        }
    }

    /// `n` storeys of 3 m and 2.5e5 kg at period `t` (a soft first storey if `soft`), Rayleigh
    /// 5 %, yielding at drift ratio `theta` (None: elastic) with post-yield ratio `b`.
    fn tower(n: usize, t: f64, soft: bool, theta: Option<f64>, b: f64) -> ShearBuilding {
        let mut profile = vec![1.0; n];
        if soft {
            profile[0] = 0.4;
        }
        let mut s = ShearBuilding::from_period(
            vec![2.5e5; n],
            &profile,
            vec![3.0; n],
            t,
            Damping::Rayleigh(0.05),
        );
        s.yielding = theta.map(|th| {
            Yielding::from_drift_ratio(&s.stiffness, &s.heights, &vec![th; n], vec![b; n])
        });
        s
    }

    /// The fast scheme at 64 substeps (these tests hold the yielding model to closed forms and
    /// to the reference at 1e-7 to 5e-3; the default setting's error is the accuracy suites'
    /// business, `configs/accuracy-inelastic.toml`), and the reference.
    fn schemes() -> [RowScheme; 2] {
        [
            RowScheme::Fast(RowFastOptions {
                energy: true,
                substeps_per_contact: 64.0,
                ..RowFastOptions::default()
            }),
            RowScheme::Reference(ReferenceOptions {
                rtol: 1e-10,
                ..ReferenceOptions::default()
            }),
        ]
    }

    /// As the row fast scheme's tests: three frequencies under an envelope, 8 s at 0.01 s,
    /// peak about 4.4 m/s^2, times `scale`.
    fn ground_motion(scale: f64) -> Vec<f64> {
        (0..800)
            .map(|i| {
                let t = i as f64 * 0.01;
                let envelope = (t / 1.5).min(1.0) * (-(t - 4.0).max(0.0) / 2.0).exp();
                let w = 2.0 * PI;
                scale
                    * envelope
                    * (2.5 * (w * 1.1 * t).sin()
                        + 1.5 * (w * 2.3 * t + 0.4).sin()
                        + 1.0 * (w * 0.7 * t + 1.3).sin())
            })
            .collect()
    }

    fn forcing(accel: &[f64]) -> Forcing<'_> {
        Forcing {
            accel,
            dt: 0.01,
            t0: 0.0,
            scale: 1.0,
            tail: 1.0,
        }
    }

    fn relative(a: f64, b: f64) -> f64 {
        (a - b).abs() / a.abs().max(b.abs()).max(1e-300)
    }

    /// An elastic-perfectly-plastic, undamped storey set moving at `v0` from rest: elastic up
    /// to `d_y`, then at the constant force `F_y` until the kinetic energy left at `d_y` is
    /// spent, so `u_max = d_y + (m v0^2 / 2 - k d_y^2 / 2) / F_y`, the plastic drift (and the
    /// residual drift) is `u_max - d_y`, the hysteretic energy `F_y (u_max - d_y)`; with
    /// kinematic hardening `b`, the force past yield is `F_y + b k (u - d_y)` and the energy
    /// balance gives `u_max` from a quadratic, the first excursion's hysteretic energy
    /// `int f dp = (1 - b)(F_y x + b k x^2 / 2)`, `x = u_max - d_y`.
    #[test]
    fn a_storey_pushed_past_yield_follows_the_closed_form() {
        let (m, t, d_y, v0) = (1e5, 0.5, 0.01, 0.3);
        let k = m * (2.0 * PI / t).powi(2);
        let f_y = k * d_y;
        for b in [0.0, 0.1] {
            let row = Row::new(
                vec![sdof(m, t, 0.0, d_y, b), tower(1, 0.3, false, None, 0.0)],
                vec![10.0],
                LawKind::Linear,
                1e9,
                0.0,
            );
            let model = RowModel::new(&row);
            let z0 = model.state_of_floors(&[vec![0.0], vec![0.0]], &[vec![v0], vec![0.0]]);
            // Spent past yield: 1/2 m v0^2 - 1/2 k d_y^2 = F_y x + b k x^2 / 2.
            let spare = 0.5 * m * v0 * v0 - 0.5 * k * d_y * d_y;
            let x = if b == 0.0 {
                spare / f_y
            } else {
                (-f_y + (f_y * f_y + 2.0 * b * k * spare).sqrt()) / (b * k)
            };
            let hysteretic = (1.0 - b) * (f_y * x + 0.5 * b * k * x * x);
            let accel = vec![0.0; 201];
            for scheme in schemes() {
                let out = simulate_row(&model, &forcing(&accel), z0.clone(), &scheme);
                assert_eq!(out.status, Status::Ok);
                let bo = &out.buildings[0];
                let ie = bo.inelastic.expect("a yielding building");
                let what = format!("b {b}, {}", scheme.key());
                assert!(
                    relative(bo.peak_drift_ratio * 3.0, d_y + x) < 1e-7,
                    "{what}: peak drift {} against {}",
                    bo.peak_drift_ratio * 3.0,
                    d_y + x
                );
                assert!(
                    relative(ie.peak_ductility, (d_y + x) / d_y) < 1e-7,
                    "{what}"
                );
                // With hardening the swing back reaches the lower bounding line (the force
                // left, F_y + b k x, exceeds F_y): later excursions dissipate more.
                let first = relative(ie.hysteretic_energy, hysteretic);
                assert!(
                    if b == 0.0 {
                        first < 1e-7
                    } else {
                        ie.hysteretic_energy > hysteretic
                    },
                    "{what}: hysteretic {} against {hysteretic}",
                    ie.hysteretic_energy
                );
                assert_eq!(ie.yielded_storeys, 1);
                assert!(out.energy.unwrap().residual.abs() < 1e-8, "{what}");
                // Undamped, it swings about its plastic drift for ever: the residual is p if
                // the energy bound closes, else not claimed.
                let r = ie.residual_drift_ratio;
                assert!(
                    r.is_nan() || b > 0.0 || relative(r * 3.0, x) < 1e-7,
                    "{what}: residual {r}"
                );
            }
        }
    }

    /// With damping, a yielding storey comes to rest at its plastic drift: the run settles
    /// after the record and reports it, the same from both schemes.
    #[test]
    fn a_damped_storey_settles_at_its_plastic_drift() {
        let row = Row::new(
            vec![
                sdof(1e5, 0.5, 0.05, 0.01, 0.05),
                tower(1, 0.3, false, None, 0.0),
            ],
            vec![10.0],
            LawKind::Linear,
            1e9,
            0.0,
        );
        let model = RowModel::new(&row);
        let accel = ground_motion(1.0);
        let [fast, reference] =
            schemes().map(|s| simulate_row(&model, &forcing(&accel), model.at_rest(), &s));
        let (a, b) = (
            fast.buildings[0].inelastic.unwrap(),
            reference.buildings[0].inelastic.unwrap(),
        );
        assert!(a.yielded_storeys == 1 && b.yielded_storeys == 1);
        assert!(a.residual_drift_ratio > 1e-4, "{a:?}");
        assert!(
            relative(a.residual_drift_ratio, b.residual_drift_ratio) < 1e-5,
            "{a:?} {b:?}"
        );
        assert!(
            relative(a.hysteretic_energy, b.hysteretic_energy) < 1e-5,
            "{a:?} {b:?}"
        );
        assert!(fast.energy.unwrap().residual.abs() < 1e-8);
    }

    /// A yield force above any demand gives the elastic run, bit for bit.
    #[test]
    fn storeys_that_never_yield_give_the_elastic_run() {
        let accel = ground_motion(1.0);
        let scene = |theta: Option<f64>| {
            Row::new(
                vec![
                    tower(8, 0.7, true, theta, 0.0),
                    tower(6, 0.45, false, theta, 0.1),
                    tower(2, 0.2, false, None, 0.0),
                ],
                vec![0.01, 0.005],
                LawKind::NonlinearViscoelastic,
                2.75e9,
                0.35,
            )
        };
        let strip = |mut o: RowOutput| {
            for b in o.buildings.iter_mut() {
                if let Some(ie) = b.inelastic.take() {
                    assert_eq!(ie.yielded_storeys, 0);
                }
            }
            for st in std::mem::take(&mut o.storeys) {
                assert_eq!((st.residual_drift_ratio, st.hysteretic_energy), (0.0, 0.0));
            }
            o
        };
        for scheme in schemes() {
            let elastic = RowModel::new(&scene(None));
            let strong = RowModel::new(&scene(Some(10.0)));
            let a = simulate_row(&elastic, &forcing(&accel), elastic.at_rest(), &scheme);
            let b = simulate_row(&strong, &forcing(&accel), strong.at_rest(), &scheme);
            assert!(a.impacts > 0);
            assert_eq!(strip(b), a, "{}", scheme.key());
        }
    }

    /// Yielding storeys that pound (a soft first storey, b = 0, beside a stiff elastic
    /// neighbour, and a third building): the fast scheme against the reference, and the energy
    /// balance closing with the hysteretic work.
    #[test]
    fn yielding_while_pounding_matches_the_reference() {
        let accel = ground_motion(1.5);
        let row = Row::new(
            vec![
                tower(8, 0.7, true, Some(0.004), 0.0),
                tower(3, 0.2, false, None, 0.0),
                tower(6, 0.5, false, Some(0.005), 0.05),
            ],
            vec![0.01, 0.01],
            LawKind::NonlinearViscoelastic,
            2.75e9,
            0.35,
        );
        let model = RowModel::new(&row);
        let [fast, reference] =
            schemes().map(|s| simulate_row(&model, &forcing(&accel), model.at_rest(), &s));
        assert_eq!(fast.status, Status::Ok);
        assert_eq!(reference.status, Status::Ok);
        assert!(fast.impacts > 0);
        let mut worst: f64 = 0.0;
        for (a, b) in fast.buildings.iter().zip(&reference.buildings) {
            worst = worst.max(relative(a.peak_drift_ratio, b.peak_drift_ratio));
            if let (Some(x), Some(y)) = (a.inelastic, b.inelastic) {
                assert!(x.yielded_storeys > 0);
                assert_eq!(x.yielded_storeys, y.yielded_storeys);
                worst = worst.max(relative(x.residual_drift_ratio, y.residual_drift_ratio));
                worst = worst.max(relative(x.hysteretic_energy, y.hysteretic_energy));
                worst = worst.max(relative(x.peak_ductility, y.peak_ductility));
            }
        }
        worst = worst.max(relative(fast.peak_force, reference.peak_force));
        eprintln!("worst {worst:e}, impacts {}", fast.impacts);
        assert!(worst < 2e-3, "worst {worst}");
        assert!(fast.energy.unwrap().residual.abs() < 1e-6);
        assert!(reference.energy.unwrap().residual.abs() < 1e-6);
    }

    /// The largest relative difference of the yielding outputs, drifts and peak force between
    /// two runs of one row.
    fn worst_difference(a: &RowOutput, b: &RowOutput) -> f64 {
        let mut worst: f64 = relative(a.peak_force, b.peak_force);
        for (x, y) in a.buildings.iter().zip(&b.buildings) {
            worst = worst.max(relative(x.peak_drift_ratio, y.peak_drift_ratio));
            if let (Some(p), Some(q)) = (x.inelastic, y.inelastic) {
                assert_eq!(p.yielded_storeys, q.yielded_storeys);
                for (u, v) in [
                    (p.residual_drift_ratio, q.residual_drift_ratio),
                    (p.peak_ductility, q.peak_ductility),
                    (p.hysteretic_energy, q.hysteretic_energy),
                ] {
                    // A residual of a storey that barely yielded is measured against the
                    // building's peak drift.
                    let scale = u.abs().max(v.abs()).max(1e-3 * x.peak_drift_ratio);
                    worst = worst.max((u - v).abs() / scale);
                }
            }
        }
        worst
    }

    /// Hard cases, fast against reference: an elastic-perfectly-plastic soft storey, yield at
    /// the first record step (a ground step), yielding neighbours pounding from gap 0, a very
    /// stiff elastic neighbour, and a 20-storey yielding frame beside a 10-storey one. Each
    /// yields, ends well, settles, and agrees with the reference.
    #[test]
    fn hard_yielding_scenes_match_the_reference() {
        let step: Vec<f64> = (0..300).map(|i| if i < 50 { 3.0 } else { 0.0 }).collect();
        let quake = ground_motion(1.5);
        let scenes: Vec<(&str, Row, &[f64])> = vec![
            (
                "soft storey, b = 0",
                Row::new(
                    vec![
                        tower(8, 0.7, true, Some(0.002), 0.0),
                        tower(2, 0.2, false, None, 0.0),
                    ],
                    vec![0.03],
                    LawKind::NonlinearViscoelastic,
                    2.75e9,
                    0.35,
                ),
                &quake,
            ),
            (
                "yield at the first step",
                Row::new(
                    vec![
                        tower(3, 0.4, false, Some(0.001), 0.0),
                        tower(3, 0.3, false, Some(0.001), 0.02),
                    ],
                    vec![0.002],
                    LawKind::NonlinearViscoelastic,
                    2.75e9,
                    0.35,
                ),
                &step,
            ),
            (
                "yielding at gap 0",
                Row::new(
                    vec![
                        tower(4, 0.5, false, Some(0.003), 0.02),
                        tower(4, 0.35, true, Some(0.003), 0.0),
                    ],
                    vec![0.0],
                    LawKind::Hertz,
                    2.75e9,
                    0.0,
                ),
                &quake,
            ),
            (
                "very stiff elastic neighbour",
                Row::new(
                    vec![
                        tower(6, 0.6, false, Some(0.003), 0.03),
                        tower(3, 0.05, false, None, 0.0),
                    ],
                    vec![0.005],
                    LawKind::KelvinVoigt,
                    1e9,
                    0.3,
                ),
                &quake,
            ),
            (
                "20 storeys beside 10",
                Row::new(
                    vec![
                        tower(20, 1.8, true, Some(0.003), 0.02),
                        tower(10, 1.0, false, Some(0.004), 0.02),
                    ],
                    vec![0.02],
                    LawKind::NonlinearViscoelastic,
                    2.75e9,
                    0.35,
                ),
                &quake,
            ),
        ];
        for (name, row, accel) in scenes {
            let model = RowModel::new(&row);
            let [fast, reference] =
                schemes().map(|s| simulate_row(&model, &forcing(accel), model.at_rest(), &s));
            assert_eq!(fast.status, Status::Ok, "{name}");
            assert_eq!(reference.status, Status::Ok, "{name}");
            let yielded: u32 = fast
                .buildings
                .iter()
                .filter_map(|b| b.inelastic)
                .map(|i| i.yielded_storeys)
                .sum();
            assert!(yielded > 0, "{name}: nothing yielded");
            for b in fast.buildings.iter().filter_map(|b| b.inelastic) {
                assert!(b.residual_drift_ratio.is_finite(), "{name}: not settled");
            }
            let worst = worst_difference(&fast, &reference);
            let mu = fast
                .buildings
                .iter()
                .filter_map(|b| b.inelastic)
                .map(|i| i.peak_ductility)
                .fold(0.0, f64::max);
            eprintln!(
                "{name}: worst {worst:.1e}, {} impacts, {yielded} storeys yielded (ductility up to {mu:.1}), energy residual {:.1e}",
                fast.impacts,
                fast.energy.unwrap().residual
            );
            assert!(worst < 5e-3, "{name}: {worst}");
            assert!(fast.energy.unwrap().residual.abs() < 1e-6, "{name}");
        }
    }

    /// The plastic loads enter the floor-coordinate right-hand side as they enter the modal
    /// one: every slot equal after the change of coordinates, with some storeys yielding.
    #[test]
    fn plastic_loads_are_the_same_in_floors_and_modes() {
        let row = Row::new(
            vec![
                tower(8, 0.7, true, Some(0.004), 0.1),
                tower(6, 0.45, false, Some(0.005), 0.0),
            ],
            vec![1.0],
            LawKind::Linear,
            1e9,
            0.0,
        );
        let m = RowModel::new(&row);
        let sub = m.substep_model().expect("tall Rayleigh buildings");
        let len = m.len();
        let mut z: Vec<f64> = (0..len)
            .map(|i| ((i * 7919 % 113) as f64 / 113.0 - 0.5) * 0.01)
            .collect();
        z[2 * m.n..m.plastic_slot(0)].fill(0.0);
        let modes: Vec<StoreyMode> = (0..m.storeys.len())
            .map(|s| match s % 3 {
                0 => StoreyMode::Elastic,
                1 => StoreyMode::Yielding(1.0),
                _ => StoreyMode::Yielding(-1.0),
            })
            .collect();
        let mut y = z.clone();
        sub.modes_to_substeps(&mut y);
        let motion = Motion {
            levels: &[],
            active: &[true; 2],
            energy: true,
            storeys: &modes,
        };
        let (mut fz, mut fy) = (vec![0.0; len], vec![0.0; len]);
        rhs(&m, &motion, 0.7, &z, &mut fz);
        rhs(&sub, &motion, 0.7, &y, &mut fy);
        sub.modes_to_substeps(&mut fz);
        for (i, (a, b)) in fz.iter().zip(&fy).enumerate() {
            assert!(
                (a - b).abs() <= 1e-9 * a.abs().max(1e-6),
                "slot {i}: {a} against {b}"
            );
        }
        for s in 0..m.storeys.len() {
            assert!(fz[m.plastic_slot(s)] != 0.0 || modes[s] == StoreyMode::Elastic);
        }
    }

    /// An elastic-perfectly-plastic storey with P-Delta (`theta = P / (k h) = 0.1`) set moving
    /// outwards from its yield drift, with no ground motion: on its plateau the storey force is
    /// `F_y - (P/h) d` (the softening slope `-P/h`), so `m d'' + c d' - (P/h) d = -F_y`, whose
    /// solution runs away from `d_p = F_y h / P` exponentially; the run collapses when
    /// `d = L h` (`L` the collapse drift ratio), at the time the closed form gives, with the
    /// peak drift ratio `L`, no residual drift, and the same from both schemes.
    #[test]
    fn a_leaning_storey_past_yield_runs_away_and_collapses_as_the_closed_form() {
        let (m, t, d_y, v0, theta, limit) = (1e5, 0.5, 0.01, 0.6, 0.1, 0.1);
        let h = 3.0;
        for damping in [Damping::Modal(0.05), Damping::Rayleigh(0.05)] {
            let mut b = sdof(m, t, 0.05, d_y, 0.0);
            b.damping = damping;
            let k = b.stiffness[0];
            let g = theta * k;
            b.geometric = Some(vec![g]);
            // c: the elastic building's (Rayleigh on one storey: 2 xi m w0), or the ratio on
            // the P-Delta mode (modal).
            let w0 = (k / m).sqrt();
            let c = match damping {
                Damping::Rayleigh(x) => 2.0 * x * m * w0,
                Damping::Modal(x) => 2.0 * x * m * ((k - g) / m).sqrt(),
            };
            let row = Row::new(
                vec![b, tower(1, 0.3, false, None, 0.0)],
                vec![10.0],
                LawKind::Linear,
                1e9,
                0.0,
            )
            .with_collapse(limit);
            let model = RowModel::new(&row);
            let z0 = model.state_of_floors(&[vec![d_y], vec![0.0]], &[vec![v0], vec![0.0]]);
            // x = d - d_p: m x'' + c x' - g x = 0.
            let d_p = k * d_y / g;
            let disc = (c * c + 4.0 * m * g).sqrt();
            let (l1, l2) = ((-c + disc) / (2.0 * m), (-c - disc) / (2.0 * m));
            let x0 = d_y - d_p;
            let a = (v0 - l2 * x0) / (l1 - l2);
            assert!(a > 0.0, "the storey runs away");
            let x = |t: f64| a * (l1 * t).exp() + (x0 - a) * (l2 * t).exp();
            // x rises monotonically: bisect x(t) = L h - d_p.
            let target = limit * h - d_p;
            let (mut lo, mut hi) = (0.0, 10.0);
            for _ in 0..200 {
                let mid = 0.5 * (lo + hi);
                if x(mid) < target {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            let t_c = 0.5 * (lo + hi);
            assert!(t_c > 0.1 && t_c < 2.5, "{t_c}");
            let accel = vec![0.0; 301];
            for scheme in schemes() {
                let out = simulate_row(&model, &forcing(&accel), z0.clone(), &scheme);
                let what = format!("{damping:?}, {}", scheme.key());
                assert_eq!(out.status, Status::Collapsed, "{what}");
                let cl = out.collapse.expect("where it collapsed");
                assert_eq!((cl.building, cl.storey), (1, 1), "{what}");
                assert!(
                    relative(cl.time, t_c) < 1e-6,
                    "{what}: {} against {t_c}",
                    cl.time
                );
                let bo = &out.buildings[0];
                assert!(
                    relative(bo.peak_drift_ratio, limit) < 1e-9,
                    "{what}: {}",
                    bo.peak_drift_ratio
                );
                let ie = bo.inelastic.unwrap();
                assert!(
                    ie.residual_drift_ratio.is_nan(),
                    "{what}: no residual drift"
                );
                // The plateau's plastic work, F_y (d - d_y) at the collapse.
                assert!(
                    relative(ie.hysteretic_energy, k * d_y * (limit * h - d_y)) < 1e-6,
                    "{what}"
                );
            }
        }
    }

    /// Without a collapse limit the same storey runs on past it (a building that stands in
    /// the model where a real one fell), as it did before collapse existed.
    #[test]
    fn without_a_collapse_limit_the_run_goes_on() {
        let mut b = sdof(1e5, 0.5, 0.05, 0.01, 0.0);
        b.geometric = Some(vec![0.1 * b.stiffness[0]]);
        let row = Row::new(
            vec![b, tower(1, 0.3, false, None, 0.0)],
            vec![10.0],
            LawKind::Linear,
            1e9,
            0.0,
        );
        let model = RowModel::new(&row);
        let z0 = model.state_of_floors(&[vec![0.01], vec![0.0]], &[vec![0.6], vec![0.0]]);
        let accel = vec![0.0; 101];
        let out = simulate_row(&model, &forcing(&accel), z0, &schemes()[0]);
        assert_ne!(out.status, Status::Collapsed);
        assert!(out.collapse.is_none());
        assert!(out.buildings[0].peak_drift_ratio > 0.1);
    }
    /// A storey's drift at rest from its building's plastic drifts: each plastic drift itself
    /// without gravity (`D K^-1 D^T diag(k) = I` for a shear building), and with P-Delta the
    /// static response to the plastic loads, `p / (1 - theta)` in one storey.
    #[test]
    fn residual_rows_give_the_static_drifts_gravity_leans_on() {
        let plain = tower(4, 0.6, true, Some(0.01), 0.03);
        let leaning = plain.clone().with_p_delta(3.0);
        for (b, lean) in [(plain, false), (leaning, true)] {
            let row = Row::new(
                vec![b, tower(1, 0.3, false, None, 0.0)],
                vec![1.0],
                LawKind::Linear,
                1e9,
                0.0,
            );
            let model = RowModel::new(&row);
            let mut z = model.at_rest();
            let p = [0.004, -0.002, 0.001, 0.003];
            for (s, &x) in p.iter().enumerate() {
                z[model.plastic_slot(s)] = x;
            }
            let mut qs = vec![0.0; model.n];
            model.static_offsets(&z, &mut qs);
            for s in 0..4 {
                let (first, c) = model.residual_row(s);
                assert_eq!(first, 0);
                let d: f64 = c.iter().zip(&p).map(|(c, p)| c * p).sum();
                let d_s = dot(&model.storeys[s].modal_row, &qs);
                assert!(
                    (d - d_s).abs() < 1e-12 * p[0].abs(),
                    "storey {s}: {d} {d_s}"
                );
                if !lean {
                    assert!((d - p[s]).abs() < 1e-12, "storey {s}: {d} against {}", p[s]);
                } else {
                    assert!(
                        (d - p[s]).abs() > 1e-6 * p[s].abs(),
                        "gravity leans on storey {s}"
                    );
                }
            }
        }
        let mut one = sdof(1e5, 0.5, 0.05, 0.01, 0.0);
        let k = one.stiffness[0];
        one.geometric = Some(vec![0.2 * k]);
        let row = Row::new(
            vec![one, tower(1, 0.3, false, None, 0.0)],
            vec![1.0],
            LawKind::Linear,
            1e9,
            0.0,
        );
        let (_, c) = RowModel::new(&row).residual_row(0);
        assert!((c[0] - 1.0 / 0.8).abs() < 1e-12, "{}", c[0]);
    }
}
