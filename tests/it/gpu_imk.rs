//! Deteriorating (IMK) storeys in the GPU row kernel (issue 67): its f64 twin of the CPU's fast
//! scheme, what f32 gives, and every run's convergence with the substeps on the test device.

use crate::convergence::{fast, judge, truths, Scene, SETTINGS};
use crate::support::gpu::ctx;
use pounding::engine::gpu::row::{run_rows, PackedRows, RowShape};
use pounding::engine::gpu::shader::row_source;
use pounding::engine::gpu::{GpuOptions, GpuRecords, Precision};
use pounding::physics::model::Status;
use pounding::physics::row::RowOutput;
use pounding::physics::solver::row::fast::simulate_whole_row;

/// Every shipped config's row kernel source (both precisions), for the check that a kernel
/// without IMK storeys is written as before: into `$POUND_WGSL_DUMP` where set (`diff -r`
/// two dumps); each such kernel carries no IMK code.
#[test]
fn kernels_without_imk_storeys_carry_no_imk_code() {
    let mut configs: Vec<_> = std::fs::read_dir("configs")
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    configs.sort();
    let dump = std::env::var_os("POUND_WGSL_DUMP").map(std::path::PathBuf::from);
    let mut rows = 0;
    for cfg in configs {
        let Ok(pounding::plan::Plan::Row(plan)) = pounding::plan::config::load(&cfg) else {
            continue;
        };
        if plan.is_empty() {
            continue;
        }
        rows += 1;
        let shape = RowShape::of_plan(&plan);
        let name = cfg.file_stem().unwrap().to_string_lossy().into_owned();
        for p in [Precision::F64, Precision::F32] {
            let src = row_source(p, &shape.wgsl_constants(), shape.has_imk());
            // A shape with IMK storeys (configs/collapse-imk.toml) carries the code, the others
            // none of it.
            assert_eq!(
                src.contains("imk_"),
                shape.has_imk(),
                "{name}: IMK code where the kernel has IMK storeys, and only there"
            );
            if let Some(dir) = &dump {
                std::fs::create_dir_all(dir).unwrap();
                std::fs::write(dir.join(format!("{name}-{p:?}.wgsl")), src).unwrap();
            }
        }
    }
    assert!(rows > 3, "{rows} row configs");
}

/// The IMK scenes of `imk` that the test device runs: rows of low buildings (within lavapipe's
/// loop limit).
fn low_scenes() -> Vec<Scene> {
    (crate::imk::scenes().into_iter())
        .filter(|sc| RowShape::of(&sc.model).storeys.iter().all(|&n| n <= 3))
        .collect()
}

/// Scene `sc` on the test device, or None where the kernel handed it back (a collapse).
fn on_gpu(sc: &Scene, opts: &GpuOptions) -> Option<RowOutput> {
    let ctx = ctx().unwrap();
    let recs = GpuRecords::upload(ctx, opts.precision, &[&sc.accel[..]]).unwrap();
    let mut packed = PackedRows::new(RowShape::of(&sc.model));
    packed.push(&sc.model, &sc.forcing(), 0, &recs, &opts.fast);
    run_rows(ctx, &recs, &packed, opts)
        .unwrap()
        .0
        .pop()
        .flatten()
}

/// The largest difference of two results of one run over every output but the residual drifts
/// (relative to the larger magnitude), and the name of the output where it is; and the largest
/// residual drift difference, over the peak drift.
fn largest_difference(a: &RowOutput, b: &RowOutput) -> (f64, String, f64) {
    let mut worst = (0.0, String::new());
    let mut diff = |name: String, x: f64, y: f64, scale: f64| {
        // Both NaN: neither reports the value (a run that did not settle has no residual).
        let d = if x == y || (x.is_nan() && y.is_nan()) {
            0.0
        } else {
            (x - y).abs() / x.abs().max(y.abs()).max(scale)
        };
        // A NaN difference (one side NaN) is the worst.
        if d > worst.0 || d.is_nan() {
            worst = (d, name);
        }
    };
    diff("peak force".into(), a.peak_force, b.peak_force, 0.0);
    for (l, (x, y)) in a.levels.iter().zip(&b.levels).enumerate() {
        diff(format!("level {l} force"), x.peak_force, y.peak_force, 0.0);
        diff(
            format!("level {l} impacts"),
            x.impacts as f64,
            y.impacts as f64,
            0.0,
        );
    }
    let mut drift: f64 = 0.0;
    for (k, (x, y)) in a.buildings.iter().zip(&b.buildings).enumerate() {
        diff(format!("building {k} roof"), x.peak_roof, y.peak_roof, 0.0);
        diff(
            format!("building {k} drift"),
            x.peak_drift_ratio,
            y.peak_drift_ratio,
            0.0,
        );
        diff(
            format!("building {k} accel"),
            x.peak_accel,
            y.peak_accel,
            0.0,
        );
        drift = drift.max(x.peak_drift_ratio);
    }
    assert_eq!(a.storeys.len(), b.storeys.len());
    let mut residual: f64 = 0.0;
    for (s, (x, y)) in a.storeys.iter().zip(&b.storeys).enumerate() {
        let at = |what: &str| format!("storey {s} {what}");
        let (u, v) = (x.residual_drift_ratio, y.residual_drift_ratio);
        if u.is_nan() != v.is_nan() {
            residual = f64::INFINITY;
        } else if !u.is_nan() {
            residual = residual.max((u - v).abs() / drift);
        }
        diff(at("ductility"), x.peak_ductility, y.peak_ductility, 0.0);
        diff(at("energy"), x.hysteretic_energy, y.hysteretic_energy, 0.0);
        if !(x.strength_ratio.is_nan() && y.strength_ratio.is_nan()) {
            diff(at("strength"), x.strength_ratio, y.strength_ratio, 0.0);
        }
        diff(
            at("capped"),
            x.capped as u8 as f64,
            y.capped as u8 as f64,
            0.0,
        );
        diff(
            at("yielded"),
            x.yielded as u8 as f64,
            y.yielded as u8 as f64,
            0.0,
        );
    }
    (worst.0, worst.1, residual)
}

