//! `pound`: the command-line front end. A thin layer over the `pounding` library.

use anyhow::{bail, Context, Result};
use clap::{Parser, Subcommand, ValueEnum};
use pounding::config;
use pounding::contact::LawKind;
use pounding::cpu::{FastOptions, ReferenceOptions, Scheme};
use pounding::gpu::{GpuContext, GpuOptions, Precision};
use pounding::record::{read_record, Format, ReadOptions, Units, G};
use pounding::restitution::{exact_damping, Formula};
use pounding::shard::{meta_path, Fingerprint, Meta};
use std::io::IsTerminal;
use std::io::Write as _;

/// A line on standard error that never panics (stderr may be closed or full).
macro_rules! note {
    ($($t:tt)*) => { pounding::note(format_args!($($t)*)) };
}

/// A line on standard output; a failed write is an error, not a panic.
macro_rules! say {
    ($($t:tt)*) => {{
        use std::io::Write as _;
        writeln!(std::io::stdout(), $($t)*).context("writing to standard output")?
    }};
}
use std::path::PathBuf;

#[derive(Parser)]
#[command(
    name = "pound",
    version,
    about = "Earthquake-induced pounding between adjacent buildings, in large sweeps"
)]
struct Cli {
    #[command(subcommand)]
    cmd: Cmd,
}

#[derive(Clone, Copy, ValueEnum)]
enum SchemeArg {
    Fast,
    Reference,
}

#[derive(Clone, Copy, PartialEq, ValueEnum)]
enum BackendArg {
    /// A hardware GPU if one is found, else the CPU (with a one-line notice saying why); a
    /// software adapter (lavapipe) is slower than the CPU path, so only `gpu` uses it.
    Auto,
    Gpu,
    Cpu,
}

#[derive(Clone, Copy, ValueEnum)]
enum PrecisionArg {
    F32,
    F64,
}

impl PrecisionArg {
    fn get(self) -> Precision {
        match self {
            PrecisionArg::F32 => Precision::F32,
            PrecisionArg::F64 => Precision::F64,
        }
    }
}

#[derive(clap::Args)]
struct SweepArgs {
    config: PathBuf,
    /// Output CSV (written as OUT.partial, renamed when complete).
    #[arg(short, long, default_value = "results.csv")]
    output: PathBuf,
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
    shard: Option<pounding::shard::Shard>,
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
    /// Output format: csv (journaled, resumable) or parquet (typed columns, the plan
    /// fingerprint in its metadata).
    #[arg(long, value_enum, default_value = "csv")]
    format: FormatArg,
    /// Write only these columns (comma-separated; `run` is always kept, first).
    #[arg(long, value_delimiter = ',', value_name = "COLUMNS")]
    columns: Option<Vec<String>>,
}

#[derive(Clone, Copy, PartialEq, ValueEnum)]
enum FormatArg {
    Csv,
    Parquet,
}

fn parse_shard(s: &str) -> std::result::Result<pounding::shard::Shard, String> {
    pounding::shard::Shard::parse(s)
        .ok_or_else(|| format!("`{s}`: expected I/N with 0 <= I < N, e.g. 3/16"))
}

#[derive(clap::Args)]
struct PlotArgs {
    /// A CSV written by `pound sweep` (or any CSV with a header row).
    results: PathBuf,
    /// Column on the x axis (a swept parameter, e.g. gap_m, e, t1_s, pga_g).
    #[arg(long)]
    x: String,
    /// Column on the y axis (an output, e.g. peak_force_n).
    #[arg(long)]
    y: String,
    /// One series per value of this column (e.g. record, law).
    #[arg(long)]
    by: Option<String>,
    /// Keep only rows with COLUMN=VALUE (also !=, <, <=, >, >=); repeat to combine.
    #[arg(long = "where", value_name = "FILTER")]
    filters: Vec<String>,
    /// How rows that share x (and series) are combined: the other swept parameters are
    /// aggregated. `none` draws every row as a point.
    #[arg(long, value_enum, default_value = "max")]
    agg: AggArg,
    #[arg(long)]
    log_x: bool,
    #[arg(long)]
    log_y: bool,
    /// Output: .svg, or .png (text in a font built into the binary).
    #[arg(short, long, default_value = "plot.svg")]
    output: PathBuf,
}

#[derive(clap::Args)]
struct FragilityArgs {
    /// A CSV written by `pound sweep`.
    results: PathBuf,
    /// Intensity measure column (e.g. pga_g, scale_factor).
    #[arg(long, default_value = "pga_g")]
    im: String,
    /// Demand column (e.g. peak_force_n; `impacts` with threshold 0 for "pounds at all").
    #[arg(long, default_value = "peak_force_n")]
    edp: String,
    /// Exceedance thresholds (EDP > threshold), comma-separated.
    #[arg(long, value_delimiter = ',', required = true)]
    threshold: Vec<f64>,
    /// Keep only rows with COLUMN=VALUE (also !=, <, <=, >, >=); repeat to combine.
    #[arg(long = "where", value_name = "FILTER")]
    filters: Vec<String>,
    /// Counts per threshold and level (CSV).
    #[arg(short, long, default_value = "fragility.csv")]
    output: PathBuf,
    /// Observed fractions and fitted curves (.svg or .png).
    #[arg(long)]
    plot: Option<PathBuf>,
}

