//! Fragility curves from a results CSV (`pound fragility`): at each intensity level, the share of
//! runs whose demand exceeds a threshold, and the lognormal fragility
//! `P(EDP > threshold | IM) = Phi(ln(IM / median) / beta)` fitted to the counts by maximum
//! likelihood (binomial at each level; Baker 2015), solved as a probit regression on `ln IM` by
//! Fisher scoring.
//!
//! Collapse (physics.md sections 10 and 12): a collapsed demand is taken as infinite, so it
//! exceeds every threshold and damage state (counted, not left out). Whose collapse it is follows
//! the demand ([`CollapseOf`]): a building's column (`bK_...`) collapses with building K alone
//! (its `bK_collapsed`), a column of the run (`peak_force_n`, a contact level's) with any building
//! (status `collapsed`). `--edp collapsed` ([`COLLAPSED`]) fits the run's collapse fragility
//! `P(collapse | IM)` itself, `--edp bK_collapsed` building K's: each run is 1 if it (building K)
//! collapsed, else 0 (FEMA P-695; Baker 2015). Runs of any other status but `ok` failed, and are
//! left out.

use crate::io::table::{caption, label, order_key, Filter, Table, TableError};
use crate::plan::sample::phi;
use crate::studies::damage_states::DamageStates;
use crate::studies::plot::{Panel, Series};
use crate::studies::report::{tell, StudyReport, Telling};
use std::collections::BTreeMap;

/// Runs at one intensity level.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Level {
    pub im: f64,
    pub n: u64,
    pub exceed: u64,
}

/// A fitted lognormal fragility, with standard errors from the inverse Fisher information.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fit {
    pub median: f64,
    pub beta: f64,
    /// Standard error of `ln median`.
    pub se_ln_median: f64,
    pub se_beta: f64,
    pub log_likelihood: f64,
    /// Goodness of fit: the deviance `2 (LL_saturated - LL)` against the model that gives each
    /// level its own share, with `levels - 2` degrees of freedom.
    pub deviance: f64,
    pub dof: usize,
    /// `P(chi^2_dof > deviance)`: small (say below 0.05) where the shares do not follow a
    /// lognormal curve; None with two levels (no degree of freedom left), and where
    /// [`Fit::no_power`].
    pub p_fit: Option<f64>,
    /// Every level's share is 0 or 1 (`0/n` or `n/n`): the saturated model is certain at every
    /// level, the deviance is the fit's own shortfall from certainty and no chi-square law
    /// describes it (a p near 1 would say the curve fits where the test cannot tell): no p.
    pub no_power: bool,
}

impl Fit {
    pub fn probability(&self, im: f64) -> f64 {
        phi((im / self.median).ln() / self.beta)
    }

    /// The goodness of fit's p as a table prints it: `-` with no degree of freedom, and where
    /// every level is `0/n` or `n/n` the words that say the test has no power there.
    pub fn p_text(&self) -> String {
        match self.p_fit {
            Some(p) => format!("{p:.3}"),
            None if self.no_power => NO_POWER.to_string(),
            None => "-".to_string(),
        }
    }
}

/// [`Fit::p_text`] of a fit whose levels are all `0/n` or `n/n` ([`Fit::no_power`]).
pub const NO_POWER: &str = "n/a: every level is 0/n or n/n, the test has no power";

/// Why no curve could be fitted.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum NoFit {
    #[error("no run with a value to count")]
    NoRuns,
    #[error("no run exceeds the threshold")]
    NoneExceed,
    #[error("every run exceeds the threshold")]
    AllExceed,
    #[error("only one intensity level with runs")]
    OneLevel,
    #[error("intensities must be > 0 for a lognormal fragility")]
    NonPositiveIm,
    #[error(
        "the counts separate perfectly (all below one intensity, none above): the dispersion is 0"
    )]
    Separated,
}

impl NoFit {
    /// The reason in a few words, for a legend entry (the table and the notice give it whole).
    pub fn short(&self) -> &'static str {
        match self {
            NoFit::NoRuns => "no runs",
            NoFit::NoneExceed => "none exceed",
            NoFit::AllExceed => "all exceed",
            NoFit::OneLevel => "one intensity",
            NoFit::NonPositiveIm => "intensity <= 0",
            NoFit::Separated => "counts separate perfectly",
        }
    }

    /// The reason in full for the collapse fragility, whose "threshold" is collapse itself.
    pub fn collapse(&self) -> String {
        self.collapse_of(None)
    }

    /// [`NoFit::collapse`] for the collapse of building `k` (None: of the run, any building).
    pub fn collapse_of(&self, building: Option<usize>) -> String {
        match (self, building) {
            (NoFit::NoneExceed, None) => "no run collapsed".into(),
            (NoFit::NoneExceed, Some(k)) => format!("building {k} collapsed in no run"),
            (NoFit::AllExceed, None) => "every run collapsed".into(),
            (NoFit::AllExceed, Some(k)) => format!("building {k} collapsed in every run"),
            (NoFit::Separated, _) => "the counts separate perfectly (no collapse below one intensity, all collapse above): the dispersion is 0".into(),
            (e, _) => e.to_string(),
        }
    }

    /// [`NoFit::short`] for the collapse fragility.
    pub fn short_collapse(&self) -> &'static str {
        match self {
            NoFit::NoneExceed => "none collapsed",
            NoFit::AllExceed => "all collapsed",
            e => e.short(),
        }
    }
}

/// Maximum-likelihood lognormal fragility through `levels`.
pub fn fit(levels: &[Level]) -> Result<Fit, NoFit> {
    let lv: Vec<&Level> = levels.iter().filter(|l| l.n > 0).collect();
    if lv.iter().any(|l| l.im <= 0.0) {
        return Err(NoFit::NonPositiveIm);
    }
    let (n, k): (u64, u64) = lv.iter().fold((0, 0), |(n, k), l| (n + l.n, k + l.exceed));
    if n == 0 {
        return Err(NoFit::NoRuns);
    }
    if k == 0 {
        return Err(NoFit::NoneExceed);
    }
    if k == n {
        return Err(NoFit::AllExceed);
    }
    if lv.len() < 2 {
        return Err(NoFit::OneLevel);
    }
    let x: Vec<f64> = lv.iter().map(|l| l.im.ln()).collect();
    // Start from a median at the weighted mean of ln IM and beta = its spread.
    let w: f64 = n as f64;
    let mx = lv.iter().zip(&x).map(|(l, x)| l.n as f64 * x).sum::<f64>() / w;
    let sx = (lv
        .iter()
        .zip(&x)
        .map(|(l, x)| l.n as f64 * (x - mx) * (x - mx))
        .sum::<f64>()
        / w)
        .sqrt()
        .max(1e-3);
    let (mut a, mut b) = (-mx / sx, 1.0 / sx);
    let loglik = |a: f64, b: f64| -> f64 {
        lv.iter()
            .zip(&x)
            .map(|(l, &x)| {
                let p = phi(a + b * x).clamp(1e-300, 1.0 - 1e-16);
                l.exceed as f64 * p.ln() + (l.n - l.exceed) as f64 * (1.0 - p).ln()
            })
            .sum()
    };
    let mut info = [[0.0; 2]; 2];
    for _ in 0..200 {
        // Fisher scoring: information I and score U of the probit model.
        let (mut i00, mut i01, mut i11, mut u0, mut u1) = (0.0, 0.0, 0.0, 0.0, 0.0);
        for (l, &x) in lv.iter().zip(&x) {
            let eta = a + b * x;
            let p = phi(eta).clamp(1e-15, 1.0 - 1e-15);
            let d = (-0.5 * eta * eta).exp() / (2.0 * std::f64::consts::PI).sqrt();
            let wi = l.n as f64 * d * d / (p * (1.0 - p));
            let r = (l.exceed as f64 - l.n as f64 * p) * d / (p * (1.0 - p));
            i00 += wi;
            i01 += wi * x;
            i11 += wi * x * x;
            u0 += r;
            u1 += r * x;
        }
        info = [[i00, i01], [i01, i11]];
        let det = i00 * i11 - i01 * i01;
        if !(det.is_finite() && det > 0.0) {
            return Err(NoFit::Separated);
        }
        let (mut da, mut db) = ((i11 * u0 - i01 * u1) / det, (i00 * u1 - i01 * u0) / det);
        // Halve the step until the likelihood does not fall (scoring can overshoot).
        let l0 = loglik(a, b);
        let mut halvings = 0;
        while loglik(a + da, b + db) < l0 - 1e-12 && halvings < 30 {
            da *= 0.5;
            db *= 0.5;
            halvings += 1;
        }
        a += da;
        b += db;
        if b > 1e6 || !b.is_finite() {
            return Err(NoFit::Separated);
        }
        if da.abs() < 1e-12 * (1.0 + a.abs()) && db.abs() < 1e-12 * (1.0 + b.abs()) {
            break;
        }
    }
    if b <= 0.0 {
        // Exceedance falling with intensity: not a fragility.
        return Err(NoFit::Separated);
    }
    // Covariance of (a, b) = I^-1; ln median = -a / b, beta = 1 / b (delta method).
    let det = info[0][0] * info[1][1] - info[0][1] * info[0][1];
    let (vaa, vab, vbb) = (info[1][1] / det, -info[0][1] / det, info[0][0] / det);
    let (ga, gb) = (-1.0 / b, a / (b * b));
    let var_ln_median = ga * ga * vaa + 2.0 * ga * gb * vab + gb * gb * vbb;
    let se_beta = vbb.sqrt() / (b * b);
    let log_likelihood = loglik(a, b);
    // The saturated model's likelihood: each level at its own share (0 ln 0 = 0).
    let xlny = |x: f64, y: f64| if x > 0.0 { x * y.ln() } else { 0.0 };
    let saturated: f64 = lv
        .iter()
        .map(|l| {
            let (k, n) = (l.exceed as f64, l.n as f64);
            xlny(k, k / n) + xlny(n - k, (n - k) / n)
        })
        .sum();
    let deviance = (2.0 * (saturated - log_likelihood)).max(0.0);
    let dof = lv.len() - 2;
    // Levels all 0/n or n/n in the order of a fragility (none exceeding below, all above) leave
    // the deviance test no power; out of that order (n/n below a 0/n) they reject the curve, and
    // its p says so.
    let mut by_im = lv.clone();
    by_im.sort_by(|x, y| x.im.total_cmp(&y.im));
    let in_order = by_im
        .windows(2)
        .all(|w| !(w[0].exceed == w[0].n && w[1].exceed == 0));
    let no_power = in_order && lv.iter().all(|l| l.exceed == 0 || l.exceed == l.n);
    Ok(Fit {
        median: (-a / b).exp(),
        beta: 1.0 / b,
        se_ln_median: var_ln_median.max(0.0).sqrt(),
        se_beta,
        log_likelihood,
        deviance,
        dof,
        p_fit: (dof > 0 && !no_power).then(|| chi_square_sf(deviance, dof as f64)),
        no_power,
    })
}

/// `ln Gamma(x)` for `x > 0` (Lanczos, g = 7, 9 terms: relative error near 1e-15).
fn ln_gamma(x: f64) -> f64 {
    const C: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    if x < 0.5 {
        // Reflection.
        let pi = std::f64::consts::PI;
        return (pi / (pi * x).sin()).ln() - ln_gamma(1.0 - x);
    }
    let x = x - 1.0;
    let t = x + 7.5;
    let sum = C[1..]
        .iter()
        .enumerate()
        .fold(C[0], |acc, (i, c)| acc + c / (x + 1.0 + i as f64));
    0.5 * (2.0 * std::f64::consts::PI).ln() + (x + 0.5) * t.ln() - t + sum.ln()
}

