//! Integration of one run of a row of shear buildings ([`crate::physics::row`]), in f64, in
//! modal coordinates: each building's motion is its mass-normalised modes `q`
//! ([`crate::physics::shear`]), so free flight is the exact propagator per mode and damping of
//! either classical kind is diagonal. A contact level adds its force to the modes of the two
//! floors it joins (`phi^T F`, `O(N)` per level).
//!
//! The state is `[q (n), q' (n), w (one per level), e_in, e_damp]`: all buildings' modal
//! displacements, then velocities, each level's contact work `w_l' = F_l delta_l'`, and the
//! input and damping work for the energy balance. Each level has its own contact mode
//! (free, approach, restitution) and impact speed; an event is any level's mode ending, located
//! on the largest of the levels' event values (which is positive as soon as one of them is).
//!
//! Two schemes, as for the pair ([`super`]): [`reference`](mod@reference) (adaptive
//! Dormand-Prince, the truth) and [`fast`] (exact modal free steps at the record's `dt`, RK4
//! substeps sized to the contact only in record steps where some level may touch, in floor
//! coordinates for the buildings whose damping allows it: `RowModel::substep_model`).

pub mod fast;
pub mod reference;
pub mod yielding;

use super::events::{error_margin, fourth_derivative_bound, hidden_rise, locate, touch};
use super::hermite::{
    cubic_max_bound, hermite_range, quintic_max_bound, quintic_range, raise_cubic_peak,
    raise_quintic_peak,
};
use super::tracker::raise_force_peak;
use super::{Mode, Segment};
use crate::physics::contact::Contact;
use crate::physics::model::{EnergyBalance, Forcing, Status};
use crate::physics::row::{
    BuildingOutput, LevelClosing, LevelOutput, Row, RowOutput, StoreyOutput,
};
use crate::physics::shear::Modes;
use yielding::{StoreyMode, StoreyModel};

pub use fast::RowFastOptions;

/// One building of the row, as the integrators see it.
#[derive(Debug, Clone)]
pub(crate) struct BuildingModel {
    /// Index of its first mode in `q`.
    pub off: usize,
    pub modes: Modes,
    /// Storey heights, m.
    pub heights: Vec<f64>,
    pub masses: Vec<f64>,
    /// `sqrt` of the total mass: modal coordinates of a 1 m motion are this large.
    pub scale: f64,
    /// Its floor-coordinate form (Rayleigh damping only: `C` is then tridiagonal like `K`).
    pub floor_form: Option<FloorForm>,
    /// Per mode, its largest `|phi|` over the floors: a bound on any floor's share of it.
    pub shape_max: Vec<f64>,
    /// Its slice of the state holds floor displacements and velocities instead of modes
    /// (in the fast scheme's contact substeps, [`RowModel::substep_model`]).
    pub in_floors: bool,
    /// Index of its storey 0 in [`RowModel::storeys`] where its storeys yield.
    pub first_storey: Option<usize>,
}

/// Buildings of this many storeys or more take their contact substeps in floor coordinates.
/// Below it the modes cost no more and the change of coordinates is overhead (`pound bench
/// --storeys 1,3,6,12,20`: 0.9x at one storey, even at three, 1.1x at six; BENCHMARKS.md).
pub(crate) const FLOOR_SUBSTEPS_FROM: usize = 4;

/// A shear building in floor coordinates: `M u'' + C u' + K u = -M 1 ag + F` with tridiagonal
/// `K` and `C = a0 M + a1 K`, so its right-hand side costs `O(N)`.
#[derive(Debug, Clone)]
pub(crate) struct FloorForm {
    /// Storey stiffnesses, N/m: `k[j]` joins floor `j - 1` (the ground for `j = 0`) and `j`.
    pub k: Vec<f64>,
    pub a0: f64,
    pub a1: f64,
    pub inv_m: Vec<f64>,
}

impl FloorForm {
    /// `out[j] = (K x)_j / m_j`.
    #[inline]
    #[allow(clippy::needless_range_loop)] // floor j of `out`, `k`, `inv_m` and `x`
    fn k_over_m(&self, x: impl Fn(usize) -> f64, out: &mut [f64]) {
        let nb = self.k.len();
        let storey = |j: usize| self.k[j] * (x(j) - if j == 0 { 0.0 } else { x(j - 1) });
        let mut s = storey(0);
        for j in 0..nb {
            let above = if j + 1 < nb { storey(j + 1) } else { 0.0 };
            out[j] = (s - above) * self.inv_m[j];
            s = above;
        }
    }
}

impl BuildingModel {
    pub fn n(&self) -> usize {
        self.modes.count()
    }
}

/// One contact level, as the integrators see it.
#[derive(Debug, Clone)]
pub(crate) struct LevelModel {
    /// Offset and length of the left and right buildings' modes in `q`.
    pub a: (usize, usize),
    pub b: (usize, usize),
    /// Buildings and floors (from 0) of the level.
    pub buildings: (usize, usize),
    pub floors: (usize, usize),
    /// Mode-shape rows of the two floors: `u_left = phi_a . q[a]`.
    pub phi_a: Vec<f64>,
    pub phi_b: Vec<f64>,
    /// How the level's force enters the two buildings' accelerations: the mode-shape rows
    /// again (`phi^T F`), or `1 / m` of the floor in floor coordinates.
    pub psi_a: Vec<f64>,
    pub psi_b: Vec<f64>,
    pub gap: f64,
    pub contact: Contact,
}

/// A row resolved for integration: modes of every building and the levels in modal terms.
#[derive(Debug, Clone)]
pub struct RowModel {
    /// Total modes.
    pub(crate) n: usize,
    /// Per mode: `w^2`, `2 xi w` and the participation `L`.
    pub(crate) w2: Vec<f64>,
    pub(crate) two_xi_w: Vec<f64>,
    pub(crate) part: Vec<f64>,
    pub(crate) buildings: Vec<BuildingModel>,
    pub(crate) levels: Vec<LevelModel>,
    /// The yielding storeys, building by building (none in an elastic row).
    pub(crate) storeys: Vec<StoreyModel>,
}

impl RowScheme {
    pub fn key(&self) -> &'static str {
        match self {
            RowScheme::Fast(_) => "fast",
            RowScheme::Reference(_) => "reference",
        }
    }
}

impl RowModel {
    pub fn new(row: &Row) -> RowModel {
        let mut buildings = Vec::new();
        let mut storeys = Vec::new();
        let mut off = 0;
        let (mut w2, mut two_xi_w, mut part) = (vec![], vec![], vec![]);
        for (k, b) in row.buildings.iter().enumerate() {
            let modes = b.modes();
            for i in 0..modes.count() {
                w2.push(modes.omega[i] * modes.omega[i]);
                two_xi_w.push(2.0 * modes.xi[i] * modes.omega[i]);
                part.push(modes.participation[i]);
            }
            let n = modes.count();
            let floor_form = b.rayleigh(&modes.omega).map(|(a0, a1)| FloorForm {
                k: b.stiffness.clone(),
                a0,
                a1,
                inv_m: b.masses.iter().map(|m| 1.0 / m).collect(),
            });
            let shape_max = (0..n)
                .map(|i| {
                    modes
                        .shape
                        .iter()
                        .fold(0.0, |a: f64, row| a.max(row[i].abs()))
                })
                .collect();
            let first_storey = b.yielding.as_ref().map(|y| {
                let first = storeys.len();
                for j in 0..n {
                    let modal_row: Vec<f64> = (0..n)
                        .map(|i| {
                            modes.shape[j][i] - if j == 0 { 0.0 } else { modes.shape[j - 1][i] }
                        })
                        .collect();
                    storeys.push(StoreyModel {
                        building: k,
                        storey: j,
                        k: b.stiffness[j],
                        d_y: y.force[j] / b.stiffness[j],
                        b: y.post_yield[j],
                        height: b.heights[j],
                        off,
                        row: modal_row.clone(),
                        psi: modal_row.clone(),
                        modal_row,
                    });
                }
                first
            });
            buildings.push(BuildingModel {
                off,
                shape_max,
                first_storey,
                modes,
                heights: b.heights.clone(),
                masses: b.masses.clone(),
                scale: b.masses.iter().sum::<f64>().sqrt(),
                floor_form,
                in_floors: false,
            });
            off += n;
        }
        let levels = row
            .levels
            .iter()
            .map(|l| {
                let (ba, bb) = (&buildings[l.left], &buildings[l.left + 1]);
                let (fa, fb) = (l.floor_left - 1, l.floor_right - 1);
                LevelModel {
                    a: (ba.off, ba.n()),
                    b: (bb.off, bb.n()),
                    buildings: (l.left, l.left + 1),
                    floors: (fa, fb),
                    phi_a: ba.modes.shape[fa].clone(),
                    phi_b: bb.modes.shape[fb].clone(),
                    psi_a: ba.modes.shape[fa].clone(),
                    psi_b: bb.modes.shape[fb].clone(),
                    gap: row.gaps[l.left],
                    contact: l.contact,
                }
            })
            .collect();
        RowModel {
            n: off,
            w2,
            two_xi_w,
            part,
            buildings,
            levels,
            storeys,
        }
    }

