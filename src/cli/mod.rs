//! The commands of `pound`, one module each: its flags (clap) turned into ready values, the
//! library called, the outcome reported. Logic lives in the library; what stays here is
//! wording, exit paths and the order of checks (every output is checked before any work).
//! Part of the binary, not the library: it may use every library layer, and nothing uses it.

use anyhow::{bail, Context, Result};
use clap::{Subcommand, ValueEnum};
use pounding::engine::gpu::Precision;
use pounding::engine::Backend;
use std::path::Path;

/// A line on standard error that never panics (stderr may be closed or full).
macro_rules! note {
    ($($t:tt)*) => { pounding::note(format_args!($($t)*)) };
}

/// A line on standard output (standard error when an output of the command goes to standard
/// output, [`tables_on_stderr`]); a failed write is an error, not a panic.
macro_rules! say {
    ($($t:tt)*) => {
        $crate::cli::say_text(&format!("{}\n", format_args!($($t)*)))?
    };
}

/// Text (a table, with its own line ends) on standard output, or on standard error when an
/// output of the command goes to standard output ([`tables_on_stderr`]).
pub fn say_text(text: &str) -> Result<()> {
    use std::io::Write as _;
    if tables_on_stderr() {
        let _ = std::io::stderr().write_all(text.as_bytes());
        Ok(())
    } else {
        std::io::stdout()
            .write_all(text.as_bytes())
            .context("writing to standard output")
    }
}

/// Set once an output of this command is standard output (`-o -`): its tables and summaries
/// then go to standard error, so standard output holds that output alone.
static STDOUT_TAKEN: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// Does an output of this command go to standard output?
pub fn tables_on_stderr() -> bool {
    STDOUT_TAKEN.load(std::sync::atomic::Ordering::Relaxed)
}

pub mod accuracy;
pub mod bench;
pub mod demands;
pub mod formulas;
pub mod fragility;
pub mod gap;
pub mod gpu;
pub mod hysteresis;
pub mod ida;
pub mod merge;
pub mod paper;
pub mod plot;
pub mod record;
pub mod restitution;
pub mod start;
pub mod sweep;
pub mod trace;

#[derive(Subcommand)]
pub enum Cmd {
    /// Run every run of a sweep config and write one CSV row per run. A starting config:
    /// `pound init pair|row|fragility|gap|inelastic`; the config keys: README.md, "A config"; the
    /// columns with units and meanings: `pound columns CONFIG`.
    Sweep(sweep::Args),
    /// GPU adapters.
    Gpu {
        #[command(subcommand)]
        cmd: gpu::Cmd,
    },
    /// Runs per second of the CPU and GPU paths on the same sweeps, with where time goes.
    Bench(bench::Args),
    /// Speed against error of every path and accuracy setting on a benchmark sweep, against the
    /// reference solved once; on rows, each run whose error rose with the setting is named
    /// ("not converging").
    Accuracy(accuracy::Args),
    /// Impact damping zeta(e) of every formula, and `exact` per law.
    Formulas(formulas::Args),
    /// Plot an output of a results CSV against a swept parameter, one series per value of a
    /// grouping column (SVG, or PNG for a .png name).
    Plot(plot::Args),
    /// Fragility curves from a results CSV: the share of runs whose EDP exceeds each threshold
    /// at each intensity level, and a lognormal curve fitted by maximum likelihood.
    Fragility(fragility::Args),
    /// Incremental dynamic analysis from a results CSV: per record the demand against the
    /// intensity, and the 16, 50 and 84 % fractiles across records at each intensity level.
    Ida(ida::Args),
    /// One building's demands from a results CSV in the SimCenter format pelicun reads: per run
    /// each storey's peak and residual drift ratio, each floor's peak acceleration, collapse.
    Demands(demands::Args),
    /// The separation each adjacent pair of a sweep's buildings needs: exactly from the time
    /// histories (the largest closing of the uncoupled responses), and by the ABS, SRSS and DDC
    /// rules from the same peaks; their ratios, and the probability of pounding against the gap.
    Gap(gap::Args),
    /// Combine the outputs of `pound sweep --shard I/N` into one CSV, checking that they come
    /// from one sweep (same fingerprint) and hold every run exactly once.
    Merge(merge::Args),
    /// The seed paper's cheap checks: Table 1 (e from the drop heights) and Fig. 2 (zeta(e) of
    /// every formula). The rest of the reproduction: docs/paper-reproduction.md.
    Paper,
    /// Restitution fidelity: one isolated collision per damped law, formula and e; the
    /// achieved e and the energy taken out against 0.5 m_eff (1 - e^2) v0^2.
    Restitution(restitution::Args),
    /// Force against penetration through one isolated impact (the seed's Fig. 5), per e; `pound
    /// hysteresis storey`: a deteriorating (IMK) storey's loops under a cyclic drift protocol.
    Hysteresis(hysteresis::Args),
    /// One run of a sweep, whole (pairs and rows, yielding storeys included): its time
    /// history at every record step and located event (CSV, plot) and its row as the sweep
    /// writes it.
    Trace(trace::Args),
    /// Print a commented starting config that runs as is: `pound init pair > my.toml`.
    Init(start::InitArgs),
    /// The output columns of a sweep (of CONFIG, or of a pair), with units and meanings.
    Columns(start::ColumnsArgs),
    /// Ground-motion records.
    Record {
        #[command(subcommand)]
        cmd: record::Cmd,
    },
}

