//! The probability of pounding against the gap, per pair and intensity, and its panels.

use super::fit::{GapFit, NoGapFit};
use super::study::{GapStudy, PairGap};
use crate::physics::separation::Rule;
use crate::studies::plot::{Panel, Series};

impl GapStudy<'_> {
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
    use crate::engine::quantile::{quantile, Interpolation::Linear};

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

    #[test]
    fn quantiles_and_round_steps() {
        let v = [1.0, 2.0, 3.0, 4.0, 5.0];
        assert_eq!(quantile(&v, 0.5, Linear), 3.0);
        assert_eq!(quantile(&v, 0.1, Linear), 1.4);
        assert_eq!(quantile(&v, 1.0, Linear), 5.0);
        assert!(quantile(&[], 0.5, Linear).is_nan());
        assert_eq!(round_step(0.0031), 0.005);
        assert_eq!(round_step(0.002), 0.002);
        assert_eq!(round_step(0.011), 0.02);
    }
}
