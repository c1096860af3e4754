//! The `pound` binary end to end.

use crate::support::{assert_same_text, ok, pound, records_dir, tempdir};

const SMALL: &str = r#"
[run]
tail_s = 1.0

[building1]
mass_kg = 1.0e5
period_s = [0.3, 0.6]
damping_ratio = 0.05

[building2]
mass_kg = 1.0e5
period_s = [0.9]
damping_ratio = 0.05

[contact]
law = ["nonlinear_viscoelastic", "linear"]
formula = "ebrahimi"
e = [0.6, 0.8]
k_n_per_m = 1e9
beta_n_per_m1_5 = 2.75e9
gap_m = [0.0, 0.01, 1.0]

[[record]]
synthetic = { seed = 4, duration_s = 6.0 }
"#;

#[test]
fn sweep_writes_complete_csv_atomically() {
    let d = tempdir();
    let cfg = d.path().join("small.toml");
    std::fs::write(&cfg, SMALL).unwrap();
    let out1 = d.path().join("one.csv");
    let out2 = d.path().join("two.csv");
    let r1 = pound(&[
        "sweep",
        cfg.to_str().unwrap(),
        "-o",
        out1.to_str().unwrap(),
        "--threads",
        "1",
        "--chunk",
        "1",
    ]);
    ok(&r1);
    let err = String::from_utf8_lossy(&r1.stderr);
    assert!(
        err.contains("18 runs in") && err.contains("0 failures"),
        "{err}"
    );
    ok(&pound(&[
        "sweep",
        cfg.to_str().unwrap(),
        "-o",
        out2.to_str().unwrap(),
        "--threads",
        "2",
    ]));
    let (a, b) = (
        std::fs::read_to_string(&out1).unwrap(),
        std::fs::read_to_string(&out2).unwrap(),
    );
    assert_same_text("threads 1 vs 2", &a, &b);
    assert!(!d.path().join("one.csv.partial").exists());
    let mut rdr = csv::Reader::from_reader(a.as_bytes());
    let header: Vec<String> = rdr.headers().unwrap().iter().map(String::from).collect();
    assert_eq!(header, pounding::plan::columns::header());
    let rows: Vec<csv::StringRecord> = rdr.records().map(|r| r.unwrap()).collect();
    assert_eq!(rows.len(), 18);
    let col = |name: &str| header.iter().position(|h| h == name).unwrap();
    for (i, r) in rows.iter().enumerate() {
        assert_eq!(r[col("run")], i.to_string());
        assert_eq!(&r[col("status")], "ok");
        let gap: f64 = r[col("gap_m")].parse().unwrap();
        let impacts: u32 = r[col("impacts")].parse().unwrap();
        let force: f64 = r[col("peak_force_n")].parse().unwrap();
        // A 1 m gap never closes; zero gap always pounds.
        if gap == 1.0 {
            assert_eq!((impacts, force), (0, 0.0));
            assert_eq!(&r[col("first_impact_s")], "");
        }
        if gap == 0.0 {
            assert!(impacts > 0 && force > 0.0, "row {i}");
        }
        let law = &r[col("law")];
        assert_eq!(r[col("formula")].is_empty(), law == "linear");
        assert_eq!(r[col("beta_n_per_m1_5")].is_empty(), law == "linear");
        assert_eq!(
            &r[col("energy_residual")],
            "",
            "asked for with --energy only"
        );
    }
    // --energy adds the balance and changes nothing else.
    let out3 = d.path().join("three.csv");
    ok(&pound(&[
        "sweep",
        cfg.to_str().unwrap(),
        "-o",
        out3.to_str().unwrap(),
        "--energy",
    ]));
    let c = std::fs::read_to_string(&out3).unwrap();
    let mut rdr = csv::Reader::from_reader(c.as_bytes());
    let n = col("input_energy_j");
    for (r, plain) in rdr.records().map(|r| r.unwrap()).zip(&rows) {
        assert_eq!(
            r.iter().take(n).collect::<Vec<_>>(),
            plain.iter().take(n).collect::<Vec<_>>()
        );
        let field = |name: &str| -> f64 { r[col(name)].parse().unwrap() };
        assert!(field("input_energy_j") > 0.0 && field("damping_energy_j") > 0.0);
        assert!(field("energy_residual").abs() < 1e-4, "{r:?}");
    }
}

