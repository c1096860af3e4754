//! Sweeps of rows of multi-storey buildings: a config with `[[building]]` entries (left to
//! right) instead of `[building1]` and `[building2]`.
//!
//! Everything but the buildings and gaps (laws, formulas, `e`, stiffness, records,
//! intensities, the scheme) is the shared [`ContactPlan`], read and validated by the same code
//! as a pair's; the row plan adds, below each contact run, the axes of each building (floor
//! mass, fundamental period, damping ratio) and each adjacent pair's gap, outermost first, the
//! last gap innermost.

use crate::physics::model::Forcing;
use crate::physics::row::{struck_side, Level, LevelRule, LevelSide, Row, RowOutput, StoreyOutput};
use crate::physics::shear::{Damping, ShearBuilding, Yielding, MAX_STOREYS};
use crate::physics::solver::row::RowScheme;
use crate::physics::solver::Scheme;
use crate::plan::columns;
use crate::plan::config::{
    draw_sampled, parse_contact, Axis, ConfigError, RawContact, RawIntensity, RawRecord, RawRun,
    RawSample, Reading,
};
use crate::plan::sample::refused_draw;
use crate::plan::{
    check_axis, config, Check, ContactPlan, ContactRun, RunSpec, DAMPING, GAP, MASS, PERIOD,
    POSITIVE,
};
use serde::Deserialize;
use std::path::Path;

/// A yield drift ratio: > 0 and at most 0.2.
const YIELD_DRIFT: Check = (|x| x > 0.0 && x <= 0.2, "a drift ratio > 0 and <= 0.2");
/// A base-shear coefficient (base shear strength over weight): > 0 and at most 10.
const YIELD_SHEAR: Check = (
    |x| x > 0.0 && x <= 10.0,
    "a coefficient > 0 and <= 10 (base shear strength / weight)",
);

/// One value for every storey, or one per storey (bottom to top).
#[derive(Debug, Clone, PartialEq)]
pub enum PerStorey {
    One(f64),
    Each(Vec<f64>),
}

config::forms!(PerStorey, "a number (every storey) or a list of numbers (one per storey, bottom to top)", {
    number: Some(PerStorey::One),
    text: None,
    list: Some(|s| config::elements(s).map(PerStorey::Each)),
    table: None,
});

/// The column prefix of a contact level: `level_b1f3_b2f3` for floor 3 of building 1 (`left`
/// = 0, buildings from 0 here) against floor 3 of building 2 (floors from 1);
/// `level_b1f3_b2c4` where floor 3 of building 1 strikes the columns of building 2's storey 4.
pub fn level_name(left: usize, sides: &[LevelSide; 2]) -> String {
    format!(
        "level_b{}{}_b{}{}",
        left + 1,
        sides[0].name(),
        left + 2,
        sides[1].name()
    )
}

/// `[levels]` as written: which contact levels a row has.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawLevels {
    /// Floors this close are one floor/floor level, m (default 0.01).
    pub same_level_m: Option<f64>,
    /// A floor that faces a neighbour's storey strikes its columns (default true).
    pub floor_column: Option<bool>,
}

/// A storey stability coefficient `P/(k h)` above which a sweep warns before any run: up to it
/// design codes neglect P-Delta (ASCE 7 section 12.8.7).
pub const WARN_STABILITY: f64 = 0.1;

/// The largest `[levels] same_level_m`: the depth of a thick slab, m.
pub const MAX_SAME_LEVEL_M: f64 = 0.5;
/// The smallest, m: two floors just beyond it apart share the contact up to twice it
/// ([`crate::physics::row::contact_points`]), so at 0 floors a rounding apart would be two
/// whole points.
pub const MIN_SAME_LEVEL_M: f64 = 0.001;

/// One `[[building]]` as written.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawShearBuilding {
    pub storeys: usize,
    pub storey_height_m: PerStorey,
    /// Every floor's mass (an axis), or `floor_masses_kg`.
    pub mass_kg: Option<Axis>,
    pub floor_masses_kg: Option<Vec<f64>>,
    /// Relative storey stiffnesses, bottom to top (default uniform), scaled to `period_s`.
    pub stiffness_profile: Option<Vec<f64>>,
    /// May be left out when sampled, as may `mass_kg`.
    pub period_s: Option<Axis>,
    pub damping_ratio: Option<Axis>,
    /// `rayleigh` (the ratio on modes 1 and 2, the default) or `modal` (on every mode).
    pub damping: Option<String>,
    /// The gap to the next building (default `contact.gap_m`).
    pub gap_right_m: Option<Axis>,
    /// Yielding storeys (physics.md section 8): one of `yield_drift_ratio` (`F_y = k theta_y
    /// h`), `yield_force_n` (per storey) or `yield_base_shear_coefficient` (`C_y`: base shear
    /// strength `C_y W`, `W` the weight, storey strengths from `yield_shear_distribution`);
    /// `post_yield_ratio` (`b`, default 0: elastic-perfectly-plastic). Absent: elastic.
    pub yield_drift_ratio: Option<YieldDrift>,
    pub yield_force_n: Option<PerStorey>,
    pub yield_base_shear_coefficient: Option<Axis>,
    /// `inverted_triangular` (lateral forces `~ m_i z_i`, the default) or `uniform` (`~ m_i`).
    pub yield_shear_distribution: Option<String>,
    pub post_yield_ratio: Option<PerStorey>,
    /// Which stiffness the Rayleigh or modal damping is built on: `initial` (the only choice;
    /// tangent-stiffness damping can create spurious damping forces after yielding).
    pub damping_stiffness: Option<String>,
    /// P-Delta (physics.md section 10): storey `j`'s force gains `-P_j d_j / h_j`.
    pub p_delta: Option<bool>,
    /// With `p_delta`: floor `j` carries the gravity load `g m_j gravity_mass_ratio` (default
    /// 1; 2 or 3 where a leaning column carries gravity the frame does not resist).
    pub gravity_mass_ratio: Option<f64>,
}

/// `yield_drift_ratio` as written: one value for every storey, one per storey, or a range
/// table (`{ from, to, n }`): an axis of values each for every storey.
#[derive(Debug, Clone, PartialEq)]
pub enum YieldDrift {
    One(f64),
    Each(Vec<f64>),
    Axis(crate::plan::config::RangeSpec),
}

config::forms!(YieldDrift, "a drift ratio (every storey), a list of them (one per storey, bottom to top), or a range table { from, to, n } / { from, to, step } (an axis of values each for every storey)", {
    number: Some(YieldDrift::One),
    text: None,
    list: Some(|s| config::elements(s).map(YieldDrift::Each)),
    table: Some(|m| {
        crate::plan::config::RangeSpec::deserialize(serde::de::value::MapAccessDeserializer::new(m))
            .map(YieldDrift::Axis)
    }),
});

/// How strong a yielding building's storeys are.
#[derive(Debug, Clone, PartialEq)]
pub enum YieldStrength {
    /// Per storey, `F_y,j = k_j theta_j h_j`.
    DriftRatio(Vec<f64>),
    /// Per storey, N.
    Force(Vec<f64>),
    /// Base shear strength `coefficient W` (`W = g sum m`), storey `j` carrying the lateral
    /// forces above it, `~ m_i z_i` (`triangular`) or `~ m_i`.
    BaseShear { coefficient: f64, triangular: bool },
}

/// A yielding building's storeys, as the config gives them.
#[derive(Debug, Clone, PartialEq)]
pub struct YieldSpec {
    pub strength: YieldStrength,
    /// Post-yield stiffness ratio per storey.
    pub post_yield: Vec<f64>,
    /// Where the strength's one value (a yield drift ratio for every storey, or a base-shear
    /// coefficient) is an axis: its values (one placeholder where it is sampled). A run's
    /// value ([`RowRunSpec::yield_value`]) replaces the strength's.
    pub axis: Option<Vec<f64>>,
}

