//! The runs of a table counted per group (record), threshold and intensity level: what a
//! fragility fits and a bootstrap resamples.

use super::demand::{
    bounding_column, check_collapse_table, demand_rows, CollapseOf, Demand, FragilitySpec, LeftOut,
};
use crate::io::table::{order_key, Table, TableError};
use crate::studies::stats::{bootstrap, Band, Level};
use std::collections::BTreeMap;

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

    /// [`bootstrap`] over the groups: `replicates` refits of the counts with the groups drawn
    /// with replacement (seeded), per threshold, the band read at `ims`.
    pub fn bootstrap(&self, replicates: usize, seed: u64, ims: &[f64]) -> Vec<Option<Band>> {
        let thresholds = self.counts.first().map_or(0, |c| c.len());
        bootstrap(
            self.groups.len(),
            thresholds,
            |w| self.pooled(w),
            replicates,
            seed,
            ims,
        )
    }

    /// Runs undecided at threshold `t`, at each level (over every group).
    pub fn undecided_at(&self, t: usize) -> Vec<u64> {
        (0..self.ims.len())
            .map(|l| self.undecided.iter().map(|u| u[t][l]).sum())
            .collect()
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
