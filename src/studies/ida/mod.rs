//! An incremental dynamic analysis summary from a results CSV (`pound ida`): per curve (a
//! record, or a record and a sample) the demand against the intensity, and across curves the
//! 16, 50 and 84 % fractiles of the demand at each intensity level.
//!
//! Collapse (Vamvatsikos & Cornell 2002; physics.md sections 10 and 12): a collapsed run is an
//! infinite demand. Of a building's demand (`bK_...`) that is a run where building K collapsed
//! (its `bK_collapsed`: a run where only another building collapsed is its value as measured);
//! of the run's (`peak_force_n`, a contact level's), a run whose status is `collapsed`; where the
//! table does not say which building collapsed (no `bK_collapsed`, or every one 0 in a collapsed
//! run) the run's status stands for the building's, and a notice says so. A curve flatlines at
//! its first collapse: from that level up it is infinite, at every level (a run above it that
//! did not collapse, "structural resurrection", is counted as collapsed and reported; a level
//! with no run there is collapsed too), and it is drawn through its points up to the last it
//! survived, then at that demand up to the level of its first collapse and along it to the
//! right edge of the plot. The fractiles are
//! over every curve with a value at a level, collapsed ones included as infinite: a fractile is
//! infinite (`inf` in the table, a flatline in the plot) where the curves collapsed there reach
//! its position among the sorted demands, about where more than `100 - p` % of them collapsed.
//! A failed run (status neither `ok` nor `collapsed`: a numerical failure) or one with no value of
//! the demand (a residual drift where the run did not settle) is left out and counted at its
//! level, and the fractiles there are over the others, and say so.

mod table;

use crate::engine::quantile::{quantile, Interpolation::Linear};
use crate::io::table::{caption, label, name, order_key, Filter, Table, TableError};
use crate::studies::fragility::{demand_rows, CollapseOf, Demand, LeftOut};
use crate::studies::plot::{Panel, Series, SMOOTH};
use crate::studies::report::{StudyReport, Telling};
use std::collections::{BTreeMap, HashMap};

/// Curves named in a plot's legend at most.
pub const NAMED_CURVES: usize = 10;

/// The fractiles reported, in %.
pub const FRACTILES: [f64; 3] = [16.0, 50.0, 84.0];

/// What to read.
#[derive(Debug, Clone, PartialEq)]
pub struct IdaSpec {
    pub im: String,
    pub edp: String,
    /// The columns whose values name a curve (e.g. `record`, `sample`).
    pub by: Vec<String>,
    pub filters: Vec<Filter>,
}

/// The curves and their fractiles.
#[derive(Debug, Clone, PartialEq)]
pub struct Ida {
    /// The intensity levels, ascending.
    pub ims: Vec<f64>,
    /// Per curve: its name and its demand at each level (None where it has no run there;
    /// infinite from its first collapse up).
    pub curves: Vec<(String, Vec<Option<f64>>)>,
    /// Per level: the curves with a value there (collapsed ones included), and the
    /// [`FRACTILES`] of their demands (infinite where collapses reach them; NaN where no curve
    /// has a value).
    pub counts: Vec<usize>,
    pub fractiles: Vec<[f64; 3]>,
    /// Per level: the curves collapsed there (a run that collapsed there or at a lower level).
    pub collapsed: Vec<usize>,
    /// The building whose own collapse flatlines the curves (read from its `bK_collapsed`);
    /// None: the run's collapse (a demand of the run, or a table that does not say which
    /// building collapsed).
    pub building: Option<usize>,
    /// Runs that did not collapse at a level above their curve's first collapse (structural
    /// resurrection), counted as collapsed; and the levels with no run of a curve above its
    /// first collapse, filled as collapsed.
    pub resurrected: usize,
    pub filled: usize,
    /// Per level: runs left out there, failed (status neither `ok` nor `collapsed`) and with no
    /// value of the demand.
    pub failed: Vec<usize>,
    pub no_value: Vec<usize>,
}

