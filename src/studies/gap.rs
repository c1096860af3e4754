//! The separation-gap study (`pound gap`): for every run of a sweep without its contact and gap
//! axes (buildings x records x intensities x samples), the gap each adjacent pair needs, exactly
//! from the time histories ([`crate::physics::solver::separation`]), against what the code rules
//! say from the same peak displacements ([`crate::physics::separation`]); a summary per rule;
//! and the probability of pounding against the gap, with a lognormal fitted by maximum likelihood
//! to the runs' required gaps themselves (each is known exactly; the gaps it is counted at are
//! for display and do not move the fit).
//!
//! Elastic responses are linear in the record's scale, so one response per record and building
//! values serves every intensity. Where storeys yield they are not: every run is its own
//! response, the row scheme's run of the uncoupled buildings under the config's collapse limit
//! ([`uncoupled`]). There a building may collapse: each pair's gaps are then taken up to the
//! earlier collapse of its two buildings, a lower bound on what the pair needs (censored,
//! [`PairGap::censored`]); a run that ends early for another reason has no gaps and is left
//! out of every statistic ([`RunEnd::Failed`]).

use crate::physics::model::{Oscillator, Status};
use crate::physics::row::{Collapse, LevelRule};
use crate::physics::separation::{cqc_rho, Rule};
use crate::physics::shear::ShearBuilding;
use crate::physics::solver::separation::{
    sampled_peak_drift_ratios, separation_with, LevelSeparation, Separation,
};
use crate::plan::columns::row::level_name;
use crate::plan::columns::{at, contact_and_motion, num, RECORD_IMS};
use crate::plan::intensity::TARGET_COLUMNS;
use crate::plan::sample::phi;
use crate::plan::{Motions, Plan};
use crate::studies::plot::{Panel, Series};
use rayon::prelude::*;

/// The share of the collapse limit at which the sweep's row kernel starts watching a building
/// for collapse (`physics::solver::row`'s `COLLAPSE_WATCH`, with which a row that ran on the
/// pair's kernel is run again on the row's).
const COLLAPSE_WATCH: f64 = 0.5;

/// Runs per CSV chunk encoded in parallel.
const CSV_CHUNK: u64 = 4096;

/// The storey height a pair's one-storey buildings are given: they share their one level.
const PAIR_STOREY_M: f64 = 3.0;

/// The plan a study runs over, with what the study reads of its scenes (a pair's or a row's).
#[derive(Clone, Copy)]
struct Scenes<'a>(&'a Plan);

impl Scenes<'_> {
    fn base(&self) -> &crate::plan::ContactPlan {
        self.0.contact()
    }

    pub fn motions(&self) -> Motions {
        self.0.motions()
    }

    /// Buildings in a scene.
    pub fn building_count(&self) -> usize {
        match self.0 {
            Plan::Pair(_) => 2,
            Plan::Row(r) => r.buildings.len(),
        }
    }

    /// The gaps a config gives pair `a` (placeholders where sampled).
    fn gap_axis(&self, a: usize) -> &[f64] {
        match self.0 {
            Plan::Pair(p) => &p.gaps,
            Plan::Row(r) => &r.gaps[a],
        }
    }

    /// Does a sample set pair `a`'s gap (so that its axis holds a placeholder)?
    fn gap_sampled(&self, a: usize) -> bool {
        use crate::plan::row::RowSampled;
        use crate::plan::SampledAxis;
        match self.0 {
            Plan::Pair(p) => p
                .samples
                .as_ref()
                .is_some_and(|s| s.axes.contains(&SampledAxis::Gap)),
            Plan::Row(r) => r.samples.as_ref().is_some_and(|s| {
                s.axes
                    .iter()
                    .any(|x| *x == RowSampled::Gap(a) || *x == RowSampled::SharedGap)
            }),
        }
    }

    /// The parameter columns: the run, the ground motion, the buildings, the sample.
    fn parameter_header(&self) -> Vec<String> {
        let mut h: Vec<String> = vec!["run".into(), "record".into()];
        h.extend(TARGET_COLUMNS.map(String::from));
        h.extend(["scale_factor", "pga_g"].map(String::from));
        match self.0 {
            Plan::Pair(_) => {
                h.extend(["m1_kg", "t1_s", "xi1", "m2_kg", "t2_s", "xi2"].map(String::from))
            }
            Plan::Row(r) => {
                for b in 1..=r.buildings.len() {
                    for c in ["storeys", "mass_kg", "t1_s", "xi"] {
                        h.push(format!("b{b}_{c}"));
                    }
                    if let Some(y) = r.swept_yield(b - 1) {
                        h.push(format!("b{b}_{}", y.value_name()));
                    }
                }
            }
        }
        h.push("sample".into());
        h
    }

    /// Motion `m`'s parameter cells, in [`Scenes::parameter_header`] order.
    fn cells(&self, m: u64) -> Vec<String> {
        let motion_cells = |plan: &crate::plan::ContactPlan, spec: &crate::plan::ContactRun| {
            let mut c = vec![m.to_string()];
            // record, the targets, scale_factor, pga_g
            c.extend(contact_and_motion(plan, spec).drain(at("record")..RECORD_IMS));
            c
        };
        let sample = |s: Option<usize>| s.map(|s| s.to_string()).unwrap_or_default();
        match self.0 {
            Plan::Pair(p) => {
                let r = p.motion_run(m);
                let mut cells = motion_cells(&p.contact, &r.contact);
                cells.extend([r.m1, r.t1, r.xi1, r.m2, r.t2, r.xi2].map(num));
                cells.push(sample(r.sample));
                cells
            }
            Plan::Row(plan) => {
                let r = plan.motion_run(m);
                let mut cells = motion_cells(&plan.contact, &r.contact);
                for (b, a) in plan.buildings.iter().enumerate() {
                    cells.push(a.storeys().to_string());
                    cells.push(r.mass[b].map(num).unwrap_or_default());
                    cells.push(num(r.period[b]));
                    cells.push(num(r.damping[b]));
                    if plan.swept_yield(b).is_some() {
                        cells.push(r.yield_value[b].map(num).unwrap_or_default());
                    }
                }
                cells.push(sample(r.sample));
                cells
            }
        }
    }

    /// Motion `m`'s fundamental periods as given (s), and its record's scale.
    fn periods(&self, m: u64) -> (Vec<f64>, f64) {
        match self.0 {
            Plan::Pair(p) => {
                let r = p.motion_run(m);
                (vec![r.t1, r.t2], r.scale)
            }
            Plan::Row(plan) => {
                let r = plan.motion_run(m);
                (r.period, r.contact.scale)
            }
        }
    }

    /// Motion `m`'s response: its separation at unit scale where the buildings are elastic,
    /// else (`per_run`) at its own scale, with how that run ended ([`uncoupled`]).
    fn response(&self, m: u64, record: usize, per_run: bool) -> (Separation, Option<Outcome>) {
        match self.0 {
            Plan::Row(plan) if per_run => {
                let run = plan.motion_run(m);
                let (sep, outcome) = uncoupled(
                    plan.row(&run).buildings,
                    plan.level_rule,
                    plan.collapse_drift_ratio,
                    &plan.forcing(&run),
                    &plan.scheme(),
                );
                (sep, Some(outcome))
            }
            _ => {
                let spec = &self.base().spec;
                let sep = separation_with(
                    &self.buildings(m),
                    &spec.records[record].forcing(1.0, spec.tail),
                    self.level_rule(),
                );
                (sep, None)
            }
        }
    }

    /// Would the sweep watch some run of this plan's elastic buildings for collapse (a
    /// building's storey drift ratio reaching [`COLLAPSE_WATCH`] of the limit)? Then the
    /// study steps every run on its own as the sweep does, collapse and all ([`uncoupled`]):
    /// a response at unit scale knows no collapse, and a sweep's building that collapses
    /// leaves the scene, so its pair's threshold is the closing before it. The drifts are
    /// those at the record's samples, with the sweep's margin.
    fn nears_collapse(&self, motions: &Motions) -> bool {
        let Plan::Row(plan) = self.0 else {
            return false;
        };
        if self.0.yields() || !plan.collapse_drift_ratio.is_finite() {
            return false;
        }
        let spec = &self.base().spec;
        let inner = motions.inner;
        let per_record = inner * motions.intensities as u64;
        let peaks: Vec<f64> = (0..motions.records as u64 * inner)
            .into_par_iter()
            .map(|u| {
                let (m, record) = ((u / inner) * per_record + u % inner, (u / inner) as usize);
                let forcing = spec.records[record].forcing(1.0, spec.tail);
                sampled_peak_drift_ratios(&self.buildings(m), &forcing)
                    .into_iter()
                    .fold(0.0, f64::max)
            })
            .collect();
        let watch = COLLAPSE_WATCH * plan.collapse_drift_ratio;
        (0..motions.len())
            .into_par_iter()
            .any(|m| peaks[motions.response(m) as usize] * self.periods(m).1 >= watch)
    }

    /// The drift ratio at which a building collapses (infinite: never, and for a pair).
    fn collapse_limit(&self) -> f64 {
        match self.0 {
            Plan::Row(r) => r.collapse_drift_ratio,
            Plan::Pair(_) => f64::INFINITY,
        }
    }

    /// Which contact levels the scene has (a pair's one floor level is the default's).
    fn level_rule(&self) -> LevelRule {
        match self.0 {
            Plan::Row(plan) => plan.level_rule,
            Plan::Pair(_) => LevelRule::default(),
        }
    }

    /// Motion `m`'s buildings, left to right.
    fn buildings(&self, m: u64) -> Vec<ShearBuilding> {
        match self.0 {
            Plan::Pair(p) => {
                let r = p.motion_run(m);
                let single = |m: f64, t: f64, xi: f64| {
                    ShearBuilding::single(&Oscillator::from_period(m, t, xi), xi, PAIR_STOREY_M)
                };
                vec![single(r.m1, r.t1, r.xi1), single(r.m2, r.t2, r.xi2)]
            }
            Plan::Row(plan) => plan.row(&plan.motion_run(m)).buildings,
        }
    }
}

