//! What a config and a record take (issue 47's classes 7, windows; 8, the config's messages; 11,
//! names that collide; and the config and record parts of 9): every key names its forms, names do
//! not collide, a record's window is the one reported, and no input is written in 300 digits.

use crate::scenes::{row_config, with};
use crate::support::cli::stderr;
use crate::support::{ok, pound, records_dir, table, tempdir};
use pounding::plan::config::load_text;
use std::path::Path;

/// The real record the window tests read.
const ELCENTRO: &str = "elcentro1940_ns_I-ELC180_peer2000.AT2";

/// `row_config`'s row with its synthetic record replaced by `record` (the `[[record]]` table's
/// lines) and `tail` after it.
fn with_record(b0: &str, record: &str, tail: &str) -> String {
    row_config(b0, "", "", "").replace(
        "synthetic = { seed = 1, duration_s = 1.0, dt_s = 0.01, pga_g = 0.3 }",
        record,
    ) + tail
}

/// The error of loading config `text`, or None if it loads.
fn error_of(text: &str) -> Option<String> {
    load_text(text, Path::new("t.toml"))
        .err()
        .map(|e| e.to_string())
}

/// Class 7, windows: with `window_s`, a target is met on the window, and `pound record
/// spectrum` and `pound record info` take the same window (`--window START:END`), so the Sa a
/// sweep scaled to is the one the spectrum reports. They had no window option.
#[test]
fn a_windowed_record_is_the_one_reported() {
    let dir = tempdir();
    let d = dir.path();
    // Absolute: the config is in a temporary folder.
    let file = std::fs::canonicalize(records_dir().join(ELCENTRO)).unwrap();
    let f = file.to_str().unwrap();
    let cfg = d.join("w.toml");
    std::fs::write(
        &cfg,
        with_record(
            "",
            &format!("path = \"{f}\"\nwindow_s = [2.0, 6.0]"),
            "[intensity]\nsa_g = 0.5\nsa_period_s = 0.5\n",
        ),
    )
    .unwrap();
    let runs = d.join("runs.csv");
    ok(&pound(&[
        "sweep",
        cfg.to_str().unwrap(),
        "--backend",
        "cpu",
        "-o",
        runs.to_str().unwrap(),
    ]));
    let row = &table(&runs)[0];
    let scale: f64 = row["scale_factor"].parse().unwrap();
    let pga: f64 = row["pga_g"].parse().unwrap();
    let spectrum = |window: &[&str], name: &str| -> f64 {
        let out = d.join(name);
        let mut args = vec!["record", "spectrum", f, "--periods", "0.5"];
        args.extend(window);
        args.extend(["-o", out.to_str().unwrap()]);
        ok(&pound(&args));
        let t = table(&out);
        assert_eq!(t.len(), 1);
        t[0]["sa_g"].parse().unwrap()
    };
    let windowed = spectrum(&["--window", "2:6"], "w.csv");
    let whole = spectrum(&[], "whole.csv");
    let rel = |a: f64, b: f64| (a - b).abs() / b.abs();
    assert!(
        rel(0.5 / scale, windowed) < 1e-9,
        "the sweep scaled Sa {} to 0.5 g; the windowed spectrum says {windowed}",
        0.5 / scale
    );
    assert!(rel(whole, windowed) > 1e-3, "the window changes nothing");
    // `record info` reads the same window: its samples, its clock, its PGA.
    let info = ok(&pound(&["record", "info", f, "--window", "2:6"]));
    assert!(info.contains("npts      401"), "{info}");
    assert!(info.contains("t0        2 s"), "{info}");
    let info_pga: f64 = info
        .lines()
        .find_map(|l| l.strip_prefix("pga       "))
        .and_then(|l| l.split_whitespace().next())
        .and_then(|x| x.parse().ok())
        .unwrap_or_else(|| panic!("{info}"));
    assert!(
        rel(info_pga * scale, pga) < 1e-3,
        "{info_pga} x {scale} vs {pga}"
    );
    // A window that holds no record is refused on both sides, naming the record's span, and a
    // far one is an error, not a panic (`window_s = [1e300, 2e300]` indexed past the record).
    // A window reaching past either end is refused too, not cut to the record in silence.
    for w in ["50:60", "6:2", "1e300:2e300", "x:1", "1", "-1:3", "0:100"] {
        let o = pound(&["record", "info", f, &format!("--window={w}")]);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(1), "--window {w}: {err}");
        assert!(err.contains("--window"), "--window {w}: {err}");
    }
    let err = stderr(&pound(&["record", "info", f, "--window", "50:60"]));
    assert!(err.contains("0 s to 39.99 s"), "{err}");
    for w in [
        "[50.0, 60.0]",
        "[1e300, 2e300]",
        "[-1e300, -1e299]",
        "[-1.0, 3.0]",
        "[0.0, 100.0]",
    ] {
        let text = with_record("", &format!("path = \"{f}\"\nwindow_s = {w}"), "");
        let err = error_of(&text).unwrap_or_else(|| panic!("{w} loads"));
        assert!(err.contains("window_s"), "{err}");
        assert!(err.contains("0 s to 39.99 s"), "{err}");
    }
}