#[derive(Clone, Copy, ValueEnum)]
enum AggArg {
    Max,
    Mean,
    Median,
    Min,
    None,
}

#[derive(Subcommand)]
enum Cmd {
    /// Run every run of a sweep config and write one CSV row per run.
    Sweep(SweepArgs),
    /// GPU adapters.
    Gpu {
        #[command(subcommand)]
        cmd: GpuCmd,
    },
    /// Runs per second of the CPU and GPU paths on the same sweeps, with where time goes.
    Bench {
        /// Sweep sizes (runs, approximate).
        #[arg(long, value_delimiter = ',', default_value = "100,1000,10000,100000")]
        sizes: Vec<u64>,
        /// Largest sweep also run on the CPU (it is the slow side).
        #[arg(long, default_value_t = 10000)]
        max_cpu_runs: u64,
        #[arg(long, value_enum, default_value = "f32")]
        precision: PrecisionArg,
        /// Runs per GPU chunk.
        #[arg(long, default_value_t = 65536)]
        chunk: usize,
        /// Also write the table to this file.
        #[arg(short, long)]
        output: Option<PathBuf>,
        /// Also time each GPU sweep with `--aggregate COLUMNS` folded on the device (e.g. gap_m).
        #[arg(long, value_delimiter = ',', value_name = "COLUMNS")]
        aggregate: Option<Vec<String>>,
    },
    /// Speed against error of every path and accuracy setting on a benchmark sweep, against the
    /// reference solved once.
    Accuracy {
        #[arg(default_value = "configs/accuracy.toml")]
        config: PathBuf,
        /// RK4 substeps per contact duration to try.
        #[arg(long, value_delimiter = ',', default_value = "8,16,32,64,128")]
        settings: Vec<f64>,
        /// Stated relative accuracy of the reference.
        #[arg(long, default_value_t = 1e-8)]
        tol: f64,
        /// `auto` adds the GPU paths when a hardware adapter is found; `gpu` also on a software
        /// one; `cpu` leaves them out.
        #[arg(long, value_enum, default_value = "auto")]
        backend: BackendArg,
        #[arg(short, long, default_value = "accuracy.csv")]
        output: PathBuf,
        /// Work-precision plot (SVG).
        #[arg(long)]
        plot: Option<PathBuf>,
    },
    /// Impact damping zeta(e) of every formula, and `exact` per law.
    Formulas {
        /// Values of e: start:stop:step, a list a,b,c, or one value.
        #[arg(long, default_value = "0.1:1:0.05")]
        e: String,
        /// Also plot zeta against e for every formula (the seed's Fig. 2): .svg or .png.
        #[arg(long)]
        plot: Option<PathBuf>,
    },
    /// Plot an output of a results CSV against a swept parameter, one series per value of a
    /// grouping column (SVG, or PNG for a .png name).
    Plot(PlotArgs),
    /// Fragility curves from a results CSV: the share of runs whose EDP exceeds each threshold
    /// at each intensity level, and a lognormal curve fitted by maximum likelihood.
    Fragility(FragilityArgs),
    /// Combine the outputs of `pound sweep --shard I/N` into one CSV, checking that they come
    /// from one sweep (same fingerprint) and hold every run exactly once.
    Merge {
        /// Shard outputs (CSV files written by `pound sweep --shard`), in any order.
        #[arg(required = true)]
        inputs: Vec<PathBuf>,
        #[arg(short, long, default_value = "results.csv")]
        output: PathBuf,
    },
    /// The seed paper's cheap checks: Table 1 (e from the drop heights) and Fig. 2 (zeta(e) of
    /// every formula). The rest of the reproduction: docs/paper-reproduction.md.
    Paper,
    /// Restitution fidelity: one isolated collision per damped law, formula and e; the
    /// achieved e and the energy taken out against 0.5 m_eff (1 - e^2) v0^2.
    Restitution {
        /// Values of e: start:stop:step, a list a,b,c, or one value.
        #[arg(long, default_value = "0.1:1:0.05")]
        e: String,
        /// Every collision as CSV.
        #[arg(short, long, default_value = "restitution.csv")]
        output: PathBuf,
        /// Achieved against asked e, one panel per law (SVG).
        #[arg(long)]
        plot: Option<PathBuf>,
    },
    /// Force against penetration through one isolated impact (the seed's Fig. 5), per e.
    Hysteresis {
        /// Contact law.
        law: String,
        /// Restitution formula (laws that take zeta).
        #[arg(long, default_value = "ebrahimi")]
        formula: String,
        /// Values of e: start:stop:step, a list a,b,c, or one value.
        #[arg(long, default_value = "0.3:0.9:0.2")]
        e: String,
        /// Approach speed, m/s.
        #[arg(long, default_value_t = 1.0)]
        v0: f64,
        /// k (N/m) or beta (N/m^1.5).
        #[arg(long, default_value_t = 2.75e9)]
        stiffness: f64,
        /// Effective mass m1 m2 / (m1 + m2), kg.
        #[arg(long, default_value_t = 5.0e4)]
        m_eff: f64,
        /// Loop points as CSV (e, delta_m, force_n).
        #[arg(short, long, default_value = "hysteresis.csv")]
        output: PathBuf,
        /// The loops as SVG.
        #[arg(long)]
        plot: Option<PathBuf>,
    },
    /// Ground-motion records.
    Record {
        #[command(subcommand)]
        cmd: RecordCmd,
    },
}

