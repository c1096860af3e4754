//! `pound sweep`: settings from flags, the output opened (fresh or resumed), the engine run,
//! the output put in place.

use super::{check_outputs, config_inputs, BackendArg, Holds, PrecisionArg};
use anyhow::{bail, Context, Result};
use clap::ValueEnum;
use pounding::engine::aggregate::Aggregator;
use pounding::engine::{Backend, Chunk, Engine, Kernel};
use pounding::io::provenance::{Fingerprint, Meta};
use pounding::io::sweep_output::{Format, Opened, SweepOutput};
use pounding::plan::settings::{
    check_threads, picked_columns, sweep_warnings, SchemeKind, SchemeSettings,
};
use pounding::plan::shard::Shard;
use pounding::plan::{config, Plan};
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
    /// GPU arithmetic. f32 (default) adds to the fast scheme's own error, by scene kind (against
    /// the CPU on the shipped configs, README "GPU precision by scene kind"): peak force within
    /// 4.5e-5 on elastic pairs and rows, 5.1e-3 where storeys yield, 1.4e-2 with P-Delta (p99
    /// 2.5e-3); impact counts differ on grazing contacts (15 of 180 runs on configs/row-3-6.toml).
    /// f64 needs an adapter with SHADER_F64 and matches the CPU to 1e-8 (nonlinear
    /// viscoelastic: 2e-6).
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
    /// in the sidecar). On a row whose storeys yield, the largest p99 error of peak force,
    /// drift, residual drift and ductility on the yielding suites.
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

pub fn run(a: Args) -> Result<()> {
    let flags = Flags::check(a)?;
    // The output is checked before anything runs: not a directory, not one of the inputs, and
    // writable.
    let config_text = config::read_text(&flags.config)?;
    let target = flags.target(&config_text)?;
    let mut plan = config::load_text(&config_text, &flags.config)?;
    let chosen = flags.settle_scheme(&mut plan, &config_text)?;
    plan.ask_storey_columns(flags.columns.as_deref().unwrap_or_default());
    let gpu = pounding::engine::gpu_for(
        &plan,
        flags.backend,
        flags.precision,
        chosen.is_some(),
        &mut |l| note!("{l}"),
    )?;
    let engine = Engine::new(plan.scheme(), gpu.as_ref(), flags.precision, flags.chunk)?;
    let Columns {
        format,
        picked,
        names,
    } = flags.output_columns(&plan)?;
    let range = match flags.shard {
        Some(s) => pounding::plan::shard::shard_range(&plan, s),
        None => 0..plan.len(),
    };
    let meta = Meta {
        fingerprint: Fingerprint::of_plan(&plan),
        plan_runs: plan.len(),
        first_run: range.start,
        end_run: range.end,
        shard: flags.shard,
        backend: engine.key(),
        kernel: Some(Kernel::of(&plan).key().into()),
        columns: names,
        content: None,
        target_error: chosen.map(pounding::io::provenance::TargetError::of),
        settings: Some(pounding::io::provenance::Settings::of_plan(&plan)),
    };
    // Every refusal that the plan decides comes before any file is made.
    engine.check(&plan)?;
    let Some(mut out) = open_output(target, meta, format, picked, flags.resume)? else {
        return Ok(());
    };
    let pool = flags.pool()?;
    let todo = out.todo();
    note!(
        "{}: {} runs of {}, {} scheme, {} kernel on the {}",
        flags.config.display(),
        todo.end - todo.start,
        plan.scene(),
        plan.scheme().key(),
        Kernel::of(&plan).key(),
        pool.install(|| engine.describe()),
    );
    let (summary, absurd, past_drift) =
        pool.install(|| integrate(&engine, &plan, &mut out, todo))?;
    // Records are read once, at the start: a file changed since then no longer matches the rows
    // (or the fingerprint), so the output is not put in place.
    let changed = config::changed_records(&config_text, &flags.config, &plan);
    let (path, what) = finish_unless_changed(*out, &changed)?;
    for w in sweep_warnings(&plan, absurd, past_drift) {
        note!("warning: {w}");
    }
    finished(&summary, &path, &format!(" ({what})"));
    Ok(())
}

