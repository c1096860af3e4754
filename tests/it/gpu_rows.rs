//! Rows of multi-storey buildings on the GPU (`shaders/row.wgsl`) against their CPU twin
//! (`physics::solver::row::fast`) on the test device (lavapipe in CI), in f64 and f32.

use crate::scenes::models::{building, forcing, record};
use crate::support::gpu::ctx;
use crate::support::rel;
use pounding::engine::gpu::row::{run_rows, PackedRows, RowShape};
use pounding::engine::gpu::{GpuOptions, GpuRecords, Precision};
use pounding::physics::contact::LawKind;
use pounding::physics::model::Status;
use pounding::physics::row::{Row, RowOutput};
use pounding::physics::shear::{Damping, ShearBuilding, Yielding};
use pounding::physics::solver::row::fast::simulate_whole_row;
use pounding::physics::solver::row::{simulate_row, RowModel, RowScheme};
use pounding::physics::solver::FastOptions;

/// Every model on the test device, each on its own record of `records`.
pub(crate) fn on_gpu(
    models: &[RowModel],
    records: &[Vec<f64>],
    opts: &GpuOptions,
) -> Vec<Option<RowOutput>> {
    let ctx = ctx().unwrap();
    let refs: Vec<&[f64]> = records.iter().map(|r| &r[..]).collect();
    let recs = GpuRecords::upload(ctx, opts.precision, &refs).unwrap();
    let mut packed = PackedRows::new(RowShape::of(&models[0]));
    for (i, m) in models.iter().enumerate() {
        packed.push(m, &forcing(&records[i]), i, &recs, &opts.fast);
    }
    run_rows(ctx, &recs, &packed, opts).unwrap().0
}

fn on_cpu(models: &[RowModel], records: &[Vec<f64>]) -> Vec<RowOutput> {
    let scheme = RowScheme::Fast(FastOptions::default());
    models
        .iter()
        .zip(records)
        .map(|(m, r)| simulate_row(m, &forcing(r), m.at_rest(), &scheme))
        .collect()
}

/// The kernel's CPU twin step for step: every building in every substep (the CPU scheme lets
/// the buildings no contact reaches stand still).
fn on_cpu_whole_row(models: &[RowModel], records: &[Vec<f64>]) -> Vec<RowOutput> {
    models
        .iter()
        .zip(records)
        .map(|(m, r)| simulate_whole_row(m, &forcing(r), m.at_rest(), &FastOptions::default()))
        .collect()
}

/// Largest relative difference of the peaks of two results of one run (force, every level's
/// force and struck column's shear, roofs, drifts, floor accelerations).
fn peak_diff(a: &RowOutput, b: &RowOutput) -> f64 {
    let mut d = rel(a.peak_force, b.peak_force);
    for (x, y) in a.levels.iter().zip(&b.levels) {
        d = d
            .max(rel(x.peak_force, y.peak_force))
            .max(rel(x.column_shear, y.column_shear));
    }
    for (x, y) in a.buildings.iter().zip(&b.buildings) {
        d = d
            .max(rel(x.peak_roof, y.peak_roof))
            .max(rel(x.peak_drift_ratio, y.peak_drift_ratio))
            .max(rel(x.peak_accel, y.peak_accel));
    }
    d
}

/// A 2- beside a 3-storey building and a row of three small buildings, across the laws and
/// gaps: small enough for lavapipe's loop limit at a useful budget.
fn scenes() -> (Vec<RowModel>, Vec<Vec<f64>>) {
    let laws = LawKind::ALL;
    let mut models = Vec::new();
    for k in 0..5 {
        let law = laws[(2 * k) % laws.len()];
        let stiffness = if law.is_hertzian() { 2.75e9 } else { 1e9 };
        let row = Row::new(
            vec![
                building(2, 0.2 + 0.03 * k as f64, Damping::Rayleigh(0.05)),
                building(3, 0.45, Damping::Modal(0.05)),
            ],
            vec![0.003 * k as f64],
            law,
            stiffness,
            0.35,
        );
        models.push(RowModel::new(&row));
    }
    let three = Row::new(
        vec![
            building(2, 0.25, Damping::Rayleigh(0.05)),
            building(3, 0.5, Damping::Rayleigh(0.05)),
            building(2, 0.2, Damping::Modal(0.03)),
        ],
        vec![0.004, 0.002],
        LawKind::NonlinearViscoelastic,
        2.75e9,
        0.35,
    );
    let records = (0..6).map(|s| record(60 + s, 4.0, 0.45)).collect();
    ([models, vec![RowModel::new(&three)]].concat(), records)
}

