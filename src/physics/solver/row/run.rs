//! One run of a row being integrated ([`RowRun`]), shared by both schemes: its state, the
//! buildings that move and those that stand still (stepped exactly), the fast scheme's substep
//! model, and free record steps.

use super::exact_step::step_still;
use super::floors::Floors;
use super::levels::{LevelState, StoreyState};
use super::model::{LevelModel, RowModel};
use super::sample::RowObserver;
use super::storey::StoreyMode;
use crate::physics::imk::ImkState;
use crate::physics::row::{BuildingDemands, BuildingOutput, Collapse, LevelClosing};
use crate::physics::solver::hermite::{quintic_max_bound, quintic_range, raise_quintic_peak};
use crate::physics::solver::state::{Mode, Segment};

/// One run of a row being integrated, shared by both schemes (as the pair's `Integration`).
pub(crate) struct RowRun<'m> {
    /// The model the state is in: `modal`, or its substep model between
    /// [`RowRun::enter_substeps`] and [`RowRun::leave_substeps`].
    pub m: &'m RowModel,
    pub(super) modal: &'m RowModel,
    pub z: Vec<f64>,
    pub levels: Vec<LevelState>,
    pub buildings: Vec<BuildingOutput>,
    pub free_steps: u64,
    /// Report the energy balance.
    pub energy: bool,
    pub(super) e_initial: f64,
    pub(super) e_peak: f64,
    /// Each building's floor kinematics at the start and end of the last tracked piece;
    /// `ends_valid`: the ends describe `z` in the levels' current modes, so the next piece
    /// starts from them instead of computing them again. Boxed: a piece's ends swap by two
    /// pointers, where the structs' eleven vectors took 3 % of a 3 + 6 storey row's CPU time.
    pub(super) floors: Vec<[Box<Floors>; 2]>,
    pub(super) ends_valid: bool,
    /// The floors hold a prepared free step's ends ([`RowRun::prepare_free_ends`]), and
    /// `ends_valid` before it.
    pub(super) ends_ready: bool,
    pub(super) valid_before: bool,
    pub(super) touched: Vec<bool>,
    /// The buildings that move in the current substeps (all, outside the fast scheme's
    /// contact steps), and the levels between two of them: only those are integrated, checked
    /// for events and tracked ([`RowRun::set_active`]).
    pub active: Vec<bool>,
    pub(super) level_on: Vec<bool>,
    /// Each yielding storey's spring state, and its record.
    pub storey_modes: Vec<StoreyMode>,
    pub(super) storeys: Vec<StoreyState>,
    /// No storey can yield again after the run's end (set by the scheme,
    /// [`RowModel::settled`]): the plastic drifts are the residual drifts.
    pub settled: bool,
    /// Per event (levels, then storeys), whether it fires in the step being located.
    pub(super) firing: Vec<bool>,
    /// Per storey, which of an IMK piece's event parts fire in the trial end (bits 0-2 of
    /// [`crate::physics::imk::Piece::event_parts`]); 0 for the other modes.
    pub(super) firing_parts: Vec<u8>,
    /// Whether an IMK storey's event is located on its parts that fire (the CPU scheme) or on
    /// their maximum (the GPU row kernel's twin).
    pub(super) firing_by_parts: bool,
    /// Per level, its floors' closing and peaks, where asked for ([`RowRun::track_closings`]).
    pub(super) closings: Option<Vec<LevelClosing>>,
    /// Hears every accepted step and event ([`RowRun::emit`]).
    pub observer: Option<RowObserver<'m>>,
    /// Per building, whether its storeys' collapse events are checked: from the time its peak
    /// drift ratio reaches [`COLLAPSE_WATCH`] of the limit (every building in the reference
    /// scheme, [`RowRun::watch_all`]).
    pub(super) watch: Vec<bool>,
    /// The run's first collapse ([`RowOutput::collapse`]); each building's is in its output.
    pub collapse: Option<Collapse>,
    /// Per building, whether it has collapsed and left the scene (physics.md section 12): it
    /// stands frozen as it was at its collapse (no further work, its peaks kept), never moves
    /// again in substeps or free steps, and its levels are dead (no contact, no check).
    pub(super) gone: Vec<bool>,
    /// Each storey's and floor's peaks, where the model asks for them
    /// ([`RowModel::track_demands`]).
    pub(super) demands: Option<Vec<BuildingDemands>>,
}

