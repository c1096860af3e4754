//! `pound bench`: runs per second of the CPU and GPU paths on the same sweeps, with where the
//! time goes. The sweep is the quickstart physics (nonlinear viscoelastic contact, Ebrahimi
//! zeta, e = 0.65) on a 20 s synthetic record at dt = 0.01 s, gaps 0..50 mm: most runs pound.
//! The multi-storey suite ([`row_plan`]) times rows of two N-storey buildings on the CPU and,
//! where a hardware GPU is found, on it.

use crate::engine::aggregate::Aggregator;
use crate::engine::gpu::{GpuError, GpuTimes};
use crate::engine::{Engine, Summary};
use crate::physics::model::RunOutput;
use crate::plan::row::RowPlan;
use crate::plan::{PairPlan, RunSpec};
use std::time::Instant;

/// The bench's contact (without its gap) and record, as config text: both suites use them.
const CONTACT: &str = r#"[contact]
law = "nonlinear_viscoelastic"
formula = "ebrahimi"
e = 0.65
beta_n_per_m1_5 = 2.75e9"#;
const RECORD: &str = r#"[[record]]
synthetic = { seed = 1, duration_s = 20.0, dt_s = 0.01, pga_g = 0.35 }
"#;

/// An axis of `n` values from `from` to `to` as config text: a range needs two or more
/// values, so one value is written as a number (`from`).
fn axis(from: f64, to: f64, n: u64) -> String {
    if n > 1 {
        format!("{{ from = {from}, to = {to}, n = {n} }}")
    } else {
        format!("{from}")
    }
}

/// A sweep of about `n` runs (periods of both buildings x up to 10 gaps). Every `n` from 1 to
/// [`crate::plan::limits::MAX_BENCH_RUNS`] gives a valid config (test `every_bounded_size_plans`).
pub fn config(n: u64) -> String {
    let gaps = n.clamp(1, 10);
    let per = (n as f64 / gaps as f64).max(1.0);
    let a = per.sqrt().ceil().max(1.0) as u64;
    let b = (per / a as f64).ceil().max(1.0) as u64;
    format!(
        r#"[building1]
mass_kg = 1.0e5
period_s = {}
damping_ratio = 0.05

[building2]
mass_kg = 1.0e5
period_s = {}
damping_ratio = 0.05

{CONTACT}
gap_m = {}

{RECORD}"#,
        axis(0.2, 2.0, a),
        axis(0.15, 1.5, b),
        axis(0.0, 0.05, gaps)
    )
}

/// The bench plan for about `n` runs.
pub fn plan(n: u64) -> PairPlan {
    crate::plan::config::parse_builtin(&config(n), "bench.toml").expect("bench config is valid")
}

/// One measured sweep; times in seconds.
#[derive(Debug, Clone, PartialEq)]
pub struct Row {
    pub runs: u64,
    pub backend: String,
    pub seconds: f64,
    pub pack: f64,
    pub upload: f64,
    pub kernel: f64,
    pub readback: f64,
    /// Finishing handed-back runs on the CPU.
    pub handoff: f64,
    pub csv: f64,
    pub impacts: u64,
    /// Runs the kernel handed back to the CPU.
    pub handed_off: u64,
    /// Exact free record steps and RK4 substeps taken (0 where the device fold kept no count).
    pub free_steps: u64,
    pub substeps: u64,
    /// Record steps settled by a shared free response, and the runs that settled any.
    pub shared_steps: u64,
    pub runs_sharing: u64,
    /// GPU: share of the lane trips the kernel held that did work.
    pub lane_utilisation: Option<f64>,
}

impl Row {
    /// The row of a finished engine call, times as the engine reports them (no CSV time).
    fn new(backend: String, s: &Summary, t: &GpuTimes) -> Row {
        Row {
            runs: s.runs,
            backend,
            seconds: s.seconds,
            pack: t.pack,
            upload: t.upload,
            kernel: t.kernel,
            readback: t.readback,
            handoff: t.handoff,
            csv: 0.0,
            impacts: s.impacts,
            handed_off: t.handed_off,
            free_steps: s.free_steps,
            substeps: s.substeps,
            shared_steps: s.shared_steps,
            runs_sharing: s.runs_sharing,
            lane_utilisation: t.lane_utilisation(),
        }
    }

    pub fn runs_per_second(&self) -> f64 {
        self.runs as f64 / self.seconds.max(1e-12)
    }
}

/// Formats each chunk's rows as CSV into a sink, timing it (the cost a real sweep pays).
struct CsvSink<'a> {
    plan: &'a PairPlan,
    w: std::io::Sink,
    seconds: f64,
}