/// f64 on the device is the CPU twin's arithmetic (every building in every substep): the same
/// impacts and substeps, peaks to rounding. f32 keeps the peaks within 1e-3 where the impact sequence is the same.
#[test]
fn row_kernel_matches_the_cpu_twin() {
    if ctx().is_none() {
        return;
    }
    let (models, records) = scenes();
    let (two, three): (Vec<_>, Vec<_>) = models
        .iter()
        .zip(&records)
        .partition(|(m, _)| RowShape::of(m).storeys.len() == 2);
    for group in [two, three] {
        let models: Vec<RowModel> = group.iter().map(|(m, _)| (*m).clone()).collect();
        let records: Vec<Vec<f64>> = group.iter().map(|(_, r)| (*r).clone()).collect();
        let cpu = on_cpu_whole_row(&models, &records);
        assert!(cpu.iter().filter(|o| o.impacts > 0).count() >= models.len().min(3));
        // Measured on lavapipe, f64: 1e-14 to 1e-11 beside two buildings; 3.1e-6 in the row
        // of three (44 impacts), whose events the kernel locates in time local to the record
        // step (the CPU in absolute time): 1e-9 s apart at first, grown through the impact
        // sequence. f32: up to 4e-5.
        assert_gpu_is_the_twin(&models, &records, &cpu, 1e-5, 0);
    }
}

/// `models` on the device against `cpu`, their CPU twin's outputs: f64 gives its impacts,
/// substeps, storeys of peak drift and floors of peak acceleration, and its peaks within
/// `f64_peaks`; f32 its peaks within 1e-3 where the impacts are the same.
fn assert_gpu_is_the_twin(
    models: &[RowModel],
    records: &[Vec<f64>],
    cpu: &[RowOutput],
    f64_peaks: f64,
    substep_slack: u64,
) {
    for precision in [Precision::F64, Precision::F32] {
        let opts = GpuOptions {
            precision,
            ..GpuOptions::default()
        };
        let gpu = on_gpu(models, records, &opts);
        for (k, (g, c)) in gpu.iter().zip(cpu).enumerate() {
            let g = g.as_ref().expect("not handed back");
            let d = peak_diff(g, c);
            assert_eq!(g.status, Status::Ok, "{precision:?} run {k}");
            if precision == Precision::F64 {
                assert_eq!(g.impacts, c.impacts, "run {k}");
                assert!(
                    g.substeps.abs_diff(c.substeps) <= substep_slack,
                    "run {k}: {} substeps, the CPU's {}",
                    g.substeps,
                    c.substeps
                );
                eprintln!("f64 run {k}: peaks {d:.1e} apart");
                assert!(d < f64_peaks, "f64 run {k}: {d:e}\n{g:?}\n{c:?}");
                let places = |o: &RowOutput| {
                    (o.buildings.iter())
                        .map(|b| (b.drift_storey, b.accel_floor))
                        .collect::<Vec<_>>()
                };
                assert_eq!(places(g), places(c), "run {k}");
            } else if g.impacts == c.impacts {
                assert!(d < 1e-3, "f32 run {k}: {d:e}");
            }
        }
    }
}

/// Two 12-storey buildings (refused on lavapipe before a unit of work was one RK4 step): f64
/// on the device gives the CPU twin's impacts, substeps and places of its peaks, and the peaks
/// within 1e-6; f32 within 1e-3 where its impacts are the CPU's.
#[test]
fn a_twelve_storey_pair_on_the_gpu_is_the_cpu_twin() {
    if ctx().is_none() {
        return;
    }
    let models: Vec<RowModel> = [0.0, 0.004]
        .iter()
        .map(|&gap| {
            RowModel::new(&Row::new(
                vec![
                    building(12, 1.2, Damping::Rayleigh(0.05)),
                    building(12, 0.9, Damping::Modal(0.05)),
                ],
                vec![gap],
                LawKind::LankaraniNikravesh,
                2.75e9,
                0.35,
            ))
        })
        .collect();
    let records: Vec<Vec<f64>> = (0..2).map(|s| record(70 + s, 2.0, 0.6)).collect();
    let cpu = on_cpu_whole_row(&models, &records);
    assert!(cpu.iter().all(|c| c.impacts > 0), "{cpu:?}");
    assert_gpu_is_the_twin(&models, &records, &cpu, 1e-6, 0);
}

