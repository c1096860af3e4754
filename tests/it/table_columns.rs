//! Issue 65, items 4, 5 (first part) and 9: a study reads the column it names and no other, says
//! what a table lacks rather than what its runs did, and prints its statistics for what they
//! are. Tables written by hand give the exact cases:
//!
//! - a results table that names a column twice is refused, naming the column and the file, by
//!   every study that reads one (`pound fragility`, `pound ida`, `pound plot`, and the library's
//!   studies that the Python package calls with a table it built);
//! - a table a study writes never names a column twice: an IDA curve named like a fixed column
//!   (a record labelled `collapsed` or `pga_g`), two curves whose `--by` cells join alike, a
//!   fragility `--im` named like the table's own column, are refused with the column named;
//! - a table written with `--columns` that left the collapse columns out, whose `status` says
//!   `collapsed`, is read as one whose runs collapsed (never as one that could not collapse);
//! - a bootstrap band over the replicates that could be fitted is named conditional in its
//!   cells, its notice and its figure; a goodness of fit over levels that are all `0/n` or `n/n`
//!   prints no p.

use crate::support::cli::{stderr, write};
use crate::support::{ok, pound, tempdir};
use pounding::io::table::Table;
use pounding::studies::fragility::{self, FragilityOptions};
use pounding::studies::ida::{self, IdaOptions};
use std::path::Path;

fn s(p: &Path) -> String {
    p.to_str().unwrap().to_string()
}

/// Seven records at four levels of PGA: building 1's drift rises with the level, and a run
/// above 0.02 collapses (status `collapsed`). `extra` is put after `status` in the header and
/// `cell(record, level)` gives its cells.
fn ladder(extra: &str, cell: &dyn Fn(usize, usize) -> String) -> String {
    let mut t = format!("record,pga_g,status,{extra},b1_peak_drift_ratio\n");
    for r in 0..7 {
        for (l, pga) in [0.2, 0.4, 0.6, 0.8].iter().enumerate() {
            let drift = 0.004 * (l + 1) as f64 * (1.0 + 0.15 * r as f64);
            let status = if drift > 0.02 { "collapsed" } else { "ok" };
            t.push_str(&format!("rec{r},{pga},{status},{},{drift}\n", cell(r, l)));
        }
    }
    t
}

/// A column of zeros put before the demand of the same name: every study refuses the table,
/// naming the column and the file, where it read the zeros (a fit of nothing exceeding) before.
#[test]
fn a_column_named_twice_is_refused_by_every_study() {
    let dir = tempdir();
    let d = dir.path();
    let twice = write(
        d,
        "twice.csv",
        &ladder("b1_peak_drift_ratio", &|_, _| "0".into()),
    );
    let out = s(&d.join("out.csv"));
    let plot = s(&d.join("p.svg"));
    let commands: [Vec<&str>; 4] = [
        vec![
            "fragility",
            "--edp",
            "b1_peak_drift_ratio",
            "--threshold",
            "0.01",
            "-o",
            &out,
        ],
        vec!["fragility", "--edp", "collapsed", "-o", &out],
        vec!["ida", "--edp", "b1_peak_drift_ratio", "-o", &out],
        vec![
            "plot",
            "--x",
            "pga_g",
            "--y",
            "b1_peak_drift_ratio",
            "-o",
            &plot,
        ],
    ];
    let file = s(&twice);
    for args in &commands {
        let mut a = vec![args[0], file.as_str()];
        a.extend(&args[1..]);
        let o = pound(&a);
        let e = stderr(&o);
        assert!(!o.status.success(), "{args:?}: accepted");
        assert!(
            e.contains(&format!(
                "{file}: the column `b1_peak_drift_ratio` appears 2 times (columns 4, 5)"
            )),
            "{args:?}: {e}"
        );
        assert!(!d.join("out.csv").exists() && !d.join("p.svg").exists());
    }
    // A name given twice is refused where the study would not read it: which one a later
    // reader takes cannot be told either.
    let notes = write(d, "notes.csv", &ladder("note,note", &|_, _| "a,b".into()));
    let o = pound(&[
        "fragility",
        &s(&notes),
        "--edp",
        "b1_peak_drift_ratio",
        "--threshold",
        "0.01",
        "-o",
        &out,
    ]);
    assert!(
        stderr(&o).contains("the column `note` appears 2 times (columns 4, 5)"),
        "{}",
        stderr(&o)
    );
    // The library's studies, handed a table built in memory as the Python package builds one
    // from an Arrow table (whose names need not differ), refuse it too.
    let read = Table::read(&write(d, "once.csv", &ladder("zeros", &|_, _| "0".into()))).unwrap();
    let mut built = read.clone();
    built.path = "<table>".into();
    built.header[3] = "b1_peak_drift_ratio".into();
    let f = fragility::study(
        &built,
        &FragilityOptions {
            edp: "b1_peak_drift_ratio".into(),
            thresholds: vec![0.01],
            ..Default::default()
        },
    )
    .unwrap_err()
    .to_string();
    assert!(
        f.contains("<table>: the column `b1_peak_drift_ratio` appears 2 times"),
        "{f}"
    );
    let i = ida::study(&built, &IdaOptions::new("b1_peak_drift_ratio"))
        .unwrap_err()
        .to_string();
    assert!(
        i.contains("<table>: the column `b1_peak_drift_ratio` appears 2 times"),
        "{i}"
    );
    // The table with its names apart reads as before.
    let r = fragility::study(
        &read,
        &FragilityOptions {
            edp: "b1_peak_drift_ratio".into(),
            thresholds: vec![0.01],
            ..Default::default()
        },
    )
    .unwrap();
    assert!(
        r.said.starts_with("28 runs at 4 levels of pga_g"),
        "{}",
        r.said
    );
}

