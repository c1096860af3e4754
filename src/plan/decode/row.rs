//! A row's config (`[[building]]` entries) decoded into a [`RowPlan`]: the shared sections as a
//! pair's ([`crate::plan::decode::contact`]), then each building, its gap to the next, the
//! samples, the collapse limit and the contact levels, in that order (the first error found
//! is the one reported).

use crate::config::axis::Axis;
use crate::config::error::ConfigError;
use crate::config::row::{PerStorey, RawLevels, RawRowConfig, RawShearBuilding};
use crate::config::sections::{CollapseLimit, RawContact, RawRun};
use crate::physics::contact::LawKind;
use crate::physics::row::LevelRule;
use crate::physics::shear::MAX_STOREYS;
use crate::plan::axes::{check_axis, Check, DAMPING, GAP, MASS, PERIOD, POSITIVE};
use crate::plan::decode::contact::{parse_contact, unused_contact, Reading, UNUSED_GAP_M};
use crate::plan::decode::sampled::{draw_sampled, grid_or_sampled, MISSING};
use crate::plan::decode::yielding::{parse_yielding, SampledImk};
use crate::plan::deterioration::ImkKey;
use crate::plan::row::{
    stability_at_1s, RowPlan, RowSampled, RowSamples, ShearAxes, YieldSpec, MAX_SAME_LEVEL_M,
    MIN_SAME_LEVEL_M,
};
use crate::plan::sample::refused_draw;
use std::path::Path;

/// What decodes each building of a row: the file (named in errors) and the samples drawn.
struct RowReader<'a> {
    path: &'a Path,
    samples: Option<&'a RowSamples>,
}

impl RowReader<'_> {
    /// The error at `key`.
    fn invalid(&self, key: &str, message: String) -> ConfigError {
        ConfigError::Invalid {
            path: self.path.into(),
            key: key.into(),
            message,
        }
    }

    /// Does `[sample]` set `a`?
    fn sampled(&self, a: RowSampled) -> bool {
        self.samples.is_some_and(|s| s.axes.contains(&a))
    }

    /// `a`'s grid axis as given, or its placeholder where it is sampled
    /// ([`grid_or_sampled`]).
    fn grid_or_sampled(
        &self,
        a: RowSampled,
        given: Option<&Axis>,
    ) -> Result<Option<Axis>, ConfigError> {
        grid_or_sampled(given, self.sampled(a)).map_err(|m| self.invalid(&a.key(), m))
    }

    /// `a`'s grid axis, given or sampled ([`MISSING`] where neither).
    fn required(&self, a: RowSampled, given: Option<&Axis>) -> Result<Axis, ConfigError> {
        self.grid_or_sampled(a, given)?
            .ok_or_else(|| self.invalid(&a.key(), MISSING.into()))
    }

    /// The values of axis `a` at `key`, each within `check`.
    fn axis(&self, key: &str, a: &Axis, (ok, expected): Check) -> Result<Vec<f64>, ConfigError> {
        let v = a.values().map_err(|m| self.invalid(key, m))?;
        check_axis(key, &v, ok, expected).map_err(|e| self.invalid(&e.key, e.message))?;
        Ok(v)
    }

    /// One value > 0 per storey of `n`.
    fn per_storey(&self, key: &str, v: &[f64], n: usize) -> Result<Vec<f64>, ConfigError> {
        if v.len() != n {
            return Err(self.invalid(
                key,
                format!("{} values for {n} storeys: give one per storey", v.len()),
            ));
        }
        match v.iter().position(|x| !(POSITIVE.0)(*x)) {
            Some(i) => Err(self.invalid(
                &format!("{key}[{i}]"),
                format!(
                    "{} is out of range: expected a value > 0",
                    crate::plan::limits::show(v[i])
                ),
            )),
            None => Ok(v.to_vec()),
        }
    }
}

