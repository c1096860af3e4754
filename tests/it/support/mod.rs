//! Every helper the integration tests share: temp dirs, a diffing text comparison, the records
//! dir, scene builders and collected sweeps here; running `pound` in [`run`]; the shared GPU
//! device and GPU comparisons in [`gpu`].

pub mod cli;
pub mod gpu;
pub mod run;

pub use gpu::{ctx, gpu_collect, gpu_run, grazing_contacts, peak_diff};
pub use run::{
    ok, pound, pound_with_file_limit, pound_with_file_limit_env, pound_with_outputs, sweep_cpu,
    table,
};

use pounding::physics::contact::{Contact, LawKind};
use pounding::physics::model::RunOutput;
use pounding::physics::model::{Oscillator, Pair};
use pounding::physics::solver::Scheme;
use pounding::plan::{PairPlan, RunSpec};
use std::path::PathBuf;

/// The fast scheme at 64 substeps per contact, the default before the contact substeps got
/// their order back (issue 34): the setting at which the tight bounds of the model tests (closed
/// forms, GPU against CPU to rounding) were measured. The default (16) is held to its calibrated
/// error by `fast_vs_reference`, the hard cases and the accuracy suites.
pub fn precise_fast() -> pounding::physics::solver::FastOptions {
    pounding::physics::solver::FastOptions {
        substeps_per_contact: 64.0,
        ..Default::default()
    }
}

/// The real-records directory (`POUND_RECORDS_DIR`, default `../shared/records`). Tests that need
/// it fail, never skip, when it is missing: CI has it beside the clone.
pub fn records_dir() -> PathBuf {
    let d = pounding::plan::config::records_dir();
    assert!(
        d.join("SOURCES.md").is_file(),
        "records directory {} not found (set POUND_RECORDS_DIR)",
        d.display()
    );
    // Absolute, so a config written to a temporary folder names its record wherever pound runs.
    std::fs::canonicalize(&d).unwrap()
}

pub fn tempdir() -> tempfile::TempDir {
    tempfile::Builder::new()
        .prefix("pound-test-")
        .tempdir()
        .expect("temp dir")
}

/// Assert two texts are equal, showing the first differing lines on failure.
pub fn assert_same_text(label: &str, a: &str, b: &str) {
    if a == b {
        return;
    }
    let (la, lb): (Vec<&str>, Vec<&str>) = (a.lines().collect(), b.lines().collect());
    let mut diff = String::new();
    let mut shown = 0;
    for i in 0..la.len().max(lb.len()) {
        let (x, y) = (
            la.get(i).copied().unwrap_or("<none>"),
            lb.get(i).copied().unwrap_or("<none>"),
        );
        if x != y {
            diff.push_str(&format!("line {}:\n  - {x}\n  + {y}\n", i + 1));
            shown += 1;
            if shown == 10 {
                break;
            }
        }
    }
    panic!(
        "{label}: texts differ ({} vs {} lines)\n{diff}",
        la.len(),
        lb.len()
    );
}

/// A run's output without its work counters (they differ between paths and chunkings that
/// compute the same result: the CPU settles some free steps from a shared free response).
pub fn without_work(o: &RunOutput) -> RunOutput {
    RunOutput {
        free_steps: 0,
        shared_steps: 0,
        ..*o
    }
}

/// Relative difference with a floor.
/// A TOML array of floats (the OpenSees cross-checks' reference data).
pub fn floats(v: &toml::Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_float().unwrap())
        .collect()
}

pub fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs().max(1e-300)
}

/// Two SDOF buildings with a contact law.
pub fn pair(
    law: LawKind,
    stiffness: f64,
    damping: f64,
    (m1, t1, xi1): (f64, f64, f64),
    (m2, t2, xi2): (f64, f64, f64),
    gap: f64,
) -> Pair {
    let b1 = Oscillator::from_period(m1, t1, xi1);
    let b2 = Oscillator::from_period(m2, t2, xi2);
    Pair {
        b1,
        b2,
        gap,
        contact: Contact::new(law, stiffness, damping, Pair::m_eff(&b1, &b2)),
    }
}

/// Every run of `plan` with `scheme`, in run order.
pub fn collect(plan: &PairPlan, scheme: &Scheme, chunk: usize) -> Vec<(RunSpec, RunOutput)> {
    let mut rows = Vec::new();
    let sink = |c: &[(RunSpec, RunOutput)]| -> Result<(), pounding::engine::gpu::GpuError> {
        rows.extend_from_slice(c);
        Ok(())
    };
    pounding::engine::Engine::cpu(*scheme, Some(chunk))
        .unwrap()
        .run(plan, 0..plan.len(), sink, |_| {})
        .unwrap();
    rows
}

/// The column `name` of CSV text `csv`, as text.
pub fn csv_column(csv: &str, name: &str) -> Vec<String> {
    let mut r = csv::Reader::from_reader(csv.as_bytes());
    let c = r.headers().unwrap().iter().position(|h| h == name).unwrap();
    r.records().map(|x| x.unwrap()[c].to_string()).collect()
}
