//! The right-hand side of a row's state: modal (or floor) accelerations under the ground motion,
//! the levels' contact forces and the yielding storeys' plastic loads, and the work rates.

use super::model::RowModel;
use super::storey::StoreyMode;
use crate::physics::solver::state::Mode;

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
                f.add_geometric_over_m(|j| u[j], acc);
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
                // Damping that couples the modes (P-Delta with Rayleigh damping on K0).
                if let Some(e) = &b.modes.coupling {
                    let v = &z[n + o..n + o + nb];
                    for (i, row) in e.iter().enumerate() {
                        let ev = super::algebra::dot(row, v);
                        out[n + o + i] -= ev;
                        if energy {
                            e_damp += v[i] * ev;
                        }
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
        let mode = motion.storeys[s];
        if mode != StoreyMode::Elastic {
            let dp = sm.flow(mode) * sm.drift(z, n);
            out[ps] = dp;
            out[ps + ns] = sm.k * (sm.drift(z, 0) - p) * dp;
        }
    }
}
