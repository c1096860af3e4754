//! Integration of one run of a row of shear buildings ([`crate::physics::row`]), in f64, in
//! modal coordinates: each building's motion is its mass-normalised modes `q`
//! ([`crate::physics::shear`]), so free flight is the exact propagator per mode and damping of
//! either classical kind is diagonal. A contact level adds its force to the modes of the two
//! floors it joins (`phi^T F`, `O(N)` per level).
//!
//! The state is `[q (n), q' (n), w (one per level), e_in, e_damp, p (one per yielding storey),
//! e_p (one per yielding storey)]`: all buildings' modal displacements, then velocities, each
//! level's contact work `w_l' = F_l delta_l'`, the input and damping work for the energy
//! balance, and each yielding storey's plastic drift and plastic work ([`yielding`]). Each level
//! has its own contact mode (free, approach, restitution) and impact speed, and each yielding
//! storey its spring state; an event is any of them ending, located on the largest of the
//! events that fire in the step.
//!
//! Two schemes, as for the pair ([`super`]): [`reference`](mod@reference) (adaptive
//! Dormand-Prince, the truth) and [`fast`] (exact modal free steps at the record's `dt`, RK4
//! substeps sized to the contact only in record steps where some level may touch, in floor
//! coordinates for the buildings whose damping allows it: `RowModel::substep_model`).
//!
//! By concern, bottom up (each file imports only those before it): `algebra` (the dot
//! product), `storey` (a yielding storey's model and spring state, its band's edges), `model`
//! (the row as the integrators see it), `levels` (a contact level's kinematics, force and
//! bounds, and each level's and storey's record), `rhs` (the right-hand side), `floors` (a
//! building's floor kinematics at an instant), `exact_step` (a building stepped exactly over a
//! free step), `sample` (what an observer hears), `run` (one run's state, the buildings that
//! move or stand still, free steps), `events` (events located and their transitions, a step
//! accepted), `outputs` (samples to an observer, peaks, the run's output), [`yielding`] (the
//! storeys' springs over a run, its settling tail), then the schemes; `tests` runs whole rows.

mod algebra;
mod events;
mod exact_step;
pub mod fast;
mod floors;
mod levels;
mod model;
mod outputs;
pub mod reference;
mod rhs;
mod run;
mod sample;
mod storey;
mod tangent;
pub mod yielding;

use crate::physics::model::Forcing;
use crate::physics::row::RowOutput;
pub use fast::RowFastOptions;
pub(crate) use model::BuildingModel;
pub use model::RowModel;
pub use sample::{ImkSample, RowObserver, RowSample, StoreySample};

impl RowScheme {
    pub fn key(&self) -> &'static str {
        match self {
            RowScheme::Fast(_) => "fast",
            RowScheme::Reference(_) => "reference",
        }
    }
}

/// Which scheme a row run uses.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum RowScheme {
    Fast(RowFastOptions),
    Reference(super::ReferenceOptions),
}

/// Would the row kernel watch this run for collapse under `collapse_limit` (a building's peak
/// drift ratio reached [`run::COLLAPSE_WATCH`] of it)? Such a run of a row that ran on the
/// pair's kernel, which does not model collapse, is run again on the row's.
pub fn near_collapse(out: &RowOutput, collapse_limit: f64) -> bool {
    let watch = run::COLLAPSE_WATCH * collapse_limit;
    out.buildings.iter().any(|b| b.peak_drift_ratio >= watch)
}

/// Simulate `m`'s buildings from rest as if no contact could ever act, tracking each level's
/// closing and its floors' peaks ([`RowOutput::closings`]; the separation of yielding
/// buildings). The levels' gaps must be beyond reach ([`UNCOUPLED_GAP_M`]). The fast scheme
/// moves every building in every substep here, so that both floors of a level share each
/// piece.
pub fn simulate_uncoupled(m: &RowModel, forcing: &Forcing, scheme: &RowScheme) -> RowOutput {
    match scheme {
        RowScheme::Fast(o) => fast::run_uncoupled(m, forcing, o),
        RowScheme::Reference(o) => reference::run_tracked(m, forcing, m.at_rest(), o, true, None),
    }
}

/// The gap given each level of a row simulated uncoupled: far beyond any floor's reach (a run
/// that closes it reports impacts, which the caller refuses).
pub const UNCOUPLED_GAP_M: f64 = 1e6;

/// Simulate one run of a row from state `z0` (see [`RowModel::at_rest`],
/// [`RowModel::state_of_floors`]) over the forcing's whole duration.
pub fn simulate_row(
    m: &RowModel,
    forcing: &Forcing,
    z0: Vec<f64>,
    scheme: &RowScheme,
) -> RowOutput {
    simulate(m, forcing, z0, scheme, None)
}

/// As [`simulate_row`] (the same output), handing `observer` the row after every accepted step
/// and event.
pub fn simulate_row_observed(
    m: &RowModel,
    forcing: &Forcing,
    z0: Vec<f64>,
    scheme: &RowScheme,
    observer: RowObserver<'_>,
) -> RowOutput {
    simulate(m, forcing, z0, scheme, Some(observer))
}

fn simulate<'a>(
    m: &'a RowModel,
    forcing: &Forcing,
    z0: Vec<f64>,
    scheme: &RowScheme,
    observer: Option<RowObserver<'a>>,
) -> RowOutput {
    match scheme {
        RowScheme::Fast(o) => fast::run(m, forcing, z0, o, observer),
        RowScheme::Reference(o) => reference::run_tracked(m, forcing, z0, o, false, observer),
    }
}

#[cfg(test)]
mod tests;