/// How a run of the study ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RunEnd {
    /// Every building stood to the end of the record and its tail.
    Whole,
    /// Some building collapsed (status `collapsed`): each pair's gaps are up to the earlier
    /// collapse of its two buildings ([`PairGap::censored`]).
    Collapsed,
    /// The run ended early for another reason (`non_finite`, `step_limit`), or a floor ran
    /// away to the levels' gap of 1e6 m with no collapse limit to stop it (`runaway`): it has
    /// no gaps and is left out of every statistic.
    Failed(&'static str),
}

impl RunEnd {
    /// The `status` cell: `ok`, `collapsed`, or why the run failed.
    pub fn key(self) -> &'static str {
        match self {
            RunEnd::Whole => "ok",
            RunEnd::Collapsed => "collapsed",
            RunEnd::Failed(why) => why,
        }
    }
}

/// How one run that the study steps on its own (storeys yield) ended.
#[derive(Debug, Clone, PartialEq)]
pub struct Outcome {
    pub end: RunEnd,
    /// The buildings that collapsed, left to right.
    pub collapses: Vec<Collapse>,
    /// Per adjacent pair, the collapse its gaps stop at (None: they are over the whole run).
    pub censors: Vec<Option<Collapse>>,
}

/// The separation `buildings` (left to right; storeys may yield) need under `forcing`, from
/// their uncoupled run ([`crate::physics::solver::separation::uncoupled_separation`]) under
/// the collapse limit `collapse_drift_ratio` (infinite: none), and how that run ended. Without
/// the limit a P-Delta storey past its collapse drift has a negative stiffness and its frame
/// runs away until a floor travels the levels' far gap (an impact: "runaway") or overflows
/// (`non_finite`). With it, each building that collapses leaves the scene and the others go on
/// (physics.md section 12): a pair's closing and peaks stop at the earlier collapse of its two
/// buildings.
pub fn uncoupled(
    buildings: Vec<ShearBuilding>,
    rule: LevelRule,
    collapse_drift_ratio: f64,
    forcing: &crate::physics::model::Forcing,
    scheme: &crate::physics::solver::row::RowScheme,
) -> (Separation, Outcome) {
    let pairs = buildings.len() - 1;
    let (sep, out) = crate::physics::solver::separation::uncoupled_separation(
        buildings,
        rule,
        collapse_drift_ratio,
        forcing,
        scheme,
    );
    let failed = match out.status {
        Status::Ok | Status::Collapsed if out.impacts > 0 => Some("runaway"),
        Status::Ok | Status::Collapsed => None,
        other => Some(other.key()),
    };
    if let Some(why) = failed {
        let sep = Separation {
            levels: Vec::new(),
            ..sep
        };
        let outcome = Outcome {
            end: RunEnd::Failed(why),
            collapses: Vec::new(),
            censors: vec![None; pairs],
        };
        return (sep, outcome);
    }
    let own: Vec<Option<Collapse>> = out.buildings.iter().map(|b| b.collapse).collect();
    let earlier = |a: Option<Collapse>, b: Option<Collapse>| match (a, b) {
        (Some(x), Some(y)) => Some(if y.time < x.time { y } else { x }),
        (x, y) => x.or(y),
    };
    let collapses: Vec<Collapse> = own.iter().flatten().copied().collect();
    let censors = (0..pairs).map(|a| earlier(own[a], own[a + 1])).collect();
    let end = if collapses.is_empty() {
        RunEnd::Whole
    } else {
        RunEnd::Collapsed
    };
    (
        sep,
        Outcome {
            end,
            collapses,
            censors,
        },
    )
}

/// What one adjacent pair needs in one run: the exact gap at its governing level (the level
/// that needs the most) and, per rule, the largest over its levels of the rule's gap.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PairGap {
    /// Index into the run's levels.
    pub level: usize,
    /// m
    pub required: f64,
    /// s
    pub time: Option<f64>,
    /// m, at the governing level.
    pub peak_left: f64,
    pub peak_right: f64,
    /// m, in the order of [`Rule::ALL`].
    pub rules: [f64; 3],
    /// Right building's fundamental period over the left one's.
    pub period_ratio: f64,
    /// CQC correlation of the two fundamental modes.
    pub rho: f64,
    /// The collapse of one of the two buildings that ended the time the gaps are taken over
    /// (the earlier one; where the solver ends the whole run at its first collapse, that
    /// one): `required` is then a lower bound on what the pair needs, and the rules' gaps are
    /// from the peaks before it. None: over the whole run.
    pub censored: Option<Collapse>,
}

impl PairGap {
    /// A rule's gap over the exact one (None where the floors never close).
    pub fn ratio(&self, rule: usize) -> Option<f64> {
        (self.required > 0.0).then(|| self.rules[rule] / self.required)
    }
}

/// The least conservative code rule whose gap covers `required`, the exact gap of a level
/// whose points' peaks are `peak_left`, `peak_right` (DDC asks for the least, ABS for the
/// most): `ddc`, `srss` or `abs`; `none` where none does; empty where the floors never close.
pub fn covering_rule(required: f64, peak_left: f64, peak_right: f64, rho: f64) -> &'static str {
    if required <= 0.0 {
        return "";
    }
    [Rule::Ddc, Rule::Srss, Rule::Abs]
        .into_iter()
        .find(|r| r.gap(peak_left, peak_right, rho) >= required)
        .map_or("none", Rule::key)
}

