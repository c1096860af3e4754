//! Fragility fits: the lognormal fit recovers a known curve, `pound fragility` counts and fits a
//! sweep, and on tables written by hand (with `pound ida`) a crossing notice names where the
//! order is wrong, runs without a value are decided or bound the fit, a fit that cannot be made
//! says why, and the study flags mean what they say (issue 47's classes 8, 9, 10 and 13).

use crate::scenes::sampled_runs as sweep;
use crate::support::cli::refusal as refused;
use crate::support::csv_column as column;
use crate::support::{ok, pound, table, tempdir};
use pounding::plan::sample::{phi, Rng};
use pounding::studies::fragility::{fit, Level};
use std::collections::HashMap;
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

/// Class 13, runs without a value bias a fit: a residual drift is empty where the run did not
/// settle (the most severe runs). A run whose peak drift is at or below a threshold is decided
/// "not exceeding" (a residual never exceeds the peak); the rest are counted as undecided, and
/// the fit is bounded by counting them each way, in the text and the `-o` CSV. `pound ida`
/// says which runs it left out at a level (it said "no run" where the run exists) and labels
/// fractiles without failed runs collapse-free.
#[test]
fn runs_without_a_value_are_decided_or_bounded() {
    let dir = tempdir();
    // 10 records at 5 levels; at the top two levels some runs did not settle (empty residual),
    // two of them with a peak below the threshold (decided), the others above (undecided).
    let mut text =
        String::from("run,record,status,pga_g,b1_peak_drift_ratio,b1_residual_drift_ratio\n");
    let mut run = 0;
    let (mut undecided, mut bounded) = (0usize, 0usize);
    for (l, pga) in [0.1, 0.2, 0.3, 0.4, 0.5].iter().enumerate() {
        for r in 0..10 {
            let peak = 0.002 * (l + 1) as f64 * (1.0 + r as f64 / 5.0);
            let mut residual = format!("{}", 0.4 * peak);
            let mut status = "ok";
            if l >= 3 && r >= 6 {
                residual.clear();
                undecided += 1;
            }
            let peak = if l == 3 && r == 6 {
                // Did not settle, but its peak is below the threshold: decided.
                bounded += 1;
                undecided -= 1;
                0.004
            } else {
                peak
            };
            if l == 4 && r == 0 {
                status = "failed";
            }
            text.push_str(&format!("{run},rec{r},{status},{pga},{peak},{residual}\n"));
            run += 1;
        }
    }
    let results = dir.path().join("runs.csv");
    std::fs::write(&results, text).unwrap();
    let f = dir.path().join("f.csv");
    let out = ok(&pound(&[
        "fragility",
        &s(&results),
        "--im",
        "pga_g",
        "--edp",
        "b1_residual_drift_ratio",
        "--threshold",
        "0.005",
        "-o",
        &s(&f),
    ]));
    // Every run is counted (one failed): none is left out for want of a value.
    assert!(
        out.contains("49 runs at 5 levels of pga_g (1 rows left out: 1 failed (status neither ok nor collapsed))"),
        "{out}"
    );
    assert!(out.contains(&format!("{} runs have no value", undecided + bounded)));
    let bounds = out
        .lines()
        .filter(|l| l.starts_with("| 0.005 |"))
        .nth(1)
        .unwrap_or_else(|| panic!("no bounds: {out}"));
    let c: Vec<&str> = bounds.split('|').map(str::trim).collect();
    assert_eq!(
        (c[2].parse(), c[3].parse()),
        (Ok(bounded), Ok(undecided)),
        "{bounds}"
    );
    let (median, _) = fitted(&out, "0.005");
    let (low, high): (f64, f64) = (c[6].parse().unwrap(), c[4].parse().unwrap());
    assert!(
        low < median && median < high,
        "{low} {median} {high}\n{out}"
    );
    // The CSV: per level the undecided runs and the fraction's bounds. At 0.5: record 0
    // failed, records 1-5 decided (residual 0.004 (1 + r / 5) above 0.005 from record 2 up),
    // records 6-9 undecided (no residual, peak above 0.005).
    let rows = table(&f);
    let top = rows.iter().find(|r| r["pga_g"] == "0.5").unwrap();
    assert_eq!((top["runs"].as_str(), top["exceed"].as_str()), ("5", "4"));
    assert_eq!(top["undecided"], "4");
    let frac = |k: &str| top[k].parse::<f64>().unwrap();
    assert_eq!(frac("fraction"), 4.0 / 5.0);
    assert_eq!(frac("fraction_if_none_exceed"), 4.0 / 9.0);
    assert_eq!(frac("fraction_if_all_exceed"), 8.0 / 9.0);

    // IDA: the runs at a level that have no value, and the failed one, are said to be there.
    let out = pound(&[
        "ida",
        &s(&results),
        "--im",
        "pga_g",
        "--edp",
        "b1_residual_drift_ratio",
        "--curves",
        "record",
        "-o",
        &s(&dir.path().join("ida.csv")),
    ]);
    let (stdout, stderr) = (ok(&out), String::from_utf8_lossy(&out.stderr).to_string());
    assert!(!stderr.contains("no run at"), "{stderr}");
    assert!(
        stderr.contains("0.5: 5 of 10 curves (1 failed (status neither ok nor collapsed), 4 with no value of b1_residual_drift_ratio"),
        "{stderr}"
    );
    assert!(stdout.contains("16 % (collapse-free)"), "{stdout}");
    assert!(stderr.contains("1 failed runs"), "{stderr}");
}

