//! What a run records as it goes (peaks, impacts, the energy balance) and the state of one run
//! being integrated, shared by both schemes.

use super::events::{event_value, hidden_touch, locate, reapproach, touch};
use super::hermite::{
    cubic_max_bound, hermite_range, raise_cubic_peak, raise_hump_peak, raise_quintic_peak,
};
use super::state::structural_accel;
use super::state::{ddelta, delta, force, force_rate, Mode, Sample, Segment, State};
use crate::physics::model::{EnergyBalance, Initial, Oscillator, Pair, RunOutput, Status};

/// Peaks and impact bookkeeping shared by both schemes.
pub(crate) struct Tracker {
    pub out: RunOutput,
    /// Track each building's peak absolute acceleration (`out.peak_accel`).
    pub accel: bool,
    /// Approach speed of the current impact.
    pub v0: f64,
    imp_peak: f64,
    /// Kinetic plus strain energy at the start, and the largest `initial + input` so far (the
    /// energy balance's scale).
    e_initial: f64,
    e_peak: f64,
    /// Onset time of the current impact (the graded cuts after a touch count from it).
    t_onset: f64,
    impacts_ended: u32,
}

/// `peak` raised to the force `f1` at the end of a contact piece of length `h` and, where the
/// force falls at its end (`r1 < 0`) and rises at its start (`start()`: the start's force and
/// rate, computed only then), to the largest value of the cubic Hermite through both ends'
/// forces and rates (`Contact::force_rate`, on the piece's branch of the law: events end
/// pieces, so no touch or turn lies inside). Its error is `O(h^4)`, RK4's order; a parabola
/// through three force samples was `O(h^3)`, and across a turn, where the nonlinear
/// viscoelastic law's damping switches off, `O(h^2)`. (The shaders' twin takes the start's
/// force and rate as values.)
#[inline]
pub(crate) fn raise_force_peak(
    peak: f64,
    f1: f64,
    r1: f64,
    h: f64,
    start: impl FnOnce() -> (f64, f64),
) -> f64 {
    let peak = peak.max(f1);
    if r1 >= 0.0 {
        return peak;
    }
    let (f0, r0) = start();
    if r0 > 0.0 {
        peak.max(hermite_range(f0, r0, f1, r1, h).1)
    } else {
        peak
    }
}

impl Tracker {
    pub fn new() -> Tracker {
        Tracker {
            out: RunOutput::default(),
            accel: false,
            v0: 0.0,
            imp_peak: 0.0,
            e_initial: 0.0,
            e_peak: 0.0,
            t_onset: 0.0,
            impacts_ended: 0,
        }
    }

    /// Onset time of the current (or last) impact.
    pub fn onset_time(&self) -> f64 {
        self.t_onset
    }

    pub fn impacts_ended(&self) -> u32 {
        self.impacts_ended
    }

    /// Account for a free record step over `seg`, from `z0` to `z1`: peak displacements from
    /// the quintic Hermite (both ends' accelerations are known in free flight), peak
    /// accelerations (where tracked) from the cubic Hermite with their rates. A peak that is
    /// `settled` (`[u1, u2, a1, a2]`: it cannot be raised over this step) skips the search.
    #[inline]
    pub fn free_step(
        &mut self,
        p: &Pair,
        seg: &Segment,
        z0: &State,
        z1: &State,
        settled: [bool; 4],
    ) {
        let o = &mut self.out;
        o.free_steps += 1;
        if !settled[0] {
            o.peak_u1 = free_peak(&p.b1, o.peak_u1, seg, [z0[0], z0[1]], [z1[0], z1[1]]);
        }
        if !settled[1] {
            o.peak_u2 = free_peak(&p.b2, o.peak_u2, seg, [z0[2], z0[3]], [z1[2], z1[3]]);
        }
        if self.accel {
            let pa = &mut o.peak_accel;
            if !settled[2] {
                pa[0] = free_accel_peak(&p.b1, pa[0], seg, [z0[0], z0[1]], [z1[0], z1[1]]);
            }
            if !settled[3] {
                pa[1] = free_accel_peak(&p.b2, pa[1], seg, [z0[2], z0[3]], [z1[2], z1[3]]);
            }
        }
        self.e_peak = self.e_peak.max(self.e_initial + z1[5]);
    }

    /// Start from a free state reached by the shared free response ([`super::shared`]):
    /// `steps` record steps taken there, with these peaks (`[u1, u2, a1, a2]`).
    pub fn resume_free(&mut self, steps: u64, peaks: [f64; 4]) {
        self.out.shared_steps += steps;
        [self.out.peak_u1, self.out.peak_u2] = [peaks[0], peaks[1]];
        if self.accel {
            self.out.peak_accel = [peaks[2], peaks[3]];
        }
    }