/// One run of the study.
#[derive(Debug, Clone, PartialEq)]
pub struct GapRun {
    pub motion: u64,
    pub separation: Separation,
    /// Per adjacent pair (None where the two share no floor level, or the run failed).
    pub pairs: Vec<Option<PairGap>>,
    pub end: RunEnd,
}

/// A study, run.
pub struct GapStudy<'a> {
    scenes: Scenes<'a>,
    motions: Motions,
    /// One per record and inner motion, at unit scale; or, where storeys yield, one per run.
    responses: Vec<Separation>,
    /// Where storeys yield, how each run ended (empty otherwise: every run is whole).
    outcomes: Vec<Outcome>,
    /// Every run is stepped on its own ([`GapStudy::per_run`]).
    per_run: bool,
    /// ... because a run of elastic buildings nears the collapse limit.
    nears_collapse: bool,
    /// Per run, what each adjacent pair needs.
    pair_gaps: Vec<Vec<Option<PairGap>>>,
    /// The contact levels' column prefixes (the same in every run).
    level_names: Vec<String>,
    /// Per level, its pair.
    level_pairs: Vec<usize>,
}

/// Why a study stopped by its flag ([`GapStudy::run_until`]) gave no result.
pub const STOPPED: &str = "the gap study was stopped";

impl<'a> GapStudy<'a> {
    /// Why `plan` has no separation gap to give, if it has none: one building alone, or a pair
    /// of neighbours whose floors never meet.
    pub fn refusal(plan: &Plan) -> Option<String> {
        if let Plan::Row(r) = plan {
            if r.buildings.len() == 1 {
                return Some("one building stands alone: a separation gap is between neighbours; give a row of two or more [[building]] entries".into());
            }
        }
        let apart = plan.pairs_without_levels();
        (!apart.is_empty()).then(|| {
            format!(
                "{}: no required gap can be computed for such a pair",
                apart.join("; ")
            )
        })
    }

    /// Compute every response (in parallel on the current rayon pool). Err: the first run
    /// whose response could not be computed, and why (only where storeys yield).
    pub fn run(plan: &'a Plan) -> Result<GapStudy<'a>, String> {
        Self::run_until(plan, &std::sync::atomic::AtomicBool::new(false))
    }

    /// [`GapStudy::run`] until `stop` is raised: each response and each run looks at it first,
    /// so a stop waits for one response per thread; a stopped study is an error.
    pub fn run_until(
        plan: &'a Plan,
        stop: &std::sync::atomic::AtomicBool,
    ) -> Result<GapStudy<'a>, String> {
        let stopped = || stop.load(std::sync::atomic::Ordering::Relaxed);
        let scenes = Scenes(plan);
        let motions = scenes.motions();
        let nears_collapse = scenes.nears_collapse(&motions);
        let per_run = plan.yields() || nears_collapse;
        let inner = motions.inner;
        let per_record = inner * motions.intensities as u64;
        let count = if per_run {
            motions.len()
        } else {
            motions.records as u64 * inner
        };
        let (responses, outcomes): (Vec<Separation>, Vec<Option<Outcome>>) = (0..count)
            .into_par_iter()
            .map(|u| {
                if stopped() {
                    return (Separation::default(), None);
                }
                // Elastic: the response's first intensity, at unit scale.
                let (m, record) = if per_run {
                    (u, motions.record_and_intensity(u).0)
                } else {
                    ((u / inner) * per_record + u % inner, (u / inner) as usize)
                };
                scenes.response(m, record, per_run)
            })
            .unzip();
        if stopped() {
            return Err(STOPPED.into());
        }
        let outcomes: Vec<Outcome> = outcomes.into_iter().flatten().collect();
        // A failed run has no levels: the names are any other's (every run has the same).
        let first = responses.iter().find(|s| !s.levels.is_empty());
        let level_names = first.map_or(Vec::new(), |s| {
            s.levels
                .iter()
                .map(|l| level_name(l.pair, &l.sides))
                .collect()
        });
        let level_pairs = first.map_or(Vec::new(), |s| s.levels.iter().map(|l| l.pair).collect());
        let mut study = GapStudy {
            scenes,
            motions,
            responses,
            outcomes,
            per_run,
            nears_collapse,
            level_names,
            level_pairs,
            pair_gaps: Vec::new(),
        };
        let failed = study.failed();
        if !study.is_empty() && failed.len() as u64 == study.len() {
            // Statistics over zero runs are not zeros.
            return Err(format!(
                "every run ended early, so there is no gap to give: {}",
                study.run_list(&failed, 5, |o| o.end.key().to_string())
            ));
        }
        study.pair_gaps = (0..study.len())
            .into_par_iter()
            .map(|m| {
                if stopped() {
                    return Vec::new();
                }
                let outcome = study.outcome(m);
                if outcome.is_some_and(|o| matches!(o.end, RunEnd::Failed(_))) {
                    return vec![None; study.pairs()];
                }
                // One decode of the motion serves its scale and its periods.
                let (periods, scale) = study.scenes.periods(m);
                let censors = outcome.map(|o| &o.censors[..]);
                study.pairs_of(&study.scaled(m, scale), &periods, censors)
            })
            .collect();
        if stopped() {
            return Err(STOPPED.into());
        }
        Ok(study)
    }

    /// How run `m` ended, where runs are stepped one by one (storeys yield).
    pub fn outcome(&self, m: u64) -> Option<&Outcome> {
        self.outcomes.get(m as usize)
    }

    /// The runs where some building collapsed, in run order.
    pub fn collapsed(&self) -> Vec<u64> {
        self.runs_where(|o| o.end == RunEnd::Collapsed)
    }

    /// The runs that ended early for another reason (left out of every statistic).
    pub fn failed(&self) -> Vec<u64> {
        self.runs_where(|o| matches!(o.end, RunEnd::Failed(_)))
    }

    fn runs_where(&self, f: impl Fn(&Outcome) -> bool) -> Vec<u64> {
        (0..self.outcomes.len() as u64)
            .filter(|&m| f(&self.outcomes[m as usize]))
            .collect()
    }

    /// Run `m` for a message: `run 43 (kobe_1995_jma, Sa 1.25 g)`.
    pub fn run_label(&self, m: u64) -> String {
        let (record, intensity) = self.motions.record_and_intensity(m);
        let name = &self.scenes.base().spec.records[record].name;
        let sample = match self.scenes.0 {
            Plan::Pair(p) => p.motion_run(m).sample,
            Plan::Row(r) => r.motion_run(m).sample,
        };
        let sample = sample.map(|s| format!(", sample {s}")).unwrap_or_default();
        format!(
            "run {m} ({name}, {}{sample})",
            self.intensity_label(intensity)
        )
    }

    /// The first `most` of `runs` labelled, each with `what` of its outcome, and how many more.
    pub fn run_list(&self, runs: &[u64], most: usize, what: impl Fn(&Outcome) -> String) -> String {
        let mut parts: Vec<String> = runs
            .iter()
            .take(most)
            .map(|&m| {
                let o = &self.outcomes[m as usize];
                format!("{}: {}", self.run_label(m), what(o))
            })
            .collect();
        if runs.len() > most {
            parts.push(format!("and {} more", runs.len() - most));
        }
        parts.join("; ")
    }

    /// Does the CSV say per pair which collapse its gaps stop at (storeys yield, with a
    /// collapse limit)?
    fn censoring(&self) -> bool {
        self.per_run() && self.scenes.collapse_limit().is_finite()
    }

    /// Run `m`'s separation: its response, scaled to its intensity (per run: a spectral target
    /// at a building's period scales each building's record by its own factor).
    fn separation(&self, m: u64) -> Separation {
        self.scaled(m, self.scenes.periods(m).1)
    }

