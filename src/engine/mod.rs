//! The engine: runs a range of any plan's runs and hands their outputs on, a chunk at a time in
//! run order ([`Engine::sweep`]), or folded into groups ([`Engine::summarise`], `--aggregate`);
//! for a pair's plan also [`Engine::run`], [`Engine::fold`] and [`Engine::collect`], which the
//! studies built on pairs use. One enum, [`Engine`], is every path: the CPU (the physics' solvers
//! on a rayon pool, [`cpu`]) or the GPU (the WGSL kernels, [`gpu`]; with `--aggregate`, a pair's
//! fold runs on the device too). [`Backend`], [`gpu_for`] and [`Engine::new`] are the one place
//! a backend is chosen; [`Kernel::of`] the one place a scene's kernels are.
//!
//! May import the physics, records and the plan; never io, studies or the command line.

pub mod aggregate;
pub mod cpu;
pub mod gpu;
pub mod quantile;

use crate::physics::model::{RunOutput, Status};
use crate::physics::row::RowOutput;
use crate::physics::solver::Scheme;
use crate::plan::limits::{MAX_CPU_CHUNK, MAX_GPU_CHUNK, WHY_CHUNK};
use crate::plan::row::{RowPlan, RowRunSpec};
use crate::plan::{PairPlan, Plan, RunSpec};
use aggregate::Aggregator;
use gpu::{GpuContext, GpuError, GpuOptions, GpuTimes, Precision};
use std::ops::Range;
use std::sync::atomic::AtomicBool;

/// Runs per parallel task on the CPU: small enough to balance uneven runs over the threads.
pub const CPU_CHUNK: usize = 64;
/// Runs per GPU chunk: enough lanes to fill a large GPU, few enough to stream the output.
pub const GPU_CHUNK: usize = 65536;

/// Totals of a finished sweep.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Summary {
    pub runs: u64,
    pub seconds: f64,
    pub runs_with_impacts: u64,
    pub impacts: u64,
    pub failures: u64,
    /// Runs that collapsed (not failures: a storey reached the collapse drift ratio).
    pub collapsed: u64,
    /// Exact free record steps and RK4 substeps, summed over runs (not counted by the device
    /// fold: 0 there).
    pub free_steps: u64,
    pub substeps: u64,
    /// Record steps settled by a shared free response, and the runs that settled any (started
    /// at their first possible contact or ended early; the CPU fast path only).
    pub shared_steps: u64,
    pub runs_sharing: u64,
}

impl Summary {
    /// Count one finished run.
    pub(crate) fn count(&mut self, o: &RunOutput) {
        self.count_work(o.status, o.impacts, o.free_steps, o.substeps);
        self.shared_steps += o.shared_steps;
        self.runs_sharing += (o.shared_steps > 0) as u64;
    }

    /// Count one finished run of a row.
    pub(crate) fn count_row(&mut self, o: &crate::physics::row::RowOutput) {
        self.count_work(o.status, o.impacts, o.free_steps, o.substeps);
        self.shared_steps += o.shared_steps;
        self.runs_sharing += (o.shared_steps > 0) as u64;
    }

    fn count_work(&mut self, status: Status, impacts: u32, free_steps: u64, substeps: u64) {
        self.runs += 1;
        self.impacts += impacts as u64;
        self.runs_with_impacts += (impacts > 0) as u64;
        self.failures += status.failed() as u64;
        self.collapsed += (status == Status::Collapsed) as u64;
        self.free_steps += free_steps;
        self.substeps += substeps;
    }

    /// Count the runs of a device partial (handed-back runs are counted when finished).
    fn count_partial(&mut self, p: &aggregate::Partial) {
        self.runs += p.runs;
        self.impacts += p.impacts;
        self.runs_with_impacts += p.pounded;
        self.failures += p.failures;
    }

    pub fn runs_per_second(&self) -> f64 {
        self.runs as f64 / self.seconds.max(1e-9)
    }
}

