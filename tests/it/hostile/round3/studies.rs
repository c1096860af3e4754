//! Hostile pass, round 3 (issue 47): see the classes named in `round3.rs`.

use crate::support::{ok, pound, tempdir};
use pounding::plan::sample::phi;
use std::path::Path;

fn s(p: &Path) -> String {
    p.to_str().unwrap().to_string()
}

/// A results CSV of `record, status, pga_g, b1_peak_drift_ratio`: at each level, runs of the
/// given drifts (one record per run).
fn drifts(dir: &Path, levels: &[(f64, Vec<f64>)]) -> std::path::PathBuf {
    let mut text = String::from("run,record,status,pga_g,target_sa_g,b1_peak_drift_ratio\n");
    let mut run = 0;
    for (pga, d) in levels {
        for (r, d) in d.iter().enumerate() {
            text.push_str(&format!("{run},rec{r},ok,{pga},,{d}\n"));
            run += 1;
        }
    }
    let p = dir.join("runs.csv");
    std::fs::write(&p, text).unwrap();
    p
}

/// At each level, `heavy` runs above 0.01, `light` more above 0.005 only, of 20.
fn counts(levels: &[(f64, usize, usize)]) -> Vec<(f64, Vec<f64>)> {
    levels
        .iter()
        .map(|&(pga, heavy, light)| {
            let mut d = vec![0.02; heavy];
            d.extend(vec![0.007; light]);
            d.resize(20, 0.001);
            (pga, d)
        })
        .collect()
}

/// The median and beta of a fit table's row that starts with `label`.
fn fitted(out: &str, label: &str) -> (f64, f64) {
    let line = out
        .lines()
        .find(|l| l.starts_with(&format!("| {label} |")))
        .unwrap_or_else(|| panic!("no row {label}: {out}"));
    let c: Vec<&str> = line.split('|').map(str::trim).collect();
    (c[2].parse().unwrap(), c[3].parse().unwrap())
}

/// Class 10, a notice that points the wrong way: where fitted curves of two states cross, the
/// notice names the interval of intensities where their order is wrong (the more severe state
/// the more probable), which the fitted curves confirm inside it and deny beyond it. It said
/// "from 0.2 ... read them only below that intensity", the wrong side.
#[test]
fn crossing_notices_name_where_the_order_is_wrong() {
    let dir = tempdir();
    // The milder threshold's shares rise steeply, the severer's slowly: the severer's fitted
    // curve lies above at the lowest levels.
    let results = drifts(
        dir.path(),
        &counts(&[
            (0.2, 2, 0),
            (0.3, 2, 1),
            (0.45, 3, 6),
            (0.6, 4, 12),
            (0.8, 6, 13),
            (1.0, 9, 11),
        ]),
    );
    let out = pound(&[
        "fragility",
        &s(&results),
        "--im",
        "pga_g",
        "--edp",
        "b1_peak_drift_ratio",
        "--threshold",
        "0.005,0.01",
        "-o",
        &s(&dir.path().join("f.csv")),
    ]);
    let (stdout, stderr) = (ok(&out), String::from_utf8_lossy(&out.stderr).to_string());
    let notice = stderr
        .lines()
        .find(|l| l.contains("0.005 and 0.01"))
        .unwrap_or_else(|| panic!("no crossing notice: {stderr}\n{stdout}"));
    let interval = notice
        .split_once("out of order from pga_g = ")
        .unwrap_or_else(|| panic!("no interval named: {notice}"))
        .1;
    let (from, rest) = interval.split_once(" to ").unwrap();
    let to = rest.split_once(':').unwrap().0;
    let (from, to): (f64, f64) = (from.parse().unwrap(), to.parse().unwrap());
    let (a, b) = (fitted(&stdout, "0.005"), fitted(&stdout, "0.01"));
    let p = |(m, beta): (f64, f64), im: f64| phi((im / m).ln() / beta);
    assert!(from == 0.2 && from < to && to < 1.0, "{notice}");
    // Inside, the severer curve is above; just beyond the named end, below.
    for im in [from, (from * to).sqrt(), 0.99 * to] {
        assert!(p(b, im) > p(a, im), "{im}: {notice}\n{stdout}");
    }
    assert!(p(b, 1.01 * to) < p(a, 1.01 * to), "{notice}\n{stdout}");
    assert!(
        notice.contains(&format!("read them only above {to:.4}")),
        "{notice}"
    );
    // Thresholds given severest first: the notice still calls the larger the more severe.
    let out = pound(&[
        "fragility",
        &s(&results),
        "--im",
        "pga_g",
        "--edp",
        "b1_peak_drift_ratio",
        "--threshold",
        "0.01,0.005",
        "-o",
        &s(&dir.path().join("f.csv")),
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr).to_string();
    assert!(
        stderr.contains("curves of 0.005 and 0.01 are out of order")
            && stderr.contains("the more severe (0.01)"),
        "{stderr}"
    );
}