    /// Run `m`'s response, scaled by `scale` (where storeys yield, its own at its scale).
    fn scaled(&self, m: u64, scale: f64) -> Separation {
        if self.per_run() {
            self.responses[m as usize].clone()
        } else {
            self.responses[self.motions.response(m) as usize].scaled(scale)
        }
    }

    /// Does every run have its own response (storeys yield: not linear in the scale; or a run
    /// of elastic buildings nears the collapse limit, [`GapStudy::nears_collapse`])?
    pub fn per_run(&self) -> bool {
        self.per_run
    }

    /// Are the runs stepped on their own because a run of elastic buildings nears the
    /// collapse limit (where the sweep watches it for collapse)?
    pub fn nears_collapse(&self) -> bool {
        self.nears_collapse
    }

    /// Substeps taken where storeys yield, over all responses.
    pub fn substeps(&self) -> u64 {
        self.responses.iter().map(|s| s.substeps).sum()
    }

    /// Runs in the study.
    pub fn len(&self) -> u64 {
        self.motions.len()
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Responses computed (runs differing only in intensity share one).
    pub fn responses(&self) -> usize {
        self.responses.len()
    }

    /// Record steps stepped again in parts, over all responses.
    pub fn refined_steps(&self) -> u64 {
        self.responses.iter().map(|s| s.refined_steps).sum()
    }

    /// Adjacent pairs.
    pub fn pairs(&self) -> usize {
        self.scenes.building_count() - 1
    }

    /// A pair's name in column names and tables: empty for a scene of two buildings, else
    /// `_1_2` for buildings 1 and 2.
    fn suffix(&self, a: usize) -> String {
        if self.scenes.building_count() == 2 {
            String::new()
        } else {
            format!("_{}_{}", a + 1, a + 2)
        }
    }

    /// Buildings `a + 1` and `a + 2`, for tables.
    pub fn pair_name(&self, a: usize) -> String {
        format!("{}-{}", a + 1, a + 2)
    }

    /// Are there per-level columns (some pair shares more than one level)?
    fn per_level(&self) -> bool {
        (0..self.pairs()).any(|a| self.level_pairs.iter().filter(|&&p| p == a).count() > 1)
    }

    /// Run `m`.
    pub fn get(&self, m: u64) -> GapRun {
        GapRun {
            motion: m,
            separation: self.separation(m),
            pairs: self.pair_gaps[m as usize].clone(),
            end: self.outcome(m).map_or(RunEnd::Whole, |o| o.end),
        }
    }

    /// What each adjacent pair needs in a run of separation `sep` whose buildings have these
    /// fundamental periods, each pair's gaps stopping at `censors`' collapse where given.
    fn pairs_of(
        &self,
        sep: &Separation,
        periods: &[f64],
        censors: Option<&[Option<Collapse>]>,
    ) -> Vec<Option<PairGap>> {
        (0..self.pairs())
            .map(|a| {
                let (wa, xa) = sep.fundamental[a];
                let (wb, xb) = sep.fundamental[a + 1];
                let rho = cqc_rho(wa, xa, wb, xb);
                let rules_at =
                    |l: &LevelSeparation| Rule::ALL.map(|r| r.gap(l.peak_left, l.peak_right, rho));
                let mut best: Option<PairGap> = None;
                for (k, l) in sep.levels.iter().enumerate().filter(|(_, l)| l.pair == a) {
                    let rules = rules_at(l);
                    match &mut best {
                        None => {
                            best = Some(PairGap {
                                level: k,
                                required: l.required,
                                time: l.time,
                                peak_left: l.peak_left,
                                peak_right: l.peak_right,
                                rules,
                                period_ratio: periods[a + 1] / periods[a],
                                rho,
                                censored: censors.and_then(|c| c[a]),
                            })
                        }
                        Some(b) => {
                            for (x, y) in b.rules.iter_mut().zip(rules) {
                                *x = x.max(y);
                            }
                            if l.required > b.required {
                                (b.level, b.required, b.time) = (k, l.required, l.time);
                                (b.peak_left, b.peak_right) = (l.peak_left, l.peak_right);
                            }
                        }
                    }
                }
                best
            })
            .collect()
    }

    /// Every column, in file order.
    pub fn header(&self) -> Vec<String> {
        let mut h = self.scenes.parameter_header();
        if self.per_run() {
            h.push("status".into());
        }
        for a in 0..self.pairs() {
            let s = self.suffix(a);
            h.push(format!("period_ratio{s}"));
            h.push(format!("rho{s}"));
            h.push(format!("required_gap{s}_m"));
            h.push(format!("required_at{s}_s"));
            if self.censoring() {
                h.push(format!("censored_by{s}"));
                h.push(format!("censored_at{s}_s"));
            }
            h.push(format!("peak_left{s}_m"));
            h.push(format!("peak_right{s}_m"));
            for r in Rule::ALL {
                h.push(format!("{}_gap{s}_m", r.key()));
            }
            for r in Rule::ALL {
                h.push(format!("{}_ratio{s}", r.key()));
            }
            if self.per_level() {
                h.push(format!("governing_level{s}"));
            }
        }
        if self.per_level() {
            for l in &self.level_names {
                for c in ["required_m", "peak_left_m", "peak_right_m"] {
                    h.push(format!("{l}_{c}"));
                }
                for r in Rule::ALL {
                    h.push(format!("{l}_{}_m", r.key()));
                }
                h.push(format!("{l}_rule"));
            }
        }
        h.push("error_bound_m".into());
        h
    }

    /// The cells of a run, in [`GapStudy::header`] order.
    pub fn cells(&self, run: &GapRun) -> Vec<String> {
        let mut c = self.scenes.cells(run.motion);
        let opt = |x: Option<f64>| x.map(num).unwrap_or_default();
        if self.per_run() {
            c.push(run.end.key().into());
        }
        let censoring = self.censoring();
        for p in &run.pairs {
            match p {
                Some(p) => {
                    c.extend([p.period_ratio, p.rho, p.required].map(num));
                    c.push(opt(p.time));
                    if censoring {
                        let by = p.censored.map(|x| x.building.to_string());
                        c.push(by.unwrap_or_default());
                        c.push(opt(p.censored.map(|x| x.time)));
                    }
                    c.extend([p.peak_left, p.peak_right].map(num));
                    c.extend(p.rules.map(num));
                    c.extend((0..3).map(|r| opt(p.ratio(r))));
                    if self.per_level() {
                        c.push(self.level_names[p.level].clone());
                    }
                }
                None => {
                    let n = 12 + usize::from(self.per_level()) + 2 * usize::from(censoring);
                    c.extend(std::iter::repeat_n(String::new(), n));
                }
            }
        }
        if self.per_level() {
            if run.separation.levels.is_empty() {
                // A failed run: no level has a value.
                let n = self.level_names.len() * (4 + Rule::ALL.len());
                c.extend(std::iter::repeat_n(String::new(), n));
            }
            for l in &run.separation.levels {
                let rho = run.pairs[l.pair].expect("a level's pair shares it").rho;
                c.extend([l.required, l.peak_left, l.peak_right].map(num));
                c.extend(Rule::ALL.map(|r| num(r.gap(l.peak_left, l.peak_right, rho))));
                c.push(covering_rule(l.required, l.peak_left, l.peak_right, rho).into());
            }
        }
        c.push(opt(run.separation.error_bound));
        c
    }

    /// The whole study as CSV (rows computed in parallel, in run order).
    pub fn csv(&self) -> Vec<u8> {
        use crate::io::csv::{encode_rows, header_line};
        let header = self.header();
        let mut out = header_line(&header.iter().map(String::as_str).collect::<Vec<_>>());
        let chunks: Vec<Vec<u8>> = (0..self.len().div_ceil(CSV_CHUNK))
            .into_par_iter()
            .map(|c| {
                let end = ((c + 1) * CSV_CHUNK).min(self.len());
                let rows: Vec<Vec<String>> = (c * CSV_CHUNK..end)
                    .map(|m| self.cells(&self.get(m)))
                    .collect();
                encode_rows(&rows)
            })
            .collect();
        for c in chunks {
            out.extend(c);
        }
        out
    }

    /// Per pair and rule: the ratio of the rule's gap to the exact one over the runs whose
    /// floors close, and how often the rule is unconservative (asks for less than the exact
    /// gap), over all runs whose gaps are over the whole run: a run censored by a collapse
    /// (its exact gap a lower bound, its rules' from the peaks before the collapse) is
    /// counted apart, and a failed one left out.
    pub fn summary(&self) -> Vec<RuleSummary> {
        let mut out = Vec::new();
        for a in 0..self.pairs() {
            let all = self.pair_gaps.iter().filter_map(|r| r[a].as_ref());
            let censored = all.clone().filter(|p| p.censored.is_some()).count();
            let pairs: Vec<&PairGap> = all.filter(|p| p.censored.is_none()).collect();
            for (k, rule) in Rule::ALL.into_iter().enumerate() {
                let mut ratios: Vec<f64> = pairs.iter().filter_map(|p| p.ratio(k)).collect();
                ratios.sort_by(f64::total_cmp);
                let unconservative = pairs.iter().filter(|p| p.rules[k] < p.required).count();
                out.push(RuleSummary {
                    pair: a,
                    rule,
                    runs: pairs.len(),
                    censored,
                    closing: ratios.len(),
                    median: quantile(&ratios, 0.5),
                    p10: quantile(&ratios, 0.1),
                    p90: quantile(&ratios, 0.9),
                    unconservative,
                });
            }
        }
        out
    }

    /// The largest required gap of pair `a` over the study's runs (or lower bound, where a
    /// collapse censored it), m.
    pub fn largest_required(&self, a: usize) -> f64 {
        self.pair_gaps
            .iter()
            .filter_map(|r| r[a].map(|p| p.required))
            .fold(0.0, f64::max)
    }

    /// The gaps the probability of pounding of pair `a` is counted at: `given`, else the
    /// config's gap axis where it has two values or more, else 21 round values from 0 to the
    /// largest required gap.
    pub fn gaps_for(&self, a: usize, given: Option<&[f64]>) -> Vec<f64> {
        if let Some(g) = given {
            return g.to_vec();
        }
        let axis = self.scenes.gap_axis(a);
        if axis.len() >= 2 && !self.scenes.gap_sampled(a) {
            return axis.to_vec();
        }
        let top = self.largest_required(a);
        let step = round_step(top / 20.0);
        (0..=((top / step).ceil() as usize).max(1))
            .map(|i| i as f64 * step)
            .collect()
    }

    /// Per intensity, the share of runs of pair `a` that pound at each of `gaps` (their
    /// required gap exceeds it), and the lognormal fitted to the runs' required gaps. A run
    /// censored by a collapse pounds at the gaps below its lower bound; above it, whether it
    /// would is unknown, so it is counted there in neither the runs nor those that pound, and
    /// it enters the fit as a lower bound ([`GapFit::censored`]).
    pub fn pounding(&self, a: usize, gaps: &[f64]) -> Vec<PoundingCurve> {
        // (intensity, required gap or its lower bound, censored)
        let required: Vec<(usize, f64, bool)> = (0..self.len())
            .filter_map(|m| {
                let (_, intensity) = self.motions.record_and_intensity(m);
                self.pair_gaps[m as usize][a].map(|p| (intensity, p.required, p.censored.is_some()))
            })
            .collect();
        (0..self.motions.intensities)
            .map(|i| {
                let of = |censored: bool| -> Vec<f64> {
                    required
                        .iter()
                        .filter(|(k, _, c)| *k == i && *c == censored)
                        .map(|(_, g, _)| *g)
                        .collect()
                };
                let (mine, bounds) = (of(false), of(true));
                let points: Vec<(f64, u64, u64)> = gaps
                    .iter()
                    .map(|&g| {
                        let known = bounds.iter().filter(|&&b| b > g).count() as u64;
                        let pound = mine.iter().filter(|&&r| r > g).count() as u64 + known;
                        (g, mine.len() as u64 + known, pound)
                    })
                    .collect();
                let closing = |v: &[f64]| v.iter().filter(|&&r| r > 0.0).count() as u64;
                PoundingCurve {
                    pair: a,
                    intensity: i,
                    points,
                    runs: mine.len() as u64 + closing(&bounds),
                    closing: closing(&mine) + closing(&bounds),
                    censored: bounds.len() as u64,
                    fit: if bounds.is_empty() {
                        GapFit::of(&mine)
                    } else {
                        GapFit::censored(&mine, &bounds)
                    },
                }
            })
            .collect()
    }

    /// The intensity `i` as a label (`pga 0.35 g` or `x 1.5`).
    pub fn intensity_label(&self, i: usize) -> String {
        match self.scenes.base().spec.intensities[i] {
            crate::plan::Intensity::PgaG(g) => format!("PGA {g} g"),
            crate::plan::Intensity::Scale(s) => format!("scale {s}"),
            crate::plan::Intensity::Spectral { g, im } if im.average => format!("Sa_avg {g} g"),
            crate::plan::Intensity::Spectral { g, .. } => format!("Sa {g} g"),
        }
    }

    /// Per pair: the required gap against the period ratio (one series per record), the rules'
    /// ratios against it, and the probability of pounding against the gap.
    pub fn panels(&self, curves: &[Vec<PoundingCurve>]) -> Vec<Panel> {
        let records = &self.scenes.base().spec.records;
        // (record, pair gaps) per run.
        let runs: Vec<(usize, &Vec<Option<PairGap>>)> = (0..self.len())
            .map(|m| {
                (
                    self.motions.record_and_intensity(m).0,
                    &self.pair_gaps[m as usize],
                )
            })
            .collect();
        let mut panels = Vec::new();
        for a in 0..self.pairs() {
            let name = if self.pairs() == 1 {
                String::new()
            } else {
                format!(", buildings {}", self.pair_name(a))
            };
            // Against the period ratio; where the pair has one (no period swept or sampled),
            // against the record instead, so each record's runs stand in a column of their own.
            let ratios = runs.iter().filter_map(|x| x.1[a].map(|p| p.period_ratio));
            let (lo, hi) = ratios.fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), x| {
                (l.min(x), h.max(x))
            });
            let one_ratio = lo.is_finite() && hi <= lo * (1.0 + 1e-9);
            let x_of = |record: usize, p: &PairGap| {
                if one_ratio {
                    (record + 1) as f64
                } else {
                    p.period_ratio
                }
            };
            let ratio_label = if one_ratio {
                format!(
                    "record, 1 to {} as in the legend (T{} / T{} = {lo:.3})",
                    records.len(),
                    a + 2,
                    a + 1
                )
            } else {
                format!("T{} / T{} (fundamental periods)", a + 2, a + 1)
            };
            let mut by_record = Vec::new();
            for (r, rec) in records.iter().enumerate() {
                let points: Vec<(f64, f64)> = runs
                    .iter()
                    .filter(|x| x.0 == r)
                    .filter_map(|x| x.1[a].filter(|p| p.censored.is_none()))
                    .map(|p| (x_of(r, &p), p.required * 1e3))
                    .collect();
                if !points.is_empty() {
                    by_record.push(Series {
                        name: rec.name.clone(),
                        points,
                        scatter: true,
                        style: None,
                    });
                }
            }
            let bounds: Vec<(f64, f64)> = runs
                .iter()
                .filter_map(|x| x.1[a].filter(|p| p.censored.is_some()).map(|p| (x.0, p)))
                .map(|(r, p)| (x_of(r, &p), p.required * 1e3))
                .collect();
            if !bounds.is_empty() {
                by_record.push(Series {
                    name: "a building collapsed: lower bound (any record)".into(),
                    points: bounds,
                    scatter: true,
                    style: None,
                });
            }
            panels.push(Panel {
                title: format!("Required gap (time history){name}"),
                x_label: ratio_label.clone(),
                y_label: "required gap (mm)".into(),
                log_x: !one_ratio,
                series: by_record,
                ..Panel::default()
            });
            let mut rules: Vec<Series> = Rule::ALL
                .iter()
                .enumerate()
                .map(|(k, r)| Series {
                    name: r.key().to_uppercase(),
                    points: runs
                        .iter()
                        .filter_map(|x| {
                            // With one ratio, the rules stand side by side in each record's
                            // column.
                            let dodge = if one_ratio {
                                0.2 * (k as f64 - 1.0)
                            } else {
                                0.0
                            };
                            // A censored run's ratio is to a lower bound: not a rule's record.
                            let p = x.1[a].filter(|p| p.censored.is_none());
                            p.and_then(|p| p.ratio(k).map(|q| (x_of(x.0, &p) + dodge, q)))
                        })
                        .collect(),
                    scatter: true,
                    style: None,
                })
                .collect();
            let xs = rules.iter().flat_map(|r| r.points.iter().map(|p| p.0));
            let (lo, hi) = xs.fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), x| {
                (l.min(x), h.max(x))
            });
            if lo.is_finite() {
                rules.push(Series {
                    name: "time history (1)".into(),
                    points: vec![(lo, 1.0), (hi, 1.0)],
                    scatter: false,
                    style: None,
                });
            }
            panels.push(Panel {
                title: format!("Code rule / time history{name}"),
                x_label: ratio_label,
                y_label: "rule gap / required gap".into(),
                log_x: !one_ratio,
                series: rules,
                ..Panel::default()
            });
            let mut series = Vec::new();
            // Each intensity's points and its fitted curve share one style; a failed fit is
            // named on its points.
            for (k, c) in curves.get(a).into_iter().flatten().enumerate() {
                let label = self.intensity_label(c.intensity);
                let unfitted = if c.fit.is_ok() {
                    ""
                } else {
                    " (no lognormal fit)"
                };
                series.push(Series {
                    name: format!("{label}: share of runs{unfitted}"),
                    points: c
                        .points
                        .iter()
                        .filter(|p| p.1 > 0)
                        .map(|&(g, n, k)| (g * 1e3, k as f64 / n as f64))
                        .collect(),
                    scatter: true,
                    style: Some(k),
                });
                if let Ok(f) = &c.fit {
                    let top = c.points.iter().map(|p| p.0).fold(0.0, f64::max);
                    series.push(Series {
                        name: format!(
                            "{label}: lognormal, median {:.2} mm, beta {:.2}",
                            f.median * 1e3,
                            f.beta
                        ),
                        points: (1..=100)
                            .map(|i| {
                                let g = top * i as f64 / 100.0;
                                (g * 1e3, f.pounding(g))
                            })
                            .collect(),
                        scatter: false,
                        style: Some(k),
                    });
                }
            }
            panels.push(Panel {
                title: format!("Probability of pounding{name}"),
                x_label: "gap (mm)".into(),
                y_label: "P(required gap > gap)".into(),
                series,
                y_span: Some((0.0, 1.0)),
                ..Panel::default()
            });
        }
        panels
    }
}

