//! GPU path: shader layout against the Rust structs, GPU against the CPU twin.

use pounding::engine::gpu::layout::{self, Layout};
use pounding::engine::gpu::shader::{aggregate_source, fast_source};
use pounding::engine::gpu::Precision;

fn parse(precision: Precision) -> naga::Module {
    parse_source(&fast_source(precision, true, true))
}

pub fn parse_source(src: &str) -> naga::Module {
    let module =
        naga::front::wgsl::parse_str(src).unwrap_or_else(|e| panic!("{}", e.emit_to_string(src)));
    let mut v = naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::FLOAT64,
    );
    if let Err(e) = v.validate(&module) {
        panic!("{}", e.emit_to_string(src));
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
    // The aggregation stage shares types.wgsl and has its own two structs.
    for p in [Precision::F64, Precision::F32] {
        let m = parse_source(&aggregate_source(p));
        check::<layout::AggConfig>(&m, size_of::<layout::AggConfig>());
        check::<layout::Segment>(&m, size_of::<layout::Segment>());
        check::<layout::Counters>(&m, size_of::<layout::Counters>());
    }
    let m = parse_source(&aggregate_source(Precision::F64));
    check::<layout::State64>(&m, size_of::<layout::State64>());
    // Every variant of the fast stage (energy balance, peak accelerations) is valid WGSL.
    for p in [Precision::F64, Precision::F32] {
        for (energy, accel) in [(false, false), (false, true), (true, false), (true, true)] {
            let m = parse_source(&fast_source(p, energy, accel));
            check::<layout::Counters>(&m, size_of::<layout::Counters>());
        }
    }
}

/// The value of the shader's `const name` (a literal).
fn constant(module: &naga::Module, name: &str) -> f64 {
    let (_, c) = module
        .constants
        .iter()
        .find(|(_, c)| c.name.as_deref() == Some(name))
        .unwrap_or_else(|| panic!("const {name} not in shader"));
    match module.global_expressions[c.init] {
        naga::Expression::Literal(l) => match l {
            naga::Literal::F64(x) | naga::Literal::AbstractFloat(x) => x,
            naga::Literal::F32(x) => x as f64,
            naga::Literal::U32(x) => x as f64,
            naga::Literal::I32(x) => x as f64,
            naga::Literal::AbstractInt(x) => x as f64,
            other => panic!("const {name}: {other:?}"),
        },
        ref e => panic!("const {name} is not a literal: {e:?}"),
    }
}

/// Every constant the shader shares with the Rust side ("keep in sync" on both).
#[test]
fn shared_constants_match_the_shader() {
    use pounding::physics::solver::fast;
    let m = parse(Precision::F64);
    for (name, rust) in [
        ("HC_V0_MIN", pounding::physics::contact::HC_V0_MIN),
        (
            "MAX_PIECES_PER_SUBSTEP",
            fast::MAX_PIECES_PER_SUBSTEP as f64,
        ),
        ("SUSTAINED", fast::SUSTAINED),
        ("LOCATE_TOL", fast::LOCATE_TOLERANCE),
        ("LOCATE_ITER", fast::LOCATE_ITERATIONS as f64),
        ("LOCATE_BISECT", fast::LOCATE_BISECTIONS as f64),
        ("MODE_FREE", layout::MODE_FREE as f64),
        ("MODE_APPROACH", layout::MODE_APPROACH as f64),
        ("MODE_RESTITUTION", layout::MODE_RESTITUTION as f64),
        ("STATUS_OK", layout::STATUS_OK as f64),
        ("STATUS_NON_FINITE", layout::STATUS_NON_FINITE as f64),
        ("STATUS_STEP_LIMIT", layout::STATUS_STEP_LIMIT as f64),
        ("STATUS_HANDOFF", layout::STATUS_HANDOFF as f64),
        ("FORMS", layout::FORMS_PER_RUN as f64),
        ("WG", layout::WORKGROUP_SIZE as f64),
    ] {
        assert_eq!(constant(&m, name), rust, "const {name}");
    }
    for (i, law) in pounding::physics::contact::LawKind::ALL
        .iter()
        .enumerate()
        .take(6)
    {
        let name = format!("LAW_{}", law.key().to_uppercase());
        assert_eq!(constant(&m, &name), i as f64, "{name}");
    }
}

