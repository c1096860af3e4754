//! An `--aggregate` summary as CSV: one row per group, in the order of the group's first run,
//! with run and failure counts, `--exceed` counts, and max, mean and quantiles of each output.

use crate::engine::aggregate::{Aggregator, QUANTILES};

/// The summary of `agg` as CSV text.
pub fn csv(agg: &Aggregator) -> String {
    let mut head: Vec<String> = agg.by().map(str::to_string).collect();
    head.push("runs".into());
    head.push("failures".into());
    for (c, t) in agg.exceed() {
        head.push(format!("exceed_{c}>{t}"));
    }
    for o in agg.outputs() {
        head.push(format!("{o}_max"));
        head.push(format!("{o}_mean"));
        for q in QUANTILES {
            head.push(format!("{o}_p{}", (q * 100.0).round()));
        }
    }
    let mut w = csv::Writer::from_writer(Vec::new());
    w.write_record(&head).expect("in memory");
    for (label, g) in agg.labelled() {
        let mut r = label.to_vec();
        r.push(g.runs.to_string());
        r.push(g.failures.to_string());
        r.extend(g.exceed.iter().map(|n| n.to_string()));
        for s in &g.stats {
            // A group with no `ok` run has no statistics: empty cells, not zeros.
            if s.count() == 0 {
                r.extend(std::iter::repeat_n(String::new(), 2 + QUANTILES.len()));
                continue;
            }
            r.push(format!("{}", s.max()));
            r.push(format!("{}", s.mean()));
            for q in QUANTILES {
                r.push(format!("{}", s.quantile(q)));
            }
        }
        w.write_record(&r).expect("in memory");
    }
    String::from_utf8(w.into_inner().expect("in memory")).expect("utf-8")
}
