//! `[sample]` decoded: the sampled keys resolved, their distributions checked and the points
//! drawn; and a key given on the grid or sampled, not both.

use crate::config::axis::Axis;
use crate::config::error::ConfigError;
use crate::config::sections::RawSample;
use crate::plan::pair::{SampledAxis, Samples};
use crate::plan::sample::{draw, Dist, Method};

/// A grid axis or a sampled one, not both: a sampled parameter's grid axis holds one placeholder
/// (0.5: valid for every axis, never used). `Err` says why `given` cannot stand; `Ok(None)`: a
/// parameter neither given nor sampled ([`MISSING`] where it is required). Shared by the pair's
/// config and the row's ([`crate::plan::row`]).
pub(crate) fn grid_or_sampled(given: Option<&Axis>, sampled: bool) -> Result<Option<Axis>, String> {
    match (given, sampled) {
        (Some(_), true) => Err("is sampled under [sample]: remove it from the grid".into()),
        (None, true) => Ok(Some(Axis::List(vec![0.5]))),
        (given, false) => Ok(given.cloned()),
    }
}

/// The error of a required parameter that is neither given nor sampled.
pub(crate) const MISSING: &str = "missing: give values or sample it";

/// Stage 2 of `[sample]`: distributions checked, points drawn.
pub(crate) fn samples(
    s: &RawSample,
    invalid: &dyn Fn(&str, String) -> ConfigError,
) -> Result<Samples, ConfigError> {
    let keys = SampledAxis::ALL.map(|x| x.key()).join(", ");
    let (axes, points) = draw_sampled(s, invalid, &SampledAxis::from_key, &keys)?;
    Ok(Samples { axes, points })
}

/// The `[[sample.axis]]` entries of `s` resolved by `resolve` (`keys` lists the keys it
/// knows, for the error), their distributions checked, and `s.n` points drawn: `points[s][j]`
/// is axis `j`'s value in sample `s`.
pub(crate) fn draw_sampled<A: PartialEq>(
    s: &RawSample,
    invalid: &dyn Fn(&str, String) -> ConfigError,
    resolve: &dyn Fn(&str) -> Option<A>,
    keys: &str,
) -> Result<(Vec<A>, Vec<Vec<f64>>), ConfigError> {
    let method = match s.method.as_deref().unwrap_or("latin_hypercube") {
        "latin_hypercube" => Method::LatinHypercube,
        "monte_carlo" => Method::MonteCarlo,
        other => {
            return Err(invalid(
                "sample.method",
                format!("`{other}`: expected latin_hypercube or monte_carlo"),
            ))
        }
    };
    if s.n == 0 {
        return Err(invalid(
            "sample.n",
            "is 0: expected at least one sample".into(),
        ));
    }
    if s.n > crate::plan::limits::MAX_SAMPLES {
        return Err(invalid(
            "sample.n",
            format!(
                "{}: expected at most {} ({})",
                s.n,
                crate::plan::limits::MAX_SAMPLES,
                crate::plan::limits::WHY_SAMPLES
            ),
        ));
    }
    if s.axes.is_empty() {
        return Err(invalid(
            "sample.axis",
            "is empty: add [[sample.axis]] entries (key, dist, ...)".into(),
        ));
    }
    let mut axes = Vec::new();
    let mut dists = Vec::new();
    for (i, a) in s.axes.iter().enumerate() {
        let key = format!("sample.axis[{i}]");
        let axis = resolve(&a.key).ok_or_else(|| {
            invalid(
                &format!("{key}.key"),
                format!("`{}`: expected one of {keys}", a.key),
            )
        })?;
        if axes.contains(&axis) {
            return Err(invalid(
                &format!("{key}.key"),
                format!("`{}` is sampled twice", a.key),
            ));
        }
        let need = |name: &str, v: Option<f64>| {
            v.filter(|x| x.is_finite()).ok_or_else(|| {
                invalid(
                    &format!("{key}.{name}"),
                    format!("a {} distribution needs a finite `{name}`", a.dist),
                )
            })
        };
        let (lo, hi) = (
            a.min.unwrap_or(f64::NEG_INFINITY),
            a.max.unwrap_or(f64::INFINITY),
        );
        let allowed: &[&str] = match a.dist.as_str() {
            "uniform" => &["min", "max"],
            "normal" => &["mean", "sd", "min", "max"],
            "lognormal" => &["median", "beta", "min", "max"],
            _ => &[],
        };
        for (name, given) in [
            ("min", a.min),
            ("max", a.max),
            ("mean", a.mean),
            ("sd", a.sd),
            ("median", a.median),
            ("beta", a.beta),
        ] {
            if given.is_some() && !allowed.is_empty() && !allowed.contains(&name) {
                return Err(invalid(
                    &format!("{key}.{name}"),
                    format!(
                        "does not apply to a {} distribution (it takes {})",
                        a.dist,
                        allowed.join(", ")
                    ),
                ));
            }
        }
        let d = match a.dist.as_str() {
            "uniform" => Dist::Uniform {
                min: need("min", a.min)?,
                max: need("max", a.max)?,
            },
            "normal" => Dist::Normal {
                mean: need("mean", a.mean)?,
                sd: need("sd", a.sd)?,
                min: lo,
                max: hi,
            },
            "lognormal" => Dist::LogNormal {
                median: need("median", a.median)?,
                beta: need("beta", a.beta)?,
                min: lo,
                max: hi,
            },
            other => {
                return Err(invalid(
                    &format!("{key}.dist"),
                    format!("`{other}`: expected uniform, normal or lognormal"),
                ))
            }
        };
        let bad = match d {
            Dist::Uniform { min, max } => (min >= max).then_some("expected min < max"),
            Dist::Normal { sd, .. } if sd <= 0.0 => Some("expected sd > 0"),
            Dist::LogNormal { median, beta, .. } if median <= 0.0 || beta <= 0.0 => {
                Some("expected median > 0 and beta > 0")
            }
            _ => (lo >= hi).then_some("expected min < max"),
        };
        if let Some(m) = bad {
            return Err(invalid(&key, m.into()));
        }
        axes.push(axis);
        dists.push(d);
    }
    Ok((axes, draw(method, s.n, &dists, s.seed)))
}