use crate::support::{
    collect, ctx, gpu_collect, gpu_run, grazing_contacts, peak_diff, rel, without_work,
};
use pounding::engine::gpu::{GpuContext, GpuOptions};
use pounding::engine::Engine;
use pounding::physics::model::RunOutput;
use pounding::physics::solver::{FastOptions, FreeResponse, Scheme};
use pounding::plan::{PairPlan, RunSpec};
use std::sync::OnceLock;

/// The GPU-vs-CPU grid: every law and every formula, e from 0.1 (overdamped contact) to 1,
/// periods 0.05 to 3 s (an undamped stiff building beside a flexible one), gaps from 0 (touching
/// at rest) to 2 m (never touching), a synthetic record (dt 0.01 s) and the strong part of Kobe
/// (dt 0.02 s), 6 s each at 0.5 g: 2,352 runs.
pub const WIDE: &str = r#"
[run]
tail_s = 0.0

[building1]
mass_kg = 1.0e5
period_s = [0.05, 3.0]
damping_ratio = 0.0

[building2]
mass_kg = 1.0e5
period_s = [0.4, 1.2]
damping_ratio = 0.05

[contact]
law = ["linear", "kelvin_voigt", "kelvin_voigt_no_tension", "modified_linear", "hertz",
       "nonlinear_viscoelastic", "hunt_crossley", "lankarani_nikravesh", "flores", "hunt_crossley_exact"]
formula = ["anagnostopoulos", "mahmoud_jankowski", "jankowski", "barros", "khatami", "ebrahimi", "exact"]
e = [0.1, 0.55, 1.0]
k_n_per_m = 1.0e9
beta_n_per_m1_5 = 2.75e9
gap_m = [0.0, 0.02, 2.0]

[[record]]
synthetic = { seed = 21, duration_s = 6.0, dt_s = 0.01 }

[[record]]
file = "kobe1995_jma_ns_RSN1106_KJM000.AT2"
window_s = [5.0, 11.0]

[intensity]
pga_g = 0.5
"#;

/// The wide grid's settings: the defaults, with the energy balance.
const WIDE_FAST: FastOptions = FastOptions {
    substeps_per_contact: 64.0,
    max_substeps_per_step: 1 << 20,
    max_substeps: 1 << 30,
    energy: true,
};

fn wide() -> &'static (PairPlan, Vec<(RunSpec, RunOutput)>) {
    static WIDE_CPU: OnceLock<(PairPlan, Vec<(RunSpec, RunOutput)>)> = OnceLock::new();
    WIDE_CPU.get_or_init(|| {
        let plan = pounding::plan::config::parse(
            WIDE,
            std::path::Path::new("wide.toml"),
            std::path::Path::new("."),
            &crate::support::records_dir(),
        )
        .unwrap();
        let cpu = collect(&plan, &Scheme::Fast(WIDE_FAST), 8);
        (plan, cpu)
    })
}

/// f64 on the GPU runs the CPU fast path's arithmetic, so the two agree to rounding: measured
/// on the 2,352 wide-grid runs (`cargo test --release gpu_f64 -- --nocapture`), median 1e-14 and
/// max 2.9e-9 over the nine laws on lavapipe (the largest on long pressed Kelvin-Voigt contacts
/// at gap 0, where rounding differences grow over hundreds of substeps). The nonlinear
/// viscoelastic law differed by up to 7.7e-6 while its `delta^(1/4)` damping was integrated
/// across the singular onset in one RK4 piece (rounding then moved some runs by as much); with
/// the graded pieces after a touch (`Contact::onset_cut`) it differs by 4.7e-9: it gets 3x
/// that. Energy residuals differ by at most 3.9e-9 on lavapipe, 1.26e-8 on an H100
/// (its compiler fuses multiply-adds, which lavapipe does not).
const RESIDUAL_BOUND: f64 = 4e-8;

/// Largest peak difference allowed between two f64 results of run `s` (see RESIDUAL_BOUND's
/// notes), `other` the one compared against.
fn f64_bound(s: &RunSpec, other: &RunOutput) -> f64 {
    if s.law == pounding::physics::contact::LawKind::NonlinearViscoelastic {
        1.5e-8
    } else {
        1e-9 + 1e-14 * other.substeps as f64
    }
}