/// A config with `key = value` set in one of its sections.
type Section = Box<dyn Fn(&str, &str) -> String>;

/// Every section of a config: its name and the config with `key = value` set in it.
fn sections() -> Vec<(&'static str, Section)> {
    let line = |k: &str, v: &str| format!("{k} = {v}");
    let inline = |base: &[(&str, &str)], k: &str, v: &str| {
        let mut cells: Vec<String> = base
            .iter()
            .filter(|(b, _)| *b != k)
            .map(|(b, x)| format!("{b} = {x}"))
            .collect();
        cells.push(format!("{k} = {v}"));
        format!("{{ {} }}", cells.join(", "))
    };
    // A record that reads, so each key's own refusal is the one seen.
    let file = std::fs::canonicalize(records_dir().join(ELCENTRO)).unwrap();
    let source = format!("path = \"{}\"\n", file.display());
    let record = {
        let source = source.clone();
        move |extra: &str| with_record("", &format!("{source}{extra}"), "")
    };
    let spectral = ["sa_g = 0.5", "sa_period_s = 0.5"];
    let sample_axis = [
        "key = \"building[0].mass_kg\"",
        "dist = \"uniform\"",
        "min = 2e5",
        "max = 3e5",
    ];
    vec![
        (
            "building",
            Box::new(move |k: &str, v: &str| row_config(&line(k, v), "", "", "")),
        ),
        (
            "building (yielding)",
            Box::new(move |k: &str, v: &str| {
                row_config(
                    &with(&["yield_drift_ratio = 0.01"], &line(k, v)),
                    "",
                    "",
                    "",
                )
            }),
        ),
        (
            "contact",
            Box::new(move |k: &str, v: &str| row_config("", "", &line(k, v), "")),
        ),
        (
            "record",
            Box::new(move |k: &str, v: &str| {
                // A file record, less the source a key replaces.
                let t = record(&line(k, v));
                match k {
                    "file" | "synthetic" | "path" => t.replace(&source, ""),
                    _ => t,
                }
            }),
        ),
        (
            "record.synthetic",
            Box::new(move |k: &str, v: &str| {
                with_record(
                    "",
                    &format!(
                        "synthetic = {}",
                        inline(&[("seed", "1"), ("duration_s", "1.0")], k, v)
                    ),
                    "",
                )
            }),
        ),
        (
            "intensity",
            Box::new(move |k: &str, v: &str| {
                row_config(
                    "",
                    "",
                    "",
                    &format!("[intensity]\n{}", with(&spectral, &line(k, v))),
                )
            }),
        ),
        (
            "intensity (sa_avg)",
            Box::new(move |k: &str, v: &str| {
                let base = ["sa_avg_g = 0.5", "sa_avg_periods_s = [0.2, 1.0]"];
                row_config(
                    "",
                    "",
                    "",
                    &format!("[intensity]\n{}", with(&base, &line(k, v))),
                )
            }),
        ),
        (
            "run",
            Box::new(move |k: &str, v: &str| {
                row_config("", "", "", &format!("[run]\n{}", line(k, v)))
            }),
        ),
        (
            "sample",
            Box::new(move |k: &str, v: &str| {
                let s = with(&["n = 3", "seed = 1"], &line(k, v));
                // `axis` given here stands for the [[sample.axis]] tables.
                let axes = match k {
                    "axis" => String::new(),
                    _ => format!("[[sample.axis]]\n{}", sample_axis.join("\n")),
                };
                row_config("-mass_kg", "", "", &format!("[sample]\n{s}\n{axes}"))
            }),
        ),
        (
            "sample.axis",
            Box::new(move |k: &str, v: &str| {
                row_config(
                    "-mass_kg",
                    "",
                    "",
                    &format!(
                        "[sample]\nn = 3\nseed = 1\n[[sample.axis]]\n{}",
                        with(&sample_axis, &line(k, v))
                    ),
                )
            }),
        ),
        (
            "range",
            Box::new(move |k: &str, v: &str| {
                row_config(
                    &format!(
                        "period_s = {}",
                        inline(&[("from", "0.3"), ("to", "0.5"), ("n", "2")], k, v)
                    ),
                    "",
                    "",
                    "",
                )
            }),
        ),
        (
            "pair building1",
            Box::new(move |k: &str, v: &str| {
                let b1 = with(
                    &["mass_kg = 1e5", "period_s = 0.5", "damping_ratio = 0.05"],
                    &line(k, v),
                );
                format!(
                    "[building1]\n{b1}\n[building2]\nmass_kg = 1e5\nperiod_s = 0.3\ndamping_ratio = 0.05\n[contact]\nlaw = \"linear\"\nk_n_per_m = 1e9\ngap_m = 0.01\n[[record]]\nsynthetic = {{ seed = 1, duration_s = 1.0 }}\n"
                )
            }),
        ),
    ]
}

