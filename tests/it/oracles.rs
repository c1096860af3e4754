//! Analytic oracles: each problem paired with its closed-form answer, checked on both schemes.

use crate::support::{pair, rel};
use pounding::physics::contact::{Contact, LawKind, HERTZ_TC};
use pounding::physics::model::{Forcing, Initial, Oscillator, Pair, Status};
use pounding::physics::restitution::{achieved_e, exact_damping, Formula};
use pounding::physics::solver::{
    simulate, simulate_observed, single_collision, FastOptions, ReferenceOptions, Sample, Scheme,
};
use pounding::record::{synthetic, SyntheticSpec};
use std::f64::consts::PI;

fn schemes() -> [Scheme; 2] {
    [
        Scheme::Fast(crate::support::precise_fast()),
        Scheme::Reference(ReferenceOptions::default()),
    ]
}

/// Far-apart buildings (no contact possible).
fn apart(t1: f64, xi1: f64, t2: f64, xi2: f64) -> Pair {
    pair(
        LawKind::Linear,
        1e8,
        0.0,
        (1e5, t1, xi1),
        (2e5, t2, xi2),
        1e3,
    )
}

/// Damped free vibration from an initial displacement and velocity, compared with
/// `u = e^{-xi w t} (u0 cos wd t + (v0 + xi w u0)/wd sin wd t)` at every observed point.
#[test]
fn free_vibration_matches_closed_form() {
    let (t, xi, u0, v0): (f64, f64, f64, f64) = (0.7, 0.05, 0.03, -0.1);
    let w = 2.0 * PI / t;
    let wd = w * (1.0 - xi * xi).sqrt();
    let exact = |tt: f64| {
        (-xi * w * tt).exp() * (u0 * (wd * tt).cos() + (v0 + xi * w * u0) / wd * (wd * tt).sin())
    };
    let zeros = vec![0.0; 1001];
    let forcing = Forcing {
        accel: &zeros,
        dt: 0.01,
        t0: 0.0,
        scale: 1.0,
        tail: 0.0,
    };
    let p = apart(t, xi, 1.3, 0.02);
    for scheme in schemes() {
        let mut worst: f64 = 0.0;
        let mut obs = |s: &Sample| worst = worst.max((s.z[0] - exact(s.t)).abs());
        let out = simulate_observed(
            &p,
            &forcing,
            &Initial {
                u1: u0,
                v1: v0,
                ..Default::default()
            },
            &scheme,
            Some(&mut obs),
        );
        assert_eq!(out.status, Status::Ok);
        assert_eq!(out.impacts, 0);
        assert!(worst < 1e-9 * u0, "{}: max error {worst}", scheme.key());
        assert!(
            rel(out.peak_u1, u0) < 1e-9,
            "{}: peak {}",
            scheme.key(),
            out.peak_u1
        );
        assert_eq!(out.peak_u2, 0.0);
    }
}

/// Harmonic ground motion `ag = A sin(W t)` from rest: particular plus homogeneous solution.
/// The record samples the sine at dt = T/200, so the forcing itself is off by O(dt^2).
#[test]
fn harmonic_response_matches_closed_form() {
    let (t, xi, amp, wf): (f64, f64, f64, f64) = (0.5, 0.05, 2.0, 2.0 * PI / 0.6);
    let w = 2.0 * PI / t;
    let wd = w * (1.0 - xi * xi).sqrt();
    let d = (w * w - wf * wf).powi(2) + (2.0 * xi * w * wf).powi(2);
    let (pp, qq) = (-amp * (w * w - wf * wf) / d, 2.0 * xi * w * wf * amp / d);
    let (c1, c2) = (-qq, (xi * w * (-qq) - pp * wf) / wd);
    let exact = |tt: f64| {
        pp * (wf * tt).sin()
            + qq * (wf * tt).cos()
            + (-xi * w * tt).exp() * (c1 * (wd * tt).cos() + c2 * (wd * tt).sin())
    };
    let dt = t / 200.0;
    let accel: Vec<f64> = (0..(10.0 / dt) as usize)
        .map(|i| amp * (wf * i as f64 * dt).sin())
        .collect();
    let forcing = Forcing {
        accel: &accel,
        dt,
        t0: 0.0,
        scale: 1.0,
        tail: 0.0,
    };
    let p = apart(t, xi, 1.0, 0.05);
    let peak = (amp / d.sqrt()) * 1.0;
    for scheme in schemes() {
        let mut worst: f64 = 0.0;
        let mut obs = |s: &Sample| worst = worst.max((s.z[0] - exact(s.t)).abs());
        let out = simulate_observed(&p, &forcing, &Initial::default(), &scheme, Some(&mut obs));
        assert_eq!(out.status, Status::Ok);
        assert!(
            worst < 2e-4 * peak,
            "{}: max error {worst} of steady amplitude {peak}",
            scheme.key()
        );
    }
}

