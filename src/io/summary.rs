//! An `--aggregate` summary as CSV: one row per group, in the order of the group's first run,
//! with run and failure counts, `--exceed` counts, and max, mean and quantiles of each output;
//! a column that may be empty (a residual drift not known) adds how many runs had no value.

use crate::engine::aggregate::{may_be_empty, Aggregator, QUANTILES};
use crate::io::parquet::{kind, Kind};

/// A summary in memory: its column names, their types, and a row of cells per group (an empty
/// cell: no value).
pub struct SummaryTable {
    pub header: Vec<String>,
    pub kinds: Vec<Kind>,
    pub rows: Vec<Vec<String>>,
}

/// The summary of `agg` as CSV text.
pub fn csv(agg: &Aggregator) -> String {
    let t = table(agg);
    let mut w = csv::Writer::from_writer(Vec::new());
    w.write_record(&t.header).expect("in memory");
    for r in &t.rows {
        w.write_record(r).expect("in memory");
    }
    String::from_utf8(w.into_inner().expect("in memory")).expect("utf-8")
}

/// The summary of `agg`: a group's columns keep their types, counts are integers, statistics
/// reals.
pub fn table(agg: &Aggregator) -> SummaryTable {
    let mut head: Vec<String> = agg.by().map(str::to_string).collect();
    let mut kinds: Vec<Kind> = agg.by().map(kind).collect();
    let count = |head: &mut Vec<String>, kinds: &mut Vec<Kind>, name: String| {
        head.push(name);
        kinds.push(Kind::Int);
    };
    count(&mut head, &mut kinds, "runs".into());
    count(&mut head, &mut kinds, "failures".into());
    if agg.collapses() {
        count(&mut head, &mut kinds, "collapsed".into());
    }
    // Columns that may be empty (a residual drift not known) say how many runs had no value.
    let exceed_open: Vec<bool> = agg.exceed().map(|(c, _)| may_be_empty(c)).collect();
    let output_open: Vec<bool> = agg.outputs().map(may_be_empty).collect();
    for (c, t) in agg.exceed() {
        count(&mut head, &mut kinds, format!("exceed_{c}>{t}"));
        if may_be_empty(c) {
            count(&mut head, &mut kinds, format!("undecided_{c}>{t}"));
        }
    }
    for o in agg.outputs() {
        if may_be_empty(o) {
            count(&mut head, &mut kinds, format!("{o}_no_value"));
        }
        head.push(format!("{o}_max"));
        head.push(format!("{o}_mean"));
        for q in QUANTILES {
            head.push(format!("{o}_p{}", (q * 100.0).round()));
        }
        kinds.resize(head.len(), Kind::Real);
    }
    let mut rows = Vec::new();
    for (label, g) in agg.labelled() {
        let mut r = label.to_vec();
        r.push(g.runs.to_string());
        r.push(g.failures.to_string());
        if agg.collapses() {
            r.push(g.collapsed.to_string());
        }
        for (k, n) in g.exceed.iter().enumerate() {
            r.push(n.to_string());
            if exceed_open[k] {
                r.push(g.undecided[k].to_string());
            }
        }
        for (o, s) in g.stats.iter().enumerate() {
            if output_open[o] {
                r.push(g.no_value[o].to_string());
            }
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
        rows.push(r);
    }
    SummaryTable {
        header: head,
        kinds,
        rows,
    }
}

#[cfg(test)]
mod tests {
    use crate::engine::aggregate::Aggregator;

    /// A residual drift not known (an empty cell: the run did not settle) is neither over a
    /// threshold nor under it, and not a value: runs with one are counted in their own columns,
    /// out of the exceedances and the statistics, only beside the columns that can be empty;
    /// the others keep their form.
    #[test]
    fn empty_residual_cells_have_their_own_columns() {
        let header: Vec<String> = ["gap_m", "status", "b1_residual_drift_ratio", "impacts"]
            .map(String::from)
            .to_vec();
        let outputs: Vec<String> = ["b1_residual_drift_ratio", "impacts"]
            .map(String::from)
            .to_vec();
        let mut a = Aggregator::of_cells(
            &header,
            1,
            &outputs,
            &["gap_m".into()],
            &["b1_residual_drift_ratio=0.01".into(), "impacts=0".into()],
        )
        .unwrap();
        for (residual, impacts) in [("0.02", "3"), ("", "5"), ("0.001", "0"), ("", "1")] {
            let cells: Vec<String> = ["0.01", "ok", residual, impacts].map(String::from).to_vec();
            a.add_cells(&cells, crate::physics::model::Status::Ok);
        }
        let csv = super::csv(&a);
        let mut lines = csv.lines();
        let head: Vec<&str> = lines.next().unwrap().split(',').collect();
        let row: Vec<&str> = lines.next().unwrap().split(',').collect();
        let at = |c: &str| {
            row[head
                .iter()
                .position(|h| *h == c)
                .unwrap_or_else(|| panic!("{c}"))]
        };
        assert_eq!(at("exceed_b1_residual_drift_ratio>0.01"), "1");
        assert_eq!(at("undecided_b1_residual_drift_ratio>0.01"), "2");
        assert_eq!(at("b1_residual_drift_ratio_no_value"), "2");
        assert_eq!(at("b1_residual_drift_ratio_max"), "0.02");
        // The mean of the two values, not of four with two zeros.
        assert_eq!(at("b1_residual_drift_ratio_mean"), "0.0105");
        assert_eq!(at("exceed_impacts>0"), "3");
        assert!(!head
            .iter()
            .any(|h| h.starts_with("undecided_impacts") || *h == "impacts_no_value"));
    }
}