/// The survival function of the chi-square distribution, `P(chi^2_dof > x)`: the regularized
/// upper incomplete gamma `Q(dof / 2, x / 2)` (series below `s + 1`, continued fraction above;
/// Numerical Recipes 6.2).
pub fn chi_square_sf(x: f64, dof: f64) -> f64 {
    let (s, x) = (0.5 * dof, 0.5 * x);
    if x <= 0.0 {
        return 1.0;
    }
    let front = (-x + s * x.ln() - ln_gamma(s)).exp();
    if x < s + 1.0 {
        let (mut term, mut sum, mut a) = (1.0 / s, 1.0 / s, s);
        for _ in 0..10_000 {
            a += 1.0;
            term *= x / a;
            sum += term;
            if term.abs() < sum.abs() * 1e-16 {
                break;
            }
        }
        (1.0 - sum * front).clamp(0.0, 1.0)
    } else {
        // Lentz's continued fraction.
        let tiny = 1e-300;
        let mut b = x + 1.0 - s;
        let mut c = 1.0 / tiny;
        let mut d = 1.0 / b;
        let mut h = d;
        for i in 1..10_000 {
            let an = -(i as f64) * (i as f64 - s);
            b += 2.0;
            d = an * d + b;
            if d.abs() < tiny {
                d = tiny;
            }
            c = b + an / c;
            if c.abs() < tiny {
                c = tiny;
            }
            d = 1.0 / d;
            let delta = d * c;
            h *= delta;
            if (delta - 1.0).abs() < 1e-16 {
                break;
            }
        }
        (front * h).clamp(0.0, 1.0)
    }
}

/// The `--edp` of the collapse fragility: not a column, the runs' status (`collapsed` or not).
pub const COLLAPSED: &str = "collapsed";

/// The building whose column `column` is (`b2_peak_drift_ratio`, `b2_s1_residual_drift_ratio`,
/// `b2_collapsed`: 2); None for a column of the run (`peak_force_n`, a contact level's
/// `level_b1f3_b2f3_...`).
pub fn building_of(column: &str) -> Option<usize> {
    let (k, _) = column.strip_prefix('b')?.split_once('_')?;
    if k.is_empty() || !k.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    k.parse().ok().filter(|&k| k > 0)
}

/// Building K's collapse column, `bK_collapsed` (0 or 1: physics.md section 12).
pub fn collapsed_column(k: usize) -> String {
    format!("b{k}_{COLLAPSED}")
}

/// The building whose collapse fragility `--edp` names (`b2_collapsed`: 2); None for any other
/// (the run's, [`COLLAPSED`], included).
pub fn collapse_building(edp: &str) -> Option<usize> {
    building_of(edp).filter(|&k| edp == collapsed_column(k))
}

/// Whether `edp` is a collapse fragility's: the run's ([`COLLAPSED`]) or a building's
/// (`bK_collapsed`).
pub fn is_collapse_edp(edp: &str) -> bool {
    edp == COLLAPSED || collapse_building(edp).is_some()
}

/// Whose collapse makes a run's demand infinite (physics.md section 12): a building's own for a
/// building's column, any building's for a column of the run.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum CollapseOf {
    /// The run's: status `collapsed` (any building collapsed).
    Run,
    /// Building `k`'s: its `bK_collapsed` column (index `column`; None where the table has none,
    /// an output from before the per-building columns, or of `--columns` that left it out: the
    /// run's status then stands for it). `all`: the table's `bJ_collapsed` columns, which tell a
    /// collapsed run that names the building that collapsed from one whose columns were written
    /// unfilled (every one 0: the run's status then stands for them too).
    Building {
        k: usize,
        column: Option<usize>,
        all: Vec<usize>,
    },
}

impl CollapseOf {
    /// Whose collapse counts for demand `edp` of `table`.
    pub fn of(table: &Table, edp: &str) -> CollapseOf {
        match building_of(edp) {
            None => CollapseOf::Run,
            Some(k) => CollapseOf::Building {
                k,
                column: table.col(&collapsed_column(k)).ok(),
                all: (0..table.header.len())
                    .filter(|&c| collapse_building(&table.header[c]).is_some())
                    .collect(),
            },
        }
    }

    /// "collapsed", or "where building K collapsed" where the table said so for every one of
    /// them (`skipped.run_collapse` 0), after a count of runs.
    pub fn runs_collapsed(&self, skipped: &LeftOut) -> String {
        match self {
            CollapseOf::Building {
                k, column: Some(_), ..
            } if skipped.run_collapse == 0 => format!("where building {k} collapsed"),
            _ => "collapsed".into(),
        }
    }

    /// The notice for `n` runs whose demand is building K's but that were counted as collapsed
    /// by the run's status (the table does not say which building collapsed); None where there
    /// are none.
    pub fn notice(&self, n: usize, edp: &str) -> Option<String> {
        let CollapseOf::Building { k, column, .. } = self else {
            return None;
        };
        if n == 0 {
            return None;
        }
        let col = collapsed_column(*k);
        let why = match column {
            None => format!("this table has no column {col} (an output from before each building's collapse was written, or of --columns that left it out)"),
            Some(_) => "in them every bJ_collapsed of this table is 0 (columns written before they were filled, or --columns that left out the building that collapsed)".to_string(),
        };
        Some(format!(
            "notice: {n} collapsed runs (status `collapsed`) are counted as collapsed for {edp}, as the run, not building {k} alone: {why}; where {col} says whether building {k} collapsed, a run where another building collapsed counts {edp} as measured"
        ))
    }
}

/// Whether a building collapsed in row `i`: its `bK_collapsed` cell (column `c`), 0 or 1
/// (`false` or `true` from a table of booleans handed to the Python package).
fn collapsed_flag(table: &Table, i: usize, c: usize) -> Result<bool, TableError> {
    let text = table.rows[i][c].trim();
    if let Some(b) = ["false", "true"]
        .iter()
        .position(|t| text.eq_ignore_ascii_case(t))
    {
        return Ok(b == 1);
    }
    match table.num(i, c).ok().flatten() {
        Some(x) if x == 0.0 || x == 1.0 => Ok(x == 1.0),
        _ => Err(TableError::Read {
            path: table.path.clone(),
            message: format!(
                "line {}, column `{}`: `{}` is not 0 or 1 (whether the building collapsed)",
                i + 2,
                table.header[c],
                table.rows[i][c]
            ),
        }),
    }
}

/// What to count.
#[derive(Debug, Clone, PartialEq)]
pub struct FragilitySpec {
    pub im: String,
    pub edp: String,
    /// Exceedance is `EDP > threshold`.
    pub thresholds: Vec<f64>,
    pub filters: Vec<Filter>,
}

impl FragilitySpec {
    /// The collapse fragility `P(collapse | IM)`: the demand is 1 for a run that collapsed, 0 for
    /// one that did not, read against the one threshold 0.
    pub fn collapse(im: &str, filters: Vec<Filter>) -> FragilitySpec {
        FragilitySpec {
            im: im.into(),
            edp: COLLAPSED.into(),
            thresholds: vec![0.0],
            filters,
        }
    }

    /// Whether this is a collapse fragility (`--edp collapsed`, `--edp bK_collapsed`).
    pub fn is_collapse(&self) -> bool {
        is_collapse_edp(&self.edp)
    }
}

/// Whether `table` shows that its sweep had a collapse limit: a collapse column
/// ([`crate::plan::columns::row::COLLAPSE_OUTPUTS`], a building's `bK_collapsed`), or a row whose status
/// is `collapsed` (a table written with `--columns` that left the collapse columns out still
/// says so in its status). False says only that the table does not tell.
pub fn shows_collapse_limit(table: &Table) -> bool {
    has_collapse_column(table)
        || table
            .col("status")
            .is_ok_and(|c| table.rows.iter().any(|r| r[c] == "collapsed"))
}

/// Whether `table` has a column only a sweep with a collapse limit writes (the run's
/// [`crate::plan::columns::row::COLLAPSE_OUTPUTS`], or a building's `bK_collapsed`...).
fn has_collapse_column(table: &Table) -> bool {
    table.header.iter().any(|c| {
        crate::plan::columns::row::COLLAPSE_OUTPUTS.contains(&c.as_str())
            || collapse_building(c).is_some()
    })
}

/// The notice for a table with no `status` column (a sweep written with `--columns` that left
/// it out, or one made by hand): its runs that collapsed or failed cannot be told from the
/// others, so they are read by their values (a collapsed building's peak drift is its limit,
/// not a demand beyond every threshold). Said, never silent: the counts may understate.
pub fn no_status_notice(table: &Table) -> Option<String> {
    if table.col("status").is_ok() || table.rows.is_empty() {
        return None;
    }
    let collapse_columns = has_collapse_column(table);
    Some(format!(
        "notice: {} has no `status` column (a sweep written with --columns that left it out?): {}; sweep with `--columns ...,status` to count them",
        table.path.display(),
        if collapse_columns {
            "runs that failed cannot be told from the others and are read by their values"
        } else {
            "runs that collapsed or failed cannot be told from the others and are read by their values, a collapse as its peaks before it (not as exceeding every threshold)"
        }
    ))
}

/// Whether `table` can give the collapse fragility of `edp` ([`is_collapse_edp`]), or why not
/// (named). The run's (`collapsed`) needs a status column (whose `collapsed` runs it counts) and
/// a sign that the sweep had a collapse limit: a run whose status is `collapsed`, or some
/// collapse column such a sweep writes ([`crate::plan::columns::row::COLLAPSE_OUTPUTS`], or a building's
/// `bK_collapsed`); with neither, the table cannot tell a sweep whose runs could not collapse (a
/// curve of none would be no result) from one written with `--columns` that left them out, and
/// says both. Building K's needs its `bK_collapsed`: a missing one is named as missing, never
/// read as runs that did not collapse. Both need rows.
pub fn check_collapse_table(table: &Table, edp: &str) -> Result<(), TableError> {
    table.check_columns()?;
    let refuse = |message: String| {
        Err(TableError::Read {
            path: table.path.clone(),
            message,
        })
    };
    let run_columns = crate::plan::columns::row::COLLAPSE_OUTPUTS;
    let has = |c: &str| table.col(c).is_ok();
    let buildings: Vec<&str> = table
        .header
        .iter()
        .map(String::as_str)
        .filter(|c| collapse_building(c).is_some())
        .collect();
    let limit = "a sweep writes them where its runs can collapse: rows of buildings with storey heights under a collapse limit, [run] collapse_drift_ratio, default 0.10";
    // Rows whose status says they collapsed show a collapse limit whatever columns are missing:
    // the columns were left out (--columns), not the collapses.
    let status_collapsed = table.col("status").map_or(0, |c| {
        table.rows.iter().filter(|r| r[c] == "collapsed").count()
    });
    let none = |missing: &[String]| {
        format!("this table has no collapse columns ({} missing; {limit}): either its sweep had no collapse limit (a pair, or a row with collapse_drift_ratio = \"none\"), so a collapse fragility of it would be no result, or it was written with --columns that left them out (give them to --columns)", missing.join(", "))
    };
    match collapse_building(edp) {
        None => {
            if !has("status") {
                return refuse(format!(
                    "--edp {COLLAPSED} counts the runs whose status is `collapsed`, and this table has no status column (the runs of a `pound sweep` table have one; a table of --aggregate or of a study has none)"
                ));
            }
            // Any collapse column, or a run whose status is `collapsed`, shows a collapse limit:
            // the status is what is counted.
            if status_collapsed == 0 && buildings.is_empty() && !run_columns.iter().any(|c| has(c))
            {
                let mut missing: Vec<String> = run_columns.iter().map(|c| c.to_string()).collect();
                missing.push("bK_collapsed".into());
                return refuse(format!("--edp {COLLAPSED}: {}", none(&missing)));
            }
        }
        Some(k) if !has(edp) => {
            let present: Vec<&str> = run_columns.iter().copied().filter(|c| has(c)).collect();
            let why = if !buildings.is_empty() {
                format!("this table has no column {edp} (it has {}): no building {k} in its rows, or it was written with --columns that left {edp} out (give it to --columns)", buildings.join(", "))
            } else if !present.is_empty() {
                format!("this table has the run's collapse columns ({}) but no building's (bK_collapsed): an output from before each building's collapse was written, or of --columns that left them out (give {edp} to --columns); --edp {COLLAPSED} gives the run's collapse fragility (any building)", present.join(", "))
            } else if status_collapsed > 0 {
                format!("{status_collapsed} rows have status `collapsed`, but this table has no column {edp} (nor any collapse column): it was written with --columns that left them out, and the status does not say which building collapsed; rerun the sweep with {edp} in --columns, or --edp {COLLAPSED} gives the run's collapse fragility (any building) from the status")
            } else {
                let mut missing = vec![edp.to_string()];
                missing.extend(run_columns.iter().map(|c| c.to_string()));
                none(&missing)
            };
            return refuse(format!("--edp {edp}: {why}"));
        }
        Some(_) => {}
    }
    if table.rows.is_empty() {
        return refuse(format!(
            "--edp {edp}: the table has no rows: no run to count"
        ));
    }
    Ok(())
}

