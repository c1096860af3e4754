//! `pound accuracy`: speed against error of every path against the reference.

use super::{check_outputs, config_inputs, BackendArg, Holds};
use anyhow::{bail, Result};
use pounding::plan::config;
use pounding::plan::limits::{MAX_SUBSTEPS_PER_CONTACT, WHY_SUBSTEPS};
use pounding::studies::accuracy;
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Args {
    #[arg(default_value = "configs/accuracy.toml")]
    config: PathBuf,
    /// RK4 substeps per contact duration to try.
    #[arg(long, value_delimiter = ',', default_value = "8,16,32,64,128")]
    settings: Vec<f64>,
    /// Stated relative accuracy of the reference.
    #[arg(long, default_value_t = 1e-8)]
    tol: f64,
    /// `auto` adds the GPU paths when a hardware adapter is found; `gpu` also on a software
    /// one; `cpu` leaves them out.
    #[arg(long, value_enum, default_value = "auto")]
    backend: BackendArg,
    /// (default: accuracy.csv, numbered `-2`, `-3`, ... where that file exists)
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Work-precision plot (SVG, or PNG for a .png name).
    #[arg(long)]
    plot: Option<PathBuf>,
    #[command(flatten)]
    figure: super::FigureArgs,
    /// Check `--target-error` instead of trying --settings: for each error E, run the setting
    /// it chooses and fail unless every path's p99 peak-force error on CONFIG is at most E (on
    /// a row whose storeys yield, the largest p99 of peak force, drift, residual drift and
    /// ductility; where runs collapse, and of the collapse time, relative to the reference's).
    /// A run that fails, or collapses on one side only or in another storey, fails the target.
    #[arg(
        long,
        value_delimiter = ',',
        value_name = "E",
        conflicts_with = "settings"
    )]
    target_error: Option<Vec<f64>>,
}

pub fn run(a: Args) -> Result<()> {
    let Args {
        config,
        settings,
        tol,
        backend,
        output,
        plot,
        target_error,
        figure,
    } = a;
    let output = super::default_output(output, "accuracy.csv");
    let text = config::read_text(&config)?;
    let plan = config::load_text(&text, &config)?;
    let suite = plan.suite();
    let choices = target_error
        .unwrap_or_default()
        .into_iter()
        .map(|e| super::target_error_in(suite, e))
        .collect::<Result<Vec<_>>>()?;
    let mut settings = if choices.is_empty() {
        settings
    } else {
        choices.iter().map(|c| c.substeps_per_contact).collect()
    };
    // In increasing order, each once: a run's error is judged against the coarser settings
    // before it ("not converging"), and targets may come in any order and share a setting.
    settings.sort_by(f64::total_cmp);
    settings.dedup();
    let most = MAX_SUBSTEPS_PER_CONTACT;
    if let Some(bad) = settings.iter().find(|s| !(**s >= 1.0 && **s <= most)) {
        bail!(
            "--settings: {} is out of range: expected substeps per contact from 1 to {most} ({WHY_SUBSTEPS})",
            pounding::plan::limits::show(*bad)
        );
    }
    // The config key's bound (run.tol).
    let tol = pounding::plan::limits::check_tol(tol).map_err(|m| anyhow::anyhow!("--tol {m}"))?;
    let records = config::input_files(&text, &config);
    check_outputs(
        &config_inputs(&config, &records),
        &[
            ("-o", Some(&output), Holds::Csv),
            ("--plot", plot.as_deref(), Holds::Plot),
        ],
    )?;
    let finest = settings.iter().cloned().fold(0.0, f64::max);
    super::warn_all(&config, plan.warnings(finest));
    let (ctx, paths) = accuracy::paths(&plan, backend.get(), &mut |l| note!("{l}"))?;
    note!(
        "{}: {} runs of {}; reference at tol {tol:e}, then {} settings on {paths}",
        config.display(),
        plan.len(),
        plan.scene(),
        settings.len(),
    );
    say!("{}", accuracy::markdown_header(&plan));
    let points = accuracy::study_plan(&plan, ctx.as_ref(), &settings, tol, |l| {
        let _ = super::say_text(&format!("{l}\n"));
    })?;
    // Every run whose error rose with more substeps, by name: a p99 hides the run that jumps.
    let rising = points.not_converging();
    if !rising.is_empty() {
        say!(
            "not converging: {} run(s) whose error (a run's worst relative error over peak force, roof, drift, ductility and residual drift) rose above {} times the larger of its errors at the two settings before, and above {:.0e} (100 --tol, at least 1e-6):",
            rising.len(),
            accuracy::SLACK,
            accuracy::rise_floor(tol)
        );
    }
    for line in rising {
        say!("{line}");
    }
    // Where runs collapse: the collapses compared, and each one the two sides disagree on.
    for line in points.collapses() {
        say!("{line}");
    }
    let runs = plan.len();
    let measured: Vec<Measured> = points
        .verdicts()
        .into_iter()
        .map(|verdict| Measured { verdict, runs })
        .collect();
    // A statistic over no run is no figure: refused, with why, before any output is written.
    let none: Vec<String> = measured
        .iter()
        .filter(|m| m.verdict.path != "reference" && m.verdict.runs_compared == 0)
        .map(|m| {
            format!(
                "{} substeps per contact, {}: {}",
                m.verdict.substeps_per_contact,
                m.verdict.path,
                m.verdict.why_none(runs)
            )
        })
        .collect();
    if !none.is_empty() {
        bail!(
            "{}: no run could be compared with the reference, so its errors are statistics over zero runs; nothing written. {}",
            config.display(),
            none.join("; ")
        );
    }
    let figure_out = plot.as_deref().map(|p| (p, points.panels(), 2));
    super::write_and_plot(&output, points.csv().as_bytes(), figure_out, &figure)?;
    check_targets(&choices, &measured, &config, suite)
}

