//! The CPU engine: chunks of consecutive runs solved in parallel with rayon
//! ([`crate::physics::solver`], f64), handed to a sink in run order as each batch finishes (so
//! output streams and is identical for any thread count).

use crate::engine::Summary;
use crate::physics::model::{Initial, RunOutput};
use crate::physics::row::{BuildingDemands, RowOutput};
use crate::physics::solver::row::{near_collapse, simulate_row, RowModel, RowScheme};
use crate::physics::solver::{
    simulate, simulate_shared, simulate_tracking_accel, FastOptions, FreeResponse, Scheme,
};
use crate::plan::row::{RowPlan, RowRunSpec};
use crate::plan::{PairPlan, RunSpec};
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

/// A stop flag never raised: for the callers that run to the end.
pub(crate) static NEVER: AtomicBool = AtomicBool::new(false);

fn stopped(stop: &AtomicBool) -> bool {
    stop.load(Ordering::Relaxed)
}

/// Run one plan entry.
pub fn run_one(plan: &PairPlan, spec: &RunSpec, scheme: &Scheme) -> RunOutput {
    simulate(
        &spec.pair(),
        &plan.forcing(spec),
        &Initial::default(),
        scheme,
    )
}

/// Consecutive runs that share buildings, record and intensity (the gap axis is the innermost)
/// share one free response when there are at least this many of them: building it costs about
/// as much as one run's free steps, and each run saves the steps before its first possible
/// contact and after its early end.
pub const MIN_SHARED_RUNS: usize = 4;

/// Runs that differ at most in gap and contact law move alike while apart.
pub(crate) fn same_free_motion(a: &RunSpec, b: &RunSpec) -> bool {
    (a.record, a.scale, a.m1, a.t1, a.xi1, a.m2, a.t2, a.xi2)
        == (b.record, b.scale, b.m1, b.t1, b.xi1, b.m2, b.t2, b.xi2)
}

/// The stretches of consecutive runs of `specs` with the same free motion, in order.
pub(crate) fn free_motion_stretches<S: std::borrow::Borrow<RunSpec>>(
    specs: &[S],
) -> impl Iterator<Item = std::ops::Range<usize>> + '_ {
    let mut k = 0;
    std::iter::from_fn(move || {
        let first = specs.get(k)?.borrow();
        let len = specs[k..]
            .iter()
            .position(|s| !same_free_motion(first, s.borrow()))
            .unwrap_or(specs.len() - k);
        k += len;
        Some(k - len..k)
    })
}

/// Run `specs` in order; the fast scheme shares one free response ([`FreeResponse`]) among each
/// stretch of at least [`MIN_SHARED_RUNS`] consecutive runs with the same free motion.
pub fn run_many(plan: &PairPlan, specs: &[RunSpec], scheme: &Scheme) -> Vec<RunOutput> {
    run_many_until(plan, specs, scheme, &NEVER)
}

/// [`run_many`], ending early (the outputs of the runs before) once `stop` is raised: it is
/// looked at before each run, so a stop waits for one run per thread, not a chunk.
fn run_many_until(
    plan: &PairPlan,
    specs: &[RunSpec],
    scheme: &Scheme,
    stop: &AtomicBool,
) -> Vec<RunOutput> {
    let mut out = Vec::with_capacity(specs.len());
    for ks in free_motion_stretches(specs) {
        let group = &specs[ks];
        let first = &group[0];
        if group.len() >= MIN_SHARED_RUNS && matches!(scheme, Scheme::Fast(_)) {
            let forcing = plan.forcing(first);
            let pair = first.pair();
            let shared = FreeResponse::new(&pair.b1, &pair.b2, &forcing);
            out.extend(group.iter().take_while(|_| !stopped(stop)).map(|s| {
                simulate_shared(&s.pair(), &forcing, &Initial::default(), scheme, &shared)
            }));
        } else {
            out.extend(
                group
                    .iter()
                    .take_while(|_| !stopped(stop))
                    .map(|s| run_one(plan, s, scheme)),
            );
        }
        if stopped(stop) {
            break;
        }
    }
    out
}