#[derive(Clone, Copy, PartialEq, ValueEnum)]
pub enum BackendArg {
    /// A hardware GPU if one is found, else the CPU (with a one-line notice saying why); a
    /// software adapter (lavapipe) is slower than the CPU path, so only `gpu` uses it.
    Auto,
    Gpu,
    Cpu,
}

impl BackendArg {
    pub fn get(self) -> Backend {
        match self {
            BackendArg::Auto => Backend::Auto,
            BackendArg::Gpu => Backend::Gpu,
            BackendArg::Cpu => Backend::Cpu,
        }
    }
}

#[derive(Clone, Copy, ValueEnum)]
pub enum PrecisionArg {
    F32,
    F64,
}

impl PrecisionArg {
    pub fn get(self) -> Precision {
        match self {
            PrecisionArg::F32 => Precision::F32,
            PrecisionArg::F64 => Precision::F64,
        }
    }
}

/// Check a command's outputs before it does any work: each resolves (not a directory, its
/// folder exists), can be written, is none of `inputs` and is not written twice (the files a
/// pound output writes beside it count). Returns the targets given.
pub fn check_outputs(
    inputs: &[(&str, &Path)],
    outputs: &[(&str, Option<&Path>, Holds)],
) -> Result<Vec<pounding::io::target::Target>> {
    use pounding::io::target::Target;
    let on_stdout: Vec<&str> = outputs
        .iter()
        .filter(|(_, p, _)| p.is_some_and(|p| p.as_os_str() == "-"))
        .map(|(w, _, _)| *w)
        .collect();
    if on_stdout.len() > 1 {
        bail!(
            "{} all name standard output (-): two outputs may not share one stream; give all but one a file name",
            on_stdout.join(" and ")
        );
    }
    let mut targets = Vec::new();
    for (what, p, _) in outputs {
        let Some(p) = p else { continue };
        let t = Target::resolve(what, p)?;
        t.probe(what)?;
        targets.push((*what, t));
    }
    let named: Vec<(&str, &Target)> = targets.iter().map(|(w, t)| (*w, t)).collect();
    pounding::io::target::check_outputs(inputs, &named)?;
    // After the checks that protect inputs, which say more about a wrong name.
    for (what, p, holds) in outputs {
        if let Some(p) = p {
            check_extension(what, p, *holds)?;
        }
    }
    if !on_stdout.is_empty() {
        STDOUT_TAKEN.store(true, std::sync::atomic::Ordering::Relaxed);
    }
    Ok(targets.into_iter().map(|(_, t)| t).collect())
}

/// What an output holds, for the check that its name's extension does not say otherwise.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Holds {
    Csv,
    Parquet,
    /// SVG, or PNG for a `.png` name.
    Plot,
    /// A table as text (`pound bench -o`): any name.
    Text,
}

/// An output whose extension names another format than the one written is refused: a file
/// called `x.pdf` that holds SVG, or `m.parquet` that holds CSV, misleads every reader.
pub fn check_extension(what: &str, path: &Path, holds: Holds) -> Result<()> {
    if path.as_os_str() == "-" || holds == Holds::Text {
        return Ok(());
    }
    let Some(ext) = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
    else {
        return Ok(());
    };
    let plots = ["svg", "png"];
    // `toml`: configs and damage-state files, never an output of these.
    let named = [
        "csv", "parquet", "svg", "png", "pdf", "jpg", "jpeg", "eps", "ps", "json", "xlsx", "tsv",
        "toml",
    ];
    let fits = match holds {
        Holds::Plot => plots.contains(&ext.as_str()),
        Holds::Parquet => ext == "parquet" || !named.contains(&ext.as_str()),
        Holds::Csv | Holds::Text => ext == "csv" || ext == "txt" || !named.contains(&ext.as_str()),
    };
    if !fits {
        let writes = match holds {
            Holds::Plot => "a plot as SVG, or PNG for a .png name",
            Holds::Parquet => "Parquet (--format parquet)",
            Holds::Csv | Holds::Text => "CSV",
        };
        bail!(
            "{what} {}: a .{ext} name for an output written as {writes}: give it a matching extension",
            path.display()
        );
    }
    Ok(())
}

