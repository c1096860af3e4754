//! `pound gap`'s required gap against the sweep's own pounding threshold, found by bisection on
//! the gap with the sweep's solver (the run a `pound sweep` of the config takes, one gap at a
//! time), scene kind by scene kind: `|g_req - threshold|` is within the study's
//! `error_bound_m` plus the bisection's bracket wherever the study states a bound; where it
//! states none (storeys yield, or a run nears the collapse limit: both are stepped by the
//! sweep's row scheme) within the measured agreement of the two runs.
//!
//! The sweep's threshold is itself off the exact one by its RK4 substeps' error where a level
//! may touch (measured up to 2.4e-9 of the gap on a record at dt 0.02 s): at the sweep's
//! default settings the bound is given [`SWEEP`] of the gap more; with 16 times the substeps
//! per contact (an error 16^4 times smaller) the bound alone must hold.

use pounding::engine::cpu::{run_one, run_row_pairs};
use pounding::physics::model::Status;
use pounding::physics::solver::row::{simulate_row, RowModel, RowScheme};
use pounding::physics::solver::{FastOptions, Scheme};
use pounding::plan::config::load_text;
use pounding::plan::row::RowPlan;
use pounding::plan::Plan;
use pounding::studies::gap::GapStudy;
use std::path::Path;

/// The bisection stops when its bracket is this share of the required gap.
const BRACKET: f64 = 1e-13;

/// Where no bound is stated: the study's uncoupled run and the sweep's run take the same
/// scheme, whose substeps differ only where the sweep's levels may touch (measured within
/// 1.1e-7 of the gap, see docs/gap-study.md).
const UNBOUNDED: f64 = 2e-7;

/// The sweep's own error at its default settings, as a share of the gap (see the module docs).
const SWEEP: f64 = 1e-8;

const CONTACT: &str = r#"
[contact]
law = "nonlinear_viscoelastic"
formula = "ebrahimi"
e = 0.65
beta_n_per_m1_5 = 2.75e9
"#;

const RECORD: &str = r#"
[[record]]
synthetic = { seed = 5, duration_s = 6.0, dt_s = 0.01, pga_g = 0.3 }

[[record]]
synthetic = { seed = 9, duration_s = 6.0, dt_s = 0.02, pga_g = 0.3 }
"#;

/// A row config of `buildings` (each `gap_right_m` but the last's is filled in), at the PGAs
/// `pga` of the synthetic record, with `run` as its `[run]` table.
fn row(run: &str, buildings: &[&str], pga: &str) -> String {
    let mut text = format!("[run]\ntail_s = 1.0\n{run}\n");
    for (k, b) in buildings.iter().enumerate() {
        text += "\n[[building]]\n";
        text += b;
        if k + 1 < buildings.len() {
            text += "\ngap_right_m = 0.01\n";
        }
    }
    format!("{text}\n{CONTACT}\n{RECORD}\n[intensity]\npga_g = {pga}\n")
}

const LOW3: &str =
    "storeys = 3\nstorey_height_m = 3.0\nmass_kg = 3.0e5\nperiod_s = 0.35\ndamping_ratio = 0.05";
const TALL5: &str =
    "storeys = 5\nstorey_height_m = 3.0\nmass_kg = 3.0e5\nperiod_s = 0.8\ndamping_ratio = 0.05";
/// A 4-storey P-Delta frame whose storeys lean unequally (Rayleigh damping then couples its
/// modes), the frame of `configs/collapse-ida.toml`.
const LEANING4: &str = "storeys = 4\nstorey_height_m = [4.0, 3.5, 3.5, 3.5]\nmass_kg = 3.0e5\nstiffness_profile = [1.0, 0.9, 0.8, 0.6]\nperiod_s = 1.0\ndamping_ratio = 0.05\np_delta = true\ngravity_mass_ratio = 2.0";
const STIFF3: &str = "storeys = 3\nstorey_height_m = [4.0, 3.5, 3.5]\nmass_kg = 2.5e5\nperiod_s = 0.3\ndamping_ratio = 0.05";
const YIELD: &str = "\nyield_drift_ratio = 0.004\npost_yield_ratio = 0.03";
const FRAME_YIELD: &str = "\nyield_drift_ratio = 0.006\npost_yield_ratio = 0.02";

