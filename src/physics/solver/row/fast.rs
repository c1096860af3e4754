//! The production scheme for rows, the pair's ([`crate::physics::solver::fast`]) on the row's
//! state:
//!
//! 1. While no level is in contact, each record step is taken with the exact propagator of
//!    every mode (no truncation error).
//! 2. The step is kept unless some level may touch inside it (the Hermite cubic of its
//!    penetration within twice its error bound of 0).
//! 3. Such a step, and every step while a level is in contact, is redone with `M` fixed RK4
//!    substeps of the buildings that contact may reach, sized as the pair's from each level
//!    that is in contact or may touch (its impact duration and local rate) and from their
//!    fastest mode. The other buildings stand still through the substeps and take their exact
//!    free step at its end; one joins when a moving neighbour's floor may reach its range
//!    (`Lookout`). Every level's events are located inside the substeps. Buildings of
//!    `FLOOR_SUBSTEPS_FROM` (4) storeys or more with Rayleigh damping take them in floor
//!    coordinates (`O(N)` per right-hand side; the same motion, `RowModel::substep_model`).
//! 4. Peaks: as the pair's (the force's cubic Hermite over each piece; displacements and drifts from
//!    the quintic Hermite over free record steps, the cubic inside contact steps). Floor
//!    accelerations: the cubic Hermite with their rates over free record steps, the samples at
//!    substep ends and events in contact steps, where a contact force's spike makes them
//!    converge with the substep (as the force peak's samples do).
//! 5. Yielding storeys ([`super::yielding`]): free steps are exact about the static response to
//!    the plastic loads; a step in which a storey yields, or may reach its band edge (bounded as a
//!    touch), is taken in substeps by its building, yield onset and unloading located as
//!    events; after the record the run goes on at rest until no storey can yield again. A
//!    building whose IMK storeys stand on pieces off their initial stiffness takes the exact
//!    step of its tangent stiffness instead ([`super::tangent`]; not in the GPU kernel's twin).

use super::exact_step::CoupledStep;
use super::model::{RowModel, FLOOR_SUBSTEPS_FROM};
use super::rhs::{rhs, Motion};
use super::run::RowRun;
use super::sample::RowObserver;
use super::tangent::TangentSteps;
use super::yielding::next_segment;
use crate::physics::model::{Forcing, Oscillator, Status};
use crate::physics::propagator::{EnergyForms, Propagator};
use crate::physics::row::RowOutput;
use crate::physics::solver::events::error_margin;
use crate::physics::solver::fast::{
    cut_tolerance, FastOptions, LOCATE_ITERATIONS, LOCATE_TOLERANCE, MAX_PIECES_PER_SUBSTEP,
    SUSTAINED,
};
use crate::physics::solver::hermite::{cubic_max_bound, hermite_range};
use crate::physics::solver::state::{impact_step, Mode, Segment};

/// The fast scheme's settings are the pair's.
pub type RowFastOptions = FastOptions;

/// The stages of an RK4 step, kept between calls.
struct Stages {
    k: [Vec<f64>; 4],
    y: Vec<f64>,
}

/// Classic RK4 over `h` from `(t, z)` with the run's `motion`.
#[inline(always)]
fn rk4(
    m: &RowModel,
    motion: &Motion,
    seg: &Segment,
    t: f64,
    z: &[f64],
    h: f64,
    st: &mut Stages,
) -> Vec<f64> {
    let (ag0, agm, ag1) = (seg.at(t), seg.at(t + 0.5 * h), seg.at(t + h));
    let Stages { k, y } = st;
    let [k1, k2, k3, k4] = k;
    rhs(m, motion, ag0, z, k1);
    for ((y, z), k) in y.iter_mut().zip(z).zip(k1.iter()) {
        *y = z + 0.5 * h * k;
    }
    rhs(m, motion, agm, y, k2);
    for ((y, z), k) in y.iter_mut().zip(z).zip(k2.iter()) {
        *y = z + 0.5 * h * k;
    }
    rhs(m, motion, agm, y, k3);
    for ((y, z), k) in y.iter_mut().zip(z).zip(k3.iter()) {
        *y = z + h * k;
    }
    rhs(m, motion, ag1, y, k4);
    (0..z.len())
        .map(|i| z[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]))
        .collect()
}

/// A level between a building in the substeps and one standing still: the still floor's
/// displacement range over the record step (its exact free motion's cubic Hermite widened by
/// twice the Hermite's error bound), against which each substep checks the moving floor.
struct Lookout {
    level: usize,
    /// The level's left building is the moving one.
    left_moves: bool,
    lo: f64,
    hi: f64,
}

impl Lookout {
    /// For level `l` of `m` (modal) over the free step `z -> z1` of length `dt`, with each
    /// mode's `|q''''|` bound ([`RowModel::fourth_derivative_bounds`]).
    fn new(
        m: &RowModel,
        l: usize,
        left_moves: bool,
        bounds: &[f64],
        z: &[f64],
        z1: &[f64],
        dt: f64,
    ) -> Lookout {
        let lm = &m.levels[l];
        let n = m.n;
        // The still floor: the right one when the left moves.
        let floor = |z: &[f64], s: usize| {
            if left_moves {
                lm.right(z, s)
            } else {
                lm.left(z, s)
            }
        };
        let (lo, hi) = hermite_range(floor(z, 0), floor(z, n), floor(z1, 0), floor(z1, n), dt);
        let bound = lm.side_fourth_derivative_bound(!left_moves, bounds);
        let margin = error_margin(bound, dt);
        Lookout {
            level: l,
            left_moves,
            lo: lo - margin,
            hi: hi + margin,
        }
    }

