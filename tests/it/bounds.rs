//! No panic, no hang: every size a user types is bounded with an error that gives the bound and
//! why, every bounded size is served, an extreme cost is said before the first run, and random
//! edits of configs and records never panic the parsers.

use crate::scenes::{row, row_config, Scene, CHEAP_SWEEP, STOREYS3};
use crate::support::cli::stderr as err;
use crate::support::cli::{refused, s, write};
use crate::support::{assert_same_text, ok, pound, tempdir};
use pounding::plan::config::load_text;
use proptest::prelude::*;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

/// Run `pound` with a deadline: a hang is a failure, not a stuck test.
fn pound_within(args: &[&str], limit: Duration) -> Output {
    let child = Command::new(env!("CARGO_BIN_EXE_pound"))
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let pid = child.id();
    let start = Instant::now();
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let _ = tx.send(child.wait_with_output());
    });
    match rx.recv_timeout(limit) {
        Ok(o) => o.unwrap(),
        Err(_) => {
            // SAFETY: killing the child this test started.
            unsafe { libc::kill(pid as i32, libc::SIGKILL) };
            panic!(
                "pound {args:?} still running after {:?}: a hang",
                start.elapsed()
            );
        }
    }
}

/// Class 5: no panic on a full stderr, and every size a user types is bounded with an error
/// that gives the bound and why, at once.
#[test]
fn sizes_are_bounded_and_nothing_panics() {
    let sc = Scene::new();
    // stderr on a full device: the sweep completes, rc 0.
    let out = sc.path("full.csv");
    let r = Command::new("bash")
        .args([
            "-c",
            &format!(
                "'{}' sweep '{}' -o '{}' --backend cpu 2>/dev/full",
                env!("CARGO_BIN_EXE_pound"),
                s(&sc.cfg),
                s(&out)
            ),
        ])
        .output()
        .unwrap();
    assert!(r.status.success(), "rc {:?}", r.status);
    assert_same_text(
        "stderr full",
        &std::fs::read_to_string(&out).unwrap(),
        &sc.whole,
    );
    let bad = |name: &str, from: &str, to: &str| -> PathBuf {
        let p = sc.path(name);
        let text = CHEAP_SWEEP.replace(from, to);
        assert_ne!(text, CHEAP_SWEEP, "{name}");
        std::fs::write(&p, text).unwrap();
        p
    };
    let limit = Duration::from_secs(60);
    let o = sc.path("x.csv");
    let cases: Vec<(Vec<String>, &str)> = vec![
        (vec![s(&bad("tail.toml", "tail_s = 0.5", "tail_s = 1e12")).into()], "expected 0 to 3600 s"),
        (vec![s(&sc.cfg).into(), "--threads".into(), "100000".into()], "expected 1 to 1024"),
        (vec![s(&sc.cfg).into(), "--threads".into(), "0".into()], "expected 1 to 1024"),
        (vec![s(&sc.cfg).into(), "--chunk".into(), "0".into()], "--chunk 0"),
        (vec![s(&sc.cfg).into(), "--chunk".into(), "100000000000".into()], "expected 1 to 1048576"),
        (vec![s(&bad("sub.toml", "tail_s = 0.5", "tail_s = 0.5\nsubsteps_per_contact = 1e9")).into()], "expected 1 to 4096"),
        (vec![s(&bad("n.toml", "gap_m = [0.0, 0.01, 0.03]", "gap_m = { from = 0, to = 1, n = 100000000000 }")).into()], "expected 1 to 1e7"),
        (vec![s(&{
            let p = sc.path("grid.toml");
            let t = CHEAP_SWEEP
                .replace("period_s = [0.3, 0.6]", "period_s = { from = 0.1, to = 2, n = 10000000 }")
                .replace("gap_m = [0.0, 0.01, 0.03]", "gap_m = { from = 0, to = 1, n = 10000000 }")
                .replace("mass_kg = 1.0e5\nperiod_s = [0.45", "mass_kg = { from = 1, to = 2, n = 10 }\nperiod_s = [0.45");
            assert!(t.contains("n = 10 }"));
            std::fs::write(&p, t).unwrap();
            p
        }).into()], "expected at most 2^53"),
        (vec![s(&bad("smp.toml", "[[record]]\nsynthetic", "[sample]\nn = 1000000000000\nseed = 1\n[[sample.axis]]\nkey = \"contact.gap_m\"\ndist = \"uniform\"\nmin = 0\nmax = 1\n\n[[record]]\nsynthetic")).into()], "at most 10000000"),
        (vec![s(&bad("syn.toml", "duration_s = 3.0", "duration_s = 3.0, fg_hz = 1e12")).into()], "Nyquist"),
    ];
    for (args, needle) in cases {
        let mut a = vec!["sweep", "-o", s(&o), "--backend", "cpu"];
        a.extend(args.iter().map(String::as_str));
        let r = pound_within(&a, limit);
        refused(&r, needle, Some(&o));
    }
    // A grid of more than 2^64 runs (13 axes of 1e7 values) is refused from the axis sizes,
    // before ~1 GB of axes is built.
    let big = bad(
        "big.toml",
        "[building1]\nmass_kg = 1.0e5\nperiod_s = [0.3, 0.6]\ndamping_ratio = 0.05",
        "[building1]\nmass_kg = { from = 1, to = 2, n = 10000000 }\nperiod_s = { from = 0.1, to = 2, n = 10000000 }\ndamping_ratio = { from = 0.01, to = 0.1, n = 10000000 }",
    );
    let r = pound_within(&["sweep", s(&big), "-o", s(&o)], limit);
    refused(&r, "more than 2^64 runs", Some(&o));
    // A record path that never ends is an error after a bounded read.
    let zero = sc.path("zero.toml");
    std::fs::write(
        &zero,
        CHEAP_SWEEP.replace("path = \"rec.txt\"", "path = \"/dev/zero\""),
    )
    .unwrap();
    refused(
        &pound_within(&["sweep", s(&zero), "-o", s(&o)], limit),
        "larger than 256 MiB",
        Some(&o),
    );
    // Bench and the single-collision studies bound their sizes too.
    refused(
        &pound_within(&["bench", "--sizes", "0"], limit),
        "--sizes",
        None,
    );
    refused(
        &pound_within(&["formulas", "--e", "0.1:1:0.000001"], limit),
        "at most 10000",
        None,
    );
    refused(
        &pound_within(&["accuracy", s(&sc.cfg), "--settings", "1e9"], limit),
        "from 1 to 4096",
        None,
    );
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

/// Class 5 where it arises in a config: a mass no building has (1e170 kg stalled a sweep with
/// no word, for seconds on end) is refused with its bound, for a pair's and a row's buildings,
/// and so is a coefficient of restitution below 0.01.
#[test]
fn a_mass_beyond_any_building_is_refused() {
    for (config, line) in [
        ("configs/quickstart.toml", "mass_kg = 1.0e5"),
        ("configs/inelastic-row.toml", "mass_kg = 3.0e5"),
    ] {
        let text = std::fs::read_to_string(config)
            .unwrap()
            .replacen(line, "mass_kg = 1e170", 1);
        let err = load_text(&text, Path::new(config))
            .expect_err(config)
            .to_string();
        assert!(err.contains("mass_kg") && err.contains("1e12 kg"), "{err}");
    }
    let floors = row_config("-mass_kg\nfloor_masses_kg = [3e5, 1e170]", "", "", "");
    let err = load_text(&floors, Path::new("floors.toml"))
        .expect_err("a floor of 1e170 kg")
        .to_string();
    assert!(
        err.contains("floor_masses_kg[1]") && err.contains("1e12 kg"),
        "{err}"
    );
    // So is an impact all but plastic: the exact damping's search costs as 1/e (a sweep at
    // e = 1e-4 printed nothing for minutes; `pound restitution --e 1e-3` ran as long).
    let text = std::fs::read_to_string("configs/quickstart.toml").unwrap();
    let e_line = text
        .lines()
        .find(|l| l.starts_with("e = "))
        .expect("an e axis");
    let err = load_text(&text.replace(e_line, "e = 1e-4"), Path::new("q.toml"))
        .expect_err("e = 1e-4")
        .to_string();
    assert!(
        err.contains("contact.e") && err.contains("0.01 <= e"),
        "{err}"
    );
    for args in [
        ["restitution", "--e", "0.001"],
        ["formulas", "--e", "0.001"],
    ] {
        let o = pound(&args);
        let said = String::from_utf8_lossy(&o.stderr);
        assert!(
            !o.status.success() && said.contains("0.01 <= e"),
            "{args:?}: {said}"
        );
    }
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

/// A valid config to mutate: every key, a record file, a sample.
fn mutable_config() -> String {
    CHEAP_SWEEP.replace(
        "[[record]]\nsynthetic = { seed = 1, duration_s = 3.0 }\n",
        "",
    )
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    /// Random edits of a valid config never panic the parser: Ok or an error naming the file.
    #[test]
    fn mutated_configs_never_panic(edits in prop::collection::vec((any::<prop::sample::Index>(), any::<u8>(), 0u8..3), 1..6)) {
        let d = tempdir();
        std::fs::write(d.path().join("rec.txt"), "0.1\n0.2\n-0.1\n0.05").unwrap();
        let mut text = mutable_config().into_bytes();
        for (at, byte, op) in edits {
            let i = at.index(text.len().max(1));
            match op {
                0 => text[i] = byte,
                1 => { text.remove(i); }
                _ => text.insert(i, byte),
            }
        }
        let text = String::from_utf8_lossy(&text);
        if let Err(e) = pounding::plan::config::parse(&text, Path::new("m.toml"), d.path(), d.path()) {
            prop_assert!(e.to_string().starts_with("m.toml"), "{e}");
        }
    }

    /// Configs with nasty values in every key (zero, negative, tiny, huge, NaN, infinite, or
    /// ordinary) never panic: they are refused with the file and key named, or they give a plan
    /// whose runs decode, whose warnings and shard cuts compute.
    #[test]
    fn nasty_values_never_panic(
        nasty in prop::collection::vec(prop_oneof![
            3 => Just(None),
            1 => prop::sample::select(vec![
                "0", "-1", "1e-300", "1e300", "nan", "inf", "-inf", "0.5", "1", "2", "1e-4", "3600", "1e7",
            ]).prop_map(Some),
        ], 16),
        law in prop::sample::select(vec!["linear", "kelvin_voigt", "hertz", "nonlinear_viscoelastic", "hunt_crossley", "hunt_crossley_exact"]),
        formula in prop::sample::select(vec!["ebrahimi", "jankowski", "exact", "anagnostopoulos", "nope"]),
    ) {
        // Each key: a sane value three times in four, else a nasty one.
        let sane = ["1", "64", "1e5", "0.4", "0.05", "1e5", "0.9", "0.05", "0.5", "1e9", "2.75e9", "0", "0.05", "2", "0.3", "1"];
        let v: Vec<&str> = nasty.iter().zip(sane).map(|(n, s)| n.unwrap_or(s)).collect();
        let text = format!(
            "[run]\ntail_s = {}\nsubsteps_per_contact = {}\n\n[building1]\nmass_kg = {}\nperiod_s = {}\ndamping_ratio = {}\n\n[building2]\nmass_kg = {}\nperiod_s = [{}, 0.5]\ndamping_ratio = {}\n\n[contact]\nlaw = \"{law}\"\nformula = \"{formula}\"\ne = {}\nk_n_per_m = {}\nbeta_n_per_m1_5 = {}\ngap_m = {{ from = {}, to = {}, n = 3 }}\n\n[[record]]\nsynthetic = {{ seed = 1, duration_s = {}, dt_s = 0.01, pga_g = {} }}\n\n[intensity]\nscale = {}\n",
            v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7], v[8], v[9], v[10], v[11], v[12], v[13], v[14], v[15]
        );
        let d = tempdir();
        match pounding::plan::config::parse(&text, Path::new("n.toml"), d.path(), d.path()) {
            Err(e) => prop_assert!(e.to_string().starts_with("n.toml"), "{e}"),
            Ok(plan) => {
                for i in 0..plan.len().min(50) {
                    let r = plan.run(i);
                    prop_assert!(r.t1 >= 1e-4 && r.gap >= 0.0 && r.scale > 0.0);
                }
                let _ = plan.warnings();
                let sh = pounding::plan::shard::shard_range(&pounding::plan::Plan::Pair(plan.clone()), pounding::plan::shard::Shard { index: 1, count: 3 });
                prop_assert!(sh.start <= sh.end && sh.end <= plan.len());
            }
        }
    }

    /// Random bytes as a record file never panic the reader, in any format.
    #[test]
    fn random_records_never_panic(bytes in prop::collection::vec(any::<u8>(), 0..400), header in 0u8..4) {
        use pounding::record::{read_record, Format, ReadOptions};
        let d = tempdir();
        let mut b = match header {
            0 => b"PEER NGA STRONG MOTION DATABASE RECORD\nX\nACCELERATION TIME SERIES IN UNITS OF G\nNPTS= 99999999999999, DT= .0100 SEC\n".to_vec(),
            1 => b"NPTS= 3, DT= 1e-300 SEC\n".to_vec(),
            _ => Vec::new(),
        };
        b.extend_from_slice(&bytes);
        let p = d.path().join("r.at2");
        std::fs::write(&p, &b).unwrap();
        for format in [Format::Auto, Format::At2, Format::Values, Format::TwoColumn] {
            let _ = read_record(&p, &ReadOptions { format, units: None, dt: Some(0.01), skip_lines: 0 });
        }
    }
}
