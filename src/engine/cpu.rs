//! The CPU engine: chunks of consecutive runs solved in parallel with rayon
//! ([`crate::physics::solver`], f64), handed to a sink in run order as each batch finishes (so
//! output streams and is identical for any thread count).

use crate::engine::Summary;
use crate::physics::model::{Initial, RunOutput};
use crate::physics::solver::{simulate, Scheme};
use crate::plan::{Plan, RunSpec};
use rayon::prelude::*;
use std::time::Instant;

/// Run one plan entry.
pub fn run_one(plan: &Plan, spec: &RunSpec, scheme: &Scheme) -> RunOutput {
    simulate(
        &spec.pair(),
        &plan.forcing(spec),
        &Initial::default(),
        scheme,
    )
}

/// Run the runs `runs` of `plan` with `scheme`, `chunk` runs per task, on the current rayon pool;
/// `sink` gets each chunk's results in run order, `progress` the number of runs done so far.
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
