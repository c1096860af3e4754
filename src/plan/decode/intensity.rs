//! `[intensity]` decoded: the intensity axis of a scene.

use crate::config::axis::Axis;
use crate::config::error::ConfigError;
use crate::config::sections::{RawIntensity, RawPeriod};
use crate::plan::intensity::{Intensity, PeriodRef, SpectralIm};

/// The periods `sa_avg_n` may ask for: Eads et al. (2015) use 10.
const MAX_SA_AVG_N: usize = 100;

/// The intensity axis, for a scene of `buildings` buildings.
pub(crate) fn intensity_axis(
    raw: &RawIntensity,
    buildings: usize,
    invalid: &dyn Fn(&str, String) -> ConfigError,
) -> Result<Vec<Intensity>, ConfigError> {
    let given: Vec<(&str, &Axis)> = [
        ("pga_g", &raw.pga_g),
        ("scale", &raw.scale),
        ("sa_g", &raw.sa_g),
        ("sa_avg_g", &raw.sa_avg_g),
    ]
    .into_iter()
    .filter_map(|(k, a)| a.as_ref().map(|a| (k, a)))
    .collect();
    let spectral = |key: &str| -> Result<(), ConfigError> {
        let owned: [(&str, bool); 4] = [
            ("sa_period_s", raw.sa_period_s.is_some()),
            ("sa_avg_periods_s", raw.sa_avg_periods_s.is_some()),
            ("sa_avg_n", raw.sa_avg_n.is_some()),
            ("sa_damping", raw.sa_damping.is_some()),
        ];
        let allowed: &[&str] = match key {
            "sa_g" => &["sa_period_s", "sa_damping"],
            "sa_avg_g" => &["sa_avg_periods_s", "sa_avg_n", "sa_damping"],
            _ => &[],
        };
        match owned.iter().find(|(k, set)| *set && !allowed.contains(k)) {
            Some((k, _)) => Err(invalid(
                &format!("intensity.{k}"),
                match key {
                    "sa_g" | "sa_avg_g" => format!("does not apply to {key}"),
                    _ => format!("applies to sa_g or sa_avg_g, not {key}"),
                },
            )),
            None => Ok(()),
        }
    };
    let (key, a) = match given[..] {
        [] => {
            spectral("scale")?;
            return Ok(vec![Intensity::Scale(1.0)]);
        }
        [one] => one,
        _ => {
            return Err(invalid(
                "intensity",
                format!(
                    "gives {}: give one of pga_g, scale, sa_g, sa_avg_g",
                    given.iter().map(|g| g.0).collect::<Vec<_>>().join(" and ")
                ),
            ))
        }
    };
    spectral(key)?;
    let full = format!("intensity.{key}");
    let values = a.values().map_err(|m| invalid(&full, m))?;
    let period = |k: &str, p: &RawPeriod| -> Result<PeriodRef, ConfigError> {
        let r = match p {
            RawPeriod::Seconds(t) => PeriodRef::Seconds(*t),
            RawPeriod::Named(n) => PeriodRef::parse(n).map_err(|m| invalid(k, m))?,
        };
        if let Some(b) = r.building() {
            if b >= buildings {
                return Err(invalid(
                    k,
                    format!(
                        "follows building{} (building[{b}]), but the scene has {buildings} buildings",
                        b + 1
                    ),
                ));
            }
        }
        if let PeriodRef::Seconds(t) = r {
            SpectralIm::check_range([t, t]).map_err(|m| invalid(k, m))?;
        }
        Ok(r)
    };
    let damping = raw
        .sa_damping
        .unwrap_or(crate::record::intensity::DEFAULT_DAMPING);
    if !(0.0..1.0).contains(&damping) {
        return Err(invalid(
            "intensity.sa_damping",
            format!(
                "{} is out of range: expected 0 <= damping ratio < 1",
                crate::plan::limits::show(damping)
            ),
        ));
    }
    let im = match key {
        "pga_g" => return Ok(values.into_iter().map(Intensity::PgaG).collect()),
        "scale" => return Ok(values.into_iter().map(Intensity::Scale).collect()),
        "sa_g" => {
            let k = "intensity.sa_period_s";
            let p = raw.sa_period_s.as_ref().ok_or_else(|| {
                invalid(
                    k,
                    "is missing: sa_g needs the period of Sa, in s or \"building1\"".into(),
                )
            })?;
            let t = period(k, p)?;
            SpectralIm {
                average: false,
                from: t,
                to: t,
                n: 1,
                damping,
            }
        }
        _ => {
            let k = "intensity.sa_avg_periods_s";
            let p = match raw.sa_avg_periods_s.as_ref().map(|p| &p.0[..]) {
                Some([a, b]) => [period(&format!("{k}[0]"), a)?, period(&format!("{k}[1]"), b)?],
                Some(v) => {
                    return Err(invalid(
                        k,
                        format!("{} values: expected two, [from, to]", v.len()),
                    ))
                }
                None => {
                    return Err(invalid(
                        k,
                        "is missing: sa_avg_g needs the periods [from, to], e.g. [\"0.2*building1\", \"3*building1\"]".into(),
                    ))
                }
            };
            let n = raw.sa_avg_n.unwrap_or(10);
            if !(2..=MAX_SA_AVG_N).contains(&n) {
                return Err(invalid(
                    "intensity.sa_avg_n",
                    format!("{n}: expected 2 to {MAX_SA_AVG_N} periods"),
                ));
            }
            if p[0] == p[1] {
                return Err(invalid(
                    k,
                    "from and to are the same period: give a range (or sa_g for one period)".into(),
                ));
            }
            SpectralIm {
                average: true,
                from: p[0],
                to: p[1],
                n,
                damping,
            }
        }
    };
    Ok(values
        .into_iter()
        .map(|g| Intensity::Spectral { g, im })
        .collect())
}
