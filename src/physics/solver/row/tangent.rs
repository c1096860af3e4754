//! The exact free step of a building whose deteriorating (IMK) storeys stand on pieces off
//! their initial stiffness: a deteriorated unloading line, a peak-oriented storey's line back
//! from its peak. On such a piece of slope `s` the storey's force is `f = k (d - p)` with `p' =
//! (1 - s/k) d'`, so `p - (1 - s/k) d` stays as it was and the building is linear: its modes
//! `q` see the stiffness `W^2 + dS`, `dS = sum_j (s_j - k_j) r_j r_j^T` (`r_j` storey `j`'s
//! modal row), under the constant load `G = sum_j r_j (k_j p_j - (k_j - s_j) d_j)` from the
//! step's start. The step is [`CoupledStep`] about the static response `(W^2 + dS)^-1 G`
//! (exact; a negative tangent gives hyperbolic motion, which the matrix exponential takes as
//! it comes), and each storey's plastic drift and work follow its drift along the piece in
//! closed form. A piece that runs one way only (`heading`: a reversal of the drift rate ends
//! it, a peak-oriented storey's line to its peak, the backbone) is held back where its rate may
//! turn inside the step ([`Tangent::may_reverse`]); a bilinear storey yielding on its bounding
//! line takes substeps as before, and so does a building whose tangent stiffness is singular.

use super::algebra::dot;
use super::exact_step::CoupledStep;
use super::model::RowModel;
use super::storey::{may_reach, StoreyMode};
use crate::physics::propagator::solve_dyn;
use crate::physics::solver::state::Segment;

/// How many sets of pieces' tangent steps a building keeps.
const KEPT_TANGENTS: usize = 4;

/// A run's tangent steps: each building's on the last few sets of pieces it stood on (the one
/// it stands on first: a peak-oriented storey goes back and forth between two lines).
pub(super) struct TangentSteps {
    /// Whether the run takes tangent steps (the CPU scheme with IMK storeys).
    enabled: bool,
    kept: Vec<Vec<Tangent>>,
    slopes: Vec<f64>,
    h: f64,
    energy: bool,
}

impl TangentSteps {
    pub fn new(m: &RowModel, enabled: bool, h: f64, energy: bool) -> TangentSteps {
        TangentSteps {
            enabled: enabled && m.storeys.iter().any(|sm| sm.imk.is_some()),
            kept: m.buildings.iter().map(|_| Vec::new()).collect(),
            slopes: Vec::new(),
            h,
            energy,
        }
    }

    /// Mark in `on` each building that takes its tangent step from modal state `z` (its
    /// storeys in `modes`, not `gone`; none unless `free`, the step's free motion taken), its
    /// step made ready; whether any.
    pub fn select(
        &mut self,
        m: &RowModel,
        (modes, gone): (&[StoreyMode], &[bool]),
        z: &[f64],
        free: bool,
        on: &mut [bool],
    ) -> bool {
        on.fill(false);
        if !(self.enabled && free) {
            return false;
        }
        let mut any = false;
        for (k, on) in on.iter_mut().enumerate() {
            if gone[k] || !Tangent::slopes(m, k, modes, &mut self.slopes) {
                continue;
            }
            let kept = &mut self.kept[k];
            match kept.iter().position(|t| t.is_for(&self.slopes)) {
                Some(i) => kept[..=i].rotate_right(1),
                None => match Tangent::new(m, k, &self.slopes, self.h, self.energy) {
                    Some(t) => {
                        kept.insert(0, t);
                        kept.truncate(KEPT_TANGENTS);
                    }
                    None => continue,
                },
            }
            kept[0].prepare(m, z);
            (*on, any) = (true, true);
        }
        any
    }

    /// The buildings `on` marks, in use.
    fn taken<'a>(&'a mut self, on: &'a [bool]) -> impl Iterator<Item = &'a mut Tangent> {
        (self.kept.iter_mut().filter_map(|k| k.first_mut())).filter(|t| on[t.building()])
    }

    /// Each marked building's exact step from `z` under the ground `ag` into `z1`, with each
    /// mode's input and damping work into `z1` where `work` is given (as the coupled steps).
    pub fn step(
        &mut self,
        m: &RowModel,
        on: &[bool],
        (z, ag): (&[f64], (f64, f64)),
        z1: &mut [f64],
        mut work: Option<&mut [(f64, f64)]>,
    ) {
        for t in self.taken(on) {
            t.step(m, z, ag, z1, work.as_deref_mut());
            if let Some(work) = work.as_deref() {
                let b = &m.buildings[t.building()];
                for (i, &w) in work.iter().enumerate().skip(b.off).take(b.n()) {
                    m.add_free_work(z1, i, w);
                }
            }
        }
    }

