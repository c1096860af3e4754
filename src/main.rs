//! `pound`: the command-line front end. A thin layer over the `pounding` library.

use anyhow::{bail, Context, Result};
use clap::{Parser, Subcommand, ValueEnum};
use pounding::config;
use pounding::contact::LawKind;
use pounding::cpu::{FastOptions, ReferenceOptions, Scheme};
use pounding::output::CsvOut;
use pounding::record::{read_record, Format, ReadOptions, Units, G};
use pounding::restitution::{exact_damping, Formula};
use std::io::IsTerminal;
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

#[derive(Subcommand)]
enum Cmd {
    /// Run every run of a sweep config and write one CSV row per run.
    Sweep {
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
        /// Runs per parallel task.
        #[arg(long, default_value_t = 64)]
        chunk: usize,
    },
    /// Impact damping zeta(e) of every formula, and `exact` per law.
    Formulas {
        /// Values of e: start:stop:step, or one value.
        #[arg(long, default_value = "0.1:1:0.05")]
        e: String,
    },
    /// Ground-motion records.
    Record {
        #[command(subcommand)]
        cmd: RecordCmd,
    },
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
    match run(Cli::parse()) {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            // The cause chain on one line; no backtrace, whatever RUST_BACKTRACE says.
            eprintln!("error: {e:#}");
            std::process::ExitCode::FAILURE
        }
    }
}

fn run(cli: Cli) -> Result<()> {
    match cli.cmd {
        Cmd::Sweep {
            config,
            output,
            threads,
            scheme,
            chunk,
        } => sweep(config, output, threads, scheme, chunk),
        Cmd::Formulas { e } => formulas(&e),
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

fn sweep(
    config: PathBuf,
    output: PathBuf,
    threads: Option<usize>,
    scheme: Option<SchemeArg>,
    chunk: usize,
) -> Result<()> {
    let plan = config::load(&config)?;
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
    let mut pool = rayon::ThreadPoolBuilder::new();
    if let Some(t) = threads {
        if t == 0 {
            bail!("--threads must be at least 1");
        }
        pool = pool.num_threads(t);
    }
    let pool = pool.build().context("starting worker threads")?;
    let mut out =
        CsvOut::create(&output).with_context(|| format!("cannot create {}", output.display()))?;
    let partial = out.partial_path().to_path_buf();
    let total = plan.len();
    let bar = if std::io::stderr().is_terminal() {
        let b = indicatif::ProgressBar::new(total);
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
    eprintln!(
        "{}: {} runs, {} scheme, {} threads",
        config.display(),
        total,
        scheme.key(),
        pool.current_num_threads()
    );
    let summary = pool
        .install(|| {
            pounding::sweep::run(
                &plan,
                &scheme,
                chunk,
                |rows| out.write(rows.iter().map(|(s, o)| pounding::output::row(&plan, s, o))),
                |done| bar.set_position(done),
            )
        })
        .with_context(|| {
            format!(
                "writing {} (finished rows are kept there)",
                partial.display()
            )
        })?;
    bar.finish_and_clear();
    let path = out
        .finish()
        .with_context(|| format!("finishing {}", output.display()))?;
    eprintln!(
        "{} runs in {:.2} s ({:.0} runs/s): {} runs pounded, {} impacts, {} failures -> {}",
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

fn formulas(e: &str) -> Result<()> {
    let es = config::parse_colon_range(e)
        .with_context(|| format!("--e `{e}`: expected start:stop:step or one value"))?;
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
    println!("{}", head.join(","));
    for &e in &es {
        let e = (e * 1e12).round() / 1e12;
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
        println!("{}", row.join(","));
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
    println!("file      {}", file.display());
    println!("npts      {}", rec.npts());
    println!("dt        {} s", rec.dt);
    println!("t0        {} s", rec.t0);
    println!("duration  {:.3} s", rec.duration());
    println!(
        "pga       {:.4} g  ({:.4} m/s^2, {:.1} cm/s^2)",
        pga.value / G,
        pga.value,
        pga.value * 100.0
    );
    println!(
        "pga at    t = {:.3} s (sample {}, value {:+.4} g)",
        pga.time,
        pga.index,
        rec.accel[pga.index] / G
    );
    Ok(())
}
