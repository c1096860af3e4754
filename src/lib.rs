//! pounding: earthquake-induced pounding between adjacent buildings, simulated in large sweeps.
//!
//! Layers, bottom up: [`record`] (ground motions), [`contact`] and [`restitution`] (the physics
//! of an impact), [`model`] and [`propagator`] (the scene and exact linear stepping), [`cpu`]
//! (integrators), [`plan`] (a validated sweep), [`config`] (TOML to plan), [`sweep`] (parallel
//! execution and streaming output).

pub mod accuracy;
pub mod aggregate;
pub mod bench;
pub mod config;
pub mod contact;
pub mod cpu;
pub mod fidelity;
pub mod fragility;
pub mod gpu;
pub mod journal;
pub mod limits;
pub mod model;
pub mod output;
pub mod paper;
pub mod parquet_out;
pub mod plan;
pub mod plot;
pub mod propagator;
pub mod record;
pub mod restitution;
pub mod sample;
pub mod sensitivity;
pub mod shard;
pub mod sweep;
pub mod sweep_output;
pub mod table;
pub mod target;

/// Print a line to standard error. A failed write (stderr closed, or on a full device) is
/// ignored, never a panic: diagnostics must not turn a good run into a crash.
pub fn note(line: impl std::fmt::Display) {
    use std::io::Write;
    let _ = writeln!(std::io::stderr(), "{line}");
}