/// `pound ida` writes a column per curve, named by its record: a record labelled like one of the
/// table's own columns (`collapsed`, the intensity `pga_g`) would give a header that names it
/// twice (polars refuses such a table; a reader by name takes the first). Refused, naming it;
/// two curves whose `--by` cells join alike are refused too.
#[test]
fn an_ida_table_never_names_a_column_twice() {
    let dir = tempdir();
    let d = dir.path();
    let out = d.join("ida.csv");
    for label in ["collapsed", "pga_g", "curves", "b1_peak_drift_ratio_p50"] {
        let text = ladder("x", &|_, _| "0".into()).replace("rec3,", &format!("{label},"));
        let p = write(d, "labelled.csv", &text);
        let o = pound(&[
            "ida",
            &s(&p),
            "--edp",
            "b1_peak_drift_ratio",
            "-o",
            &s(&out),
        ]);
        let e = stderr(&o);
        assert!(!o.status.success(), "{label}: accepted");
        assert!(
            e.contains(&format!("the IDA table would have two columns `{label}`"))
                && e.contains(&format!("the curve `{label}`"))
                && e.contains("--curves"),
            "{label}: {e}"
        );
        assert!(!out.exists(), "{label}: written");
    }
    // `a/1` of sample 2 and `a` of sample `1/2` are both `a/1/2`.
    let mut text = String::from("record,sample,pga_g,status,b1_peak_drift_ratio\n");
    for (rec, sample) in [("a/1", "2"), ("a", "1/2")] {
        for pga in [0.2, 0.4] {
            text.push_str(&format!("{rec},{sample},{pga},ok,{}\n", pga / 100.0));
        }
    }
    let p = write(d, "joined.csv", &text);
    let o = pound(&[
        "ida",
        &s(&p),
        "--edp",
        "b1_peak_drift_ratio",
        "--curves",
        "record,sample",
        "-o",
        &s(&out),
    ]);
    let e = stderr(&o);
    assert!(
        !o.status.success() && e.contains("would both be named `a/1/2`"),
        "{e}"
    );
    // A record of an ordinary label gives the table it gave.
    let p = write(d, "plain.csv", &ladder("x", &|_, _| "0".into()));
    ok(&pound(&[
        "ida",
        &s(&p),
        "--edp",
        "b1_peak_drift_ratio",
        "-o",
        &s(&out),
    ]));
    let head = std::fs::read_to_string(&out).unwrap();
    assert!(head.starts_with("pga_g,curves,b1_peak_drift_ratio_p16,b1_peak_drift_ratio_p50,b1_peak_drift_ratio_p84,collapsed,collapsed_fraction,rec0,rec1,"), "{head}");
}

/// `pound fragility` writes the intensity's column beside its own (`runs`, `collapsed`, ...):
/// an `--im` of one of those names is refused, naming it.
#[test]
fn a_fragility_table_never_names_a_column_twice() {
    let dir = tempdir();
    let d = dir.path();
    let text = ladder("runs", &|_, l| format!("{}", l + 1));
    let p = write(d, "runs.csv", &text);
    let out = d.join("f.csv");
    for edp in [
        vec!["--edp", "b1_peak_drift_ratio", "--threshold", "0.01"],
        vec!["--edp", "collapsed"],
    ] {
        let mut a = vec!["fragility", p.to_str().unwrap(), "--im", "runs", "-o"];
        let o_s = s(&out);
        a.push(&o_s);
        a.extend(edp.iter().copied());
        let o = pound(&a);
        let e = stderr(&o);
        assert!(
            !o.status.success()
                && e.contains("--im runs: the fragility table has its own column `runs`"),
            "{edp:?}: {e}"
        );
        assert!(!out.exists());
    }
}