/// Class 8 (fragility), a cause named wrong: with no run left to count, `pound fragility` said
/// "check --where" with no `--where` given. It names the cause: an intensity column the sweep
/// was not scaled to, a demand empty in every run, every run failed, `--where` keeping no row.
#[test]
fn fragility_says_why_nothing_was_fitted() {
    let dir = tempdir();
    let results = drifts(dir.path(), &counts(&[(0.2, 1, 2), (0.4, 5, 5)]));
    let f = s(&dir.path().join("f.csv"));
    let base = |extra: &[&str]| {
        let mut a = vec![
            "fragility".to_string(),
            s(&results),
            "--threshold".into(),
            "0.005".into(),
            "-o".into(),
            f.clone(),
        ];
        a.extend(extra.iter().map(|x| x.to_string()));
        a
    };
    let run = |extra: &[&str]| {
        let a = base(extra);
        refused(&a.iter().map(String::as_str).collect::<Vec<_>>())
    };
    // An intensity column this PGA sweep does not fill.
    let e = run(&["--im", "target_sa_g", "--edp", "b1_peak_drift_ratio"]);
    assert!(
        e.contains("--im target_sa_g") && e.contains("empty in every row") && e.contains("pga_g"),
        "{e}"
    );
    assert!(!e.contains("check --where"), "{e}");
    // A demand empty in every run.
    let text = std::fs::read_to_string(&results).unwrap();
    let blank: String = text
        .lines()
        .enumerate()
        .map(|(i, l)| match i {
            0 => format!("{l},peak_force_n\n"),
            _ => format!("{l},\n"),
        })
        .collect();
    let blank_path = dir.path().join("blank.csv");
    std::fs::write(&blank_path, &blank).unwrap();
    let e = refused(&[
        "fragility",
        &s(&blank_path),
        "--im",
        "pga_g",
        "--edp",
        "peak_force_n",
        "--threshold",
        "0",
        "-o",
        &f,
    ]);
    assert!(
        e.contains("--edp peak_force_n") && e.contains("empty in every row"),
        "{e}"
    );
    assert!(!e.contains("check --where"), "{e}");
    // Every run failed.
    let failed = text.replace(",ok,", ",failed,");
    let failed_path = dir.path().join("failed.csv");
    std::fs::write(&failed_path, failed).unwrap();
    let e = refused(&[
        "fragility",
        &s(&failed_path),
        "--im",
        "pga_g",
        "--edp",
        "b1_peak_drift_ratio",
        "--threshold",
        "0.005",
        "-o",
        &f,
    ]);
    assert!(
        e.contains("40 failed (status neither ok nor collapsed)"),
        "{e}"
    );
    assert!(!e.contains("check --where"), "{e}");
    // A `--where` that keeps nothing is named as the cause.
    let e = run(&[
        "--im",
        "pga_g",
        "--edp",
        "b1_peak_drift_ratio",
        "--where",
        "pga_g>5",
    ]);
    assert!(e.contains("--where pga_g>5 keeps none"), "{e}");
}

