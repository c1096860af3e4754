//! A range of runs on the GPU, chunk after chunk: packed on the host while the device integrates
//! the previous chunk, read back, the runs the kernel hands back finished on the CPU in f64.

use super::layout::NO_RESPONSE;
use super::run::Packed;
use super::shared::{fill_table, table_reals, Start};
use crate::engine::cpu::{free_motion_stretches, same_free_motion, MIN_SHARED_RUNS};
use crate::engine::Summary;
use crate::physics::model::{Forcing, RunOutput};
use crate::physics::row::RowOutput;
use crate::physics::solver::{simulate_tracking_accel, FastOptions, FreeResponse, Scheme};
use crate::plan::contact::ContactPlan;
use crate::plan::row::{RowPlan, RowRunSpec as RowSpec};
use crate::plan::{PairPlan, RunSpec};
use rayon::prelude::*;
use std::time::Instant;

/// The runs a GPU sweep of the pair kernel integrates: a pair's plan, or a row plan that runs as
/// a pair ([`RowPairs`]).
pub trait PairRuns: Sync {
    /// Runs in all (the shared responses look past a chunk's ends, up to here).
    fn runs(&self) -> u64;
    /// Run `index`, as a pair's run (its `index` is `index`).
    fn run(&self, index: u64) -> RunSpec;
    /// The laws, records, intensities and scheme.
    fn contact(&self) -> &ContactPlan;
    /// Do its runs track their buildings' peak accelerations (a row's output has them)?
    fn accel(&self) -> bool;

    fn forcing(&self, spec: &RunSpec) -> Forcing<'_> {
        self.contact().forcing(&spec.contact)
    }

    /// Run `spec` on the CPU in f64 (a run the kernel handed back).
    fn run_on_cpu(&self, spec: &RunSpec, fast: &FastOptions) -> RunOutput;
}

impl PairRuns for PairPlan {
    fn runs(&self) -> u64 {
        self.len()
    }
    fn run(&self, index: u64) -> RunSpec {
        PairPlan::run(self, index)
    }
    fn contact(&self) -> &ContactPlan {
        &self.contact
    }
    fn accel(&self) -> bool {
        false
    }
    fn run_on_cpu(&self, spec: &RunSpec, fast: &FastOptions) -> RunOutput {
        crate::engine::cpu::run_one(self, spec, &Scheme::Fast(*fast))
    }
}

/// A row plan that runs as a pair ([`RowPlan::runs_as_pair`]), seen as the pair's runs.
pub struct RowPairs<'a>(pub &'a RowPlan);

impl PairRuns for RowPairs<'_> {
    fn runs(&self) -> u64 {
        self.0.len()
    }
    fn run(&self, index: u64) -> RunSpec {
        self.0.pair_run(&self.0.run(index))
    }
    fn contact(&self) -> &ContactPlan {
        &self.0.contact
    }
    fn accel(&self) -> bool {
        true
    }
    fn run_on_cpu(&self, spec: &RunSpec, fast: &FastOptions) -> RunOutput {
        simulate_tracking_accel(&spec.pair(), &self.forcing(spec), fast, None, None)
    }
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
    /// The kernel's lane tally ([`super::ChunkTimes`]): trips that did work, trips lanes were
    /// held for.
    pub lane_units: u64,
    pub lane_slots: u64,
}

impl GpuTimes {
    /// Add a chunk's device times.
    pub(crate) fn add_chunk(&mut self, ct: &super::ChunkTimes) {
        self.upload += ct.upload.as_secs_f64();
        self.kernel += ct.kernel.as_secs_f64();
        self.readback += ct.readback.as_secs_f64();
        self.lane_units += ct.lane_units;
        self.lane_slots += ct.lane_slots;
    }

    /// Share of the lane trips the kernel held that did work (None before any dispatch).
    pub fn lane_utilisation(&self) -> Option<f64> {
        (self.lane_slots > 0).then(|| self.lane_units as f64 / self.lane_slots as f64)
    }

