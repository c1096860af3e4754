//! What a command writes: nothing a user points at is destroyed (an output that is one of the
//! command's inputs is refused, by inode), streams are written in place, an output says what it
//! is and never replaces an earlier one, and a refusal leaves nothing behind.

use crate::scenes::{row, Scene, CHEAP_SWEEP, STOREYS2, STOREYS3};
use crate::support::cli::stderr as err;
use crate::support::cli::{
    fails_with, fragility, interrupt, pound_in, refused, s, sibling, stderr, sweep, warns, write,
    yielding_runs,
};
use crate::support::{assert_same_text, ok, pound, tempdir};
use std::path::Path;
use std::process::Command;

/// Class 1: an output that is one of the command's inputs is refused (by inode, so links and
/// other spellings are caught), and streams are written in place with nothing beside them.
#[test]
fn outputs_never_replace_inputs() {
    let sc = Scene::new();
    let cfg_text = std::fs::read_to_string(&sc.cfg).unwrap();
    let rec_text = std::fs::read_to_string(&sc.record).unwrap();
    // The config itself, a hard link to it, another spelling, a symlink, a record file.
    let hard = sc.path("hard.csv");
    std::fs::hard_link(&sc.cfg, &hard).unwrap();
    let soft = sc.path("soft.csv");
    std::os::unix::fs::symlink(&sc.cfg, &soft).unwrap();
    let dotted = sc.dir.path().join(".").join("sweep.toml");
    for out in [&sc.cfg, &hard, &soft, &dotted] {
        refused(&sweep(&sc.cfg, out, &[]), "the config", None);
    }
    refused(&sweep(&sc.cfg, &sc.record, &[]), "the record", None);
    // `pound sweep a.partial -o a`: the config is the output's partial file.
    let p = sc.path("p.csv.partial");
    std::fs::write(&p, &cfg_text).unwrap();
    refused(&sweep(&p, &sc.path("p.csv"), &[]), "partial file", None);
    assert_eq!(std::fs::read_to_string(&p).unwrap(), cfg_text);
    assert_eq!(std::fs::read_to_string(&sc.cfg).unwrap(), cfg_text);
    assert_eq!(std::fs::read_to_string(&sc.record).unwrap(), rec_text);

    // Studies reading a results file may not write over it, nor write two outputs to one file.
    let results = sc.path("r.csv");
    std::fs::write(&results, &sc.whole).unwrap();
    let r = s(&results);
    refused(
        &pound(&["plot", r, "--x", "gap_m", "--y", "peak_force_n", "-o", r]),
        "same file as the results",
        None,
    );
    refused(
        &fragility(&results, &["-o", r]),
        "same file as the results",
        None,
    );
    let f = sc.path("f.csv");
    refused(
        &fragility(&results, &["-o", s(&f), "--plot", s(&f)]),
        "also written as -o",
        Some(&f),
    );
    refused(
        &pound(&[
            "accuracy",
            s(&sc.cfg),
            "--backend",
            "cpu",
            "-o",
            s(&sc.record),
        ]),
        "the record",
        None,
    );
    assert_eq!(std::fs::read_to_string(&results).unwrap(), sc.whole);

    // Merge: the output may not be one of the shards.
    let shard = sc.path("s0.csv");
    ok(&sweep(&sc.cfg, &shard, &["--shard", "0/2"]));
    let before = std::fs::read(&shard).unwrap();
    refused(
        &pound(&["merge", s(&shard), "-o", s(&shard)]),
        "same file as the input",
        None,
    );
    assert_eq!(std::fs::read(&shard).unwrap(), before);

    // /dev/null: written in place, still a device, no sidecar beside it.
    let o = sweep(&sc.cfg, Path::new("/dev/null"), &[]);
    ok(&o);
    use std::os::unix::fs::FileTypeExt;
    assert!(std::fs::metadata("/dev/null")
        .unwrap()
        .file_type()
        .is_char_device());
    assert!(!Path::new("/dev/null.meta.toml").exists());
    assert!(!Path::new("/dev/null.partial").exists());
    // `-o -`: the CSV on standard output, whole.
    let o = sweep(&sc.cfg, Path::new("-"), &[]);
    assert_same_text("-o -", &ok(&o), &sc.whole);
    let o = pound(&["plot", r, "--x", "gap_m", "--y", "peak_force_n", "-o", "-"]);
    assert!(ok(&o).starts_with("<svg"), "an SVG on stdout");
    // A FIFO: written in place, read by another thread.
    let fifo = sc.path("rows.fifo");
    let c = std::ffi::CString::new(s(&fifo)).unwrap();
    // SAFETY: mkfifo on a path this test owns.
    assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
    let reader = {
        let fifo = fifo.clone();
        std::thread::spawn(move || std::fs::read_to_string(fifo).unwrap())
    };
    ok(&sweep(&sc.cfg, &fifo, &[]));
    assert_same_text("FIFO", &reader.join().unwrap(), &sc.whole);
    assert!(!sibling(&fifo, ".meta.toml").exists());
    // `--resume` needs a journal, which a stream cannot have.
    refused(
        &sweep(&sc.cfg, Path::new("/dev/null"), &["--resume"]),
        "--resume needs a file output",
        None,
    );
    // A directory is refused before any run.
    refused(&sweep(&sc.cfg, sc.dir.path(), &[]), "is a directory", None);

    // An unfinished CSV sweep's rows are not taken over by another format or a study's output.
    let u = sc.path("u"); // no extension: a name every format and a plot may take
    sc.interrupted(&u, 0.5);
    let held = std::fs::read(sibling(&u, ".partial")).unwrap();
    for extra in [&["--format", "parquet"][..], &["--aggregate", "gap_m"][..]] {
        refused(&sweep(&sc.cfg, &u, extra), "unfinished CSV sweep", None);
    }
    refused(
        &pound(&[
            "plot",
            r,
            "--x",
            "gap_m",
            "--y",
            "peak_force_n",
            "-o",
            s(&u),
        ]),
        "unfinished sweep",
        None,
    );
    assert_eq!(std::fs::read(sibling(&u, ".partial")).unwrap(), held);
    ok(&sweep(&sc.cfg, &u, &["--resume"]));
    assert_same_text(
        "resumed after the refusals",
        &std::fs::read_to_string(&u).unwrap(),
        &sc.whole,
    );

    // A config read from a pipe is read once (process substitution).
    let piped = sc.path("piped.toml");
    let synthetic_only = CHEAP_SWEEP.replace(
        "[[record]]\npath = \"rec.txt\"\nformat = \"values\"\ndt_s = 0.01\nunits = \"g\"\n",
        "",
    );
    assert_ne!(synthetic_only, CHEAP_SWEEP);
    std::fs::write(&piped, &synthetic_only).unwrap();
    let o = Command::new("bash")
        .args([
            "-c",
            &format!(
                "'{}' sweep <(cat '{}') -o - --backend cpu",
                env!("CARGO_BIN_EXE_pound"),
                s(&piped)
            ),
        ])
        .output()
        .unwrap();
    assert_eq!(ok(&o).lines().count(), 49, "{}", stderr(&o));
}