/// The output file of a flag left at its default `name`: `name` unless a file of that name
/// exists, else the first of `stem-2.ext`, `stem-3.ext`, ... that does not, so a default never
/// replaces an earlier output (of another config or command); said on stderr.
pub fn default_output(given: Option<std::path::PathBuf>, name: &str) -> std::path::PathBuf {
    if let Some(p) = given {
        return p;
    }
    let plain = Path::new(name);
    if !plain.exists() {
        return plain.to_path_buf();
    }
    let stem = plain.file_stem().unwrap_or_default().to_string_lossy();
    let ext = plain.extension().map(|e| e.to_string_lossy().into_owned());
    let free = (2u64..)
        .map(|k| match &ext {
            Some(e) => std::path::PathBuf::from(format!("{stem}-{k}.{e}")),
            None => std::path::PathBuf::from(format!("{stem}-{k}")),
        })
        .find(|p| !p.exists() && !pounding::io::atomic::partial_path(p).exists())
        .expect("a free name");
    note!(
        "notice: {name} exists and is kept: writing {} (name the output with -o)",
        free.display()
    );
    free
}

/// Write `bytes` to `output` and, where a figure is asked for, its `panels` (`cols` a row):
/// the figure is checked first ([`FigureArgs::check`]), so one refused leaves no output behind.
pub fn write_and_plot(
    output: &Path,
    bytes: &[u8],
    plot: Option<(&Path, Vec<pounding::studies::plot::Panel>, usize)>,
    figure: &FigureArgs,
) -> Result<()> {
    if let Some((path, panels, cols)) = &plot {
        figure.check(path, panels, *cols)?;
    }
    write_file(output, bytes)?;
    if let Some((path, panels, cols)) = plot {
        save_plot(path, &panels, cols, figure)?;
    }
    Ok(())
}

/// A flag's value under its name or under its old spelling, which still works with a notice:
/// `--by` meant three things (plot's series, ida's curves, fragility's bootstrap groups) and is
/// spelled for what it does now.
pub fn renamed<T>(given: Option<T>, old: Option<T>, old_name: &str, name: &str) -> Option<T> {
    if old.is_some() {
        note!("notice: {old_name} is spelled {name} now (what it does); {old_name} still works");
    }
    given.or(old)
}

/// Write each of a study's other `tables` that `paths` asks for (by name; None: not asked).
pub fn write_tables(tables: &[(&str, String)], paths: &[(&str, Option<&Path>)]) -> Result<()> {
    for (name, path) in paths {
        let Some(path) = path else { continue };
        let (_, csv) = (tables.iter().find(|(n, _)| n == name))
            .with_context(|| format!("the study gave no {name} table"))?;
        write_file(path, csv.as_bytes())?;
    }
    Ok(())
}

/// Save a plot, saying where.
pub fn save_plot(
    path: &Path,
    panels: &[pounding::studies::plot::Panel],
    cols: usize,
    figure: &FigureArgs,
) -> Result<()> {
    figure.save(path, panels, cols)?;
    wrote(path);
    Ok(())
}

/// How a command's figure is drawn, the same flags on every command that plots.
#[derive(clap::Args, Clone, Default)]
pub struct FigureArgs {
    /// The figure's title: a one-panel figure's, or put before the first panel's own title
    /// (default: what is plotted).
    #[arg(long)]
    pub title: Option<String>,
    /// Each panel's size in pixels, WIDTHxHEIGHT (each 320 to 4000; default 640x480).
    #[arg(long, value_parser = parse_size)]
    pub size: Option<(u32, u32)>,
    /// The x-axis label (default: the quantity in words, with its unit). A unit in parentheses
    /// at its end is the axis's: a multiple of the quantity's unit scales the values to it
    /// (kN, MN for N; kJ, MJ for J; kN/m, MN/m for N/m; mm, cm for m; % for m/m; ms for s),
    /// and a base unit, (N), (J), (N/m), (m) or (m/m), is turned into kN, mm, %... as the
    /// default's is; a unit of another quantity is refused. Of several panels, a label with a
    /// unit goes to those whose quantity is in that unit (`--y-label "force (kN)"` on a trace
    /// relabels the force panels, not the displacements); one without goes to all where all
    /// hold quantities in one unit, and is refused where they do not.
    #[arg(long)]
    pub x_label: Option<String>,
    /// The y-axis label, as `--x-label`.
    #[arg(long)]
    pub y_label: Option<String>,
    /// A PNG's resolution in dots per inch, 48 to 600 (default 96): `--size` is at 96 dpi, so
    /// 300 draws the same figure with 3.125 times the pixels, text and marks scaled alike. An
    /// SVG has no resolution and is drawn at `--size`.
    #[arg(long, value_parser = clap::value_parser!(u32).range(48..=600))]
    pub dpi: Option<u32>,
}