/// A table written with `--columns` that left the collapse columns out, whose status says
/// `collapsed` in some rows: the run's collapse fragility is counted from the status (as it is
/// from the whole table), building 1's names the column missing and the rows that collapsed,
/// and an IDA's fractiles are not called collapse-free.
#[test]
fn collapse_columns_left_out_are_named_missing_not_read_as_no_collapse() {
    let dir = tempdir();
    let d = dir.path();
    // The whole table: the run's collapse columns and building 1's, as a sweep writes them.
    let whole = ladder(
        "collapse_time_s,collapse_building,collapse_storey,b1_collapsed",
        &|r, l| {
            let drift = 0.004 * (l + 1) as f64 * (1.0 + 0.15 * r as f64);
            if drift > 0.02 {
                "3,1,1,1".into()
            } else {
                ",,,0".into()
            }
        },
    );
    let cut = ladder("x", &|_, _| "0".into());
    let (pw, pc) = (write(d, "whole.csv", &whole), write(d, "cut.csv", &cut));
    let collapsed_rows = cut.matches(",collapsed,").count();
    assert!(collapsed_rows > 0 && collapsed_rows < 28);
    let fit = |p: &Path, name: &str| {
        let out = d.join(name);
        let said = ok(&pound(&[
            "fragility",
            &s(p),
            "--edp",
            "collapsed",
            "-o",
            &s(&out),
        ]));
        (said, std::fs::read_to_string(&out).unwrap())
    };
    let (a, b) = (fit(&pw, "fw.csv"), fit(&pc, "fc.csv"));
    assert_eq!(a, b);
    assert!(
        a.0.starts_with(&format!(
            "28 runs at 4 levels of pga_g, {collapsed_rows} collapsed"
        )),
        "{}",
        a.0
    );
    let o = pound(&[
        "fragility",
        &s(&pc),
        "--edp",
        "b1_collapsed",
        "-o",
        &s(&d.join("f1.csv")),
    ]);
    let e = stderr(&o);
    assert!(!o.status.success(), "accepted");
    assert!(
        e.contains(&format!("--edp b1_collapsed: {collapsed_rows} rows have status `collapsed`, but this table has no column b1_collapsed"))
            && e.contains("--columns that left them out")
            && !e.contains("no collapse limit")
            && !e.contains("could not collapse"),
        "{e}"
    );
    // A failed run beside them: the fractiles are over the runs that did not fail, not
    // collapse-free (the table's criterion shows in its status).
    let failed = cut.replacen("rec0,0.2,ok,", "rec0,0.2,failed,", 1);
    let pf = write(d, "failed.csv", &failed);
    let said = ok(&pound(&[
        "ida",
        &s(&pf),
        "--edp",
        "b1_peak_drift_ratio",
        "-o",
        &s(&d.join("i.csv")),
    ]));
    assert!(
        said.contains("(failed runs left out)") && !said.contains("collapse-free"),
        "{said}"
    );
}