/// The scene kinds the sweep runs, each a config.
fn scenes() -> Vec<(&'static str, String)> {
    let modal = |b: &str| format!("{b}\ndamping = \"modal\"");
    let one = |t: f64, m: f64| {
        format!("storeys = 1\nstorey_height_m = 3.0\nmass_kg = {m}\nperiod_s = {t}\ndamping_ratio = 0.05")
    };
    let pair = format!(
        "[building1]\nmass_kg = 1.0e5\nperiod_s = [0.3, 0.75]\ndamping_ratio = 0.05\n\n\
         [building2]\nmass_kg = 2.0e5\nperiod_s = 0.45\ndamping_ratio = 0.03\n\
         {CONTACT}gap_m = 0.01\n{RECORD}\n[intensity]\npga_g = [0.2, 0.4]\n"
    );
    let low_yield = format!("{LOW3}{YIELD}");
    let frame = format!("{LEANING4}{FRAME_YIELD}");
    // Storeys of 3.5 m beside 3 m: every floor strikes the neighbour's columns.
    let columns = "storeys = 3\nstorey_height_m = 3.5\nmass_kg = 2.0e5\nperiod_s = 0.45\ndamping_ratio = 0.05";
    let struck =
        "storeys = 4\nstorey_height_m = 3.0\nmass_kg = 3.0e5\nperiod_s = 0.6\ndamping_ratio = 0.05";
    vec![
        ("elastic pair (SDOF)", pair),
        (
            "one-storey row (the pair's kernel)",
            row("", &[&one(0.45, 1e5), &one(0.3, 2e5)], "[0.25]"),
        ),
        ("multistorey elastic, Rayleigh", row("", &[LOW3, TALL5], "[0.3]")),
        (
            "multistorey elastic, modal damping",
            row("", &[&modal(LOW3), &modal(TALL5)], "[0.3]"),
        ),
        (
            "P-Delta elastic, Rayleigh (coupled modes)",
            row("", &[LEANING4, STIFF3], "[0.2, 0.4]"),
        ),
        (
            "P-Delta elastic, modal damping",
            row("", &[&modal(LEANING4), STIFF3], "[0.2, 0.4]"),
        ),
        (
            "row of three, P-Delta in the middle",
            row("", &[LOW3, LEANING4, STIFF3], "[0.3]"),
        ),
        ("floors that strike columns", row("", &[columns, struck], "[0.3]")),
        (
            "floors that strike columns, P-Delta Rayleigh",
            row(
                "",
                &[columns, &format!("{struck}\nstiffness_profile = [1.0, 0.9, 0.7, 0.5]\np_delta = true\ngravity_mass_ratio = 2.0")],
                "[0.3]",
            ),
        ),
        ("yielding storeys", row("", &[&low_yield, TALL5], "[0.3, 0.5]")),
        ("yielding with P-Delta", row("", &[&frame, STIFF3], "[0.3, 0.5]")),
        (
            "elastic P-Delta near collapse (censored)",
            row("collapse_drift_ratio = 0.01", &[LEANING4, STIFF3], "[0.3, 0.6]"),
        ),
        (
            "collapse (censored)",
            row("collapse_drift_ratio = 0.03", &[&frame, STIFF3], "[0.8, 1.2]"),
        ),
    ]
}

/// Does the sweep's run of `plan`'s motion `m`, with pair `a` at `gap` and every other pair
/// far apart, pound?
fn pounds(plan: &Plan, m: u64, a: usize, gap: f64) -> bool {
    match plan {
        Plan::Pair(p) => {
            let mut spec = p.motion_run(m);
            spec.gap = gap;
            run_one(p, &spec, &plan.scheme()).impacts > 0
        }
        Plan::Row(r) => {
            let mut spec = r.motion_run(m);
            for (k, g) in spec.gaps.iter_mut().enumerate() {
                *g = if k == a { gap } else { 10.0 };
            }
            row_run(r, &spec).impacts > 0
        }
    }
}

