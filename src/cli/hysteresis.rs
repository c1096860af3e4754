//! `pound hysteresis`: force against penetration through one isolated impact, per e; `pound
//! hysteresis storey`: an IMK storey's loops under a cyclic drift protocol ([`storey`]).

pub mod storey;

use super::{check_outputs, e_values, Holds};
use anyhow::{bail, Context, Result};
use pounding::physics::contact::LawKind;
use pounding::physics::restitution::Formula;
use pounding::studies::fidelity;
use std::path::PathBuf;

#[derive(clap::Args)]
#[command(args_conflicts_with_subcommands = true, subcommand_negates_reqs = true)]
pub struct Args {
    #[command(subcommand)]
    storey: Option<Of>,
    /// Contact law.
    #[arg(required = true)]
    law: Option<String>,
    /// Restitution formula (laws that take zeta).
    #[arg(long, default_value = "ebrahimi")]
    formula: String,
    /// Values of e: start:stop:step, a list a,b,c, or one value.
    #[arg(long, default_value = "0.3:0.9:0.2")]
    e: String,
    /// Approach speed, m/s.
    #[arg(long, default_value_t = 1.0)]
    v0: f64,
    /// k (N/m) or beta (N/m^1.5).
    #[arg(long, default_value_t = 2.75e9)]
    stiffness: f64,
    /// Effective mass m1 m2 / (m1 + m2), kg.
    #[arg(long, default_value_t = 5.0e4)]
    m_eff: f64,
    /// Loop points as CSV (e, delta_m, force_n).
    /// (default: hysteresis.csv, numbered `-2`, `-3`, ... where that file exists)
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// The loops as SVG.
    #[arg(long)]
    plot: Option<PathBuf>,
    #[command(flatten)]
    figure: super::FigureArgs,
}

/// What else the command draws the loops of.
#[derive(clap::Subcommand)]
enum Of {
    /// A deteriorating (IMK) storey's shear against its drift through a cyclic drift protocol
    /// (physics.md section 13), quasi-static: every vertex of the loops (CSV) and the loops
    /// over the undeteriorated backbone (SVG).
    Storey(Box<storey::Args>),
}

pub fn run(a: Args) -> Result<()> {
    if let Some(Of::Storey(s)) = a.storey {
        return storey::run(*s);
    }
    let law_key = a.law.clone().unwrap_or_default();
    let output = super::default_output(a.output.clone(), "hysteresis.csv");
    let law = LawKind::from_key(&law_key)
        .with_context(|| format!("law `{law_key}`: expected one of {}", LawKind::keys()))?;
    let formula = Formula::from_key(&a.formula).with_context(|| {
        format!(
            "--formula `{}`: expected one of {}",
            a.formula,
            Formula::keys()
        )
    })?;
    if !law.is_damped() {
        bail!(
            "law `{}` has no damping: its loop encloses no area",
            law.key()
        );
    }
    for (name, x) in [
        ("--v0", a.v0),
        ("--stiffness", a.stiffness),
        ("--m-eff", a.m_eff),
    ] {
        if !(x > 0.0 && x.is_finite()) {
            bail!("{name}: {x} is out of range: expected a positive number");
        }
    }
    check_outputs(
        &[],
        &[
            ("-o", Some(&output), Holds::Csv),
            ("--plot", a.plot.as_deref(), Holds::Plot),
        ],
    )?;
    let es = e_values(&a.e)?;
    let loops = fidelity::loops(law, formula, &es, a.v0, a.stiffness, a.m_eff)?;
    super::say_text(&loops.markdown())?;
    let plot = a.plot.as_deref().map(|p| (p, vec![loops.panel()], 1));
    super::write_and_plot(&output, loops.csv().as_bytes(), plot, &a.figure)
}
