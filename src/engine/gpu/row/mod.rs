//! Rows of shear buildings on the GPU (`shaders/row.wgsl`, the twin of
//! [`crate::physics::solver::row::fast`]): the row's shape, which the kernel is built for
//! (storey counts and contact levels become WGSL constants, so a kernel loops over exactly the
//! modes and levels its row has); packing runs and their building models into flat buffers;
//! the dispatch loop; reading results back.
//!
//! Buffers, per run: a block of reals (`P_*`: record and contact settings, the gaps, each
//! level's contact), a block of u32 (`M_*`: law, record, each building's model), and the state
//! that persists between dispatches (`S_*` reals, `C_*` u32). Building models (modes, shapes,
//! masses, heights, propagators) are shared by the runs that use the same one.
//!
//! - [`shape`]: the shape and the offsets of its blocks;
//! - [`wgsl`]: the shape as WGSL constants and written-out functions;
//! - [`pack`]: a chunk's runs and building models packed;
//! - here: the kernels, the dispatch loop, reading results back, the sweep of a row plan.

mod pack;
mod shape;
mod wgsl;

pub use pack::{collapse_param, PackedRows};
use pack::{model_blocks, StoreyReadout};
// The offsets of the row kernel's blocks are part of its public layout.
pub use shape::*;
pub use wgsl::UNROLL_MAX_SQUARES;

use super::buffers::{bind_group, read, storage, wait, zeroed};
use super::context::{check_stop, stopped, GpuContext, GpuError, Kernel, Stage, Stop};
use super::layout::{MODE_FREE, STATUS_COLLAPSE, STATUS_HANDOFF, STATUS_NON_FINITE, STATUS_OK};
use super::precision::Precision;
use super::run::{came_back_ended, unit_cap, ChunkTimes, GpuOptions, GpuRecords, WorkLists};
use super::sweep::GpuTimes;
use crate::engine::Summary;
use crate::physics::model::Status;
use crate::physics::row::{BuildingOutput, LevelOutput, RowOutput, StoreyOutput};
use crate::physics::solver::row::{simulate_row, RowModel, RowScheme};
use crate::physics::solver::FastOptions;
use crate::plan::row::{RowPlan, RowRunSpec};
use rayon::prelude::*;
use std::sync::Arc;
use std::time::Instant;

/// lavapipe ends a shader's loops after about 65,535 back edges per invocation, counted over
/// all its loops (see [`super::run::CPU_ADAPTER_BUDGET`]): a dispatch's units on a software
/// adapter are capped to stay below this many loop trips.
const SOFTWARE_LOOP_TRIPS: u64 = 60_000;

/// The row kernels, kept by the context as every other (it knows no row shape: the shape
/// gives the stage its key and its source).
impl GpuContext {
    /// The row kernel for `shape` in `precision`, compiled on first use; `stop` watched while
    /// it is built ([`GpuContext::stage`]).
    pub fn row_kernel(
        &self,
        precision: Precision,
        shape: &RowShape,
        stop: Stop<'_>,
    ) -> Result<Arc<Kernel>, GpuError> {
        use std::hash::{Hash, Hasher};
        let constants = shape.wgsl_constants();
        let mut h = std::collections::hash_map::DefaultHasher::new();
        constants.hash(&mut h);
        let stage = Stage::Row {
            hash: h.finish(),
            loops: !shape.unrolled(),
        };
        self.stage(
            stage,
            precision,
            || super::shader::row_source(precision, &constants, shape.has_imk()),
            stop,
        )
    }
}

/// Units of work per dispatch on a software adapter (unbounded on hardware), or an error when
/// a row of `shape` cannot run there at all.
fn software_cap(ctx: &GpuContext, shape: &RowShape) -> Result<u64, GpuError> {
    let cap = SOFTWARE_LOOP_TRIPS / shape.loop_trips_per_unit();
    if ctx.is_software() && cap == 0 {
        return Err(GpuError::Other {
            message: format!(
                "a row of {} storeys and {} contact levels is too large for the software adapter's loop limit (use --backend cpu)",
                shape.modes(),
                shape.levels.len()
            ),
        });
    }
    Ok(cap)
}