    /// Each mode's bound on `|q''''|` over the free step `z -> z1` of `seg`
    /// ([`RowModel::fourth_derivative_bounds`]), a marked building's from its tangent step
    /// (`on` None: none marked).
    pub fn bounds(
        &mut self,
        m: &RowModel,
        (seg, z, z1): (&Segment, &[f64], &[f64]),
        bounds: &mut Vec<f64>,
        on: Option<&[bool]>,
    ) {
        m.fourth_derivative_bounds(seg, (z, z1), bounds, on);
        if let Some(on) = on {
            for t in self.taken(on) {
                t.bounds(m, seg, z, z1, bounds);
            }
        }
    }

    /// Mark in `watch` each marked building (`on`, storeys in `modes`) whose storey heading one
    /// way may turn inside the free step `z -> z1` under `ag` ([`Tangent::may_reverse`]; after
    /// [`TangentSteps::bounds`] over it); whether any.
    pub fn may_reverse(
        &mut self,
        m: &RowModel,
        (on, modes): (&[bool], &[StoreyMode]),
        ag: (f64, f64),
        (z, z1): (&[f64], &[f64]),
        watch: &mut [bool],
    ) -> bool {
        let h = self.h;
        let mut any = false;
        for t in self.taken(on) {
            let k = t.building();
            if !watch[k] && t.may_reverse(m, modes, ag, (z, z1), h) {
                (watch[k], any) = (true, true);
            }
        }
        any
    }
}

/// One building's tangent step, kept while its storeys stay on pieces of the same slopes.
pub(super) struct Tangent {
    building: usize,
    /// Each of the building's storeys' slope, N/m (its initial stiffness on an elastic piece).
    slopes: Vec<f64>,
    /// `(W^2 + dS)^-1`, row-major: the static response to the constant load.
    inverse: Vec<f64>,
    /// `dS` row by row, and each row's `sum_k |dS_ik|` (for the derivative bounds).
    coupling: Vec<Vec<f64>>,
    sums: Vec<f64>,
    /// Each of the building's modes' bound on `|q'''''|` over the step, from
    /// [`Tangent::bounds`] (for the reversal checks).
    fifth: Vec<f64>,
    step: CoupledStep,
    /// The static response this step is taken about, in the row's modes (0 outside the
    /// building's).
    offset: Vec<f64>,
    /// Room for four of the building's modal vectors (no allocation per step).
    scratch: Vec<f64>,
}

impl Tangent {
    /// Building `k`'s storeys' slopes under `modes` into `out`; false where it takes no
    /// tangent step: a bilinear storey that yields, or every storey on its initial stiffness
    /// and none heading one way (the modal step is exact then).
    pub fn slopes(m: &RowModel, k: usize, modes: &[StoreyMode], out: &mut Vec<f64>) -> bool {
        out.clear();
        let b = &m.buildings[k];
        let Some(first) = b.first_storey else {
            return false;
        };
        let mut off = false;
        for (sm, mode) in m.storeys[first..first + b.n()]
            .iter()
            .zip(&modes[first..first + b.n()])
        {
            let s = match mode {
                StoreyMode::Elastic => sm.k,
                StoreyMode::Yielding(_) => return false,
                StoreyMode::Imk(piece) => {
                    off |= piece.heading != 0.0;
                    piece.slope
                }
            };
            off |= s != sm.k;
            out.push(s);
        }
        off
    }

    /// The step of building `k` of `m` over `h` on storeys of `slopes`; None where its
    /// tangent stiffness is singular (to rounding).
    pub fn new(m: &RowModel, k: usize, slopes: &[f64], h: f64, energy: bool) -> Option<Tangent> {
        let b = &m.buildings[k];
        let (o, nb) = (b.off, b.n());
        let first = b.first_storey.expect("a building with storeys");
        let mut coupling = vec![vec![0.0; nb]; nb];
        for (sm, s) in m.storeys[first..first + nb].iter().zip(slopes) {
            let ds = s - sm.k;
            if ds == 0.0 {
                continue;
            }
            for (i, row) in coupling.iter_mut().enumerate() {
                for (c, r) in row.iter_mut().zip(&sm.modal_row) {
                    *c += ds * sm.modal_row[i] * r;
                }
            }
        }
        let mut stiffness: Vec<f64> = coupling.iter().flatten().copied().collect();
        for i in 0..nb {
            stiffness[i * nb + i] += m.w2[o + i];
        }
        let scale = m.w2[o..o + nb].iter().fold(0.0, |a: f64, w| a.max(*w));
        let eye = (0..nb * nb)
            .map(|i| if i.is_multiple_of(nb + 1) { 1.0 } else { 0.0 })
            .collect();
        let inverse = solve_dyn(stiffness, eye, nb, 1e-12 * scale)?;
        let sums = coupling
            .iter()
            .map(|row| row.iter().map(|c| c.abs()).sum())
            .collect();
        Some(Tangent {
            building: k,
            slopes: slopes.to_vec(),
            inverse,
            step: CoupledStep::tangent(m, k, h, energy, &coupling),
            coupling,
            sums,
            fifth: vec![0.0; nb],
            offset: vec![0.0; m.n],
            scratch: vec![0.0; 4 * nb],
        })
    }

