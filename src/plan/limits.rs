//! Bounds on every size a user types, each with the reason an error quotes. They sit far beyond
//! any real study; they exist so that a typo (`tail_s = 1e12`, `--threads 100000`) is an
//! immediate, explained error instead of a hang, a crash or gigabytes of allocation.

/// Worker threads (`--threads`).
pub const MAX_THREADS: usize = 1024;
pub const WHY_THREADS: &str =
    "threads beyond the cores only add switching, and 1,024 is past the largest CPU nodes";

/// Runs per CPU task (`--chunk` on the CPU).
pub const MAX_CPU_CHUNK: usize = 1 << 20;
/// Runs per GPU chunk (`--chunk` on the GPU): a chunk's buffers are a few hundred bytes a run.
pub const MAX_GPU_CHUNK: usize = 1 << 22;
pub const WHY_CHUNK: &str =
    "a chunk is held in memory whole (CPU: 1,048,576 runs; GPU: 4,194,304 runs, about 2 GB of buffers)";

/// The shortest building period (s). Contact substeps resolve the structures' own rate: at
/// 1e-4 s a 20 s run takes about a second; far below it runs crawl.
pub const MIN_PERIOD_S: f64 = 1e-4;

/// Free vibration after the record (`run.tail_s`).
pub const MAX_TAIL_S: f64 = 3600.0;
pub const WHY_TAIL: &str = "an hour of free vibration is far past the decay of any damped building";

/// Record steps one run integrates (record plus tail).
pub const MAX_INTERVALS: u64 = 100_000_000;
pub const WHY_INTERVALS: &str =
    "the GPU counts steps in 32 bits, and 1e8 steps is 11 days of motion at 0.01 s";

/// RK4 substeps per contact duration (`run.substeps_per_contact`, `--settings`).
pub const MAX_SUBSTEPS_PER_CONTACT: f64 = 4096.0;
pub const WHY_SUBSTEPS: &str =
    "the peak-force error falls ~16x per doubling and reaches f64 round-off well before 4,096 (pound accuracy)";

/// The reference scheme's stated relative accuracy (`run.tol`, `pound accuracy --tol`): an
/// open interval. Below 1e-13 the local error test asks for less than f64 round-off.
pub const TOL_RANGE: (f64, f64) = (1e-13, 1e-2);

/// `tol` checked against [`TOL_RANGE`]: the message names what was expected.
pub fn check_tol(tol: f64) -> Result<f64, String> {
    let (lo, hi) = TOL_RANGE;
    if tol > lo && tol < hi {
        Ok(tol)
    } else {
        Err(format!("{}: expected {lo:e} < tol < {hi:e}", show(tol)))
    }
}

/// Samples of `[sample]` (`sample.n`).
pub const MAX_SAMPLES: usize = 10_000_000;
pub const WHY_SAMPLES: &str = "every sample is held in memory and crossed with the whole grid";

/// Runs in one sweep.
pub const MAX_RUNS: u64 = 1 << 53;
pub const WHY_RUNS: &str =
    "run numbers stay exact in the f64 columns of spreadsheet and dataframe readers only up to 2^53";

/// Values of `--e` for the single-collision studies.
pub const MAX_E_VALUES: usize = 10_000;

/// Gaps of `pound gap --gaps` (each is a row of the probability table, per pair and intensity).
pub const MAX_CURVE_GAPS: usize = 10_000;

/// Pixels of one PNG figure: its panels, `--size` and `--dpi` together (each within its own
/// bounds, [`crate::studies::plot::PANEL_SIZES`] and [`crate::studies::plot::DPIS`], six
/// panels of 4000x4000 px at 600 dpi asked for 3.75 gigapixels, 11 GB, and aborted). Checked
/// before a pixel is drawn. An SVG has no pixels and is not bound.
pub const MAX_FIGURE_PIXELS: u64 = 100_000_000;
pub const WHY_FIGURE_PIXELS: &str =
    "a PNG is drawn whole in memory at 3 bytes a pixel, so 100 megapixels is 300 MB; six 640x480 panels at 300 dpi, for print, are 18";

/// Runs of one `pound bench` size.
pub const MAX_BENCH_RUNS: u64 = 1_000_000_000;

/// Above this PGA (g) a sweep warns: no recorded earthquake comes close (a units mix-up?).
pub const WARN_PGA_G: f64 = 5.0;

/// A record scaled by more than this factor is named before the first run (`[intensity]
/// warn_scale_factor` sets another): scaled this far, a record keeps its own duration and
/// spectral shape, not those of an earthquake of the intensity it is scaled to.
pub const WARN_SCALE_FACTOR: f64 = 5.0;

/// A building's (or a floor's) mass, kg: the heaviest floors weigh about 1e7 kg, and a mass of
/// 1e170 kg stalled a sweep with no word.
pub const MAX_MASS_KG: f64 = 1e12;

/// The smallest coefficient of restitution (the physics' bound, listed here with the others).
pub use crate::physics::restitution::MIN_E;

/// A storey drift ratio past which a building has collapsed in the field's collapse studies
/// (FEMA P-695 uses 0.10 with P-Delta). The model has neither P-Delta nor a collapse criterion
/// yet, so a sweep counts the runs that pass it.
pub const WARN_DRIFT_RATIO: f64 = 0.10;

/// A building's height estimated from its period (m per s of period: T ~ 0.1 s per storey of
/// about 3 m). A peak displacement above it is physically absurd, and a sweep warns.
pub const HEIGHT_PER_PERIOD_M: f64 = 30.0;

/// The runs of a grid axis or range (`{ from, to, n }`): the config's own bound, listed here
/// with the others.
pub use crate::config::axis::MAX_AXIS_POINTS;

/// A number as a message shows it ([`crate::show`], beside the records that show numbers too).
pub use crate::show;

/// A row's run collapses when any storey's drift ratio reaches this, unless its config says
/// otherwise (`[run] collapse_drift_ratio`): the limit FEMA P-695 collapse studies often use
/// with P-Delta (physics.md section 10).
pub const COLLAPSE_DRIFT_RATIO: f64 = 0.10;

/// The largest gravity mass ratio a P-Delta building takes: the gravity its leaning column
/// carries over its frame's own floors' (2 or 3 in the archetypes of FEMA P-695).
pub const MAX_GRAVITY_MASS_RATIO: f64 = 10.0;

/// Periods of a response spectrum at most (each is an exact response over the whole record).
pub const MAX_PERIODS: usize = 10_000;

/// A spectrum's periods: at most [`MAX_PERIODS`], each once, each from [`MIN_PERIOD_S`] to
/// 100 s (a shorter period would take the exact response millions of steps per sample).
pub fn check_periods(periods: &[f64]) -> Result<(), String> {
    if periods.is_empty() {
        return Err("no period given".into());
    }
    if periods.len() > MAX_PERIODS {
        return Err(format!(
            "{} periods: expected at most {MAX_PERIODS}",
            periods.len()
        ));
    }
    if let Some(t) = crate::config::number_given_twice(periods) {
        return Err(format!(
            "{} s is given twice: give each period once",
            show(t)
        ));
    }
    if let Some(t) = periods
        .iter()
        .find(|t| !(**t >= MIN_PERIOD_S && **t <= 100.0))
    {
        return Err(format!(
            "{} s is out of range: expected {MIN_PERIOD_S} to 100 s",
            show(*t)
        ));
    }
    Ok(())
}
