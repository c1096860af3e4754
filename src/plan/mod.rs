//! A validated sweep: every axis checked, every run numbered. The engine consumes only this:
//! one [`Plan`], of a pair ([`PairPlan`]) or of a row of shear buildings ([`row::RowPlan`]).
//!
//! - [`config`]: a TOML config (stage 1, raw serde structs) turned into a [`Plan`] (stage 2);
//!   the one place a config's kind is told;
//! - [`row`]: the axes of a row's buildings and gaps;
//! - [`sample`]: Latin hypercube and Monte Carlo samples of uncertain parameters;
//! - [`columns`]: the schema, every run's parameters and outputs as named columns;
//! - [`meaning`]: what each column holds, and its unit;
//! - [`shard`]: cost-balanced run ranges for job arrays;
//! - [`limits`]: the bound on every size a user types, with its reason.
//!
//! May import the physics and the records; never the engine, io or studies.
//!
//! A pair's runs (below; a row's in [`row`], in the same order) are grouped by contact law. Within a law's block, only the axes that law uses vary
//! (elastic laws ignore `e` and the formula; linear laws take `k`, Hertz-type laws `beta`), so no
//! run is a duplicate of another. Axis order, outermost first: law, formula, e, stiffness, record,
//! intensity, sample, m1, T1, xi1, m2, T2, xi2, gap. A sample (of uncertain parameters, see
//! [`Samples`]) sets the parameters it holds; their grid axes then hold one placeholder value.
//! Run `i` is decoded from its index (mixed radix), so the plan is never expanded in memory and
//! run numbers do not depend on threads or chunking.

pub mod columns;
pub mod config;
pub mod intensity;
pub mod limits;
pub mod meaning;
pub mod row;
pub mod sample;
pub mod shard;

use crate::physics::contact::{Contact, LawKind};
use crate::physics::model::{Forcing, Oscillator, Pair};
use crate::physics::restitution::{damping_for, Formula};
use crate::physics::solver::Scheme;
use crate::record::{Record, G};
use std::collections::HashMap;
use std::sync::Arc;

pub use intensity::Intensity;

/// A validated sweep of one scene, the one plan every command holds: the config reader
/// ([`config::load_text`]) decides the scene's kind once, and the layers below ask the plan,
/// never the config. A `[building1]`/`[building2]` config is a pair of one-storey buildings,
/// planned by [`PairPlan`] (whose runs the engine's pair kernels take); a `[[building]]` config
/// is a row of 2..n shear buildings of 1..N storeys, planned by [`row::RowPlan`] (the row
/// kernels). Both number their runs in the same axis order (contact, record, intensity,
/// sample, each building's values, the gaps), so a pair written as a row of two one-storey
/// buildings has the same runs in the same order (`tests/it/scenes.rs`).
#[derive(Debug, Clone)]
pub enum Plan {
    Pair(PairPlan),
    Row(row::RowPlan),
}

