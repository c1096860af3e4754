//! `pound hysteresis storey`: an IMK storey's loops under a cyclic drift protocol.

use crate::cli::{check_outputs, default_output, say_text, values_arg, write_and_plot, Holds};
use anyhow::{bail, Result};
use pounding::physics::shear::ImkRule;
use pounding::studies::hysteresis::{loops, Protocol, Storey};
use std::path::PathBuf;

/// Most amplitudes, and cycles at each, a protocol may have.
const MAX_AMPLITUDES: usize = 100;
const MAX_CYCLES: usize = 1000;

#[derive(clap::Args)]
#[command(allow_negative_numbers = true)]
pub struct Args {
    /// The hysteresis rule: imk_bilinear (OpenSees' IMKBilin) or imk_peak_oriented
    /// (IMKPeakOriented).
    #[arg(long, default_value = "imk_bilinear")]
    hysteresis: String,
    /// Yield drift ratio theta_y, in (0, 0.2].
    #[arg(long, default_value_t = 0.005)]
    yield_drift_ratio: f64,
    /// Hardening (post-yield) stiffness over the initial, b, in [0, 1).
    #[arg(long, default_value_t = 0.03)]
    post_yield_ratio: f64,
    /// Yield to capping, theta_p (> 0).
    #[arg(long, default_value_t = 0.02)]
    plastic_drift_ratio: f64,
    /// Capping to zero strength, theta_pc (> 0).
    #[arg(long, default_value_t = 0.08)]
    post_capping_drift_ratio: f64,
    /// Residual strength over the initial yield strength, kappa, in [0, 1).
    #[arg(long, default_value_t = 0.2)]
    residual_strength_ratio: f64,
    /// No strength beyond this drift ratio theta_u, from the origin, beyond the capping point
    /// (inf: none).
    #[arg(long, default_value_t = 0.15)]
    ultimate_drift_ratio: f64,
    /// Energy capacity gamma, E_t = gamma F_y theta_y h (> 0; `none`: no cyclic
    /// deterioration).
    #[arg(long, default_value = "50")]
    energy_capacity_ratio: String,
    /// Storey stiffness k, N/m (the loop in drift ratios and shear over F_y does not depend on
    /// it).
    #[arg(long, default_value_t = 2.0e7)]
    stiffness: f64,
    /// Storey height h, m (the loop in drift ratios and shear over F_y does not depend on it).
    #[arg(long, default_value_t = 3.0)]
    height: f64,
    /// growing: each of --amplitudes --cycles times; constant: --amplitude --cycles times.
    #[arg(long, default_value = "growing")]
    protocol: String,
    /// Drift ratio amplitudes of a growing protocol, a list a,b,c or start:stop:step
    /// (default 0.01,0.02,0.03,0.04).
    #[arg(long)]
    amplitudes: Option<String>,
    /// Drift ratio amplitude of a constant protocol (default 0.02).
    #[arg(long)]
    amplitude: Option<f64>,
    /// Cycles at each amplitude (default 2 growing, 10 constant).
    #[arg(long)]
    cycles: Option<usize>,
    /// Every vertex of the loops as CSV (cycle, point, drift_ratio, drift_m, shear_n,
    /// shear_over_fy, branch, strength_ratio). (default: storey-hysteresis.csv, numbered
    /// `-2`, `-3`, ... where that file exists)
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// The loops as SVG (PNG for a .png name). (default: storey-hysteresis.svg, numbered as
    /// the CSV)
    #[arg(long)]
    plot: Option<PathBuf>,
    #[command(flatten)]
    figure: crate::cli::FigureArgs,
}

pub fn run(a: Args) -> Result<()> {
    let rule = match a.hysteresis.as_str() {
        "imk_bilinear" => ImkRule::Bilinear,
        "imk_peak_oriented" => ImkRule::PeakOriented,
        other => {
            bail!("--hysteresis `{other}`: expected one of imk_bilinear, imk_peak_oriented")
        }
    };
    let energy = match a.energy_capacity_ratio.trim() {
        "none" => None,
        text => Some(text.parse::<f64>().map_err(|_| {
            anyhow::anyhow!(
                "--energy-capacity-ratio `{text}`: expected a positive number, or none (no cyclic deterioration)"
            )
        })?),
    };
    let storey = Storey {
        rule,
        stiffness: a.stiffness,
        height: a.height,
        yield_drift: a.yield_drift_ratio,
        post_yield: a.post_yield_ratio,
        plastic: a.plastic_drift_ratio,
        post_capping: a.post_capping_drift_ratio,
        residual: a.residual_strength_ratio,
        ultimate: a.ultimate_drift_ratio,
        energy,
    };
    if let Err((key, value, expected)) = storey.check() {
        bail!(
            "--{}: {} is out of range: expected {expected}",
            key.replace('_', "-"),
            pounding::plan::limits::show(value)
        );
    }
    let protocol = protocol(&a)?;
    let output = default_output(a.output.clone(), "storey-hysteresis.csv");
    let plot = default_output(a.plot.clone(), "storey-hysteresis.svg");
    check_outputs(
        &[],
        &[
            ("-o", Some(&output), Holds::Csv),
            ("--plot", Some(&plot), Holds::Plot),
        ],
    )?;
    let loops = loops(&storey, &protocol);
    say_text(&loops.markdown())?;
    write_and_plot(
        &output,
        loops.csv().as_bytes(),
        Some((&plot, vec![loops.panel()], 1)),
        &a.figure,
    )
}

/// The protocol the flags ask for, each amplitude a drift ratio in (0, 1].
fn protocol(a: &Args) -> Result<Protocol> {
    let (amplitudes, default_cycles) = match a.protocol.as_str() {
        "growing" => {
            if a.amplitude.is_some() {
                bail!("--amplitude is for --protocol constant: give a growing protocol's amplitudes with --amplitudes");
            }
            let text = a.amplitudes.as_deref().unwrap_or("0.01,0.02,0.03,0.04");
            let values = values_arg("--amplitudes", text, " (drift ratios)", MAX_AMPLITUDES, "")?;
            (values, 2)
        }
        "constant" => {
            if a.amplitudes.is_some() {
                bail!("--amplitudes is for --protocol growing: give a constant protocol's amplitude with --amplitude");
            }
            (vec![a.amplitude.unwrap_or(0.02)], 10)
        }
        other => bail!("--protocol `{other}`: expected growing or constant"),
    };
    let flag = if a.protocol == "constant" {
        "--amplitude"
    } else {
        "--amplitudes"
    };
    if let Some(bad) = amplitudes.iter().find(|x| !(**x > 0.0 && **x <= 1.0)) {
        bail!(
            "{flag}: {} is out of range: expected a drift ratio in (0, 1]",
            pounding::plan::limits::show(*bad)
        );
    }
    let cycles = a.cycles.unwrap_or(default_cycles);
    if !(1..=MAX_CYCLES).contains(&cycles) {
        bail!("--cycles: {cycles} is out of range: expected 1 to {MAX_CYCLES}");
    }
    Ok(Protocol {
        steps: amplitudes.into_iter().map(|x| (x, cycles)).collect(),
    })
}
