//! The GPU paths answer a raised stop flag (`Engine::sweep_until`, what Python's Ctrl-C raises)
//! within a dispatch, with `GpuError::Interrupted`; a flag watched but never raised changes no
//! result (the dispatches are sized by time then, and the budget only splits a run's work).

use crate::support::gpu::ctx;
use pounding::engine::aggregate::Aggregator;
use pounding::engine::gpu::{GpuContext, GpuError, Precision};
use pounding::engine::{Chunk, Engine};
use pounding::plan::{config, Plan};
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// A shipped config, or (`pair-row`) a row of two one-storey buildings.
fn plan(name: &str) -> Plan {
    if name == "pair-row" {
        let b = |t: f64| {
            format!("[[building]]\nstoreys = 1\nstorey_height_m = 3.0\nmass_kg = 3e5\nperiod_s = {t}\ndamping_ratio = 0.05\n")
        };
        let text = format!(
            "{}{}[contact]\nlaw = \"linear\"\nk_n_per_m = 1e9\ngap_m = {{ from = 0.0, to = 0.02, n = 300 }}\n[[record]]\nsynthetic = {{ seed = 1, duration_s = 4.0 }}\n",
            b(0.3),
            b(0.7)
        );
        let plan = config::load_text(&text, Path::new("pair-row.toml")).unwrap();
        assert_eq!(
            pounding::engine::Kernel::of(&plan),
            pounding::engine::Kernel::Pair
        );
        return plan;
    }
    config::load(
        &Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("configs")
            .join(name),
    )
    .unwrap()
}

/// Each run's index and output, as the sink got them.
fn cells(c: Chunk<'_>) -> Vec<String> {
    match c {
        Chunk::Pairs(_, rows) => rows
            .iter()
            .map(|(s, o)| format!("{} {o:?}", s.index))
            .collect(),
        Chunk::Rows(_, rows) => rows
            .iter()
            .map(|(s, o)| format!("{} {o:?}", s.index))
            .collect(),
    }
}

/// A pair's plan (the pair kernel), rows (the row kernel; elastic, and yielding with P-Delta and
/// collapse) and a row of one-storey buildings (the pair kernel in the row's form).
const CONFIGS: [&str; 4] = [
    "quickstart.toml",
    "row-3-6.toml",
    "collapse-fragility.toml",
    "pair-row",
];

#[test]
fn a_raised_stop_ends_a_gpu_sweep_with_interrupted() {
    let Some(ctx) = ctx() else { return };
    for name in CONFIGS {
        let plan = plan(name);
        let engine = Engine::new(plan.scheme(), Some(ctx), Precision::F32, Some(64)).unwrap();
        // Raised before the first dispatch: no chunk reaches the sink.
        let stop = AtomicBool::new(true);
        let mut sunk = 0;
        let r = engine.sweep_until(
            &plan,
            0..plan.len().min(256),
            &stop,
            |_: Chunk<'_>| -> Result<(), GpuError> {
                sunk += 1;
                Ok(())
            },
            |_| {},
        );
        assert!(matches!(r, Err(GpuError::Interrupted)), "{name}: {r:?}");
        assert_eq!(sunk, 0, "{name}");
        // Raised by the sink of the first chunk: the next chunk ends in its dispatch loop.
        let stop = AtomicBool::new(false);
        let mut sunk = 0;
        let r = engine.sweep_until(
            &plan,
            0..plan.len().min(256),
            &stop,
            |_: Chunk<'_>| -> Result<(), GpuError> {
                sunk += 1;
                stop.store(true, Ordering::Relaxed);
                Ok(())
            },
            |_| {},
        );
        assert!(matches!(r, Err(GpuError::Interrupted)), "{name}: {r:?}");
        assert_eq!(sunk, 1, "{name}");
    }
    // The device fold (`aggregate` of a pair) too.
    let plan = plan("quickstart.toml");
    let engine = Engine::new(plan.scheme(), Some(ctx), Precision::F32, Some(64)).unwrap();
    let mut agg = Aggregator::for_plan(&plan, &["gap_m".into()], &[]).unwrap();
    let r = engine.summarise_until(&plan, 0..256, &AtomicBool::new(true), &mut agg, |_| {});
    assert!(matches!(r, Err(GpuError::Interrupted)), "{r:?}");
}

