//! `pound sweep`: settings from flags, the output opened (fresh or resumed), the engine run,
//! the output put in place.

use super::{check_outputs, config_inputs, BackendArg, Holds, PrecisionArg};
use anyhow::{bail, Context, Result};
use clap::ValueEnum;
use pounding::engine::{Backend, Engine, EngineError};
use pounding::io::provenance::{Fingerprint, Meta};
use pounding::io::sweep_output::{Format, Opened, SweepOutput};
use pounding::physics::model::RunOutput;
use pounding::physics::solver::{FastOptions, ReferenceOptions, Scheme};
use pounding::plan::shard::Shard;
use pounding::plan::{config, RunSpec};
use std::io::IsTerminal;
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Args {
    /// The sweep config (TOML; keys in README.md, "A config"; a start: `pound init pair`).
    config: PathBuf,
    /// Output CSV (written as OUT.partial, renamed when complete; default results.csv,
    /// numbered `-2`, `-3`, ... where that file exists, except with --resume).
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Worker threads (default: all cores).
    #[arg(long)]
    threads: Option<usize>,
    /// Override the config's integration scheme.
    #[arg(long, value_enum)]
    scheme: Option<SchemeArg>,
    /// Where runs are integrated. The GPU runs the `fast` scheme only.
    #[arg(long, value_enum, default_value = "auto")]
    backend: BackendArg,
    /// GPU arithmetic. f32 (default) adds a peak-force error of at most 6.2e-4 to the fast
    /// scheme's (measured, README); f64 needs an adapter with SHADER_F64.
    #[arg(long, value_enum, default_value = "f32")]
    precision: PrecisionArg,
    /// Runs per parallel task (CPU, default 64) or per GPU chunk (default 65536).
    #[arg(long)]
    chunk: Option<usize>,
    /// Write each run's energy balance (input, damping work, relative residual); the same
    /// as `energy = true` under `[run]`. The reference scheme always writes it.
    #[arg(long)]
    energy: bool,
    /// Run only shard I of N (0-based, `I/N`): a contiguous, cost-balanced part of the plan, for
    /// job arrays; combine the outputs with `pound merge`.
    #[arg(long, value_name = "I/N", value_parser = parse_shard)]
    shard: Option<Shard>,
    /// Continue an interrupted sweep of the same config into the same output: only the runs
    /// not yet on disk are computed.
    #[arg(long)]
    resume: bool,
    /// Write, instead of a row per run, one row per group of these swept columns (e.g.
    /// record,pga_g): runs, failures, --exceed counts, and max, mean, p50, p90, p99 of each output.
    #[arg(long, value_delimiter = ',', value_name = "COLUMNS")]
    aggregate: Option<Vec<String>>,
    /// With --aggregate: count runs with COLUMN > THRESHOLD (e.g. peak_force_n=1e6); repeatable.
    #[arg(long, value_name = "COLUMN=THRESHOLD", requires = "aggregate")]
    exceed: Vec<String>,
    /// Output format: csv (journaled, resumable; the default) or parquet (typed columns, the
    /// plan fingerprint in its metadata; the default for a .parquet output name).
    #[arg(long, value_enum)]
    format: Option<FormatArg>,
    /// Write only these columns (comma-separated; `run` is always kept, first).
    #[arg(long, value_delimiter = ',', value_name = "COLUMNS")]
    columns: Option<Vec<String>>,
    /// The relative peak-force error you accept (e.g. 1e-2 for a fragility study): the fast
    /// scheme takes the cheapest accuracy setting whose p99 error on the accuracy suite is at
    /// most this (calibrated by `pound accuracy`; overrides `run.substeps_per_contact`; recorded
    /// in the sidecar).
    #[arg(long, value_name = "E")]
    target_error: Option<f64>,
}

#[derive(Clone, Copy, ValueEnum)]
enum SchemeArg {
    Fast,
    Reference,
}

#[derive(Clone, Copy, PartialEq, ValueEnum)]
enum FormatArg {
    Csv,
    Parquet,
}