    /// Account for a step `t0 -> t0 + h` spent in `mode`, from `z0` to `z1` (inside the record
    /// step `seg`). Peak accelerations, where tracked, from the cubic Hermite through both
    /// ends' accelerations and rates: in free flight over the piece; in contact, with the
    /// force and its rate, where the acceleration peaks inside the piece (`raise_hump_peak`:
    /// a force's rate is unbounded at first touch under the nonlinear viscoelastic law).
    /// Events end pieces at the force's kinks (but one: a restituting contact that closes again
    /// goes back to approach after the piece, unlocated, `reapproach`), so inside a piece the
    /// acceleration is as smooth as the force, whose peak the same cubic finds; the ends'
    /// values alone were 2e-3 from the reference at the default setting in tests/it/scenes.rs.
    /// The end is read in the mode the run goes on in: a piece that closes again ends with the
    /// approach's damping force, which the restitution's law leaves out (its acceleration was
    /// 2.9e-3 too large at 16 substeps per contact, and the error rose at 32).
    #[inline]
    #[allow(clippy::too_many_arguments)] // the piece: its mode, ends, length and place
    pub fn step(
        &mut self,
        p: &Pair,
        mode: Mode,
        h: f64,
        z0: &State,
        z1: &State,
        seg: &Segment,
        t0: f64,
    ) {
        let o = &mut self.out;
        o.peak_u1 = raise_cubic_peak(o.peak_u1, z0[0], z0[1], z1[0], z1[1], h);
        o.peak_u2 = raise_cubic_peak(o.peak_u2, z0[2], z0[3], z1[2], z1[3], h);
        if self.accel {
            let ag = (seg.at(t0), seg.at(t0 + h));
            let ends = [
                accel_and_jerk(p, mode, self.v0, z0, ag.0),
                accel_and_jerk(p, reapproach(mode, z1), self.v0, z1, ag.1),
            ];
            let pa = &mut o.peak_accel;
            for (b, peak) in pa.iter_mut().enumerate() {
                let ([a0, j0], [a1, j1]) = (ends[0][b], ends[1][b]);
                *peak = if mode == Mode::Free {
                    raise_cubic_peak(*peak, a0, j0, a1, j1, h)
                } else {
                    raise_hump_peak(*peak, a0, j0, a1, j1, h)
                };
            }
        }
        self.e_peak = self.e_peak.max(self.e_initial + z1[5]);
        if mode != Mode::Free {
            o.contact_time += h;
            let (y0, d0, y1, d1) = (delta(p, z0), ddelta(z0), delta(p, z1), ddelta(z1));
            if cubic_max_bound(y0, d0, y1, d1, h) > o.peak_penetration {
                let (_, dmax) = hermite_range(y0, d0, y1, d1, h);
                o.peak_penetration = o.peak_penetration.max(dmax);
            }
            o.dissipated_energy = z1[4];
            let f = force(p, mode, self.v0, z1);
            let v0 = self.v0;
            let r1 = force_rate(p, mode, v0, z1, f);
            self.imp_peak = raise_force_peak(self.imp_peak, f, r1, h, || {
                let f0 = force(p, mode, v0, z0);
                (f0, force_rate(p, mode, v0, z0, f0))
            });
        }
    }

    #[inline]
    pub fn onset(&mut self, t: f64, v0: f64, f: f64) {
        self.out.impacts += 1;
        if self.out.first_impact.is_none() {
            self.out.first_impact = Some(t);
        }
        self.v0 = v0;
        self.imp_peak = f.max(0.0);
        self.t_onset = t;
    }

    #[inline]
    pub fn end_impact(&mut self) {
        if self.imp_peak > self.out.peak_force {
            self.out.peak_force = self.imp_peak;
            self.out.impact_velocity = self.v0;
        }
        self.impacts_ended += 1;
    }

    pub fn finish(mut self, mode: Mode, status: Status) -> RunOutput {
        if mode != Mode::Free {
            self.end_impact();
        }
        self.out.status = status;
        self.out
    }

    /// The energy balance at state `z`.
    #[inline]
    pub fn energy(&self, p: &Pair, z: &State) -> EnergyBalance {
        let held = mechanical_energy(p, z);
        EnergyBalance::close(self.e_initial, z[5], z[6], z[4], held, self.e_peak)
    }
}

/// Apply the mode change an event at state `z` (time `t`) calls for; `before` is the state at
/// the start of the step in which the event was located.
#[inline]
pub(crate) fn transition(
    p: &Pair,
    mode: Mode,
    t: f64,
    z: &State,
    before: &State,
    tr: &mut Tracker,
) -> Mode {
    match mode {
        Mode::Free => {
            let (v0, next) = touch(delta(p, before), ddelta(z), tr.v0);
            tr.onset(t, v0, force(p, next, v0, z));
            next
        }
        Mode::Approach => Mode::Restitution,
        Mode::Restitution => {
            tr.end_impact();
            Mode::Free
        }
    }
}

