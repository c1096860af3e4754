//! Restitution fidelity: does a law with a formula's damping give the `e` it was asked for?
//! One isolated collision per law, formula and `e` (the seed paper's energy check, done for every
//! formula in every damped law), and the hysteresis loop of one impact.

use crate::physics::contact::{Contact, LawKind};
use crate::physics::restitution::{damping_for, Formula, RestitutionError};
use crate::physics::solver::{single_collision_observed, Mode, Sample, EXACT_RTOL};
use crate::studies::plot::{Panel, Series};

/// One isolated collision of a law with a formula's damping, in units where `m_eff = 1`, the
/// stiffness is 1 and `v0 = 1` (for these laws `e` depends on the dimensionless damping alone).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fidelity {
    pub law: LawKind,
    /// None for the Hunt-Crossley laws, whose damping follows from `e` by their own formula.
    pub formula: Option<Formula>,
    /// The `e` asked for.
    pub e: f64,
    /// zeta, or `a` in `chi = a / v0`.
    pub damping: f64,
    /// `-delta'_out / delta'_in` of the simulated collision.
    pub achieved_e: f64,
    /// Energy the contact took out, over `0.5 m_eff (1 - e^2) v0^2` for the `e` asked for
    /// (1 when the formula is right; NaN at e = 1).
    pub energy_ratio: f64,
}

/// Every damped law with every formula it takes (Hunt-Crossley laws: their own), over `es`.
pub fn table(es: &[f64]) -> Result<Vec<Fidelity>, RestitutionError> {
    use rayon::prelude::*;
    let mut cases = Vec::new();
    for law in LawKind::ALL.into_iter().filter(|l| l.is_damped()) {
        let formulas: Vec<Option<Formula>> = if law.uses_zeta() {
            Formula::ALL.into_iter().map(Some).collect()
        } else {
            vec![None]
        };
        for formula in formulas {
            cases.extend(es.iter().map(|&e| (law, formula, e)));
        }
    }
    cases
        .into_par_iter()
        .map(|(law, formula, e)| {
            let damping = damping_for(law, formula.unwrap_or(Formula::Exact), e)?;
            let c = crate::physics::solver::single_collision(
                &Contact::new(law, 1.0, damping, 1.0),
                1.0,
                EXACT_RTOL,
            );
            Ok(Fidelity {
                law,
                formula,
                e,
                damping,
                achieved_e: c.e,
                energy_ratio: c.dissipated / (0.5 * (1.0 - e * e)),
            })
        })
        .collect()
}

/// Force against penetration through one impact, and the loop's enclosed area.
#[derive(Debug, Clone, PartialEq)]
pub struct Loop {
    /// `(delta, F)` at every step in contact, m and N.
    pub points: Vec<(f64, f64)>,
    /// `closed integral F d(delta)` by the trapezoid rule over `points`, J.
    pub area: f64,
    /// The contact's work on the relative motion from the integrator, J.
    pub dissipated: f64,
    pub achieved_e: f64,
}

/// The hysteresis loop of one isolated collision at approach speed `v0`.
pub fn hysteresis(contact: &Contact, v0: f64) -> Loop {
    let mut points = Vec::new();
    let mut obs = |s: &Sample| {
        if s.mode != Mode::Free || points.is_empty() {
            points.push((s.z[0] - s.z[2], s.force));
        }
    };
    // Dense samples: the area is a trapezoid sum over them (error ~ 1/steps^2).
    let c = single_collision_observed(contact, v0, 1e-10, 2000.0, &mut obs);
    // Close the loop at separation (delta = 0, F = 0).
    points.push((0.0, 0.0));
    let area = points
        .windows(2)
        .map(|w| 0.5 * (w[0].1 + w[1].1) * (w[1].0 - w[0].0))
        .sum();
    Loop {
        points,
        area,
        dissipated: c.dissipated,
        achieved_e: c.e,
    }
}

/// The table as CSV text.
pub fn csv(rows: &[Fidelity]) -> String {
    let mut s = String::from("law,formula,e,damping,achieved_e,e_error,energy_ratio\n");
    for r in rows {
        s.push_str(&format!(
            "{},{},{},{},{},{},{}\n",
            r.law.key(),
            r.formula.map_or(r.law.key(), |f| f.key()),
            r.e,
            r.damping,
            r.achieved_e,
            r.achieved_e - r.e,
            r.energy_ratio
        ));
    }
    s
}