/// The keys a section takes, as serde lists them for an unknown one.
fn keys_of(section: &dyn Fn(&str, &str) -> String) -> Vec<String> {
    let err = error_of(&section("no_such_key", "1")).expect("an unknown key is refused");
    let list = err
        .split("expected one of")
        .nth(1)
        .unwrap_or_else(|| panic!("no key list in: {err}"));
    let keys: Vec<String> = list
        .split('`')
        .skip(1)
        .step_by(2)
        .map(str::to_string)
        .collect();
    assert!(!keys.is_empty(), "{err}");
    keys
}

/// Words of Rust, not of the config: a message that says them names no form a user can write.
const RUST_WORDS: [&str; 9] = [
    "untagged", "variant", "struct ", "usize", "u64", "f64", "i64", "u32", "Raw",
];

/// Class 8, messages: every key of every section (listed by the config's own refusal of an
/// unknown key), given a value of a wrong kind, is refused by a message that names the key and
/// the forms it takes, in the config's words. `post_yield_ratio = "0.05"`, `yield_force_n =
/// true`, `yield_drift_ratio = "0.01"`, `sa_period_s = [0.5, 1.0]` said `data did not match any
/// variant of untagged enum ...`. And a record whose simulated part is all zeros, under a
/// spectral target, says it has no Sa to scale (it spoke of a target PGA).
#[test]
fn every_key_names_its_forms() {
    let wrong = ["true", "\"0.05\"", "[true]", "[true, 0.5]", "{ x = 1 }"];
    let mut checked = 0;
    for (name, section) in sections() {
        for key in keys_of(&*section) {
            let mut refused = 0;
            for v in wrong {
                let text = section(&key, v);
                let Some(err) = error_of(&text) else { continue };
                refused += 1;
                // A value of a kind the key never takes: named with the forms it does take.
                if err.contains("TOML parse error") {
                    assert!(
                        err.contains(&key) && err.contains("expected"),
                        "[{name}] {key} = {v}: the message does not name the key and its forms: {err}"
                    );
                }
                for w in RUST_WORDS {
                    assert!(!err.contains(w), "[{name}] {key} = {v}: `{w}` in: {err}");
                }
            }
            assert!(refused > 0, "[{name}] {key}: no wrong value refused");
            checked += 1;
        }
    }
    assert!(checked >= 60, "{checked} keys");
    // The four name the forms they take.
    for (b0, tail, forms) in [
        (
            "yield_drift_ratio = 0.01\npost_yield_ratio = \"0.05\"",
            "",
            "a list",
        ),
        ("yield_force_n = true", "", "a list"),
        ("yield_drift_ratio = \"0.01\"", "", "range"),
        (
            "",
            "[intensity]\nsa_g = 0.5\nsa_period_s = [0.5, 1.0]",
            "building1",
        ),
    ] {
        let err = error_of(&row_config(b0, "", "", tail)).unwrap();
        assert!(err.contains("expected a"), "{err}");
        assert!(err.contains(forms), "expected `{forms}` in: {err}");
    }
    // A simulated part of zeros under a spectral target: no Sa, not no PGA.
    let dir = tempdir();
    let zeros = dir.path().join("z.txt");
    std::fs::write(&zeros, "0\n0\n0\n0\n0.1\n0.2\n-0.1\n0\n").unwrap();
    let record = format!(
        "path = \"{}\"\nformat = \"values\"\ndt_s = 0.01\nwindow_s = [0.0, 0.03]",
        zeros.display()
    );
    for (tail, says) in [
        ("[intensity]\nsa_g = 0.5\nsa_period_s = 0.5\n", "Sa"),
        (
            "[intensity]\nsa_avg_g = 0.5\nsa_avg_periods_s = [0.2, 1.0]\n",
            "Sa_avg",
        ),
        ("[intensity]\npga_g = 0.5\n", "PGA"),
    ] {
        let err = error_of(&with_record("", &record, tail)).unwrap();
        assert!(err.contains("all zeros"), "{err}");
        assert!(
            err.contains(&format!("no {says} ")),
            "expected `no {says}` in: {err}"
        );
        assert!(err.contains("0 s to 0.03 s"), "{err}");
    }
}