impl FigureArgs {
    /// Save `panels` (their title and labels as asked, `cols` a row) at the size and
    /// resolution asked for.
    pub fn save(
        &self,
        path: &Path,
        panels: &[pounding::studies::plot::Panel],
        cols: usize,
    ) -> Result<()> {
        use pounding::studies::plot;
        let mut panels = panels.to_vec();
        self.apply(&mut panels)?;
        let size = self.size.unwrap_or(plot::PANEL);
        plot::save_at(
            path,
            &panels,
            cols,
            size,
            self.dpi.unwrap_or(plot::BASE_DPI),
        )?;
        Ok(())
    }
}

impl FigureArgs {
    /// Whether `panels` can be drawn into `path` as asked (labels that agree with the data,
    /// a PNG within its pixel bound), before a command writes any of its outputs: a figure
    /// refused leaves nothing behind.
    pub fn check(
        &self,
        path: &Path,
        panels: &[pounding::studies::plot::Panel],
        cols: usize,
    ) -> Result<()> {
        use pounding::studies::plot;
        self.apply(&mut panels.to_vec())?;
        if path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("png"))
        {
            plot::check_pixels(
                panels.len(),
                cols,
                self.size.unwrap_or(plot::PANEL),
                self.dpi.unwrap_or(plot::BASE_DPI),
            )
            .map_err(|m| anyhow::anyhow!("{}: cannot draw the plot: {m}", path.display()))?;
        }
        Ok(())
    }

    /// Give `panels` the title and axis labels asked for, each axis's values in its label's
    /// unit ([`pounding::studies::plot::relabel`]); Err: a label that contradicts the data. A
    /// second call changes nothing more (the panels are in the labels' units by then).
    pub fn apply(&self, panels: &mut [pounding::studies::plot::Panel]) -> Result<()> {
        use pounding::studies::plot::{relabel, Axis};
        for (flag, asked, axis) in [
            ("--x-label", &self.x_label, Axis::X),
            ("--y-label", &self.y_label, Axis::Y),
        ] {
            if let Some(l) = asked {
                relabel(panels, axis, l).map_err(|why| anyhow::anyhow!("{flag} `{l}`: {why}"))?;
            }
        }
        match (&self.title, panels) {
            (Some(t), [only]) => only.title = t.clone(),
            (Some(t), [first, ..]) => first.title = format!("{t}: {}", first.title),
            _ => {}
        }
        Ok(())
    }
}

/// `--size`: WIDTHxHEIGHT, each within [`pounding::studies::plot::PANEL_SIZES`].
pub fn parse_size(text: &str) -> std::result::Result<(u32, u32), String> {
    let range = pounding::studies::plot::PANEL_SIZES;
    let bad = || {
        format!(
            "`{text}`: expected WIDTHxHEIGHT in pixels, each {} to {}, e.g. 1200x800",
            range.start(),
            range.end()
        )
    };
    let (w, h) = text.split_once(['x', 'X']).ok_or_else(bad)?;
    let (w, h): (u32, u32) = (
        w.trim().parse().map_err(|_| bad())?,
        h.trim().parse().map_err(|_| bad())?,
    );
    if !(range.contains(&w) && range.contains(&h)) {
        return Err(bad());
    }
    Ok((w, h))
}

/// Each warning a config's plan gives, one line each on stderr, named by the config.
pub fn warn_all(config: &Path, warnings: impl IntoIterator<Item = String>) {
    for w in warnings {
        note!("warning: {}: {w}", config.display());
    }
}

/// The text of `config`, once `outputs` are checked against it and the record files it names
/// (none may replace an input).
pub fn config_checked(config: &Path, outputs: &[(&str, Option<&Path>, Holds)]) -> Result<String> {
    let text = pounding::plan::config::read_text(config)?;
    let records = pounding::plan::config::input_files(&text, config);
    check_outputs(&config_inputs(config, &records), outputs)?;
    Ok(text)
}

