//! `pound fragility`: exceedance counts and fitted lognormal curves from a results CSV, per
//! threshold or per named damage state, with bootstrap bands over records.

use super::{check_study_outputs, Holds};
use anyhow::{anyhow, bail, Result};
use pounding::io::table::{Filter, Table};
use pounding::studies::damage_states::{self, DamageStates};
use pounding::studies::fragility::{
    bootstrap, check_collapse_table, crossings, csv, default_im, fit, number, panel, Band,
    FragilitySpec, Grouped, Undecided, COLLAPSED,
};
use pounding::studies::plot::Series;
use std::path::{Path, PathBuf};

/// Bootstrap replicates at most (each refits every threshold).
const MAX_BOOTSTRAP: usize = 100_000;

/// Bootstrap replicates at least: a 5 % and a 95 % percentile need some replicates beyond each
/// (5 at 100), or the "90 %" band is the smallest and largest of a few draws.
const MIN_BOOTSTRAP: usize = 100;

#[derive(clap::Args)]
#[command(group(clap::ArgGroup::new("limits").args(["threshold", "damage_states"])))]
pub struct Args {
    /// A CSV written by `pound sweep` (not needed with `--damage-states list`).
    #[arg(required_unless_present = "damage_states")]
    results: Option<PathBuf>,
    /// Intensity measure: any numeric column (e.g. pga_g, target_sa_g, target_sa_avg_g,
    /// scale_factor, or an intensity measure every run writes of its scaled record: pgv_m_s,
    /// arias_m_s, cav_m_s, sa_t1_g / sa_t2_g of a pair, b1_sa_t1_g ... of a row). Default: the
    /// spectral target the CSV was scaled to, else pga_g.
    #[arg(long)]
    im: Option<String>,
    /// Demand column (e.g. peak_force_n, b1_peak_drift_ratio; `impacts` with threshold 0 for
    /// "pounds at all"), or `collapsed` for the collapse fragility P(collapse | IM) (no
    /// threshold: a run collapsed, its status `collapsed`, or it did not). A collapsed run counts
    /// as exceeding every threshold and damage state of any column (an infinite demand).
    #[arg(long, default_value = "peak_force_n")]
    edp: String,
    /// Exceedance thresholds (EDP > threshold), comma-separated (one of --threshold and
    /// --damage-states, except with --edp collapsed, which takes neither).
    #[arg(long, value_delimiter = ',')]
    threshold: Vec<f64>,
    /// Named damage states instead of thresholds: a built-in set (hazus-TYPE-LEVEL, e.g.
    /// hazus-c1l-high or hazus-s1m-moderate: HAZUS-MH peak drift ratios per model building type
    /// and code level, read on bK_peak_drift_ratio; fema-p58-residual: FEMA P-58 residual drift
    /// ratios, read on bK_residual_drift_ratio) or a TOML file of `[[state]]` entries with `name`
    /// and `limit`. `--damage-states list` prints the built-in sets with their sources and
    /// limits.
    #[arg(long, value_name = "SET")]
    damage_states: Option<String>,
    /// Bootstrap replicates over the groups of `--by` (records), for 90 % bands of each
    /// fitted median, beta and curve (0: none; else at least 100).
    #[arg(long, default_value_t = 0)]
    bootstrap: usize,
    /// Seed of the bootstrap draws (with --bootstrap; default 1).
    #[arg(long)]
    seed: Option<u64>,
    /// The column whose groups the bootstrap draws with replacement (with --bootstrap; default
    /// record).
    #[arg(long)]
    by: Option<String>,
    /// Keep only rows with COLUMN=VALUE (also !=, <, <=, >, >=); repeat to combine.
    #[arg(long = "where", value_name = "FILTER")]
    filters: Vec<String>,
    /// Counts per threshold and level (CSV).
    /// (default: fragility.csv, numbered `-2`, `-3`, ... where that file exists)
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Observed fractions and fitted curves (.svg or .png).
    #[arg(long)]
    plot: Option<PathBuf>,
    #[command(flatten)]
    figure: super::FigureArgs,
}