#[test]
fn gpu_f64_matches_cpu_fast_on_a_wide_grid() {
    let Some(ctx) = ctx() else { return };
    assert!(ctx.supports_f64(), "{} has no SHADER_F64", ctx.describe());
    let (plan, cpu) = wide();
    let opts = GpuOptions {
        precision: pounding::engine::gpu::Precision::F64,
        fast: WIDE_FAST,
        ..Default::default()
    };
    let gpu = gpu_collect(plan, &opts, 100_000);
    assert_eq!(cpu.len(), gpu.len());
    let mut worst = std::collections::BTreeMap::new();
    let mut worst_residual = 0.0f64;
    let mut all = Vec::new();
    // Every difference is measured before any is judged, so a failure reports the whole picture.
    let mut bad = Vec::new();
    for ((s, c), (_, g)) in cpu.iter().zip(&gpu) {
        if (c.status, c.impacts, c.peak_force == 0.0) != (g.status, g.impacts, g.peak_force == 0.0)
        {
            bad.push(format!("run {}: CPU {c:?}, GPU {g:?}", s.index));
            continue;
        }
        let (rg, rc) = (g.energy.unwrap().residual, c.energy.unwrap().residual);
        worst_residual = worst_residual.max((rg - rc).abs());
        if (rg - rc).abs() >= RESIDUAL_BOUND {
            bad.push(format!(
                "run {}: energy residual {rg:e} on the GPU, {rc:e} on the CPU",
                s.index
            ));
        }
        let e = peak_diff(g, c);
        let w = worst.entry(s.law.key()).or_insert(0.0f64);
        *w = w.max(e);
        all.push(e);
        if e > f64_bound(s, c) {
            bad.push(format!(
                "run {} ({}): GPU-CPU difference {e:e}",
                s.index,
                s.law.key()
            ));
        }
    }
    all.sort_by(f64::total_cmp);
    eprintln!(
        "f64 GPU vs CPU on {} runs ({}): median {:e}; max by law {worst:?}; energy residuals differ by at most {worst_residual:e}",
        all.len(),
        ctx.info.name,
        all[all.len() / 2]
    );
    assert!(
        bad.is_empty(),
        "{} runs out of bounds:\n{}",
        bad.len(),
        bad.join("\n")
    );
}

/// f32 against the CPU f64 fast path on the wide grid (runs past f32's reach are handed to the
/// CPU, `gpu_hands_runs_past_its_precision_to_the_cpu`: 187 of the 2,352 here, all at e = 0.1
/// with a formula giving zeta = 5 to 125). Measured over runs with equal impact counts (all of
/// them here): peak force median 1.3e-6, p99 1.5e-4, max 6.2e-4 (nonlinear viscoelastic);
/// peak displacements max 2.3e-3 (a long pressed contact at gap 0). Without the hand-off the
/// same grid gave 7 % and 12 %. The fast scheme's own peak-force error against the reference is
/// up to 1.3e-3, so f32 is the default. Bounds: about 3x the measured maxima and p99, 8x the
/// median (f32 rounding moves with the record, law and adapter).
#[test]
fn gpu_f32_error_against_cpu_f64() {
    let Some(_) = ctx() else { return };
    let (plan, cpu) = wide();
    let opts = GpuOptions {
        fast: WIDE_FAST,
        ..Default::default()
    };
    let gpu = gpu_collect(plan, &opts, 100_000);
    let mut f: Vec<f64> = Vec::new();
    let mut u: Vec<f64> = Vec::new();
    let mut imp_diff = 0;
    let mut residual = 0.0f64;
    for ((s, c), (_, g)) in cpu.iter().zip(&gpu) {
        assert_eq!(c.status, g.status, "run {}", s.index);
        residual = residual.max(g.energy.unwrap().residual.abs());
        if c.impacts != g.impacts {
            imp_diff += 1;
            continue;
        }
        if c.peak_force > 0.0 {
            f.push(rel(g.peak_force, c.peak_force));
        }
        u.push(rel(g.peak_u1, c.peak_u1).max(rel(g.peak_u2, c.peak_u2)));
    }
    f.sort_by(f64::total_cmp);
    u.sort_by(f64::total_cmp);
    let q = |v: &[f64], p: f64| v[((v.len() - 1) as f64 * p) as usize];
    eprintln!(
        "f32: peak force median {:e} p99 {:e} max {:e}; peak u median {:e} max {:e}; impact counts differ on {imp_diff}/{}; energy residual max {residual:e}",
        q(&f, 0.5), q(&f, 0.99), q(&f, 1.0), q(&u, 0.5), q(&u, 1.0), cpu.len()
    );
    assert!(residual < 5e-4, "energy residual {residual:e}");
    assert!(
        q(&f, 1.0) < 2e-3 && q(&f, 0.99) < 5e-4 && q(&f, 0.5) < 1e-5,
        "peak force median {:e} p99 {:e} max {:e}",
        q(&f, 0.5),
        q(&f, 0.99),
        q(&f, 1.0)
    );
    assert!(q(&u, 1.0) < 5e-3, "peak displacement {:e}", q(&u, 1.0));
}

