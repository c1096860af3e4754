//! What a row run reports: its time history to an observer ([`RowSample`]), the peaks tracked
//! between samples (floors, levels, closings), and the run's output at its end.

use super::exact_step::step_still;
use super::model::BuildingModel;
use super::run::RowRun;
use super::sample::{ImkSample, RowSample, StoreySample};
use super::storey::StoreyMode;
use crate::physics::model::{EnergyBalance, Status};
use crate::physics::row::{RowOutput, StoreyOutput};
use crate::physics::solver::hermite::{
    cubic_max_bound, hermite_range, raise_cubic_peak, raise_hump_peak, raise_quintic_peak,
};
use crate::physics::solver::state::{Mode, Segment};
use crate::physics::solver::tracker::raise_force_peak;

impl<'m> RowRun<'m> {
    /// Set the contact forces on each building's floors in state `z` into `floors[.][end]`.
    pub(super) fn set_floor_forces(&mut self, z: &[f64], end: usize) {
        let n = self.m.n;
        for f in self.floors.iter_mut() {
            f[end].force.fill(0.0);
        }
        for (lm, ls) in self.m.levels.iter().zip(&self.levels) {
            if ls.mode == Mode::Free {
                continue;
            }
            // On a floor its one share is 1: the whole force, to the bit.
            let fl = lm.force(n, ls.mode, ls.v0, z);
            for (f, w) in lm.sides[0].shares() {
                self.floors[lm.buildings.0][end].force[f] -= w * fl;
            }
            for (f, w) in lm.sides[1].shares() {
                self.floors[lm.buildings.1][end].force[f] += w * fl;
            }
        }
    }