impl YieldSpec {
    /// The name of the swept or sampled value: `yield_drift_ratio` or
    /// `yield_base_shear_coefficient`.
    pub fn value_name(&self) -> &'static str {
        match self.strength {
            YieldStrength::BaseShear { .. } => "yield_base_shear_coefficient",
            _ => "yield_drift_ratio",
        }
    }

    /// The storeys of `b` (its stiffnesses, masses and heights final), with the run's `value`
    /// of the swept strength where it has one.
    pub fn of(&self, b: &ShearBuilding, value: Option<f64>) -> Yielding {
        let force = match &self.strength {
            YieldStrength::DriftRatio(theta) => {
                let theta = match value {
                    Some(v) => vec![v; theta.len()],
                    None => theta.clone(),
                };
                return Yielding::from_drift_ratio(
                    &b.stiffness,
                    &b.heights,
                    &theta,
                    self.post_yield.clone(),
                );
            }
            YieldStrength::Force(f) => f.clone(),
            YieldStrength::BaseShear {
                coefficient,
                triangular,
            } => {
                let coefficient = value.unwrap_or(*coefficient);
                let z = b.elevations();
                let w: Vec<f64> = b
                    .masses
                    .iter()
                    .zip(&z)
                    .map(|(m, z)| if *triangular { m * z } else { *m })
                    .collect();
                let total: f64 = w.iter().sum();
                let base = coefficient * crate::record::G * b.masses.iter().sum::<f64>();
                (0..w.len())
                    .map(|j| base * w[j..].iter().sum::<f64>() / total)
                    .collect()
            }
        };
        Yielding {
            force,
            post_yield: self.post_yield.clone(),
        }
    }
}

/// A row config as written.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawRowConfig {
    #[serde(default)]
    pub run: RawRun,
    pub building: Vec<RawShearBuilding>,
    /// May be left out for a building alone (nothing to touch).
    pub contact: Option<RawContact>,
    #[serde(rename = "record", default)]
    pub records: Vec<RawRecord>,
    #[serde(default)]
    pub intensity: RawIntensity,
    pub sample: Option<RawSample>,
    #[serde(default)]
    pub levels: RawLevels,
}

/// One building's axes.
#[derive(Debug, Clone, PartialEq)]
pub struct ShearAxes {
    pub heights: Vec<f64>,
    /// Fixed floor masses, or None where `mass` is swept.
    pub floor_masses: Option<Vec<f64>>,
    /// kg, every floor (one placeholder where `floor_masses` is given).
    pub mass: Vec<f64>,
    pub profile: Vec<f64>,
    pub period: Vec<f64>,
    pub damping: Vec<f64>,
    pub modal: bool,
    /// With P-Delta, its gravity mass ratio (None: no P-Delta).
    pub p_delta: Option<f64>,
    /// With P-Delta, its largest storey stability coefficient at a period of 1 s: at period
    /// `T` it is this times `T^2` (the storey stiffnesses scale as `1 / T^2`, the gravity loads
    /// and the stiffnesses alike with a uniform floor mass).
    pub stability_at_1s: f64,
}

impl ShearAxes {
    pub fn storeys(&self) -> usize {
        self.heights.len()
    }
}

/// A parameter of a row that `[sample]` can set (buildings numbered from 0, as in the keys).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RowSampled {
    /// `building[b].mass_kg`: every floor of building `b`.
    Mass(usize),
    /// `building[b].period_s`.
    Period(usize),
    /// `building[b].damping_ratio`.
    Damping(usize),
    /// `building[b].gap_right_m`: the gap between buildings `b` and `b + 1`.
    Gap(usize),
    /// `contact.gap_m`: every gap not given per building.
    SharedGap,
    /// `contact.k_n_per_m`, for linear laws.
    KLinear,
    /// `contact.beta_n_per_m1_5`, for Hertz-type laws.
    Beta,
    /// `building[b].yield_drift_ratio`: every storey's yield drift ratio.
    YieldDrift(usize),
    /// `building[b].yield_base_shear_coefficient`.
    YieldShear(usize),
}

impl RowSampled {
    /// The config key.
    pub fn key(self) -> String {
        match self {
            RowSampled::Mass(b) => format!("building[{b}].mass_kg"),
            RowSampled::Period(b) => format!("building[{b}].period_s"),
            RowSampled::Damping(b) => format!("building[{b}].damping_ratio"),
            RowSampled::Gap(b) => format!("building[{b}].gap_right_m"),
            RowSampled::SharedGap => "contact.gap_m".into(),
            RowSampled::KLinear => "contact.k_n_per_m".into(),
            RowSampled::Beta => "contact.beta_n_per_m1_5".into(),
            RowSampled::YieldDrift(b) => format!("building[{b}].yield_drift_ratio"),
            RowSampled::YieldShear(b) => format!("building[{b}].yield_base_shear_coefficient"),
        }
    }

    /// Every key of a row of `nb` buildings.
    fn all(nb: usize) -> Vec<RowSampled> {
        let mut all: Vec<RowSampled> = (0..nb)
            .flat_map(|b| [Self::Mass(b), Self::Period(b), Self::Damping(b)])
            .collect();
        all.extend((0..nb - 1).map(Self::Gap));
        all.extend([Self::SharedGap, Self::KLinear, Self::Beta]);
        all.extend((0..nb).flat_map(|b| [Self::YieldDrift(b), Self::YieldShear(b)]));
        all
    }

    /// What a drawn value must be.
    fn check(self) -> Check {
        match self {
            RowSampled::Period(_) => PERIOD,
            RowSampled::Damping(_) => DAMPING,
            RowSampled::Gap(_) | RowSampled::SharedGap => GAP,
            RowSampled::YieldDrift(_) => YIELD_DRIFT,
            RowSampled::YieldShear(_) => YIELD_SHEAR,
            _ => POSITIVE,
        }
    }
}

impl RowSampled {
    /// Does it set a building's mass, period or damping?
    pub fn moves_buildings(self) -> bool {
        matches!(
            self,
            RowSampled::Mass(_)
                | RowSampled::Period(_)
                | RowSampled::Damping(_)
                | RowSampled::YieldDrift(_)
                | RowSampled::YieldShear(_)
        )
    }
}

/// Joint samples of some of a row's parameters: `points[s][j]` is the value of `axes[j]` in
/// sample `s`.
#[derive(Debug, Clone, PartialEq)]
pub struct RowSamples {
    pub axes: Vec<RowSampled>,
    pub points: Vec<Vec<f64>>,
}

/// A validated row sweep.
#[derive(Debug, Clone)]
pub struct RowPlan {
    /// Laws, formulas, `e`, stiffness, records, intensities and the scheme: the axes every
    /// scene shares.
    pub contact: ContactPlan,
    /// A run collapses when any storey's drift ratio reaches this (infinite: never).
    pub collapse_drift_ratio: f64,
    /// Which contact levels the rows have (`[levels]`).
    pub level_rule: LevelRule,
    /// Per contact level where a floor strikes a column: whether the struck storey yields
    /// (None for a floor/floor level). Set once the plan is made ([`RowPlan::struck_columns`]).
    struck: Vec<Option<bool>>,
    pub buildings: Vec<ShearAxes>,
    /// m, per adjacent pair.
    pub gaps: Vec<Vec<f64>>,
    /// Sampled parameters, crossed with every grid axis (their grid axes hold a placeholder).
    pub samples: Option<RowSamples>,
    /// Which gaps `contact.gap_m` gives (the others are given per building).
    shared_gap: Vec<bool>,
    /// Per adjacent pair, the gap axis it reads: its own, or for every pair that
    /// `contact.gap_m` gives, the first such pair's. `contact.gap_m` is one gap shared by those
    /// pairs, in the grid as under `[sample]`; `gap_right_m` gives a pair an axis of its own.
    gap_axis: Vec<usize>,
    /// Sizes of the axes below a contact run: the samples, then mass, period, damping per
    /// building, then the gaps.
    dims: Vec<usize>,
    /// Keys the config gives that no run uses, with why.
    ignored: Vec<String>,
    per_scene: u64,
    /// Per building, its yielding storeys (None: elastic).
    pub yielding: Vec<Option<YieldSpec>>,
    /// Per building, the index in `dims` of its swept or sampled strength (after the gaps).
    yield_dim: Vec<Option<usize>>,
    /// Write each yielding storey's columns too (`bk_sj_...`, [`STOREY_OUTPUTS`]): set where
    /// `--columns` asks for one ([`RowPlan::asks_storey_columns`]).
    pub storey_columns: bool,
}

/// One run of a row sweep, decoded.
#[derive(Debug, Clone, PartialEq)]
pub struct RowRunSpec {
    pub index: u64,
    /// Law, formula, `e`, stiffness, record and intensity.
    pub contact: ContactRun,
    /// Per building: floor mass (None where fixed per floor), fundamental period, damping ratio.
    pub mass: Vec<Option<f64>>,
    pub period: Vec<f64>,
    pub damping: Vec<f64>,
    pub gaps: Vec<f64>,
    /// Index of the sample that set the sampled parameters (None without sampling).
    pub sample: Option<usize>,
    /// Per building, the value of its swept or sampled strength (None where fixed or elastic).
    pub yield_value: Vec<Option<f64>>,
}

