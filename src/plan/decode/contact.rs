//! The sections every scene shares decoded: `[run]`'s scheme, `[contact]`'s laws and axes,
//! the records and the intensities, into a [`ContactSpec`] or a [`ContactPlan`], and the
//! whole sweep's size checked before any axis is built.

use crate::config::axis::Axis;
use crate::config::error::ConfigError;
use crate::config::sections::{Names, RawContact, RawIntensity, RawRecord, RawRun};
use crate::physics::contact::LawKind;
use crate::physics::restitution::Formula;
use crate::physics::solver::{FastOptions, ReferenceOptions, Scheme};
use crate::plan::axes::PlanError;
use crate::plan::contact::{ContactPlan, ContactSpec};
use crate::plan::decode::intensity::intensity_axis;
use crate::plan::decode::records::{load_record, LoadError};
use crate::record::Record;
use std::path::Path;
use std::sync::Arc;

/// What a config is read for: a sweep needs its contact and gaps; a gap study does not.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Reading {
    Sweep,
    GapStudy,
}

/// The contact of a scene that has none to run (a building alone, or a gap study without
/// `[contact]`): a linear law that no run uses.
pub(crate) fn unused_contact() -> RawContact {
    RawContact {
        law: Names::One("linear".into()),
        formula: None,
        e: None,
        gap_m: None,
        k_n_per_m: Some(Axis::List(vec![1e9])),
        beta_n_per_m1_5: None,
    }
}

/// The gap a gap study takes for a pair whose gap the config leaves out: one value, so no run
/// is repeated and no gap is counted at it (a gap study counts at a config's gap axis of two
/// values or more only).
pub(crate) const UNUSED_GAP_M: f64 = 0.0;
/// The `[run]` section's scheme.
pub(crate) fn parse_scheme(
    run: &RawRun,
    invalid: &dyn Fn(&str, String) -> ConfigError,
) -> Result<Scheme, ConfigError> {
    Ok(match run.scheme.as_deref().unwrap_or("fast") {
        "fast" => {
            let mut o = FastOptions::default();
            if let Some(n) = run.substeps_per_contact {
                if !(n.is_finite()
                    && (1.0..=crate::plan::limits::MAX_SUBSTEPS_PER_CONTACT).contains(&n))
                {
                    return Err(invalid(
                        "run.substeps_per_contact",
                        format!(
                            "{}: expected 1 to {} ({})",
                            crate::plan::limits::show(n),
                            crate::plan::limits::MAX_SUBSTEPS_PER_CONTACT,
                            crate::plan::limits::WHY_SUBSTEPS
                        ),
                    ));
                }
                o.substeps_per_contact = n;
            }
            o.energy = run.energy.unwrap_or(false);
            Scheme::Fast(o)
        }
        "reference" => {
            let tol = run
                .tol
                .unwrap_or(crate::physics::solver::reference::DEFAULT_TOL);
            let tol = crate::plan::limits::check_tol(tol).map_err(|m| invalid("run.tol", m))?;
            Scheme::Reference(ReferenceOptions::with_tol(tol))
        }
        other => {
            return Err(invalid(
                "run.scheme",
                format!("`{other}`: expected fast or reference"),
            ))
        }
    })
}

/// The `[contact]` section's laws and formulas.
pub(crate) fn parse_laws(
    contact: &RawContact,
    invalid: &dyn Fn(&str, String) -> ConfigError,
) -> Result<(Vec<LawKind>, Vec<Formula>), ConfigError> {
    let mut laws = Vec::new();
    for (i, k) in contact.law.list().iter().enumerate() {
        let law = LawKind::from_key(k).ok_or_else(|| {
            invalid(
                &format!("contact.law[{i}]"),
                format!("unknown law `{k}`: expected one of {}", LawKind::keys()),
            )
        })?;
        // Twice would write two runs of one label for every other value.
        if let Some(j) = laws.iter().position(|l| *l == law) {
            return Err(invalid(
                &format!("contact.law[{i}]"),
                format!("`{k}` is given twice (also contact.law[{j}])"),
            ));
        }
        laws.push(law);
    }
    let mut formulas = Vec::new();
    for (i, k) in contact
        .formula
        .as_ref()
        .map(Names::list)
        .unwrap_or_default()
        .iter()
        .enumerate()
    {
        let formula = Formula::from_key(k).ok_or_else(|| {
            invalid(
                &format!("contact.formula[{i}]"),
                format!("unknown formula `{k}`: expected one of {}", Formula::keys()),
            )
        })?;
        if let Some(j) = formulas.iter().position(|f| *f == formula) {
            return Err(invalid(
                &format!("contact.formula[{i}]"),
                format!("`{k}` is given twice (also contact.formula[{j}])"),
            ));
        }
        formulas.push(formula);
    }
    Ok((laws, formulas))
}

