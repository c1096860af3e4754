//! In-engine aggregation for sweeps too large to store run by run (`pound sweep --aggregate`):
//! per group of swept parameters, run counts, exceedance counts for given thresholds, and the
//! max, mean and quantiles of each output. Rows are folded in as chunks finish, so memory is
//! bounded by the number of groups, not of runs. Quantiles come from a log-bucket sketch with a
//! relative error of at most 1 % (DDSketch-style: a value's bucket is `ceil(log_g |x|)`,
//! `g = 1.02`); max and mean are exact.

use crate::output::header;
use std::collections::hash_map::Entry;
use std::collections::{BTreeMap, HashMap};

/// Outputs summarised per group.
pub const OUTPUTS: [&str; 8] = [
    "impacts",
    "peak_force_n",
    "peak_penetration_m",
    "peak_u1_m",
    "peak_u2_m",
    "impact_velocity_m_s",
    "contact_time_s",
    "dissipated_energy_j",
];

/// Quantiles reported for each output.
pub const QUANTILES: [f64; 3] = [0.5, 0.9, 0.99];

const GAMMA: f64 = 1.02;

/// Quantile sketch of non-negative values (outputs are magnitudes).
#[derive(Debug, Clone, Default)]
pub struct Sketch {
    zeros: u64,
    buckets: BTreeMap<i32, u64>,
    count: u64,
    sum: f64,
    max: f64,
}

impl Sketch {
    pub fn add(&mut self, x: f64) {
        let x = x.abs();
        self.count += 1;
        self.sum += x;
        self.max = self.max.max(x);
        if x < 1e-300 {
            self.zeros += 1;
        } else {
            *self
                .buckets
                .entry((x.ln() / GAMMA.ln()).ceil() as i32)
                .or_default() += 1;
        }
    }

    pub fn mean(&self) -> f64 {
        self.sum / self.count.max(1) as f64
    }

    /// The `q` quantile, within 1 % of a value of the data at that rank.
    pub fn quantile(&self, q: f64) -> f64 {
        if self.count == 0 {
            return f64::NAN;
        }
        let rank = (q * (self.count - 1) as f64).round() as u64;
        if rank < self.zeros {
            return 0.0;
        }
        let mut seen = self.zeros;
        for (&k, &n) in &self.buckets {
            seen += n;
            if seen > rank {
                // The bucket's midpoint in the sense of relative error.
                return 2.0 * GAMMA.powi(k) / (1.0 + GAMMA);
            }
        }
        self.max
    }
}

/// One group's summary.
#[derive(Debug, Clone, Default)]
pub struct Group {
    pub runs: u64,
    pub failures: u64,
    pub exceed: Vec<u64>,
    pub stats: Vec<Sketch>,
}

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum AggregateError {
    #[error("--aggregate: `{0}` is not a column; group by swept parameters such as record, pga_g, gap_m, t1_s, law, e")]
    NoColumn(String),
    #[error("--exceed `{0}`: expected COLUMN=THRESHOLD with a numeric output column, e.g. peak_force_n=1e6")]
    BadExceed(String),
}

/// Folds rows into groups.
#[derive(Debug, Clone)]
pub struct Aggregator {
    by: Vec<(String, usize)>,
    exceed: Vec<(String, usize, f64)>,
    outputs: Vec<usize>,
    status: usize,
    groups: HashMap<Vec<String>, Group>,
    /// Group keys in the order of their first run (the summary's row order).
    order: Vec<Vec<String>>,
}

