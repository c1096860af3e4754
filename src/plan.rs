//! A validated sweep: every axis checked, every run numbered. The engine consumes only this.
//!
//! Runs are grouped by contact law. Within a law's block, only the axes that law uses vary
//! (elastic laws ignore `e` and the formula; linear laws take `k`, Hertz-type laws `beta`), so no
//! run is a duplicate of another. Axis order, outermost first: law, formula, e, stiffness, record,
//! intensity, sample, m1, T1, xi1, m2, T2, xi2, gap. A sample (of uncertain parameters, see
//! [`Samples`]) sets the parameters it holds; their grid axes then hold one placeholder value. Run `i` is decoded from its index (mixed radix), so
//! the plan is never expanded in memory and run numbers do not depend on threads or chunking.

use crate::contact::{Contact, LawKind};
use crate::cpu::Scheme;
use crate::model::{Forcing, Oscillator, Pair};
use crate::record::{Record, G};
use crate::restitution::{damping_for, Formula};
use std::collections::HashMap;
use std::sync::Arc;

/// A value of the intensity axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Intensity {
    /// Scale each record to this PGA, g.
    PgaG(f64),
    /// Multiply each record by this factor.
    Scale(f64),
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
pub struct Plan {
    pub spec: PlanSpec,
    blocks: Vec<Block>,
    total: u64,
    /// Dimensionless damping per (law, formula, e index).
    damping: HashMap<(LawKind, Formula, usize), f64>,
    /// Scale factor per (record, intensity).
    scales: Vec<Vec<f64>>,
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

fn check_axis(
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
                format!("{v} is out of range: expected {expected}"),
            ));
        }
    }
    Ok(())
}

impl Plan {
    pub fn new(spec: PlanSpec) -> Result<Plan, PlanError> {
        let pos = |v: f64| v.is_finite() && v > 0.0;
        for (name, b) in [
            ("building1", &spec.building1),
            ("building2", &spec.building2),
        ] {
            check_axis(&format!("{name}.mass_kg"), &b.mass, pos, "a mass > 0 kg")?;
            check_axis(
                &format!("{name}.period_s"),
                &b.period,
                pos,
                "a period > 0 s",
            )?;
            check_axis(
                &format!("{name}.damping_ratio"),
                &b.damping,
                |v| (0.0..1.0).contains(&v),
                "0 <= damping ratio < 1",
            )?;
        }
        check_axis(
            "contact.gap_m",
            &spec.gaps,
            |v| v.is_finite() && v >= 0.0,
            "a gap >= 0 m",
        )?;
        if let Some(s) = &spec.samples {
            if s.points.is_empty() {
                return Err(err("sample.n", "is 0: expected at least one sample"));
            }
            for (j, a) in s.axes.iter().enumerate() {
                let col: Vec<f64> = s.points.iter().map(|p| p[j]).collect();
                let (ok, expected): (fn(f64) -> bool, &str) = match a {
                    SampledAxis::Damping1 | SampledAxis::Damping2 => {
                        (|v| (0.0..1.0).contains(&v), "0 <= damping ratio < 1")
                    }
                    SampledAxis::Gap => (|v| v.is_finite() && v >= 0.0, "a gap >= 0 m"),
                    _ => (|v| v.is_finite() && v > 0.0, "a value > 0"),
                };
                if let Some(i) = col.iter().position(|&v| !ok(v)) {
                    return Err(err(
                        format!("sample.axis[{j}] ({})", a.key()),
                        format!(
                            "sample {i} drew {}: expected {expected}; truncate the distribution with min/max",
                            col[i]
                        ),
                    ));
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
            match *v {
                Intensity::PgaG(g) if !pos(g) => {
                    return Err(err(
                        format!("intensity.pga_g[{i}]"),
                        format!("{g} is out of range: expected a PGA > 0 g"),
                    ))
                }
                Intensity::Scale(s) if !pos(s) => {
                    return Err(err(
                        format!("intensity.scale[{i}]"),
                        format!("{s} is out of range: expected a factor > 0"),
                    ))
                }
                _ => {}
            }
        }
        if !(spec.tail.is_finite() && spec.tail >= 0.0) {
            return Err(err(
                "run.tail_s",
                format!("{} is out of range: expected >= 0 s", spec.tail),
            ));
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
        let mut scales = Vec::with_capacity(spec.records.len());
        for (r, rec) in spec.records.iter().enumerate() {
            let mut row = Vec::with_capacity(spec.intensities.len());
            for v in &spec.intensities {
                row.push(match *v {
                    Intensity::PgaG(g) => rec
                        .scale_to_pga(g * G)
                        .map_err(|e| err(format!("record[{r}]"), e.to_string()))?,
                    Intensity::Scale(s) => s,
                });
            }
            scales.push(row);
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
        let mut blocks = Vec::with_capacity(spec.laws.len());
        let mut total: u64 = 0;
        for &law in &spec.laws {
            let b1 = &spec.building1;
            let b2 = &spec.building2;
            let dims = [
                if law.uses_zeta() {
                    spec.formulas.len()
                } else {
                    1
                },
                if law.is_damped() { spec.e.len() } else { 1 },
                if law.is_hertzian() {
                    spec.beta.len()
                } else {
                    spec.k_linear.len()
                },
                spec.records.len(),
                spec.intensities.len(),
                spec.samples.as_ref().map_or(1, |s| s.points.len()),
                b1.mass.len(),
                b1.period.len(),
                b1.damping.len(),
                b2.mass.len(),
                b2.period.len(),
                b2.damping.len(),
                spec.gaps.len(),
            ];
            let len = dims
                .iter()
                .try_fold(1u64, |acc, &d| acc.checked_mul(d as u64));
            let Some(len) = len.filter(|l| total.checked_add(*l).is_some()) else {
                return Err(err("contact", "the sweep has more than 2^64 runs"));
            };
            blocks.push(Block {
                law,
                start: total,
                len,
                dims,
            });
            total += len;
        }
        Ok(Plan {
            spec,
            blocks,
            total,
            damping,
            scales,
        })
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
        let scale = self.scales[record][inten];
        let mut run = RunSpec {
            index,
            law,
            formula,
            e,
            damping,
            stiffness,
            record,
            intensity: s.intensities[inten],
            scale,
            pga_g: s.records[record].pga().value * scale / G,
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

    pub fn forcing(&self, run: &RunSpec) -> Forcing<'_> {
        self.spec.records[run.record].forcing(run.scale, self.spec.tail)
    }
}
