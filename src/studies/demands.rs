//! A sweep's demands in the SimCenter format pelicun reads (`pound demands`): one building's
//! storeys and floors, a row per run, columns `{event}-{EDP}-{location}-{direction}` with a
//! units row, as FEMA P-58 loss assessments take them.
//!
//! Per storey `j`: `1-PID-j-1`, the peak interstorey drift ratio, and `1-RID-j-1`, the residual
//! drift ratio's magnitude (pelicun compares it with its irreparable limit, unsigned); per floor
//! `j` from 0, the ground: `1-PFA-j-1`, the peak absolute acceleration in m/s^2 (`mps2`); and
//! `1-SA_T-0-1`, the target Sa(T) in g the runs were scaled to (`T` the period where they share
//! one; `SA_T1` where each run's is the building's own sampled T1, `SA_Ts` where it is another
//! building's: the demand a collapse fragility reads); `1-COL-0-1`, 1 where the building collapsed in the simulation, else 0: pelicun's
//! `CollapseLimits` `{"COL": 0.5}` drops those realizations from the demand sample, collapse
//! being the collapse fragility's (`pound fragility --edp bK_collapsed --fits`). The index is
//! the run number. A residual drift that is not known (a run that did not settle, or a building
//! that collapsed) is an empty cell, counted in a notice; failed runs are left out, counted.

use crate::io::table::{Filter, Table, TableError};
use crate::studies::report::{StudyReport, Telling};

/// What to export.
#[derive(Debug, Clone, PartialEq)]
pub struct DemandsOptions {
    /// The building (from 1).
    pub building: usize,
    pub filters: Vec<String>,
}