/// Watched and never raised, the GPU's dispatches are sized by time (from a budget of 4 units),
/// and each run's output is the one the command line's dispatches give, bit for bit.
#[test]
fn a_watched_stop_never_raised_changes_no_gpu_result() {
    let Some(ctx) = ctx() else { return };
    for name in CONFIGS {
        let plan = plan(name);
        let runs = 0..plan.len().min(200);
        let engine = Engine::new(plan.scheme(), Some(ctx), Precision::F32, None).unwrap();
        let mut plain = Vec::new();
        engine
            .sweep(
                &plan,
                runs.clone(),
                |c: Chunk<'_>| -> Result<(), GpuError> {
                    plain.extend(cells(c));
                    Ok(())
                },
                |_| {},
            )
            .unwrap();
        let mut watched = Vec::new();
        let stop = AtomicBool::new(false);
        engine
            .sweep_until(
                &plan,
                runs.clone(),
                &stop,
                |c: Chunk<'_>| -> Result<(), GpuError> {
                    watched.extend(cells(c));
                    Ok(())
                },
                |_| {},
            )
            .unwrap();
        assert_eq!(plain.len(), runs.end as usize, "{name}");
        crate::support::assert_same_text(name, &watched.join("\n"), &plain.join("\n"));
    }
}

/// A kernel's build is one driver call no flag cuts short (lavapipe builds a row of five's for
/// seconds), so a watched sweep builds it on a thread of its own and looks at the flag
/// meanwhile: raised during the build, the call returns `Interrupted` before the kernel is
/// built (none is kept yet), and the build, left to finish alone, keeps its kernel whole for
/// the next call.
#[test]
fn a_raised_stop_leaves_a_row_kernel_build() {
    let Some(shared) = ctx() else { return };
    if !shared.is_software() {
        // A hardware driver builds the kernel well within the flag's delay: nothing to leave.
        return;
    }
    // A device of its own: no kernel kept from another test.
    let ctx = GpuContext::new().unwrap();
    let plan = plan("row-of-five.toml");
    let engine = Engine::new(plan.scheme(), Some(&ctx), Precision::F32, Some(64)).unwrap();
    let runs = 0..plan.len();
    let stop = AtomicBool::new(false);
    let mut sunk = 0;
    let r = std::thread::scope(|s| {
        s.spawn(|| {
            std::thread::sleep(Duration::from_millis(500));
            stop.store(true, Ordering::Relaxed);
        });
        engine.sweep_until(
            &plan,
            runs.clone(),
            &stop,
            |_: Chunk<'_>| -> Result<(), GpuError> {
                sunk += 1;
                Ok(())
            },
            |_| {},
        )
    });
    assert!(matches!(r, Err(GpuError::Interrupted)), "{r:?}");
    assert_eq!(sunk, 0);
    assert_eq!(
        ctx.kernels_built(),
        0,
        "the call waited for the kernel's build"
    );
    // The build was under way: it ends alone and keeps its kernel.
    let t = Instant::now();
    while ctx.kernels_built() == 0 {
        assert!(
            t.elapsed().as_secs() < 600,
            "the build left behind never ended"
        );
        std::thread::sleep(Duration::from_millis(50));
    }
    let mut rows = 0;
    let report = engine
        .sweep(
            &plan,
            runs.clone(),
            |c: Chunk<'_>| -> Result<(), GpuError> {
                rows += cells(c).len();
                Ok(())
            },
            |_| {},
        )
        .unwrap();
    assert_eq!((rows as u64, report.summary.runs), (runs.end, runs.end));
    assert_eq!(ctx.kernels_built(), 1, "the next call builds it again");
}