/// A sweep or a gap study of a row config read from `path` (records resolved beside it,
/// `base`, and in `records`; a gap study may leave out the contact and the gaps:
/// [`crate::plan::config::load_text_for_gaps`]).
pub(crate) fn parse_row_as(
    raw: &RawRowConfig,
    path: &Path,
    base: &Path,
    records: &Path,
    reading: Reading,
) -> Result<RowPlan, ConfigError> {
    let invalid = |key: &str, message: String| ConfigError::Invalid {
        path: path.into(),
        key: key.into(),
        message,
    };
    // One building is a scene too: the no-pounding baseline of a study.
    if raw.building.is_empty() {
        return Err(invalid(
            "building",
            "no [[building]] entries: give at least one".into(),
        ));
    }
    let nb = raw.building.len();
    let samples = row_samples(raw, nb, &invalid)?;
    let reader = RowReader {
        path,
        samples: samples.as_ref(),
    };
    let rc = contact_section(raw, reading, &invalid)?;
    let k_grid = reader.grid_or_sampled(RowSampled::KLinear, rc.k_n_per_m.as_ref())?;
    let beta_grid = reader.grid_or_sampled(RowSampled::Beta, rc.beta_n_per_m1_5.as_ref())?;
    let mut shared_gap = reader.grid_or_sampled(RowSampled::SharedGap, rc.gap_m.as_ref())?;
    // A gap study computes the gaps: a pair whose gap is left out takes one it never uses.
    if reading == Reading::GapStudy && shared_gap.is_none() {
        shared_gap = Some(Axis::List(vec![UNUSED_GAP_M]));
    }
    let mut contact = parse_contact(
        &raw.run,
        &rc,
        k_grid.as_ref(),
        beta_grid.as_ref(),
        &raw.records,
        &raw.intensity,
        nb,
        (path, base, records),
    )?;
    let mut buildings = Vec::new();
    let mut yielding = Vec::new();
    let mut gaps = Vec::new();
    let mut shared = Vec::new();
    for (b, r) in raw.building.iter().enumerate() {
        let (axes, yields) = reader.building(b, r)?;
        buildings.push(axes);
        yielding.push(yields);
        let (gap, from_contact) = reader.gap_right(b, r, nb, shared_gap.as_ref())?;
        shared.push(from_contact);
        gaps.extend(gap);
    }
    shared.truncate(nb - 1);
    let ignored = ignored_keys(raw, &rc, &shared);
    if nb > 1 && reader.sampled(RowSampled::SharedGap) && !shared.contains(&true) {
        return Err(invalid(
            "contact.gap_m",
            "is sampled, but every gap is given per building (gap_right_m): sample those instead"
                .into(),
        ));
    }
    let taken = periods_taken(&buildings, samples.as_ref());
    crate::plan::intensity::check_periods(&contact.spec.intensities, &taken)
        .map_err(|(k, m)| invalid(&k, m))?;
    check_stability(&mut buildings, &taken).map_err(|(k, m)| invalid(&k, m))?;
    let collapse_drift_ratio = collapse_limit(&raw.run, &invalid)?;
    contact.list_periods(&taken);
    let layout = Layout::of(&buildings, &gaps, &shared, &yielding, samples.as_ref());
    let per_scene = layout.per_scene(contact.len()).ok_or_else(|| {
        invalid(
            "building",
            format!(
                "the sweep has more than 2^53 runs ({})",
                crate::plan::limits::WHY_RUNS
            ),
        )
    })?;
    let level_rule = level_rule(&raw.levels).map_err(|(k, m)| invalid(k, m))?;
    let mut plan = RowPlan {
        contact,
        collapse_drift_ratio,
        level_rule,
        buildings,
        gaps,
        samples,
        shared_gap: shared,
        gap_axis: layout.gap_axis,
        dims: layout.dims,
        ignored,
        per_scene,
        yielding,
        yield_dim: layout.yield_dim,
        imk_dim: layout.imk_dim,
        storey_columns: false,
        storey_demands: false,
        floor_demands: false,
        struck: Vec::new(),
    };
    plan.struck = plan.struck_columns();
    check_struck_columns(&plan).map_err(|(k, m)| invalid(&k, m))?;
    // A gap study runs no contact and no gap axis: none of them can repeat its runs.
    if reading == Reading::Sweep {
        let shared_values = (rc.gap_m.as_ref()).map_or(0, |a| a.count().unwrap_or(1));
        plan.refuse_idle_axes(raw.contact.is_some(), shared_values)
            .map_err(|(k, m)| invalid(&k, m))?;
    }
    Ok(plan)
}

