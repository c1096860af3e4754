//! The production scheme. Steps follow the record's samples `t_i = t0 + i dt`:
//!
//! 1. While the buildings are apart, each record step is taken with the exact propagator of each
//!    oscillator under the piecewise-linear ground motion ([`crate::physics::propagator`]): no truncation
//!    error and one multiply-add per coefficient.
//! 2. The step is kept unless contact may occur inside it: the cubic Hermite interpolant of the
//!    penetration `delta` over the step (exact ends, exact slopes) comes within twice its error
//!    bound of 0, or a body already overlaps.
//! 3. Such a step (and every step while in contact) is redone with `M` fixed RK4 substeps, where
//!    `M dt` resolves an impact with about `substeps_per_contact` substeps (`impact_step`: the
//!    shorter of the free-collision duration at the approach speed, estimated from the step's end
//!    velocities or the current impact's `v0`, and the time the structures take to reverse the
//!    relative motion), and keeps RK4 stable at the current penetration
//!    ([`crate::physics::contact::Contact::local_rate`]) and at the structures' own rate
//!    ([`crate::physics::model::Pair::structural_rate`]). A contact that has lasted [`SUSTAINED`] contact
//!    durations is no longer an impact to resolve: only the local-rate bound applies. Inside a
//!    substep, the instants of first touch, of the turn `delta' = 0` and of separation are
//!    located by regula falsi on re-taken partial RK4 steps, so no substep integrates across a
//!    kink of the force; the substep grid stays aligned with the record step.
//! 4. The peak force of each impact is the largest of the cubic Hermites of the force through
//!    each contact piece's ends (values and rates, `tracker::raise_force_peak`); the peak penetration and the
//!    peak displacements are maxima of the Hermite cubics of each step, except over free record
//!    steps, where peak displacements come from the quintic Hermite (the accelerations at both
//!    ends are known; the cubic's `(omega dt)^4 / 384` error was 5e-3 at T = 0.1 s, dt = 0.02 s).
//!
//! Cost is therefore one cheap exact step per record sample for runs that never pound, plus
//! `M` RK4 substeps only for the record steps near or in contact. With a shared free response
//! ([`super::shared`]) a run also skips the steps before its first possible contact, settles
//! most free steps with a comparison, and ends early, all with the same output.

use super::events::may_touch;
pub use super::events::{LOCATE_BISECTIONS, LOCATE_ITERATIONS, LOCATE_TOLERANCE};
use super::shared::FreeResponse;
use super::state::{
    ddelta, delta, finite, impact_step, structural_rel_accel, Mode, Sample, Segment, State,
};
use super::tracker::Integration;
use crate::physics::model::{Forcing, Initial, Pair, RunOutput, Status};
use crate::physics::propagator::{EnergyForms, Propagator};

/// Accuracy and safety settings of the fast scheme.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FastOptions {
    /// RK4 substeps per estimated contact duration (the accuracy setting; by default 16, the
    /// cheapest whose p99 peak-force error on the accuracy suite is at most
    /// [`super::calibration::DEFAULT_TARGET_ERROR`] with every impact count as the
    /// reference's).
    pub substeps_per_contact: f64,
    /// A record step that would need more substeps than this ends the run with `step_limit`.
    pub max_substeps_per_step: u32,
    /// Substep budget of one run (u32 as on the GPU).
    pub max_substeps: u32,
    /// Integrate the input and damping work over free steps too, and report the energy
    /// balance ([`crate::physics::model::EnergyBalance`]).
    pub energy: bool,
}

/// An impact that has lasted this many estimated contact durations is a sustained contact: the
/// buildings stay pressed together and move with the structures, so the step need only resolve
/// the contact's local rate (`h_rate`), not a fresh impact.
pub const SUSTAINED: f64 = 2.0;

/// Accepted pieces one substep may be cut into by events before the run ends with
/// `step_limit` (a guard against a stalled event search; the shader has the same cap).
pub const MAX_PIECES_PER_SUBSTEP: u32 = 64;

impl Default for FastOptions {
    fn default() -> Self {
        FastOptions {
            substeps_per_contact: 16.0,
            max_substeps_per_step: 1 << 20,
            max_substeps: 1 << 30,
            energy: false,
        }
    }
}

