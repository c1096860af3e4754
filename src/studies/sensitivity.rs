//! Sensitivity plots from a results CSV (`pound plot`): an output against a swept parameter, one
//! series per value of a grouping column. Rows can be fixed by filters; the parameters neither
//! plotted nor grouped are aggregated over (max, mean, median or min of the output at each x),
//! or every row is drawn as a point.

use crate::io::table::{
    caption, label, level, name, order_key, quantity, value_label, Filter, Table, TableError,
};
use crate::studies::plot::{Panel, Series};
use std::collections::BTreeMap;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Aggregate {
    Max,
    Mean,
    Median,
    Min,
    /// No aggregation: every row is a point.
    None,
}

impl Aggregate {
    pub fn key(self) -> &'static str {
        match self {
            Aggregate::Max => "max",
            Aggregate::Mean => "mean",
            Aggregate::Median => "median",
            Aggregate::Min => "min",
            Aggregate::None => "none",
        }
    }

    fn apply(self, v: &mut [f64]) -> f64 {
        match self {
            Aggregate::Max | Aggregate::None => v.iter().copied().fold(f64::NEG_INFINITY, f64::max),
            Aggregate::Min => v.iter().copied().fold(f64::INFINITY, f64::min),
            Aggregate::Mean => v.iter().sum::<f64>() / v.len() as f64,
            Aggregate::Median => {
                v.sort_by(f64::total_cmp);
                let n = v.len();
                if n % 2 == 1 {
                    v[n / 2]
                } else {
                    0.5 * (v[n / 2 - 1] + v[n / 2])
                }
            }
        }
    }
}

/// What to plot.
#[derive(Debug, Clone, PartialEq)]
pub struct PlotSpec {
    pub x: String,
    pub y: String,
    pub by: Option<String>,
    pub filters: Vec<Filter>,
    pub aggregate: Aggregate,
    pub log_x: bool,
    pub log_y: bool,
}

/// Order group names as numbers when they all are, else as text.
fn sorted_groups(names: Vec<String>) -> Vec<String> {
    let mut v = names;
    if v.iter().all(|s| s.parse::<f64>().is_ok()) {
        v.sort_by(|a, b| {
            a.parse::<f64>()
                .unwrap()
                .total_cmp(&b.parse::<f64>().unwrap())
        });
    } else {
        v.sort();
    }
    v.dedup();
    v
}

/// What a plot does with the runs that collapsed (`pound plot --collapsed`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Collapsed {
    /// Left out of the series, and counted in the figure's caption per x value (and series):
    /// a collapsed run's peaks are its motion up to the collapse, not a demand.
    #[default]
    Omit,
    /// Drawn apart: their peaks before the collapse, aggregated as the series' points are,
    /// with the collapse marker and a legend entry of their own.
    Mark,
}

/// The rows a plot left out, by reason (none is left out silently).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct LeftOut {
    /// Runs that failed (`status` neither `ok` nor `collapsed`): their values are whatever a
    /// diverged run held.
    pub failed: usize,
    /// Runs left out because they collapsed (`--collapsed omit`): the figure's caption counts
    /// them per x value.
    pub collapsed: usize,
    /// Rows with a value that is not finite.
    pub not_finite: usize,
    /// Per plotted column, rows where it is empty (a run that did not pound has no first
    /// impact; a run that did not settle, no residual drift).
    pub empty: Vec<(String, usize)>,
    /// Series (`--by` values) of which every row was left out, so none is drawn.
    pub vanished: Vec<String>,
}

impl LeftOut {
    /// One line per reason, each with its count, in the table of meanings' words.
    pub fn lines(&self) -> Vec<String> {
        let mut out = Vec::new();
        if self.failed > 0 {
            out.push(format!(
                "{} rows left out: runs whose status is not ok",
                self.failed
            ));
        }
        if self.collapsed > 0 {
            out.push(format!(
                "{} rows left out: runs that collapsed (counted in the figure's caption; --collapsed mark draws their peaks before the collapse)",
                self.collapsed
            ));
        }
        if self.not_finite > 0 {
            out.push(format!(
                "{} rows left out: values that are not finite",
                self.not_finite
            ));
        }
        for (column, n) in self.empty.iter().filter(|(_, n)| *n > 0) {
            let why = crate::plan::meaning::meaning(column)
                .and_then(|m| m.when_empty().map(str::to_string))
                .map_or(String::new(), |w| format!(" ({w})"));
            out.push(format!("{n} rows left out: {column} is empty{why}"));
        }
        for g in &self.vanished {
            out.push(format!(
                "no series drawn for {g}: every one of its rows was left out"
            ));
        }
        out
    }
}

