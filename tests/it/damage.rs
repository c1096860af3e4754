//! Damage states, bootstrap bands and IDA summaries (`pound fragility --damage-states`,
//! `--bootstrap`, `pound ida`) on data drawn from a known demand model, and on a real sweep
//! scaled to Sa(T1).

use crate::support::{ok, pound, tempdir};
use pounding::plan::sample::{phi_inv, Rng};
use std::path::Path;

/// Demands `ln EDP = a + b ln IM + sigma eps` (10 records x 60 draws x 8 levels): then
/// `P(EDP > L | IM) = Phi(ln(IM / m) / beta)` with `beta = sigma / b` and
/// `ln m = (ln L - a) / b`, for every limit `L`.
const A: f64 = -4.0;
const B: f64 = 1.1;
const SIGMA: f64 = 0.45;

fn draws(dir: &Path) -> std::path::PathBuf {
    let mut rng = Rng::new(2027);
    let mut s = String::from("run,record,sample,target_sa_g,status,b1_peak_drift_ratio\n");
    let mut run = 0;
    for im in [0.1, 0.2, 0.3, 0.45, 0.6, 0.8, 1.0, 1.4] {
        for r in 0..10 {
            for k in 0..60 {
                let eps = phi_inv(rng.uniform());
                let edp = (A + B * f64::ln(im) + SIGMA * eps).exp();
                s.push_str(&format!("{run},rec{r},{k},{im},ok,{edp}\n"));
                run += 1;
            }
        }
    }
    let p = dir.join("draws.csv");
    std::fs::write(&p, s).unwrap();
    p
}

/// The table rows of `pound fragility`'s output: label, median, beta, se(ln median), se(beta).
fn rows(out: &str) -> Vec<(String, [f64; 4])> {
    out.lines()
        .filter(|l| l.starts_with("| ") && !l.contains("median"))
        .filter_map(|l| {
            let c: Vec<&str> = l.split('|').map(str::trim).collect();
            let v: Vec<f64> = c[2..6].iter().filter_map(|x| x.parse().ok()).collect();
            (v.len() == 4).then(|| (c[1].to_string(), [v[0], v[1], v[2], v[3]]))
        })
        .collect()
}

#[test]
fn damage_states_recover_known_medians_with_bands_and_crossings_named() {
    let dir = tempdir();
    let results = draws(dir.path());
    let states = dir.path().join("states.toml");
    std::fs::write(
        &states,
        "name = \"test frames\"\nsource = \"drawn\"\n[[state]]\nname = \"light\"\nlimit = 0.004\n[[state]]\nname = \"medium\"\nlimit = 0.01\n[[state]]\nname = \"heavy\"\nlimit = 0.02\n",
    )
    .unwrap();
    let s = |p: &Path| p.to_str().unwrap().to_string();
    let out = ok(&pound(&[
        "fragility",
        &s(&results),
        "--im",
        "target_sa_g",
        "--edp",
        "b1_peak_drift_ratio",
        "--damage-states",
        &s(&states),
        "--bootstrap",
        "200",
        "--seed",
        "5",
        "-o",
        &s(&dir.path().join("f.csv")),
        "--plot",
        &s(&dir.path().join("f.svg")),
    ]));
    let r = rows(&out);
    assert_eq!(r.len(), 3, "{out}");
    let beta = SIGMA / B;
    for (((name, v), limit), state) in r
        .iter()
        .zip([0.004f64, 0.01, 0.02])
        .zip(["light", "medium", "heavy"])
    {
        let median = ((limit.ln() - A) / B).exp();
        assert_eq!(name, &format!("{state} ({limit})"));
        let z_median = (v[0].ln() - median.ln()) / v[2];
        let z_beta = (v[1] - beta) / v[3];
        assert!(
            z_median.abs() < 3.0 && z_beta.abs() < 3.0,
            "{name}: {v:?} against {median}, {beta}"
        );
    }
    assert!(r[0].1[0] < r[1].1[0] && r[1].1[0] < r[2].1[0]);
    // The bands: one per state, around the fitted median.
    let bands: Vec<&str> = out.lines().filter(|l| l.starts_with("| ")).collect();
    assert!(out.contains("bootstrap: 200 replicates over 10 groups of record (seed 5)"));
    for l in &bands[2..] {
        let c: Vec<&str> = l.split('|').map(str::trim).collect();
        let median: f64 = c[2].parse().unwrap();
        let (lo, hi) = c[9].split_once('-').unwrap();
        let (lo, hi): (f64, f64) = (lo.parse().unwrap(), hi.parse().unwrap());
        assert!(lo < median && median < hi, "{l}");
    }
    assert!(
        out.contains("test frames") && !out.contains("cross"),
        "{out}"
    );

    // A built-in set names its table (crossing curves: studies::fragility's unit tests).
    let out = ok(&pound(&[
        "fragility",
        &s(&results),
        "--im",
        "target_sa_g",
        "--edp",
        "b1_peak_drift_ratio",
        "--damage-states",
        "hazus-c1l-moderate",
        "-o",
        &s(&dir.path().join("g.csv")),
    ]));
    assert!(out.contains("Table 5.9b, C1L"), "{out}");
    assert!(out.contains("| slight (0.005) |") && out.contains("| complete (0.06) |"));
    let e = pound(&["fragility", &s(&results), "--damage-states", "hazus-c9"]);
    assert!(!e.status.success());
    assert!(String::from_utf8_lossy(&e.stderr).contains("hazus-c1l-high"));
}