/// A building's storeys are watched for collapse once its peak drift ratio reaches this share
/// of the limit: from there to the limit within one record step would take a drift velocity of
/// metres per second per storey, and below it the collapse events cost nothing.
pub(crate) const COLLAPSE_WATCH: f64 = 0.5;

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
                .map(|b| [Box::new(Floors::new(b.n())), Box::new(Floors::new(b.n()))])
                .collect(),
            ends_valid: false,
            ends_ready: false,
            valid_before: false,
            touched: vec![false; m.buildings.len()],
            active: vec![true; m.buildings.len()],
            level_on: vec![true; m.levels.len()],
            storey_modes: (m.storeys.iter())
                .map(|sm| match &sm.imk {
                    Some(sp) => StoreyMode::Imk(*ImkState::new(sp).piece()),
                    None => StoreyMode::Elastic,
                })
                .collect(),
            storeys: (m.storeys.iter())
                .map(|sm| StoreyState {
                    imk: sm.imk.as_ref().map(ImkState::new),
                    ..StoreyState::default()
                })
                .collect(),
            settled: false,
            firing: Vec::with_capacity(m.levels.len() + m.storeys.len()),
            firing_parts: vec![0; m.storeys.len()],
            firing_by_parts: false,
            closings: None,
            observer: None,
            watch: vec![false; m.buildings.len()],
            collapse: None,
            gone: vec![false; m.buildings.len()],
            demands: m.track_demands.then(|| {
                (m.buildings.iter())
                    .map(|b| BuildingDemands {
                        peak_drift_ratio: vec![0.0; b.n()],
                        peak_accel: vec![0.0; b.n()],
                    })
                    .collect()
            }),
            z,
        };
        let z = run.z.clone();
        run.transitions(t0, &z, &z);
        if !m.storeys.is_empty() {
            run.storey_transitions();
        }
        run
    }

    /// Check every building's storeys for collapse at every step (the reference scheme).
    pub fn watch_all(&mut self) {
        if self.m.collapse_limit.is_finite() {
            self.watch.fill(true);
        }
    }

    /// Watch the buildings still standing whose peak drift ratio has reached
    /// [`COLLAPSE_WATCH`] of the limit; whether any is watched.
    pub fn refresh_watch(&mut self) -> bool {
        let limit = COLLAPSE_WATCH * self.m.collapse_limit;
        for ((w, b), &gone) in self.watch.iter_mut().zip(&self.buildings).zip(&self.gone) {
            *w = !gone && (*w || b.peak_drift_ratio >= limit);
        }
        self.watch.iter().any(|&w| w)
    }

    /// Watch each moving building not yet watched one of whose storeys' drift in `z` (the
    /// end of a step about to be taken, whose floors [`RowRun::prepare_free_ends`] may hold)
    /// reaches [`COLLAPSE_WATCH`] of the limit; whether any
    /// was added. The peaks only say where a building has been: one whose drift runs from
    /// below half the limit past it within a step (a P-Delta storey running away) would
    /// otherwise cross unwatched, its collapse not located.
    pub(super) fn watch_reached(&mut self, z: &[f64]) -> bool {
        let limit = COLLAPSE_WATCH * self.m.collapse_limit;
        let mut added = false;
        for d in &self.m.drifts {
            let k = d.building;
            if self.watch[k] || !self.active[k] {
                continue;
            }
            // From the floors where a prepared free step holds them (O(1), not O(N)).
            let drift = if self.ends_ready {
                let u = &self.floors[k][1].u;
                u[d.storey] - if d.storey > 0 { u[d.storey - 1] } else { 0.0 }
            } else {
                d.drift(z, 0)
            };
            if drift.abs() >= limit * d.height {
                self.watch[k] = true;
                added = true;
            }
        }
        added
    }

    /// Has every building left the scene? Nothing moves any more: the run can end.
    pub fn all_gone(&self) -> bool {
        self.gone.iter().all(|&g| g)
    }

    /// Whether level `l` joins a building that has left the scene (no contact, no check).
    pub fn level_dead(&self, l: usize) -> bool {
        let (a, b) = self.m.levels[l].buildings;
        self.gone[a] || self.gone[b]
    }

    /// Building `k` collapses at `t` in storey `storey` (from 0) and leaves the scene: its
    /// peaks are those over `[0, t]`, the collapsing storey's drift ratio the limit (the
    /// crossing is located to the event tolerance; the limit is where it is), its contacts end
    /// there, and it moves no more. The run's first collapse is the earliest building's.
    pub(super) fn leave_scene(&mut self, k: usize, t: f64, storey: usize) {
        if self.gone[k] {
            return;
        }
        let cl = Collapse {
            time: t,
            building: k as u32 + 1,
            storey: storey as u32 + 1,
        };
        let limit = self.m.collapse_limit;
        let b = &mut self.buildings[k];
        b.collapse = Some(cl);
        (b.peak_drift_ratio, b.drift_storey) = (limit, cl.storey);
        if let Some(d) = &mut self.demands {
            d[k].peak_drift_ratio[storey] = limit;
        }
        if let Some(first) = self.m.buildings[k].first_storey {
            self.storeys[first + storey].peak_drift_ratio = limit;
        }
        if self.collapse.is_none_or(|c| t < c.time) {
            self.collapse = Some(cl);
        }
        // Back to its modes (the coordinates it stands in from here on) if it was in the
        // substeps' floor coordinates.
        if !std::ptr::eq(self.m, self.modal) && self.active[k] {
            self.m.building_to_modes(k, &mut self.z);
        }
        self.gone[k] = true;
        self.watch[k] = false;
        for (ls, lm) in self.levels.iter_mut().zip(&self.m.levels) {
            let (a, b) = lm.buildings;
            if (a == k || b == k) && ls.mode != Mode::Free {
                ls.end_impact();
                ls.mode = Mode::Free;
            }
        }
        // The contact forces and storey states at the last piece's end change.
        self.ends_valid = false;
        self.active[k] = false;
        self.refresh_levels_on();
    }

    /// A building whose tracked peaks reached the limit inside a step without a located event
    /// (a crossing between the step's ends that no watch saw) collapses at the step's end
    /// `t`: a last guard, which [`RowRun::watch_reached`] keeps from firing.
    pub(super) fn collapse_by_peaks(&mut self, t: f64) {
        let limit = self.m.collapse_limit;
        for k in 0..self.buildings.len() {
            let b = &self.buildings[k];
            if !self.gone[k] && b.peak_drift_ratio >= limit {
                let storey = b.drift_storey.max(1) as usize - 1;
                self.leave_scene(k, t, storey);
            }
        }
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
    pub(super) fn raise_closings(&mut self, t0: f64, h: f64) {
        let Some(closings) = self.closings.as_mut() else {
            return;
        };
        for (c, lm) in closings.iter_mut().zip(&self.m.levels) {
            let ((a, b), [sa, sb]) = (lm.buildings, &lm.sides);
            // A level's closing is known up to the first collapse of its two buildings.
            if self.gone[a] || self.gone[b] {
                continue;
            }
            let ([a0, a1], [b0, b1]) = (&self.floors[a], &self.floors[b]);
            let (ua, va, aa) = (
                [sa.at(&a0.u), sa.at(&a1.u)],
                [sa.at(&a0.v), sa.at(&a1.v)],
                [sa.at(&a0.a_rel), sa.at(&a1.a_rel)],
            );
            let (ub, vb, ab) = (
                [sb.at(&b0.u), sb.at(&b1.u)],
                [sb.at(&b0.v), sb.at(&b1.v)],
                [sb.at(&b0.a_rel), sb.at(&b1.a_rel)],
            );
            let y = [ua[0] - ub[0], ua[1] - ub[1]];
            let d = [va[0] - vb[0], va[1] - vb[1]];
            let acc = [aa[0] - ab[0], aa[1] - ab[1]];
            if quintic_max_bound(y, d, acc, h) > c.closing {
                let (hi, s) = quintic_range(y, d, acc, h)[1];
                if hi > c.closing {
                    (c.closing, c.time) = (hi, Some(t0 + s * h));
                }
            }
            c.peak_left = raise_quintic_peak(c.peak_left, ua, va, aa, h);
            c.peak_right = raise_quintic_peak(c.peak_right, ub, vb, ab, h);
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
        for ((a, &b), &gone) in self.active.iter_mut().zip(active).zip(&self.gone) {
            *a = b && !gone;
        }
        self.refresh_levels_on();
    }

    /// A level is checked when both its buildings move.
    pub(super) fn refresh_levels_on(&mut self) {
        for (on, lm) in self.level_on.iter_mut().zip(&self.m.levels) {
            *on = self.active[lm.buildings.0] && self.active[lm.buildings.1];
        }
    }

    /// Whether level `l` is checked: both its buildings move.
    pub fn level_on(&self, l: usize) -> bool {
        self.level_on[l]
    }

    /// Every building still standing moves again (after a record step with some standing
    /// still).
    pub fn all_active(&mut self) {
        for (a, &gone) in self.active.iter_mut().zip(&self.gone) {
            *a = !gone;
        }
        self.refresh_levels_on();
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
            if self.active[k] || self.gone[k] {
                continue;
            }
            let b = &modal.buildings[k];
            for i in b.off..b.off + b.n() {
                self.z[i] = z1[i];
                self.z[n + i] = z1[n + i];
                if let Some(&w) = work.get(i) {
                    modal.add_free_work(&mut self.z, i, w);
                }
            }
            self.track_still(k, z0, z1, (seg.a0, seg.a1), seg.dt);
        }
        self.e_peak = self.e_peak.max(self.e_initial + self.z[2 * n + nl]);
        self.all_active();
    }

    /// Raise building `k`'s peaks over a free piece of length `h` from `z0` to `z1` (modal
    /// states; no contact acts on it), leaving its floor kinematics at `z1` as the piece's end.
    pub(super) fn track_still(&mut self, k: usize, z0: &[f64], z1: &[f64], ag: (f64, f64), h: f64) {
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
    pub(super) fn levels_in(&self, mode: Mode) -> impl Iterator<Item = (&LevelModel, &LevelState)> {
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

    /// Is some bilinear storey of a building still standing on a bounding line? (An IMK
    /// storey's pieces are judged by [`RowModel::settled`].)
    pub fn any_yielding(&self) -> bool {
        (self.storey_modes.iter().zip(&self.m.storeys)).any(|(m, sm)| {
            let one_way = match m {
                StoreyMode::Elastic => false,
                StoreyMode::Yielding(_) => true,
                StoreyMode::Imk(_) => false,
            };
            one_way && !self.gone[sm.building]
        })
    }

    /// `z` with the buildings that left the scene at rest: what the settling check reads (a
    /// frozen building's motion is not the row's any more).
    pub(super) fn standing_state(&self, z: &[f64]) -> Option<Vec<f64>> {
        if !self.gone.iter().any(|&g| g) {
            return None;
        }
        let m = self.modal;
        let mut live = z.to_vec();
        for (k, b) in m
            .buildings
            .iter()
            .enumerate()
            .filter(|(k, _)| self.gone[*k])
        {
            for i in b.off..b.off + b.n() {
                (live[i], live[m.n + i]) = (0.0, 0.0);
            }
            for (s, sm) in m.storeys.iter().enumerate() {
                if sm.building == k {
                    live[m.plastic_slot(s)] = 0.0;
                }
            }
        }
        Some(live)
    }

    /// The storeys' modes with those of the buildings that left the scene elastic, as
    /// [`RowRun::standing_state`] leaves them at rest with no plastic drift: a collapsed
    /// building's storeys, frozen on whatever piece they were, do not hold its neighbours'
    /// settling back.
    pub(super) fn standing_modes(&self) -> Vec<StoreyMode> {
        (self.storey_modes.iter().zip(&self.modal.storeys))
            .map(|(&mode, sm)| {
                if self.gone[sm.building] {
                    StoreyMode::Elastic
                } else {
                    mode
                }
            })
            .collect()
    }

    /// A free record step over `seg` to `z1`, with no possible contact (checked by the caller);
    /// `z1` is left holding the step's start.
    pub fn free_step(&mut self, seg: &Segment, z1: &mut Vec<f64>) {
        // The state and the step's end trade buffers: `z1` gets the start (for the caller to
        // reuse), no allocation.
        let end = std::mem::take(z1);
        let z0 = std::mem::take(&mut self.z);
        self.track(seg.t0, seg.dt, &z0, &end, (seg.a0, seg.a1));
        self.free_steps += 1;
        self.z = end;
        *z1 = z0;
        self.collapse_by_peaks(seg.t1());
        self.emit(seg, seg.t1());
    }
}