/// What a row is, for the plotted column.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum RowIs {
    Result,
    Collapsed,
    Failed,
}

/// How a table tells whether a run collapsed, for the plotted column: a building's column
/// (`b2_peak_drift_ratio`) reads that building's `b2_collapsed` where the table has it, so a
/// run where only its neighbour collapsed is a result for it; any other column reads the run's
/// `status`.
struct CollapseOf {
    status: Option<usize>,
    /// The plotted building's `bK_collapsed`, where the y column is a building's.
    building: Option<(usize, String)>,
    /// Every building's `bK_collapsed`: a collapsed run where none of them is 1 was written
    /// before each building's collapse had its columns, and its `status` says it all.
    buildings: Vec<usize>,
}

impl CollapseOf {
    fn new(table: &Table, y: &str) -> CollapseOf {
        let building = y
            .strip_prefix('b')
            .and_then(|rest| rest.split_once('_'))
            .filter(|(k, _)| !k.is_empty() && k.bytes().all(|b| b.is_ascii_digit()))
            .and_then(|(k, _)| {
                let c = table.col(&format!("b{k}_collapsed")).ok()?;
                Some((c, k.to_string()))
            });
        let buildings = (table.header.iter().enumerate())
            .filter(|(_, h)| {
                h.strip_prefix('b')
                    .and_then(|r| r.strip_suffix("_collapsed"))
                    .is_some_and(|k| !k.is_empty() && k.bytes().all(|b| b.is_ascii_digit()))
            })
            .map(|(c, _)| c)
            .collect();
        CollapseOf {
            status: table.col("status").ok(),
            building,
            buildings,
        }
    }

    /// What `row` is, and whether its building's own column said so.
    fn of(&self, row: &[String]) -> (RowIs, bool) {
        let status = self.status.map(|c| row[c].trim());
        if status.is_some_and(|s| s != "ok" && s != "collapsed") {
            return (RowIs::Failed, false);
        }
        let one = |c: usize| row[c].trim() == "1";
        if let Some((c, _)) = self.building {
            if status.is_none() || self.buildings.iter().any(|&b| one(b)) {
                let is = if one(c) {
                    RowIs::Collapsed
                } else {
                    RowIs::Result
                };
                return (is, true);
            }
        }
        match status {
            Some("collapsed") => (RowIs::Collapsed, false),
            _ => (RowIs::Result, false),
        }
    }
}

/// Runs at one x of one series: how many, and how many collapsed.
#[derive(Debug, Clone, Copy, Default)]
struct AtX {
    x: f64,
    runs: usize,
    collapsed: usize,
}

impl AtX {
    /// `all 80` or `76 of 80`.
    fn share(&self) -> String {
        if self.collapsed == self.runs {
            format!("all {}", self.runs)
        } else {
            format!("{} of {}", self.collapsed, self.runs)
        }
    }
}

/// `points` aggregated at each x by `agg` (none: every point), in increasing x.
fn aggregated(points: &[(f64, f64)], agg: Aggregate) -> Vec<(f64, f64)> {
    if agg == Aggregate::None {
        return points.to_vec();
    }
    let mut at: BTreeMap<u64, (f64, Vec<f64>)> = BTreeMap::new();
    for &(x, y) in points {
        at.entry(order_key(x)).or_insert((x, Vec::new())).1.push(y);
    }
    at.into_values()
        .map(|(x, mut ys)| (x, agg.apply(&mut ys)))
        .collect()
}

/// The panel for `spec` over `table`, and the rows left out (counted by reason): runs whose
/// `status` is not `ok` (their values are whatever a diverged run held), rows with an empty x
/// or y (a run that did not pound has no first impact) and non-finite values. Runs that
/// collapsed are left out as [`Collapsed::Omit`] does: [`panel_with`] chooses.
pub fn panel(table: &Table, spec: &PlotSpec) -> Result<(Panel, LeftOut), TableError> {
    panel_with(table, spec, Collapsed::Omit)
}