    /// The model of the fast scheme's contact substeps: every building of
    /// [`FLOOR_SUBSTEPS_FROM`] storeys or more with Rayleigh damping in floor coordinates
    /// (each level then reads and pushes one floor of it, `O(1)`), the others in modes. RK4 is affine-invariant, so its steps in either coordinates are the
    /// same motion to rounding; the floor form costs `O(N)` per right-hand side where the
    /// modes cost `O(N)` per level.
    /// None when no building would change coordinates.
    pub(crate) fn substep_model(&self) -> Option<RowModel> {
        let floors = |b: &BuildingModel| b.floor_form.is_some() && b.n() >= FLOOR_SUBSTEPS_FROM;
        if !self.buildings.iter().any(floors) {
            return None;
        }
        let mut m = self.clone();
        for b in m.buildings.iter_mut() {
            b.in_floors = floors(b);
        }
        for l in m.levels.iter_mut() {
            let (ba, bb) = (&m.buildings[l.buildings.0], &m.buildings[l.buildings.1]);
            if ba.in_floors {
                l.a = (ba.off + l.floors.0, 1);
                l.phi_a = vec![1.0];
                l.psi_a = vec![1.0 / ba.masses[l.floors.0]];
            }
            if bb.in_floors {
                l.b = (bb.off + l.floors.1, 1);
                l.phi_b = vec![1.0];
                l.psi_b = vec![1.0 / bb.masses[l.floors.1]];
            }
        }
        m.storeys_to_coordinates();
        Some(m)
    }

    /// Express `z`, a state of `modal` (this model's modal twin), in this model's
    /// coordinates: `u = Phi q` for the buildings in floors.
    #[cfg(test)]
    pub(crate) fn modes_to_substeps(&self, z: &mut [f64]) {
        for k in 0..self.buildings.len() {
            self.building_to_substeps(k, z);
        }
    }

    /// Back to modes: `q = Phi^T M u` for the buildings in floors.
    #[cfg(test)]
    pub(crate) fn substeps_to_modes(&self, z: &mut [f64]) {
        for k in 0..self.buildings.len() {
            self.building_to_modes(k, z);
        }
    }

    /// [`RowModel::modes_to_substeps`] for building `k` alone.
    pub(crate) fn building_to_substeps(&self, k: usize, z: &mut [f64]) {
        let (n, b) = (self.n, &self.buildings[k]);
        if b.in_floors {
            let (o, nb) = (b.off, b.n());
            let u = b.modes.to_floors(&z[o..o + nb]);
            let v = b.modes.to_floors(&z[n + o..n + o + nb]);
            z[o..o + nb].copy_from_slice(&u);
            z[n + o..n + o + nb].copy_from_slice(&v);
        }
    }

    /// [`RowModel::substeps_to_modes`] for building `k` alone.
    pub(crate) fn building_to_modes(&self, k: usize, z: &mut [f64]) {
        let (n, b) = (self.n, &self.buildings[k]);
        if b.in_floors {
            let (o, nb) = (b.off, b.n());
            let q = b.modes.to_modes(&b.masses, &z[o..o + nb]);
            let qd = b.modes.to_modes(&b.masses, &z[n + o..n + o + nb]);
            z[o..o + nb].copy_from_slice(&q);
            z[n + o..n + o + nb].copy_from_slice(&qd);
        }
    }

    /// Each building's largest modal rate, `w + 2 xi w` (1/s).
    pub(crate) fn building_rates(&self) -> Vec<f64> {
        self.buildings
            .iter()
            .map(|b| {
                (b.off..b.off + b.n())
                    .map(|i| self.mode_rate(i))
                    .fold(0.0, f64::max)
            })
            .collect()
    }

    /// Length of the state vector.
    pub(crate) fn len(&self) -> usize {
        2 * self.n + self.levels.len() + 2 + 2 * self.storeys.len()
    }

    /// The state at rest.
    pub fn at_rest(&self) -> Vec<f64> {
        vec![0.0; self.len()]
    }

    /// The state with floor displacements `u[b]` and velocities `v[b]` of every building `b`
    /// (relative to the ground).
    pub fn state_of_floors(&self, u: &[Vec<f64>], v: &[Vec<f64>]) -> Vec<f64> {
        let mut z = self.at_rest();
        for (k, b) in self.buildings.iter().enumerate() {
            let q = b.modes.to_modes(&b.masses, &u[k]);
            let qd = b.modes.to_modes(&b.masses, &v[k]);
            z[b.off..b.off + b.n()].copy_from_slice(&q);
            z[self.n + b.off..self.n + b.off + b.n()].copy_from_slice(&qd);
        }
        z
    }

    /// Floor displacements of building `b` in state `z` (in this model's coordinates: its
    /// modes, or its floors in a substep model).
    pub fn floors(&self, b: usize, z: &[f64]) -> Vec<f64> {
        let bm = &self.buildings[b];
        let own = &z[bm.off..bm.off + bm.n()];
        if bm.in_floors {
            own.to_vec()
        } else {
            bm.modes.to_floors(own)
        }
    }

    /// The largest rate of any mode (1/s): `w + 2 xi w`, as [`crate::physics::model::Oscillator::rate`].
    pub(crate) fn structural_rate(&self) -> f64 {
        (0..self.n).map(|i| self.mode_rate(i)).fold(0.0, f64::max)
    }

    /// Mode `i`'s rate, `w + 2 xi w` (1/s).
    fn mode_rate(&self, i: usize) -> f64 {
        self.w2[i].sqrt() + self.two_xi_w[i]
    }

    /// Kinetic plus strain energy (what the springs hold), J, in modal state `z`.
    pub(crate) fn mechanical_energy(&self, z: &[f64]) -> f64 {
        let n = self.n;
        let modal: f64 = (0..n)
            .map(|i| 0.5 * (z[n + i] * z[n + i] + self.w2[i] * z[i] * z[i]))
            .sum();
        if self.storeys.is_empty() {
            modal
        } else {
            modal + self.plastic_strain_correction(z)
        }
    }
}

#[inline]
fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

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
        acc(&self.phi_a, self.a) - acc(&self.phi_b, self.b)
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
        m.fourth_derivative_bounds(seg, z0, z1, &mut bounds);
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

impl RowModel {
    /// Each building's bound on the `|u''''|` of any of its floors over a free step, from each
    /// mode's bound on `|q''''|` (`bounds`): `sum_i max_j |phi_ji| bound_i`, `O(N)` per
    /// building where each level's own bound costs `O(N)` per level.
    pub(crate) fn coarse_floor_bounds(&self, bounds: &[f64], out: &mut Vec<f64>) {
        out.clear();
        out.extend(self.buildings.iter().map(|b| {
            b.shape_max
                .iter()
                .zip(&bounds[b.off..b.off + b.n()])
                .map(|(p, q)| p * q)
                .sum::<f64>()
        }));
    }

    /// Each mode's bound on `|q''''|` over a free step from `z0` to `z1` in `seg`
    /// ([`fourth_derivative_bound`] of the mode's oscillator under its share of the ground
    /// motion), into `out`.
    pub(crate) fn fourth_derivative_bounds(
        &self,
        seg: &Segment,
        z0: &[f64],
        z1: &[f64],
        out: &mut Vec<f64>,
    ) {
        let n = self.n;
        // About the static response to the plastic loads: the motion the propagator steps.
        let mut shift = [Vec::new(), Vec::new()];
        if !self.storeys.is_empty() {
            for (s, z) in shift.iter_mut().zip([z0, z1]) {
                s.resize(n, 0.0);
                self.static_offsets(z, s);
            }
        }
        let at = |s: &Vec<f64>, k: usize| s.get(k).copied().unwrap_or(0.0);
        out.clear();
        out.extend((0..n).map(|k| {
            let osc = crate::physics::model::Oscillator {
                m: 1.0,
                k: self.w2[k],
                c: self.two_xi_w[k],
            };
            let s = Segment {
                a0: seg.a0 * self.part[k],
                a1: seg.a1 * self.part[k],
                ..*seg
            };
            let q = if shift[0].is_empty() {
                z0[k].abs().max(z1[k].abs())
            } else {
                (z0[k] - at(&shift[0], k))
                    .abs()
                    .max((z1[k] - at(&shift[1], k)).abs())
            };
            let qd = z0[n + k].abs().max(z1[n + k].abs());
            fourth_derivative_bound(&osc, q, qd, &s)
        }));
    }
}