/// `[sample]` of a row of `nb` buildings: its keys resolved, its points drawn, each checked
/// against what its key takes.
fn row_samples(
    raw: &RawRowConfig,
    nb: usize,
    invalid: &dyn Fn(&str, String) -> ConfigError,
) -> Result<Option<RowSamples>, ConfigError> {
    let Some(smp) = &raw.sample else {
        return Ok(None);
    };
    let all = RowSampled::all(nb);
    let keys = all.iter().map(|a| a.key()).collect::<Vec<_>>().join(", ");
    let (axes, points) = draw_sampled(
        smp,
        invalid,
        &|k| all.iter().copied().find(|a| a.key() == k),
        &keys,
    )?;
    for (j, a) in axes.iter().enumerate() {
        if let Some(m) = refused_draw(&points, j, a.check()) {
            return Err(invalid(&format!("sample.axis[{j}] ({})", a.key()), m));
        }
    }
    Ok(Some(RowSamples { axes, points }))
}

/// `[contact]` as the row runs it. A building alone touches nothing, and a gap study runs no
/// contact: without `[contact]` either takes a linear law it never uses.
fn contact_section(
    raw: &RawRowConfig,
    reading: Reading,
    invalid: &dyn Fn(&str, String) -> ConfigError,
) -> Result<RawContact, ConfigError> {
    match (&raw.contact, raw.building.len()) {
        (Some(c), _) => Ok(c.clone()),
        (None, 1) => Ok(unused_contact()),
        (None, _) if reading == Reading::GapStudy => Ok(unused_contact()),
        (None, _) => Err(invalid(
            "contact",
            "missing: a row of buildings that may touch needs [contact] (law and its stiffness)"
                .into(),
        )),
    }
}

