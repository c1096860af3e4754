//! A building's floor kinematics at an instant (displacements, velocities, relative and absolute
//! accelerations, jerks and contact forces), from its modal or floor state.

use super::algebra::dot;
use super::model::{BuildingModel, RowModel, FLOOR_SUBSTEPS_FROM};
use super::storey::StoreyMode;

/// Floor kinematics of one building at one instant: displacements, velocities, relative
/// accelerations and absolute accelerations (with contact forces), and, in free flight, the
/// absolute accelerations' rates.
#[derive(Debug, Clone, Default)]
pub(super) struct Floors {
    pub(super) u: Vec<f64>,
    pub(super) v: Vec<f64>,
    pub(super) a_rel: Vec<f64>,
    pub(super) a_abs: Vec<f64>,
    pub(super) jerk: Vec<f64>,
    /// The contact force on each floor (positive to the right).
    pub(super) force: Vec<f64>,
    /// Scratch: modal accelerations and jerks.
    pub(super) acc: Vec<f64>,
    pub(super) jrk: Vec<f64>,
    /// Scratch of a yielding building: its plastic loads' accelerations and their rates.
    pub(super) pl_acc: Vec<f64>,
    pub(super) pl_jerk: Vec<f64>,
    /// Scratch of a building whose damping couples its modes: `q''` with the ground's part.
    pub(super) qdd: Vec<f64>,
}

impl Floors {
    pub(super) fn new(nb: usize) -> Floors {
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
            pl_jerk: v.clone(),
            qdd: v,
        }
    }

    /// Building `k`'s plastic loads (`M^-1 D^T K p` and its rate) in state `z`, into `pl_acc`
    /// and `pl_jerk`: in its modes, or in its floors when `floors`.
    pub(super) fn plastic(
        &mut self,
        m: &RowModel,
        k: usize,
        z: &[f64],
        storeys: &[StoreyMode],
        floors: bool,
    ) {
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
    pub(super) fn fill(
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
            // With P-Delta the stiffness is `K - K_G`.
            f.add_geometric_over_m(|j| -u[j], &mut self.acc);
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
            f.add_geometric_over_m(|j| -v[j], &mut self.jrk);
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
        // Damping that couples the modes: `-E q'` in the accelerations, `-E q''` in the jerks.
        if let Some(e) = &b.modes.coupling {
            let v = &z[n + o..n + o + nb];
            for (i, row) in e.iter().enumerate() {
                let ev = dot(row, v);
                self.acc[i] -= ev;
                // The jerk's own damping term read the acceleration without it.
                self.jrk[i] += m.two_xi_w[o + i] * ev;
            }
            for k in 0..nb {
                self.qdd[k] = self.acc[k] - m.part[o + k] * ag;
            }
            for (i, row) in e.iter().enumerate() {
                self.jrk[i] -= dot(row, &self.qdd);
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