#[derive(Debug, thiserror::Error)]
pub enum DemandsError {
    #[error(transparent)]
    Table(#[from] TableError),
    #[error("{0}")]
    Refused(String),
}

/// The column of the target Sa the kept `rows` were scaled to and the demand type it is written
/// as, with a notice where the name needs one: `SA_T` where every row shares the period `T`;
/// `SA_T1` where each run was scaled at building `k`'s own (sampled) fundamental period; `SA_Ts`
/// where each run was scaled at a period of its own that is not building `k`'s (another
/// building's). None where a row has no target Sa.
fn sa_column(
    table: &Table,
    rows: &[usize],
    k: usize,
) -> Result<Option<(usize, String, Option<String>)>, DemandsError> {
    let (Ok(sa), Ok(at)) = (table.col("target_sa_g"), table.col("sa_period_s")) else {
        return Ok(None);
    };
    let own = table.col(&format!("b{k}_t1_s")).ok();
    let (mut lo, mut hi, mut its_own) = (f64::INFINITY, f64::NEG_INFINITY, own.is_some());
    for &i in rows {
        match (table.num(i, sa)?, table.num(i, at)?) {
            (Some(_), Some(t)) => {
                (lo, hi) = (lo.min(t), hi.max(t));
                if let Some(c) = own {
                    its_own &= table.num(i, c)? == Some(t);
                }
            }
            _ => return Ok(None),
        }
    }
    if lo > hi {
        return Ok(None);
    }
    if lo == hi {
        return Ok(Some((sa, format!("SA_{}", crate::show(lo)), None)));
    }
    Ok(Some(if its_own {
        (
            sa,
            "SA_T1".into(),
            Some(format!(
                "notice: each run was scaled to Sa at building {k}'s own sampled period T1 ({lo:.3} to {hi:.3} s): 1-SA_T1-0-1 holds those targets"
            )),
        )
    } else {
        (
            sa,
            "SA_Ts".into(),
            Some(format!(
                "notice: each run was scaled to Sa at a period of its own that is not building {k}'s (sa_period_s, {lo:.3} to {hi:.3} s: another building's): 1-SA_Ts-0-1 holds those targets"
            )),
        )
    }))
}

/// `pound demands` of `table`: the SimCenter demand file of building `o.building`.
pub fn study(table: &Table, o: &DemandsOptions) -> Result<StudyReport, DemandsError> {
    table.check_columns()?;
    let k = o.building;
    if k == 0 {
        return Err(DemandsError::Refused(
            "--building 0: buildings are numbered from 1, left to right".into(),
        ));
    }
    let has = |c: &str| table.header.iter().any(|h| h == c);
    let storeys = (1..)
        .take_while(|j| has(&format!("b{k}_s{j}_peak_drift_ratio")))
        .count();
    let floors = (0..)
        .take_while(|j| has(&format!("b{k}_f{j}_peak_accel_m_s2")))
        .count();
    if storeys == 0 && floors == 0 {
        let prefix = format!("b{k}_");
        if !table.header.iter().any(|h| h.starts_with(&prefix)) {
            let buildings = (1..)
                .take_while(|b| {
                    table
                        .header
                        .iter()
                        .any(|h| h.starts_with(&format!("b{b}_")))
                })
                .count();
            return Err(DemandsError::Refused(format!(
                "{}: no building {k} (the table's columns name buildings 1 to {buildings})",
                table.path.display()
            )));
        }
    }
    let missing = match (storeys, floors) {
        (0, 0) => {
            Some("storeys and floors (b{k}_s1_peak_drift_ratio, b{k}_f0_peak_accel_m_s2, ...)")
        }
        (0, _) => Some("storeys (b{k}_s1_peak_drift_ratio, ...)"),
        (_, 0) => Some("floors (b{k}_f0_peak_accel_m_s2, ...)"),
        (n, f) if f != n + 1 => Some("floors (one more than its storeys, from floor 0)"),
        _ => None,
    };
    if let Some(what) = missing {
        return Err(DemandsError::Refused(format!(
            "{}: building {k}'s {} are not all in the table: run the sweep with --columns +storeys,+floors",
            table.path.display(),
            what.replace("{k}", &k.to_string())
        )));
    }
    let filters = Filter::parse_all(&o.filters)?;
    let rows = table.select(&filters)?;
    let (run, status) = (table.col("run")?, table.col("status")?);
    let collapsed_col = table
        .header
        .iter()
        .position(|h| *h == format!("b{k}_collapsed"));
    // Without the building's collapse column, a collapsed run cannot be told apart.
    if collapsed_col.is_none()
        && rows
            .iter()
            .any(|&i| table.rows[i][status].trim() == "collapsed")
    {
        return Err(DemandsError::Refused(format!(
            "{}: runs collapsed, but the table has no b{k}_collapsed column to say whether building {k} did (it was left out by --columns): keep it in the sweep's columns",
            table.path.display()
        )));
    }
    let mut head = vec![String::new()];
    let mut units = vec!["Units".to_string()];
    let mut cols = Vec::new();
    for j in 1..=storeys {
        for (edp, column) in [("PID", "peak_drift_ratio"), ("RID", "residual_drift_ratio")] {
            head.push(format!("1-{edp}-{j}-1"));
            units.push("rad".into());
            cols.push(table.col(&format!("b{k}_s{j}_{column}"))?);
        }
    }
    for j in 0..floors {
        head.push(format!("1-PFA-{j}-1"));
        units.push("mps2".into());
        cols.push(table.col(&format!("b{k}_f{j}_peak_accel_m_s2"))?);
    }
    // The spectral acceleration the runs were scaled to, where they share its period: the
    // demand a collapse fragility of `pound fragility` reads (`SA_T`, in g).
    let sa = sa_column(table, &rows, k)?;
    if let Some((_, kind, _)) = &sa {
        head.push(format!("1-{kind}-0-1"));
        units.push("g".into());
    }
    head.push("1-COL-0-1".into());
    units.push("unitless".into());
    let mut csv = format!("{}\n{}\n", head.join(","), units.join(","));
    let (mut written, mut failed, mut collapsed, mut no_residual) = (0, 0, 0, 0);
    for &i in &rows {
        let st = table.rows[i][status].trim();
        if st != "ok" && st != "collapsed" {
            failed += 1;
            continue;
        }
        let gone = match collapsed_col {
            Some(c) => table.num(i, c)? == Some(1.0),
            None => false,
        };
        let mut line = vec![table.rows[i][run].trim().to_string()];
        let mut unknown = false;
        for (x, &c) in cols.iter().enumerate() {
            let residual = x < 2 * storeys && x % 2 == 1;
            // The cell as the sweep wrote it (a residual unsigned).
            let cell = table.rows[i][c].trim();
            line.push(match table.num(i, c)? {
                Some(v) if !v.is_finite() => {
                    return Err(DemandsError::Refused(format!(
                        "{}, line {}: `{}` is {cell}: a demand is a finite number",
                        table.path.display(),
                        i + 2,
                        table.header[c]
                    )))
                }
                Some(_) if residual => cell.trim_start_matches('-').to_string(),
                Some(_) => cell.to_string(),
                None if residual => {
                    unknown = true;
                    String::new()
                }
                None => {
                    return Err(DemandsError::Refused(format!(
                        "{}, line {}: `{}` is empty in a run that did not fail",
                        table.path.display(),
                        i + 2,
                        table.header[c]
                    )))
                }
            });
        }
        if let Some((c, _, _)) = &sa {
            line.push(table.rows[i][*c].trim().to_string());
        }
        line.push(u8::from(gone).to_string());
        csv.push_str(&line.join(","));
        csv.push('\n');
        written += 1;
        collapsed += usize::from(gone);
        no_residual += usize::from(unknown && !gone);
    }
    if written == 0 {
        return Err(DemandsError::Refused(format!(
            "{}: no run left to export ({} rows, {} kept by --where, {failed} failed)",
            table.path.display(),
            table.rows.len(),
            rows.len()
        )));
    }
    let mut t = Telling::default();
    t.say(format_args!(
        "{written} runs of building {k} ({storeys} {}, floors 0 to {}): {collapsed} collapsed (1-COL-0-1 = 1)",
        if storeys == 1 { "storey" } else { "storeys" },
        floors - 1
    ));
    // pelicun takes every row as a realization of one intensity.
    for column in ["target_sa_g", "target_sa_avg_g", "target_pga_g"] {
        let Ok(c) = table.col(column) else { continue };
        let mut levels: Vec<&str> = (rows.iter())
            .map(|&i| table.rows[i][c].trim())
            .filter(|v| !v.is_empty())
            .collect();
        levels.sort_unstable();
        levels.dedup();
        if levels.len() > 1 {
            t.note(format_args!(
                "notice: the runs are at {} levels of {column}: pelicun takes every row as a realization of one intensity; keep one level with --where {column}=VALUE",
                levels.len()
            ));
        }
    }
    if let Some((_, _, Some(notice))) = &sa {
        t.note(notice);
    }
    if failed > 0 {
        t.note(format_args!(
            "notice: {failed} failed runs (status neither ok nor collapsed) are left out"
        ));
    }
    if no_residual > 0 {
        t.note(format_args!(
            "notice: {no_residual} runs that did not settle have no residual drift: their RID cells are empty (pelicun's residual drift inference can stand in for them)"
        ));
    }
    Ok(StudyReport {
        csv,
        tables: Vec::new(),
        said: t.said,
        notices: t.notices,
        notices_at: t.notices_at,
        panels: Vec::new(),
    })
}