impl Plan {
    /// Number of runs.
    pub fn len(&self) -> u64 {
        match self {
            Plan::Pair(p) => p.len(),
            Plan::Row(r) => r.len(),
        }
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The plan of the contact, record and intensity axes: the pair's own, a row's base.
    pub fn contact(&self) -> &PairPlan {
        match self {
            Plan::Pair(p) => p,
            Plan::Row(r) => &r.base,
        }
    }

    /// The integration scheme the runs take.
    pub fn scheme(&self) -> Scheme {
        self.contact().spec.scheme
    }

    /// Set the scheme as run (the fingerprint covers it).
    pub fn set_scheme(&mut self, scheme: Scheme) {
        match self {
            Plan::Pair(p) => p.spec.scheme = scheme,
            Plan::Row(r) => r.base.spec.scheme = scheme,
        }
    }

    /// The accuracy suite that calibrates `--target-error` for this scene.
    pub fn suite(&self) -> crate::physics::solver::calibration::Suite {
        use crate::physics::solver::calibration::Suite;
        match self {
            Plan::Pair(_) => Suite::Pairs,
            Plan::Row(_) => Suite::Rows,
        }
    }

    /// The most storeys of any building (1 for a pair).
    pub fn max_storeys(&self) -> usize {
        match self {
            Plan::Pair(_) => 1,
            Plan::Row(r) => r.buildings.iter().map(|b| b.storeys()).max().unwrap_or(1),
        }
    }

    /// The scene in words: `a pair of one-storey buildings`, `a row of 3 buildings (9
    /// storeys, 7 contact levels)`.
    pub fn scene(&self) -> String {
        match self {
            Plan::Pair(_) => "a pair of one-storey buildings".into(),
            Plan::Row(r) => format!(
                "a row of {} buildings ({} storeys, {} contact levels)",
                r.buildings.len(),
                r.buildings.iter().map(|b| b.storeys()).sum::<usize>(),
                r.row(&r.run(0)).levels.len(),
            ),
        }
    }

    /// What a user should hear before any run, for contact substeps of `substeps_per_contact`
    /// (a row's cost grows with its stiffest building): absurd intensities, a row's pairs that
    /// never touch, keys no run uses, extreme costs.
    pub fn warnings(&self, substeps_per_contact: f64) -> Vec<String> {
        let mut w = self.input_warnings();
        if let Plan::Row(r) = self {
            w.extend(r.cost_warning(substeps_per_contact));
        }
        w
    }

    /// [`Plan::warnings`] without the cost of contact (for studies that integrate none).
    pub fn input_warnings(&self) -> Vec<String> {
        match self {
            Plan::Pair(p) => p.warnings(),
            Plan::Row(r) => r.warnings(),
        }
    }

    /// Each adjacent pair of buildings with no floor at a common elevation, and why (none for
    /// a pair of one-storey buildings, which touch at their roofs).
    pub fn pairs_without_levels(&self) -> Vec<String> {
        match self {
            Plan::Pair(_) => Vec::new(),
            Plan::Row(r) => r.pairs_without_levels(),
        }
    }

    /// How a building's height is known, for the warning on runs whose displacement passes it.
    pub fn height_basis(&self) -> String {
        match self {
            Plan::Pair(_) => format!(
                "estimated from its period, {} m per s: T ~ 0.1 s per 3 m storey",
                limits::HEIGHT_PER_PERIOD_M
            ),
            Plan::Row(_) => "the sum of its storey heights, storey_height_m".into(),
        }
    }

    /// Every column, in file order: the pair's fixed schema ([`columns::header`]) or the
    /// row's, which follows its buildings and levels ([`row::RowPlan::header`]).
    pub fn header(&self) -> Vec<String> {
        match self {
            Plan::Pair(_) => columns::header().into_iter().map(String::from).collect(),
            Plan::Row(r) => r.header(),
        }
    }

    /// The summed cost of runs `0..end` when a run costs `record_cost[r]` for its record `r`.
    pub fn cost_before(&self, end: u64, record_cost: &[u64]) -> u128 {
        match self {
            Plan::Pair(p) => p.cost_before(end, record_cost),
            Plan::Row(r) => r.cost_before(end, record_cost),
        }
    }

    /// The runs that differ in their motion before any contact ([`PairPlan::motions`]).
    pub fn motions(&self) -> Motions {
        match self {
            Plan::Pair(p) => p.motions(),
            Plan::Row(r) => r.motions(),
        }
    }
}

/// Sweep axes of one building.
#[derive(Debug, Clone, PartialEq)]
pub struct BuildingAxes {
    /// kg
    pub mass: Vec<f64>,
    /// s
    pub period: Vec<f64>,
    pub damping: Vec<f64>,
}

/// Everything a plan is built from (engine types; the config layer fills it).
#[derive(Debug, Clone)]
pub struct PlanSpec {
    pub laws: Vec<LawKind>,
    pub formulas: Vec<Formula>,
    pub e: Vec<f64>,
    /// N/m, for linear laws
    pub k_linear: Vec<f64>,
    /// N/m^1.5, for Hertz-type laws
    pub beta: Vec<f64>,
    pub records: Vec<Arc<Record>>,
    pub intensities: Vec<Intensity>,
    pub building1: BuildingAxes,
    pub building2: BuildingAxes,
    /// m
    pub gaps: Vec<f64>,
    pub scheme: Scheme,
    /// Free vibration after each record, s.
    pub tail: f64,
    /// Sampled parameters, crossed with every grid axis.
    pub samples: Option<Samples>,
}

/// A parameter that a sample can set.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SampledAxis {
    Mass1,
    Period1,
    Damping1,
    Mass2,
    Period2,
    Damping2,
    Gap,
    /// `k` of linear laws.
    KLinear,
    /// `beta` of Hertz-type laws.
    Beta,
}

