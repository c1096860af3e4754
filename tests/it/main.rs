//! Integration tests: one binary, one module per area.

mod accuracy;
pub mod cli;
mod config;
pub mod fast_vs_reference;
mod fidelity;
mod gpu;
mod hard;
mod hostile;
mod oracles;
mod records;
mod scale;
mod studies;
mod support;
