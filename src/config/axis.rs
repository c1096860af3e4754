//! A sweep axis as written: a number, a list of numbers, or a range table
//! `{ from = .., to = .., n = .. }` (add `log = true` for log spacing) or `{ from, to, step }`.

use serde::de::{self, Deserializer, MapAccess, SeqAccess, Visitor};
use serde::Deserialize;
use std::fmt;

/// The runs of a grid axis or range (`{ from, to, n }`).
pub const MAX_AXIS_POINTS: usize = 10_000_000;

/// A sweep axis as written.
#[derive(Debug, Clone, PartialEq)]
pub enum Axis {
    List(Vec<f64>),
    Range(RangeSpec),
}

#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RangeSpec {
    pub from: f64,
    pub to: f64,
    pub n: Option<usize>,
    pub step: Option<f64>,
    #[serde(default)]
    pub log: bool,
}

impl<'de> Deserialize<'de> for Axis {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Axis, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = Axis;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a number, a list of numbers, or a range table { from, to, n } / { from, to, step }")
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<Axis, E> {
                Ok(Axis::List(vec![v]))
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<Axis, E> {
                Ok(Axis::List(vec![v as f64]))
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<Axis, E> {
                Ok(Axis::List(vec![v as f64]))
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Axis, A::Error> {
                let mut v = Vec::new();
                while let Some(x) = seq.next_element::<f64>()? {
                    v.push(x);
                }
                Ok(Axis::List(v))
            }
            fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<Axis, A::Error> {
                RangeSpec::deserialize(de::value::MapAccessDeserializer::new(map)).map(Axis::Range)
            }
        }
        d.deserialize_any(V)
    }
}

/// Parse `start:stop:step` (the CLI's range syntax) into values, stop included.
pub fn parse_colon_range(s: &str) -> Option<Vec<f64>> {
    let p: Vec<f64> = s
        .split(':')
        .map(|x| x.trim().parse().ok())
        .collect::<Option<_>>()?;
    match p[..] {
        [v] => Some(vec![v]),
        [a, b, st] => Axis::Range(RangeSpec {
            from: a,
            to: b,
            n: None,
            step: Some(st),
            log: false,
        })
        .values()
        .ok(),
        _ => None,
    }
}

/// Round to 12 significant digits, so generated ranges read as typed (0.35, not
/// 0.35000000000000003) in outputs.
fn tidy(v: f64) -> f64 {
    format!("{v:.11e}").parse().unwrap_or(v)
}

/// The first number `values` holds twice (a list a user typed: each value once).
pub fn number_given_twice(values: &[f64]) -> Option<f64> {
    let mut sorted = values.to_vec();
    sorted.sort_by(f64::total_cmp);
    sorted.windows(2).find(|w| w[0] == w[1]).map(|w| w[0])
}

/// The first name `names` holds twice.
pub fn name_given_twice<S: AsRef<str>>(names: &[S]) -> Option<&str> {
    let mut seen = std::collections::HashSet::new();
    names.iter().map(AsRef::as_ref).find(|n| !seen.insert(*n))
}

impl Axis {
    pub fn values(&self) -> Result<Vec<f64>, String> {
        match self {
            Axis::List(v) => match number_given_twice(v) {
                // A value listed twice runs its runs twice, weighting them double in a fit.
                Some(x) => Err(format!(
                    "{} is given twice: give each value once (a repeated value repeats its runs)",
                    crate::show(x)
                )),
                None => Ok(v.clone()),
            },
            Axis::Range(r) => {
                let v: Vec<f64> = Self::range_values(r)?.into_iter().map(tidy).collect();
                // Points closer than the 12 digits they are written to would be runs repeated
                // (a range is monotonic: a repeat is next to its twin, found without a sort).
                match v.windows(2).find(|w| w[0] == w[1]).map(|w| w[0]) {
                    Some(x) => Err(format!(
                        "gives {} twice (its points are closer than 12 significant digits): a repeated value repeats its runs; give fewer points",
                        crate::show(x)
                    )),
                    None => Ok(v),
                }
            }
        }
    }

    /// The number of values, without computing them (so a sweep too large to run is refused
    /// before gigabytes of axes are built).
    pub fn count(&self) -> Result<usize, String> {
        match self {
            Axis::List(v) => Ok(v.len()),
            Axis::Range(r) => Self::range_count(r),
        }
    }

    fn range_count(r: &RangeSpec) -> Result<usize, String> {
        let max = MAX_AXIS_POINTS;
        if !(r.from.is_finite() && r.to.is_finite()) {
            return Err("range ends must be finite".into());
        }
        match (r.n, r.step) {
            (Some(n), None) => {
                if n == 0 || n > max {
                    return Err(format!("n = {n}: expected 1 to 1e7 points"));
                }
                if n == 1 && r.to != r.from {
                    return Err(format!(
                        "n = 1 gives the single value from = {}, and to = {} would be ignored: give one value, or n >= 2",
                        r.from, r.to
                    ));
                }
                Ok(n)
            }
            (None, Some(step)) if !r.log => {
                if !(step.is_finite() && step != 0.0) || (r.to - r.from) * step < 0.0 {
                    return Err(format!(
                        "step = {step:?} does not lead from {:?} to {:?}",
                        r.from, r.to
                    ));
                }
                let count = ((r.to - r.from) / step + 1e-9).floor() + 1.0;
                if count.is_nan() || count > max as f64 {
                    return Err(format!(
                        "step = {step:?} gives {count:.3e} points from {:?} to {:?}: expected at most 1e7",
                        r.from, r.to
                    ));
                }
                Ok(count as usize)
            }
            _ => Err("give exactly one of n or step (log ranges take n)".into()),
        }
    }

    fn range_values(r: &RangeSpec) -> Result<Vec<f64>, String> {
        let count = Self::range_count(r)?;
        match (r.n, r.step) {
            (Some(n), None) => {
                if n == 1 {
                    return Ok(vec![r.from]);
                }
                if r.log {
                    if !(r.from > 0.0 && r.to > 0.0) {
                        return Err("a log range needs from > 0 and to > 0".into());
                    }
                    let (a, b) = (r.from.ln(), r.to.ln());
                    Ok((0..n)
                        .map(|i| {
                            if i == n - 1 {
                                r.to
                            } else {
                                (a + (b - a) * i as f64 / (n - 1) as f64).exp()
                            }
                        })
                        .collect())
                } else {
                    Ok((0..n)
                        .map(|i| {
                            if i == n - 1 {
                                r.to
                            } else {
                                r.from + (r.to - r.from) * i as f64 / (n - 1) as f64
                            }
                        })
                        .collect())
                }
            }
            (None, Some(step)) => Ok((0..count).map(|i| r.from + step * i as f64).collect()),
            _ => Err("give exactly one of n or step (log ranges take n)".into()),
        }
    }
}
