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

use crate::physics::solver::FreeResponse;

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