#[derive(Debug, thiserror::Error)]
pub enum EngineError {
    #[error("--chunk {chunk}: expected 1 to {max} on the {on} ({WHY_CHUNK})")]
    Chunk {
        chunk: usize,
        max: usize,
        on: &'static str,
    },
    #[error("--backend gpu runs the fast scheme only; use --scheme fast or --backend cpu")]
    GpuNeedsFast,
    /// A scene the GPU kernels do not take as asked.
    #[error("--backend gpu: {0}; use --backend cpu")]
    GpuUnfit(&'static str),
    #[error(transparent)]
    Gpu(#[from] GpuError),
}

/// Where runs should be integrated, as asked (`--backend`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Backend {
    /// A hardware GPU if one is found, else the CPU (with a notice saying why): a software
    /// adapter (lavapipe) is slower than the CPU path on the same cores.
    Auto,
    /// Any adapter, software ones included; none is an error.
    Gpu,
    /// Any adapter, software ones included, else the CPU with a notice (`pound bench`, which
    /// measures whatever is there).
    Any,
    Cpu,
}

impl Backend {
    /// The GPU this backend asks for: none for `Cpu`, an error if `Gpu` finds none, and for
    /// `Auto` a hardware adapter (`Any`: any adapter) or, without one, none and a notice
    /// (`fallback: why`).
    pub fn acquire(
        self,
        fallback: &str,
        note: &mut dyn FnMut(String),
    ) -> Result<Option<GpuContext>, GpuError> {
        Ok(match self {
            Backend::Cpu => None,
            Backend::Gpu => Some(GpuContext::new()?),
            Backend::Auto | Backend::Any => match GpuContext::new() {
                Ok(c) if c.is_software() && self == Backend::Auto => {
                    note(format!(
                        "notice: {fallback}: the adapter found, {}, is a software one (slower than the CPU path on the same cores); --backend gpu uses it",
                        c.info.name
                    ));
                    None
                }
                Ok(c) => Some(c),
                Err(e) => {
                    note(format!("notice: {fallback}: {e}"));
                    None
                }
            },
        })
    }
}

/// The kernels a plan's runs take, chosen from its scene alone ([`Kernel::of`]): the one place
/// that choice is made.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kernel {
    /// Two elastic one-storey buildings, written as a pair or as a row of two
    /// ([`RowPlan::runs_as_pair`]; the fast scheme): the specialised pair kernels (CPU
    /// `solver::fast` with the shared free response, `shaders/fast.wgsl`).
    Pair,
    /// A row of shear buildings: the row kernels (CPU `solver::row`, `shaders/row.wgsl`).
    Row,
}

impl Kernel {
    pub fn of(plan: &Plan) -> Kernel {
        match plan {
            Plan::Pair(_) => Kernel::Pair,
            Plan::Row(r) if r.runs_as_pair() => Kernel::Pair,
            Plan::Row(_) => Kernel::Row,
        }
    }

    /// `pair` or `row` (the sidecar's `kernel`).
    pub fn key(self) -> &'static str {
        match self {
            Kernel::Pair => "pair",
            Kernel::Row => "row",
        }
    }

    /// Why `plan` cannot run on the GPU kernel at `precision`, if it cannot; `calibrated`:
    /// `--target-error` chose its setting.
    fn gpu_refusal(plan: &Plan, precision: Precision, calibrated: bool) -> Option<EngineError> {
        if matches!(plan, Plan::Row(r) if r.tracks_demands()) {
            return Some(EngineError::GpuUnfit(
                "every storey's and floor's demands (--columns +storeys, +floors or one of their columns) are tracked on the CPU only",
            ));
        }
        let fast = match plan.scheme() {
            Scheme::Fast(o) => o,
            Scheme::Reference(_) => {
                return Some(match Kernel::of(plan) {
                    Kernel::Pair => EngineError::GpuNeedsFast,
                    Kernel::Row => {
                        EngineError::GpuUnfit("the reference scheme runs on the CPU only")
                    }
                })
            }
        };
        match Kernel::of(plan) {
            Kernel::Pair => None,
            // The row kernel runs the fast scheme without the energy balance; the rows'
            // calibration is of the CPU's f64 (the GPU in f64 agrees with it to 3.7e-6,
            // BENCHMARKS.md; f32 adds up to 7.2e-5).
            Kernel::Row if fast.energy => Some(EngineError::GpuUnfit(
                "the energy balance of rows is integrated on the CPU only",
            )),
            // The row kernel's IMK storeys are the CPU's twin in f64; f32 does not resolve their
            // thresholds' slack (1e-9 of the yield drift).
            Kernel::Row if matches!(plan, Plan::Row(r) if r.has_imk()) && precision == Precision::F32 => {
                Some(EngineError::GpuUnfit(
                    "IMK storeys (hysteresis = \"imk_bilinear\" or \"imk_peak_oriented\") run on the GPU in f64 only (add --precision f64)",
                ))
            }
            Kernel::Row if calibrated && precision == Precision::F32 => {
                Some(EngineError::GpuUnfit(
                    "--target-error on rows is calibrated in f64 (add --precision f64)",
                ))
            }
            Kernel::Row => None,
        }
    }
}

