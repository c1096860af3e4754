//! Integration tests: one binary, one module per area.

mod accuracy;
mod cli;
mod config;
mod convergence;
mod damage;
mod fast_vs_reference;
mod fidelity;
mod figures;
mod gap;
mod gpu;
mod gpu_rows;
mod hard;
mod hostile;
mod inelastic;
mod intensity;
mod layers;
pub mod multistorey;
mod oracles;
mod records;
mod row_sweeps;
mod scale;
mod scenes;
mod shared;
mod start;
mod studies;
pub mod support;
mod trace;