/// Rows a fragility count left out, by reason.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct LeftOut {
    /// Failed: `status` neither `ok` nor `collapsed`.
    pub failed: usize,
    /// An empty IM cell.
    pub empty_im: usize,
    /// An empty EDP cell (of a column that may be empty: counted apart by the caller that keeps
    /// such runs, see [`Demand::Unknown`]).
    pub empty_edp: usize,
    /// A NaN or infinite IM or EDP: neither exceeding nor not.
    pub non_finite: usize,
    /// Not left out, counted here to be reported: the runs kept that collapsed (status
    /// `collapsed`, [`Demand::Collapsed`]), which a fragility counts as exceeding every threshold
    /// and an IDA as an infinite demand. Not in [`LeftOut::total`].
    pub collapsed: usize,
    /// Of `collapsed`, the runs of a building's demand counted by the run's status, the table not
    /// saying which building collapsed ([`CollapseOf::notice`]).
    pub run_collapse: usize,
}

impl LeftOut {
    /// The rows left out (the collapsed runs, counted, are not).
    pub fn total(&self) -> usize {
        self.failed + self.empty_im + self.empty_edp + self.non_finite
    }
}

impl std::fmt::Display for LeftOut {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let parts: Vec<String> = [
            (self.failed, "failed (status neither ok nor collapsed)"),
            (self.empty_im, "no value of the intensity"),
            (self.empty_edp, "no value of the demand"),
            (self.non_finite, "a value not finite (NaN or infinite)"),
        ]
        .iter()
        .filter(|(n, _)| *n > 0)
        .map(|(n, why)| format!("{n} {why}"))
        .collect();
        write!(f, "{}", parts.join(", "))
    }
}

/// Counts per threshold and intensity level of the runs decided, and the rows left out (status
/// not `ok`, no IM or EDP value, or one that is not finite). Thresholds must be finite.
pub fn levels(
    table: &Table,
    spec: &FragilitySpec,
) -> Result<(Vec<Vec<Level>>, LeftOut), TableError> {
    let (grouped, skipped) = Grouped::read(table, spec, None)?;
    Ok((grouped.pooled(&[1]), skipped))
}

/// The intensity measure a results CSV was scaled to: its spectral target column where it has
/// one filled (`target_sa_g`, `target_sa_avg_g`), else `pga_g` (the PGA of each scaled record,
/// which is the target PGA where one was given).
pub fn default_im(table: &Table) -> String {
    ["target_sa_g", "target_sa_avg_g"]
        .into_iter()
        .find(|c| {
            table
                .col(c)
                .is_ok_and(|i| table.rows.iter().any(|r| !r[i].is_empty()))
        })
        .unwrap_or("pga_g")
        .to_string()
}

/// The column whose value bounds demand column `edp` from above, for a demand that may be empty
/// in a run that did not fail: a residual drift (`bK_residual_drift_ratio`, and a storey's signed
/// `bK_sJ_residual_drift_ratio`) is a storey's plastic drift at rest, which never exceeds the
/// largest drift the storey reached (plastic drift moves only while the storey yields, and then
/// lies between zero and the drift: docs/inelastic.md), so building K's
/// `bK_peak_drift_ratio` bounds it. None for any other column.
pub fn bounding_column(edp: &str) -> Option<String> {
    let digits = |s: &str| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit());
    let (k, suffix) = edp.strip_prefix('b')?.split_once('_')?;
    let storey = |s: &str| {
        s.strip_prefix('s')
            .and_then(|r| r.split_once('_'))
            .is_some_and(|(j, rest)| digits(j) && rest == "residual_drift_ratio")
    };
    (digits(k) && (suffix == "residual_drift_ratio" || storey(suffix)))
        .then(|| format!("b{k}_peak_drift_ratio"))
}

/// A run's demand.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Demand {
    Value(f64),
    /// The run collapsed (status `collapsed`), or for a building's demand the building did
    /// ([`CollapseOf`]): an infinite demand, above every threshold (physics.md sections 10 and
    /// 12), whatever its cells hold (its peaks end at the collapse, its residual drifts are
    /// empty).
    Collapsed,
    /// No value in a run that did not fail, of a column that may be empty there (a residual
    /// drift where the run did not settle: [`crate::engine::aggregate::may_be_empty`]): not
    /// known, but at most `bound` where the [`bounding_column`] has a finite value.
    Unknown {
        bound: Option<f64>,
    },
}

/// The rows of `table` that `filters` keep, whose status is `ok` or `collapsed` (where there is a
/// status column) and whose IM (column `ci`) and EDP (`ce`) are finite numbers: (row, intensity
/// level, EDP). A collapsed run (`collapse` says whose collapse: the run's, or the building's
/// whose demand it is) is [`Demand::Collapsed`] whatever its EDP cell holds (counted in
/// `skipped.collapsed`); with `ce` None (a collapse fragility) a run that did not collapse is
/// `Value(0)`. An empty EDP of a column that may be empty in a run that did not fail is kept as
/// [`Demand::Unknown`] (with its bound where the table has the [`bounding_column`]); an empty one
/// of another column is left out. The level is the IM rounded to 12 significant digits (CSV
/// text round-trips exactly, but scaled PGAs computed per record may differ in the last bits).
/// `skipped` counts the rest.
pub fn demand_rows(
    table: &Table,
    filters: &[Filter],
    ci: usize,
    ce: Option<usize>,
    collapse: &CollapseOf,
    skipped: &mut LeftOut,
) -> Result<Vec<(usize, f64, Demand)>, TableError> {
    let cs = table.col("status").ok();
    let edp = ce.map(|c| table.header[c].as_str());
    let may_be_empty = edp.is_some_and(crate::engine::aggregate::may_be_empty);
    let cb = edp
        .and_then(bounding_column)
        .and_then(|b| table.col(&b).ok());
    let mut out = Vec::new();
    for i in table.select(filters)? {
        let status = cs.map(|c| table.rows[i][c].as_str());
        let run_collapsed = status == Some("collapsed");
        if status.is_some_and(|s| s != "ok" && !run_collapsed) {
            skipped.failed += 1;
            continue;
        }
        let Some(im) = table.num(i, ci)? else {
            skipped.empty_im += 1;
            continue;
        };
        // Whether the demand is collapsed, and whether the run's status decided it for a
        // building's demand (the table not saying which building collapsed).
        let (collapsed, by_status) = match collapse {
            CollapseOf::Run => (run_collapsed, false),
            CollapseOf::Building {
                column: Some(c),
                all,
                ..
            } => {
                if collapsed_flag(table, i, *c)? {
                    (true, false)
                } else if run_collapsed {
                    // A collapsed run where no building says it collapsed: unfilled columns.
                    let mut named = false;
                    for &a in all {
                        named |= collapsed_flag(table, i, a)?;
                    }
                    (!named, !named)
                } else {
                    (false, false)
                }
            }
            CollapseOf::Building { column: None, .. } => (run_collapsed, run_collapsed),
        };
        let demand = match ce {
            _ if collapsed => Demand::Collapsed,
            None => Demand::Value(0.0),
            Some(ce) => match table.num(i, ce)? {
                Some(v) => Demand::Value(v),
                None if may_be_empty => {
                    let bound = cb.map(|c| table.num(i, c)).transpose()?.flatten();
                    Demand::Unknown {
                        bound: bound.filter(|b| b.is_finite()),
                    }
                }
                None => {
                    skipped.empty_edp += 1;
                    continue;
                }
            },
        };
        let finite = im.is_finite() && !matches!(demand, Demand::Value(v) if !v.is_finite());
        if !finite {
            skipped.non_finite += 1;
            continue;
        }
        skipped.collapsed += usize::from(collapsed);
        skipped.run_collapse += usize::from(by_status);
        out.push((i, crate::io::table::level(im), demand));
    }
    Ok(out)
}

/// Counts per group of runs (e.g. per record), threshold and intensity level: what a bootstrap
/// over the groups resamples.
#[derive(Debug, Clone, PartialEq)]
pub struct Grouped {
    /// The intensity levels, ascending (every group's counts use them all, with n = 0 where a
    /// group has no run at a level).
    pub ims: Vec<f64>,
    /// The groups' names (the group column's text), in order of first appearance.
    pub groups: Vec<String>,
    /// `counts[group][threshold][level]`: runs decided and exceedances among them.
    pub counts: Vec<Vec<Vec<(u64, u64)>>>,
    /// `undecided[group][threshold][level]`: runs with no value of the demand that its bound
    /// does not decide ([`Demand::Unknown`]); empty where there are none.
    pub undecided: Vec<Vec<Vec<u64>>>,
    /// Runs read (decided or not), and those among them with no value of the demand.
    pub runs: usize,
    pub unknown: usize,
    /// Per threshold: runs with no value decided by their bound (at or below the threshold).
    pub bounded: Vec<u64>,
    /// The column that bounds the demand from above, where the table has it.
    pub bound: Option<String>,
    /// Per level (over every group): the runs that collapsed, counted as exceeding every
    /// threshold ([`Demand::Collapsed`]).
    pub collapsed: Vec<u64>,
}

/// How [`Grouped::pooled_counting`] counts the undecided runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Undecided {
    /// Left out: the central estimate, on the runs decided.
    Left,
    /// All as exceeding, or all as not: the bounds.
    Exceeding,
    NotExceeding,
}

impl Grouped {
    /// The counts of `table` under `spec`, grouped by the column `group` (one group if None).
    pub fn read(
        table: &Table,
        spec: &FragilitySpec,
        group: Option<&str>,
    ) -> Result<(Grouped, LeftOut), TableError> {
        table.check_columns()?;
        if let Some(t) = spec.thresholds.iter().find(|t| !t.is_finite()) {
            return Err(TableError::Read {
                path: table.path.clone(),
                message: format!("--threshold {t}: expected a finite number (EDP > threshold is never decided by NaN or infinity)"),
            });
        }
        let ci = table.col(&spec.im)?;
        let ce = if spec.is_collapse() {
            check_collapse_table(table, &spec.edp)?;
            if spec.thresholds != [0.0] {
                return Err(TableError::Read {
                    path: table.path.clone(),
                    message: format!(
                        "--edp {} takes no threshold: a run collapsed or it did not",
                        spec.edp
                    ),
                });
            }
            None
        } else {
            Some(table.col(&spec.edp)?)
        };
        let cg = group.map(|g| table.col(g)).transpose()?;
        let mut skipped = LeftOut::default();
        let mut ims: BTreeMap<u64, f64> = BTreeMap::new();
        let mut groups: Vec<String> = Vec::new();
        let mut group_of: std::collections::HashMap<String, usize> = Default::default();
        let mut runs: Vec<(usize, u64, Demand)> = Vec::new();
        let collapse = CollapseOf::of(table, &spec.edp);
        for (i, level, demand) in
            demand_rows(table, &spec.filters, ci, ce, &collapse, &mut skipped)?
        {
            ims.insert(order_key(level), level);
            let name = cg.map_or(String::new(), |c| table.rows[i][c].clone());
            let g = *group_of.entry(name.clone()).or_insert_with(|| {
                groups.push(name);
                groups.len() - 1
            });
            runs.push((g, order_key(level), demand));
        }
        let at: BTreeMap<u64, usize> = ims.keys().enumerate().map(|(i, k)| (*k, i)).collect();
        let nt = spec.thresholds.len();
        let mut counts = vec![vec![vec![(0u64, 0u64); ims.len()]; nt]; groups.len()];
        let mut undecided = vec![vec![vec![0u64; ims.len()]; nt]; groups.len()];
        let mut bounded = vec![0u64; nt];
        let mut collapsed = vec![0u64; ims.len()];
        let unknown = runs
            .iter()
            .filter(|r| matches!(r.2, Demand::Unknown { .. }))
            .count();
        for &(g, key, demand) in &runs {
            collapsed[at[&key]] += u64::from(demand == Demand::Collapsed);
            for (t, &limit) in spec.thresholds.iter().enumerate() {
                let c = &mut counts[g][t][at[&key]];
                match demand {
                    // An infinite demand: above every threshold.
                    Demand::Collapsed => {
                        c.0 += 1;
                        c.1 += 1;
                    }
                    Demand::Value(edp) => {
                        c.0 += 1;
                        c.1 += u64::from(edp > limit);
                    }
                    // Not above its bound, so not above a limit at or above the bound.
                    Demand::Unknown { bound: Some(b) } if b <= limit => {
                        c.0 += 1;
                        bounded[t] += 1;
                    }
                    Demand::Unknown { .. } => undecided[g][t][at[&key]] += 1,
                }
            }
        }
        let grouped = Grouped {
            ims: ims.into_values().collect(),
            groups,
            counts,
            undecided: if unknown > 0 { undecided } else { Vec::new() },
            runs: runs.len(),
            unknown,
            bounded,
            bound: bounding_column(&spec.edp).filter(|b| table.col(b).is_ok()),
            collapsed,
        };
        Ok((grouped, skipped))
    }