/// Class 11, names that collide: two `[[record]]`s with one label (a name given twice, two
/// windows of one file, one seed twice) were accepted and written under one label; a law or a
/// formula given twice made runs of one label; `--aggregate gap_m,gap_m` and one `--exceed`
/// twice wrote a summary with two columns of one name. Each is refused, naming both.
#[test]
fn names_do_not_collide() {
    let file = std::fs::canonicalize(records_dir().join(ELCENTRO)).unwrap();
    let f = file.to_str().unwrap();
    let two = |a: &str, b: &str| {
        row_config("", "", "", "").replace(
            "synthetic = { seed = 1, duration_s = 1.0, dt_s = 0.01, pga_g = 0.3 }",
            a,
        ) + &format!("[[record]]\n{b}\n")
    };
    let syn = "synthetic = { seed = 1, duration_s = 1.0 }";
    for (a, b, label) in [
        (
            format!("path = \"{f}\"\nwindow_s = [0.0, 5.0]"),
            format!("path = \"{f}\"\nwindow_s = [5.0, 10.0]"),
            "elcentro1940_ns_I-ELC180_peer2000",
        ),
        (
            format!("name = \"x\"\n{syn}"),
            "name = \"x\"\nsynthetic = { seed = 2, duration_s = 1.0 }".to_string(),
            "x",
        ),
        (syn.to_string(), syn.to_string(), "synthetic-s1"),
        (
            syn.to_string(),
            "name = \"synthetic-s1\"\nsynthetic = { seed = 2, duration_s = 1.0 }".into(),
            "synthetic-s1",
        ),
    ] {
        let text = two(&a, &b);
        let err = error_of(&text).unwrap_or_else(|| panic!("loads:\n{text}"));
        for n in ["record[0]", "record[1]", label, "name"] {
            assert!(err.contains(n), "expected `{n}` in: {err}");
        }
    }
    // Named apart, they load.
    let text = two(
        &format!("path = \"{f}\"\nwindow_s = [0.0, 5.0]\nname = \"early\""),
        &format!("path = \"{f}\"\nwindow_s = [5.0, 10.0]\nname = \"late\""),
    );
    assert!(error_of(&text).is_none(), "{:?}", error_of(&text));
    for (contact, key) in [
        ("law = [\"linear\", \"linear\"]", "contact.law[1]"),
        (
            "law = \"nonlinear_viscoelastic\"\nbeta_n_per_m1_5 = 2.75e9\ne = 0.6\nformula = [\"ebrahimi\", \"jankowski\", \"ebrahimi\"]",
            "contact.formula[2]",
        ),
    ] {
        let err = error_of(&row_config("", "", contact, "")).expect(contact);
        assert!(err.contains(key), "expected `{key}` in: {err}");
        assert!(err.contains("twice"), "{err}");
    }
    // A summary's columns: a pair's and a row's.
    let dir = tempdir();
    let row = dir.path().join("row.toml");
    std::fs::write(&row, row_config("", "", "gap_m = [0.0, 0.01]", "")).unwrap();
    let pair = concat!(env!("CARGO_MANIFEST_DIR"), "/configs/quickstart.toml");
    let out = dir.path().join("summary.csv");
    for cfg in [pair, row.to_str().unwrap()] {
        let by = if cfg == pair { "gap_m" } else { "gap_1_2_m" };
        let twice = format!("{by},{by}");
        let repeated = [
            vec!["--aggregate", twice.as_str()],
            vec![
                "--aggregate",
                by,
                "--exceed",
                "peak_force_n=1e6",
                "--exceed",
                "peak_force_n=1000000",
            ],
        ];
        for extra in repeated {
            let mut args = vec![
                "sweep",
                cfg,
                "--backend",
                "cpu",
                "-o",
                out.to_str().unwrap(),
            ];
            args.extend(extra);
            let o = pound(&args);
            let err = stderr(&o);
            assert!(!o.status.success(), "{args:?}: rc 0");
            assert!(err.contains("twice"), "{args:?}: {err}");
            assert!(!out.exists(), "{args:?} wrote a summary");
        }
    }
    // Every other list a command or a config takes: a value given twice is refused, naming it,
    // before anything is written (a repeated threshold wrote its curve twice; a repeated axis
    // value ran its runs twice, weighting them double in a fit).
    let results = dir.path().join("runs.csv");
    ok(&pound(&[
        "sweep",
        row.to_str().unwrap(),
        "-o",
        results.to_str().unwrap(),
    ]));
    let r = results.to_str().unwrap();
    let o = |name: &str| dir.path().join(name).to_str().unwrap().to_string();
    let record = std::fs::canonicalize(records_dir().join(ELCENTRO)).unwrap();
    for (args, named) in [
        (
            vec![
                "sweep",
                pair,
                "--columns",
                "run,peak_force_n,run",
                "-o",
                &o("c.csv"),
            ],
            "`run`",
        ),
        (
            vec![
                "fragility",
                r,
                "--im",
                "pga_g",
                "--edp",
                "peak_force_n",
                "--threshold",
                "1e6,1e6",
                "-o",
                &o("f.csv"),
            ],
            "1000000",
        ),
        (
            vec![
                "ida",
                r,
                "--im",
                "pga_g",
                "--edp",
                "b1_peak_drift_ratio",
                "--curves",
                "record,record",
                "-o",
                &o("i.csv"),
            ],
            "`record`",
        ),
        (
            vec!["gap", pair, "--gaps", "0.01,0.01", "-o", &o("g.csv")],
            "0.01",
        ),
        (
            vec!["restitution", "--e", "0.5,0.5", "-o", &o("r.csv")],
            "0.5",
        ),
        (
            vec![
                "record",
                "spectrum",
                record.to_str().unwrap(),
                "--periods",
                "0.5,0.5",
                "-o",
                &o("s.csv"),
            ],
            "0.5 s",
        ),
    ] {
        let out = pound(&args);
        let err = stderr(&out);
        assert!(!out.status.success(), "{args:?}: rc 0");
        assert!(
            err.contains("twice") && err.contains(named),
            "{args:?}: {err}"
        );
        let written = args.last().unwrap();
        assert!(!Path::new(written).exists(), "{args:?} wrote {written}");
    }
    // A list's form that drops a value it was given is refused too (FROM:TO:1 ignored TO).
    let o = pound(&[
        "record",
        "spectrum",
        record.to_str().unwrap(),
        "--periods",
        "0.05:4:1",
        "-o",
        &o("s1.csv"),
    ]);
    assert!(
        !o.status.success() && stderr(&o).contains("ignores TO"),
        "{}",
        stderr(&o)
    );
    let err = error_of(&row_config("", "", "gap_m = [0.01, 0.01]", "")).expect("a repeated gap");
    assert!(
        err.contains("contact.gap_m") && err.contains("twice"),
        "{err}"
    );
}

