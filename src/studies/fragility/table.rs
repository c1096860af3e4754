//! A fragility as a CSV table and a plot panel.

use super::demand::{collapse_building, FragilitySpec};
use super::grouping::Grouped;
use crate::io::csv::quote_cell as quote;
use crate::io::table::{caption, label};
use crate::studies::plot::{Panel, Series};
use crate::studies::stats::{Band, Fit, Level, NoFit};

/// The counts as CSV, a row per threshold and level: the state's name (with `states`), the
/// threshold, the intensity, the runs decided, those exceeding, the runs among them that
/// collapsed (counted as exceeding), their fraction, the runs undecided (no value, not decided by
/// the bound: [`Demand::Unknown`]) and the fraction's bounds with those counted as none exceeding
/// and as all exceeding. The collapse fragility ([`FragilitySpec::is_collapse`]) has a row per
/// level: the intensity, the runs, those that collapsed and their fraction.
pub fn csv(spec: &FragilitySpec, states: Option<&[String]>, grouped: &Grouped) -> String {
    let ratio = |k: u64, n: u64| {
        if n > 0 {
            (k as f64 / n as f64).to_string()
        } else {
            String::new()
        }
    };
    let mut s = csv_header(spec, states.is_some())
        .iter()
        .map(|h| quote(h))
        .collect::<Vec<_>>()
        .join(",");
    s.push('\n');
    if spec.is_collapse() {
        for l in grouped.pooled(&[1]).first().into_iter().flatten() {
            s.push_str(&format!(
                "{},{},{},{}\n",
                l.im,
                l.n,
                l.exceed,
                ratio(l.exceed, l.n)
            ));
        }
        return s;
    }
    for (t, &limit) in spec.thresholds.iter().enumerate() {
        let undecided = grouped.undecided_at(t);
        for (l, &im) in grouped.ims.iter().enumerate() {
            let (n, k) = grouped
                .counts
                .iter()
                .fold((0, 0), |(n, k), c| (n + c[t][l].0, k + c[t][l].1));
            let u = undecided[l];
            if n + u == 0 {
                continue;
            }
            if let Some(names) = states {
                s.push_str(&quote(&names[t]));
                s.push(',');
            }
            s.push_str(&format!(
                "{},{im},{n},{k},{},{},{u},{},{}\n",
                crate::show(limit),
                grouped.collapsed.get(l).copied().unwrap_or(0),
                ratio(k, n),
                ratio(k, n + u),
                ratio(k + u, n + u)
            ));
        }
    }
    s
}

/// The fitted curves as CSV, a row per threshold (or damage state; the collapse fragility's one
/// curve): the demand and intensity columns, the state's name (with `states`) and the threshold
/// (none for a collapse fragility), the lognormal's median and beta with their standard errors
/// (`se_ln_median` of `ln median`), the log-likelihood, the deviance against each level's own
/// share with its degrees of freedom and p (empty with no degree of freedom, and where every
/// level is `0/n` or `n/n`: no power), the runs counted and the levels they are at, and `fit`:
/// `ok` or why no curve was fitted (its cells then empty). With `bootstrap`, the 90 % band of the
/// median and beta (5 and 95 % of the replicates fitted) and the replicates fitted and not.
pub fn fits_csv(
    spec: &FragilitySpec,
    states: Option<&[String]>,
    levels: &[Vec<Level>],
    fits: &[Result<Fit, NoFit>],
    bands: Option<&[Option<Band>]>,
) -> String {
    let mut head: Vec<&str> = vec!["edp", "im"];
    if states.is_some() {
        head.push("state");
    }
    if !spec.is_collapse() {
        head.push("threshold");
    }
    head.extend([
        "median",
        "beta",
        "se_ln_median",
        "se_beta",
        "log_likelihood",
        "deviance",
        "dof",
        "p_fit",
        "runs",
        "levels",
        "fit",
    ]);
    if bands.is_some() {
        head.extend([
            "median_p5",
            "median_p95",
            "beta_p5",
            "beta_p95",
            "replicates_fitted",
            "replicates_unfitted",
        ]);
    }
    let mut s = head.join(",");
    s.push('\n');
    for (i, f) in fits.iter().enumerate() {
        let mut row: Vec<String> = vec![quote(&spec.edp), quote(&spec.im)];
        if let Some(names) = states {
            row.push(quote(&names[i]));
        }
        if !spec.is_collapse() {
            row.push(crate::show(spec.thresholds[i]));
        }
        let counted = levels.get(i).map_or(&[][..], |l| &l[..]);
        let runs: u64 = counted.iter().map(|l| l.n).sum();
        let at = counted.iter().filter(|l| l.n > 0).count();
        match f {
            Ok(f) => {
                row.extend(
                    [f.median, f.beta, f.se_ln_median, f.se_beta]
                        .into_iter()
                        .chain([f.log_likelihood, f.deviance])
                        .map(|x| x.to_string()),
                );
                row.push(f.dof.to_string());
                row.push(f.p_fit.map_or(String::new(), |p| p.to_string()));
                row.extend([runs.to_string(), at.to_string()]);
                row.push(if f.no_power { "ok (no power)" } else { "ok" }.into());
            }
            Err(e) => {
                row.extend(std::iter::repeat_n(String::new(), 8));
                row.extend([runs.to_string(), at.to_string()]);
                let why = match collapse_building(&spec.edp) {
                    _ if !spec.is_collapse() => e.to_string(),
                    k => e.collapse_of(k),
                };
                row.push(quote(&format!("no fit: {why}")));
            }
        }
        if let Some(bands) = bands {
            match &bands[i] {
                Some(b) => {
                    row.extend(
                        [b.median[0], b.median[1], b.beta[0], b.beta[1]].map(|x| x.to_string()),
                    );
                    row.extend([b.fitted.to_string(), b.unfitted.to_string()]);
                }
                None => row.extend(std::iter::repeat_n(String::new(), 6)),
            }
        }
        s.push_str(&row.join(","));
        s.push('\n');
    }
    s
}