#[derive(Debug, thiserror::Error)]
pub enum IdaError {
    #[error(transparent)]
    Table(#[from] TableError),
    #[error("{path}: rows {first} and {second} are both curve `{curve}` at {im} = {level}: name the columns that tell them apart with --curves (e.g. --curves record,sample,gap_m) or keep one with --where")]
    Duplicate {
        path: String,
        curve: String,
        im: String,
        level: f64,
        first: usize,
        second: usize,
    },
    #[error("{path}: no run with a value of {edp} left to read: of {rows} rows, {why}")]
    Empty {
        path: String,
        edp: String,
        rows: usize,
        why: String,
    },
    /// A setting that gives no result (`--by` naming a column twice, `--edp collapsed`): the
    /// message as `pound ida` prints it.
    #[error("{0}")]
    Refused(String),
}

/// Read the curves of `table` under `spec`, and the rows left out (failed, no value, a value not
/// finite; the collapsed runs, kept, counted in `collapsed`).
pub fn read(table: &Table, spec: &IdaSpec) -> Result<(Ida, LeftOut), IdaError> {
    table.check_columns()?;
    let (ci, ce) = (table.col(&spec.im)?, table.col(&spec.edp)?);
    let by: Vec<usize> = spec
        .by
        .iter()
        .map(|b| table.col(b))
        .collect::<Result<_, _>>()?;
    let mut skipped = LeftOut::default();
    let mut ims: BTreeMap<u64, f64> = BTreeMap::new();
    let mut names: Vec<String> = Vec::new();
    let mut curve_of: HashMap<Vec<&str>, usize> = HashMap::new();
    // A curve's name is its cells joined by `/`: two curves whose cells join alike (`a/b`, `c`
    // and `a`, `b/c`) would be one column of the table, and one curve in its counts.
    let mut named: HashMap<String, Vec<&str>> = HashMap::new();
    // (curve, level key) -> (row, demand: infinite where the run collapsed)
    let mut points: HashMap<(usize, u64), (usize, f64)> = HashMap::new();
    // Runs kept out at a level: failed, and with no value of the demand.
    let mut missing: HashMap<u64, (usize, usize)> = HashMap::new();
    let collapse = CollapseOf::of(table, &spec.edp);
    for (i, key, demand) in
        demand_rows(table, &spec.filters, ci, Some(ce), &collapse, &mut skipped)?
    {
        ims.insert(order_key(key), key);
        let edp = match demand {
            Demand::Value(edp) => edp,
            Demand::Collapsed => f64::INFINITY,
            Demand::Unknown { .. } => {
                skipped.empty_edp += 1;
                missing.entry(order_key(key)).or_default().1 += 1;
                continue;
            }
        };
        let cells: Vec<&str> = by.iter().map(|&c| table.rows[i][c].as_str()).collect();
        let name = cells.join("/");
        if let Some(other) = named.get(&name).filter(|o| **o != cells) {
            return Err(IdaError::Refused(format!(
                "{}: the curves of --curves {} cells `{}` and `{}` would both be named `{name}` (a curve is named by its cells joined by `/`): name the curves by other columns with --curves, or rename the records",
                table.path.display(),
                spec.by.join(","),
                other.join("`, `"),
                cells.join("`, `"),
            )));
        }
        named.insert(name.clone(), cells.clone());
        let c = *curve_of.entry(cells).or_insert_with(|| {
            names.push(name.clone());
            names.len() - 1
        });
        if let Some(&(first, _)) = points.get(&(c, order_key(key))) {
            // Rows are numbered as in the file: the header is line 1.
            return Err(IdaError::Duplicate {
                path: table.path.display().to_string(),
                curve: name,
                im: spec.im.clone(),
                level: key,
                first: first + 2,
                second: i + 2,
            });
        }
        points.insert((c, order_key(key)), (i, edp));
    }
    if names.is_empty() {
        let kept = table.select(&spec.filters)?.len();
        let mut why = Vec::new();
        if kept < table.rows.len() {
            why.push(format!("--where keeps {kept}"));
        }
        if skipped.total() > 0 {
            why.push(skipped.to_string());
        }
        if why.is_empty() {
            why.push("none to read".into());
        }
        return Err(IdaError::Empty {
            path: table.path.display().to_string(),
            edp: spec.edp.clone(),
            rows: table.rows.len(),
            why: why.join("; "),
        });
    }
    // A failed run's intensity, where it has one, places it at its level.
    if let Ok(cs) = table.col("status") {
        for i in table.select(&spec.filters)? {
            if !matches!(table.rows[i][cs].as_str(), "ok" | "collapsed") {
                if let Ok(Some(im)) = table.num(i, ci) {
                    let key = crate::io::table::level(im);
                    ims.insert(order_key(key), key);
                    missing.entry(order_key(key)).or_default().0 += 1;
                }
            }
        }
    }
    let keys: Vec<u64> = ims.keys().copied().collect();
    let (mut resurrected, mut filled) = (0, 0);
    let curves: Vec<(String, Vec<Option<f64>>)> = names
        .into_iter()
        .enumerate()
        .map(|(c, n)| {
            let mut v: Vec<Option<f64>> = keys
                .iter()
                .map(|k| points.get(&(c, *k)).map(|p| p.1))
                .collect();
            // The flatline: infinite from the first collapse up.
            if let Some(first) = v.iter().position(|x| x.is_some_and(f64::is_infinite)) {
                for x in &mut v[first + 1..] {
                    match x {
                        Some(d) if d.is_finite() => resurrected += 1,
                        Some(_) => {}
                        None => filled += 1,
                    }
                    *x = Some(f64::INFINITY);
                }
            }
            (n, v)
        })
        .collect();
    let mut counts = Vec::new();
    let mut fractiles = Vec::new();
    let mut collapsed = Vec::new();
    for l in 0..keys.len() {
        let mut v: Vec<f64> = curves.iter().filter_map(|c| c.1[l]).collect();
        v.sort_by(f64::total_cmp);
        counts.push(v.len());
        collapsed.push(v.iter().filter(|x| x.is_infinite()).count());
        fractiles.push(FRACTILES.map(|f| quantile(&v, f / 100.0, Linear)));
    }
    let at = |k: &u64| missing.get(k).copied().unwrap_or_default();
    Ok((
        Ida {
            ims: ims.into_values().collect(),
            curves,
            counts,
            fractiles,
            collapsed,
            // Where the run's status stood for some building's collapse, the run's.
            building: match collapse {
                CollapseOf::Building {
                    k, column: Some(_), ..
                } if skipped.run_collapse == 0 => Some(k),
                _ => None,
            },
            resurrected,
            filled,
            failed: keys.iter().map(|k| at(k).0).collect(),
            no_value: keys.iter().map(|k| at(k).1).collect(),
        },
        skipped,
    ))
}

impl Ida {
    /// Whether any curve collapsed.
    pub fn any_collapsed(&self) -> bool {
        self.collapsed.iter().any(|&c| c > 0)
    }

