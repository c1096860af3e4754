//! `pound sweep`: its flags as the library's sweep options ([`pounding::sweep`]), the output
//! name checked, the sweep run with its lines and progress shown on standard error.

use super::{check_outputs, config_inputs, BackendArg, Holds, PrecisionArg};
use anyhow::Result;
use clap::ValueEnum;
use pounding::plan::config;
use pounding::plan::settings::SchemeKind;
use pounding::plan::shard::Shard;
use pounding::sweep::options::{FileFormat, Options, Said};
use pounding::sweep::prepare::Prepared;
use pounding::sweep::run::Front;
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
    // A default name is never an earlier output; --resume continues the one it names.
    let output = match (&a.output, a.resume) {
        (None, true) => PathBuf::from("results.csv"),
        (given, _) => super::default_output(given.clone(), "results.csv"),
    };
    let options = Options {
        scheme: a.scheme.map(|s| match s {
            SchemeArg::Fast => SchemeKind::Fast,
            SchemeArg::Reference => SchemeKind::Reference,
        }),
        energy: a.energy,
        target_error: a.target_error,
        backend: a.backend.get(),
        precision: a.precision.get(),
        chunk: a.chunk,
        threads: a.threads,
        format: FileFormat::for_output(
            a.format.map(|f| match f {
                FormatArg::Csv => FileFormat::Csv,
                FormatArg::Parquet => FileFormat::Parquet,
            }),
            &output,
            a.aggregate.is_some(),
        ),
        columns: a.columns,
        aggregate: a.aggregate,
        exceed: a.exceed,
        shard: a.shard,
        resume: a.resume,
    };
    options.check()?;
    // The output is checked before anything runs: not a directory, not one of the inputs, and
    // writable.
    let holds = match options.format {
        FileFormat::Parquet => Holds::Parquet,
        FileFormat::Csv => Holds::Csv,
    };
    let text = config::read_text(&a.config)?;
    let records = config::input_files(&text, &a.config);
    let target = check_outputs(
        &config_inputs(&a.config, &records),
        &[("-o", Some(&output), holds)],
    )?
    .pop()
    .expect("one output");
    let mut front = Shown { progress: None };
    let prepared = Prepared::new(&options, &a.config, text, &mut |s| front.say(s))?;
    if let Some(done) = prepared.run_to_file(target, &mut front)? {
        finished(&done.summary, &done.path, &format!(" ({})", done.what));
    }
    Ok(())
}

/// The command line's [`Front`]: lines on standard error, progress as a bar or lines.
struct Shown {
    progress: Option<Progress>,
}

impl Front for Shown {
    fn say(&mut self, said: Said) {
        let line = match said {
            Said::Notice(n) => n,
            Said::Warning(w) => format!("warning: {w}"),
        };
        match &self.progress {
            Some(p) => p.suspend(|| note!("{line}")),
            None => note!("{line}"),
        }
    }

    fn start(&mut self, runs: u64) {
        self.progress = Some(progress_bar(runs));
    }

    fn progress(&mut self, done: u64) {
        if let Some(p) = &self.progress {
            p.set_position(done);
        }
    }

    fn end(&mut self) {
        if let Some(mut p) = self.progress.take() {
            p.finish_and_clear();
        }
    }
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