/// The GPU that `backend` asks for to run `plan` at `precision` (`calibrated`: the setting
/// came from `--target-error`): None where the plan's runs go to the CPU, with a notice
/// (`note`) where the user may not expect it; an error where `--backend gpu` asked for what
/// the GPU kernels cannot do.
pub fn gpu_for(
    plan: &Plan,
    backend: Backend,
    precision: Precision,
    calibrated: bool,
    note: &mut dyn FnMut(String),
) -> Result<Option<GpuContext>, EngineError> {
    if let Some(why) = Kernel::gpu_refusal(plan, precision, calibrated) {
        return match backend {
            Backend::Gpu => Err(why),
            _ => Ok(None),
        };
    }
    if let (Backend::Auto, Plan::Row(rows), Kernel::Row) = (backend, plan, Kernel::of(plan)) {
        if let Some(why) = row_stays_on_cpu(rows) {
            note(format!("notice: running on the CPU: {why} (BENCHMARKS.md, \"Rows on an H200\"); --backend gpu uses it"));
            return Ok(None);
        }
    }
    Ok(backend.acquire("running on the CPU", note)?)
}

/// Runs a row sweep needs before `--backend auto` takes a hardware GPU for it: on an H200 the
/// row kernel took about 5 s to build per shape, then ran 20,000-run sweeps of 3- and
/// 4-storey pairs at 2.6-3.3x the rate of 16 CPU threads (5,228-7,942 runs/s against
/// 2,040-2,752), so at 20,000 runs the GPU, build included, is about 1.2x the CPU and below
/// it loses (180 runs of `configs/row-3-6.toml`: 5.7 s against 0.44 s).
pub const ROW_GPU_MIN_RUNS: u64 = 20_000;

/// Why `--backend auto` keeps a row sweep on the CPU though a hardware GPU may be there, if it
/// does: whatever the row kernel was not measured faster at (BENCHMARKS.md, "Rows on an H200").
pub fn row_stays_on_cpu(plan: &RowPlan) -> Option<String> {
    if plan.len() < ROW_GPU_MIN_RUNS {
        return Some(format!(
            "a row sweep of fewer than {ROW_GPU_MIN_RUNS} runs is done sooner on the CPU than the GPU builds its kernel and runs it"
        ));
    }
    if plan.buildings.iter().any(|b| b.p_delta.is_some()) {
        return Some(
            "the row kernel is not measured faster than the CPU path on P-Delta buildings".into(),
        );
    }
    if !gpu::row::RowShape::of_plan(plan).unrolled() {
        return Some(format!(
            "the row kernel runs rows taller than two 5-storey buildings (storey counts whose squares sum past {}) as loops, slower than the CPU path",
            gpu::row::UNROLL_MAX_SQUARES
        ));
    }
    None
}

/// A chunk of finished runs, in run order, with the plan they belong to: a pair's or a row's.
#[derive(Clone, Copy)]
pub enum Chunk<'a> {
    Pairs(&'a PairPlan, &'a [(RunSpec, RunOutput)]),
    Rows(&'a RowPlan, &'a [(RowRunSpec, RowOutput)]),
}

