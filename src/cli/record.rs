//! `pound record info`: what a record file holds.

use anyhow::{Context, Result};
use pounding::record::{read_record, Format, ReadOptions, Units, G};
use std::path::PathBuf;

#[derive(clap::Subcommand)]
pub enum Cmd {
    /// Print npts, dt, duration and PGA of a record file.
    Info {
        file: PathBuf,
        /// auto, at2, values or two_column.
        #[arg(long, default_value = "auto")]
        format: String,
        /// Sample interval, s (needed for value files without a header).
        #[arg(long)]
        dt: Option<f64>,
        /// g, m/s2 or cm/s2 (default: from the header, else g).
        #[arg(long)]
        units: Option<String>,
        /// Lines to skip before parsing.
        #[arg(long, default_value_t = 0)]
        skip_lines: usize,
    },
}

pub fn run(cmd: Cmd) -> Result<()> {
    let Cmd::Info {
        file,
        format,
        dt,
        units,
        skip_lines,
    } = cmd;
    let format = Format::parse(&format)
        .with_context(|| format!("--format `{format}`: expected {}", Format::KEYS))?;
    let units = match units {
        Some(u) => Some(
            Units::parse(&u).with_context(|| format!("--units `{u}`: expected {}", Units::KEYS))?,
        ),
        None => None,
    };
    let rec = read_record(
        &file,
        &ReadOptions {
            format,
            units,
            dt,
            skip_lines,
        },
    )?;
    let pga = rec.pga();
    say!("file      {}", file.display());
    say!("npts      {}", rec.npts());
    say!("dt        {} s", rec.dt);
    say!("t0        {} s", rec.t0);
    say!("duration  {:.3} s", rec.duration());
    say!(
        "pga       {:.4} g  ({:.4} m/s^2, {:.1} cm/s^2)",
        pga.value / G,
        pga.value,
        pga.value * 100.0
    );
    say!(
        "pga at    t = {:.3} s (sample {}, value {:+.4} g)",
        pga.time,
        pga.index,
        rec.accel[pga.index] / G
    );
    let limit = pounding::plan::limits::WARN_PGA_G;
    if pga.value / G > limit {
        note!(
            "warning: {}: a PGA of {:.3} g is above {limit} g, where no recorded earthquake reaches: are the values in {} (--units)?",
            file.display(),
            pga.value / G,
            if pga.value / G > 100.0 { "cm/s2" } else { "m/s2 or cm/s2" }
        );
    }
    Ok(())
}
