//! Sweeps of rows of multi-storey buildings: a config with `[[building]]` entries (left to
//! right) instead of `[building1]` and `[building2]`.
//!
//! Everything but the buildings and gaps (laws, formulas, `e`, stiffness, records,
//! intensities, the scheme) is the shared [`ContactPlan`], read and validated by the same code
//! as a pair's; the row plan adds, below each contact run, the axes of each building (floor
//! mass, fundamental period, damping ratio) and each adjacent pair's gap, outermost first, the
//! last gap innermost.

use crate::physics::model::Forcing;
use crate::physics::row::{struck_side, Level, LevelRule, Row, RowOutput};
use crate::physics::shear::{Damping, ShearBuilding, Yielding};
use crate::physics::solver::row::RowScheme;
use crate::physics::solver::Scheme;
use crate::plan::axes::Motions;
use crate::plan::contact::{ContactPlan, ContactRun};
use crate::plan::deterioration::ImkSpec;
use crate::plan::pair::RunSpec;
pub use crate::plan::row_sampled::RowSampled;

/// design codes neglect P-Delta (ASCE 7 section 12.8.7).
pub const WARN_STABILITY: f64 = 0.1;

/// The largest `[levels] same_level_m`: the depth of a thick slab, m.
pub const MAX_SAME_LEVEL_M: f64 = 0.5;
/// The smallest, m: two floors just beyond it apart share the contact up to twice it
/// ([`crate::physics::row::contact_points`]), so at 0 floors a rounding apart would be two
/// whole points.
pub const MIN_SAME_LEVEL_M: f64 = 0.001;

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
#[derive(Clone, PartialEq)]
pub struct YieldSpec {
    pub strength: YieldStrength,
    /// Post-yield stiffness ratio per storey.
    pub post_yield: Vec<f64>,
    /// Where the strength's one value (a yield drift ratio for every storey, or a base-shear
    /// coefficient) is an axis: its values (one placeholder where it is sampled). A run's
    /// value ([`RowRunSpec::yield_value`]) replaces the strength's.
    pub axis: Option<Vec<f64>>,
    /// Capped, deteriorating (IMK) storeys; None: bilinear.
    pub deterioration: Option<ImkSpec>,
}

// The plan's fingerprint hashes this text: a bilinear building's reads as it did before IMK
// storeys, so its sidecars still match.
impl std::fmt::Debug for YieldSpec {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let mut d = f.debug_struct("YieldSpec");
        d.field("strength", &self.strength)
            .field("post_yield", &self.post_yield)
            .field("axis", &self.axis);
        if let Some(imk) = &self.deterioration {
            d.field("deterioration", imk);
        }
        d.finish()
    }
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

    /// The names of building `b`'s swept or sampled values, in column order (each a column
    /// `bk_<name>`): its strength's, then each IMK key given as an axis.
    pub fn swept_names(&self) -> Vec<&'static str> {
        let strength = self.axis.is_some().then(|| self.value_name());
        let imk = self.deterioration.iter().flat_map(|d| &d.axes);
        strength
            .into_iter()
            .chain(imk.map(|(k, _)| k.key()))
            .collect()
    }

    /// The storeys of `b` (its stiffnesses, masses and heights final), with the run's `value`
    /// of the swept strength where it has one and its `imk` values of the IMK axes.
    pub fn of(&self, b: &ShearBuilding, value: Option<f64>, imk: &[f64]) -> Yielding {
        let deterioration = self.deterioration.as_ref().map(|d| d.of(imk));
        let force = match &self.strength {
            YieldStrength::DriftRatio(theta) => {
                let theta = match value {
                    Some(v) => vec![v; theta.len()],
                    None => theta.clone(),
                };
                let y = Yielding::from_drift_ratio(
                    &b.stiffness,
                    &b.heights,
                    &theta,
                    self.post_yield.clone(),
                );
                return Yielding { deterioration, ..y };
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
            deterioration,
        }
    }
}

/// A row config as written.
#[derive(Clone, PartialEq)]
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
    /// The share of its storeys that the columns a neighbour's slab strikes carry (None: the
    /// struck point is rigid, [`crate::physics::shear::ShearBuilding::struck_column_share`]).
    pub struck_column_share: Option<f64>,
}

// The plan's fingerprint hashes this text: a building without `struck_column_share` reads as
// it did before the key, so its sidecars still match.
impl std::fmt::Debug for ShearAxes {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let mut d = f.debug_struct("ShearAxes");
        d.field("heights", &self.heights)
            .field("floor_masses", &self.floor_masses)
            .field("mass", &self.mass)
            .field("profile", &self.profile)
            .field("period", &self.period)
            .field("damping", &self.damping)
            .field("modal", &self.modal)
            .field("p_delta", &self.p_delta)
            .field("stability_at_1s", &self.stability_at_1s);
        if let Some(alpha) = &self.struck_column_share {
            d.field("struck_column_share", alpha);
        }
        d.finish()
    }
}