/// A dispatch of one unit per run gives what a dispatch of many gives: the kernel's state
/// carries everything between dispatches.
#[test]
fn row_kernel_resumes_between_dispatches() {
    if ctx().is_none() {
        return;
    }
    let (models, records) = scenes();
    let (models, records) = (&models[1..3], &records[1..3]);
    let run = |units: u32| {
        on_gpu(
            models,
            records,
            &GpuOptions {
                precision: Precision::F64,
                units_per_dispatch: units,
                ..GpuOptions::default()
            },
        )
    };
    assert_eq!(run(1), run(4096));
}

/// With a hand-off above one substep per record step, every run that needs substeps comes back
/// to the host (None) and the others finish on the device.
#[test]
fn row_kernel_hands_back_runs_past_its_substep_limit() {
    if ctx().is_none() {
        return;
    }
    let (models, records) = scenes();
    let cpu = on_cpu(&models[..3], &records[..3]);
    let opts = GpuOptions {
        precision: Precision::F32,
        handoff_substeps_per_step: Some(1),
        ..GpuOptions::default()
    };
    let gpu = on_gpu(&models[..3], &records[..3], &opts);
    for (g, c) in gpu.iter().zip(&cpu) {
        assert_eq!(g.is_none(), c.substeps > 0, "{c:?}");
    }
    assert!(gpu.iter().any(|g| g.is_none()));
}

/// On a software adapter a row whose unit of work could run past lavapipe's loop limit (which
/// silently ends loops) is refused with a clear error instead of wrong results.
#[test]
fn rows_too_large_for_the_software_loop_limit_are_refused() {
    let Some(ctx) = ctx() else { return };
    if !ctx.is_software() {
        return;
    }
    let row = Row::new(
        vec![
            building(30, 3.0, Damping::Rayleigh(0.05)),
            building(30, 2.7, Damping::Rayleigh(0.05)),
        ],
        vec![0.01],
        LawKind::Linear,
        1e9,
        0.0,
    );
    let accel = record(1, 1.0, 0.3);
    let recs = GpuRecords::upload(ctx, Precision::F32, &[&accel[..]]).unwrap();
    let m = RowModel::new(&row);
    let mut packed = PackedRows::new(RowShape::of(&m));
    packed.push(&m, &forcing(&accel), 0, &recs, &FastOptions::default());
    let err = run_rows(ctx, &recs, &packed, &GpuOptions::default()).unwrap_err();
    assert!(err.to_string().contains("loop limit"), "{err}");
}