fn parse_shard(s: &str) -> std::result::Result<Shard, String> {
    Shard::parse(s).ok_or_else(|| format!("`{s}`: expected I/N with 0 <= I < N, e.g. 3/16"))
}

/// The scheme as run: the config's, or `--scheme` (keeping the config's settings when it names
/// the same scheme), with `--energy` added to the fast scheme.
fn scheme_as_run(configured: Scheme, asked: Option<SchemeArg>, energy: bool) -> Scheme {
    let scheme = match asked {
        None => configured,
        Some(SchemeArg::Fast) => Scheme::Fast(match configured {
            Scheme::Fast(o) => o,
            _ => FastOptions::default(),
        }),
        Some(SchemeArg::Reference) => Scheme::Reference(match configured {
            Scheme::Reference(o) => o,
            _ => ReferenceOptions::default(),
        }),
    };
    match scheme {
        Scheme::Fast(o) => Scheme::Fast(FastOptions {
            energy: o.energy || energy,
            ..o
        }),
        reference => reference,
    }
}

/// Say that `--target-error` replaces a `run.substeps_per_contact` the config gives.
fn overrides_configured(config_text: &str, chosen: f64) {
    let given = config_text
        .parse::<toml::Table>()
        .ok()
        .and_then(|t| t.get("run")?.get("substeps_per_contact").cloned());
    if let Some(v) = given {
        note!("notice: --target-error overrides the config's run.substeps_per_contact = {v} with {chosen}");
    }
}

/// `--threads`, checked.
pub fn check_threads(t: usize) -> Result<usize> {
    use pounding::plan::limits::{MAX_THREADS, WHY_THREADS};
    if t == 0 || t > MAX_THREADS {
        bail!(
            "--threads {t}: expected 1 to {MAX_THREADS} ({WHY_THREADS}; this machine has {})",
            std::thread::available_parallelism().map_or(1, |n| n.get())
        );
    }
    Ok(t)
}

