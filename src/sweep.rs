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

    /// Count the runs of a device partial (handed-back runs are counted when finished).
    fn count_partial(&mut self, p: &crate::aggregate::Partial) {
        self.runs += p.runs;
        self.impacts += p.impacts;
        self.runs_with_impacts += p.pounded;
        self.failures += p.failures;
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
    /// `--aggregate`: folding on the device and reading the partials back, s.
    pub aggregate: f64,
    /// `--aggregate`: chunks with more groups than the device's histogram slots (read back and
    /// folded on the host), and times the slots were flushed to the host before the end.
    pub host_folded_chunks: u64,
    pub slot_flushes: u64,
}

impl GpuTimes {
    /// Add a chunk's device times.
    fn add_chunk(&mut self, ct: &crate::gpu::ChunkTimes) {
        self.upload += ct.upload.as_secs_f64();
        self.kernel += ct.kernel.as_secs_f64();
        self.readback += ct.readback.as_secs_f64();
    }

    /// A chunk's outputs as read back, with the runs the kernel handed back finished on the CPU
    /// in f64 (`spec(k)` is the run of `outs[k]`).
    fn finish<'a>(
        &mut self,
        plan: &Plan,
        fast: &crate::cpu::FastOptions,
        outs: Vec<Option<RunOutput>>,
        spec: impl Fn(usize) -> &'a RunSpec + Sync,
    ) -> Vec<RunOutput> {
        let t = Instant::now();
        let cpu = Scheme::Fast(*fast);
        self.handed_off += outs.iter().filter(|o| o.is_none()).count() as u64;
        let done = outs
            .into_par_iter()
            .enumerate()
            .map(|(k, o)| o.unwrap_or_else(|| run_one(plan, spec(k), &cpu)))
            .collect();
        self.handoff += t.elapsed().as_secs_f64();
        done
    }
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
    // Packing is host work: the next chunk is packed while the device integrates this one.
    let prep = |c0: u64| {
        let t = Instant::now();
        let (specs, packed): (Vec<RunSpec>, Vec<_>) = (c0..(c0 + chunk).min(n))
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
        (specs, packed, t.elapsed().as_secs_f64())
    };
    let mut c0 = runs.start;
    let mut next = (c0 < n).then(|| prep(c0));
    while let Some((specs, packed, pack_s)) = next.take() {
        let c1 = (c0 + chunk).min(n);
        times.pack += pack_s;
        let (done, upcoming) = rayon::join(
            || run_chunk(ctx, &recs, &packed, opts),
            || (c1 < n).then(|| prep(c1)),
        );
        next = upcoming;
        let (outs, ct) = done?;
        times.add_chunk(&ct);
        let outs = times.finish(plan, &opts.fast, outs, |k| &specs[k]);
        let rows: Vec<(RunSpec, RunOutput)> = specs.into_iter().zip(outs).collect();
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

/// As [`run_gpu_range`] with `--aggregate`: each chunk is packed sorted by group, integrated,
/// and folded into `agg` on the device (`shaders/aggregate.wgsl`), so only the groups' partials
/// come back per chunk and the histograms at the end, not a state per run. Runs the kernel hands
/// back are finished on the CPU and folded on the host. A chunk with more groups than
/// `max_slots` (or than one buffer holds) is read back and folded on the host instead.
#[allow(clippy::too_many_arguments)]
pub fn run_gpu_aggregate(
    plan: &Plan,
    runs: std::ops::Range<u64>,
    ctx: &crate::gpu::GpuContext,
    opts: &crate::gpu::GpuOptions,
    chunk: usize,
    max_slots: u32,
    agg: &mut crate::aggregate::Aggregator,
    mut progress: impl FnMut(u64),
) -> Result<(Summary, GpuTimes), crate::gpu::GpuError> {
    use crate::gpu::layout::{Segment, MAX_SEGMENT};
    use crate::gpu::reduce::{reduce, Slots};
    use crate::gpu::{integrate, pack, run_chunk, GpuRecords};
    let start = Instant::now();
    let mut times = GpuTimes::default();
    let accels: Vec<&[f64]> = plan.spec.records.iter().map(|r| &r.accel[..]).collect();
    let recs = GpuRecords::upload(ctx, opts.precision, &accels)?;
    let chunk = (chunk.max(1) as u64).min(ctx.max_runs_per_chunk(opts.precision));
    let mut slots = Slots::new(ctx, max_slots);
    let thresholds = agg.thresholds().to_vec();
    let mut s = Summary::default();
    let end = runs.end;
    // Host work for a chunk: decode, group, order by group, pack, cut into segments. It runs
    // for the next chunk while the device integrates this one.
    let prep = |c0: u64, agg: &mut crate::aggregate::Aggregator| {
        let t = Instant::now();
        let specs: Vec<RunSpec> = (c0..(c0 + chunk).min(end))
            .into_par_iter()
            .map(|i| plan.run(i))
            .collect();
        let gids: Vec<u32> = specs.iter().map(|r| agg.group_of(plan, r)).collect();
        // Pack sorted by group (stable), so each group is a run of consecutive runs.
        let mut order: Vec<usize> = (0..specs.len()).collect();
        order.sort_by_key(|&i| gids[i]);
        let packed: Vec<_> = order
            .par_iter()
            .map(|&i| {
                let r = &specs[i];
                pack(&r.pair(), &plan.forcing(r), r.record, &recs, &opts.fast)
            })
            .collect();
        let mut segments: Vec<(u32, Segment)> = Vec::new();
        for (k, &i) in order.iter().enumerate() {
            match segments.last_mut() {
                Some((g, seg)) if *g == gids[i] && seg.len < MAX_SEGMENT => seg.len += 1,
                _ => segments.push((
                    gids[i],
                    Segment {
                        start: k as u32,
                        len: 1,
                        ..Default::default()
                    },
                )),
            }
        }
        let mut groups: Vec<u32> = segments.iter().map(|(g, _)| *g).collect();
        groups.dedup();
        Prepared {
            specs,
            gids,
            order,
            packed,
            segments,
            groups,
            seconds: t.elapsed().as_secs_f64(),
        }
    };
    let mut c0 = runs.start;
    let mut next = (c0 < end).then(|| prep(c0, agg));
    while let Some(p) = next.take() {
        let c1 = (c0 + chunk).min(end);
        times.pack += p.seconds;
        let Some(slot) = slots.assign(ctx, &p.groups, agg)? else {
            // More groups than slots: read every run back and fold here.
            let (done, upcoming) = rayon::join(
                || run_chunk(ctx, &recs, &p.packed, opts),
                || (c1 < end).then(|| prep(c1, &mut *agg)),
            );
            next = upcoming;
            let (outs, ct) = done?;
            times.add_chunk(&ct);
            times.host_folded_chunks += 1;
            let outs = times.finish(plan, &opts.fast, outs, |k| &p.specs[p.order[k]]);
            for (&i, o) in p.order.iter().zip(&outs) {
                agg.add(p.gids[i], o);
                s.count(o);
            }
            progress(s.runs);
            c0 = c1;
            continue;
        };
        let slot_of: std::collections::HashMap<u32, u32> =
            p.groups.iter().copied().zip(slot).collect();
        let segs: Vec<Segment> = p
            .segments
            .iter()
            .map(|(g, seg)| Segment {
                slot: slot_of[g],
                ..*seg
            })
            .collect();
        let (done, upcoming) = rayon::join(
            || -> Result<_, crate::gpu::GpuError> {
                let (done, ct) = integrate(ctx, &recs, &p.packed, opts)?;
                let t = Instant::now();
                let folded = reduce(ctx, &done, opts.precision, &segs, &thresholds, &slots)?;
                Ok((ct, folded, t.elapsed().as_secs_f64()))
            },
            || (c1 < end).then(|| prep(c1, &mut *agg)),
        );
        next = upcoming;
        let (ct, (partials, handed), fold_s) = done?;
        times.add_chunk(&ct);
        times.aggregate += fold_s;
        for ((g, _), part) in p.segments.iter().zip(&partials) {
            agg.group(*g).add_partial(part);
            s.count_partial(part);
        }
        // Runs handed back: `handed` holds their places in the packed (sorted) chunk.
        let run = |k: usize| p.order[handed[k] as usize];
        let outs = times.finish(plan, &opts.fast, vec![None; handed.len()], |k| {
            &p.specs[run(k)]
        });
        for (k, o) in outs.iter().enumerate() {
            agg.add(p.gids[run(k)], o);
            s.count(o);
        }
        progress(s.runs);
        c0 = c1;
    }
    let t = Instant::now();
    slots.flush(ctx, agg)?;
    times.aggregate += t.elapsed().as_secs_f64();
    times.slot_flushes = slots.flushes.saturating_sub(1) as u64;
    s.seconds = start.elapsed().as_secs_f64();
    Ok((s, times))
}

/// One chunk's host work for [`run_gpu_aggregate`].
struct Prepared {
    specs: Vec<RunSpec>,
    /// Group of each run (in run order).
    gids: Vec<u32>,
    /// Runs sorted by group: `packed[k]` is run `specs[order[k]]`.
    order: Vec<usize>,
    packed: Vec<crate::gpu::run::Packed>,
    /// Each segment's group, and the segment (slot not yet assigned).
    segments: Vec<(u32, crate::gpu::layout::Segment)>,
    /// The distinct groups, in segment order.
    groups: Vec<u32>,
    seconds: f64,
}
