//! Fragility curves from a results CSV (`pound fragility`): at each intensity level, the share of
//! runs whose demand exceeds a threshold, and the lognormal fragility
//! `P(EDP > threshold | IM) = Phi(ln(IM / median) / beta)` fitted to the counts by maximum
//! likelihood (binomial at each level; Baker 2015), solved as a probit regression on `ln IM` by
//! Fisher scoring.
//!
//! Collapse (physics.md sections 10 and 12): a collapsed demand is taken as infinite, so it
//! exceeds every threshold and damage state (counted, not left out). Whose collapse it is follows
//! the demand ([`CollapseOf`]): a building's column (`bK_...`) collapses with building K alone
//! (its `bK_collapsed`), a column of the run (`peak_force_n`, a contact level's) with any building
//! (status `collapsed`). `--edp collapsed` ([`COLLAPSED`]) fits the run's collapse fragility
//! `P(collapse | IM)` itself, `--edp bK_collapsed` building K's: each run is 1 if it (building K)
//! collapsed, else 0 (FEMA P-695; Baker 2015). Runs of any other status but `ok` failed, and are
//! left out.

mod demand;
mod grouping;
mod table;

pub use crate::studies::stats::{
    bootstrap, chi_square_sf, crossings, fit, Band, Fit, Level, NoFit, NO_POWER,
};
pub use demand::*;
pub use grouping::{levels, Grouped, Undecided};
mod series;

pub use table::{collapse_probability, csv, csv_header, fits_csv, panel, threshold_name};

use crate::io::table::{Filter, Table, TableError};
use crate::studies::damage_states::DamageStates;
use crate::studies::plot::Series;
use crate::studies::report::{tell, StudyReport, Telling};

// The command's study: `pound fragility` from a table already read to the text it tells and the
// CSV it writes, so that the command line and the Python package hold none of it.

/// Bootstrap replicates at most (each refits every threshold).
pub const MAX_BOOTSTRAP: usize = 100_000;

/// Bootstrap replicates at least: a 5 % and a 95 % percentile need some replicates beyond each
/// (5 at 100), or the "90 %" band is the smallest and largest of a few draws.
pub const MIN_BOOTSTRAP: usize = 100;

/// What a fragility study counts and fits: every setting of `pound fragility` but where it
/// writes and how it draws. [`Default`] holds the command's defaults (`--edp peak_force_n`, no
/// threshold, no bootstrap).
#[derive(Debug, Clone, PartialEq)]
pub struct FragilityOptions {
    /// Intensity measure column; None: the table's [`default_im`].
    pub im: Option<String>,
    /// Demand column, or [`COLLAPSED`] for the collapse fragility.
    pub edp: String,
    /// Exceedance thresholds (EDP > threshold), as given (one of these and `damage_states`,
    /// except with [`COLLAPSED`], which takes neither).
    pub thresholds: Vec<f64>,
    /// A built-in set's name or the path of a TOML file of states ([`DamageStates::get`]).
    pub damage_states: Option<String>,
    /// Bootstrap replicates (0: no bands; else [`MIN_BOOTSTRAP`] to [`MAX_BOOTSTRAP`]).
    pub bootstrap: usize,
    /// Seed of the bootstrap draws (None: 1); only with a bootstrap.
    pub seed: Option<u64>,
    /// The column whose groups the bootstrap draws (None: `record`); only with a bootstrap.
    pub by: Option<String>,
    /// `--where` filters as typed (`COLUMN=VALUE`, `!=`, `<`, `<=`, `>`, `>=`), all kept.
    pub filters: Vec<String>,
    /// A column whose every value gets its own curves, in one figure and one table
    /// ([`series::study_series`]); None: one study of every row kept.
    pub series: Option<String>,
}

impl Default for FragilityOptions {
    fn default() -> FragilityOptions {
        FragilityOptions {
            im: None,
            edp: "peak_force_n".into(),
            thresholds: Vec::new(),
            damage_states: None,
            bootstrap: 0,
            seed: None,
            by: None,
            filters: Vec::new(),
            series: None,
        }
    }
}

/// Why a fragility study gives no result; its text is the message `pound fragility` prints.
#[derive(Debug, thiserror::Error)]
pub enum FragilityError {
    #[error(transparent)]
    Table(#[from] TableError),
    /// A setting, or a table, that gives no result.
    #[error("{0}")]
    Refused(String),
    /// Refused after the study had told what it read (a bootstrap over fewer than two groups):
    /// `said` and `notices`, told first ([`FragilityError::tell`]), then the message.
    #[error("{message}")]
    RefusedAfter {
        message: String,
        said: String,
        notices: Vec<String>,
        notices_at: Vec<usize>,
    },
}

impl FragilityError {
    /// Tell what the study had told before it refused ([`tell`]; nothing for a refusal before).
    pub fn tell<E>(
        &self,
        say: impl FnMut(&str) -> Result<(), E>,
        note: impl FnMut(&str),
    ) -> Result<(), E> {
        match self {
            FragilityError::RefusedAfter {
                said,
                notices,
                notices_at,
                ..
            } => tell(said, notices, notices_at, say, note),
            _ => Ok(()),
        }
    }
}

/// The settings resolved before any table is read.
struct Settled {
    collapse: bool,
    states: Option<DamageStates>,
    thresholds: Vec<f64>,
    names: Vec<String>,
    by: String,
    seed: u64,
}

impl FragilityOptions {
    /// The checks of the settings alone, in `pound fragility`'s order, before any table is read
    /// (a damage-state file is read here): [`study`] makes them again first.
    pub fn check(&self) -> Result<(), FragilityError> {
        self.settle().map(|_| ())
    }

