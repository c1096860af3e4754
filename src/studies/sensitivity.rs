//! Sensitivity plots from a results CSV (`pound plot`): an output against a swept parameter, one
//! series per value of a grouping column. Rows can be fixed by filters; the parameters neither
//! plotted nor grouped are aggregated over (max, mean, median or min of the output at each x),
//! or every row is drawn as a point.

use crate::io::table::{
    caption, label, level, name, order_key, value_label, Filter, Table, TableError,
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

/// The rows a plot left out, by reason (none is left out silently).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct LeftOut {
    /// Runs whose `status` is not `ok`: their values are whatever a diverged run held.
    pub failed: usize,
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

/// The panel for `spec` over `table`, and the rows left out (counted by reason): runs whose
/// `status` is not `ok` (their values are whatever a diverged run held), rows with an empty x
/// or y (a run that did not pound has no first impact) and non-finite values.
pub fn panel(table: &Table, spec: &PlotSpec) -> Result<(Panel, LeftOut), TableError> {
    let (cx, cy) = (table.col(&spec.x)?, table.col(&spec.y)?);
    let cby = spec.by.as_deref().map(|b| table.col(b)).transpose()?;
    let cstatus = table.col("status").ok();
    let rows = table.select(&spec.filters)?;
    let mut groups: BTreeMap<String, Vec<(f64, f64)>> = BTreeMap::new();
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
        if cstatus.is_some_and(|c| table.rows[i][c] != "ok") {
            left.failed += 1;
            continue;
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
    if let Some(b) = &spec.by {
        left.vanished = sorted_groups(seen.into_iter().collect())
            .into_iter()
            .filter(|g| !groups.contains_key(g))
            .map(|g| value_label(b, &g))
            .collect();
    }
    let names = sorted_groups(groups.keys().cloned().collect());
    let series = names
        .into_iter()
        .map(|g| {
            let pts = &groups[&g];
            let points = if spec.aggregate == Aggregate::None {
                pts.clone()
            } else {
                let mut at: BTreeMap<u64, (f64, Vec<f64>)> = BTreeMap::new();
                for &(x, y) in pts {
                    at.entry(order_key(x)).or_insert((x, Vec::new())).1.push(y);
                }
                at.into_values()
                    .map(|(x, mut ys)| (x, spec.aggregate.apply(&mut ys)))
                    .collect()
            };
            let name = match &spec.by {
                Some(b) => value_label(b, &g),
                None => label(&spec.y),
            };
            Series {
                name,
                points,
                scatter: spec.aggregate == Aggregate::None,
                style: None,
            }
        })
        .collect();
    let mut title = format!("{} against {}", name(&spec.y), name(&spec.x));
    if spec.aggregate != Aggregate::None {
        title.push_str(&format!(
            " ({} over the other parameters)",
            spec.aggregate.key()
        ));
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
        },
        left,
    ))
}