/// One rule's record against the time histories, for one pair.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RuleSummary {
    pub pair: usize,
    pub rule: Rule,
    /// Runs where the pair shares a level, whose gaps are over the whole run.
    pub runs: usize,
    /// Runs censored by a collapse (left out of the statistics here).
    pub censored: usize,
    /// Of those, runs whose floors close at all (the ratio is defined).
    pub closing: usize,
    /// Quantiles of rule / exact over the closing runs (NaN where there are none).
    pub median: f64,
    pub p10: f64,
    pub p90: f64,
    /// Runs where the rule asks for less than the exact gap.
    pub unconservative: usize,
}

/// The probability of pounding of one pair at one intensity.
#[derive(Debug, Clone, PartialEq)]
pub struct PoundingCurve {
    pub pair: usize,
    pub intensity: usize,
    /// `(gap, runs, runs that pound)`, at the gaps counted (for display).
    pub points: Vec<(f64, u64, u64)>,
    /// Runs of the pair at this intensity, and of those, runs whose floors close (a run
    /// censored by a collapse counts in both where its lower bound is above 0; at 0 it says
    /// nothing and counts in neither).
    pub runs: u64,
    pub closing: u64,
    /// Runs censored by a collapse at this intensity (their required gaps lower bounds).
    pub censored: u64,
    /// The lognormal fitted to the runs' required gaps.
    pub fit: Result<GapFit, NoGapFit>,
}