    /// The share of the curves at level `l` that collapsed (None with no curve there).
    pub fn collapsed_fraction(&self, l: usize) -> Option<f64> {
        (self.counts[l] > 0).then(|| self.collapsed[l] as f64 / self.counts[l] as f64)
    }

    /// The names of [`Ida::csv`]'s columns: the intensity, `curves`, the demand's fractiles,
    /// `collapsed`, `collapsed_fraction`, then each curve's name.
    pub fn header(&self, spec: &IdaSpec) -> Vec<String> {
        let mut h = vec![spec.im.clone(), "curves".to_string()];
        h.extend(FRACTILES.map(|f| format!("{}_p{f}", spec.edp)));
        h.extend(["collapsed", "collapsed_fraction"].map(String::from));
        h.extend(self.curves.iter().map(|(n, _)| n.clone()));
        h
    }

    /// Refuse a table whose columns [`Ida::header`] would name twice: a curve is a column named
    /// by its `--by` cells (a record's label), which may spell a fixed column's name
    /// (`collapsed`, the intensity's `pga_g`); a reader of the table would then take one for the
    /// other (polars refuses it).
    pub fn check_header(&self, spec: &IdaSpec) -> Result<(), IdaError> {
        let header = self.header(spec);
        let Some((column, at)) = crate::io::table::duplicate_column(&header) else {
            return Ok(());
        };
        let fixed = header.len() - self.curves.len();
        let what = if at[0] < fixed && at.len() > 1 && at[1] >= fixed {
            format!(
                "the curve `{column}` (its {} cells) is named like the table's own column `{column}` ({}), and each curve is a column named by its {}",
                spec.by.join("/"),
                match at[0] {
                    0 => "the intensity",
                    1 => "the curves at a level",
                    i if i < 5 => "a fractile of the demand",
                    5 => "the curves collapsed at a level",
                    _ => "their share",
                },
                spec.by.join("/")
            )
        } else {
            format!(
                "`{column}` names two of its fixed columns (--im {} and --edp {})",
                spec.im, spec.edp
            )
        };
        Err(IdaError::Refused(format!(
            "the IDA table would have two columns `{column}` (columns {}): {what}; rename the record (its `name` in the config's [[record]]) and rerun the sweep, or name the curves by other columns with --curves",
            at.iter().map(|i| (i + 1).to_string()).collect::<Vec<_>>().join(", ")
        )))
    }

    /// A line through `(demand, intensity)` per level (None: no point there) up to its first
    /// infinite demand, and its flatline there: from the last finite point it rises at that
    /// demand to the intensity of the collapse, and runs along it to `right` (from `left` where
    /// no level before the collapse has a value). The flatline is sampled densely, so that it is
    /// drawn as a line with no markers (it holds no run); with the intensity of the collapse.
    #[allow(clippy::type_complexity)]
    fn flatlined(
        &self,
        values: impl Iterator<Item = Option<f64>>,
        left: f64,
        right: f64,
    ) -> (Vec<(f64, f64)>, Option<(Vec<(f64, f64)>, f64)>) {
        let mut points: Vec<(f64, f64)> = Vec::new();
        for (x, &im) in values.zip(&self.ims) {
            match x {
                Some(x) if x.is_infinite() => {
                    let corners = match points.last() {
                        Some(&(x, below)) => vec![(x, below), (x, im), (right, im)],
                        None => vec![(left, im), (right, im)],
                    };
                    let per = SMOOTH / (corners.len() - 1) + 1;
                    let mut flat: Vec<(f64, f64)> = corners
                        .windows(2)
                        .flat_map(|w| {
                            let ((ax, ay), (bx, by)) = (w[0], w[1]);
                            (0..per).map(move |k| {
                                let f = k as f64 / per as f64;
                                (ax + f * (bx - ax), ay + f * (by - ay))
                            })
                        })
                        .collect();
                    flat.push((right, im));
                    return (points, Some((flat, im)));
                }
                Some(x) if x.is_finite() => points.push((x, im)),
                _ => {}
            }
        }
        (points, None)
    }