/// Each level's contact mode and impact speed: what the right-hand side needs of them.
pub(crate) type LevelModes = [(Mode, f64)];

/// What the right-hand side needs of a run besides its state.
pub(crate) struct Motion<'a> {
    /// Each level's contact mode and impact speed.
    pub levels: &'a LevelModes,
    /// The buildings that move; the others stand still (derivative 0): the fast scheme steps
    /// them exactly after a record step's substeps, and none of their levels is in contact.
    pub active: &'a [bool],
    /// Integrate the input and damping work (the energy balance); else their slots stay.
    pub energy: bool,
    /// Each yielding storey's spring state.
    pub storeys: &'a [StoreyMode],
}

/// The right-hand side at ground acceleration `ag`, into `out`.
pub(crate) fn rhs(m: &RowModel, motion: &Motion, ag: f64, z: &[f64], out: &mut [f64]) {
    let (lv, active, energy) = (motion.levels, motion.active, motion.energy);
    let n = m.n;
    let nl = m.levels.len();
    let (mut e_in, mut e_damp) = (0.0, 0.0);
    for (b, &on) in m.buildings.iter().zip(active) {
        let (o, nb) = (b.off, b.n());
        if !on {
            out[o..o + nb].fill(0.0);
            out[n + o..n + o + nb].fill(0.0);
            continue;
        }
        match (&b.floor_form, b.in_floors) {
            (Some(f), true) => {
                // u'' = -a0 u' - M^-1 K (u + a1 u') - ag; the input is -ag 1^T M u', the
                // damping work u'^T C u'.
                let (u, v) = (&z[o..o + nb], &z[n + o..n + o + nb]);
                out[o..o + nb].copy_from_slice(v);
                let acc = &mut out[n + o..n + o + nb];
                f.k_over_m(|j| u[j] + f.a1 * v[j], acc);
                for j in 0..nb {
                    acc[j] = -f.a0 * v[j] - acc[j] - ag;
                }
                if energy {
                    for j in 0..nb {
                        let mv = b.masses[j] * v[j];
                        let dv = v[j] - if j == 0 { 0.0 } else { v[j - 1] };
                        e_in -= ag * mv;
                        e_damp += f.a0 * mv * v[j] + f.a1 * f.k[j] * dv * dv;
                    }
                }
            }
            _ => {
                for i in o..o + nb {
                    let v = z[n + i];
                    out[i] = v;
                    out[n + i] = -m.two_xi_w[i] * v - m.w2[i] * z[i] - m.part[i] * ag;
                }
                if energy {
                    for i in o..o + nb {
                        let v = z[n + i];
                        e_in -= ag * m.part[i] * v;
                        e_damp += m.two_xi_w[i] * v * v;
                    }
                }
            }
        }
    }
    if !m.storeys.is_empty() {
        plastic_rhs(m, motion, z, out);
    }
    for (l, (lm, &(mode, v0))) in m.levels.iter().zip(lv).enumerate() {
        if mode == Mode::Free {
            out[2 * n + l] = 0.0;
            continue;
        }
        let f = lm.force(n, mode, v0, z);
        for (i, p) in lm.psi_a.iter().enumerate() {
            out[n + lm.a.0 + i] -= p * f;
        }
        for (i, p) in lm.psi_b.iter().enumerate() {
            out[n + lm.b.0 + i] += p * f;
        }
        out[2 * n + l] = f * lm.ddelta(n, z);
    }
    out[2 * n + nl] = e_in;
    out[2 * n + nl + 1] = e_damp;
}

/// The yielding storeys' part of the right-hand side: each plastic load on the accelerations,
/// and while a storey yields, its plastic drift rate `(1 - b) d'` and plastic work rate
/// `f p'`.
fn plastic_rhs(m: &RowModel, motion: &Motion, z: &[f64], out: &mut [f64]) {
    let (n, ns) = (m.n, m.storeys.len());
    for (s, sm) in m.storeys.iter().enumerate() {
        let ps = m.plastic_slot(s);
        (out[ps], out[ps + ns]) = (0.0, 0.0);
        if !motion.active[sm.building] {
            continue;
        }
        let p = z[ps];
        let kp = sm.k * p;
        for (i, psi) in sm.psi.iter().enumerate() {
            out[n + sm.off + i] += psi * kp;
        }
        if let StoreyMode::Yielding(_) = motion.storeys[s] {
            let dp = (1.0 - sm.b) * sm.drift(z, n);
            out[ps] = dp;
            out[ps + ns] = sm.k * (sm.drift(z, 0) - p) * dp;
        }
    }
}

/// One yielding storey's record (its spring state is in [`RowRun::storey_modes`]).
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct StoreyState {
    /// It has yielded at least once.
    pub yielded: bool,
    /// Its largest `|d| / h`.
    pub peak_drift_ratio: f64,
}

/// The contact state of one level and its impact bookkeeping.
#[derive(Debug, Clone, Default)]
pub(crate) struct LevelState {
    pub mode: Mode,
    /// Approach speed of the current impact.
    pub v0: f64,
    pub t_onset: f64,
    imp_peak: f64,
    pub out: LevelOutput,
}

impl LevelState {
    fn onset(&mut self, t: f64, v0: f64, f: f64) {
        self.out.impacts += 1;
        if self.out.first_impact.is_none() {
            self.out.first_impact = Some(t);
        }
        self.v0 = v0;
        self.t_onset = t;
        self.imp_peak = f.max(0.0);
    }

    fn end_impact(&mut self) {
        if self.imp_peak > self.out.peak_force {
            self.out.peak_force = self.imp_peak;
            self.out.impact_velocity = self.v0;
        }
    }
}

/// Floor kinematics of one building at one instant: displacements, velocities, relative
/// accelerations and absolute accelerations (with contact forces), and, in free flight, the
/// absolute accelerations' rates.
#[derive(Debug, Clone, Default)]
struct Floors {
    u: Vec<f64>,
    v: Vec<f64>,
    a_rel: Vec<f64>,
    a_abs: Vec<f64>,
    jerk: Vec<f64>,
    /// The contact force on each floor (positive to the right).
    force: Vec<f64>,
    /// Scratch: modal accelerations and jerks.
    acc: Vec<f64>,
    jrk: Vec<f64>,
    /// Scratch of a yielding building: its plastic loads' accelerations and their rates.
    pl_acc: Vec<f64>,
    pl_jerk: Vec<f64>,
}

impl Floors {
    fn new(nb: usize) -> Floors {
        let v = vec![0.0; nb];
        Floors {
            u: v.clone(),
            v: v.clone(),
            a_rel: v.clone(),
            a_abs: v.clone(),
            jerk: v.clone(),
            force: v.clone(),
            acc: v.clone(),
            jrk: v.clone(),
            pl_acc: v.clone(),
            pl_jerk: v,
        }
    }

    /// Building `k`'s plastic loads (`M^-1 D^T K p` and its rate) in state `z`, into `pl_acc`
    /// and `pl_jerk`: in its modes, or in its floors when `floors`.
    fn plastic(&mut self, m: &RowModel, k: usize, z: &[f64], storeys: &[StoreyMode], floors: bool) {
        self.pl_acc.fill(0.0);
        self.pl_jerk.fill(0.0);
        m.add_plastic(k, z, storeys, &mut self.pl_acc, &mut self.pl_jerk);
        let b = &m.buildings[k];
        if floors && !b.in_floors {
            // M^-1 g = Phi Phi^T g: the modal loads back to the floors. The modal loads move to
            // the `acc` and `jrk` scratch, which the floor form overwrites after this.
            std::mem::swap(&mut self.pl_acc, &mut self.acc);
            std::mem::swap(&mut self.pl_jerk, &mut self.jrk);
            for (j, row) in b.modes.shape.iter().enumerate() {
                self.pl_acc[j] = dot(row, &self.acc);
                self.pl_jerk[j] = dot(row, &self.jrk);
            }
        }
    }