    /// Could the level close over the substep `z0 -> z1` of length `h` (in `m`'s coordinates):
    /// the moving floor's cubic bound against the still floor's range.
    fn may_close(&self, m: &RowModel, z0: &[f64], z1: &[f64], h: f64) -> bool {
        let lm = &m.levels[self.level];
        let n = m.n;
        if self.left_moves {
            let (u0, v0, u1, v1) = (
                lm.left(z0, 0),
                lm.left(z0, n),
                lm.left(z1, 0),
                lm.left(z1, n),
            );
            cubic_max_bound(u0, v0, u1, v1, h) - self.lo - lm.gap > 0.0
        } else {
            let (u0, v0, u1, v1) = (
                lm.right(z0, 0),
                lm.right(z0, n),
                lm.right(z1, 0),
                lm.right(z1, n),
            );
            self.hi + cubic_max_bound(-u0, -v0, -u1, -v1, h) - lm.gap > 0.0
        }
    }
}

fn mode_oscillator(m: &RowModel, k: usize) -> Oscillator {
    Oscillator {
        m: 1.0,
        k: m.w2[k],
        c: m.two_xi_w[k],
    }
}

/// One run of the row from `z0`; `observer`, if any, hears every accepted step and event (the
/// output is the same with or without one).
pub(crate) fn run(
    m: &RowModel,
    forcing: &Forcing,
    z0: Vec<f64>,
    o: &FastOptions,
    observer: Option<RowObserver<'_>>,
) -> RowOutput {
    // Contact substeps run in floor coordinates where the damping allows (O(N) each), and only
    // for the buildings that contact may reach.
    let sub = m.substep_model();
    run_with(
        m,
        sub.as_ref(),
        Standing::Grown,
        forcing,
        z0,
        o,
        Steps::Tangent,
        false,
        // Shortened to the substep model's life (a coercion `Option` does not make itself).
        observer.map(|o| o as RowObserver<'_>),
    )
    .0
}

/// The fast scheme with every building in every substep: the twin of the GPU row kernel
/// (`shaders/row.wgsl`), which lets no building stand still and takes IMK storeys' pieces off
/// their initial stiffness in substeps, for comparing the two step for step. The scheme
/// ([`super::simulate_row`]) differs from it by the exact free steps of the buildings that
/// stand still and of those on such pieces ([`super::tangent`]).
pub fn simulate_whole_row(
    m: &RowModel,
    forcing: &Forcing,
    z0: Vec<f64>,
    o: &FastOptions,
) -> RowOutput {
    let sub = m.substep_model();
    run_with(
        m,
        sub.as_ref(),
        Standing::None,
        forcing,
        z0,
        o,
        Steps::Modal,
        false,
        None,
    )
    .0
}

/// The fast scheme from rest with every building in every substep, tracking the levels'
/// closings ([`super::simulate_uncoupled`]).
pub(crate) fn run_uncoupled(m: &RowModel, forcing: &Forcing, o: &FastOptions) -> RowOutput {
    let sub = m.substep_model();
    run_with(
        m,
        sub.as_ref(),
        Standing::None,
        forcing,
        m.at_rest(),
        o,
        Steps::Tangent,
        true,
        None,
    )
    .0
}

/// Which buildings stand still through a record step of substeps (stepped exactly at its end).
#[derive(Debug, Clone, Copy, PartialEq)]
enum Standing {
    /// None: the whole row takes the substeps (as the GPU kernel).
    None,
    /// Those that no level in contact or that may touch in free flight reaches; one joins the
    /// substeps when a moving neighbour's floor may reach its range ([`Lookout`]). Tests
    /// check the watch alone with it.
    #[cfg(test)]
    Watched,
    /// As `Watched`, and a neighbour whose level would close within the step at its present
    /// rate takes the substeps from the step's start (the scheme).
    Grown,
}

/// Which free steps a building whose IMK storeys stand on pieces off their initial stiffness
/// takes.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Steps {
    /// Substeps, as the GPU row kernel (which locates an IMK storey's events on the maximum
    /// of its parts, as this does then).
    Modal,
    /// Exact steps of its tangent stiffness ([`super::tangent`]).
    Tangent,
}

/// Building-steps stood still, and buildings that joined the substeps inside a record step.
#[derive(Debug, Clone, Copy, Default)]
struct Tally {
    still: u64,
    joined: u64,
}