impl PoundingCurve {
    /// The gap at which the fitted probability of pounding is `p`.
    pub fn gap_for(&self, p: f64) -> Option<f64> {
        self.fit.as_ref().ok()?.gap_for(p)
    }
}

/// The probability of pounding against the gap, fitted to the runs' required gaps: a share
/// `closing / runs` of the runs whose floors close at all, and among those a lognormal
/// required gap, `P(pounding | gap g) = closing / runs * (1 - Phi(ln(g / median) / beta))`.
///
/// Every run's required gap is known exactly, so the lognormal is fitted to those values by
/// maximum likelihood (`ln median` their mean logarithm, `beta` the root-mean-square spread
/// of the logarithms about it), not to counts at the gaps a grid happens to hold: counts at a
/// coarse grid move the median by as much as the grid's spacing.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GapFit {
    /// m: the median of the closing runs' required gaps.
    pub median: f64,
    pub beta: f64,
    /// Standard errors of `ln median` (`beta / sqrt(n)`) and of `beta` (`beta / sqrt(2 n)`).
    pub se_ln_median: f64,
    pub se_beta: f64,
    /// Runs counted, and of those, runs whose floors close (required gap > 0).
    pub runs: u64,
    pub closing: u64,
    /// Of the closing runs, those whose required gap is a lower bound ([`GapFit::censored`]).
    pub censored: u64,
}

/// Why no lognormal could be fitted to the required gaps.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum NoGapFit {
    #[error("no run at this intensity")]
    NoRuns,
    #[error("the floors close in no run: no gap is needed")]
    NoneClose,
    #[error("the floors close in only one run: a lognormal needs two")]
    OneCloses,
    #[error("every run whose floors close needs the same gap: the dispersion is 0")]
    AllEqual,
    #[error("fewer than two exact gaps (the other runs collapsed): their lower bounds alone fix no lognormal")]
    TooFewExact,
}

impl GapFit {
    /// The maximum-likelihood lognormal of the positive values of `required` (m), with the
    /// share of runs whose floors close.
    pub fn of(required: &[f64]) -> Result<GapFit, NoGapFit> {
        let logs: Vec<f64> = required
            .iter()
            .filter(|&&r| r > 0.0)
            .map(|r| r.ln())
            .collect();
        let n = logs.len();
        match (required.len(), n) {
            (0, _) => return Err(NoGapFit::NoRuns),
            (_, 0) => return Err(NoGapFit::NoneClose),
            (_, 1) => return Err(NoGapFit::OneCloses),
            _ => {}
        }
        let mean = logs.iter().sum::<f64>() / n as f64;
        let beta = (logs.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / n as f64).sqrt();
        // Equal values give a spread of rounding noise, not a dispersion.
        if beta.is_nan() || beta <= 1e-12 {
            return Err(NoGapFit::AllEqual);
        }
        Ok(GapFit {
            median: mean.exp(),
            beta,
            se_ln_median: beta / (n as f64).sqrt(),
            se_beta: beta / (2.0 * n as f64).sqrt(),
            runs: required.len() as u64,
            closing: n as u64,
            censored: 0,
        })
    }