/// Class 1, an input destroyed: a damage-state file, as the results and the config are, is
/// refused as an output, also through a symbolic link (`fragility -o states.toml` wrote its CSV
/// over the file, rc 0), and an output whose extension names another format (`-o x.toml` for
/// CSV) is refused as `.svg` for CSV is; the file is left as it was.
#[test]
fn an_input_is_never_an_output() {
    let dir = tempdir();
    let d = dir.path();
    let runs = yielding_runs(d);
    let states = d.join("states.toml");
    let text = "name = \"t\"\nsource = \"drawn\"\n[[state]]\nname = \"light\"\nlimit = 0.004\n[[state]]\nname = \"heavy\"\nlimit = 0.02\n";
    std::fs::write(&states, text).unwrap();
    #[cfg(unix)]
    std::os::unix::fs::symlink(&states, d.join("link.csv")).unwrap();
    let s = |p: &Path| p.to_str().unwrap().to_string();
    let fragility = |limits: &[&str], output: &str| {
        let mut args = vec![
            "fragility".to_string(),
            s(&runs),
            "--edp".into(),
            "b1_peak_drift_ratio".into(),
        ];
        args.extend(limits.iter().map(|x| x.to_string()));
        args.extend(["-o".to_string(), s(&d.join(output))]);
        let refs: Vec<&str> = args.iter().map(String::as_str).collect();
        pound(&refs)
    };
    let mut cases = vec![
        (
            fragility(&["--damage-states", &s(&states)], "states.toml"),
            "damage-state file",
        ),
        (
            fragility(&["--threshold", "0.01"], "x.toml"),
            "a .toml name",
        ),
    ];
    #[cfg(unix)]
    cases.push((
        fragility(&["--damage-states", &s(&states)], "link.csv"),
        "damage-state file",
    ));
    for (o, needle) in cases {
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "rc 0: {err}");
        assert!(err.contains(needle), "expected `{needle}` in: {err}");
    }
    assert_eq!(std::fs::read_to_string(&states).unwrap(), text);
    assert!(!d.join("x.toml").exists());
    // The same file as a damage-state set is read, and a CSV next to it is written.
    ok(&fragility(&["--damage-states", &s(&states)], "states.csv"));
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
        fails_with(&o, "too large for the software adapter");
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
    ok(&sweep(&cfg, &whole, &[]));
    let whole = std::fs::read_to_string(&whole).unwrap();
    let header = format!("{}\n", whole.lines().next().unwrap());
    let journal = pounding::io::atomic::sibling(&x, ".progress.toml");
    let partial = pounding::io::atomic::sibling(&x, ".partial");
    let args = ["sweep", s(&cfg), "-o", s(&x), "--backend", "cpu"];
    for extra in [None, Some("--resume")] {
        interrupt(&cfg, whole.len(), &x, 0.6);
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
    interrupt(&cfg, whole.len(), &x, 0.6);
    let text = std::fs::read_to_string(&journal).unwrap();
    let done = text
        .lines()
        .find(|l| l.starts_with("done = "))
        .unwrap()
        .to_string();
    std::fs::write(&journal, text.replace(&done, "done = 0")).unwrap();
    fails_with(&pound(&args), "unfinished CSV sweep");
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
    fails_with(
        &pound(&["gap", s(&cfg), "-o", "-", "--curve", "-"]),
        "two outputs may not share one stream",
    );
    // The `.partial` of an input, existing or not.
    let results = d.path().join("r.csv");
    ok(&sweep(&cfg, &results, &[]));
    fails_with(
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
    fails_with(
        &sweep(&cfg, &d.path().join("p.csv"), &["--format", "parquet"]),
        "a .csv name for an output written as Parquet",
    );
    fails_with(
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
    fails_with(
        &pound(&["merge", "-o", s(&d.path().join("m.parquet")), s(&results)]),
        "a .parquet name for an output written as CSV",
    );
    // A .parquet name chooses Parquet.
    let pq = d.path().join("p.parquet");
    ok(&sweep(&cfg, &pq, &[]));
    assert_eq!(&std::fs::read(&pq).unwrap()[..4], b"PAR1");
    // ... which plot and fragility name as such.
    fails_with(
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

/// Classes 4 and 5 before any output: a figure that would be refused (a label that
/// contradicts the data, a PNG past its pixel bound) is refused before the command writes
/// anything, so no CSV is left behind (trace, gap, fragility, ida, hysteresis and record
/// spectrum wrote theirs first).
#[test]
fn a_refused_figure_leaves_nothing_behind() {
    let dir = tempdir();
    let runs = dir.path().join("runs.csv");
    ok(&pound(&[
        "sweep",
        "configs/inelastic-row.toml",
        "-o",
        runs.to_str().unwrap(),
    ]));
    let r = runs.to_str().unwrap();
    let record = crate::support::records_dir().join("elcentro1940_ns_I-ELC180_peer2000.AT2");
    let huge = ["--size", "4000x4000", "--dpi", "600"];
    let cases: Vec<(Vec<&str>, &[&str])> = vec![
        (
            vec!["trace", "configs/inelastic-row.toml", "--run", "1"],
            &["--y-label", "whatever"],
        ),
        (
            vec!["trace", "configs/inelastic-row.toml", "--run", "1"],
            &huge,
        ),
        (vec!["gap", "configs/gap-example.toml"], &huge),
        (
            vec![
                "fragility",
                r,
                "--im",
                "pga_g",
                "--edp",
                "b1_peak_drift_ratio",
                "--threshold",
                "0.005",
            ],
            &huge,
        ),
        (
            vec!["ida", r, "--im", "pga_g", "--edp", "b1_peak_drift_ratio"],
            &huge,
        ),
        (vec!["hysteresis", "hertz"], &huge),
        (vec!["record", "spectrum", record.to_str().unwrap()], &huge),
    ];
    for (i, (command, figure)) in cases.into_iter().enumerate() {
        let out = dir.path().join(format!("out-{i}.csv"));
        let plot = dir.path().join(format!("plot-{i}.png"));
        let mut args = command.clone();
        args.extend([
            "-o",
            out.to_str().unwrap(),
            "--plot",
            plot.to_str().unwrap(),
        ]);
        args.extend(figure);
        let o = pound(&args);
        assert!(!o.status.success(), "{args:?}: rc 0");
        assert!(!out.exists(), "{args:?} wrote {}", out.display());
        assert!(!plot.exists(), "{args:?} drew {}", plot.display());
    }
}