impl ShearAxes {
    pub fn storeys(&self) -> usize {
        self.heights.len()
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
    pub(crate) struck: Vec<Option<bool>>,
    pub buildings: Vec<ShearAxes>,
    /// m, per adjacent pair.
    pub gaps: Vec<Vec<f64>>,
    /// Sampled parameters, crossed with every grid axis (their grid axes hold a placeholder).
    pub samples: Option<RowSamples>,
    /// Which gaps `contact.gap_m` gives (the others are given per building).
    pub(crate) shared_gap: Vec<bool>,
    /// Per adjacent pair, the gap axis it reads: its own, or for every pair that
    /// `contact.gap_m` gives, the first such pair's. `contact.gap_m` is one gap shared by those
    /// pairs, in the grid as under `[sample]`; `gap_right_m` gives a pair an axis of its own.
    pub(crate) gap_axis: Vec<usize>,
    /// Sizes of the axes below a contact run: the samples, then mass, period, damping per
    /// building, then the gaps.
    pub(crate) dims: Vec<usize>,
    /// Keys the config gives that no run uses, with why.
    pub(crate) ignored: Vec<String>,
    pub(crate) per_scene: u64,
    /// Per building, its yielding storeys (None: elastic).
    pub yielding: Vec<Option<YieldSpec>>,
    /// Per building, the index in `dims` of its swept or sampled strength (after the gaps).
    pub(crate) yield_dim: Vec<Option<usize>>,
    /// Per building, the index in `dims` of each of its IMK axes (after its strength's).
    pub(crate) imk_dim: Vec<Vec<usize>>,
    /// Write each yielding storey's columns too (`bk_sj_...`, [`STOREY_OUTPUTS`]): set where
    /// `--columns` asks for one ([`RowPlan::asks_storey_columns`]).
    pub storey_columns: bool,
    /// Write every building's storey demands (`bk_sj_peak_drift_ratio`, and an elastic one's
    /// `bk_sj_residual_drift_ratio`) and floor accelerations (`bk_fj_peak_accel_m_s2`, floor 0
    /// the ground): set where `--columns` asks for `+storeys`, `+floors` or one of their columns
    /// ([`RowPlan::ask_demands`]).
    pub storey_demands: bool,
    pub floor_demands: bool,
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
    /// Per building, the value of each of its IMK axes ([`ImkSpec::axes`]; none where it has
    /// none).
    pub imk_value: Vec<Vec<f64>>,
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
            imk_value: (0..nb)
                .map(|b| {
                    let axes = self.yielding[b].iter().flat_map(|y| &y.deterioration);
                    let axes = axes.flat_map(|d| &d.axes);
                    (axes.zip(&self.imk_dim[b]))
                        .map(|((_, v), &k)| v[at[k]])
                        .collect()
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
                    // A sampled IMK key is its building's one-value axis, the draw its value.
                    RowSampled::Imk(b, k) => {
                        let axes = self.yielding[b].iter().flat_map(|y| &y.deterioration);
                        if let Some(i) = axes.flat_map(|d| &d.axes).position(|(a, _)| *a == k) {
                            run.imk_value[b][i] = v;
                        }
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
    pub fn motions(&self) -> Motions {
        let dims = self.motion_dims();
        Motions {
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
            .chain(self.imk_dim.iter().flatten().map(|&k| (k, self.dims[k])))
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
    /// ([`crate::plan::pair::above_height`]).
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
                    .map(|y| y.of(&s, run.yield_value[b], &run.imk_value[b]));
                let s = match a.p_delta {
                    Some(ratio) => s.with_p_delta(ratio),
                    None => s,
                };
                ShearBuilding {
                    struck_column_share: a.struck_column_share,
                    ..s
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

    /// Per contact level where a floor strikes a column, whether the struck storey yields
    /// (None for a floor/floor level).
    pub(crate) fn struck_columns(&self) -> Vec<Option<bool>> {
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

    /// Building `b`'s swept or sampled values' names, each a parameter column `bk_<name>`
    /// after `bk_xi` ([`YieldSpec::swept_names`]; none for an elastic building).
    pub fn swept_names(&self, b: usize) -> Vec<&'static str> {
        self.yielding[b]
            .as_ref()
            .map_or_else(Vec::new, YieldSpec::swept_names)
    }

    /// `run`'s values of building `b`'s [`RowPlan::swept_names`], in their order.
    pub fn swept_values(&self, b: usize, run: &RowRunSpec) -> Vec<Option<f64>> {
        let strength = self.yielding[b]
            .as_ref()
            .filter(|y| y.axis.is_some())
            .map(|_| run.yield_value[b]);
        let imk = run.imk_value[b].iter().map(|&v| Some(v));
        strength.into_iter().chain(imk).collect()
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

/// Each storey's stability coefficient `theta_j = P_j / (k_j h_j)` of a P-Delta building (of
/// gravity mass ratio `ratio`) at a period of 1 s: at period `T` it is this times `T^2`.
pub(crate) fn stability_at_1s(a: &ShearAxes, ratio: f64) -> Vec<f64> {
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