    /// A chunk's outputs as read back, with the runs the kernel handed back finished on the CPU
    /// in f64 (`spec(k)` is the run of `outs[k]`); `Err(Interrupted)` if `stop` is raised
    /// (looked at before each run finished here).
    pub(crate) fn finish<'a>(
        &mut self,
        plan: &dyn PairRuns,
        fast: &crate::physics::solver::FastOptions,
        outs: Vec<Option<RunOutput>>,
        spec: impl Fn(usize) -> &'a RunSpec + Sync,
        stop: super::Stop<'_>,
    ) -> Result<Vec<RunOutput>, super::GpuError> {
        let t = Instant::now();
        self.handed_off += outs.iter().filter(|o| o.is_none()).count() as u64;
        let done = outs
            .into_par_iter()
            .enumerate()
            .map(|(k, o)| match o {
                Some(o) => Some(o),
                None if super::context::stopped(stop) => None,
                None => Some(plan.run_on_cpu(spec(k), fast)),
            })
            .collect::<Option<Vec<_>>>()
            .ok_or(super::GpuError::Interrupted);
        self.handoff += t.elapsed().as_secs_f64();
        done
    }
}

/// The plan's records on the device, and `chunk` capped by what one chunk's buffers may hold:
/// what every GPU sweep of `plan` starts with.
pub(crate) fn upload_records(
    plan: &dyn PairRuns,
    ctx: &super::GpuContext,
    opts: &super::GpuOptions,
    chunk: usize,
) -> Result<(super::GpuRecords, u64), super::GpuError> {
    let accels = plan.contact().accels();
    let recs = super::GpuRecords::upload(ctx, opts.precision, &accels)?;
    let chunk = (chunk.max(1) as u64).min(ctx.max_runs_per_chunk(opts.precision));
    Ok((recs, chunk))
}

/// Pack run `spec` of `plan` for the kernel.
pub(crate) fn pack_run(
    plan: &dyn PairRuns,
    spec: &RunSpec,
    recs: &super::GpuRecords,
    opts: &super::GpuOptions,
) -> super::run::Packed {
    super::pack(
        &spec.pair(),
        &plan.forcing(spec),
        spec.record,
        recs,
        &opts.fast,
    )
}

/// Pack the runs `specs` of `plan`, in this order, as one chunk: the runs that can share a free
/// response ([`share`]) get one, unless `opts` says not to or asks for the energy
/// balance (the shortcuts skip its integrals).
pub(crate) fn pack_chunk(
    plan: &dyn PairRuns,
    specs: &[&RunSpec],
    ctx: &super::GpuContext,
    recs: &super::GpuRecords,
    opts: &super::GpuOptions,
) -> super::PackedChunk {
    let mut runs: Vec<_> = specs
        .par_iter()
        .map(|spec| pack_run(plan, spec, recs, opts))
        .collect();
    let shared = if opts.share_free_response && !opts.fast.energy {
        let max = ctx.max_buffer_reals(opts.precision);
        share(plan, specs, &mut runs, max)
    } else {
        Vec::new()
    };
    super::PackedChunk {
        runs,
        shared,
        accel: plan.accel(),
    }
}

/// Run the runs `runs` of a row plan that runs as a pair ([`RowPlan::runs_as_pair`]) on the pair
/// kernel, tracking the buildings' accelerations ([`run_range`] of [`RowPairs`]); `sink` gets
/// each chunk in the row's form, a run that nears the collapse limit run again on the CPU's row
/// kernel (`cpu::row_of_pair`).
pub fn run_row_pairs<E: From<super::GpuError>>(
    plan: &RowPlan,
    runs: std::ops::Range<u64>,
    ctx: &super::GpuContext,
    opts: &super::GpuOptions,
    chunk: usize,
    sink: impl FnMut(&[(RowSpec, RowOutput)]) -> Result<(), E>,
    progress: impl FnMut(u64),
) -> Result<(Summary, GpuTimes), E> {
    run_row_pairs_until(plan, runs, ctx, opts, chunk, None, sink, progress)
}