#[test]
fn sweep_reports_bad_config_without_output() {
    let d = tempdir();
    let cfg = d.path().join("bad.toml");
    std::fs::write(&cfg, SMALL.replace("e = [0.6, 0.8]", "e = [0.6, -0.8]")).unwrap();
    let out = d.path().join("r.csv");
    let r = pound(&["sweep", cfg.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    assert!(!r.status.success());
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(
        err.contains("bad.toml: contact.e[1]: -0.8 is out of range"),
        "{err}"
    );
    assert!(!out.exists() && !d.path().join("r.csv.partial").exists());
}

#[test]
fn formulas_table() {
    let text = ok(&pound(&["formulas", "--e", "0.1:0.5:0.4"]));
    let mut rdr = csv::Reader::from_reader(text.as_bytes());
    let h: Vec<String> = rdr.headers().unwrap().iter().map(String::from).collect();
    assert_eq!(h[0], "e");
    assert!(h.contains(&"ebrahimi".to_string()) && h.contains(&"exact:kelvin_voigt".to_string()));
    let rows: Vec<csv::StringRecord> = rdr.records().map(|r| r.unwrap()).collect();
    assert_eq!(rows.len(), 2);
    let at = |row: usize, name: &str| -> f64 {
        rows[row][h.iter().position(|x| x == name).unwrap()]
            .parse()
            .unwrap()
    };
    assert!((at(0, "ebrahimi") - 7.248146).abs() < 1e-6);
    // Kelvin-Voigt's exact zeta is Anagnostopoulos' formula.
    for r in 0..2 {
        assert!(
            (at(r, "exact:kelvin_voigt") - at(r, "anagnostopoulos")).abs() < 2e-6,
            "row {r}"
        );
    }
    let bad = pound(&["formulas", "--e", "1.5"]);
    assert!(!bad.status.success());
    assert!(String::from_utf8_lossy(&bad.stderr).contains("e = 1.5 is out of range"));
}

#[test]
fn record_info_prints_pga() {
    let f = records_dir().join("elcentro1940_ns_I-ELC180_peer2000.AT2");
    let text = ok(&pound(&["record", "info", f.to_str().unwrap()]));
    assert!(text.contains("npts      4000"), "{text}");
    assert!(text.contains("pga       0.3129 g"), "{text}");
    assert!(text.contains("t = 2.150 s"), "{text}");
    let kobe = records_dir().join("kobe1995_jma_ns_cms2_KOBE_NS.txt");
    let text = ok(&pound(&[
        "record",
        "info",
        kobe.to_str().unwrap(),
        "--dt",
        "0.02",
        "--units",
        "cm/s2",
        "--skip-lines",
        "3",
    ]));
    assert!(
        text.contains("pga       0.8342 g") && text.contains("818.0 cm/s^2"),
        "{text}"
    );
    let d = tempdir();
    let bad = d.path().join("bad.AT2");
    std::fs::write(&bad, "a\nb\nc\nNPTS= 3, DT= .01\n1.0 oops 2.0\n").unwrap();
    let r = pound(&["record", "info", bad.to_str().unwrap()]);
    assert!(!r.status.success());
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(
        err.contains("bad.AT2:5: expected numbers, found `oops`"),
        "{err}"
    );
    // `record info` only reads: the file is as it was and nothing appeared beside it.
    assert_eq!(
        std::fs::read_to_string(&bad).unwrap(),
        "a\nb\nc\nNPTS= 3, DT= .01\n1.0 oops 2.0\n"
    );
    let beside: Vec<_> = std::fs::read_dir(d.path()).unwrap().collect();
    assert_eq!(beside.len(), 1, "{beside:?}");
}

/// `pound accuracy` on a small config: one table row and one CSV row per path and setting, a
/// plot, and bad settings refused with the flag named.
#[test]
fn accuracy_writes_table_csv_and_plot() {
    let d = tempdir();
    let cfg = d.path().join("small.toml");
    std::fs::write(&cfg, SMALL).unwrap();
    let (csv, svg) = (d.path().join("a.csv"), d.path().join("a.svg"));
    let out = ok(&pound(&[
        "accuracy",
        cfg.to_str().unwrap(),
        "--settings",
        "16,64",
        "--backend",
        "cpu",
        "-o",
        csv.to_str().unwrap(),
        "--plot",
        svg.to_str().unwrap(),
    ]));
    assert_eq!(
        out.lines()
            .filter(|l| l.starts_with("| cpu-fast-f64 |"))
            .count(),
        2,
        "{out}"
    );
    assert!(out.contains("\n| reference | - |"), "{out}");
    let text = std::fs::read_to_string(&csv).unwrap();
    // Header, the reference, two settings.
    assert_eq!(text.lines().count(), 4, "{text}");
    assert!(std::fs::read_to_string(&svg)
        .unwrap()
        .contains("\nmedian error\n"));
    let bad = pound(&["accuracy", cfg.to_str().unwrap(), "--settings", "0.5"]);
    assert!(!bad.status.success());
    let err = String::from_utf8_lossy(&bad.stderr);
    assert!(err.contains("--settings: 0.5 is out of range"), "{err}");
}

/// A reader that closes the pipe early (`| head`) ends `pound` quietly, not with a panic.
#[test]
fn closed_pipe_ends_quietly() {
    let r = std::process::Command::new("bash")
        .args([
            "-c",
            &format!(
                "'{}' formulas --e 0.1:1:0.001 | head -1",
                env!("CARGO_BIN_EXE_pound")
            ),
        ])
        .output()
        .unwrap();
    assert_eq!(String::from_utf8_lossy(&r.stdout).lines().count(), 1);
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(!err.contains("panicked"), "{err}");
}

/// `--target-error` picks the calibrated setting, says so, records it in the sidecar, and the
/// runs take it (fewer substeps at 1e-2 than at 2e-5); a target below the calibration
/// is refused. `pound accuracy --target-error` checks the choice on a suite.
#[test]
fn target_error_chooses_records_and_is_checked() {
    let d = tempdir();
    let cfg = d.path().join("small.toml");
    std::fs::write(&cfg, SMALL).unwrap();
    let sweep = |out: &std::path::Path, extra: &[&str]| {
        let mut args = vec!["sweep", cfg.to_str().unwrap(), "-o", out.to_str().unwrap()];
        args.extend_from_slice(extra);
        pound(&args)
    };
    let substeps = |p: &std::path::Path| -> u64 {
        let text = std::fs::read_to_string(p).unwrap();
        let mut lines = text.lines();
        let h: Vec<&str> = lines.next().unwrap().split(',').collect();
        let i = h.iter().position(|c| *c == "substeps").unwrap();
        lines
            .map(|l| l.split(',').nth(i).unwrap().parse::<u64>().unwrap())
            .sum()
    };
    let (coarse, fine) = (d.path().join("coarse.csv"), d.path().join("fine.csv"));
    let r = sweep(&coarse, &["--target-error", "1e-2", "--backend", "cpu"]);
    ok(&r);
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(err.contains("8 RK4 substeps per contact"), "{err}");
    let meta = std::fs::read_to_string(d.path().join("coarse.csv.meta.toml")).unwrap();
    assert!(
        meta.contains("[target_error]") && meta.contains("substeps_per_contact = 8.0"),
        "{meta}"
    );
    let r = sweep(&fine, &["--target-error", "2e-5", "--backend", "cpu"]);
    ok(&r);
    assert!(String::from_utf8_lossy(&r.stderr).contains("48 RK4 substeps per contact"));
    let (few, many) = (substeps(&coarse), substeps(&fine));
    assert!(
        few > 0 && few * 2 < many,
        "{few} substeps at 1e-2 (8 per contact), {many} at 2e-5 (48)"
    );
    let bad = sweep(&d.path().join("never.csv"), &["--target-error", "1e-6"]);
    // (below the pairs' calibration: 1.8e-5, the floor of GPU f32)
    assert!(!bad.status.success());
    let err = String::from_utf8_lossy(&bad.stderr);
    assert!(
        err.contains("below what the fast scheme is calibrated for"),
        "{err}"
    );
    assert!(!d.path().join("never.csv").exists());
    let out = ok(&pound(&[
        "accuracy",
        cfg.to_str().unwrap(),
        "--target-error",
        "1e-2",
        "--backend",
        "cpu",
        "-o",
        d.path().join("a.csv").to_str().unwrap(),
    ]));
    assert!(
        out.contains("--target-error 1e-2: 8 substeps per contact, cpu-fast-f64")
            && out.contains("(met)"),
        "{out}"
    );
}