/// The sections every scene shares, as a scene's reader settled them.
pub(crate) struct ContactSections<'a> {
    pub scheme: Scheme,
    pub laws: Vec<LawKind>,
    pub formulas: Vec<Formula>,
    pub contact: &'a RawContact,
    /// `k` and `beta` as the scene gives them (a sampled one holds a placeholder value).
    pub k_linear: Option<&'a Axis>,
    pub beta: Option<&'a Axis>,
    pub records: &'a [RawRecord],
    pub intensity: &'a RawIntensity,
    /// The scene's buildings, for the intensity's references to their periods.
    pub buildings: usize,
    /// `run.tail_s`
    pub tail: f64,
}

/// The axes every scene shares, validated but for the buildings' periods a spectral target
/// reads (the scene checks those): records read (`path =` beside `base`, `file =` in
/// `records`), intensities, `e`, `k` and `beta`.
pub(crate) fn contact_spec(
    c: ContactSections,
    base: &Path,
    records: &Path,
    path: &Path,
) -> Result<ContactSpec, ConfigError> {
    let invalid = |key: &str, message: String| ConfigError::Invalid {
        path: path.into(),
        key: key.into(),
        message,
    };
    let axis = |key: &str, a: &Axis| a.values().map_err(|m| invalid(key, m));
    let opt_axis = |key: &str, a: Option<&Axis>| a.map_or(Ok(Vec::new()), |a| axis(key, a));
    let intensities = intensity_axis(c.intensity, c.buildings, &invalid)?;
    // A set's search scale factors scale a record where `[intensity] scale` does; a target
    // scales each record to itself whatever it was before.
    if let Some(r) = c.records.iter().find(|r| r.factor.is_some()) {
        if let Some(t) = intensities
            .iter()
            .find(|x| !matches!(x, crate::plan::intensity::Intensity::Scale(_)))
        {
            return Err(invalid(
                &format!("record[{}].search_scale", r.written_at.unwrap_or(0)),
                format!(
                    "scales each record by its search's factor, which the {} target replaces (a target scales every record to itself): give [intensity] scale = [...] with it, or leave search_scale out",
                    t.key()
                ),
            ));
        }
    }
    let warn_scale = c
        .intensity
        .warn_scale_factor
        .unwrap_or(crate::plan::limits::WARN_SCALE_FACTOR);
    if !(warn_scale.is_finite() && warn_scale >= 1.0) {
        return Err(invalid(
            "intensity.warn_scale_factor",
            format!(
                "{} is out of range: expected a scale factor >= 1 (default {})",
                crate::plan::limits::show(warn_scale),
                crate::plan::limits::WARN_SCALE_FACTOR
            ),
        ));
    }
    let mut recs = Vec::new();
    for (i, r) in c.records.iter().enumerate() {
        let key = r.key(i);
        let rec = load_record(r, base, records).map_err(|e| match e {
            LoadError::Invalid(m) => invalid(&key, m),
            LoadError::Record(error) => ConfigError::Record {
                path: path.into(),
                key: key.clone(),
                error,
            },
        })?;
        // A label names a record's runs in every output: two records of one label could not be
        // told apart (a name given twice, two windows of one file, one seed twice).
        if let Some(j) = recs.iter().position(|r: &Arc<Record>| r.name == rec.name) {
            let other = c.records[j].key(j);
            let advice = if r.meta.is_some() || c.records[j].meta.is_some() {
                "list each RSN in one record set only (a set's records are labelled by RSN and component, not renamed)"
            } else {
                "give each a distinct name = \"...\""
            };
            return Err(invalid(
                &key,
                format!("is labelled `{}`, as {other} is: {advice}", rec.name),
            ));
        }
        // The same motion under another label would repeat every run of the first.
        if let Some(j) = recs
            .iter()
            .position(|r| r.dt == rec.dt && r.t0 == rec.t0 && r.accel == rec.accel)
        {
            return Err(invalid(
                &key,
                format!(
                    "`{}` holds the same accelerations (same dt and start) as {other} `{}`: its runs would repeat {other}'s with the same physics; remove one",
                    rec.name,
                    recs[j].name,
                    other = c.records[j].key(j)
                ),
            ));
        }
        recs.push(Arc::new(rec));
    }
    Ok(ContactSpec {
        laws: c.laws,
        formulas: c.formulas,
        e: opt_axis("contact.e", c.contact.e.as_ref())?,
        k_linear: opt_axis("contact.k_n_per_m", c.k_linear)?,
        beta: opt_axis("contact.beta_n_per_m1_5", c.beta)?,
        records: recs,
        record_meta: c.records.iter().map(|r| r.meta.clone()).collect(),
        record_factor: c.records.iter().map(|r| r.factor.unwrap_or(1.0)).collect(),
        intensities,
        scheme: c.scheme,
        tail: c.tail,
        warn_scale,
    })
}

