//! A pair's config (`[building1]` and `[building2]`) decoded into a [`PairPlan`].

use crate::config::axis::Axis;
use crate::config::error::ConfigError;
use crate::config::pair::{RawBuilding, RawConfig};
use crate::plan::axes::PlanError;
use crate::plan::decode::contact::{
    check_size, contact_spec, parse_laws, parse_scheme, unused_contact, ContactSections, Reading,
    SceneCounts, UNUSED_GAP_M,
};
use crate::plan::decode::sampled::{grid_or_sampled, samples, MISSING};
use crate::plan::pair::{BuildingAxes, PairPlan, PlanSpec, SampledAxis};
use std::path::Path;

/// [`crate::plan::config::parse`] of a config already read into its raw form.
pub(crate) fn parse_raw(
    raw: &RawConfig,
    path: &Path,
    base: &Path,
    records: &Path,
    reading: Reading,
) -> Result<PairPlan, ConfigError> {
    let invalid = |key: &str, message: String| ConfigError::Invalid {
        path: path.into(),
        key: key.into(),
        message,
    };
    let mut rc = match (&raw.contact, reading) {
        (Some(c), _) => c.clone(),
        (None, Reading::GapStudy) => unused_contact(),
        (None, Reading::Sweep) => {
            return Err(invalid(
                "contact",
                "missing: a pair of buildings that may touch needs [contact] (law, its stiffness and gap_m)".into(),
            ))
        }
    };
    let gap_sampled =
        (raw.sample.iter()).any(|s| s.axes.iter().any(|a| a.key == SampledAxis::Gap.key()));
    if reading == Reading::GapStudy && rc.gap_m.is_none() && !gap_sampled {
        rc.gap_m = Some(Axis::List(vec![UNUSED_GAP_M]));
    }
    let rc = &rc;
    let axis = |key: &str, a: &Axis| a.values().map_err(|m| invalid(key, m));
    if raw.run.collapse_drift_ratio.is_some() {
        return Err(invalid(
            "run.collapse_drift_ratio",
            "a collapse is a storey's drift ratio, and [building1]/[building2] have no storey height: write the buildings as [[building]] entries with storey_height_m".into(),
        ));
    }
    let scheme = parse_scheme(&raw.run, &invalid)?;
    let (laws, formulas) = parse_laws(rc, &invalid)?;
    let count = |key: &str, a: &Option<Axis>| -> Result<usize, ConfigError> {
        a.as_ref()
            .map_or(Ok(1), |a| a.count().map_err(|m| invalid(key, m)))
    };
    let b = |name: &str, r: &RawBuilding| -> Result<[usize; 3], ConfigError> {
        Ok([
            count(&format!("{name}.mass_kg"), &r.mass_kg)?,
            count(&format!("{name}.period_s"), &r.period_s)?,
            count(&format!("{name}.damping_ratio"), &r.damping_ratio)?,
        ])
    };
    let scene = SceneCounts {
        samples: raw.sample.as_ref().map_or(1, |s| s.n.max(1)),
        building1: b("building1", &raw.building1)?,
        building2: b("building2", &raw.building2)?,
        gaps: count("contact.gap_m", &rc.gap_m)?,
    };
    check_size(
        rc,
        raw.records.len(),
        &raw.intensity,
        &laws,
        scene,
        &invalid,
    )?;
    let samples = raw
        .sample
        .as_ref()
        .map(|s| samples(s, &invalid))
        .transpose()?;
    let sampled = |key: &str| {
        samples
            .as_ref()
            .is_some_and(|s| s.axes.iter().any(|a| a.key() == key))
    };
    let grid = |key: &str, a: &Option<Axis>| -> Result<Vec<f64>, ConfigError> {
        match grid_or_sampled(a.as_ref(), sampled(key)).map_err(|m| invalid(key, m))? {
            Some(a) => axis(key, &a),
            None => Err(invalid(key, MISSING.into())),
        }
    };
    let building = |name: &str, b: &RawBuilding| -> Result<BuildingAxes, ConfigError> {
        Ok(BuildingAxes {
            mass: grid(&format!("{name}.mass_kg"), &b.mass_kg)?,
            period: grid(&format!("{name}.period_s"), &b.period_s)?,
            damping: grid(&format!("{name}.damping_ratio"), &b.damping_ratio)?,
        })
    };
    let contact = contact_spec(
        ContactSections {
            scheme,
            laws,
            formulas,
            contact: rc,
            k_linear: rc.k_n_per_m.as_ref(),
            beta: rc.beta_n_per_m1_5.as_ref(),
            records: &raw.records,
            intensity: &raw.intensity,
            buildings: 2,
            tail: raw.run.tail_s.unwrap_or(0.0),
        },
        base,
        records,
        path,
    )?;
    let spec = PlanSpec {
        contact,
        building1: building("building1", &raw.building1)?,
        building2: building("building2", &raw.building2)?,
        gaps: grid("contact.gap_m", &rc.gap_m)?,
        samples,
    };
    let plan = PairPlan::new(spec).map_err(|PlanError { key, message }| invalid(&key, message))?;
    // A gap study runs no contact axis: none can repeat its runs.
    if reading == Reading::Sweep {
        plan.refuse_unused()
            .map_err(|PlanError { key, message }| invalid(&key, message))?;
    }
    Ok(plan)
}