/// One path at one setting, as `--target-error` judges it, of a study of `runs` runs.
struct Measured {
    verdict: accuracy::Verdict,
    runs: u64,
}

impl Measured {
    /// Why this point cannot certify `target`, or None when it meets it. A failed run on either
    /// side is evidence against the target, and no compared run is no evidence for it.
    fn short_of(&self, target: f64) -> Option<String> {
        if self.verdict.failed > 0 {
            Some(format!(
                "{} of {} runs failed (here or in the reference; pound sweep shows their status)",
                self.verdict.failed, self.runs
            ))
        } else if self.verdict.collapse_differs > 0 {
            Some(format!(
                "{} of {} runs collapsed otherwise than in the reference (named above)",
                self.verdict.collapse_differs, self.runs
            ))
        } else if self.verdict.compared == 0 {
            Some(format!(
                "no run was compared (of {}, none pounded with the reference's impact count)",
                self.runs
            ))
        } else if !self.verdict.over_no_run.is_empty() {
            Some(format!(
                "the {} error is a statistic over zero runs (no run compared gives it), no evidence",
                self.verdict.over_no_run.join(", ")
            ))
        } else if self.verdict.p99.is_nan() || self.verdict.p99 > target {
            Some(format!("p99 above {target:e}"))
        } else {
            None
        }
    }
}

/// `--target-error`: each chosen setting's p99 peak-force error on every path against its
/// target; an error naming the targets missed. Met only where no run failed on either side,
/// every collapse is the reference's (building and storey), and at least one run was compared.
fn check_targets(
    choices: &[pounding::physics::solver::calibration::Choice],
    measured: &[Measured],
    config: &std::path::Path,
    suite: pounding::physics::solver::calibration::Suite,
) -> Result<()> {
    let mut missed = Vec::new();
    for c in choices {
        for m in measured.iter().filter(|m| {
            m.verdict.path != "reference"
                && m.verdict.substeps_per_contact == c.substeps_per_contact
        }) {
            let short = m.short_of(c.target);
            // Where runs collapse, the collapse time's error is in the p99 too.
            let collapses = match m.verdict.collapses_compared {
                Some(n) => format!(
                    " and the collapse time (relative to the reference's collapse time; {n} collapse(s) compared, {} run(s) whose collapse differs)",
                    m.verdict.collapse_differs
                ),
                None => String::new(),
            };
            // A statistic over zero runs is no figure: named, not printed as NaN.
            let p99 = if m.verdict.over_no_run.is_empty() {
                format!("{:.2e}", m.verdict.p99)
            } else {
                format!(
                    "none (the {} error over zero runs)",
                    m.verdict.over_no_run.join(", ")
                )
            };
            say!(
                "--target-error {:e}: {} substeps per contact, {}: {}{collapses} {p99} over {} runs compared, {} failed ({})",
                c.target,
                c.substeps_per_contact,
                m.verdict.path,
                suite.measure(),
                m.verdict.compared,
                m.verdict.failed,
                match &short {
                    None => "met".to_string(),
                    Some(why) => format!("NOT met: {why}"),
                }
            );
            if short.is_some() {
                missed.push(format!("{:e} on {}", c.target, m.verdict.path));
            }
        }
    }
    if !missed.is_empty() {
        bail!(
            "--target-error not met on {}: {}",
            config.display(),
            missed.join(", ")
        );
    }
    Ok(())
}