#[derive(Subcommand)]
enum GpuCmd {
    /// List the adapters found: backend, type, f64 support, limits.
    Info,
}

#[derive(Subcommand)]
enum RecordCmd {
    /// Print npts, dt, duration and PGA of a record file.
    Info {
        file: PathBuf,
        /// auto, at2, values or two_column.
        #[arg(long, default_value = "auto")]
        format: String,
        /// Sample interval, s (needed for value files without a header).
        #[arg(long)]
        dt: Option<f64>,
        /// g, m/s2 or cm/s2 (default: from the header, else g).
        #[arg(long)]
        units: Option<String>,
        /// Lines to skip before parsing.
        #[arg(long, default_value_t = 0)]
        skip_lines: usize,
    },
}

fn main() -> std::process::ExitCode {
    // Like other command-line tools, end quietly when a reader such as `head` closes the pipe
    // (Rust ignores SIGPIPE, and printing to a closed pipe then panics). An interrupted sweep
    // keeps its finished chunks for --resume.
    #[cfg(unix)]
    // SAFETY: restoring the default disposition of one signal before any thread starts.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    // Mesa's software Vulkan driver probes for a Wayland display and prints "XDG_RUNTIME_DIR is
    // invalid" twice when there is none. Without XDG_RUNTIME_DIR no Wayland display can be
    // reached anyway; an absolute WAYLAND_DISPLAY that does not exist makes the probe fail
    // quietly. Set here, before any thread starts.
    if std::env::var_os("XDG_RUNTIME_DIR").is_none()
        && std::env::var_os("WAYLAND_DISPLAY").is_none()
    {
        std::env::set_var("WAYLAND_DISPLAY", "/nonexistent/pound-compute-only");
    }
    match run(Cli::parse()) {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            // The cause chain on one line; no backtrace, whatever RUST_BACKTRACE says.
            note!("error: {e:#}");
            std::process::ExitCode::FAILURE
        }
    }
}

fn run(cli: Cli) -> Result<()> {
    match cli.cmd {
        Cmd::Sweep(a) => sweep(a),
        Cmd::Gpu { cmd: GpuCmd::Info } => gpu_info(),
        Cmd::Bench {
            sizes,
            max_cpu_runs,
            precision,
            chunk,
            output,
            aggregate,
        } => bench(
            &sizes,
            max_cpu_runs,
            precision.get(),
            chunk,
            output,
            aggregate.as_deref(),
        ),
        Cmd::Formulas { e, plot } => formulas(&e, plot.as_deref()),
        Cmd::Plot(a) => plot(a),
        Cmd::Fragility(a) => fragility(a),
        Cmd::Merge { inputs, output } => {
            let rows = pounding::shard::merge(&output, &inputs)?;
            note!(
                "{rows} runs from {} inputs -> {}",
                inputs.len(),
                output.display()
            );
            Ok(())
        }
        Cmd::Paper => {
            {
                use std::io::Write as _;
                write!(std::io::stdout(), "{}", pounding::paper::report()?)
                    .context("writing to standard output")?;
            }
            Ok(())
        }
        Cmd::Accuracy {
            config,
            settings,
            tol,
            backend,
            output,
            plot,
        } => accuracy(&config, &settings, tol, backend, &output, plot.as_deref()),
        Cmd::Restitution { e, output, plot } => restitution(&e, &output, plot.as_deref()),
        Cmd::Hysteresis {
            law,
            formula,
            e,
            v0,
            stiffness,
            m_eff,
            output,
            plot,
        } => hysteresis(
            &law,
            &formula,
            &e,
            v0,
            stiffness,
            m_eff,
            &output,
            plot.as_deref(),
        ),
        Cmd::Record {
            cmd:
                RecordCmd::Info {
                    file,
                    format,
                    dt,
                    units,
                    skip_lines,
                },
        } => record_info(file, &format, dt, units, skip_lines),
    }
}

