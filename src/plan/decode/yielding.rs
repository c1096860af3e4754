//! A building's yielding storeys decoded from its `[[building]]` keys: their strength, their
//! hardening, and where `hysteresis` names an IMK rule, their capping and deterioration.

use crate::config::axis::Axis;
use crate::config::error::ConfigError;
use crate::config::row::{PerStorey, RawShearBuilding, StoreyValues, YieldDrift};
use crate::physics::shear::{Deterioration, ImkRule};
use crate::plan::axes::{check_axis, Check};
use crate::plan::deterioration::{hysteresis, ImkKey, ImkSpec, HYSTERESIS_WORDS};
use crate::plan::row::{YieldSpec, YieldStrength};
use crate::plan::row_sampled::{YIELD_DRIFT, YIELD_SHEAR};

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

    /// A value for every storey, one per storey, or an axis, each within `check`: the values
    /// per storey (an axis's first for every storey), and the axis's values where it is one.
    fn storey_values(
        &self,
        name: &str,
        v: &StoreyValues,
        (ok, expected): Check,
    ) -> Result<(Vec<f64>, Option<Vec<f64>>), ConfigError> {
        let one = match v {
            StoreyValues::One(x) => PerStorey::One(*x),
            StoreyValues::Each(v) => PerStorey::Each(v.clone()),
            StoreyValues::Axis(range) => {
                let v = self.values(name, &Axis::Range(range.clone()), (ok, expected))?;
                return Ok((vec![v[0]; self.n], Some(v)));
            }
        };
        Ok((self.per_storey(name, &one, &ok, expected)?, None))
    }
}

