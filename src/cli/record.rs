//! `pound record info` and `pound record spectrum`: what a record file holds.

use anyhow::{bail, Context, Result};
use pounding::record::intensity;
use pounding::record::{read_record, Format, ReadOptions, Record, Units, G};
use std::path::PathBuf;

/// A record file and how to read it.
#[derive(clap::Args)]
pub struct FileArgs {
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
    /// Read only the samples from START to END s, on the record's clock: a config's
    /// `window_s = [START, END]`, so the numbers are those a sweep scales to.
    #[arg(long, value_name = "START:END")]
    window: Option<String>,
}

impl FileArgs {
    fn read(&self) -> Result<Record> {
        let format = Format::parse(&self.format)
            .with_context(|| format!("--format `{}`: expected {}", self.format, Format::KEYS))?;
        let units = match &self.units {
            Some(u) => Some(
                Units::parse(u)
                    .with_context(|| format!("--units `{u}`: expected {}", Units::KEYS))?,
            ),
            None => None,
        };
        let window = self.window.as_deref().map(parse_window).transpose()?;
        let rec = read_record(
            &self.file,
            &ReadOptions {
                format,
                units,
                dt: self.dt,
                skip_lines: self.skip_lines,
            },
        )?;
        match (window, &self.window) {
            (Some(w), Some(text)) => rec
                .windowed(w)
                .map_err(|m| anyhow::anyhow!("--window {text}: {m}")),
            _ => Ok(rec),
        }
    }
}

/// `--window START:END` (s), the command line's `window_s = [START, END]`.
fn parse_window(text: &str) -> Result<[f64; 2]> {
    match text
        .split(':')
        .map(|x| x.trim().parse::<f64>().ok())
        .collect::<Option<Vec<_>>>()
        .as_deref()
    {
        Some(&[start, end]) if start.is_finite() && end.is_finite() => Ok([start, end]),
        _ => bail!("--window `{text}`: expected START:END in s (e.g. 0:15), as a config's window_s = [START, END]"),
    }
}

#[derive(clap::Subcommand)]
pub enum Cmd {
    /// Print npts, dt, duration, PGA, PGV, PGD and Sa at a few periods of a record file; of a
    /// folder of PEER NGA-West2 records (its `_SearchResults.csv`), the set as a CSV table.
    Info {
        #[command(flatten)]
        record: FileArgs,
    },
    /// The 5 %-damped pseudo-acceleration response spectrum Sa(T) of a record file (CSV), with
    /// PGA, PGV and PGD.
    Spectrum {
        #[command(flatten)]
        record: FileArgs,
        /// Periods, s: FROM:TO:N (N periods evenly spaced in log) or a list a,b,c.
        #[arg(long, default_value = "0.05:4:100")]
        periods: String,
        /// Damping ratio of the oscillators.
        #[arg(long, default_value_t = intensity::DEFAULT_DAMPING)]
        damping: f64,
        /// (default: spectrum.csv, numbered `-2`, `-3`, ... where that file exists)
        #[arg(short, long)]
        output: Option<PathBuf>,
        /// Sa against the period (.svg or .png).
        #[arg(long)]
        plot: Option<PathBuf>,
        #[command(flatten)]
        figure: super::FigureArgs,
    },
}

/// `--periods`: FROM:TO:N, log-spaced, or a list; each from the shortest building period
/// ([`pounding::plan::limits::MIN_PERIOD_S`]) to 100 s.
fn parse_periods(text: &str) -> Result<Vec<f64>> {
    let bad = || {
        anyhow::anyhow!(
            "--periods `{text}`: expected FROM:TO:N (N periods evenly spaced in log, e.g. 0.05:4:100) or a list a,b,c"
        )
    };
    let periods = match text.split(':').collect::<Vec<_>>()[..] {
        [a, b, n] => {
            let (a, b) = (
                a.trim().parse::<f64>().map_err(|_| bad())?,
                b.trim().parse::<f64>().map_err(|_| bad())?,
            );
            let n: usize = n.trim().parse().map_err(|_| bad())?;
            if n == 0 || n > pounding::plan::limits::MAX_PERIODS {
                bail!(
                    "--periods `{text}`: {n} periods: expected 1 to {}",
                    pounding::plan::limits::MAX_PERIODS
                );
            }
            if !(a > 0.0 && b > a) {
                bail!("--periods `{text}`: expected 0 < FROM < TO");
            }
            if n == 1 {
                // One period would be FROM alone, TO ignored without a word.
                bail!("--periods `{text}`: N = 1 gives FROM alone and ignores TO: give the one period alone (--periods {a}), or N >= 2");
            }
            intensity::log_periods(a, b, n)
        }
        [_] => text
            .split(',')
            .map(|x| x.trim().parse::<f64>().map_err(|_| bad()))
            .collect::<Result<Vec<_>>>()?,
        _ => return Err(bad()),
    };
    pounding::plan::limits::check_periods(&periods)
        .map_err(|m| anyhow::anyhow!("--periods: {m}"))?;
    Ok(periods)
}

