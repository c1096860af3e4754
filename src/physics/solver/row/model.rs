//! The row as the integrators see it: each building's modes (and floor form), the contact levels
//! in modal terms, the yielding storeys, and what the schemes ask of the whole model (the state
//! at rest, floors from modes, free-step bounds).

use super::algebra::dot;
use super::storey::StoreyModel;
use crate::physics::contact::Contact;
use crate::physics::imk::ImkSpring;
use crate::physics::row::{struck_side, LevelSide, Row};
use crate::physics::shear::{storey_drift_row, Modes};
use crate::physics::solver::events::fourth_derivative_bound;
use crate::physics::solver::state::Segment;

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
    /// Where its damping couples its modes, each mode's `sum_k |E_ik|` (for the free steps'
    /// bounds); empty where it does not.
    pub coupling_sums: Vec<f64>,
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
    /// With P-Delta, each storey's geometric stiffness `P / h`: the stiffness is `K - K_G`,
    /// the damping stays `a0 M + a1 K`.
    pub geometric: Option<Vec<f64>>,
}

impl FloorForm {
    /// `out[j] = (K x)_j / m_j`.
    #[inline]
    #[allow(clippy::needless_range_loop)] // floor j of `out`, `k`, `inv_m` and `x`
    pub(super) fn k_over_m(&self, x: impl Fn(usize) -> f64, out: &mut [f64]) {
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

impl FloorForm {
    /// `out[j] += (K_G x)_j / m_j` (nothing without P-Delta).
    #[inline]
    #[allow(clippy::needless_range_loop)] // floor j of `out`, `g` and `inv_m`
    pub(super) fn add_geometric_over_m(&self, x: impl Fn(usize) -> f64, out: &mut [f64]) {
        let Some(g) = &self.geometric else { return };
        let nb = g.len();
        let storey = |j: usize| g[j] * (x(j) - if j == 0 { 0.0 } else { x(j - 1) });
        let mut s = storey(0);
        for j in 0..nb {
            let above = if j + 1 < nb { storey(j + 1) } else { 0.0 };
            out[j] += (s - above) * self.inv_m[j];
            s = above;
        }
    }
}

impl BuildingModel {
    pub fn n(&self) -> usize {
        self.modes.count()
    }

    /// A level's point on this building in floor coordinates: the offset and length of its
    /// floors in the state, the row its motion reads (the shares) and the one its force
    /// enters the floors' accelerations by (share over mass).
    fn point_in_floors(&self, side: &LevelSide) -> ((usize, usize), Vec<f64>, Vec<f64>) {
        let shares: Vec<(usize, f64)> = side.shares().collect();
        let first = shares[0].0;
        let phi = shares.iter().map(|&(_, w)| w).collect();
        let psi = shares.iter().map(|&(f, w)| w / self.masses[f]).collect();
        ((self.off + first, shares.len()), phi, psi)
    }

    /// Storey `j`'s drift in this building's current coordinates (`modal_row` in its modes):
    /// the offset in the state and the row, `d = row . z[off..]`.
    pub(crate) fn drift_row(&self, j: usize, modal_row: &[f64]) -> (usize, Vec<f64>) {
        match (self.in_floors, j) {
            (false, _) => (self.off, modal_row.to_vec()),
            (true, 0) => (self.off, vec![1.0]),
            (true, j) => (self.off + j - 1, vec![-1.0, 1.0]),
        }
    }
}

/// One contact level, as the integrators see it.
#[derive(Debug, Clone)]
pub(crate) struct LevelModel {
    /// Offset and length of the left and right buildings' modes in `q`.
    pub a: (usize, usize),
    pub b: (usize, usize),
    /// Buildings of the level, and where it meets each.
    pub buildings: (usize, usize),
    pub sides: [LevelSide; 2],
    /// Mode-shape rows of the two points: `u_left = phi_a . q[a]`.
    pub phi_a: Vec<f64>,
    pub phi_b: Vec<f64>,
    /// How the level's force enters the two buildings' accelerations: the mode-shape rows
    /// again (`phi^T F`), or `1 / m` of the floor in floor coordinates.
    pub psi_a: Vec<f64>,
    pub psi_b: Vec<f64>,
    pub gap: f64,
    pub contact: Contact,
    /// Where a floor strikes a column: the struck storey, whose shear the level reports.
    pub column: Option<StruckColumn>,
}

/// The storey a floor strikes between its floors (physics.md section 11).
#[derive(Debug, Clone, Copy)]
pub(crate) struct StruckColumn {
    /// Which side of the level it is on (0 left, 1 right), its building and storey (from 0:
    /// storey 0 joins the ground and floor 0).
    pub side: usize,
    pub building: usize,
    pub storey: usize,
    /// The share `s` of the force on the floor above (`1 - s` on the floor below).
    pub weight: f64,
    /// The share `alpha` of the storey the struck columns carry (`struck_column_share`; 1
    /// without it: the storey's columns together).
    pub share: f64,
    /// The struck columns' initial stiffness, `alpha` times the storey's, N/m: their shear is
    /// `alpha V` plus the contact's share.
    pub k: f64,
    /// Its index in [`RowModel::storeys`] where it yields.
    pub yielding: Option<usize>,
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
    /// The collapse limit on any storey's drift ratio (infinite: none), and every storey of
    /// every building as its collapse event sees it (empty without a limit).
    pub(crate) collapse_limit: f64,
    pub(crate) drifts: Vec<DriftRow>,
    /// Track every storey's peak drift ratio and every floor's peak acceleration
    /// ([`crate::physics::row::RowOutput::demands`]): off unless asked (a sweep's `--columns
    /// +storeys,+floors`).
    pub track_demands: bool,
}

/// A storey's drift in the model's coordinates, for its collapse event:
/// `d = row . z[off..off + row.len()]`.
#[derive(Debug, Clone)]
pub(crate) struct DriftRow {
    pub building: usize,
    /// From 0.
    pub storey: usize,
    pub height: f64,
    pub off: usize,
    pub row: Vec<f64>,
    /// The drift in the building's modes.
    pub modal_row: Vec<f64>,
}

impl DriftRow {
    /// Drift (`n = 0`) or drift rate (`n` the mode count) in state `z`.
    #[inline]
    pub fn drift(&self, z: &[f64], n: usize) -> f64 {
        dot(&self.row, &z[n + self.off..n + self.off + self.row.len()])
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
            // With P-Delta the damping stays `a0 M + a1 K0`, the stiffness is `K0 - K_G`.
            let floor_form = modes.rayleigh.map(|(a0, a1)| FloorForm {
                k: b.stiffness.clone(),
                a0,
                a1,
                inv_m: b.masses.iter().map(|m| 1.0 / m).collect(),
                geometric: b.geometric.clone(),
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
                    let modal_row = storey_drift_row(&modes.shape, j);
                    let imk = y.deterioration.as_ref().map(|det| {
                        let k = b.stiffness[j];
                        let h = b.heights[j];
                        ImkSpring::from_ratios(
                            det.rule,
                            k,
                            h,
                            y.force[j] / (k * h),
                            y.post_yield[j],
                            (
                                det.plastic[j],
                                det.post_capping[j],
                                det.residual[j],
                                det.ultimate[j],
                            ),
                            det.energy.as_ref().map(|e| e[j]),
                        )
                    });
                    storeys.push(StoreyModel {
                        building: k,
                        storey: j,
                        k: b.stiffness[j],
                        d_y: y.force[j] / b.stiffness[j],
                        b: y.post_yield[j],
                        height: b.heights[j],
                        geometric: b.geometric.as_ref().map_or(0.0, |g| g[j]),
                        off,
                        row: modal_row.clone(),
                        psi: modal_row.clone(),
                        modal_row,
                        imk,
                    });
                }
                first
            });
            let coupling_sums = (modes.coupling.iter().flatten())
                .map(|row| row.iter().map(|c| c.abs()).sum())
                .collect();
            buildings.push(BuildingModel {
                off,
                shape_max,
                coupling_sums,
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
                let [phi_a, phi_b] =
                    [(ba, 0), (bb, 1)].map(|(bm, k)| l.sides[k].mode_row(&bm.modes.shape));
                LevelModel {
                    a: (ba.off, ba.n()),
                    b: (bb.off, bb.n()),
                    buildings: (l.left, l.left + 1),
                    sides: l.sides,
                    psi_a: phi_a.clone(),
                    psi_b: phi_b.clone(),
                    phi_a,
                    phi_b,
                    gap: row.gaps[l.left],
                    contact: l.contact,
                    column: struck_side(&l.sides).map(|side| {
                        let building = l.left + side;
                        let storey = l.sides[side].floor - 1;
                        let share = row.buildings[building].struck_column_share.unwrap_or(1.0);
                        StruckColumn {
                            side,
                            building,
                            storey,
                            weight: l.sides[side].weight,
                            share,
                            k: share * row.buildings[building].stiffness[storey],
                            yielding: buildings[building].first_storey.map(|f| f + storey),
                        }
                    }),
                }
            })
            .collect();
        let collapse_limit = row.collapse_drift_ratio;
        let drifts = if collapse_limit.is_finite() {
            buildings
                .iter()
                .enumerate()
                .flat_map(|(k, b)| {
                    (0..b.n()).map(move |j| {
                        let modal_row = storey_drift_row(&b.modes.shape, j);
                        DriftRow {
                            building: k,
                            storey: j,
                            height: b.heights[j],
                            off: b.off,
                            row: modal_row.clone(),
                            modal_row,
                        }
                    })
                })
                .collect()
        } else {
            Vec::new()
        };
        RowModel {
            n: off,
            w2,
            two_xi_w,
            part,
            buildings,
            levels,
            storeys,
            collapse_limit,
            drifts,
            track_demands: false,
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
                (l.a, l.phi_a, l.psi_a) = ba.point_in_floors(&l.sides[0]);
            }
            if bb.in_floors {
                (l.b, l.phi_b, l.psi_b) = bb.point_in_floors(&l.sides[1]);
            }
        }
        m.storeys_to_coordinates();
        for d in m.drifts.iter_mut() {
            (d.off, d.row) = m.buildings[d.building].drift_row(d.storey, &d.modal_row);
        }
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

    /// Mode `i`'s work over an exact free step, `(int L_i ag q_i', int q_i'^2)`, into the energy
    /// balance's input and damping slots of `z`.
    #[inline]
    pub(crate) fn add_free_work(&self, z: &mut [f64], i: usize, (agv, vv): (f64, f64)) {
        let (n, nl) = (self.n, self.levels.len());
        z[2 * n + nl] -= agv;
        z[2 * n + nl + 1] += self.two_xi_w[i] * vv;
    }

    /// Each mode's bound on `|q''''|` over a free step from `z0` to `z1` in `seg`
    /// ([`fourth_derivative_bound`] of the mode's oscillator under its share of the ground
    /// motion), into `out`; the buildings `skip` marks are left out (their bounds left for
    /// their tangent steps to give).
    pub(crate) fn fourth_derivative_bounds(
        &self,
        seg: &Segment,
        (z0, z1): (&[f64], &[f64]),
        out: &mut Vec<f64>,
        skip: Option<&[bool]>,
    ) {
        let n = self.n;
        // Scratch after the bounds (no allocation once `out` has grown): each mode's
        // displacement amplitude, the static responses at both ends, a coupled building's
        // velocity and acceleration amplitudes.
        out.clear();
        out.resize(7 * n, 0.0);
        let (bound, rest) = out.split_at_mut(n);
        let (q, rest) = rest.split_at_mut(n);
        let (shift0, rest) = rest.split_at_mut(n);
        let (shift1, scratch) = rest.split_at_mut(n);
        // About the static response to the plastic loads: the motion the propagator steps
        // (0 without yielding storeys).
        if !self.storeys.is_empty() {
            self.static_offsets(z0, shift0);
            self.static_offsets(z1, shift1);
        }
        let skipped = |b: usize| skip.is_some_and(|s| s[b]);
        let kept = (self.buildings.iter().enumerate())
            .filter(|(b, _)| !skipped(*b))
            .flat_map(|(_, b)| b.off..b.off + b.n());
        for k in kept {
            q[k] = (z0[k] - shift0[k]).abs().max((z1[k] - shift1[k]).abs());
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
            let qd = z0[n + k].abs().max(z1[n + k].abs());
            bound[k] = fourth_derivative_bound(&osc, q[k], qd, &s);
        }
        for (bi, b) in self.buildings.iter().enumerate() {
            if b.coupling_sums.is_empty() || skipped(bi) {
                continue;
            }
            let (o, nb) = (b.off, b.n());
            let q = &q[o..o + nb];
            self.coupled_mode_bounds(bi, seg, (z0, z1), q, None, scratch, &mut bound[o..o + nb]);
        }
        out.truncate(n);
    }

    /// Building `k`'s modes' bounds on `|q''''|` over the free step `z0 -> z1` of `seg` where
    /// its modes are coupled: by its damping (`coupling_sums`, where it has them) and, on a
    /// tangent step, by its stiffness (`stiffness`: each row's `sum_k |dS_ik|`). Each term of
    /// [`fourth_derivative_bound`]'s gains the couplings', at most each sum times the largest
    /// of the other modes' (from the ends; O(N) where the couplings times each would be
    /// O(N^2)). `q`: each mode's displacement amplitude about the static response the motion
    /// is free about; the bounds into `bound` (the building's modes from 0). `scratch` holds
    /// three of the building's vectors, the last each mode's bound on `|q'''|` on return.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn coupled_mode_bounds(
        &self,
        k: usize,
        seg: &Segment,
        (z0, z1): (&[f64], &[f64]),
        q: &[f64],
        stiffness: Option<&[f64]>,
        scratch: &mut [f64],
        bound: &mut [f64],
    ) {
        let b = &self.buildings[k];
        let (n, o, nb) = (self.n, b.off, b.n());
        let (v, rest) = scratch.split_at_mut(nb);
        let (a2, rest) = rest.split_at_mut(nb);
        let a3 = &mut rest[..nb];
        for (i, v) in v.iter_mut().enumerate() {
            *v = z0[n + o + i].abs().max(z1[n + o + i].abs());
        }
        let largest = |x: &[f64]| x.iter().fold(0.0, |m: f64, y| m.max(*y));
        // The couplings' terms, each after the mode's own (damping, then stiffness).
        let coupled = |i: usize, damped: f64, stiff: f64| -> f64 {
            let mut x = 0.0;
            if let Some(s) = b.coupling_sums.get(i) {
                x = s * damped;
            }
            match stiffness {
                Some(s) if b.coupling_sums.is_empty() => s[i] * stiff,
                Some(s) => x + s[i] * stiff,
                None => x,
            }
        };
        let (qm, vm) = (largest(q), largest(v));
        for i in 0..nb {
            let k = o + i;
            a2[i] = self.w2[k] * q[i]
                + self.two_xi_w[k] * v[i]
                + (self.part[k] * seg.a0)
                    .abs()
                    .max((self.part[k] * seg.a1).abs())
                + coupled(i, vm, qm);
        }
        let a2m = largest(a2);
        for i in 0..nb {
            let k = o + i;
            a3[i] = self.w2[k] * v[i]
                + self.two_xi_w[k] * a2[i]
                + (self.part[k] * (seg.a1 - seg.a0) / seg.dt).abs()
                + coupled(i, a2m, vm);
        }
        let a3m = largest(a3);
        for i in 0..nb {
            let k = o + i;
            bound[i] = self.w2[k] * a2[i] + self.two_xi_w[k] * a3[i] + coupled(i, a3m, a2m);
        }
    }
}