/// [`run_row_pairs`] watching `stop` (as [`run_range_until`]; also before each run taken again
/// on the CPU's row kernel).
#[allow(clippy::too_many_arguments)]
pub fn run_row_pairs_until<E: From<super::GpuError>>(
    plan: &RowPlan,
    runs: std::ops::Range<u64>,
    ctx: &super::GpuContext,
    opts: &super::GpuOptions,
    chunk: usize,
    stop: super::Stop<'_>,
    mut sink: impl FnMut(&[(RowSpec, RowOutput)]) -> Result<(), E>,
    progress: impl FnMut(u64),
) -> Result<(Summary, GpuTimes), E> {
    let mut summary = Summary::default();
    let pairs = RowPairs(plan);
    let (s, times) = run_range_until(
        &pairs,
        runs,
        ctx,
        opts,
        chunk,
        stop,
        |done: &[(RunSpec, RunOutput)]| {
            let rows: Vec<(RowSpec, RowOutput)> = done
                .par_iter()
                .map(|(p, o)| {
                    if super::context::stopped(stop) {
                        return None;
                    }
                    let spec = plan.run(p.index);
                    let out = crate::engine::cpu::row_of_pair(plan, &spec, o, &opts.fast);
                    Some((spec, out))
                })
                .collect::<Option<_>>()
                .ok_or(super::GpuError::Interrupted)?;
            for (_, o) in &rows {
                summary.count_row(o);
            }
            sink(&rows)
        },
        progress,
    )?;
    summary.seconds = s.seconds;
    Ok((summary, times))
}

/// Run the runs `runs` of `plan` on the GPU, `chunk` runs per chunk (capped by the device's limits);
/// `sink` gets each chunk's results in run order as it finishes. Runs the kernel hands back
/// (more substeps per record step than its precision resolves) are finished on the CPU's fast
/// path in f64. Rows already handed to `sink` stay there if a later chunk fails (device loss,
/// out of memory).
pub fn run_range<E: From<super::GpuError>>(
    plan: &dyn PairRuns,
    runs: std::ops::Range<u64>,
    ctx: &super::GpuContext,
    opts: &super::GpuOptions,
    chunk: usize,
    sink: impl FnMut(&[(RunSpec, RunOutput)]) -> Result<(), E>,
    progress: impl FnMut(u64),
) -> Result<(Summary, GpuTimes), E> {
    run_range_until(plan, runs, ctx, opts, chunk, None, sink, progress)
}