    /// Fill building `k` (`b`) from state `z` at ground acceleration `ag`, with `self.force`
    /// already set; `storeys`: the yielding storeys' spring states.
    #[allow(clippy::needless_range_loop)] // floor j of five vectors
    fn fill(
        &mut self,
        m: &RowModel,
        (k, b): (usize, &BuildingModel),
        z: &[f64],
        ag: f64,
        storeys: &[StoreyMode],
    ) {
        let n = m.n;
        let nb = b.n();
        let o = b.off;
        let yields = b.first_storey.is_some();
        // Below FLOOR_SUBSTEPS_FROM storeys the modes' four products cost no more.
        if let Some(f) = b.floor_form.as_ref().filter(|_| nb >= FLOOR_SUBSTEPS_FROM) {
            if yields {
                self.plastic(m, k, z, storeys, true);
            }
            // With Rayleigh damping, from the floors' motion: the structural acceleration (no
            // ground, no contact) `-a0 u' - M^-1 K (u + a1 u')`, and the jerk
            // `-a0 u''_s - M^-1 K (u' + a1 u''_s)` of the structural-and-ground acceleration
            // `u''_s`, as the modes give them, at O(N) once the floors' displacements and
            // velocities are known (two products with the mode shapes from modes, where the
            // accelerations and jerks would take two more).
            if b.in_floors {
                self.u.copy_from_slice(&z[o..o + nb]);
                self.v.copy_from_slice(&z[n + o..n + o + nb]);
            } else {
                let sh = &b.modes.shape;
                for j in 0..nb {
                    self.u[j] = dot(&sh[j], &z[o..o + nb]);
                    self.v[j] = dot(&sh[j], &z[n + o..n + o + nb]);
                }
            }
            let (u, v) = (&self.u, &self.v);
            f.k_over_m(|j| u[j] + f.a1 * v[j], &mut self.acc);
            for j in 0..nb {
                let mut acc = -f.a0 * v[j] - self.acc[j];
                if yields {
                    acc += self.pl_acc[j];
                }
                self.acc[j] = acc;
                let a_abs = acc + self.force[j] / b.masses[j];
                self.a_abs[j] = a_abs;
                self.a_rel[j] = a_abs - ag;
            }
            let (acc, v) = (&self.acc, &self.v);
            f.k_over_m(|j| v[j] + f.a1 * (acc[j] - ag), &mut self.jrk);
            for j in 0..nb {
                self.jerk[j] = -f.a0 * (self.acc[j] - ag) - self.jrk[j];
                if yields {
                    self.jerk[j] += self.pl_jerk[j];
                }
            }
            return;
        }
        if yields {
            self.plastic(m, k, z, storeys, false);
        }
        // Modal accelerations without ground and contact (they enter floor by floor below), and
        // the jerk of the structural part, with the ground's contribution to q''.
        for i in 0..nb {
            let mut acc = -m.two_xi_w[o + i] * z[n + o + i] - m.w2[o + i] * z[o + i];
            if yields {
                acc += self.pl_acc[i];
            }
            self.acc[i] = acc;
            let qdd = acc - m.part[o + i] * ag;
            self.jrk[i] = -m.two_xi_w[o + i] * qdd - m.w2[o + i] * z[n + o + i];
            if yields {
                self.jrk[i] += self.pl_jerk[i];
            }
        }
        let sh = &b.modes.shape;
        for j in 0..nb {
            self.u[j] = dot(&sh[j], &z[o..o + nb]);
            self.v[j] = dot(&sh[j], &z[n + o..n + o + nb]);
            // Phi L = 1, so the ground's part of the relative acceleration is -ag on every floor.
            let a_abs = dot(&sh[j], &self.acc) + self.force[j] / b.masses[j];
            self.a_abs[j] = a_abs;
            self.a_rel[j] = a_abs - ag;
            self.jerk[j] = dot(&sh[j], &self.jrk);
        }
    }
}

/// A point of a row's time history handed to an observer after every accepted step and
/// event (as the pair's [`super::Sample`]).
#[derive(Debug, Clone, PartialEq)]
pub struct RowSample {
    pub t: f64,
    /// Each building's floor displacements relative to the ground, m (lowest floor first).
    pub floors: Vec<Vec<f64>>,
    /// Each level's penetration (0 where apart), m, contact force, N, and contact mode.
    pub penetrations: Vec<f64>,
    pub forces: Vec<f64>,
    pub modes: Vec<Mode>,
    /// Each yielding storey, building by building (none in an elastic row).
    pub storeys: Vec<StoreySample>,
}

/// A yielding storey at a sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StoreySample {
    /// Its building and storey, from 0 (storey 0 joins the ground and the lowest floor).
    pub building: usize,
    pub storey: usize,
    /// Drift and plastic drift over the storey's height; its shear `k (d - p)`, N; the work
    /// its plastic drift has absorbed, `int f dp`, J (its hysteretic energy so far).
    pub drift_ratio: f64,
    pub plastic_drift_ratio: f64,
    pub shear_n: f64,
    pub hysteretic_energy_j: f64,
}

/// What observes a row's run.
pub type RowObserver<'o> = &'o mut dyn FnMut(&RowSample);

/// Building `k` of `modal`, standing still since `seg.t0` (its modes at `z0`, the row's modal
/// state then), stepped exactly to `t` into `z`: `Propagator` over `t - seg.t0` about the static
/// response to its plastic loads (constant while it stands still), with the input and damping
/// work where `energy`.
fn step_still(
    modal: &RowModel,
    k: usize,
    seg: &Segment,
    t: f64,
    z0: &[f64],
    z: &mut [f64],
    energy: bool,
) {
    let b = &modal.buildings[k];
    let (n, nl) = (modal.n, modal.levels.len());
    let h = t - seg.t0;
    let qs = b.first_storey.map(|_| {
        let mut qs = vec![0.0; n];
        modal.static_offsets(z0, &mut qs);
        qs
    });
    let shift = |i: usize| qs.as_ref().map_or(0.0, |q| q[i]);
    for i in b.off..b.off + b.n() {
        let osc = crate::physics::model::Oscillator {
            m: 1.0,
            k: modal.w2[i],
            c: modal.two_xi_w[i],
        };
        let (a0, a1) = (modal.part[i] * seg.a0, modal.part[i] * seg.at(t));
        let p = crate::physics::propagator::Propagator::new(&osc, h);
        let q0 = z0[i] - shift(i);
        let (q1, v1) = p.step(q0, z0[n + i], a0, a1);
        (z[i], z[n + i]) = (q1 + shift(i), v1);
        if energy {
            let f = crate::physics::propagator::EnergyForms::new(&osc, h);
            let (vv, agv) = f.integrals(q0, z0[n + i], a0, a1);
            z[2 * n + nl] -= agv;
            z[2 * n + nl + 1] += modal.two_xi_w[i] * vv;
        }
    }
}

/// One run of a row being integrated, shared by both schemes (as the pair's `Integration`).
pub(crate) struct RowRun<'m> {
    /// The model the state is in: `modal`, or its substep model between
    /// [`RowRun::enter_substeps`] and [`RowRun::leave_substeps`].
    pub m: &'m RowModel,
    modal: &'m RowModel,
    pub z: Vec<f64>,
    pub levels: Vec<LevelState>,
    pub buildings: Vec<BuildingOutput>,
    pub free_steps: u64,
    /// Report the energy balance.
    pub energy: bool,
    e_initial: f64,
    e_peak: f64,
    /// Each building's floor kinematics at the start and end of the last tracked piece;
    /// `ends_valid`: the ends describe `z` in the levels' current modes, so the next piece
    /// starts from them instead of computing them again.
    floors: Vec<[Floors; 2]>,
    ends_valid: bool,
    /// The floors hold a prepared free step's ends ([`RowRun::prepare_free_ends`]), and
    /// `ends_valid` before it.
    ends_ready: bool,
    valid_before: bool,
    touched: Vec<bool>,
    /// The buildings that move in the current substeps (all, outside the fast scheme's
    /// contact steps), and the levels between two of them: only those are integrated, checked
    /// for events and tracked ([`RowRun::set_active`]).
    pub active: Vec<bool>,
    level_on: Vec<bool>,
    /// Each yielding storey's spring state, and its record.
    pub storey_modes: Vec<StoreyMode>,
    storeys: Vec<StoreyState>,
    /// No storey can yield again after the run's end (set by the scheme,
    /// [`RowModel::settled`]): the plastic drifts are the residual drifts.
    pub settled: bool,
    /// Per event (levels, then storeys), whether it fires in the step being located.
    firing: Vec<bool>,
    /// Per level, its floors' closing and peaks, where asked for ([`RowRun::track_closings`]).
    closings: Option<Vec<LevelClosing>>,
    /// Hears every accepted step and event ([`RowRun::emit`]).
    pub observer: Option<RowObserver<'m>>,
}