pub fn run(a: Args) -> Result<()> {
    let Args {
        config,
        output,
        threads,
        scheme,
        backend,
        precision,
        chunk,
        energy,
        shard,
        resume,
        aggregate,
        exceed,
        format,
        columns,
        target_error,
    } = a;
    // A default name is never an earlier output; --resume continues the one it names.
    let output = match (output, resume) {
        (None, true) => PathBuf::from("results.csv"),
        (given, _) => super::default_output(given, "results.csv"),
    };
    let parquet_name = output
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("parquet"));
    let format = format.unwrap_or(if parquet_name && aggregate.is_none() {
        FormatArg::Parquet
    } else {
        FormatArg::Csv
    });
    if format == FormatArg::Parquet && resume {
        bail!("--resume continues CSV output only: a Parquet file is readable only once its footer is written at the end");
    }
    if aggregate.is_some() && (format == FormatArg::Parquet || columns.is_some()) {
        bail!("--aggregate writes its own summary columns: --format and --columns do not apply");
    }
    if aggregate.is_some() && (resume || shard.is_some()) {
        bail!("--aggregate keeps its summary in memory until the sweep ends: it cannot be combined with --resume or --shard");
    }
    let threads = threads.map(check_threads).transpose()?;
    // The output is checked before anything runs: not a directory, not one of the inputs, and
    // writable.
    let config_text = config::read_text(&config)?;
    let records = config::input_files(&config_text, &config);
    let holds = if format == FormatArg::Parquet {
        Holds::Parquet
    } else {
        Holds::Csv
    };
    let target = check_outputs(
        &config_inputs(&config, &records),
        &[("-o", Some(&output), holds)],
    )?
    .pop()
    .expect("one output");
    if pounding::plan::row::is_row_config(&config_text) {
        let mut plan = config::load_row_text(&config_text, &config)?;
        super::warn_all(&config, plan.warnings());
        plan.base.spec.scheme = scheme_as_run(plan.base.spec.scheme, scheme, energy);
        let chosen = match (target_error, &mut plan.base.spec.scheme) {
            (None, _) => None,
            (Some(_), Scheme::Reference(_)) => bail!(
                "--target-error chooses the fast scheme's setting; the reference scheme is controlled by its tolerance (run.tol)"
            ),
            (Some(e), Scheme::Fast(o)) => {
                let c = super::target_error_in(
                    pounding::physics::solver::calibration::Suite::Rows,
                    e,
                )?;
                overrides_configured(&config_text, c.substeps_per_contact);
                o.substeps_per_contact = c.substeps_per_contact;
                Some(c)
            }
        };
        let spc = match plan.base.spec.scheme {
            Scheme::Fast(o) => o.substeps_per_contact,
            Scheme::Reference(_) => FastOptions::default().substeps_per_contact,
        };
        super::warn_all(&config, plan.cost_warning(spc));
        // The row kernel runs the fast scheme without the energy balance; the rows' calibration
        // is of the CPU's f64 (the GPU in f64 agrees with it to 3.7e-6, BENCHMARKS.md; f32
        // adds up to 7.2e-5).
        let gpu_fit = match plan.base.spec.scheme {
            Scheme::Fast(o) if o.energy => {
                Some("the energy balance of rows is integrated on the CPU only")
            }
            Scheme::Fast(_)
                if chosen.is_some() && precision.get() == pounding::engine::gpu::Precision::F32 =>
            {
                Some("--target-error on rows is calibrated in f64 (add --precision f64)")
            }
            Scheme::Fast(_) => None,
            Scheme::Reference(_) => Some("the reference scheme runs on the CPU only"),
        };
        let backend = backend.get();
        let gpu = match (backend, gpu_fit) {
            (Backend::Gpu, Some(why)) => bail!("--backend gpu: {why}; use --backend cpu"),
            (_, Some(_)) => None,
            // Measured on an H100: the row kernel beats 16 CPU threads only for rows of
            // one-storey buildings (2.4x); 0.59x at 3 storeys, 0.17x at 6 (BENCHMARKS.md).
            (Backend::Auto, None) if plan.buildings.iter().any(|b| b.storeys() > 1) => {
                note!("notice: running on the CPU: the row kernel is slower than the CPU path for buildings of more than one storey (BENCHMARKS.md, \"Rows on the GPU\"); --backend gpu uses it");
                None
            }
            _ => backend.acquire("running on the CPU", &mut |l| note!("{l}"))?,
        };
        let header = plan.header();
        let picked = columns
            .as_ref()
            .map(|c| pounding::plan::columns::select_in(&header, c))
            .transpose()
            .map_err(|bad| {
                anyhow::anyhow!(
                    "--columns: `{bad}` is not a column of this row sweep; its columns are: {}",
                    header.join(", ")
                )
            })?;
        let summary = aggregate
            .as_ref()
            .map(|by| {
                pounding::engine::aggregate::Aggregator::of_cells(
                    &header,
                    plan.parameter_columns(),
                    &plan.summarised(),
                    by,
                    &exceed,
                )
            })
            .transpose()?;
        return run_row(
            &config,
            &config_text,
            &plan,
            RowSettings {
                target,
                threads,
                chunk,
                gpu: gpu.as_ref().map(|c| (c, precision.get())),
                header,
                picked,
                shard,
                resume,
                format: output_format(summary, format),
                target_error: chosen,
            },
        );
    }
    let picked = columns
        .as_ref()
        .map(|c| pounding::plan::columns::select(c))
        .transpose()
        .map_err(|bad| {
            anyhow::anyhow!(
                "--columns: `{bad}` is not a column; the columns are: {}",
                pounding::plan::columns::header().join(", ")
            )
        })?;
    let picked_names: Option<Vec<String>> = picked.as_ref().map(|ix| {
        let h = pounding::plan::columns::header();
        ix.iter().map(|&i| h[i].to_string()).collect()
    });
    let precision = precision.get();
    let mut plan = config::load_text(&config_text, &config)?;
    super::warn_all(&config, plan.warnings());
    let mut scheme = scheme_as_run(plan.spec.scheme, scheme, energy);
    let chosen = match (target_error, &mut scheme) {
        (None, _) => None,
        (Some(_), Scheme::Reference(_)) => bail!(
            "--target-error chooses the fast scheme's setting; the reference scheme is controlled by its tolerance (run.tol)"
        ),
        (Some(e), Scheme::Fast(o)) => {
            let c = super::target_error(e)?;
            overrides_configured(&config_text, c.substeps_per_contact);
            o.substeps_per_contact = c.substeps_per_contact;
            Some(c)
        }
    };
    // The fingerprint covers the scheme as run, not as configured.
    plan.spec.scheme = scheme;
    let fast = matches!(scheme, Scheme::Fast(_));
    let backend = backend.get();
    if backend == Backend::Gpu && !fast {
        bail!(EngineError::GpuNeedsFast)
    }
    // The reference scheme runs on the CPU only: no adapter is looked for.
    let gpu = if fast {
        backend.acquire("running on the CPU", &mut |l| note!("{l}"))?
    } else {
        None
    };
    let engine = Engine::new(scheme, gpu.as_ref(), precision, chunk)?;
    let mut pool = rayon::ThreadPoolBuilder::new();
    if let Some(t) = threads {
        pool = pool.num_threads(t);
    }
    let pool = pool.build().context("starting worker threads")?;
    let range = match shard {
        Some(s) => pounding::plan::shard::shard_range(&plan, s),
        None => 0..plan.len(),
    };
    let meta = Meta {
        fingerprint: Fingerprint::of(&plan),
        plan_runs: plan.len(),
        first_run: range.start,
        end_run: range.end,
        shard,
        backend: engine.key(),
        columns: picked_names.clone(),
        content: None,
        target_error: chosen.map(pounding::io::provenance::TargetError::of),
    };
    let summary = aggregate
        .as_ref()
        .map(|by| pounding::engine::aggregate::Aggregator::new(by, &exceed))
        .transpose()?;
    let fmt = output_format(summary, format);
    let Some(mut out) = open_output(target, meta, fmt, picked, resume)? else {
        return Ok(());
    };
    let todo = out.todo();
    let partial = out.partial_path();
    let mut bar = progress_bar(todo.end - todo.start);
    note!(
        "{}: {} runs, {} scheme, {}",
        config.display(),
        todo.end - todo.start,
        scheme.key(),
        pool.install(|| engine.describe()),
    );
    let mut absurd = 0u64;
    let report = pool
        .install(|| -> Result<_> {
            let progress = |done| bar.set_position(done);
            let report = match out.aggregator() {
                Some(agg) => {
                    let r = engine.fold(&plan, todo.clone(), agg, progress)?;
                    if let Engine::Gpu { .. } = engine {
                        let t = r.gpu;
                        bar.suspend(|| {
                            note!(
                                "aggregated on the device: {:.2} s folding; {} chunks with more than {} groups folded on the host; histograms flushed {} times",
                                t.aggregate,
                                t.host_folded_chunks,
                                pounding::engine::gpu::reduce::DEFAULT_SLOTS,
                                t.slot_flushes
                            )
                        });
                    }
                    r
                }
                None => engine.run(
                    &plan,
                    todo.clone(),
                    |c: &[(RunSpec, RunOutput)]| {
                        absurd += pounding::plan::limits::above_height(c);
                        out.take(&plan, c).map_err(anyhow::Error::from)
                    },
                    progress,
                )?,
            };
            if let Engine::Gpu { opts, .. } = engine {
                if report.gpu.handed_off > 0 {
                    bar.suspend(|| {
                        note!(
                            "{} runs needed more than {} RK4 substeps per record step, past what {} resolves: finished on the CPU in f64",
                            report.gpu.handed_off,
                            opts.handoff(),
                            precision.key()
                        )
                    });
                }
            }
            Ok(report)
        })
        .with_context(|| {
            format!(
                "writing {} (finished rows are kept there)",
                partial.display()
            )
        })?;
    let summary = report.summary;
    bar.finish_and_clear();
    // Records are read once, at the start: a file changed since then no longer matches the rows
    // (or the fingerprint), so the output is not put in place.
    let changed = config::changed_records(&config_text, &config, &plan);
    let (path, what) = finish_unless_changed(*out, &changed)?;
    if absurd > 0 {
        note!(
            "warning: {absurd} runs have a peak displacement above the building's height estimated from its period ({} m per s: T ~ 0.1 s per 3 m storey): check the record's units and the intensity",
            pounding::plan::limits::HEIGHT_PER_PERIOD_M
        );
    }
    finished(&summary, &path, &format!(" ({what})"));
    Ok(())
}