impl RowPlan {
    pub fn len(&self) -> u64 {
        self.contact.len() * self.per_scene
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    pub fn run(&self, index: u64) -> RowRunSpec {
        let mut contact = self.contact.decode(index / self.per_scene);
        contact.index = index;
        let mut rest = index % self.per_scene;
        let mut at = vec![0usize; self.dims.len()];
        for (k, &d) in self.dims.iter().enumerate().rev() {
            at[k] = (rest % d as u64) as usize;
            rest /= d as u64;
        }
        let nb = self.buildings.len();
        let mut run = RowRunSpec {
            index,
            contact,
            mass: (0..nb)
                .map(|b| {
                    let a = &self.buildings[b];
                    a.floor_masses.is_none().then(|| a.mass[at[1 + 3 * b]])
                })
                .collect(),
            period: (0..nb)
                .map(|b| self.buildings[b].period[at[2 + 3 * b]])
                .collect(),
            damping: (0..nb)
                .map(|b| self.buildings[b].damping[at[3 + 3 * b]])
                .collect(),
            gaps: (0..nb - 1)
                .map(|a| self.gaps[a][at[1 + 3 * nb + self.gap_axis[a]]])
                .collect(),
            sample: None,
            yield_value: (0..nb)
                .map(|b| {
                    let axis = self.yielding[b].as_ref()?.axis.as_ref()?;
                    Some(axis[at[self.yield_dim[b]?]])
                })
                .collect(),
        };
        if let Some(smp) = &self.samples {
            run.sample = Some(at[0]);
            let law = run.contact.law;
            for (a, &v) in smp.axes.iter().zip(&smp.points[at[0]]) {
                match *a {
                    RowSampled::Mass(b) => run.mass[b] = Some(v),
                    RowSampled::Period(b) => run.period[b] = v,
                    RowSampled::Damping(b) => run.damping[b] = v,
                    RowSampled::Gap(b) => run.gaps[b] = v,
                    RowSampled::SharedGap => {
                        for (g, shared) in run.gaps.iter_mut().zip(&self.shared_gap) {
                            if *shared {
                                *g = v;
                            }
                        }
                    }
                    RowSampled::KLinear if !law.is_hertzian() => run.contact.stiffness = v,
                    RowSampled::Beta if law.is_hertzian() => run.contact.stiffness = v,
                    RowSampled::KLinear | RowSampled::Beta => {}
                    RowSampled::YieldDrift(b) | RowSampled::YieldShear(b) => {
                        run.yield_value[b] = Some(v)
                    }
                }
            }
        }
        self.contact.scale(&mut run.contact, &run.period);
        run
    }

    /// The runs that differ in their motion before any contact ([`PairPlan::motions`]): per
    /// record and intensity, the samples (one where they set no building value), every
    /// building's values and swept strengths, the gaps at their first values.
    pub fn motions(&self) -> crate::plan::Motions {
        let dims = self.motion_dims();
        crate::plan::Motions {
            records: self.contact.spec.records.len(),
            intensities: self.contact.spec.intensities.len(),
            inner: dims.iter().map(|&(_, d)| d as u64).product(),
        }
    }

    /// The axes below a contact run that move the buildings, as (index in `dims`, size): the
    /// samples (one where they set no building value), each building's mass, period and
    /// damping, and each swept strength.
    fn motion_dims(&self) -> Vec<(usize, usize)> {
        let nb = self.buildings.len();
        let samples = match &self.samples {
            Some(s) if s.axes.iter().any(|a| a.moves_buildings()) => s.points.len(),
            _ => 1,
        };
        std::iter::once((0, samples))
            .chain((1..1 + 3 * nb).map(|k| (k, self.dims[k])))
            .chain(self.yield_dim.iter().flatten().map(|&k| (k, self.dims[k])))
            .collect()
    }

    /// Motion `m` of [`RowPlan::motions`], as the run of the plan that has it (its sample
    /// `None` where the samples move nothing).
    pub fn motion_run(&self, m: u64) -> RowRunSpec {
        let dims = self.motion_dims();
        let inner: u64 = dims.iter().map(|&(_, d)| d as u64).product();
        let contact = self.contact.motion_index(m / inner);
        let mut rem = m % inner;
        let mut at = vec![0usize; self.dims.len()];
        for &(k, d) in dims.iter().rev() {
            at[k] = (rem % d as u64) as usize;
            rem /= d as u64;
        }
        let within =
            (0..self.dims.len()).fold(0u64, |acc, k| acc * self.dims[k] as u64 + at[k] as u64);
        let mut run = self.run(contact * self.per_scene + within);
        if dims[0].1 == 1 {
            run.sample = None;
        }
        run
    }

    /// How the gaps take their axes (the fingerprint covers it): per adjacent pair, whether
    /// `contact.gap_m` gives its gap, and the gap axis it reads.
    pub fn gap_layout(&self) -> (&[bool], &[usize]) {
        (&self.shared_gap, &self.gap_axis)
    }

    /// The summed cost of runs `0..end` when a run costs `record_cost[r]` for its record `r`
    /// (the contact runs', each repeated for the row's own axes).
    pub fn cost_before(&self, end: u64, record_cost: &[u64]) -> u128 {
        self.contact
            .scene_cost_before(end, self.per_scene, record_cost)
    }

    /// What a user should hear before any run: records scaled past 5 g (a target at a
    /// building's period read at the first run's), each adjacent pair that shares no floor
    /// level, and keys the config gives that no run uses.
    pub fn warnings(&self) -> Vec<String> {
        let mut w = self.contact.pga_warnings(&self.run(0).period);
        w.extend(self.pairs_without_levels());
        w.extend(self.leaning_storeys());
        w.extend(self.ignored.iter().cloned());
        w
    }

    /// Each P-Delta building with a storey whose stability coefficient `P/(k h)` passes
    /// [`WARN_STABILITY`] at the longest period it takes (where it is largest: it grows as the
    /// period squared), naming the storey and the value. Such a building is stable (the plan
    /// refuses `theta >= 1`) but far softer than its `period_s` says.
    pub fn leaning_storeys(&self) -> Vec<String> {
        let mut w = Vec::new();
        for (b, a) in self.buildings.iter().enumerate() {
            let Some(ratio) = a.p_delta else { continue };
            let mut period = a.period.iter().cloned().fold(0.0, f64::max);
            if let Some(smp) = &self.samples {
                for (j, x) in smp.axes.iter().enumerate() {
                    if *x == RowSampled::Period(b) {
                        period = smp.points.iter().map(|p| p[j]).fold(0.0, f64::max);
                    }
                }
            }
            let theta: Vec<f64> = stability_at_1s(a, ratio)
                .iter()
                .map(|t| t * period * period)
                .collect();
            let above = theta.iter().filter(|t| **t > WARN_STABILITY).count();
            let Some((j, worst)) = theta
                .iter()
                .enumerate()
                .filter(|(_, t)| **t > WARN_STABILITY)
                .max_by(|x, y| x.1.total_cmp(y.1))
            else {
                continue;
            };
            let others = match above {
                1 => String::new(),
                n => format!(
                    "; {} storeys of {} are above {WARN_STABILITY}",
                    n,
                    theta.len()
                ),
            };
            w.push(format!(
                "building {} (p_delta, gravity_mass_ratio {}): storey {} has a stability coefficient P/(k h) of {worst:.3} at period_s = {} (its longest{others}), above {WARN_STABILITY}: gravity takes that share of the storey's stiffness (an elastic storey's period is T0 / sqrt(1 - theta), {:.2} T0 here), past where design codes neglect P-Delta (ASCE 7 section 12.8.7); check gravity_mass_ratio and period_s",
                b + 1,
                crate::show(ratio),
                j + 1,
                crate::show(period),
                1.0 / (1.0 - worst).sqrt(),
            ));
        }
        w
    }

    /// Each adjacent pair with no contact level, and why: no floor at a common elevation, and
    /// floors that strike columns turned off (`[levels] floor_column = false`), so no run
    /// checks them for contact. Heights are not swept, so this holds for every run of the
    /// plan.
    pub fn pairs_without_levels(&self) -> Vec<String> {
        let row = self.row(&self.run(0));
        let elevations = |b: &ShearBuilding| -> Vec<String> {
            // To the micrometre: a sum of storey heights shows its rounding past that.
            (b.elevations().iter())
                .map(|z| {
                    let t = format!("{z:.6}");
                    t.trim_end_matches('0').trim_end_matches('.').to_string()
                })
                .collect()
        };
        (0..self.buildings.len() - 1)
            .filter(|&a| !row.levels.iter().any(|l| l.left == a))
            .map(|a| {
                format!(
                    "buildings {} and {} share no floor level (floors at {} m against {} m; levels meet within {} m) and [levels] floor_column = false: floors that strike columns are turned off, so this pair is never checked for contact and has no level columns",
                    a + 1,
                    a + 2,
                    elevations(&row.buildings[a]).join(", "),
                    elevations(&row.buildings[a + 1]).join(", "),
                    self.level_rule.same_level_m
                )
            })
            .collect()
    }

    /// RK4 substeps per record step in contact above which a sweep says, before it starts,
    /// that its runs are costly (typical scenes take tens to a few hundred).
    pub const COSTLY_SUBSTEPS: f64 = 20_000.0;

    /// A notice when a run of this plan may take extreme work: contact substeps resolve the
    /// fastest mode of the buildings in contact (`h = 2 pi / (substeps_per_contact rate)`, the
    /// rate the solver takes, `RowModel::building_rates`), so a record step in contact costs
    /// `dt substeps_per_contact rate / 2 pi` substeps, which grows as 1 / T. Estimated with
    /// every building at its shortest swept (or sampled) period.
    pub fn cost_warning(&self, substeps_per_contact: f64) -> Option<String> {
        if self.is_empty() {
            return None;
        }
        let dt = self
            .contact
            .spec
            .records
            .iter()
            .map(|r| r.dt)
            .fold(0.0, f64::max);
        let mut run = self.run(0);
        for (b, axes) in self.buildings.iter().enumerate() {
            let mut shortest = axes.period.iter().cloned().fold(f64::INFINITY, f64::min);
            if let Some(smp) = &self.samples {
                for (j, a) in smp.axes.iter().enumerate() {
                    if *a == RowSampled::Period(b) {
                        shortest = smp.points.iter().map(|p| p[j]).fold(shortest, f64::min);
                    }
                }
            }
            run.period[b] = shortest;
        }
        let rates = crate::physics::solver::row::RowModel::new(&self.row(&run)).building_rates();
        let (b, rate) = rates
            .into_iter()
            .enumerate()
            .max_by(|x, y| x.1.total_cmp(&y.1))?;
        let period = run.period[b];
        let per_step = dt * substeps_per_contact * rate / (2.0 * std::f64::consts::PI);
        (per_step > Self::COSTLY_SUBSTEPS).then(|| {
            format!(
                "building {} at period_s = {period} s: its fastest mode makes every record step in contact take about {per_step:.0} RK4 substeps (dt {dt} s x substeps_per_contact {substeps_per_contact} x its rate / 2 pi; typical scenes take tens to hundreds): runs may take minutes each",
                b + 1
            )
        })
    }

    /// Runs among `rows` in which a building's peak roof displacement exceeds its height (the
    /// sum of its storey heights): physically absurd, as for pairs
    /// ([`crate::plan::limits::above_height`]).
    pub fn above_height(&self, rows: &[(RowRunSpec, RowOutput)]) -> u64 {
        let heights: Vec<f64> = self
            .buildings
            .iter()
            .map(|b| b.heights.iter().sum())
            .collect();
        rows.iter()
            .filter(|(_, o)| {
                o.buildings
                    .iter()
                    .zip(&heights)
                    .any(|(b, h)| b.peak_roof > *h)
            })
            .count() as u64
    }

    /// The scene of `run`.
    pub fn row(&self, run: &RowRunSpec) -> Row {
        let buildings = self
            .buildings
            .iter()
            .enumerate()
            .map(|(b, a)| {
                let masses = match (&a.floor_masses, run.mass[b]) {
                    (Some(m), _) => m.clone(),
                    (None, m) => vec![m.expect("a swept mass"); a.storeys()],
                };
                let damping = if a.modal {
                    Damping::Modal(run.damping[b])
                } else {
                    Damping::Rayleigh(run.damping[b])
                };
                let mut s = ShearBuilding::from_period(
                    masses,
                    &a.profile,
                    a.heights.clone(),
                    run.period[b],
                    damping,
                );
                s.yielding = self.yielding[b]
                    .as_ref()
                    .map(|y| y.of(&s, run.yield_value[b]));
                match a.p_delta {
                    Some(ratio) => s.with_p_delta(ratio),
                    None => s,
                }
            })
            .collect();
        let s = &run.contact;
        let rule = self.level_rule;
        Row::with_levels(
            buildings,
            run.gaps.clone(),
            s.law,
            s.stiffness,
            s.damping,
            rule,
        )
        .with_collapse(self.collapse_drift_ratio)
    }

    pub fn forcing(&self, run: &RowRunSpec) -> Forcing<'_> {
        self.contact.forcing(&run.contact)
    }