/// Class 9 (fragility and damage states), the small ones: a "90 %" band of 1 or 2 replicates,
/// `--by` and `--seed` ignored without `--bootstrap`, damage-state names that are duplicate,
/// empty or span lines, an `-o` CSV with no state names, and thresholds written out to 300
/// digits.
#[test]
fn small_ones_in_studies() {
    let dir = tempdir();
    let results = drifts(
        dir.path(),
        &counts(&[(0.2, 1, 2), (0.4, 5, 5), (0.6, 10, 5)]),
    );
    let (r, f) = (s(&results), s(&dir.path().join("f.csv")));
    fn with_args<'a>(r: &'a str, f: &'a str, extra: &[&'a str]) -> Vec<&'a str> {
        let mut a = vec![
            "fragility",
            r,
            "--im",
            "pga_g",
            "--edp",
            "b1_peak_drift_ratio",
            "-o",
            f,
        ];
        a.extend_from_slice(extra);
        a
    }

    for n in ["1", "2"] {
        let e = refused(&with_args(
            &r,
            &f,
            &["--threshold", "0.005", "--bootstrap", n],
        ));
        assert!(
            e.contains(&format!("--bootstrap {n}")) && e.contains("at least 100"),
            "{e}"
        );
    }
    for flag in [["--bootstrap-groups", "record"], ["--seed", "3"]] {
        let e = refused(&with_args(
            &r,
            &f,
            &["--threshold", "0.005", flag[0], flag[1]],
        ));
        assert!(e.contains(flag[0]) && e.contains("--bootstrap"), "{e}");
    }
    // Damage-state names: each its own, not empty, one line.
    let states = dir.path().join("states.toml");
    for (names, want) in [
        (
            ["light", "light"],
            "state[1] name `light` is also state[0]'s",
        ),
        (["light", " "], "state[1]: name is empty"),
        (
            ["light", "heavy\\nand more"],
            "state[1] name \"heavy\\nand more\"",
        ),
    ] {
        std::fs::write(
            &states,
            format!(
                "[[state]]\nname = \"{}\"\nlimit = 0.004\n[[state]]\nname = \"{}\"\nlimit = 0.01\n",
                names[0], names[1]
            ),
        )
        .unwrap();
        let e = refused(&with_args(&r, &f, &["--damage-states", &s(&states)]));
        assert!(e.contains(want), "{want}: {e}");
    }
    // The -o CSV names each row's state.
    ok(&pound(&with_args(
        &r,
        &f,
        &["--damage-states", "hazus-c1l-high"],
    )));
    let rows = table(Path::new(&f));
    assert_eq!(rows[0]["state"], "slight");
    assert_eq!(rows.last().unwrap()["state"], "complete");
    // A tiny threshold is written as a number, not 300 digits, in the table, the CSV and the
    // legend.
    let svg = s(&dir.path().join("f.svg"));
    let out = ok(&pound(&with_args(
        &r,
        &f,
        &["--threshold", "1e-300,0.005", "--plot", &svg],
    )));
    let csv = std::fs::read_to_string(&f).unwrap();
    let svg = std::fs::read_to_string(&svg).unwrap();
    assert!(svg.contains("1e-298 %"), "{svg}");
    assert!(!svg.contains("0000000000"));
    for text in [&out, &csv] {
        assert!(text.contains("1e-300"), "{text}");
        assert!(!text.contains("0000000000"), "{text}");
    }
}

/// The fit recovers a known fragility from binomial draws: over 40 synthetic data sets (10
/// levels, 100 runs each), the true median and dispersion lie within two standard errors in at
/// least 85 % of them (95 % expected), and the mean estimates are within 3 % of the truth.
#[test]
fn fragility_fit_recovers_a_known_curve() {
    let (median, beta) = (0.35, 0.45);
    let mut rng = Rng::new(77);
    let (mut hit_m, mut hit_b, mut sum_m, mut sum_b) = (0, 0, 0.0, 0.0);
    let sets = 40;
    for _ in 0..sets {
        let levels: Vec<Level> = (1..=10)
            .map(|i| {
                let im = 0.08 * i as f64;
                let p = phi((im / median).ln() / beta);
                let n = 100;
                let exceed = (0..n).filter(|_| rng.uniform() < p).count() as u64;
                Level { im, n, exceed }
            })
            .collect();
        let f = fit(&levels).unwrap();
        hit_m += ((f.median.ln() - median.ln()).abs() < 2.0 * f.se_ln_median) as usize;
        hit_b += ((f.beta - beta).abs() < 2.0 * f.se_beta) as usize;
        sum_m += f.median;
        sum_b += f.beta;
    }
    assert!(
        hit_m * 100 >= 85 * sets && hit_b * 100 >= 85 * sets,
        "{hit_m} {hit_b}"
    );
    let (mm, mb) = (sum_m / sets as f64, sum_b / sets as f64);
    assert!((mm / median - 1.0).abs() < 0.03, "mean median {mm}");
    assert!((mb / beta - 1.0).abs() < 0.03, "mean beta {mb}");
}

