//! `pound gap`: the separation each adjacent pair of a sweep's buildings needs, exactly and by
//! the code rules, with the probability of pounding against the gap.

use super::{write_file, Holds};
use anyhow::{bail, Context, Result};
use pounding::physics::separation::Rule;
use pounding::studies::gap::{GapStudy, PoundingCurve};
use std::path::PathBuf;
use std::time::Instant;

#[derive(clap::Args)]
pub struct Args {
    /// A sweep config (pair or row), whose contact and gap axes are left out: it may have no
    /// [contact] and no gaps; a gap axis of two values or more is where the probability of
    /// pounding is counted.
    config: PathBuf,
    /// One row per run: the required gap of each adjacent pair (and of each shared floor
    /// level of multi-storey buildings), the rules' gaps and their ratios to it.
    /// (default: gaps.csv, numbered `-2`, `-3`, ... where that file exists)
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Per pair: required gap and rule ratios against the period ratio, and the probability of
    /// pounding against the gap (.svg or .png).
    #[arg(long)]
    plot: Option<PathBuf>,
    #[command(flatten)]
    figure: super::FigureArgs,
    /// The share of runs that pound at each gap counted, per pair and intensity, with the
    /// fitted probability there (CSV).
    #[arg(long)]
    curve: Option<PathBuf>,
    /// Gaps (m) at which to count the share of runs that pound, for `--curve` and the figure:
    /// start:stop:step or a,b,c (default: the config's gap axis, or 21 round values up to the
    /// largest required gap). The lognormal is fitted to the runs' required gaps, whatever
    /// the gaps counted.
    #[arg(long)]
    gaps: Option<String>,
    /// Worker threads (default: all cores).
    #[arg(long)]
    threads: Option<usize>,
}