pub fn run(cmd: Cmd) -> Result<()> {
    match cmd {
        Cmd::Info { record } => info(&record),
        Cmd::Spectrum {
            record,
            periods,
            damping,
            output,
            plot,
            figure,
        } => {
            let output = super::default_output(output, "spectrum.csv");
            let periods = parse_periods(&periods)?;
            if !(0.0..1.0).contains(&damping) {
                bail!(
                    "--damping {}: expected 0 <= damping < 1",
                    pounding::show(damping)
                );
            }
            super::check_outputs(
                &[("the record", record.file.as_path())],
                &[
                    ("-o", Some(&output), super::Holds::Csv),
                    ("--plot", plot.as_deref(), super::Holds::Plot),
                ],
            )?;
            let rec = record.read()?;
            spectrum(&rec, &periods, damping, &output, plot.as_deref(), &figure)
        }
    }
}

/// `pound record spectrum`: the CSV, the peaks on stdout (stderr with `-o -`), the plot.
fn spectrum(
    rec: &Record,
    periods: &[f64],
    damping: f64,
    output: &std::path::Path,
    plot: Option<&std::path::Path>,
    figure: &super::FigureArgs,
) -> Result<()> {
    let mut csv = String::from("period_s,sa_g,sa_m_s2,sd_m\n");
    let mut points = Vec::new();
    for o in intensity::spectrum(rec, periods, damping) {
        // Shortest round trip, in exponent form beyond ordinary magnitudes (never 300 digits).
        let show = pounding::show;
        csv.push_str(&format!(
            "{},{},{},{}\n",
            show(o.period_s),
            show(o.sa_m_s2 / G),
            show(o.sa_m_s2),
            show(o.sd_m)
        ));
        points.push((o.period_s, o.sa_m_s2 / G));
    }
    let (pgv, pgd) = intensity::pgv_pgd(rec);
    let peak = points
        .iter()
        .cloned()
        .fold((0.0, 0.0), |b, p| if p.1 > b.1 { p } else { b });
    let places = pounding::show_places;
    say!(
        "{}: PGA {} g, PGV {} m/s, PGD {} m (from rest, no baseline correction); Sa peaks at {} g at T = {} s ({} periods, {} % damping)",
        rec.name,
        places(rec.pga().value / G, 4),
        places(pgv, 4),
        places(pgd, 4),
        places(peak.1, 4),
        places(peak.0, 3),
        periods.len(),
        pounding::show_derived(100.0 * damping)
    );
    let plot = plot.map(|p| {
        let panel = pounding::studies::plot::Panel {
            title: format!(
                "{}: {} % damped spectrum",
                rec.name,
                pounding::show_derived(100.0 * damping)
            ),
            x_label: "period T (s)".into(),
            y_label: "Sa (g)".into(),
            log_x: true,
            log_y: false,
            series: vec![pounding::studies::plot::Series {
                name: "Sa".into(),
                points,
                scatter: false,
                style: None,
            }],
            y_span: None,
            ..Default::default()
        };
        (p, vec![panel], 1)
    });
    super::write_and_plot(output, csv.as_bytes(), plot, figure)
}