impl SampledAxis {
    pub const ALL: [SampledAxis; 9] = [
        SampledAxis::Mass1,
        SampledAxis::Period1,
        SampledAxis::Damping1,
        SampledAxis::Mass2,
        SampledAxis::Period2,
        SampledAxis::Damping2,
        SampledAxis::Gap,
        SampledAxis::KLinear,
        SampledAxis::Beta,
    ];

    /// The config key.
    pub fn key(self) -> &'static str {
        match self {
            SampledAxis::Mass1 => "building1.mass_kg",
            SampledAxis::Period1 => "building1.period_s",
            SampledAxis::Damping1 => "building1.damping_ratio",
            SampledAxis::Mass2 => "building2.mass_kg",
            SampledAxis::Period2 => "building2.period_s",
            SampledAxis::Damping2 => "building2.damping_ratio",
            SampledAxis::Gap => "contact.gap_m",
            SampledAxis::KLinear => "contact.k_n_per_m",
            SampledAxis::Beta => "contact.beta_n_per_m1_5",
        }
    }

    pub fn from_key(s: &str) -> Option<SampledAxis> {
        SampledAxis::ALL.into_iter().find(|a| a.key() == s)
    }
}

impl SampledAxis {
    /// Does it set a building's mass, period or damping?
    pub fn moves_buildings(self) -> bool {
        !matches!(
            self,
            SampledAxis::Gap | SampledAxis::KLinear | SampledAxis::Beta
        )
    }
}

/// The motions of a sweep ([`PairPlan::motions`]): `records x intensities x inner`, the record
/// outermost, then the intensity; `inner` counts the samples and building values.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Motions {
    pub records: usize,
    pub intensities: usize,
    pub inner: u64,
}

impl Motions {
    pub fn len(&self) -> u64 {
        (self.records * self.intensities) as u64 * self.inner
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Motion `m`'s record and intensity indices.
    pub fn record_and_intensity(&self, m: u64) -> (usize, usize) {
        let ri = (m / self.inner) as usize;
        (ri / self.intensities, ri % self.intensities)
    }

    /// The motions that differ only in intensity share one response at unit scale: motion
    /// `m`'s index among those `records x inner` responses.
    pub fn response(&self, m: u64) -> u64 {
        let (r, _) = self.record_and_intensity(m);
        r as u64 * self.inner + m % self.inner
    }
}

/// Joint samples of some parameters: `points[s][j]` is the value of `axes[j]` in sample `s`.
#[derive(Debug, Clone, PartialEq)]
pub struct Samples {
    pub axes: Vec<SampledAxis>,
    pub points: Vec<Vec<f64>>,
}

/// A plan value that is out of range; `key` is the config key (with index).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{key}: {message}")]
pub struct PlanError {
    pub key: String,
    pub message: String,
}

fn err(key: impl Into<String>, message: impl Into<String>) -> PlanError {
    PlanError {
        key: key.into(),
        message: message.into(),
    }
}

const NAXES: usize = 13;

/// The size of each axis of a sweep (before its values are built).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct AxisCounts {
    pub formulas: usize,
    pub e: usize,
    pub k_linear: usize,
    pub beta: usize,
    pub records: usize,
    pub intensities: usize,
    pub samples: usize,
    /// mass, period, damping
    pub building1: [usize; 3],
    pub building2: [usize; 3],
    pub gaps: usize,
}

/// The sizes of the 13 axes below `law`, outermost first: only the axes the law uses vary.
fn block_dims(law: LawKind, c: &AxisCounts) -> [usize; NAXES] {
    [
        if law.uses_zeta() { c.formulas } else { 1 },
        if law.is_damped() { c.e } else { 1 },
        if law.is_hertzian() {
            c.beta
        } else {
            c.k_linear
        },
        c.records,
        c.intensities,
        c.samples,
        c.building1[0],
        c.building1[1],
        c.building1[2],
        c.building2[0],
        c.building2[1],
        c.building2[2],
        c.gaps,
    ]
}