    /// The levels per threshold when group `g` counts `weights[g]` times (a weight of 1 for
    /// every group, or `[1]` for all: the counts as read), of the runs decided.
    pub fn pooled(&self, weights: &[u32]) -> Vec<Vec<Level>> {
        self.pooled_counting(weights, Undecided::Left)
    }

    /// [`Grouped::pooled`], with the undecided runs counted as `how` says.
    pub fn pooled_counting(&self, weights: &[u32], how: Undecided) -> Vec<Vec<Level>> {
        let thresholds = self.counts.first().map_or(0, |c| c.len());
        (0..thresholds)
            .map(|t| {
                self.ims
                    .iter()
                    .enumerate()
                    .map(|(l, &im)| {
                        let (mut n, mut exceed) = (0, 0);
                        for (g, c) in self.counts.iter().enumerate() {
                            let w = u64::from(*weights.get(g).unwrap_or(&weights[0]));
                            let u = self.undecided.get(g).map_or(0, |u| u[t][l]);
                            n += w * c[t][l].0;
                            exceed += w * c[t][l].1;
                            if how != Undecided::Left {
                                n += w * u;
                            }
                            if how == Undecided::Exceeding {
                                exceed += w * u;
                            }
                        }
                        Level { im, n, exceed }
                    })
                    .filter(|l| l.n > 0)
                    .collect()
            })
            .collect()
    }

    /// Runs undecided at threshold `t`, at each level (over every group).
    pub fn undecided_at(&self, t: usize) -> Vec<u64> {
        (0..self.ims.len())
            .map(|l| self.undecided.iter().map(|u| u[t][l]).sum())
            .collect()
    }
}

/// A bootstrap over groups of runs (records): the fitted median's and beta's 5 and 95 %
/// percentiles and the curve's, pointwise, at `ims`.
#[derive(Debug, Clone, PartialEq)]
pub struct Band {
    pub median: [f64; 2],
    pub beta: [f64; 2],
    /// At each of `ims`: the 5 and 95 % percentiles of the fitted probability.
    pub ims: Vec<f64>,
    pub curve: Vec<[f64; 2]>,
    /// Replicates fitted, and those where no curve could be (left out of the band, which is
    /// then conditional on a fit: [`Band::conditional`]).
    pub fitted: usize,
    pub unfitted: usize,
    /// Of `unfitted`, how many for each reason, in the order first met.
    pub why_unfitted: Vec<(NoFit, usize)>,
}

impl Band {
    /// Whether replicates were left out: the band is then the percentiles of the replicates
    /// fitted, conditional on a fit, and not of the bootstrap distribution.
    pub fn conditional(&self) -> bool {
        self.unfitted > 0
    }
}

/// Per threshold, `replicates` bootstrap fits of `grouped` (groups drawn with replacement,
/// seeded), the band read at `ims`; None for a threshold where no replicate could be fitted.
pub fn bootstrap(
    grouped: &Grouped,
    replicates: usize,
    seed: u64,
    ims: &[f64],
) -> Vec<Option<Band>> {
    let ng = grouped.groups.len();
    let thresholds = grouped.counts.first().map_or(0, |c| c.len());
    let mut rng = crate::plan::sample::Rng::new(seed);
    let mut fits: Vec<Vec<Fit>> = vec![Vec::new(); thresholds];
    let mut unfitted = vec![0usize; thresholds];
    let mut why: Vec<Vec<(NoFit, usize)>> = vec![Vec::new(); thresholds];
    for _ in 0..replicates {
        let mut weights = vec![0u32; ng];
        for _ in 0..ng {
            weights[((rng.uniform() * ng as f64) as usize).min(ng - 1)] += 1;
        }
        for (t, lv) in grouped.pooled(&weights).iter().enumerate() {
            match fit(lv) {
                Ok(f) => fits[t].push(f),
                Err(e) => {
                    unfitted[t] += 1;
                    match why[t].iter_mut().find(|(w, _)| *w == e) {
                        Some((_, n)) => *n += 1,
                        None => why[t].push((e, 1)),
                    }
                }
            }
        }
    }
    let band = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        [quantile(&v, 0.05), quantile(&v, 0.95)]
    };
    fits.into_iter()
        .zip(unfitted)
        .zip(why)
        .map(|((f, unfitted), why_unfitted)| {
            (!f.is_empty()).then(|| Band {
                median: band(f.iter().map(|x| x.median).collect()),
                beta: band(f.iter().map(|x| x.beta).collect()),
                ims: ims.to_vec(),
                curve: ims
                    .iter()
                    .map(|&im| band(f.iter().map(|x| x.probability(im)).collect()))
                    .collect(),
                fitted: f.len(),
                unfitted,
                why_unfitted,
            })
        })
        .collect()
}

/// Where fitted curves of ascending thresholds disagree with their order, within the
/// intensities `lo..=hi`: for each pair `(i, j)`, `i < j`, the interval `(from, to)` where the
/// curve of the higher threshold `j` lies above the curve of `i`. Counts cannot do that (a run
/// above `j` is above `i`); fitted curves of different betas can. Two lognormal curves differ in
/// sign as `ln IM (1 / beta_j - 1 / beta_i) + ln m_i / beta_i - ln m_j / beta_j`, linear in
/// `ln IM`: they meet at one intensity at most, so the wrong order is one interval, on the side
/// of the meeting point where the flatter curve is the higher (of equal betas, everywhere where
/// `m_j < m_i`).
pub fn crossings(fits: &[Result<Fit, NoFit>], lo: f64, hi: f64) -> Vec<(usize, usize, f64, f64)> {
    let mut out = Vec::new();
    for (i, a) in fits.iter().enumerate() {
        for (j, b) in fits.iter().enumerate().skip(i + 1) {
            let (Ok(a), Ok(b)) = (a, b) else { continue };
            // `b` above `a` where `slope ln IM + offset > 0`.
            let slope = 1.0 / b.beta - 1.0 / a.beta;
            let offset = a.median.ln() / a.beta - b.median.ln() / b.beta;
            let (from, to) = if slope.abs() < 1e-12 * (1.0 / a.beta + 1.0 / b.beta) {
                if offset > 0.0 {
                    (lo, hi)
                } else {
                    continue;
                }
            } else {
                let meet = (-offset / slope).exp();
                if slope > 0.0 {
                    (meet.max(lo), hi)
                } else {
                    (lo, meet.min(hi))
                }
            };
            if from < to {
                out.push((i, j, from, to));
            }
        }
    }
    out
}

/// Quantile `q` of sorted values, interpolated linearly between order statistics (NaN when
/// there are none).
pub fn quantile(sorted: &[f64], q: f64) -> f64 {
    match sorted.len() {
        0 => f64::NAN,
        n => {
            let x = q * (n - 1) as f64;
            let (i, f) = (x.floor() as usize, x - x.floor());
            let next = sorted[(i + 1).min(n - 1)];
            sorted[i] + f * (next - sorted[i])
        }
    }
}

/// The counts as CSV, a row per threshold and level: the state's name (with `states`), the
/// threshold, the intensity, the runs decided, those exceeding, the runs among them that
/// collapsed (counted as exceeding), their fraction, the runs undecided (no value, not decided by
/// the bound: [`Demand::Unknown`]) and the fraction's bounds with those counted as none exceeding
/// and as all exceeding. The collapse fragility ([`FragilitySpec::is_collapse`]) has a row per
/// level: the intensity, the runs, those that collapsed and their fraction.
pub fn csv(spec: &FragilitySpec, states: Option<&[String]>, grouped: &Grouped) -> String {
    let quote = |s: &str| {
        if s.contains([',', '"', '\n', '\r']) {
            format!("\"{}\"", s.replace('"', "\"\""))
        } else {
            s.to_string()
        }
    };
    let ratio = |k: u64, n: u64| {
        if n > 0 {
            (k as f64 / n as f64).to_string()
        } else {
            String::new()
        }
    };
    let mut s = csv_header(spec, states.is_some())
        .iter()
        .map(|h| quote(h))
        .collect::<Vec<_>>()
        .join(",");
    s.push('\n');
    if spec.is_collapse() {
        for l in grouped.pooled(&[1]).first().into_iter().flatten() {
            s.push_str(&format!(
                "{},{},{},{}\n",
                l.im,
                l.n,
                l.exceed,
                ratio(l.exceed, l.n)
            ));
        }
        return s;
    }
    for (t, &limit) in spec.thresholds.iter().enumerate() {
        let undecided = grouped.undecided_at(t);
        for (l, &im) in grouped.ims.iter().enumerate() {
            let (n, k) = grouped
                .counts
                .iter()
                .fold((0, 0), |(n, k), c| (n + c[t][l].0, k + c[t][l].1));
            let u = undecided[l];
            if n + u == 0 {
                continue;
            }
            if let Some(names) = states {
                s.push_str(&quote(&names[t]));
                s.push(',');
            }
            s.push_str(&format!(
                "{},{im},{n},{k},{},{},{u},{},{}\n",
                number(limit),
                grouped.collapsed.get(l).copied().unwrap_or(0),
                ratio(k, n),
                ratio(k, n + u),
                ratio(k + u, n + u)
            ));
        }
    }
    s
}