/// Every shipped row config runs on the software adapter as on the CPU: a unit of work is one
/// RK4 step (or a record step's start) and the tracking all units share, so its loop trips,
/// summed over the branches a lockstep group of lanes runs, stay under lavapipe's loop limit
/// even for `row-of-five.toml` (five buildings, 48 storeys, 28 contact levels; before the event
/// search was resumable ten of them were refused). The first run of each, `pound sweep CONFIG
/// --shard 0/RUNS` with `--backend gpu --precision f64` against `--backend cpu`: the same
/// columns, labels and impacts, substeps at most 2 apart (the kernel's event times, local to
/// the record step, differ from the CPU's in the last bits), every other number within 1e-4
/// relative or 1e-9 absolute (measured: 1.9e-5 at most, BENCHMARKS.md, "Rows on lavapipe").
/// Both ways of writing the kernel's per-shape functions run among them (written out: row-3-6;
/// loops: row-of-five).
#[test]
fn shipped_row_configs_run_on_the_software_adapter_as_on_the_cpu() {
    let Some(ctx) = ctx() else { return };
    if !ctx.is_software() {
        return;
    }
    let mut configs: Vec<_> = std::fs::read_dir("configs")
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    configs.sort();
    let dir = crate::support::tempdir();
    let (mut rows, mut refused, mut unrolled) = (0, Vec::new(), [false; 2]);
    for cfg in configs {
        let plan = pounding::plan::config::load(&cfg).unwrap();
        let pounding::plan::Plan::Row(plan) = plan else {
            continue;
        };
        rows += 1;
        let name = cfg.file_stem().unwrap().to_string_lossy().into_owned();
        // IMK storeys run on the GPU in f64 only (their twin is checked in gpu_imk): the default
        // f32 is refused.
        if std::fs::read_to_string(&cfg)
            .unwrap()
            .contains("hysteresis = \"imk_")
        {
            let out = dir.path().join(format!("{name}.csv"));
            let (cfg, out) = (cfg.to_str().unwrap(), out.to_str().unwrap());
            let o = crate::support::pound(&["sweep", cfg, "--backend", "gpu", "-o", out]);
            let says = String::from_utf8_lossy(&o.stderr);
            assert!(
                !o.status.success() && says.contains("in f64 only"),
                "{name}: {says}"
            );
            continue;
        }
        if let Err(e) = pounding::engine::gpu::row::check_fits(ctx, &plan) {
            assert!(e.to_string().contains("loop limit"), "{e}");
            refused.push(name);
            continue;
        }
        let shape = RowShape::of_plan(&plan);
        unrolled[shape.unrolled() as usize] = true;
        let shard = format!("0/{}", plan.len());
        let csv = |backend: &str| {
            let out = dir.path().join(format!("{name}-{backend}.csv"));
            let mut args = vec!["sweep", cfg.to_str().unwrap(), "-o", out.to_str().unwrap()];
            args.extend_from_slice(&["--backend", backend, "--shard", &shard]);
            if backend == "gpu" {
                args.extend_from_slice(&["--precision", "f64"]);
            }
            crate::support::run::ok(&crate::support::pound(&args));
            std::fs::read_to_string(&out).unwrap()
        };
        let (cpu, gpu) = (csv("cpu"), csv("gpu"));
        let (cpu, gpu): (Vec<&str>, Vec<&str>) = (cpu.lines().collect(), gpu.lines().collect());
        assert_eq!(cpu.len(), 2, "{name}: one run");
        assert_eq!(cpu[0], gpu[0], "{name}: columns");
        for ((col, x), y) in cpu[0]
            .split(',')
            .zip(cpu[1].split(','))
            .zip(gpu[1].split(','))
        {
            match (x.parse::<f64>(), y.parse::<f64>()) {
                _ if col.contains("impacts") => assert_eq!(x, y, "{name} {col}"),
                (Ok(u), Ok(v)) if col == "substeps" => {
                    assert!((u - v).abs() <= 2.0, "{name} {col}: {x} vs {y}")
                }
                (Ok(u), Ok(v)) => assert!(
                    (u - v).abs() <= 1e-4 * u.abs().max(v.abs()) + 1e-9,
                    "{name} {col}: {x} vs {y}"
                ),
                _ => assert_eq!(x, y, "{name} {col}"),
            }
        }
    }
    assert!(rows >= 12, "{rows} row configs");
    assert!(
        refused.is_empty(),
        "refused on the software adapter: {refused:?}"
    );
    assert_eq!(unrolled, [true, true], "written out and loops both ran");
}

