//! In-engine aggregation for sweeps too large to store per run (`pound sweep --aggregate`): per
//! group of swept parameters, run counts, exceedance counts for given thresholds, and the max,
//! mean and quantiles of each output. Memory is bounded by the number of groups, not of runs.
//!
//! Quantiles come from a log-bucket histogram with a relative error of at most 1 % (a value's
//! bucket is `ceil(log_g x)`, `g = 1.02`, DDSketch-style), over a fixed range
//! [`SKETCH_MIN`, `SKETCH_MAX`] so that the GPU can keep it as a dense array of counters (see
//! `shaders/aggregate.wgsl`, whose per-run body [`Group::add`] is the CPU twin of). Values below
//! the range count as zero; values above it land in the top bucket, whose quantile is the exact
//! max. Max and mean are exact.

use crate::physics::model::{RunOutput, Status};
use crate::plan::columns::{header, row};
use crate::plan::intensity::target_values;
use crate::plan::{PairPlan, RunSpec};
use std::collections::{BTreeMap, HashMap};

/// Outputs summarised per group: named by the schema, in [`outputs`] order.
pub const OUTPUTS: [&str; NOUT] = crate::plan::columns::SUMMARISED;
pub const NOUT: usize = crate::plan::columns::SUMMARISED.len();

/// Quantiles reported for each output.
pub const QUANTILES: [f64; 3] = [0.5, 0.9, 0.99];

/// Bucket growth factor: a bucket's midpoint is within 1 % of every value in it.
pub const GAMMA: f64 = 1.02;
/// Values below this (in the output's SI unit) count as zero.
pub const SKETCH_MIN: f64 = 1e-12;
/// Values above this share the top bucket.
pub const SKETCH_MAX: f64 = 1e12;
/// `ceil(log_g SKETCH_MIN)` and `ceil(log_g SKETCH_MAX)` (checked by a test).
pub const KMIN: i32 = -1395;
pub const KMAX: i32 = 1396;
/// Buckets per output: the zero bucket, then `KMIN..=KMAX`.
pub const BUCKETS: usize = (KMAX - KMIN + 2) as usize;
/// Most `--exceed` thresholds one sweep may count.
pub const MAX_EXCEED: usize = 8;

/// The bucket of a non-negative value (0 for zero, tiny values and NaN).
pub fn bucket(x: f64) -> usize {
    if x.is_nan() || x < SKETCH_MIN {
        return 0;
    }
    let k = (x.min(SKETCH_MAX).ln() / GAMMA.ln()).ceil() as i32;
    (k.clamp(KMIN, KMAX) - KMIN + 1) as usize
}

/// The value a bucket stands for: its midpoint in the sense of relative error.
pub fn bucket_value(b: usize) -> f64 {
    if b == 0 {
        return 0.0;
    }
    let k = b as i32 - 1 + KMIN;
    2.0 * GAMMA.powi(k) / (1.0 + GAMMA)
}

/// The summarised outputs of a run, in [`OUTPUTS`] order, as magnitudes.
pub fn outputs(o: &RunOutput) -> [f64; NOUT] {
    [
        o.impacts as f64,
        o.peak_force,
        o.peak_penetration,
        o.peak_u1,
        o.peak_u2,
        o.impact_velocity,
        o.contact_time,
        o.dissipated_energy,
    ]
    .map(f64::abs)
}

/// Histogram, count, sum and max of one output's values in one group.
#[derive(Debug, Clone, Default)]
pub struct Sketch {
    buckets: BTreeMap<u32, u64>,
    count: u64,
    sum: f64,
    max: f64,
}

impl Sketch {
    pub fn add(&mut self, x: f64) {
        self.count += 1;
        self.sum += x;
        self.max = self.max.max(x);
        *self.buckets.entry(bucket(x) as u32).or_default() += 1;
    }

    /// Fold in values summarised elsewhere (a device partial); their buckets come separately,
    /// through [`Sketch::add_bucket`].
    pub fn add_moments(&mut self, count: u64, sum: f64, max: f64) {
        self.count += count;
        self.sum += sum;
        self.max = self.max.max(max);
    }

    pub fn add_bucket(&mut self, b: usize, n: u64) {
        if n > 0 {
            *self.buckets.entry(b as u32).or_default() += n;
        }
    }