    /// Raise the buildings' peaks over the piece `z0 -> z1` of length `h` (ground acceleration
    /// `ag0`, `ag1` at its ends). A building no contact acts on takes its displacement and
    /// drift peaks from the quintic Hermite (both ends' accelerations are exact) and its floor
    /// accelerations' from the cubic Hermite with their rates; one in contact takes the cubic
    /// Hermite of displacements and drifts, and its accelerations at the piece's ends (a
    /// contact force's spike is not smooth enough for the cubic).
    pub(super) fn track_buildings(&mut self, z0: &[f64], z1: &[f64], ag: (f64, f64), h: f64) {
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
    pub(super) fn floor_ends(&mut self, z0: &[f64], z1: &[f64], ag: (f64, f64)) {
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
        let ((a, b), [sa, sb]) = (lm.buildings, &lm.sides);
        let [a0, a1] = &self.floors[a];
        let [b0, b1] = &self.floors[b];
        [
            sa.at(&a0.u) - sb.at(&b0.u) - lm.gap,
            sa.at(&a0.v) - sb.at(&b0.v),
            sa.at(&a1.u) - sb.at(&b1.u) - lm.gap,
            sa.at(&a1.v) - sb.at(&b1.v),
        ]
    }

    /// Raise building `k`'s peaks over a piece of length `h` between its floor kinematics
    /// `floors[k]`: `free` when no contact acts on it.
    #[inline(always)]
    pub(super) fn raise_building(&mut self, k: usize, bm: &BuildingModel, h: f64, free: bool) {
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
                if let Some(dm) = &mut self.demands {
                    let peak = &mut dm[k].peak_drift_ratio[j];
                    *peak = raise(*peak, y, d, a);
                }
                if let Some(first) = bm.first_storey {
                    let st = &mut self.storeys[first + j];
                    st.peak_drift_ratio = raise(st.peak_drift_ratio, y, d, a);
                }
                // Floor j's acceleration peak over the piece, raised from `peak`.
                let raise_accel = |peak: f64| {
                    let (a0, a1) = (s0.a_abs[j], s1.a_abs[j]);
                    if free {
                        raise_cubic_peak(peak, a0, s0.jerk[j], a1, s1.jerk[j], h)
                    } else {
                        peak.max(a0.abs()).max(a1.abs())
                    }
                };
                let p = raise_accel(out.peak_accel);
                if p > out.peak_accel {
                    out.peak_accel = p;
                    out.accel_floor = j as u32 + 1;
                }
                if let Some(dm) = &mut self.demands {
                    let peak = &mut dm[k].peak_accel[j];
                    *peak = raise_accel(*peak);
                }
            }
        }
    }

    /// Account for a piece `t0 -> t0 + h` from `z0` to `z1` in the current modes.
    pub(super) fn track(&mut self, t0: f64, h: f64, z0: &[f64], z1: &[f64], ag: (f64, f64)) {
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
            let ((a, b), [sa, sb]) = (lm.buildings, &lm.sides);
            let accel =
                |e: usize| sa.at(&self.floors[a][e].a_rel) - sb.at(&self.floors[b][e].a_rel);
            let approaching = ls.mode == Mode::Approach;
            let f = lm.force(n, ls.mode, ls.v0, z1);
            let r1 = lm.contact.force_rate(y1, d1, accel(1), ls.v0, approaching);
            let start = || {
                let f0 = lm.force(n, ls.mode, ls.v0, z0);
                (
                    f0,
                    lm.contact.force_rate(y0, d0, accel(0), ls.v0, approaching),
                )
            };
            // The start's force and rate, where a struck column needs them too.
            let mut known = None;
            if lm.column.is_some() {
                let (f0, r0) = start();
                known = Some((f0, r0));
                let mut bound = f0.abs().max(f.abs());
                if r1 < 0.0 && r0 > 0.0 {
                    bound = bound.max(hermite_range(f0, r0, f, r1, h).1);
                }
                ls.column_load = ([f0, r0, f, r1], bound, y0 <= 0.0 || y1 <= 0.0);
            }
            ls.imp_peak = raise_force_peak(ls.imp_peak, f, r1, h, || known.unwrap_or_else(start));
        }
        if m.levels.iter().any(|lm| lm.column.is_some()) {
            self.track_columns(z0, z1, h);
        }
    }

    /// The struck columns' shear over a contact piece (physics.md section 11): for each level
    /// in contact on a column, its storey's spring force `V` with the shares of every contact
    /// force on that storey's columns at once (floors of both neighbours at several heights),
    /// on each column segment between the points: above all of them `V - sum s_i F_i`, and
    /// below point `k` `F_i` more for each point at or above it.
    fn track_columns(&mut self, z0: &[f64], z1: &[f64], h: f64) {
        let m = self.m;
        for (l, lm) in m.levels.iter().enumerate() {
            let Some(c) = &lm.column else { continue };
            if self.levels[l].mode == Mode::Free {
                continue;
            }
            let fl = &self.floors[c.building];
            let j = c.storey;
            let drift = |x: &[f64]| x[j] - if j > 0 { x[j - 1] } else { 0.0 };
            let spring = |e: usize, z: &[f64]| -> (f64, f64) {
                let (d, dv) = (drift(&fl[e].u), drift(&fl[e].v));
                match c.yielding {
                    Some(s) => {
                        let sm = &m.storeys[s];
                        let p = z[m.plastic_slot(s)];
                        let pv = match self.storey_modes[s] {
                            StoreyMode::Elastic => 0.0,
                            mode => sm.flow(mode) * dv,
                        };
                        (c.k * (d - p), c.k * (dv - pv))
                    }
                    None => (c.k * d, c.k * dv),
                }
            };
            let ((v0, vr0), (v1, vr1)) = (spring(0, z0), spring(1, z1));
            // The levels in contact on the same storey's columns, this one among them: each
            // force on the struck building with its share `s` on the floor above.
            let together = || {
                (m.levels.iter().zip(&self.levels)).filter_map(|(lk, sk)| {
                    let ck = lk.column.as_ref()?;
                    let same = ck.building == c.building && ck.storey == j;
                    (same && sk.mode != Mode::Free).then(|| {
                        let on_struck = if ck.side == 0 { -1.0 } else { 1.0 };
                        (ck.weight, on_struck, sk.column_load)
                    })
                })
            };
            let touches = together().any(|(_, _, (_, _, t))| t);
            // The segment above every point, then the one below each point.
            let mut peak = self.levels[l].out.column_shear;
            let cuts = std::iter::once(None).chain(together().map(|(s, _, _)| Some(s)));
            for cut in cuts {
                let (mut load, mut bound) = ([0.0; 4], 0.0);
                for (s, on_struck, (force, f_bound, _)) in together() {
                    let below = cut.is_some_and(|at| s >= at);
                    let share = on_struck * (if below { 1.0 - s } else { -s });
                    for (x, f) in load.iter_mut().zip(force) {
                        *x += share * f;
                    }
                    bound += share.abs() * f_bound;
                }
                peak = raise_column_peak(peak, [v0, vr0, v1, vr1], load, bound, touches, h);
            }
            self.levels[l].out.column_shear = peak;
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
                } else if self.gone[k] {
                    // Frozen where it collapsed, in its modes.
                    modal.floors(k, &self.z)
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
            // A level beside a building that left the scene is gone with it.
            penetrations: (m.levels.iter().enumerate())
                .map(|(l, lm)| {
                    let ((a, b), [sa, sb]) = (lm.buildings, &lm.sides);
                    if self.level_dead(l) {
                        0.0
                    } else {
                        (sa.at(&floors[a]) - sb.at(&floors[b]) - lm.gap).max(0.0)
                    }
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
                        imk: self.storeys[s].imk.map(|state| ImkSample {
                            drift_m: drift,
                            force_n: state.piece().force(drift),
                            branch: state.branch,
                        }),
                    }
                })
                .collect(),
            floors,
        };
        if let Some(obs) = self.observer.as_mut() {
            obs(&sample);
        }
    }

    /// End the run with `status`, after `substeps` steps of integration work.
    pub fn finish(mut self, status: Status, substeps: u64) -> RowOutput {
        self.leave_substeps();
        // A run in which a building collapsed and the rest went on to the end has collapsed.
        let status = match status {
            Status::Ok if self.collapse.is_some() => Status::Collapsed,
            s => s,
        };
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
        for (ls, lm) in self.levels.iter_mut().zip(&m.levels) {
            if ls.mode != Mode::Free {
                ls.end_impact();
            }
            if let Some(c) = lm.column {
                if let Some(s) = c.yielding {
                    // Against the struck columns' yield force, `alpha F_y`.
                    let sm = &m.storeys[s];
                    ls.out.column_shear_ratio = ls.out.column_shear / (c.share * (sm.k * sm.d_y));
                }
            }
        }
        // At rest a storey's drift is its plastic drift, but with P-Delta gravity leans on it:
        // the static response to the plastic loads, `d_s = p / (1 - theta)` in one storey.
        let leaning = m.storeys.iter().any(|sm| sm.geometric != 0.0).then(|| {
            let mut qs = vec![0.0; n];
            m.static_offsets(&self.z, &mut qs);
            qs
        });
        let residual = |s: usize, sm: &super::storey::StoreyModel| match &leaning {
            Some(qs) if sm.geometric != 0.0 => {
                let o = m.buildings[sm.building].off;
                super::algebra::dot(&sm.modal_row, &qs[o..]) / sm.height
            }
            _ => self.z[m.plastic_slot(s)] / sm.height,
        };
        // Each storey's outputs, which each yielding building gathers.
        let storeys: Vec<StoreyOutput> = m
            .storeys
            .iter()
            .zip(&self.storeys)
            .enumerate()
            .map(|(s, (sm, st))| StoreyOutput {
                residual_drift_ratio: residual(s, sm),
                peak_ductility: st.peak_drift_ratio * sm.height / sm.d_y,
                hysteretic_energy: self.z[m.plastic_slot(s) + ns],
                yielded: st.yielded,
                strength_ratio: match (&sm.imk, &st.imk) {
                    (Some(sp), Some(state)) => state.strength_ratio(sp),
                    _ => f64::NAN,
                },
                capped: st.imk.is_some_and(|state| state.capped),
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
            collapse: self.collapse,
            demands: self.demands.unwrap_or_default(),
            ..RowOutput::default()
        };
        if ns > 0 {
            // The buildings still standing have residual drifts where the run went on to the
            // end and settled; those that collapsed have none.
            let ended = matches!(status, Status::Ok | Status::Collapsed) && self.settled;
            let settled: Vec<bool> = self.gone.iter().map(|&g| ended && !g).collect();
            out.gather_storeys(&m.storey_spans(), &settled);
        }
        out.gather();
        out
    }
}

