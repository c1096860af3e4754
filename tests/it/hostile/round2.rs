//! Hostile pass, round 2 (issue 30): one test per class. No certificate without evidence, no
//! silent physics, nothing left behind, outputs that say what they are, and every bounded input
//! served or refused with its reason.

use super::{s, stderr as err};
use crate::support::{ok, pound, tempdir};
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

fn out(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// Fails with `needle` in its message, without a panic ([`super::refused`] with no output to
/// check).
fn refused(o: &Output, needle: &str) {
    super::refused(o, needle, None);
}

/// Succeeds, and says `needle` on stderr.
fn warns(o: &Output, needle: &str) {
    let e = err(o);
    assert!(o.status.success(), "failed: {e}");
    assert!(e.contains(needle), "expected `{needle}` in: {e}");
}

/// `pound ARGS` run from folder `cwd` with `POUND_RECORDS_DIR` unset.
fn pound_in(cwd: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_pound"))
        .args(args)
        .current_dir(cwd)
        .env_remove("POUND_RECORDS_DIR")
        .output()
        .unwrap()
}

/// A row of two buildings; `left` and `right` are the `[[building]]` bodies.
fn row(left: &str, right: &str, extra: &str) -> String {
    format!(
        r#"[run]
tail_s = 0.5

[[building]]
{left}

[[building]]
{right}

[contact]
law = "nonlinear_viscoelastic"
formula = "ebrahimi"
e = 0.65
beta_n_per_m1_5 = 2.75e9
gap_m = [0.0, 0.01]

[[record]]
synthetic = {{ seed = 1, duration_s = 2.0, dt_s = 0.01, pga_g = 0.35 }}
{extra}"#
    )
}

const STOREYS3: &str =
    "storeys = 3\nstorey_height_m = 3.0\nmass_kg = 3.0e5\nperiod_s = 0.4\ndamping_ratio = 0.05";
const STOREYS2: &str =
    "storeys = 2\nstorey_height_m = 3.0\nmass_kg = 3.0e5\nperiod_s = 0.3\ndamping_ratio = 0.05";

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// Class 1: every size the bench's flags accept is served (the unit test
/// `studies::bench::tests::every_bounded_size_plans` covers 1 to 1e9); sizes 1 to 20 used to
/// panic building a one-value range.
#[test]
fn bench_serves_every_bounded_size() {
    let o = pound(&["bench", "--sizes", "1,10,20", "--max-cpu-runs", "20"]);
    let text = ok(&o);
    assert!(!err(&o).contains("panicked"));
    for n in ["| 10 |", "| 20 |"] {
        assert!(text.contains(n), "{n} missing from: {text}");
    }
}

/// Class 2: `--target-error` is met only with evidence: failed runs on either side (here both:
/// floor masses of 1e-30 and 1e12 kg) and zero compared runs are "NOT met" with exit 1; the
/// pair table shows failures; `--tol` has `run.tol`'s bound.
#[test]
fn no_certificate_without_evidence() {
    let d = tempdir();
    let cfg = write(
        d.path(),
        "mass.toml",
        &row(
            "storeys = 3\nstorey_height_m = 3.0\nfloor_masses_kg = [1e-30, 1e5, 1e12]\nperiod_s = 0.4\ndamping_ratio = 0.05",
            STOREYS3,
            "",
        ),
    );
    let acc = d.path().join("acc.csv");
    let o = pound(&["accuracy", s(&cfg), "--target-error", "1e-2", "-o", s(&acc)]);
    // Statistics over zero runs are no figure: `-` in the table, and the study is an error
    // naming why no run could be compared, with nothing written (issue 64).
    refused(&o, "no run could be compared");
    assert!(err(&o).contains("of 2 runs, 2 failed"), "{}", err(&o));
    let text = out(&o);
    assert!(!text.contains("(met)"), "{text}");
    assert!(text.contains("| - |"), "{text}");
    assert!(!acc.exists());
    // --tol: the config key's bound, before any run.
    refused(
        &pound(&["accuracy", s(&cfg), "--tol", "1e-20", "-o", s(&acc)]),
        "1e-13 < tol < 1e-2",
    );
    // The pair table has a failed column.
    assert!(pounding::studies::accuracy::MARKDOWN_HEADER.contains("| failed |"));
}

/// Class 3: what a file's header states cannot be contradicted; rows get the pair's absurd-
/// input warnings with their real height; a pair with no shared floor level is said before
/// any run; NaN is never "not exceeding"; a BOM or a typo never shortens a record silently.
#[test]
fn no_silent_physics() {
    let d = tempdir();
    // An AT2 whose header says g, read with units = cm/s2: refused, as a contradicting dt is.
    let values: Vec<String> = (0..200)
        .map(|i| format!("{:.6}", 0.3 * (i as f64 * 0.2).sin()))
        .collect();
    let at2 = format!(
        "PEER NGA STRONG MOTION DATABASE RECORD\nTest\nACCELERATION TIME SERIES IN UNITS OF G\nNPTS=  200, DT= .0100 SEC\n{}\n",
        values.join("\n")
    );
    write(d.path(), "rec.AT2", &at2);
    let pair = |units: &str| {
        format!(
            "[building1]\nmass_kg = 1e5\nperiod_s = 0.5\ndamping_ratio = 0.05\n[building2]\nmass_kg = 1e5\nperiod_s = 0.3\ndamping_ratio = 0.05\n[contact]\nlaw = \"linear\"\nk_n_per_m = 1e9\ngap_m = 0.01\n[[record]]\npath = \"rec.AT2\"\n{units}\n"
        )
    };
    let bad = write(d.path(), "units.toml", &pair("units = \"cm/s2\""));
    let o = d.path().join("o.csv");
    refused(
        &super::sweep(&bad, &o, &[]),
        "header says its values are in g but units = cm/s2 was given",
    );
    ok(&super::sweep(
        &write(d.path(), "g.toml", &pair("units = \"g\"")),
        &o,
        &[],
    ));
    // Rows: PGA above 5 g, and displacements above the building's real height.
    let hot = write(
        d.path(),
        "hot.toml",
        &row(STOREYS3, STOREYS3, "").replace("pga_g = 0.35", "pga_g = 6.0"),
    );
    warns(
        &super::sweep(&hot, &d.path().join("hot.csv"), &[]),
        "above 5 g",
    );
    // Without a collapse limit (with one, each building collapses at 10 % of its 3 nm and
    // stands there: its peaks end at the limit).
    let flat = write(
        d.path(),
        "flat.toml",
        &row(
            &STOREYS3.replace("storey_height_m = 3.0", "storey_height_m = 1e-9"),
            &STOREYS3.replace("storey_height_m = 3.0", "storey_height_m = 1e-9"),
            "",
        )
        .replace(
            "tail_s = 0.5",
            "tail_s = 0.5\ncollapse_drift_ratio = \"none\"",
        ),
    );
    warns(
        &super::sweep(&flat, &d.path().join("flat.csv"), &[]),
        "exceeds its height",
    );
    // Neighbours that share no floor level pound floor against column (issue 50); with that
    // turned off they never touch: said before any run, refused by the gap study.
    let offset = STOREYS2.replace("storey_height_m = 3.0", "storey_height_m = 3.2");
    let struck = write(d.path(), "struck.toml", &row(STOREYS3, &offset, ""));
    let o = super::sweep(&struck, &d.path().join("struck.csv"), &[]);
    assert!(o.status.success() && !err(&o).contains("share no floor level"));
    let header = std::fs::read_to_string(d.path().join("struck.csv")).unwrap();
    assert!(
        header.contains("level_b1c2_b2f1_column_shear_n"),
        "{header}"
    );
    let apart = write(
        d.path(),
        "apart.toml",
        // One gap: a list would repeat each run (refused, `idle_axes`).
        &row(STOREYS3, &offset, "[levels]\nfloor_column = false\n")
            .replace("gap_m = [0.0, 0.01]", "gap_m = 0.0"),
    );
    warns(
        &super::sweep(&apart, &d.path().join("apart.csv"), &[]),
        "buildings 1 and 2 share no floor level (floors at 3, 6, 9 m against 3.2, 6.4 m",
    );
    let gaps = d.path().join("apart-gaps.csv");
    refused(
        &pound(&["gap", s(&apart), "-o", s(&gaps)]),
        "buildings 1 and 2 share no floor level",
    );
    assert!(!gaps.exists());
    // Fragility: NaN EDPs are left out with a count (the median is that of the finite rows);
    // a non-finite threshold is refused wherever one is typed.
    let mut clean = String::from("run,pga_g,status,peak_force_n\n");
    let mut nan = clean.clone();
    for (i, im) in [0.1, 0.2, 0.3, 0.4, 0.5, 0.6].iter().enumerate() {
        for k in 0..10 {
            let f = if (k as f64) < 10.0 * im { 2e6 } else { 0.0 };
            clean.push_str(&format!("{},{im},ok,{f}\n", i * 10 + k));
            nan.push_str(&format!("{},{im},ok,{f}\n", i * 10 + k));
            nan.push_str(&format!("{},{im},ok,NaN\n", 1000 + i * 10 + k));
        }
    }
    let fit = |name: &str, text: &str| {
        let r = write(d.path(), name, text);
        let o = pound(&[
            "fragility",
            s(&r),
            "--threshold",
            "1e6",
            "-o",
            s(&d.path().join(format!("{name}.frag.csv"))),
        ]);
        (ok(&o), err(&o))
    };
    let (a, _) = fit("clean.csv", &clean);
    let (b, _) = fit("nan.csv", &nan);
    assert!(b.contains("60 rows left out: 60 a value not finite"), "{b}");
    let median = |t: &str| {
        t.lines()
            .find(|l| l.starts_with("| 1000000 |"))
            .unwrap()
            .split('|')
            .nth(2)
            .unwrap()
            .trim()
            .to_string()
    };
    assert_eq!(median(&a), median(&b));
    let r = d.path().join("nan.csv");
    refused(
        &pound(&[
            "fragility",
            s(&r),
            "--threshold",
            "nan",
            "-o",
            s(&d.path().join("t.csv")),
        ]),
        "--threshold NaN: expected a finite number",
    );
    refused(
        &pound(&[
            "plot",
            s(&r),
            "--x",
            "pga_g",
            "--y",
            "peak_force_n",
            "--where",
            "pga_g>inf",
            "-o",
            s(&d.path().join("t.svg")),
        ]),
        "finite number",
    );
    let cfg = write(d.path(), "row.toml", &row(STOREYS3, STOREYS2, ""));
    refused(
        &super::sweep(
            &cfg,
            &d.path().join("agg.csv"),
            &["--aggregate", "gap_1_2_m", "--exceed", "b1_peak_roof_m=nan"],
        ),
        "must be a finite number",
    );
    // Two-column records: a BOM is not part of the first line, a typo is an error.
    let rows: Vec<String> = (0..200)
        .map(|i| {
            format!(
                "{:.2} {:.4}",
                i as f64 * 0.01,
                if i == 0 { 0.9 } else { 0.1 }
            )
        })
        .collect();
    let bom = write(
        d.path(),
        "bom.txt",
        &format!("\u{feff}{}\n", rows.join("\n")),
    );
    let info = ok(&pound(&[
        "record",
        "info",
        s(&bom),
        "--format",
        "two_column",
    ]));
    assert!(
        info.contains("npts      200") && info.contains("pga       0.9000 g"),
        "{info}"
    );
    let typo = write(
        d.path(),
        "typo.txt",
        &format!("{}\n", rows.join("\n").replacen("0.9000", "0.9O00", 1)),
    );
    refused(
        &pound(&["record", "info", s(&typo), "--format", "two_column"]),
        "typo.txt:1:",
    );
    // A cm/s2 file read as g: record info says so.
    let cms: Vec<String> = (0..100)
        .map(|i| format!("{:.2}", 300.0 * (i as f64 * 0.3).sin()))
        .collect();
    let cms = write(d.path(), "cms.txt", &cms.join("\n"));
    warns(
        &pound(&["record", "info", s(&cms), "--dt", "0.01"]),
        "above 5 g",
    );
}

/// Class 4: a refusal the plan decides comes before any file is made, and a journal of 0 runs
/// never blocks a new sweep.
#[test]
fn refusals_leave_nothing_behind() {
    let d = tempdir();
    let x = d.path().join("x.csv");
    // A row too large for the software adapter's loop limit (lavapipe, as in CI): refused
    // with no `.partial` and no journal; the advised --backend cpu then runs.
    if let Some(ctx) = crate::support::gpu::ctx().filter(|c| c.is_software()) {
        let _ = ctx;
        let tall = write(
            d.path(),
            "tall.toml",
            r#"[[building]]
storeys = 30
storey_height_m = 3.0
mass_kg = 3.0e5
period_s = 3.0
damping_ratio = 0.05

[[building]]
storeys = 30
storey_height_m = 3.0
mass_kg = 3.0e5
period_s = 2.7
damping_ratio = 0.05

[contact]
law = "lankarani_nikravesh"
formula = "khatami"
e = 0.6
beta_n_per_m1_5 = 2.75e9
gap_m = [0.01]

[[record]]
synthetic = { seed = 9, duration_s = 2.0, dt_s = 0.01, pga_g = 0.3 }
"#,
        );
        let o = pound(&["sweep", s(&tall), "--backend", "gpu", "-o", s(&x)]);
        refused(&o, "too large for the software adapter");
        for p in [
            x.clone(),
            pounding::io::atomic::sibling(&x, ".partial"),
            pounding::io::atomic::sibling(&x, ".progress.toml"),
        ] {
            assert!(!p.exists(), "{} left behind", p.display());
        }
    }
    // A sweep stopped before its first chunk leaves a journal of 0 runs beside a `.partial`
    // that holds the header alone (made here from a sweep cut off mid-way, rolled back to that
    // state): a new sweep starts afresh, and so does --resume.
    let cfg = write(
        d.path(),
        "row.toml",
        &row(STOREYS3, STOREYS2, "").replace(
            "gap_m = [0.0, 0.01]",
            "gap_m = { from = 0.0, to = 0.03, n = 16 }",
        ),
    );
    let whole = d.path().join("whole.csv");
    ok(&super::sweep(&cfg, &whole, &[]));
    let whole = std::fs::read_to_string(&whole).unwrap();
    let header = format!("{}\n", whole.lines().next().unwrap());
    let journal = pounding::io::atomic::sibling(&x, ".progress.toml");
    let partial = pounding::io::atomic::sibling(&x, ".partial");
    let args = ["sweep", s(&cfg), "-o", s(&x), "--backend", "cpu"];
    for extra in [None, Some("--resume")] {
        super::interrupt(&cfg, whole.len(), &x, 0.6);
        let text = std::fs::read_to_string(&journal).unwrap();
        let done = text
            .lines()
            .find(|l| l.starts_with("done = "))
            .unwrap()
            .to_string();
        std::fs::write(&journal, text.replace(&done, "done = 0")).unwrap();
        std::fs::write(&partial, &header).unwrap();
        let mut a = args.to_vec();
        a.extend(extra);
        warns(&pound(&a), "recorded 0 finished runs: starting afresh");
        assert_eq!(std::fs::read_to_string(&x).unwrap(), whole);
        std::fs::remove_file(&x).unwrap();
        std::fs::remove_file(pounding::io::atomic::sibling(&x, ".meta.toml")).unwrap();
    }
    // A journal edited to 0 beside rows still blocks: the rows decide.
    super::interrupt(&cfg, whole.len(), &x, 0.6);
    let text = std::fs::read_to_string(&journal).unwrap();
    let done = text
        .lines()
        .find(|l| l.starts_with("done = "))
        .unwrap()
        .to_string();
    std::fs::write(&journal, text.replace(&done, "done = 0")).unwrap();
    refused(&pound(&args), "unfinished CSV sweep");
}

/// Class 5: standard output holds one output alone; no output is the `.partial` of an input;
/// default names never replace an earlier output; an extension never contradicts the format.
#[test]
fn outputs_say_what_they_are() {
    let d = tempdir();
    let cfg = write(d.path(), "row.toml", &row(STOREYS3, STOREYS2, ""));
    // `pound gap -o -`: the CSV alone on stdout, the tables on stderr.
    let o = pound(&["gap", s(&cfg), "-o", "-"]);
    let csv = ok(&o);
    assert!(csv.starts_with("run,"), "{csv}");
    assert!(err(&o).contains("| pair | rule |"));
    refused(
        &pound(&["gap", s(&cfg), "-o", "-", "--curve", "-"]),
        "two outputs may not share one stream",
    );
    // The `.partial` of an input, existing or not.
    let results = d.path().join("r.csv");
    ok(&super::sweep(&cfg, &results, &[]));
    refused(
        &pound(&[
            "fragility",
            s(&results),
            "--threshold",
            "0",
            "--edp",
            "impacts",
            "-o",
            &format!("{}.partial", s(&results)),
        ]),
        "is the .partial of the results",
    );
    // Default names: a second sweep of another config and a second fragility do not replace
    // the first outputs; each command says what it wrote.
    let other = write(d.path(), "other.toml", &row(STOREYS2, STOREYS2, ""));
    ok(&pound_in(
        d.path(),
        &["sweep", "row.toml", "--backend", "cpu"],
    ));
    let first = std::fs::read_to_string(d.path().join("results.csv")).unwrap();
    let o = pound_in(d.path(), &["sweep", s(&other), "--backend", "cpu"]);
    warns(&o, "results.csv exists and is kept: writing results-2.csv");
    assert_eq!(
        std::fs::read_to_string(d.path().join("results.csv")).unwrap(),
        first
    );
    assert!(d.path().join("results-2.csv").exists());
    for _ in 0..2 {
        warns(
            &pound_in(
                d.path(),
                &[
                    "fragility",
                    "results.csv",
                    "--edp",
                    "impacts",
                    "--threshold",
                    "0",
                    "--im",
                    "pga_g",
                ],
            ),
            "wrote fragility",
        );
    }
    assert!(d.path().join("fragility.csv").exists() && d.path().join("fragility-2.csv").exists());
    // Extensions that contradict the format.
    refused(
        &super::sweep(&cfg, &d.path().join("p.csv"), &["--format", "parquet"]),
        "a .csv name for an output written as Parquet",
    );
    refused(
        &pound(&[
            "plot",
            s(&results),
            "--x",
            "gap_1_2_m",
            "--y",
            "b1_peak_roof_m",
            "-o",
            s(&d.path().join("p.pdf")),
        ]),
        "a .pdf name for an output written as a plot",
    );
    refused(
        &pound(&["merge", "-o", s(&d.path().join("m.parquet")), s(&results)]),
        "a .parquet name for an output written as CSV",
    );
    // A .parquet name chooses Parquet.
    let pq = d.path().join("p.parquet");
    ok(&super::sweep(&cfg, &pq, &[]));
    assert_eq!(&std::fs::read(&pq).unwrap()[..4], b"PAR1");
    // ... which plot and fragility name as such.
    refused(
        &pound(&[
            "fragility",
            s(&pq),
            "--threshold",
            "0",
            "-o",
            s(&d.path().join("f.csv")),
        ]),
        "is a Parquet file",
    );
}

/// Class 6: `contact.gap_m` is one gap shared by the pairs it gives, in the grid as under
/// `[sample]`; one value is ignored when every pair has its own (a list refused);
/// `gap_right_m` is a pair's own axis.
#[test]
fn a_shared_gap_means_one_gap() {
    let three = |extra_left: &str| {
        format!(
            "[run]\ntail_s = 0.5\n[[building]]\n{STOREYS3}\n{extra_left}\n[[building]]\n{STOREYS3}\n[[building]]\n{STOREYS3}\n[contact]\nlaw = \"linear\"\nk_n_per_m = 1e9\ngap_m = [0.0, 0.01, 0.02]\n[[record]]\nsynthetic = {{ seed = 1, duration_s = 1.0 }}\n"
        )
    };
    let plan = pounding::plan::config::parse_row(
        &three(""),
        Path::new("t.toml"),
        Path::new("."),
        Path::new("."),
    )
    .unwrap();
    assert_eq!(plan.len(), 3, "one shared axis, not one per pair");
    for i in 0..plan.len() {
        let r = plan.run(i);
        assert_eq!(r.gaps[0], r.gaps[1], "run {i}: {:?}", r.gaps);
    }
    // A pair's own gap_right_m is its own axis, crossed with the shared one.
    let plan = pounding::plan::config::parse_row(
        &three("gap_right_m = [0.05, 0.06]"),
        Path::new("t.toml"),
        Path::new("."),
        Path::new("."),
    )
    .unwrap();
    assert_eq!(plan.len(), 6);
    // Ignored when every pair has its own.
    let all = three("gap_right_m = 0.05")
        .replace(
            &format!("[[building]]\n{STOREYS3}\n[contact]"),
            &format!(
                "[[building]]\n{STOREYS3}\ngap_right_m = 0.0\n[[building]]\n{STOREYS3}\n[contact]"
            ),
        )
        .replacen(
            &format!("[[building]]\n{STOREYS3}\n[[building]]"),
            &format!("[[building]]\n{STOREYS3}\ngap_right_m = 0.01\n[[building]]"),
            1,
        );
    // A list no pair reads would be dropped: refused (`idle_axes`); one value is a leftover.
    let e = pounding::plan::config::parse_row(
        &all,
        Path::new("t.toml"),
        Path::new("."),
        Path::new("."),
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("contact.gap_m: every pair has its own gap_right_m"),
        "{e}"
    );
    let all = all.replace("gap_m = [0.0, 0.01, 0.02]", "gap_m = 0.02");
    let plan = pounding::plan::config::parse_row(
        &all,
        Path::new("t.toml"),
        Path::new("."),
        Path::new("."),
    )
    .unwrap();
    assert!(
        plan.warnings()
            .iter()
            .any(|w| w.contains("contact.gap_m is ignored")),
        "{:?}",
        plan.warnings()
    );
}

/// Class 7: an extreme cost is said before the first run, and a sweep whose stderr is not a
/// terminal reports progress lines while its first chunk still runs.
#[test]
fn costly_scenes_say_so_and_report_progress() {
    let d = tempdir();
    let tall = "storeys = 20\nstorey_height_m = 3.0\nmass_kg = 3.0e5\nperiod_s = 1e-4\ndamping_ratio = 0.05";
    let cfg = write(
        d.path(),
        "tall.toml",
        &row(tall, STOREYS3, "").replace("gap_m = [0.0, 0.01]", "gap_m = 0.0"),
    );
    let plan = pounding::plan::config::parse_row(
        &std::fs::read_to_string(&cfg).unwrap(),
        &cfg,
        d.path(),
        d.path(),
    )
    .unwrap();
    assert!(plan.cost_warning(64.0).is_some());
    let easy = pounding::plan::config::load_row_text(
        &std::fs::read_to_string("configs/row-3-6.toml").unwrap(),
        Path::new("configs/row-3-6.toml"),
    )
    .unwrap();
    assert_eq!(easy.cost_warning(64.0), None);
    let mut child = Command::new(env!("CARGO_BIN_EXE_pound"))
        .args([
            "sweep",
            s(&cfg),
            "-o",
            s(&d.path().join("t.csv")),
            "--backend",
            "cpu",
        ])
        .env("POUND_PROGRESS_S", "0.3")
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(std::time::Duration::from_secs(3));
    let _ = child.kill();
    let o = child.wait_with_output().unwrap();
    let e = err(&o);
    assert!(
        e.contains("RK4 substeps") && e.contains("runs may take minutes"),
        "{e}"
    );
    assert!(e.matches("progress: 0/1 runs").count() >= 2, "{e}");
}

/// Class 8: `file =` records of a config in a checkout beside `shared/records` are found
/// from any working directory; a missing one says where it looked and how to point elsewhere.
#[test]
fn records_resolve_from_the_config() {
    let d = tempdir();
    let recs = d.path().join("shared/records");
    std::fs::create_dir_all(&recs).unwrap();
    let v: Vec<String> = (0..300)
        .map(|i| format!("{:.5}", 0.2 * (i as f64 * 0.1).sin()))
        .collect();
    std::fs::write(recs.join("r.txt"), v.join("\n")).unwrap();
    let proj = d.path().join("checkout/configs");
    std::fs::create_dir_all(&proj).unwrap();
    let body = "[building1]\nmass_kg = 1e5\nperiod_s = 0.5\ndamping_ratio = 0.05\n[building2]\nmass_kg = 1e5\nperiod_s = 0.3\ndamping_ratio = 0.05\n[contact]\nlaw = \"linear\"\nk_n_per_m = 1e9\ngap_m = 0.01\n[[record]]\nfile = \"FILE\"\ndt_s = 0.01\n";
    let cfg = write(&proj, "c.toml", &body.replace("FILE", "r.txt"));
    let elsewhere = tempdir();
    ok(&pound_in(
        elsewhere.path(),
        &[
            "sweep",
            s(&cfg),
            "-o",
            s(&d.path().join("o.csv")),
            "--backend",
            "cpu",
        ],
    ));
    let missing = write(&proj, "m.toml", &body.replace("FILE", "nope.txt"));
    let o = pound_in(
        elsewhere.path(),
        &[
            "sweep",
            s(&missing),
            "-o",
            s(&d.path().join("m.csv")),
            "--backend",
            "cpu",
        ],
    );
    refused(&o, "no such record in");
    refused(&o, "POUND_RECORDS_DIR");
}

/// Class 9: messages give the bound or the fact, not a generic complaint.
#[test]
fn messages_name_the_bound_and_the_fact() {
    let d = tempdir();
    let cfg = write(d.path(), "row.toml", &row(STOREYS3, STOREYS2, ""));
    refused(
        &pound(&[
            "gap",
            s(&cfg),
            "-o",
            s(&d.path().join("g.csv")),
            "--gaps",
            "0:1e9:1",
        ]),
        "expected at most 10000",
    );
    let zero = write(
        d.path(),
        "zero.AT2",
        "PEER\nx\nUNITS OF G\nNPTS=   0, DT= .0000 SEC\n0.1 0.2\n",
    );
    refused(&pound(&["record", "info", s(&zero)]), "NPTS = 0 and DT = 0");
    let reference = write(
        d.path(),
        "ref.toml",
        &row(STOREYS3, STOREYS2, "")
            .replace("tail_s = 0.5", "tail_s = 0.5\nscheme = \"reference\""),
    );
    refused(
        &pound(&[
            "sweep",
            s(&reference),
            "--target-error",
            "1e-2",
            "-o",
            s(&d.path().join("r.csv")),
        ]),
        "(run.tol)",
    );
    let spc = write(
        d.path(),
        "spc.toml",
        &row(STOREYS3, STOREYS2, "")
            .replace("tail_s = 0.5", "tail_s = 0.5\nsubsteps_per_contact = 32"),
    );
    warns(
        &super::sweep(&spc, &d.path().join("s.csv"), &["--target-error", "1e-2"]),
        "overrides the config's run.substeps_per_contact = 32",
    );
    let results = d.path().join("s.csv");
    warns(
        &pound(&[
            "plot",
            s(&results),
            "--x",
            "gap_1_2_m",
            "--y",
            "b1_peak_roof_m",
            "--log-x",
            "-o",
            s(&d.path().join("p.svg")),
        ]),
        "points left out: a value <= 0 on a log axis",
    );
    let huge = write(
        d.path(),
        "huge.toml",
        &row(STOREYS3, STOREYS2, "").replace("tail_s = 0.5", "tail_s = 1e300"),
    );
    let o = pound(&["sweep", s(&huge), "-o", s(&d.path().join("h.csv"))]);
    refused(&o, "1e300 is out of range");
    // The storey bound is documented.
    let doc = std::fs::read_to_string("docs/multistorey.md").unwrap();
    assert!(doc.contains(&format!(
        "{} storeys",
        pounding::physics::shear::MAX_STOREYS
    )));
}