impl CsvSink<'_> {
    fn write(&mut self, rows: &[(RunSpec, RunOutput)]) {
        use std::io::Write;
        let t = Instant::now();
        let lines = crate::io::csv::encode_csv(self.plan, rows, None);
        self.w
            .write_all(&lines)
            .expect("writing to a sink cannot fail");
        self.seconds += t.elapsed().as_secs_f64();
    }
}

/// The table's name for `engine`.
fn label(engine: &Engine) -> String {
    match engine {
        Engine::Cpu { .. } => format!("cpu ({} threads)", rayon::current_num_threads()),
        Engine::Gpu { ctx, opts, .. } => {
            format!("gpu {} ({})", opts.precision.key(), ctx.info.name)
        }
    }
}

/// Every run of `plan` on `engine`, each chunk's rows formatted as CSV (into a sink): the CPU
/// fast path on all threads of the current pool, or the GPU path.
pub fn run(plan: &PairPlan, engine: &Engine) -> Result<Row, GpuError> {
    let mut sink = CsvSink {
        plan,
        w: std::io::sink(),
        seconds: 0.0,
    };
    let r = engine.run(
        plan,
        0..plan.len(),
        |rows| -> Result<(), GpuError> {
            sink.write(rows);
            Ok(())
        },
        |_| {},
    )?;
    let (s, t) = (r.summary, r.gpu);
    Ok(Row {
        // The CPU integrates and formats in one loop: its kernel time is what formatting left.
        kernel: match engine {
            Engine::Cpu { .. } => s.seconds - sink.seconds,
            Engine::Gpu { .. } => t.kernel,
        },
        csv: sink.seconds,
        ..Row::new(label(engine), &s, &t)
    })
}

/// Every run of `plan` on `engine` folded by `--aggregate by` (on the device for the GPU):
/// `readback` is the fold and its partials' readback, `csv` writing the summary.
pub fn fold(plan: &PairPlan, engine: &Engine, by: &[String]) -> Result<Row, GpuError> {
    let mut agg = Aggregator::new(by, &[]).map_err(|e| GpuError::Other {
        message: e.to_string(),
    })?;
    let r = engine.fold(plan, 0..plan.len(), &mut agg, |_| {})?;
    let (s, t) = (r.summary, r.gpu);
    let c = Instant::now();
    let summary = crate::io::summary::csv(&agg);
    let csv = c.elapsed().as_secs_f64();
    let backend = format!(
        "{}, --aggregate {} ({} groups, {} bytes)",
        label(engine),
        by.join(","),
        agg.groups(),
        summary.len()
    );
    Ok(Row {
        seconds: s.seconds + csv,
        readback: t.aggregate,
        csv,
        ..Row::new(backend, &s, &t)
    })
}

/// A markdown table of rows.
pub fn table(rows: &[Row]) -> String {
    let mut s = String::from(
        "| runs | backend | total s | runs/s | free steps/s | RK4 substeps/s | runs sharing | steps shared | lanes busy | pack s | upload s | kernel s | readback s | handoff s (runs) | csv s | impacts |\n|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n",
    );
    let rate = |n: u64, r: &Row| {
        if n == 0 {
            "-".to_string()
        } else {
            format!("{:.3e}", n as f64 / r.seconds.max(1e-12))
        }
    };
    for r in rows {
        let lanes = r
            .lane_utilisation
            .map_or("-".to_string(), |u| format!("{:.0} %", 100.0 * u));
        let share = |part: u64, whole: u64| {
            if whole == 0 {
                "-".to_string()
            } else {
                format!("{:.0} %", 100.0 * part as f64 / whole as f64)
            }
        };
        let steps = r.free_steps + r.shared_steps;
        s.push_str(&format!(
            "| {} | {} | {:.3} | {:.0} | {} | {} | {} | {} | {} | {:.3} | {:.3} | {:.3} | {:.3} | {:.3} ({}) | {:.3} | {} |\n",
            r.runs,
            r.backend,
            r.seconds,
            r.runs_per_second(),
            rate(r.free_steps, r),
            rate(r.substeps, r),
            share(r.runs_sharing, if steps == 0 { 0 } else { r.runs }),
            share(r.shared_steps, steps),
            lanes,
            r.pack,
            r.upload,
            r.kernel,
            r.readback,
            r.handoff,
            r.handed_off,
            r.csv,
            r.impacts
        ));
    }
    s
}