/// The contact plan of a row config ([`crate::plan::row`]): its `[run]`, `[contact]`,
/// `[[record]]` and `[intensity]` sections, with `k` and `beta` as the row settled them, for a
/// row of `buildings` buildings.
#[allow(clippy::too_many_arguments)]
pub(crate) fn parse_contact(
    run: &RawRun,
    contact: &RawContact,
    k_linear: Option<&Axis>,
    beta: Option<&Axis>,
    raw_records: &[RawRecord],
    intensity: &RawIntensity,
    buildings: usize,
    (path, base, records): (&Path, &Path, &Path),
) -> Result<ContactPlan, ConfigError> {
    let invalid = |key: &str, message: String| ConfigError::Invalid {
        path: path.into(),
        key: key.into(),
        message,
    };
    let scheme = parse_scheme(run, &invalid)?;
    let (laws, formulas) = parse_laws(contact, &invalid)?;
    // The row checks its whole count once its buildings are read; here the contact runs'.
    check_size(
        contact,
        raw_records.len(),
        intensity,
        &laws,
        SceneCounts::ONE,
        &invalid,
    )?;
    let spec = contact_spec(
        ContactSections {
            scheme,
            laws,
            formulas,
            contact,
            k_linear,
            beta,
            records: raw_records,
            intensity,
            buildings,
            tail: run.tail_s.unwrap_or(0.0),
        },
        base,
        records,
        path,
    )?;
    ContactPlan::new(spec).map_err(|PlanError { key, message }| invalid(&key, message))
}

/// The sizes of a pair's own axes, for [`check_size`].
#[derive(Clone, Copy)]
pub(crate) struct SceneCounts {
    pub samples: usize,
    pub building1: [usize; 3],
    pub building2: [usize; 3],
    pub gaps: usize,
}

impl SceneCounts {
    /// One scene value per contact run: the contact runs alone.
    const ONE: SceneCounts = SceneCounts {
        samples: 1,
        building1: [1; 3],
        building2: [1; 3],
        gaps: 1,
    };
}

/// Refuse a sweep of more than [`crate::plan::limits::MAX_RUNS`] runs from the axes' sizes alone,
/// before any axis is built or sample drawn.
pub(crate) fn check_size(
    contact: &RawContact,
    records: usize,
    intensity: &RawIntensity,
    laws: &[LawKind],
    scene: SceneCounts,
    invalid: &dyn Fn(&str, String) -> ConfigError,
) -> Result<(), ConfigError> {
    let count = |key: &str, a: &Option<Axis>| -> Result<usize, ConfigError> {
        a.as_ref()
            .map_or(Ok(1), |a| a.count().map_err(|m| invalid(key, m)))
    };
    let counts = crate::plan::pair::AxisCounts {
        formulas: contact.formula.as_ref().map_or(0, |f| f.list().len()),
        e: count("contact.e", &contact.e)?,
        k_linear: count("contact.k_n_per_m", &contact.k_n_per_m)?,
        beta: count("contact.beta_n_per_m1_5", &contact.beta_n_per_m1_5)?,
        records,
        intensities: count("intensity.pga_g", &intensity.pga_g)?
            * count("intensity.scale", &intensity.scale)?
            * count("intensity.sa_g", &intensity.sa_g)?
            * count("intensity.sa_avg_g", &intensity.sa_avg_g)?,
        samples: scene.samples,
        building1: scene.building1,
        building2: scene.building2,
        gaps: scene.gaps,
    };
    crate::plan::pair::check_run_count(laws, &counts)
        .map(|_| ())
        .map_err(|e| invalid(&e.key, e.message))
}