/// Run the runs `specs` of a row plan that runs as a pair ([`RowPlan::runs_as_pair`]) on the
/// pair's kernel, in order, each tracking its buildings' accelerations, sharing free responses
/// as [`run_many`] does; outputs in the row's form ([`RowOutput::of_pair`]). A run that comes
/// near the plan's collapse limit ([`near_collapse`]) is run again on the row's kernel, which
/// models collapse.
pub fn run_row_pairs(plan: &RowPlan, specs: &[RowRunSpec], o: &FastOptions) -> Vec<RowOutput> {
    run_row_pairs_until(plan, specs, o, &NEVER)
}

/// [`run_row_pairs`], ending early once `stop` is raised (looked at before each run).
fn run_row_pairs_until(
    plan: &RowPlan,
    specs: &[RowRunSpec],
    o: &FastOptions,
    stop: &AtomicBool,
) -> Vec<RowOutput> {
    let pairs: Vec<RunSpec> = specs.iter().map(|s| plan.pair_run(s)).collect();
    let mut out = Vec::with_capacity(specs.len());
    for ks in free_motion_stretches(&pairs) {
        if stopped(stop) {
            break;
        }
        let group = &pairs[ks.clone()];
        let forcing = plan.forcing(&specs[ks.start]);
        let pair = group[0].pair();
        let shared = (group.len() >= MIN_SHARED_RUNS)
            .then(|| FreeResponse::with_accel(&pair.b1, &pair.b2, &forcing));
        let todo = group.iter().zip(&specs[ks]).take_while(|_| !stopped(stop));
        out.extend(todo.map(|(s, spec)| {
            let run = simulate_tracking_accel(&s.pair(), &forcing, o, shared.as_ref(), None);
            row_of_pair(plan, spec, &run, o)
        }));
    }
    out
}

/// Run `spec` of a row plan that runs as a pair in the row's form, from `run`, its pair run:
/// run again on the row's kernel where it nears the collapse limit ([`near_collapse`]).
pub(crate) fn row_of_pair(
    plan: &RowPlan,
    spec: &RowRunSpec,
    run: &RunOutput,
    o: &FastOptions,
) -> RowOutput {
    let mut row = RowOutput::of_pair(run, plan.pair_heights());
    if near_collapse(&row, plan.collapse_drift_ratio) {
        let model = row_model(plan, spec);
        let forcing = plan.forcing(spec);
        return simulate_row(&model, &forcing, model.at_rest(), &RowScheme::Fast(*o));
    }
    if plan.tracks_demands() {
        row.demands = (row.buildings.iter())
            .map(BuildingDemands::of_one_storey)
            .collect();
    }
    row
}

/// The model of run `spec` of `plan`, tracking its storeys' and floors' demands where the sweep
/// writes them.
fn row_model(plan: &RowPlan, spec: &RowRunSpec) -> RowModel {
    let mut model = RowModel::new(&plan.row(spec));
    model.track_demands = plan.tracks_demands();
    model
}

/// Run the runs `runs` of `plan` with `scheme`, `chunk` runs per task, on the current rayon pool;
/// `sink` gets each chunk's results in run order, `progress` the number of runs done so far.
pub fn run_range<E>(
    plan: &PairPlan,
    runs: std::ops::Range<u64>,
    scheme: &Scheme,
    chunk: usize,
    sink: impl FnMut(&[(RunSpec, RunOutput)]) -> Result<(), E>,
    progress: impl FnMut(u64),
) -> Result<Summary, E> {
    run_range_until(plan, runs, scheme, chunk, &NEVER, sink, progress)
}

/// [`run_range`] until `stop` is raised (see [`in_batches`]).
pub fn run_range_until<E>(
    plan: &PairPlan,
    runs: std::ops::Range<u64>,
    scheme: &Scheme,
    chunk: usize,
    stop: &AtomicBool,
    sink: impl FnMut(&[(RunSpec, RunOutput)]) -> Result<(), E>,
    progress: impl FnMut(u64),
) -> Result<Summary, E> {
    let solve = |ids: std::ops::Range<u64>| {
        let specs: Vec<RunSpec> = ids.map(|i| plan.run(i)).collect();
        let outs = run_many_until(plan, &specs, scheme, stop);
        specs.into_iter().zip(outs).collect()
    };
    in_batches(runs, chunk, stop, solve, Summary::count, sink, progress)
}

