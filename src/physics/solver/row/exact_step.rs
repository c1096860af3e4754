//! A building stepped exactly over a free step: one standing still (its modes, or its coupled
//! modes, over the whole step) and one whose damping couples its modes ([`CoupledStep`]).

use super::algebra::dot;
use super::model::RowModel;
use crate::physics::propagator::{CoupledPropagator, GAUSS5};
use crate::physics::solver::state::Segment;

/// Building `k` of `modal`, standing still since `seg.t0` (its modes at `z0`, the row's modal
/// state then), stepped exactly to `t` into `z`: `Propagator` over `t - seg.t0` about the static
/// response to its plastic loads (constant while it stands still), with the input and damping
/// work where `energy`.
pub(super) fn step_still(
    modal: &RowModel,
    k: usize,
    seg: &Segment,
    t: f64,
    z0: &[f64],
    z: &mut [f64],
    energy: bool,
) {
    let b = &modal.buildings[k];
    let n = modal.n;
    let h = t - seg.t0;
    let qs = b.first_storey.map(|_| {
        let mut qs = vec![0.0; n];
        modal.static_offsets(z0, &mut qs);
        qs
    });
    if let Some(mut c) = CoupledStep::new(modal, k, h, energy) {
        let mut work = vec![(0.0, 0.0); n];
        let ag = (seg.a0, seg.at(t));
        c.step(
            modal,
            z0,
            qs.as_deref(),
            ag,
            z,
            energy.then_some(&mut work[..]),
        );
        if energy {
            for (i, &w) in work.iter().enumerate().skip(b.off).take(b.n()) {
                modal.add_free_work(z, i, w);
            }
        }
        return;
    }
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
            modal.add_free_work(z, i, (agv, vv));
        }
    }
}

/// The exact free step of a building whose damping couples its modes (P-Delta with Rayleigh
/// damping on `K0`, storeys leaning unequally): [`CoupledPropagator`] over `h`, and where the
/// energy is kept, the input and damping work by 5-point Gauss-Legendre over the exact motion
/// (the propagator to each node; the integrands are smooth over a free step, so this is exact
/// to rounding where `h` is short beside the building's periods, as a record step is).
pub(crate) struct CoupledStep {
    k: usize,
    prop: CoupledPropagator,
    /// Per node: its fraction of the step, its weight (of `h`), the propagator to it.
    nodes: Vec<(f64, f64, CoupledPropagator)>,
    h: f64,
    /// Scratch: the modes' state `[q, q']` before and after.
    x0: Vec<f64>,
    x: Vec<f64>,
}

impl CoupledStep {
    /// The building it steps.
    pub fn building(&self) -> usize {
        self.k
    }

    /// Building `k` of `m` over `h`; None where its modes are not coupled.
    pub fn new(m: &RowModel, k: usize, h: f64, energy: bool) -> Option<CoupledStep> {
        let e = m.buildings[k].modes.coupling.as_ref()?;
        Some(Self::build(m, k, h, energy, e, None))
    }

    /// Building `k` of `m` over `h` with its modes' stiffness coupled by `stiffness` (its
    /// storeys on pieces off their initial stiffness, [`super::tangent`]), and by its damping
    /// where that couples them.
    pub fn tangent(
        m: &RowModel,
        k: usize,
        h: f64,
        energy: bool,
        stiffness: &[Vec<f64>],
    ) -> CoupledStep {
        let b = &m.buildings[k];
        let zero;
        let e = match b.modes.coupling.as_ref() {
            Some(e) => e,
            None => {
                zero = vec![vec![0.0; b.n()]; b.n()];
                &zero
            }
        };
        Self::build(m, k, h, energy, e, Some(stiffness))
    }

    fn build(
        m: &RowModel,
        k: usize,
        h: f64,
        energy: bool,
        e: &[Vec<f64>],
        stiffness: Option<&[Vec<f64>]>,
    ) -> CoupledStep {
        let b = &m.buildings[k];
        let r = b.off..b.off + b.n();
        let at = |x: f64| {
            CoupledPropagator::with_stiffness(
                &m.w2[r.clone()],
                stiffness,
                &m.two_xi_w[r.clone()],
                e,
                &m.part[r.clone()],
                x,
            )
        };
        let nodes = if energy {
            GAUSS5
                .iter()
                .map(|&(x, w)| {
                    let s = 0.5 * (1.0 + x);
                    (s, 0.5 * w, at(s * h))
                })
                .collect()
        } else {
            Vec::new()
        };
        CoupledStep {
            k,
            prop: at(h),
            nodes,
            h,
            x0: vec![0.0; 2 * b.n()],
            x: vec![0.0; 2 * b.n()],
        }
    }

    /// Step the building's modes of `z` (the row's modal state; `qs` the static response to
    /// the plastic loads, about which the motion is free) into `z1`, over `seg`'s ground
    /// from `ag.0` to `ag.1`; with the energy kept, each mode's input work `int L_i ag q_i'`
    /// and its share of the damping work over `2 xi_i w_i` into `work` (at the mode's index).
    pub fn step(
        &mut self,
        m: &RowModel,
        z: &[f64],
        qs: Option<&[f64]>,
        ag: (f64, f64),
        z1: &mut [f64],
        work: Option<&mut [(f64, f64)]>,
    ) {
        let (n, b) = (m.n, &m.buildings[self.k]);
        let (o, nb) = (b.off, b.n());
        let shift = |i: usize| qs.map_or(0.0, |q| q[o + i]);
        let (x0, x) = (&mut self.x0, &mut self.x);
        for i in 0..nb {
            x0[i] = z[o + i] - shift(i);
            x0[nb + i] = z[n + o + i];
        }
        self.prop.step(x0, ag.0, ag.1, x);
        for i in 0..nb {
            z1[o + i] = x[i] + shift(i);
            z1[n + o + i] = x[nb + i];
        }
        let Some(work) = work else { return };
        // A tangent step's modes may be coupled by their stiffness alone.
        let e = b.modes.coupling.as_ref();
        for w in work[o..o + nb].iter_mut() {
            *w = (0.0, 0.0);
        }
        for (s, weight, p) in &self.nodes {
            let a = ag.0 + (ag.1 - ag.0) * s;
            p.step(x0, ag.0, a, x);
            let v = &x[nb..];
            for i in 0..nb {
                let dv = m.two_xi_w[o + i] * v[i] + e.map_or(0.0, |e| dot(&e[i], v));
                let (agv, vv) = &mut work[o + i];
                *agv += weight * self.h * m.part[o + i] * a * v[i];
                *vv += weight * self.h * v[i] * dv / m.two_xi_w[o + i];
            }
        }
    }
}