    /// As [`GapFit::of`], with `bounds` the required gaps of runs a collapse censored: each is
    /// a lower bound (the floors had closed that far when a building collapsed; how far they
    /// would have closed had it stood is unknown). A bound above 0 is a run whose floors close
    /// and enters the likelihood with the probability of exceeding it,
    /// `1 - Phi((ln b - ln median) / beta)` (right-censored maximum likelihood, as survival
    /// analysis fits lifetimes still running); a bound of 0 says nothing and is left out.
    /// At least two exact required gaps above 0, not all equal, are needed: the bounds alone
    /// fix no lognormal (its likelihood grows without limit as the median does).
    ///
    /// The maximum is found by Newton's method in `(ln median / beta, 1 / beta)`, where the
    /// log-likelihood is concave (Olsen 1978, for the Tobit model), so it is the only one;
    /// the standard errors are from the observed information there.
    pub fn censored(required: &[f64], bounds: &[f64]) -> Result<GapFit, NoGapFit> {
        let c: Vec<f64> = bounds
            .iter()
            .filter(|&&b| b > 0.0)
            .map(|b| b.ln())
            .collect();
        if c.is_empty() {
            return GapFit::of(required);
        }
        let x: Vec<f64> = required
            .iter()
            .filter(|&&r| r > 0.0)
            .map(|r| r.ln())
            .collect();
        if x.len() < 2 {
            return Err(NoGapFit::TooFewExact);
        }
        let n = x.len() as f64;
        let mean = x.iter().sum::<f64>() / n;
        let spread = (x.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / n).sqrt();
        if spread.is_nan() || spread <= 1e-12 {
            return Err(NoGapFit::AllEqual);
        }
        // (g, h) = (mu / sigma, 1 / sigma): an exact value's log-density is
        // ln h - (h x - g)^2 / 2, a bound's ln(1 - Phi(h c - g)).
        let loglik = |g: f64, h: f64| -> f64 {
            let exact: f64 = x.iter().map(|&v| h.ln() - 0.5 * (h * v - g).powi(2)).sum();
            exact + c.iter().map(|&v| ln_upper_tail(h * v - g)).sum::<f64>()
        };
        // The gradient and the Hessian (negative definite everywhere).
        let derivatives = |g: f64, h: f64| -> ([f64; 2], [f64; 3]) {
            let (mut dg, mut dh) = (0.0, 0.0);
            let (mut hgg, mut hgh, mut hhh) = (0.0, 0.0, 0.0);
            for &v in &x {
                let r = h * v - g;
                dg += r;
                dh += 1.0 / h - r * v;
                hgg -= 1.0;
                hgh += v;
                hhh -= 1.0 / (h * h) + v * v;
            }
            for &v in &c {
                let z = h * v - g;
                let l = mills(z);
                let d = l * (l - z);
                dg += l;
                dh -= l * v;
                hgg -= d;
                hgh += d * v;
                hhh -= d * v * v;
            }
            ([dg, dh], [hgg, hgh, hhh])
        };
        let (mut g, mut h) = (mean / spread, 1.0 / spread);
        for _ in 0..200 {
            let ([dg, dh], [a, b, d]) = derivatives(g, h);
            let det = a * d - b * b;
            // Newton's step -H^-1 grad.
            let (mut sg, mut sh) = (-(d * dg - b * dh) / det, -(a * dh - b * dg) / det);
            let l0 = loglik(g, h);
            let mut halvings = 0;
            while !(h + sh > 0.0 && loglik(g + sg, h + sh) >= l0 - 1e-12 * l0.abs())
                && halvings < 60
            {
                sg *= 0.5;
                sh *= 0.5;
                halvings += 1;
            }
            if halvings == 60 {
                break;
            }
            g += sg;
            h += sh;
            if sg.abs() <= 1e-12 * (1.0 + g.abs()) && sh.abs() <= 1e-12 * h {
                break;
            }
        }
        let (_, [a, b, d]) = derivatives(g, h);
        // Covariance of (g, h): the inverse of the observed information -H; then the delta
        // method for ln median = g / h and beta = 1 / h.
        let det = a * d - b * b;
        let (vgg, vgh, vhh) = (-d / det, b / det, -a / det);
        let (ug, uh) = (1.0 / h, -g / (h * h));
        let var_ln_median = ug * ug * vgg + 2.0 * ug * uh * vgh + uh * uh * vhh;
        let beta = 1.0 / h;
        if !(beta.is_finite() && beta > 1e-12 && g.is_finite()) {
            return Err(NoGapFit::AllEqual);
        }
        let positive = |v: &[f64]| v.iter().filter(|&&r| r > 0.0).count() as u64;
        let known = required.len() as u64 + c.len() as u64;
        Ok(GapFit {
            median: (g / h).exp(),
            beta,
            se_ln_median: var_ln_median.max(0.0).sqrt(),
            se_beta: vhh.max(0.0).sqrt() / (h * h),
            runs: known,
            closing: positive(required) + c.len() as u64,
            censored: c.len() as u64,
        })
    }

    /// The share of runs whose floors close.
    pub fn closing_share(&self) -> f64 {
        self.closing as f64 / self.runs as f64
    }

    /// The fitted probability of pounding at a gap of `g` m.
    pub fn pounding(&self, g: f64) -> f64 {
        if g <= 0.0 {
            return self.closing_share();
        }
        self.closing_share() * (1.0 - phi((g / self.median).ln() / self.beta))
    }

    /// The gap at which the fitted probability of pounding is `p` (0 where the runs whose
    /// floors close are fewer than that share: no gap is needed for it).
    pub fn gap_for(&self, p: f64) -> Option<f64> {
        if !(p > 0.0 && p < 1.0) {
            return None;
        }
        let q = p / self.closing_share();
        if q >= 1.0 {
            return Some(0.0);
        }
        Some(self.median * (self.beta * crate::plan::sample::phi_inv(1.0 - q)).exp())
    }
}

/// `ln(1 - Phi(z))`, also where `1 - Phi(z)` underflows (its asymptotic series there).
fn ln_upper_tail(z: f64) -> f64 {
    if z < 30.0 {
        phi(-z).ln()
    } else {
        -0.5 * z * z - (z * (2.0 * std::f64::consts::PI).sqrt()).ln() + (-1.0 / (z * z)).ln_1p()
    }
}

/// The inverse Mills ratio `phi(z) / (1 - Phi(z))`: the mean of a standard normal above `z`.
fn mills(z: f64) -> f64 {
    if z < 30.0 {
        let density = (-0.5 * z * z).exp() / (2.0 * std::f64::consts::PI).sqrt();
        density / phi(-z)
    } else {
        // z + 1/z - 2/z^3 + ...: within 1e-7 of it from z = 30.
        z + 1.0 / z - 2.0 / (z * z * z)
    }
}

pub use crate::studies::fragility::quantile;