/// Can the row kernel run `plan` on `ctx`? Decided from the plan alone, so a sweep refuses
/// before it makes any file.
pub fn check_fits(ctx: &GpuContext, plan: &RowPlan) -> Result<(), GpuError> {
    if plan.is_empty() {
        return Ok(());
    }
    let shape = RowShape::of_plan(plan);
    software_cap(ctx, &shape).map(|_| ())
}

/// How the kernel left a run. Nearly every run ends with its output, so it is not boxed.
#[allow(clippy::large_enum_variant)]
enum Ended {
    Output(RowOutput),
    /// More substeps per record step than the precision resolves (`STATUS_HANDOFF`).
    HandedBack,
    /// A building's peak drift ratio reached the collapse limit (`STATUS_COLLAPSE`).
    Collapse,
}

impl Ended {
    fn output(self) -> Option<RowOutput> {
        match self {
            Ended::Output(o) => Some(o),
            Ended::HandedBack | Ended::Collapse => None,
        }
    }
}

/// Integrate a chunk of packed rows over their whole records; results in input order, None
/// for runs handed back to the host (more substeps per record step than `opts` allows the
/// precision, or a building's peak drift ratio reached the collapse limit: the kernel ends
/// such a run there).
pub fn run_rows(
    ctx: &GpuContext,
    recs: &GpuRecords,
    chunk: &PackedRows,
    opts: &GpuOptions,
) -> Result<(Vec<Option<RowOutput>>, ChunkTimes), GpuError> {
    let (ends, times) = integrate_rows(ctx, recs, chunk, opts, None)?;
    Ok((ends.into_iter().map(Ended::output).collect(), times))
}

/// [`run_rows`], each run's end as the kernel left it; `stop` watched between dispatches
/// (`Err(Interrupted)` once raised).
fn integrate_rows(
    ctx: &GpuContext,
    recs: &GpuRecords,
    chunk: &PackedRows,
    opts: &GpuOptions,
    stop: Stop<'_>,
) -> Result<(Vec<Ended>, ChunkTimes), GpuError> {
    let mut times = ChunkTimes::default();
    let n = chunk.runs;
    if n == 0 {
        return Ok((Vec::new(), times));
    }
    if opts.fast.energy {
        return Err(GpuError::Other {
            message: "the GPU row kernel does not integrate the energy balance".into(),
        });
    }
    let shape = &chunk.shape;
    let cap = software_cap(ctx, shape)?;
    let kernel = ctx.row_kernel(opts.precision, shape, stop)?;
    let t = Instant::now();
    let p = opts.precision;
    let params = storage(
        ctx,
        "row params",
        &p.reals(&chunk.params_in(p)),
        wgpu::BufferUsages::empty(),
    )?;
    let meta = storage(
        ctx,
        "row metas",
        bytemuck::cast_slice(&chunk.meta),
        wgpu::BufferUsages::empty(),
    )?;
    let models = storage(
        ctx,
        "building models",
        &p.reals(&chunk.models.reals),
        wgpu::BufferUsages::empty(),
    )?;
    // Runs start at rest: a new buffer is zeroed, which is the state at rest, every level
    // free and every counter 0.
    let states = zeroed(
        ctx,
        "row states",
        (n * shape.s_stride() * p.bytes()) as u64,
        wgpu::BufferUsages::COPY_SRC,
    )?;
    let counters = zeroed(
        ctx,
        "row counters",
        (n * shape.c_stride() * 4) as u64,
        wgpu::BufferUsages::COPY_SRC,
    )?;
    let lists = WorkLists::new(ctx, n)?;
    let bind = |from: &wgpu::Buffer, to: &wgpu::Buffer, label| {
        let buffers = [
            &lists.uniform,
            &params,
            &meta,
            recs.buffer(),
            &states,
            &counters,
            &lists.tally,
            from,
            to,
            &models,
        ];
        bind_group(ctx, &kernel.layout, label, &buffers)
    };
    let binds = [
        bind(&lists.ids[0], &lists.ids[1], "row bind group a->b"),
        bind(&lists.ids[1], &lists.ids[0], "row bind group b->a"),
    ];
    wait(ctx)?;
    times.upload = t.elapsed();
    let budget = opts
        .units_per_dispatch
        .max(1)
        .min(unit_cap(ctx, cap.min(u32::MAX as u64) as u32));
    let max_units = row_units(shape.last_interval(&chunk.meta), &opts.fast);
    lists.run(
        "row", ctx, &kernel, &binds, budget, max_units, opts, stop, &mut times,
    )?;
    let t = Instant::now();
    let sbytes = read(ctx, &states)?;
    let cbytes = read(ctx, &counters)?;
    let reals: Vec<f64> = match p {
        Precision::F64 => bytemuck::cast_slice::<u8, f64>(&sbytes).to_vec(),
        Precision::F32 => bytemuck::cast_slice::<u8, f32>(&sbytes)
            .iter()
            .map(|&x| x as f64)
            .collect(),
    };
    let words: &[u32] = bytemuck::cast_slice(&cbytes);
    unfinished(shape, &chunk.meta, words)?;
    let out = (0..n)
        .map(|r| {
            let s = &reals[r * shape.s_stride()..(r + 1) * shape.s_stride()];
            let c = &words[r * shape.c_stride()..(r + 1) * shape.c_stride()];
            let ns = shape.yielding_storeys();
            output(shape, s, c, &chunk.storey_readouts[r * ns..(r + 1) * ns])
        })
        .collect();
    times.readback = t.elapsed();
    Ok((out, times))
}