/// An impact count may differ between f32 and f64 only where a contact is grazing: for every
/// run of the quickstart sweep and the wide grid whose counts differ, the f64 run must hold at
/// least as many grazing contacts (see `grazing_contacts`) as the counts differ by, at a distance
/// scale of 1e-3 of the run's peak displacement (the f32 displacement error is at most 1.1e-3 of
/// it, `gpu_f32_error_against_cpu_f64`). Measured: one run in 2,700 of the quickstart differs
/// (15 impacts against 14: two impacts 0.9 ms apart, re-touching at 1.4 mm/s), none of the wide
/// grid (without the f32 hand-off, 7 runs there, each with as many grazing contacts).
#[test]
fn gpu_f32_impact_counts_differ_only_at_grazing_contacts() {
    let Some(_) = ctx() else { return };
    let quick =
        pounding::plan::config::load_pair(std::path::Path::new("configs/quickstart.toml")).unwrap();
    // At 64 substeps on both sides, the setting the wide grid runs at.
    let precise = crate::support::precise_fast();
    let quick_cpu = collect(&quick, &Scheme::Fast(precise), 8);
    let (wide_plan, wide_cpu) = wide();
    let mut differ = 0;
    for (plan, cpu) in [(&quick, &quick_cpu), (wide_plan, wide_cpu)] {
        let gpu = gpu_collect(
            plan,
            &GpuOptions {
                fast: precise,
                ..Default::default()
            },
            100_000,
        );
        for ((s, c), (_, g)) in cpu.iter().zip(&gpu) {
            if c.impacts == g.impacts {
                continue;
            }
            differ += 1;
            let tau = 1e-3 * c.peak_u1.max(c.peak_u2);
            let grazing = grazing_contacts(plan, s, tau);
            let by = c.impacts.abs_diff(g.impacts) as usize;
            eprintln!(
                "run {}: {} impacts in f64, {} in f32; {grazing} grazing contacts at {tau:e} m",
                s.index, c.impacts, g.impacts
            );
            assert!(
                grazing >= by,
                "run {} ({:?}): impact counts {} (f64) and {} (f32) differ by {by} but only {grazing} contacts are grazing at {tau:e} m",
                s.index, s, c.impacts, g.impacts
            );
        }
    }
    eprintln!("{differ} runs with different impact counts, each explained by grazing contacts");
}

fn csv_text(plan: &PairPlan, rows: &[(RunSpec, RunOutput)]) -> String {
    let mut w = csv::Writer::from_writer(Vec::new());
    for (s, o) in rows {
        w.write_record(pounding::plan::columns::row(plan, s, o))
            .unwrap();
    }
    String::from_utf8(w.into_inner().unwrap()).unwrap()
}