/// Energy balance under a constant ground acceleration `a` from rest: the input work is
/// `-a sum m_i int v_i dt = -a (m1 u1(T) + m2 u2(T))` whatever the damping, and the damping work
/// is what the input leaves after the kinetic and strain energy. Apart and pounding (the balance
/// then also holds the contact work). The fast scheme's free steps are exact, so apart its
/// residual is rounding.
#[test]
fn energy_balance_under_constant_ground_acceleration() {
    let a = 1.5;
    let accel = vec![a; 801];
    let forcing = Forcing {
        accel: &accel,
        dt: 0.01,
        t0: 0.0,
        scale: 1.0,
        tail: 0.0,
    };
    let fast = Scheme::Fast(FastOptions {
        energy: true,
        ..crate::support::precise_fast()
    });
    let schemes = [fast, Scheme::Reference(ReferenceOptions::default())];
    // Apart; then touching: building 1 (stiffer, heavier) rests against building 2.
    let touching = pair(
        LawKind::KelvinVoigt,
        1e8,
        0.3,
        (1e5, 0.3, 0.05),
        (2e5, 1.1, 0.02),
        0.0,
    );
    for (p, bound) in [(apart(0.7, 0.05, 1.3, 0.02), 1e-12), (touching, 1e-6)] {
        for scheme in &schemes {
            let bound = match scheme {
                Scheme::Fast(_) => bound,
                Scheme::Reference(_) => 1e-8,
            };
            let mut last = None;
            let mut obs = |s: &Sample| last = Some(s.z);
            let out = simulate_observed(&p, &forcing, &Initial::default(), scheme, Some(&mut obs));
            let z = last.unwrap();
            let e = out.energy.expect("energy asked for");
            let input = -a * (p.b1.m * z[0] + p.b2.m * z[2]);
            let held = 0.5
                * (p.b1.m * z[1] * z[1]
                    + p.b1.k * z[0] * z[0]
                    + p.b2.m * z[3] * z[3]
                    + p.b2.k * z[2] * z[2]);
            let what = format!("{} gap {}", scheme.key(), p.gap);
            assert!(rel(e.input, input) < 1e-9, "{what}: {} vs {input}", e.input);
            let damping = input - held - out.dissipated_energy;
            assert!(
                (e.damping - damping).abs() < 1e-8 * input,
                "{what}: {} vs {damping}",
                e.damping
            );
            assert!(e.damping > 0.0 && e.residual.abs() < bound, "{what}: {e:?}");
            assert_eq!(out.impacts > 0, p.gap == 0.0, "{what}");
        }
    }
}