/// The multi-storey suite's sweep: two `storeys`-storey shear buildings (3 m storeys, 3e5 kg
/// floors, uniform stiffness, Rayleigh 5 %), the left one's period swept, 10 gaps from 0 to
/// 45 mm, the bench's record and contact: about `n` runs. Past 10,000 periods (an axis holds
/// at most [`crate::plan::limits::MAX_AXIS_POINTS`]) the right one's period is swept too.
pub fn row_config(storeys: usize, n: u64) -> String {
    let gaps = n.clamp(1, 10);
    let mut periods = (n as f64 / gaps as f64).ceil().max(1.0) as u64;
    let mut right = 1;
    if periods > 10_000 {
        right = (periods as f64 / 10_000.0).ceil() as u64;
        periods = (periods as f64 / right as f64).ceil() as u64;
    }
    let t = 0.1 * storeys as f64;
    format!(
        r#"[[building]]
storeys = {storeys}
storey_height_m = 3.0
mass_kg = 3.0e5
period_s = {l}
damping_ratio = 0.05

[[building]]
storeys = {storeys}
storey_height_m = 3.0
mass_kg = 3.0e5
period_s = {c}
damping_ratio = 0.05

{CONTACT}
gap_m = {g}

{RECORD}"#,
        l = axis(t + 0.05, 2.0 * t + 0.1, periods),
        c = axis(1.5 * t + 0.1, 2.5 * t + 0.1, right),
        g = axis(0.0, 0.045, gaps),
    )
}

/// The multi-storey suite's yielding twin: [`row_config`] with every storey yielding at 0.5 %
/// drift with 3 % hardening (docs/inelastic.md).
pub fn yielding_row_config(storeys: usize, n: u64) -> String {
    row_config(storeys, n).replace(
        "damping_ratio = 0.05\n",
        "damping_ratio = 0.05\nyield_drift_ratio = 0.005\npost_yield_ratio = 0.03\n",
    )
}

/// The multi-storey suite's plan of two `storeys`-storey buildings, about `n` runs (their
/// storeys `yielding`: [`yielding_row_config`]).
pub fn row_plan(storeys: usize, n: u64, yielding: bool) -> RowPlan {
    let text = if yielding {
        yielding_row_config(storeys, n)
    } else {
        row_config(storeys, n)
    };
    crate::plan::config::parse_row(
        &text,
        std::path::Path::new("bench-rows.toml"),
        std::path::Path::new("."),
        std::path::Path::new("."),
    )
    .expect("row bench config is valid")
}

/// One measured multi-storey sweep.
#[derive(Debug, Clone, PartialEq)]
pub struct StoreyRow {
    pub storeys: usize,
    /// The yielding twin of the suite ([`yielding_row_config`]).
    pub yielding: bool,
    /// `cpu (T threads)` or `gpu PRECISION (ADAPTER)`.
    pub backend: String,
    pub summary: Summary,
    /// Formatting the rows as CSV, s (inside `summary.seconds`).
    pub csv: f64,
    /// On the GPU: the share of the lane trips the kernel held that did work.
    pub lane_utilisation: Option<f64>,
    /// On the GPU: the host's packing (overlapping the device's previous chunk) and the
    /// kernel's dispatches, s (inside `summary.seconds`).
    pub pack_and_kernel: Option<(f64, f64)>,
}

/// Seconds to format a chunk of row results as CSV (the text is thrown away).
fn csv_seconds(
    plan: &RowPlan,
    rows: &[(crate::plan::row::RowRunSpec, crate::physics::row::RowOutput)],
) -> f64 {
    // The sweep's own encoder (in parallel blocks): formatted one by one, a 20,000-run sweep's
    // rows took 1.6 s of an H200's 2.7 s (BENCHMARKS.md, "Rows on an H200").
    let t = Instant::now();
    std::hint::black_box(crate::io::csv::encode_csv(plan, rows, None));
    t.elapsed().as_secs_f64()
}

/// Every run of the row plan on the CPU (the current pool), rows formatted as CSV.
pub fn run_storeys(storeys: usize, plan: &RowPlan) -> StoreyRow {
    let mut csv = 0.0;
    let summary = crate::engine::cpu::run_rows(
        plan,
        0..plan.len(),
        crate::engine::CPU_CHUNK,
        |rows| -> Result<(), std::convert::Infallible> {
            csv += csv_seconds(plan, rows);
            Ok(())
        },
        |_| {},
    )
    .unwrap_or_else(|e| match e {});
    StoreyRow {
        storeys,
        yielding: plan.yielding.iter().any(Option::is_some),
        backend: format!("cpu ({} threads)", rayon::current_num_threads()),
        summary,
        csv,
        lane_utilisation: None,
        pack_and_kernel: None,
    }
}

