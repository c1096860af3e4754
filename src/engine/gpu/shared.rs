//! Shared free responses for the kernel: the GPU side of [`FreeResponse`]. Runs of a chunk that
//! differ only in gap and contact law (consecutive, as the CPU engine groups them) get one free
//! response, computed here on the host; each run starts at its first possible contact with the
//! response's state and peaks there (a run that never comes within its gap is done before the
//! first dispatch), and the kernel (`fast.wgsl`, "shared free response") ends a run early from
//! the response's table, as `fast::run` does on the CPU.
//!
//! Unlike the CPU, the kernel does not settle single free steps from the response (a per-step
//! table of reach and peak bounds): on lavapipe that made the kernel 15 % slower, as lanes that
//! cannot settle a step hold those that can (`pound bench --sizes 10000`, kernel 1.74 s without,
//! 2.0 s with).
//!
//! A response's table at `responses[Meta::response..]`, in reals:
//! - [`header_reals`]: `omega`, reach growth and peak growth, each for building 1 then 2
//!   (`FreeResponse::rates`), then, where the runs track their accelerations (`accel`), the
//!   acceleration bounds' growth;
//! - [`reals_per_check`] per checkpoint, the samples `i = CHECK_EVERY * c < intervals`: the
//!   state `[u1, v1, u2, v2]` there and the largest reach and peak bounds over steps `i..`
//!   (then the acceleration bounds' with `accel`).
//!
//! A run takes its distance `R` from the shared motion only at checkpoints, where it checks for
//! an early end, so one state per `CHECK_EVERY` steps is all the kernel reads.

use super::layout::NO_RESPONSE;
use super::run::Packed;
use super::sweep::PairRuns;
use crate::engine::cpu::{free_motion_stretches, same_free_motion, MIN_SHARED_RUNS};
use crate::physics::solver::FreeResponse;
use crate::plan::RunSpec;
use rayon::prelude::*;

/// Reals of a table's header, and per checkpoint (see the module's notes).
pub const fn header_reals(accel: bool) -> usize {
    6 + 2 * accel as usize
}
pub const fn reals_per_check(accel: bool) -> usize {
    7 + 2 * accel as usize
}
/// Record steps between checkpoints: a run may end early, or learn its distance again after a
/// contact, at these samples (the CPU checks for an early end as often, `fast::END_CHECK_EVERY`).
pub const CHECK_EVERY: usize = 8;

/// Reals of one response's table over `intervals` record steps.
pub fn table_reals(intervals: usize, accel: bool) -> usize {
    header_reals(accel) + reals_per_check(accel) * intervals.div_ceil(CHECK_EVERY)
}

/// Write a response's table (see the module's notes) into `out`, `table_reals` long.
pub fn fill_table(r: &FreeResponse, out: &mut [f64]) {
    let n = r.intervals();
    let accel = r.accel();
    let (head, checks) = out.split_at_mut(header_reals(accel));
    for (k, pair) in r.rates().iter().enumerate() {
        head[2 * k..2 * k + 2].copy_from_slice(pair);
    }
    if accel {
        head[6..].copy_from_slice(&r.accel_growth());
    }
    let per = reals_per_check(accel);
    debug_assert_eq!(checks.len(), per * n.div_ceil(CHECK_EVERY));
    for (c, t) in checks.chunks_exact_mut(per).enumerate() {
        let i = c * CHECK_EVERY;
        let (z, _) = r.at(i);
        let (reach, bound) = r.maxima_after(i);
        t[..4].copy_from_slice(&z[..4]);
        t[4..7].copy_from_slice(&[reach, bound[0], bound[1]]);
        if accel {
            t[7..].copy_from_slice(&r.accel_bounds_after(i));
        }
    }
}

/// Where a run sharing a response starts: its first possible contact (`i = intervals`: it never
/// comes within its gap, and is done), the response's state and peaks there.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Start {
    pub i: u32,
    pub state: [f64; 4],
    /// `[u1, u2, a1, a2]` (the accelerations' 0 where the runs do not track them).
    pub peaks: [f64; 4],
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