    pub fn building(&self) -> usize {
        self.building
    }

    /// Was it built for these slopes?
    pub fn is_for(&self, slopes: &[f64]) -> bool {
        self.slopes == slopes
    }

    /// The static response about which the building moves from modal state `z`, set for
    /// [`Tangent::step`] and [`Tangent::bounds`].
    pub fn prepare(&mut self, m: &RowModel, z: &[f64]) {
        let b = &m.buildings[self.building];
        let (o, nb, first) = (b.off, b.n(), b.first_storey.expect("storeys"));
        let load = &mut self.scratch[..nb];
        load.fill(0.0);
        for (s, (sm, slope)) in m.storeys[first..first + nb]
            .iter()
            .zip(&self.slopes)
            .enumerate()
        {
            let p = z[m.plastic_slot(first + s)];
            let d = sm.drift(z, 0);
            let g = sm.k * p - (sm.k - slope) * d;
            for (l, r) in load.iter_mut().zip(&sm.modal_row) {
                *l += r * g;
            }
        }
        for (i, q) in self.offset[o..o + nb].iter_mut().enumerate() {
            *q = (0..nb).map(|j| self.inverse[i * nb + j] * load[j]).sum();
        }
    }

    /// The exact free step from modal state `z` over `ag` into `z1`: the building's modes, its
    /// storeys' plastic drifts and plastic work; with `work`, each mode's input and damping
    /// work as [`CoupledStep::step`] gives them (the caller adds them).
    pub fn step(
        &mut self,
        m: &RowModel,
        z: &[f64],
        ag: (f64, f64),
        z1: &mut [f64],
        work: Option<&mut [(f64, f64)]>,
    ) {
        let b = &m.buildings[self.building];
        let nb = b.n();
        self.step.step(m, z, Some(&self.offset), ag, z1, work);
        let ns = m.storeys.len();
        let first = b.first_storey.expect("storeys");
        for (s, slope) in (first..first + nb).zip(&self.slopes) {
            let sm = &m.storeys[s];
            let slot = m.plastic_slot(s);
            let flow = 1.0 - slope / sm.k;
            if flow == 0.0 {
                continue;
            }
            let (d0, d1) = (sm.drift(z, 0), sm.drift(z1, 0));
            let (p0, p1) = (z[slot], z[slot] + flow * (d1 - d0));
            // The force is linear in the drift along the piece: the work `int f dp` is
            // `flow` times the trapezoid of `f` over the drift.
            let (f0, f1) = (sm.k * (d0 - p0), sm.k * (d1 - p1));
            z1[slot] = p1;
            z1[slot + ns] = z[slot + ns] + flow * 0.5 * (f0 + f1) * (d1 - d0);
        }
    }

    /// Each of the building's modes' bound on `|q''''|` over the free step `z -> z1` into
    /// `bounds` (as [`RowModel::fourth_derivative_bounds`] builds them, with the stiffness
    /// coupling's terms: `sum_k |dS_ik|` times the largest of the other modes').
    pub fn bounds(
        &mut self,
        m: &RowModel,
        seg: &Segment,
        z: &[f64],
        z1: &[f64],
        bounds: &mut [f64],
    ) {
        let b = &m.buildings[self.building];
        let (o, nb) = (b.off, b.n());
        let largest = |x: &[f64]| x.iter().fold(0.0, |a: f64, y| a.max(*y));
        let (q, rest) = self.scratch.split_at_mut(nb);
        for (i, q) in q.iter_mut().enumerate() {
            let k = o + i;
            *q = (z[k] - self.offset[k])
                .abs()
                .max((z1[k] - self.offset[k]).abs());
        }
        let bound = &mut bounds[o..o + nb];
        m.coupled_mode_bounds(
            self.building,
            seg,
            (z, z1),
            q,
            Some(&self.sums),
            rest,
            bound,
        );
        // `q''''' = -(W^2 + dS) q''' - C q''''` (the ground is linear over the step).
        let a3 = &rest[2 * nb..3 * nb];
        let (a3m, a4m) = (largest(a3), largest(bound));
        let damping = |i: usize| b.coupling_sums.get(i).copied().unwrap_or(0.0);
        for (i, (fifth, a3)) in self.fifth.iter_mut().zip(a3).enumerate() {
            let k = o + i;
            *fifth =
                m.w2[k] * a3 + self.sums[i] * a3m + m.two_xi_w[k] * bound[i] + damping(i) * a4m;
        }
    }