/// The names of [`csv`]'s columns (`states`: with damage states' names).
pub fn csv_header(spec: &FragilitySpec, states: bool) -> Vec<String> {
    let im = spec.im.clone();
    fn rest<'a>(names: &'a [&'a str]) -> impl Iterator<Item = String> + 'a {
        names.iter().map(|n| n.to_string())
    }
    if spec.is_collapse() {
        return std::iter::once(im)
            .chain(rest(&["runs", "collapsed", "fraction"]))
            .collect();
    }
    let mut h: Vec<String> = Vec::new();
    if states {
        h.push("state".into());
    }
    h.push("threshold".into());
    h.push(im);
    h.extend(rest(&[
        "runs",
        "exceed",
        "collapsed",
        "fraction",
        "undecided",
        "fraction_if_none_exceed",
        "fraction_if_all_exceed",
    ]));
    h
}

/// A number as a person reads it: its shortest round-trip text, in exponent form where the
/// decimal would be long (a threshold of 1e-300 is not 300 digits).
pub fn number(x: f64) -> String {
    if x == 0.0 || !x.is_finite() || (1e-4..1e15).contains(&x.abs()) {
        x.to_string()
    } else {
        format!("{x:e}")
    }
}

/// A threshold's legend entry: `> 1 MN` for `peak_force_n` above 1e6 ([`crate::io::table::quantity`]).
pub fn threshold_name(edp: &str, t: f64) -> String {
    format!("> {}", crate::io::table::quantity(edp, t))
}

/// What a collapse fragility of `edp` gives: `P(collapse)` (the run's), `P(building K
/// collapses)`.
pub fn collapse_probability(edp: &str) -> String {
    match collapse_building(edp) {
        Some(k) => format!("P(building {k} collapses)"),
        None => "P(collapse)".into(),
    }
}

/// One panel: the observed fractions (points) and the fitted curves (lines), per threshold (the
/// collapse fragility's one curve is named `collapse`).
pub fn panel(spec: &FragilitySpec, levels: &[Vec<Level>], fits: &[Result<Fit, NoFit>]) -> Panel {
    let mut series = Vec::new();
    let (lo, hi) = levels
        .iter()
        .flatten()
        .fold((f64::INFINITY, 0.0f64), |(a, b), l| {
            (a.min(l.im), b.max(l.im))
        });
    for (k, ((t, lv), f)) in spec.thresholds.iter().zip(levels).zip(fits).enumerate() {
        // The EDP is in the title; a threshold's points and its curve share one style; a failed
        // fit says why.
        let name = if spec.is_collapse() {
            "collapse".to_string()
        } else {
            threshold_name(&spec.edp, *t)
        };
        series.push(Series {
            name: match f {
                Ok(_) => format!("{name}: observed"),
                Err(e) if spec.is_collapse() => {
                    format!("{name}: observed (no fit: {})", e.short_collapse())
                }
                Err(e) => format!("{name}: observed (no fit: {})", e.short()),
            },
            points: lv
                .iter()
                .map(|l| (l.im, l.exceed as f64 / l.n as f64))
                .collect(),
            scatter: true,
            style: Some(k),
        });
        if let Ok(f) = f {
            let n = 100;
            series.push(Series {
                name: format!("{name}: fit, median {:.3}, beta {:.3}", f.median, f.beta),
                points: (0..=n)
                    .map(|i| {
                        let im = lo + (hi - lo) * i as f64 / n as f64;
                        (im, if im > 0.0 { f.probability(im) } else { 0.0 })
                    })
                    .collect(),
                scatter: false,
                style: Some(k),
            });
        }
    }
    let (edp, im) = (
        crate::io::table::name(&spec.edp),
        crate::io::table::name(&spec.im),
    );
    let what = if spec.is_collapse() {
        collapse_probability(&spec.edp)
    } else {
        format!("P({edp} > threshold)")
    };
    Panel {
        title: match caption(&spec.filters) {
            c if c.is_empty() => format!("{what} against {im}"),
            c => format!("{what} against {im}; {c}"),
        },
        x_label: label(&spec.im),
        y_label: if let Some(k) = collapse_building(&spec.edp) {
            format!("probability of building {k}'s collapse")
        } else if spec.is_collapse() {
            "probability of collapse".into()
        } else {
            "probability of exceedance".into()
        },
        log_x: false,
        log_y: false,
        series,
        y_span: Some((0.0, 1.0)),
        ..Default::default()
    }
}

// The command's study: `pound fragility` from a table already read to the text it tells and the
// CSV it writes, so that the command line and the Python package hold none of it.

/// Bootstrap replicates at most (each refits every threshold).
pub const MAX_BOOTSTRAP: usize = 100_000;

/// Bootstrap replicates at least: a 5 % and a 95 % percentile need some replicates beyond each
/// (5 at 100), or the "90 %" band is the smallest and largest of a few draws.
pub const MIN_BOOTSTRAP: usize = 100;

/// What a fragility study counts and fits: every setting of `pound fragility` but where it
/// writes and how it draws. [`Default`] holds the command's defaults (`--edp peak_force_n`, no
/// threshold, no bootstrap).
#[derive(Debug, Clone, PartialEq)]
pub struct FragilityOptions {
    /// Intensity measure column; None: the table's [`default_im`].
    pub im: Option<String>,
    /// Demand column, or [`COLLAPSED`] for the collapse fragility.
    pub edp: String,
    /// Exceedance thresholds (EDP > threshold), as given (one of these and `damage_states`,
    /// except with [`COLLAPSED`], which takes neither).
    pub thresholds: Vec<f64>,
    /// A built-in set's name or the path of a TOML file of states ([`DamageStates::get`]).
    pub damage_states: Option<String>,
    /// Bootstrap replicates (0: no bands; else [`MIN_BOOTSTRAP`] to [`MAX_BOOTSTRAP`]).
    pub bootstrap: usize,
    /// Seed of the bootstrap draws (None: 1); only with a bootstrap.
    pub seed: Option<u64>,
    /// The column whose groups the bootstrap draws (None: `record`); only with a bootstrap.
    pub by: Option<String>,
    /// `--where` filters as typed (`COLUMN=VALUE`, `!=`, `<`, `<=`, `>`, `>=`), all kept.
    pub filters: Vec<String>,
}

impl Default for FragilityOptions {
    fn default() -> FragilityOptions {
        FragilityOptions {
            im: None,
            edp: "peak_force_n".into(),
            thresholds: Vec::new(),
            damage_states: None,
            bootstrap: 0,
            seed: None,
            by: None,
            filters: Vec::new(),
        }
    }
}

/// Why a fragility study gives no result; its text is the message `pound fragility` prints.
#[derive(Debug, thiserror::Error)]
pub enum FragilityError {
    #[error(transparent)]
    Table(#[from] TableError),
    /// A setting, or a table, that gives no result.
    #[error("{0}")]
    Refused(String),
    /// Refused after the study had told what it read (a bootstrap over fewer than two groups):
    /// `said` and `notices`, told first ([`FragilityError::tell`]), then the message.
    #[error("{message}")]
    RefusedAfter {
        message: String,
        said: String,
        notices: Vec<String>,
        notices_at: Vec<usize>,
    },
}

impl FragilityError {
    /// Tell what the study had told before it refused ([`tell`]; nothing for a refusal before).
    pub fn tell<E>(
        &self,
        say: impl FnMut(&str) -> Result<(), E>,
        note: impl FnMut(&str),
    ) -> Result<(), E> {
        match self {
            FragilityError::RefusedAfter {
                said,
                notices,
                notices_at,
                ..
            } => tell(said, notices, notices_at, say, note),
            _ => Ok(()),
        }
    }
}

/// The settings resolved before any table is read.
struct Settled {
    collapse: bool,
    states: Option<DamageStates>,
    thresholds: Vec<f64>,
    names: Vec<String>,
    by: String,
    seed: u64,
}

impl FragilityOptions {
    /// The checks of the settings alone, in `pound fragility`'s order, before any table is read
    /// (a damage-state file is read here): [`study`] makes them again first.
    pub fn check(&self) -> Result<(), FragilityError> {
        self.settle().map(|_| ())
    }

    fn settle(&self) -> Result<Settled, FragilityError> {
        let refuse = |m: String| Err(FragilityError::Refused(m));
        if self.bootstrap > MAX_BOOTSTRAP {
            return refuse(format!(
                "--bootstrap {}: expected at most {MAX_BOOTSTRAP} replicates",
                self.bootstrap
            ));
        }
        if self.bootstrap > 0 && self.bootstrap < MIN_BOOTSTRAP {
            return refuse(format!(
                "--bootstrap {}: expected 0 (no bands) or at least {MIN_BOOTSTRAP} replicates: the 90 % band is the 5 and 95 % percentiles of the replicates, which fewer cannot place",
                self.bootstrap
            ));
        }
        // Flags of the bootstrap mean nothing without it.
        for (flag, given) in [("--by", self.by.is_some()), ("--seed", self.seed.is_some())] {
            if given && self.bootstrap == 0 {
                return refuse(format!("{flag} applies to the bootstrap bands: give --bootstrap N (N >= {MIN_BOOTSTRAP}) with it, or leave {flag} out"));
            }
        }
        let collapse = is_collapse_edp(&self.edp);
        if collapse {
            let (what, which) = match collapse_building(&self.edp) {
                None => (
                    "a run collapsed (status `collapsed`)".to_string(),
                    "P(collapse | IM)".to_string(),
                ),
                Some(k) => (
                    format!("building {k} collapsed in a run ({})", self.edp),
                    format!("P(building {k} collapses | IM)"),
                ),
            };
            for (flag, given) in [
                ("--threshold", !self.thresholds.is_empty()),
                ("--damage-states", self.damage_states.is_some()),
            ] {
                if given {
                    return refuse(format!("{flag} makes no sense with --edp {}: {what} or it did not, and {which} is fitted to that; leave {flag} out, or give a demand column to --edp", self.edp));
                }
            }
        } else if self.thresholds.is_empty() && self.damage_states.is_none() {
            return refuse(format!("give --threshold T1,T2 (EDP > threshold) or --damage-states SET, or --edp {COLLAPSED} for the collapse fragility (which takes neither)"));
        }
        let states = self
            .damage_states
            .as_deref()
            .map(DamageStates::get)
            .transpose()
            .map_err(FragilityError::Refused)?;
        // Limits in another unit, or of another demand (a built-in set names its own).
        if let Some(why) = states.as_ref().and_then(|d| {
            let unit = crate::plan::meaning::meaning(&self.edp).map(|m| m.unit);
            d.unit_mismatch(&self.edp, unit)
                .or_else(|| d.demand_mismatch(&self.edp))
        }) {
            return refuse(why);
        }
        if let Some(t) = crate::config::number_given_twice(&self.thresholds) {
            return refuse(format!(
                "--threshold: {} is given twice: give each threshold once",
                number(t)
            ));
        }
        let (thresholds, names): (Vec<f64>, Vec<String>) = match &states {
            Some(d) => (d.limits(), d.states.iter().map(|s| s.0.clone()).collect()),
            None if collapse => (vec![0.0], vec!["collapse".into()]),
            None => (
                self.thresholds.clone(),
                self.thresholds.iter().map(|&t| number(t)).collect(),
            ),
        };
        Ok(Settled {
            collapse,
            states,
            thresholds,
            names,
            by: self.by.clone().unwrap_or_else(|| "record".into()),
            seed: self.seed.unwrap_or(1),
        })
    }
}

/// `pound fragility` of `table`: the counts per threshold (or damage state) and level, the
/// lognormal fits with their goodness of fit, the bootstrap bands over the groups of `by`, the
/// bounds of the runs with no value of the demand, and the notices (a poor fit, fitted curves
/// out of order, replicates with no fit, no run collapsed, a median extrapolated beyond the
/// levels run, a building's collapse read from the run's status).
pub fn study(table: &Table, o: &FragilityOptions) -> Result<StudyReport, FragilityError> {
    let Settled {
        collapse,
        states,
        thresholds,
        names,
        by,
        seed,
    } = o.settle()?;
    // Before any column is looked up: a name given twice would read the first silently.
    table.check_columns()?;
    let spec = FragilitySpec {
        im: o.im.clone().unwrap_or_else(|| default_im(table)),
        edp: o.edp.clone(),
        thresholds,
        filters: Filter::parse_all(&o.filters)?,
    };
    if collapse {
        check_collapse_table(table, &spec.edp)?;
    }
    // The intensity is a column of the table written, beside its own: one of theirs (`--im
    // runs`, `--im collapsed`) would be a column named twice, the one read for the other.
    let head = csv_header(&spec, states.is_some());
    if let Some((column, _)) = crate::io::table::duplicate_column(&head) {
        return Err(FragilityError::Refused(format!(
            "--im {}: the fragility table has its own column `{column}` ({}), which the intensity's column would name twice: give another intensity column to --im",
            spec.im,
            head.join(", ")
        )));
    }
    let group = (o.bootstrap > 0).then_some(by.as_str());
    let (grouped, skipped) = Grouped::read(table, &spec, group)?;
    let lv = grouped.pooled(&[1]);
    let runs = grouped.runs;
    if runs == 0 {
        return Err(FragilityError::Refused(format!(
            "{}: no run left to count: {}",
            table.path.display(),
            why_none(table, &spec, &o.filters, &skipped)?
        )));
    }
    let fits: Vec<_> = lv.iter().map(|l| fit(l)).collect();
    let collapsed = skipped.collapsed;
    let whose = CollapseOf::of(table, &spec.edp);
    let mut t = Telling::default();
    t.say(format_args!(
        "{runs} runs at {} levels of {}{}{}",
        grouped.ims.len(),
        spec.im,
        match (collapse, collapsed) {
            (true, _) => format!(", {collapsed} {}", whose.runs_collapsed(&skipped)),
            (false, 0) => String::new(),
            (false, _) => format!(
                ", {collapsed} {} (counted as exceeding every {}: an infinite demand)",
                whose.runs_collapsed(&skipped),
                if states.is_some() {
                    "state"
                } else {
                    "threshold"
                }
            ),
        },
        if skipped.total() > 0 {
            format!(" ({} rows left out: {skipped})", skipped.total())
        } else {
            String::new()
        }
    ));
    if let Some(n) = whose.notice(skipped.run_collapse, &spec.edp) {
        t.note(n);
    }
    if let Some(n) = no_status_notice(table) {
        t.note(n);
    }
    if grouped.ims.len() * 2 > runs && runs >= 10 {
        t.note(format_args!(
            "notice: {} takes {} values over {runs} runs: an intensity measure that differs from run to run (levels of one or two runs each) gives shares of little meaning; the level a sweep scales to is a target column (target_pga_g, target_sa_g, target_sa_avg_g)",
            spec.im,
            grouped.ims.len()
        ));
    }
    if let Some(d) = &states {
        t.say(format_args!(
            "damage states {} ({}) on {}",
            d.name, d.source, spec.edp
        ));
    }
    let (lo, hi) = (grouped.ims[0], grouped.ims[grouped.ims.len() - 1]);
    let plot_ims: Vec<f64> = (0..=100)
        .map(|i| lo + (hi - lo) * i as f64 / 100.0)
        .collect();
    let bands = if o.bootstrap > 0 {
        if grouped.groups.len() < 2 {
            return Err(FragilityError::RefusedAfter {
                message: format!(
                    "--bootstrap: the runs fall in {} group of {}: resampling needs at least two",
                    grouped.groups.len(),
                    by
                ),
                said: t.said,
                notices: t.notices,
                notices_at: t.notices_at,
            });
        }
        t.say(format_args!(
            "bootstrap: {} replicates over {} groups of {} (seed {}), 90 % bands{}",
            o.bootstrap,
            grouped.groups.len(),
            by,
            seed,
            if grouped.unknown > 0 {
                " (of the fits to the runs decided)"
            } else {
                ""
            }
        ));
        bootstrap(&grouped, o.bootstrap, seed, &plot_ims)
    } else {
        vec![None; spec.thresholds.len()]
    };
    let first = if collapse {
        collapse_probability(&spec.edp)
    } else if states.is_some() {
        format!("state ({} >)", spec.edp)
    } else {
        format!("{} >", spec.edp)
    };
    let band_head = if o.bootstrap > 0 {
        " median 90 % | beta 90 % |"
    } else {
        ""
    };
    let band_rule = if o.bootstrap > 0 { "---:|---:|" } else { "" };
    t.say(format_args!("\n| {first} | median {} | beta | se(ln median) | se(beta) | log-likelihood | deviance (dof) | p (fit) |{band_head}\n|---:|---:|---:|---:|---:|---:|---:|---:|{band_rule}", spec.im));
    let mut poor = Vec::new();
    let mut unfitted = Vec::new();
    let mut extrapolated = Vec::new();
    for (i, f) in fits.iter().enumerate() {
        let label = match &states {
            Some(_) => format!("{} ({})", names[i], number(spec.thresholds[i])),
            None => names[i].clone(),
        };
        let band = match (&bands[i], o.bootstrap > 0) {
            (Some(b), _) => {
                // A band of the replicates fitted alone says so in its cells, not only in a
                // notice: it is conditional on a fit, and narrower than the spread it stands for.
                let (of_median, of_beta) = if b.conditional() {
                    let why: Vec<String> = (b.why_unfitted.iter())
                        .map(|(e, n)| {
                            let w = if collapse {
                                e.short_collapse()
                            } else {
                                e.short()
                            };
                            format!("{n} {w}")
                        })
                        .collect();
                    unfitted.push(format!(
                        "{label}: {} of {} ({})",
                        b.unfitted,
                        b.unfitted + b.fitted,
                        why.join(", ")
                    ));
                    (
                        format!(
                            " (conditional: {} of {} replicates fitted)",
                            b.fitted,
                            b.fitted + b.unfitted
                        ),
                        " (conditional)".to_string(),
                    )
                } else {
                    (String::new(), String::new())
                };
                format!(
                    " {:.4}-{:.4}{of_median} | {:.4}-{:.4}{of_beta} |",
                    b.median[0], b.median[1], b.beta[0], b.beta[1],
                )
            }
            (None, true) => " no replicate fitted | |".into(),
            (None, false) => String::new(),
        };
        match f {
            Ok(f) => {
                t.say(format_args!(
                    "| {label} | {:.4} | {:.4} | {:.4} | {:.4} | {:.2} | {:.2} ({}) | {} |{band}",
                    f.median,
                    f.beta,
                    f.se_ln_median,
                    f.se_beta,
                    f.log_likelihood,
                    f.deviance,
                    f.dof,
                    f.p_text()
                ));
                // A median outside the levels this fit counted is read off the curve's tail.
                let (lowest, highest) = (lv[i][0].im, lv[i][lv[i].len() - 1].im);
                if f.median > highest || f.median < lowest {
                    let what = if collapse {
                        collapse_probability(&spec.edp)
                    } else if states.is_some() {
                        format!(
                            "{} ({} > {})",
                            names[i],
                            spec.edp,
                            number(spec.thresholds[i])
                        )
                    } else {
                        format!("{} > {}", spec.edp, names[i])
                    };
                    extrapolated.push((what, f.median, lowest, highest));
                }
                if f.p_fit.is_some_and(|p| p < 0.05) {
                    poor.push(label);
                }
            }
            Err(e) if collapse => t.say(format_args!(
                "| {label} | no fit: {} | | | | | | |{band}",
                e.collapse_of(collapse_building(&spec.edp))
            )),
            Err(e) => t.say(format_args!("| {label} | no fit: {e} | | | | | | |{band}")),
        }
    }
    for (what, median, lowest, highest) in extrapolated {
        let q = |x: f64| crate::io::table::quantity(&spec.im, x);
        let (side, end, beyond) = if median > highest {
            ("ends", highest, "above the highest")
        } else {
            ("starts", lowest, "below the lowest")
        };
        t.note(format_args!(
            "notice: the fitted median of {what} is {} from a ladder of {} that {side} at {}: extrapolated, read off the fitted curve {beyond} level run, where no run bracketed it; read it with care, or run levels that reach it",
            q(median),
            spec.im,
            q(end)
        ));
    }
    if collapse && collapsed == 0 {
        let (none, p) = match collapse_building(&spec.edp) {
            Some(k) => (
                format!("building {k} collapsed in no run"),
                format!("P(building {k} collapses | IM)"),
            ),
            None => (
                "no run collapsed".to_string(),
                "P(collapse | IM)".to_string(),
            ),
        };
        t.note(format_args!(
            "notice: {none} (of {runs}, at {} levels of {} up to {}): {p} has no fit; a collapse fragility needs runs that collapse, at intensities higher than these or with a lower [run] collapse_drift_ratio",
            grouped.ims.len(),
            spec.im,
            hi
        ));
    }
    if !unfitted.is_empty() {
        t.note(format_args!(
            "notice: the 90 % bands marked conditional are the percentiles of the bootstrap replicates that could be fitted, not of all: replicates with no fit were left out, {}. A replicate with no fit is an extreme draw of the {by} groups (a median beyond the levels run, where none or every run exceeds, or a dispersion of 0, where the counts separate), so a band of the others is narrower than the uncertainty it stands for: read it as a lower bound on that spread, or add {by} groups or levels (docs/fragility.md, \"Bootstrap bands\")",
            unfitted.join("; ")
        ));
    }
    if !poor.is_empty() {
        t.note(format_args!(
            "notice: the shares above {} do not follow a lognormal curve (goodness of fit p < 0.05): the deviance against each level's own share is larger than chance allows; read the fitted median and beta with care",
            poor.join(", ")
        ));
    }
    // The severer of two thresholds is the larger, in whatever order --threshold gave them.
    let mut order: Vec<usize> = (0..fits.len()).collect();
    order.sort_by(|&x, &y| spec.thresholds[x].total_cmp(&spec.thresholds[y]));
    let ascending: Vec<_> = order.iter().map(|&k| fits[k].clone()).collect();
    for (i, j, from, to) in crossings(&ascending, lo, hi) {
        let (i, j) = (order[i], order[j]);
        // The wrong order is one interval of the levels' range (two lognormal curves meet once
        // at most): name it, and where the curves are in order.
        let outside = match (from > lo, to < hi) {
            (false, false) => "no level run is free of it: read them with care".to_string(),
            (false, true) => format!("read them only above {to:.4}"),
            (true, false) => format!("read them only below {from:.4}"),
            (true, true) => "read them only outside it".to_string(),
        };
        t.note(format_args!(
            "notice: the fitted curves of {} and {} are out of order from {} = {from:.4} to {to:.4}: there the more severe ({}) is the more probable, which no run can be (every run above {} is above {}); the curves are kept as fitted: {outside}, or fit with more runs",
            names[i], names[j], spec.im, names[j], number(spec.thresholds[j]), number(spec.thresholds[i])
        ));
    }
    if grouped.unknown > 0 {
        undecided_table(&mut t, &grouped, &spec, states.as_ref().map(|_| &names[..]));
    }
    let state_names = states.as_ref().map(|_| names.as_slice());
    let mut pl = panel(&spec, &lv, &fits);
    if states.is_some() {
        for s in &mut pl.series {
            for (n, limit) in names.iter().zip(&spec.thresholds) {
                let threshold = threshold_name(&spec.edp, *limit);
                if let Some(rest) = s.name.strip_prefix(&format!("{threshold}:")) {
                    s.name = format!("{n} ({threshold}):{rest}");
                }
            }
        }
    }
    for b in bands.iter().flatten() {
        pl.series.extend(band_series(b));
    }
    if bands.iter().flatten().any(Band::conditional) {
        pl.title
            .push_str(" (grey: 90 % bands, conditional on a fit: some replicates left out)");
    } else if bands.iter().any(|b| b.is_some()) {
        pl.title.push_str(" (grey: 90 % bands)");
    }
    Ok(StudyReport {
        csv: csv(&spec, state_names, &grouped),
        said: t.said,
        notices: t.notices,
        notices_at: t.notices_at,
        panels: vec![pl],
    })
}

/// A bootstrap band as two grey lines (unnamed: no legend entry).
fn band_series(b: &Band) -> [Series; 2] {
    [0, 1].map(|k| Series {
        name: String::new(),
        points: b
            .ims
            .iter()
            .zip(&b.curve)
            .map(|(&im, c)| (im, c[k]))
            .collect(),
        scatter: false,
        style: None,
    })
}

/// Why no run was left to count, naming the cause: `--where` keeping no row, every run failed,
/// the intensity or the demand column empty in every row (an intensity the sweep was not scaled
/// to), values not finite.
fn why_none(
    table: &Table,
    spec: &FragilitySpec,
    filters: &[String],
    skipped: &LeftOut,
) -> Result<String, TableError> {
    let rows = table.rows.len();
    let kept = table.select(&spec.filters)?.len();
    if rows == 0 {
        return Ok("the file has no rows".into());
    }
    if kept == 0 {
        return Ok(format!(
            "--where {} keeps none of its {rows} rows",
            filters.join(" --where ")
        ));
    }
    let mut why = Vec::new();
    if kept < rows {
        why.push(format!("--where keeps {kept} of {rows} rows"));
    }
    if skipped.failed > 0 {
        why.push(format!(
            "{} failed (status neither ok nor collapsed)",
            skipped.failed
        ));
    }
    let empty_everywhere = |c: &str| {
        table
            .col(c)
            .is_ok_and(|i| table.rows.iter().all(|r| r[i].trim().is_empty()))
    };
    if skipped.empty_im > 0 {
        let mut w = format!("{} have no value of --im {}", skipped.empty_im, spec.im);
        if empty_everywhere(&spec.im) {
            w.push_str(&format!(
                " (empty in every row: not an intensity this sweep was scaled to; it has {})",
                default_im(table)
            ));
        }
        why.push(w);
    }
    if skipped.empty_edp > 0 {
        let mut w = format!("{} have no value of --edp {}", skipped.empty_edp, spec.edp);
        if empty_everywhere(&spec.edp) {
            w.push_str(" (empty in every row)");
        }
        why.push(w);
    }
    if skipped.non_finite > 0 {
        why.push(format!(
            "{} have a value not finite (NaN or infinite)",
            skipped.non_finite
        ));
    }
    Ok(format!("of {kept} rows, {}", why.join(", ")))
}

/// The runs with no value of the demand (a residual drift where the run did not settle): how
/// many each threshold decides by the bounding column, how many stay undecided, and the fit
/// with those counted as none exceeding and as all exceeding, which bound the fit to the runs
/// decided.
fn undecided_table(
    t: &mut Telling,
    grouped: &Grouped,
    spec: &FragilitySpec,
    states: Option<&[String]>,
) {
    let decided = match &grouped.bound {
        Some(b) => format!("; {b} decides those at or below a threshold as not exceeding it (a residual drift never exceeds the peak drift)"),
        None => ", and no column of this file bounds it: each is undecided".into(),
    };
    t.say(format_args!(
        "\n{} runs have no value of {} (the run did not settle){decided}. The fits above are to the runs decided; the undecided, counted as none exceeding and as all exceeding, bound them:",
        grouped.unknown,
        spec.edp
    ));
    t.say(format_args!("\n| {} > | decided by the bound | undecided | median if none exceed | beta | median if all exceed | beta |\n|---:|---:|---:|---:|---:|---:|---:|", spec.edp));
    let none = grouped.pooled_counting(&[1], Undecided::NotExceeding);
    let all = grouped.pooled_counting(&[1], Undecided::Exceeding);
    let show = |lv: &[Level]| match fit(lv) {
        Ok(f) => format!("{:.4} | {:.4}", f.median, f.beta),
        Err(e) => format!("no fit: {e} |"),
    };
    for (k, &limit) in spec.thresholds.iter().enumerate() {
        let label = match states {
            Some(n) => format!("{} ({})", n[k], number(limit)),
            None => number(limit),
        };
        let undecided: u64 = grouped.undecided_at(k).iter().sum();
        t.say(format_args!(
            "| {label} | {} | {undecided} | {} | {} |",
            grouped.bounded[k],
            show(&none[k]),
            show(&all[k])
        ));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Groups of `(n, exceed)` per level at `ims`, one threshold.
    fn grouped(ims: &[f64], groups: &[Vec<(u64, u64)>]) -> Grouped {
        Grouped {
            ims: ims.to_vec(),
            groups: (0..groups.len()).map(|g| format!("r{g}")).collect(),
            counts: groups.iter().map(|c| vec![c.clone()]).collect(),
            undecided: Vec::new(),
            runs: groups.iter().flatten().map(|c| c.0 as usize).sum(),
            unknown: 0,
            bounded: vec![0],
            bound: None,
            collapsed: vec![0; ims.len()],
        }
    }

    /// Identical groups: every replicate is the pooled counts scaled, so the band is the point
    /// fit itself; different groups give a band around it that the seed reproduces exactly.
    #[test]
    fn bootstrap_bands_collapse_for_identical_groups_and_follow_the_seed() {
        let ims = [0.1, 0.2, 0.4, 0.8];
        let one = vec![(10, 1), (10, 3), (10, 6), (10, 9)];
        let same = grouped(&ims, &vec![one.clone(); 5]);
        let f = fit(&same.pooled(&[1])[0]).unwrap();
        let b = bootstrap(&same, 50, 7, &[0.3])[0].clone().unwrap();
        for x in b.median {
            assert!((x / f.median - 1.0).abs() < 1e-9);
        }
        assert!((b.curve[0][1] - f.probability(0.3)).abs() < 1e-9);
        let mixed = grouped(
            &ims,
            &[
                one.clone(),
                vec![(10, 0), (10, 1), (10, 4), (10, 7)],
                vec![(10, 3), (10, 6), (10, 8), (10, 10)],
                vec![(10, 1), (10, 2), (10, 7), (10, 9)],
            ],
        );
        let f = fit(&mixed.pooled(&[1])[0]).unwrap();
        let b = bootstrap(&mixed, 400, 7, &[0.3])[0].clone().unwrap();
        assert!(
            b.median[0] < f.median && f.median < b.median[1],
            "{b:?} {f:?}"
        );
        assert!(b.median[1] / b.median[0] > 1.05);
        assert_eq!(b.fitted + b.unfitted, 400);
        assert_eq!(bootstrap(&mixed, 400, 7, &[0.3])[0], Some(b.clone()));
        assert_ne!(bootstrap(&mixed, 400, 8, &[0.3])[0], Some(b));
    }

    /// Curves of ascending thresholds whose betas differ cross where the flatter one rises
    /// above the steeper; ordered curves of one beta never do.
    #[test]
    fn crossing_curves_are_found() {
        let curve = |median: f64, beta: f64| -> Result<Fit, NoFit> {
            Ok(Fit {
                median,
                beta,
                se_ln_median: 0.0,
                se_beta: 0.0,
                log_likelihood: 0.0,
                deviance: 0.0,
                dof: 0,
                p_fit: None,
                no_power: false,
            })
        };
        assert!(crossings(&[curve(0.5, 0.4), curve(0.8, 0.4)], 0.05, 3.0).is_empty());
        // ln(im) where they meet: (b2 ln m1 - b1 ln m2) / (b2 - b1), below which the flatter
        // (higher threshold) curve lies above the steeper one: the interval runs from the
        // lowest level to there, and the curves are in order on either side of its ends.
        let (a, b) = (curve(0.5, 0.2), curve(0.6, 0.8));
        let meet = ((0.8 * 0.5f64.ln() - 0.2 * 0.6f64.ln()) / (0.8 - 0.2)).exp();
        let c = crossings(&[a.clone(), b.clone()], 0.05, 3.0);
        assert_eq!(c.len(), 1);
        let (i, j, from, to) = c[0];
        assert_eq!((i, j, from), (0, 1, 0.05));
        assert!((to / meet - 1.0).abs() < 1e-12, "{to} {meet}");
        let (a, b) = (a.unwrap(), b.unwrap());
        assert!(b.probability(0.99 * to) > a.probability(0.99 * to));
        assert!(b.probability(1.01 * to) < a.probability(1.01 * to));
        // The steeper higher curve is above from the meeting point up; not at all when it
        // meets beyond the levels.
        let c = crossings(&[curve(0.6, 0.8), curve(0.5, 0.2)], 0.05, 3.0);
        assert_eq!(c.len(), 1);
        assert!(
            (c[0].2 / meet - 1.0).abs() < 1e-12 && c[0].3 == 3.0,
            "{c:?}"
        );
        assert!(crossings(&[curve(0.6, 0.8), curve(0.5, 0.2)], 0.05, 0.9 * meet).is_empty());
        // Equal betas, medians out of order: wrong everywhere.
        assert_eq!(
            crossings(&[curve(0.8, 0.4), curve(0.5, 0.4)], 0.05, 3.0),
            vec![(0, 1, 0.05, 3.0)]
        );
    }

    /// A residual drift, of a building or a storey, is bounded by its building's peak drift;
    /// no other column is.
    #[test]
    fn residual_drifts_are_bounded_by_the_peak() {
        for (edp, bound) in [
            ("b1_residual_drift_ratio", Some("b1_peak_drift_ratio")),
            ("b12_s3_residual_drift_ratio", Some("b12_peak_drift_ratio")),
            ("b1_peak_drift_ratio", None),
            ("b1_residual_storey", None),
            ("bx_residual_drift_ratio", None),
            ("b1_s_residual_drift_ratio", None),
        ] {
            assert_eq!(bounding_column(edp).as_deref(), bound, "{edp}");
        }
        assert_eq!(number(1e-300), "1e-300");
        assert_eq!(number(0.005), "0.005");
        assert_eq!(number(2e6), "2000000");
    }

    /// Runs with no value: decided where the bound is at or below a threshold, else undecided,
    /// and counted each way for the bounds.
    #[test]
    fn runs_with_no_value_are_decided_by_the_bound_or_counted_apart() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("r.csv");
        std::fs::write(
            &p,
            "status,pga_g,b1_peak_drift_ratio,b1_residual_drift_ratio\nok,0.1,0.002,0.001\nok,0.1,0.004,\nok,0.2,0.02,0.006\nok,0.2,0.03,\nfailed,0.2,,\n",
        )
        .unwrap();
        let table = Table::read(&p).unwrap();
        let spec = FragilitySpec {
            im: "pga_g".into(),
            edp: "b1_residual_drift_ratio".into(),
            thresholds: vec![0.005],
            filters: Vec::new(),
        };
        let (g, left) = Grouped::read(&table, &spec, None).unwrap();
        assert_eq!((g.runs, g.unknown, left.failed), (4, 2, 1));
        assert_eq!(g.bounded, vec![1]);
        assert_eq!(g.undecided_at(0), vec![0, 1]);
        let at = |how| {
            g.pooled_counting(&[1], how)[0]
                .iter()
                .map(|l| (l.n, l.exceed))
                .collect::<Vec<_>>()
        };
        assert_eq!(at(Undecided::Left), vec![(2, 0), (1, 1)]);
        assert_eq!(at(Undecided::NotExceeding), vec![(2, 0), (2, 1)]);
        assert_eq!(at(Undecided::Exceeding), vec![(2, 0), (2, 2)]);
    }

    /// A collapsed run counts as exceeding every threshold whatever its cell holds (empty, or
    /// below every threshold), a failed one is left out; the collapse fragility counts the
    /// collapsed runs among those that did not fail, and refuses a table that cannot collapse.
    #[test]
    fn collapsed_runs_exceed_every_threshold() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("r.csv");
        std::fs::write(
            &p,
            "status,pga_g,collapse_time_s,collapse_building,collapse_storey,b2_peak_drift_ratio,b1_residual_drift_ratio\n\
             ok,0.1,,,,0.001,0.001\ncollapsed,0.1,2,1,1,0.0005,\nok,0.2,,,,0.02,0.004\ncollapsed,0.2,1,1,2,0.001,\nfailed,0.2,,,,,\n",
        )
        .unwrap();
        let table = Table::read(&p).unwrap();
        let spec = |edp: &str, thresholds: Vec<f64>| FragilitySpec {
            im: "pga_g".into(),
            edp: edp.into(),
            thresholds,
            filters: Vec::new(),
        };
        let counts = |g: &Grouped| -> Vec<Vec<(u64, u64)>> {
            g.pooled(&[1])
                .iter()
                .map(|t| t.iter().map(|l| (l.n, l.exceed)).collect())
                .collect()
        };
        let (g, left) =
            Grouped::read(&table, &spec("b2_peak_drift_ratio", vec![0.01, 0.5]), None).unwrap();
        assert_eq!((left.failed, left.collapsed, left.total()), (1, 2, 1));
        assert_eq!(counts(&g), vec![vec![(2, 1), (2, 2)], vec![(2, 1), (2, 1)]]);
        assert_eq!(g.collapsed, vec![1, 1]);
        // A residual drift: the collapsed runs' empty cells are no undecided runs.
        let (g, _) =
            Grouped::read(&table, &spec("b1_residual_drift_ratio", vec![0.002]), None).unwrap();
        assert_eq!((g.unknown, counts(&g)), (0, vec![vec![(2, 1), (2, 2)]]));
        let collapse = FragilitySpec::collapse("pga_g", Vec::new());
        let (g, left) = Grouped::read(&table, &collapse, None).unwrap();
        assert_eq!((left.failed, g.runs), (1, 4));
        assert_eq!(counts(&g), vec![vec![(2, 1), (2, 1)]]);
        assert_eq!(
            csv(&collapse, None, &g),
            "pga_g,runs,collapsed,fraction\n0.1,2,1,0.5\n0.2,2,1,0.5\n"
        );
        assert!(csv(&spec("b2_peak_drift_ratio", vec![0.01]), None, &g)
            .starts_with("threshold,pga_g,runs,exceed,collapsed,fraction,"));
        // A threshold with it is refused; so is a table with no collapse columns.
        let mut with = collapse.clone();
        with.thresholds = vec![0.1];
        assert!(Grouped::read(&table, &with, None).is_err());
        let q = dir.path().join("pair.csv");
        std::fs::write(&q, "status,pga_g,peak_force_n\nok,0.1,1\n").unwrap();
        let e = Grouped::read(&Table::read(&q).unwrap(), &collapse, None)
            .unwrap_err()
            .to_string();
        assert!(e.contains("no collapse columns"), "{e}");
    }

    /// A curve through exact probabilities is recovered to the solver's precision.
    #[test]
    fn fit_recovers_exact_probabilities() {
        let (median, beta) = (0.4, 0.35);
        let levels: Vec<Level> = (1..=10)
            .map(|i| {
                let im = 0.1 * i as f64;
                let n = 1_000_000u64;
                let p = phi((im / median).ln() / beta);
                Level {
                    im,
                    n,
                    exceed: (p * n as f64).round() as u64,
                }
            })
            .collect();
        let f = fit(&levels).unwrap();
        assert!((f.median / median - 1.0).abs() < 1e-4, "{f:?}");
        assert!((f.beta / beta - 1.0).abs() < 1e-3, "{f:?}");
        let none: Vec<Level> = levels.iter().map(|l| Level { exceed: 0, ..*l }).collect();
        assert_eq!(fit(&none), Err(NoFit::NoneExceed));
        let step: Vec<Level> = levels
            .iter()
            .map(|l| Level {
                exceed: if l.im > 0.5 { l.n } else { 0 },
                ..*l
            })
            .collect();
        assert_eq!(fit(&step), Err(NoFit::Separated));
    }

    /// The chi-square survival function at its 5 % points (tables), and its extremes.
    #[test]
    fn chi_square_tail_matches_the_tables() {
        for (x, dof) in [
            (3.841_458_820_694_124, 1.0),
            (5.991_464_547_107_979, 2.0),
            (11.070_497_693_516_35, 5.0),
            (18.307_038_053_275_146, 10.0),
            (43.772_971_825_742_19, 30.0),
        ] {
            let p = chi_square_sf(x, dof);
            assert!((p - 0.05).abs() < 1e-10, "dof {dof}: {p}");
        }
        assert_eq!(chi_square_sf(0.0, 3.0), 1.0);
        assert!(chi_square_sf(500.0, 3.0) < 1e-100);
        // dof 2: exp(-x / 2) exactly.
        assert!((chi_square_sf(3.0, 2.0) - (-1.5f64).exp()).abs() < 1e-15);
    }

    /// Binomial draws from a known lognormal (seeded, 200 runs at each of 10 levels, 40
    /// trials): the medians and betas fall within 2 standard errors of the truth about 95 % of
    /// the time, and the goodness of fit rejects (p < 0.001) in at most 1 trial; counts from a
    /// law that is not
    /// lognormal (a plateau at 1/2 from 0.3 to 0.7 g) are rejected.
    #[test]
    fn fit_recovers_known_states_and_flags_other_laws() {
        let (median, beta) = (0.4, 0.5);
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut uniform = || {
            // xorshift64*: reproducible on every platform.
            state ^= state >> 12;
            state ^= state << 25;
            state ^= state >> 27;
            (state.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
        };
        let (mut rejected, mut within, mut far) = (0, [0usize; 2], [0usize; 2]);
        for _ in 0..40 {
            let levels: Vec<Level> = (1..=10)
                .map(|i| {
                    let im = 0.1 * i as f64;
                    let p = phi((im / median).ln() / beta);
                    let n = 200u64;
                    let exceed = (0..n).filter(|_| uniform() < p).count() as u64;
                    Level { im, n, exceed }
                })
                .collect();
            let f = fit(&levels).unwrap();
            let z = [
                (f.median.ln() - median.ln()) / f.se_ln_median,
                (f.beta - beta) / f.se_beta,
            ];
            for (k, z) in z.iter().enumerate() {
                within[k] += (z.abs() < 2.0) as usize;
                far[k] += (z.abs() > 3.0) as usize;
            }
            assert_eq!(f.dof, 8);
            if f.p_fit.unwrap() < 1e-3 {
                rejected += 1;
            }
        }
        // About 95 % of the estimates within 2 standard errors, hardly any beyond 3.
        assert!(
            within.iter().all(|&w| w >= 34),
            "within 2 se: {within:?} of 40"
        );
        assert!(far.iter().all(|&f| f <= 2), "beyond 3 se: {far:?} of 40");
        assert!(
            rejected <= 1,
            "{rejected} of 40 true lognormal samples rejected"
        );
        let plateau: Vec<Level> = (1..=10)
            .map(|i| {
                let im = 0.1 * i as f64;
                let share = if im < 0.25 {
                    0.02
                } else if im < 0.75 {
                    0.5
                } else {
                    0.98
                };
                Level {
                    im,
                    n: 200,
                    exceed: (share * 200.0) as u64,
                }
            })
            .collect();
        let f = fit(&plateau).unwrap();
        assert!(f.p_fit.unwrap() < 1e-6, "{f:?}");
    }

    /// A table in memory: `rows` of `record, target_sa_g, status, drift`.
    fn study_table(rows: &[(&str, f64, &str, f64)]) -> Table {
        Table {
            path: "r.csv".into(),
            header: ["record", "target_sa_g", "status", "drift"]
                .map(String::from)
                .to_vec(),
            rows: rows
                .iter()
                .map(|(r, im, st, d)| {
                    vec![r.to_string(), im.to_string(), st.to_string(), d.to_string()]
                })
                .collect(),
        }
    }

    /// Ten runs at each of four levels, two per record r0..r4, the first 1, 3, 6, 9 above 1.
    fn ladder() -> Vec<(&'static str, f64, &'static str, f64)> {
        let records = ["r0", "r1", "r2", "r3", "r4"];
        [(0.1, 1), (0.2, 3), (0.4, 6), (0.8, 9)]
            .into_iter()
            .flat_map(|(im, k)| {
                (0..10).map(move |j| (records[j / 2], im, "ok", if j < k { 2.0 } else { 0.5 }))
            })
            .collect()
    }

    /// The study of a table read gives the counts' CSV, the summary and the fits' table, a
    /// notice placed after the line it follows, and refuses a bootstrap of one group after
    /// telling what it read; its settings are refused before any table.
    #[test]
    fn the_study_counts_fits_and_tells_in_order() {
        let o = FragilityOptions {
            edp: "drift".into(),
            thresholds: vec![1.0, 5.0],
            ..FragilityOptions::default()
        };
        let r = study(&study_table(&ladder()), &o).unwrap();
        assert_eq!(
            r.csv,
            "threshold,target_sa_g,runs,exceed,collapsed,fraction,undecided,fraction_if_none_exceed,fraction_if_all_exceed\n\
             1,0.1,10,1,0,0.1,0,0.1,0.1\n1,0.2,10,3,0,0.3,0,0.3,0.3\n1,0.4,10,6,0,0.6,0,0.6,0.6\n1,0.8,10,9,0,0.9,0,0.9,0.9\n\
             5,0.1,10,0,0,0,0,0,0\n5,0.2,10,0,0,0,0,0,0\n5,0.4,10,0,0,0,0,0,0\n5,0.8,10,0,0,0,0,0,0\n"
        );
        let lines: Vec<&str> = r.said.lines().collect();
        assert_eq!(lines[0], "40 runs at 4 levels of target_sa_g");
        assert!(lines[1].is_empty() && lines[2].starts_with("| drift > | median target_sa_g |"));
        let fitted = fit(&Grouped::read(
            &study_table(&ladder()),
            &FragilitySpec {
                im: "target_sa_g".into(),
                edp: "drift".into(),
                thresholds: vec![1.0],
                filters: Vec::new(),
            },
            None,
        )
        .unwrap()
        .0
        .pooled(&[1])[0])
        .unwrap();
        assert!(
            lines[4].starts_with(&format!(
                "| 1 | {:.4} | {:.4} |",
                fitted.median, fitted.beta
            )),
            "{}",
            lines[4]
        );
        assert!(lines[5].starts_with("| 5 | no fit: "), "{}", lines[5]);
        assert_eq!(r.panels.len(), 1);

        // An intensity that differs from run to run: the notice comes after the first line.
        let spread: Vec<_> = (0..12)
            .map(|i| ("r0", 0.1 + i as f64 / 100.0, "ok", i as f64))
            .collect();
        let o = FragilityOptions {
            edp: "drift".into(),
            thresholds: vec![5.0],
            ..FragilityOptions::default()
        };
        let r = study(&study_table(&spread), &o).unwrap();
        assert!(r.notices[0].starts_with("notice: target_sa_g takes 12 values over 12 runs"));
        assert_eq!(r.notices_at[0], r.said.find('\n').unwrap() + 1);
        let told = std::cell::RefCell::new(Vec::new());
        r.tell(
            |s| -> Result<(), ()> {
                told.borrow_mut().push(format!("say {s}"));
                Ok(())
            },
            |n| told.borrow_mut().push(format!("note {n}")),
        )
        .unwrap();
        let told = told.into_inner();
        assert_eq!(told[0], "say 12 runs at 12 levels of target_sa_g\n");
        assert!(told[1].starts_with("note notice: target_sa_g takes"));
        assert_eq!(
            told.iter()
                .filter(|t| t.starts_with("say "))
                .map(|t| &t[4..])
                .collect::<String>(),
            r.said
        );

        // A bootstrap over one record: refused after the summary, which it carries.
        let o = FragilityOptions {
            edp: "drift".into(),
            thresholds: vec![1.0],
            bootstrap: 100,
            filters: vec!["record=r0".into()],
            ..FragilityOptions::default()
        };
        match study(&study_table(&ladder()), &o) {
            Err(e @ FragilityError::RefusedAfter { .. }) => {
                assert_eq!(e.to_string(), "--bootstrap: the runs fall in 1 group of record: resampling needs at least two");
                let mut said = String::new();
                e.tell(
                    |s| -> Result<(), ()> {
                        said.push_str(s);
                        Ok(())
                    },
                    |_| (),
                )
                .unwrap();
                assert_eq!(said, "8 runs at 4 levels of target_sa_g\n");
            }
            other => panic!("{other:?}"),
        }
        // Settings refused with no table; a filter keeping nothing named with the file.
        let o = FragilityOptions {
            bootstrap: 50,
            thresholds: vec![1.0],
            ..FragilityOptions::default()
        };
        assert!(o
            .check()
            .unwrap_err()
            .to_string()
            .starts_with("--bootstrap 50: expected 0 (no bands) or at least 100"));
        assert!(FragilityOptions::default()
            .check()
            .unwrap_err()
            .to_string()
            .starts_with("give --threshold T1,T2"));
        let o = FragilityOptions {
            edp: "drift".into(),
            thresholds: vec![1.0],
            filters: vec!["record=none".into()],
            ..FragilityOptions::default()
        };
        assert_eq!(
            study(&study_table(&ladder()), &o).unwrap_err().to_string(),
            "r.csv: no run left to count: --where record=none keeps none of its 40 rows"
        );
    }
}