/// Classic RK4 over `h` from `(t, z)` in `mode`.
#[inline]
pub(crate) fn rk4(
    p: &Pair,
    mode: Mode,
    v0: f64,
    seg: &Segment,
    t: f64,
    z: &State,
    h: f64,
) -> State {
    // Three ground samples and the masses' reciprocals once per call, off the stages'
    // dependency chain (7 % of the bench sweep's CPU time).
    let slope = (seg.a1 - seg.a0) / seg.dt;
    let tau = t - seg.t0;
    let ag = [
        seg.a0 + slope * tau,
        seg.a0 + slope * (tau + 0.5 * h),
        seg.a0 + slope * (tau + h),
    ];
    let inv_m = [1.0 / p.b1.m, 1.0 / p.b2.m];
    let f = |ag: f64, y: &State| super::state::rhs(p, mode, v0, ag, inv_m, y);
    let add = |y: &State, k: &State, s: f64| -> State { std::array::from_fn(|i| y[i] + s * k[i]) };
    let k1 = f(ag[0], z);
    let k2 = f(ag[1], &add(z, &k1, 0.5 * h));
    let k3 = f(ag[1], &add(z, &k2, 0.5 * h));
    let k4 = f(ag[2], &add(z, &k3, h));
    std::array::from_fn(|i| z[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]))
}

/// The shortest piece a graded cut may make at time `t` in substeps of `h`: a billionth of
/// the substep, and more than the resolution of `t` (a shorter piece would not move the time
/// on, and the substep would never end).
#[inline]
pub(crate) fn cut_tolerance(t: f64, h: f64) -> f64 {
    (1e-9 * h).max(8.0 * f64::EPSILON * t.abs())
}

/// A free run checks whether it can end early (the shared response's `can_end`) every this
/// many record steps: the check costs about a tenth of a free step.
const END_CHECK_EVERY: usize = 8;

