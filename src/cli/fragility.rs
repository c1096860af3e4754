//! `pound fragility`: exceedance counts and fitted lognormal curves from a results CSV, per
//! threshold or per named damage state, with bootstrap bands over records.

use super::{check_study_outputs, Holds};
use anyhow::{bail, Result};
use pounding::io::table::Table;
use pounding::studies::damage_states::{self, DamageStates};
use pounding::studies::fragility::{study, FragilityOptions};
use std::path::{Path, PathBuf};

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
    /// threshold: a run collapsed, its status `collapsed`, or it did not), `bK_collapsed` for
    /// building K's, P(building K collapses | IM). A collapse counts as exceeding every threshold
    /// and damage state (an infinite demand): of a building's column (bK_...), building K's own
    /// collapse (bK_collapsed); of a column of the run, any building's.
    #[arg(long, default_value = "peak_force_n")]
    edp: String,
    /// Exceedance thresholds (EDP > threshold), comma-separated (one of --threshold and
    /// --damage-states, except with --edp collapsed or bK_collapsed, which take neither).
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
    /// Bootstrap replicates over the groups of `--bootstrap-groups` (records), for 90 % bands of each
    /// fitted median, beta and curve (0: none; else at least 100).
    #[arg(long, default_value_t = 0)]
    bootstrap: usize,
    /// Seed of the bootstrap draws (with --bootstrap; default 1).
    #[arg(long)]
    seed: Option<u64>,
    /// The column whose groups the bootstrap draws with replacement (with --bootstrap; default
    /// record, or record_rsn where every run's record came from a PEER record set: a record's
    /// components are drawn together).
    #[arg(long, value_name = "COLUMN")]
    bootstrap_groups: Option<String>,
    /// The old spelling of --bootstrap-groups.
    #[arg(long, hide = true, conflicts_with = "bootstrap_groups")]
    by: Option<String>,
    /// Keep only rows with COLUMN=VALUE (also !=, <, <=, >, >=); repeat to combine.
    #[arg(long = "where", value_name = "FILTER")]
    filters: Vec<String>,
    /// Fit and draw the curves of each value of COLUMN (e.g. gap_1_2_m) in one figure, with
    /// COLUMN first in the counts' and fits' tables (2 to 12 values).
    #[arg(long, value_name = "COLUMN")]
    series: Option<String>,
    /// Counts per threshold and level (CSV).
    /// (default: fragility.csv, numbered `-2`, `-3`, ... where that file exists)
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// The fitted curves as a table (CSV): per threshold or damage state, the median, beta,
    /// their standard errors, log-likelihood, deviance, p, runs and levels, and with
    /// --bootstrap the 90 % bands of median and beta (the report's table, as data).
    #[arg(long, value_name = "FILE")]
    fits: Option<PathBuf>,
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
            ("--fits", a.fits.as_deref(), Holds::Csv),
            ("--plot", a.plot.as_deref(), Holds::Plot),
        ],
    )?;
    let options = FragilityOptions {
        im: a.im,
        edp: a.edp,
        thresholds: a.threshold,
        damage_states: a.damage_states,
        bootstrap: a.bootstrap,
        seed: a.seed,
        by: super::renamed(a.bootstrap_groups, a.by, "--by", "--bootstrap-groups"),
        filters: a.filters,
        series: a.series,
    };
    // The settings are checked before the results are read.
    options.check()?;
    let table = Table::read(&results)?;
    let report = match study(&table, &options) {
        Ok(r) => r,
        Err(e) => {
            e.tell(super::say_text, |n| note!("{n}"))?;
            return Err(e.into());
        }
    };
    report.tell(super::say_text, |n| note!("{n}"))?;
    let plot = a.plot.as_deref().map(|p| (p, report.panels, 1));
    super::write_and_plot(&output, report.csv.as_bytes(), plot, &a.figure)?;
    super::write_tables(&report.tables, &[("fits", a.fits.as_deref())])
}
