//! The shared test device and what GPU tests compare.

use super::rel;
use pounding::engine::gpu::{GpuContext, GpuOptions};
use pounding::engine::{Engine, Report};
use pounding::physics::model::RunOutput;
use pounding::physics::solver::Scheme;
use pounding::plan::{PairPlan, RunSpec};
use std::sync::OnceLock;

/// The shared test device. With `POUND_REQUIRE_GPU=1` (CI) a missing adapter fails the test.
pub fn ctx() -> Option<&'static GpuContext> {
    static CTX: OnceLock<Option<GpuContext>> = OnceLock::new();
    CTX.get_or_init(|| match GpuContext::new() {
        Ok(c) => {
            eprintln!("GPU tests on {}", c.describe());
            Some(c)
        }
        Err(e) => {
            if std::env::var("POUND_REQUIRE_GPU").is_ok_and(|v| v == "1") {
                panic!("POUND_REQUIRE_GPU=1 but {e}");
            }
            eprintln!("skipping GPU test: {e}");
            None
        }
    })
    .as_ref()
}

pub fn gpu_collect(plan: &PairPlan, opts: &GpuOptions, chunk: usize) -> Vec<(RunSpec, RunOutput)> {
    gpu_run(plan, opts, chunk).0
}

/// Every run of `plan` on the shared device, with the engine's report (times, lane tally).
pub fn gpu_run(
    plan: &PairPlan,
    opts: &GpuOptions,
    chunk: usize,
) -> (Vec<(RunSpec, RunOutput)>, Report) {
    let mut rows = Vec::new();
    let sink = |c: &[(RunSpec, RunOutput)]| -> Result<(), pounding::engine::gpu::GpuError> {
        rows.extend_from_slice(c);
        Ok(())
    };
    let report = Engine::gpu(ctx().unwrap(), *opts, Some(chunk))
        .unwrap()
        .run(plan, 0..plan.len(), sink, |_| {})
        .unwrap();
    (rows, report)
}

/// Largest relative difference of the peak outputs of two results of one run.
pub fn peak_diff(a: &RunOutput, b: &RunOutput) -> f64 {
    [
        rel(a.peak_force, b.peak_force),
        rel(a.peak_u1, b.peak_u1),
        rel(a.peak_u2, b.peak_u2),
        rel(a.peak_penetration, b.peak_penetration),
        rel(a.impact_velocity, b.impact_velocity),
    ]
    .into_iter()
    .filter(|x| x.is_finite())
    .fold(0.0, f64::max)
}

/// Contacts of a CPU run that a small change of the trajectory can add or remove, for a
/// distance scale `tau`: an impact whose peak penetration is below `tau`, a separation between
/// two impacts that opens less than `tau`, and an approach in free flight that comes within `tau`
/// of touching without touching. Closest approaches are maxima of the Hermite cubic of `delta`
/// over each step.
pub fn grazing_contacts(plan: &PairPlan, spec: &RunSpec, tau: f64) -> usize {
    use pounding::physics::solver::{simulate_observed, Mode, Sample};
    let pair = spec.pair();
    let delta = |z: &pounding::physics::solver::State| z[0] - z[2] - pair.gap;
    let mut prev: Option<Sample> = None;
    let (mut count, mut impacts, mut pen) = (0usize, 0u32, 0.0f64);
    // Most open and closest distances of the current free episode; a local max of delta.
    let (mut opening, mut rising) = (0.0f64, false);
    let mut obs = |s: &Sample| {
        if let Some(p) = prev {
            match (p.mode, s.mode) {
                (Mode::Free, Mode::Free) => {
                    let (y0, d0, y1, d1) =
                        (delta(&p.z), p.z[1] - p.z[3], delta(&s.z), s.z[1] - s.z[3]);
                    let h = s.t - p.t;
                    let (m0, m1) = (h * d0, h * d1);
                    let b = 3.0 * (y1 - y0) - 2.0 * m0 - m1;
                    let c = 2.0 * (y0 - y1) + m0 + m1;
                    for k in 0..=64 {
                        let x = k as f64 / 64.0;
                        let y = y0 + x * (m0 + x * (b + x * c));
                        opening = opening.max(-y);
                        let dy = m0 + x * (2.0 * b + 3.0 * c * x);
                        if rising && dy < 0.0 && y > -tau {
                            count += 1; // a near miss
                        }
                        rising = dy > 0.0;
                    }
                }
                (Mode::Free, _) => {
                    if impacts > 0 && opening < tau {
                        count += 1; // the bodies barely separated before this impact
                    }
                    impacts += 1;
                    pen = delta(&s.z).max(0.0);
                }
                (_, Mode::Free) => {
                    if pen < tau {
                        count += 1; // a barely touching impact
                    }
                    (opening, rising) = (0.0, false);
                }
                _ => pen = pen.max(delta(&s.z)),
            }
        }
        prev = Some(*s);
    };
    simulate_observed(
        &pair,
        &plan.forcing(spec),
        &pounding::physics::model::Initial::default(),
        &Scheme::Fast(super::precise_fast()),
        Some(&mut obs),
    );
    count
}