impl RowReader<'_> {
    /// Building `b` (`r` as written): its axes, and its yielding storeys (None: elastic).
    fn building(
        &self,
        b: usize,
        r: &RawShearBuilding,
    ) -> Result<(ShearAxes, Option<YieldSpec>), ConfigError> {
        let key = |k: &str| format!("building[{b}].{k}");
        let n = r.storeys;
        if !(1..=MAX_STOREYS).contains(&n) {
            return Err(self.invalid(&key("storeys"), format!("{n}: expected 1 to {MAX_STOREYS}")));
        }
        let heights = match &r.storey_height_m {
            PerStorey::One(h) => self
                .per_storey(&key("storey_height_m"), &[*h], 1)?
                .repeat(n),
            PerStorey::Each(v) => self.per_storey(&key("storey_height_m"), v, n)?,
        };
        let (floor_masses, mass) = self.masses(b, r, &key)?;
        let profile = match &r.stiffness_profile {
            Some(v) => self.per_storey(&key("stiffness_profile"), v, n)?,
            None => vec![1.0; n],
        };
        let modal = match r.damping.as_deref().unwrap_or("rayleigh") {
            "rayleigh" => false,
            "modal" => true,
            other => {
                return Err(self.invalid(
                    &key("damping"),
                    format!("`{other}`: expected rayleigh or modal"),
                ))
            }
        };
        // A sampled yield drift ratio at its largest (an IMK storey's capping point).
        let sampled_drift = self.samples.and_then(|s| {
            let j = s
                .axes
                .iter()
                .position(|a| *a == RowSampled::YieldDrift(b))?;
            Some(s.points.iter().map(|p| p[j]).fold(0.0, f64::max))
        });
        let sampled_yield = (sampled_drift, self.sampled(RowSampled::YieldShear(b)));
        // Each sampled IMK key with its draws, sample by sample.
        let sampled_imk: Vec<SampledImk> = ImkKey::ALL
            .into_iter()
            .filter_map(|k| {
                let s = self.samples?;
                let j = s.axes.iter().position(|a| *a == RowSampled::Imk(b, k))?;
                Some((k, s.points.iter().map(|p| p[j]).collect()))
            })
            .collect();
        let invalid = |k: &str, m: String| self.invalid(k, m);
        let yielding = parse_yielding(r, n, sampled_yield, &sampled_imk, &key, &invalid)?;
        let period_s = self.required(RowSampled::Period(b), r.period_s.as_ref())?;
        let damping_ratio = self.required(RowSampled::Damping(b), r.damping_ratio.as_ref())?;
        let p_delta = self.p_delta(r, &key)?;
        let struck_column_share = match r.struck_column_share {
            Some(alpha) if !(alpha > 0.0 && alpha <= 1.0) => {
                return Err(self.invalid(
                    &key("struck_column_share"),
                    format!(
                        "{} is out of range: expected a share > 0 and <= 1 (of the storey's stiffness and strength the struck columns carry)",
                        crate::show(alpha)
                    ),
                ))
            }
            alpha => alpha,
        };
        let axes = ShearAxes {
            heights,
            floor_masses,
            mass,
            profile,
            period: self.axis(&key("period_s"), &period_s, PERIOD)?,
            damping: self.axis(&key("damping_ratio"), &damping_ratio, DAMPING)?,
            modal,
            p_delta,
            stability_at_1s: 0.0,
            struck_column_share,
        };
        Ok((axes, yielding))
    }

    /// Building `b`'s masses: fixed per floor (`floor_masses_kg`), or one swept or sampled
    /// mass for every floor (`mass_kg`, its axis; a placeholder where the floors are fixed).
    fn masses(
        &self,
        b: usize,
        r: &RawShearBuilding,
        key: &dyn Fn(&str) -> String,
    ) -> Result<(Option<Vec<f64>>, Vec<f64>), ConfigError> {
        let mass_kg = self.grid_or_sampled(RowSampled::Mass(b), r.mass_kg.as_ref())?;
        if self.sampled(RowSampled::Mass(b)) && r.floor_masses_kg.is_some() {
            return Err(self.invalid(
                &key("floor_masses_kg"),
                format!(
                    "{} is sampled under [sample]: remove floor_masses_kg",
                    key("mass_kg")
                ),
            ));
        }
        match (&mass_kg, &r.floor_masses_kg) {
            (Some(a), None) => Ok((None, self.axis(&key("mass_kg"), a, MASS)?)),
            (None, Some(v)) => {
                let masses = self.per_storey(&key("floor_masses_kg"), v, r.storeys)?;
                if let Some(i) = masses.iter().position(|m| !(MASS.0)(*m)) {
                    return Err(self.invalid(
                        &format!("{}[{i}]", key("floor_masses_kg")),
                        format!(
                            "{} is out of range: expected {}",
                            crate::plan::limits::show(masses[i]),
                            MASS.1
                        ),
                    ));
                }
                Ok((Some(masses), vec![0.0]))
            }
            _ => Err(self.invalid(
                &key("mass_kg"),
                "give mass_kg (every floor, an axis) or floor_masses_kg (one per floor), one of them"
                    .into(),
            )),
        }
    }

    /// A building's P-Delta: its gravity mass ratio, or None without P-Delta.
    fn p_delta(
        &self,
        r: &RawShearBuilding,
        key: &dyn Fn(&str) -> String,
    ) -> Result<Option<f64>, ConfigError> {
        match (r.p_delta, r.gravity_mass_ratio) {
            (Some(true), ratio) => {
                let ratio = ratio.unwrap_or(1.0);
                let max = crate::plan::limits::MAX_GRAVITY_MASS_RATIO;
                if !(0.0..=max).contains(&ratio) {
                    return Err(self.invalid(
                        &key("gravity_mass_ratio"),
                        format!(
                            "{} is out of range: expected a ratio >= 0 and <= {max} (the gravity load over the floors' own weight)",
                            crate::show(ratio)
                        ),
                    ));
                }
                Ok(Some(ratio))
            }
            (_, Some(_)) => Err(self.invalid(
                &key("gravity_mass_ratio"),
                "applies with p_delta = true: add it, or remove gravity_mass_ratio".into(),
            )),
            _ => Ok(None),
        }
    }

    /// The gap between building `b` and the next (none for the last of `nb`), and whether it
    /// is `contact.gap_m`'s (`shared_gap`) rather than its own `gap_right_m`.
    fn gap_right(
        &self,
        b: usize,
        r: &RawShearBuilding,
        nb: usize,
        shared_gap: Option<&Axis>,
    ) -> Result<(Option<Vec<f64>>, bool), ConfigError> {
        let key = format!("building[{b}].gap_right_m");
        let has_right = b + 1 < nb;
        let gap_right = if has_right {
            self.grid_or_sampled(RowSampled::Gap(b), r.gap_right_m.as_ref())?
        } else {
            r.gap_right_m.clone()
        };
        let from_contact = gap_right.is_none();
        let gap = match (&gap_right, has_right, shared_gap) {
            (Some(_), false, _) => {
                return Err(self.invalid(
                    &key,
                    "the last building has no neighbour to its right".into(),
                ))
            }
            (Some(a), true, _) => Some(self.axis(&key, a, GAP)?),
            (None, true, Some(a)) => Some(self.axis("contact.gap_m", a, GAP)?),
            (None, true, None) => {
                return Err(self.invalid(
                    &key,
                    "missing: give contact.gap_m (every pair) or gap_right_m".into(),
                ))
            }
            (None, false, _) => None,
        };
        Ok((gap, from_contact))
    }
}