    /// The contact levels of every run (with the first run's contact elements): they depend
    /// only on storeys and heights, which no axis sweeps, so every run of the plan has the
    /// same levels.
    pub fn levels(&self) -> Vec<Level> {
        self.row(&self.run(0)).levels
    }

    /// The contact levels' column prefixes ([`level_name`]).
    pub fn level_names(&self) -> Vec<String> {
        (self.levels().iter())
            .map(|l| level_name(l.left, &l.sides))
            .collect()
    }

    /// Per contact level where a floor strikes a column, whether the struck storey yields
    /// (None for a floor/floor level).
    fn struck_columns(&self) -> Vec<Option<bool>> {
        if self.is_empty() {
            return Vec::new();
        }
        (self.levels().iter())
            .map(|l| {
                let side = struck_side(&l.sides)?;
                Some(self.yielding[l.left + side].is_some())
            })
            .collect()
    }

    /// The contact levels as a Markdown table: each one's column prefix, kind (floor/floor or
    /// floor/column), elevation and, on a column, the struck storey's height fraction `xi` and
    /// the share `s` of the force on its top floor (`pound columns CONFIG`).
    pub fn level_table(&self) -> String {
        let mut t = String::from(
            "| level | kind | elevation m | struck storey: xi | share on its top floor s |\n|---|---|---:|---:|---:|\n",
        );
        let row = self.row(&self.run(0));
        for (l, name) in row.levels.iter().zip(self.level_names()) {
            let (kind, xi, s) = match struck_side(&l.sides) {
                None => ("floor/floor", String::new(), String::new()),
                Some(k) => {
                    let b = &row.buildings[l.left + k];
                    let j = l.sides[k].floor;
                    let below: f64 = b.heights[..j - 1].iter().sum();
                    let xi = (l.elevation - below) / b.heights[j - 1];
                    let s = l.sides[k].weight;
                    ("floor/column", format!("{xi:.3}"), format!("{s:.3}"))
                }
            };
            t.push_str(&format!(
                "| `{name}` | {kind} | {} | {xi} | {s} |\n",
                crate::show(l.elevation)
            ));
        }
        t
    }

    /// Every column, in file order: the contact and motion columns of the pair, each
    /// building's `Sa(T1)` of the scaled record (`b1_sa_t1_g`, ...), each building's
    /// parameters (`b1_...`), each gap, the status and totals, each building's
    /// peaks, each level's, and the energy balance (empty unless asked for).
    pub fn header(&self) -> Vec<String> {
        let mut h: Vec<String> = columns::HEADER[..columns::CONTACT_AND_MOTION]
            .iter()
            .map(|s| s.to_string())
            .collect();
        let nb = self.buildings.len();
        for b in 1..=nb {
            h.push(format!("b{b}_{}", crate::plan::intensity::SA_T1_COLUMN));
        }
        for b in 1..=nb {
            for c in ["storeys", "mass_kg", "t1_s", "xi"] {
                h.push(format!("b{b}_{c}"));
            }
            if let Some(y) = self.swept_yield(b - 1) {
                h.push(format!("b{b}_{}", y.value_name()));
            }
        }
        for a in 1..nb {
            h.push(format!("gap_{a}_{}_m", a + 1));
        }
        h.push("sample".into());
        for c in [
            "status",
            "impacts",
            "peak_force_n",
            "peak_penetration_m",
            "impact_velocity_m_s",
            "first_impact_s",
            "contact_time_s",
            "dissipated_energy_j",
            "substeps",
        ] {
            h.push(c.into());
        }
        if self.collapse_drift_ratio.is_finite() {
            for c in COLLAPSE_OUTPUTS {
                h.push(c.into());
            }
        }
        for (b, y) in self.yielding.iter().enumerate() {
            for c in BUILDING_OUTPUTS {
                h.push(format!("b{}_{c}", b + 1));
            }
            if self.buildings[b].p_delta.is_some() {
                h.push(format!("b{}_stability_coefficient", b + 1));
            }
            if self.collapse_drift_ratio.is_finite() {
                for c in BUILDING_COLLAPSE_OUTPUTS {
                    h.push(format!("b{}_{c}", b + 1));
                }
            }
            if y.is_some() {
                for c in INELASTIC_OUTPUTS {
                    h.push(format!("b{}_{c}", b + 1));
                }
                if self.storey_columns {
                    for j in 1..=self.buildings[b].storeys() {
                        for c in STOREY_OUTPUTS {
                            h.push(format!("b{}_s{j}_{c}", b + 1));
                        }
                    }
                }
            }
        }
        for (l, struck) in self.level_names().iter().zip(&self.struck) {
            for c in LEVEL_OUTPUTS {
                h.push(format!("{l}_{c}"));
            }
            if let Some(yields) = struck {
                h.push(format!("{l}_column_shear_n"));
                if *yields {
                    h.push(format!("{l}_column_shear_ratio"));
                }
            }
        }
        for c in ["input_energy_j", "damping_energy_j", "energy_residual"] {
            h.push(c.into());
        }
        h
    }

