//! An incremental dynamic analysis summary from a results CSV (`pound ida`): per curve (a
//! record, or a record and a sample) the demand against the intensity, and across curves the
//! 16, 50 and 84 % fractiles of the demand at each intensity level, over the runs with a value
//! there: a failed run (a collapse or a numerical failure) or one with no value of the demand (a
//! residual drift where the run did not settle) is left out and counted at its level, so the
//! fractiles are collapse-free where runs failed, and say so.

use crate::io::table::{caption, label, name, order_key, Filter, Table, TableError};
use crate::studies::fragility::{demand_rows, quantile, Demand, LeftOut};
use crate::studies::plot::{Panel, Series};
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
    /// Per curve: its name and its demand at each level (None where it has no run there).
    pub curves: Vec<(String, Vec<Option<f64>>)>,
    /// Per level: the curves with a run there, and the [`FRACTILES`] of their demands.
    pub counts: Vec<usize>,
    pub fractiles: Vec<[f64; 3]>,
    /// Per level: runs left out there, failed (status not `ok`) and with no value of the demand.
    pub failed: Vec<usize>,
    pub no_value: Vec<usize>,
}

#[derive(Debug, thiserror::Error)]
pub enum IdaError {
    #[error(transparent)]
    Table(#[from] TableError),
    #[error("{path}: rows {first} and {second} are both curve `{curve}` at {im} = {level}: name the columns that tell them apart with --by (e.g. --by record,sample,gap_m) or keep one with --where")]
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
}

/// Read the curves of `table` under `spec`, and the rows left out (status not `ok`, no value,
/// a value not finite).
pub fn read(table: &Table, spec: &IdaSpec) -> Result<(Ida, LeftOut), IdaError> {
    let (ci, ce) = (table.col(&spec.im)?, table.col(&spec.edp)?);
    let by: Vec<usize> = spec
        .by
        .iter()
        .map(|b| table.col(b))
        .collect::<Result<_, _>>()?;
    let mut skipped = LeftOut::default();
    let mut ims: BTreeMap<u64, f64> = BTreeMap::new();
    let mut names: Vec<String> = Vec::new();
    let mut curve_of: HashMap<String, usize> = HashMap::new();
    // (curve, level key) -> (row, demand)
    let mut points: HashMap<(usize, u64), (usize, f64)> = HashMap::new();
    // Runs kept out at a level: failed, and with no value of the demand.
    let mut missing: HashMap<u64, (usize, usize)> = HashMap::new();
    for (i, key, demand) in demand_rows(table, &spec.filters, ci, ce, &mut skipped)? {
        ims.insert(order_key(key), key);
        let Demand::Value(edp) = demand else {
            skipped.empty_edp += 1;
            missing.entry(order_key(key)).or_default().1 += 1;
            continue;
        };
        let name = by
            .iter()
            .map(|&c| table.rows[i][c].as_str())
            .collect::<Vec<_>>()
            .join("/");
        let c = *curve_of.entry(name.clone()).or_insert_with(|| {
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
            if table.rows[i][cs] != "ok" {
                if let Ok(Some(im)) = table.num(i, ci) {
                    let key = format!("{im:.11e}").parse::<f64>().unwrap_or(im);
                    ims.insert(order_key(key), key);
                    missing.entry(order_key(key)).or_default().0 += 1;
                }
            }
        }
    }
    let keys: Vec<u64> = ims.keys().copied().collect();
    let curves: Vec<(String, Vec<Option<f64>>)> = names
        .into_iter()
        .enumerate()
        .map(|(c, n)| {
            let v = keys
                .iter()
                .map(|k| points.get(&(c, *k)).map(|p| p.1))
                .collect();
            (n, v)
        })
        .collect();
    let mut counts = Vec::new();
    let mut fractiles = Vec::new();
    for l in 0..keys.len() {
        let mut v: Vec<f64> = curves.iter().filter_map(|c| c.1[l]).collect();
        v.sort_by(f64::total_cmp);
        counts.push(v.len());
        fractiles.push(FRACTILES.map(|f| quantile(&v, f / 100.0)));
    }
    let at = |k: &u64| missing.get(k).copied().unwrap_or_default();
    Ok((
        Ida {
            ims: ims.into_values().collect(),
            curves,
            counts,
            fractiles,
            failed: keys.iter().map(|k| at(k).0).collect(),
            no_value: keys.iter().map(|k| at(k).1).collect(),
        },
        skipped,
    ))
}

impl Ida {
    /// One row per level: the intensity, the curves there, the fractiles, each curve's demand.
    pub fn csv(&self, spec: &IdaSpec) -> String {
        let quote = |s: &str| {
            if s.contains([',', '"', '\n']) {
                format!("\"{}\"", s.replace('"', "\"\""))
            } else {
                s.to_string()
            }
        };
        let mut s = format!("{},curves", quote(&spec.im));
        for f in FRACTILES {
            s.push_str(&format!(",{}_p{f}", quote(&spec.edp)));
        }
        for (n, _) in &self.curves {
            s.push(',');
            s.push_str(&quote(n));
        }
        s.push('\n');
        for (l, im) in self.ims.iter().enumerate() {
            s.push_str(&format!("{im},{}", self.counts[l]));
            for f in self.fractiles[l] {
                // No fractile of no runs: an empty cell.
                s.push(',');
                if self.counts[l] > 0 {
                    s.push_str(&f.to_string());
                }
            }
            for (_, v) in &self.curves {
                s.push(',');
                if let Some(x) = v[l] {
                    s.push_str(&x.to_string());
                }
            }
            s.push('\n');
        }
        s
    }

    /// The curves (demand on x, intensity on y, as IDA curves are drawn) and the fractiles;
    /// beyond [`NAMED_CURVES`] curves, each is a grey line with no legend entry.
    pub fn panel(&self, spec: &IdaSpec) -> Panel {
        let named = self.curves.len() <= NAMED_CURVES;
        let mut series: Vec<Series> = self
            .curves
            .iter()
            .map(|(n, v)| Series {
                name: if named { n.clone() } else { String::new() },
                points: v
                    .iter()
                    .zip(&self.ims)
                    .filter_map(|(x, &im)| x.map(|x| (x, im)))
                    .collect(),
                scatter: false,
                style: None,
            })
            .collect();
        for (k, f) in FRACTILES.iter().enumerate() {
            series.push(Series {
                name: format!("{f} % fractile"),
                points: self
                    .fractiles
                    .iter()
                    .zip(&self.ims)
                    .filter(|(q, _)| q[k].is_finite())
                    .map(|(q, &im)| (q[k], im))
                    .collect(),
                scatter: false,
                style: None,
            });
        }
        Panel {
            // The rows kept, as pound plot's and pound fragility's titles say them.
            title: format!(
                "IDA: {} against {} ({} curves{}){}",
                name(&spec.edp),
                name(&spec.im),
                self.curves.len(),
                if named { "" } else { " in grey" },
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
        }
    }
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
            "target_sa_g,curves,drift_p16,drift_p50,drift_p84,rec1,rec2,rec3,rec4,rec5\n0.1,5,"
        ));
    }

    #[test]
    fn two_runs_of_one_curve_at_one_level_are_refused() {
        let text = "run,record,sample,target_sa_g,status,drift\n0,a,0,0.1,ok,1\n1,a,1,0.1,ok,2\n";
        let e = read(&table(text), &spec(&["record"]))
            .unwrap_err()
            .to_string();
        assert!(e.contains("rows 2 and 3") && e.contains("--by"), "{e}");
        let (ida, _) = read(&table(text), &spec(&["record", "sample"])).unwrap();
        assert_eq!(ida.curves.len(), 2);
        assert_eq!(ida.curves[1].0, "a/1");
    }
}
