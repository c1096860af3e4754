//! Integration tests: one binary, one module per area.

mod cli;
mod config;
mod fast_vs_reference;
mod oracles;
mod records;
mod support;
