//! Run a plan on the CPU with rayon: chunks of consecutive runs in parallel, handed to a sink in
//! run order as each batch finishes (so output streams and is identical for any thread count).

use crate::cpu::{simulate, Scheme};
use crate::model::{Initial, RunOutput, Status};
use crate::plan::{Plan, RunSpec};
use rayon::prelude::*;
use std::time::Instant;

/// Totals of a finished sweep.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Summary {
    pub runs: u64,
    pub seconds: f64,
    pub runs_with_impacts: u64,
    pub impacts: u64,
    pub failures: u64,
}

impl Summary {
    /// Count one finished run.
    fn count(&mut self, o: &RunOutput) {
        self.runs += 1;
        self.impacts += o.impacts as u64;
        self.runs_with_impacts += (o.impacts > 0) as u64;
        self.failures += (o.status != Status::Ok) as u64;
    }

    pub fn runs_per_second(&self) -> f64 {
        self.runs as f64 / self.seconds.max(1e-9)
    }
}

/// Run one plan entry.
pub fn run_one(plan: &Plan, spec: &RunSpec, scheme: &Scheme) -> RunOutput {
    simulate(
        &spec.pair(),
        &plan.forcing(spec),
        &Initial::default(),
        scheme,
    )
}

/// Run every run of `plan` with `scheme`, `chunk` runs per task; `sink` gets each chunk's results
/// in run order, `progress` the number of runs done so far.
pub fn run<E>(
    plan: &Plan,
    scheme: &Scheme,
    chunk: usize,
    sink: impl FnMut(&[(RunSpec, RunOutput)]) -> Result<(), E>,
    progress: impl FnMut(u64),
) -> Result<Summary, E> {
    run_range(plan, 0..plan.len(), scheme, chunk, sink, progress)
}

/// As [`run`], for the runs `runs` of the plan only (a shard, or what a resumed sweep has left).
pub fn run_range<E>(
    plan: &Plan,
    runs: std::ops::Range<u64>,
    scheme: &Scheme,
    chunk: usize,
    mut sink: impl FnMut(&[(RunSpec, RunOutput)]) -> Result<(), E>,
    mut progress: impl FnMut(u64),
) -> Result<Summary, E> {
    let start = Instant::now();
    let chunk = chunk.max(1) as u64;
    let (first, n) = (runs.start, runs.end);
    let nchunks = (n - first.min(n)).div_ceil(chunk);
    let batch = (rayon::current_num_threads() as u64 * 4).max(1);
    let mut s = Summary::default();
    let mut c0 = 0;
    while c0 < nchunks {
        let c1 = (c0 + batch).min(nchunks);
        let results: Vec<Vec<(RunSpec, RunOutput)>> = (c0..c1)
            .into_par_iter()
            .map(|c| {
                (first + c * chunk..(first + (c + 1) * chunk).min(n))
                    .map(|i| {
                        let spec = plan.run(i);
                        let out = run_one(plan, &spec, scheme);
                        (spec, out)
                    })
                    .collect()
            })
            .collect();
        for r in &results {
            for (_, o) in r {
                s.count(o);
            }
            sink(r)?;
        }
        progress(s.runs);
        c0 = c1;
    }
    s.seconds = start.elapsed().as_secs_f64();
    Ok(s)
}

/// Where a GPU sweep spent its time, s (packing is host work; upload, kernel and readback are
/// timed around the GPU calls that wait for completion).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct GpuTimes {
    pub pack: f64,
    pub upload: f64,
    pub kernel: f64,
    pub readback: f64,
    /// Finishing handed-back runs on the CPU.
    pub handoff: f64,
    pub sink: f64,
    /// Runs handed back by the kernel and finished on the CPU in f64.
    pub handed_off: u64,
}

/// Run every run of `plan` on the GPU, `chunk` runs per chunk (capped by the device's limits);
/// `sink` gets each chunk's results in run order as it finishes. Runs the kernel hands back
/// (more substeps per record step than its precision resolves) are finished on the CPU's fast
/// path in f64. Rows already handed to `sink` stay there if a later chunk fails (device loss,
/// out of memory).
pub fn run_gpu<E: From<crate::gpu::GpuError>>(
    plan: &Plan,
    ctx: &crate::gpu::GpuContext,
    opts: &crate::gpu::GpuOptions,
    chunk: usize,
    sink: impl FnMut(&[(RunSpec, RunOutput)]) -> Result<(), E>,
    progress: impl FnMut(u64),
) -> Result<(Summary, GpuTimes), E> {
    run_gpu_range(plan, 0..plan.len(), ctx, opts, chunk, sink, progress)
}

/// As [`run_gpu`], for the runs `runs` of the plan only.
pub fn run_gpu_range<E: From<crate::gpu::GpuError>>(
    plan: &Plan,
    runs: std::ops::Range<u64>,
    ctx: &crate::gpu::GpuContext,
    opts: &crate::gpu::GpuOptions,
    chunk: usize,
    mut sink: impl FnMut(&[(RunSpec, RunOutput)]) -> Result<(), E>,
    mut progress: impl FnMut(u64),
) -> Result<(Summary, GpuTimes), E> {
    use crate::gpu::{pack, run_chunk, GpuRecords};
    let start = Instant::now();
    let mut times = GpuTimes::default();
    let accels: Vec<&[f64]> = plan.spec.records.iter().map(|r| &r.accel[..]).collect();
    let recs = GpuRecords::upload(ctx, opts.precision, &accels)?;
    let chunk = (chunk.max(1) as u64).min(ctx.max_runs_per_chunk(opts.precision));
    let n = runs.end;
    let mut s = Summary::default();
    let mut c0 = runs.start;
    while c0 < n {
        let c1 = (c0 + chunk).min(n);
        let t = Instant::now();
        let (specs, packed): (Vec<RunSpec>, Vec<_>) = (c0..c1)
            .into_par_iter()
            .map(|i| {
                let spec = plan.run(i);
                let p = pack(
                    &spec.pair(),
                    &plan.forcing(&spec),
                    spec.record,
                    &recs,
                    &opts.fast,
                );
                (spec, p)
            })
            .unzip();
        times.pack += t.elapsed().as_secs_f64();
        let (outs, ct) = run_chunk(ctx, &recs, &packed, opts)?;
        times.upload += ct.upload.as_secs_f64();
        times.kernel += ct.kernel.as_secs_f64();
        times.readback += ct.readback.as_secs_f64();
        let t = Instant::now();
        let cpu = Scheme::Fast(opts.fast);
        times.handed_off += outs.iter().filter(|o| o.is_none()).count() as u64;
        let rows: Vec<(RunSpec, RunOutput)> = specs
            .into_par_iter()
            .zip(outs)
            .map(|(spec, o)| {
                let o = o.unwrap_or_else(|| run_one(plan, &spec, &cpu));
                (spec, o)
            })
            .collect();
        times.handoff += t.elapsed().as_secs_f64();
        let t = Instant::now();
        for (_, o) in &rows {
            s.count(o);
        }
        sink(&rows)?;
        times.sink += t.elapsed().as_secs_f64();
        progress(s.runs);
        c0 = c1;
    }
    s.seconds = start.elapsed().as_secs_f64();
    Ok((s, times))
}