/// `pound fragility` on the sampled sweep: counts per level, a fitted curve for pounding at all,
/// and the plot.
#[test]
fn fragility_command_counts_and_fits() {
    let d = tempdir();
    let runs = sweep(d.path());
    let (csv, svg) = (d.path().join("f.csv"), d.path().join("f.svg"));
    let out = ok(&pound(&[
        "fragility",
        runs.to_str().unwrap(),
        "--im",
        "pga_g",
        "--edp",
        "impacts",
        "--threshold",
        "0,5",
        "--where",
        "law=hertz",
        "-o",
        csv.to_str().unwrap(),
        "--plot",
        svg.to_str().unwrap(),
    ]));
    assert!(out.contains("72 runs at 3 levels of pga_g"), "{out}");
    let text = std::fs::read_to_string(&csv).unwrap();
    assert_eq!(text.lines().count(), 1 + 2 * 3, "{text}");
    // Exceedance counts never fall with intensity here, and threshold 5 never exceeds 0.
    let frac: Vec<f64> = column(&text, "fraction")
        .iter()
        .map(|x| x.parse().unwrap())
        .collect();
    assert!(frac[..3].windows(2).all(|w| w[0] <= w[1]), "{frac:?}");
    assert!(frac[3..].iter().zip(&frac[..3]).all(|(a, b)| a <= b));
    // The EDP in the title, each threshold's points named in the legend.
    let svg = std::fs::read_to_string(&svg).unwrap();
    assert!(svg.contains("P(impacts &gt; threshold)") || svg.contains("P(impacts > threshold)"));
    assert!(svg.contains("&gt; 0: observed") || svg.contains("> 0: observed"));
}

/// `--fits` writes the report's fitted curves as data: each row's median, beta and standard
/// errors are the maximum-likelihood fit of the counts `-o` writes (refitted here from them,
/// equal to the last bit), the runs and levels are those counts', a curve that cannot be fitted
/// says why with empty cells, and the report's rounded cells are these values.
#[test]
fn the_fits_table_is_the_fit_of_the_counts() {
    let d = tempdir();
    let runs = drifts(
        d.path(),
        &counts(&[(0.1, 0, 2), (0.2, 1, 6), (0.4, 5, 9), (0.8, 12, 6)]),
    );
    let (csv, fits) = (d.path().join("f.csv"), d.path().join("fits.csv"));
    let out = ok(&pound(&[
        "fragility",
        &s(&runs),
        "--edp",
        "b1_peak_drift_ratio",
        "--threshold",
        "0.005,0.01,0.05",
        "-o",
        &s(&csv),
        "--fits",
        &s(&fits),
    ]));
    let counted = table(&csv);
    let rows = table(&fits);
    assert_eq!(rows.len(), 3);
    let num = |r: &std::collections::HashMap<String, String>, c: &str| -> f64 {
        r[c].parse().unwrap_or_else(|_| panic!("{c}: {:?}", r[c]))
    };
    let mut fitted_rows = 0;
    for r in &rows {
        assert_eq!(
            (r["edp"].as_str(), r["im"].as_str()),
            ("b1_peak_drift_ratio", "pga_g")
        );
        let levels: Vec<Level> = (counted.iter())
            .filter(|c| c["threshold"] == r["threshold"])
            .map(|c| Level {
                im: num(c, "pga_g"),
                n: num(c, "runs") as u64,
                exceed: num(c, "exceed") as u64,
            })
            .collect();
        assert_eq!(levels.len(), 4);
        assert_eq!(num(r, "runs"), 80.0);
        assert_eq!(num(r, "levels"), 4.0);
        match fit(&levels) {
            Ok(f) => {
                fitted_rows += 1;
                assert_eq!(r["fit"], "ok");
                assert_eq!(num(r, "median"), f.median);
                assert_eq!(num(r, "beta"), f.beta);
                assert_eq!(num(r, "se_ln_median"), f.se_ln_median);
                assert_eq!(num(r, "se_beta"), f.se_beta);
                assert_eq!(num(r, "deviance"), f.deviance);
                assert_eq!(num(r, "p_fit"), f.p_fit.unwrap());
                let cells = format!(
                    "| {:.4} | {:.4} | {:.4} |",
                    f.median, f.beta, f.se_ln_median
                );
                assert!(out.contains(&cells), "{cells} in {out}");
            }
            Err(e) => {
                assert_eq!(r["fit"], format!("no fit: {e}"));
                assert!(r["median"].is_empty() && r["beta"].is_empty());
            }
        }
    }
    // 0.005 and 0.01 are fitted; none exceeds 0.05.
    assert_eq!(fitted_rows, 2, "{rows:?}");
}