    /// The curves (demand on x, intensity on y, as IDA curves are drawn) and the fractiles;
    /// beyond [`NAMED_CURVES`] curves, each is a grey line with no legend entry. A collapsed curve
    /// or an infinite fractile ends in its flatline (see the module's note), a second series of
    /// its name and style, to the right edge: a fifth beyond the largest finite demand drawn.
    pub fn panel(&self, spec: &IdaSpec) -> Panel {
        let named = self.curves.len() <= NAMED_CURVES;
        let finite = self
            .curves
            .iter()
            .flat_map(|c| c.1.iter().flatten())
            .chain(self.fractiles.iter().flatten())
            .copied()
            .filter(|x| x.is_finite());
        let (lo, hi) = finite.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
            (a.min(x), b.max(x))
        });
        // No finite demand at all (every run collapsed): the flatlines span 0 to 1.
        let left = if lo.is_finite() { lo.min(0.0) } else { 0.0 };
        let right = if hi.is_finite() && hi > left {
            left + 1.2 * (hi - left)
        } else {
            left + 1.0
        };
        let mut series: Vec<Series> = Vec::new();
        let mut collapsed = 0;
        for (c, (n, v)) in self.curves.iter().enumerate() {
            let (points, flat) = self.flatlined(v.iter().copied(), left, right);
            let name = if named { n.clone() } else { String::new() };
            series.push(Series {
                name: name.clone(),
                points,
                scatter: false,
                style: Some(c),
            });
            if let Some((flat, _)) = flat {
                collapsed += 1;
                series.push(Series {
                    name,
                    points: flat,
                    scatter: false,
                    style: Some(c),
                });
            }
        }
        for (k, f) in FRACTILES.iter().enumerate() {
            let values = self
                .fractiles
                .iter()
                .zip(&self.counts)
                .map(|(q, &n)| (n > 0).then_some(q[k]));
            let (points, flat) = self.flatlined(values, left, right);
            let style = Some(self.curves.len() + k);
            let name = match &flat {
                Some((_, im)) => format!(
                    "{f} % fractile (collapse from {})",
                    crate::io::table::quantity(&spec.im, *im)
                ),
                None => format!("{f} % fractile"),
            };
            series.push(Series {
                name: name.clone(),
                points,
                scatter: false,
                style,
            });
            if let Some((flat, _)) = flat {
                series.push(Series {
                    name,
                    points: flat,
                    scatter: false,
                    style,
                });
            }
        }
        Panel {
            // The rows kept, as pound plot's and pound fragility's titles say them.
            title: format!(
                "IDA: {} against {} ({} curves{}{}){}",
                name(&spec.edp),
                name(&spec.im),
                self.curves.len(),
                if named { "" } else { " in grey" },
                if collapsed > 0 {
                    format!(", {collapsed} collapse: flatlines")
                } else {
                    String::new()
                },
                match caption(&spec.filters) {
                    c if c.is_empty() => c,
                    c => format!("; {c}"),
                }
            ),
            x_label: label(&spec.edp),
            y_label: label(&spec.im),
            log_x: false,
            log_y: false,
            series,
            y_span: None,
            ..Default::default()
        }
    }

    /// The share of the curves collapsed at each level, against the intensity (the observed
    /// collapse fragility of the curves); None where none collapsed.
    pub fn collapse_panel(&self, spec: &IdaSpec) -> Option<Panel> {
        if !self.any_collapsed() {
            return None;
        }
        let whose = match self.building {
            Some(k) => format!("where building {k} collapsed"),
            None => "collapsed".into(),
        };
        Some(Panel {
            title: format!(
                "Share of the curves {whose} against {}{}",
                name(&spec.im),
                match caption(&spec.filters) {
                    c if c.is_empty() => c,
                    c => format!("; {c}"),
                }
            ),
            x_label: label(&spec.im),
            y_label: format!("share of curves {whose}"),
            log_x: false,
            log_y: false,
            series: vec![Series {
                name: "collapsed".into(),
                points: (0..self.ims.len())
                    .filter_map(|l| self.collapsed_fraction(l).map(|f| (self.ims[l], f)))
                    .collect(),
                scatter: false,
                style: None,
            }],
            y_span: Some((0.0, 1.0)),
            ..Default::default()
        })
    }
}