/// The row kernel's source parses and validates (naga, f32 and f64) for shapes from single
/// storeys to a row of five and a row with no common floor level, elastic and yielding, with
/// the per-shape functions written out and as loops: the
/// constants the host prepends make a complete module for every shape (P-Delta buildings whose
/// damping couples their modes among them).
#[test]
fn row_kernel_builds_for_every_shape() {
    use pounding::engine::gpu::shader::row_source;
    let shapes = [
        RowShape::elastic(vec![1, 1], vec![[0, 0, 0]]),
        RowShape::elastic(vec![3, 6], vec![[0, 0, 0], [0, 1, 1], [0, 2, 2]]),
        RowShape::elastic(vec![20, 2], vec![[0, 0, 0], [0, 1, 1]]),
        RowShape::elastic(
            vec![3, 5, 2],
            vec![[0, 0, 0], [0, 1, 1], [0, 2, 2], [1, 0, 0], [1, 1, 1]],
        ),
        RowShape::elastic(vec![3, 3], vec![]),
        RowShape {
            storeys: vec![1, 1],
            levels: vec![[0, 0, 0]],
            yielding: vec![true, true],
            imk: vec![false; 2],
            coupled: vec![false, false],
            columns: vec![],
        },
        RowShape {
            storeys: vec![3, 6, 2],
            levels: vec![[0, 0, 0], [0, 1, 1], [0, 2, 2], [1, 0, 0], [1, 1, 1]],
            yielding: vec![false, true, true],
            imk: vec![false; 3],
            coupled: vec![false, false, false],
            columns: vec![],
        },
        // P-Delta buildings whose damping may couple their modes, elastic and yielding.
        RowShape {
            storeys: vec![3, 6, 2],
            levels: vec![[0, 0, 0], [0, 1, 1], [0, 2, 2], [1, 0, 0], [1, 1, 1]],
            yielding: vec![false, true, false],
            imk: vec![false; 3],
            coupled: vec![true, true, false],
            columns: vec![],
        },
        // Too tall to write out: the loops of row_loops.wgsl, yielding and coupled.
        RowShape {
            storeys: vec![9, 4],
            levels: vec![[0, 0, 0], [0, 1, 1], [0, 2, 2], [0, 3, 3]],
            yielding: vec![true, true],
            imk: vec![false; 2],
            coupled: vec![true, false],
            columns: vec![],
        },
        // Floors that strike columns, written out and as loops (one in a first storey, whose
        // column shares its point with the ground).
        RowShape {
            storeys: vec![3, 4],
            levels: vec![[0, 0, 0], [0, 0, 1], [0, 1, 1], [0, 1, 2]],
            yielding: vec![false, true],
            imk: vec![false; 2],
            coupled: vec![false, false],
            columns: vec![
                (0, 0, 0.9f64.to_bits()),
                (1, 1, 0.07f64.to_bits()),
                (3, 1, 0.5f64.to_bits()),
            ],
        },
        RowShape {
            storeys: vec![9, 4],
            levels: vec![[0, 0, 0], [0, 0, 1], [0, 1, 1]],
            yielding: vec![true, false],
            imk: vec![false; 2],
            coupled: vec![false, false],
            columns: vec![(0, 0, 0.9f64.to_bits()), (1, 1, 0.07f64.to_bits())],
        },
        // IMK storeys (shaders/imk.wgsl): beside a bilinear one, written out and as loops with
        // coupled modes.
        RowShape {
            storeys: vec![1, 1],
            levels: vec![[0, 0, 0]],
            yielding: vec![true, true],
            imk: vec![true, false],
            coupled: vec![false, false],
            columns: vec![],
        },
        RowShape {
            storeys: vec![9, 4],
            levels: vec![[0, 0, 0], [0, 1, 1], [0, 2, 2], [0, 3, 3]],
            yielding: vec![true, true],
            imk: vec![true, true],
            coupled: vec![true, false],
            columns: vec![(0, 0, 0.9f64.to_bits())],
        },
    ];
    // Both ways of writing the per-shape functions are among them.
    assert!(shapes.iter().any(|s| s.unrolled()) && shapes.iter().any(|s| !s.unrolled()));
    for shape in &shapes {
        for precision in [Precision::F32, Precision::F64] {
            let src = row_source(precision, &shape.wgsl_constants(), shape.has_imk());
            crate::gpu::parse_source(&src);
        }
    }
}

