//! One isolated collision of two free bodies, solved with the reference scheme: what the
//! `exact` restitution formula root-finds on, and what `pound restitution` and `pound
//! hysteresis` report.

use super::reference::{self, ReferenceOptions};
use super::state::{Mode, Sample};
use crate::physics::contact::Contact;
use crate::physics::model::{Forcing, Initial, Oscillator, Pair, Status};

/// Result of one isolated collision of two free bodies (NaN fields if the solve failed).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Collision {
    /// `-delta'_out / delta'_in`
    pub e: f64,
    pub peak_force: f64,
    pub peak_penetration: f64,
    pub duration: f64,
    pub dissipated: f64,
}

/// Tolerance of the single-collision solves behind the `exact` formula.
pub const EXACT_RTOL: f64 = 1e-11;

/// Two free bodies (masses `2 m_eff` each) meeting at relative speed `v0` with `contact`; solved
/// with the reference scheme at `rtol` until they separate.
pub fn single_collision(contact: &Contact, v0: f64, rtol: f64) -> Collision {
    single_collision_observed(contact, v0, rtol, 20.0, &mut |_| {})
}

/// As [`single_collision`], with at least `contact_steps` steps per estimated contact duration,
/// calling `observer` after every step (body 1 starts at `u1 = 0` touching body 2, so
/// `delta = u1 - u2`).
pub fn single_collision_observed(
    contact: &Contact,
    v0: f64,
    rtol: f64,
    contact_steps: f64,
    observer: &mut dyn FnMut(&Sample),
) -> Collision {
    let m = 2.0 * contact.m_eff;
    let pair = Pair {
        b1: Oscillator::free(m),
        b2: Oscillator::free(m),
        gap: 0.0,
        contact: *contact,
    };
    let tc = contact.duration_estimate(v0);
    let horizon = tc * 200.0 * (1.0 + contact.damping_ratio);
    let zeros = [0.0, 0.0];
    let forcing = Forcing {
        accel: &zeros,
        dt: horizon,
        t0: 0.0,
        scale: 0.0,
        tail: 0.0,
    };
    let init = Initial {
        u1: 0.0,
        v1: 0.5 * v0,
        u2: 0.0,
        v2: -0.5 * v0,
    };
    let opts = ReferenceOptions {
        rtol,
        contact_steps,
        max_steps: 50_000_000,
    };
    let mut last = [0.0; 7];
    let mut separated = false;
    let mut obs = |s: &Sample| {
        last = s.z;
        separated = s.mode == Mode::Free;
        observer(s);
    };
    let out = reference::run(
        &pair,
        &forcing,
        &init,
        &opts,
        Some(&mut obs),
        Some(1),
        false,
    );
    if out.status != Status::Ok {
        return Collision {
            e: f64::NAN,
            peak_force: f64::NAN,
            peak_penetration: f64::NAN,
            duration: f64::NAN,
            dissipated: f64::NAN,
        };
    }
    Collision {
        // Overdamped Kelvin-Voigt never lets go: the bodies creep together until the horizon.
        e: if separated {
            -(last[1] - last[3]) / v0
        } else {
            0.0
        },
        peak_force: out.peak_force,
        peak_penetration: out.peak_penetration,
        duration: out.contact_time,
        dissipated: out.dissipated_energy,
    }
}