    /// Could a storey on a piece with a heading see its drift rate turn against it inside the
    /// free step `z -> z1` (after [`Tangent::bounds`] over it)? As a band edge in `may_yield`:
    /// the edge `-heading d'` with its rate `-heading d''` at both ends, and the bound on
    /// `|d'''''|` from each mode's.
    pub fn may_reverse(
        &mut self,
        m: &RowModel,
        modes: &[StoreyMode],
        (ag0, ag1): (f64, f64),
        (z, z1): (&[f64], &[f64]),
        h: f64,
    ) -> bool {
        let b = &m.buildings[self.building];
        let (n, nb, first) = (m.n, b.n(), b.first_storey.expect("storeys"));
        let mut accels = false;
        for (sm, mode) in m.storeys[first..first + nb]
            .iter()
            .zip(&modes[first..first + nb])
        {
            let StoreyMode::Imk(piece) = *mode else {
                continue;
            };
            if piece.heading == 0.0 {
                continue;
            }
            if !accels {
                self.accel(m, z, ag0, 0);
                self.accel(m, z1, ag1, 1);
                accels = true;
            }
            let (a0, a1) = (&self.scratch[..nb], &self.scratch[nb..2 * nb]);
            let edge = |z: &[f64], a: &[f64]| {
                let e = (
                    -piece.heading * sm.drift(z, n),
                    -piece.heading * dot(&sm.modal_row, a),
                );
                [e, e]
            };
            let bound: f64 = (sm.modal_row.iter().zip(&self.fifth))
                .map(|(r, f)| r.abs() * f)
                .sum();
            if may_reach(edge(z, a0), edge(z1, a1), bound, h) {
                return true;
            }
        }
        false
    }

    /// The building's modal accelerations in modal state `z` under ground acceleration `ag`,
    /// into the scratch's vector `at` (0 or 1; its last holds the displacements about the
    /// static response).
    fn accel(&mut self, m: &RowModel, z: &[f64], ag: f64, at: usize) {
        let b = &m.buildings[self.building];
        let (n, o, nb) = (m.n, b.off, b.n());
        let (out, x) = self.scratch.split_at_mut(3 * nb);
        let (out, x) = (&mut out[at * nb..(at + 1) * nb], &mut x[..nb]);
        for (i, x) in x.iter_mut().enumerate() {
            *x = z[o + i] - self.offset[o + i];
        }
        let v = &z[n + o..n + o + nb];
        for (i, a) in out.iter_mut().enumerate() {
            let k = o + i;
            let damping = b.modes.coupling.as_ref().map_or(0.0, |e| dot(&e[i], v));
            *a = -m.w2[k] * x[i]
                - dot(&self.coupling[i], x)
                - m.two_xi_w[k] * v[i]
                - damping
                - m.part[k] * ag;
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::physics::propagator::solve_dyn;

    /// The solve the tangent steps invert their stiffness with: the inverse to rounding, and
    /// None for a singular matrix.
    #[test]
    fn the_solve_inverts_and_refuses_a_singular_matrix() {
        let a = [4.0, 1.0, 2.0, 0.5, -3.0, 1.0, 2.0, 1.0, 5.0];
        let eye = |n: usize| {
            (0..n * n)
                .map(|i| if i.is_multiple_of(n + 1) { 1.0 } else { 0.0 })
                .collect()
        };
        let inv = solve_dyn(a.to_vec(), eye(3), 3, 1e-12).unwrap();
        for i in 0..3 {
            for j in 0..3 {
                let x: f64 = (0..3).map(|k| a[i * 3 + k] * inv[k * 3 + j]).sum();
                assert!((x - if i == j { 1.0 } else { 0.0 }).abs() < 1e-14);
            }
        }
        assert!(solve_dyn(vec![1.0, 2.0, 2.0, 4.0], eye(2), 2, 1e-12).is_none());
    }
}
