//! The shared free response ([`FreeResponse`]): a run that starts at its first possible contact
//! and ends early must report what it reports when it steps the whole record, field for field;
//! only the work counters move (and the skipped steps are exactly free steps it no longer takes).

use crate::support::{collect, records_dir, without_work};
use pounding::physics::model::{Initial, RunOutput};
use pounding::physics::solver::{
    simulate, simulate_observed, simulate_shared, simulate_tracking_accel, FastOptions,
    FreeResponse, Scheme,
};
use pounding::plan::{config, PairPlan};
use std::path::Path;

/// Every law, stiff and soft and equal buildings, a real record with a tail of free vibration
/// and a synthetic one; gaps from 0 to beyond contact.
pub const SCENES: &str = r#"
[run]
tail_s = 4.0

[building1]
mass_kg = 1.0e5
period_s = [0.3, 1.0]
damping_ratio = [0.02, 0.05]

[building2]
mass_kg = [1.0e5, 3.0e5]
period_s = [0.3, 1.2]
damping_ratio = 0.05

[contact]
law = ["linear", "kelvin_voigt", "kelvin_voigt_no_tension", "modified_linear", "hertz",
       "nonlinear_viscoelastic", "hunt_crossley", "lankarani_nikravesh", "flores", "hunt_crossley_exact"]
formula = "exact"
e = 0.6
k_n_per_m = 1.0e9
beta_n_per_m1_5 = 2.75e9
gap_m = [0.0, 0.002, 0.01, 0.03, 0.08, 0.5]

[[record]]
file = "elcentro1940_ns_I-ELC180_peer2000.AT2"
window_s = [0.0, 12.0]

[[record]]
synthetic = { seed = 3, duration_s = 10.0, dt_s = 0.01 }

[intensity]
pga_g = 0.4
"#;

pub fn plan(text: &str) -> PairPlan {
    config::parse(
        text,
        Path::new("shared.toml"),
        Path::new("."),
        &records_dir(),
    )
    .unwrap()
}

fn assert_same_but_work(label: &str, stepped: &RunOutput, shared: &RunOutput) {
    assert_eq!(without_work(stepped), without_work(shared), "{label}");
    assert_eq!(stepped.shared_steps, 0, "{label}");
    assert_eq!(
        shared.free_steps + shared.shared_steps,
        stepped.free_steps,
        "{label}: the steps settled by the shared response are free steps the run no longer takes"
    );
}

/// Each run, stepped whole and with its group's shared response, at gaps from the grid and at
/// gaps within 1e-9 to 1e-3 of the free response's largest relative displacement (grazing: the
/// first touch and the early end are decided by slack there).
#[test]
fn shortcuts_change_nothing_but_the_work() {
    shortcuts_change_nothing(false);
}

/// The same with each building's peak acceleration tracked (a row of two one-storey buildings
/// runs so): the response keeps the accelerations' peaks and bounds, the runs' accelerations
/// are the ones they step to, and tracking them changes no other output.
#[test]
fn shortcuts_change_nothing_with_accelerations_tracked() {
    shortcuts_change_nothing(true);
}