/// How a sweep's runs are written: a summary, Parquet or CSV; `--columns` as indices into the
/// plan's header; the column names the sidecar records (None where they are the pair's fixed
/// schema, which a reader knows).
struct Columns {
    format: Format,
    picked: Option<Vec<usize>>,
    names: Option<Vec<String>>,
}

/// The flags of `pound sweep`, checked against each other: the settings stage before any file
/// is read.
struct Flags {
    config: PathBuf,
    output: PathBuf,
    format: FormatArg,
    threads: Option<usize>,
    scheme: Option<SchemeArg>,
    backend: Backend,
    precision: pounding::engine::gpu::Precision,
    chunk: Option<usize>,
    energy: bool,
    shard: Option<Shard>,
    resume: bool,
    aggregate: Option<Vec<String>>,
    exceed: Vec<String>,
    columns: Option<Vec<String>>,
    target_error: Option<f64>,
}

impl Flags {
    fn check(a: Args) -> Result<Flags> {
        // A default name is never an earlier output; --resume continues the one it names.
        let output = match (a.output, a.resume) {
            (None, true) => PathBuf::from("results.csv"),
            (given, _) => super::default_output(given, "results.csv"),
        };
        let parquet_name = output
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("parquet"));
        let format = a
            .format
            .unwrap_or(if parquet_name && a.aggregate.is_none() {
                FormatArg::Parquet
            } else {
                FormatArg::Csv
            });
        if format == FormatArg::Parquet && a.resume {
            bail!("--resume continues CSV output only: a Parquet file is readable only once its footer is written at the end");
        }
        if a.aggregate.is_some() && (format == FormatArg::Parquet || a.columns.is_some()) {
            bail!(
                "--aggregate writes its own summary columns: --format and --columns do not apply"
            );
        }
        if a.aggregate.is_some() && (a.resume || a.shard.is_some()) {
            bail!("--aggregate keeps its summary in memory until the sweep ends: it cannot be combined with --resume or --shard");
        }
        Ok(Flags {
            threads: a.threads.map(check_threads).transpose()?,
            config: a.config,
            output,
            format,
            scheme: a.scheme,
            backend: a.backend.get(),
            precision: a.precision.get(),
            chunk: a.chunk,
            energy: a.energy,
            shard: a.shard,
            resume: a.resume,
            aggregate: a.aggregate,
            exceed: a.exceed,
            columns: a.columns,
            target_error: a.target_error,
        })
    }

    /// The output, checked: not a directory, not one of the config's inputs, writable.
    fn target(&self, config_text: &str) -> Result<pounding::io::target::Target> {
        let records = config::input_files(config_text, &self.config);
        let holds = if self.format == FormatArg::Parquet {
            Holds::Parquet
        } else {
            Holds::Csv
        };
        Ok(check_outputs(
            &config_inputs(&self.config, &records),
            &[("-o", Some(&self.output), holds)],
        )?
        .pop()
        .expect("one output"))
    }

    /// Set the scheme as run on `plan` (the fingerprint covers it: the config's, `--scheme`,
    /// `--energy`, and the setting `--target-error` chooses from the scene's calibration), and
    /// say what a user should hear before any run. Returns the `--target-error` choice.
    fn settle_scheme(
        &self,
        plan: &mut Plan,
        config_text: &str,
    ) -> Result<Option<pounding::physics::solver::calibration::Choice>> {
        let settled = SchemeSettings {
            scheme: self.scheme.map(|s| match s {
                SchemeArg::Fast => SchemeKind::Fast,
                SchemeArg::Reference => SchemeKind::Reference,
            }),
            energy: self.energy,
            target_error: self.target_error,
        }
        .settle(plan, config_text)?;
        for n in &settled.notices {
            note!("{n}");
        }
        super::warn_all(&self.config, settled.warnings);
        Ok(settled.chosen)
    }

    /// How runs are written ([`Columns`]).
    fn output_columns(&self, plan: &Plan) -> Result<Columns> {
        let picked = picked_columns(plan, self.columns.as_deref())?;
        let summary = self
            .aggregate
            .as_ref()
            .map(|by| Aggregator::for_plan(plan, by, &self.exceed))
            .transpose()?;
        let format = output_format(summary, self.format);
        let names = picked.names;
        let fixed = names
            .iter()
            .map(String::as_str)
            .eq(pounding::plan::columns::header());
        let named = !matches!(format, Format::Summary(_)) && !fixed;
        Ok(Columns {
            format,
            picked: picked.indices,
            names: named.then_some(names),
        })
    }

    /// The worker threads (`--threads`, default all cores).
    fn pool(&self) -> Result<rayon::ThreadPool> {
        let mut pool = rayon::ThreadPoolBuilder::new();
        if let Some(t) = self.threads {
            pool = pool.num_threads(t);
        }
        pool.build().context("starting worker threads")
    }
}