fn info(record: &FileArgs) -> Result<()> {
    let file = &record.file;
    let named = file.file_name().and_then(|n| n.to_str());
    if file.is_dir() || named == Some(pounding::record::set::SEARCH_RESULTS) {
        return set_info(record);
    }
    let rec = record.read()?;
    let pga = rec.pga();
    // Bounded however large or small the record's numbers are.
    let places = pounding::show_places;
    say!("file      {}", file.display());
    if let Some(w) = &record.window {
        say!("window    {w} s (the samples a config's window_s reads)");
    }
    say!("npts      {}", rec.npts());
    // A time column's dt is a difference of two times: shown as derived, not to the last ulp.
    let derived = pounding::show_derived;
    say!("dt        {} s", derived(rec.dt));
    say!("t0        {} s", derived(rec.t0));
    say!("duration  {} s", places(rec.duration(), 3));
    say!(
        "pga       {} g  ({} m/s^2, {} cm/s^2)",
        places(pga.value / G, 4),
        places(pga.value, 4),
        places(pga.value * 100.0, 1)
    );
    say!(
        "pga at    t = {} s (sample {}, value {} g)",
        places(pga.time, 3),
        pga.index,
        places(rec.accel[pga.index] / G, 4)
    );
    let (pgv, pgd) = intensity::pgv_pgd(&rec);
    say!(
        "pgv       {} m/s  (from rest, no baseline correction)",
        places(pgv, 4)
    );
    say!("pgd       {} m", places(pgd, 4));
    let sa: Vec<String> = [0.2, 0.5, 1.0, 2.0]
        .iter()
        .map(|&t| {
            format!(
                "{t} s {} g",
                places(intensity::sa(&rec, t, intensity::DEFAULT_DAMPING) / G, 4)
            )
        })
        .collect();
    say!("sa (5 %)  {}", sa.join(", "));
    let limit = pounding::plan::limits::WARN_PGA_G;
    if pga.value / G > limit {
        note!(
            "warning: {}: a PGA of {} g is above {limit} g, where no recorded earthquake reaches: are the values in {} (--units)?",
            file.display(),
            places(pga.value / G, 3),
            if pga.value / G > 100.0 { "cm/s2" } else { "m/s2 or cm/s2" }
        );
    }
    Ok(())
}

/// `pound record info DIR`: a PEER search's record set as a table (CSV on stdout), one row per
/// record and component, `record` the label its runs carry in a sweep (`[[record]] set =
/// "DIR"`), with each file's samples, step and PGA as read.
fn set_info(args: &FileArgs) -> Result<()> {
    use pounding::io::csv::quote_cell;
    use pounding::record::set::{read_set, COMPONENTS};
    if args.window.is_some() || args.dt.is_some() || args.skip_lines != 0 {
        bail!("--window, --dt and --skip-lines read one record file: give them in a set's [[record]] (window_s, dt_s, skip_lines), not to `record info` of a set");
    }
    let set = read_set(&args.file)?;
    let show = pounding::show;
    let opt = |x: Option<f64>| x.map_or(String::new(), show);
    let mut out = String::from("record,rsn,component,event,year,station,magnitude,mechanism,rjb_km,rrup_km,vs30_m_s,scale_factor,file,npts,dt_s,pga_g\n");
    for r in &set.records {
        for (c, file) in r.files.iter().enumerate() {
            let Some(file) = file else { continue };
            let rec = FileArgs {
                file: file.clone(),
                format: args.format.clone(),
                dt: None,
                units: args.units.clone(),
                skip_lines: 0,
                window: None,
            }
            .read()?;
            let cells = [
                r.label(c),
                r.rsn.to_string(),
                COMPONENTS[c].to_string(),
                r.event.clone(),
                r.year.clone(),
                r.station.clone(),
                opt(r.magnitude),
                r.mechanism.clone(),
                opt(r.rjb_km),
                opt(r.rrup_km),
                opt(r.vs30_m_s),
                opt(r.scale_factor),
                file.file_name()
                    .map_or(String::new(), |n| n.to_string_lossy().into_owned()),
                rec.npts().to_string(),
                pounding::show_derived(rec.dt),
                show(rec.pga().value / G),
            ];
            let row: Vec<String> = cells.iter().map(|c| quote_cell(c)).collect();
            out.push_str(&row.join(","));
            out.push('\n');
        }
    }
    super::say_text(&out)?;
    let files: usize = set
        .records
        .iter()
        .map(|r| r.files.iter().flatten().count())
        .sum();
    let plural =
        |n: usize, one: &str, many: &str| format!("{n} {}", if n == 1 { one } else { many });
    eprintln!(
        "{} ({}) in {}; `[[record]] set = \"...\"` runs their horizontal components (components = [...] picks) under these labels",
        plural(set.records.len(), "record", "records"),
        plural(files, "file", "files"),
        set.results.display()
    );
    Ok(())
}