pub fn run(a: Args) -> Result<()> {
    if a.damage_states.as_deref() == Some(damage_states::LIST) {
        use std::io::Write;
        std::io::stdout().write_all(DamageStates::list().as_bytes())?;
        return Ok(());
    }
    let Some(results) = a.results.clone() else {
        bail!("give the results CSV (written by pound sweep): pound fragility RESULTS.csv --damage-states SET ... (`--damage-states list` alone prints the built-in sets)");
    };
    let output = super::default_output(a.output.clone(), "fragility.csv");
    // A damage-state file is an input like the results (a built-in set's name is no file).
    let states_file = a
        .damage_states
        .as_deref()
        .map(Path::new)
        .filter(|p| p.is_file());
    let other: Vec<(&str, &Path)> = states_file
        .map(|p| ("the damage-state file", p))
        .into_iter()
        .collect();
    check_study_outputs(
        &results,
        &other,
        &[
            ("-o", Some(&output), Holds::Csv),
            ("--plot", a.plot.as_deref(), Holds::Plot),
        ],
    )?;
    if a.bootstrap > MAX_BOOTSTRAP {
        bail!(
            "--bootstrap {}: expected at most {MAX_BOOTSTRAP} replicates",
            a.bootstrap
        );
    }
    if a.bootstrap > 0 && a.bootstrap < MIN_BOOTSTRAP {
        bail!(
            "--bootstrap {}: expected 0 (no bands) or at least {MIN_BOOTSTRAP} replicates: the 90 % band is the 5 and 95 % percentiles of the replicates, which fewer cannot place",
            a.bootstrap
        );
    }
    // Flags of the bootstrap mean nothing without it.
    for (flag, given) in [("--by", a.by.is_some()), ("--seed", a.seed.is_some())] {
        if given && a.bootstrap == 0 {
            bail!("{flag} applies to the bootstrap bands: give --bootstrap N (N >= {MIN_BOOTSTRAP}) with it, or leave {flag} out");
        }
    }
    let collapse = a.edp == COLLAPSED;
    if collapse {
        for (flag, given) in [
            ("--threshold", !a.threshold.is_empty()),
            ("--damage-states", a.damage_states.is_some()),
        ] {
            if given {
                bail!("{flag} makes no sense with --edp {COLLAPSED}: a run collapsed (status `collapsed`) or it did not, and P(collapse | IM) is fitted to that; leave {flag} out, or give a demand column to --edp");
            }
        }
    } else if a.threshold.is_empty() && a.damage_states.is_none() {
        bail!("give --threshold T1,T2 (EDP > threshold) or --damage-states SET, or --edp {COLLAPSED} for the collapse fragility (which takes neither)");
    }
    let by = a.by.clone().unwrap_or_else(|| "record".into());
    let seed = a.seed.unwrap_or(1);
    let states = a
        .damage_states
        .as_deref()
        .map(DamageStates::get)
        .transpose()
        .map_err(|e| anyhow!(e))?;
    // Limits in another unit, or of another demand (a built-in set names its own).
    if let Some(why) = states.as_ref().and_then(|d| {
        let unit = pounding::plan::meaning::meaning(&a.edp).map(|m| m.unit);
        d.unit_mismatch(&a.edp, unit)
            .or_else(|| d.demand_mismatch(&a.edp))
    }) {
        bail!(why);
    }
    if let Some(t) = pounding::plan::config::number_given_twice(&a.threshold) {
        bail!(
            "--threshold: {} is given twice: give each threshold once",
            number(t)
        );
    }
    let (thresholds, names): (Vec<f64>, Vec<String>) = match &states {
        Some(d) => (d.limits(), d.states.iter().map(|s| s.0.clone()).collect()),
        None if collapse => (vec![0.0], vec!["collapse".into()]),
        None => (
            a.threshold.clone(),
            a.threshold.iter().map(|&t| number(t)).collect(),
        ),
    };
    let table = Table::read(&results)?;
    let spec = FragilitySpec {
        im: a.im.unwrap_or_else(|| default_im(&table)),
        edp: a.edp,
        thresholds,
        filters: Filter::parse_all(&a.filters)?,
    };
    if collapse {
        check_collapse_table(&table)?;
    }
    let group = (a.bootstrap > 0).then_some(by.as_str());
    let (grouped, skipped) = Grouped::read(&table, &spec, group)?;
    let lv = grouped.pooled(&[1]);
    let runs = grouped.runs;
    if runs == 0 {
        bail!(
            "{}: no run left to count: {}",
            results.display(),
            why_none(&table, &spec, &a.filters, &skipped)?
        );
    }
    let fits: Vec<_> = lv.iter().map(|l| fit(l)).collect();
    let collapsed = skipped.collapsed;
    say!(
        "{runs} runs at {} levels of {}{}{}",
        grouped.ims.len(),
        spec.im,
        match (collapse, collapsed) {
            (true, _) => format!(", {collapsed} collapsed"),
            (false, 0) => String::new(),
            (false, _) => format!(
                ", {collapsed} collapsed (counted as exceeding every {}: an infinite demand)",
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
    );
    if grouped.ims.len() * 2 > runs && runs >= 10 {
        note!(
            "notice: {} takes {} values over {runs} runs: an intensity measure that differs from run to run (levels of one or two runs each) gives shares of little meaning; the level a sweep scales to is a target column (target_pga_g, target_sa_g, target_sa_avg_g)",
            spec.im,
            grouped.ims.len()
        );
    }
    if let Some(d) = &states {
        say!("damage states {} ({}) on {}", d.name, d.source, spec.edp);
    }
    let (lo, hi) = (grouped.ims[0], grouped.ims[grouped.ims.len() - 1]);
    let plot_ims: Vec<f64> = (0..=100)
        .map(|i| lo + (hi - lo) * i as f64 / 100.0)
        .collect();
    let bands = if a.bootstrap > 0 {
        if grouped.groups.len() < 2 {
            bail!(
                "--bootstrap: the runs fall in {} group of {}: resampling needs at least two",
                grouped.groups.len(),
                by
            );
        }
        say!(
            "bootstrap: {} replicates over {} groups of {} (seed {}), 90 % bands{}",
            a.bootstrap,
            grouped.groups.len(),
            by,
            seed,
            if grouped.unknown > 0 {
                " (of the fits to the runs decided)"
            } else {
                ""
            }
        );
        bootstrap(&grouped, a.bootstrap, seed, &plot_ims)
    } else {
        vec![None; spec.thresholds.len()]
    };
    let first = if collapse {
        "P(collapse)".to_string()
    } else if states.is_some() {
        format!("state ({} >)", spec.edp)
    } else {
        format!("{} >", spec.edp)
    };
    let band_head = if a.bootstrap > 0 {
        " median 90 % | beta 90 % |"
    } else {
        ""
    };
    let band_rule = if a.bootstrap > 0 { "---:|---:|" } else { "" };
    say!("\n| {first} | median {} | beta | se(ln median) | se(beta) | log-likelihood | deviance (dof) | p (fit) |{band_head}\n|---:|---:|---:|---:|---:|---:|---:|---:|{band_rule}", spec.im);
    let mut poor = Vec::new();
    let mut unfitted = Vec::new();
    for (i, f) in fits.iter().enumerate() {
        let label = match &states {
            Some(_) => format!("{} ({})", names[i], number(spec.thresholds[i])),
            None => names[i].clone(),
        };
        let band = match (&bands[i], a.bootstrap > 0) {
            (Some(b), _) => {
                if b.unfitted > 0 {
                    unfitted.push(format!(
                        "{label}: {} of {}",
                        b.unfitted,
                        b.unfitted + b.fitted
                    ));
                }
                format!(
                    " {:.4}-{:.4} | {:.4}-{:.4} |",
                    b.median[0], b.median[1], b.beta[0], b.beta[1],
                )
            }
            (None, true) => " no replicate fitted | |".into(),
            (None, false) => String::new(),
        };
        match f {
            Ok(f) => {
                say!(
                    "| {label} | {:.4} | {:.4} | {:.4} | {:.4} | {:.2} | {:.2} ({}) | {} |{band}",
                    f.median,
                    f.beta,
                    f.se_ln_median,
                    f.se_beta,
                    f.log_likelihood,
                    f.deviance,
                    f.dof,
                    f.p_fit.map_or("-".into(), |p| format!("{p:.3}"))
                );
                if f.p_fit.is_some_and(|p| p < 0.05) {
                    poor.push(label);
                }
            }
            Err(e) if collapse => say!("| {label} | no fit: {} | | | | | | |{band}", e.collapse()),
            Err(e) => say!("| {label} | no fit: {e} | | | | | | |{band}"),
        }
    }
    if collapse && collapsed == 0 {
        note!(
            "notice: no run collapsed (of {runs}, at {} levels of {} up to {}): P(collapse | IM) has no fit; a collapse fragility needs runs that collapse, at intensities higher than these or with a lower [run] collapse_drift_ratio",
            grouped.ims.len(),
            spec.im,
            hi
        );
    }
    if !unfitted.is_empty() {
        note!(
            "notice: bootstrap replicates with no fit (left out of the bands): {}",
            unfitted.join("; ")
        );
    }
    if !poor.is_empty() {
        note!(
            "notice: the shares above {} do not follow a lognormal curve (goodness of fit p < 0.05): the deviance against each level's own share is larger than chance allows; read the fitted median and beta with care",
            poor.join(", ")
        );
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
        note!(
            "notice: the fitted curves of {} and {} are out of order from {} = {from:.4} to {to:.4}: there the more severe ({}) is the more probable, which no run can be (every run above {} is above {}); the curves are kept as fitted: {outside}, or fit with more runs",
            names[i], names[j], spec.im, names[j], number(spec.thresholds[j]), number(spec.thresholds[i])
        );
    }
    if grouped.unknown > 0 {
        undecided_table(&grouped, &spec, &states.as_ref().map(|_| names.clone()))?;
    }
    let state_names = states.as_ref().map(|_| names.as_slice());
    let plot = a.plot.as_deref().map(|p| {
        let mut pl = panel(&spec, &lv, &fits);
        if states.is_some() {
            for s in &mut pl.series {
                for (n, t) in names.iter().zip(&spec.thresholds) {
                    let threshold = pounding::studies::fragility::threshold_name(&spec.edp, *t);
                    if let Some(rest) = s.name.strip_prefix(&format!("{threshold}:")) {
                        s.name = format!("{n} ({threshold}):{rest}");
                    }
                }
            }
        }
        for b in bands.iter().flatten() {
            pl.series.extend(band_series(b));
        }
        if bands.iter().any(|b| b.is_some()) {
            pl.title.push_str(" (grey: 90 % bands)");
        }
        (p, vec![pl], 1)
    });
    super::write_and_plot(
        &output,
        csv(&spec, state_names, &grouped).as_bytes(),
        plot,
        &a.figure,
    )
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
    skipped: &pounding::studies::fragility::LeftOut,
) -> Result<String> {
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
    grouped: &Grouped,
    spec: &FragilitySpec,
    states: &Option<Vec<String>>,
) -> Result<()> {
    let decided = match &grouped.bound {
        Some(b) => format!("; {b} decides those at or below a threshold as not exceeding it (a residual drift never exceeds the peak drift)"),
        None => ", and no column of this file bounds it: each is undecided".into(),
    };
    say!(
        "\n{} runs have no value of {} (the run did not settle){decided}. The fits above are to the runs decided; the undecided, counted as none exceeding and as all exceeding, bound them:",
        grouped.unknown,
        spec.edp
    );
    say!("\n| {} > | decided by the bound | undecided | median if none exceed | beta | median if all exceed | beta |\n|---:|---:|---:|---:|---:|---:|---:|", spec.edp);
    let none = grouped.pooled_counting(&[1], Undecided::NotExceeding);
    let all = grouped.pooled_counting(&[1], Undecided::Exceeding);
    let show = |lv: &[pounding::studies::fragility::Level]| match fit(lv) {
        Ok(f) => format!("{:.4} | {:.4}", f.median, f.beta),
        Err(e) => format!("no fit: {e} |"),
    };
    for (t, &limit) in spec.thresholds.iter().enumerate() {
        let label = match states {
            Some(n) => format!("{} ({})", n[t], number(limit)),
            None => number(limit),
        };
        let undecided: u64 = grouped.undecided_at(t).iter().sum();
        say!(
            "| {label} | {} | {undecided} | {} | {} |",
            grouped.bounded[t],
            show(&none[t]),
            show(&all[t])
        );
    }
    Ok(())
}