// The command's study: `pound ida` from a table already read to the text it tells and the CSV
// it writes, so that the command line and the Python package hold none of it.

/// What an IDA reads: every setting of `pound ida` but where it writes and how it draws.
#[derive(Debug, Clone, PartialEq)]
pub struct IdaOptions {
    /// Intensity measure column; None: the table's [`crate::studies::fragility::default_im`].
    pub im: Option<String>,
    /// Demand column (a collapsed run is an infinite demand).
    pub edp: String,
    /// The columns that name a curve; empty: `record`, and `sample` where the table has samples.
    pub by: Vec<String>,
    /// `--where` filters as typed (`COLUMN=VALUE`, `!=`, `<`, `<=`, `>`, `>=`), all kept.
    pub filters: Vec<String>,
}

impl IdaOptions {
    /// The demand `edp` with the command's defaults for the rest.
    pub fn new(edp: impl Into<String>) -> IdaOptions {
        IdaOptions {
            im: None,
            edp: edp.into(),
            by: Vec::new(),
            filters: Vec::new(),
        }
    }

    /// The checks of the settings alone, made before any table is read (as `pound ida` makes
    /// them): [`study`] makes them again first.
    pub fn check(&self) -> Result<(), IdaError> {
        if let Some(twice) = crate::config::name_given_twice(&self.by) {
            return Err(IdaError::Refused(format!(
                "--curves: `{twice}` is given twice: give each column once"
            )));
        }
        Ok(())
    }
}

