//! What a row run hands its observer after every accepted step and event.

use crate::physics::imk::Branch;
use crate::physics::solver::state::Mode;

/// A point of a row's time history handed to an observer after every accepted step and
/// event (as the pair's [`super::Sample`]).
#[derive(Debug, Clone, PartialEq)]
pub struct RowSample {
    pub t: f64,
    /// Each building's floor displacements relative to the ground, m (lowest floor first).
    pub floors: Vec<Vec<f64>>,
    /// Each level's penetration (0 where apart), m, contact force, N, and contact mode.
    pub penetrations: Vec<f64>,
    pub forces: Vec<f64>,
    pub modes: Vec<Mode>,
    /// Each yielding storey, building by building (none in an elastic row).
    pub storeys: Vec<StoreySample>,
}

/// A yielding storey at a sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StoreySample {
    /// Its building and storey, from 0 (storey 0 joins the ground and the lowest floor).
    pub building: usize,
    pub storey: usize,
    /// Drift and plastic drift over the storey's height; its shear `k (d - p)`, N; the work
    /// its plastic drift has absorbed, `int f dp`, J (its hysteretic energy so far).
    pub drift_ratio: f64,
    pub plastic_drift_ratio: f64,
    pub shear_n: f64,
    pub hysteretic_energy_j: f64,
    /// An IMK storey's law at the sample (None: a bilinear storey).
    pub imk: Option<ImkSample>,
}

/// An IMK storey at a sample: its drift, m, the force its law gives there (its current piece's),
/// N, and the branch that piece is on.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImkSample {
    pub drift_m: f64,
    pub force_n: f64,
    pub branch: Branch,
}

/// What observes a row's run.
pub type RowObserver<'o> = &'o mut dyn FnMut(&RowSample);
