//! Hostile but realistic inputs (issue 13): nothing the user points at is destroyed, nothing
//! incomplete or wrong is ever called complete. One test per class of the issue, then property
//! tests that feed random edits to configs, records, partial outputs, journals and shards.

use crate::support::{assert_same_text, tempdir};
use crate::support::{ok, pound};
use proptest::prelude::*;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

/// 96 cheap runs: a synthetic record and a record file (so `-o` can name an input record).
const SWEEP: &str = r#"
[run]
tail_s = 0.5

[building1]
mass_kg = 1.0e5
period_s = [0.3, 0.6]
damping_ratio = 0.05

[building2]
mass_kg = 1.0e5
period_s = [0.45, 1.0]
damping_ratio = 0.05

[contact]
law = ["nonlinear_viscoelastic", "kelvin_voigt"]
formula = "exact"
e = [0.5, 0.8]
k_n_per_m = 1e9
beta_n_per_m1_5 = 2.75e9
gap_m = [0.0, 0.01, 0.03]

[[record]]
synthetic = { seed = 1, duration_s = 3.0 }

[[record]]
path = "rec.txt"
format = "values"
dt_s = 0.01
units = "g"
"#;

struct Scene {
    dir: tempfile::TempDir,
    cfg: PathBuf,
    record: PathBuf,
    /// The uninterrupted sweep's CSV.
    whole: String,
}

impl Scene {
    fn new() -> Scene {
        let dir = tempdir();
        let record = dir.path().join("rec.txt");
        let v: Vec<String> = (0..400)
            .map(|i| format!("{}", 0.3 * (i as f64 * 0.07).sin()))
            .collect();
        std::fs::write(&record, v.join("\n")).unwrap();
        let cfg = dir.path().join("sweep.toml");
        std::fs::write(&cfg, SWEEP).unwrap();
        let out = dir.path().join("whole.csv");
        ok(&sweep(&cfg, &out, &[]));
        let whole = std::fs::read_to_string(&out).unwrap();
        Scene {
            dir,
            cfg,
            record,
            whole,
        }
    }

    fn path(&self, name: &str) -> PathBuf {
        self.dir.path().join(name)
    }

    /// See [`interrupt`].
    fn interrupted(&self, out: &Path, fraction: f64) {
        interrupt(&self.cfg, self.whole.len(), out, fraction);
    }
}

