//! Impact damping ratio formulas `zeta(e)` (physics.md section 3, as printed in the seed paper),
//! and `exact`: the damping that makes one isolated collision in a given law reproduce `e`.
//!
//! Formulas (7) Barros and (8) Khatami could not be checked against their original papers; they
//! are implemented exactly as the seed prints them.

use crate::physics::contact::{Contact, LawKind};

/// A restitution formula. Keys are the config/CSV spelling.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Formula {
    Anagnostopoulos,
    MahmoudJankowski,
    Jankowski,
    Barros,
    Khatami,
    Ebrahimi,
    Exact,
}

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RestitutionError {
    #[error("coefficient of restitution e = {e} is out of range: expected {E_EXPECTED}")]
    OutOfRange { e: f64 },
    #[error("no damping reproduces e = {e} in the {law} law (searched up to {limit})")]
    NotFound {
        e: f64,
        law: &'static str,
        limit: f64,
    },
    #[error("the single-collision solve failed in the {law} law at damping {damping}")]
    SolveFailed { law: &'static str, damping: f64 },
    #[error("the {law} law takes no restitution formula")]
    NotDamped { law: &'static str },
}

/// The smallest coefficient of restitution taken. Below it an impact is practically plastic
/// (measured e of concrete, steel and timber pounding lie from about 0.4 to 0.9), and the
/// `exact` damping's search costs as 1/e: `pound restitution --e 1e-3` ran for minutes, a sweep
/// at e = 1e-4 printed nothing for as long.
pub const MIN_E: f64 = 0.01;

/// What `e` must be, in an error's words.
pub const E_EXPECTED: &str =
    "0.01 <= e <= 1 (below 0.01 an impact is practically plastic, and the exact damping's search costs as 1/e)";

/// Whether `e` is a coefficient of restitution this crate takes (`MIN_E <= e <= 1`; not NaN).
pub fn e_in_range(e: f64) -> bool {
    (MIN_E..=1.0).contains(&e)
}

/// Check `MIN_E <= e <= 1` (rejects NaN).
pub fn check_e(e: f64) -> Result<f64, RestitutionError> {
    if e_in_range(e) {
        Ok(e)
    } else {
        Err(RestitutionError::OutOfRange { e })
    }
}

impl Formula {
    pub const ALL: [Formula; 7] = [
        Formula::Anagnostopoulos,
        Formula::MahmoudJankowski,
        Formula::Jankowski,
        Formula::Barros,
        Formula::Khatami,
        Formula::Ebrahimi,
        Formula::Exact,
    ];

    pub fn key(self) -> &'static str {
        match self {
            Formula::Anagnostopoulos => "anagnostopoulos",
            Formula::MahmoudJankowski => "mahmoud_jankowski",
            Formula::Jankowski => "jankowski",
            Formula::Barros => "barros",
            Formula::Khatami => "khatami",
            Formula::Ebrahimi => "ebrahimi",
            Formula::Exact => "exact",
        }
    }

    pub fn from_key(s: &str) -> Option<Formula> {
        Formula::ALL.into_iter().find(|f| f.key() == s)
    }

    pub fn keys() -> String {
        Formula::ALL.map(|f| f.key()).join(", ")
    }

    /// `zeta(e)` of a printed formula; `None` for `Exact`, which depends on the law
    /// (see [`exact_damping`]).
    pub fn zeta(self, e: f64) -> Result<Option<f64>, RestitutionError> {
        let e = check_e(e)?;
        let pi = std::f64::consts::PI;
        let z: f64 = match self {
            Formula::Anagnostopoulos => -e.ln() / (pi * pi + e.ln() * e.ln()).sqrt(),
            Formula::MahmoudJankowski => (1.0 - e * e) / (e * (e * (pi - 2.0) + 2.0)),
            Formula::Jankowski => {
                4.5 * 5f64.sqrt() * (1.0 - e * e) / (e * (e * (9.0 * pi - 16.0) + 16.0))
            }
            Formula::Barros => {
                let x = 2.0 * (1.0 - e * e) / (e * pi.sqrt());
                x * x
            }
            Formula::Khatami => {
                let alpha = 1.05 * e.powf(0.653);
                e.powf(0.204) * (1.0 - e) / (e.powf(alpha + 0.204) + 3.351 * e * pi)
            }
            Formula::Ebrahimi => {
                let x = 6.0 * (1.0 - e * e) / (7.0 * pi.sqrt() * e.powf(0.75));
                x * x
            }
            Formula::Exact => return Ok(None),
        };
        // + 0.0 turns the -0 of -ln(1) into 0.
        Ok(Some(z + 0.0))
    }
}

/// Dimensionless damping (`zeta`, or `a` in `chi = a/v0` for Hunt-Crossley laws) for `law`,
/// `formula` and `e`. Elastic laws give 0. Calls [`exact_damping`] for `Formula::Exact` and
/// `LawKind::HuntCrossleyExact`; callers that resolve many runs cache it (it depends on the law
/// and `e` only).
pub fn damping_for(law: LawKind, formula: Formula, e: f64) -> Result<f64, RestitutionError> {
    if !law.is_damped() {
        return Ok(0.0);
    }
    let e = check_e(e)?;
    if let Some(a) = law.chi_coefficient(e) {
        return Ok(a);
    }
    if law == LawKind::HuntCrossleyExact {
        return exact_damping(law, e);
    }
    match formula.zeta(e)? {
        Some(z) => Ok(z),
        None => exact_damping(law, e),
    }
}

/// Coefficient of restitution achieved by one isolated collision of two free bodies in `law`
/// with dimensionless damping `d` (zeta, or `a` for Hunt-Crossley). For these laws it depends on
/// `d` alone, so the collision is solved in units where `m_eff = 1`, stiffness 1, `v0 = 1`.
pub fn achieved_e(law: LawKind, d: f64) -> f64 {
    let contact = Contact::new(law, 1.0, d, 1.0);
    crate::physics::solver::single_collision(&contact, 1.0, crate::physics::solver::EXACT_RTOL).e
}

fn solved_e(law: LawKind, d: f64) -> Result<f64, RestitutionError> {
    let e = achieved_e(law, d);
    if e.is_finite() {
        Ok(e)
    } else {
        Err(RestitutionError::SolveFailed {
            law: law.key(),
            damping: d,
        })
    }
}

/// The damping that makes one isolated collision in `law` reproduce `e` (to about 1e-10).
/// `e(d)` falls monotonically from 1 at `d = 0`; bracket by doubling, then bisect.
pub fn exact_damping(law: LawKind, e: f64) -> Result<f64, RestitutionError> {
    let e = check_e(e)?;
    if !law.is_damped() {
        return Err(RestitutionError::NotDamped { law: law.key() });
    }
    if e == 1.0 {
        return Ok(0.0);
    }
    let limit = 1e6;
    let (mut lo, mut hi) = (0.0f64, 0.5f64);
    while solved_e(law, hi)? > e {
        lo = hi;
        hi *= 2.0;
        if hi > limit {
            return Err(RestitutionError::NotFound {
                e,
                law: law.key(),
                limit,
            });
        }
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if solved_e(law, mid)? > e {
            lo = mid;
        } else {
            hi = mid;
        }
        if hi - lo <= 1e-12 * hi {
            break;
        }
    }
    Ok(0.5 * (lo + hi))
}