/// Keys the config gives that no run uses, said before the first run (`shared`: per adjacent
/// pair, whether `contact.gap_m` gives its gap).
fn ignored_keys(raw: &RawRowConfig, rc: &RawContact, shared: &[bool]) -> Vec<String> {
    let mut ignored = Vec::new();
    if raw.building.len() == 1 && raw.contact.is_some() {
        ignored.push("[contact] is ignored: a building alone has no contact".to_string());
    } else if rc.gap_m.is_some() && !shared.contains(&true) {
        ignored.push("contact.gap_m is ignored: every pair has its own gap_right_m".to_string());
    }
    ignored
}

/// Every period each building takes: its samples where sampled (its axis then holds a
/// placeholder), else its axis.
fn periods_taken(buildings: &[ShearAxes], samples: Option<&RowSamples>) -> Vec<Vec<f64>> {
    buildings
        .iter()
        .enumerate()
        .map(|(b, a)| {
            samples
                .iter()
                .find_map(|s| {
                    let j = s.axes.iter().position(|x| *x == RowSampled::Period(b))?;
                    Some(s.points.iter().map(|p| p[j]).collect())
                })
                .unwrap_or_else(|| a.period.clone())
        })
        .collect()
}

/// `run.collapse_drift_ratio`: the drift ratio at which a run collapses (infinite: never).
fn collapse_limit(
    run: &RawRun,
    invalid: &dyn Fn(&str, String) -> ConfigError,
) -> Result<f64, ConfigError> {
    match &run.collapse_drift_ratio {
        None => Ok(crate::plan::limits::COLLAPSE_DRIFT_RATIO),
        Some(CollapseLimit::Ratio(x)) if *x > 0.0 && *x <= 1.0 => Ok(*x),
        Some(CollapseLimit::None) => Ok(f64::INFINITY),
        Some(other) => {
            let given = match other {
                CollapseLimit::Ratio(x) => crate::show(*x),
                CollapseLimit::Other(t) => format!("`{t}`"),
                CollapseLimit::None => unreachable!(),
            };
            Err(invalid(
                "run.collapse_drift_ratio",
                format!(
                    "{given}: expected a drift ratio > 0 and <= 1 (a storey's drift over its height), or \"none\""
                ),
            ))
        }
    }
}

/// The axes below a contact run, in the order runs are numbered.
struct Layout {
    /// Sizes: the samples, then mass, period, damping per building, then the gaps, then each
    /// swept or sampled strength.
    dims: Vec<usize>,
    /// Per adjacent pair, the gap axis it reads ([`RowPlan`]'s `gap_axis`).
    gap_axis: Vec<usize>,
    /// Per building, the index in `dims` of its swept or sampled strength.
    yield_dim: Vec<Option<usize>>,
    /// Per building, the index in `dims` of each of its IMK axes.
    imk_dim: Vec<Vec<usize>>,
}

impl Layout {
    fn of(
        buildings: &[ShearAxes],
        gaps: &[Vec<f64>],
        shared: &[bool],
        yielding: &[Option<YieldSpec>],
        samples: Option<&RowSamples>,
    ) -> Layout {
        let mut dims = vec![samples.map_or(1, |s| s.points.len())];
        dims.extend(
            buildings
                .iter()
                .flat_map(|a| [a.mass.len(), a.period.len(), a.damping.len()]),
        );
        // `contact.gap_m` is one axis: the first pair it gives carries it, the others read it.
        let first_shared = shared.iter().position(|&s| s);
        let gap_axis: Vec<usize> = (0..buildings.len() - 1)
            .map(|a| match first_shared {
                Some(f) if shared[a] => f,
                _ => a,
            })
            .collect();
        dims.extend(
            gaps.iter()
                .enumerate()
                .map(|(a, g)| if gap_axis[a] == a { g.len() } else { 1 }),
        );
        // Each swept or sampled strength, then that building's IMK axes: axes after the gaps
        // (none in an elastic row).
        let mut yield_dim = Vec::new();
        let mut imk_dim = Vec::new();
        for y in yielding {
            let mut push = |n: usize| {
                dims.push(n);
                dims.len() - 1
            };
            yield_dim.push(
                y.as_ref()
                    .and_then(|y| y.axis.as_ref())
                    .map(|a| push(a.len())),
            );
            let imk = y.iter().flat_map(|y| &y.deterioration);
            imk_dim.push(
                imk.flat_map(|d| &d.axes)
                    .map(|(_, v)| push(v.len()))
                    .collect(),
            );
        }
        Layout {
            dims,
            gap_axis,
            yield_dim,
            imk_dim,
        }
    }

