//! The scenes a study runs over (a pair's or a row's, from the plan) and each run's response:
//! at unit scale per record where the buildings stay elastic, else the row scheme's run of the
//! uncoupled buildings, which may collapse.

use crate::physics::model::{Oscillator, Status};
use crate::physics::row::{Collapse, LevelRule};
use crate::physics::shear::ShearBuilding;
use crate::physics::solver::separation::{sampled_peak_drift_ratios, separation_with, Separation};
use crate::plan::columns::{at, contact_and_motion, num, RECORD_IMS};
use crate::plan::intensity::TARGET_COLUMNS;
use crate::plan::{Motions, Plan};
use rayon::prelude::*;

/// The share of the collapse limit at which the sweep's row kernel starts watching a building
/// for collapse (`physics::solver::row`'s `COLLAPSE_WATCH`, with which a row that ran on the
/// pair's kernel is run again on the row's).
const COLLAPSE_WATCH: f64 = 0.5;

/// The storey height a pair's one-storey buildings are given: they share their one level.
const PAIR_STOREY_M: f64 = 3.0;

/// The plan a study runs over, with what the study reads of its scenes (a pair's or a row's).
#[derive(Clone, Copy)]
pub(super) struct Scenes<'a>(pub(super) &'a Plan);

impl Scenes<'_> {
    pub(super) fn base(&self) -> &crate::plan::ContactPlan {
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
    pub(super) fn gap_axis(&self, a: usize) -> &[f64] {
        match self.0 {
            Plan::Pair(p) => &p.gaps,
            Plan::Row(r) => &r.gaps[a],
        }
    }

    /// Does a sample set pair `a`'s gap (so that its axis holds a placeholder)?
    pub(super) fn gap_sampled(&self, a: usize) -> bool {
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
    pub(super) fn parameter_header(&self) -> Vec<String> {
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
                    for name in r.swept_names(b - 1) {
                        h.push(format!("b{b}_{name}"));
                    }
                }
            }
        }
        h.push("sample".into());
        h
    }

    /// Motion `m`'s parameter cells, in [`Scenes::parameter_header`] order.
    pub(super) fn cells(&self, m: u64) -> Vec<String> {
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
                    for v in plan.swept_values(b, &r) {
                        cells.push(v.map(num).unwrap_or_default());
                    }
                }
                cells.push(sample(r.sample));
                cells
            }
        }
    }

    /// Motion `m`'s fundamental periods as given (s), and its record's scale.
    pub(super) fn periods(&self, m: u64) -> (Vec<f64>, f64) {
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
    pub(super) fn response(
        &self,
        m: u64,
        record: usize,
        per_run: bool,
    ) -> (Separation, Option<Outcome>) {
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
    pub(super) fn nears_collapse(&self, motions: &Motions) -> bool {
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
    pub(super) fn collapse_limit(&self) -> f64 {
        match self.0 {
            Plan::Row(r) => r.collapse_drift_ratio,
            Plan::Pair(_) => f64::INFINITY,
        }
    }

    /// Which contact levels the scene has (a pair's one floor level is the default's).
    pub(super) fn level_rule(&self) -> LevelRule {
        match self.0 {
            Plan::Row(plan) => plan.level_rule,
            Plan::Pair(_) => LevelRule::default(),
        }
    }

    /// Motion `m`'s buildings, left to right.
    pub(super) fn buildings(&self, m: u64) -> Vec<ShearBuilding> {
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
