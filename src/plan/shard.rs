//! Deterministic cost-balanced shards of a plan (`--shard I/N`, for Slurm job arrays or
//! Kubernetes Indexed Jobs): contiguous run ranges that tile the plan.

use crate::plan::contact::ContactPlan;
use crate::plan::scene::Plan;
use serde::{Deserialize, Serialize};
use std::ops::Range;

/// Shard `i` of `n` (0-based).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Shard {
    pub index: u64,
    pub count: u64,
}

impl Shard {
    /// `I/N` with `0 <= I < N`.
    pub fn parse(s: &str) -> Option<Shard> {
        let (i, n) = s.split_once('/')?;
        let (index, count) = (i.trim().parse().ok()?, n.trim().parse().ok()?);
        (count > 0 && index < count).then_some(Shard { index, count })
    }
}

/// The runs of shard `shard`: contiguous ranges cut where the cumulative estimated cost reaches
/// `k / N` of the total. A run's cost is its number of record intervals (record plus tail): the
/// free stepping that every run pays; contact work is not known before the run. Shards of one
/// plan tile `0..len` exactly. Each cut is a binary search over [`PairPlan::cost_before`], so a
/// shard of 1e8 runs is planned in microseconds.
pub fn shard_range(plan: &Plan, shard: Shard) -> Range<u64> {
    // Every run of a row has the same buildings' storeys, so for pairs and rows alike a run's
    // cost is its record's intervals.
    let costs = record_costs(plan.contact());
    cut_by_cost(plan.len(), |end| plan.cost_before(end, &costs), shard)
}

/// Each record's intervals (record plus tail), at least 1.
fn record_costs(plan: &ContactPlan) -> Vec<u64> {
    plan.spec
        .records
        .iter()
        .map(|r| r.forcing(1.0, plan.spec.tail).intervals().max(1) as u64)
        .collect()
}

/// Shard `shard` of `0..n`, given the summed cost of the runs before each run.
fn cut_by_cost(n: u64, cost_before: impl Fn(u64) -> u128, shard: Shard) -> Range<u64> {
    let total = cost_before(n);
    // Cut k: the first run i whose preceding cost reaches k / N of the total (exact integers).
    let cut = |k: u64| -> u64 {
        if k == 0 {
            return 0;
        }
        if k >= shard.count {
            return n;
        }
        let target = total * k as u128;
        let (mut lo, mut hi) = (0u64, n);
        while lo < hi {
            let mid = lo + (hi - lo) / 2;
            if cost_before(mid) * shard.count as u128 >= target {
                hi = mid;
            } else {
                lo = mid + 1;
            }
        }
        lo
    };
    cut(shard.index)..cut(shard.index + 1)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two records of different lengths, so runs differ in cost: 3 x 2 x 2 = 12 runs.
    fn plan() -> crate::plan::pair::PairPlan {
        crate::plan::config::parse_builtin(
            r#"
[building1]
mass_kg = 1.0e5
period_s = [0.3, 0.5, 0.7]
damping_ratio = 0.05
[building2]
mass_kg = 1.0e5
period_s = 0.9
damping_ratio = 0.05
[contact]
law = "linear"
k_n_per_m = 1e9
gap_m = [0.0, 0.01]
[[record]]
synthetic = { seed = 1, duration_s = 2.0 }
[[record]]
synthetic = { seed = 2, duration_s = 8.0 }
"#,
            "shards.toml",
        )
        .unwrap()
    }

    #[test]
    fn parse_takes_i_of_n_only() {
        assert_eq!(
            Shard::parse("3/16"),
            Some(Shard {
                index: 3,
                count: 16
            })
        );
        assert_eq!(Shard::parse(" 0 / 1 "), Some(Shard { index: 0, count: 1 }));
        for bad in ["16/16", "1/0", "-1/4", "1", "a/b", "1/2/3", ""] {
            assert_eq!(Shard::parse(bad), None, "{bad}");
        }
    }

    /// For every N, the shards tile `0..len` in order, with no gap and no overlap, and each
    /// holds close to `1/N` of the cost (within one run's cost of the ideal cut).
    #[test]
    fn shards_tile_the_plan_and_balance_cost() {
        let plan = plan();
        let n = plan.len();
        assert_eq!(n, 12);
        let cost = |r: Range<u64>| -> u64 {
            r.map(|i| {
                let s = plan.run(i);
                plan.contact.spec.records[s.record]
                    .forcing(1.0, plan.contact.spec.tail)
                    .intervals() as u64
            })
            .sum()
        };
        let total = cost(0..n);
        let most = (0..n).map(|i| cost(i..i + 1)).max().unwrap();
        for count in [1, 2, 3, 5, 12, 13, 40] {
            let mut next = 0;
            for index in 0..count {
                let r = shard_range(&Plan::Pair(plan.clone()), Shard { index, count });
                assert_eq!(
                    r.start, next,
                    "shard {index}/{count} starts where the last ended"
                );
                assert!(r.end >= r.start);
                let ideal = total as f64 / count as f64;
                assert!(
                    (cost(r.clone()) as f64 - ideal).abs() <= most as f64,
                    "shard {index}/{count}: cost {} against {ideal}",
                    cost(r.clone())
                );
                next = r.end;
            }
            assert_eq!(next, n, "{count} shards cover every run");
        }
    }
}