/// `pound sweep --backend gpu` on a row config writes the CPU's CSV: the same columns and
/// labels, every number within 1e-6 in f64 (energy columns aside: rows on the GPU do not
/// integrate the balance), and says where it ran in the sidecar.
#[test]
fn row_sweep_on_the_gpu_writes_the_cpu_csv() {
    if ctx().is_none() {
        return;
    }
    let dir = crate::support::tempdir();
    let cfg = dir.path().join("row.toml");
    std::fs::write(
        &cfg,
        r#"[[building]]
storeys = 2
storey_height_m = 3.0
mass_kg = 3.0e5
period_s = [0.2, 0.3]
damping_ratio = 0.05

[[building]]
storeys = 3
storey_height_m = 3.0
mass_kg = 3.0e5
period_s = 0.5
damping_ratio = 0.05
damping = "modal"

[contact]
law = "lankarani_nikravesh"
formula = "khatami"
e = 0.6
beta_n_per_m1_5 = 2.75e9
gap_m = [0.0, 0.005, 0.02]

[[record]]
synthetic = { seed = 9, duration_s = 3.0, dt_s = 0.01, pga_g = 0.5 }
"#,
    )
    .unwrap();
    let csv = |backend: &str| {
        let out = dir.path().join(format!("{backend}.csv"));
        let mut args = vec!["sweep", cfg.to_str().unwrap(), "-o", out.to_str().unwrap()];
        args.extend_from_slice(&["--backend", backend, "--precision", "f64"]);
        crate::support::run::ok(&crate::support::pound(&args));
        (std::fs::read_to_string(&out).unwrap(), out)
    };
    let (cpu, _) = csv("cpu");
    let (gpu, gpu_path) = csv("gpu");
    let (cpu, gpu): (Vec<&str>, Vec<&str>) = (cpu.lines().collect(), gpu.lines().collect());
    assert_eq!(cpu.len(), 7);
    assert_eq!(cpu[0], gpu[0]);
    let mut pounded = 0;
    for (a, b) in cpu[1..].iter().zip(&gpu[1..]) {
        for (x, y) in a.split(',').zip(b.split(',')) {
            match (x.parse::<f64>(), y.parse::<f64>()) {
                (Ok(u), Ok(v)) => assert!(rel(u, v) < 1e-6, "{x} vs {y}\n{a}\n{b}"),
                _ => assert_eq!(x, y),
            }
        }
        pounded += (a
            .split(',')
            .nth(cpu[0].split(',').position(|c| c == "impacts").unwrap())
            != Some("0")) as usize;
    }
    assert!(pounded >= 2);
    let meta = std::fs::read_to_string(pounding::io::provenance::meta_path(&gpu_path)).unwrap();
    assert!(meta.contains("backend = \"gpu-f64\""), "{meta}");
}

/// N = 1 on the GPU: the row kernel in f64 on single-storey rows takes the pair fast scheme's
/// steps (the same impacts and substeps) and reports its peaks within 1e-6. Measured on
/// lavapipe: 4.9e-8 (nonlinear viscoelastic, 14 impacts), where the kernel's events, located in
/// time local to the record step, start 1e-9 s from the CPU's.
#[test]
fn single_storey_rows_on_the_gpu_are_the_pair() {
    if ctx().is_none() {
        return;
    }
    let scenes = crate::scenes::models::single_storey_scenes();
    let accel = record(3, 10.0, 0.4);
    let models: Vec<RowModel> = scenes.iter().map(|(_, m)| m.clone()).collect();
    let records = vec![accel.clone(); models.len()];
    let opts = GpuOptions {
        precision: Precision::F64,
        ..GpuOptions::default()
    };
    let rows: Vec<RowOutput> = on_gpu(&models, &records, &opts)
        .into_iter()
        .map(|o| o.expect("not handed back"))
        .collect();
    crate::multistorey::assert_rows_are_the_pair_fast("gpu f64", &scenes, &rows, &accel, 1e-6);
}

/// `building` with storeys that yield at drift ratio `theta` (post-yield ratio `b`).
fn yielding(n: usize, period: f64, damping: Damping, theta: f64, b: f64) -> ShearBuilding {
    let mut s = building(n, period, damping);
    s.yielding = Some(Yielding::from_drift_ratio(
        &s.stiffness,
        &s.heights,
        &vec![theta; n],
        vec![b; n],
    ));
    s
}

/// A yielding 3-storey P-Delta frame whose Rayleigh damping couples its modes.
fn leaning_frame() -> ShearBuilding {
    let b = yielding(3, 0.6, Damping::Rayleigh(0.05), 0.003, 0.03).with_p_delta(4.0);
    assert!(
        b.modes().coupling.is_some(),
        "the damping couples the modes"
    );
    b
}