/// `peak` raised to the largest `|V + L|` over a contact piece of length `h`: a struck column
/// segment's shear, from the storey's spring force `V` and the contact forces' shares on the
/// segment `L = sum_i w_i F_i` (with their rates) at both ends, `spring = [V0, V0', V1, V1']`,
/// `load = [L0, L0', L1, L1']`. The ends, and where `|V + L|` humps inside, the cubic
/// Hermite's largest value, held within `max |V| + load_bound` (the cubic of `V`; `load_bound =
/// sum_i |w_i| max F_i`, each force's own peak as `tracker::raise_force_peak` takes it): the
/// force's rate grows without bound as the penetration nears 0 (the nonlinear viscoelastic
/// law's `delta^(1/4)` damping), where the cubic would overshoot. A piece that begins at a
/// touch or ends at a separation (`touches`) takes its ends alone.
pub(super) fn raise_column_peak(
    peak: f64,
    spring: [f64; 4],
    load: [f64; 4],
    load_bound: f64,
    touches: bool,
    h: f64,
) -> f64 {
    let [v0, vr0, v1, vr1] = spring;
    let [l0, lr0, l1, lr1] = load;
    let (y0, y1) = (v0 + l0, v1 + l1);
    let ends = peak.max(y0.abs()).max(y1.abs());
    if touches {
        return ends;
    }
    let hump = raise_hump_peak(ends, y0, vr0 + lr0, y1, vr1 + lr1, h);
    if hump <= ends {
        return ends;
    }
    let bound = raise_cubic_peak(0.0, v0, vr0, v1, vr1, h) + load_bound;
    ends.max(hump.min(bound))
}