    /// The number of parameter columns, which lead the header: the status column's index.
    pub fn parameter_columns(&self) -> usize {
        let swept = (0..self.buildings.len())
            .filter(|&b| self.swept_yield(b).is_some())
            .count();
        columns::CONTACT_AND_MOTION + 5 * self.buildings.len() + swept + self.gaps.len() + 1
    }

    /// Building `b`'s yielding storeys where their strength is swept or sampled (it then has
    /// a parameter column, `bk_yield_drift_ratio` or `bk_yield_base_shear_coefficient`).
    pub fn swept_yield(&self, b: usize) -> Option<&YieldSpec> {
        self.yielding[b].as_ref().filter(|y| y.axis.is_some())
    }

    /// The outputs an `--aggregate` summary folds per group (as magnitudes): the row's totals,
    /// each building's peaks and each contact level's; not the storey and floor numbers, the
    /// first impact's time, the step count or the energy balance.
    pub fn summarised(&self) -> Vec<String> {
        let skip = [
            "first_impact_s",
            "substeps",
            "input_energy_j",
            "damping_energy_j",
            "energy_residual",
        ];
        self.header()
            .into_iter()
            .skip(self.parameter_columns() + 1)
            .filter(|c| {
                !skip.contains(&c.as_str())
                    && !COLLAPSE_OUTPUTS.contains(&c.as_str())
                    && !c.ends_with("_collapsed")
                    && !c.ends_with("_collapse_time_s")
                    && !c.ends_with("_collapse_storey")
                    && !c.ends_with("_stability_coefficient")
                    && !c.ends_with("_drift_storey")
                    && !c.ends_with("_accel_floor")
                    && !c.ends_with("_residual_storey")
                    && !c.ends_with("_ductility_storey")
            })
            .collect()
    }

    /// The fields of one run, in [`RowPlan::header`] order.
    pub fn cells(&self, run: &RowRunSpec, out: &RowOutput) -> Vec<String> {
        let num = columns::num;
        let opt = |x: Option<f64>| x.map(num).unwrap_or_default();
        let mut c = columns::contact_and_motion(&self.contact, &run.contact);
        c.extend(
            run.period
                .iter()
                .map(|&t| num(self.contact.sa_g(&run.contact, t))),
        );
        for (b, a) in self.buildings.iter().enumerate() {
            c.push(a.storeys().to_string());
            c.push(opt(run.mass[b]));
            c.push(num(run.period[b]));
            c.push(num(run.damping[b]));
            if self.swept_yield(b).is_some() {
                c.push(opt(run.yield_value[b]));
            }
        }
        c.extend(run.gaps.iter().map(|&g| num(g)));
        c.push(run.sample.map(|s| s.to_string()).unwrap_or_default());
        let penetration = out
            .levels
            .iter()
            .map(|l| l.peak_penetration)
            .fold(0.0, f64::max);
        c.extend([
            out.status.key().to_string(),
            out.impacts.to_string(),
            num(out.peak_force),
            num(penetration),
            num(out.impact_velocity),
            opt(out.first_impact),
            num(out.contact_time),
            num(out.dissipated_energy),
            out.substeps.to_string(),
        ]);
        if self.collapse_drift_ratio.is_finite() {
            let cl = out.collapse;
            c.extend([
                opt(cl.map(|x| x.time)),
                cl.map(|x| x.building.to_string()).unwrap_or_default(),
                cl.map(|x| x.storey.to_string()).unwrap_or_default(),
            ]);
        }
        let mut storeys = out.storeys.iter();
        for (k, (b, y)) in out.buildings.iter().zip(&self.yielding).enumerate() {
            c.extend([
                num(b.peak_roof),
                num(b.peak_drift_ratio),
                b.drift_storey.to_string(),
                num(b.peak_accel),
                b.accel_floor.to_string(),
            ]);
            let a = &self.buildings[k];
            if a.p_delta.is_some() {
                c.push(num(a.stability_at_1s * run.period[k] * run.period[k]));
            }
            if self.collapse_drift_ratio.is_finite() {
                let cl = b.collapse;
                c.extend([
                    (cl.is_some() as u8).to_string(),
                    opt(cl.map(|x| x.time)),
                    cl.map(|x| x.storey.to_string()).unwrap_or_default(),
                ]);
            }
            if y.is_some() {
                // A run that failed, or did not settle, has no residual drift: empty.
                let ie = b.inelastic.unwrap_or_default();
                let known = |x: f64| if x.is_finite() { num(x) } else { String::new() };
                c.extend([
                    known(ie.residual_drift_ratio),
                    ie.residual_storey.to_string(),
                    num(ie.peak_ductility),
                    ie.ductility_storey.to_string(),
                    num(ie.hysteretic_energy),
                    ie.yielded_storeys.to_string(),
                ]);
                for _ in 0..self.buildings[k].storeys() {
                    let st = storeys.next().copied().unwrap_or(StoreyOutput {
                        residual_drift_ratio: f64::NAN,
                        peak_ductility: f64::NAN,
                        hysteretic_energy: f64::NAN,
                        yielded: false,
                    });
                    if self.storey_columns {
                        c.extend([
                            known(st.residual_drift_ratio),
                            known(st.peak_ductility),
                            known(st.hysteretic_energy),
                        ]);
                    }
                }
            }
        }
        for (l, struck) in out.levels.iter().zip(&self.struck) {
            c.extend([
                l.impacts.to_string(),
                num(l.peak_force),
                num(l.peak_penetration),
                num(l.impact_velocity),
            ]);
            if let Some(yields) = struck {
                c.push(num(l.column_shear));
                if *yields {
                    c.push(num(l.column_shear_ratio));
                }
            }
        }
        c.extend([
            opt(out.energy.map(|e| e.input)),
            opt(out.energy.map(|e| e.damping)),
            opt(out.energy.map(|e| e.residual)),
        ]);
        c
    }

    /// Is every run of this plan two elastic one-storey buildings whose floors meet (one contact
    /// level), without P-Delta, run by the fast scheme? Then the pair's kernels run it
    /// ([`crate::engine::Kernel::of`], [`RowPlan::pair_run`]) and its output keeps this plan's
    /// columns ([`RowOutput::of_pair`]); a run that nears the collapse limit goes back to the
    /// row's kernel ([`crate::physics::solver::row::near_collapse`]).
    pub fn runs_as_pair(&self) -> bool {
        self.buildings.len() == 2
            && self
                .buildings
                .iter()
                .all(|b| b.storeys() == 1 && b.p_delta.is_none())
            && self.yielding.iter().all(Option::is_none)
            && matches!(self.contact.spec.scheme, Scheme::Fast(_))
            && matches!(&self.levels()[..], [l] if !l.floor_column())
    }

    /// `run` as the pair's run of the same buildings (floor mass, period, damping ratio), gap,
    /// contact and forcing: for a plan that [`RowPlan::runs_as_pair`].
    pub fn pair_run(&self, run: &RowRunSpec) -> RunSpec {
        debug_assert!(self.runs_as_pair());
        let mass = |b: usize| match (&self.buildings[b].floor_masses, run.mass[b]) {
            (Some(m), _) => m[0],
            (None, m) => m.expect("a swept mass"),
        };
        RunSpec {
            contact: run.contact,
            m1: mass(0),
            t1: run.period[0],
            xi1: run.damping[0],
            m2: mass(1),
            t2: run.period[1],
            xi2: run.damping[1],
            gap: run.gaps[0],
            sample: run.sample,
        }
    }