/// With a gap just above the largest free relative displacement there is no contact and each
/// building's response equals its uncoupled response; just below it, they pound.
#[test]
fn no_contact_beyond_free_relative_displacement() {
    let rec = synthetic(&SyntheticSpec {
        seed: 3,
        duration: 15.0,
        ..Default::default()
    })
    .unwrap();
    let forcing = rec.forcing(1.0, 0.0);
    let (b1, b2) = ((1e5, 0.4, 0.05), (3e5, 1.1, 0.05));
    for scheme in schemes() {
        let mut max_rel: f64 = 0.0;
        let mut obs = |s: &Sample| max_rel = max_rel.max(s.z[0] - s.z[2]);
        let _ = simulate_observed(
            &pair(LawKind::Hertz, 1e9, 0.0, b1, b2, 10.0),
            &forcing,
            &Initial::default(),
            &scheme,
            Some(&mut obs),
        );
        assert!(max_rel > 0.005, "scene too quiet: {max_rel}");
        // Uncoupled responses, each alone.
        let alone1 = simulate(
            &pair(LawKind::Hertz, 1e9, 0.0, b1, (1.0, 1.0, 0.0), 10.0),
            &forcing,
            &Initial::default(),
            &scheme,
        );
        let alone2 = simulate(
            &pair(LawKind::Hertz, 1e9, 0.0, (1.0, 1.0, 0.0), b2, 10.0),
            &forcing,
            &Initial::default(),
            &scheme,
        );
        let above = simulate(
            &pair(LawKind::Hertz, 1e9, 0.0, b1, b2, max_rel * 1.001),
            &forcing,
            &Initial::default(),
            &scheme,
        );
        assert_eq!(above.impacts, 0, "{}", scheme.key());
        assert_eq!(above.peak_force, 0.0);
        assert!(
            rel(above.peak_u1, alone1.peak_u1) < 1e-9 && rel(above.peak_u2, alone2.peak_u2) < 1e-9,
            "{}: {above:?} vs {alone1:?} {alone2:?}",
            scheme.key()
        );
        let below = simulate(
            &pair(LawKind::Hertz, 1e9, 0.0, b1, b2, max_rel * 0.95),
            &forcing,
            &Initial::default(),
            &scheme,
        );
        assert!(
            below.impacts >= 1 && below.peak_force > 0.0,
            "{}: {below:?}",
            scheme.key()
        );
    }
}

/// Undamped linear collision of free bodies: `F_max = v0 sqrt(k m_eff)`, `t_c = pi sqrt(m_eff/k)`, e = 1.
#[test]
fn undamped_linear_collision() {
    let (k, m_eff, v0) = (4e7, 250.0, 0.8);
    let c = single_collision(&Contact::new(LawKind::Linear, k, 0.0, m_eff), v0, 1e-10);
    assert!(rel(c.peak_force, v0 * (k * m_eff).sqrt()) < 1e-8, "{c:?}");
    assert!(rel(c.duration, PI * (m_eff / k).sqrt()) < 1e-8, "{c:?}");
    assert!(
        (c.e - 1.0).abs() < 1e-8 && c.dissipated.abs() < 1e-8 * 0.5 * m_eff * v0 * v0,
        "{c:?}"
    );
}

/// Undamped Hertz collision: `delta_max = (5 m_eff v0^2 / (4 beta))^(2/5)`,
/// `F_max = beta delta_max^1.5`, `t_c = 2.9433 delta_max / v0`, e = 1.
#[test]
fn undamped_hertz_collision() {
    for (beta, m_eff, v0) in [(2.75e9, 5e4, 0.5), (1e6, 10.0, 21.0)] {
        let c = single_collision(&Contact::new(LawKind::Hertz, beta, 0.0, m_eff), v0, 1e-10);
        let dmax = (1.25 * m_eff * v0 * v0 / beta).powf(0.4);
        assert!(rel(c.peak_penetration, dmax) < 1e-8, "{c:?} vs {dmax}");
        assert!(rel(c.peak_force, beta * dmax.powf(1.5)) < 1e-8, "{c:?}");
        assert!(rel(c.duration, HERTZ_TC * dmax / v0) < 1e-6, "{c:?}");
        assert!((c.e - 1.0).abs() < 1e-8, "{c:?}");
    }
}