/// A building's yielding storeys as its `[[building]]` gives them (`key` names its keys), or
/// None where it gives none (elastic).
///
/// `sampled_drift`: the largest yield drift ratio `[sample]` draws, where it samples it;
/// `sampled_imk`: the IMK keys it samples, with their draws.
pub(crate) fn parse_yielding(
    r: &RawShearBuilding,
    n: usize,
    (sampled_drift, sampled_shear): (Option<f64>, bool),
    sampled_imk: &[SampledImk],
    key: &dyn Fn(&str) -> String,
    invalid: &dyn Fn(&str, String) -> ConfigError,
) -> Result<Option<YieldSpec>, ConfigError> {
    let imk_sampled = |k: ImkKey| sampled_imk.iter().any(|(s, _)| *s == k);
    let imk_named = |k: ImkKey| imk_given(r, k).is_some() || imk_sampled(k);
    for (sampled, given, name) in [
        (
            sampled_drift.is_some(),
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
    let rule = match r.hysteresis.as_deref().map(|w| (w, hysteresis(w))) {
        None => None,
        Some((_, Some(rule))) => rule,
        Some((other, None)) => {
            return Err(invalid(
                &key("hysteresis"),
                format!("`{other}`: expected {HYSTERESIS_WORDS}"),
            ))
        }
    };
    let storeys = Storeys { n, key, invalid };
    let strengths = [
        r.yield_drift_ratio.is_some() || sampled_drift.is_some(),
        r.yield_force_n.is_some(),
        r.yield_base_shear_coefficient.is_some() || sampled_shear,
    ];
    let (strength, axis) = match strengths.iter().filter(|&&x| x).count() {
        0 => {
            let imk = ImkKey::ALL.map(|k| (imk_named(k), k.key()));
            for (given, name) in [
                (r.post_yield_ratio.is_some(), "post_yield_ratio"),
                (
                    r.yield_shear_distribution.is_some(),
                    "yield_shear_distribution",
                ),
                (r.hysteresis.is_some(), "hysteresis"),
            ]
            .into_iter()
            .chain(imk)
            {
                if given {
                    return Err(invalid(
                        &key(name),
                        "is given, but the storeys have no strength: give yield_drift_ratio, yield_force_n or yield_base_shear_coefficient".into(),
                    ));
                }
            }
            return Ok(None);
        }
        1 => strength(r, sampled_drift.is_some(), &storeys)?,
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
    // The yield drift ratio per storey at its largest, where the config tells it.
    let theta_y = match (&strength, sampled_drift) {
        (_, Some(max)) => Some(vec![max; n]),
        (YieldStrength::DriftRatio(theta), None) => Some(match &axis {
            Some(a) => vec![a.iter().cloned().fold(0.0, f64::max); n],
            None => theta.clone(),
        }),
        _ => None,
    };
    let deterioration = match rule {
        Some(rule) => Some(imk_storeys(
            r,
            rule,
            (theta_y.as_deref(), sampled_imk),
            &storeys,
        )?),
        None => {
            if let Some(k) = ImkKey::ALL.into_iter().find(|k| imk_named(*k)) {
                return Err(invalid(
                    &key(k.key()),
                    format!(
                        "applies to IMK storeys only: add hysteresis = \"imk_bilinear\" or \"imk_peak_oriented\", or remove {}",
                        k.key()
                    ),
                ));
            }
            None
        }
    };
    Ok(Some(YieldSpec {
        strength,
        post_yield,
        axis,
        deterioration,
    }))
}

/// IMK key `k` as `r` gives it.
fn imk_given(r: &RawShearBuilding, k: ImkKey) -> Option<&StoreyValues> {
    match k {
        ImkKey::Plastic => r.plastic_drift_ratio.as_ref(),
        ImkKey::PostCapping => r.post_capping_drift_ratio.as_ref(),
        ImkKey::Residual => r.residual_strength_ratio.as_ref(),
        ImkKey::Ultimate => r.ultimate_drift_ratio.as_ref(),
        ImkKey::Energy => r.energy_capacity_ratio.as_ref(),
    }
}

/// An IMK key as given: its values per storey, and per storey the smallest and largest value
/// a run takes.
type Given = (Vec<f64>, Vec<(f64, f64)>);

/// An IMK key `[sample]` draws for a building, with its draws, sample by sample.
pub(crate) type SampledImk = (ImkKey, Vec<f64>);

/// A building's IMK storeys (`hysteresis` names `rule`): `theta_p` and `theta_pc` required,
/// `kappa` 0, `theta_u` infinite and `gamma` none where absent. `theta_y`: the yield drift
/// ratio per storey at its largest where the config tells it (a yield drift); the ultimate
/// drift must lie beyond the capping point `theta_y + theta_p` at its largest, or beyond
/// `theta_p` where `theta_y` follows each run's stiffness (a force or base-shear strength).
///
/// A key `[sample]` draws (`sampled`) is a one-value axis whose value each run's draw replaces
/// ([`crate::plan::row::RowPlan::run`]); the ultimate drift is checked against capping draw by
/// draw, each sample's against its own `theta_p`.
fn imk_storeys(
    r: &RawShearBuilding,
    rule: ImkRule,
    (theta_y, sampled): (Option<&[f64]>, &[SampledImk]),
    storeys: &Storeys,
) -> Result<ImkSpec, ConfigError> {
    let mut axes = Vec::new();
    let mut read = |k: ImkKey| -> Result<Option<Given>, ConfigError> {
        if let Some((_, draws)) = sampled.iter().find(|(s, _)| *s == k) {
            let lo = draws.iter().cloned().fold(f64::INFINITY, f64::min);
            let hi = draws.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
            if imk_given(r, k).is_some() {
                let name = (storeys.key)(k.key());
                return Err((storeys.invalid)(
                    &name,
                    format!("{name} is sampled under [sample]: remove it here"),
                ));
            }
            axes.push((k, vec![lo]));
            return Ok(Some((vec![lo; storeys.n], vec![(lo, hi); storeys.n])));
        }
        let Some(v) = imk_given(r, k) else {
            return Ok(None);
        };
        let (values, axis) = storeys.storey_values(k.key(), v, k.check())?;
        let range = match &axis {
            Some(a) => {
                let lo = a.iter().cloned().fold(f64::INFINITY, f64::min);
                let hi = a.iter().cloned().fold(0.0, f64::max);
                vec![(lo, hi); storeys.n]
            }
            None => values.iter().map(|&x| (x, x)).collect(),
        };
        if let Some(a) = axis {
            axes.push((k, a));
        }
        Ok(Some((values, range)))
    };
    let required = |k: ImkKey, what: &str| {
        (storeys.invalid)(
            &(storeys.key)(k.key()),
            format!(
                "missing: IMK storeys (hysteresis = \"{}\") need {} ({what})",
                rule.key(),
                k.key()
            ),
        )
    };
    let (plastic, plastic_range) = read(ImkKey::Plastic)?.ok_or_else(|| {
        required(
            ImkKey::Plastic,
            "theta_p, the drift ratio from yield to capping",
        )
    })?;
    let (post_capping, _) = read(ImkKey::PostCapping)?.ok_or_else(|| {
        required(
            ImkKey::PostCapping,
            "theta_pc, the drift ratio from capping to zero strength",
        )
    })?;
    let residual = read(ImkKey::Residual)?.map_or(vec![0.0; storeys.n], |(v, _)| v);
    let ultimate = read(ImkKey::Ultimate)?;
    let energy = read(ImkKey::Energy)?.map(|(v, _)| v);
    let drawn = |k: ImkKey| sampled.iter().find(|(s, _)| *s == k).map(|(_, d)| d);
    match (&ultimate, drawn(ImkKey::Ultimate), drawn(ImkKey::Plastic)) {
        (Some((_, range)), None, None) => {
            check_ultimate(r, range, &plastic_range, theta_y, storeys, None)?;
        }
        // A sampled theta_u or theta_p: each sample's pair, the other key as given.
        (Some((_, range)), u_draws, p_draws) => {
            let samples = u_draws.or(p_draws).map_or(0, Vec::len);
            for k in 0..samples {
                let at =
                    |d: Option<&Vec<f64>>, given: &[(f64, f64)], hi: bool| -> Vec<(f64, f64)> {
                        match d {
                            Some(d) => vec![(d[k], d[k]); storeys.n],
                            None => given
                                .iter()
                                .map(|&(lo, h)| if hi { (h, h) } else { (lo, lo) })
                                .collect(),
                        }
                    };
                let (u, p) = (at(u_draws, range, false), at(p_draws, &plastic_range, true));
                check_ultimate(r, &u, &p, theta_y, storeys, Some(k))?;
            }
        }
        _ => {}
    }
    Ok(ImkSpec {
        deterioration: Deterioration {
            rule,
            plastic,
            post_capping,
            residual,
            ultimate: ultimate.map_or(vec![f64::INFINITY; storeys.n], |(v, _)| v),
            energy,
        },
        axes,
    })
}

/// Each storey's ultimate drift ratio (its smallest, per storey in `ultimate`) beyond its
/// capping point: `theta_y + theta_p` at their largest, or `theta_p` where `theta_y` is not
/// known before a run.
fn check_ultimate(
    r: &RawShearBuilding,
    ultimate: &[(f64, f64)],
    plastic: &[(f64, f64)],
    theta_y: Option<&[f64]>,
    storeys: &Storeys,
    sample: Option<usize>,
) -> Result<(), ConfigError> {
    let show = crate::plan::limits::show;
    let drawn = sample.map_or_else(String::new, |k| format!("in [sample]'s sample {k}, "));
    for (i, (&(u, _), &(_, p))) in ultimate.iter().zip(plastic).enumerate() {
        let (capping, what) = match theta_y {
            Some(y) => (
                y[i] + p,
                format!(
                    "capping point theta_y + theta_p = {} + {} = {}",
                    show(y[i]),
                    show(p),
                    show(y[i] + p)
                ),
            ),
            None => (
                p,
                format!(
                    "plastic_drift_ratio theta_p = {} (theta_y follows each run's storey stiffness under yield_force_n or yield_base_shear_coefficient, so only theta_p is checked here)",
                    show(p)
                ),
            ),
        };
        // "At" as written: 0.005 + 0.03 rounds below 0.035.
        if u <= capping * (1.0 + 1e-12) {
            let name = (storeys.key)(ImkKey::Ultimate.key());
            let at = match r.ultimate_drift_ratio {
                Some(StoreyValues::Each(_)) => format!("{name}[{i}]"),
                _ => name,
            };
            return Err((storeys.invalid)(
                &at,
                format!(
                    "{drawn}{} is at or before storey {}'s {what}: expected an ultimate drift ratio beyond it",
                    show(u),
                    i + 1
                ),
            ));
        }
    }
    Ok(())
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
