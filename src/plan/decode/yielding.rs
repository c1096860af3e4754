//! A building's yielding storeys decoded from its `[[building]]` keys.

use crate::config::axis::Axis;
use crate::config::error::ConfigError;
use crate::config::row::{PerStorey, RawShearBuilding, YieldDrift};
use crate::plan::axes::{check_axis, Check};
use crate::plan::row::{YieldSpec, YieldStrength, YIELD_DRIFT, YIELD_SHEAR};

/// The keys of one building's storeys: `n` of them; `key` names a key, `invalid` makes its
/// error.
struct Storeys<'a> {
    n: usize,
    key: &'a dyn Fn(&str) -> String,
    invalid: &'a dyn Fn(&str, String) -> ConfigError,
}

impl Storeys<'_> {
    /// One value for every storey, or one per storey, each within `ok` (`expected` says what).
    fn per_storey(
        &self,
        name: &str,
        v: &PerStorey,
        ok: &dyn Fn(f64) -> bool,
        expected: &str,
    ) -> Result<Vec<f64>, ConfigError> {
        let n = self.n;
        let values = match v {
            PerStorey::One(x) => vec![*x; n],
            PerStorey::Each(v) if v.len() == n => v.clone(),
            PerStorey::Each(v) => {
                return Err((self.invalid)(
                    &(self.key)(name),
                    format!(
                        "{} values for {n} storeys: give one, or one per storey",
                        v.len()
                    ),
                ))
            }
        };
        match values.iter().position(|x| !ok(*x)) {
            Some(i) => Err((self.invalid)(
                &format!("{}[{i}]", (self.key)(name)),
                format!(
                    "{} is out of range: expected {expected}",
                    crate::plan::limits::show(values[i])
                ),
            )),
            None => Ok(values),
        }
    }

    /// The values of the axis `a` at key `name`, each within `check`.
    fn values(&self, name: &str, a: &Axis, (ok, expected): Check) -> Result<Vec<f64>, ConfigError> {
        let key = (self.key)(name);
        let v = a.values().map_err(|m| (self.invalid)(&key, m))?;
        check_axis(&key, &v, ok, expected).map_err(|e| (self.invalid)(&e.key, e.message))?;
        Ok(v)
    }
}

/// A building's yielding storeys as its `[[building]]` gives them (`key` names its keys), or
/// None where it gives none (elastic).
pub(crate) fn parse_yielding(
    r: &RawShearBuilding,
    n: usize,
    (sampled_drift, sampled_shear): (bool, bool),
    key: &dyn Fn(&str) -> String,
    invalid: &dyn Fn(&str, String) -> ConfigError,
) -> Result<Option<YieldSpec>, ConfigError> {
    for (sampled, given, name) in [
        (
            sampled_drift,
            r.yield_drift_ratio.is_some(),
            "yield_drift_ratio",
        ),
        (
            sampled_shear,
            r.yield_base_shear_coefficient.is_some(),
            "yield_base_shear_coefficient",
        ),
    ] {
        if sampled && given {
            return Err(invalid(
                &key(name),
                format!("{} is sampled under [sample]: remove it here", key(name)),
            ));
        }
    }
    check_damping_stiffness(r, key, invalid)?;
    let storeys = Storeys { n, key, invalid };
    let strengths = [
        r.yield_drift_ratio.is_some() || sampled_drift,
        r.yield_force_n.is_some(),
        r.yield_base_shear_coefficient.is_some() || sampled_shear,
    ];
    let (strength, axis) = match strengths.iter().filter(|&&x| x).count() {
        0 => {
            for (given, name) in [
                (r.post_yield_ratio.is_some(), "post_yield_ratio"),
                (
                    r.yield_shear_distribution.is_some(),
                    "yield_shear_distribution",
                ),
            ] {
                if given {
                    return Err(invalid(
                        &key(name),
                        "is given, but the storeys have no strength: give yield_drift_ratio, yield_force_n or yield_base_shear_coefficient".into(),
                    ));
                }
            }
            return Ok(None);
        }
        1 => strength(r, sampled_drift, &storeys)?,
        _ => {
            return Err(invalid(
                &key("yield_drift_ratio"),
                "give one of yield_drift_ratio, yield_force_n and yield_base_shear_coefficient, not several".into(),
            ))
        }
    };
    if r.yield_shear_distribution.is_some() && !matches!(strength, YieldStrength::BaseShear { .. })
    {
        return Err(invalid(
            &key("yield_shear_distribution"),
            "applies to yield_base_shear_coefficient only".into(),
        ));
    }
    let post_yield = match &r.post_yield_ratio {
        Some(v) => storeys.per_storey(
            "post_yield_ratio",
            v,
            &|x| (0.0..1.0).contains(&x),
            "a ratio >= 0 and < 1",
        )?,
        None => vec![0.0; n],
    };
    Ok(Some(YieldSpec {
        strength,
        post_yield,
        axis,
    }))
}

