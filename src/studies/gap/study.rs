//! A study, run: every run's response and what each adjacent pair needs in it.

use super::scenes::{Outcome, RunEnd, Scenes};
use crate::physics::row::Collapse;
use crate::physics::separation::{cqc_rho, Rule};
use crate::physics::solver::separation::{LevelSeparation, Separation};
use crate::plan::columns::row::level_name;
use crate::plan::{Motions, Plan};
use rayon::prelude::*;

/// Why a config gives no gap study: its text is not a config, or it has no gap to give.
#[derive(Debug, thiserror::Error)]
pub enum GapPlanError {
    #[error(transparent)]
    Config(#[from] crate::config::ConfigError),
    #[error("{0}")]
    Refused(String),
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
    pub(super) scenes: Scenes<'a>,
    pub(super) motions: Motions,
    /// One per record and inner motion, at unit scale; or, where storeys yield, one per run.
    pub(super) responses: Vec<Separation>,
    /// Where storeys yield, how each run ended (empty otherwise: every run is whole).
    pub(super) outcomes: Vec<Outcome>,
    /// Every run is stepped on its own ([`GapStudy::per_run`]).
    pub(super) per_run: bool,
    /// ... because a run of elastic buildings nears the collapse limit.
    pub(super) nears_collapse: bool,
    /// Per run, what each adjacent pair needs.
    pub(super) pair_gaps: Vec<Vec<Option<PairGap>>>,
    /// The contact levels' column prefixes (the same in every run).
    pub(super) level_names: Vec<String>,
    /// Per level, its pair.
    pub(super) level_pairs: Vec<usize>,
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

    /// The plan a gap study runs, from a config's text at `path`, as `pound gap` and
    /// `pounding.gap` both take it: read without its contact and gap axes
    /// ([`crate::plan::config::load_text_for_gaps`]), then refused where it has no gap to give
    /// ([`GapStudy::refusal`], the message led by the path).
    pub fn plan_of(text: &str, path: &std::path::Path) -> Result<Plan, GapPlanError> {
        let plan = crate::plan::config::load_text_for_gaps(text, path)?;
        match Self::refusal(&plan) {
            Some(why) => Err(GapPlanError::Refused(format!("{}: {why}", path.display()))),
            None => Ok(plan),
        }
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
    pub(super) fn censoring(&self) -> bool {
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
    pub(super) fn suffix(&self, a: usize) -> String {
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
    pub(super) fn per_level(&self) -> bool {
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
}
