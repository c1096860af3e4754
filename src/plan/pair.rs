//! A validated sweep of a pair of one-storey buildings ([`PairPlan`]): the shared contact axes
//! and, below each contact run, the pair's own.

use crate::physics::contact::{Contact, LawKind};
use crate::physics::model::{Forcing, Oscillator, Pair};
use crate::plan::axes::{
    check_axis, err, Motions, PlanError, DAMPING, GAP, MASS, PERIOD, POSITIVE,
};
use crate::plan::contact::{ContactPlan, ContactRun, ContactSpec};
use crate::plan::{intensity, limits, sample};

/// Sweep axes of one building.
#[derive(Debug, Clone, PartialEq)]
pub struct BuildingAxes {
    /// kg
    pub mass: Vec<f64>,
    /// s
    pub period: Vec<f64>,
    pub damping: Vec<f64>,
}

/// Everything a pair's plan is built from (engine types; the config layer fills it): the axes
/// every scene shares, and the pair's buildings, gap and samples.
#[derive(Debug, Clone)]
pub struct PlanSpec {
    pub contact: ContactSpec,
    pub building1: BuildingAxes,
    pub building2: BuildingAxes,
    /// m
    pub gaps: Vec<f64>,
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

/// Joint samples of some parameters: `points[s][j]` is the value of `axes[j]` in sample `s`.
#[derive(Debug, Clone, PartialEq)]
pub struct Samples {
    pub axes: Vec<SampledAxis>,
    pub points: Vec<Vec<f64>>,
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

/// A validated, numbered sweep of a pair of one-storey buildings: the shared contact axes
/// ([`ContactPlan`]) and, below each contact run, the pair's: sample, m1, T1, xi1, m2, T2, xi2,
/// gap, outermost first.
#[derive(Debug, Clone)]
pub struct PairPlan {
    pub contact: ContactPlan,
    pub building1: BuildingAxes,
    pub building2: BuildingAxes,
    /// m
    pub gaps: Vec<f64>,
    /// Sampled parameters, crossed with every grid axis.
    pub samples: Option<Samples>,
    /// Sizes of the pair's axes below a contact run: samples, m1, T1, xi1, m2, T2, xi2, gap.
    dims: [usize; 8],
    per_scene: u64,
}

/// One run of a pair, decoded: the shared contact part ([`ContactRun`], whose fields read
/// through: `spec.law`, `spec.scale`) and the pair's buildings and gap.
#[derive(Debug, Clone, PartialEq)]
pub struct RunSpec {
    pub contact: ContactRun,
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

impl std::ops::Deref for RunSpec {
    type Target = ContactRun;
    fn deref(&self) -> &ContactRun {
        &self.contact
    }
}

impl std::ops::DerefMut for RunSpec {
    fn deref_mut(&mut self) -> &mut ContactRun {
        &mut self.contact
    }
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

impl PairPlan {
    pub fn new(spec: PlanSpec) -> Result<PairPlan, PlanError> {
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
        // Every period each building takes: its samples where sampled (its axis then holds a
        // placeholder), else its axis.
        let periods = |b: &BuildingAxes, axis: SampledAxis| -> Vec<f64> {
            spec.samples
                .iter()
                .find_map(|s| {
                    let j = s.axes.iter().position(|a| *a == axis)?;
                    Some(s.points.iter().map(|p| p[j]).collect())
                })
                .unwrap_or_else(|| b.period.clone())
        };
        let taken = [
            periods(&spec.building1, SampledAxis::Period1),
            periods(&spec.building2, SampledAxis::Period2),
        ];
        let mut contact = ContactPlan::new(spec.contact)?;
        intensity::check_periods(&contact.spec.intensities, &taken).map_err(|(k, m)| err(k, m))?;
        contact.list_periods(&taken);
        let c = &contact.spec;
        let counts = AxisCounts {
            formulas: c.formulas.len(),
            e: c.e.len(),
            k_linear: c.k_linear.len(),
            beta: c.beta.len(),
            records: c.records.len(),
            intensities: c.intensities.len(),
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
        check_run_count(&c.laws, &counts)?;
        let dims = [
            counts.samples,
            counts.building1[0],
            counts.building1[1],
            counts.building1[2],
            counts.building2[0],
            counts.building2[1],
            counts.building2[2],
            counts.gaps,
        ];
        Ok(PairPlan {
            contact,
            building1: spec.building1,
            building2: spec.building2,
            gaps: spec.gaps,
            samples: spec.samples,
            dims,
            per_scene: dims.iter().map(|&d| d as u64).product(),
        })
    }

    /// Refuse the contact axes and sampled stiffnesses none of the laws takes: a pair always
    /// may touch, so only the laws decide which contact axes a run takes
    /// ([`ContactSpec::refuse_unused`]).
    pub(crate) fn refuse_unused(&self) -> Result<(), PlanError> {
        let spec = &self.contact.spec;
        spec.refuse_unused()?;
        for (j, a) in self.samples.iter().flat_map(|s| s.axes.iter().enumerate()) {
            if matches!(a, SampledAxis::KLinear | SampledAxis::Beta) {
                spec.refuse_unused_sample(j, a.key())?;
            }
        }
        Ok(())
    }

    /// What the plan was built from (to rebuild it with records changed).
    pub fn spec(&self) -> PlanSpec {
        PlanSpec {
            contact: self.contact.spec.clone(),
            building1: self.building1.clone(),
            building2: self.building2.clone(),
            gaps: self.gaps.clone(),
            samples: self.samples.clone(),
        }
    }

    /// Inputs that are valid but physically absurd (a units mix-up?), one line each.
    pub fn warnings(&self) -> Vec<String> {
        let first = self.run(0);
        self.contact.pga_warnings(&[first.t1, first.t2])
    }

    /// Number of runs.
    pub fn len(&self) -> u64 {
        self.contact.len() * self.per_scene
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Decode run `index` (< `len()`).
    pub fn run(&self, index: u64) -> RunSpec {
        assert!(
            index < self.len(),
            "run {index} out of range (plan has {})",
            self.len()
        );
        let mut c = self.contact.decode(index / self.per_scene);
        let mut rem = index % self.per_scene;
        let mut ix = [0usize; 8];
        for a in (0..8).rev() {
            let d = self.dims[a] as u64;
            ix[a] = (rem % d) as usize;
            rem /= d;
        }
        let (b1, b2) = (&self.building1, &self.building2);
        c.index = index;
        let mut run = RunSpec {
            contact: c,
            m1: b1.mass[ix[1]],
            t1: b1.period[ix[2]],
            xi1: b1.damping[ix[3]],
            m2: b2.mass[ix[4]],
            t2: b2.period[ix[5]],
            xi2: b2.damping[ix[6]],
            gap: self.gaps[ix[7]],
            sample: None,
        };
        if let Some(smp) = &self.samples {
            run.sample = Some(ix[0]);
            let law = run.law;
            for (a, &v) in smp.axes.iter().zip(&smp.points[ix[0]]) {
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
        let periods = [run.t1, run.t2];
        self.contact.scale(&mut run.contact, &periods);
        run
    }

    /// The runs that differ in their motion before any contact: one per record, intensity,
    /// sample and building values, with the first law's first contact values and the first gap
    /// (what a separation study needs: [`PairPlan::motion_run`]). A sample axis that sets no
    /// building value moves nothing and counts once.
    pub fn motions(&self) -> Motions {
        let c = &self.contact.spec;
        Motions {
            records: c.records.len(),
            intensities: c.intensities.len(),
            inner: self.motion_samples() as u64
                * self.dims[1..7].iter().map(|&x| x as u64).product::<u64>(),
        }
    }

    /// Samples that move the buildings: all of them, or one where they set no building value.
    fn motion_samples(&self) -> usize {
        match &self.samples {
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
    fn motion_index(&self, m: u64) -> u64 {
        let mut dims = self.dims;
        dims[0] = self.motion_samples();
        let inner: u64 = dims[..7].iter().map(|&d| d as u64).product();
        let contact = self.contact.motion_index(m / inner);
        // Decode over the motion axes (sample to xi2), the gap at its first value.
        let mut ix = [0usize; 8];
        let mut rem = m % inner;
        for a in (0..7).rev() {
            ix[a] = (rem % dims[a] as u64) as usize;
            rem /= dims[a] as u64;
        }
        let within = (0..8).fold(0u64, |acc, a| acc * self.dims[a] as u64 + ix[a] as u64);
        contact * self.per_scene + within
    }

    /// The summed cost of runs `0..end` when a run costs `record_cost[r]` for its record `r`:
    /// O(blocks x records), never O(runs) ([`ContactPlan`]).
    pub fn cost_before(&self, end: u64, record_cost: &[u64]) -> u128 {
        self.contact
            .scene_cost_before(end, self.per_scene, record_cost)
    }

    pub fn forcing(&self, run: &RunSpec) -> Forcing<'_> {
        self.contact.spec.records[run.record].forcing(run.scale, self.contact.spec.tail)
    }
}

/// Runs whose peak displacement exceeds a building's height estimated from its period
/// ([`limits::HEIGHT_PER_PERIOD_M`]).
pub fn above_height(rows: &[(RunSpec, crate::physics::model::RunOutput)]) -> u64 {
    let h = limits::HEIGHT_PER_PERIOD_M;
    rows.iter()
        .filter(|(s, o)| o.peak_u1 > h * s.t1 || o.peak_u2 > h * s.t2)
        .count() as u64
}