/// Acceleration of a free oscillator at `(u, v)` under ground acceleration `ag`.
#[inline]
pub(crate) fn free_accel(o: &Oscillator, u: f64, v: f64, ag: f64) -> f64 {
    (-o.c * v - o.k * u) / o.m - ag
}

/// Absolute acceleration `-(c v + k u) / m` of a free oscillator at `(u, v)` and its rate
/// `-(c a + k v) / m` (`a` the relative acceleration under ground acceleration `ag`).
#[inline]
pub(crate) fn free_accel_and_jerk(o: &Oscillator, u: f64, v: f64, ag: f64) -> (f64, f64) {
    let a_abs = (-o.c * v - o.k * u) / o.m;
    (a_abs, (-o.c * (a_abs - ag) - o.k * v) / o.m)
}

/// Each building's absolute acceleration and its rate at `z` in `mode` (ground acceleration
/// `ag`): `-(c v + k u -+ F) / m` and `-(c a + k v -+ F') / m`, `a` the relative acceleration
/// and `F'` the force's rate. Free: [`free_accel_and_jerk`] of each.
#[inline]
pub(crate) fn accel_and_jerk(p: &Pair, mode: Mode, v0: f64, z: &State, ag: f64) -> [[f64; 2]; 2] {
    if mode == Mode::Free {
        let (a1, j1) = free_accel_and_jerk(&p.b1, z[0], z[1], ag);
        let (a2, j2) = free_accel_and_jerk(&p.b2, z[2], z[3], ag);
        return [[a1, j1], [a2, j2]];
    }
    let f = force(p, mode, v0, z);
    let r = force_rate(p, mode, v0, z, f);
    let a = structural_accel(p, z, f);
    let (b1, b2) = (&p.b1, &p.b2);
    [
        [a[0], (-b1.c * (a[0] - ag) - b1.k * z[1] - r) / b1.m],
        [a[1], (-b2.c * (a[1] - ag) - b2.k * z[3] + r) / b2.m],
    ]
}

/// `peak` raised to the largest `|a|` of one oscillator's absolute acceleration over the free
/// record step `seg` from `(u, v)` = `s0` to `s1`: the cubic Hermite through its values and
/// rates at both ends (as a row's building's). The run and the shared free response both call
/// it, so their peaks agree to the bit.
#[inline]
pub(crate) fn free_accel_peak(
    o: &Oscillator,
    peak: f64,
    seg: &Segment,
    s0: [f64; 2],
    s1: [f64; 2],
) -> f64 {
    let (a0, j0) = free_accel_and_jerk(o, s0[0], s0[1], seg.a0);
    let (a1, j1) = free_accel_and_jerk(o, s1[0], s1[1], seg.a1);
    raise_cubic_peak(peak, a0, j0, a1, j1, seg.dt)
}

/// `peak` raised to the largest `|u|` of one oscillator's quintic Hermite over the free record
/// step `seg` from `(u, v)` = `s0` to `s1`. The run and the shared free response
/// ([`super::shared`]) both call it, so their peaks agree to the bit.
#[inline]
pub(crate) fn free_peak(
    o: &Oscillator,
    peak: f64,
    seg: &Segment,
    s0: [f64; 2],
    s1: [f64; 2],
) -> f64 {
    let a = [
        free_accel(o, s0[0], s0[1], seg.a0),
        free_accel(o, s1[0], s1[1], seg.a1),
    ];
    raise_quintic_peak(peak, [s0[0], s1[0]], [s0[1], s1[1]], a, seg.dt)
}

/// Kinetic plus strain energy of both buildings, J.
#[inline]
pub(crate) fn mechanical_energy(p: &Pair, z: &State) -> f64 {
    p.b1.energy(z[0], z[1]) + p.b2.energy(z[2], z[3])
}

/// The state of one run being integrated, shared by both schemes: they decide step lengths and
/// take trial steps; [`Integration::accept`] does the rest.
pub(crate) struct Integration<'a, 'o> {
    pub pair: &'a Pair,
    pub z: State,
    pub mode: Mode,
    pub tr: Tracker,
    /// Report the energy balance (its integrals are complete).
    pub energy: bool,
    observer: Option<&'o mut dyn FnMut(&Sample)>,
}