    /// The two buildings' storey heights, for [`RowOutput::of_pair`] (a plan that
    /// [`RowPlan::runs_as_pair`]).
    pub fn pair_heights(&self) -> [f64; 2] {
        [self.buildings[0].heights[0], self.buildings[1].heights[0]]
    }

    /// The row scheme of the plan's scheme.
    pub fn scheme(&self) -> RowScheme {
        match self.contact.spec.scheme {
            Scheme::Fast(o) => RowScheme::Fast(o),
            Scheme::Reference(o) => RowScheme::Reference(o),
        }
    }
}

/// Each building's output columns (after its `b1_` prefix).
pub const BUILDING_OUTPUTS: [&str; 5] = [
    "peak_roof_m",
    "peak_drift_ratio",
    "drift_storey",
    "peak_accel_m_s2",
    "accel_floor",
];

/// Where a run collapsed (empty where it did not): the time, the building and its storey (from
/// 1). Rows with a collapse limit have them.
pub const COLLAPSE_OUTPUTS: [&str; 3] = ["collapse_time_s", "collapse_building", "collapse_storey"];

/// Each building's collapse columns (after its `b1_` prefix), in rows with a collapse limit:
/// whether it collapsed (0 or 1), when and in which storey (empty where it did not).
pub const BUILDING_COLLAPSE_OUTPUTS: [&str; 3] =
    ["collapsed", "collapse_time_s", "collapse_storey"];

/// A yielding building's further output columns (after its `b1_` prefix).
pub const INELASTIC_OUTPUTS: [&str; 6] = [
    "residual_drift_ratio",
    "residual_storey",
    "peak_ductility",
    "ductility_storey",
    "hysteretic_energy_j",
    "yielded_storeys",
];

/// A yielding storey's output columns with `--columns` (after its `b1_s2_` prefix: building 1,
/// storey 2 from the ground).
pub const STOREY_OUTPUTS: [&str; 3] = [
    "residual_drift_ratio",
    "peak_ductility",
    "hysteretic_energy_j",
];

impl RowPlan {
    /// Does `column` name a yielding storey's own column (`b1_s2_peak_ductility`)?
    pub fn asks_storey_columns(column: &str) -> bool {
        column
            .strip_prefix('b')
            .and_then(|r| r.split_once("_s"))
            .and_then(|(k, rest)| {
                let (j, suffix) = rest.split_once('_')?;
                let digits = |x: &str| !x.is_empty() && x.bytes().all(|c| c.is_ascii_digit());
                (digits(k) && digits(j) && STOREY_OUTPUTS.contains(&suffix)).then_some(())
            })
            .is_some()
    }
}

/// Each contact level's output columns (after its `level_b1f3_b2f3_` prefix).
pub const LEVEL_OUTPUTS: [&str; 4] = [
    "impacts",
    "peak_force_n",
    "peak_penetration_m",
    "impact_velocity_m_s",
];

/// Validate a row config read from `path` (records resolved beside it, `base`, and in
/// `records`).
pub fn parse_row(
    text: &str,
    path: &Path,
    base: &Path,
    records: &Path,
) -> Result<RowPlan, ConfigError> {
    parse_row_as(text, path, base, records, Reading::Sweep)
}