/// The one line a finished sweep ends with.
fn finished(summary: &pounding::engine::Summary, path: &std::path::Path, what: &str) {
    note!(
        "{} runs in {:.2} s ({:.0} runs/s): {} runs pounded, {} impacts, {} failures -> {}{what}",
        summary.runs,
        summary.seconds,
        summary.runs_per_second(),
        summary.runs_with_impacts,
        summary.impacts,
        summary.failures,
        path.display()
    );
}

/// How a row sweep runs and where it goes.
struct RowSettings<'a> {
    target: pounding::io::target::Target,
    threads: Option<usize>,
    chunk: Option<usize>,
    gpu: Option<(
        &'a pounding::engine::gpu::GpuContext,
        pounding::engine::gpu::Precision,
    )>,
    /// The row's columns ([`pounding::plan::row::RowPlan::header`]), and `--columns` as
    /// indices into them.
    header: Vec<String>,
    picked: Option<Vec<usize>>,
    shard: Option<Shard>,
    resume: bool,
    format: Format,
    /// `--target-error`, and the setting it chose.
    target_error: Option<pounding::physics::solver::calibration::Choice>,
}

/// `pound sweep` of a row config, on the CPU or the GPU, through the same output protocol as
/// the pair's: CSV (journaled, resumable), Parquet or a summary, written to `OUT.partial` and
/// renamed when complete with its sidecar.
fn run_row(
    config: &std::path::Path,
    config_text: &str,
    plan: &pounding::plan::row::RowPlan,
    settings: RowSettings,
) -> Result<()> {
    let RowSettings {
        target,
        threads,
        chunk,
        gpu,
        header,
        picked,
        shard,
        resume,
        format,
        target_error,
    } = settings;
    let (default_chunk, max_chunk, on) = match gpu {
        Some(_) => (
            pounding::engine::GPU_CHUNK,
            pounding::plan::limits::MAX_GPU_CHUNK,
            "GPU",
        ),
        None => (
            pounding::engine::CPU_CHUNK,
            pounding::plan::limits::MAX_CPU_CHUNK,
            "CPU",
        ),
    };
    let chunk = chunk.unwrap_or(default_chunk);
    if chunk == 0 || chunk > max_chunk {
        bail!(EngineError::Chunk {
            chunk,
            max: max_chunk,
            on
        });
    }
    let names: Vec<String> = match &picked {
        Some(ix) => ix.iter().map(|&i| header[i].clone()).collect(),
        None => header,
    };
    let range = match shard {
        Some(s) => pounding::plan::shard::row_shard_range(plan, s),
        None => 0..plan.len(),
    };
    let summary_only = matches!(format, Format::Summary(_));
    let meta = Meta {
        fingerprint: Fingerprint::of_row(plan),
        plan_runs: plan.len(),
        first_run: range.start,
        end_run: range.end,
        shard,
        backend: gpu.map_or("cpu".into(), |(_, p)| format!("gpu-{}", p.key())),
        // A row's columns depend on its buildings, so they are always named.
        columns: (!summary_only).then_some(names),
        content: None,
        target_error: target_error.map(pounding::io::provenance::TargetError::of),
    };
    // Every refusal that the plan decides comes before any file is made.
    if let Some((ctx, _)) = gpu {
        pounding::engine::gpu::row::check_fits(ctx, plan)?;
    }
    let Some(mut out) = open_output(target, meta, format, picked, resume)? else {
        return Ok(());
    };
    let todo = out.todo();
    let partial = out.partial_path();
    let mut pool = rayon::ThreadPoolBuilder::new();
    if let Some(t) = threads {
        pool = pool.num_threads(t);
    }
    let pool = pool.build().context("starting worker threads")?;
    let on = match gpu {
        Some((ctx, p)) => format!("GPU {} in {}", ctx.describe(), p.key()),
        None => format!("CPU, {} threads", pool.current_num_threads()),
    };
    note!(
        "{}: {} runs of a row of {} buildings ({} storeys, {} contact levels), {} scheme, on the {on}",
        config.display(),
        todo.end - todo.start,
        plan.buildings.len(),
        plan.buildings.iter().map(|b| b.storeys()).sum::<usize>(),
        plan.row(&plan.run(0)).levels.len(),
        plan.scheme().key(),
    );
    let mut bar = progress_bar(todo.end - todo.start);
    let mut absurd = 0u64;
    let write = |rows: &[(
        pounding::plan::row::RowRunSpec,
        pounding::physics::row::RowOutput,
    )]| {
        absurd += plan.above_height(rows);
        out.take(plan, rows).map_err(anyhow::Error::from)
    };
    let progress = |done| bar.set_position(done);
    let summary = pool
        .install(|| match gpu {
            Some((ctx, precision)) => {
                let Scheme::Fast(fast) = plan.base.spec.scheme else {
                    unreachable!("the GPU runs the fast scheme")
                };
                let opts = pounding::engine::gpu::GpuOptions {
                    precision,
                    fast,
                    ..Default::default()
                };
                pounding::engine::gpu::row::sweep_rows(
                    ctx,
                    plan,
                    todo.clone(),
                    chunk,
                    &opts,
                    write,
                    progress,
                )
            }
            None => pounding::engine::cpu::run_rows(plan, todo.clone(), chunk, write, progress),
        })
        .with_context(|| {
            format!(
                "writing {} (finished rows are kept there)",
                partial.display()
            )
        })?;
    bar.finish_and_clear();
    // Records are read once, at the start, as for pairs.
    let changed = config::changed_records(config_text, config, &plan.base);
    let (path, what) = finish_unless_changed(*out, &changed)?;
    if absurd > 0 {
        note!(
            "warning: {absurd} runs have a building whose peak roof displacement exceeds its height (the sum of its storey heights): check the record's units, the intensity and storey_height_m"
        );
    }
    finished(&summary, &path, &format!(" ({what})"));
    Ok(())
}