impl<'a, 'o> Integration<'a, 'o> {
    /// Start at `t0` from `init` (already in contact if the bodies overlap).
    pub fn start(
        pair: &'a Pair,
        init: &Initial,
        t0: f64,
        observer: Option<&'o mut dyn FnMut(&Sample)>,
    ) -> Self {
        let z = [init.u1, init.v1, init.u2, init.v2, 0.0, 0.0, 0.0];
        let mut run = Integration {
            pair,
            z,
            mode: Mode::Free,
            tr: Tracker::new(),
            energy: true,
            observer,
        };
        run.tr.e_initial = mechanical_energy(pair, &z);
        if event_value(pair, run.mode, 0.0, &z) > 0.0 {
            run.mode = transition(pair, run.mode, t0, &z, &z, &mut run.tr);
        }
        run.emit(t0);
        run
    }

    pub fn emit(&mut self, t: f64) {
        if let Some(obs) = self.observer.as_mut() {
            let force = force(self.pair, self.mode, self.tr.v0, &self.z);
            obs(&Sample {
                t,
                z: self.z,
                force,
                mode: self.mode,
            });
        }
    }

    /// The free record step over `seg` to `z1`, with no possible contact (already checked by the
    /// caller); `settled`: the buildings whose peaks this step cannot raise.
    pub fn free_step(&mut self, seg: &Segment, z1: State, settled: [bool; 4]) {
        self.tr.free_step(self.pair, seg, &self.z, &z1, settled);
        self.z = z1;
        self.emit(seg.t1());
    }

    /// Accept `trial`, the step `t -> t + h` in the current mode; `step(x)` re-takes it with
    /// length `x`. A touch hidden inside a free step and any event inside the step are located
    /// (to `tol_rel * h`, at most `max_iter` iterations); the step then ends there. Updates peaks
    /// and mode and returns the length advanced.
    #[allow(clippy::too_many_arguments)] // the step, its trial, and how to locate events in it
    pub fn accept(
        &mut self,
        seg: &Segment,
        t: f64,
        h: f64,
        trial: State,
        tol_rel: f64,
        max_iter: u32,
        mut step: impl FnMut(f64) -> State,
    ) -> f64 {
        let (p, mode, v0, z0) = (self.pair, self.mode, self.tr.v0, self.z);
        let (mut trial, mut h) = (trial, h);
        let mut f1 = event_value(p, mode, v0, &trial);
        if mode == Mode::Free && f1 <= 0.0 {
            if let Some(s) = hidden_touch(p, &z0, &trial, h) {
                let zs = step(s * h);
                let fs = event_value(p, mode, v0, &zs);
                if fs > 0.0 {
                    (trial, f1, h) = (zs, fs, s * h);
                }
            }
        }
        let advanced = if f1 > 0.0 {
            let f0 = event_value(p, mode, v0, &z0);
            let tol = (tol_rel * h).max(4.0 * f64::EPSILON * t.abs());
            let eval = |s: &State| event_value(p, mode, v0, s);
            let (x, zb) = locate(h, f0, trial, f1, tol, max_iter, &mut step, eval);
            self.tr.step(p, mode, x, &z0, &zb, seg, t);
            self.mode = transition(p, mode, t + x, &zb, &z0, &mut self.tr);
            self.z = zb;
            x
        } else {
            self.tr.step(p, mode, h, &z0, &trial, seg, t);
            self.z = trial;
            self.mode = reapproach(mode, &self.z);
            h
        };
        self.emit(t + advanced);
        advanced
    }

    /// End the run with `status`, after `substeps` steps of integration work.
    pub fn finish(self, status: Status, substeps: u64) -> RunOutput {
        let energy = self.energy.then(|| self.tr.energy(self.pair, &self.z));
        let mut out = self.tr.finish(self.mode, status);
        out.substeps = substeps;
        out.energy = energy;
        out
    }
}

#[cfg(test)]
mod tests {
    use super::raise_force_peak;

    /// The cubic Hermite through the ends' values and rates holds a quadratic exactly: the peak
    /// of `1 - (t - 0.3)^2` over `[0, 1]` from its ends alone; no interior peak is sought where
    /// the force does not rise then fall.
    #[test]
    fn the_peak_inside_a_piece_is_the_hermite_maximum() {
        let f = |t: f64| 1.0 - (t - 0.3) * (t - 0.3);
        let r = |t: f64| -2.0 * (t - 0.3);
        let peak = raise_force_peak(0.0, f(1.0), r(1.0), 1.0, || (f(0.0), r(0.0)));
        assert!((peak - 1.0).abs() < 1e-15, "{peak}");
        assert_eq!(raise_force_peak(0.2, 0.5, 0.3, 1.0, || (0.1, 1.0)), 0.5);
        assert_eq!(raise_force_peak(0.7, 0.5, -0.3, 1.0, || (0.6, -1.0)), 0.7);
    }
}