/// [`panel`], with the runs that collapsed left out or drawn apart as `collapsed` says. Either
/// way the panel's caption counts them per x value (and series), and an x value at which no
/// run gives a point is kept on the axis, marked with its count (`all 80 collapsed`); a
/// table where nothing collapsed gives the panel it gave before.
pub fn panel_with(
    table: &Table,
    spec: &PlotSpec,
    collapsed: Collapsed,
) -> Result<(Panel, LeftOut), TableError> {
    table.check_columns()?;
    let (cx, cy) = (table.col(&spec.x)?, table.col(&spec.y)?);
    let cby = spec.by.as_deref().map(|b| table.col(b)).transpose()?;
    let collapse = CollapseOf::new(table, &spec.y);
    let rows = table.select(&spec.filters)?;
    let mut groups: BTreeMap<String, Vec<(f64, f64)>> = BTreeMap::new();
    // Per series, the collapsed runs' points, and the runs at each x.
    let mut fallen: BTreeMap<String, Vec<(f64, f64)>> = BTreeMap::new();
    let mut runs_at: BTreeMap<String, BTreeMap<u64, AtX>> = BTreeMap::new();
    let mut by_building = false;
    let mut left = LeftOut::default();
    let (mut empty_x, mut empty_y) = (0, 0);
    // Every series a kept row belongs to, drawn or not.
    let mut seen: std::collections::BTreeSet<String> = std::collections::BTreeSet::new();
    for i in rows {
        // A numeric series and x are taken at `level`: one value computed per record is one
        // series and one x (a scaled PGA of `0.20000000000000004` joins `0.2`'s).
        let g = cby.map_or(String::new(), |c| {
            let cell = &table.rows[i][c];
            match cell.trim().parse::<f64>() {
                Ok(v) if v.is_finite() => level(v).to_string(),
                _ => cell.clone(),
            }
        });
        if !seen.contains(&g) {
            seen.insert(g.clone());
        }
        let (is, own) = collapse.of(&table.rows[i]);
        // Every run at an x counts there, whatever became of it (a failed run's x may be an
        // output it did not reach: then it counts nowhere).
        let at_x = table.num(i, cx).ok().flatten().filter(|x| x.is_finite());
        if let Some(x) = at_x.map(level) {
            let at = (runs_at.entry(g.clone()).or_default())
                .entry(order_key(x))
                .or_insert(AtX {
                    x,
                    ..AtX::default()
                });
            at.runs += 1;
            at.collapsed += usize::from(is == RowIs::Collapsed);
        }
        match is {
            RowIs::Failed => {
                left.failed += 1;
                continue;
            }
            RowIs::Collapsed => {
                by_building |= own;
                match collapsed {
                    Collapsed::Omit => left.collapsed += 1,
                    Collapsed::Mark => {
                        let y = table.num(i, cy)?.filter(|y| y.is_finite());
                        if let (Some(x), Some(y)) = (at_x, y) {
                            fallen.entry(g).or_default().push((level(x), y));
                        }
                    }
                }
                continue;
            }
            RowIs::Result => {}
        }
        let (x, y) = (table.num(i, cx)?, table.num(i, cy)?);
        let (Some(x), Some(y)) = (x, y) else {
            empty_x += usize::from(x.is_none());
            empty_y += usize::from(x.is_some() && y.is_none());
            continue;
        };
        if !(x.is_finite() && y.is_finite()) {
            left.not_finite += 1;
            continue;
        }
        groups.entry(g).or_default().push((level(x), y));
    }
    left.empty = vec![(spec.x.clone(), empty_x), (spec.y.clone(), empty_y)];
    // A series whose runs all collapsed is drawn where its collapsed runs are.
    for g in fallen.keys() {
        groups.entry(g.clone()).or_default();
    }
    if let Some(b) = &spec.by {
        left.vanished = sorted_groups(seen.into_iter().collect())
            .into_iter()
            .filter(|g| !groups.contains_key(g))
            .map(|g| value_label(b, &g))
            .collect();
    }
    let names = sorted_groups(groups.keys().cloned().collect());
    let series_name = |g: &str| match &spec.by {
        Some(b) => value_label(b, g),
        None => label(&spec.y),
    };
    let series: Vec<Series> = names
        .iter()
        .map(|g| Series {
            name: series_name(g),
            points: aggregated(&groups[g], spec.aggregate),
            scatter: spec.aggregate == Aggregate::None,
            style: None,
        })
        .collect();
    let mut notes = crate::studies::plot::Notes::default();
    for (k, g) in names.iter().enumerate() {
        let marked = fallen
            .get(g)
            .map_or(Vec::new(), |v| aggregated(v, spec.aggregate));
        notes.collapsed.extend(marked.into_iter().map(|q| (k, q)));
    }
    let any_collapsed = runs_at
        .values()
        .flat_map(|m| m.values())
        .any(|a| a.collapsed > 0);
    if any_collapsed {
        let who = match (&collapse.building, by_building) {
            (Some((_, k)), true) => format!("runs in which building {k} collapsed"),
            _ => "runs that collapsed".to_string(),
        };
        let (what, how) = match collapsed {
            Collapsed::Omit => ("left out", String::new()),
            Collapsed::Mark => (
                "drawn apart",
                format!(
                    " (crossed squares: their peaks before the collapse{})",
                    match spec.aggregate {
                        Aggregate::None => String::new(),
                        a => format!(", the {} at each x", a.key()),
                    }
                ),
            ),
        };
        let shares = |m: &BTreeMap<u64, AtX>| -> Vec<String> {
            m.values()
                .filter(|a| a.collapsed > 0)
                .map(|a| format!("{}, {}", quantity(&spec.x, a.x), a.share()))
                .collect()
        };
        let head = format!("{} {what}{how}", capitalised(&who));
        match &spec.by {
            None => {
                let m = runs_at.values().next().expect("a run collapsed");
                notes.caption.push(format!(
                    "{head}, of the runs at each {}: {}.",
                    name(&spec.x),
                    shares(m).join("; ")
                ));
            }
            Some(_) => {
                notes.caption.push(format!(
                    "{head}, of each series' runs at each {}:",
                    name(&spec.x)
                ));
                for g in sorted_groups(runs_at.keys().cloned().collect()) {
                    let s = shares(&runs_at[&g]);
                    if !s.is_empty() {
                        notes
                            .caption
                            .push(format!("{}: {}.", series_name(&g), s.join("; ")));
                    }
                }
            }
        }
        notes.collapsed_name = "collapsed: peak before the collapse".into();
        // The x values where no series has a point of a run that did not collapse, each kept
        // on the axis with the count of its runs (over every series).
        let mut at: BTreeMap<u64, AtX> = BTreeMap::new();
        for a in runs_at.values().flat_map(|m| m.values()) {
            let t = at.entry(order_key(a.x)).or_insert(AtX {
                x: a.x,
                ..AtX::default()
            });
            t.runs += a.runs;
            t.collapsed += a.collapsed;
        }
        let drawn: std::collections::BTreeSet<u64> = groups
            .values()
            .flat_map(|v| v.iter().map(|q| order_key(q.0)))
            .collect();
        notes.x_marks = at
            .into_iter()
            .filter(|(k, a)| a.collapsed > 0 && !drawn.contains(k))
            .map(|(_, a)| (a.x, format!("{} collapsed", a.share())))
            .collect();
    }
    let mut title = format!("{} against {}", name(&spec.y), name(&spec.x));
    let apart = match (any_collapsed, collapsed) {
        (false, _) => "",
        (true, Collapsed::Omit) => "; collapsed runs left out",
        (true, Collapsed::Mark) => "; collapsed runs marked",
    };
    if spec.aggregate != Aggregate::None {
        title.push_str(&format!(
            " ({} over the other parameters{apart})",
            spec.aggregate.key()
        ));
    } else if !apart.is_empty() {
        title.push_str(&format!(" ({})", &apart[2..]));
    }
    if !spec.filters.is_empty() {
        title.push_str(&format!("; {}", caption(&spec.filters)));
    }
    Ok((
        Panel {
            title,
            x_label: label(&spec.x),
            y_label: label(&spec.y),
            log_x: spec.log_x,
            log_y: spec.log_y,
            series,
            y_span: None,
            notes,
        },
        left,
    ))
}

/// `text` with its first letter in capitals.
fn capitalised(text: &str) -> String {
    let mut c = text.chars();
    match c.next() {
        Some(f) => f.to_uppercase().chain(c).collect(),
        None => String::new(),
    }
}