/// `damping_stiffness`: `initial`, the only choice.
fn check_damping_stiffness(
    r: &RawShearBuilding,
    key: &dyn Fn(&str) -> String,
    invalid: &dyn Fn(&str, String) -> ConfigError,
) -> Result<(), ConfigError> {
    match r.damping_stiffness.as_deref() {
        None | Some("initial") => Ok(()),
        Some("tangent") => Err(invalid(
            &key("damping_stiffness"),
            "`tangent` is not offered: damping on the tangent stiffness can create spurious damping forces once storeys yield; the damping is built on the initial stiffness (`initial`)".into(),
        )),
        Some(other) => Err(invalid(
            &key("damping_stiffness"),
            format!("`{other}`: expected initial"),
        )),
    }
}

/// The one strength a building gives (or samples), and its one value as an axis where it has
/// one (a placeholder where sampled).
fn strength(
    r: &RawShearBuilding,
    sampled_drift: bool,
    storeys: &Storeys,
) -> Result<(YieldStrength, Option<Vec<f64>>), ConfigError> {
    if sampled_drift {
        Ok((
            YieldStrength::DriftRatio(vec![f64::NAN; storeys.n]),
            Some(vec![f64::NAN]),
        ))
    } else if let Some(v) = &r.yield_drift_ratio {
        drift_strength(v, storeys)
    } else if let Some(v) = &r.yield_force_n {
        let force = storeys.per_storey(
            "yield_force_n",
            v,
            &|x| x > 0.0 && x.is_finite(),
            "a force > 0 N",
        )?;
        Ok((YieldStrength::Force(force), None))
    } else {
        base_shear_strength(r, storeys)
    }
}

/// `yield_drift_ratio`: one value, one per storey, or a range (an axis of values each for
/// every storey).
fn drift_strength(
    v: &YieldDrift,
    storeys: &Storeys,
) -> Result<(YieldStrength, Option<Vec<f64>>), ConfigError> {
    let mut axis = None;
    let one = match v {
        YieldDrift::One(x) => PerStorey::One(*x),
        YieldDrift::Each(v) => PerStorey::Each(v.clone()),
        YieldDrift::Axis(range) => {
            let v = storeys.values(
                "yield_drift_ratio",
                &Axis::Range(range.clone()),
                YIELD_DRIFT,
            )?;
            let first = v[0];
            axis = Some(v);
            PerStorey::One(first)
        }
    };
    let theta = storeys.per_storey("yield_drift_ratio", &one, &YIELD_DRIFT.0, YIELD_DRIFT.1)?;
    Ok((YieldStrength::DriftRatio(theta), axis))
}

/// `yield_base_shear_coefficient` (an axis where it takes two values or more, a placeholder
/// where sampled) and `yield_shear_distribution`.
fn base_shear_strength(
    r: &RawShearBuilding,
    storeys: &Storeys,
) -> Result<(YieldStrength, Option<Vec<f64>>), ConfigError> {
    let mut axis = None;
    let coefficient = match &r.yield_base_shear_coefficient {
        Some(a) => {
            let v = storeys.values("yield_base_shear_coefficient", a, YIELD_SHEAR)?;
            let first = v[0];
            if v.len() > 1 {
                axis = Some(v);
            }
            first
        }
        None => {
            axis = Some(vec![f64::NAN]);
            f64::NAN
        }
    };
    let triangular = match r.yield_shear_distribution.as_deref() {
        None | Some("inverted_triangular") => true,
        Some("uniform") => false,
        Some(other) => {
            return Err((storeys.invalid)(
                &(storeys.key)("yield_shear_distribution"),
                format!("`{other}`: expected inverted_triangular or uniform"),
            ))
        }
    };
    Ok((
        YieldStrength::BaseShear {
            coefficient,
            triangular,
        },
        axis,
    ))
}