/// [`run_range`] watching `stop`: looked at before each dispatch ([`super::integrate_until`])
/// and before each run finished on the CPU; `Err(Interrupted)` once it is raised (the sink
/// has had whole chunks, in run order).
#[allow(clippy::too_many_arguments)]
pub fn run_range_until<E: From<super::GpuError>>(
    plan: &dyn PairRuns,
    runs: std::ops::Range<u64>,
    ctx: &super::GpuContext,
    opts: &super::GpuOptions,
    chunk: usize,
    stop: super::Stop<'_>,
    mut sink: impl FnMut(&[(RunSpec, RunOutput)]) -> Result<(), E>,
    mut progress: impl FnMut(u64),
) -> Result<(Summary, GpuTimes), E> {
    let start = Instant::now();
    let mut times = GpuTimes::default();
    let (recs, chunk) = upload_records(plan, ctx, opts, chunk)?;
    let n = runs.end;
    let mut s = Summary::default();
    // Packing is host work: the next chunk is packed while the device integrates this one.
    let prep = |c0: u64| {
        let t = Instant::now();
        let specs: Vec<RunSpec> = (c0..(c0 + chunk).min(n))
            .into_par_iter()
            .map(|i| plan.run(i))
            .collect();
        // Stopped while the device integrates the chunk before: left unpacked.
        super::context::check_stop(stop)?;
        let refs: Vec<&RunSpec> = specs.iter().collect();
        let packed = pack_chunk(plan, &refs, ctx, &recs, opts);
        Ok((specs, packed, t.elapsed().as_secs_f64()))
    };
    let mut c0 = runs.start;
    let mut next = (c0 < n).then(|| prep(c0)).transpose()?;
    while let Some((specs, packed, pack_s)) = next.take() {
        let c1 = (c0 + chunk).min(n);
        times.pack += pack_s;
        let (done, upcoming) = rayon::join(
            || super::run_chunk_until(ctx, &recs, &packed, opts, stop),
            || (c1 < n).then(|| prep(c1)),
        );
        let (outs, ct) = done?;
        next = upcoming.transpose()?;
        times.add_chunk(&ct);
        let outs = times.finish(plan, &opts.fast, outs, |k| &specs[k], stop)?;
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

/// Does `spec` lie in a stretch of at least [`MIN_SHARED_RUNS`] consecutive runs of `plan` with
/// its free motion? Decided on the plan, not the chunk, so that whether a run shares (which
/// moves an f32 result by rounding: the response is stepped in f64) does not depend on where
/// chunks end or how a chunk is ordered.
fn in_long_stretch(plan: &dyn PairRuns, spec: &RunSpec) -> bool {
    let same = |j: u64| same_free_motion(spec, &plan.run(j));
    let (mut lo, mut hi) = (spec.index, spec.index);
    while ((hi - lo + 1) as usize) < MIN_SHARED_RUNS && lo > 0 && same(lo - 1) {
        lo -= 1;
    }
    while ((hi - lo + 1) as usize) < MIN_SHARED_RUNS && hi + 1 < plan.runs() && same(hi + 1) {
        hi += 1;
    }
    (hi - lo + 1) as usize >= MIN_SHARED_RUNS
}

/// Give the runs of `packed` (`specs[k]` is the run of `packed[k]`) that lie in a stretch of at
/// least [`MIN_SHARED_RUNS`] consecutive runs of the plan with the same free motion a shared
/// response, one per stretch of such runs that are consecutive in `packed`: sets
/// `meta.response` and `start` of those runs, and returns the responses' tables, one after
/// another. Stretches past `max_reals` in all step their whole records.
pub fn share(
    plan: &dyn PairRuns,
    specs: &[&RunSpec],
    packed: &mut [Packed],
    max_reals: usize,
) -> Vec<f64> {
    let mut stretches: Vec<Vec<usize>> = Vec::new();
    for ks in free_motion_stretches(specs) {
        let len = ks.len();
        let contiguous = specs[ks.end - 1].index - specs[ks.start].index == len as u64 - 1;
        let members: Vec<usize> = if len >= MIN_SHARED_RUNS && contiguous {
            ks.collect()
        } else {
            ks.filter(|&j| in_long_stretch(plan, specs[j])).collect()
        };
        if !members.is_empty() {
            stretches.push(members);
        }
    }
    // Each table's place, as long as they fit; the tables are then built in parallel in place.
    let max_reals = max_reals.min(u32::MAX as usize);
    let mut total = 0;
    let mut placed = Vec::new();
    for ks in stretches {
        let len = table_reals(plan.forcing(specs[ks[0]]).intervals(), plan.accel());
        if total + len > max_reals {
            break;
        }
        placed.push((ks, total, len));
        total += len;
    }
    let mut tables = vec![0.0; total];
    let mut slots = Vec::with_capacity(placed.len());
    let mut rest = &mut tables[..];
    for (_, _, len) in &placed {
        let (slot, tail) = rest.split_at_mut(*len);
        slots.push(slot);
        rest = tail;
    }
    let starts: Vec<Vec<Start>> = placed
        .par_iter()
        .zip(slots)
        .map(|((ks, _, _), slot)| {
            let forcing = plan.forcing(specs[ks[0]]);
            let pair = specs[ks[0]].pair();
            let r = if plan.accel() {
                FreeResponse::with_accel(&pair.b1, &pair.b2, &forcing)
            } else {
                FreeResponse::new(&pair.b1, &pair.b2, &forcing)
            };
            fill_table(&r, slot);
            ks.iter()
                .map(|&k| {
                    let first = r.first_possible_contact(specs[k].gap);
                    let (z, peaks) = r.at(first);
                    Start {
                        i: first as u32,
                        state: [z[0], z[1], z[2], z[3]],
                        peaks,
                    }
                })
                .collect()
        })
        .collect();
    for ((ks, offset, _), starts) in placed.into_iter().zip(starts) {
        for (k, start) in ks.into_iter().zip(starts) {
            packed[k].meta.response = offset as u32;
            packed[k].start = Some(start);
        }
    }
    debug_assert!(packed
        .iter()
        .all(|p| (p.meta.response == NO_RESPONSE) == p.start.is_none()));
    tables
}