/// A sweep of `cfg` into `out` cut off by a file-size limit at `fraction` of the whole output
/// (`whole_len` bytes): it leaves `out.partial` and its journal, as a kill or a full disk does.
pub fn interrupt(cfg: &Path, whole_len: usize, out: &Path, fraction: f64) {
    let limit = (whole_len as f64 * fraction) as u64;
    let r = crate::support::pound_with_file_limit(
        &[
            "sweep",
            s(cfg),
            "-o",
            s(out),
            "--backend",
            "cpu",
            "--chunk",
            "2",
            "--threads",
            "1",
        ],
        limit,
    );
    assert!(!r.status.success(), "the sweep was not cut off");
    assert!(sibling(out, ".progress.toml").exists());
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn sibling(p: &Path, suffix: &str) -> PathBuf {
    pounding::io::atomic::sibling(p, suffix)
}

fn sweep(cfg: &Path, out: &Path, extra: &[&str]) -> Output {
    let mut args = vec!["sweep", s(cfg), "-o", s(out), "--backend", "cpu"];
    args.extend_from_slice(extra);
    pound(&args)
}

/// `pound fragility RESULTS --threshold 0 --edp impacts EXTRA...` ("pounds at all").
fn fragility(results: &Path, extra: &[&str]) -> Output {
    let mut args = vec![
        "fragility",
        s(results),
        "--threshold",
        "0",
        "--edp",
        "impacts",
    ];
    args.extend_from_slice(extra);
    pound(&args)
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Fails with `needle` in its message, and leaves no output and no sidecar under `out`.
fn refused(o: &Output, needle: &str, out: Option<&Path>) {
    let err = stderr(o);
    assert!(!o.status.success(), "rc 0 where an error was due: {err}");
    assert!(err.contains(needle), "expected `{needle}` in: {err}");
    assert!(!err.contains("panicked"), "{err}");
    if let Some(out) = out {
        assert!(!out.exists(), "{} exists", out.display());
        assert!(!sibling(out, ".meta.toml").exists());
    }
}

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
    let synthetic_only = SWEEP.replace(
        "[[record]]\npath = \"rec.txt\"\nformat = \"values\"\ndt_s = 0.01\nunits = \"g\"\n",
        "",
    );
    assert_ne!(synthetic_only, SWEEP);
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

/// Class 2: `--resume` checks what the partial holds against its journal (run numbers 0..k in
/// order, the byte count, the checksum); every edit is refused, none gives rc 0 with wrong rows.
#[test]
fn resume_verifies_what_the_journal_vouches_for() {
    let sc = Scene::new();
    let out = sc.path("o.csv");
    let journal = sibling(&out, ".progress.toml");
    let partial = sibling(&out, ".partial");
    sc.interrupted(&out, 0.5);
    let (j0, p0) = (
        std::fs::read_to_string(&journal).unwrap(),
        std::fs::read(&partial).unwrap(),
    );
    let field = |name: &str| -> u64 {
        let line = j0.lines().find(|l| l.starts_with(name)).unwrap();
        line.split('=').nth(1).unwrap().trim().parse().unwrap()
    };
    let (done, bytes) = (field("done"), field("bytes"));
    assert!(done > 4, "{j0}");
    let set = |name: &str, v: u64| {
        j0.lines()
            .map(|l| {
                if l.starts_with(&format!("{name} =")) {
                    format!("{name} = {v}")
                } else {
                    l.to_string()
                }
            })
            .collect::<Vec<_>>()
            .join("\n")
    };
    let text = String::from_utf8(p0.clone()).unwrap();
    let second_row = text.match_indices('\n').nth(1).unwrap().0 + 1;
    let mut edited_value = p0.clone();
    let comma = second_row + text[second_row..].find(",0.").unwrap() + 3;
    edited_value[comma] = if edited_value[comma] == b'9' {
        b'8'
    } else {
        b'9'
    };
    let mut dropped_row = text.clone();
    let row_end = second_row + text[second_row..].find('\n').unwrap() + 1;
    // The same length, so the byte count holds and the run sequence is what catches it.
    let row1 = text[second_row..row_end].to_string();
    dropped_row.replace_range(second_row..row_end, "");
    dropped_row.push_str(&row1);
    let cases: Vec<(&str, String, Vec<u8>, &str)> = vec![
        (
            "done = 999999",
            set("done", 999_999),
            p0.clone(),
            "claims 999999 runs",
        ),
        ("done = 0", set("done", 0), p0.clone(), "vouches for 0 runs"),
        (
            "a smaller byte count",
            set("bytes", bytes - 7),
            p0.clone(),
            "cut off",
        ),
        (
            "a larger byte count",
            set("bytes", bytes + 5000),
            p0.clone(),
            "fewer than",
        ),
        (
            "another checksum",
            j0.replace("sha256 = \"", "sha256 = \"00"),
            p0.clone(),
            "checksum",
        ),
        ("an edited value", j0.clone(), edited_value, "checksum"),
        (
            "a dropped row",
            j0.clone(),
            dropped_row.into_bytes(),
            "expected",
        ),
        (
            "a truncated file",
            j0.clone(),
            p0[..p0.len() / 2].to_vec(),
            "fewer than",
        ),
        (
            "a journal that is not TOML",
            "done = ".into(),
            p0.clone(),
            "cannot resume",
        ),
    ];
    for (what, journal_text, partial_bytes, needle) in cases {
        std::fs::write(&journal, &journal_text).unwrap();
        std::fs::write(&partial, &partial_bytes).unwrap();
        let r = sweep(&sc.cfg, &out, &["--resume"]);
        let err = stderr(&r);
        assert!(!r.status.success(), "{what}: rc 0: {err}");
        assert!(err.contains(needle), "{what}: expected `{needle}` in {err}");
        assert!(!out.exists(), "{what}");
        // Nothing the user may want was touched.
        assert_eq!(std::fs::read(&partial).unwrap(), partial_bytes, "{what}");
    }
    // The untouched pair resumes to the uninterrupted output, with `done` runs reused.
    std::fs::write(&journal, &j0).unwrap();
    std::fs::write(&partial, &p0).unwrap();
    let r = sweep(&sc.cfg, &out, &["--resume"]);
    assert!(stderr(&r).contains(&format!("{done} runs already on disk")));
    ok(&r);
    assert_same_text(
        "resumed",
        &std::fs::read_to_string(&out).unwrap(),
        &sc.whole,
    );
    assert!(!journal.exists() && !partial.exists());
    // The sidecar's content hash is the file's.
    let meta: pounding::io::provenance::Meta =
        pounding::io::provenance::read_toml(&sibling(&out, ".meta.toml")).unwrap();
    let c = meta.content.unwrap();
    assert_eq!(c.rows, 96);
    assert_eq!(c.sha256, pounding::io::journal::file_sha256(&out).unwrap());
}

/// Class 3: merge verifies each shard's content against its sidecar and names the shard and
/// runs that differ; studies warn about results without a sidecar or edited since.
#[test]
fn merge_checks_content_and_studies_warn() {
    let sc = Scene::new();
    let shards: Vec<PathBuf> = (0..3).map(|i| sc.path(&format!("s{i}.csv"))).collect();
    for (i, p) in shards.iter().enumerate() {
        ok(&sweep(&sc.cfg, p, &["--shard", &format!("{i}/3")]));
    }
    let merged = sc.path("m.csv");
    let merge = |out: &Path| {
        let mut a = vec!["merge", "-o", s(out)];
        a.extend(shards.iter().map(|p| s(p)));
        pound(&a)
    };
    ok(&merge(&merged));
    assert_same_text(
        "merged",
        &std::fs::read_to_string(&merged).unwrap(),
        &sc.whole,
    );
    let original = std::fs::read_to_string(&shards[1]).unwrap();
    let first_run: u64 = original
        .lines()
        .nth(1)
        .unwrap()
        .split(',')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    let edits = [
        ("a value", original.replacen(",0.0", ",0.1", 1)),
        ("a status", original.replacen(",ok,", ",garbage,", 1)),
    ];
    for (what, text) in edits {
        assert_ne!(text, original, "{what}");
        std::fs::write(&shards[1], &text).unwrap();
        let out = sc.path("bad.csv");
        let r = merge(&out);
        refused(&r, "differ from what the sweep wrote", Some(&out));
        let err = stderr(&r);
        assert!(
            err.contains("s1.csv") && err.contains(&format!("runs {first_run}..")),
            "{what}: {err}"
        );
        assert!(!sibling(&out, ".partial").exists(), "{what}");
        // The studies warn, and still run.
        let w = pound(&[
            "plot",
            s(&shards[1]),
            "--x",
            "gap_m",
            "--y",
            "peak_force_n",
            "-o",
            s(&sc.path("p.svg")),
        ]);
        assert!(stderr(&w).contains("it was edited since"), "{}", stderr(&w));
    }
    // A dropped row is a run missing, named by line.
    let mut lines: Vec<&str> = original.lines().collect();
    lines.remove(3);
    std::fs::write(&shards[1], lines.join("\n") + "\n").unwrap();
    refused(
        &merge(&sc.path("bad.csv")),
        "where run",
        Some(&sc.path("bad.csv")),
    );
    // No sidecar: studies warn.
    let bare = sc.path("bare.csv");
    std::fs::write(&bare, &sc.whole).unwrap();
    let w = fragility(&bare, &["-o", s(&sc.path("f.csv"))]);
    assert!(stderr(&w).contains("has no sidecar"), "{}", stderr(&w));
    ok(&w);
    // A complete output with its sidecar: no warning.
    let w = fragility(&merged, &["-o", s(&sc.path("f.csv"))]);
    assert!(!stderr(&w).contains("warning"), "{}", stderr(&w));
}

/// Class 4: one sweep per output. A second sweep, with or without `--resume`, is refused while
/// the first runs, and leaves nothing that blocks later runs; a journal whose sweep died is
/// recoverable with `--resume`.
#[test]
fn one_sweep_writes_an_output_at_a_time() {
    let sc = Scene::new();
    // A slower copy of the scene (longer records), so the first sweep is surely running.
    let slow = sc.path("slow.toml");
    std::fs::write(
        &slow,
        SWEEP
            .replace("duration_s = 3.0", "duration_s = 40.0")
            .replace(
                "gap_m = [0.0, 0.01, 0.03]",
                "gap_m = { from = 0.0, to = 0.05, n = 30 }",
            ),
    )
    .unwrap();
    let out = sc.path("o.csv");
    let first = Command::new(env!("CARGO_BIN_EXE_pound"))
        .args([
            "sweep",
            s(&slow),
            "-o",
            s(&out),
            "--backend",
            "cpu",
            "--threads",
            "1",
            "--chunk",
            "1",
        ])
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let journal = sibling(&out, ".progress.toml");
    let t = Instant::now();
    while !journal.exists() && t.elapsed() < Duration::from_secs(60) {
        std::thread::sleep(Duration::from_millis(5));
    }
    for extra in [&["--resume"][..], &[][..]] {
        let mut args = vec!["sweep", s(&slow), "-o", s(&out), "--backend", "cpu"];
        args.extend_from_slice(extra);
        let r = pound(&args);
        let err = stderr(&r);
        assert!(!r.status.success());
        assert!(err.contains("another running `pound sweep`"), "{err}");
    }
    let r = first.wait_with_output().unwrap();
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    assert!(!journal.exists(), "the winner removes its journal");
    let whole = std::fs::read_to_string(&out).unwrap();
    // Plain reruns are not blocked by anything the refused sweeps left.
    ok(&sweep(&slow, &out, &[]));
    assert_same_text("rerun", &std::fs::read_to_string(&out).unwrap(), &whole);
    // A sweep that died holds no lock: its journal resumes.
    let out2 = sc.path("o2.csv");
    sc.interrupted(&out2, 0.4);
    refused(&sweep(&sc.cfg, &out2, &[]), "rerun with --resume", None);
    ok(&sweep(&sc.cfg, &out2, &["--resume"]));
    assert_same_text(
        "after a dead sweep",
        &std::fs::read_to_string(&out2).unwrap(),
        &sc.whole,
    );
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
        let text = SWEEP.replace(from, to);
        assert_ne!(text, SWEEP, "{name}");
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
            let t = SWEEP
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
        SWEEP.replace("path = \"rec.txt\"", "path = \"/dev/zero\""),
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

/// Class 6: cutting a shard costs O(blocks x records) per probe, not O(runs): a 1e8-run plan
/// is cut at once, and the cuts equal the linear scan's on a small plan.
#[test]
fn shard_cuts_are_cheap_and_exact() {
    use pounding::plan::shard::{shard_range, Shard};
    let d = tempdir();
    let text = SWEEP
        .replace(
            "period_s = [0.3, 0.6]",
            "period_s = { from = 0.1, to = 2, n = 10000 }",
        )
        .replace(
            "gap_m = [0.0, 0.01, 0.03]",
            "gap_m = { from = 0, to = 0.1, n = 1250 }",
        );
    std::fs::write(d.path().join("rec.txt"), "0.1\n0.2\n0.1\n0.0\n-0.1").unwrap();
    let p =
        pounding::plan::config::parse(&text, Path::new("big.toml"), d.path(), d.path()).unwrap();
    assert_eq!(p.len(), 200_000_000);
    let t = Instant::now();
    let p = pounding::plan::Plan::Pair(p);
    let last = shard_range(
        &p,
        Shard {
            index: 999_999,
            count: 1_000_000,
        },
    );
    assert!(last.end == p.len() && last.start < last.end);
    // Generous: a linear scan of 4e8 runs takes minutes.
    assert!(t.elapsed() < Duration::from_secs(5), "{:?}", t.elapsed());
    // Against the linear scan's definition on the small plan: cut k is the first run whose
    // preceding cost reaches k / N of the total.
    let small =
        pounding::plan::config::parse(SWEEP, Path::new("s.toml"), d.path(), d.path()).unwrap();
    let costs: Vec<u64> = small
        .contact
        .spec
        .records
        .iter()
        .map(|r| r.forcing(1.0, small.contact.spec.tail).intervals().max(1) as u64)
        .collect();
    let mut acc = vec![0u128];
    for i in 0..small.len() {
        acc.push(acc[i as usize] + costs[small.run(i).record] as u128);
        assert_eq!(small.cost_before(i + 1, &costs), acc[i as usize + 1]);
    }
    let total = *acc.last().unwrap();
    for n in [1u64, 2, 3, 7, 96, 200] {
        let cut = |k: u64| -> u64 {
            (0..=small.len())
                .find(|&i| acc[i as usize] * n as u128 >= total * k as u128)
                .unwrap()
        };
        let mut next = 0;
        let whole = pounding::plan::Plan::Pair(small.clone());
        for k in 0..n {
            let r = shard_range(&whole, Shard { index: k, count: n });
            assert_eq!(
                r,
                cut(k)..if k + 1 == n { small.len() } else { cut(k + 1) },
                "{k}/{n}"
            );
            assert_eq!(r.start, next);
            next = r.end;
        }
        assert_eq!(next, small.len());
    }
}

/// Class 7: a very stiff building is solved (not `non_finite`), failed runs are kept out of
/// plots and summaries, and absurd inputs are warned about.
#[test]
fn stiff_structures_failed_runs_and_absurd_inputs() {
    let sc = Scene::new();
    let stiff = sc.path("stiff.toml");
    std::fs::write(
        &stiff,
        SWEEP
            .replace("period_s = [0.3, 0.6]", "period_s = 1e-4")
            .replace("period_s = [0.45, 1.0]", "period_s = 0.5")
            .replace(
                "law = [\"nonlinear_viscoelastic\", \"kelvin_voigt\"]",
                "law = \"nonlinear_viscoelastic\"",
            )
            .replace("e = [0.5, 0.8]", "e = 0.5")
            .replace("gap_m = [0.0, 0.01, 0.03]", "gap_m = 0.0")
            .replace("duration_s = 3.0", "duration_s = 1.0"),
    )
    .unwrap();
    let (fast, refr) = (sc.path("fast.csv"), sc.path("ref.csv"));
    ok(&sweep(&stiff, &fast, &[]));
    ok(&sweep(&stiff, &refr, &["--scheme", "reference"]));
    let read = |p: &Path| -> Vec<(String, f64, f64)> {
        let mut r = csv::Reader::from_path(p).unwrap();
        let h = r.headers().unwrap().clone();
        let c = |n: &str| h.iter().position(|x| x == n).unwrap();
        r.records()
            .map(|x| {
                let x = x.unwrap();
                (
                    x[c("status")].to_string(),
                    x[c("peak_force_n")].parse().unwrap(),
                    x[c("peak_u2_m")].parse().unwrap(),
                )
            })
            .collect()
    };
    let (a, b) = (read(&fast), read(&refr));
    assert_eq!(a.len(), 2);
    for (x, y) in a.iter().zip(&b) {
        assert_eq!(x.0, "ok");
        assert!(x.1 > 0.0, "it pounds");
        assert!(crate::support::rel(x.1, y.1) < 1e-4, "{x:?} vs {y:?}");
        assert!(crate::support::rel(x.2, y.2) < 1e-4, "{x:?} vs {y:?}");
    }
    // Plots leave failed runs out (their values are whatever a diverged run held).
    let mut text = sc.whole.clone();
    let row = text.lines().nth(1).unwrap().to_string();
    let bad_row = row.replacen(",ok,", ",non_finite,", 1);
    let cells: Vec<&str> = bad_row.split(',').collect();
    let force = pounding::plan::columns::header()
        .iter()
        .position(|c| *c == "peak_force_n")
        .unwrap();
    let mut cells: Vec<String> = cells.iter().map(|c| c.to_string()).collect();
    cells[force] = "1e205".into();
    text = text.replacen(&row, &cells.join(","), 1);
    let t = sc.path("t.csv");
    std::fs::write(&t, text).unwrap();
    let table = pounding::io::table::Table::read(&t).unwrap();
    let spec = pounding::studies::sensitivity::PlotSpec {
        x: "gap_m".into(),
        y: "peak_force_n".into(),
        by: None,
        filters: vec![],
        aggregate: pounding::studies::sensitivity::Aggregate::Max,
        log_x: false,
        log_y: false,
    };
    let (panel, left_out) = pounding::studies::sensitivity::panel(&table, &spec).unwrap();
    assert_eq!(left_out.failed, 1);
    let top = panel.series[0]
        .points
        .iter()
        .map(|p| p.1)
        .fold(0.0, f64::max);
    assert!(top < 1e10, "{top}");
    // A group with no ok run has empty statistics, not zeros.
    let plan = pounding::plan::config::parse(SWEEP, &sc.cfg, sc.dir.path(), sc.dir.path()).unwrap();
    let mut agg = pounding::engine::aggregate::Aggregator::new(&["gap_m".into()], &[]).unwrap();
    let spec0 = plan.run(0);
    let g = agg.group_of(&plan, &spec0);
    agg.add(
        g,
        &pounding::physics::model::RunOutput {
            status: pounding::physics::model::Status::NonFinite,
            peak_force: 1e205,
            ..Default::default()
        },
    );
    let csv = pounding::io::summary::csv(&agg);
    let row: Vec<&str> = csv.lines().nth(1).unwrap().split(',').collect();
    assert_eq!(&row[..3], &["0", "1", "1"], "{csv}");
    assert!(row[3..].iter().all(|c| c.is_empty()), "{csv}");
    // A record of 1e6 g: a warning on the PGA and on drifts above the buildings' height.
    let g = sc.path("g.toml");
    std::fs::write(
        &g,
        SWEEP.replace("duration_s = 3.0", "duration_s = 3.0, pga_g = 1e6"),
    )
    .unwrap();
    let r = sweep(&g, &sc.path("g.csv"), &[]);
    let err = stderr(&r);
    ok(&r);
    assert!(
        err.contains("warning") && err.contains("PGA of 1000000.000 g"),
        "{err}"
    );
    assert!(
        err.contains("exceeds its height (estimated from its period"),
        "{err}"
    );
    assert!(!stderr(&sweep(&sc.cfg, &sc.path("q.csv"), &[])).contains("warning"));
}

/// Class 8: no window-system noise, `auto` passes software adapters by and says so, ranges
/// that would drop or mangle values are refused.
#[test]
fn quiet_starts_and_honest_defaults() {
    let sc = Scene::new();
    let o = sc.path("g.csv");
    let r = Command::new(env!("CARGO_BIN_EXE_pound"))
        .args(["sweep", s(&sc.cfg), "-o", s(&o), "--backend", "gpu"])
        .env_remove("XDG_RUNTIME_DIR")
        .env_remove("WAYLAND_DISPLAY")
        .output()
        .unwrap();
    let err = stderr(&r);
    ok(&r);
    assert!(!err.contains("XDG_RUNTIME_DIR"), "{err}");
    // On CI's only adapter (lavapipe, a software one) auto runs on the CPU and says why.
    let info = pounding::engine::gpu::context::adapters();
    if info
        .iter()
        .all(|a| a.info.device_type == wgpu::DeviceType::Cpu)
    {
        let r = pound(&["sweep", s(&sc.cfg), "-o", s(&o)]);
        let err = stderr(&r);
        ok(&r);
        assert!(
            err.contains("is a software one") && err.contains("CPU, "),
            "{err}"
        );
    }
    let bad = |from: &str, to: &str, needle: &str| {
        let p = sc.path("b.toml");
        std::fs::write(&p, SWEEP.replace(from, to)).unwrap();
        refused(&sweep(&p, &o, &[]), needle, None);
    };
    bad(
        "gap_m = [0.0, 0.01, 0.03]",
        "gap_m = { from = 0.0, to = 0.1, n = 1 }",
        "to = 0.1 would be ignored",
    );
    bad(
        "gap_m = [0.0, 0.01, 0.03]",
        "gap_m = { from = 0.0, to = 0.1, step = 1e-300 }",
        "step = 1e-300 gives 1.000e299 points",
    );
}

/// A valid config to mutate: every key, a record file, a sample.
fn mutable_config() -> String {
    SWEEP.replace(
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

proptest! {
    #![proptest_config(ProptestConfig { cases: 12, ..ProptestConfig::default() })]

    /// Random byte edits of an interrupted sweep's partial output and journal: `--resume`
    /// either refuses or gives exactly the uninterrupted output. Never rc 0 with other rows.
    #[test]
    fn edited_partials_never_resume_into_wrong_output(
        edits in prop::collection::vec((any::<prop::sample::Index>(), any::<u8>(), any::<bool>()), 1..4),
        fraction in 0.2f64..0.8,
    ) {
        let sc = scene();
        let d = tempdir();
        let out = d.path().join("o.csv");
        let cfg = d.path().join("sweep.toml");
        std::fs::copy(&sc.cfg, &cfg).unwrap();
        std::fs::copy(&sc.record, d.path().join("rec.txt")).unwrap();
        interrupt(&cfg, sc.whole.len(), &out, fraction);
        for (at, byte, journal) in edits {
            let p = if journal { sibling(&out, ".progress.toml") } else { sibling(&out, ".partial") };
            let mut b = std::fs::read(&p).unwrap();
            if b.is_empty() { continue; }
            let i = at.index(b.len());
            b[i] = byte;
            std::fs::write(&p, b).unwrap();
        }
        let r = sweep(&cfg, &out, &["--resume"]);
        prop_assert!(!stderr(&r).contains("panicked"));
        if r.status.success() {
            prop_assert_eq!(std::fs::read_to_string(&out).unwrap(), sc.whole.clone());
        } else {
            prop_assert!(!out.exists());
        }
    }

    /// Random byte edits of a shard: merge refuses, or gives exactly the unsharded output.
    #[test]
    fn edited_shards_never_merge_into_wrong_output(
        edits in prop::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 1..4),
        which in 0usize..2,
    ) {
        let sc = scene();
        let d = tempdir();
        let shards: Vec<PathBuf> = (0..2).map(|i| d.path().join(format!("s{i}.csv"))).collect();
        for (i, p) in shards.iter().enumerate() {
            std::fs::copy(sc.dir.path().join(format!("shard{i}.csv")), p).unwrap();
            std::fs::copy(sc.dir.path().join(format!("shard{i}.csv.meta.toml")), sibling(p, ".meta.toml")).unwrap();
        }
        let mut b = std::fs::read(&shards[which]).unwrap();
        for (at, byte) in edits {
            let i = at.index(b.len());
            b[i] = byte;
        }
        std::fs::write(&shards[which], b).unwrap();
        let out = d.path().join("m.csv");
        let r = pound(&["merge", "-o", s(&out), s(&shards[0]), s(&shards[1])]);
        prop_assert!(!stderr(&r).contains("panicked"));
        if r.status.success() {
            prop_assert_eq!(std::fs::read_to_string(&out).unwrap(), sc.whole.clone());
        } else {
            prop_assert!(!out.exists());
        }
    }
}

/// One scene and its two shards for the property tests (built once).
fn scene() -> &'static Scene {
    static SCENE: std::sync::OnceLock<Scene> = std::sync::OnceLock::new();
    SCENE.get_or_init(|| {
        let sc = Scene::new();
        for i in 0..2 {
            ok(&sweep(
                &sc.cfg,
                &sc.path(&format!("shard{i}.csv")),
                &["--shard", &format!("{i}/2")],
            ));
        }
        sc
    })
}

mod round2;
mod round3;