impl Chunk<'_> {
    /// Fold these runs into their groups of `agg` (built for this chunk's plan) on the host.
    pub fn fold_into(&self, agg: &mut Aggregator) {
        match self {
            Chunk::Pairs(p, rows) => agg.add_rows(p, rows),
            Chunk::Rows(r, rows) => agg.add_row_runs(r, rows),
        }
    }

    /// Runs in which a building's peak displacement exceeds its height: physically absurd (a
    /// units mix-up?). A pair's height is estimated from its period, a row's is the sum of its
    /// storey heights.
    pub fn above_height(&self) -> u64 {
        match self {
            Chunk::Pairs(_, rows) => crate::plan::pair::above_height(rows),
            Chunk::Rows(plan, rows) => plan.above_height(rows),
        }
    }

    /// Runs that did not collapse in which a storey's peak drift ratio passes
    /// [`crate::plan::limits::WARN_DRIFT_RATIO`], where collapse studies call a building
    /// collapsed (rows whose collapse limit is higher or none; a pair's buildings have no
    /// storey height).
    pub fn past_collapse_drift(&self) -> u64 {
        match self {
            Chunk::Pairs(..) => 0,
            Chunk::Rows(_, rows) => rows
                .iter()
                .filter(|(_, o)| {
                    o.status != Status::Collapsed
                        && o.buildings
                            .iter()
                            .any(|b| b.peak_drift_ratio > crate::plan::limits::WARN_DRIFT_RATIO)
                })
                .count() as u64,
        }
    }
}

/// What a finished engine call reports: the sweep's totals, and on the GPU where time went.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Report {
    pub summary: Summary,
    /// All zero on the CPU.
    pub gpu: GpuTimes,
}

/// One way of integrating runs. Every caller (the sweep, the studies, the benchmarks) goes
/// through it, so the paths share chunking, ordering and the hand-off of hard runs.
#[derive(Clone, Copy)]
pub enum Engine<'c> {
    /// The physics' solvers in f64 ([`Scheme`]), `chunk` runs per rayon task on the current pool.
    Cpu { scheme: Scheme, chunk: usize },
    /// The WGSL kernel (the fast scheme), `chunk` runs per dispatch chunk (capped by the device).
    Gpu {
        ctx: &'c GpuContext,
        opts: GpuOptions,
        chunk: usize,
    },
}

/// `chunk`, or the path's default, checked against the path's bound (`gpu`: the GPU's).
pub fn check_chunk(chunk: Option<usize>, gpu: bool) -> Result<usize, EngineError> {
    let (default, max, on) = if gpu {
        (GPU_CHUNK, MAX_GPU_CHUNK, "GPU")
    } else {
        (CPU_CHUNK, MAX_CPU_CHUNK, "CPU")
    };
    let chunk = chunk.unwrap_or(default);
    if chunk == 0 || chunk > max {
        return Err(EngineError::Chunk { chunk, max, on });
    }
    Ok(chunk)
}