/// Largest `|achieved_e - e|` per law (rows) and formula (columns), as a markdown table.
pub fn summary(rows: &[Fidelity]) -> String {
    let mut s = String::from("| law | ");
    s.push_str(&Formula::ALL.map(|f| f.key()).join(" | "));
    s.push_str(" | own |\n|---|");
    s.push_str(&"---:|".repeat(Formula::ALL.len() + 1));
    s.push('\n');
    for law in LawKind::ALL.into_iter().filter(|l| l.is_damped()) {
        let worst = |f: Option<Formula>| {
            rows.iter()
                .filter(|r| r.law == law && r.formula == f)
                .map(|r| (r.achieved_e - r.e).abs())
                .fold(None, |m: Option<f64>, x| Some(m.map_or(x, |m| m.max(x))))
                .map_or("-".to_string(), |x| format!("{x:.3}"))
        };
        let mut cells: Vec<String> = Formula::ALL.into_iter().map(|f| worst(Some(f))).collect();
        cells.push(worst(None));
        s.push_str(&format!("| {} | {} |\n", law.key(), cells.join(" | ")));
    }
    s
}

/// One panel per law: achieved `e` against the `e` asked for, one series per formula.
pub fn panels(rows: &[Fidelity]) -> Vec<Panel> {
    let mut out = Vec::new();
    for law in LawKind::ALL.into_iter().filter(|l| l.is_damped()) {
        let mine: Vec<&Fidelity> = rows.iter().filter(|r| r.law == law).collect();
        let es: Vec<f64> = mine.iter().map(|r| r.e).collect();
        let mut series = vec![Series {
            name: "achieved = asked".into(),
            points: es.iter().map(|&e| (e, e)).collect(),
            scatter: false,
            style: None,
        }];
        let mut formulas: Vec<Option<Formula>> = mine.iter().map(|r| r.formula).collect();
        formulas.dedup();
        for f in formulas {
            series.push(Series {
                name: f.map_or(law.key(), |f| f.key()).to_string(),
                points: mine
                    .iter()
                    .filter(|r| r.formula == f)
                    .map(|r| (r.e, r.achieved_e))
                    .collect(),
                scatter: true,
                style: None,
            });
        }
        out.push(Panel {
            title: law.key().to_string(),
            x_label: "e asked for".into(),
            y_label: "e achieved".into(),
            series,
            ..Default::default()
        });
    }
    out
}

/// `pound hysteresis`: one isolated collision per `e` of `law` with `formula`'s damping.
#[derive(Debug, Clone, PartialEq)]
pub struct Loops {
    /// Per `e`: e, the damping, and its loop.
    pub loops: Vec<(f64, f64, Loop)>,
    pub law: LawKind,
    pub formula: Formula,
    pub v0: f64,
    pub m_eff: f64,
}

/// The loops of `law` with `formula`'s damping at each of `es`: approach speed `v0`, stiffness
/// `stiffness` (k or beta), effective mass `m_eff`.
pub fn loops(
    law: LawKind,
    formula: Formula,
    es: &[f64],
    v0: f64,
    stiffness: f64,
    m_eff: f64,
) -> Result<Loops, RestitutionError> {
    let loops = es
        .iter()
        .map(|&e| {
            let d = damping_for(law, formula, e)?;
            Ok((
                e,
                d,
                hysteresis(&Contact::new(law, stiffness, d, m_eff), v0),
            ))
        })
        .collect::<Result<_, RestitutionError>>()?;
    Ok(Loops {
        loops,
        law,
        formula,
        v0,
        m_eff,
    })
}

impl Loops {
    /// Every loop point as CSV (e, delta_m, force_n).
    pub fn csv(&self) -> String {
        let mut csv = String::from("e,delta_m,force_n\n");
        for (e, _, l) in &self.loops {
            for (x, f) in &l.points {
                csv.push_str(&format!("{e},{x},{f}\n"));
            }
        }
        csv
    }

    /// A markdown table: per `e`, the damping, the achieved e, the loop area and the energy
    /// `0.5 m_eff (1 - e^2) v0^2` it should take out.
    pub fn markdown(&self) -> String {
        let mut s = String::from("| e | damping | achieved e | loop area J | 0.5 m_eff (1-e^2) v0^2 J |\n|---:|---:|---:|---:|---:|\n");
        for (e, d, l) in &self.loops {
            s.push_str(&format!(
                "| {e} | {d:.6} | {:.6} | {:.6e} | {:.6e} |\n",
                l.achieved_e,
                l.area,
                0.5 * self.m_eff * (1.0 - e * e) * self.v0 * self.v0
            ));
        }
        s
    }

    /// Force (kN) against penetration (mm), one series per `e`.
    pub fn panel(&self) -> Panel {
        Panel {
            title: format!(
                "{} ({}), v0 = {} m/s",
                self.law.key(),
                self.formula.key(),
                self.v0
            ),
            x_label: "penetration (mm)".into(),
            y_label: "contact force (kN)".into(),
            series: self
                .loops
                .iter()
                .map(|(e, _, l)| Series {
                    name: format!("e = {e}"),
                    points: l.points.iter().map(|&(x, f)| (x * 1e3, f / 1e3)).collect(),
                    scatter: false,
                    style: None,
                })
                .collect(),
            ..Default::default()
        }
    }
}