/// Every run of the row plan on the GPU (`shaders/row.wgsl`, compiled before the clock
/// starts), rows formatted as CSV.
pub fn run_storeys_gpu(
    storeys: usize,
    plan: &RowPlan,
    ctx: &crate::engine::gpu::GpuContext,
    opts: &crate::engine::gpu::GpuOptions,
) -> Result<StoreyRow, crate::engine::gpu::GpuError> {
    use crate::engine::gpu::row::{sweep_rows, RowShape};
    use crate::engine::gpu::sweep::run_row_pairs;
    let mut csv = 0.0;
    let sink = |rows: &[_]| -> Result<(), crate::engine::gpu::GpuError> {
        csv += csv_seconds(plan, rows);
        Ok(())
    };
    let (runs, chunk) = (0..plan.len(), crate::engine::GPU_CHUNK);
    // The kernels a sweep of this plan takes (`engine::Kernel::of`): a row of two one-storey
    // buildings runs on the pair's.
    let (summary, times) = if plan.runs_as_pair() {
        ctx.kernel(opts.precision, opts.fast.energy, true, None)?;
        run_row_pairs(plan, runs, ctx, opts, chunk, sink, |_| {})?
    } else {
        ctx.row_kernel(opts.precision, &RowShape::of_plan(plan), None)?;
        sweep_rows(ctx, plan, runs, chunk, opts, sink, |_| {})?
    };
    Ok(StoreyRow {
        storeys,
        yielding: plan.yielding.iter().any(Option::is_some),
        backend: format!("gpu {} ({})", opts.precision.key(), ctx.info.name),
        summary,
        csv,
        lane_utilisation: times.lane_utilisation(),
        pack_and_kernel: Some((times.pack, times.kernel)),
    })
}

/// A markdown table of the multi-storey suite.
pub fn storey_table(rows: &[StoreyRow]) -> String {
    let mut s = String::from(
        "| storeys per building | runs | backend | total s | runs/s | storeys x runs/s | free steps/s | RK4 substeps/s | csv s | pack s | kernel s | impacts | lanes busy |\n|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n",
    );
    for r in rows {
        let m = &r.summary;
        let per_s = |x: u64| x as f64 / m.seconds.max(1e-12);
        s.push_str(&format!(
            "| {}{} | {} | {} | {:.3} | {:.0} | {:.0} | {:.3e} | {:.3e} | {:.3} | {} | {} | {} | {} |\n",
            r.storeys,
            if r.yielding { ", yielding" } else { "" },
            m.runs,
            r.backend,
            m.seconds,
            m.runs_per_second(),
            2.0 * r.storeys as f64 * m.runs_per_second(),
            per_s(m.free_steps),
            per_s(m.substeps),
            r.csv,
            r.pack_and_kernel
                .map_or("-".to_string(), |(p, _)| format!("{p:.3}")),
            r.pack_and_kernel
                .map_or("-".to_string(), |(_, k)| format!("{k:.3}")),
            m.impacts,
            r.lane_utilisation
                .map_or("-".to_string(), |u| format!("{:.1} %", 100.0 * u))
        ));
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plan::limits::MAX_BENCH_RUNS;

    /// `pound bench --sizes N` and `--storey-runs N` are served for every N the flags accept:
    /// each size plans (no panic) with at least N and at most 2 N + 20 runs.
    #[test]
    fn every_bounded_size_plans() {
        let sizes: Vec<u64> = (1..=120)
            .chain([
                999,
                1001,
                12_345,
                99_999,
                1_000_001,
                123_456_789,
                MAX_BENCH_RUNS,
            ])
            .collect();
        for &n in &sizes {
            let runs = plan(n).len();
            assert!(runs >= n && runs <= 2 * n + 20, "{n}: {runs}");
        }
        for storeys in [1, 3, crate::physics::shear::MAX_STOREYS] {
            for &n in &sizes {
                let runs = row_plan(storeys, n, false).len();
                assert!(
                    runs >= n && runs <= 2 * n + 20,
                    "{storeys} storeys, {n}: {runs}"
                );
            }
            // The yielding twin: the same runs, every building yielding.
            let twin = row_plan(storeys, 200, true);
            assert_eq!(twin.len(), row_plan(storeys, 200, false).len());
            assert!(twin.yielding.iter().all(Option::is_some));
        }
    }
}
