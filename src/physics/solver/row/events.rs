//! A row run's events: each level's contact mode and each yielding storey's spring state
//! ending, located within a step, and the transitions they call for; the acceptance of a step.

use super::run::RowRun;
use super::storey::{band_edges, may_reach, StoreyMode};
use crate::physics::solver::events::{hidden_rise, locate, touch};
use crate::physics::solver::state::{Mode, Segment};

impl<'m> RowRun<'m> {
    /// Each event's value in state `z`, levels then storeys (positive once that level's contact
    /// mode or storey's spring state must end); `-inf` where it is not checked (a level whose
    /// buildings do not both move, a storey of a building standing still).
    pub(super) fn event_values<'a>(
        &'a self,
        z: &'a [f64],
    ) -> impl Iterator<Item = f64> + use<'a, 'm> {
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
        // A watched storey's collapse: its drift past the limit.
        let limit = self.m.collapse_limit;
        let drifts = self.m.drifts.iter().map(move |d| {
            if self.watch[d.building] && self.active[d.building] {
                d.drift(z, 0).abs() - limit * d.height
            } else {
                f64::NEG_INFINITY
            }
        });
        levels.chain(storeys).chain(drifts)
    }

    /// The watched buildings (near collapse) with a storey that may reach the collapse limit
    /// inside the exact free step `z -> z1` of length `h` (modal states, each mode's `|q''''|`
    /// bound in `bounds`), marked in `out` (the others left as they are); whether any. Its
    /// drift's edges `[d - D, -d - D]`, `D` the limit's drift, as a storey's band edges in
    /// `may_yield`: a building that passed half the limit moves in substeps only while the
    /// limit is within reach, not for the rest of the run.
    pub(super) fn collapse_watch(
        &self,
        (z, z1): (&[f64], &[f64]),
        bounds: &[f64],
        h: f64,
        out: &mut [bool],
    ) -> bool {
        let limit = self.m.collapse_limit;
        let mut any = false;
        for d in &self.m.drifts {
            let k = d.building;
            if !self.watch[k] || out[k] {
                any |= out[k];
                continue;
            }
            let ([d0, r0, d1, r1], bound) =
                self.m.drift_over_step(k, &d.modal_row, (z, z1), bounds);
            let top = limit * d.height;
            if may_reach(band_edges(d0, r0, top), band_edges(d1, r1, top), bound, h) {
                out[k] = true;
                any = true;
            }
        }
        any
    }

    /// The largest collapse event value in `z` of the watched moving buildings' storeys
    /// (positive once a drift is past the limit; `-inf` where none is watched).
    fn collapse_max(&self, z: &[f64]) -> f64 {
        let limit = self.m.collapse_limit;
        (self.m.drifts.iter())
            .filter(|d| self.watch[d.building] && self.active[d.building])
            .map(|d| d.drift(z, 0).abs() - limit * d.height)
            .fold(f64::NEG_INFINITY, f64::max)
    }

    /// The collapses at a located event's state `zb`: each watched moving building with a
    /// storey past the limit there (to leave the scene), with its storey furthest past it.
    fn collapses_at(&self, zb: &[f64]) -> Vec<(usize, usize)> {
        let limit = self.m.collapse_limit;
        let mut best: Vec<Option<(f64, usize)>> = vec![None; self.m.buildings.len()];
        for d in &self.m.drifts {
            if !self.watch[d.building] || !self.active[d.building] {
                continue;
            }
            let v = d.drift(zb, 0).abs() - limit * d.height;
            if v <= 0.0 {
                continue;
            }
            let b = &mut best[d.building];
            if b.is_none_or(|(x, _)| v > x) {
                *b = Some((v, d.storey));
            }
        }
        (best.into_iter().enumerate())
            .filter_map(|(k, b)| b.map(|(_, storey)| (k, storey)))
            .collect()
    }

    /// The largest event value of the checked levels and storeys (positive once any level's
    /// contact mode or storey's spring state must end).
    pub(super) fn event_max(&self, z: &[f64]) -> f64 {
        self.event_values(z).fold(f64::NEG_INFINITY, f64::max)
    }

    /// The largest event value in `z` of the events that fire in a step's trial end (marked by
    /// [`RowRun::mark_firing`]): the function an event is located on. The others are left out
    /// because one of them can sit at 0 where a step starts (a storey that has just unloaded
    /// stays on its band edge, a level that has just separated) and leave it there while the
    /// event that fires grows from far below: regula falsi on their maximum then creeps from
    /// that end and stalls, and the event is taken late, by up to the whole step.
    pub(super) fn firing_max(&self, z: &[f64]) -> f64 {
        let nl = self.m.levels.len();
        (self.event_values(z).zip(&self.firing).enumerate())
            .filter(|(_, (_, &f))| f)
            .map(
                |(i, (v, _))| match self.firing_parts.get(i.wrapping_sub(nl)) {
                    Some(&mask) if i >= nl && mask != 0 => self.storey_parts(i - nl, z, mask),
                    _ => v,
                },
            )
            .fold(f64::NEG_INFINITY, f64::max)
    }

    /// The largest of storey `s`'s IMK event parts in `mask` in state `z`.
    fn storey_parts(&self, s: usize, z: &[f64], mask: u8) -> f64 {
        let (sm, n) = (&self.m.storeys[s], self.m.n);
        let parts = sm.event_parts(self.storey_modes[s], sm.drift(z, 0), sm.drift(z, n));
        (parts.into_iter().flatten().enumerate())
            .filter(|(j, _)| mask & (1 << j) != 0)
            .fold(f64::NEG_INFINITY, |m, (_, v)| m.max(v))
    }

    /// Mark the events whose value is positive in `z` as the ones that fire (and an IMK
    /// storey's parts that do).
    pub(super) fn mark_firing(&mut self, z: &[f64]) {
        let mut firing = std::mem::take(&mut self.firing);
        firing.clear();
        firing.extend(self.event_values(z).map(|v| v > 0.0));
        self.firing = firing;
        if !self.firing_by_parts {
            return;
        }
        let n = self.m.n;
        for (s, (sm, &mode)) in self.m.storeys.iter().zip(&self.storey_modes).enumerate() {
            let parts = sm.event_parts(mode, sm.drift(z, 0), sm.drift(z, n));
            self.firing_parts[s] = parts.map_or(0, |p| {
                (p.iter().enumerate()).fold(0, |m, (j, v)| if *v > 0.0 { m | 1 << j } else { m })
            });
        }
    }

    /// The earliest fraction of a step `z0 -> z1` (length `h`) at which an elastic storey's
    /// back drift could rise past its band between the ends (both inside it), or an IMK
    /// storey's drift past a threshold of its piece.
    pub(super) fn hidden_yield(&self, z0: &[f64], z1: &[f64], h: f64) -> Option<f64> {
        let n = self.m.n;
        let mut first: Option<f64> = None;
        for (s, (sm, &mode)) in self.m.storeys.iter().zip(&self.storey_modes).enumerate() {
            if !self.active[sm.building] {
                continue;
            }
            let p = self.m.plastic_slot(s);
            let edges = |z: &[f64]| sm.mode_edges(mode, sm.drift(z, 0), sm.drift(z, n), z[p]);
            let (Some(e0), Some(e1)) = (edges(z0), edges(z1)) else {
                continue;
            };
            for (a, b) in e0.iter().zip(&e1) {
                if let Some(x) = hidden_rise(a.0, a.1, b.0, b.1, h) {
                    first = Some(first.map_or(x, |f| f.min(x)));
                }
            }
        }
        first
    }

    /// The earliest fraction of a step `z0 -> z1` (length `h`) at which a watched storey's
    /// drift could pass the collapse limit between the ends (both below it): a storey that
    /// turns back just past the limit inside a step (the Hermite peaks see it) collapses there.
    pub(super) fn hidden_collapse(&self, z0: &[f64], z1: &[f64], h: f64) -> Option<f64> {
        let (n, limit) = (self.m.n, self.m.collapse_limit);
        let mut first: Option<f64> = None;
        for d in &self.m.drifts {
            if !self.watch[d.building] || !self.active[d.building] {
                continue;
            }
            let top = limit * d.height;
            let edges = |z: &[f64]| band_edges(d.drift(z, 0), d.drift(z, n), top);
            for (a, b) in edges(z0).iter().zip(&edges(z1)) {
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
    pub(super) fn storey_transitions(&mut self) {
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
                StoreyMode::Imk(_) => {
                    // The spring takes its pieces' changes at this drift and rate; the plastic
                    // drift moves to the new piece's force (by rounding, or by the whole force
                    // where a side has just lost its strength), with the work of that move.
                    let record = &mut self.storeys[s];
                    let sp = sm.imk.as_ref().expect("an IMK mode has its spring");
                    let st = record.imk.as_mut().expect("and its state");
                    let f = st.advance(sp, d, r);
                    record.yielded |= st.yielded;
                    let p_new = d - f / sm.k;
                    let f_mid = sm.k * (d - 0.5 * (p + p_new));
                    z[slot + ns] += f_mid * (p_new - p);
                    z[slot] = p_new;
                    StoreyMode::Imk(*st.piece())
                }
            };
        }
    }

    /// Apply the mode changes that the events at state `z` (time `t`) call for; `before` is
    /// the state at the start of the step in which they were located. A level whose event
    /// value is not positive only goes back to approach if its restitution closes again (a
    /// law whose phase is not an event).
    pub(super) fn transitions(&mut self, t: f64, z: &[f64], before: &[f64]) {
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
        if !self.m.drifts.is_empty() {
            self.watch_reached(&trial);
        }
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
            let earliest = |a: Option<f64>, b: Option<f64>| match (a, b) {
                (Some(a), Some(b)) => Some(a.min(b)),
                (a, b) => a.or(b),
            };
            let hidden = earliest(hidden, self.hidden_yield(&z0, &trial, h));
            let hidden = earliest(hidden, self.hidden_collapse(&z0, &trial, h));
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
            let (mut x, mut zb) = locate(
                h,
                f0,
                trial,
                f1,
                tol,
                max_iter,
                &mut step,
                |s: &Vec<f64>| self.firing_max(s),
            );
            // A drift that passed the collapse limit before the event located (and turned back
            // inside the step, so that its event did not fire at the trial's end): the
            // collapse is where it crossed, located on its own.
            if !self.m.drifts.is_empty() {
                let c = self.collapse_max(&zb);
                let c0 = if c > 0.0 { self.collapse_max(&z0) } else { 0.0 };
                if c > 0.0 && c0 <= 0.0 {
                    (x, zb) = locate(x, c0, zb, c, tol, max_iter, &mut step, |s: &Vec<f64>| {
                        self.collapse_max(s)
                    });
                }
            }
            self.track(t, x, &z0, &zb, (ag(t), ag(t + x)));
            let collapsing = if self.m.drifts.is_empty() {
                Vec::new()
            } else {
                self.collapses_at(&zb)
            };
            self.transitions(t + x, &zb, &z0);
            self.z = zb;
            for (k, storey) in collapsing {
                self.leave_scene(k, t + x, storey);
            }
            if !self.m.storeys.is_empty() {
                self.storey_transitions();
            }
            x
        } else {
            self.track(t, h, &z0, &trial, (ag(t), ag(t + h)));
            self.z = trial;
            if !self.m.drifts.is_empty() {
                self.collapse_by_peaks(t + h);
            }
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
}