    fn settle(&self) -> Result<Settled, FragilityError> {
        let refuse = |m: String| Err(FragilityError::Refused(m));
        if self.bootstrap > MAX_BOOTSTRAP {
            return refuse(format!(
                "--bootstrap {}: expected at most {MAX_BOOTSTRAP} replicates",
                self.bootstrap
            ));
        }
        if self.bootstrap > 0 && self.bootstrap < MIN_BOOTSTRAP {
            return refuse(format!(
                "--bootstrap {}: expected 0 (no bands) or at least {MIN_BOOTSTRAP} replicates: the 90 % band is the 5 and 95 % percentiles of the replicates, which fewer cannot place",
                self.bootstrap
            ));
        }
        // Flags of the bootstrap mean nothing without it.
        for (flag, given) in [
            ("--bootstrap-groups", self.by.is_some()),
            ("--seed", self.seed.is_some()),
        ] {
            if given && self.bootstrap == 0 {
                return refuse(format!("{flag} applies to the bootstrap bands: give --bootstrap N (N >= {MIN_BOOTSTRAP}) with it, or leave {flag} out"));
            }
        }
        let collapse = is_collapse_edp(&self.edp);
        if collapse {
            let (what, which) = match collapse_building(&self.edp) {
                None => (
                    "a run collapsed (status `collapsed`)".to_string(),
                    "P(collapse | IM)".to_string(),
                ),
                Some(k) => (
                    format!("building {k} collapsed in a run ({})", self.edp),
                    format!("P(building {k} collapses | IM)"),
                ),
            };
            for (flag, given) in [
                ("--threshold", !self.thresholds.is_empty()),
                ("--damage-states", self.damage_states.is_some()),
            ] {
                if given {
                    return refuse(format!("{flag} makes no sense with --edp {}: {what} or it did not, and {which} is fitted to that; leave {flag} out, or give a demand column to --edp", self.edp));
                }
            }
        } else if self.thresholds.is_empty() && self.damage_states.is_none() {
            return refuse(format!("give --threshold T1,T2 (EDP > threshold) or --damage-states SET, or --edp {COLLAPSED} for the collapse fragility (which takes neither)"));
        }
        let states = self
            .damage_states
            .as_deref()
            .map(DamageStates::get)
            .transpose()
            .map_err(FragilityError::Refused)?;
        // Limits in another unit, or of another demand (a built-in set names its own).
        if let Some(why) = states.as_ref().and_then(|d| {
            let unit = crate::plan::meaning::meaning(&self.edp).map(|m| m.unit);
            d.unit_mismatch(&self.edp, unit)
                .or_else(|| d.demand_mismatch(&self.edp))
        }) {
            return refuse(why);
        }
        if let Some(t) = crate::config::number_given_twice(&self.thresholds) {
            return refuse(format!(
                "--threshold: {} is given twice: give each threshold once",
                crate::show(t)
            ));
        }
        let (thresholds, names): (Vec<f64>, Vec<String>) = match &states {
            Some(d) => (d.limits(), d.states.iter().map(|s| s.0.clone()).collect()),
            None if collapse => (vec![0.0], vec!["collapse".into()]),
            None => (
                self.thresholds.clone(),
                self.thresholds.iter().map(|&t| crate::show(t)).collect(),
            ),
        };
        Ok(Settled {
            collapse,
            states,
            thresholds,
            names,
            by: self.by.clone().unwrap_or_else(|| "record".into()),
            seed: self.seed.unwrap_or(1),
        })
    }
}

/// `pound fragility` of `table`: the counts per threshold (or damage state) and level, the
/// lognormal fits with their goodness of fit, the bootstrap bands over the groups of `by`, the
/// bounds of the runs with no value of the demand, and the notices (a poor fit, fitted curves
/// out of order, replicates with no fit, no run collapsed, a median extrapolated beyond the
/// levels run, a building's collapse read from the run's status).
pub fn study(table: &Table, o: &FragilityOptions) -> Result<StudyReport, FragilityError> {
    if let Some(column) = &o.series {
        return series::study_series(table, o, column);
    }
    let Settled {
        collapse,
        states,
        thresholds,
        names,
        by,
        seed,
    } = o.settle()?;
    let by = if o.by.is_some() {
        by
    } else {
        default_groups(table)
    };
    // Before any column is looked up: a name given twice would read the first silently.
    table.check_columns()?;
    let spec = FragilitySpec {
        im: o.im.clone().unwrap_or_else(|| default_im(table)),
        edp: o.edp.clone(),
        thresholds,
        filters: Filter::parse_all(&o.filters)?,
    };
    if collapse {
        check_collapse_table(table, &spec.edp)?;
    }
    // The intensity is a column of the table written, beside its own: one of theirs (`--im
    // runs`, `--im collapsed`) would be a column named twice, the one read for the other.
    let head = csv_header(&spec, states.is_some());
    if let Some((column, _)) = crate::io::table::duplicate_column(&head) {
        return Err(FragilityError::Refused(format!(
            "--im {}: the fragility table has its own column `{column}` ({}), which the intensity's column would name twice: give another intensity column to --im",
            spec.im,
            head.join(", ")
        )));
    }
    let group = (o.bootstrap > 0).then_some(by.as_str());
    let (grouped, skipped) = Grouped::read(table, &spec, group)?;
    let lv = grouped.pooled(&[1]);
    let runs = grouped.runs;
    if runs == 0 {
        return Err(FragilityError::Refused(format!(
            "{}: no run left to count: {}",
            table.path.display(),
            why_none(table, &spec, &o.filters, &skipped)?
        )));
    }
    let fits: Vec<_> = lv.iter().map(|l| fit(l)).collect();
    let collapsed = skipped.collapsed;
    let whose = CollapseOf::of(table, &spec.edp);
    let mut t = Telling::default();
    t.say(format_args!(
        "{runs} runs at {} levels of {}{}{}",
        grouped.ims.len(),
        spec.im,
        match (collapse, collapsed) {
            (true, _) => format!(", {collapsed} {}", whose.runs_collapsed(&skipped)),
            (false, 0) => String::new(),
            (false, _) => format!(
                ", {collapsed} {} (counted as exceeding every {}: an infinite demand)",
                whose.runs_collapsed(&skipped),
                if states.is_some() {
                    "state"
                } else {
                    "threshold"
                }
            ),
        },
        if skipped.total() > 0 {
            format!(" ({} rows left out: {skipped})", skipped.total())
        } else {
            String::new()
        }
    ));
    if let Some(n) = whose.notice(skipped.run_collapse, &spec.edp) {
        t.note(n);
    }
    if let Some(n) = no_status_notice(table) {
        t.note(n);
    }
    if let Some(n) = signed_notice(&spec.edp) {
        t.note(n);
    }
    if grouped.ims.len() * 2 > runs && runs >= 10 {
        t.note(format_args!(
            "notice: {} takes {} values over {runs} runs: an intensity measure that differs from run to run (levels of one or two runs each) gives shares of little meaning; the level a sweep scales to is a target column (target_pga_g, target_sa_g, target_sa_avg_g)",
            spec.im,
            grouped.ims.len()
        ));
    }
    if let Some(d) = &states {
        t.say(format_args!(
            "damage states {} ({}) on {}",
            d.name, d.source, spec.edp
        ));
    }
    let (lo, hi) = (grouped.ims[0], grouped.ims[grouped.ims.len() - 1]);
    let plot_ims: Vec<f64> = (0..=100)
        .map(|i| lo + (hi - lo) * i as f64 / 100.0)
        .collect();
    let bands = if o.bootstrap > 0 {
        if grouped.groups.len() < 2 {
            return Err(FragilityError::RefusedAfter {
                message: format!(
                    "--bootstrap: the runs fall in {} group of {}: resampling needs at least two",
                    grouped.groups.len(),
                    by
                ),
                said: t.said,
                notices: t.notices,
                notices_at: t.notices_at,
            });
        }
        t.say(format_args!(
            "bootstrap: {} replicates over {} groups of {} (seed {}), 90 % bands{}",
            o.bootstrap,
            grouped.groups.len(),
            by,
            seed,
            if grouped.unknown > 0 {
                " (of the fits to the runs decided)"
            } else {
                ""
            }
        ));
        grouped.bootstrap(o.bootstrap, seed, &plot_ims)
    } else {
        vec![None; spec.thresholds.len()]
    };
    let first = if collapse {
        collapse_probability(&spec.edp)
    } else if states.is_some() {
        format!("state ({} >)", spec.edp)
    } else {
        format!("{} >", spec.edp)
    };
    let band_head = if o.bootstrap > 0 {
        " median 90 % | beta 90 % |"
    } else {
        ""
    };
    let band_rule = if o.bootstrap > 0 { "---:|---:|" } else { "" };
    t.say(format_args!("\n| {first} | median {} | beta | se(ln median) | se(beta) | log-likelihood | deviance (dof) | p (fit) |{band_head}\n|---:|---:|---:|---:|---:|---:|---:|---:|{band_rule}", spec.im));
    let mut poor = Vec::new();
    let mut unfitted = Vec::new();
    let mut extrapolated = Vec::new();
    for (i, f) in fits.iter().enumerate() {
        let label = match &states {
            Some(_) => format!("{} ({})", names[i], crate::show(spec.thresholds[i])),
            None => names[i].clone(),
        };
        let band = match (&bands[i], o.bootstrap > 0) {
            (Some(b), _) => {
                // A band of the replicates fitted alone says so in its cells, not only in a
                // notice: it is conditional on a fit, and narrower than the spread it stands for.
                let (of_median, of_beta) = if b.conditional() {
                    let why: Vec<String> = (b.why_unfitted.iter())
                        .map(|(e, n)| {
                            let w = if collapse {
                                e.short_collapse()
                            } else {
                                e.short()
                            };
                            format!("{n} {w}")
                        })
                        .collect();
                    unfitted.push(format!(
                        "{label}: {} of {} ({})",
                        b.unfitted,
                        b.unfitted + b.fitted,
                        why.join(", ")
                    ));
                    (
                        format!(
                            " (conditional: {} of {} replicates fitted)",
                            b.fitted,
                            b.fitted + b.unfitted
                        ),
                        " (conditional)".to_string(),
                    )
                } else {
                    (String::new(), String::new())
                };
                format!(
                    " {:.4}-{:.4}{of_median} | {:.4}-{:.4}{of_beta} |",
                    b.median[0], b.median[1], b.beta[0], b.beta[1],
                )
            }
            (None, true) => " no replicate fitted | |".into(),
            (None, false) => String::new(),
        };
        match f {
            Ok(f) => {
                t.say(format_args!(
                    "| {label} | {:.4} | {:.4} | {:.4} | {:.4} | {:.2} | {:.2} ({}) | {} |{band}",
                    f.median,
                    f.beta,
                    f.se_ln_median,
                    f.se_beta,
                    f.log_likelihood,
                    f.deviance,
                    f.dof,
                    f.p_text()
                ));
                // A median outside the levels this fit counted is read off the curve's tail.
                let (lowest, highest) = (lv[i][0].im, lv[i][lv[i].len() - 1].im);
                if f.median > highest || f.median < lowest {
                    let what = if collapse {
                        collapse_probability(&spec.edp)
                    } else if states.is_some() {
                        format!(
                            "{} ({} > {})",
                            names[i],
                            spec.edp,
                            crate::show(spec.thresholds[i])
                        )
                    } else {
                        format!("{} > {}", spec.edp, names[i])
                    };
                    extrapolated.push((what, f.median, lowest, highest));
                }
                if f.p_fit.is_some_and(|p| p < 0.05) {
                    poor.push(label);
                }
            }
            Err(e) if collapse => t.say(format_args!(
                "| {label} | no fit: {} | | | | | | |{band}",
                e.collapse_of(collapse_building(&spec.edp))
            )),
            Err(e) => t.say(format_args!("| {label} | no fit: {e} | | | | | | |{band}")),
        }
    }
    for (what, median, lowest, highest) in extrapolated {
        let q = |x: f64| crate::io::table::quantity(&spec.im, x);
        let (side, end, beyond) = if median > highest {
            ("ends", highest, "above the highest")
        } else {
            ("starts", lowest, "below the lowest")
        };
        t.note(format_args!(
            "notice: the fitted median of {what} is {} from a ladder of {} that {side} at {}: extrapolated, read off the fitted curve {beyond} level run, where no run bracketed it; read it with care, or run levels that reach it",
            q(median),
            spec.im,
            q(end)
        ));
    }
    if collapse && collapsed == 0 {
        let (none, p) = match collapse_building(&spec.edp) {
            Some(k) => (
                format!("building {k} collapsed in no run"),
                format!("P(building {k} collapses | IM)"),
            ),
            None => (
                "no run collapsed".to_string(),
                "P(collapse | IM)".to_string(),
            ),
        };
        t.note(format_args!(
            "notice: {none} (of {runs}, at {} levels of {} up to {}): {p} has no fit; a collapse fragility needs runs that collapse, at intensities higher than these or with a lower [run] collapse_drift_ratio",
            grouped.ims.len(),
            spec.im,
            hi
        ));
    }
    if !unfitted.is_empty() {
        t.note(format_args!(
            "notice: the 90 % bands marked conditional are the percentiles of the bootstrap replicates that could be fitted, not of all: replicates with no fit were left out, {}. A replicate with no fit is an extreme draw of the {by} groups (a median beyond the levels run, where none or every run exceeds, or a dispersion of 0, where the counts separate), so a band of the others is narrower than the uncertainty it stands for: read it as a lower bound on that spread, or add {by} groups or levels (docs/fragility.md, \"Bootstrap bands\")",
            unfitted.join("; ")
        ));
    }
    if !poor.is_empty() {
        t.note(format_args!(
            "notice: the shares above {} do not follow a lognormal curve (goodness of fit p < 0.05): the deviance against each level's own share is larger than chance allows; read the fitted median and beta with care",
            poor.join(", ")
        ));
    }
    // The severer of two thresholds is the larger, in whatever order --threshold gave them.
    let mut order: Vec<usize> = (0..fits.len()).collect();
    order.sort_by(|&x, &y| spec.thresholds[x].total_cmp(&spec.thresholds[y]));
    let ascending: Vec<_> = order.iter().map(|&k| fits[k].clone()).collect();
    for (i, j, from, to) in crossings(&ascending, lo, hi) {
        let (i, j) = (order[i], order[j]);
        // The wrong order is one interval of the levels' range (two lognormal curves meet once
        // at most): name it, and where the curves are in order.
        let outside = match (from > lo, to < hi) {
            (false, false) => "no level run is free of it: read them with care".to_string(),
            (false, true) => format!("read them only above {to:.4}"),
            (true, false) => format!("read them only below {from:.4}"),
            (true, true) => "read them only outside it".to_string(),
        };
        t.note(format_args!(
            "notice: the fitted curves of {} and {} are out of order from {} = {from:.4} to {to:.4}: there the more severe ({}) is the more probable, which no run can be (every run above {} is above {}); the curves are kept as fitted: {outside}, or fit with more runs",
            names[i], names[j], spec.im, names[j], crate::show(spec.thresholds[j]), crate::show(spec.thresholds[i])
        ));
    }
    if grouped.unknown > 0 {
        undecided_table(&mut t, &grouped, &spec, states.as_ref().map(|_| &names[..]));
    }
    let state_names = states.as_ref().map(|_| names.as_slice());
    let mut pl = panel(&spec, &lv, &fits);
    if states.is_some() {
        for s in &mut pl.series {
            for (n, limit) in names.iter().zip(&spec.thresholds) {
                let threshold = threshold_name(&spec.edp, *limit);
                if let Some(rest) = s.name.strip_prefix(&format!("{threshold}:")) {
                    s.name = format!("{n} ({threshold}):{rest}");
                }
            }
        }
    }
    for b in bands.iter().flatten() {
        pl.series.extend(band_series(b));
    }
    if bands.iter().flatten().any(Band::conditional) {
        pl.title
            .push_str(" (grey: 90 % bands, conditional on a fit: some replicates left out)");
    } else if bands.iter().any(|b| b.is_some()) {
        pl.title.push_str(" (grey: 90 % bands)");
    }
    let fits = fits_csv(
        &spec,
        state_names,
        &lv,
        &fits,
        (o.bootstrap > 0).then_some(&bands[..]),
    );
    Ok(StudyReport {
        csv: csv(&spec, state_names, &grouped),
        tables: vec![("fits", fits)],
        said: t.said,
        notices: t.notices,
        notices_at: t.notices_at,
        panels: vec![pl],
    })
}

/// A bootstrap band as two grey lines (unnamed: no legend entry).
fn band_series(b: &Band) -> [Series; 2] {
    [0, 1].map(|k| Series {
        name: String::new(),
        points: b
            .ims
            .iter()
            .zip(&b.curve)
            .map(|(&im, c)| (im, c[k]))
            .collect(),
        scatter: false,
        style: None,
    })
}

/// Why no run was left to count, naming the cause: `--where` keeping no row, every run failed,
/// the intensity or the demand column empty in every row (an intensity the sweep was not scaled
/// to), values not finite.
fn why_none(
    table: &Table,
    spec: &FragilitySpec,
    filters: &[String],
    skipped: &LeftOut,
) -> Result<String, TableError> {
    let rows = table.rows.len();
    let kept = table.select(&spec.filters)?.len();
    if rows == 0 {
        return Ok("the file has no rows".into());
    }
    if kept == 0 {
        return Ok(format!(
            "--where {} keeps none of its {rows} rows",
            filters.join(" --where ")
        ));
    }
    let mut why = Vec::new();
    if kept < rows {
        why.push(format!("--where keeps {kept} of {rows} rows"));
    }
    if skipped.failed > 0 {
        why.push(format!(
            "{} failed (status neither ok nor collapsed)",
            skipped.failed
        ));
    }
    let empty_everywhere = |c: &str| {
        table
            .col(c)
            .is_ok_and(|i| table.rows.iter().all(|r| r[i].trim().is_empty()))
    };
    if skipped.empty_im > 0 {
        let mut w = format!("{} have no value of --im {}", skipped.empty_im, spec.im);
        if empty_everywhere(&spec.im) {
            w.push_str(&format!(
                " (empty in every row: not an intensity this sweep was scaled to; it has {})",
                default_im(table)
            ));
        }
        why.push(w);
    }
    if skipped.empty_edp > 0 {
        let mut w = format!("{} have no value of --edp {}", skipped.empty_edp, spec.edp);
        if empty_everywhere(&spec.edp) {
            w.push_str(" (empty in every row)");
        }
        why.push(w);
    }
    if skipped.non_finite > 0 {
        why.push(format!(
            "{} have a value not finite (NaN or infinite)",
            skipped.non_finite
        ));
    }
    Ok(format!("of {kept} rows, {}", why.join(", ")))
}

/// The runs with no value of the demand (a residual drift where the run did not settle): how
/// many each threshold decides by the bounding column, how many stay undecided, and the fit
/// with those counted as none exceeding and as all exceeding, which bound the fit to the runs
/// decided.
fn undecided_table(
    t: &mut Telling,
    grouped: &Grouped,
    spec: &FragilitySpec,
    states: Option<&[String]>,
) {
    let decided = match &grouped.bound {
        Some(b) => format!("; {b} decides those at or below a threshold as not exceeding it (a residual drift never exceeds the peak drift)"),
        None => ", and no column of this file bounds it: each is undecided".into(),
    };
    t.say(format_args!(
        "\n{} runs have no value of {} (the run did not settle){decided}. The fits above are to the runs decided; the undecided, counted as none exceeding and as all exceeding, bound them:",
        grouped.unknown,
        spec.edp
    ));
    t.say(format_args!("\n| {} > | decided by the bound | undecided | median if none exceed | beta | median if all exceed | beta |\n|---:|---:|---:|---:|---:|---:|---:|", spec.edp));
    let none = grouped.pooled_counting(&[1], Undecided::NotExceeding);
    let all = grouped.pooled_counting(&[1], Undecided::Exceeding);
    let show = |lv: &[Level]| match fit(lv) {
        Ok(f) => format!("{:.4} | {:.4}", f.median, f.beta),
        Err(e) => format!("no fit: {e} |"),
    };
    for (k, &limit) in spec.thresholds.iter().enumerate() {
        let label = match states {
            Some(n) => format!("{} ({})", n[k], crate::show(limit)),
            None => crate::show(limit),
        };
        let undecided: u64 = grouped.undecided_at(k).iter().sum();
        t.say(format_args!(
            "| {label} | {} | {undecided} | {} | {} |",
            grouped.bounded[k],
            show(&none[k]),
            show(&all[k])
        ));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::studies::stats::normal_cdf;

    /// Groups of `(n, exceed)` per level at `ims`, one threshold.
    fn grouped(ims: &[f64], groups: &[Vec<(u64, u64)>]) -> Grouped {
        Grouped {
            ims: ims.to_vec(),
            groups: (0..groups.len()).map(|g| format!("r{g}")).collect(),
            counts: groups.iter().map(|c| vec![c.clone()]).collect(),
            undecided: Vec::new(),
            runs: groups.iter().flatten().map(|c| c.0 as usize).sum(),
            unknown: 0,
            bounded: vec![0],
            bound: None,
            collapsed: vec![0; ims.len()],
        }
    }

    /// Identical groups: every replicate is the pooled counts scaled, so the band is the point
    /// fit itself; different groups give a band around it that the seed reproduces exactly.
    #[test]
    fn bootstrap_bands_collapse_for_identical_groups_and_follow_the_seed() {
        let ims = [0.1, 0.2, 0.4, 0.8];
        let one = vec![(10, 1), (10, 3), (10, 6), (10, 9)];
        let same = grouped(&ims, &vec![one.clone(); 5]);
        let f = fit(&same.pooled(&[1])[0]).unwrap();
        let b = same.bootstrap(50, 7, &[0.3])[0].clone().unwrap();
        for x in b.median {
            assert!((x / f.median - 1.0).abs() < 1e-9);
        }
        assert!((b.curve[0][1] - f.probability(0.3)).abs() < 1e-9);
        let mixed = grouped(
            &ims,
            &[
                one.clone(),
                vec![(10, 0), (10, 1), (10, 4), (10, 7)],
                vec![(10, 3), (10, 6), (10, 8), (10, 10)],
                vec![(10, 1), (10, 2), (10, 7), (10, 9)],
            ],
        );
        let f = fit(&mixed.pooled(&[1])[0]).unwrap();
        let b = mixed.bootstrap(400, 7, &[0.3])[0].clone().unwrap();
        assert!(
            b.median[0] < f.median && f.median < b.median[1],
            "{b:?} {f:?}"
        );
        assert!(b.median[1] / b.median[0] > 1.05);
        assert_eq!(b.fitted + b.unfitted, 400);
        assert_eq!(mixed.bootstrap(400, 7, &[0.3])[0], Some(b.clone()));
        assert_ne!(mixed.bootstrap(400, 8, &[0.3])[0], Some(b));
    }

    /// Curves of ascending thresholds whose betas differ cross where the flatter one rises
    /// above the steeper; ordered curves of one beta never do.
    #[test]
    fn crossing_curves_are_found() {
        let curve = |median: f64, beta: f64| -> Result<Fit, NoFit> {
            Ok(Fit {
                median,
                beta,
                se_ln_median: 0.0,
                se_beta: 0.0,
                log_likelihood: 0.0,
                deviance: 0.0,
                dof: 0,
                p_fit: None,
                no_power: false,
            })
        };
        assert!(crossings(&[curve(0.5, 0.4), curve(0.8, 0.4)], 0.05, 3.0).is_empty());
        // ln(im) where they meet: (b2 ln m1 - b1 ln m2) / (b2 - b1), below which the flatter
        // (higher threshold) curve lies above the steeper one: the interval runs from the
        // lowest level to there, and the curves are in order on either side of its ends.
        let (a, b) = (curve(0.5, 0.2), curve(0.6, 0.8));
        let meet = ((0.8 * 0.5f64.ln() - 0.2 * 0.6f64.ln()) / (0.8 - 0.2)).exp();
        let c = crossings(&[a.clone(), b.clone()], 0.05, 3.0);
        assert_eq!(c.len(), 1);
        let (i, j, from, to) = c[0];
        assert_eq!((i, j, from), (0, 1, 0.05));
        assert!((to / meet - 1.0).abs() < 1e-12, "{to} {meet}");
        let (a, b) = (a.unwrap(), b.unwrap());
        assert!(b.probability(0.99 * to) > a.probability(0.99 * to));
        assert!(b.probability(1.01 * to) < a.probability(1.01 * to));
        // The steeper higher curve is above from the meeting point up; not at all when it
        // meets beyond the levels.
        let c = crossings(&[curve(0.6, 0.8), curve(0.5, 0.2)], 0.05, 3.0);
        assert_eq!(c.len(), 1);
        assert!(
            (c[0].2 / meet - 1.0).abs() < 1e-12 && c[0].3 == 3.0,
            "{c:?}"
        );
        assert!(crossings(&[curve(0.6, 0.8), curve(0.5, 0.2)], 0.05, 0.9 * meet).is_empty());
        // Equal betas, medians out of order: wrong everywhere.
        assert_eq!(
            crossings(&[curve(0.8, 0.4), curve(0.5, 0.4)], 0.05, 3.0),
            vec![(0, 1, 0.05, 3.0)]
        );
    }

    /// A residual drift, of a building or a storey, is bounded by its building's peak drift;
    /// no other column is.
    #[test]
    fn residual_drifts_are_bounded_by_the_peak() {
        for (edp, bound) in [
            ("b1_residual_drift_ratio", Some("b1_peak_drift_ratio")),
            ("b12_s3_residual_drift_ratio", Some("b12_peak_drift_ratio")),
            ("b1_peak_drift_ratio", None),
            ("b1_residual_storey", None),
            ("bx_residual_drift_ratio", None),
            ("b1_s_residual_drift_ratio", None),
        ] {
            assert_eq!(bounding_column(edp).as_deref(), bound, "{edp}");
        }
        assert_eq!(crate::show(1e-300), "1e-300");
        assert_eq!(crate::show(0.005), "0.005");
        assert_eq!(crate::show(2e6), "2000000");
    }

    /// Runs with no value: decided where the bound is at or below a threshold, else undecided,
    /// and counted each way for the bounds.
    #[test]
    fn runs_with_no_value_are_decided_by_the_bound_or_counted_apart() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("r.csv");
        std::fs::write(
            &p,
            "status,pga_g,b1_peak_drift_ratio,b1_residual_drift_ratio\nok,0.1,0.002,0.001\nok,0.1,0.004,\nok,0.2,0.02,0.006\nok,0.2,0.03,\nfailed,0.2,,\n",
        )
        .unwrap();
        let table = Table::read(&p).unwrap();
        let spec = FragilitySpec {
            im: "pga_g".into(),
            edp: "b1_residual_drift_ratio".into(),
            thresholds: vec![0.005],
            filters: Vec::new(),
        };
        let (g, left) = Grouped::read(&table, &spec, None).unwrap();
        assert_eq!((g.runs, g.unknown, left.failed), (4, 2, 1));
        assert_eq!(g.bounded, vec![1]);
        assert_eq!(g.undecided_at(0), vec![0, 1]);
        let at = |how| {
            g.pooled_counting(&[1], how)[0]
                .iter()
                .map(|l| (l.n, l.exceed))
                .collect::<Vec<_>>()
        };
        assert_eq!(at(Undecided::Left), vec![(2, 0), (1, 1)]);
        assert_eq!(at(Undecided::NotExceeding), vec![(2, 0), (2, 1)]);
        assert_eq!(at(Undecided::Exceeding), vec![(2, 0), (2, 2)]);
    }

    /// A storey's residual drift is signed (the side it leans to): its demand is the magnitude,
    /// so a storey leaning 0.006 to the negative side exceeds 0.005 as one leaning to the
    /// positive side does; a building's (a magnitude already) is read as written.
    #[test]
    fn a_storeys_signed_residual_is_read_as_its_magnitude() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("r.csv");
        std::fs::write(
            &p,
            "status,pga_g,b1_peak_drift_ratio,b1_s2_residual_drift_ratio\nok,0.1,0.01,-0.006\nok,0.1,0.01,0.001\nok,0.2,0.02,0.007\nok,0.2,0.02,-0.004\n",
        )
        .unwrap();
        let table = Table::read(&p).unwrap();
        let spec = FragilitySpec {
            im: "pga_g".into(),
            edp: "b1_s2_residual_drift_ratio".into(),
            thresholds: vec![0.005],
            filters: Vec::new(),
        };
        let (g, _) = Grouped::read(&table, &spec, None).unwrap();
        let counts: Vec<(u64, u64)> = g.pooled(&[1])[0].iter().map(|l| (l.n, l.exceed)).collect();
        assert_eq!(counts, vec![(2, 1), (2, 1)]);
        assert!(is_signed("b1_s2_residual_drift_ratio"));
        assert!(!is_signed("b1_residual_drift_ratio"));
        assert!(!is_signed("b1_s2_peak_drift_ratio"));
        assert!(
            signed_notice("b1_s2_residual_drift_ratio").is_some_and(|n| n.contains("magnitude"))
        );
    }