/// A config and the record files it names, as the inputs its outputs must not replace.
pub fn config_inputs<'a>(
    config: &'a Path,
    records: &'a [std::path::PathBuf],
) -> Vec<(&'a str, &'a Path)> {
    let mut ins: Vec<(&str, &Path)> = vec![("the config", config)];
    ins.extend(records.iter().map(|p| ("the record", p.as_path())));
    ins
}

/// Check the outputs of a study of a results file (`plot`, `fragility`) against the file, its
/// sidecar and the study's `other` inputs (a damage-state file), then warn when the results are
/// not vouched for by that sidecar.
pub fn check_study_outputs(
    results: &Path,
    other: &[(&str, &Path)],
    outputs: &[(&str, Option<&Path>, Holds)],
) -> Result<()> {
    let sidecar = pounding::io::provenance::meta_path(results);
    let mut inputs = vec![("the results", results), ("the results' sidecar", &sidecar)];
    inputs.extend_from_slice(other);
    check_outputs(&inputs, outputs)?;
    if let Some(w) = pounding::io::provenance::provenance_warning(results) {
        note!("warning: {w}");
    }
    Ok(())
}

/// Write `bytes` to `path` whole (temporary file, fsync, rename), naming the file on error.
pub fn write_file(path: &Path, bytes: &[u8]) -> Result<()> {
    pounding::io::atomic::write_atomic(path, bytes)
        .with_context(|| format!("writing {}", path.display()))?;
    wrote(path);
    Ok(())
}

/// Say that `path` was written (standard output needs no saying).
fn wrote(path: &Path) {
    if path.as_os_str() != "-" {
        note!("wrote {}", path.display());
    }
}

/// A flag's values from `text`: start:stop:step, a list a,b,c, or one value; at most `max`
/// (`why` follows that bound in the message, `unit` the expected forms).
pub fn values_arg(flag: &str, text: &str, unit: &str, max: usize, why: &str) -> Result<Vec<f64>> {
    // A range's count is checked before its values are made: `0:1e9:1` is over the bound, not
    // a syntax error.
    let parts: Vec<f64> = text
        .split(':')
        .filter_map(|x| x.trim().parse::<f64>().ok())
        .collect();
    if let [a, b, step] = parts[..] {
        let count = ((b - a) / step).floor() + 1.0;
        if step > 0.0 && b >= a && count > max as f64 {
            bail!("{flag} `{text}` gives {count:.0} values: expected at most {max}{why}");
        }
    }
    let values = if text.contains(',') {
        text.split(',')
            .map(|x| x.trim().parse::<f64>().ok())
            .collect()
    } else {
        pounding::config::parse_colon_range(text)
    }
    .with_context(|| {
        format!("{flag} `{text}`: expected start:stop:step, a list a,b,c or one value{unit}")
    })?;
    if values.len() > max {
        bail!(
            "{flag} `{text}` gives {} values: expected at most {max}{why}",
            values.len()
        );
    }
    if let Some(v) = pounding::config::number_given_twice(&values) {
        bail!(
            "{flag} `{text}`: {} is given twice: give each value once",
            pounding::plan::limits::show(v)
        );
    }
    Ok(values)
}

/// `--e`: start:stop:step, a list a,b,c, or one value; each in (0, 1].
pub fn e_values(e: &str) -> Result<Vec<f64>> {
    let es = values_arg(
        "--e",
        e,
        "",
        pounding::plan::limits::MAX_E_VALUES,
        " (each is a root-found collision)",
    )?;
    let es: Vec<f64> = es.iter().map(|e| (e * 1e12).round() / 1e12).collect();
    if let Some(bad) = es
        .iter()
        .find(|e| !pounding::physics::restitution::e_in_range(**e))
    {
        bail!(
            "--e: e = {} is out of range: expected {}",
            pounding::plan::limits::show(*bad),
            pounding::physics::restitution::E_EXPECTED
        );
    }
    Ok(es)
}

/// `--target-error E`: the cheapest calibrated accuracy setting of the fast scheme whose p99
/// peak-force error is at most `E`, said on stderr.
pub fn target_error(target: f64) -> Result<pounding::physics::solver::calibration::Choice> {
    target_error_in(pounding::physics::solver::calibration::Suite::Pairs, target)
}

/// [`target_error`] from the calibration of `suite` (pairs or rows).
pub fn target_error_in(
    suite: pounding::physics::solver::calibration::Suite,
    target: f64,
) -> Result<pounding::physics::solver::calibration::Choice> {
    let (c, said) = pounding::plan::settings::target_error_in(suite, target)?;
    note!("{said}");
    Ok(c)
}
