//! Criterion benches of whole sweeps on every engine, on the `pound bench` model (the same plan
//! builder and the same `studies::bench::run`), so the figures compare with BENCHMARKS.md.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use pounding::engine::gpu::{GpuContext, GpuOptions, Precision};
use pounding::engine::Engine;
use pounding::physics::solver::{FastOptions, Scheme};
use pounding::studies::bench;

fn sweeps(c: &mut Criterion) {
    let plan = bench::plan(1000);
    let mut g = c.benchmark_group("sweep_1000_runs_20s_record");
    g.sample_size(10);
    g.throughput(Throughput::Elements(plan.len()));
    let cpu = Engine::cpu(Scheme::Fast(FastOptions::default()), None).expect("default chunk");
    g.bench_function("cpu_fast", |b| {
        b.iter(|| bench::run(&plan, &cpu).expect("cpu sweep"))
    });
    match GpuContext::new() {
        Ok(ctx) => {
            for precision in [Precision::F32, Precision::F64] {
                if precision == Precision::F64 && !ctx.supports_f64() {
                    continue;
                }
                let opts = GpuOptions {
                    precision,
                    ..Default::default()
                };
                let gpu = Engine::gpu(&ctx, opts, None).expect("default chunk");
                ctx.kernel(precision, false, false, None)
                    .expect("kernel compiles");
                g.bench_function(format!("gpu_{}", precision.key()), |b| {
                    b.iter(|| bench::run(&plan, &gpu).expect("gpu sweep"))
                });
            }
        }
        Err(e) => eprintln!("GPU benches not run: {e}"),
    }
    g.finish();
}

criterion_group!(benches, sweeps);
criterion_main!(benches);