/// Run the runs `runs` of the row plan `plan`, `chunk` runs per task, on the current rayon pool;
/// `sink` gets each chunk's results in run order, `progress` the number of runs done so far
/// (as [`run_range`]).
pub fn run_rows<E>(
    plan: &RowPlan,
    runs: std::ops::Range<u64>,
    chunk: usize,
    sink: impl FnMut(&[(RowRunSpec, RowOutput)]) -> Result<(), E>,
    progress: impl FnMut(u64),
) -> Result<Summary, E> {
    run_rows_until(plan, runs, chunk, &NEVER, sink, progress)
}

/// [`run_rows`] until `stop` is raised (see [`in_batches`]).
pub fn run_rows_until<E>(
    plan: &RowPlan,
    runs: std::ops::Range<u64>,
    chunk: usize,
    stop: &AtomicBool,
    sink: impl FnMut(&[(RowRunSpec, RowOutput)]) -> Result<(), E>,
    progress: impl FnMut(u64),
) -> Result<Summary, E> {
    let scheme = plan.scheme();
    let as_pair = match scheme {
        RowScheme::Fast(o) if plan.runs_as_pair() => Some(o),
        _ => None,
    };
    let solve = |ids: std::ops::Range<u64>| {
        if let Some(o) = &as_pair {
            let specs: Vec<RowRunSpec> = ids.map(|i| plan.run(i)).collect();
            let outs = run_row_pairs_until(plan, &specs, o, stop);
            return specs.into_iter().zip(outs).collect();
        }
        ids.take_while(|_| !stopped(stop))
            .map(|i| {
                let spec = plan.run(i);
                let model = row_model(plan, &spec);
                let out = simulate_row(&model, &plan.forcing(&spec), model.at_rest(), &scheme);
                (spec, out)
            })
            .collect()
    };
    in_batches(runs, chunk, stop, solve, Summary::count_row, sink, progress)
}

/// The runs `runs` in chunks of `chunk`, `solve`d in parallel a batch of chunks at a time (a few
/// per thread, so uneven runs balance); `sink` gets each chunk in run order, `count` adds each
/// output to the summary, `progress` gets the runs done after each batch.
///
/// Once `stop` is raised the sweep ends within a run per thread (`solve` looks at it before
/// each run): the batch in flight is dropped whole, so the sink has had whole chunks in run
/// order, and the summary counts those; the caller, who raised the flag, knows it stopped.
fn in_batches<S: Send, O: Send, E>(
    runs: std::ops::Range<u64>,
    chunk: usize,
    stop: &AtomicBool,
    solve: impl Fn(std::ops::Range<u64>) -> Vec<(S, O)> + Sync,
    count: impl Fn(&mut Summary, &O),
    mut sink: impl FnMut(&[(S, O)]) -> Result<(), E>,
    mut progress: impl FnMut(u64),
) -> Result<Summary, E> {
    let start = Instant::now();
    let chunk = chunk.max(1) as u64;
    let (first, n) = (runs.start, runs.end);
    let nchunks = (n - first.min(n)).div_ceil(chunk);
    let batch = (rayon::current_num_threads() as u64 * 4).max(1);
    let mut s = Summary::default();
    let mut c0 = 0;
    while c0 < nchunks && !stopped(stop) {
        let c1 = (c0 + batch).min(nchunks);
        let results: Vec<Vec<(S, O)>> = (c0..c1)
            .into_par_iter()
            .map(|c| solve(first + c * chunk..(first + (c + 1) * chunk).min(n)))
            .collect();
        if stopped(stop) {
            break;
        }
        for r in &results {
            for (_, o) in r {
                count(&mut s, o);
            }
            sink(r)?;
        }
        progress(s.runs);
        c0 = c1;
    }
    s.seconds = start.elapsed().as_secs_f64();
    Ok(s)
}
