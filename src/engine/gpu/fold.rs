//! `--aggregate` on the device: each chunk packed sorted by group, integrated, and folded into
//! per-group partials and histograms by `shaders/aggregate.wgsl` ([`super::reduce`]).

use super::sweep::GpuTimes;
use crate::engine::aggregate::Aggregator;
use crate::engine::Summary;
use crate::plan::{PairPlan, RunSpec};
use rayon::prelude::*;
use std::time::Instant;

/// As [`super::sweep::run_range`] with `--aggregate`: each chunk is packed sorted by group, integrated,
/// and folded into `agg` on the device (`shaders/aggregate.wgsl`), so only the groups' partials
/// come back per chunk and the histograms at the end, not a state per run. Runs the kernel hands
/// back are finished on the CPU and folded on the host. A chunk with more groups than
/// `max_slots` (or than one buffer holds) is read back and folded on the host instead.
#[allow(clippy::too_many_arguments)]
pub fn fold_range(
    plan: &PairPlan,
    runs: std::ops::Range<u64>,
    ctx: &super::GpuContext,
    opts: &super::GpuOptions,
    chunk: usize,
    max_slots: u32,
    agg: &mut Aggregator,
    progress: impl FnMut(u64),
) -> Result<(Summary, GpuTimes), super::GpuError> {
    fold_range_until(plan, runs, ctx, opts, chunk, max_slots, None, agg, progress)
}

/// [`fold_range`] watching `stop` (as [`super::sweep::run_range_until`]): `Err(Interrupted)`
/// once it is raised, `agg` then holding part of the runs.
#[allow(clippy::too_many_arguments)]
pub fn fold_range_until(
    plan: &PairPlan,
    runs: std::ops::Range<u64>,
    ctx: &super::GpuContext,
    opts: &super::GpuOptions,
    chunk: usize,
    max_slots: u32,
    stop: super::Stop<'_>,
    agg: &mut Aggregator,
    mut progress: impl FnMut(u64),
) -> Result<(Summary, GpuTimes), super::GpuError> {
    use super::layout::{Segment, MAX_SEGMENT};
    use super::reduce::{reduce, Slots};
    use super::sweep::{pack_chunk, upload_records};
    use super::{integrate_until, run_chunk_until};
    let start = Instant::now();
    let mut times = GpuTimes::default();
    let (recs, chunk) = upload_records(plan, ctx, opts, chunk)?;
    let mut slots = Slots::new(ctx, max_slots);
    let thresholds = agg.thresholds().to_vec();
    let mut s = Summary::default();
    let end = runs.end;
    // Host work for a chunk: decode, group, order by group, pack, cut into segments. It runs
    // for the next chunk while the device integrates this one.
    let prep = |c0: u64, agg: &mut Aggregator| {
        let t = Instant::now();
        let specs: Vec<RunSpec> = (c0..(c0 + chunk).min(end))
            .into_par_iter()
            .map(|i| plan.run(i))
            .collect();
        let gids: Vec<u32> = specs.iter().map(|r| agg.group_of(plan, r)).collect();
        // Pack sorted by group (stable), so each group is a run of consecutive runs.
        let mut order: Vec<usize> = (0..specs.len()).collect();
        order.sort_by_key(|&i| gids[i]);
        let sorted: Vec<&RunSpec> = order.iter().map(|&i| &specs[i]).collect();
        let packed = pack_chunk(plan, &sorted, ctx, &recs, opts);
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
                || run_chunk_until(ctx, &recs, &p.packed, opts, stop),
                || (c1 < end).then(|| prep(c1, &mut *agg)),
            );
            next = upcoming;
            let (outs, ct) = done?;
            times.add_chunk(&ct);
            times.host_folded_chunks += 1;
            let outs = times.finish(plan, &opts.fast, outs, |k| &p.specs[p.order[k]], stop)?;
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
            || -> Result<_, super::GpuError> {
                let (done, ct) = integrate_until(ctx, &recs, &p.packed, opts, stop)?;
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
        let outs = times.finish(
            plan,
            &opts.fast,
            vec![None; handed.len()],
            |k| &p.specs[run(k)],
            stop,
        )?;
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

/// One chunk's host work for [`fold_range`].
struct Prepared {
    specs: Vec<RunSpec>,
    /// Group of each run (in run order).
    gids: Vec<u32>,
    /// Runs sorted by group: `packed[k]` is run `specs[order[k]]`.
    order: Vec<usize>,
    packed: super::PackedChunk,
    /// Each segment's group, and the segment (slot not yet assigned).
    segments: Vec<(u32, super::layout::Segment)>,
    /// The distinct groups, in segment order.
    groups: Vec<u32>,
    seconds: f64,
}