/// Runs of a sweep of these laws and axis sizes; None past 2^64.
pub fn count_runs(laws: &[LawKind], c: &AxisCounts) -> Option<u64> {
    laws.iter().try_fold(0u64, |total, &law| {
        let len = block_dims(law, c)
            .iter()
            .try_fold(1u64, |acc, &d| acc.checked_mul(d as u64))?;
        total.checked_add(len)
    })
}

/// Refuse a sweep of more than [`crate::plan::limits::MAX_RUNS`] runs (key `contact`, as the laws
/// are where the blocks of runs start), from the axis sizes alone.
pub fn check_run_count(laws: &[LawKind], c: &AxisCounts) -> Result<u64, PlanError> {
    match count_runs(laws, c) {
        Some(n) if n <= crate::plan::limits::MAX_RUNS => Ok(n),
        n => Err(err(
            "contact",
            format!(
                "the sweep has {} runs: expected at most 2^53 ({})",
                n.map_or("more than 2^64".to_string(), |n| n.to_string()),
                crate::plan::limits::WHY_RUNS
            ),
        )),
    }
}

#[derive(Debug, Clone)]
struct Block {
    law: LawKind,
    start: u64,
    len: u64,
    /// Sizes of the 13 axes below the law, outermost first.
    dims: [usize; NAXES],
}

/// A validated, numbered sweep.
#[derive(Debug, Clone)]
pub struct PairPlan {
    pub spec: PlanSpec,
    blocks: Vec<Block>,
    total: u64,
    /// Dimensionless damping per (law, formula, e index).
    damping: HashMap<(LawKind, Formula, usize), f64>,
    /// PGA of each record as read, m/s^2.
    pgas: Vec<f64>,
    /// Spectral measures of the records, as runs ask for them.
    ims: intensity::ImCache,
}

/// One run, decoded.
#[derive(Debug, Clone, PartialEq)]
pub struct RunSpec {
    pub index: u64,
    pub law: LawKind,
    /// None for laws without a formula (elastic and Hunt-Crossley).
    pub formula: Option<Formula>,
    /// None for elastic laws.
    pub e: Option<f64>,
    /// zeta, or `a` in `chi = a / v0` for Hunt-Crossley laws; 0 for elastic laws.
    pub damping: f64,
    /// k (N/m) or beta (N/m^1.5).
    pub stiffness: f64,
    pub record: usize,
    pub intensity: Intensity,
    pub scale: f64,
    /// For a spectral target, the periods it was read at (s, from and to).
    pub im_periods: Option<[f64; 2]>,
    /// PGA of the scaled record, g.
    pub pga_g: f64,
    pub m1: f64,
    pub t1: f64,
    pub xi1: f64,
    pub m2: f64,
    pub t2: f64,
    pub xi2: f64,
    pub gap: f64,
    /// Index of the sample that set the sampled parameters (None without sampling).
    pub sample: Option<usize>,
}

impl RunSpec {
    pub fn pair(&self) -> Pair {
        let b1 = Oscillator::from_period(self.m1, self.t1, self.xi1);
        let b2 = Oscillator::from_period(self.m2, self.t2, self.xi2);
        let contact = Contact::new(
            self.law,
            self.stiffness,
            self.damping,
            Pair::m_eff(&b1, &b2),
        );
        Pair {
            b1,
            b2,
            gap: self.gap,
            contact,
        }
    }
}

fn period_ok(v: f64) -> bool {
    v.is_finite() && v >= crate::plan::limits::MIN_PERIOD_S
}

const PERIOD_EXPECTED: &str = "a period >= 1e-4 s (stiffer is a rigid body, not a building: contact substeps resolve the structure's period, so runs would crawl)";