/// A sweep split into many chunks (and many dispatches per chunk) writes the same CSV as one.
#[test]
fn gpu_chunking_does_not_change_results() {
    let Some(_) = ctx() else { return };
    let plan = pounding::studies::bench::plan(200);
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

/// Runs needing more substeps per record step than the hand-off threshold come back from the
/// kernel unfinished and are finished on the CPU: with a threshold of 16, exactly the handed-off
/// runs equal the CPU f64 result bit for bit (an f32 result never does), and the rest were
/// integrated on the GPU.
#[test]
fn gpu_hands_runs_past_its_precision_to_the_cpu() {
    let Some(_) = ctx() else { return };
    let plan = pounding::studies::bench::plan(200);
    let cpu = collect(&plan, &Scheme::Fast(FastOptions::default()), 8);
    let opts = GpuOptions {
        handoff_substeps_per_step: Some(16),
        ..Default::default()
    };
    let (gpu, report) = gpu_run(&plan, &opts, 1000);
    let t = report.gpu;
    let exact = cpu
        .iter()
        .zip(&gpu)
        .filter(|((_, c), (_, g))| without_work(c) == without_work(g))
        .count() as u64;
    eprintln!("{} of {} runs handed off", t.handed_off, plan.len());
    assert!(
        t.handed_off > 0 && t.handed_off < plan.len(),
        "{} handed off",
        t.handed_off
    );
    assert_eq!(exact, t.handed_off);
}

/// A device lost in the middle of a sweep ends it with `DeviceLost` (a message that points to
/// `--backend cpu`), and the chunks finished before the loss stay with the sink. The loss is
/// real: the device is destroyed from the sink after the first chunk.
#[test]
fn gpu_device_loss_keeps_finished_chunks() {
    let Some(_) = ctx() else { return };
    let own = GpuContext::new().unwrap();
    let plan = pounding::studies::bench::plan(200);
    let mut rows = Vec::new();
    let res = Engine::gpu(&own, GpuOptions::default(), Some(50))
        .unwrap()
        .run(
            &plan,
            0..plan.len(),
            |c: &[(RunSpec, RunOutput)]| -> Result<(), pounding::engine::gpu::GpuError> {
                rows.extend_from_slice(c);
                if rows.len() == 50 {
                    own.device.destroy();
                }
                Ok(())
            },
            |_| {},
        );
    let err = res.expect_err("a sweep on a destroyed device must fail");
    assert!(
        matches!(err, pounding::engine::gpu::GpuError::DeviceLost { .. }),
        "{err:?}"
    );
    assert!(err.to_string().contains("--backend cpu"), "{err}");
    assert_eq!(rows.len(), 50);
    for (i, (s, o)) in rows.iter().enumerate() {
        assert_eq!(s.index, i as u64);
        assert_eq!(o.status, pounding::physics::model::Status::Ok, "run {i}");
    }
    assert!(rows.iter().any(|(_, o)| o.impacts > 0));
}

/// `--aggregate` folded on the device (`shaders/aggregate.wgsl`) against the host's fold of the
/// same GPU runs read back one by one: run, failure and exceedance counts equal, maxima equal,
/// means to the precision's rounding, quantiles at most one 2 % bucket apart (the device takes
/// the bucket's log in f32). Cases: every group in every chunk with runs handed back to the CPU;
/// f32; more groups over the sweep than histogram slots (flushed to the host); more groups in a
/// chunk than slots (that chunk folded on the host).
#[test]
fn gpu_aggregate_on_device_matches_the_host_fold() {
    use pounding::engine::aggregate::Aggregator;
    let Some(ctx) = ctx() else { return };
    let plan = pounding::studies::bench::plan(200);
    let exceed = ["peak_force_n=1e6".to_string(), "impacts=2".to_string()];
    struct Case {
        precision: Precision,
        by: &'static str,
        chunk: usize,
        slots: u32,
        handoff: Option<u32>,
        mean_tol: f64,
    }
    let cases = [
        Case {
            precision: Precision::F64,
            by: "gap_m",
            chunk: 64,
            slots: 1024,
            handoff: Some(16),
            mean_tol: 1e-12,
        },
        Case {
            precision: Precision::F32,
            by: "t1_s",
            chunk: 64,
            slots: 1024,
            handoff: None,
            mean_tol: 1e-5,
        },
        Case {
            precision: Precision::F64,
            by: "t1_s,gap_m",
            chunk: 40,
            slots: 12,
            handoff: None,
            mean_tol: 1e-12,
        },
        Case {
            precision: Precision::F64,
            by: "t1_s,gap_m",
            chunk: 40,
            slots: 8,
            handoff: None,
            mean_tol: 1e-12,
        },
    ];
    for (n, c) in cases.iter().enumerate() {
        let by: Vec<String> = c.by.split(',').map(String::from).collect();
        let opts = GpuOptions {
            precision: c.precision,
            handoff_substeps_per_step: c.handoff,
            ..Default::default()
        };
        let mut host = Aggregator::new(&by, &exceed).unwrap();
        host.add_rows(&plan, &gpu_collect(&plan, &opts, c.chunk));
        let mut dev = Aggregator::new(&by, &exceed).unwrap();
        let (summary, t) = pounding::engine::gpu::fold::fold_range(
            &plan,
            0..plan.len(),
            ctx,
            &opts,
            c.chunk,
            c.slots,
            &mut dev,
            |_| {},
        )
        .unwrap();
        eprintln!(
            "case {n}: {} groups, {} handed off, {} chunks folded on the host, {} flushes",
            dev.groups(),
            t.handed_off,
            t.host_folded_chunks,
            t.slot_flushes
        );
        assert_eq!(summary.runs, plan.len());
        match n {
            0 => assert!(t.handed_off > 0),
            2 => assert!(t.slot_flushes > 0 && t.host_folded_chunks == 0),
            3 => assert!(t.host_folded_chunks == 5),
            _ => assert!(t.host_folded_chunks == 0 && t.slot_flushes == 0),
        }
        let (d, h) = (
            pounding::io::summary::csv(&dev),
            pounding::io::summary::csv(&host),
        );
        let mut dr = csv::Reader::from_reader(d.as_bytes());
        let mut hr = csv::Reader::from_reader(h.as_bytes());
        let head = hr.headers().unwrap().clone();
        assert_eq!(dr.headers().unwrap(), &head);
        let drows: Vec<csv::StringRecord> = dr.records().map(|r| r.unwrap()).collect();
        let hrows: Vec<csv::StringRecord> = hr.records().map(|r| r.unwrap()).collect();
        assert_eq!(drows.len(), hrows.len());
        let mut moved = 0;
        for (a, b) in drows.iter().zip(&hrows) {
            for ((col, x), y) in head.iter().zip(a).zip(b) {
                let (fx, fy) = (x.parse::<f64>(), y.parse::<f64>());
                let (Ok(fx), Ok(fy)) = (fx, fy) else {
                    assert_eq!(x, y, "case {n} {col}");
                    continue;
                };
                if col.ends_with("_mean") {
                    assert!(rel(fx, fy) <= c.mean_tol, "case {n} {col}: {fx} vs {fy}");
                } else if col.contains("_p") && fx != fy {
                    moved += 1;
                    assert!(rel(fx, fy) <= 0.021, "case {n} {col}: {fx} vs {fy}");
                } else if !col.contains("_p") {
                    assert_eq!(fx, fy, "case {n} {col}");
                }
            }
        }
        eprintln!("case {n}: {moved} quantiles one bucket apart");
    }
}

/// The kernel's lane tally and work counts: every free interval and RK4 piece is one unit of a
/// lane, so the units cover the free steps and substeps the runs report; the units fit in the
/// slots the lanes were held for; and the free steps and substeps match the CPU's work on the
/// same runs (f64: the same decisions, up to rounding at the edge of the near-contact test).
#[test]
fn gpu_lane_tally_and_work_counts_match_the_runs() {
    let Some(ctx) = ctx() else { return };
    let plan = pounding::studies::bench::plan(200);
    let opts = GpuOptions {
        precision: pounding::engine::gpu::Precision::F64,
        ..Default::default()
    };
    let (gpu, report) = gpu_run(&plan, &opts, pounding::engine::GPU_CHUNK);
    let cpu = collect(&plan, &Scheme::Fast(FastOptions::default()), 8);
    let (t, s) = (report.gpu, report.summary);
    let (free, sub): (u64, u64) = (s.free_steps, s.substeps);
    assert_eq!(free, gpu.iter().map(|(_, o)| o.free_steps).sum::<u64>());
    assert!(free > 0 && sub > 0, "{s:?}");
    assert!(s.shared_steps > 0 && s.runs_sharing > 0, "{s:?}");
    assert!(t.lane_units >= free + sub, "{t:?} against {s:?}");
    assert!(t.lane_units <= t.lane_slots, "{t:?}");
    let u = t.lane_utilisation().unwrap();
    assert!(u > 0.0 && u <= 1.0, "{u}");
    for ((spec, g), (_, c)) in gpu.iter().zip(&cpu) {
        let intervals = plan.forcing(spec).intervals() as u64;
        // Both paths settle free steps from shared free responses, not always the same ones
        // (the GPU learns its distance from the shared motion only at checkpoints).
        let c = &RunOutput {
            free_steps: c.free_steps + c.shared_steps,
            ..*c
        };
        let g = &RunOutput {
            free_steps: g.free_steps + g.shared_steps,
            ..*g
        };
        assert!(g.free_steps <= intervals && c.free_steps <= intervals);
        if c.substeps == 0 {
            assert_eq!(c.free_steps, intervals, "run {}", spec.index);
        }
        let near = |a: u64, b: u64| a.abs_diff(b) <= 2 + a.max(b) / 1000;
        assert!(
            near(g.free_steps, c.free_steps) && near(g.substeps, c.substeps),
            "run {}: GPU {} free steps, {} substeps; CPU {}, {}",
            spec.index,
            g.free_steps,
            g.substeps,
            c.free_steps,
            c.substeps
        );
    }
    eprintln!(
        "lane utilisation on {}: {:.1} % ({} units in {} slots)",
        ctx.info.name,
        100.0 * u,
        t.lane_units,
        t.lane_slots
    );
}

/// The shared free response on the GPU (`engine::gpu::shared`, `fast.wgsl`'s shared section):
/// in f64, runs that start at their first possible contact, settle free steps from the
/// response's tables and end early report what they report stepping every interval on the GPU,
/// and what the CPU reports, within the bounds of `gpu_f64_matches_cpu_fast_on_a_wide_grid`
/// (every law, real and synthetic records, a tail of free vibration, gaps 0 to 0.5 m); and the
/// shortcuts are taken: most runs share, over a sixth end early, and over a third of the record
/// steps is settled (measured on lavapipe: 1,600 of 1,920 share, 367 end early, 49 % of the
/// steps settled; largest difference 6.6e-6, nonlinear viscoelastic).
#[test]
fn gpu_f64_shared_free_response_changes_nothing_but_the_work() {
    let Some(_) = ctx() else { return };
    let plan = crate::shared::plan(crate::shared::SCENES);
    // At 64 substeps (f64_bound was measured there).
    let stepped_opts = GpuOptions {
        precision: pounding::engine::gpu::Precision::F64,
        share_free_response: false,
        fast: crate::support::precise_fast(),
        ..Default::default()
    };
    let shared_opts = GpuOptions {
        share_free_response: true,
        ..stepped_opts
    };
    let (stepped, _) = gpu_run(&plan, &stepped_opts, 100_000);
    let (shared, report) = gpu_run(&plan, &shared_opts, 100_000);
    let cpu = collect(&plan, &Scheme::Fast(crate::support::precise_fast()), 64);
    let mut bad = Vec::new();
    let (mut worst, mut ended_early) = (0.0f64, 0u64);
    let mut responses = std::collections::HashMap::new();
    for ((s, g), ((_, st), (_, c))) in shared.iter().zip(stepped.iter().zip(&cpu)) {
        assert_eq!(st.shared_steps, 0, "run {}", s.index);
        // Settled past the first possible contact: the run ended early.
        let key = [s.m1, s.t1, s.xi1, s.m2, s.t2, s.xi2].map(f64::to_bits);
        let response = responses.entry((s.record, key)).or_insert_with(|| {
            let p = s.pair();
            FreeResponse::new(&p.b1, &p.b2, &plan.forcing(s))
        });
        ended_early += (g.shared_steps > response.first_possible_contact(s.gap) as u64) as u64;
        // Buildings of equal period and damping move alike; at gap 0 they touch only by
        // rounding (forces of 1e-16 to 1e-7 N), which differs between the CPU and the GPU:
        // those runs are compared on the GPU only.
        let rounding_only = (s.t1, s.xi1) == (s.t2, s.xi2) && s.gap == 0.0;
        let others = [("stepped on the GPU", st), ("on the CPU", c)];
        for (what, other) in &others[..if rounding_only { 1 } else { 2 }] {
            if (g.status, g.impacts) != (other.status, other.impacts) {
                bad.push(format!("run {}: shared {g:?}, {what} {other:?}", s.index));
                continue;
            }
            let e = peak_diff(g, other);
            worst = worst.max(e);
            if e > f64_bound(s, other) {
                bad.push(format!(
                    "run {} ({}): {e:e} from {what}",
                    s.index,
                    s.law.key()
                ));
            }
        }
    }
    let sum = report.summary;
    eprintln!(
        "shared on the GPU: {} of {} runs share, {} of {} record steps settled, {ended_early} ended early; largest difference {worst:e}",
        sum.runs_sharing,
        sum.runs,
        sum.shared_steps,
        sum.shared_steps + sum.free_steps,
    );
    assert!(
        bad.is_empty(),
        "{} runs differ:\n{}",
        bad.len(),
        bad.join("\n")
    );
    assert!(sum.runs_sharing * 2 > sum.runs, "{sum:?}");
    assert!(
        ended_early * 6 > sum.runs,
        "{ended_early} of {} ended early",
        sum.runs
    );
    assert!(sum.shared_steps * 3 > sum.free_steps, "{sum:?}");
}
