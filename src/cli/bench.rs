//! `pound bench`: the benchmark sweeps on every engine found, as a markdown table.

use super::{check_outputs, write_file, Holds, PrecisionArg};
use anyhow::{bail, Result};
use pounding::engine::gpu::GpuOptions;
use pounding::engine::{Backend, Engine};
use pounding::physics::solver::{FastOptions, Scheme};
use pounding::plan::limits::MAX_BENCH_RUNS;
use pounding::studies::bench;
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Args {
    /// Sweep sizes (runs, approximate).
    #[arg(long, value_delimiter = ',', default_value = "100,1000,10000,100000")]
    sizes: Vec<u64>,
    /// Largest sweep also run on the CPU (it is the slow side).
    #[arg(long, default_value_t = 10000)]
    max_cpu_runs: u64,
    #[arg(long, value_enum, default_value = "f32")]
    precision: PrecisionArg,
    /// Runs per GPU chunk.
    #[arg(long, default_value_t = pounding::engine::GPU_CHUNK)]
    chunk: usize,
    /// Also write the table to this file.
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Also time each GPU sweep with `--aggregate COLUMNS` folded on the device (e.g. gap_m).
    #[arg(long, value_delimiter = ',', value_name = "COLUMNS")]
    aggregate: Option<Vec<String>>,
    /// Run the fast scheme at the setting this peak-force error chooses (as `pound sweep
    /// --target-error`), instead of the default (16 substeps per contact, calibrated for 1e-3).
    #[arg(long, value_name = "E")]
    target_error: Option<f64>,
    /// Instead, the multi-storey suite: rows of two buildings of each of these storey counts
    /// (e.g. 1,3,6,12,20), about `--storey-runs` runs each on the CPU and `--storey-gpu-runs`
    /// on the GPU adapter found, a software one too (in `--precision`; its runs/s and the
    /// share of its lanes busy, its host packing and kernel seconds; rows the adapter cannot
    /// run are named and left out). Each runs on the kernels a sweep of it takes: elastic
    /// one-storey rows on the pair's.
    #[arg(long, value_delimiter = ',', value_name = "N")]
    storeys: Option<Vec<usize>>,
    /// Runs per sweep of the multi-storey suite.
    #[arg(long, default_value_t = 200)]
    storey_runs: u64,
    /// Runs per GPU sweep of the multi-storey suite (default: `--storey-runs`).
    #[arg(long)]
    storey_gpu_runs: Option<u64>,
    /// With `--storeys`: also each suite's yielding twin (every storey yielding at 0.5 % drift,
    /// 3 % hardening), and its time against the elastic suite's.
    #[arg(long, requires = "storeys")]
    yielding: bool,
}

pub fn run(a: Args) -> Result<()> {
    if let Some(storeys) = &a.storeys {
        let gpu_runs = a.storey_gpu_runs.unwrap_or(a.storey_runs);
        return run_storeys(
            storeys,
            (a.storey_runs, gpu_runs),
            (a.precision.get(), a.yielding),
            a.output.as_deref(),
        );
    }
    let precision = a.precision.get();
    if let Some(n) = a.sizes.iter().find(|&&n| n == 0 || n > MAX_BENCH_RUNS) {
        bail!("--sizes: {n} runs is out of range: expected 1 to {MAX_BENCH_RUNS}");
    }
    // Checked here, not only when an adapter is found, so a typo fails on every machine.
    let chunk = pounding::engine::check_chunk(Some(a.chunk), true)?;
    check_outputs(&[], &[("-o", a.output.as_deref(), Holds::Text)])?;
    let mut fast = FastOptions::default();
    if let Some(e) = a.target_error {
        fast.substeps_per_contact = super::target_error(e)?.substeps_per_contact;
    }
    match pounding::physics::solver::calibration::calibrated_p99(fast.substeps_per_contact) {
        Some(e) => note!(
            "fast scheme at {} substeps per contact: p99 peak-force error {e:.1e} on configs/accuracy.toml (pound accuracy)",
            fast.substeps_per_contact
        ),
        None => note!(
            "fast scheme at {} substeps per contact (not a calibrated setting: pound accuracy --settings measures its error)",
            fast.substeps_per_contact
        ),
    }
    let ctx = Backend::Any.acquire("CPU only", &mut |l| note!("{l}"))?;
    let gpu = match &ctx {
        Some(ctx) => {
            let opts = GpuOptions {
                precision,
                fast,
                ..Default::default()
            };
            Some(Engine::gpu(ctx, opts, Some(chunk))?)
        }
        None => None,
    };
    let cpu = Engine::cpu(Scheme::Fast(fast), None)?;
    let mut rows = Vec::new();
    for &n in &a.sizes {
        let plan = bench::plan(n);
        if let (Some(ctx), Some(gpu)) = (&ctx, &gpu) {
            // The first call compiles the kernel; keep that out of the figures.
            ctx.kernel(precision, false, false, None)?;
            let r = bench::run(&plan, gpu)?;
            note!("{} runs on GPU: {:.0} runs/s", r.runs, r.runs_per_second());
            rows.push(r);
            if let Some(by) = &a.aggregate {
                ctx.aggregator(precision)?;
                let r = bench::fold(&plan, gpu, by)?;
                note!(
                    "{} runs on GPU, aggregated: {:.0} runs/s",
                    r.runs,
                    r.runs_per_second()
                );
                rows.push(r);
            }
        }
        if plan.len() <= a.max_cpu_runs {
            let r = bench::run(&plan, &cpu)?;
            note!("{} runs on CPU: {:.0} runs/s", r.runs, r.runs_per_second());
            rows.push(r);
        }
    }
    let table = bench::table(&rows);
    super::say_text(&table)?;
    if let Some(p) = &a.output {
        write_file(p, table.as_bytes())?;
    }
    Ok(())
}