/// How rows are written: a summary (`--aggregate`), Parquet or CSV.
fn output_format(
    summary: Option<pounding::engine::aggregate::Aggregator>,
    format: FormatArg,
) -> Format {
    match summary {
        Some(agg) => Format::Summary(Box::new(agg)),
        None if format == FormatArg::Parquet => Format::Parquet,
        None => Format::Csv,
    }
}

/// Open the sweep's output (fresh, or resumed) and say which runs it takes: None when a resume
/// found it already complete.
fn open_output(
    target: pounding::io::target::Target,
    meta: Meta,
    format: Format,
    picked: Option<Vec<usize>>,
    resume: bool,
) -> Result<Option<Box<SweepOutput>>> {
    let output = target.path().to_path_buf();
    let (shard, range, plan_runs) = (meta.shard, meta.first_run..meta.end_run, meta.plan_runs);
    let out = match SweepOutput::open(target, meta, format, picked, resume, &mut |l| note!("{l}"))?
    {
        Opened::Ready(o) => o,
        Opened::Complete(_) => return Ok(None),
    };
    if let Some(s) = shard {
        note!(
            "shard {}/{}: runs {}..{} of {plan_runs}",
            s.index,
            s.count,
            range.start,
            range.end,
        );
    }
    if out.done() > 0 {
        note!(
            "resuming {}: {} runs already on disk",
            output.display(),
            out.done()
        );
    }
    Ok(Some(out))
}