/// A round step (1, 2 or 5 times a power of ten) of at least `x`.
fn round_step(x: f64) -> f64 {
    if !(x > 0.0 && x.is_finite()) {
        return 1e-3;
    }
    let p = 10f64.powf(x.log10().floor());
    [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .map(|k| k * p)
        .find(|&s| s >= x * (1.0 - 1e-12))
        .unwrap_or(10.0 * p)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Peaks 3 and 4 cm: DDC asks for sqrt(25 - 24 rho) cm, SRSS 5, ABS 7.
    #[test]
    fn the_covering_rule_is_the_least_conservative_that_covers() {
        let rho = 0.5; // DDC: sqrt(13) = 3.606 cm
        for (required, want) in [
            (0.0, ""),
            (0.03, "ddc"),
            (0.036, "ddc"),
            (0.0361, "srss"),
            (0.05, "srss"),
            (0.06, "abs"),
            (0.0701, "none"),
        ] {
            assert_eq!(covering_rule(required, 0.03, 0.04, rho), want, "{required}");
        }
    }

    /// In the probability-of-pounding panel each intensity's points and its fitted curve share
    /// one style, and intensities differ; a failed fit is named on its points.
    #[test]
    fn pounding_points_and_their_curve_share_a_style() {
        let plan = crate::plan::config::parse_builtin(
            "[building1]\nmass_kg = 1.0e5\nperiod_s = [0.2, 0.3, 0.5, 0.8]\ndamping_ratio = 0.05\n[building2]\nmass_kg = 1.0e5\nperiod_s = [0.4, 0.6, 1.0, 1.5]\ndamping_ratio = 0.05\n[contact]\nlaw = \"linear\"\nk_n_per_m = 1e9\ngap_m = 0.0\n[[record]]\nsynthetic = { seed = 3, duration_s = 4.0 }\n[intensity]\npga_g = [0.2, 0.4]\n",
            "styles.toml",
        )
        .unwrap();
        let plan = crate::plan::Plan::Pair(plan);
        let study = GapStudy::run(&plan).unwrap();
        let gaps = study.gaps_for(0, None);
        let mut curves = vec![study.pounding(0, &gaps)];
        assert_eq!(curves[0].len(), 2);
        let panels = study.panels(&curves);
        let pounding = panels.last().unwrap();
        let styles: Vec<(Option<usize>, bool)> = pounding
            .series
            .iter()
            .map(|s| (s.style, s.scatter))
            .collect();
        assert_eq!(
            styles,
            [
                (Some(0), true),
                (Some(0), false),
                (Some(1), true),
                (Some(1), false)
            ],
            "{:?}",
            pounding.series.iter().map(|s| &s.name).collect::<Vec<_>>()
        );
        curves[0][1].fit = Err(NoGapFit::NoneClose);
        let panels = study.panels(&curves);
        let last = panels.last().unwrap();
        assert_eq!(last.series.len(), 3);
        assert!(last.series[2].name.ends_with("(no lognormal fit)"));
    }

    /// The fit of the required gaps: the lognormal's maximum-likelihood parameters, the runs
    /// whose floors never close as a share apart, and `gap_for` the inverse of `pounding`.
    #[test]
    fn the_gap_fit_is_the_required_gaps_lognormal() {
        let f = GapFit::of(&[0.0, 0.01, 0.04, 0.0]).unwrap();
        assert_eq!((f.runs, f.closing), (4, 2));
        assert!((f.median - 0.02).abs() < 1e-15);
        assert!((f.beta - 2f64.ln()).abs() < 1e-15);
        assert_eq!(f.pounding(0.0), 0.5);
        assert!((f.pounding(0.02) - 0.25).abs() < 1e-7);
        for p in [0.01, 0.1, 0.4] {
            let g = f.gap_for(p).unwrap();
            assert!((f.pounding(g) - p).abs() < 1e-7, "{p}: {g}");
        }
        // No gap is needed for a probability the closing runs cannot reach.
        assert_eq!(f.gap_for(0.6), Some(0.0));
        assert_eq!(GapFit::of(&[]), Err(NoGapFit::NoRuns));
        assert_eq!(GapFit::of(&[0.0, 0.0]), Err(NoGapFit::NoneClose));
        assert_eq!(GapFit::of(&[0.0, 0.03]), Err(NoGapFit::OneCloses));
        assert_eq!(GapFit::of(&[0.03, 0.03]), Err(NoGapFit::AllEqual));
    }

    /// The right-censored fit: with no bound above 0 it is the exact fit; bounds far below
    /// every exact gap carry no information (the same median, beta and standard errors, from
    /// the observed information); bounds above them raise the median.
    #[test]
    fn a_censored_fit_without_information_is_the_exact_one() {
        let exact = [0.0, 0.011, 0.023, 0.017, 0.031, 0.014];
        assert_eq!(GapFit::censored(&exact, &[]), GapFit::of(&exact));
        assert_eq!(GapFit::censored(&exact, &[0.0, 0.0]), GapFit::of(&exact));
        let of = GapFit::of(&exact).unwrap();
        let far = GapFit::censored(&exact, &[1e-9, 2e-9]).unwrap();
        assert_eq!((far.runs, far.closing, far.censored), (8, 7, 2));
        for (a, b) in [
            (far.median, of.median),
            (far.beta, of.beta),
            (far.se_ln_median, of.se_ln_median),
            (far.se_beta, of.se_beta),
        ] {
            assert!((a - b).abs() < 1e-9 * b, "{a} against {b}");
        }
        let high = GapFit::censored(&exact, &[0.03, 0.04]).unwrap();
        assert!(high.median > of.median * 1.2, "{high:?}");
        assert_eq!(
            GapFit::censored(&[0.0, 0.02], &[0.03]),
            Err(NoGapFit::TooFewExact)
        );
        assert_eq!(
            GapFit::censored(&[0.02, 0.02], &[0.03]),
            Err(NoGapFit::AllEqual)
        );
    }

    /// The right-censored fit is the maximum of its likelihood, written here in `(ln median,
    /// beta)` and searched on a grid: no grid point beats it, and the best is within a grid
    /// step of it.
    #[test]
    fn the_censored_fit_maximises_its_likelihood() {
        let exact = [0.012, 0.02, 0.027, 0.035, 0.016, 0.05, 0.022];
        let bounds = [0.03, 0.045, 0.06, 0.018];
        let f = GapFit::censored(&exact, &bounds).unwrap();
        assert_eq!((f.runs, f.closing, f.censored), (11, 11, 4));
        let loglik = |mu: f64, beta: f64| -> f64 {
            let density: f64 = exact
                .iter()
                .map(|g| {
                    let z = (g.ln() - mu) / beta;
                    -beta.ln() - 0.5 * z * z
                })
                .sum();
            let tails: f64 = bounds
                .iter()
                .map(|b| (1.0 - phi((b.ln() - mu) / beta)).ln())
                .sum();
            density + tails
        };
        let (mu, beta) = (f.median.ln(), f.beta);
        let top = loglik(mu, beta);
        let (step_mu, step_beta) = (0.002, 0.001);
        let mut best = (f64::NEG_INFINITY, 0.0, 0.0);
        for i in -200..=200 {
            for j in -200..=200 {
                let (m, b) = (mu + i as f64 * step_mu, beta + j as f64 * step_beta);
                let l = loglik(m, b);
                assert!(l <= top + 1e-6, "({m}, {b}): {l} above {top}");
                if l > best.0 {
                    best = (l, m, b);
                }
            }
        }
        assert!((best.1 - mu).abs() <= step_mu && (best.2 - beta).abs() <= step_beta);
        // The censored runs needed more than their bounds: the median is above the exact
        // gaps' alone.
        assert!(f.median > GapFit::of(&exact).unwrap().median);
    }

    #[test]
    fn quantiles_and_round_steps() {
        let v = [1.0, 2.0, 3.0, 4.0, 5.0];
        assert_eq!(quantile(&v, 0.5), 3.0);
        assert_eq!(quantile(&v, 0.1), 1.4);
        assert_eq!(quantile(&v, 1.0), 5.0);
        assert!(quantile(&[], 0.5).is_nan());
        assert_eq!(round_step(0.0031), 0.005);
        assert_eq!(round_step(0.002), 0.002);
        assert_eq!(round_step(0.011), 0.02);
    }
}