/// The kernel in f64 is the CPU fast scheme's twin on IMK scenes (both rules, with and without
/// the energy rule, contact, past capping, onto the residual plateau, P-Delta up to collapse):
/// every output within 1e-9 of the whole-row CPU path's at the same setting; in f32, the
/// differences are printed (`--nocapture`).
#[test]
fn the_kernel_is_the_cpus_twin_on_imk_storeys() {
    if ctx().is_none() {
        return;
    }
    let scenes = low_scenes();
    assert!(scenes.len() >= 4, "{} scenes", scenes.len());
    let names: Vec<&str> = scenes.iter().map(|sc| sc.name).collect();
    for s in [16.0, 64.0] {
        for sc in &scenes {
            let cpu = simulate_whole_row(&sc.model, &sc.forcing(), sc.model.at_rest(), &fast(s));
            let collapsed = cpu.buildings.iter().any(|b| b.collapse.is_some());
            for precision in [Precision::F64, Precision::F32] {
                let opts = GpuOptions {
                    precision,
                    fast: fast(s),
                    ..GpuOptions::default()
                };
                let Some(gpu) = on_gpu(sc, &opts) else {
                    assert!(
                        collapsed,
                        "{}: handed back at {s} in {precision:?}",
                        sc.name
                    );
                    continue;
                };
                assert_eq!(gpu.status, Status::Ok, "{}", sc.name);
                let (d, at, residual) = largest_difference(&gpu, &cpu);
                eprintln!(
                    "{precision:?} {s:>4} {}: {d:.2e} ({at}), residual drifts {residual:.2e}",
                    sc.name
                );
                if precision == Precision::F64 {
                    assert!(d <= 1e-9, "{} at {s}: {d:e} at {at}", sc.name);
                    // A peak-oriented storey's rest point is taken once its reach is below 1e-4
                    // of its yield drift (`ImkSpring::rest_reach`): the two may settle a step
                    // apart, the residual then differing by the motion of that step.
                    assert!(
                        residual <= 1e-6,
                        "{} at {s}: residual drifts {residual:e}",
                        sc.name
                    );
                    // The same substeps, but for a settling tail a step longer or shorter.
                    let apart = gpu.substeps.abs_diff(cpu.substeps) as f64;
                    assert!(
                        apart <= 1e-3 * cpu.substeps as f64,
                        "{}: {} substeps, the CPU {}",
                        sc.name,
                        gpu.substeps,
                        cpu.substeps
                    );
                }
            }
        }
    }
    eprintln!("{names:?}");
}

/// Every IMK run on the test device converges with the substeps (8 to 512), run by run, as the
/// CPU paths do (`imk::every_imk_run_converges_on_the_cpu_paths`).
#[test]
fn every_imk_run_converges_on_the_gpu() {
    if ctx().is_none() {
        return;
    }
    let all: Vec<Scene> = low_scenes()
        .into_iter()
        .filter(|sc| !sc.collapses)
        .collect();
    let scenes: Vec<&Scene> = all.iter().collect();
    let truth = truths(&scenes);
    let outs: Vec<Vec<RowOutput>> = SETTINGS
        .iter()
        .map(|&s| {
            let opts = GpuOptions {
                precision: Precision::F64,
                fast: fast(s),
                ..GpuOptions::default()
            };
            (scenes.iter())
                .map(|sc| on_gpu(sc, &opts).expect("not handed back"))
                .collect()
        })
        .collect();
    let bad = judge("gpu f64", &scenes, &truth, &outs);
    assert!(bad.is_empty(), "{}", bad.join("\n"));
}