/// Records whose collapses are all or nothing at each level, out of a fragility's order (7/7
/// at 0.4 g below 0/7 at 0.6 g): a fit exists and the goodness of fit rejects it, its p printed
/// (never hidden as "no power", which is for levels in order). A bootstrap over four records leaves out the
/// replicates with no fit: the band is named conditional, with its count, in its cells, its
/// notice and its figure's title.
#[test]
fn statistics_say_what_they_rest_on() {
    let dir = tempdir();
    let d = dir.path();
    // Collapses at 0.4 and 0.8 in every record, none at 0.2 and 0.6.
    let mut t = String::from("record,pga_g,status,collapse_time_s\n");
    for r in 0..7 {
        for pga in [0.2, 0.4, 0.6, 0.8] {
            let c = pga == 0.4 || pga == 0.8;
            let (status, time) = if c { ("collapsed", "3") } else { ("ok", "") };
            t.push_str(&format!("rec{r},{pga},{status},{time}\n"));
        }
    }
    let p = write(d, "allornone.csv", &t);
    let said = ok(&pound(&[
        "fragility",
        &s(&p),
        "--edp",
        "collapsed",
        "-o",
        &s(&d.join("a.csv")),
    ]));
    let row = said
        .lines()
        .find(|l| l.starts_with("| collapse |"))
        .unwrap();
    let p_fit: f64 = row
        .trim_end_matches('|')
        .rsplit('|')
        .next()
        .unwrap()
        .trim()
        .parse()
        .unwrap_or_else(|_| panic!("a p (fit) in {row}"));
    assert!(p_fit < 0.01 && !row.contains("no power"), "{said}");
    // Four records whose shares differ: some replicates draw counts that give no fit.
    let mut t = String::from("record,pga_g,status,collapse_time_s\n");
    let collapses = [
        [0, 0, 1, 1, 1],
        [0, 0, 0, 1, 1],
        [0, 1, 1, 1, 1],
        [0, 0, 0, 0, 1],
    ];
    for (r, row) in collapses.iter().enumerate() {
        for (l, &c) in row.iter().enumerate() {
            let pga = 0.2 * (l + 1) as f64;
            let (status, time) = if c == 1 {
                ("collapsed", "3")
            } else {
                ("ok", "")
            };
            t.push_str(&format!("rec{r},{pga},{status},{time}\n"));
        }
    }
    let p = write(d, "few.csv", &t);
    let plot = d.join("few.svg");
    let o = pound(&[
        "fragility",
        &s(&p),
        "--edp",
        "collapsed",
        "--bootstrap",
        "200",
        "-o",
        &s(&d.join("b.csv")),
        "--plot",
        &s(&plot),
    ]);
    let (said, e) = (ok(&o), stderr(&o));
    let row = said
        .lines()
        .find(|l| l.starts_with("| collapse |"))
        .unwrap();
    let kept: usize = row
        .split("(conditional: ")
        .nth(1)
        .and_then(|r| r.split(' ').next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no conditional band: {said}"));
    assert!(kept > 0 && kept < 200, "{row}");
    assert!(
        row.contains(&format!("(conditional: {kept} of 200 replicates fitted) |"))
            && row.ends_with("(conditional) |"),
        "{row}"
    );
    assert!(
        e.contains("notice: the 90 % bands marked conditional are the percentiles of the bootstrap replicates that could be fitted")
            && e.contains(&format!("collapse: {} of 200 (", 200 - kept)),
        "{e}"
    );
    let svg = std::fs::read_to_string(&plot).unwrap();
    assert!(svg.contains("conditional on a fit"), "title");
}

/// A table without `status` (a sweep written with --columns that left it out) cannot tell its
/// collapsed runs from the others: fragility and ida say so, naming the column, rather than
/// counting a collapse as a run that stood (the hostile pass's 16 collapses read as none).
#[test]
fn a_table_without_status_says_its_collapses_cannot_be_told() {
    let dir = tempdir();
    let d = dir.path();
    let mut t = String::from("record,pga_g,b1_peak_drift_ratio\n");
    for r in 0..4 {
        for (l, pga) in [0.2, 0.4, 0.6, 0.8].iter().enumerate() {
            t.push_str(&format!("rec{r},{pga},{}\n", 0.002 * (l + 1 + r) as f64));
        }
    }
    let p = write(d, "nostatus.csv", &t);
    for args in [
        vec![
            "fragility",
            "--edp",
            "b1_peak_drift_ratio",
            "--threshold",
            "0.006",
        ],
        vec!["ida", "--edp", "b1_peak_drift_ratio"],
    ] {
        let out = d.join(format!("{}.csv", args[0]));
        let mut a = vec![args[0].to_string(), s(&p)];
        a.extend(args[1..].iter().map(|x| x.to_string()));
        a.extend(["-o".to_string(), s(&out)]);
        let a: Vec<&str> = a.iter().map(|x| x.as_str()).collect();
        let r = pound(&a);
        let said = format!(
            "{}{}",
            String::from_utf8_lossy(&r.stdout),
            String::from_utf8_lossy(&r.stderr)
        );
        assert!(r.status.success(), "{said}");
        assert!(
            said.contains("has no `status` column") && said.contains("runs that collapsed"),
            "{}: {said}",
            args[0]
        );
    }
    // With the column, no such notice.
    let with = write(
        d,
        "status.csv",
        &t.replacen("b1_peak_drift_ratio\n", "b1_peak_drift_ratio,status\n", 1)
            .lines()
            .enumerate()
            .map(|(i, l)| {
                if i == 0 {
                    l.to_string()
                } else {
                    format!("{l},ok")
                }
            })
            .collect::<Vec<_>>()
            .join("\n"),
    );
    let r = pound(&[
        "fragility",
        &s(&with),
        "--edp",
        "b1_peak_drift_ratio",
        "--threshold",
        "0.006",
        "-o",
        &s(&d.join("w.csv")),
    ]);
    let said = format!(
        "{}{}",
        String::from_utf8_lossy(&r.stdout),
        String::from_utf8_lossy(&r.stderr)
    );
    assert!(
        r.status.success() && !said.contains("no `status`"),
        "{said}"
    );
}