/// The run `pound sweep` takes for `spec` (as `engine::cpu::run_rows`).
fn row_run(
    plan: &RowPlan,
    spec: &pounding::plan::row::RowRunSpec,
) -> pounding::physics::row::RowOutput {
    let scheme = plan.scheme();
    let out = match scheme {
        RowScheme::Fast(o) if plan.runs_as_pair() => {
            run_row_pairs(plan, std::slice::from_ref(spec), &o).remove(0)
        }
        _ => {
            let model = RowModel::new(&plan.row(spec));
            simulate_row(&model, &plan.forcing(spec), model.at_rest(), &scheme)
        }
    };
    assert!(
        matches!(out.status, Status::Ok | Status::Collapsed),
        "{:?}",
        out.status
    );
    out
}

/// The smallest gap at which `pounds` is false, bracketed to [`BRACKET`] of `need`: `(lo, hi)`
/// with `lo` pounding and `hi` not.
fn threshold(pounds: impl Fn(f64) -> bool, need: f64) -> (f64, f64) {
    let (mut lo, mut hi) = (need * (1.0 - 1e-3), need * (1.0 + 1e-3));
    while !pounds(lo) {
        hi = lo;
        lo *= 0.9;
        assert!(lo > 1e-3 * need, "no pounding near {need}");
    }
    while pounds(hi) {
        lo = hi;
        hi *= 1.1;
        assert!(hi < 1e3 * need, "pounding far above {need}");
    }
    while hi - lo > BRACKET * need {
        let mid = 0.5 * (lo + hi);
        if pounds(mid) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    (lo, hi)
}

/// Every scene kind, at the sweep's default settings and with 16 times its substeps: each
/// run's required gap of each pair is the sweep's pounding threshold, within the stated bound
/// (plus the bracket, plus [`SWEEP`] of the gap at the defaults), or within [`UNBOUNDED`]
/// where none is stated.
#[test]
fn required_gap_is_the_sweeps_threshold_on_every_scene_kind() {
    let mut failures = Vec::new();
    let fine = FastOptions {
        substeps_per_contact: 16.0 * FastOptions::default().substeps_per_contact,
        ..FastOptions::default()
    };
    for ((kind, text), finer) in scenes()
        .into_iter()
        .flat_map(|s| [(s.clone(), false), (s, true)])
    {
        let mut plan =
            load_text(&text, Path::new("scene.toml")).unwrap_or_else(|e| panic!("{kind}: {e}"));
        assert_eq!(
            plan.scheme(),
            Scheme::Fast(FastOptions::default()),
            "{kind}"
        );
        if finer {
            plan.set_scheme(Scheme::Fast(fine));
        }
        let sweep = if finer { 0.0 } else { SWEEP };
        let kind = format!("{kind}{}", if finer { ", 16x substeps" } else { "" });
        let study = GapStudy::run(&plan).unwrap_or_else(|e| panic!("{kind}: {e}"));
        let (mut checked, mut censored, mut worst, mut used) = (0, 0, 0.0f64, 0.0f64);
        for m in 0..study.len() {
            let run = study.get(m);
            let bound = run.separation.error_bound;
            for (a, p) in run.pairs.iter().enumerate() {
                let p = p.unwrap_or_else(|| panic!("{kind}: run {m} pair {a} has no gap"));
                if p.required == 0.0 {
                    continue;
                }
                censored += p.censored.is_some() as usize;
                let (lo, hi) = threshold(|g| pounds(&plan, m, a, g), p.required);
                let off = (p.required - hi).abs();
                let allowed = match bound {
                    Some(b) => b + (hi - lo) + sweep * p.required,
                    None => UNBOUNDED * p.required + (hi - lo),
                };
                worst = worst.max(off / p.required);
                used = used.max(off / allowed);
                if off > allowed {
                    failures.push(format!(
                        "{kind}, run {m}, pair {a}: required {} against the sweep's threshold \
                         {hi} (bracket {}): off by {off:e} ({:e} relative), allowed {allowed:e} \
                         (error bound {bound:?})",
                        p.required,
                        hi - lo,
                        off / p.required
                    ));
                }
                checked += 1;
            }
        }
        assert!(checked > 0, "{kind}: no pair closes");
        if kind.contains("censored") {
            assert!(censored > 0, "{kind}: no run collapsed");
        }
        eprintln!(
            "{kind}: {checked} pairs, {censored} censored; worst {worst:.2e} of the gap, {used:.3} of what is allowed"
        );
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