impl<'m> RowRun<'m> {
    /// Start at `t0` from state `z` (levels already overlapping start in contact).
    pub fn start(m: &'m RowModel, z: Vec<f64>, t0: f64) -> Self {
        let mut run = RowRun {
            m,
            modal: m,
            levels: vec![LevelState::default(); m.levels.len()],
            buildings: vec![BuildingOutput::default(); m.buildings.len()],
            free_steps: 0,
            energy: true,
            e_initial: m.mechanical_energy(&z),
            e_peak: 0.0,
            floors: m
                .buildings
                .iter()
                .map(|b| [Floors::new(b.n()), Floors::new(b.n())])
                .collect(),
            ends_valid: false,
            ends_ready: false,
            valid_before: false,
            touched: vec![false; m.buildings.len()],
            active: vec![true; m.buildings.len()],
            level_on: vec![true; m.levels.len()],
            storey_modes: vec![StoreyMode::Elastic; m.storeys.len()],
            storeys: vec![StoreyState::default(); m.storeys.len()],
            settled: false,
            firing: Vec::with_capacity(m.levels.len() + m.storeys.len()),
            closings: None,
            observer: None,
            z,
        };
        let z = run.z.clone();
        run.transitions(t0, &z, &z);
        if !m.storeys.is_empty() {
            run.storey_transitions();
        }
        run
    }

    /// Track each level's closing and its floors' peaks from here on (into
    /// [`RowOutput::closings`]). Every piece must move both buildings of every level: no
    /// building may stand still.
    pub fn track_closings(&mut self) {
        self.closings = Some(vec![LevelClosing::default(); self.m.levels.len()]);
    }

    /// Raise each level's closing and its floors' peaks over a piece `t0 -> t0 + h` between
    /// the floors' kinematics at its ends (no contact acts: the quintic Hermite, as the
    /// buildings' peaks).
    fn raise_closings(&mut self, t0: f64, h: f64) {
        let Some(closings) = self.closings.as_mut() else {
            return;
        };
        for (c, lm) in closings.iter_mut().zip(&self.m.levels) {
            let ((a, b), (fa, fb)) = (lm.buildings, lm.floors);
            let ([a0, a1], [b0, b1]) = (&self.floors[a], &self.floors[b]);
            let y = [a0.u[fa] - b0.u[fb], a1.u[fa] - b1.u[fb]];
            let d = [a0.v[fa] - b0.v[fb], a1.v[fa] - b1.v[fb]];
            let acc = [a0.a_rel[fa] - b0.a_rel[fb], a1.a_rel[fa] - b1.a_rel[fb]];
            if quintic_max_bound(y, d, acc, h) > c.closing {
                let (hi, s) = quintic_range(y, d, acc, h)[1];
                if hi > c.closing {
                    (c.closing, c.time) = (hi, Some(t0 + s * h));
                }
            }
            c.peak_left = raise_quintic_peak(
                c.peak_left,
                [a0.u[fa], a1.u[fa]],
                [a0.v[fa], a1.v[fa]],
                [a0.a_rel[fa], a1.a_rel[fa]],
                h,
            );
            c.peak_right = raise_quintic_peak(
                c.peak_right,
                [b0.u[fb], b1.u[fb]],
                [b0.v[fb], b1.v[fb]],
                [b0.a_rel[fb], b1.a_rel[fb]],
                h,
            );
        }
    }

    /// Take the state into `sub` (the modal model's [`RowModel::substep_model`]) for a record
    /// step of substeps.
    /// The floors' kinematics at the last piece's end stay valid: they are the same motion
    /// in either coordinates.
    /// Only the active buildings change coordinates: the others keep their modal state at the
    /// step's start until they are activated or stepped exactly.
    pub fn enter_substeps(&mut self, sub: &'m RowModel) {
        for k in 0..sub.buildings.len() {
            if self.active[k] {
                sub.building_to_substeps(k, &mut self.z);
            }
        }
        self.m = sub;
    }

    /// Back to the modal model after the substeps.
    pub fn leave_substeps(&mut self) {
        if !std::ptr::eq(self.m, self.modal) {
            for k in 0..self.m.buildings.len() {
                if self.active[k] {
                    self.m.building_to_modes(k, &mut self.z);
                }
            }
            self.m = self.modal;
        }
    }

    /// Let only the `active` buildings move in the substeps to come (and the levels between
    /// two of them be checked).
    pub fn set_active(&mut self, active: &[bool]) {
        self.active.copy_from_slice(active);
        self.refresh_levels_on();
    }

    /// A level is checked when both its buildings move.
    fn refresh_levels_on(&mut self) {
        for (on, lm) in self.level_on.iter_mut().zip(&self.m.levels) {
            *on = self.active[lm.buildings.0] && self.active[lm.buildings.1];
        }
    }

    /// Whether level `l` is checked: both its buildings move.
    pub fn level_on(&self, l: usize) -> bool {
        self.level_on[l]
    }

    /// Every building moves again (after a record step with some standing still).
    pub fn all_active(&mut self) {
        self.active.fill(true);
        self.level_on.fill(true);
    }

    /// A building that stood still since `seg.t0` joins the substeps at `t`: its modes are
    /// stepped exactly from the step's start (`Propagator` over `t - seg.t0`, with the input and
    /// damping work), its peaks tracked over that free piece, and its state moved into the
    /// substeps' coordinates.
    pub fn activate(&mut self, k: usize, seg: &Segment, t: f64) {
        let modal = self.modal;
        let h = t - seg.t0;
        let z0 = self.z.clone();
        if h > 0.0 {
            step_still(modal, k, seg, t, &z0, &mut self.z, self.energy);
            let z1 = self.z.clone();
            self.track_still(k, &z0, &z1, (seg.a0, seg.at(t)), h);
        }
        self.active[k] = true;
        self.refresh_levels_on();
        if !std::ptr::eq(self.m, modal) {
            self.m.building_to_substeps(k, &mut self.z);
        }
    }

    /// End a record step over `seg` for the buildings that stood still through it: their
    /// exact free step `z1` (modal, the whole row's), with `work` (each mode's input and
    /// damping work over the step, when the energy is kept), and their peaks over it. Call in
    /// modal coordinates ([`RowRun::leave_substeps`]).
    pub fn finish_still(&mut self, seg: &Segment, z0: &[f64], z1: &[f64], work: &[(f64, f64)]) {
        let modal = self.modal;
        let (n, nl) = (modal.n, modal.levels.len());
        for k in 0..modal.buildings.len() {
            if self.active[k] {
                continue;
            }
            let b = &modal.buildings[k];
            for i in b.off..b.off + b.n() {
                self.z[i] = z1[i];
                self.z[n + i] = z1[n + i];
                if let Some(&(agv, vv)) = work.get(i) {
                    self.z[2 * n + nl] -= agv;
                    self.z[2 * n + nl + 1] += modal.two_xi_w[i] * vv;
                }
            }
            self.track_still(k, z0, z1, (seg.a0, seg.a1), seg.dt);
        }
        self.e_peak = self.e_peak.max(self.e_initial + self.z[2 * n + nl]);
        self.all_active();
    }

    /// Raise building `k`'s peaks over a free piece of length `h` from `z0` to `z1` (modal
    /// states; no contact acts on it), leaving its floor kinematics at `z1` as the piece's end.
    fn track_still(&mut self, k: usize, z0: &[f64], z1: &[f64], ag: (f64, f64), h: f64) {
        let modal = self.modal;
        let bm = &modal.buildings[k];
        for (end, z, a) in [(0, z0, ag.0), (1, z1, ag.1)] {
            let f = &mut self.floors[k][end];
            f.force.fill(0.0);
            f.fill(modal, (k, bm), z, a, &self.storey_modes);
        }
        self.raise_building(k, bm, h, true);
    }

    /// Each level's mode and impact speed, into `out`.
    pub fn level_modes(&self, out: &mut Vec<(Mode, f64)>) {
        out.clear();
        out.extend(self.levels.iter().map(|l| (l.mode, l.v0)));
    }

    /// The checked levels ([`RowRun::level_on`]) in contact mode `mode`.
    fn levels_in(&self, mode: Mode) -> impl Iterator<Item = (&LevelModel, &LevelState)> {
        self.m
            .levels
            .iter()
            .zip(&self.levels)
            .zip(&self.level_on)
            .filter(move |((_, ls), &on)| on && ls.mode == mode)
            .map(|(l, _)| l)
    }

    /// The shortest [`Contact::onset_cut`] at `t` of the checked levels that approach.
    pub fn onset_cut(&self, t: f64, per_contact: f64, tol: f64) -> f64 {
        self.levels_in(Mode::Approach)
            .map(|(lm, ls)| {
                lm.contact
                    .onset_cut(t - ls.t_onset, ls.v0, per_contact, tol)
            })
            .fold(f64::INFINITY, f64::min)
    }