/// The fast scheme on the same isolated collision (free masses, no ground motion).
#[test]
fn fast_scheme_single_collision() {
    let (k, m, v0) = (1e8, 2e4, 0.3);
    let contact = Contact::new(LawKind::Linear, k, 0.0, m / 2.0);
    let p = Pair {
        b1: Oscillator::free(m),
        b2: Oscillator::free(m),
        gap: 0.001,
        contact,
    };
    let zeros = [0.0; 3];
    let forcing = Forcing {
        accel: &zeros,
        dt: 0.02,
        t0: 0.0,
        scale: 0.0,
        tail: 0.0,
    };
    let out = simulate(
        &p,
        &forcing,
        &Initial {
            v1: v0 / 2.0,
            v2: -v0 / 2.0,
            ..Default::default()
        },
        &Scheme::Fast(crate::support::precise_fast()),
    );
    assert_eq!(out.impacts, 1);
    assert!(rel(out.first_impact.unwrap(), 0.001 / v0) < 1e-9, "{out:?}");
    assert!(
        rel(out.peak_force, v0 * (k * m / 2.0).sqrt()) < 1e-6,
        "{out:?}"
    );
    assert!(
        rel(out.contact_time, PI * (m / 2.0 / k).sqrt()) < 1e-6,
        "{out:?}"
    );
    assert!(rel(out.impact_velocity, v0) < 1e-9, "{out:?}");
}

/// Kelvin-Voigt with tension, zeta from Anagnostopoulos' formula: e reproduced exactly, for any
/// stiffness, mass and speed (dimensionless problem).
#[test]
fn kelvin_voigt_reproduces_anagnostopoulos() {
    for &e in &[0.1, 0.3, 0.5, 0.65, 0.8, 0.95] {
        let z = Formula::Anagnostopoulos.zeta(e).unwrap().unwrap();
        for (k, m_eff, v0) in [(1.0, 1.0, 1.0), (3e9, 7e4, 0.4)] {
            let c = single_collision(&Contact::new(LawKind::KelvinVoigt, k, z, m_eff), v0, 1e-10);
            assert!((c.e - e).abs() < 1e-7, "e {e}: achieved {} (k {k})", c.e);
            let lost = 0.5 * m_eff * (1.0 - e * e) * v0 * v0;
            assert!(
                rel(c.dissipated, lost) < 1e-6,
                "e {e}: dissipated {} expected {lost}",
                c.dissipated
            );
        }
    }
}

/// `exact` reproduces its target e to 1e-4 in every damped law (checked at a different
/// stiffness, mass and speed than the dimensionless solve), and the energy lost matches.
#[test]
fn exact_reproduces_target_e_in_every_damped_law() {
    for law in LawKind::ALL
        .into_iter()
        .filter(|l| l.uses_zeta() || *l == LawKind::HuntCrossleyExact)
    {
        for &e in &[0.1, 0.4, 0.71, 0.9] {
            let d = exact_damping(law, e).unwrap();
            let stiffness = if law.is_hertzian() { 2.75e9 } else { 5e8 };
            let (m_eff, v0) = (3.3e4, 0.35);
            let c = single_collision(&Contact::new(law, stiffness, d, m_eff), v0, 1e-10);
            assert!(
                (c.e - e).abs() < 1e-4,
                "{}: e {e}, damping {d}, achieved {}",
                law.key(),
                c.e
            );
            let lost = 0.5 * m_eff * (1.0 - e * e) * v0 * v0;
            assert!(
                rel(c.dissipated, lost) < 3e-4,
                "{}: e {e}: dissipated {} expected {lost}",
                law.key(),
                c.dissipated
            );
        }
    }
}