/// The most units of work a row run of at most `end` record intervals (its settling tail
/// included) can take with `fast`'s caps (`shaders/row.wgsl`, `integrate_run`), doubled for
/// what a count by hand may miss: each interval is begun once; a piece takes one RK4 substep in
/// its trial (the run ends at `max_substeps + 1`), then at most a probe of a hidden touch and
/// its retake, or the event search (its estimates each with a guard probe, its bisections, the
/// step to its end); a unit that only moves to the next substep comes at most
/// `max_substeps_per_step` times per interval.
fn row_units(end: u64, fast: &FastOptions) -> u64 {
    use crate::physics::solver::fast::{LOCATE_BISECTIONS, LOCATE_ITERATIONS};
    let search = 2 * LOCATE_ITERATIONS as u64 + LOCATE_BISECTIONS as u64 + 1;
    let pieces = (fast.max_substeps as u64 + 1).saturating_mul(2 + search);
    let moves = end.saturating_mul(fast.max_substeps_per_step as u64);
    let count = end.saturating_add(moves).saturating_add(pieces);
    count.saturating_mul(2)
}

/// Every run of a chunk read back (`meta` and `counters`: the chunk's blocks) must have ended
/// as `ended()` in `shaders/row.wgsl` says (its record integrated and, with yielding storeys,
/// settled or its settling time spent), or with a status that ends it: one still running would
/// be written as a finished run with part of its record.
fn unfinished(shape: &RowShape, meta: &[u32], counters: &[u32]) -> Result<(), GpuError> {
    let nb = shape.storeys.len();
    came_back_ended(meta.len() / shape.m_stride(), |r| {
        let m = &meta[r * shape.m_stride()..(r + 1) * shape.m_stride()];
        let c = &counters[r * shape.c_stride()..(r + 1) * shape.c_stride()];
        // The interval a run runs to: its record's end, or with yielding storeys its settling
        // time's, unless it settled first.
        let (end, settled) = match shape.yields() {
            0 => (m[M_INTERVALS], false),
            _ => (m[M_MODELS + nb], c[shape.c_settled()] != 0),
        };
        let done = c[C_I] >= m[M_INTERVALS] && (settled || c[C_I] >= end);
        (c[C_STATUS] == STATUS_OK && !done).then_some((c[C_I], end))
    })
}