/// Put the output in place, unless a record (`changed`, by name) changed on disk during the
/// sweep: the runs were computed from the content read at the start, so they no longer match
/// the records (or the fingerprint) and stay in the `.partial`.
fn finish_unless_changed(
    mut out: SweepOutput,
    changed: &[String],
) -> Result<(std::path::PathBuf, String)> {
    if !changed.is_empty() {
        let summary_only = out.aggregator().is_some();
        let partial = out.partial_path();
        drop(out);
        bail!(
            "{} changed on disk during the sweep; the runs were computed from the content read at the start ({}); rerun the sweep (without --resume) to use the new content",
            changed.join(", "),
            if summary_only {
                "no summary was written".to_string()
            } else {
                format!("their rows are left in {}", partial.display())
            }
        );
    }
    Ok(out.finish()?)
}

/// Progress: a bar on a terminal; elsewhere (a log, a batch job) a line every
/// `POUND_PROGRESS_S` seconds (default 10) from a watcher thread, so a long sweep is never
/// silent, even while its first chunk runs.
enum Progress {
    Bar(indicatif::ProgressBar),
    Lines {
        /// Runs done.
        done: std::sync::Arc<std::sync::atomic::AtomicU64>,
        /// Dropped when the sweep is over, which ends the watcher's wait at once.
        stop: Option<std::sync::mpsc::Sender<()>>,
        watcher: Option<std::thread::JoinHandle<()>>,
    },
}

