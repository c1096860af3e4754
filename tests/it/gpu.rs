//! GPU path: shader layout against the Rust structs, GPU against the CPU twin.

use pounding::gpu::layout::{self, Layout};
use pounding::gpu::shader::{fast_source, Precision};

fn parse(precision: Precision) -> naga::Module {
    let src = fast_source(precision);
    let module =
        naga::front::wgsl::parse_str(&src).unwrap_or_else(|e| panic!("{}", e.emit_to_string(&src)));
    let mut v = naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::FLOAT64,
    );
    if let Err(e) = v.validate(&module) {
        panic!("{}", e.emit_to_string(&src));
    }
    module
}

fn check<T: Layout>(module: &naga::Module, size: usize) {
    let (_, ty) = module
        .types
        .iter()
        .find(|(_, t)| t.name.as_deref() == Some(T::NAME))
        .unwrap_or_else(|| panic!("struct {} not in shader", T::NAME));
    let naga::TypeInner::Struct { members, span } = &ty.inner else {
        panic!("{} is not a struct", T::NAME);
    };
    let wgsl: Vec<(String, usize)> = members
        .iter()
        .map(|m| (m.name.clone().unwrap_or_default(), m.offset as usize))
        .collect();
    let rust: Vec<(String, usize)> = T::fields()
        .into_iter()
        .map(|(n, o)| (n.to_string(), o))
        .collect();
    assert_eq!(wgsl, rust, "{}: fields and offsets differ", T::NAME);
    assert_eq!(*span as usize, size, "{}: size differs", T::NAME);
}

#[test]
fn shared_structs_match_the_shader_in_both_precisions() {
    let m = parse(Precision::F64);
    check::<layout::Params64>(&m, size_of::<layout::Params64>());
    check::<layout::State64>(&m, size_of::<layout::State64>());
    check::<layout::Meta>(&m, size_of::<layout::Meta>());
    check::<layout::Counters>(&m, size_of::<layout::Counters>());
    check::<layout::Dispatch>(&m, size_of::<layout::Dispatch>());
    let m = parse(Precision::F32);
    check::<layout::Params32>(&m, size_of::<layout::Params32>());
    check::<layout::State32>(&m, size_of::<layout::State32>());
    check::<layout::Meta>(&m, size_of::<layout::Meta>());
}

use crate::support::{collect, rel};
use pounding::cpu::{FastOptions, Scheme};
use pounding::gpu::{GpuContext, GpuOptions};
use pounding::model::RunOutput;
use pounding::plan::{Plan, RunSpec};
use std::sync::OnceLock;

/// The shared test device. With `POUND_REQUIRE_GPU=1` (CI) a missing adapter fails the test.
fn ctx() -> Option<&'static GpuContext> {
    static CTX: OnceLock<Option<GpuContext>> = OnceLock::new();
    CTX.get_or_init(|| match GpuContext::new() {
        Ok(c) => {
            eprintln!("GPU tests on {}", c.describe());
            Some(c)
        }
        Err(e) => {
            if std::env::var("POUND_REQUIRE_GPU").is_ok_and(|v| v == "1") {
                panic!("POUND_REQUIRE_GPU=1 but {e}");
            }
            eprintln!("skipping GPU test: {e}");
            None
        }
    })
    .as_ref()
}

fn gpu_collect(plan: &Plan, opts: &GpuOptions, chunk: usize) -> Vec<(RunSpec, RunOutput)> {
    let mut rows = Vec::new();
    let sink = |c: &[(RunSpec, RunOutput)]| -> Result<(), pounding::gpu::GpuError> {
        rows.extend_from_slice(c);
        Ok(())
    };
    pounding::sweep::run_gpu(plan, ctx().unwrap(), opts, chunk, sink, |_| {}).unwrap();
    rows
}