/// Yielding storeys, rows of two (lavapipe's loop limit keeps them small): single storeys
/// pounding (elastic-perfectly-plastic beside hardening), a yielding 3-storey frame beside an
/// elastic 2-storey one, two yielding frames at gap 0, and a yielding P-Delta frame; each on
/// its own record.
fn yielding_scenes() -> (Vec<Vec<RowModel>>, Vec<Vec<f64>>) {
    let row = |a: ShearBuilding, b: ShearBuilding, gap: f64, law: LawKind| {
        let stiffness = if law.is_hertzian() { 2.75e9 } else { 1e9 };
        RowModel::new(&Row::new(vec![a, b], vec![gap], law, stiffness, 0.35))
    };
    let groups = vec![
        vec![
            row(
                yielding(1, 0.6, Damping::Modal(0.05), 0.004, 0.0),
                yielding(1, 0.3, Damping::Modal(0.05), 0.003, 0.05),
                0.01,
                LawKind::NonlinearViscoelastic,
            ),
            row(
                yielding(1, 0.5, Damping::Modal(0.05), 0.002, 0.02),
                yielding(1, 0.25, Damping::Modal(0.03), 0.002, 0.1),
                0.0,
                LawKind::KelvinVoigt,
            ),
        ],
        vec![row(
            yielding(3, 0.5, Damping::Rayleigh(0.05), 0.003, 0.03),
            building(2, 0.2, Damping::Modal(0.05)),
            0.005,
            LawKind::Hertz,
        )],
        // P-Delta: gravity (four times the floors' weight, as a leaning column carries) leans
        // on two yielding frames, which settle about the static drifts it holds; the first's
        // Rayleigh damping on K0 couples its modes (its storeys lean unequally).
        vec![row(
            leaning_frame(),
            yielding(2, 0.3, Damping::Modal(0.05), 0.003, 0.05).with_p_delta(4.0),
            0.004,
            LawKind::Hertz,
        )],
    ];
    let records = (0..4).map(|s| record(80 + s, 3.0, 0.8)).collect();
    (groups, records)
}

/// Yielding storeys on the GPU against the kernel's CPU twin: in f64 the same impacts and
/// substeps, peaks and the yielding outputs (residual drift, ductility, hysteretic energy,
/// storeys yielded) to the twin's agreement on elastic rows; every run yields and settles. In
/// f32 the peaks and ductility within 1e-3 where the impact sequence is the same.
#[test]
fn row_kernel_yields_as_the_cpu_twin() {
    if ctx().is_none() {
        return;
    }
    let (groups, records) = yielding_scenes();
    let mut k = 0;
    for models in groups {
        let records: Vec<Vec<f64>> = records[k..k + models.len()].to_vec();
        k += models.len();
        let cpu = on_cpu_whole_row(&models, &records);
        for precision in [Precision::F64, Precision::F32] {
            let opts = GpuOptions {
                precision,
                ..GpuOptions::default()
            };
            let gpu = on_gpu(&models, &records, &opts);
            for (r, (g, c)) in gpu.iter().zip(&cpu).enumerate() {
                let g = g.as_ref().expect("not handed back");
                assert_eq!(g.status, Status::Ok, "{precision:?} run {r}");
                assert!(c.impacts > 0, "run {r} pounds");
                let mut d = peak_diff(g, c);
                let mut yielded = 0;
                for (x, y) in g.buildings.iter().zip(&c.buildings) {
                    assert_eq!(x.inelastic.is_some(), y.inelastic.is_some());
                    let (Some(a), Some(b)) = (x.inelastic, y.inelastic) else {
                        continue;
                    };
                    assert!(
                        b.residual_drift_ratio.is_finite(),
                        "run {r} settles on the CPU"
                    );
                    yielded += b.yielded_storeys;
                    d = d.max(rel(a.peak_ductility, b.peak_ductility));
                    if precision == Precision::F64 {
                        assert_eq!(a.yielded_storeys, b.yielded_storeys, "run {r}");
                        // A residual of a storey that barely yielded, against the peak drift.
                        let scale = b.residual_drift_ratio.abs().max(1e-2 * y.peak_drift_ratio);
                        d = d.max((a.residual_drift_ratio - b.residual_drift_ratio).abs() / scale);
                        d = d.max(rel(a.hysteretic_energy, b.hysteretic_energy));
                    }
                }
                assert!(yielded > 0, "run {r} yields");
                eprintln!(
                    "{precision:?} run {r}: {d:.1e} ({} impacts, {yielded} storeys yielded)",
                    c.impacts
                );
                if precision == Precision::F64 {
                    // The same steps, but for a few pieces: a storey's event located within
                    // rounding of a substep's end (the kernel in time local to the record
                    // step, the CPU in absolute time) ends the substep on one side and leaves
                    // a piece of 1e-9 of it on the other (measured on lavapipe: 19 of 6,535
                    // at gap 0, with peaks within 1.7e-11).
                    assert_eq!(
                        (g.impacts, g.free_steps),
                        (c.impacts, c.free_steps),
                        "run {r}"
                    );
                    assert!(
                        g.substeps.abs_diff(c.substeps) * 100 <= c.substeps,
                        "run {r}"
                    );
                    assert!(d < 1e-5, "f64 run {r}: {d:e}\n{g:?}\n{c:?}");
                } else if g.impacts == c.impacts {
                    assert!(d < 1e-3, "f32 run {r}: {d:e}");
                }
            }
        }
    }
}