/// A run's results from its final state and counters (what `RowRun::finish` does on the CPU,
/// without the energy balance), `storeys`: its yielding storeys'; or that it was handed back.
fn output(shape: &RowShape, s: &[f64], c: &[u32], storeys: &[StoreyReadout]) -> Ended {
    let status = match c[C_STATUS] {
        STATUS_HANDOFF => return Ended::HandedBack,
        STATUS_COLLAPSE => return Ended::Collapse,
        STATUS_OK => Status::Ok,
        STATUS_NON_FINITE => Status::NonFinite,
        _ => Status::StepLimit,
    };
    let levels = (0..shape.levels.len())
        .map(|l| {
            let ls = &s[shape.s_levels() + LS_STRIDE * l..];
            let lc = &c[C_LEVELS + LC_STRIDE * l..];
            let (mut peak_force, mut impact_velocity) = (ls[LS_PEAK_FORCE], ls[LS_IMPACT_VELOCITY]);
            // An impact still under way ends with the run.
            if lc[LC_MODE] != MODE_FREE && ls[LS_IMP_PEAK] > peak_force {
                peak_force = ls[LS_IMP_PEAK];
                impact_velocity = ls[LS_V0];
            }
            LevelOutput {
                impacts: lc[LC_IMPACTS],
                peak_force,
                peak_penetration: ls[LS_PENETRATION],
                impact_velocity,
                first_impact: (lc[LC_IMPACTS] > 0).then_some(ls[LS_FIRST_IMPACT]),
                contact_time: ls[LS_CONTACT_TIME],
                dissipated_energy: ls[LS_DISSIPATED],
                column_shear: ls[LS_COLUMN_SHEAR],
                column_shear_ratio: shape.struck_storey(l).map_or(0.0, |st| {
                    let st = &storeys[st];
                    ls[LS_COLUMN_SHEAR] / (st.column_share * st.yield_force)
                }),
            }
        })
        .collect();
    let buildings = (0..shape.storeys.len())
        .map(|b| {
            let bs = &s[shape.s_buildings() + BS_STRIDE * b..];
            let bc = &c[shape.c_buildings() + BC_STRIDE * b..];
            BuildingOutput {
                peak_roof: bs[BS_ROOF],
                peak_drift_ratio: bs[BS_DRIFT],
                drift_storey: bc[BC_DRIFT_STOREY],
                peak_accel: bs[BS_ACCEL],
                accel_floor: bc[BC_ACCEL_FLOOR],
                inelastic: None,
                collapse: None,
            }
        })
        .collect();
    let mut out = RowOutput {
        status,
        levels,
        buildings,
        substeps: c[C_SUBSTEPS] as u64,
        free_steps: c[C_FREE_STEPS] as u64,
        ..RowOutput::default()
    };
    let ns = shape.yielding_storeys();
    if ns > 0 {
        let ps = shape.plastic_slot0();
        out.storeys = storeys
            .iter()
            .enumerate()
            .map(|(k, st)| StoreyOutput {
                residual_drift_ratio: st.residual(&s[ps..ps + ns]) / st.height,
                peak_ductility: s[shape.s_storeys() + k] * st.height / st.d_y,
                hysteretic_energy: s[ps + ns + k],
                yielded: c[shape.c_storeys() + SC_STRIDE * k + SC_YIELDED] != 0,
                strength_ratio: st.fcap0.map_or(f64::NAN, |fcap0| {
                    // ImkState::strength_ratio: the weaker side's capping strength left.
                    let flags = c[shape.c_imk() + IC_STRIDE * k + IC_FLAGS];
                    let left = |i: usize| {
                        let failed = flags & (IF_FAILED0 << i) != 0;
                        let side = shape.s_imk() + IS_STRIDE * k + IR_SIDE * i;
                        if failed {
                            0.0
                        } else {
                            s[side + IR_FCAP]
                        }
                    };
                    left(0).min(left(1)) / fcap0
                }),
                capped: st.fcap0.is_some()
                    && c[shape.c_imk() + IC_STRIDE * k + IC_FLAGS] & IF_CAPPED != 0,
            })
            .collect();
        let spans: Vec<_> = (shape.first_storeys().into_iter())
            .zip(&shape.storeys)
            .map(|(f, &n)| f.map(|f| f..f + n))
            .collect();
        let settled = c[shape.c_settled()] != 0 && status == Status::Ok;
        out.gather_storeys(&spans, &vec![settled; spans.len()]);
    }
    out.gather();
    Ended::Output(out)
}