#[test]
fn ida_of_a_spectral_ladder_on_real_records() {
    let dir = tempdir();
    let s = |p: &Path| p.to_str().unwrap().to_string();
    let cfg = dir.path().join("ida.toml");
    // The worked example's scene, cut to 3 samples and 4 levels.
    let text = std::fs::read_to_string("configs/fragility-sa.toml")
        .unwrap()
        .replace("n = 20", "n = 3")
        .replace(
            "sa_g = [0.1, 0.2, 0.3, 0.45, 0.6, 0.8, 1.0, 1.25, 1.5, 2.0]",
            "sa_g = [0.2, 0.6, 1.0, 1.5]",
        );
    std::fs::write(&cfg, text).unwrap();
    let records = pounding::plan::config::records_dir();
    let csv = dir.path().join("r.csv");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_pound"))
        .args(["sweep", &s(&cfg), "-o", &s(&csv)])
        .env("POUND_RECORDS_DIR", &records)
        .output()
        .unwrap();
    ok(&out);
    let ida = dir.path().join("ida.csv");
    let out = ok(&pound(&[
        "ida",
        &s(&csv),
        "--edp",
        "b1_peak_drift_ratio",
        "-o",
        &s(&ida),
        "--plot",
        &s(&dir.path().join("ida.svg")),
    ]));
    assert!(
        out.contains("15 curves (by record, sample) at 4 levels of target_sa_g"),
        "{out}"
    );
    let text = std::fs::read_to_string(&ida).unwrap();
    let mut lines = text.lines();
    let head: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(
        head[..5],
        [
            "target_sa_g",
            "curves",
            "b1_peak_drift_ratio_p16",
            "b1_peak_drift_ratio_p50",
            "b1_peak_drift_ratio_p84"
        ]
    );
    // Then the curves collapsed and their share (none: this pair cannot collapse), and the
    // curves.
    assert_eq!(head[5..7], ["collapsed", "collapsed_fraction"]);
    assert_eq!(head.len(), 7 + 15);
    for line in lines {
        let v: Vec<f64> = line.split(',').map(|x| x.parse().unwrap()).collect();
        assert_eq!(v[1], 15.0);
        assert_eq!((v[5], v[6]), (0.0, 0.0));
        let mut d = v[7..].to_vec();
        d.sort_by(f64::total_cmp);
        // Type-7 quantiles of the 15 demands: the 50 % is the 8th.
        assert_eq!(v[3], d[7]);
        assert!(v[2] <= v[3] && v[3] <= v[4]);
    }
}