/// A CSV's rows by column name.
type Rows = Vec<HashMap<String, String>>;

/// `--series COLUMN` fits each value's curves as `--where COLUMN=VALUE` does, value by value
/// (its fits and counts rows those of the study of that value alone, with the value first), and
/// draws them in one figure; one value is refused, naming it.
#[test]
fn a_series_is_the_study_of_each_value() {
    let d = tempdir();
    let runs = drifts(
        d.path(),
        &counts(&[(0.1, 0, 2), (0.2, 1, 6), (0.4, 5, 9), (0.8, 12, 6)]),
    );
    // Two "gaps": the table's records split in halves.
    let text = std::fs::read_to_string(&runs).unwrap();
    let mut lines = text.lines();
    let mut with = format!("{},gap_m\n", lines.next().unwrap());
    for (k, l) in lines.enumerate() {
        with.push_str(&format!("{l},{}\n", if k % 2 == 0 { "0" } else { "0.02" }));
    }
    std::fs::write(&runs, with).unwrap();
    let run = |extra: &[&str], tag: &str| -> (Rows, Rows) {
        let (csv, fits) = (
            d.path().join(format!("{tag}.csv")),
            d.path().join(format!("{tag}-fits.csv")),
        );
        let mut args = vec![
            "fragility".to_string(),
            s(&runs),
            "--edp".into(),
            "b1_peak_drift_ratio".into(),
            "--threshold".into(),
            "0.005,0.01".into(),
            "-o".into(),
            s(&csv),
            "--fits".into(),
            s(&fits),
        ];
        args.extend(extra.iter().map(|x| x.to_string()));
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        ok(&pound(&args));
        (table(&csv), table(&fits))
    };
    let svg = d.path().join("series.svg");
    let (counted, fitted) = run(
        &["--series", "gap_m", "--plot", svg.to_str().unwrap()],
        "series",
    );
    let mut compared = 0;
    for gap in ["0", "0.02"] {
        let (c, f) = run(&["--where", &format!("gap_m={gap}")], gap);
        let pick = |rows: &[HashMap<String, String>]| -> Rows {
            (rows.iter().filter(|r| r["gap_m"] == gap))
                .map(|r| {
                    let mut r = r.clone();
                    r.remove("gap_m");
                    r
                })
                .collect()
        };
        assert_eq!(pick(&counted), c, "gap {gap}: counts");
        assert_eq!(pick(&fitted), f, "gap {gap}: fits");
        compared += f.len();
    }
    assert_eq!(compared, 4);
    let svg = std::fs::read_to_string(&svg).unwrap();
    for gap in ["0 m", "0.02 m"] {
        assert!(
            svg.contains(&format!("= {gap}, &gt; 0.5 %: observed"))
                || svg.contains(&format!("= {gap}, > 0.5 %: observed")),
            "{gap}"
        );
    }
    let e = refused(&[
        "fragility",
        &s(&runs),
        "--edp",
        "b1_peak_drift_ratio",
        "--threshold",
        "0.01",
        "--series",
        "gap_m",
        "--where",
        "gap_m=0",
        "-o",
        &s(&d.path().join("x.csv")),
    ]);
    assert!(
        e.contains("--series gap_m: 1 value among the rows kept (0)"),
        "{e}"
    );
    // Not a series of what each curve is made of: its IM, its demand, its bootstrap groups.
    for (series, said) in [
        ("pga_g", "the intensity measure"),
        ("b1_peak_drift_ratio", "the demand"),
        ("record", "the bootstrap draws"),
    ] {
        let e = refused(&[
            "fragility",
            &s(&runs),
            "--im",
            "pga_g",
            "--edp",
            "b1_peak_drift_ratio",
            "--threshold",
            "0.01",
            "--bootstrap",
            "100",
            "--series",
            series,
            "-o",
            &s(&d.path().join("x.csv")),
        ]);
        assert!(
            e.contains(&format!("--series {series}: {series} is ")),
            "{e}"
        );
        assert!(e.contains(said), "{e}");
    }
}