/// The runs `runs` of a row plan on the GPU in chunks of `chunk`, each chunk's runs handed back
/// by the kernel finished on the CPU in f64 (as for pairs); `sink` gets each chunk in run order,
/// `progress` the runs done after each. With the summary, where the time went and the kernel's
/// lane tally (`handed_off`: the runs the kernel handed back; `handoff` also times the runs
/// that reached the collapse limit, run again on the CPU).
pub fn sweep_rows<E: From<GpuError>>(
    ctx: &GpuContext,
    plan: &RowPlan,
    runs: std::ops::Range<u64>,
    chunk: usize,
    opts: &GpuOptions,
    sink: impl FnMut(&[(RowRunSpec, RowOutput)]) -> Result<(), E>,
    progress: impl FnMut(u64),
) -> Result<(Summary, GpuTimes), E> {
    sweep_rows_until(ctx, plan, runs, chunk, opts, None, sink, progress)
}

/// [`sweep_rows`] watching `stop`: looked at before each dispatch, before each run's model is
/// built for the next chunk and before each run taken again on the CPU; `Err(Interrupted)` once
/// it is raised (the sink has had whole chunks, in run order).
#[allow(clippy::too_many_arguments)]
pub fn sweep_rows_until<E: From<GpuError>>(
    ctx: &GpuContext,
    plan: &RowPlan,
    runs: std::ops::Range<u64>,
    chunk: usize,
    opts: &GpuOptions,
    stop: Stop<'_>,
    mut sink: impl FnMut(&[(RowRunSpec, RowOutput)]) -> Result<(), E>,
    mut progress: impl FnMut(u64),
) -> Result<(Summary, GpuTimes), E> {
    let start = Instant::now();
    let mut times = GpuTimes::default();
    if runs.is_empty() {
        return Ok((Summary::default(), times));
    }
    let accels = plan.contact.accels();
    let recs = GpuRecords::upload(ctx, opts.precision, &accels)?;
    // Every per-run buffer of a chunk must fit one binding (tall rows carry large blocks).
    let shape = RowShape::of_plan(plan);
    let chunk =
        (chunk.max(1) as u64).min(ctx.runs_fitting(shape.largest_block_bytes(opts.precision)));
    let cpu = RowScheme::Fast(opts.fast);
    let mut summary = Summary::default();
    // A chunk's host work: its runs, their models (a Jacobi decomposition per building) and
    // model blocks (a propagator per mode) on every thread, then packed in run order. The next
    // chunk's is done while the device integrates this one, as for pairs.
    let prep = |first: u64| {
        let t = Instant::now();
        let end = (first + chunk).min(runs.end);
        let specs: Vec<RowRunSpec> = (first..end).into_par_iter().map(|i| plan.run(i)).collect();
        // Stopped while the device integrates the chunk before: the rest left unbuilt.
        let built: Option<Vec<(RowModel, Vec<Vec<f64>>)>> = specs
            .par_iter()
            .map(|s| {
                if stopped(stop) {
                    return None;
                }
                let m = RowModel::new(&plan.row(s));
                let b = model_blocks(&m, plan.forcing(s).dt);
                Some((m, b))
            })
            .collect();
        let (models, blocks): (Vec<RowModel>, Vec<Vec<Vec<f64>>>) =
            built.ok_or(GpuError::Interrupted)?.into_iter().unzip();
        let mut packed = PackedRows::new(shape.clone());
        for ((s, m), b) in specs.iter().zip(&models).zip(blocks) {
            let forcing = plan.forcing(s);
            packed.push_with_blocks(m, &forcing, s.contact.record, &recs, &opts.fast, b);
        }
        Ok((specs, models, packed, t.elapsed().as_secs_f64()))
    };
    let mut first = runs.start;
    // The kernel is built while the first chunk is prepared (lavapipe builds a tall row's for
    // seconds), watching the stop; the chunks then find it built.
    software_cap(ctx, &shape)?;
    let (kernel, prepared) = rayon::join(
        || ctx.row_kernel(opts.precision, &shape, stop),
        || prep(first),
    );
    kernel?;
    let mut next = Some(prepared?);
    while let Some((specs, models, packed, pack_s)) = next.take() {
        let end = first + specs.len() as u64;
        times.pack += pack_s;
        let (done, upcoming) = rayon::join(
            || integrate_rows(ctx, &recs, &packed, opts, stop),
            || (end < runs.end).then(|| prep(end)),
        );
        let (outs, ct) = done?;
        next = upcoming.transpose()?;
        times.add_chunk(&ct);
        let t = Instant::now();
        times.handed_off += outs
            .iter()
            .filter(|o| matches!(o, Ended::HandedBack))
            .count() as u64;
        // The runs handed back, on every thread.
        let rows: Vec<(RowRunSpec, RowOutput)> = specs
            .into_par_iter()
            .zip(outs)
            .zip(&models)
            .map(|((s, o), m)| -> Result<_, GpuError> {
                // The kernel has no collapse event: it ends a run once a building's peak drift
                // ratio reaches the limit (`Ended::Collapse`), and the CPU runs it again and
                // ends it at the collapse. The kernel's test is this one (the limit rounded up
                // in f32), so this only restates it.
                let o = o.output().filter(|o| {
                    o.buildings
                        .iter()
                        .all(|b| b.peak_drift_ratio < plan.collapse_drift_ratio)
                });
                let o = match o {
                    Some(o) => o,
                    None => {
                        check_stop(stop)?;
                        simulate_row(m, &plan.forcing(&s), m.at_rest(), &cpu)
                    }
                };
                Ok((s, o))
            })
            .collect::<Result<_, GpuError>>()?;
        times.handoff += t.elapsed().as_secs_f64();
        for (_, o) in &rows {
            summary.count_row(o);
        }
        sink(&rows)?;
        progress(summary.runs);
        first = end;
    }
    summary.seconds = start.elapsed().as_secs_f64();
    Ok((summary, times))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A row read back with its status OK before its record's end (or, with yielding storeys,
    /// before it settled or its settling time ran out) is refused, named.
    #[test]
    fn a_row_read_back_unfinished_is_an_error() {
        // Three runs of 10 record intervals; counters (status, interval, settled).
        let check = |shape: &RowShape, runs: &[(u32, u32, u32)]| {
            let (ms, cs) = (shape.m_stride(), shape.c_stride());
            let mut meta = vec![0; ms * runs.len()];
            let mut counters = vec![0; cs * runs.len()];
            for (r, &(status, i, settled)) in runs.iter().enumerate() {
                meta[r * ms + M_INTERVALS] = 10;
                if shape.yields() > 0 {
                    meta[r * ms + M_MODELS + shape.storeys.len()] = 15;
                    counters[r * cs + shape.c_settled()] = settled;
                }
                counters[r * cs + C_STATUS] = status;
                counters[r * cs + C_I] = i;
            }
            unfinished(shape, &meta, &counters).map_err(|e| e.to_string())
        };
        let elastic = RowShape::elastic(vec![2, 3], vec![[0, 1, 2]]);
        let ended = [
            (STATUS_OK, 10, 0),
            (STATUS_NON_FINITE, 3, 0),
            (STATUS_HANDOFF, 0, 0),
            (STATUS_COLLAPSE, 4, 0),
        ];
        check(&elastic, &ended).unwrap();
        let e = check(
            &elastic,
            &[(STATUS_OK, 10, 0), (STATUS_OK, 4, 0), (STATUS_OK, 0, 0)],
        )
        .unwrap_err();
        assert!(
            e.contains("2 runs of a chunk of 3")
                && e.contains("chunk run 1, at record interval 4 of 10"),
            "{e}"
        );
        // With yielding storeys a run goes on past its record until it settles (or its
        // settling time, here 15 intervals, runs out).
        let yielding = RowShape {
            yielding: vec![true, false],
            ..elastic
        };
        check(&yielding, &[(STATUS_OK, 12, 1), (STATUS_OK, 15, 0)]).unwrap();
        let e = check(&yielding, &[(STATUS_OK, 12, 1), (STATUS_OK, 12, 0)]).unwrap_err();
        assert!(
            e.contains("1 runs of a chunk of 2")
                && e.contains("chunk run 1, at record interval 12 of 15"),
            "{e}"
        );
        let e = check(&yielding, &[(STATUS_OK, 9, 1)]).unwrap_err();
        assert!(e.contains("at record interval 9 of 15"), "{e}");
    }
}