impl Progress {
    fn set_position(&self, done: u64) {
        match self {
            Progress::Bar(b) => b.set_position(done),
            Progress::Lines { done: d, .. } => d.store(done, std::sync::atomic::Ordering::Relaxed),
        }
    }

    fn suspend(&self, f: impl FnOnce()) {
        match self {
            Progress::Bar(b) => b.suspend(f),
            Progress::Lines { .. } => f(),
        }
    }

    fn finish_and_clear(&mut self) {
        match self {
            Progress::Bar(b) => b.finish_and_clear(),
            Progress::Lines { stop, watcher, .. } => {
                stop.take();
                if let Some(w) = watcher.take() {
                    let _ = w.join();
                }
            }
        }
    }
}

impl Drop for Progress {
    fn drop(&mut self) {
        self.finish_and_clear();
    }
}

/// The watcher of [`Progress::Lines`]: a line every `every` until `stop` is dropped.
fn watch(
    runs: u64,
    every: std::time::Duration,
    done: std::sync::Arc<std::sync::atomic::AtomicU64>,
    stop: std::sync::mpsc::Receiver<()>,
) {
    let start = std::time::Instant::now();
    let mut next = start + every;
    while let Err(std::sync::mpsc::RecvTimeoutError::Timeout) =
        stop.recv_timeout(next.saturating_duration_since(std::time::Instant::now()))
    {
        let now = start.elapsed().as_secs_f64();
        let done = done.load(std::sync::atomic::Ordering::Relaxed);
        let rate = done as f64 / now.max(1e-9);
        let eta = if done > 0 {
            format!("{:.0} s", runs.saturating_sub(done) as f64 / rate)
        } else {
            "unknown until the first chunk ends".into()
        };
        note!(
            "progress: {done}/{runs} runs ({:.1} %) in {now:.0} s, {rate:.1} runs/s, eta {eta}",
            100.0 * done as f64 / runs.max(1) as f64
        );
        next += every;
    }
}

/// A progress bar on a terminal, progress lines otherwise ([`Progress`]).
fn progress_bar(runs: u64) -> Progress {
    if std::io::stderr().is_terminal() {
        let b = indicatif::ProgressBar::new(runs);
        b.set_style(
            indicatif::ProgressStyle::with_template(
                "{bar:40} {pos}/{len} runs  {per_sec}  eta {eta}",
            )
            .expect("valid template"),
        );
        Progress::Bar(b)
    } else {
        let seconds = std::env::var("POUND_PROGRESS_S")
            .ok()
            .and_then(|s| s.parse::<f64>().ok())
            .filter(|s| s.is_finite() && *s >= 0.0)
            .unwrap_or(10.0);
        let every = std::time::Duration::from_secs_f64(seconds.max(0.05));
        let done = std::sync::Arc::new(std::sync::atomic::AtomicU64::new(0));
        let (stop, stopped) = std::sync::mpsc::channel();
        let watcher = {
            let done = done.clone();
            std::thread::Builder::new()
                .name("progress".into())
                .spawn(move || watch(runs, every, done, stopped))
                .ok()
        };
        Progress::Lines {
            done,
            stop: Some(stop),
            watcher,
        }
    }
}
