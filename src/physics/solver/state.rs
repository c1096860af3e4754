//! The pair's state and its right-hand side, shared by every scheme: the state vector, the
//! contact mode, the ground's segment between two record samples, the penetration, the
//! contact force and its rate, and the step that resolves an impact.

use crate::physics::contact::Contact;
use crate::physics::model::{Forcing, Pair};

/// `[u1, v1, u2, v2, w, e_in, e_damp]`: displacements and velocities, then the contact work
/// `w' = F delta'`, the input work `e_in' = -ag (m1 v1 + m2 v2)` and the structural damping work
/// `e_damp' = c1 v1^2 + c2 v2^2`. The last two ride along for the energy balance; error control
/// and events look only at the first five.
pub type State = [f64; 7];

/// Contact mode; changes only at located events.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Mode {
    #[default]
    Free,
    Approach,
    Restitution,
}

/// A point handed to an observer after every accepted step and event.
#[derive(Debug, Clone, Copy)]
pub struct Sample {
    pub t: f64,
    pub z: State,
    pub force: f64,
    pub mode: Mode,
}

/// Ground acceleration over one record interval: linear from `a0` at `t0` to `a1` at `t0 + dt`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Segment {
    pub t0: f64,
    pub dt: f64,
    pub a0: f64,
    pub a1: f64,
}

impl Segment {
    pub fn of(forcing: &Forcing, i: usize) -> Segment {
        Segment {
            t0: forcing.t0 + i as f64 * forcing.dt,
            dt: forcing.dt,
            a0: forcing.sample(i),
            a1: forcing.sample(i + 1),
        }
    }
    #[inline]
    pub fn at(&self, t: f64) -> f64 {
        self.a0 + (self.a1 - self.a0) * ((t - self.t0) / self.dt)
    }
    pub fn t1(&self) -> f64 {
        self.t0 + self.dt
    }
}

#[inline]
pub(crate) fn delta(p: &Pair, z: &State) -> f64 {
    z[0] - z[2] - p.gap
}

#[inline]
pub(crate) fn ddelta(z: &State) -> f64 {
    z[1] - z[3]
}

/// Contact force in `mode`.
#[inline]
pub(crate) fn force(p: &Pair, mode: Mode, v0: f64, z: &State) -> f64 {
    match mode {
        Mode::Free => 0.0,
        _ => p
            .contact
            .force(delta(p, z), ddelta(z), v0, mode == Mode::Approach),
    }
}

/// The rate of [`force`] at `z` in `mode` (the relative acceleration from the structures and
/// the contact force itself; the ground's acceleration moves both bodies alike).
#[inline]
pub(crate) fn force_rate(p: &Pair, mode: Mode, v0: f64, z: &State, f: f64) -> f64 {
    match mode {
        Mode::Free => 0.0,
        _ => {
            let a = structural_rel_accel(p, z) - f * (1.0 / p.b1.m + 1.0 / p.b2.m);
            p.contact
                .force_rate(delta(p, z), ddelta(z), a, v0, mode == Mode::Approach)
        }
    }
}

// Always inlined: with the energy terms it grew past the inliner's threshold, and the call
// cost 25 % of the CPU fast path's runs/s. `inv_m` holds the masses' reciprocals, computed
// once per step by the caller.
#[inline(always)]
pub(crate) fn rhs(p: &Pair, mode: Mode, v0: f64, ag: f64, inv_m: [f64; 2], z: &State) -> State {
    let f = force(p, mode, v0, z);
    let (b1, b2) = (&p.b1, &p.b2);
    [
        z[1],
        (-b1.c * z[1] - b1.k * z[0] - f) * inv_m[0] - ag,
        z[3],
        (-b2.c * z[3] - b2.k * z[2] + f) * inv_m[1] - ag,
        f * ddelta(z),
        -ag * (b1.m * z[1] + b2.m * z[3]),
        b1.c * z[1] * z[1] + b2.c * z[3] * z[3],
    ]
}

/// Each building's absolute acceleration (relative plus the ground's) at `z` under contact
/// force `f`: `-(c v + k u + f) / m1` and `-(c v + k u - f) / m2`.
#[inline]
pub(crate) fn structural_accel(p: &Pair, z: &State, f: f64) -> [f64; 2] {
    let (b1, b2) = (&p.b1, &p.b2);
    [
        (-b1.c * z[1] - b1.k * z[0] - f) / b1.m,
        (-b2.c * z[3] - b2.k * z[2] + f) / b2.m,
    ]
}

/// Relative acceleration `delta''` from the structures alone (the ground motion cancels).
#[inline]
pub(crate) fn structural_rel_accel(p: &Pair, z: &State) -> f64 {
    let (b1, b2) = (&p.b1, &p.b2);
    -(b1.c * z[1] + b1.k * z[0]) / b1.m + (b2.c * z[3] + b2.k * z[2]) / b2.m
}

/// Step that resolves an impact at approach speed `v` with `per_contact` steps. The impact
/// lasts the free-collision duration `t_c(v)`, or less when the structures reverse the relative
/// motion first (about `2 v / |a|` for a relative deceleration `a`); the kinematic bound is
/// floored at `t_c / 16` so a grazing touch cannot ask for unbounded steps.
pub(crate) fn impact_step(c: &Contact, v: f64, a: f64, per_contact: f64) -> f64 {
    let tc = c.duration_estimate(v);
    let tk = if a != 0.0 {
        2.0 * v / a.abs()
    } else {
        f64::INFINITY
    };
    let t = tc.min(tk.max(tc / 16.0));
    t / (per_contact * (1.0 + 2.0 * c.damping_ratio))
}

pub(crate) fn finite(z: &State) -> bool {
    z.iter().all(|x| x.is_finite())
}