impl Aggregator {
    /// Group by the columns `by`; count runs whose `column > threshold` for each `exceed`.
    pub fn new(by: &[String], exceed: &[String]) -> Result<Aggregator, AggregateError> {
        let h = header();
        let col = |name: &str| h.iter().position(|c| *c == name);
        let by = by
            .iter()
            .map(|b| {
                col(b)
                    .map(|i| (b.clone(), i))
                    .ok_or_else(|| AggregateError::NoColumn(b.clone()))
            })
            .collect::<Result<_, _>>()?;
        let exceed = exceed
            .iter()
            .map(|e| {
                let bad = || AggregateError::BadExceed(e.clone());
                let (c, t) = e.split_once('=').ok_or_else(bad)?;
                let i = col(c.trim())
                    .filter(|_| OUTPUTS.contains(&c.trim()))
                    .ok_or_else(bad)?;
                let t: f64 = t.trim().parse().map_err(|_| bad())?;
                Ok((c.trim().to_string(), i, t))
            })
            .collect::<Result<_, _>>()?;
        Ok(Aggregator {
            by,
            exceed,
            outputs: OUTPUTS
                .iter()
                .map(|o| col(o).expect("output column"))
                .collect(),
            status: col("status").expect("status column"),
            groups: HashMap::new(),
            order: Vec::new(),
        })
    }

    /// Fold in one run's row (`output::row`). Failed runs are counted, not summarised.
    pub fn add(&mut self, row: &[String]) {
        let key: Vec<String> = self.by.iter().map(|(_, i)| row[*i].clone()).collect();
        let (ne, no) = (self.exceed.len(), self.outputs.len());
        let g = match self.groups.entry(key) {
            Entry::Occupied(e) => e.into_mut(),
            Entry::Vacant(e) => {
                self.order.push(e.key().clone());
                e.insert(Group {
                    exceed: vec![0; ne],
                    stats: vec![Sketch::default(); no],
                    ..Default::default()
                })
            }
        };
        g.runs += 1;
        if row[self.status] != "ok" {
            g.failures += 1;
            return;
        }
        let num = |i: usize| row[i].parse::<f64>().unwrap_or(0.0);
        for (k, (_, i, t)) in self.exceed.iter().enumerate() {
            g.exceed[k] += (num(*i) > *t) as u64;
        }
        for (k, &i) in self.outputs.iter().enumerate() {
            g.stats[k].add(num(i));
        }
    }

    pub fn groups(&self) -> usize {
        self.groups.len()
    }

    /// The summary as CSV, groups in the order of their first run.
    pub fn csv(&self) -> String {
        let mut head: Vec<String> = self.by.iter().map(|(b, _)| b.clone()).collect();
        head.push("runs".into());
        head.push("failures".into());
        for (c, _, t) in &self.exceed {
            head.push(format!("exceed_{c}>{t}"));
        }
        for o in OUTPUTS {
            head.push(format!("{o}_max"));
            head.push(format!("{o}_mean"));
            for q in QUANTILES {
                head.push(format!("{o}_p{}", (q * 100.0).round()));
            }
        }
        let mut w = csv::Writer::from_writer(Vec::new());
        w.write_record(&head).expect("in memory");
        for key in &self.order {
            let g = &self.groups[key];
            let mut r = key.clone();
            r.push(g.runs.to_string());
            r.push(g.failures.to_string());
            r.extend(g.exceed.iter().map(|n| n.to_string()));
            for s in &g.stats {
                r.push(format!("{}", s.max));
                r.push(format!("{}", s.mean()));
                for q in QUANTILES {
                    r.push(format!("{}", s.quantile(q)));
                }
            }
            w.write_record(&r).expect("in memory");
        }
        String::from_utf8(w.into_inner().expect("in memory")).expect("utf-8")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sketch_quantiles_within_one_percent() {
        let mut s = Sketch::default();
        let xs: Vec<f64> = (0..10_000).map(|i| 1.0 + (i as f64).powf(1.7)).collect();
        for &x in &xs {
            s.add(x);
        }
        s.add(0.0);
        let mut sorted = xs.clone();
        sorted.push(0.0);
        sorted.sort_by(f64::total_cmp);
        for q in [0.0, 0.5, 0.9, 0.99, 1.0] {
            let exact = sorted[(q * (sorted.len() - 1) as f64).round() as usize];
            let got = s.quantile(q);
            assert!(
                (got - exact).abs() <= 0.01 * exact,
                "q {q}: {got} vs {exact}"
            );
        }
        assert_eq!(s.max, *sorted.last().unwrap());
    }
}
