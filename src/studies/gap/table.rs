//! The study's table: one row per run (its parameters, each pair's required gap and the rules'
//! gaps), and each rule's record against the time histories.

use super::study::{covering_rule, GapRun, GapStudy, PairGap};
use crate::engine::quantile::{quantile, Interpolation::Linear};
use crate::physics::separation::Rule;
use crate::plan::columns::num;
use rayon::prelude::*;

impl GapStudy<'_> {
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
                    median: quantile(&ratios, 0.5, Linear),
                    p10: quantile(&ratios, 0.1, Linear),
                    p90: quantile(&ratios, 0.9, Linear),
                    unconservative,
                });
            }
        }
        out
    }
}

/// Runs per CSV chunk encoded in parallel.
const CSV_CHUNK: u64 = 4096;

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
