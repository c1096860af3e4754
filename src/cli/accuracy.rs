//! `pound accuracy`: speed against error of every path against the reference.

use super::{check_outputs, config_inputs, write_file, BackendArg};
use anyhow::{bail, Result};
use pounding::plan::config;
use pounding::plan::limits::{MAX_SUBSTEPS_PER_CONTACT, WHY_SUBSTEPS};
use pounding::studies::accuracy;
use std::io::Write as _;
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
    #[arg(short, long, default_value = "accuracy.csv")]
    output: PathBuf,
    /// Work-precision plot (SVG, or PNG for a .png name).
    #[arg(long)]
    plot: Option<PathBuf>,
    /// Check `--target-error` instead of trying --settings: for each error E, run the setting
    /// it chooses and fail unless every path's p99 peak-force error on CONFIG is at most E.
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
    } = a;
    let text = config::read_text(&config)?;
    let is_row = pounding::plan::row::is_row_config(&text);
    let suite = if is_row {
        pounding::physics::solver::calibration::Suite::Rows
    } else {
        pounding::physics::solver::calibration::Suite::Pairs
    };
    let choices = target_error
        .unwrap_or_default()
        .into_iter()
        .map(|e| super::target_error_in(suite, e))
        .collect::<Result<Vec<_>>>()?;
    let settings = if choices.is_empty() {
        settings
    } else {
        // Targets may come in any order and share a setting: each setting runs once.
        let mut s: Vec<f64> = choices.iter().map(|c| c.substeps_per_contact).collect();
        s.sort_by(f64::total_cmp);
        s.dedup();
        s
    };
    let most = MAX_SUBSTEPS_PER_CONTACT;
    if let Some(bad) = settings.iter().find(|s| !(**s >= 1.0 && **s <= most)) {
        bail!(
            "--settings: {bad} is out of range: expected substeps per contact from 1 to {most} ({WHY_SUBSTEPS})"
        );
    }
    if !(tol > 0.0 && tol < 1e-3) {
        bail!("--tol: {tol} is out of range: expected 0 < tol < 1e-3");
    }
    let records = config::input_files(&text, &config);
    check_outputs(
        &config_inputs(&config, &records),
        &[("-o", Some(&output)), ("--plot", plot.as_deref())],
    )?;
    if is_row {
        // Rows: the CPU paths only, as a table, CSV and plot.
        if backend.get() == pounding::engine::Backend::Gpu {
            bail!("--backend gpu is not available for the accuracy of rows of multi-storey buildings ([[building]] configs) yet: it compares the CPU paths");
        }
        let plan = config::load_row_text(&text, &config)?;
        note!(
            "{}: {} runs of a row; reference at tol {tol:e}, then {} settings on the CPU",
            config.display(),
            plan.len(),
            settings.len()
        );
        say!("{}", accuracy::ROW_MARKDOWN_HEADER);
        let points = accuracy::row_study(&plan, &settings, tol, |p| {
            let _ = writeln!(std::io::stdout(), "{}", accuracy::row_markdown(p));
        });
        write_file(&output, accuracy::row_csv(&points).as_bytes())?;
        if let Some(p) = plot {
            pounding::studies::plot::save(&p, &accuracy::row_panels(&points), 2)?;
        }
        let measured: Vec<(&str, f64, f64)> = points
            .iter()
            .map(|p| (p.path.as_str(), p.substeps_per_contact, p.force[1]))
            .collect();
        return check_targets(&choices, &measured, &config);
    }
    let plan = config::load_text(&text, &config)?;
    for w in plan.warnings() {
        note!("warning: {}: {w}", config.display());
    }
    let ctx = backend
        .get()
        .acquire("CPU path only", &mut |l| note!("{l}"))?;
    note!(
        "{}: {} runs; reference at tol {tol:e}, then {} settings on {} paths",
        config.display(),
        plan.len(),
        settings.len(),
        if ctx.is_some() { 3 } else { 1 }
    );
    say!("{}", accuracy::MARKDOWN_HEADER);
    let points = accuracy::study(&plan, ctx.as_ref(), &settings, tol, |p| {
        let _ = writeln!(std::io::stdout(), "{}", accuracy::markdown_row(p));
    })?;
    write_file(&output, accuracy::csv(&points).as_bytes())?;
    if let Some(p) = plot {
        pounding::studies::plot::save(&p, &accuracy::panels(&points), 2)?;
    }
    let measured: Vec<(&str, f64, f64)> = points
        .iter()
        .map(|p| (p.path.as_str(), p.substeps_per_contact, p.errors.force_p99))
        .collect();
    check_targets(&choices, &measured, &config)
}

/// `--target-error`: each chosen setting's p99 peak-force error on every path (`measured`:
/// path, setting, error) against its target; an error naming the targets missed.
fn check_targets(
    choices: &[pounding::physics::solver::calibration::Choice],
    measured: &[(&str, f64, f64)],
    config: &std::path::Path,
) -> Result<()> {
    let mut missed = Vec::new();
    for c in choices {
        for &(path, _, force_p99) in measured
            .iter()
            .filter(|(path, s, _)| *path != "reference" && *s == c.substeps_per_contact)
        {
            let met = force_p99 <= c.target;
            say!(
                "--target-error {:e}: {} substeps per contact, {path}: p99 peak-force error {force_p99:.2e} ({})",
                c.target,
                c.substeps_per_contact,
                if met { "met" } else { "NOT met" }
            );
            if !met {
                missed.push(format!("{:e} on {path}", c.target));
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