    pub fn any_contact(&self) -> bool {
        self.levels.iter().any(|l| l.mode != Mode::Free)
    }

    /// Is some storey on a bounding line?
    pub fn any_yielding(&self) -> bool {
        self.storey_modes
            .iter()
            .any(|m| matches!(m, StoreyMode::Yielding(_)))
    }

    /// Each event's value in state `z`, levels then storeys (positive once that level's contact
    /// mode or storey's spring state must end); `-inf` where it is not checked (a level whose
    /// buildings do not both move, a storey of a building standing still).
    fn event_values<'a>(&'a self, z: &'a [f64]) -> impl Iterator<Item = f64> + use<'a, 'm> {
        let n = self.m.n;
        let levels = (self.m.levels.iter().zip(&self.levels).zip(&self.level_on)).map(
            move |((lm, ls), &on)| {
                if on {
                    lm.event_value(n, ls.mode, ls.v0, z)
                } else {
                    f64::NEG_INFINITY
                }
            },
        );
        let storeys = (self.m.storeys.iter().zip(&self.storey_modes).enumerate()).map(
            move |(s, (sm, &mode))| {
                if self.active[sm.building] {
                    let p = z[self.m.plastic_slot(s)];
                    sm.event_value(mode, sm.drift(z, 0), sm.drift(z, n), p)
                } else {
                    f64::NEG_INFINITY
                }
            },
        );
        levels.chain(storeys)
    }

    /// The largest event value of the checked levels and storeys (positive once any level's
    /// contact mode or storey's spring state must end).
    fn event_max(&self, z: &[f64]) -> f64 {
        self.event_values(z).fold(f64::NEG_INFINITY, f64::max)
    }

    /// The largest event value in `z` of the events that fire in a step's trial end (marked by
    /// [`RowRun::mark_firing`]): the function an event is located on. The others are left out
    /// because one of them can sit at 0 where a step starts (a storey that has just unloaded
    /// stays on its band edge, a level that has just separated) and leave it there while the
    /// event that fires grows from far below: regula falsi on their maximum then creeps from
    /// that end and stalls, and the event is taken late, by up to the whole step.
    fn firing_max(&self, z: &[f64]) -> f64 {
        (self.event_values(z).zip(&self.firing))
            .filter(|(_, &f)| f)
            .fold(f64::NEG_INFINITY, |m, (v, _)| m.max(v))
    }

    /// Mark the events whose value is positive in `z` as the ones that fire.
    fn mark_firing(&mut self, z: &[f64]) {
        let mut firing = std::mem::take(&mut self.firing);
        firing.clear();
        firing.extend(self.event_values(z).map(|v| v > 0.0));
        self.firing = firing;
    }

    /// The earliest fraction of a step `z0 -> z1` (length `h`) at which an elastic storey's
    /// back drift could rise past its band between the ends (both inside it).
    fn hidden_yield(&self, z0: &[f64], z1: &[f64], h: f64) -> Option<f64> {
        let n = self.m.n;
        let mut first: Option<f64> = None;
        for (s, (sm, &mode)) in self.m.storeys.iter().zip(&self.storey_modes).enumerate() {
            if mode != StoreyMode::Elastic || !self.active[sm.building] {
                continue;
            }
            let p = self.m.plastic_slot(s);
            let e0 = sm.edges(sm.drift(z0, 0), sm.drift(z0, n), z0[p]);
            let e1 = sm.edges(sm.drift(z1, 0), sm.drift(z1, n), z1[p]);
            for (a, b) in e0.iter().zip(&e1) {
                if let Some(x) = hidden_rise(a.0, a.1, b.0, b.1, h) {
                    first = Some(first.map_or(x, |f| f.min(x)));
                }
            }
        }
        first
    }

    /// The storeys' spring changes that the events at the run's state call for: yield onset
    /// on a bounding line when moving outwards, unloading when the drift velocity reverses. A
    /// storey that reached its bounding line already turning back (a grazing touch, located
    /// just past its turning point) takes the return map instead: its plastic drift moves by
    /// the overshoot, `(1 - b)` times it, as OpenSees' `Steel01` would, so it is on its band
    /// again and stays elastic (with the work of that flow).
    fn storey_transitions(&mut self) {
        let m = self.m;
        let (n, ns) = (m.n, m.storeys.len());
        for (s, sm) in m.storeys.iter().enumerate() {
            if !self.active[sm.building] {
                continue;
            }
            let slot = m.plastic_slot(s);
            let z = &mut self.z;
            let (d, r, p) = (sm.drift(z, 0), sm.drift(z, n), z[slot]);
            let mode = self.storey_modes[s];
            if sm.event_value(mode, d, r, p) <= 0.0 {
                continue;
            }
            // The plastic load's rate at the last piece's end was the old state's.
            self.ends_valid = false;
            self.storey_modes[s] = match mode {
                StoreyMode::Elastic => {
                    let sign = sm.back_drift(d, p).signum();
                    self.storeys[s].yielded = true;
                    if sign * r > 0.0 {
                        StoreyMode::Yielding(sign)
                    } else {
                        let p_new = (1.0 - sm.b) * (d - sign * sm.d_y);
                        let f_mid = sm.k * (d - 0.5 * (p + p_new));
                        z[slot + ns] += f_mid * (p_new - p);
                        z[slot] = p_new;
                        StoreyMode::Elastic
                    }
                }
                StoreyMode::Yielding(_) => StoreyMode::Elastic,
            };
        }
    }

    /// Set the contact forces on each building's floors in state `z` into `floors[.][end]`.
    fn set_floor_forces(&mut self, z: &[f64], end: usize) {
        let n = self.m.n;
        for f in self.floors.iter_mut() {
            f[end].force.fill(0.0);
        }
        for (lm, ls) in self.m.levels.iter().zip(&self.levels) {
            if ls.mode == Mode::Free {
                continue;
            }
            let fl = lm.force(n, ls.mode, ls.v0, z);
            self.floors[lm.buildings.0][end].force[lm.floors.0] -= fl;
            self.floors[lm.buildings.1][end].force[lm.floors.1] += fl;
        }
    }

    /// Raise the buildings' peaks over the piece `z0 -> z1` of length `h` (ground acceleration
    /// `ag0`, `ag1` at its ends). A building no contact acts on takes its displacement and
    /// drift peaks from the quintic Hermite (both ends' accelerations are exact) and its floor
    /// accelerations' from the cubic Hermite with their rates; one in contact takes the cubic
    /// Hermite of displacements and drifts, and its accelerations at the piece's ends (a
    /// contact force's spike is not smooth enough for the cubic).
    fn track_buildings(&mut self, z0: &[f64], z1: &[f64], ag: (f64, f64), h: f64) {
        let m = self.m;
        if self.ends_ready {
            self.ends_ready = false;
        } else {
            self.floor_ends(z0, z1, ag);
        }
        self.touched.fill(false);
        for (lm, ls) in m.levels.iter().zip(&self.levels) {
            if ls.mode != Mode::Free {
                self.touched[lm.buildings.0] = true;
                self.touched[lm.buildings.1] = true;
            }
        }
        for (k, bm) in m.buildings.iter().enumerate() {
            if self.active[k] {
                self.raise_building(k, bm, h, !self.touched[k]);
            }
        }
    }

    /// The moving buildings' floor kinematics at both ends of the piece `z0 -> z1` into
    /// `floors[.][0]` and `[1]` (the start's from the last piece's end while still valid).
    #[inline(always)]
    fn floor_ends(&mut self, z0: &[f64], z1: &[f64], ag: (f64, f64)) {
        let m = self.m;
        if self.ends_valid {
            for (f, _) in self.floors.iter_mut().zip(&self.active).filter(|(_, &a)| a) {
                f.swap(0, 1);
            }
        } else {
            self.set_floor_forces(z0, 0);
            for (k, bm) in m.buildings.iter().enumerate() {
                if self.active[k] {
                    self.floors[k][0].fill(m, (k, bm), z0, ag.0, &self.storey_modes);
                }
            }
        }
        self.set_floor_forces(z1, 1);
        for (k, bm) in m.buildings.iter().enumerate() {
            if self.active[k] {
                self.floors[k][1].fill(m, (k, bm), z1, ag.1, &self.storey_modes);
            }
        }
    }

    /// The floors' kinematics at both ends of a free record step `z0 -> z1` (ground
    /// acceleration `ag` at its ends), computed before the step is taken so that the levels'
    /// checks read them ([`RowRun::level_ends`]): [`RowRun::free_step`] then tracks the peaks
    /// from them, and [`RowRun::drop_free_ends`] puts the floors back when the step is redone in
    /// substeps instead.
    pub fn prepare_free_ends(&mut self, z0: &[f64], z1: &[f64], ag: (f64, f64)) {
        self.valid_before = self.ends_valid;
        self.floor_ends(z0, z1, ag);
        self.ends_ready = true;
    }

    /// Undo [`RowRun::prepare_free_ends`]: the start's kinematics are the last piece's end
    /// again.
    pub fn drop_free_ends(&mut self) {
        if self.ends_ready {
            for f in self.floors.iter_mut() {
                f.swap(0, 1);
            }
            self.ends_valid = self.valid_before;
            self.ends_ready = false;
        }
    }

    /// Level `l`'s penetration and its rate at the start and end of the prepared free step,
    /// `[delta0, delta0', delta1, delta1']`, from the floors (the same products as
    /// [`LevelModel::delta`] from the modes).
    pub fn level_ends(&self, l: usize) -> [f64; 4] {
        let lm = &self.m.levels[l];
        let ((a, b), (fa, fb)) = (lm.buildings, lm.floors);
        let [a0, a1] = &self.floors[a];
        let [b0, b1] = &self.floors[b];
        [
            a0.u[fa] - b0.u[fb] - lm.gap,
            a0.v[fa] - b0.v[fb],
            a1.u[fa] - b1.u[fb] - lm.gap,
            a1.v[fa] - b1.v[fb],
        ]
    }

    /// Raise building `k`'s peaks over a piece of length `h` between its floor kinematics
    /// `floors[k]`: `free` when no contact acts on it.
    #[inline(always)]
    fn raise_building(&mut self, k: usize, bm: &BuildingModel, h: f64, free: bool) {
        {
            let [s0, s1] = &self.floors[k];
            let out = &mut self.buildings[k];
            let nb = bm.n();
            let raise = |peak: f64, y: [f64; 2], d: [f64; 2], a: [f64; 2]| -> f64 {
                if free {
                    raise_quintic_peak(peak, y, d, a, h)
                } else {
                    raise_cubic_peak(peak, y[0], d[0], y[1], d[1], h)
                }
            };
            let top = nb - 1;
            out.peak_roof = raise(
                out.peak_roof,
                [s0.u[top], s1.u[top]],
                [s0.v[top], s1.v[top]],
                [s0.a_rel[top], s1.a_rel[top]],
            );
            for j in 0..nb {
                let below = |x: &[f64]| if j == 0 { 0.0 } else { x[j - 1] };
                let inv_h = 1.0 / bm.heights[j];
                let y = [
                    (s0.u[j] - below(&s0.u)) * inv_h,
                    (s1.u[j] - below(&s1.u)) * inv_h,
                ];
                let d = [
                    (s0.v[j] - below(&s0.v)) * inv_h,
                    (s1.v[j] - below(&s1.v)) * inv_h,
                ];
                // The ground's floor 0 moves with the frame: its relative acceleration is 0.
                let a = [
                    (s0.a_rel[j] - below(&s0.a_rel)) * inv_h,
                    (s1.a_rel[j] - below(&s1.a_rel)) * inv_h,
                ];
                let p = raise(out.peak_drift_ratio, y, d, a);
                if p > out.peak_drift_ratio {
                    out.peak_drift_ratio = p;
                    out.drift_storey = j as u32 + 1;
                }
                if let Some(first) = bm.first_storey {
                    let st = &mut self.storeys[first + j];
                    st.peak_drift_ratio = raise(st.peak_drift_ratio, y, d, a);
                }
                let p = if free {
                    raise_cubic_peak(
                        out.peak_accel,
                        s0.a_abs[j],
                        s0.jerk[j],
                        s1.a_abs[j],
                        s1.jerk[j],
                        h,
                    )
                } else {
                    out.peak_accel.max(s0.a_abs[j].abs()).max(s1.a_abs[j].abs())
                };
                if p > out.peak_accel {
                    out.peak_accel = p;
                    out.accel_floor = j as u32 + 1;
                }
            }
        }
    }

    /// Account for a piece `t0 -> t0 + h` from `z0` to `z1` in the current modes.
    fn track(&mut self, t0: f64, h: f64, z0: &[f64], z1: &[f64], ag: (f64, f64)) {
        let m = self.m;
        let n = m.n;
        self.track_buildings(z0, z1, ag, h);
        self.raise_closings(t0, h);
        self.ends_valid = true;
        let nl = m.levels.len();
        self.e_peak = self.e_peak.max(self.e_initial + z1[2 * n + nl]);
        for (l, (lm, ls)) in m.levels.iter().zip(self.levels.iter_mut()).enumerate() {
            if ls.mode == Mode::Free {
                continue;
            }
            let o = &mut ls.out;
            o.contact_time += h;
            let (y0, d0, y1, d1) = (
                lm.delta(z0),
                lm.ddelta(n, z0),
                lm.delta(z1),
                lm.ddelta(n, z1),
            );
            if cubic_max_bound(y0, d0, y1, d1, h) > o.peak_penetration {
                o.peak_penetration = o.peak_penetration.max(hermite_range(y0, d0, y1, d1, h).1);
            }
            o.dissipated_energy = z1[2 * n + l];
            // The force's rates from the floors' accelerations at both ends (with the contact
            // forces of these modes: the ends are recomputed where a mode changes).
            let ((a, b), (fa, fb)) = (lm.buildings, lm.floors);
            let accel = |e: usize| self.floors[a][e].a_rel[fa] - self.floors[b][e].a_rel[fb];
            let approaching = ls.mode == Mode::Approach;
            let f = lm.force(n, ls.mode, ls.v0, z1);
            let r1 = lm.contact.force_rate(y1, d1, accel(1), ls.v0, approaching);
            ls.imp_peak = raise_force_peak(ls.imp_peak, f, r1, h, || {
                let f0 = lm.force(n, ls.mode, ls.v0, z0);
                (
                    f0,
                    lm.contact.force_rate(y0, d0, accel(0), ls.v0, approaching),
                )
            });
        }
    }

    /// Hand the observer, if any, the row at time `t` inside the record step `seg`: the moving
    /// buildings from the state (in the current model), those standing still stepped exactly
    /// from the step's start to `t` (as [`RowRun::activate`] would, without changing the run).
    pub fn emit(&mut self, seg: &Segment, t: f64) {
        if self.observer.is_none() {
            return;
        }
        let (m, modal, n) = (self.m, self.modal, self.m.n);
        let floors: Vec<Vec<f64>> = (0..m.buildings.len())
            .map(|k| {
                if self.active[k] {
                    m.floors(k, &self.z)
                } else {
                    let mut z = self.z.clone();
                    if t > seg.t0 {
                        step_still(modal, k, seg, t, &self.z, &mut z, false);
                    }
                    modal.floors(k, &z)
                }
            })
            .collect();
        let sample = RowSample {
            t,
            penetrations: m
                .levels
                .iter()
                .map(|lm| {
                    let ((a, b), (fa, fb)) = (lm.buildings, lm.floors);
                    (floors[a][fa] - floors[b][fb] - lm.gap).max(0.0)
                })
                .collect(),
            forces: (m.levels.iter().zip(&self.levels).zip(&self.level_on))
                .map(|((lm, ls), &on)| {
                    if on {
                        lm.force(n, ls.mode, ls.v0, &self.z)
                    } else {
                        0.0
                    }
                })
                .collect(),
            modes: self.levels.iter().map(|ls| ls.mode).collect(),
            // A still building's plastic drifts stay as they are until it moves again.
            storeys: m
                .storeys
                .iter()
                .enumerate()
                .map(|(s, sm)| {
                    let u = &floors[sm.building];
                    let below = if sm.storey == 0 {
                        0.0
                    } else {
                        u[sm.storey - 1]
                    };
                    let drift = u[sm.storey] - below;
                    let p = self.z[m.plastic_slot(s)];
                    StoreySample {
                        building: sm.building,
                        storey: sm.storey,
                        drift_ratio: drift / sm.height,
                        plastic_drift_ratio: p / sm.height,
                        shear_n: sm.k * (drift - p),
                        hysteretic_energy_j: self.z[m.plastic_slot(s) + m.storeys.len()],
                    }
                })
                .collect(),
            floors,
        };
        if let Some(obs) = self.observer.as_mut() {
            obs(&sample);
        }
    }

    /// A free record step over `seg` to `z1`, with no possible contact (checked by the caller).
    pub fn free_step(&mut self, seg: &Segment, z1: Vec<f64>) {
        let z0 = std::mem::take(&mut self.z);
        self.track(seg.t0, seg.dt, &z0, &z1, (seg.a0, seg.a1));
        self.free_steps += 1;
        self.z = z1;
        self.emit(seg, seg.t1());
    }

    /// Apply the mode changes that the events at state `z` (time `t`) call for; `before` is
    /// the state at the start of the step in which they were located. A level whose event
    /// value is not positive only goes back to approach if its restitution closes again (a
    /// law whose phase is not an event).
    fn transitions(&mut self, t: f64, z: &[f64], before: &[f64]) {
        let n = self.m.n;
        let on = self.level_on.iter();
        for ((lm, ls), _) in self
            .m
            .levels
            .iter()
            .zip(self.levels.iter_mut())
            .zip(on)
            .filter(|(_, &on)| on)
        {
            if lm.event_value(n, ls.mode, ls.v0, z) <= 0.0 {
                if lm.reapproaches(n, ls.mode, z) {
                    ls.mode = Mode::Approach;
                    self.ends_valid = false;
                }
                continue;
            }
            // The forces at the end of the last piece were those of the old mode.
            self.ends_valid = false;
            ls.mode = match ls.mode {
                Mode::Free => {
                    let (v0, next) = touch(lm.delta(before), lm.ddelta(n, z), ls.v0);
                    let f = lm.force(n, next, v0, z);
                    ls.onset(t, v0, f);
                    next
                }
                Mode::Approach => Mode::Restitution,
                // Closing again: the same impact goes on.
                Mode::Restitution if lm.reapproaches(n, Mode::Restitution, z) => Mode::Approach,
                Mode::Restitution => {
                    ls.end_impact();
                    Mode::Free
                }
            };
        }
    }

    /// Accept `trial`, the step `t -> t + h` over `seg` in the current modes; `step(x)` re-takes
    /// it with length `x`. As the pair's `Integration::accept`: a touch hidden inside the step
    /// (at a free level) and any event are located, the step then ends there. Returns the
    /// length advanced.
    #[allow(clippy::too_many_arguments)]
    pub fn accept(
        &mut self,
        seg: &Segment,
        t: f64,
        h: f64,
        trial: Vec<f64>,
        tol_rel: f64,
        max_iter: u32,
        mut step: impl FnMut(f64) -> Vec<f64>,
    ) -> f64 {
        let n = self.m.n;
        let z0 = std::mem::take(&mut self.z);
        let (mut trial, mut h) = (trial, h);
        let mut f1 = self.event_max(&trial);
        if f1 <= 0.0 {
            let hidden = self
                .levels_in(Mode::Free)
                .filter_map(|(lm, _)| {
                    hidden_rise(
                        lm.delta(&z0),
                        lm.ddelta(n, &z0),
                        lm.delta(&trial),
                        lm.ddelta(n, &trial),
                        h,
                    )
                })
                .fold(None, |acc: Option<f64>, s| {
                    Some(acc.map_or(s, |a| a.min(s)))
                });
            let hidden = match (hidden, self.hidden_yield(&z0, &trial, h)) {
                (Some(a), Some(b)) => Some(a.min(b)),
                (a, b) => a.or(b),
            };
            if let Some(s) = hidden {
                let zs = step(s * h);
                let fs = self.event_max(&zs);
                if fs > 0.0 {
                    (trial, f1, h) = (zs, fs, s * h);
                }
            }
        }
        let ag = |x: f64| seg.at(x);
        let advanced = if f1 > 0.0 {
            self.mark_firing(&trial);
            let f0 = self.firing_max(&z0);
            let tol = (tol_rel * h).max(4.0 * f64::EPSILON * t.abs());
            let (x, zb) = locate(
                h,
                f0,
                trial,
                f1,
                tol,
                max_iter,
                &mut step,
                |s: &Vec<f64>| self.firing_max(s),
            );
            self.track(t, x, &z0, &zb, (ag(t), ag(t + x)));
            self.transitions(t + x, &zb, &z0);
            self.z = zb;
            if !self.m.storeys.is_empty() {
                self.storey_transitions();
            }
            x
        } else {
            self.track(t, h, &z0, &trial, (ag(t), ag(t + h)));
            self.z = trial;
            // A level whose phase is not an event (the law's force does not depend on it).
            for (lm, ls) in self.m.levels.iter().zip(self.levels.iter_mut()) {
                if lm.reapproaches(n, ls.mode, &self.z) {
                    ls.mode = Mode::Approach;
                    self.ends_valid = false;
                }
            }
            h
        };
        self.emit(seg, t + advanced);
        advanced
    }

    /// End the run with `status`, after `substeps` steps of integration work.
    pub fn finish(mut self, status: Status, substeps: u64) -> RowOutput {
        self.leave_substeps();
        let m = self.m;
        let n = m.n;
        let nl = m.levels.len();
        let ns = m.storeys.len();
        let hysteretic: f64 = (0..ns).map(|s| self.z[m.plastic_slot(s) + ns]).sum();
        let energy = self.energy.then(|| {
            let contact: f64 = (0..nl).map(|l| self.z[2 * n + l]).sum::<f64>() + hysteretic;
            EnergyBalance::close(
                self.e_initial,
                self.z[2 * n + nl],
                self.z[2 * n + nl + 1],
                contact,
                m.mechanical_energy(&self.z),
                self.e_peak,
            )
        });
        for ls in self.levels.iter_mut() {
            if ls.mode != Mode::Free {
                ls.end_impact();
            }
        }
        // Each storey's outputs, which each yielding building gathers.
        let storeys: Vec<StoreyOutput> = m
            .storeys
            .iter()
            .zip(&self.storeys)
            .enumerate()
            .map(|(s, (sm, st))| StoreyOutput {
                residual_drift_ratio: self.z[m.plastic_slot(s)] / sm.height,
                peak_ductility: st.peak_drift_ratio * sm.height / sm.d_y,
                hysteretic_energy: self.z[m.plastic_slot(s) + ns],
                yielded: st.yielded,
            })
            .collect();
        let mut out = RowOutput {
            status,
            levels: self.levels.iter().map(|l| l.out).collect(),
            buildings: self.buildings,
            substeps,
            free_steps: self.free_steps,
            energy,
            storeys,
            closings: self.closings.unwrap_or_default(),
            ..RowOutput::default()
        };
        if ns > 0 {
            out.gather_storeys(&m.storey_spans(), self.settled && status == Status::Ok);
        }
        out.gather();
        out
    }
}