/// [`run`] with the contact substeps in `sub` (None: in modes, as the reference) and the
/// buildings standing still as `standing` says, tracking the levels' closings where
/// `closings` (with no building standing still).
#[allow(clippy::too_many_arguments)]
fn run_with<'a>(
    m: &'a RowModel,
    sub: Option<&'a RowModel>,
    standing: Standing,
    forcing: &Forcing,
    z0: Vec<f64>,
    o: &FastOptions,
    steps: Steps,
    closings: bool,
    observer: Option<RowObserver<'a>>,
) -> (RowOutput, Tally) {
    let mut tally = Tally::default();
    let finish = |run: RowRun, status: Status, substeps: u32, tally: Tally| {
        (run.finish(status, substeps as u64), tally)
    };
    let n = m.n;
    let nl = m.levels.len();
    let dt = forcing.dt;
    let props: Vec<Propagator> = (0..n)
        .map(|k| Propagator::new(&mode_oscillator(m, k), dt))
        .collect();
    let forms: Option<Vec<EnergyForms>> = o.energy.then(|| {
        (0..n)
            .map(|k| EnergyForms::new(&mode_oscillator(m, k), dt))
            .collect()
    });
    let rates = m.building_rates();
    // Buildings whose damping couples their modes take their free steps whole.
    let mut coupled: Vec<CoupledStep> = (0..m.buildings.len())
        .filter_map(|k| CoupledStep::new(m, k, dt, o.energy))
        .collect();
    let mut in_coupled = vec![false; n];
    for c in &coupled {
        let b = &m.buildings[c.building()];
        in_coupled[b.off..b.off + b.n()].fill(true);
    }
    let mut run = RowRun::start(m, z0, forcing.t0);
    run.energy = o.energy;
    run.firing_by_parts = steps == Steps::Tangent;
    run.observer = observer;
    if closings {
        debug_assert_eq!(
            standing,
            Standing::None,
            "closings need every building moving"
        );
        run.track_closings();
    }
    let mut substeps: u32 = 0;
    let len = m.len();
    let mut stages = Stages {
        k: std::array::from_fn(|_| vec![0.0; len]),
        y: vec![0.0; len],
    };
    let mut modes = Vec::with_capacity(nl);
    let mut bounds = Vec::with_capacity(n);
    let mut coarse = Vec::with_capacity(m.buildings.len());
    // Tall buildings' levels read a free step's penetrations from its floors, computed first
    // (O(1) per level, where the modes cost O(N)); low ones from the modes, which cost no more
    // than computing the floors of a step that is then redone in substeps.
    let prepare_ends = m.buildings.iter().any(|b| b.n() >= FLOOR_SUBSTEPS_FROM);
    let mut z1 = vec![0.0; len];
    let mut work = Vec::new();
    // Per level: may it touch over the exact free step (None: not asked this step).
    let mut may_touch: Vec<Option<bool>> = vec![None; nl];
    let mut active = vec![false; m.buildings.len()];
    let mut moving = active.clone();
    // In a row of two, a level that touches moves both buildings.
    let can_stand = standing != Standing::None && m.buildings.len() > 2;
    let mut lookouts: Vec<Lookout> = Vec::new();
    // Yielding storeys: the static response to their plastic loads (free steps are exact about
    // it), their spring states for the substeps, and the buildings one may yield in.
    let yields = !m.storeys.is_empty();
    let mut q_static = vec![0.0; n];
    let mut storey_modes = Vec::with_capacity(m.storeys.len());
    let mut yield_watch = vec![false; m.buildings.len()];
    // Buildings on IMK pieces off their initial stiffness: their exact tangent steps, and
    // which take one this step.
    let mut tangents = TangentSteps::new(m, steps == Steps::Tangent, dt, o.energy);
    let mut on_tangent = vec![false; m.buildings.len()];
    let mut i = 0;
    // The step's start, in a buffer kept from step to step (as `z1`, its end).
    let mut z_start = Vec::with_capacity(len);
    // Each mode's building: a building that collapsed stands frozen, out of the free steps.
    let mode_building: Vec<usize> = (m.buildings.iter().enumerate())
        .flat_map(|(k, b)| std::iter::repeat_n(k, b.n()))
        .collect();
    while let Some(seg) = next_segment(m, forcing, i, &mut run) {
        i += 1;
        // A building near collapse moves in substeps, where its storeys' collapse is an event.
        let mut watched = !m.drifts.is_empty() && run.refresh_watch();
        let any_gone = run.gone.iter().any(|&g| g);
        z_start.clone_from(&run.z);
        let z = &z_start;
        // Only where the step's free motion is taken (not while a level is in contact in a
        // row where every building moves).
        let free = can_stand || !run.any_contact();
        let any_tangent =
            tangents.select(m, (&run.storey_modes, &run.gone), z, free, &mut on_tangent);
        let tangent_on = any_tangent.then_some(&on_tangent[..]);
        // The exact free step of every mode: the step itself when no level may touch, and the
        // buildings' that stand still through a step of substeps (none in a row of two).
        let any_contact = run.any_contact();
        z1.copy_from_slice(z);
        work.clear();
        if can_stand || !any_contact {
            if yields {
                m.static_offsets(z, &mut q_static);
            }
            for k in 0..n {
                if in_coupled[k]
                    || (any_gone && run.gone[mode_building[k]])
                    || tangent_on.is_some_and(|on| on[mode_building[k]])
                {
                    if forms.is_some() {
                        work.push((0.0, 0.0));
                    }
                    continue;
                }
                let (a0, a1) = (m.part[k] * seg.a0, m.part[k] * seg.a1);
                let q = if yields { z[k] - q_static[k] } else { z[k] };
                (z1[k], z1[n + k]) = props[k].step(q, z[n + k], a0, a1);
                if yields {
                    z1[k] += q_static[k];
                }
                if let Some(f) = &forms {
                    let (vv, agv) = f[k].integrals(q, z[n + k], a0, a1);
                    m.add_free_work(&mut z1, k, (agv, vv));
                    work.push((agv, vv));
                }
            }
            for c in coupled.iter_mut() {
                if run.gone[c.building()] || tangent_on.is_some_and(|on| on[c.building()]) {
                    continue;
                }
                let qs = yields.then_some(&q_static[..]);
                let w = forms.is_some().then_some(&mut work[..]);
                c.step(m, z, qs, (seg.a0, seg.a1), &mut z1, w);
                if forms.is_some() {
                    let b = &m.buildings[c.building()];
                    for (i, &w) in work.iter().enumerate().skip(b.off).take(b.n()) {
                        m.add_free_work(&mut z1, i, w);
                    }
                }
            }
            if let Some(on) = tangent_on {
                let w = forms.is_some().then_some(&mut work[..]);
                tangents.step(m, on, (z, (seg.a0, seg.a1)), &mut z1, w);
            }
        }
        if prepare_ends && !any_contact {
            run.prepare_free_ends(z, &z1, (seg.a0, seg.a1));
        }
        // A building whose drift runs past half the limit within the step is watched from its
        // start, so that a crossing inside it is located.
        if !m.drifts.is_empty() && (can_stand || !any_contact) && run.watch_reached(&z1) {
            watched = true;
        }
        may_touch.fill(None);
        let mut bounded = false;
        // A storey that yields, or may in the exact free step, moves its building in substeps.
        let mut yielding = false;
        if yields && (can_stand || !any_contact) {
            tangents.bounds(m, (&seg, z, &z1), &mut bounds, tangent_on);
            bounded = true;
            yielding = m.yield_watch(
                (&run.storey_modes, tangent_on),
                (z, &z1),
                &bounds,
                dt,
                &mut yield_watch,
            );
            // A storey heading one way on a tangent step: its rate must not turn inside it.
            if let Some(on) = tangent_on {
                let ag = (seg.a0, seg.a1);
                yielding |= tangents.may_reverse(
                    m,
                    (on, &run.storey_modes),
                    ag,
                    (z, &z1),
                    &mut yield_watch,
                );
            }
        }
        if watched {
            if !yields {
                yield_watch.fill(false);
            }
            if can_stand || !any_contact {
                // Near collapse: in substeps while a storey may reach the limit in the step.
                if !bounded {
                    tangents.bounds(m, (&seg, z, &z1), &mut bounds, tangent_on);
                    bounded = true;
                }
                yielding |= run.collapse_watch((z, &z1), &bounds, dt, &mut yield_watch);
            } else {
                for (y, w) in yield_watch.iter_mut().zip(&run.watch) {
                    *y |= *w;
                }
                yielding = true;
            }
        }
        // A building that left the scene neither yields nor collapses again.
        if any_gone && (yields || watched) {
            for (y, &g) in yield_watch.iter_mut().zip(&run.gone) {
                *y &= !g;
            }
            yielding = yield_watch.iter().any(|&y| y) || (yielding && any_contact && !can_stand);
        }
        if !any_contact {
            if !bounded {
                tangents.bounds(m, (&seg, z, &z1), &mut bounds, tangent_on);
                bounded = true;
            }
            // The floors at both ends are needed for the peaks if the step is free; the levels
            // read their penetrations from them (O(1) each), and weigh each mode's bound only
            // where the building's coarse bound leaves the touch open.
            let mut touching = false;
            if prepare_ends {
                m.coarse_floor_bounds(&bounds, &mut coarse);
                for (l, ((lm, ls), may)) in m
                    .levels
                    .iter()
                    .zip(&run.levels)
                    .zip(may_touch.iter_mut())
                    .enumerate()
                {
                    if any_gone && run.level_dead(l) {
                        *may = Some(false);
                        continue;
                    }
                    let ends = run.level_ends(l);
                    let open = coarse[lm.buildings.0] + coarse[lm.buildings.1];
                    let t = lm.may_touch_within(ends, open, dt, ls.v0)
                        && lm.may_touch_within(
                            ends,
                            lm.fourth_derivative_bound(&bounds),
                            dt,
                            ls.v0,
                        );
                    *may = Some(t);
                    touching |= t;
                }
            } else {
                for (l, ((lm, ls), may)) in (m.levels.iter().zip(&run.levels))
                    .zip(may_touch.iter_mut())
                    .enumerate()
                {
                    if any_gone && run.level_dead(l) {
                        *may = Some(false);
                        continue;
                    }
                    let t = lm.may_touch_bounded(n, &bounds, z, &z1, dt, ls.v0);
                    *may = Some(t);
                    touching |= t;
                }
            }
            if touching || yielding {
                run.drop_free_ends();
            } else {
                run.free_step(&seg, &mut z1);
                if !run.z.iter().all(|x| x.is_finite()) {
                    return finish(run, Status::NonFinite, substeps, tally);
                }
                if run.all_gone() {
                    return finish(run, Status::Collapsed, substeps, tally);
                }
                continue;
            }
        }
        // The buildings that take substeps: both of every level in contact or that may touch in
        // free flight, and from them outwards each neighbour whose level may close within the
        // step at its present rate. The others stand still and are stepped exactly.
        active.fill(!can_stand);
        if can_stand {
            for ((lm, ls), may) in m.levels.iter().zip(&run.levels).zip(&may_touch) {
                if ls.mode != Mode::Free || *may == Some(true) {
                    active[lm.buildings.0] = true;
                    active[lm.buildings.1] = true;
                }
            }
            if yielding || watched {
                for (a, w) in active.iter_mut().zip(&yield_watch) {
                    *a |= *w;
                }
            }
            // A building on its tangent stiffness does not stand still (its still step is
            // the modal one).
            if let Some(on) = tangent_on {
                for (a, w) in active.iter_mut().zip(on) {
                    *a |= *w;
                }
            }
        }
        let mut grew = can_stand;
        while grew {
            grew = false;
            for (l, (lm, ls)) in m.levels.iter().zip(&run.levels).enumerate() {
                let (a, b) = lm.buildings;
                if (active[a] && active[b]) || (any_gone && run.level_dead(l)) {
                    continue;
                }
                let (d, r) = (lm.delta(z), lm.ddelta(n, z));
                let mut close = standing == Standing::Grown
                    && active[a] != active[b]
                    && d + 2.0 * r.max(0.0) * dt > 0.0;
                if !close {
                    if !bounded {
                        tangents.bounds(m, (&seg, z, &z1), &mut bounds, tangent_on);
                        bounded = true;
                    }
                    close = *may_touch[l]
                        .get_or_insert_with(|| lm.may_touch_bounded(n, &bounds, z, &z1, dt, ls.v0));
                }
                if close {
                    (active[a], active[b]) = (true, true);
                    grew = true;
                }
            }
        }
        if any_gone {
            for (a, &g) in active.iter_mut().zip(&run.gone) {
                *a &= !g;
            }
        }
        // The substep: the shortest any level asks for, and the moving structures' own rate.
        let rate = rates
            .iter()
            .zip(&active)
            .filter(|(_, &a)| a)
            .fold(0.0, |r, (x, _)| x.max(r));
        let h_rate_of = |d_est: f64, v0: f64, c: &crate::physics::contact::Contact| {
            2.0 * std::f64::consts::PI
                / o.substeps_per_contact
                / c.local_rate(2.0 * d_est, v0).max(rate)
        };
        let mut h = 2.0 * std::f64::consts::PI / o.substeps_per_contact / rate;
        if !any_contact {
            for ((lm, ls), may) in m.levels.iter().zip(&run.levels).zip(&may_touch) {
                if *may != Some(true) {
                    continue;
                }
                let v_est = 1.5 * lm.ddelta(n, z).abs().max(lm.ddelta(n, &z1).abs());
                let d_est = lm.delta(z).max(lm.delta(&z1));
                let a_est = lm
                    .structural_rel_accel(m, z)
                    .abs()
                    .max(lm.structural_rel_accel(m, &z1).abs());
                let c = &lm.contact;
                h = h.min(
                    impact_step(c, v_est, a_est, o.substeps_per_contact)
                        .min(h_rate_of(d_est, ls.v0, c)),
                );
            }
        } else {
            for (lm, ls) in m.levels.iter().zip(&run.levels) {
                if !(active[lm.buildings.0] && active[lm.buildings.1]) {
                    continue;
                }
                let c = &lm.contact;
                let (d, r) = (lm.delta(z), lm.ddelta(n, z));
                let a = lm.structural_rel_accel(m, z).abs();
                if ls.mode == Mode::Free {
                    // A free level beside a contact: size for its touch if it could close within
                    // the step at its present rate.
                    if d + 2.0 * r.max(0.0) * dt > 0.0 {
                        h = h.min(impact_step(c, 1.5 * r.abs(), a, o.substeps_per_contact));
                    }
                    continue;
                }
                let h_rate = h_rate_of(d, ls.v0, c);
                let sustained = seg.t0 - ls.t_onset > SUSTAINED * c.duration_estimate(ls.v0);
                h = h.min(if sustained {
                    h_rate
                } else {
                    impact_step(c, ls.v0.max(r.abs()), a, o.substeps_per_contact).min(h_rate)
                });
            }
        }
        let msub = (dt / h).ceil().max(1.0);
        if msub.is_nan() || msub > o.max_substeps_per_step as f64 {
            return finish(run, Status::StepLimit, substeps, tally);
        }
        let msub = msub as u32;
        let h = dt / msub as f64;
        let mut t = seg.t0;
        run.set_active(&active);
        moving.clone_from(&active);
        let any_still = active.iter().any(|a| !a);
        tally.still += (active.iter().zip(&run.gone))
            .filter(|(a, g)| !**a && !**g)
            .count() as u64;
        lookouts.clear();
        if any_still {
            if !bounded {
                tangents.bounds(m, (&seg, z, &z1), &mut bounds, tangent_on);
            }
            for (l, lm) in m.levels.iter().enumerate() {
                let (a, b) = lm.buildings;
                if active[a] != active[b] && !(any_gone && run.level_dead(l)) {
                    lookouts.push(Lookout::new(m, l, active[a], &bounds, z, &z1, dt));
                }
            }
        }
        if let Some(sub) = sub {
            run.enter_substeps(sub);
        }
        let sm = sub.unwrap_or(m);
        for j in 1..=msub {
            let t_target = if j == msub {
                seg.t1()
            } else {
                seg.t0 + j as f64 * h
            };
            let mut pieces = 0;
            while t_target - t > 1e-9 * h {
                substeps += 1;
                // Cut at the graded mesh after a touch, as the pair's scheme; such pieces do
                // not count against the cap on event cuts.
                let cut = run.onset_cut(t, o.substeps_per_contact, cut_tolerance(t, h));
                let hs = (t_target - t).min(cut);
                if hs == t_target - t {
                    pieces += 1;
                }
                if substeps > o.max_substeps || pieces > MAX_PIECES_PER_SUBSTEP {
                    return finish(run, Status::StepLimit, substeps, tally);
                }
                let (z0, trial) = loop {
                    let z0 = run.z.clone();
                    run.level_modes(&mut modes);
                    storey_modes.clone_from(&run.storey_modes);
                    let motion = Motion {
                        levels: &modes,
                        active: &moving,
                        energy: o.energy,
                        storeys: &storey_modes,
                    };
                    let trial = rk4(sm, &motion, &seg, t, &z0, hs, &mut stages);
                    // A building standing still that a moving neighbour may reach in this
                    // substep moves from its start on.
                    let Some(p) = lookouts
                        .iter()
                        .position(|w| w.may_close(sm, &z0, &trial, hs))
                    else {
                        break (z0, trial);
                    };
                    let lm = &m.levels[lookouts[p].level];
                    let k = if lookouts[p].left_moves {
                        lm.buildings.1
                    } else {
                        lm.buildings.0
                    };
                    tally.joined += 1;
                    run.activate(k, &seg, t);
                    moving.clone_from(&run.active);
                    lookouts.retain(|w| !run.level_on(w.level));
                    for (l, lm) in m.levels.iter().enumerate() {
                        let (a, b) = lm.buildings;
                        if (a == k || b == k)
                            && run.active[a] != run.active[b]
                            && !run.level_dead(l)
                        {
                            lookouts.push(Lookout::new(m, l, a == k, &bounds, z, &z1, dt));
                        }
                    }
                };
                let motion = Motion {
                    levels: &modes,
                    active: &moving,
                    energy: o.energy,
                    storeys: &storey_modes,
                };
                let step = |x: f64| rk4(sm, &motion, &seg, t, &z0, x, &mut stages);
                t += run.accept(
                    &seg,
                    t,
                    hs,
                    trial,
                    LOCATE_TOLERANCE,
                    LOCATE_ITERATIONS,
                    step,
                );
                if !run.z.iter().all(|x| x.is_finite()) {
                    return finish(run, Status::NonFinite, substeps, tally);
                }
                if run.active != moving {
                    // A building left the scene: it stands frozen from here on.
                    if run.all_gone() {
                        return finish(run, Status::Collapsed, substeps, tally);
                    }
                    moving.clone_from(&run.active);
                    lookouts.retain(|w| !run.level_dead(w.level));
                }
            }
            t = t_target;
        }
        run.leave_substeps();
        if any_still {
            run.finish_still(&seg, z, &z1, &work);
        }
    }
    finish(run, Status::Ok, substeps, tally)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::contact::LawKind;
    use crate::physics::row::Row;
    use crate::physics::shear::{Damping, ShearBuilding};
    use crate::physics::solver::row::sample::RowSample;

    /// Two tall buildings (one with a soft first storey) and a low one, `gaps` apart.
    fn row(gaps: Vec<f64>) -> RowModel {
        row_of(&[(8, 0.7, true), (6, 0.45, false), (2, 0.2, false)], gaps)
    }

    /// The largest relative difference between the floor-coordinate and modal substeps' runs
    /// of `m` (after checking they take the same substeps and impacts at every level), and the
    /// impacts.
    fn floors_against_modes(m: &RowModel) -> (f64, u32) {
        let sub = m
            .substep_model()
            .expect("two buildings of 4 storeys or more");
        assert_eq!(
            sub.buildings
                .iter()
                .map(|b| b.in_floors)
                .collect::<Vec<_>>(),
            [true, true, false]
        );
        let modal = run_on(m, None, Standing::Grown).0;
        let floors = run_on(m, Some(&sub), Standing::Grown).0;
        assert_eq!(floors.substeps, modal.substeps);
        compare(&floors, &modal)
    }

    /// A ground motion of three frequencies under a rising and decaying envelope, 8 s at
    /// 0.01 s, peak about 4.4 m/s^2 (physics knows no records).
    fn ground_motion() -> Vec<f64> {
        (0..800)
            .map(|i| {
                let t = i as f64 * 0.01;
                let envelope = (t / 1.5).min(1.0) * (-(t - 4.0).max(0.0) / 2.0).exp();
                let w = 2.0 * std::f64::consts::PI;
                envelope
                    * (2.5 * (w * 1.1 * t).sin()
                        + 1.5 * (w * 2.3 * t + 0.4).sin()
                        + 1.0 * (w * 0.7 * t + 1.3).sin())
            })
            .collect()
    }

    /// The largest relative difference between two runs of one row (after checking they end
    /// well and take the same impacts at every level), and the impacts.
    fn compare(floors: &RowOutput, modal: &RowOutput) -> (f64, u32) {
        assert_eq!(modal.status, Status::Ok);
        assert_eq!(floors.status, Status::Ok);
        let mut worst = 0.0f64;
        let mut diff = |a: f64, b: f64| {
            let d = (a - b).abs() / a.abs().max(b.abs()).max(1e-300);
            worst = worst.max(d);
        };
        for (a, b) in floors.levels.iter().zip(&modal.levels) {
            assert_eq!(a.impacts, b.impacts);
            diff(a.peak_force, b.peak_force);
            diff(a.peak_penetration, b.peak_penetration);
            diff(a.dissipated_energy, b.dissipated_energy);
        }
        for (a, b) in floors.buildings.iter().zip(&modal.buildings) {
            diff(a.peak_roof, b.peak_roof);
            diff(a.peak_drift_ratio, b.peak_drift_ratio);
            diff(a.peak_accel, b.peak_accel);
        }
        let (ea, eb) = (floors.energy.unwrap(), modal.energy.unwrap());
        diff(ea.input, eb.input);
        diff(ea.damping, eb.damping);
        assert!(ea.residual.abs() < 1e-6, "residual {}", ea.residual);
        (worst, modal.impacts)
    }

    /// The floor-coordinate right-hand side is the modal one in floor coordinates (every slot,
    /// energy terms included, with every level pressing), and the change of coordinates
    /// round-trips: the two are one ODE.
    #[test]
    fn floor_rhs_is_the_modal_rhs() {
        use crate::physics::solver::state::Mode;
        // Negative gaps: every level overlaps, so every level's force enters.
        let m = row(vec![-0.0005, -0.0005]);
        let sub = m.substep_model().unwrap();
        let len = m.len();
        let mut z: Vec<f64> = (0..len)
            .map(|i| ((i * 7919 % 113) as f64 / 113.0 - 0.5) * 0.01)
            .collect();
        z[2 * m.n..].fill(0.0);
        let mut y = z.clone();
        sub.modes_to_substeps(&mut y);
        let mut back = y.clone();
        sub.substeps_to_modes(&mut back);
        for (a, b) in z.iter().zip(&back) {
            assert!((a - b).abs() <= 1e-15, "round trip {a} {b}");
        }
        let levels: Vec<(Mode, f64)> = m.levels.iter().map(|_| (Mode::Approach, 0.5)).collect();
        for (lm, ls) in m.levels.iter().zip(&sub.levels) {
            assert!(lm.delta(&z) > 0.0);
            assert!((lm.delta(&z) - ls.delta(&y)).abs() < 1e-15);
        }
        let (mut fz, mut fy) = (vec![0.0; len], vec![0.0; len]);
        let motion = super::super::rhs::Motion {
            levels: &levels,
            active: &[true; 3],
            energy: true,
            storeys: &[],
        };
        super::super::rhs::rhs(&m, &motion, 0.7, &z, &mut fz);
        super::super::rhs::rhs(&sub, &motion, 0.7, &y, &mut fy);
        sub.modes_to_substeps(&mut fz);
        let scale = fy.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        for (i, (a, b)) in fz.iter().zip(&fy).enumerate() {
            assert!(
                (a - b).abs() <= 1e-12 * scale,
                "slot {i}: {a} (modes) {b} (floors)"
            );
        }
    }

    /// Contact substeps in floor coordinates against the modal substeps over whole runs: the
    /// same substeps and impacts at every level; over one impact, peaks and energy terms to
    /// rounding (within 1e-8, measured 8e-10); over many, within 1e-4 (the fast scheme's p99
    /// peak-force error at 64 substeps is 2.8e-4). They are one ODE (above) and RK4 is
    /// affine-invariant, but an event location that ends at its 16 iterations rather than its
    /// tolerance (a contact force's root is not smooth) lands where rounding moves it by up to
    /// 1e-8 s, and later impacts carry that on: measured 1.8e-5 over 102 impacts.
    #[test]
    fn floor_substeps_are_the_modal_substeps() {
        for (gap, impacts, tol) in [(0.11, 1..=1, 1e-8), (0.01, 50..=1000, 1e-4)] {
            let (worst, n) = floors_against_modes(&row(vec![gap, gap / 2.0]));
            assert!(impacts.contains(&n), "gap {gap}: {n} impacts");
            assert!(worst < tol, "gap {gap}: {worst:e} over {n} impacts");
        }
    }

    /// A row of `buildings` (storeys, period, soft first storey), `gaps` apart.
    fn row_of(buildings: &[(usize, f64, bool)], gaps: Vec<f64>) -> RowModel {
        let buildings = buildings
            .iter()
            .map(|&(n, period, soft)| {
                let mut profile = vec![1.0; n];
                if soft {
                    profile[0] = 0.4;
                }
                ShearBuilding::from_period(
                    vec![2.5e5; n],
                    &profile,
                    vec![3.0; n],
                    period,
                    Damping::Rayleigh(0.05),
                )
            })
            .collect();
        RowModel::new(&Row::new(
            buildings,
            gaps,
            LawKind::NonlinearViscoelastic,
            2.75e9,
            0.35,
        ))
    }

    /// One run of `m` under [`ground_motion`] with the energy kept, its substeps in `sub`'s
    /// coordinates.
    fn run_on(m: &RowModel, sub: Option<&RowModel>, standing: Standing) -> (RowOutput, Tally) {
        run_observed_on(m, sub, standing, None)
    }

    /// [`run_on`] with `observer` hearing every step and event.
    fn run_observed_on<'a>(
        m: &'a RowModel,
        sub: Option<&'a RowModel>,
        standing: Standing,
        observer: Option<RowObserver<'a>>,
    ) -> (RowOutput, Tally) {
        let accel = ground_motion();
        let forcing = Forcing {
            accel: &accel,
            dt: 0.01,
            t0: 0.0,
            scale: 1.0,
            tail: 1.0,
        };
        let o = FastOptions {
            energy: true,
            ..FastOptions::default()
        };
        run_with(
            m,
            sub,
            standing,
            &forcing,
            m.at_rest(),
            &o,
            Steps::Tangent,
            false,
            observer,
        )
    }

    /// [`run_on`] with the scheme's substep coordinates.
    fn run_standing(m: &RowModel, standing: Standing) -> (RowOutput, Tally) {
        run_on(m, m.substep_model().as_ref(), standing)
    }

    /// An observed run samples a building that stands still through the others' substeps by
    /// its exact free step to the sample's time: at the record steps' ends its floors are those
    /// of the same row with no contact anywhere (every step exact), to rounding; and observing
    /// changes no output.
    #[test]
    fn an_observer_samples_still_buildings_at_their_exact_motion() {
        let (a, b, c) = ((8, 0.7, true), (6, 0.45, false), (2, 0.2, false));
        let observe = |m: &RowModel| {
            let mut samples = Vec::new();
            let sub = m.substep_model();
            let mut hear = |s: &RowSample| samples.push(s.clone());
            let (out, tally) = run_observed_on(m, sub.as_ref(), Standing::Grown, Some(&mut hear));
            (out, tally, samples)
        };
        let triple = row_of(&[a, b, c], vec![0.01, 1.0]);
        let (out, tally, samples) = observe(&triple);
        assert!(tally.still > 100, "{tally:?}");
        let (unobserved, _) = run_standing(&triple, Standing::Grown);
        assert_eq!(format!("{out:?}"), format!("{unobserved:?}"));
        let (_, _, apart) = observe(&row_of(&[a, b, c], vec![1.0, 1.0]));
        let on_grid = |t: f64| ((t / 0.01).round() * 0.01 - t).abs() < 1e-9;
        let scale = apart
            .iter()
            .flat_map(|s| s.floors[2].iter())
            .fold(0.0f64, |m, u| m.max(u.abs()));
        let mut compared = 0;
        for s in samples.iter().filter(|s| on_grid(s.t)) {
            let twin = apart
                .iter()
                .find(|x| (x.t - s.t).abs() < 1e-9)
                .expect("every record step sampled");
            for (u, v) in s.floors[2].iter().zip(&twin.floors[2]) {
                assert!((u - v).abs() <= 1e-9 * scale, "t {}: {u} against {v}", s.t);
            }
            compared += 1;
        }
        assert!(compared > 400, "{compared} samples compared");
        assert!(samples.iter().any(|s| !on_grid(s.t)), "events sampled");
    }

    /// A building that no contact reaches stands still through the others' substeps and takes
    /// its exact free steps: its peaks are those of the same row with no contact anywhere, and
    /// the two that pound give the pair's run without it, to rounding.
    #[test]
    fn still_buildings_take_their_exact_free_steps() {
        let (a, b, c) = ((8, 0.7, true), (6, 0.45, false), (2, 0.2, false));
        let (triple, tally) = run_standing(&row_of(&[a, b, c], vec![0.01, 1.0]), Standing::Grown);
        let (pair, _) = run_standing(&row_of(&[a, b], vec![0.01]), Standing::Grown);
        let (apart, _) = run_standing(&row_of(&[a, b, c], vec![1.0, 1.0]), Standing::Grown);
        assert!(pair.impacts > 20, "{} impacts", pair.impacts);
        assert_eq!(apart.impacts, 0);
        assert!(tally.still > 100, "{tally:?}");
        let close = |x: f64, y: f64, what: &str| {
            let d = (x - y).abs() / x.abs().max(y.abs());
            assert!(d < 1e-12, "{what}: {x} {y} ({d:e})");
        };
        for (k, (x, y)) in [
            (0, &pair.buildings[0]),
            (1, &pair.buildings[1]),
            (2, &apart.buildings[2]),
        ]
        .into_iter()
        .map(|(k, y)| (k, (&triple.buildings[k], y)))
        {
            close(x.peak_roof, y.peak_roof, &format!("building {k} roof"));
            close(
                x.peak_drift_ratio,
                y.peak_drift_ratio,
                &format!("building {k} drift"),
            );
            close(x.peak_accel, y.peak_accel, &format!("building {k} accel"));
        }
        for (x, y) in triple.levels.iter().zip(&pair.levels) {
            assert_eq!(x.impacts, y.impacts);
            close(x.peak_force, y.peak_force, "force");
        }
        assert!(triple.levels[pair.levels.len()..]
            .iter()
            .all(|l| l.impacts == 0));
        let e = triple.energy.unwrap();
        assert!(e.residual.abs() < 1e-6, "residual {}", e.residual);
    }

    /// Buildings that stand still join the substeps when a moving neighbour may reach them:
    /// with the lookouts alone (`Watched`) and with the scheme's growth (`Grown`), a row whose
    /// every pair pounds takes the same impacts at every level as the whole row in substeps,
    /// with peaks within the scheme's error.
    #[test]
    fn still_buildings_join_where_a_neighbour_reaches_them() {
        let m = row(vec![0.01, 0.005]);
        let (whole, none) = run_standing(&m, Standing::None);
        assert_eq!(none.still, 0);
        for standing in [Standing::Watched, Standing::Grown] {
            let (out, tally) = run_standing(&m, standing);
            assert!(
                tally.still > 0 && tally.joined > 0,
                "{standing:?}: {tally:?}"
            );
            let (worst, impacts) = compare(&out, &whole);
            assert!(impacts > 50, "{impacts} impacts");
            // Measured 4.4e-5 over 102 impacts, both ways (the fast scheme's p99 peak-force
            // error at 64 substeps is 2.8e-4).
            assert!(
                worst < 2e-4,
                "{standing:?}: {worst:e} over {impacts} impacts ({tally:?})"
            );
        }
    }

    /// A free step's levels read their penetrations from the floors prepared for its peaks:
    /// the same products as from the modes (to the bit), and each building's coarse bound on
    /// its floors' fourth derivative is at least every one of its levels' own.
    #[test]
    fn prepared_free_ends_are_the_levels_penetrations() {
        let m = row(vec![0.01, 0.005]);
        let state = |seed: usize| {
            let mut z: Vec<f64> = (0..m.len())
                .map(|i| (((i + seed) * 7919 % 113) as f64 / 113.0 - 0.5) * 0.01)
                .collect();
            z[2 * m.n..].fill(0.0);
            z
        };
        let (z0, z1) = (state(3), state(17));
        let mut run = RowRun::start(&m, z0.clone(), 0.0);
        run.prepare_free_ends(&z0, &z1, (0.3, -0.2));
        let n = m.n;
        for (l, lm) in m.levels.iter().enumerate() {
            let ends = [
                lm.delta(&z0),
                lm.ddelta(n, &z0),
                lm.delta(&z1),
                lm.ddelta(n, &z1),
            ];
            assert_eq!(run.level_ends(l), ends, "level {l}");
        }
        let bounds: Vec<f64> = (0..n).map(|i| 1.0 + (i * 31 % 7) as f64).collect();
        let mut coarse = Vec::new();
        m.coarse_floor_bounds(&bounds, &mut coarse);
        for lm in &m.levels {
            let (a, b) = lm.buildings;
            assert!(coarse[a] + coarse[b] >= lm.fourth_derivative_bound(&bounds));
        }
    }
}