    /// A bootstrap draws a PEER record set's records by RSN (its components together), other
    /// tables' (and one that mixes a set's records with others) by record.
    #[test]
    fn a_record_sets_runs_are_drawn_by_rsn() {
        let dir = tempfile::tempdir().unwrap();
        let read = |name: &str, text: &str| {
            let p = dir.path().join(name);
            std::fs::write(&p, text).unwrap();
            Table::read(&p).unwrap()
        };
        let set = read(
            "s.csv",
            "record,pga_g,record_rsn\nRSN6_H1,0.1,6\nRSN6_H2,0.1,6\n",
        );
        let mixed = read(
            "m.csv",
            "record,pga_g,record_rsn\nRSN6_H1,0.1,6\nelcentro,0.1,\n",
        );
        let plain = read("p.csv", "record,pga_g,record_rsn\nelcentro,0.1,\n");
        assert_eq!(default_groups(&set), "record_rsn");
        // A record not of a set has no RSN: every record its own group then.
        assert_eq!(default_groups(&mixed), "record");
        assert_eq!(default_groups(&plain), "record");
    }

    /// A collapsed run counts as exceeding every threshold whatever its cell holds (empty, or
    /// below every threshold), a failed one is left out; the collapse fragility counts the
    /// collapsed runs among those that did not fail, and refuses a table that cannot collapse.
    #[test]
    fn collapsed_runs_exceed_every_threshold() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("r.csv");
        std::fs::write(
            &p,
            "status,pga_g,collapse_time_s,collapse_building,collapse_storey,b2_peak_drift_ratio,b1_residual_drift_ratio\n\
             ok,0.1,,,,0.001,0.001\ncollapsed,0.1,2,1,1,0.0005,\nok,0.2,,,,0.02,0.004\ncollapsed,0.2,1,1,2,0.001,\nfailed,0.2,,,,,\n",
        )
        .unwrap();
        let table = Table::read(&p).unwrap();
        let spec = |edp: &str, thresholds: Vec<f64>| FragilitySpec {
            im: "pga_g".into(),
            edp: edp.into(),
            thresholds,
            filters: Vec::new(),
        };
        let counts = |g: &Grouped| -> Vec<Vec<(u64, u64)>> {
            g.pooled(&[1])
                .iter()
                .map(|t| t.iter().map(|l| (l.n, l.exceed)).collect())
                .collect()
        };
        let (g, left) =
            Grouped::read(&table, &spec("b2_peak_drift_ratio", vec![0.01, 0.5]), None).unwrap();
        assert_eq!((left.failed, left.collapsed, left.total()), (1, 2, 1));
        assert_eq!(counts(&g), vec![vec![(2, 1), (2, 2)], vec![(2, 1), (2, 1)]]);
        assert_eq!(g.collapsed, vec![1, 1]);
        // A residual drift: the collapsed runs' empty cells are no undecided runs.
        let (g, _) =
            Grouped::read(&table, &spec("b1_residual_drift_ratio", vec![0.002]), None).unwrap();
        assert_eq!((g.unknown, counts(&g)), (0, vec![vec![(2, 1), (2, 2)]]));
        let collapse = FragilitySpec::collapse("pga_g", Vec::new());
        let (g, left) = Grouped::read(&table, &collapse, None).unwrap();
        assert_eq!((left.failed, g.runs), (1, 4));
        assert_eq!(counts(&g), vec![vec![(2, 1), (2, 1)]]);
        assert_eq!(
            csv(&collapse, None, &g),
            "pga_g,runs,collapsed,fraction\n0.1,2,1,0.5\n0.2,2,1,0.5\n"
        );
        assert!(csv(&spec("b2_peak_drift_ratio", vec![0.01]), None, &g)
            .starts_with("threshold,pga_g,runs,exceed,collapsed,fraction,"));
        // A threshold with it is refused; so is a table with no collapse columns.
        let mut with = collapse.clone();
        with.thresholds = vec![0.1];
        assert!(Grouped::read(&table, &with, None).is_err());
        let q = dir.path().join("pair.csv");
        std::fs::write(&q, "status,pga_g,peak_force_n\nok,0.1,1\n").unwrap();
        let e = Grouped::read(&Table::read(&q).unwrap(), &collapse, None)
            .unwrap_err()
            .to_string();
        assert!(e.contains("no collapse columns"), "{e}");
    }

    /// A curve through exact probabilities is recovered to the solver's precision.
    #[test]
    fn fit_recovers_exact_probabilities() {
        let (median, beta) = (0.4, 0.35);
        let levels: Vec<Level> = (1..=10)
            .map(|i| {
                let im = 0.1 * i as f64;
                let n = 1_000_000u64;
                let p = normal_cdf((im / median).ln() / beta);
                Level {
                    im,
                    n,
                    exceed: (p * n as f64).round() as u64,
                }
            })
            .collect();
        let f = fit(&levels).unwrap();
        assert!((f.median / median - 1.0).abs() < 1e-4, "{f:?}");
        assert!((f.beta / beta - 1.0).abs() < 1e-3, "{f:?}");
        let none: Vec<Level> = levels.iter().map(|l| Level { exceed: 0, ..*l }).collect();
        assert_eq!(fit(&none), Err(NoFit::NoneExceed));
        let step: Vec<Level> = levels
            .iter()
            .map(|l| Level {
                exceed: if l.im > 0.5 { l.n } else { 0 },
                ..*l
            })
            .collect();
        assert_eq!(fit(&step), Err(NoFit::Separated));
    }

    /// The chi-square survival function at its 5 % points (tables), and its extremes.
    #[test]
    fn chi_square_tail_matches_the_tables() {
        for (x, dof) in [
            (3.841_458_820_694_124, 1.0),
            (5.991_464_547_107_979, 2.0),
            (11.070_497_693_516_35, 5.0),
            (18.307_038_053_275_146, 10.0),
            (43.772_971_825_742_19, 30.0),
        ] {
            let p = chi_square_sf(x, dof);
            assert!((p - 0.05).abs() < 1e-10, "dof {dof}: {p}");
        }
        assert_eq!(chi_square_sf(0.0, 3.0), 1.0);
        assert!(chi_square_sf(500.0, 3.0) < 1e-100);
        // dof 2: exp(-x / 2) exactly.
        assert!((chi_square_sf(3.0, 2.0) - (-1.5f64).exp()).abs() < 1e-15);
    }

    /// Binomial draws from a known lognormal (seeded, 200 runs at each of 10 levels, 40
    /// trials): the medians and betas fall within 2 standard errors of the truth about 95 % of
    /// the time, and the goodness of fit rejects (p < 0.001) in at most 1 trial; counts from a
    /// law that is not
    /// lognormal (a plateau at 1/2 from 0.3 to 0.7 g) are rejected.
    #[test]
    fn fit_recovers_known_states_and_flags_other_laws() {
        let (median, beta) = (0.4, 0.5);
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut uniform = || {
            // xorshift64*: reproducible on every platform.
            state ^= state >> 12;
            state ^= state << 25;
            state ^= state >> 27;
            (state.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
        };
        let (mut rejected, mut within, mut far) = (0, [0usize; 2], [0usize; 2]);
        for _ in 0..40 {
            let levels: Vec<Level> = (1..=10)
                .map(|i| {
                    let im = 0.1 * i as f64;
                    let p = normal_cdf((im / median).ln() / beta);
                    let n = 200u64;
                    let exceed = (0..n).filter(|_| uniform() < p).count() as u64;
                    Level { im, n, exceed }
                })
                .collect();
            let f = fit(&levels).unwrap();
            let z = [
                (f.median.ln() - median.ln()) / f.se_ln_median,
                (f.beta - beta) / f.se_beta,
            ];
            for (k, z) in z.iter().enumerate() {
                within[k] += (z.abs() < 2.0) as usize;
                far[k] += (z.abs() > 3.0) as usize;
            }
            assert_eq!(f.dof, 8);
            if f.p_fit.unwrap() < 1e-3 {
                rejected += 1;
            }
        }
        // About 95 % of the estimates within 2 standard errors, hardly any beyond 3.
        assert!(
            within.iter().all(|&w| w >= 34),
            "within 2 se: {within:?} of 40"
        );
        assert!(far.iter().all(|&f| f <= 2), "beyond 3 se: {far:?} of 40");
        assert!(
            rejected <= 1,
            "{rejected} of 40 true lognormal samples rejected"
        );
        let plateau: Vec<Level> = (1..=10)
            .map(|i| {
                let im = 0.1 * i as f64;
                let share = if im < 0.25 {
                    0.02
                } else if im < 0.75 {
                    0.5
                } else {
                    0.98
                };
                Level {
                    im,
                    n: 200,
                    exceed: (share * 200.0) as u64,
                }
            })
            .collect();
        let f = fit(&plateau).unwrap();
        assert!(f.p_fit.unwrap() < 1e-6, "{f:?}");
    }

    /// A table in memory: `rows` of `record, target_sa_g, status, drift`.
    fn study_table(rows: &[(&str, f64, &str, f64)]) -> Table {
        Table {
            path: "r.csv".into(),
            header: ["record", "target_sa_g", "status", "drift"]
                .map(String::from)
                .to_vec(),
            rows: rows
                .iter()
                .map(|(r, im, st, d)| {
                    vec![r.to_string(), im.to_string(), st.to_string(), d.to_string()]
                })
                .collect(),
        }
    }

    /// Ten runs at each of four levels, two per record r0..r4, the first 1, 3, 6, 9 above 1.
    fn ladder() -> Vec<(&'static str, f64, &'static str, f64)> {
        let records = ["r0", "r1", "r2", "r3", "r4"];
        [(0.1, 1), (0.2, 3), (0.4, 6), (0.8, 9)]
            .into_iter()
            .flat_map(|(im, k)| {
                (0..10).map(move |j| (records[j / 2], im, "ok", if j < k { 2.0 } else { 0.5 }))
            })
            .collect()
    }

    /// The study of a table read gives the counts' CSV, the summary and the fits' table, a
    /// notice placed after the line it follows, and refuses a bootstrap of one group after
    /// telling what it read; its settings are refused before any table.
    #[test]
    fn the_study_counts_fits_and_tells_in_order() {
        let o = FragilityOptions {
            edp: "drift".into(),
            thresholds: vec![1.0, 5.0],
            ..FragilityOptions::default()
        };
        let r = study(&study_table(&ladder()), &o).unwrap();
        assert_eq!(
            r.csv,
            "threshold,target_sa_g,runs,exceed,collapsed,fraction,undecided,fraction_if_none_exceed,fraction_if_all_exceed\n\
             1,0.1,10,1,0,0.1,0,0.1,0.1\n1,0.2,10,3,0,0.3,0,0.3,0.3\n1,0.4,10,6,0,0.6,0,0.6,0.6\n1,0.8,10,9,0,0.9,0,0.9,0.9\n\
             5,0.1,10,0,0,0,0,0,0\n5,0.2,10,0,0,0,0,0,0\n5,0.4,10,0,0,0,0,0,0\n5,0.8,10,0,0,0,0,0,0\n"
        );
        let lines: Vec<&str> = r.said.lines().collect();
        assert_eq!(lines[0], "40 runs at 4 levels of target_sa_g");
        assert!(lines[1].is_empty() && lines[2].starts_with("| drift > | median target_sa_g |"));
        let fitted = fit(&Grouped::read(
            &study_table(&ladder()),
            &FragilitySpec {
                im: "target_sa_g".into(),
                edp: "drift".into(),
                thresholds: vec![1.0],
                filters: Vec::new(),
            },
            None,
        )
        .unwrap()
        .0
        .pooled(&[1])[0])
        .unwrap();
        assert!(
            lines[4].starts_with(&format!(
                "| 1 | {:.4} | {:.4} |",
                fitted.median, fitted.beta
            )),
            "{}",
            lines[4]
        );
        assert!(lines[5].starts_with("| 5 | no fit: "), "{}", lines[5]);
        assert_eq!(r.panels.len(), 1);

        // An intensity that differs from run to run: the notice comes after the first line.
        let spread: Vec<_> = (0..12)
            .map(|i| ("r0", 0.1 + i as f64 / 100.0, "ok", i as f64))
            .collect();
        let o = FragilityOptions {
            edp: "drift".into(),
            thresholds: vec![5.0],
            ..FragilityOptions::default()
        };
        let r = study(&study_table(&spread), &o).unwrap();
        assert!(r.notices[0].starts_with("notice: target_sa_g takes 12 values over 12 runs"));
        assert_eq!(r.notices_at[0], r.said.find('\n').unwrap() + 1);
        let told = std::cell::RefCell::new(Vec::new());
        r.tell(
            |s| -> Result<(), ()> {
                told.borrow_mut().push(format!("say {s}"));
                Ok(())
            },
            |n| told.borrow_mut().push(format!("note {n}")),
        )
        .unwrap();
        let told = told.into_inner();
        assert_eq!(told[0], "say 12 runs at 12 levels of target_sa_g\n");
        assert!(told[1].starts_with("note notice: target_sa_g takes"));
        assert_eq!(
            told.iter()
                .filter(|t| t.starts_with("say "))
                .map(|t| &t[4..])
                .collect::<String>(),
            r.said
        );

        // A bootstrap over one record: refused after the summary, which it carries.
        let o = FragilityOptions {
            edp: "drift".into(),
            thresholds: vec![1.0],
            bootstrap: 100,
            filters: vec!["record=r0".into()],
            ..FragilityOptions::default()
        };
        match study(&study_table(&ladder()), &o) {
            Err(e @ FragilityError::RefusedAfter { .. }) => {
                assert_eq!(e.to_string(), "--bootstrap: the runs fall in 1 group of record: resampling needs at least two");
                let mut said = String::new();
                e.tell(
                    |s| -> Result<(), ()> {
                        said.push_str(s);
                        Ok(())
                    },
                    |_| (),
                )
                .unwrap();
                assert_eq!(said, "8 runs at 4 levels of target_sa_g\n");
            }
            other => panic!("{other:?}"),
        }
        // Settings refused with no table; a filter keeping nothing named with the file.
        let o = FragilityOptions {
            bootstrap: 50,
            thresholds: vec![1.0],
            ..FragilityOptions::default()
        };
        assert!(o
            .check()
            .unwrap_err()
            .to_string()
            .starts_with("--bootstrap 50: expected 0 (no bands) or at least 100"));
        assert!(FragilityOptions::default()
            .check()
            .unwrap_err()
            .to_string()
            .starts_with("give --threshold T1,T2"));
        let o = FragilityOptions {
            edp: "drift".into(),
            thresholds: vec![1.0],
            filters: vec!["record=none".into()],
            ..FragilityOptions::default()
        };
        assert_eq!(
            study(&study_table(&ladder()), &o).unwrap_err().to_string(),
            "r.csv: no run left to count: --where record=none keeps none of its 40 rows"
        );
    }
}
