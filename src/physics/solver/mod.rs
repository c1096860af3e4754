//! CPU integration of one run, in f64. Two schemes share the machinery here:
//!
//! - [`fast`] (production): exact linear stepping at the record's `dt` while the buildings are
//!   apart, fixed RK4 substeps sized to the contact duration only in record steps where a contact
//!   may happen.
//! - [`reference`](mod@reference) (truth): adaptive Dormand-Prince 5(4) with error control,
//!   steps that never cross a record sample (where `ag` has kinks), and a cap on the step in
//!   contact.
//!
//! Both locate every non-smooth instant inside the step (first touch `delta = 0`, the turn
//! `delta' = 0`, separation at `delta = 0` or `F = 0`) by regula falsi on re-taken partial
//! steps (`events.rs`), so each step integrates a smooth right-hand side. The contact work
//! `w' = F delta'` rides along as a fifth state so the dissipated energy is integrated to the
//! scheme's own order. `tracker.rs` keeps peaks and impacts, `hermite.rs` the peaks between
//! samples, [`shared`] the free response that runs differing only in gap and contact share;
//! [`collision`] solves one isolated collision (the `exact` restitution formula).
//! `shaders/fast.wgsl` is the GPU twin of [`fast`], function for function.

pub mod calibration;
pub mod collision;
mod events;
pub mod fast;
pub(crate) mod hermite;
pub mod reference;
pub mod row;
pub mod separation;
pub mod shared;
pub(crate) mod state;
mod tracker;

pub use collision::{single_collision, single_collision_observed, Collision, EXACT_RTOL};
pub use fast::FastOptions;
pub use reference::ReferenceOptions;
pub use shared::FreeResponse;
pub use state::{Mode, Sample, State};

use crate::physics::model::{Forcing, Initial, Pair, RunOutput};

/// Which integration scheme a run uses.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Scheme {
    Fast(FastOptions),
    Reference(ReferenceOptions),
}

impl Scheme {
    pub fn key(&self) -> &'static str {
        match self {
            Scheme::Fast(_) => "fast",
            Scheme::Reference(_) => "reference",
        }
    }
}

/// Simulate one run from rest (or from `init`) over the forcing's whole duration.
pub fn simulate(pair: &Pair, forcing: &Forcing, init: &Initial, scheme: &Scheme) -> RunOutput {
    simulate_observed(pair, forcing, init, scheme, None)
}

/// As [`simulate`], calling `observer` after every step.
pub fn simulate_observed(
    pair: &Pair,
    forcing: &Forcing,
    init: &Initial,
    scheme: &Scheme,
    observer: Option<&mut dyn FnMut(&Sample)>,
) -> RunOutput {
    match scheme {
        Scheme::Fast(o) => fast::run(pair, forcing, init, o, None, observer, false),
        Scheme::Reference(o) => reference::run(pair, forcing, init, o, observer, None, false),
    }
}

/// As [`simulate`], with the shared free response of the run's buildings under `forcing`
/// ([`shared`]): the fast scheme starts at the first possible contact and may end early, with
/// the same output. A response that does not serve this run (other buildings or forcing, an
/// initial state other than rest), energy balances and the reference scheme ignore it.
pub fn simulate_shared(
    pair: &Pair,
    forcing: &Forcing,
    init: &Initial,
    scheme: &Scheme,
    shared: &FreeResponse,
) -> RunOutput {
    match scheme {
        Scheme::Fast(o) => fast::run(pair, forcing, init, o, Some(shared), None, false),
        Scheme::Reference(o) => reference::run(pair, forcing, init, o, None, None, false),
    }
}

/// A run of the fast scheme from rest that also tracks each building's peak absolute
/// acceleration ([`RunOutput::peak_accel`]), as a row's buildings report it: how a row of two
/// one-storey elastic buildings runs on the pair's kernel. `shared`: a free response of its
/// buildings built [`FreeResponse::with_accel`] (one that does not serve it, or a run with an
/// `observer`, steps the whole record instead: the same output).
pub fn simulate_tracking_accel(
    pair: &Pair,
    forcing: &Forcing,
    o: &FastOptions,
    shared: Option<&FreeResponse>,
    observer: Option<&mut dyn FnMut(&Sample)>,
) -> RunOutput {
    fast::run(
        pair,
        forcing,
        &Initial::default(),
        o,
        shared,
        observer,
        true,
    )
}

/// As [`simulate_tracking_accel`], under the reference scheme (the truth its accelerations are
/// checked against).
pub fn simulate_reference_tracking_accel(
    pair: &Pair,
    forcing: &Forcing,
    o: &ReferenceOptions,
) -> RunOutput {
    reference::run(pair, forcing, &Initial::default(), o, None, None, true)
}