/// Floors that strike columns (issue 50) on the device: a 3-storey of 3.5 m storeys beside a
/// 4-storey of 3 m storeys (every level floor against column; written out), elastic and
/// yielding, at two gaps, a 9-storey of 3.2 m storeys beside it (the loops), and floors 1.5 cm
/// apart (points sharing the contact's stiffness, which each level reads), and four floors on
/// one 13 m storey's columns (their shear summing the four forces): f64 gives the CPU twin's
/// impacts, substeps and peaks (the struck columns' shear among them).
#[test]
fn floors_that_strike_columns_on_the_gpu_are_the_cpu_twin() {
    if ctx().is_none() {
        return;
    }
    let frame = |n: usize, h: f64, period: f64| {
        ShearBuilding::from_period(
            vec![2.5e5; n],
            &vec![1.0; n],
            vec![h; n],
            period,
            Damping::Modal(0.05),
        )
    };
    let yielding = |mut b: ShearBuilding| {
        let n = b.storeys();
        b.yielding = Some(Yielding::from_drift_ratio(
            &b.stiffness,
            &b.heights,
            &vec![0.005; n],
            vec![0.05; n],
        ));
        b
    };
    let row = |left: ShearBuilding, right: ShearBuilding, gap: f64| {
        RowModel::new(&Row::new(
            vec![left, right],
            vec![gap],
            LawKind::NonlinearViscoelastic,
            2.75e9,
            0.35,
        ))
    };
    for (left, right) in [
        (frame(3, 3.5, 0.45), frame(4, 3.0, 0.55)),
        (frame(3, 3.5, 0.45), yielding(frame(4, 3.0, 0.55))),
        (frame(9, 3.2, 0.9), frame(4, 3.0, 0.55)),
        // Floors 1.5 cm apart: two points, each with a share of the contact's stiffness.
        (frame(3, 3.0, 0.45), frame(3, 3.015, 0.35)),
        // Four floors on one 13 m storey's columns: its shear sums their forces.
        (
            frame(4, 3.0, 0.5),
            ShearBuilding::from_period(
                vec![2.5e5; 2],
                &[1.0; 2],
                vec![13.0, 3.0],
                0.7,
                Damping::Modal(0.05),
            ),
        ),
    ] {
        let models: Vec<RowModel> = [0.0, 0.004]
            .iter()
            .map(|&gap| row(left.clone(), right.clone(), gap))
            .collect();
        let shape = RowShape::of(&models[0]);
        assert!(!shape.columns.is_empty());
        let records: Vec<Vec<f64>> = (0..2).map(|s| record(80 + s, 3.0, 0.5)).collect();
        let cpu = on_cpu_whole_row(&models, &records);
        assert!(
            cpu.iter()
                .all(|c| c.levels.iter().any(|l| l.column_shear > 0.0)),
            "a floor strikes a column: {cpu:?}"
        );
        // The CPU's free steps read a column's point from its floors (`w u_j + (1 - w)
        // u_(j-1)`), the kernel from its row of mode shapes (the same motion, rounded
        // differently): a check of a free step that rounds the other way takes a piece more
        // or less.
        assert_gpu_is_the_twin(&models, &records, &cpu, 1e-6, 4);
    }
}