pub fn run(a: Args) -> Result<()> {
    let output = super::default_output(a.output.clone(), "gaps.csv");
    let text = super::config_checked(
        &a.config,
        &[
            ("-o", Some(&output), Holds::Csv),
            ("--plot", a.plot.as_deref(), Holds::Plot),
            ("--curve", a.curve.as_deref(), Holds::Csv),
        ],
    )?;
    let gaps = a.gaps.as_deref().map(parse_gaps).transpose()?;
    let threads = a
        .threads
        .map(pounding::plan::settings::check_threads)
        .transpose()?;
    // The study runs no contact and computes the gaps: the config may leave both out.
    let plan = GapStudy::plan_of(&text, &a.config)?;
    super::warn_all(&a.config, plan.input_warnings());
    let mut pool = rayon::ThreadPoolBuilder::new();
    if let Some(t) = threads {
        pool = pool.num_threads(t);
    }
    let pool = pool.build().context("starting worker threads")?;
    let started = Instant::now();
    let study = pool
        .install(|| GapStudy::run(&plan))
        .map_err(|e| anyhow::anyhow!("{}: {e}", a.config.display()))?;
    let seconds = started.elapsed().as_secs_f64();
    let runs = study.len();
    let threads = pool.current_num_threads();
    let rate = runs as f64 / seconds.max(1e-9);
    if study.per_run() {
        say!(
            "{runs} runs ({}: one response per run, by the row scheme; no error bound) in {seconds:.3} s on {threads} threads: {rate:.0} runs/s; {} substeps",
            if study.nears_collapse() {
                "a run nears the collapse limit, watched as the sweep watches it"
            } else {
                "yielding storeys"
            },
            study.substeps()
        );
    } else {
        say!(
            "{runs} runs ({} responses, each serving every intensity) in {seconds:.3} s on {threads} threads: {rate:.0} runs/s; {} record steps refined",
            study.responses(),
            study.refined_steps()
        );
    }
    // Collapses and failures, each run with its record and intensity (the first few).
    const LISTED: usize = 8;
    let collapsed = study.collapsed();
    if !collapsed.is_empty() {
        let list = study.run_list(&collapsed, LISTED, |o| {
            let each: Vec<String> = o
                .collapses
                .iter()
                .map(|c| format!("building {} at {:.2} s", c.building, c.time))
                .collect();
            each.join(", ")
        });
        say!(
            "{} of {runs} runs collapsed (a building's storey reached [run] collapse_drift_ratio): each pair's gaps are up to the earlier collapse of its two buildings, the required gap a lower bound (columns censored_by, censored_at_s): {list}",
            collapsed.len()
        );
    }
    let failed = study.failed();
    if !failed.is_empty() {
        let list = study.run_list(&failed, LISTED, |o| o.end.key().to_string());
        say!(
            "{} of {runs} runs ended early and are left out of every statistic (status in the CSV): {list}",
            failed.len()
        );
    }
    let summary = study.summary();
    say!("\n| pair | rule | runs | floors close | median rule / exact | p10 | p90 | unconservative |\n|---|---|---:|---:|---:|---:|---:|---:|");
    for s in &summary {
        if s.runs == 0 {
            // No statistic over zero runs.
            say!(
                "| {} | {} | 0 | 0 | no run: {} | | | |",
                study.pair_name(s.pair),
                s.rule.key().to_uppercase(),
                if s.censored > 0 {
                    "a collapse censored every run of this pair"
                } else {
                    "every run of this pair ended early"
                }
            );
            continue;
        }
        say!(
            "| {} | {} | {} | {} | {:.3} | {:.3} | {:.3} | {} ({:.1} %) |",
            study.pair_name(s.pair),
            s.rule.key().to_uppercase(),
            s.runs,
            s.closing,
            s.median,
            s.p10,
            s.p90,
            s.unconservative,
            100.0 * s.unconservative as f64 / s.runs as f64
        );
    }
    for s in summary
        .iter()
        .filter(|s| s.rule == Rule::ALL[0] && s.censored > 0)
    {
        say!(
            "Pair {}: {} runs censored by a collapse are left out of this table (a rule's gap against a lower bound of the exact one is no record of the rule).",
            study.pair_name(s.pair),
            s.censored
        );
    }
    let curves: Vec<Vec<PoundingCurve>> = (0..study.pairs())
        .map(|p| {
            let at = study.gaps_for(p, gaps.as_deref());
            let (top, need) = (at.iter().cloned().fold(0.0, f64::max), study.largest_required(p));
            if top < need {
                note!(
                    "notice: pair {}: the gaps counted end at {:.2} mm, below the largest required gap ({:.2} mm); --gaps reaches further",
                    study.pair_name(p),
                    top * 1e3,
                    need * 1e3
                );
            }
            study.pounding(p, &at)
        })
        .collect();
    say!("\n| pair | intensity | runs | floors close | median required gap (fit) | beta | gap for P(pounding) = 10 % | 5 % | 1 % |\n|---|---|---:|---:|---:|---:|---:|---:|---:|");
    for c in curves.iter().flatten() {
        let g = |p: f64| {
            c.gap_for(p)
                .map_or("".into(), |g| format!("{:.2} mm", g * 1e3))
        };
        match &c.fit {
            Ok(f) => say!(
                "| {} | {} | {} | {} | {:.2} mm | {:.3} | {} | {} | {} |",
                study.pair_name(c.pair),
                study.intensity_label(c.intensity),
                c.runs,
                c.closing,
                f.median * 1e3,
                f.beta,
                g(0.10),
                g(0.05),
                g(0.01)
            ),
            Err(e) => say!(
                "| {} | {} | {} | {} | no fit: {e} | | | | |",
                study.pair_name(c.pair),
                study.intensity_label(c.intensity),
                c.runs,
                c.closing,
            ),
        }
    }
    let censored: Vec<String> = curves
        .iter()
        .flatten()
        .filter(|c| c.censored > 0)
        .map(|c| {
            format!(
                "pair {}, {}: {}",
                study.pair_name(c.pair),
                study.intensity_label(c.intensity),
                c.censored
            )
        })
        .collect();
    if !censored.is_empty() {
        say!(
            "Runs censored by a collapse count as pounding at every gap below their lower bound and enter each fit as that bound (right-censored maximum likelihood; docs/gap-study.md): {}.",
            censored.join("; ")
        );
    }
    // The figure is checked before any output is written: one refused leaves none behind.
    let panels = a.plot.as_deref().map(|p| (p, study.panels(&curves)));
    if let Some((p, panels)) = &panels {
        a.figure.check(p, panels, 3)?;
    }
    write_file(&output, &study.csv())?;
    if let Some(p) = &a.curve {
        write_file(p, curve_csv(&study, &curves).as_bytes())?;
    }
    if let Some((p, panels)) = panels {
        super::save_plot(p, &panels, 3, &a.figure)?;
    }
    Ok(())
}

/// `--gaps`: start:stop:step, a list a,b,c, or one value; each >= 0 m.
fn parse_gaps(text: &str) -> Result<Vec<f64>> {
    let limit = pounding::plan::limits::MAX_CURVE_GAPS;
    let gaps = super::values_arg("--gaps", text, " (m)", limit, "")?;
    if let Some(bad) = gaps.iter().find(|g| !(g.is_finite() && **g >= 0.0)) {
        bail!(
            "--gaps: {} is out of range: expected gaps >= 0 m",
            pounding::plan::limits::show(*bad)
        );
    }
    Ok(gaps)
}

/// The probability of pounding per pair, intensity and gap, with the fitted curve's value.
fn curve_csv(study: &GapStudy, curves: &[Vec<PoundingCurve>]) -> String {
    let mut s = String::from("pair,intensity,gap_m,runs,pounding,share,fitted\n");
    for c in curves.iter().flatten() {
        for &(g, n, k) in &c.points {
            let fitted = match &c.fit {
                Ok(f) => format!("{}", f.pounding(g)),
                _ => String::new(),
            };
            // No share over zero runs (at a gap above every run's bound, all censored).
            let share = if n > 0 {
                format!("{}", k as f64 / n as f64)
            } else {
                String::new()
            };
            s.push_str(&format!(
                "{},{},{g},{n},{k},{share},{fitted}\n",
                study.pair_name(c.pair),
                study.intensity_label(c.intensity),
            ));
        }
    }
    s
}