/// One run; `accel`: track each building's peak absolute acceleration too.
pub(crate) fn run(
    pair: &Pair,
    forcing: &Forcing,
    init: &Initial,
    o: &FastOptions,
    shared: Option<&FreeResponse>,
    observer: Option<&mut dyn FnMut(&Sample)>,
    accel: bool,
) -> RunOutput {
    // The shortcuts keep every output but the energy integrals and the observer's samples.
    let shared = shared.filter(|s| {
        !o.energy && observer.is_none() && s.serves(pair, forcing, init) && s.accel() == accel
    });
    let dt = forcing.dt;
    let (p1, p2) = (Propagator::new(&pair.b1, dt), Propagator::new(&pair.b2, dt));
    let forms = o.energy.then(|| {
        (
            EnergyForms::new(&pair.b1, dt),
            EnergyForms::new(&pair.b2, dt),
        )
    });
    let mut run = Integration::start(pair, init, forcing.t0, observer);
    run.energy = o.energy;
    run.tr.accel = accel;
    let mut substeps: u32 = 0;
    let n = forcing.intervals();
    let mut first = 0;
    if let Some(sh) = shared.filter(|_| run.mode == Mode::Free) {
        first = sh.first_possible_contact(pair.gap);
        let (z, peaks) = sh.at(first);
        run.z = z;
        run.tr.resume_free(first as u64, peaks);
    }
    // While the run steps free with the exact propagator, its distance from the shared motion
    // (`FreeResponse::distance`); None after any other step.
    let mut distance: Option<[f64; 2]> = None;
    for i in first..n {
        let pa = run.tr.out.peak_accel;
        let peaks = [run.tr.out.peak_u1, run.tr.out.peak_u2, pa[0], pa[1]];
        if let Some(sh) = shared.filter(|_| run.mode == Mode::Free) {
            if distance.is_none() || i % END_CHECK_EVERY == 0 {
                let r = sh.distance(i, &run.z);
                if sh.can_end(i, r, pair.gap, peaks) {
                    run.tr.out.shared_steps += (n - i) as u64;
                    break;
                }
                distance = Some(r);
            }
        }
        let seg = Segment::of(forcing, i);
        let z = run.z;
        let (v_est, d_est, a_est) = if run.mode == Mode::Free {
            let (u1, v1) = p1.step(z[0], z[1], seg.a0, seg.a1);
            let (u2, v2) = p2.step(z[2], z[3], seg.a0, seg.a1);
            let mut z1 = [u1, v1, u2, v2, z[4], z[5], z[6]];
            // The shared response settles most free steps with a comparison or three; the
            // rest take the full test and peak search.
            let (clear, settled) = match (shared, distance) {
                (Some(sh), Some(r)) if sh.clears(i, r, pair.gap) => {
                    (true, sh.peaks_settled(i, r, peaks))
                }
                _ => (false, [false; 4]),
            };
            if clear || !may_touch(pair, &seg, &z, &z1, dt, run.tr.v0) {
                if let Some((f1, f2)) = &forms {
                    let (vv1, agv1) = f1.integrals(z[0], z[1], seg.a0, seg.a1);
                    let (vv2, agv2) = f2.integrals(z[2], z[3], seg.a0, seg.a1);
                    z1[5] -= pair.b1.m * agv1 + pair.b2.m * agv2;
                    z1[6] += pair.b1.c * vv1 + pair.b2.c * vv2;
                }
                run.free_step(&seg, z1, settled);
                if !finite(&run.z) {
                    return run.finish(Status::NonFinite, substeps as u64);
                }
                continue;
            }
            let a = structural_rel_accel(pair, &z).abs();
            (
                1.5 * ddelta(&z).abs().max(ddelta(&z1).abs()),
                delta(pair, &z).max(delta(pair, &z1)),
                a.max(structural_rel_accel(pair, &z1).abs()),
            )
        } else {
            let a = structural_rel_accel(pair, &z).abs();
            (run.tr.v0.max(ddelta(&z).abs()), delta(pair, &z), a)
        };
        // Resolve an impact at v_est, and stay stable at the current penetration (twice it, as
        // it may grow within the step).
        let h_rate = 2.0 * std::f64::consts::PI
            / o.substeps_per_contact
            / pair
                .contact
                .local_rate(2.0 * d_est, run.tr.v0)
                .max(pair.structural_rate());
        let sustained = run.mode != Mode::Free
            && seg.t0 - run.tr.onset_time() > SUSTAINED * pair.contact.duration_estimate(run.tr.v0);
        let h = if sustained {
            h_rate
        } else {
            impact_step(&pair.contact, v_est, a_est, o.substeps_per_contact).min(h_rate)
        };
        distance = None;
        let m = (dt / h).ceil().max(1.0);
        if m.is_nan() || m > o.max_substeps_per_step as f64 {
            return run.finish(Status::StepLimit, substeps as u64);
        }
        let m = m as u32;
        let h = dt / m as f64;
        let mut t = seg.t0;
        for j in 1..=m {
            let t_target = if j == m {
                seg.t1()
            } else {
                seg.t0 + j as f64 * h
            };
            let mut pieces = 0;
            while t_target - t > 1e-9 * h {
                substeps += 1;
                // Cut at the graded mesh after a touch (`Contact::onset_cut`); such pieces
                // do not count against the cap on event cuts.
                let mut hs = t_target - t;
                if run.mode == Mode::Approach {
                    let since = t - run.tr.onset_time();
                    hs = hs.min(pair.contact.onset_cut(
                        since,
                        run.tr.v0,
                        o.substeps_per_contact,
                        cut_tolerance(t, h),
                    ));
                }
                if hs == t_target - t {
                    pieces += 1;
                }
                if substeps > o.max_substeps || pieces > MAX_PIECES_PER_SUBSTEP {
                    return run.finish(Status::StepLimit, substeps as u64);
                }
                let (z0, mode, v0) = (run.z, run.mode, run.tr.v0);
                let step = |x: f64| rk4(pair, mode, v0, &seg, t, &z0, x);
                let (tol, iters) = (LOCATE_TOLERANCE, LOCATE_ITERATIONS);
                t += run.accept(&seg, t, hs, step(hs), tol, iters, step);
                if !finite(&run.z) {
                    return run.finish(Status::NonFinite, substeps as u64);
                }
            }
            t = t_target;
        }
    }
    run.finish(Status::Ok, substeps as u64)
}