impl<'c> Engine<'c> {
    /// The engine for `scheme`: the GPU kernel at `precision` when `gpu` is given and the scheme
    /// is `fast`, else the CPU. `chunk` defaults to [`CPU_CHUNK`] or [`GPU_CHUNK`].
    pub fn new(
        scheme: Scheme,
        gpu: Option<&'c GpuContext>,
        precision: Precision,
        chunk: Option<usize>,
    ) -> Result<Engine<'c>, EngineError> {
        match (gpu, scheme) {
            (Some(ctx), Scheme::Fast(fast)) => Engine::gpu(
                ctx,
                GpuOptions {
                    precision,
                    fast,
                    ..Default::default()
                },
                chunk,
            ),
            _ => Engine::cpu(scheme, chunk),
        }
    }

    /// The CPU engine.
    pub fn cpu(scheme: Scheme, chunk: Option<usize>) -> Result<Engine<'c>, EngineError> {
        Ok(Engine::Cpu {
            scheme,
            chunk: check_chunk(chunk, false)?,
        })
    }

    /// The GPU engine; f64 needs an adapter that has it.
    pub fn gpu(
        ctx: &'c GpuContext,
        opts: GpuOptions,
        chunk: Option<usize>,
    ) -> Result<Engine<'c>, EngineError> {
        if opts.precision == Precision::F64 && !ctx.supports_f64() {
            return Err(GpuError::NoF64 {
                adapter: ctx.info.name.clone(),
            }
            .into());
        }
        Ok(Engine::Gpu {
            ctx,
            opts,
            chunk: check_chunk(chunk, true)?,
        })
    }

    /// The scheme's settings as run.
    pub fn scheme(&self) -> Scheme {
        match self {
            Engine::Cpu { scheme, .. } => *scheme,
            Engine::Gpu { opts, .. } => Scheme::Fast(opts.fast),
        }
    }

    /// `cpu`, `gpu-f32` or `gpu-f64` (the sidecar's `backend`).
    pub fn key(&self) -> String {
        match self {
            Engine::Cpu { .. } => "cpu".into(),
            Engine::Gpu { opts, .. } => format!("gpu-{}", opts.precision.key()),
        }
    }

    /// Where runs go, in words (`GPU <adapter> in f32`, `CPU, 8 threads`).
    pub fn describe(&self) -> String {
        match self {
            Engine::Cpu { .. } => format!("CPU, {} threads", rayon::current_num_threads()),
            Engine::Gpu { ctx, opts, .. } => {
                format!("GPU {} in {}", ctx.describe(), opts.precision.key())
            }
        }
    }

    /// Refuse, before any file is made, a plan this engine cannot run (a row too large for a
    /// software adapter's loop limit).
    pub fn check(&self, plan: &Plan) -> Result<(), GpuError> {
        match (self, plan) {
            (Engine::Gpu { ctx, .. }, Plan::Row(r)) if Kernel::of(plan) == Kernel::Row => {
                gpu::row::check_fits(ctx, r)
            }
            _ => Ok(()),
        }
    }

    /// Run the runs `runs` of any plan, through the kernels its scene takes ([`Kernel::of`]):
    /// `sink` gets each chunk's results in run order (rows already handed to it stay there if
    /// a later chunk fails), `progress` the runs done so far.
    pub fn sweep<E: From<GpuError>>(
        &self,
        plan: &Plan,
        runs: Range<u64>,
        sink: impl FnMut(Chunk<'_>) -> Result<(), E>,
        progress: impl FnMut(u64),
    ) -> Result<Report, E> {
        self.sweep_watching(plan, runs, None, sink, progress)
    }

    /// [`Engine::sweep`] until `stop` is raised: on the CPU the sweep then ends within a run
    /// per thread, the batch in flight dropped, and returns as if done; on the GPU within a
    /// dispatch (each sized to about 0.2 s while a flag is watched) or a run finished on the
    /// host, with `GpuError::Interrupted`. Either way the sink has had whole chunks, in run
    /// order, and the caller, who raises the flag, knows the sweep stopped.
    pub fn sweep_until<E: From<GpuError>>(
        &self,
        plan: &Plan,
        runs: Range<u64>,
        stop: &AtomicBool,
        sink: impl FnMut(Chunk<'_>) -> Result<(), E>,
        progress: impl FnMut(u64),
    ) -> Result<Report, E> {
        self.sweep_watching(plan, runs, Some(stop), sink, progress)
    }

    /// [`Engine::sweep`], watching `stop` if there is one (None: the GPU's dispatches keep
    /// their whole budget, as the command line runs them).
    fn sweep_watching<E: From<GpuError>>(
        &self,
        plan: &Plan,
        runs: Range<u64>,
        stop: gpu::Stop<'_>,
        mut sink: impl FnMut(Chunk<'_>) -> Result<(), E>,
        progress: impl FnMut(u64),
    ) -> Result<Report, E> {
        let row = match plan {
            Plan::Pair(p) => {
                let sink = |rows: &[_]| sink(Chunk::Pairs(p, rows));
                return self.run_watching(p, runs, stop, sink, progress);
            }
            Plan::Row(r) => r,
        };
        let sink = |rows: &[_]| sink(Chunk::Rows(row, rows));
        let (summary, gpu) = match self {
            Engine::Cpu { scheme, chunk } => {
                debug_assert_eq!(*scheme, plan.scheme(), "the engine runs the plan's scheme");
                let stop = stop.unwrap_or(&cpu::NEVER);
                let summary = cpu::run_rows_until(row, runs, *chunk, stop, sink, progress)?;
                (summary, GpuTimes::default())
            }
            Engine::Gpu { ctx, opts, chunk } if Kernel::of(plan) == Kernel::Pair => {
                gpu::sweep::run_row_pairs_until(row, runs, ctx, opts, *chunk, stop, sink, progress)?
            }
            Engine::Gpu { ctx, opts, chunk } => {
                gpu::row::sweep_rows_until(ctx, row, runs, *chunk, opts, stop, sink, progress)?
            }
        };
        Ok(Report { summary, gpu })
    }

    /// Run the runs `runs` of any plan and fold each into its group of `agg` (built for this
    /// plan: [`Aggregator::for_plan`]): a pair's on the device on the GPU (only the groups'
    /// partials come back), otherwise on the host.
    pub fn summarise(
        &self,
        plan: &Plan,
        runs: Range<u64>,
        agg: &mut Aggregator,
        progress: impl FnMut(u64),
    ) -> Result<Report, GpuError> {
        self.summarise_watching(plan, runs, None, agg, progress)
    }

    /// [`Engine::summarise`] until `stop` is raised (as [`Engine::sweep_until`]; `agg` then
    /// holds part of the runs).
    pub fn summarise_until(
        &self,
        plan: &Plan,
        runs: Range<u64>,
        stop: &AtomicBool,
        agg: &mut Aggregator,
        progress: impl FnMut(u64),
    ) -> Result<Report, GpuError> {
        self.summarise_watching(plan, runs, Some(stop), agg, progress)
    }

    fn summarise_watching(
        &self,
        plan: &Plan,
        runs: Range<u64>,
        stop: gpu::Stop<'_>,
        agg: &mut Aggregator,
        progress: impl FnMut(u64),
    ) -> Result<Report, GpuError> {
        match plan {
            Plan::Pair(p) => self.fold_watching(p, runs, stop, agg, progress),
            Plan::Row(_) => self.sweep_watching(
                plan,
                runs,
                stop,
                |c: Chunk<'_>| -> Result<(), GpuError> {
                    c.fold_into(agg);
                    Ok(())
                },
                progress,
            ),
        }
    }

    /// Run the runs `runs` of a pair's plan (the pair kernels; every scene: [`Engine::sweep`]);
    /// `sink` gets each chunk's results in run order (rows already
    /// handed to it stay there if a later chunk fails), `progress` the runs done so far.
    pub fn run<E: From<GpuError>>(
        &self,
        plan: &PairPlan,
        runs: Range<u64>,
        sink: impl FnMut(&[(RunSpec, RunOutput)]) -> Result<(), E>,
        progress: impl FnMut(u64),
    ) -> Result<Report, E> {
        self.run_watching(plan, runs, None, sink, progress)
    }

    /// [`Engine::run`] until `stop` is raised (as [`Engine::sweep_until`]).
    pub fn run_until<E: From<GpuError>>(
        &self,
        plan: &PairPlan,
        runs: Range<u64>,
        stop: &AtomicBool,
        sink: impl FnMut(&[(RunSpec, RunOutput)]) -> Result<(), E>,
        progress: impl FnMut(u64),
    ) -> Result<Report, E> {
        self.run_watching(plan, runs, Some(stop), sink, progress)
    }

    fn run_watching<E: From<GpuError>>(
        &self,
        plan: &PairPlan,
        runs: Range<u64>,
        stop: gpu::Stop<'_>,
        sink: impl FnMut(&[(RunSpec, RunOutput)]) -> Result<(), E>,
        progress: impl FnMut(u64),
    ) -> Result<Report, E> {
        match self {
            Engine::Cpu { scheme, chunk } => {
                let stop = stop.unwrap_or(&cpu::NEVER);
                Ok(Report {
                    summary: cpu::run_range_until(
                        plan, runs, scheme, *chunk, stop, sink, progress,
                    )?,
                    gpu: GpuTimes::default(),
                })
            }
            Engine::Gpu { ctx, opts, chunk } => {
                let (summary, gpu) = gpu::sweep::run_range_until(
                    plan, runs, ctx, opts, *chunk, stop, sink, progress,
                )?;
                Ok(Report { summary, gpu })
            }
        }
    }

    /// Run the runs `runs` of `plan` and fold each into its group of `agg`: on the host for the
    /// CPU, on the device for the GPU (only the groups' partials come back).
    pub fn fold(
        &self,
        plan: &PairPlan,
        runs: Range<u64>,
        agg: &mut Aggregator,
        progress: impl FnMut(u64),
    ) -> Result<Report, GpuError> {
        self.fold_watching(plan, runs, None, agg, progress)
    }

    fn fold_watching(
        &self,
        plan: &PairPlan,
        runs: Range<u64>,
        stop: gpu::Stop<'_>,
        agg: &mut Aggregator,
        progress: impl FnMut(u64),
    ) -> Result<Report, GpuError> {
        match self {
            Engine::Cpu { .. } => self.run_watching(
                plan,
                runs,
                stop,
                |rows: &[(RunSpec, RunOutput)]| -> Result<(), GpuError> {
                    agg.add_rows(plan, rows);
                    Ok(())
                },
                progress,
            ),
            Engine::Gpu { ctx, opts, chunk } => {
                let (summary, gpu) = gpu::fold::fold_range_until(
                    plan,
                    runs,
                    ctx,
                    opts,
                    *chunk,
                    gpu::reduce::DEFAULT_SLOTS,
                    stop,
                    agg,
                    progress,
                )?;
                Ok(Report { summary, gpu })
            }
        }
    }

    /// Every run of `plan`, its output in run order.
    pub fn collect(&self, plan: &PairPlan) -> Result<(Vec<RunOutput>, Report), GpuError> {
        let mut outs = Vec::with_capacity(plan.len() as usize);
        let report = self.run(
            plan,
            0..plan.len(),
            |rows: &[(RunSpec, RunOutput)]| -> Result<(), GpuError> {
                outs.extend(rows.iter().map(|(_, o)| *o));
                Ok(())
            },
            |_| {},
        )?;
        Ok((outs, report))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::solver::{FastOptions, ReferenceOptions};

    #[test]
    fn chunks_default_per_path_and_are_bounded() {
        assert_eq!(check_chunk(None, false).unwrap(), CPU_CHUNK);
        assert_eq!(check_chunk(None, true).unwrap(), GPU_CHUNK);
        assert_eq!(check_chunk(Some(7), false).unwrap(), 7);
        for (chunk, gpu) in [(0, false), (0, true), (MAX_CPU_CHUNK + 1, false)] {
            let e = check_chunk(Some(chunk), gpu).unwrap_err().to_string();
            assert!(
                e.starts_with(&format!("--chunk {chunk}: expected 1 to ")),
                "{e}"
            );
        }
        assert!(check_chunk(Some(MAX_CPU_CHUNK + 1), true).is_ok());
    }

    /// `--backend auto` takes the GPU for a row only where the row kernel was measured faster
    /// than the CPU: enough runs, no P-Delta, a shape written out.
    #[test]
    fn auto_takes_the_gpu_for_rows_only_where_measured_faster() {
        let row = |storeys: (usize, usize), runs: u64, extra: &str| {
            let text = format!(
                "[[building]]\nstoreys = {}\nstorey_height_m = 3.0\nmass_kg = 3e5\nperiod_s = 0.3\ndamping_ratio = 0.05\n{extra}\n\
                 [[building]]\nstoreys = {}\nstorey_height_m = 3.0\nmass_kg = 3e5\nperiod_s = 0.5\ndamping_ratio = 0.05\n\
                 [contact]\nlaw = \"linear\"\nk_n_per_m = 1e9\ngap_m = {{ from = 0.0, to = 0.05, n = {runs} }}\n\
                 [[record]]\nsynthetic = {{ seed = 1, duration_s = 2.0 }}\n",
                storeys.0, storeys.1
            );
            crate::plan::config::load_row_text(&text, std::path::Path::new("auto.toml")).unwrap()
        };
        let n = ROW_GPU_MIN_RUNS;
        assert_eq!(row_stays_on_cpu(&row((3, 4), n, "")), None);
        assert_eq!(row_stays_on_cpu(&row((1, 1), n, "")), None);
        // Two 4 + 7 storeys are the tallest written out (16 + 49 = 65).
        assert_eq!(row_stays_on_cpu(&row((4, 7), n, "")), None);
        let why = |r: &RowPlan| row_stays_on_cpu(r).unwrap_or_default();
        assert!(why(&row((3, 4), n - 1, "")).contains("fewer than 20000 runs"));
        assert!(why(&row((6, 6), n, "")).contains("as loops"));
        assert!(why(&row((5, 7), n, "")).contains("as loops"));
        let leaning = "yield_drift_ratio = 0.006\npost_yield_ratio = 0.02\np_delta = true";
        assert!(why(&row((3, 4), n, leaning)).contains("P-Delta"));
        // Yielding storeys without P-Delta were measured (2.6x on an H200).
        let yielding = "yield_drift_ratio = 0.006\npost_yield_ratio = 0.02";
        assert_eq!(row_stays_on_cpu(&row((3, 4), n, yielding)), None);
    }

    /// Without a GPU every scheme runs on the CPU, with its settings as given.
    #[test]
    fn without_a_gpu_the_engine_is_the_cpu() {
        for scheme in [
            Scheme::Fast(FastOptions::default()),
            Scheme::Reference(ReferenceOptions::default()),
        ] {
            let e = Engine::new(scheme, None, Precision::F32, None).unwrap();
            assert!(matches!(
                e,
                Engine::Cpu {
                    chunk: CPU_CHUNK,
                    ..
                }
            ));
            assert_eq!(e.scheme(), scheme);
            assert_eq!(e.key(), "cpu");
        }
    }

    /// Folding on the CPU gives the summary a host fold of the rows gives, for any chunking.
    #[test]
    fn cpu_fold_is_the_fold_of_the_rows() {
        let plan = crate::plan::config::parse_builtin(
            "[building1]\nmass_kg = 1.0e5\nperiod_s = [0.3, 0.5]\ndamping_ratio = 0.05\n[building2]\nmass_kg = 1.0e5\nperiod_s = 0.9\ndamping_ratio = 0.05\n[contact]\nlaw = \"linear\"\nk_n_per_m = 1e9\ngap_m = [0.0, 0.005, 0.5]\n[[record]]\nsynthetic = { seed = 3, duration_s = 2.0 }\n",
            "fold.toml",
        )
        .unwrap();
        let by = ["gap_m".to_string()];
        let exceed = ["impacts=0".to_string()];
        let engine = Engine::cpu(plan.contact.spec.scheme, Some(1)).unwrap();
        let mut host = Aggregator::new(&by, &exceed).unwrap();
        let rows = engine
            .run(
                &plan,
                0..plan.len(),
                |c: &[(RunSpec, RunOutput)]| -> Result<(), GpuError> {
                    host.add_rows(&plan, c);
                    Ok(())
                },
                |_| {},
            )
            .unwrap();
        let mut folded = Aggregator::new(&by, &exceed).unwrap();
        let report = Engine::cpu(plan.contact.spec.scheme, Some(4))
            .unwrap()
            .fold(&plan, 0..plan.len(), &mut folded, |_| {})
            .unwrap();
        assert_eq!(report.summary.runs, plan.len());
        assert_eq!(report.summary.impacts, rows.summary.impacts);
        assert!(report.summary.runs_with_impacts > 0);
        assert_eq!(folded.groups(), 3);
        // Each group's label, runs, exceedances, and per output its count, max and median.
        let stats = |a: &Aggregator| {
            a.labelled()
                .map(|(label, g)| {
                    let s = g
                        .stats
                        .iter()
                        .map(|s| (s.count(), s.max(), s.quantile(0.5)));
                    (
                        label.to_vec(),
                        g.runs,
                        g.exceed.clone(),
                        s.collect::<Vec<_>>(),
                    )
                })
                .collect::<Vec<_>>()
        };
        assert_eq!(stats(&folded), stats(&host));
    }
}