/// Run the runs `out` still needs through `engine`, into `out` (rows, or folded into its
/// summary): the report's totals, the runs whose peak displacement passed a building's
/// height, and the runs with a storey past the collapse drift ratio.
fn integrate(
    engine: &Engine,
    plan: &Plan,
    out: &mut SweepOutput,
    todo: std::ops::Range<u64>,
) -> Result<(pounding::engine::Summary, u64, u64)> {
    let partial = out.partial_path();
    let mut bar = progress_bar(todo.end - todo.start);
    let progress = |done| bar.set_position(done);
    let (mut absurd, mut past_drift) = (0u64, 0u64);
    let report = match out.aggregator() {
        Some(agg) => engine
            .summarise(plan, todo, agg, progress)
            .map_err(anyhow::Error::from),
        None => engine.sweep(
            plan,
            todo,
            |c: Chunk<'_>| {
                absurd += c.above_height();
                past_drift += c.past_collapse_drift();
                out.take_chunk(c).map_err(anyhow::Error::from)
            },
            progress,
        ),
    }
    .with_context(|| {
        format!(
            "writing {} (finished rows are kept there)",
            partial.display()
        )
    })?;
    if let Engine::Gpu { opts, .. } = engine {
        let t = report.gpu;
        bar.suspend(|| {
            if out.aggregator().is_some() && t.aggregate > 0.0 {
                note!(
                    "aggregated on the device: {:.2} s folding; {} chunks with more than {} groups folded on the host; histograms flushed {} times",
                    t.aggregate,
                    t.host_folded_chunks,
                    pounding::engine::gpu::reduce::DEFAULT_SLOTS,
                    t.slot_flushes
                );
            }
            if t.handed_off > 0 {
                note!(
                    "{} runs needed more than {} RK4 substeps per record step, past what {} resolves: finished on the CPU in f64",
                    t.handed_off,
                    opts.handoff(),
                    opts.precision.key()
                );
            }
        });
    }
    bar.finish_and_clear();
    Ok((report.summary, absurd, past_drift))
}

/// The one line a finished sweep ends with.
fn finished(summary: &pounding::engine::Summary, path: &std::path::Path, what: &str) {
    let collapsed = if summary.collapsed > 0 {
        format!(", {} collapsed", summary.collapsed)
    } else {
        String::new()
    };
    note!(
        "{} runs in {:.2} s ({:.0} runs/s): {} runs pounded, {} impacts{collapsed}, {} failures -> {}{what}",
        summary.runs,
        summary.seconds,
        summary.runs_per_second(),
        summary.runs_with_impacts,
        summary.impacts,
        summary.failures,
        path.display()
    );
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
