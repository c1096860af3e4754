//! Criterion benches of whole sweeps on the CPU fast path and the GPU path, on the `pound bench`
//! model (the same plan builder), so the figures compare with BENCHMARKS.md.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use pounding::gpu::{GpuContext, GpuOptions, Precision};

fn sweeps(c: &mut Criterion) {
    let plan = pounding::bench::plan(1000);
    let mut g = c.benchmark_group("sweep_1000_runs_20s_record");
    g.sample_size(10);
    g.throughput(Throughput::Elements(plan.len()));
    g.bench_function("cpu_fast", |b| b.iter(|| pounding::bench::cpu(&plan)));
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
                ctx.kernel(precision, false).expect("kernel compiles");
                g.bench_function(format!("gpu_{}", precision.key()), |b| {
                    b.iter(|| pounding::bench::gpu(&plan, &ctx, &opts, 65536).expect("gpu sweep"))
                });
            }
        }
        Err(e) => eprintln!("GPU benches not run: {e}"),
    }
    g.finish();
}

criterion_group!(benches, sweeps);
criterion_main!(benches);