    /// Values folded in.
    pub fn count(&self) -> u64 {
        self.count
    }

    /// The largest value folded in (exact).
    pub fn max(&self) -> f64 {
        self.max
    }

    pub fn mean(&self) -> f64 {
        self.sum / self.count.max(1) as f64
    }

    /// The `q` quantile, within 1 % of a value of the data at that rank (for values inside the
    /// sketch's range).
    pub fn quantile(&self, q: f64) -> f64 {
        if self.count == 0 {
            return f64::NAN;
        }
        let rank = crate::engine::quantile::nearest_rank(self.count as usize, q) as u64;
        let mut seen = 0;
        for (&b, &n) in &self.buckets {
            seen += n;
            if seen > rank {
                return if b as usize == BUCKETS - 1 {
                    self.max
                } else {
                    bucket_value(b as usize).min(self.max)
                };
            }
        }
        self.max
    }
}

/// One group's summary.
#[derive(Debug, Clone, Default)]
pub struct Group {
    pub runs: u64,
    pub failures: u64,
    /// Runs in which a building collapsed: counted apart; a collapsed building's outputs and
    /// the run's own count as exceeding every `--exceed` threshold (an infinite demand) and
    /// stay out of the statistics (their peaks end at the collapse), a building left standing
    /// is summarised as in any run (physics.md section 12).
    pub collapsed: u64,
    pub exceed: Vec<u64>,
    pub stats: Vec<Sketch>,
    /// Per `--exceed`, `ok` runs whose cell was empty (neither exceeding nor not; see
    /// [`may_be_empty`]).
    pub undecided: Vec<u64>,
    /// Per output, `ok` runs whose cell was empty (not in its statistics).
    pub no_value: Vec<u64>,
}

/// Can an output column of an `ok` run be empty? A yielding building's residual drift (and its
/// storey) where the run did not settle: not known, so neither a value nor a zero
/// (docs/inelastic.md). The summary counts such runs apart for these columns.
pub fn may_be_empty(column: &str) -> bool {
    column.ends_with("residual_drift_ratio") || column.ends_with("residual_storey")
}

impl Group {
    fn new(nexceed: usize, noutputs: usize) -> Group {
        Group {
            exceed: vec![0; nexceed],
            stats: vec![Sketch::default(); noutputs],
            undecided: vec![0; nexceed],
            no_value: vec![0; noutputs],
            ..Default::default()
        }
    }

    /// Fold in one run: `exceed` holds (output index, threshold) pairs. Failed runs are
    /// counted, not summarised. The per-run body of `shaders/aggregate.wgsl`, line for line.
    pub fn add(&mut self, o: &RunOutput, exceed: &[(usize, f64)]) {
        // A pair's outputs are never empty, and a pair never collapses.
        self.add_values(o.status, &outputs(o).map(Some), exceed, &[]);
    }

    /// Fold in one run's summarised outputs `x` (magnitudes, in the aggregator's output order),
    /// None where its cell was empty: such a run is counted apart (`undecided`, `no_value`),
    /// neither exceeding nor in the statistics. In a collapsed run, the outputs marked in
    /// `standing` (a building that did not collapse) are taken as in any run; the others
    /// exceed every threshold and stay out of the statistics.
    fn add_values(
        &mut self,
        status: Status,
        x: &[Option<f64>],
        exceed: &[(usize, f64)],
        standing: &[bool],
    ) {
        self.runs += 1;
        let collapsed = status == Status::Collapsed;
        if collapsed {
            self.collapsed += 1;
        } else if status != Status::Ok {
            self.failures += 1;
            return;
        }
        let stands = |i: usize| !collapsed || standing.get(i).copied().unwrap_or(false);
        for (k, &(i, t)) in exceed.iter().enumerate() {
            match x[i] {
                _ if !stands(i) => self.exceed[k] += 1,
                Some(v) => self.exceed[k] += (v > t) as u64,
                None => self.undecided[k] += 1,
            }
        }
        for (_, ((s, n), v)) in (self.stats.iter_mut().zip(self.no_value.iter_mut()).zip(x))
            .enumerate()
            .filter(|(i, _)| stands(*i))
        {
            match v {
                Some(v) => s.add(*v),
                None => *n += 1,
            }
        }
    }