/// A run of 25 digits or more: a number written out in full where a bounded form belongs.
fn long_number(text: &str) -> Option<String> {
    let mut run = String::new();
    for c in text.chars() {
        if c.is_ascii_digit() || (c == '.' && !run.is_empty()) {
            run.push(c);
            if run.chars().filter(char::is_ascii_digit).count() >= 25 {
                return Some(run);
            }
        } else {
            run.clear();
        }
    }
    None
}

/// Class 9, the config and record parts: an `Sa_avg` whose ends are the same period in some
/// run (`["0.5*building[0]", 0.5]` with building[0] at 1 s) is refused as the literal
/// `[0.5, 0.5]` is (it ran, from = to); and no record or config command writes a number of
/// hundreds of digits: every key of every section given 1e300 and 1e-300, and the record
/// commands on records and flags of those magnitudes, write a bounded form.
#[test]
fn small_ones_in_inputs() {
    for (period, refused) in [
        ("period_s = 1.0", true),
        ("period_s = [0.8, 1.0]", true),
        ("period_s = 0.8", false),
    ] {
        let tail = "[intensity]\nsa_avg_g = 0.5\nsa_avg_periods_s = [\"0.5*building[0]\", 0.5]\n";
        let err = error_of(&row_config(period, "", "", tail));
        assert_eq!(err.is_some(), refused, "{period}: {err:?}");
        if let Some(err) = err {
            assert!(err.contains("sa_avg_periods_s"), "{err}");
            assert!(err.contains("same period"), "{err}");
        }
    }
    // Every key of every section, huge and tiny.
    let mut checked = 0;
    for (name, section) in sections() {
        for key in keys_of(&*section) {
            for v in [
                "1e300",
                "-1e300",
                "1e-300",
                "[1e300, 2e300]",
                "[1e-300, 2e-300]",
            ] {
                if let Some(err) = error_of(&section(&key, v)) {
                    if let Some(n) = long_number(&err) {
                        panic!("[{name}] {key} = {v}: {n}... in: {err}");
                    }
                    checked += 1;
                }
            }
        }
    }
    assert!(checked > 100, "{checked}");
    // The record commands.
    let dir = tempdir();
    let d = dir.path();
    let big = d.join("big.txt");
    let tiny = d.join("tiny.txt");
    std::fs::write(&big, "0\n1e300\n-2e300\n5e299\n0\n").unwrap();
    std::fs::write(&tiny, "0\n1e-300\n-2e-300\n5e-299\n0\n").unwrap();
    let csv = d.join("s.csv");
    let c = csv.to_str().unwrap();
    let read = ["--dt", "0.01", "--units", "m/s2"];
    for file in [&big, &tiny] {
        let f = file.to_str().unwrap();
        let runs: Vec<Vec<&str>> = vec![
            vec!["record", "info", f],
            vec!["record", "spectrum", f, "--periods", "0.5,1", "-o", c],
            vec!["record", "spectrum", f, "--damping", "1e300", "-o", c],
            vec!["record", "spectrum", f, "--periods", "1e300", "-o", c],
            vec!["record", "info", f, "--window", "1e300:2e300"],
            vec!["record", "info", f, "--window", "-1e-300:1e-300"],
        ];
        for mut args in runs {
            args.extend(read);
            let _ = std::fs::remove_file(&csv);
            let o = pound(&args);
            let all = format!(
                "{}{}{}",
                String::from_utf8_lossy(&o.stdout),
                stderr(&o),
                std::fs::read_to_string(&csv).unwrap_or_default()
            );
            if let Some(n) = long_number(&all) {
                panic!("{args:?}: {n}... in:\n{all}");
            }
        }
    }
    let o = pound(&["record", "info", big.to_str().unwrap(), "--dt", "1e-300"]);
    let all = format!("{}{}", String::from_utf8_lossy(&o.stdout), stderr(&o));
    assert!(long_number(&all).is_none(), "{all}");
}