/// f64 on the GPU runs the CPU fast path's arithmetic, so the two agree to rounding: measured
/// on these 1,632 mixed runs, max 1.4e-11 for nine laws. The nonlinear viscoelastic law differs
/// by up to 7.2e-6 on lavapipe (123 of its runs above 1e-9). Its `delta^(1/4)` damping is
/// singular at first touch, and on the CPU alone moving the damping by 4 ulps changes some of
/// those runs by as much (7.2e-6), but not all of them, so the cause is not pinned down yet
/// (issue 4's accuracy work): it gets a bound of 3x its measured maximum, every other law 1e-9.
#[test]
fn gpu_f64_matches_cpu_fast_on_mixed_runs() {
    let Some(ctx) = ctx() else { return };
    assert!(ctx.supports_f64(), "{} has no SHADER_F64", ctx.describe());
    let plan = crate::fast_vs_reference::mixed_plan();
    let cpu = collect(&plan, &Scheme::Fast(FastOptions::default()), 8);
    let opts = GpuOptions {
        precision: pounding::gpu::Precision::F64,
        ..Default::default()
    };
    let gpu = gpu_collect(&plan, &opts, 100_000);
    assert_eq!(cpu.len(), gpu.len());
    let (mut worst, mut worst_nlve) = (0.0f64, 0.0f64);
    for ((s, c), (_, g)) in cpu.iter().zip(&gpu) {
        assert_eq!(c.status, g.status, "run {}", s.index);
        assert_eq!(c.impacts, g.impacts, "run {}", s.index);
        assert_eq!(c.peak_force == 0.0, g.peak_force == 0.0, "run {}", s.index);
        let e = [
            rel(g.peak_force, c.peak_force),
            rel(g.peak_u1, c.peak_u1),
            rel(g.peak_u2, c.peak_u2),
            rel(g.peak_penetration, c.peak_penetration),
            rel(g.impact_velocity, c.impact_velocity),
        ]
        .into_iter()
        .filter(|x| x.is_finite())
        .fold(0.0, f64::max);
        let nlve = s.law == pounding::contact::LawKind::NonlinearViscoelastic;
        if nlve {
            worst_nlve = worst_nlve.max(e);
        } else {
            worst = worst.max(e);
        }
        let bound = if nlve { 2e-5 } else { 1e-9 };
        assert!(
            e <= bound,
            "run {} ({}): GPU-CPU difference {e:e}",
            s.index,
            s.law.key()
        );
    }
    eprintln!("f64 GPU vs CPU: max {worst:e} (nonlinear viscoelastic {worst_nlve:e})");
}

/// f32 against the CPU f64 fast path on the same 1,632 runs. Measured: peak force median 1e-6,
/// p99 7.2e-5, max 1.4e-4; peak displacements max 5.9e-5; impact counts equal on every run. The
/// scheme's own error against the reference is ~1e-3 (fast_vs_reference), so f32 adds at most a
/// seventh of it. Bounds: 7x the measured maxima (f32 rounding moves with the record and law).
#[test]
fn gpu_f32_error_against_cpu_f64() {
    let Some(_) = ctx() else { return };
    let plan = crate::fast_vs_reference::mixed_plan();
    let cpu = collect(&plan, &Scheme::Fast(FastOptions::default()), 8);
    let gpu = gpu_collect(&plan, &GpuOptions::default(), 100_000);
    let mut f: Vec<f64> = Vec::new();
    let mut u: Vec<f64> = Vec::new();
    let mut imp_diff = 0;
    for ((s, c), (_, g)) in cpu.iter().zip(&gpu) {
        assert_eq!(c.status, g.status, "run {}", s.index);
        if c.impacts != g.impacts {
            imp_diff += 1;
        }
        if c.peak_force > 0.0 {
            f.push(rel(g.peak_force, c.peak_force));
        }
        u.push(rel(g.peak_u1, c.peak_u1).max(rel(g.peak_u2, c.peak_u2)));
    }
    f.sort_by(f64::total_cmp);
    u.sort_by(f64::total_cmp);
    let q = |v: &[f64], p: f64| v[((v.len() - 1) as f64 * p) as usize];
    assert_eq!(imp_diff, 0, "impact counts differ");
    assert!(
        q(&f, 1.0) < 1e-3 && q(&f, 0.5) < 1e-5,
        "peak force {:e} {:e}",
        q(&f, 1.0),
        q(&f, 0.5)
    );
    assert!(q(&u, 1.0) < 4e-4, "peak displacement {:e}", q(&u, 1.0));
    eprintln!(
        "f32: peak force median {:e} p99 {:e} max {:e}; peak u median {:e} max {:e}; impact counts differ on {imp_diff}/{}",
        q(&f, 0.5), q(&f, 0.99), q(&f, 1.0), q(&u, 0.5), q(&u, 1.0), cpu.len()
    );
}

fn csv_text(plan: &Plan, rows: &[(RunSpec, RunOutput)]) -> String {
    let mut w = csv::Writer::from_writer(Vec::new());
    for (s, o) in rows {
        w.write_record(pounding::output::row(plan, s, o)).unwrap();
    }
    String::from_utf8(w.into_inner().unwrap()).unwrap()
}

/// A sweep split into many chunks (and many dispatches per chunk) writes the same CSV as one.
#[test]
fn gpu_chunking_does_not_change_results() {
    let Some(_) = ctx() else { return };
    let plan = pounding::bench::plan(200);
    let one = gpu_collect(&plan, &GpuOptions::default(), 1 << 20);
    let small = GpuOptions {
        units_per_dispatch: 37,
        ..Default::default()
    };
    let many = gpu_collect(&plan, &small, 7);
    assert!(one.iter().any(|(_, o)| o.impacts > 0));
    crate::support::assert_same_text(
        "chunked GPU CSV",
        &csv_text(&plan, &many),
        &csv_text(&plan, &one),
    );
}