    /// Fold in a device partial (its histogram counts come through [`Group::add_histogram`]).
    pub fn add_partial(&mut self, p: &Partial) {
        self.runs += p.runs;
        self.failures += p.failures;
        for (e, n) in self.exceed.iter_mut().zip(&p.exceed) {
            *e += n;
        }
        let ok = p.runs - p.failures;
        for (o, s) in self.stats.iter_mut().enumerate() {
            s.add_moments(ok, p.sum[o], p.max[o]);
        }
    }

    /// Fold in bucket counts: [`NOUT`] outputs of [`BUCKETS`] counters each.
    pub fn add_histogram(&mut self, counts: &[u32]) {
        for (s, c) in self.stats.iter_mut().zip(counts.chunks_exact(BUCKETS)) {
            for (b, &n) in c.iter().enumerate() {
                s.add_bucket(b, n as u64);
            }
        }
    }
}

/// What the device folded for one segment of runs of one group (histograms aside); runs handed
/// back to the CPU are not in it.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Partial {
    pub runs: u64,
    pub failures: u64,
    /// Runs with at least one impact, and their impacts (for the sweep's totals).
    pub pounded: u64,
    pub impacts: u64,
    pub exceed: [u64; MAX_EXCEED],
    pub max: [f64; NOUT],
    pub sum: [f64; NOUT],
}

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum AggregateError {
    #[error("--aggregate: `{column}` is not a swept-parameter column; group by columns such as {examples}")]
    NoColumn { column: String, examples: String },
    #[error("--exceed `{given}`: expected COLUMN=THRESHOLD with an output column ({columns}), e.g. {example}=1e6")]
    BadExceed {
        given: String,
        columns: String,
        example: String,
    },
    #[error("--exceed `{given}`: the threshold must be a finite number (COLUMN > THRESHOLD is never decided by NaN or infinity)")]
    NonFiniteThreshold { given: String },
    #[error("--exceed: at most {MAX_EXCEED} thresholds, {0} given")]
    TooManyExceed(usize),
    /// One name for two columns of the summary.
    #[error("{flag}: `{given}` is given twice (a summary's columns each have their own name)")]
    Twice { flag: &'static str, given: String },
}

/// A swept-parameter column, as a key (floats by their bits; an absent value is `u64::MAX`).
#[derive(Debug, Clone, Copy, PartialEq)]
enum Param {
    Run,
    Law,
    Formula,
    E,
    Damping,
    K,
    Beta,
    Record,
    /// One of [`crate::plan::intensity::TARGET_COLUMNS`].
    Target(usize),
    Scale,
    Pga,
    /// One of [`crate::plan::intensity::IM_COLUMNS`].
    RecordIm(usize),
    /// `Sa(T1)` of building 1 or 2 (0 or 1).
    SaT1(usize),
    M1,
    T1,
    Xi1,
    M2,
    T2,
    Xi2,
    Gap,
    Sample,
}

impl Param {
    fn from_column(c: &str) -> Option<Param> {
        use Param::*;
        Some(match c {
            "run" => Run,
            "law" => Law,
            "formula" => Formula,
            "e" => E,
            "impact_damping" => Damping,
            "k_n_per_m" => K,
            "beta_n_per_m1_5" => Beta,
            "record" => Record,
            "target_pga_g" => Target(0),
            "target_sa_g" => Target(1),
            "sa_period_s" => Target(2),
            "target_sa_avg_g" => Target(3),
            "sa_avg_from_s" => Target(4),
            "sa_avg_to_s" => Target(5),
            "scale_factor" => Scale,
            "pga_g" => Pga,
            "pgv_m_s" => RecordIm(0),
            "arias_m_s" => RecordIm(1),
            "cav_m_s" => RecordIm(2),
            "sa_t1_g" => SaT1(0),
            "sa_t2_g" => SaT1(1),
            "m1_kg" => M1,
            "t1_s" => T1,
            "xi1" => Xi1,
            "m2_kg" => M2,
            "t2_s" => T2,
            "xi2" => Xi2,
            "gap_m" => Gap,
            "sample" => Sample,
            _ => return None,
        })
    }

    fn key(self, plan: &PairPlan, s: &RunSpec) -> u64 {
        const NONE: u64 = u64::MAX;
        let bits = |x: Option<f64>| x.map_or(NONE, f64::to_bits);
        let hertz = s.law.is_hertzian();
        match self {
            Param::Run => s.index,
            Param::Law => s.law as u64,
            Param::Formula => s.formula.map_or(NONE, |f| f as u64),
            Param::E => bits(s.e),
            Param::Damping => bits(s.law.is_damped().then_some(s.damping)),
            Param::K => bits((!hertz).then_some(s.stiffness)),
            Param::Beta => bits(hertz.then_some(s.stiffness)),
            Param::Record => s.record as u64,
            Param::Target(i) => bits(target_values(&s.intensity, s.im_periods)[i]),
            Param::Scale => s.scale.to_bits(),
            Param::Pga => s.pga_g.to_bits(),
            Param::RecordIm(i) => plan.contact.record_ims(s)[i].to_bits(),
            Param::SaT1(b) => plan
                .contact
                .sa_g(s, if b == 0 { s.t1 } else { s.t2 })
                .to_bits(),
            Param::M1 => s.m1.to_bits(),
            Param::T1 => s.t1.to_bits(),
            Param::Xi1 => s.xi1.to_bits(),
            Param::M2 => s.m2.to_bits(),
            Param::T2 => s.t2.to_bits(),
            Param::Xi2 => s.xi2.to_bits(),
            Param::Gap => s.gap.to_bits(),
            Param::Sample => s.sample.map_or(NONE, |i| i as u64),
        }
    }
}

/// Groups runs and folds their outputs in: the pair's runs by their typed parameters (the
/// device fold's keys), or any sweep's rows by the text of their cells.
#[derive(Debug, Clone)]
pub struct Aggregator {
    /// Column name, its index in the header, its key (None: keyed by the cell's text).
    by: Vec<(String, usize, Option<Param>)>,
    /// The summarised outputs: name and index in the header.
    outputs: Vec<(String, usize)>,
    /// Column name of each `--exceed`.
    exceed_names: Vec<String>,
    /// Output index and threshold of each `--exceed`.
    exceed: Vec<(usize, f64)>,
    ids: HashMap<Vec<u64>, u32>,
    /// Groups keyed by their labels' text ([`Aggregator::add_cells`]).
    label_ids: HashMap<Vec<String>, u32>,
    /// In the order of each group's first run (the summary's row order), with its labels.
    groups: Vec<(Vec<String>, Group)>,
    /// Its runs may collapse (rows of buildings with storey heights): the summary counts them.
    collapses: bool,
    /// Per output, the header index of its building's `bK_collapsed` column (a row's
    /// per-building outputs): in a collapsed run, an output of a building left standing is
    /// summarised as in any run.
    building_collapsed: Vec<Option<usize>>,
}

impl Aggregator {
    /// The summary of a sweep of `plan`: a pair's runs keyed by their typed parameters (which
    /// the device fold can key too), a row's by its cells.
    pub fn for_plan(
        plan: &crate::plan::Plan,
        by: &[String],
        exceed: &[String],
    ) -> Result<Aggregator, AggregateError> {
        match plan {
            crate::plan::Plan::Pair(_) => Aggregator::new(by, exceed),
            crate::plan::Plan::Row(r) => Aggregator::of_cells(
                &r.header(),
                r.parameter_columns(),
                &r.summarised(),
                by,
                exceed,
            )
            .map(|a| {
                let h = r.header();
                let building_collapsed = (a.outputs.iter())
                    .map(|(o, _)| {
                        let (k, _) = o.strip_prefix('b')?.split_once('_')?;
                        k.bytes().all(|c| c.is_ascii_digit()).then_some(())?;
                        let c = format!("b{k}_collapsed");
                        h.iter().position(|x| *x == c)
                    })
                    .collect();
                Aggregator {
                    collapses: true,
                    building_collapsed,
                    ..a
                }
            }),
        }
    }

    /// Whether its runs may collapse: the summary then has a `collapsed` count.
    pub fn collapses(&self) -> bool {
        self.collapses
    }

    /// Group the pair's runs by the columns `by`; count runs whose `column > threshold` for
    /// each `exceed`.
    pub fn new(by: &[String], exceed: &[String]) -> Result<Aggregator, AggregateError> {
        let h = header();
        let by = by
            .iter()
            .map(|b| {
                let b = b.trim();
                Param::from_column(b)
                    .map(|p| {
                        let i = h.iter().position(|c| *c == b).expect("parameter column");
                        (b.to_string(), i, Some(p))
                    })
                    .ok_or_else(|| AggregateError::NoColumn {
                        column: b.to_string(),
                        examples: "record, pga_g, gap_m, t1_s, law, e".into(),
                    })
            })
            .collect::<Result<_, _>>()?;
        let outputs = OUTPUTS
            .iter()
            .map(|o| {
                (
                    o.to_string(),
                    h.iter().position(|c| c == o).expect("output"),
                )
            })
            .collect();
        Self::with(by, outputs, exceed)
    }

    /// Group the rows of a table with columns `header` by the columns `by`, which must be
    /// among its first `parameters` columns (the swept parameters), and summarise `outputs`
    /// (magnitudes of numeric cells); rows are folded in by [`Aggregator::add_cells`].
    pub fn of_cells(
        header: &[String],
        parameters: usize,
        outputs: &[String],
        by: &[String],
        exceed: &[String],
    ) -> Result<Aggregator, AggregateError> {
        let by = by
            .iter()
            .map(|b| {
                let b = b.trim();
                header[..parameters]
                    .iter()
                    .position(|c| c == b)
                    .map(|i| (b.to_string(), i, None))
                    .ok_or_else(|| AggregateError::NoColumn {
                        column: b.to_string(),
                        examples: header[..parameters].join(", "),
                    })
            })
            .collect::<Result<_, _>>()?;
        let outputs = outputs
            .iter()
            .map(|o| {
                let i = header
                    .iter()
                    .position(|c| c == o)
                    .expect("an output column");
                (o.clone(), i)
            })
            .collect();
        Self::with(by, outputs, exceed)
    }

    fn with(
        by: Vec<(String, usize, Option<Param>)>,
        outputs: Vec<(String, usize)>,
        exceed: &[String],
    ) -> Result<Aggregator, AggregateError> {
        if exceed.len() > MAX_EXCEED {
            return Err(AggregateError::TooManyExceed(exceed.len()));
        }
        if let Some((b, _, _)) = by
            .iter()
            .enumerate()
            .find_map(|(i, b)| by[..i].iter().any(|x| x.1 == b.1).then_some(b))
        {
            return Err(AggregateError::Twice {
                flag: "--aggregate",
                given: b.clone(),
            });
        }
        let parsed: Vec<(String, usize, f64)> = exceed
            .iter()
            .map(|e| {
                let bad = || AggregateError::BadExceed {
                    given: e.clone(),
                    columns: outputs
                        .iter()
                        .map(|(o, _)| o.as_str())
                        .collect::<Vec<_>>()
                        .join(", "),
                    example: outputs
                        .iter()
                        .find(|(o, _)| o.ends_with("peak_force_n"))
                        .map_or("peak_force_n", |(o, _)| o.as_str())
                        .to_string(),
                };
                let (c, t) = e.split_once('=').ok_or_else(bad)?;
                let i = outputs
                    .iter()
                    .position(|(o, _)| *o == c.trim())
                    .ok_or_else(bad)?;
                let t: f64 = t.trim().parse().map_err(|_| bad())?;
                if !t.is_finite() {
                    return Err(AggregateError::NonFiniteThreshold { given: e.clone() });
                }
                Ok((c.trim().to_string(), i, t))
            })
            .collect::<Result<_, _>>()?;
        // One column and threshold, however spelled (`1e6`, `1000000`), is one column.
        if let Some(k) = (0..parsed.len()).find(|&k| {
            parsed[..k]
                .iter()
                .any(|p| (p.1, p.2) == (parsed[k].1, parsed[k].2))
        }) {
            return Err(AggregateError::Twice {
                flag: "--exceed",
                given: exceed[k].clone(),
            });
        }
        Ok(Aggregator {
            by,
            outputs,
            exceed: parsed.iter().map(|&(_, i, t)| (i, t)).collect(),
            exceed_names: parsed.into_iter().map(|(c, _, _)| c).collect(),
            ids: HashMap::new(),
            label_ids: HashMap::new(),
            groups: Vec::new(),
            collapses: false,
            building_collapsed: Vec::new(),
        })
    }

    /// The summarised outputs' names, in the summary's order.
    pub fn outputs(&self) -> impl Iterator<Item = &str> {
        self.outputs.iter().map(|(o, _)| o.as_str())
    }

    /// Fold in finished runs of a row of buildings, by their cells (a summary built by
    /// [`Aggregator::for_plan`]).
    pub fn add_row_runs(
        &mut self,
        plan: &crate::plan::row::RowPlan,
        rows: &[(crate::plan::row::RowRunSpec, crate::physics::row::RowOutput)],
    ) {
        for (s, o) in rows {
            self.add_cells(&plan.cells(s, o), o.status);
        }
    }

    /// Fold in one run given as its cells (in the header's order) and its status: grouped by
    /// the text of its `by` cells; a failed run is counted as one, a collapsed one apart. An
    /// empty output cell of an `ok` row is counted apart (no value: a residual drift not
    /// known); an unreadable one counts as NaN (the zero bucket).
    pub fn add_cells(&mut self, cells: &[String], status: Status) {
        let label: Vec<String> = self.by.iter().map(|(_, i, _)| cells[*i].clone()).collect();
        let next = self.groups.len() as u32;
        let nout = self.outputs.len();
        let nexceed = self.exceed.len();
        let id = *self.label_ids.entry(label.clone()).or_insert(next);
        if id == next {
            self.groups.push((label, Group::new(nexceed, nout)));
        }
        let x: Vec<Option<f64>> = self
            .outputs
            .iter()
            .map(|(_, i)| {
                let c = &cells[*i];
                (!c.is_empty()).then(|| c.parse::<f64>().map_or(f64::NAN, f64::abs))
            })
            .collect();
        let standing: Vec<bool> = (self.building_collapsed.iter())
            .map(|c| c.is_some_and(|i| cells[i] == "0"))
            .collect();
        let exceed = &self.exceed;
        self.groups[id as usize]
            .1
            .add_values(status, &x, exceed, &standing);
    }

    /// The (output index, threshold) pairs of `--exceed`.
    pub fn thresholds(&self) -> &[(usize, f64)] {
        &self.exceed
    }

    /// The group of a run (numbered in the order of first appearance).
    pub fn group_of(&mut self, plan: &PairPlan, spec: &RunSpec) -> u32 {
        let key: Vec<u64> = self
            .by
            .iter()
            .map(|(_, _, p)| p.expect("a pair's aggregator").key(plan, spec))
            .collect();
        let next = self.groups.len() as u32;
        let id = *self.ids.entry(key).or_insert(next);
        if id == next {
            let r = row(plan, spec, &RunOutput::default());
            let label = self.by.iter().map(|(_, i, _)| r[*i].clone()).collect();
            self.groups
                .push((label, Group::new(self.exceed.len(), self.outputs.len())));
        }
        id
    }

    pub fn group(&mut self, id: u32) -> &mut Group {
        &mut self.groups[id as usize].1
    }

    /// Fold in one run of group `id`.
    pub fn add(&mut self, id: u32, o: &RunOutput) {
        self.groups[id as usize].1.add(o, &self.exceed);
    }

    /// Fold in finished runs of `plan`, each into its group.
    pub fn add_rows(&mut self, plan: &PairPlan, rows: &[(RunSpec, RunOutput)]) {
        for (s, o) in rows {
            let g = self.group_of(plan, s);
            self.add(g, o);
        }
    }

    pub fn groups(&self) -> usize {
        self.groups.len()
    }

    /// Runs folded in so far, over all groups.
    pub fn runs(&self) -> u64 {
        self.groups.iter().map(|(_, g)| g.runs).sum()
    }

    /// The grouping columns, in `--aggregate` order.
    pub fn by(&self) -> impl Iterator<Item = &str> {
        self.by.iter().map(|(b, _, _)| b.as_str())
    }

    /// Each `--exceed`: its column name and threshold.
    pub fn exceed(&self) -> impl Iterator<Item = (&str, f64)> {
        self.exceed_names
            .iter()
            .zip(&self.exceed)
            .map(|(c, (_, t))| (c.as_str(), *t))
    }

    /// Each group's labels (the values of the grouping columns) and statistics, in the order of
    /// its first run.
    pub fn labelled(&self) -> impl Iterator<Item = (&[String], &Group)> {
        self.groups.iter().map(|(l, g)| (l.as_slice(), g))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `outputs` returns the magnitudes of the cells a row writes under [`OUTPUTS`]' names, so
    /// a summary's columns and a CSV's say the same thing.
    #[test]
    fn outputs_are_the_cells_of_the_summarised_columns() {
        let plan = crate::plan::config::parse_builtin(
            "[building1]\nmass_kg = 1.0e5\nperiod_s = 0.3\ndamping_ratio = 0.05\n[building2]\nmass_kg = 1.0e5\nperiod_s = 0.9\ndamping_ratio = 0.05\n[contact]\nlaw = \"linear\"\nk_n_per_m = 1e9\ngap_m = 0.0\n[[record]]\nsynthetic = { seed = 1, duration_s = 1.0 }\n",
            "one.toml",
        )
        .unwrap();
        let out = RunOutput {
            impacts: 3,
            peak_force: 1.5e6,
            peak_penetration: 2.5e-3,
            peak_u1: -0.04,
            peak_u2: 0.05,
            impact_velocity: 0.7,
            first_impact: Some(1.25),
            contact_time: 0.02,
            dissipated_energy: 125.0,
            substeps: 77,
            ..Default::default()
        };
        let row = crate::plan::columns::row(&plan, &plan.run(0), &out);
        let h = crate::plan::columns::header();
        for (name, value) in OUTPUTS.iter().zip(outputs(&out)) {
            let cell: f64 = row[h.iter().position(|c| c == name).unwrap()]
                .parse()
                .unwrap();
            assert_eq!(cell.abs(), value, "{name}");
        }
    }

    /// A pair's summary may group by any parameter column (every one before `status`, the
    /// intensity measures of the scaled record among them), and by none after it.
    #[test]
    fn every_parameter_column_of_a_pair_is_a_key() {
        let h = header();
        let status = h.iter().position(|c| *c == "status").unwrap();
        for (i, c) in h.iter().enumerate() {
            assert_eq!(Param::from_column(c).is_some(), i < status, "{c}");
        }
    }

    #[test]
    fn bucket_range_constants() {
        assert_eq!((SKETCH_MIN.ln() / GAMMA.ln()).ceil() as i32, KMIN);
        assert_eq!((SKETCH_MAX.ln() / GAMMA.ln()).ceil() as i32, KMAX);
        assert_eq!(bucket(0.0), 0);
        assert_eq!(bucket(f64::NAN), 0);
        assert_eq!(bucket(1e-13), 0);
        assert_eq!(bucket(SKETCH_MIN), 1);
        assert_eq!(bucket(1e30), BUCKETS - 1);
        for x in [1e-11, 3e-5, 1.0, 7.5, 2e6, 9e11] {
            let v = bucket_value(bucket(x));
            assert!((v - x).abs() <= 0.01 * x, "{x}: {v}");
        }
    }

    #[test]
    fn sketch_quantiles_within_one_percent() {
        let mut s = Sketch::default();
        let xs: Vec<f64> = (0..10_000).map(|i| 1.0 + (i as f64).powf(1.7)).collect();
        for &x in &xs {
            s.add(x);
        }
        s.add(0.0);
        let mut sorted = xs.clone();
        sorted.push(0.0);
        sorted.sort_by(f64::total_cmp);
        for q in [0.0, 0.5, 0.9, 0.99, 1.0] {
            let exact = sorted[(q * (sorted.len() - 1) as f64).round() as usize];
            let got = s.quantile(q);
            assert!(
                (got - exact).abs() <= 0.01 * exact,
                "q {q}: {got} vs {exact}"
            );
        }
        assert_eq!(s.max, *sorted.last().unwrap());
    }

    #[test]
    fn moments_and_buckets_merge_like_values() {
        let xs = [0.0, 2.5, 3.0, 1e13, 4e-3];
        let mut a = Sketch::default();
        for x in xs {
            a.add(x);
        }
        let mut b = Sketch::default();
        b.add_moments(xs.len() as u64, xs.iter().sum(), 1e13);
        for x in xs {
            b.add_bucket(bucket(x), 1);
        }
        for q in [0.0, 0.25, 0.5, 0.75, 1.0] {
            assert_eq!(a.quantile(q), b.quantile(q));
        }
        assert_eq!(a.mean(), b.mean());
        assert_eq!(a.quantile(1.0), 1e13, "the top bucket reports the max");
    }
}