    /// The runs below each of `contact_runs` contact runs; None past
    /// [`crate::plan::limits::MAX_RUNS`] in all.
    fn per_scene(&self, contact_runs: u64) -> Option<u64> {
        self.dims
            .iter()
            .try_fold(1u64, |p, &d| p.checked_mul(d as u64))
            .filter(|&p| {
                p.checked_mul(contact_runs)
                    .is_some_and(|n| n <= crate::plan::limits::MAX_RUNS)
            })
    }
}

/// `[levels]` as the rows' rule. Err: the key and why.
fn level_rule(raw: &RawLevels) -> Result<LevelRule, (&'static str, String)> {
    let mut rule = LevelRule::default();
    if let Some(x) = raw.same_level_m {
        if !(MIN_SAME_LEVEL_M..=MAX_SAME_LEVEL_M).contains(&x) {
            return Err((
                "levels.same_level_m",
                format!(
                    "{}: expected a height in m >= {MIN_SAME_LEVEL_M} and <= {MAX_SAME_LEVEL_M} (floors this close are one level; two floors just farther apart share the contact up to twice it, so it cannot be 0)",
                    crate::show(x)
                ),
            ));
        }
        rule.same_level_m = x;
    }
    if let Some(on) = raw.floor_column {
        rule.floor_column = on;
    }
    Ok(rule)
}

/// Each building with `struck_column_share`: a neighbour's floor strikes its columns at some
/// level, and every law of the sweep is the linear one, whose series spring is exact as `k_eff
/// = k k_loc / (k + k_loc)` (the other laws need the struck point as an internal coordinate,
/// not built yet). Err: the key and why.
fn check_struck_columns(plan: &RowPlan) -> Result<(), (String, String)> {
    let levels = if plan.is_empty() {
        Vec::new()
    } else {
        plan.levels()
    };
    for (b, a) in plan.buildings.iter().enumerate() {
        if a.struck_column_share.is_none() {
            continue;
        }
        let key = format!("building[{b}].struck_column_share");
        if let Some(law) = (plan.contact.spec.laws.iter()).find(|l| **l != LawKind::Linear) {
            return Err((
                key,
                format!(
                    "applies with law = \"linear\" only so far (its series spring with the columns is exact as k_eff = k k_loc / (k + k_loc)); `{}` needs the struck point as an internal coordinate, which is not built yet: use the linear law or remove the key",
                    law.key()
                ),
            ));
        }
        let struck = levels.iter().any(|l| {
            crate::physics::row::struck_side(&l.sides).is_some_and(|side| l.left + side == b)
        });
        if !struck {
            return Err((
                key,
                "no neighbour's floor strikes this building's columns (every level is floor against floor, or floor_column is off): remove the key".into(),
            ));
        }
    }
    Ok(())
}

/// Every P-Delta building stable under gravity alone at every period it takes (`taken`): each
/// storey's stability coefficient `theta_j = P_j / (k_j h_j)` below 1. With the floor masses
/// fixed, or all one swept mass, `theta` grows with the period squared and does not depend on
/// the mass, so the longest period decides. Err: the key and why.
fn check_stability(
    buildings: &mut [ShearAxes],
    taken: &[Vec<f64>],
) -> Result<(), (String, String)> {
    for (b, (a, periods)) in buildings.iter_mut().zip(taken).enumerate() {
        let Some(ratio) = a.p_delta else { continue };
        let period = periods.iter().cloned().fold(0.0, f64::max);
        let at_1s = stability_at_1s(a, ratio);
        a.stability_at_1s = at_1s.iter().cloned().fold(0.0, f64::max);
        // As the column reads it: theta at `period` is theta at 1 s times `period^2`.
        let theta: Vec<f64> = at_1s.iter().map(|t| t * period * period).collect();
        if let Some(j) = theta.iter().position(|t| *t >= 1.0) {
            return Err((
                format!("building[{b}].p_delta"),
                format!(
                    "storey {} is unstable under gravity alone at period_s = {}: its stability coefficient P/(k h) is {} (>= 1; gravity_mass_ratio {}): a shorter period, a lower gravity_mass_ratio or a stiffer storey",
                    j + 1,
                    crate::show(period),
                    crate::show(theta[j]),
                    crate::show(ratio)
                ),
            ));
        }
    }
    Ok(())
}
