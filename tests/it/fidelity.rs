//! Restitution fidelity and hysteresis loops against analytic facts: the `exact` damping
//! reproduces `e` in every law, Anagnostopoulos' closed form is exact for Kelvin-Voigt, the
//! energy taken out of a collision is `0.5 m_eff (1 - e^2) v0^2` for the achieved `e`, and a
//! loop's enclosed area is that energy.

use crate::support::{pound_with_outputs, tempdir};
use pounding::physics::contact::{Contact, LawKind};
use pounding::physics::restitution::{damping_for, Formula};
use pounding::studies::fidelity::{hysteresis, table};

#[test]
fn exact_damping_and_anagnostopoulos_in_kelvin_voigt_reproduce_e() {
    let rows = table(&[0.2, 0.5, 0.8]).unwrap();
    // 4 zeta laws x 7 formulas + 4 Hunt-Crossley laws, 3 values of e each.
    assert_eq!(rows.len(), (4 * 7 + 4) * 3);
    for r in &rows {
        assert!(
            r.achieved_e.is_finite() && r.energy_ratio.is_finite(),
            "{r:?}"
        );
        // Energy out of a collision that ends at the achieved e (the solver's own balance).
        let expected = (1.0 - r.achieved_e * r.achieved_e) / (1.0 - r.e * r.e);
        assert!((r.energy_ratio - expected).abs() < 1e-6, "{r:?}");
        let exact = r.formula == Some(Formula::Exact)
            || r.law == LawKind::HuntCrossleyExact
            || (r.law == LawKind::KelvinVoigt && r.formula == Some(Formula::Anagnostopoulos));
        if exact {
            assert!((r.achieved_e - r.e).abs() < 1e-6, "{r:?}");
        }
    }
    // Formulas derived for another law are off by far more than the solver error: the check
    // can tell a right formula from a wrong one.
    let worst = rows
        .iter()
        .filter(|r| r.law == LawKind::KelvinVoigt && r.formula == Some(Formula::Barros))
        .map(|r| (r.achieved_e - r.e).abs())
        .fold(0.0, f64::max);
    assert!(worst > 0.1, "{worst}");
}

#[test]
fn hysteresis_loop_area_is_the_dissipated_energy() {
    let (m_eff, v0, e) = (5.0e4, 1.5, 0.6);
    for law in [
        LawKind::NonlinearViscoelastic,
        LawKind::KelvinVoigtNoTension,
        LawKind::HuntCrossley,
    ] {
        let d = damping_for(law, Formula::Exact, e).unwrap();
        let l = hysteresis(&Contact::new(law, 2.75e9, d, m_eff), v0);
        let expected = 0.5 * m_eff * (1.0 - l.achieved_e * l.achieved_e) * v0 * v0;
        assert!(
            (l.dissipated - expected).abs() < 1e-6 * expected,
            "{law:?}: {} {expected}",
            l.dissipated
        );
        assert!(
            (l.area - expected).abs() < 2e-3 * expected,
            "{law:?}: area {} expected {expected}",
            l.area
        );
        assert!(l.points.len() > 50, "{law:?}: {} points", l.points.len());
    }
}

#[test]
fn restitution_and_hysteresis_commands_write_csv_and_svg() {
    let d = tempdir();
    let csv = d.path().join("r.csv");
    let svg = d.path().join("r.svg");
    let table = pound_with_outputs(&["restitution", "--e", "0.4:0.8:0.2"], &csv, &svg);
    assert!(table.contains("| kelvin_voigt | 0.000 |"), "{table}");
    let text = std::fs::read_to_string(&csv).unwrap();
    assert_eq!(text.lines().count(), 1 + (4 * 7 + 4) * 3);
    let plot = std::fs::read_to_string(&svg).unwrap();
    assert!(plot.starts_with("<svg") && plot.trim_end().ends_with("</svg>"));
    for law in LawKind::ALL.into_iter().filter(|l| l.is_damped()) {
        assert!(
            plot.contains(&format!("\n{}\n", law.key())),
            "no panel for {}",
            law.key()
        );
    }
    // Per zeta-law panel: the diagonal and seven formulas in the legend.
    assert_eq!(plot.matches("\nachieved = asked\n").count(), 8);
    assert_eq!(plot.matches("\nbarros\n").count(), 4);

    let loops = d.path().join("l.csv");
    let lsvg = d.path().join("l.svg");
    pound_with_outputs(
        &[
            "hysteresis",
            "kelvin_voigt",
            "--formula",
            "exact",
            "--e",
            "0.5,0.9",
        ],
        &loops,
        &lsvg,
    );
    let text = std::fs::read_to_string(&loops).unwrap();
    assert!(text.starts_with("e,delta_m,force_n\n"));
    assert!(text.lines().filter(|l| l.starts_with("0.9,")).count() > 20);
    let plot = std::fs::read_to_string(&lsvg).unwrap();
    assert!(plot.contains("\ne = 0.5\n") && plot.contains("\ne = 0.9\n"));
}