fn sweep(a: SweepArgs) -> Result<()> {
    use pounding::sweep_output::{Format, Opened, SweepOutput};
    let SweepArgs {
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
    } = a;
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
    let picked = columns
        .as_ref()
        .map(|c| pounding::output::select(c))
        .transpose()
        .map_err(|bad| {
            anyhow::anyhow!(
                "--columns: `{bad}` is not a column; the columns are: {}",
                pounding::output::header().join(", ")
            )
        })?;
    let picked_names: Option<Vec<String>> = picked.as_ref().map(|ix| {
        let h = pounding::output::header();
        ix.iter().map(|&i| h[i].to_string()).collect()
    });
    // The output is checked before anything runs: not a directory, not one of the inputs, and
    // writable.
    let config_text = config::read_text(&config)?;
    let records = config::input_files(&config_text, &config);
    let mut ins: Vec<(&str, &std::path::Path)> = vec![("the config", &config)];
    ins.extend(records.iter().map(|p| ("the record", p.as_path())));
    let target = check_outputs(&ins, &[("-o", Some(&output))])?
        .pop()
        .expect("one output");
    let precision = precision.get();
    let mut plan = config::load_text(&config_text, &config)?;
    for w in plan.warnings() {
        note!("warning: {}: {w}", config.display());
    }
    let scheme = match scheme {
        None => plan.spec.scheme,
        Some(SchemeArg::Fast) => Scheme::Fast(match plan.spec.scheme {
            Scheme::Fast(o) => o,
            _ => FastOptions::default(),
        }),
        Some(SchemeArg::Reference) => Scheme::Reference(match plan.spec.scheme {
            Scheme::Reference(o) => o,
            _ => ReferenceOptions::default(),
        }),
    };
    let fast = match scheme {
        Scheme::Fast(o) => Some(FastOptions {
            energy: o.energy || energy,
            ..o
        }),
        Scheme::Reference(_) => None,
    };
    let scheme = fast.map_or(scheme, Scheme::Fast);
    // The fingerprint covers the scheme as run, not as configured.
    plan.spec.scheme = scheme;
    if backend == BackendArg::Gpu && fast.is_none() {
        bail!("--backend gpu runs the fast scheme only; use --scheme fast or --backend cpu")
    }
    let gpu = match fast {
        Some(_) => gpu_context(backend, "running on the CPU")?,
        None => None,
    };
    if let Some(ctx) = &gpu {
        if precision == Precision::F64 && !ctx.supports_f64() {
            bail!(pounding::gpu::GpuError::NoF64 {
                adapter: ctx.info.name.clone()
            });
        }
    }
    let chunk = check_chunk(chunk, gpu.is_some())?;
    let mut pool = rayon::ThreadPoolBuilder::new();
    if let Some(t) = threads {
        pool = pool.num_threads(t);
    }
    let pool = pool.build().context("starting worker threads")?;
    let range = match shard {
        Some(s) => pounding::shard::shard_range(&plan, s),
        None => 0..plan.len(),
    };
    let meta = Meta {
        fingerprint: Fingerprint::of(&plan),
        plan_runs: plan.len(),
        first_run: range.start,
        end_run: range.end,
        shard,
        backend: match &gpu {
            Some(_) => format!("gpu-{}", precision.key()),
            None => "cpu".into(),
        },
        columns: picked_names.clone(),
        content: None,
    };
    let fmt = match &aggregate {
        Some(by) => Format::Summary(Box::new(pounding::aggregate::Aggregator::new(by, &exceed)?)),
        None if format == FormatArg::Parquet => Format::Parquet,
        None => Format::Csv,
    };
    let mut out = match SweepOutput::open(target, meta, fmt, picked, resume, &mut |l| note!("{l}"))?
    {
        Opened::Ready(o) => o,
        Opened::Complete(_) => return Ok(()),
    };
    let todo = out.todo();
    let done = out.done();
    let partial = out.partial_path();
    if let Some(s) = shard {
        note!(
            "shard {}/{}: runs {}..{} of {}",
            s.index,
            s.count,
            range.start,
            range.end,
            plan.len()
        );
    }
    if done > 0 {
        note!("resuming {}: {done} runs already on disk", output.display());
    }
    let bar = if std::io::stderr().is_terminal() {
        let b = indicatif::ProgressBar::new(todo.end - todo.start);
        b.set_style(
            indicatif::ProgressStyle::with_template(
                "{bar:40} {pos}/{len} runs  {per_sec}  eta {eta}",
            )
            .expect("valid template"),
        );
        b
    } else {
        indicatif::ProgressBar::hidden()
    };
    let on = match &gpu {
        Some(ctx) => format!("GPU {} in {}", ctx.describe(), precision.key()),
        None => format!("CPU, {} threads", pool.current_num_threads()),
    };
    note!(
        "{}: {} runs, {} scheme, {on}",
        config.display(),
        todo.end - todo.start,
        scheme.key(),
    );
    let mut absurd = 0u64;
    let summary = pool
        .install(|| -> Result<_> {
            match (&gpu, fast) {
                (Some(ctx), Some(fast)) => {
                    let opts = GpuOptions {
                        precision,
                        fast,
                        ..Default::default()
                    };
                    let (s, t) = match out.aggregator() {
                        Some(agg) => {
                            let (s, t) = pounding::sweep::run_gpu_aggregate(
                                &plan,
                                todo.clone(),
                                ctx,
                                &opts,
                                chunk,
                                pounding::gpu::reduce::DEFAULT_SLOTS,
                                agg,
                                |done| bar.set_position(done),
                            )?;
                            bar.suspend(|| {
                                note!(
                                    "aggregated on the device: {:.2} s folding; {} chunks with more than {} groups folded on the host; histograms flushed {} times",
                                    t.aggregate,
                                    t.host_folded_chunks,
                                    pounding::gpu::reduce::DEFAULT_SLOTS,
                                    t.slot_flushes
                                )
                            });
                            (s, t)
                        }
                        None => pounding::sweep::run_gpu_range(
                            &plan,
                            todo.clone(),
                            ctx,
                            &opts,
                            chunk,
                            |c: &[(pounding::plan::RunSpec, pounding::model::RunOutput)]| {
                                absurd += absurd_drifts(c);
                                out.take(&plan, c).map_err(anyhow::Error::from)
                            },
                            |done| bar.set_position(done),
                        )?,
                    };
                    if t.handed_off > 0 {
                        bar.suspend(|| {
                            note!(
                                "{} runs needed more than {} RK4 substeps per record step, past what {} resolves: finished on the CPU in f64",
                                t.handed_off,
                                opts.handoff(),
                                precision.key()
                            )
                        });
                    }
                    Ok(s)
                }
                _ => Ok(pounding::sweep::run_range(
                    &plan,
                    todo.clone(),
                    &scheme,
                    chunk,
                    |c: &[(pounding::plan::RunSpec, pounding::model::RunOutput)]| {
                        absurd += absurd_drifts(c);
                        out.take(&plan, c).map_err(anyhow::Error::from)
                    },
                    |done| bar.set_position(done),
                )?),
            }
        })
        .with_context(|| {
            format!(
                "writing {} (finished rows are kept there)",
                partial.display()
            )
        })?;
    bar.finish_and_clear();
    // Records are read once, at the start: a file changed since then no longer matches the rows
    // (or the fingerprint), so the output is not put in place.
    let changed = config::changed_records(&config_text, &config, &plan);
    if !changed.is_empty() {
        let summary_only = out.aggregator().is_some();
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
    let (path, what) = out.finish()?;
    if absurd > 0 {
        note!(
            "warning: {absurd} runs have a peak displacement above the building's height estimated from its period ({} m per s: T ~ 0.1 s per 3 m storey): check the record's units and the intensity",
            pounding::limits::HEIGHT_PER_PERIOD_M
        );
    }
    note!(
        "{} runs in {:.2} s ({:.0} runs/s): {} runs pounded, {} impacts, {} failures -> {} ({what})",
        summary.runs,
        summary.seconds,
        summary.runs_per_second(),
        summary.runs_with_impacts,
        summary.impacts,
        summary.failures,
        path.display()
    );
    Ok(())
}

/// Runs whose peak displacement exceeds the building's height estimated from its period.
fn absurd_drifts(rows: &[(pounding::plan::RunSpec, pounding::model::RunOutput)]) -> u64 {
    let h = pounding::limits::HEIGHT_PER_PERIOD_M;
    rows.iter()
        .filter(|(s, o)| o.peak_u1 > h * s.t1 || o.peak_u2 > h * s.t2)
        .count() as u64
}

/// Check a command's outputs before it does any work: each resolves (not a directory, its
/// folder exists), can be written, is none of `inputs` and is not written twice (the files a
/// pound output writes beside it count). Returns the targets given.
fn check_outputs(
    inputs: &[(&str, &std::path::Path)],
    outputs: &[(&str, Option<&std::path::Path>)],
) -> Result<Vec<pounding::target::Target>> {
    use pounding::target::Target;
    let mut targets = Vec::new();
    for (what, p) in outputs {
        let Some(p) = p else { continue };
        let t = Target::resolve(what, p)?;
        t.probe(what)?;
        targets.push((*what, t));
    }
    let named: Vec<(&str, &Target)> = targets.iter().map(|(w, t)| (*w, t)).collect();
    pounding::target::check_outputs(inputs, &named)?;
    Ok(targets.into_iter().map(|(_, t)| t).collect())
}

/// Warn when a results file is not vouched for by its sweep's sidecar.
fn warn_provenance(results: &std::path::Path) {
    if let Some(w) = pounding::journal::provenance_warning(results) {
        note!("warning: {w}");
    }
}

fn check_threads(t: usize) -> Result<usize> {
    if t == 0 || t > pounding::limits::MAX_THREADS {
        bail!(
            "--threads {t}: expected 1 to {} ({}; this machine has {})",
            pounding::limits::MAX_THREADS,
            pounding::limits::WHY_THREADS,
            std::thread::available_parallelism().map_or(1, |n| n.get())
        );
    }
    Ok(t)
}

/// `--chunk`, or the default for the path (64 runs per CPU task, 65,536 per GPU chunk).
fn check_chunk(chunk: Option<usize>, gpu: bool) -> Result<usize> {
    let (default, max) = if gpu {
        (65536, pounding::limits::MAX_GPU_CHUNK)
    } else {
        (64, pounding::limits::MAX_CPU_CHUNK)
    };
    let c = chunk.unwrap_or(default);
    if c == 0 || c > max {
        bail!(
            "--chunk {c}: expected 1 to {max} on the {} ({})",
            if gpu { "GPU" } else { "CPU" },
            pounding::limits::WHY_CHUNK
        );
    }
    Ok(c)
}

fn gpu_info() -> Result<()> {
    let all = pounding::gpu::context::adapters();
    if all.is_empty() {
        bail!("no GPU adapters found; install a Vulkan driver (software: apt-get install mesa-vulkan-drivers libvulkan1) or use --backend cpu");
    }
    for a in all {
        let l = &a.limits;
        say!(
            "{} | backend {:?} | type {:?} | driver {} {} | f64 {} | max storage binding {} MiB | max buffer {} MiB | workgroups/dim {}",
            a.info.name,
            a.info.backend,
            a.info.device_type,
            a.info.driver,
            a.info.driver_info,
            if a.f64 { "yes" } else { "no" },
            l.max_storage_buffer_binding_size >> 20,
            l.max_buffer_size >> 20,
            l.max_compute_workgroups_per_dimension
        );
    }
    Ok(())
}

fn bench(
    sizes: &[u64],
    max_cpu_runs: u64,
    precision: Precision,
    chunk: usize,
    output: Option<PathBuf>,
    aggregate: Option<&[String]>,
) -> Result<()> {
    if let Some(n) = sizes
        .iter()
        .find(|&&n| n == 0 || n > pounding::limits::MAX_BENCH_RUNS)
    {
        bail!(
            "--sizes: {n} runs is out of range: expected 1 to {}",
            pounding::limits::MAX_BENCH_RUNS
        );
    }
    if chunk == 0 || chunk > pounding::limits::MAX_GPU_CHUNK {
        bail!(
            "--chunk {chunk}: expected 1 to {} ({})",
            pounding::limits::MAX_GPU_CHUNK,
            pounding::limits::WHY_CHUNK
        );
    }
    check_outputs(&[], &[("-o", output.as_deref())])?;
    let ctx = match GpuContext::new() {
        Ok(c) => Some(c),
        Err(e) => {
            note!("notice: CPU only: {e}");
            None
        }
    };
    let mut rows = Vec::new();
    for &n in sizes {
        let plan = pounding::bench::plan(n);
        if let Some(ctx) = &ctx {
            let opts = GpuOptions {
                precision,
                ..Default::default()
            };
            // The first call compiles the kernel; keep that out of the figures.
            ctx.kernel(precision, false)?;
            let r = pounding::bench::gpu(&plan, ctx, &opts, chunk)?;
            note!("{} runs on GPU: {:.0} runs/s", r.runs, r.runs_per_second());
            rows.push(r);
            if let Some(by) = aggregate {
                ctx.aggregator(precision)?;
                let r = pounding::bench::gpu_aggregate(&plan, ctx, &opts, chunk, by)?;
                note!(
                    "{} runs on GPU, aggregated: {:.0} runs/s",
                    r.runs,
                    r.runs_per_second()
                );
                rows.push(r);
            }
        }
        if plan.len() <= max_cpu_runs {
            let r = pounding::bench::cpu(&plan);
            note!("{} runs on CPU: {:.0} runs/s", r.runs, r.runs_per_second());
            rows.push(r);
        }
    }
    let table = pounding::bench::table(&rows);
    write!(std::io::stdout(), "{table}").context("writing to standard output")?;
    if let Some(p) = output {
        pounding::output::write_atomic(&p, table.as_bytes())
            .with_context(|| format!("writing {}", p.display()))?;
    }
    Ok(())
}

fn formulas(e: &str, plot: Option<&std::path::Path>) -> Result<()> {
    let es = e_values(e)?;
    check_outputs(&[], &[("--plot", plot)])?;
    if let Some(path) = plot {
        let panels = pounding::restitution::zeta_panels(&es)?;
        pounding::plot::save(path, &panels, 2)?;
        note!(
            "zeta(e) of {} formulas -> {}",
            Formula::ALL.len(),
            path.display()
        );
    }
    let exact_laws = [
        LawKind::KelvinVoigt,
        LawKind::KelvinVoigtNoTension,
        LawKind::ModifiedLinear,
        LawKind::NonlinearViscoelastic,
    ];
    let mut head: Vec<String> = vec!["e".into()];
    head.extend(
        Formula::ALL
            .iter()
            .filter(|f| **f != Formula::Exact)
            .map(|f| f.key().to_string()),
    );
    head.extend(exact_laws.iter().map(|l| format!("exact:{}", l.key())));
    head.push("exact_a:hunt_crossley".into());
    say!("{}", head.join(","));
    for &e in &es {
        let mut row = vec![format!("{e}")];
        for f in Formula::ALL.iter().filter(|f| **f != Formula::Exact) {
            let z = f.zeta(e)?.expect("printed formula");
            row.push(format!("{z:.6}"));
        }
        for l in exact_laws
            .iter()
            .copied()
            .chain([LawKind::HuntCrossleyExact])
        {
            row.push(format!("{:.6}", exact_damping(l, e)?));
        }
        say!("{}", row.join(","));
    }
    Ok(())
}

fn fragility(a: FragilityArgs) -> Result<()> {
    use pounding::fragility::{csv, fit, levels, panel, FragilitySpec};
    let sidecar = meta_path(&a.results);
    check_outputs(
        &[
            ("the results", &a.results),
            ("the results' sidecar", &sidecar),
        ],
        &[("-o", Some(&a.output)), ("--plot", a.plot.as_deref())],
    )?;
    warn_provenance(&a.results);
    let table = pounding::table::Table::read(&a.results)?;
    let spec = FragilitySpec {
        im: a.im,
        edp: a.edp,
        thresholds: a.threshold,
        filters: pounding::table::Filter::parse_all(&a.filters)?,
    };
    let (lv, skipped) = levels(&table, &spec)?;
    let runs: u64 = lv.first().map_or(0, |l| l.iter().map(|x| x.n).sum());
    if runs == 0 {
        bail!(
            "{}: no runs left to count (check --where)",
            a.results.display()
        );
    }
    let fits: Vec<_> = lv.iter().map(|l| fit(l)).collect();
    say!(
        "{runs} runs at {} levels of {}{}",
        lv[0].len(),
        spec.im,
        if skipped > 0 {
            format!(" ({skipped} rows left out: status not ok, or no value)")
        } else {
            String::new()
        }
    );
    say!("\n| {} > | median {} | beta | se(ln median) | se(beta) | log-likelihood |\n|---:|---:|---:|---:|---:|---:|", spec.edp, spec.im);
    for (t, f) in spec.thresholds.iter().zip(&fits) {
        match f {
            Ok(f) => say!(
                "| {t} | {:.4} | {:.4} | {:.4} | {:.4} | {:.2} |",
                f.median,
                f.beta,
                f.se_ln_median,
                f.se_beta,
                f.log_likelihood
            ),
            Err(e) => say!("| {t} | no fit: {e} | | | | |"),
        }
    }
    pounding::output::write_atomic(&a.output, csv(&spec, &lv).as_bytes())
        .with_context(|| format!("writing {}", a.output.display()))?;
    if let Some(p) = &a.plot {
        pounding::plot::save(p, &[panel(&spec, &lv, &fits)], 1)?;
    }
    Ok(())
}

fn plot(a: PlotArgs) -> Result<()> {
    use pounding::sensitivity::{panel, Aggregate, PlotSpec};
    let sidecar = meta_path(&a.results);
    check_outputs(
        &[
            ("the results", &a.results),
            ("the results' sidecar", &sidecar),
        ],
        &[("-o", Some(&a.output))],
    )?;
    warn_provenance(&a.results);
    let table = pounding::table::Table::read(&a.results)?;
    let filters = pounding::table::Filter::parse_all(&a.filters)?;
    let spec = PlotSpec {
        x: a.x,
        y: a.y,
        by: a.by,
        filters,
        aggregate: match a.agg {
            AggArg::Max => Aggregate::Max,
            AggArg::Mean => Aggregate::Mean,
            AggArg::Median => Aggregate::Median,
            AggArg::Min => Aggregate::Min,
            AggArg::None => Aggregate::None,
        },
        log_x: a.log_x,
        log_y: a.log_y,
    };
    let (p, failed) = panel(&table, &spec)?;
    if failed > 0 {
        note!(
            "{}: {failed} rows left out: runs whose status is not ok, or values that are not finite",
            a.results.display()
        );
    }
    let points: usize = p.series.iter().map(|s| s.points.len()).sum();
    if points == 0 {
        bail!(
            "{}: no rows left to plot (check --where and that {} and {} have values)",
            a.results.display(),
            spec.x,
            spec.y
        );
    }
    pounding::plot::save(&a.output, std::slice::from_ref(&p), 1)?;
    note!(
        "{} series, {points} points -> {}",
        p.series.len(),
        a.output.display()
    );
    Ok(())
}

/// The GPU `backend` asks for: none for `cpu`, an error if `gpu` finds none, and for `auto` the
/// default adapter or, without one, a one-line notice (`fallback: why`) and none.
fn gpu_context(backend: BackendArg, fallback: &str) -> Result<Option<GpuContext>> {
    Ok(match backend {
        BackendArg::Cpu => None,
        BackendArg::Gpu => Some(GpuContext::new()?),
        BackendArg::Auto => match GpuContext::new() {
            Ok(c) if c.is_software() => {
                note!(
                    "notice: {fallback}: the adapter found, {}, is a software one (slower than the CPU path on the same cores); --backend gpu uses it",
                    c.info.name
                );
                None
            }
            Ok(c) => Some(c),
            Err(e) => {
                note!("notice: {fallback}: {e}");
                None
            }
        },
    })
}

fn accuracy(
    config: &std::path::Path,
    settings: &[f64],
    tol: f64,
    backend: BackendArg,
    output: &std::path::Path,
    plot: Option<&std::path::Path>,
) -> Result<()> {
    use pounding::accuracy;
    let most = pounding::limits::MAX_SUBSTEPS_PER_CONTACT;
    if let Some(bad) = settings.iter().find(|s| !(**s >= 1.0 && **s <= most)) {
        bail!(
            "--settings: {bad} is out of range: expected substeps per contact from 1 to {most} ({})",
            pounding::limits::WHY_SUBSTEPS
        );
    }
    if !(tol > 0.0 && tol < 1e-3) {
        bail!("--tol: {tol} is out of range: expected 0 < tol < 1e-3");
    }
    let text = config::read_text(config)?;
    let records = config::input_files(&text, config);
    let mut ins: Vec<(&str, &std::path::Path)> = vec![("the config", config)];
    ins.extend(records.iter().map(|p| ("the record", p.as_path())));
    check_outputs(&ins, &[("-o", Some(output)), ("--plot", plot)])?;
    let plan = config::load_text(&text, config)?;
    for w in plan.warnings() {
        note!("warning: {}: {w}", config.display());
    }
    let ctx = gpu_context(backend, "CPU path only")?;
    note!(
        "{}: {} runs; reference at tol {tol:e}, then {} settings on {} paths",
        config.display(),
        plan.len(),
        settings.len(),
        if ctx.is_some() { 3 } else { 1 }
    );
    say!("{}", accuracy::MARKDOWN_HEADER);
    let points = accuracy::study(&plan, ctx.as_ref(), settings, tol, |p| {
        let _ = writeln!(std::io::stdout(), "{}", accuracy::markdown_row(p));
    })?;
    pounding::output::write_atomic(output, accuracy::csv(&points).as_bytes())
        .with_context(|| format!("writing {}", output.display()))?;
    if let Some(p) = plot {
        pounding::plot::svg(p, &accuracy::panels(&points), 2)?;
    }
    Ok(())
}

fn e_values(e: &str) -> Result<Vec<f64>> {
    let es = if e.contains(',') {
        e.split(',').map(|x| x.trim().parse::<f64>().ok()).collect()
    } else {
        config::parse_colon_range(e)
    }
    .with_context(|| format!("--e `{e}`: expected start:stop:step, a list a,b,c or one value"))?;
    if es.len() > pounding::limits::MAX_E_VALUES {
        bail!(
            "--e `{e}` gives {} values: expected at most {} (each is a root-found collision)",
            es.len(),
            pounding::limits::MAX_E_VALUES
        );
    }
    let es: Vec<f64> = es.iter().map(|e| (e * 1e12).round() / 1e12).collect();
    if let Some(bad) = es.iter().find(|e| !(**e > 0.0 && **e <= 1.0)) {
        bail!("--e: e = {bad} is out of range: expected 0 < e <= 1");
    }
    Ok(es)
}

fn restitution(e: &str, output: &std::path::Path, plot: Option<&std::path::Path>) -> Result<()> {
    use pounding::fidelity;
    check_outputs(&[], &[("-o", Some(output)), ("--plot", plot)])?;
    let rows = fidelity::table(&e_values(e)?)?;
    pounding::output::write_atomic(output, fidelity::csv(&rows).as_bytes())
        .with_context(|| format!("writing {}", output.display()))?;
    say!("max |achieved e - asked e| per law and formula (`own`: the law's own chi(e)):\n");
    {
        use std::io::Write as _;
        write!(std::io::stdout(), "{}", fidelity::summary(&rows))
            .context("writing to standard output")?;
    }
    if let Some(p) = plot {
        pounding::plot::svg(p, &fidelity::panels(&rows), 4)?;
    }
    note!("{} collisions -> {}", rows.len(), output.display());
    Ok(())
}

#[allow(clippy::too_many_arguments)]
fn hysteresis(
    law: &str,
    formula: &str,
    e: &str,
    v0: f64,
    stiffness: f64,
    m_eff: f64,
    output: &std::path::Path,
    plot: Option<&std::path::Path>,
) -> Result<()> {
    use pounding::contact::Contact;
    use pounding::plot::{Panel, Series};
    let law = LawKind::from_key(law)
        .with_context(|| format!("law `{law}`: expected one of {}", LawKind::keys()))?;
    let formula = Formula::from_key(formula)
        .with_context(|| format!("--formula `{formula}`: expected one of {}", Formula::keys()))?;
    if !law.is_damped() {
        bail!(
            "law `{}` has no damping: its loop encloses no area",
            law.key()
        );
    }
    for (name, x) in [("--v0", v0), ("--stiffness", stiffness), ("--m-eff", m_eff)] {
        if !(x > 0.0 && x.is_finite()) {
            bail!("{name}: {x} is out of range: expected a positive number");
        }
    }
    check_outputs(&[], &[("-o", Some(output)), ("--plot", plot)])?;
    let mut csv = String::from("e,delta_m,force_n\n");
    let mut series = Vec::new();
    say!("| e | damping | achieved e | loop area J | 0.5 m_eff (1-e^2) v0^2 J |\n|---:|---:|---:|---:|---:|");
    for e in e_values(e)? {
        let d = pounding::restitution::damping_for(law, formula, e)?;
        let l = pounding::fidelity::hysteresis(&Contact::new(law, stiffness, d, m_eff), v0);
        for (x, f) in &l.points {
            csv.push_str(&format!("{e},{x},{f}\n"));
        }
        say!(
            "| {e} | {d:.6} | {:.6} | {:.6e} | {:.6e} |",
            l.achieved_e,
            l.area,
            0.5 * m_eff * (1.0 - e * e) * v0 * v0
        );
        series.push(Series {
            name: format!("e = {e}"),
            points: l.points.iter().map(|&(x, f)| (x * 1e3, f / 1e3)).collect(),
            scatter: false,
        });
    }
    pounding::output::write_atomic(output, csv.as_bytes())
        .with_context(|| format!("writing {}", output.display()))?;
    if let Some(p) = plot {
        let panel = Panel {
            title: format!("{} ({}), v0 = {v0} m/s", law.key(), formula.key()),
            x_label: "penetration (mm)".into(),
            y_label: "contact force (kN)".into(),
            series,
            ..Default::default()
        };
        pounding::plot::svg(p, &[panel], 1)?;
    }
    Ok(())
}

fn record_info(
    file: PathBuf,
    format: &str,
    dt: Option<f64>,
    units: Option<String>,
    skip_lines: usize,
) -> Result<()> {
    let format = Format::parse(format)
        .with_context(|| format!("--format `{format}`: expected {}", Format::KEYS))?;
    let units = match units {
        Some(u) => Some(
            Units::parse(&u).with_context(|| format!("--units `{u}`: expected {}", Units::KEYS))?,
        ),
        None => None,
    };
    let rec = read_record(
        &file,
        &ReadOptions {
            format,
            units,
            dt,
            skip_lines,
        },
    )?;
    let pga = rec.pga();
    say!("file      {}", file.display());
    say!("npts      {}", rec.npts());
    say!("dt        {} s", rec.dt);
    say!("t0        {} s", rec.t0);
    say!("duration  {:.3} s", rec.duration());
    say!(
        "pga       {:.4} g  ({:.4} m/s^2, {:.1} cm/s^2)",
        pga.value / G,
        pga.value,
        pga.value * 100.0
    );
    say!(
        "pga at    t = {:.3} s (sample {}, value {:+.4} g)",
        pga.time,
        pga.index,
        rec.accel[pga.index] / G
    );
    Ok(())
}