/// The names of [`csv`]'s columns (`states`: with damage states' names).
pub fn csv_header(spec: &FragilitySpec, states: bool) -> Vec<String> {
    let im = spec.im.clone();
    fn rest<'a>(names: &'a [&'a str]) -> impl Iterator<Item = String> + 'a {
        names.iter().map(|n| n.to_string())
    }
    if spec.is_collapse() {
        return std::iter::once(im)
            .chain(rest(&["runs", "collapsed", "fraction"]))
            .collect();
    }
    let mut h: Vec<String> = Vec::new();
    if states {
        h.push("state".into());
    }
    h.push("threshold".into());
    h.push(im);
    h.extend(rest(&[
        "runs",
        "exceed",
        "collapsed",
        "fraction",
        "undecided",
        "fraction_if_none_exceed",
        "fraction_if_all_exceed",
    ]));
    h
}

/// A threshold's legend entry: `> 1 MN` for `peak_force_n` above 1e6 ([`crate::io::table::quantity`]).
pub fn threshold_name(edp: &str, t: f64) -> String {
    format!("> {}", crate::io::table::quantity(edp, t))
}

/// What a collapse fragility of `edp` gives: `P(collapse)` (the run's), `P(building K
/// collapses)`.
pub fn collapse_probability(edp: &str) -> String {
    match collapse_building(edp) {
        Some(k) => format!("P(building {k} collapses)"),
        None => "P(collapse)".into(),
    }
}

/// One panel: the observed fractions (points) and the fitted curves (lines), per threshold (the
/// collapse fragility's one curve is named `collapse`).
pub fn panel(spec: &FragilitySpec, levels: &[Vec<Level>], fits: &[Result<Fit, NoFit>]) -> Panel {
    let mut series = Vec::new();
    let (lo, hi) = levels
        .iter()
        .flatten()
        .fold((f64::INFINITY, 0.0f64), |(a, b), l| {
            (a.min(l.im), b.max(l.im))
        });
    for (k, ((t, lv), f)) in spec.thresholds.iter().zip(levels).zip(fits).enumerate() {
        // The EDP is in the title; a threshold's points and its curve share one style; a failed
        // fit says why.
        let name = if spec.is_collapse() {
            "collapse".to_string()
        } else {
            threshold_name(&spec.edp, *t)
        };
        series.push(Series {
            name: match f {
                Ok(_) => format!("{name}: observed"),
                Err(e) if spec.is_collapse() => {
                    format!("{name}: observed (no fit: {})", e.short_collapse())
                }
                Err(e) => format!("{name}: observed (no fit: {})", e.short()),
            },
            points: lv
                .iter()
                .map(|l| (l.im, l.exceed as f64 / l.n as f64))
                .collect(),
            scatter: true,
            style: Some(k),
        });
        if let Ok(f) = f {
            let n = 100;
            series.push(Series {
                name: format!("{name}: fit, median {:.3}, beta {:.3}", f.median, f.beta),
                points: (0..=n)
                    .map(|i| {
                        let im = lo + (hi - lo) * i as f64 / n as f64;
                        (im, if im > 0.0 { f.probability(im) } else { 0.0 })
                    })
                    .collect(),
                scatter: false,
                style: Some(k),
            });
        }
    }
    let (edp, im) = (
        crate::io::table::name(&spec.edp),
        crate::io::table::name(&spec.im),
    );
    let what = if spec.is_collapse() {
        collapse_probability(&spec.edp)
    } else {
        format!("P({edp} > threshold)")
    };
    Panel {
        title: match caption(&spec.filters) {
            c if c.is_empty() => format!("{what} against {im}"),
            c => format!("{what} against {im}; {c}"),
        },
        x_label: label(&spec.im),
        y_label: if let Some(k) = collapse_building(&spec.edp) {
            format!("probability of building {k}'s collapse")
        } else if spec.is_collapse() {
            "probability of collapse".into()
        } else {
            "probability of exceedance".into()
        },
        log_x: false,
        log_y: false,
        series,
        y_span: Some((0.0, 1.0)),
        ..Default::default()
    }
}