/// Achieved e falls with damping in every damped law (what the root-finding relies on): strictly
/// while the bodies still separate, and Kelvin-Voigt with tension never separates once
/// overdamped (zeta >= 1), so e = 0 there.
#[test]
fn achieved_e_falls_with_damping() {
    for law in LawKind::ALL
        .into_iter()
        .filter(|l| l.uses_zeta() || *l == LawKind::HuntCrossleyExact)
    {
        let es: Vec<f64> = [0.0, 0.05, 0.2, 0.5, 0.9, 2.0, 8.0]
            .iter()
            .map(|&d| achieved_e(law, d))
            .collect();
        assert!((es[0] - 1.0).abs() < 1e-8, "{}: {es:?}", law.key());
        assert!(
            es.iter().all(|e| e.is_finite() && *e >= 0.0),
            "{}: {es:?}",
            law.key()
        );
        assert!(
            es.windows(2).all(|w| w[1] < w[0] || w[0] < 1e-12),
            "{}: {es:?}",
            law.key()
        );
    }
    let kv = |z: f64| achieved_e(LawKind::KelvinVoigt, z);
    assert!(kv(1.0) < 1e-6 && kv(2.0) < 1e-6, "{} {}", kv(1.0), kv(2.0));
}

/// The seed's stated values of eq. (22): "zeta(0.1) = 7.269" and "zeta <= 1 needs e > 0.33".
/// Eq. (22) as printed gives 7.248 at e = 0.1 (0.3 % below the stated value) and crosses 1 at
/// e = 0.327; both checks pin what the printed formula gives and how far the claims are.
#[test]
fn ebrahimi_formula_stated_values() {
    let z = |e: f64| Formula::Ebrahimi.zeta(e).unwrap().unwrap();
    let z01 = (6.0 * 0.99 / (7.0 * PI.sqrt() * 0.1f64.powf(0.75))).powi(2);
    assert!(
        (z(0.1) - z01).abs() < 1e-12 && (z(0.1) - 7.248).abs() < 1e-3,
        "{}",
        z(0.1)
    );
    assert!(
        rel(z(0.1), 7.269) < 0.003,
        "stated 7.269, printed formula gives {}",
        z(0.1)
    );
    // Where zeta = 1 (stated: e > 0.33): studies::paper_table1_and_fig2.
    assert!(z(1.0).abs() < 1e-15);
}

/// Halving the reference tolerance changes peak force by less than that tolerance.
#[test]
fn reference_tolerance_is_converged() {
    let rec = synthetic(&SyntheticSpec {
        seed: 11,
        duration: 10.0,
        ..Default::default()
    })
    .unwrap();
    let forcing = rec.forcing(1.0, 0.0);
    for (law, k, d) in [
        (LawKind::NonlinearViscoelastic, 2.75e9, 0.35),
        (LawKind::KelvinVoigt, 1e9, 0.2),
        (LawKind::HuntCrossley, 2.75e9, 0.5),
    ] {
        let p = pair(law, k, d, (1e5, 0.5, 0.05), (1e5, 1.2, 0.05), 0.002);
        let tol = pounding::physics::solver::reference::DEFAULT_TOL;
        let a = simulate(
            &p,
            &forcing,
            &Initial::default(),
            &Scheme::Reference(ReferenceOptions::with_tol(tol)),
        );
        let b = simulate(
            &p,
            &forcing,
            &Initial::default(),
            &Scheme::Reference(ReferenceOptions::with_tol(tol / 2.0)),
        );
        assert!(
            a.impacts > 0 && a.impacts == b.impacts,
            "{}: {a:?} {b:?}",
            law.key()
        );
        assert!(
            rel(a.peak_force, b.peak_force) < tol,
            "{}: {} vs {}",
            law.key(),
            a.peak_force,
            b.peak_force
        );
        // Dissipated energy converges more slowly (its integrand carries the delta^(1/4) onset
        // singularity of the nonlinear viscoelastic law at every touch): within 5 tol.
        assert!(
            rel(a.dissipated_energy, b.dissipated_energy) < 5.0 * tol,
            "{}: {} vs {}",
            law.key(),
            a.dissipated_energy,
            b.dissipated_energy
        );
    }
}