/// What a swept or sampled value must be, and the words an error gives for it: shared by the
/// pair's plan and the row's ([`crate::plan::row`]).
pub(crate) type Check = (fn(f64) -> bool, &'static str);
pub(crate) const PERIOD: Check = (period_ok, PERIOD_EXPECTED);
pub(crate) const DAMPING: Check = (|v| (0.0..1.0).contains(&v), "0 <= damping ratio < 1");
pub(crate) const GAP: Check = (|v| v.is_finite() && v >= 0.0, "a gap >= 0 m");
pub(crate) const MASS: Check = (|v| v.is_finite() && v > 0.0, "a mass > 0 kg");
pub(crate) const POSITIVE: Check = (|v| v.is_finite() && v > 0.0, "a value > 0");

/// `values` of the axis `key`: not empty, each passing `ok` (else an error naming the value and
/// its index, `expected` saying what it must be).
pub(crate) fn check_axis(
    key: &str,
    values: &[f64],
    ok: impl Fn(f64) -> bool,
    expected: &str,
) -> Result<(), PlanError> {
    if values.is_empty() {
        return Err(err(key, "is empty: give at least one value"));
    }
    for (i, &v) in values.iter().enumerate() {
        if !ok(v) {
            return Err(err(
                format!("{key}[{i}]"),
                format!(
                    "{} is out of range: expected {expected}",
                    crate::plan::limits::show(v)
                ),
            ));
        }
    }
    Ok(())
}

impl PairPlan {
    pub fn new(spec: PlanSpec) -> Result<PairPlan, PlanError> {
        PairPlan::build(spec, false)
    }

    /// The plan of a row's contact, record and intensity axes, its buildings placeholders.
    pub(crate) fn row_base(spec: PlanSpec) -> Result<PairPlan, PlanError> {
        PairPlan::build(spec, true)
    }

    fn build(spec: PlanSpec, row_base: bool) -> Result<PairPlan, PlanError> {
        let pos = POSITIVE.0;
        for (name, b) in [
            ("building1", &spec.building1),
            ("building2", &spec.building2),
        ] {
            check_axis(&format!("{name}.mass_kg"), &b.mass, MASS.0, MASS.1)?;
            check_axis(&format!("{name}.period_s"), &b.period, PERIOD.0, PERIOD.1)?;
            check_axis(
                &format!("{name}.damping_ratio"),
                &b.damping,
                DAMPING.0,
                DAMPING.1,
            )?;
        }
        check_axis("contact.gap_m", &spec.gaps, GAP.0, GAP.1)?;
        if let Some(s) = &spec.samples {
            if s.points.is_empty() {
                return Err(err("sample.n", "is 0: expected at least one sample"));
            }
            for (j, a) in s.axes.iter().enumerate() {
                let check = match a {
                    SampledAxis::Damping1 | SampledAxis::Damping2 => DAMPING,
                    SampledAxis::Gap => GAP,
                    SampledAxis::Period1 | SampledAxis::Period2 => PERIOD,
                    _ => POSITIVE,
                };
                if let Some(m) = sample::refused_draw(&s.points, j, check) {
                    return Err(err(format!("sample.axis[{j}] ({})", a.key()), m));
                }
            }
        }
        if spec.laws.is_empty() {
            return Err(err(
                "contact.law",
                format!("is empty: give one or more of {}", LawKind::keys()),
            ));
        }
        if spec.records.is_empty() {
            return Err(err("record", "no records: add at least one [[record]]"));
        }
        if spec.intensities.is_empty() {
            return Err(err("intensity", "is empty"));
        }
        for (i, v) in spec.intensities.iter().enumerate() {
            let (value, expected) = match v {
                Intensity::PgaG(_) => (v.value(), "a PGA > 0 g"),
                Intensity::Scale(_) => (v.value(), "a factor > 0"),
                Intensity::Spectral { im, .. } if im.average => (v.value(), "an Sa_avg > 0 g"),
                Intensity::Spectral { .. } => (v.value(), "an Sa > 0 g"),
            };
            if !pos(value) {
                return Err(err(
                    format!("{}[{i}]", v.key()),
                    format!(
                        "{} is out of range: expected {expected}",
                        crate::plan::limits::show(value)
                    ),
                ));
            }
        }
        let extremes = |b: &BuildingAxes, axis: SampledAxis| {
            let sampled = spec.samples.iter().flat_map(|s| {
                let j = s.axes.iter().position(|a| *a == axis);
                j.into_iter()
                    .flat_map(move |j| s.points.iter().map(move |p| p[j]))
            });
            intensity::span(b.period.iter().copied().chain(sampled))
        };
        let (lo1, hi1) = extremes(&spec.building1, SampledAxis::Period1);
        let (lo2, hi2) = extremes(&spec.building2, SampledAxis::Period2);
        // A row's base plan holds placeholder buildings: the row checks its targets' periods
        // against its own buildings ([`row::RowPlan`]).
        if !row_base {
            intensity::check_periods(&spec.intensities, &[lo1, lo2], &[hi1, hi2])
                .map_err(|(k, m)| err(k, m))?;
        }
        if !(spec.tail.is_finite() && (0.0..=crate::plan::limits::MAX_TAIL_S).contains(&spec.tail))
        {
            return Err(err(
                "run.tail_s",
                format!(
                    "{} is out of range: expected 0 to {} s ({})",
                    crate::plan::limits::show(spec.tail),
                    crate::plan::limits::MAX_TAIL_S,
                    crate::plan::limits::WHY_TAIL
                ),
            ));
        }
        for (r, rec) in spec.records.iter().enumerate() {
            let n = rec.forcing(1.0, spec.tail).intervals() as u64;
            if n > crate::plan::limits::MAX_INTERVALS {
                return Err(err(
                    format!("record[{r}]"),
                    format!(
                        "`{}` with a tail of {} s is {n} steps of {} s: expected at most 1e8 per run ({})",
                        rec.name,
                        spec.tail,
                        rec.dt,
                        crate::plan::limits::WHY_INTERVALS
                    ),
                ));
            }
        }
        let damped = spec.laws.iter().any(|l| l.is_damped());
        let uses_formula = spec.laws.iter().any(|l| l.uses_zeta());
        if damped {
            check_axis(
                "contact.e",
                &spec.e,
                |e| e > 0.0 && e <= 1.0,
                "a coefficient of restitution 0 < e <= 1",
            )?;
        }
        if uses_formula && spec.formulas.is_empty() {
            return Err(err(
                "contact.formula",
                format!(
                    "is empty: the laws given need one or more of {}",
                    Formula::keys()
                ),
            ));
        }
        if spec.laws.iter().any(|l| !l.is_hertzian()) {
            check_axis(
                "contact.k_n_per_m",
                &spec.k_linear,
                pos,
                "a stiffness > 0 N/m",
            )?;
        }
        if spec.laws.iter().any(|l| l.is_hertzian()) {
            check_axis(
                "contact.beta_n_per_m1_5",
                &spec.beta,
                pos,
                "a stiffness > 0 N/m^1.5",
            )?;
        }
        let mut pgas = Vec::with_capacity(spec.records.len());
        for (r, rec) in spec.records.iter().enumerate() {
            let scaled = spec
                .intensities
                .iter()
                .any(|i| !matches!(i, Intensity::Scale(_)));
            if scaled {
                // A record of zeros has no PGA or Sa to scale to.
                rec.scale_to_pga(1.0)
                    .map_err(|e| err(format!("record[{r}]"), e.to_string()))?;
            }
            pgas.push(rec.pga().value);
        }
        // Damping per (law, formula, e): printed formulas are cheap, `exact` root-finds once here.
        let mut damping = HashMap::new();
        for &law in &spec.laws {
            if !law.is_damped() {
                continue;
            }
            let formulas: &[Formula] = if law.uses_zeta() {
                &spec.formulas
            } else {
                &[Formula::Exact]
            };
            for &f in formulas {
                for (i, &e) in spec.e.iter().enumerate() {
                    let d = damping_for(law, f, e)
                        .map_err(|x| err(format!("contact.e[{i}]"), x.to_string()))?;
                    damping.insert((law, f, i), d);
                }
            }
        }
        let counts = AxisCounts {
            formulas: spec.formulas.len(),
            e: spec.e.len(),
            k_linear: spec.k_linear.len(),
            beta: spec.beta.len(),
            records: spec.records.len(),
            intensities: spec.intensities.len(),
            samples: spec.samples.as_ref().map_or(1, |s| s.points.len()),
            building1: [
                spec.building1.mass.len(),
                spec.building1.period.len(),
                spec.building1.damping.len(),
            ],
            building2: [
                spec.building2.mass.len(),
                spec.building2.period.len(),
                spec.building2.damping.len(),
            ],
            gaps: spec.gaps.len(),
        };
        check_run_count(&spec.laws, &counts)?;
        let mut blocks = Vec::with_capacity(spec.laws.len());
        let mut total: u64 = 0;
        for &law in &spec.laws {
            let dims = block_dims(law, &counts);
            let len = dims.iter().map(|&d| d as u64).product();
            blocks.push(Block {
                law,
                start: total,
                len,
                dims,
            });
            total += len;
        }
        Ok(PairPlan {
            spec,
            blocks,
            total,
            damping,
            pgas,
            ims: intensity::ImCache::default(),
        })
    }

    /// Inputs that are valid but physically absurd (a units mix-up?), one line each.
    pub fn warnings(&self) -> Vec<String> {
        let first = self.run(0);
        self.pga_warnings(&[first.t1, first.t2])
    }

    /// The records scaled past a PGA no earthquake reaches, for buildings of these fundamental
    /// periods (a spectral target at a building's period scales by the first run's).
    pub(crate) fn pga_warnings(&self, periods: &[f64]) -> Vec<String> {
        let mut w = Vec::new();
        for (r, rec) in self.spec.records.iter().enumerate() {
            let pga = self
                .spec
                .intensities
                .iter()
                .map(|i| {
                    let s = i.scaling(r, rec, self.pgas[r], periods, &self.ims);
                    self.pgas[r] * s.scale / G
                })
                .fold(0.0, f64::max);
            if pga > crate::plan::limits::WARN_PGA_G {
                w.push(format!(
                    "record `{}` reaches a PGA of {pga:.3} g, above {} g where no recorded earthquake reaches: check its units and the intensity",
                    rec.name,
                    crate::plan::limits::WARN_PGA_G
                ));
            }
        }
        w
    }

    /// Number of runs.
    pub fn len(&self) -> u64 {
        self.total
    }

    pub fn is_empty(&self) -> bool {
        self.total == 0
    }

    /// Decode run `index` (< `len()`).
    pub fn run(&self, index: u64) -> RunSpec {
        let mut run = self.decode(index);
        let periods = [run.t1, run.t2];
        self.scale(&mut run, &periods);
        run
    }

    /// Set `run`'s scale factor, the periods its intensity read and its PGA, for buildings of
    /// these fundamental periods (left to right).
    pub(crate) fn scale(&self, run: &mut RunSpec, periods: &[f64]) {
        let r = run.record;
        let s = run
            .intensity
            .scaling(r, &self.spec.records[r], self.pgas[r], periods, &self.ims);
        run.scale = s.scale;
        run.im_periods = s.periods;
        run.pga_g = self.pgas[r] * s.scale / G;
    }

    /// Run `index`, its scale left unset (NaN) until its buildings' periods are known
    /// ([`PairPlan::scale`]).
    pub(crate) fn decode(&self, index: u64) -> RunSpec {
        assert!(
            index < self.total,
            "run {index} out of range (plan has {})",
            self.total
        );
        let block = self
            .blocks
            .iter()
            .find(|b| index < b.start + b.len)
            .expect("index within total");
        let mut rem = index - block.start;
        let mut ix = [0usize; NAXES];
        for a in (0..NAXES).rev() {
            let d = block.dims[a] as u64;
            ix[a] = (rem % d) as usize;
            rem /= d;
        }
        let s = &self.spec;
        let law = block.law;
        let formula = law.uses_zeta().then(|| s.formulas[ix[0]]);
        let e = law.is_damped().then(|| s.e[ix[1]]);
        let damping = if law.is_damped() {
            self.damping[&(law, formula.unwrap_or(Formula::Exact), ix[1])]
        } else {
            0.0
        };
        let stiffness = if law.is_hertzian() {
            s.beta[ix[2]]
        } else {
            s.k_linear[ix[2]]
        };
        let (record, inten) = (ix[3], ix[4]);
        let mut run = RunSpec {
            index,
            law,
            formula,
            e,
            damping,
            stiffness,
            record,
            intensity: s.intensities[inten],
            scale: f64::NAN,
            im_periods: None,
            pga_g: f64::NAN,
            m1: s.building1.mass[ix[6]],
            t1: s.building1.period[ix[7]],
            xi1: s.building1.damping[ix[8]],
            m2: s.building2.mass[ix[9]],
            t2: s.building2.period[ix[10]],
            xi2: s.building2.damping[ix[11]],
            gap: s.gaps[ix[12]],
            sample: None,
        };
        if let Some(smp) = &s.samples {
            run.sample = Some(ix[5]);
            for (a, &v) in smp.axes.iter().zip(&smp.points[ix[5]]) {
                match a {
                    SampledAxis::Mass1 => run.m1 = v,
                    SampledAxis::Period1 => run.t1 = v,
                    SampledAxis::Damping1 => run.xi1 = v,
                    SampledAxis::Mass2 => run.m2 = v,
                    SampledAxis::Period2 => run.t2 = v,
                    SampledAxis::Damping2 => run.xi2 = v,
                    SampledAxis::Gap => run.gap = v,
                    SampledAxis::KLinear if !law.is_hertzian() => run.stiffness = v,
                    SampledAxis::Beta if law.is_hertzian() => run.stiffness = v,
                    SampledAxis::KLinear | SampledAxis::Beta => {}
                }
            }
        }
        run
    }

    /// The runs that differ in their motion before any contact: one per record, intensity,
    /// sample and building values, with the first law's first contact values and the first gap
    /// (what a separation study needs: [`PairPlan::motion_run`]). A sample axis that sets no
    /// building value moves nothing and counts once.
    pub fn motions(&self) -> Motions {
        let d = &self.blocks[0].dims;
        Motions {
            records: d[3],
            intensities: d[4],
            inner: self.motion_samples() as u64
                * d[6..12].iter().map(|&x| x as u64).product::<u64>(),
        }
    }

    /// Samples that move the buildings: all of them, or one where they set no building value.
    fn motion_samples(&self) -> usize {
        match &self.spec.samples {
            Some(s) if s.axes.iter().any(|a| a.moves_buildings()) => s.points.len(),
            _ => 1,
        }
    }

    /// Motion `m` of [`PairPlan::motions`], as the run of the plan that has it (its sample `None`
    /// where the samples move nothing).
    pub fn motion_run(&self, m: u64) -> RunSpec {
        let mut run = self.run(self.motion_index(m));
        if self.motion_samples() == 1 {
            run.sample = None;
        }
        run
    }

    /// The index of the run that has motion `m` ([`PairPlan::motion_run`]).
    pub(crate) fn motion_index(&self, m: u64) -> u64 {
        let b = &self.blocks[0];
        let mut dims = b.dims;
        dims[5] = self.motion_samples();
        // Decode over the motion axes (record to xi2), the others at 0.
        let mut ix = [0usize; NAXES];
        let mut rem = m;
        for a in (3..12).rev() {
            ix[a] = (rem % dims[a] as u64) as usize;
            rem /= dims[a] as u64;
        }
        let index = (0..NAXES).fold(0u64, |acc, a| acc * b.dims[a] as u64 + ix[a] as u64);
        b.start + index
    }

    /// The summed cost of runs `0..end` when a run costs `record_cost[r]` for its record `r`:
    /// in closed form per law block (the record axis repeats with a fixed stride), so
    /// O(blocks x records), never O(runs).
    pub fn cost_before(&self, end: u64, record_cost: &[u64]) -> u128 {
        let mut acc: u128 = 0;
        for b in &self.blocks {
            if end <= b.start {
                break;
            }
            let rem = (end - b.start).min(b.len) as u128;
            let inner: u128 = b.dims[4..].iter().map(|&d| d as u128).product();
            let nrec = b.dims[3] as u128;
            let cost = |r: usize| record_cost[r] as u128;
            let cycle: u128 = inner * (0..b.dims[3]).map(cost).sum::<u128>();
            let (q, r_rem) = (rem / (inner * nrec), rem % (inner * nrec));
            let (full, part) = ((r_rem / inner) as usize, r_rem % inner);
            acc += q * cycle + inner * (0..full).map(cost).sum::<u128>();
            if part > 0 {
                acc += part * cost(full);
            }
        }
        acc
    }

    pub fn forcing(&self, run: &RunSpec) -> Forcing<'_> {
        self.spec.records[run.record].forcing(run.scale, self.spec.tail)
    }
}