/// [`parse_row`] for a sweep or a gap study ([`config::load_text_for_gaps`]: the contact and
/// the gaps may be left out).
pub(crate) fn parse_row_as(
    text: &str,
    path: &Path,
    base: &Path,
    records: &Path,
    reading: Reading,
) -> Result<RowPlan, ConfigError> {
    let raw: RawRowConfig = toml::from_str(text).map_err(|e| config::toml_error(path, e))?;
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
    let samples = match &raw.sample {
        Some(smp) => {
            let all = RowSampled::all(nb);
            let keys = all.iter().map(|a| a.key()).collect::<Vec<_>>().join(", ");
            let (axes, points) = draw_sampled(
                smp,
                &invalid,
                &|k| all.iter().copied().find(|a| a.key() == k),
                &keys,
            )?;
            for (j, a) in axes.iter().enumerate() {
                if let Some(m) = refused_draw(&points, j, a.check()) {
                    return Err(invalid(&format!("sample.axis[{j}] ({})", a.key()), m));
                }
            }
            Some(RowSamples { axes, points })
        }
        None => None,
    };
    let sampled = |a: RowSampled| samples.as_ref().is_some_and(|s| s.axes.contains(&a));
    let grid_or_sampled = |a: RowSampled, given: Option<&Axis>| {
        config::grid_or_sampled(given, sampled(a)).map_err(|m| invalid(&a.key(), m))
    };
    // A building alone touches nothing, and a gap study runs no contact: without [contact]
    // either takes a linear law it never uses.
    let rc = match (&raw.contact, nb) {
        (Some(c), _) => c.clone(),
        (None, 1) => config::unused_contact(),
        (None, _) if reading == Reading::GapStudy => config::unused_contact(),
        (None, _) => return Err(invalid(
            "contact",
            "missing: a row of buildings that may touch needs [contact] (law and its stiffness)"
                .into(),
        )),
    };
    let k_grid = grid_or_sampled(RowSampled::KLinear, rc.k_n_per_m.as_ref())?;
    let beta_grid = grid_or_sampled(RowSampled::Beta, rc.beta_n_per_m1_5.as_ref())?;
    let mut shared_gap = grid_or_sampled(RowSampled::SharedGap, rc.gap_m.as_ref())?;
    // A gap study computes the gaps: a pair whose gap is left out takes one it never uses.
    if reading == Reading::GapStudy && shared_gap.is_none() {
        shared_gap = Some(Axis::List(vec![config::UNUSED_GAP_M]));
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
    let axis = |key: &str, a: &Axis, (ok, expected): Check| {
        let v = a.values().map_err(|m| invalid(key, m))?;
        check_axis(key, &v, ok, expected).map_err(|e| invalid(&e.key, e.message))?;
        Ok(v)
    };
    let positive = POSITIVE.0;
    let per_storey = |key: &str, v: &[f64], n: usize| {
        if v.len() != n {
            return Err(invalid(
                key,
                format!("{} values for {n} storeys: give one per storey", v.len()),
            ));
        }
        match v.iter().position(|x| !positive(*x)) {
            Some(i) => Err(invalid(
                &format!("{key}[{i}]"),
                format!(
                    "{} is out of range: expected a value > 0",
                    crate::plan::limits::show(v[i])
                ),
            )),
            None => Ok(v.to_vec()),
        }
    };
    let mut buildings = Vec::new();
    let mut yielding = Vec::new();
    let mut gaps = Vec::new();
    let mut shared = Vec::new();
    for (b, r) in raw.building.iter().enumerate() {
        let key = |k: &str| format!("building[{b}].{k}");
        let n = r.storeys;
        if !(1..=MAX_STOREYS).contains(&n) {
            return Err(invalid(
                &key("storeys"),
                format!("{n}: expected 1 to {MAX_STOREYS}"),
            ));
        }
        let heights = match &r.storey_height_m {
            PerStorey::One(h) => per_storey(&key("storey_height_m"), &[*h], 1)?.repeat(n),
            PerStorey::Each(v) => per_storey(&key("storey_height_m"), v, n)?,
        };
        let mass_kg = grid_or_sampled(RowSampled::Mass(b), r.mass_kg.as_ref())?;
        if sampled(RowSampled::Mass(b)) && r.floor_masses_kg.is_some() {
            return Err(invalid(
                &key("floor_masses_kg"),
                format!(
                    "{} is sampled under [sample]: remove floor_masses_kg",
                    key("mass_kg")
                ),
            ));
        }
        let (floor_masses, mass) = match (&mass_kg, &r.floor_masses_kg) {
            (Some(a), None) => (None, axis(&key("mass_kg"), a, MASS)?),
            (None, Some(v)) => {
                let masses = per_storey(&key("floor_masses_kg"), v, n)?;
                if let Some(i) = masses.iter().position(|m| !(MASS.0)(*m)) {
                    return Err(invalid(
                        &format!("{}[{i}]", key("floor_masses_kg")),
                        format!(
                            "{} is out of range: expected {}",
                            crate::plan::limits::show(masses[i]),
                            MASS.1
                        ),
                    ));
                }
                (Some(masses), vec![0.0])
            }
            _ => {
                return Err(invalid(
                    &key("mass_kg"),
                    "give mass_kg (every floor, an axis) or floor_masses_kg (one per floor), one of them"
                        .into(),
                ))
            }
        };
        let profile = match &r.stiffness_profile {
            Some(v) => per_storey(&key("stiffness_profile"), v, n)?,
            None => vec![1.0; n],
        };
        let modal = match r.damping.as_deref().unwrap_or("rayleigh") {
            "rayleigh" => false,
            "modal" => true,
            other => {
                return Err(invalid(
                    &key("damping"),
                    format!("`{other}`: expected rayleigh or modal"),
                ))
            }
        };
        let required = |a: RowSampled, given: Option<&Axis>| {
            grid_or_sampled(a, given)?.ok_or_else(|| invalid(&a.key(), config::MISSING.into()))
        };
        let sampled_yield = (
            sampled(RowSampled::YieldDrift(b)),
            sampled(RowSampled::YieldShear(b)),
        );
        yielding.push(parse_yielding(r, n, sampled_yield, &key, &invalid)?);
        let period_s = required(RowSampled::Period(b), r.period_s.as_ref())?;
        let damping_ratio = required(RowSampled::Damping(b), r.damping_ratio.as_ref())?;
        let p_delta = match (r.p_delta, r.gravity_mass_ratio) {
            (Some(true), ratio) => {
                let ratio = ratio.unwrap_or(1.0);
                let max = crate::plan::limits::MAX_GRAVITY_MASS_RATIO;
                if !(0.0..=max).contains(&ratio) {
                    return Err(invalid(
                        &key("gravity_mass_ratio"),
                        format!(
                            "{} is out of range: expected a ratio >= 0 and <= {max} (the gravity load over the floors' own weight)",
                            crate::show(ratio)
                        ),
                    ));
                }
                Some(ratio)
            }
            (_, Some(_)) => {
                return Err(invalid(
                    &key("gravity_mass_ratio"),
                    "applies with p_delta = true: add it, or remove gravity_mass_ratio".into(),
                ))
            }
            _ => None,
        };
        buildings.push(ShearAxes {
            heights,
            floor_masses,
            mass,
            profile,
            period: axis(&key("period_s"), &period_s, PERIOD)?,
            damping: axis(&key("damping_ratio"), &damping_ratio, DAMPING)?,
            modal,
            p_delta,
            stability_at_1s: 0.0,
        });
        let gap_right = if b + 1 < nb {
            grid_or_sampled(RowSampled::Gap(b), r.gap_right_m.as_ref())?
        } else {
            r.gap_right_m.clone()
        };
        shared.push(gap_right.is_none());
        match (&gap_right, b + 1 < nb, &shared_gap) {
            (Some(_), false, _) => {
                return Err(invalid(
                    &key("gap_right_m"),
                    "the last building has no neighbour to its right".into(),
                ))
            }
            (Some(a), true, _) => gaps.push(axis(&key("gap_right_m"), a, GAP)?),
            (None, true, Some(a)) => gaps.push(axis("contact.gap_m", a, GAP)?),
            (None, true, None) => {
                return Err(invalid(
                    &key("gap_right_m"),
                    "missing: give contact.gap_m (every pair) or gap_right_m".into(),
                ))
            }
            (None, false, _) => {}
        }
    }
    shared.truncate(nb - 1);
    let mut ignored = Vec::new();
    if nb == 1 && raw.contact.is_some() {
        ignored.push("[contact] is ignored: a building alone has no contact".to_string());
    } else if rc.gap_m.is_some() && !shared.contains(&true) {
        ignored.push("contact.gap_m is ignored: every pair has its own gap_right_m".to_string());
    }
    if nb > 1 && sampled(RowSampled::SharedGap) && !shared.contains(&true) {
        return Err(invalid(
            "contact.gap_m",
            "is sampled, but every gap is given per building (gap_right_m): sample those instead"
                .into(),
        ));
    }
    // Every period each building takes: its samples where sampled (its axis then holds a
    // placeholder), else its axis.
    let taken: Vec<Vec<f64>> = buildings
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
        .collect();
    crate::plan::intensity::check_periods(&contact.spec.intensities, &taken)
        .map_err(|(k, m)| invalid(&k, m))?;
    check_stability(&mut buildings, &taken).map_err(|(k, m)| invalid(&k, m))?;
    let collapse_drift_ratio = match &raw.run.collapse_drift_ratio {
        None => crate::plan::limits::COLLAPSE_DRIFT_RATIO,
        Some(config::CollapseLimit::Ratio(x)) if *x > 0.0 && *x <= 1.0 => *x,
        Some(config::CollapseLimit::None) => f64::INFINITY,
        Some(other) => {
            let given = match other {
                config::CollapseLimit::Ratio(x) => crate::show(*x),
                config::CollapseLimit::Other(t) => format!("`{t}`"),
                config::CollapseLimit::None => unreachable!(),
            };
            return Err(invalid(
                "run.collapse_drift_ratio",
                format!(
                    "{given}: expected a drift ratio > 0 and <= 1 (a storey's drift over its height), or \"none\""
                ),
            ));
        }
    };
    contact.list_periods(&taken);
    let mut dims = vec![samples.as_ref().map_or(1, |s| s.points.len())];
    dims.extend(
        buildings
            .iter()
            .flat_map(|a| [a.mass.len(), a.period.len(), a.damping.len()]),
    );
    // `contact.gap_m` is one axis: the first pair it gives carries it, the others read it.
    let first_shared = shared.iter().position(|&s| s);
    let gap_axis: Vec<usize> = (0..nb - 1)
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
    // Each swept or sampled strength: an axis after the gaps (none in an elastic row).
    let yield_dim: Vec<Option<usize>> = yielding
        .iter()
        .map(|y: &Option<YieldSpec>| {
            let axis = y.as_ref()?.axis.as_ref()?;
            dims.push(axis.len());
            Some(dims.len() - 1)
        })
        .collect();
    let per_scene = dims
        .iter()
        .try_fold(1u64, |p, &d| p.checked_mul(d as u64))
        .filter(|&p| {
            p.checked_mul(contact.len())
                .is_some_and(|n| n <= crate::plan::limits::MAX_RUNS)
        })
        .ok_or_else(|| {
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
        gap_axis,
        dims,
        ignored,
        per_scene,
        yielding,
        yield_dim,
        storey_columns: false,
        struck: Vec::new(),
    };
    plan.struck = plan.struck_columns();
    // A gap study runs no contact and no gap axis: none of them can repeat its runs.
    if reading == Reading::Sweep {
        let shared_values = (rc.gap_m.as_ref()).map_or(0, |a| a.count().unwrap_or(1));
        plan.refuse_idle_axes(raw.contact.is_some(), shared_values)
            .map_err(|(k, m)| invalid(&k, m))?;
    }
    Ok(plan)
}

impl RowPlan {
    /// Refuse every axis (a key of two values or more, or a sampled one) that cannot change a
    /// run of this row: it would repeat each run with the same physics, or be dropped, and a
    /// statistic over the runs would count each one as several. `contact_given`: the config
    /// has `[contact]`; `shared_values`: the values of `contact.gap_m` it gives. Err: the keys
    /// and why.
    fn refuse_idle_axes(
        &self,
        contact_given: bool,
        shared_values: usize,
    ) -> Result<(), (String, String)> {
        let nb = self.buildings.len();
        let c = &self.contact.spec;
        // Levels depend on the storeys and heights alone, which no axis sweeps.
        let levels = if nb > 1 { self.levels() } else { Vec::new() };
        let touching: Vec<bool> = (0..nb - 1)
            .map(|a| levels.iter().any(|l| l.left == a))
            .collect();
        let contact = touching.contains(&true);
        let sampled = |a: RowSampled| {
            (self.samples.iter())
                .flat_map(|s| s.axes.iter().position(|x| *x == a))
                .next()
        };
        // (key, values that multiply the runs, or 1 where they are dropped).
        let mut idle: Vec<(String, usize)> = Vec::new();
        let mut idle_sampled: Vec<String> = Vec::new();
        if !contact && contact_given {
            let repeated = self.contact.len() as usize / (c.records.len() * c.intensities.len());
            for (key, n) in [
                ("contact.law", c.laws.len()),
                ("contact.formula", c.formulas.len()),
                ("contact.e", c.e.len()),
                ("contact.k_n_per_m", c.k_linear.len()),
                ("contact.beta_n_per_m1_5", c.beta.len()),
            ] {
                if n > 1 {
                    idle.push((key.into(), 1));
                }
            }
            if let Some((_, n)) = idle.first_mut() {
                *n = repeated;
            }
            for a in [RowSampled::KLinear, RowSampled::Beta] {
                if let Some(j) = sampled(a) {
                    idle_sampled.push(format!("sample.axis[{j}] ({})", a.key()));
                }
            }
        }
        if nb == 1 {
            if let Some(j) = sampled(RowSampled::SharedGap) {
                idle_sampled.push(format!("sample.axis[{j}] (contact.gap_m)"));
            }
        }
        // Each gap axis: its own pair's, or `contact.gap_m` for every pair it gives.
        for a in 0..nb - 1 {
            if self.gap_axis[a] != a {
                continue;
            }
            let readers: Vec<usize> = (0..nb - 1).filter(|&p| self.gap_axis[p] == a).collect();
            if readers.iter().any(|&p| touching[p]) {
                continue;
            }
            let key = if self.shared_gap[a] {
                "contact.gap_m".to_string()
            } else {
                format!("building[{a}].gap_right_m")
            };
            let axis = if self.shared_gap[a] {
                RowSampled::SharedGap
            } else {
                RowSampled::Gap(a)
            };
            match sampled(axis) {
                Some(j) => idle_sampled.push(format!("sample.axis[{j}] ({key})")),
                None if self.gaps[a].len() > 1 => idle.push((key, self.gaps[a].len())),
                None => {}
            }
        }
        // A shared gap list no pair reads (a building alone, or every pair with its own).
        let dropped_shared = shared_values > 1 && !self.shared_gap.contains(&true);
        if dropped_shared {
            idle.push(("contact.gap_m".into(), 1));
        }
        if idle.is_empty() && idle_sampled.is_empty() {
            return self
                .refuse_unused_by_laws(contact)
                .map_err(|e| (e.key, e.message));
        }
        let samples = self.samples.as_ref().map_or(1, |s| s.points.len());
        let all_sampled_idle = self
            .samples
            .as_ref()
            .is_some_and(|s| s.axes.len() == idle_sampled.len());
        let repeat: usize = idle.iter().map(|(_, n)| n).product::<usize>()
            * if all_sampled_idle { samples } else { 1 };
        let keys: Vec<String> = idle
            .iter()
            .map(|(k, _)| k.clone())
            .chain(idle_sampled)
            .collect();
        let why = if nb == 1 {
            "a building alone has no contact".to_string()
        } else if !contact {
            "no two neighbours share a contact level (no floor at a common elevation, and [levels] floor_column = false), so no run has contact".to_string()
        } else if dropped_shared && keys.len() == 1 && keys[0] == "contact.gap_m" {
            "every pair has its own gap_right_m, so no pair reads contact.gap_m".to_string()
        } else {
            let apart: Vec<String> = (0..nb - 1)
                .filter(|&a| !touching[a])
                .map(|a| format!("buildings {} and {}", a + 1, a + 2))
                .collect();
            format!(
                "{} share no contact level (no floor at a common elevation, and [levels] floor_column = false), so their gap is never checked",
                apart.join(", ")
            )
        };
        let (this, it) = if keys.len() == 1 {
            ("this axis", "it")
        } else {
            ("these axes", "them")
        };
        let effect = if repeat > 1 {
            format!("{this} would repeat each run {repeat} times with the same physics")
        } else {
            format!("{this} cannot change a run (the values would be dropped)")
        };
        let remedy = if nb == 1 {
            "add a second [[building]]"
        } else if dropped_shared && keys.len() == 1 {
            "give the gaps in one place"
        } else {
            "give the buildings a common floor level or [levels] floor_column = true"
        };
        Err((
            keys.join(", "),
            format!("{why}: {effect}; remove {it} or {remedy}"),
        ))
    }

    /// Where some pair has contact: refuse the contact axes and sampled stiffnesses that no
    /// law given takes ([`crate::plan::ContactSpec::refuse_unused`]).
    fn refuse_unused_by_laws(&self, contact: bool) -> Result<(), crate::plan::PlanError> {
        if !contact {
            return Ok(());
        }
        let spec = &self.contact.spec;
        spec.refuse_unused()?;
        for (j, a) in self.samples.iter().flat_map(|s| s.axes.iter().enumerate()) {
            if matches!(a, RowSampled::KLinear | RowSampled::Beta) {
                spec.refuse_unused_sample(j, &a.key())?;
            }
        }
        Ok(())
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

/// Each storey's stability coefficient `theta_j = P_j / (k_j h_j)` of a P-Delta building (of
/// gravity mass ratio `ratio`) at a period of 1 s: at period `T` it is this times `T^2`.
fn stability_at_1s(a: &ShearAxes, ratio: f64) -> Vec<f64> {
    let masses = a
        .floor_masses
        .clone()
        .unwrap_or_else(|| vec![1.0; a.storeys()]);
    ShearBuilding::from_period(
        masses,
        &a.profile,
        a.heights.clone(),
        1.0,
        Damping::Modal(0.05),
    )
    .with_p_delta(ratio)
    .stability_coefficients()
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

/// A building's yielding storeys as its `[[building]]` gives them (`key` names its keys), or
/// None where it gives none (elastic).
fn parse_yielding(
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
    match r.damping_stiffness.as_deref() {
        None | Some("initial") => {}
        Some("tangent") => return Err(invalid(
            &key("damping_stiffness"),
            "`tangent` is not offered: damping on the tangent stiffness can create spurious damping forces once storeys yield; the damping is built on the initial stiffness (`initial`)".into(),
        )),
        Some(other) => {
            return Err(invalid(
                &key("damping_stiffness"),
                format!("`{other}`: expected initial"),
            ))
        }
    }
    // One value for every storey, or one per storey, each within `ok` (`expected` says what).
    let per_storey = |name: &str, v: &PerStorey, ok: &dyn Fn(f64) -> bool, expected: &str| {
        let values = match v {
            PerStorey::One(x) => vec![*x; n],
            PerStorey::Each(v) if v.len() == n => v.clone(),
            PerStorey::Each(v) => {
                return Err(invalid(
                    &key(name),
                    format!(
                        "{} values for {n} storeys: give one, or one per storey",
                        v.len()
                    ),
                ))
            }
        };
        match values.iter().position(|x| !ok(*x)) {
            Some(i) => Err(invalid(
                &format!("{}[{i}]", key(name)),
                format!(
                    "{} is out of range: expected {expected}",
                    crate::plan::limits::show(values[i])
                ),
            )),
            None => Ok(values),
        }
    };
    let strengths = [
        r.yield_drift_ratio.is_some() || sampled_drift,
        r.yield_force_n.is_some(),
        r.yield_base_shear_coefficient.is_some() || sampled_shear,
    ];
    // The strength's one value as an axis (a placeholder where sampled).
    let mut axis = None;
    let values = |name: &str, a: &Axis, (ok, expected): Check| {
        let v = a.values().map_err(|m| invalid(&key(name), m))?;
        check_axis(&key(name), &v, ok, expected).map_err(|e| invalid(&e.key, e.message))?;
        Ok(v)
    };
    let strength = match strengths.iter().filter(|&&x| x).count() {
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
        1 => {
            if sampled_drift {
                axis = Some(vec![f64::NAN]);
                YieldStrength::DriftRatio(vec![f64::NAN; n])
            } else if let Some(v) = &r.yield_drift_ratio {
                let one = match v {
                    YieldDrift::One(x) => PerStorey::One(*x),
                    YieldDrift::Each(v) => PerStorey::Each(v.clone()),
                    YieldDrift::Axis(range) => {
                        let v = values("yield_drift_ratio", &Axis::Range(range.clone()), YIELD_DRIFT)?;
                        let first = v[0];
                        axis = Some(v);
                        PerStorey::One(first)
                    }
                };
                YieldStrength::DriftRatio(per_storey(
                    "yield_drift_ratio",
                    &one,
                    &YIELD_DRIFT.0,
                    YIELD_DRIFT.1,
                )?)
            } else if let Some(v) = &r.yield_force_n {
                YieldStrength::Force(per_storey(
                    "yield_force_n",
                    v,
                    &|x| x > 0.0 && x.is_finite(),
                    "a force > 0 N",
                )?)
            } else {
                let c = match &r.yield_base_shear_coefficient {
                    Some(a) => {
                        let v = values("yield_base_shear_coefficient", a, YIELD_SHEAR)?;
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
                        return Err(invalid(
                            &key("yield_shear_distribution"),
                            format!("`{other}`: expected inverted_triangular or uniform"),
                        ))
                    }
                };
                YieldStrength::BaseShear {
                    coefficient: c,
                    triangular,
                }
            }
        }
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
        Some(v) => per_storey(
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