/// `pound ida` of `table`: the curves, their fractiles per level, and the notices (curves
/// missing at a level and why, failed runs left out, collapses and where the fractiles
/// flatline, runs counted as collapsed above a curve's first collapse).
pub fn study(table: &Table, o: &IdaOptions) -> Result<StudyReport, IdaError> {
    o.check()?;
    table.check_columns()?;
    let by = if o.by.is_empty() {
        let sampled = table
            .col("sample")
            .is_ok_and(|c| table.rows.iter().any(|r| !r[c].is_empty()));
        let mut by = vec!["record".to_string()];
        if sampled {
            by.push("sample".into());
        }
        by
    } else {
        o.by.clone()
    };
    let spec = IdaSpec {
        im: o
            .im
            .clone()
            .unwrap_or_else(|| crate::studies::fragility::default_im(table)),
        edp: o.edp.clone(),
        by,
        filters: Filter::parse_all(&o.filters)?,
    };
    use crate::studies::fragility::{collapse_building, collapse_probability, COLLAPSED};
    if spec.edp == COLLAPSED && table.col(&spec.edp).is_err() {
        return Err(IdaError::Refused(format!("--edp {}: an IDA reads a demand column (e.g. b1_peak_drift_ratio), where a collapsed run is an infinite demand; the collapse fragility P(collapse | IM) is `pound fragility --edp collapsed`", spec.edp)));
    }
    // A 0/1 column would draw curves of 0 that flatline at the collapse: the fragility's.
    if collapse_building(&spec.edp).is_some() {
        return Err(IdaError::Refused(format!("--edp {}: an IDA reads a demand column (e.g. b1_peak_drift_ratio), where the building's collapse is an infinite demand; its collapse fragility {} is `pound fragility --edp {}`", spec.edp, collapse_probability(&spec.edp), spec.edp)));
    }
    let (ida, skipped) = read(table, &spec)?;
    ida.check_header(&spec)?;
    let whose = CollapseOf::of(table, &spec.edp);
    let mut t = Telling::default();
    let collapsed_runs = skipped.collapsed;
    t.say(format_args!(
        "{} curves (by {}) at {} levels of {}{}{}",
        ida.curves.len(),
        spec.by.join(", "),
        ida.ims.len(),
        spec.im,
        if collapsed_runs > 0 {
            format!(
                ", {collapsed_runs} runs {} (an infinite demand)",
                whose.runs_collapsed(&skipped)
            )
        } else {
            String::new()
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
    if let Some(n) = crate::studies::fragility::no_status_notice(table) {
        t.note(n);
    }
    if let Some(n) = crate::studies::fragility::signed_notice(&spec.edp) {
        t.note(n);
    }
    // Failed runs are left out of the fractiles. Where the table has no collapse criterion a
    // failed run may be a collapse, so the fractiles over the others are collapse-free; where it
    // has one, they are over the runs that did not fail. A table written with --columns that
    // left out collapse_time_s still shows its criterion (a status `collapsed`, a bK_collapsed).
    let failed: usize = ida.failed.iter().sum();
    let can_collapse = crate::studies::fragility::shows_collapse_limit(table);
    let over = match (failed > 0, can_collapse) {
        (false, _) => "",
        (true, false) => " (collapse-free)",
        (true, true) => " (failed runs left out)",
    };
    let head: Vec<String> = FRACTILES
        .iter()
        .map(|f| format!("{} {f} %{over}", spec.edp))
        .collect();
    t.say(format_args!(
        "\n| {} | curves | collapsed | {} |\n|---:|---:|---:|---:|---:|---:|",
        spec.im,
        head.join(" | ")
    ));
    let show = |x: f64| {
        if x.is_infinite() {
            "inf (collapse)".to_string()
        } else {
            format!("{x:.4e}")
        }
    };
    for (l, im) in ida.ims.iter().enumerate() {
        let f = ida.fractiles[l];
        if ida.counts[l] == 0 {
            t.say(format_args!("| {im} | 0 | | no run with a value | | |"));
            continue;
        }
        t.say(format_args!(
            "| {im} | {} | {} ({:.0} %) | {} | {} | {} |",
            ida.counts[l],
            ida.collapsed[l],
            100.0 * ida.collapsed_fraction(l).unwrap_or(0.0),
            show(f[0]),
            show(f[1]),
            show(f[2])
        ));
    }
    // Where curves are missing at a level, say why: no run there, or a run left out.
    let short: Vec<String> = ida
        .ims
        .iter()
        .enumerate()
        .filter(|(l, _)| ida.counts[*l] < ida.curves.len())
        .map(|(l, im)| {
            let (n, f, e) = (ida.counts[l], ida.failed[l], ida.no_value[l]);
            let mut why = Vec::new();
            if f > 0 {
                why.push(format!("{f} failed (status neither ok nor collapsed)"));
            }
            if e > 0 {
                why.push(format!(
                    "{e} with no value of {} (a run that did not settle)",
                    spec.edp
                ));
            }
            let absent = ida.curves.len().saturating_sub(n + f + e);
            if absent > 0 {
                why.push(format!("{absent} with no run"));
            }
            format!(
                "{im}: {n} of {} curves ({})",
                ida.curves.len(),
                why.join(", ")
            )
        })
        .collect();
    if ida.curves.len() == 1 {
        // Fractiles across one curve are that curve: no spread across records to read.
        t.note(format_args!(
            "notice: one curve ({}): its 16, 50 and 84 % fractiles are its own demands, with no spread across records; an IDA's fractiles need several curves (records, or the columns --curves names)",
            ida.curves[0].0
        ));
    }
    if !short.is_empty() {
        t.note(format_args!(
            "notice: not every curve has a value at each level of {}: {}; the fractiles there are over the runs with a value",
            spec.im,
            short.join("; ")
        ));
    }
    if failed > 0 {
        if can_collapse {
            t.note(format_args!(
                "notice: {failed} failed runs (status neither ok nor collapsed: a numerical failure) are left out of the fractiles, which are over the runs that did not fail (the collapsed ones among them, as infinite demands)"
            ));
        } else {
            t.note(format_args!(
                "notice: {failed} failed runs (status not ok: a collapse or a numerical failure, this table having no collapse criterion) are left out of the fractiles, which are therefore collapse-free: below the fractiles of every run where the failed runs are the most severe"
            ));
        }
    }
    if ida.any_collapsed() {
        let flat: Vec<String> = FRACTILES
            .iter()
            .enumerate()
            .filter_map(|(k, f)| {
                let l = (0..ida.ims.len())
                    .find(|&l| ida.counts[l] > 0 && ida.fractiles[l][k].is_infinite())?;
                Some(format!("the {f} % from {}", ida.ims[l]))
            })
            .collect();
        let what = match ida.building {
            Some(k) => format!("runs where building {k} collapsed are infinite demands of {} (a run where only another building collapsed is its value as measured)", spec.edp),
            None => "collapsed runs are infinite demands".to_string(),
        };
        t.note(format_args!(
            "notice: {what} (Vamvatsikos & Cornell 2002): a curve flatlines at its first collapse and is collapsed at every level above it; a fractile is infinite (`inf`) where the collapses reach it{}",
            if flat.is_empty() {
                ": none does here".to_string()
            } else {
                format!(": {}", flat.join(", "))
            }
        ));
    }
    if ida.resurrected + ida.filled > 0 {
        let mut what = Vec::new();
        if ida.resurrected > 0 {
            what.push(format!(
                "{} runs that did not collapse (structural resurrection)",
                ida.resurrected
            ));
        }
        if ida.filled > 0 {
            what.push(format!("{} levels with no run", ida.filled));
        }
        t.note(format_args!(
            "notice: above their curve's first collapse, {} are counted as collapsed: the first collapse is the curve's capacity",
            what.join(" and ")
        ));
    }
    let mut panels = vec![ida.panel(&spec)];
    panels.extend(ida.collapse_panel(&spec));
    Ok(StudyReport {
        csv: ida.csv(&spec),
        tables: vec![("long", ida.long_csv(&spec))],
        said: t.said,
        notices: t.notices,
        notices_at: t.notices_at,
        panels,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table(text: &str) -> Table {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("r.csv");
        std::fs::write(&p, text).unwrap();
        Table::read(&p).unwrap()
    }

    fn spec(by: &[&str]) -> IdaSpec {
        IdaSpec {
            im: "target_sa_g".into(),
            edp: "drift".into(),
            by: by.iter().map(|s| s.to_string()).collect(),
            filters: Vec::new(),
        }
    }

    /// Five records with demands 1..5 x IM: the fractiles at each level are the type-7
    /// quantiles of those five; a failed run is left out and its curve has no point there.
    #[test]
    fn fractiles_are_the_quantiles_across_curves() {
        let mut text = String::from("run,record,target_sa_g,status,drift\n");
        let mut run = 0;
        for im in [0.1, 0.2, 0.4] {
            for r in 1..=5 {
                let status = if r == 5 && im == 0.4 { "failed" } else { "ok" };
                text.push_str(&format!("{run},rec{r},{im},{status},{}\n", r as f64 * im));
                run += 1;
            }
        }
        let (ida, left) = read(&table(&text), &spec(&["record"])).unwrap();
        assert_eq!(left.failed, 1);
        assert_eq!(ida.ims, vec![0.1, 0.2, 0.4]);
        assert_eq!(ida.counts, vec![5, 5, 4]);
        for (l, im) in [0.1, 0.2].iter().enumerate() {
            // 1..5 x im: p16 at 0.64 of the way from 1 to 2, p50 = 3, p84 at 4.36.
            let want = [1.64 * im, 3.0 * im, 4.36 * im];
            for (got, want) in ida.fractiles[l].iter().zip(want) {
                assert!((got - want).abs() < 1e-12, "{l}: {got} {want}");
            }
        }
        assert_eq!(ida.curves[4].1[2], None);
        assert!(ida.csv(&spec(&["record"])).starts_with(
            "target_sa_g,curves,drift_p16,drift_p50,drift_p84,collapsed,collapsed_fraction,rec1,rec2,rec3,rec4,rec5\n0.1,5,"
        ));
    }

    /// A curve flatlines at its first collapse: infinite at every level above (a run that
    /// stood there counted as resurrected, a level with no run filled), drawn through its points,
    /// up at its last demand to the collapse's intensity and along it to the right edge (a fifth
    /// beyond the largest finite demand); a curve that collapsed at its first level flatlines
    /// from the left edge.
    #[test]
    fn a_collapse_flatlines_the_curve() {
        let text = "record,target_sa_g,status,drift\n\
            a,0.1,ok,1\na,0.2,ok,2\na,0.4,collapsed,0.1\na,0.8,ok,3\n\
            b,0.1,ok,2\nb,0.2,ok,4\nb,0.4,ok,5\nb,0.8,ok,8\n\
            c,0.1,collapsed,\n";
        let (ida, left) = read(&table(text), &spec(&["record"])).unwrap();
        assert_eq!((left.collapsed, left.total()), (2, 0));
        let inf = f64::INFINITY;
        assert_eq!(
            ida.curves[0].1,
            vec![Some(1.0), Some(2.0), Some(inf), Some(inf)]
        );
        assert_eq!(ida.curves[2].1, vec![Some(inf); 4]);
        assert_eq!((ida.resurrected, ida.filled), (1, 3));
        assert_eq!(ida.collapsed, vec![1, 1, 2, 2]);
        assert_eq!(ida.counts, vec![3; 4]);
        assert_eq!(ida.collapsed_fraction(2), Some(2.0 / 3.0));
        // [2, 4, inf] at 0.2: the 50 % is b's 4; [5, inf, inf] at 0.4: infinite.
        assert_eq!(ida.fractiles[1][1], 4.0);
        assert_eq!(ida.fractiles[2][1], inf);
        let p = ida.panel(&spec(&["record"]));
        // The right edge: 0 + 1.2 x 8 (the largest finite demand).
        let right = 1.2 * 8.0;
        let a: Vec<&Series> = p.series.iter().filter(|s| s.name == "a").collect();
        assert_eq!(a.len(), 2);
        assert_eq!(a[0].points, vec![(1.0, 0.1), (2.0, 0.2)]);
        let flat = &a[1].points;
        assert!(flat.len() > SMOOTH, "drawn with no markers");
        assert_eq!(flat[0], (2.0, 0.2));
        assert_eq!(*flat.last().unwrap(), (right, 0.4));
        // Up at the last demand, then along the collapse's intensity: no other point.
        assert!(flat
            .iter()
            .all(|&(x, y)| (x == 2.0 && (0.2..=0.4).contains(&y)) || (y == 0.4 && x >= 2.0)));
        assert!(flat.contains(&(2.0, 0.4)));
        // b stands: one series through its four points.
        let b: Vec<&Series> = p.series.iter().filter(|s| s.name == "b").collect();
        assert_eq!(b.len(), 1);
        assert_eq!(b[0].points.len(), 4);
        // c collapsed at its first level: from the left edge (0).
        let c: Vec<&Series> = p.series.iter().filter(|s| s.name == "c").collect();
        assert!(c[0].points.is_empty());
        assert_eq!(c[1].points[0], (0.0, 0.1));
        assert_eq!(*c[1].points.last().unwrap(), (right, 0.1));
        // The 50 % fractile: finite at 0.1 and 0.2, its flatline at 0.4.
        assert!(p
            .series
            .iter()
            .any(|s| s.name.starts_with("50 % fractile (collapse from 0.4")));
        let share = ida.collapse_panel(&spec(&["record"])).unwrap();
        assert_eq!(share.series[0].points[2], (0.4, 2.0 / 3.0));
        assert_eq!(share.y_span, Some((0.0, 1.0)));
        let csv = ida.csv(&spec(&["record"]));
        assert!(csv.contains("\n0.4,3,"), "{csv}");
        assert!(csv.ends_with(",2,0.6666666666666666,inf,8,inf\n"), "{csv}");
    }

    #[test]
    fn two_runs_of_one_curve_at_one_level_are_refused() {
        let text = "run,record,sample,target_sa_g,status,drift\n0,a,0,0.1,ok,1\n1,a,1,0.1,ok,2\n";
        let e = read(&table(text), &spec(&["record"]))
            .unwrap_err()
            .to_string();
        assert!(e.contains("rows 2 and 3") && e.contains("--curves"), "{e}");
        let (ida, _) = read(&table(text), &spec(&["record", "sample"])).unwrap();
        assert_eq!(ida.curves.len(), 2);
        assert_eq!(ida.curves[1].0, "a/1");
    }

    /// The study of a table read: the curves by record (the default, with no samples), the CSV
    /// of [`read`], the summary, and the notices of a level short of a curve and of a failed run
    /// in a table with no collapse criterion, in that order; `--by` twice refused first.
    #[test]
    fn the_study_reads_by_record_and_tells_why_curves_are_short() {
        let mut rows = Vec::new();
        for (r, k) in [("a", 1.0), ("b", 2.0), ("c", 3.0)] {
            for im in [0.1, 0.2, 0.4] {
                let status = if r == "c" && im == 0.4 {
                    "failed"
                } else {
                    "ok"
                };
                rows.push(vec![
                    r.to_string(),
                    String::new(),
                    im.to_string(),
                    status.to_string(),
                    (k * im).to_string(),
                ]);
            }
        }
        let table = Table {
            path: "r.csv".into(),
            header: ["record", "sample", "target_sa_g", "status", "drift"]
                .map(String::from)
                .to_vec(),
            rows,
        };
        let r = study(&table, &IdaOptions::new("drift")).unwrap();
        let (ida, _) = read(&table, &spec(&["record"])).unwrap();
        assert_eq!(r.csv, ida.csv(&spec(&["record"])));
        assert!(
            r.said.starts_with(
                "3 curves (by record) at 3 levels of target_sa_g (1 rows left out: 1 failed"
            ),
            "{}",
            r.said
        );
        assert!(r.said.contains("| 0.4 | 2 | 0 (0 %) |"), "{}", r.said);
        assert_eq!(r.notices.len(), 2);
        assert!(r.notices[0].starts_with("notice: not every curve has a value at each level of target_sa_g: 0.4: 2 of 3 curves (1 failed"), "{}", r.notices[0]);
        assert!(
            r.notices[1].starts_with("notice: 1 failed runs (status not ok: a collapse"),
            "{}",
            r.notices[1]
        );
        assert_eq!(r.notices_at, vec![r.said.len(); 2]);
        assert_eq!(r.panels.len(), 1);
        let twice = IdaOptions {
            by: vec!["record".into(), "record".into()],
            ..IdaOptions::new("drift")
        };
        assert_eq!(
            twice.check().unwrap_err().to_string(),
            "--curves: `record` is given twice: give each column once"
        );
        assert!(matches!(study(&table, &twice), Err(IdaError::Refused(_))));
    }
}