fn shortcuts_change_nothing(accel: bool) {
    let plan = plan(SCENES);
    let scheme = Scheme::Fast(FastOptions::default());
    let (mut runs, mut started_late, mut ended_early, mut shared, mut all) = (0, 0, 0, 0u64, 0u64);
    let mut groups = std::collections::BTreeMap::new();
    for i in 0..plan.len() {
        let spec = plan.run(i);
        let key = (spec.record, spec.t1.to_bits(), spec.xi1.to_bits());
        let key = (key, spec.m2.to_bits(), spec.t2.to_bits());
        groups.entry(key).or_insert_with(Vec::new).push(spec);
    }
    for specs in groups.values() {
        let forcing = plan.forcing(&specs[0]);
        let pair = specs[0].pair();
        let response = if accel {
            FreeResponse::with_accel(&pair.b1, &pair.b2, &forcing)
        } else {
            FreeResponse::new(&pair.b1, &pair.b2, &forcing)
        };
        // The free response's largest u1 - u2, from a run that cannot touch.
        let mut far = pair;
        far.gap = 1e9;
        let mut reach = 0.0f64;
        let mut obs = |s: &pounding::physics::solver::Sample| reach = reach.max(s.z[0] - s.z[2]);
        simulate_observed(&far, &forcing, &Initial::default(), &scheme, Some(&mut obs));
        let grazing = [-1e-3, -1e-6, -1e-9, 0.0, 1e-9, 1e-6, 1e-3].map(|f| reach * (1.0 + f));
        let gaps = specs.iter().map(|s| s.gap).chain(grazing);
        for gap in gaps {
            let mut p = pair;
            p.gap = gap;
            let label = format!("{:?} gap {gap:e}", specs[0]);
            let (stepped, fast) = if accel {
                let o = FastOptions::default();
                let stepped = simulate_tracking_accel(&p, &forcing, &o, None, None);
                let fast = simulate_tracking_accel(&p, &forcing, &o, Some(&response), None);
                assert!(stepped.peak_accel.iter().all(|&a| a > 0.0), "{label}");
                let mut untracked = simulate(&p, &forcing, &Initial::default(), &scheme);
                untracked.peak_accel = stepped.peak_accel;
                assert_eq!(untracked, stepped, "{label}: tracking changes nothing else");
                (stepped, fast)
            } else {
                let stepped = simulate(&p, &forcing, &Initial::default(), &scheme);
                let fast = simulate_shared(&p, &forcing, &Initial::default(), &scheme, &response);
                (stepped, fast)
            };
            assert_same_but_work(&label, &stepped, &fast);
            let first = response.first_possible_contact(gap) as u64;
            runs += 1;
            started_late += (first > 0) as u32;
            ended_early += (fast.shared_steps > first) as u32;
            shared += fast.shared_steps;
            all += stepped.free_steps;
        }
    }
    eprintln!("{runs} runs: {started_late} started late, {ended_early} ended early, {shared} of {all} free steps shared");
    // The shortcuts must also be taken: most runs start late, many end early, and a large
    // share of the free steps is settled (the real record's weak end and the 4 s tail).
    assert!(
        started_late * 2 > runs,
        "{started_late} of {runs} started late"
    );
    assert!(
        ended_early * 4 > runs,
        "{ended_early} of {runs} ended early"
    );
    assert!(shared * 3 > all, "{shared} of {all} free steps shared");
}

/// The engine shares a response among consecutive runs of one group (the gap axis is the
/// innermost) and hands the same rows out whatever the chunking: one run per chunk shares
/// nothing.
#[test]
fn engine_shares_within_chunks_with_the_same_rows() {
    let text = SCENES.replace("tail_s = 4.0", "tail_s = 1.0").replace(
        r#"law = ["linear", "kelvin_voigt", "kelvin_voigt_no_tension", "modified_linear", "hertz",
       "nonlinear_viscoelastic", "hunt_crossley", "lankarani_nikravesh", "flores", "hunt_crossley_exact"]"#,
        r#"law = ["kelvin_voigt_no_tension", "hertz"]"#,
    );
    let plan = plan(&text);
    let scheme = Scheme::Fast(FastOptions::default());
    let one = collect(&plan, &scheme, 1);
    let many = collect(&plan, &scheme, 64);
    assert_eq!(one.len() as u64, plan.len());
    for ((sa, a), (sb, b)) in one.iter().zip(&many) {
        assert_eq!(sa, sb);
        assert_same_but_work(&format!("run {}", sa.index), a, b);
    }
    assert!(many.iter().any(|(_, o)| o.shared_steps > 0));
    // The reference scheme never shares.
    let reference = Scheme::Reference(Default::default());
    let small = plan.len().min(12);
    let sub: Vec<_> = (0..small).map(|i| plan.run(i)).collect();
    let outs = pounding::engine::cpu::run_many(&plan, &sub, &reference);
    assert!(outs.iter().all(|o| o.shared_steps == 0));
}