/// `--storeys`: the multi-storey suite.
fn run_storeys(
    storeys: &[usize],
    (runs, gpu_runs): (u64, u64),
    (precision, yielding): (pounding::engine::gpu::Precision, bool),
    output: Option<&std::path::Path>,
) -> Result<()> {
    use pounding::physics::shear::MAX_STOREYS;
    if let Some(n) = storeys.iter().find(|&&n| n == 0 || n > MAX_STOREYS) {
        bail!("--storeys: {n} is out of range: expected 1 to {MAX_STOREYS}");
    }
    for (flag, n) in [("--storey-runs", runs), ("--storey-gpu-runs", gpu_runs)] {
        if n == 0 || n > MAX_BENCH_RUNS {
            bail!("{flag}: {n} is out of range: expected 1 to {MAX_BENCH_RUNS}");
        }
    }
    check_outputs(&[], &[("-o", output, Holds::Text)])?;
    // Any adapter, a software one too: its runs/s and lane utilisation beside the CPU's are
    // what the row kernels are measured by (issue 49), lavapipe's a proxy for a GPU's lanes.
    let ctx = Backend::Any.acquire("rows on the CPU only", &mut |l| note!("{l}"))?;
    let opts = GpuOptions {
        precision,
        ..Default::default()
    };
    let mut rows = Vec::new();
    // Each suite, then its yielding twin with its time per run against the suite's.
    let mut say = |r: bench::StoreyRow, on: &str, elastic: &mut f64| {
        let (n, rate) = (r.storeys, r.summary.runs_per_second());
        if r.yielding {
            note!(
                "{} runs of two yielding {n}-storey buildings on {on}: {rate:.0} runs/s ({:.2}x the elastic suite's time per run)",
                r.summary.runs,
                *elastic / rate
            );
        } else {
            note!(
                "{} runs of two {n}-storey buildings on {on}: {rate:.0} runs/s",
                r.summary.runs
            );
            *elastic = rate;
        }
        rows.push(r);
    };
    let twins: &[bool] = if yielding { &[false, true] } else { &[false] };
    for &n in storeys {
        let mut elastic = 0.0;
        for &y in twins {
            say(
                bench::run_storeys(n, &bench::row_plan(n, runs, y)),
                "CPU",
                &mut elastic,
            );
        }
        if let Some(ctx) = &ctx {
            for &y in twins {
                let plan = bench::row_plan(n, gpu_runs, y);
                // A row the adapter cannot run (a software one's loop limit) is said, not fatal.
                if let Err(e) = pounding::engine::gpu::row::check_fits(ctx, &plan) {
                    let kind = if y { "yielding " } else { "" };
                    note!("notice: {kind}{n}-storey rows on {}: {e}", ctx.info.name);
                    continue;
                }
                let r = bench::run_storeys_gpu(n, &plan, ctx, &opts)?;
                say(r, "GPU", &mut elastic);
            }
        }
    }
    let table = bench::storey_table(&rows);
    super::say_text(&table)?;
    if let Some(p) = output {
        write_file(p, table.as_bytes())?;
    }
    Ok(())
}
