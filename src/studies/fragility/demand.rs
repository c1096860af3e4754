//! What a fragility reads of a table: its spec (intensity, demand, thresholds, filters), whose
//! collapse a demand counts, each run's demand, and the rows left out.

use crate::io::table::{Filter, Table, TableError};

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

/// The column whose groups a bootstrap draws unless `--bootstrap-groups` names one: the
/// record's RSN where every run's record came from a PEER record set (`record_rsn`: the
/// components of one record are one draw, not independent ones), else the record.
pub fn default_groups(table: &Table) -> String {
    let rsn = table
        .col("record_rsn")
        .is_ok_and(|i| !table.rows.is_empty() && table.rows.iter().all(|r| !r[i].is_empty()));
    if rsn { "record_rsn" } else { "record" }.to_string()
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

/// Whether demand column `edp` is signed: a storey's residual drift ratio
/// (`bK_sJ_residual_drift_ratio`, the side the storey leans to), whose demand is its magnitude.
pub fn is_signed(edp: &str) -> bool {
    bounding_column(edp).is_some()
        && edp
            .split_once('_')
            .is_some_and(|(_, rest)| rest != "residual_drift_ratio")
}

/// The notice of a study of a signed demand ([`is_signed`]): it reads the magnitude.
pub fn signed_notice(edp: &str) -> Option<String> {
    is_signed(edp).then(|| {
        format!("notice: {edp} is signed (the side the storey leans to at rest): its magnitude is the demand")
    })
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
    let signed = edp.is_some_and(is_signed);
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
                Some(v) if signed => Demand::Value(v.abs()),
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
