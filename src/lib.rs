//! pounding: earthquake-induced pounding between adjacent buildings, simulated in large sweeps.
//!
//! The data path, in the order of the folders:
//!
//! ```text
//! TOML config --config--> raw sections --plan::config--> Plan (a pair or a row)
//!     --engine::Engine (cpu | gpu), with the kernels the scene takes (engine::Kernel)-->
//!     chunks of runs --io--> CSV / Parquet / summary with sidecar (a sweep's stages: sweep)
//!     --studies--> tables and plots
//! ```
//!
//! One path for every scene: the config reader is the one place a config's kind is told, and
//! [`engine::Kernel::of`] the one place the kernels are chosen (the pair kernels for two
//! one-storey buildings, the row kernels otherwise); commands hold a [`plan::Plan`].
//!
//! - [`physics`]: one run in f64: buildings, contact laws, restitution, free stepping, solvers;
//! - [`record`]: ground motions, read from files or synthesised, and their intensity measures;
//! - [`config`]: a TOML config as written (plain data: its sections, their parsing, errors in
//!   the config's words: file, key, what was expected), knowing nothing of plans;
//! - [`plan`]: a validated sweep of a pair or a row ([`plan::Plan`]), decoded from a config,
//!   its intensity axis, its columns and their meanings, samples, shards and input bounds;
//! - [`engine`]: the one enum that runs a range of any plan on the CPU or the GPU (`shaders/`);
//! - [`io`]: outputs that are never destroyed nor called complete when they are not;
//! - [`sweep`]: one sweep as the command line and the Python package both run it: options
//!   checked, the config settled into a plan, engine and columns, the runs into a file or a
//!   table in memory;
//! - [`studies`]: accuracy, benchmarks, fidelity, fragility (damage states, bootstrap bands), IDA,
//!   the gap study, sensitivity, the seed paper, plots.
//!
//! Each layer imports only those above it in this list (the command line, `src/cli/`, sits on
//! top of them all, in the binary).

pub mod config;
pub mod engine;
pub mod io;
pub mod physics;
pub mod plan;
pub mod record;
pub mod studies;
pub mod sweep;

/// A number as a message or a record command shows it: as typed (shortest round trip) for
/// ordinary magnitudes, in exponent form beyond (`1e300`, not three hundred digits). At crate
/// root so the records, below the plans, show numbers as the plans do.
pub fn show(x: f64) -> String {
    let a = x.abs();
    if a == 0.0 || !a.is_finite() || (1e-4..1e15).contains(&a) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

/// A number derived by arithmetic (a sample interval from a time column's differences), as
/// [`show`] draws it once rounded to 12 significant digits: `0.02`, not the
/// `0.019999999999999997` that `0.04 - 0.02` leaves. Values as typed keep [`show`].
pub fn show_derived(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return show(x);
    }
    let rounded: f64 = format!("{x:.11e}").parse().unwrap_or(x);
    show(rounded)
}

/// `x` to `places` decimals where that reads (a table's fixed columns), in exponent form with
/// as many beyond, as [`show`] draws the line: bounded however large or small `x` is.
pub fn show_places(x: f64, places: usize) -> String {
    let a = x.abs();
    if a == 0.0 || !a.is_finite() || (1e-4..1e15).contains(&a) {
        format!("{x:.places$}")
    } else {
        format!("{x:.places$e}")
    }
}

/// Print a line to standard error. A failed write (stderr closed, or on a full device) is
/// ignored, never a panic: diagnostics must not turn a good run into a crash.
pub fn note(line: impl std::fmt::Display) {
    use std::io::Write;
    let _ = writeln!(std::io::stderr(), "{line}");
}