/// Which scheme a row run uses.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum RowScheme {
    Fast(RowFastOptions),
    Reference(super::ReferenceOptions),
}

/// Simulate `m`'s buildings from rest as if no contact could ever act, tracking each level's
/// closing and its floors' peaks ([`RowOutput::closings`]; the separation of yielding
/// buildings). The levels' gaps must be beyond reach ([`UNCOUPLED_GAP_M`]). The fast scheme
/// moves every building in every substep here, so that both floors of a level share each
/// piece.
pub fn simulate_uncoupled(m: &RowModel, forcing: &Forcing, scheme: &RowScheme) -> RowOutput {
    match scheme {
        RowScheme::Fast(o) => fast::run_uncoupled(m, forcing, o),
        RowScheme::Reference(o) => reference::run_tracked(m, forcing, m.at_rest(), o, true, None),
    }
}

/// The gap given each level of a row simulated uncoupled: far beyond any floor's reach (a run
/// that closes it reports impacts, which the caller refuses).
pub const UNCOUPLED_GAP_M: f64 = 1e6;

/// Simulate one run of a row from state `z0` (see [`RowModel::at_rest`],
/// [`RowModel::state_of_floors`]) over the forcing's whole duration.
pub fn simulate_row(
    m: &RowModel,
    forcing: &Forcing,
    z0: Vec<f64>,
    scheme: &RowScheme,
) -> RowOutput {
    simulate(m, forcing, z0, scheme, None)
}

/// As [`simulate_row`] (the same output), handing `observer` the row after every accepted step
/// and event.
pub fn simulate_row_observed(
    m: &RowModel,
    forcing: &Forcing,
    z0: Vec<f64>,
    scheme: &RowScheme,
    observer: RowObserver<'_>,
) -> RowOutput {
    simulate(m, forcing, z0, scheme, Some(observer))
}

fn simulate<'a>(
    m: &'a RowModel,
    forcing: &Forcing,
    z0: Vec<f64>,
    scheme: &RowScheme,
    observer: Option<RowObserver<'a>>,
) -> RowOutput {
    match scheme {
        RowScheme::Fast(o) => fast::run(m, forcing, z0, o, observer),
        RowScheme::Reference(o) => reference::run_tracked(m, forcing, z0, o, false, observer),
    }
}
