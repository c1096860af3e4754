//! Issue 65, items 1, 8 and 10: nothing a user points at is destroyed by a sweep the user did
//! not ask to replace it (`--resume` onto another sweep's finished output, an output named like
//! an unfinished sweep's rows); the journal is committed by time, not by chunk, and a killed
//! sweep still resumes to the uninterrupted output; a GPU sweep ends with its output and its
//! summary line, or with an error and a resumable `.partial`.

use crate::support::cli::{s, sibling, stderr as err, sweep};
use crate::support::{ctx, ok, pound, pound_with_file_limit, pound_with_file_limit_env, tempdir};
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

/// 24 cheap runs.
const A: &str = r#"
[run]
tail_s = 0.5
[building1]
mass_kg = 1.0e5
period_s = [0.3, 0.6]
damping_ratio = 0.05
[building2]
mass_kg = 1.0e5
period_s = [0.45, 0.9]
damping_ratio = 0.05
[contact]
law = "linear"
k_n_per_m = 1e9
gap_m = [0.0, 0.005, 0.01, 0.02, 0.03, 0.04]
[[record]]
synthetic = { seed = 1, duration_s = 3.0 }
"#;

/// Refused with each of `needles` in the message, no panic.
fn refused(o: &Output, needles: &[&str]) {
    let e = err(o);
    assert!(!o.status.success(), "rc 0 where a refusal was due: {e}");
    assert!(!e.contains("panicked"), "{e}");
    for n in needles {
        assert!(e.contains(n), "expected `{n}` in: {e}");
    }
}

/// The bytes of `files` (None: absent).
fn snapshot(files: &[&Path]) -> Vec<Option<Vec<u8>>> {
    files.iter().map(|f| std::fs::read(f).ok()).collect()
}

/// Item 1: `--resume` where no journal is never replaces a file that holds something: another
/// config's finished output (the keys that differ named), another shard's, an edited output, a
/// file without a sidecar. The file, its sidecar and its absent `.partial` and journal are left
/// exactly as they were. Before the fix the first printed "nothing to resume ...: starting" and
/// overwrote it.
#[test]
fn resume_never_replaces_a_finished_output_it_cannot_continue() {
    let d = tempdir();
    let (a, b) = (d.path().join("a.toml"), d.path().join("b.toml"));
    std::fs::write(&a, A).unwrap();
    std::fs::write(&b, A.replace("0.04]", "0.05]")).unwrap();
    let done = d.path().join("done.csv");
    ok(&sweep(&a, &done, &[]));
    let files = [
        done.clone(),
        sibling(&done, ".meta.toml"),
        sibling(&done, ".partial"),
        sibling(&done, ".progress.toml"),
    ];
    let refs: Vec<&Path> = files.iter().map(PathBuf::as_path).collect();
    let before = snapshot(&refs);
    let r = sweep(&b, &done, &["--resume"]);
    refused(
        &r,
        &[
            s(&done),
            "finished output of another sweep",
            "[contact] gap_m",
            "refusing to overwrite it",
        ],
    );
    assert_eq!(snapshot(&refs), before, "the finished output was touched");
    // Another shard of the same config.
    refused(
        &sweep(&a, &done, &["--resume", "--shard", "0/2"]),
        &["another --shard"],
    );
    assert_eq!(snapshot(&refs), before);
    // The same sweep: complete, nothing written.
    let r = sweep(&a, &done, &["--resume"]);
    ok(&r);
    assert!(err(&r).contains("is already complete"), "{}", err(&r));
    assert_eq!(snapshot(&refs), before);
    // Edited since its sweep wrote it.
    let mut edited = before[0].clone().unwrap();
    edited.extend_from_slice(b"24,x\n");
    std::fs::write(&done, &edited).unwrap();
    refused(
        &sweep(&a, &done, &["--resume"]),
        &["is not what its sweep wrote"],
    );
    assert_eq!(std::fs::read(&done).unwrap(), edited);
    // A file pound did not write.
    let plain = d.path().join("notes.csv");
    std::fs::write(&plain, "my,own\n1,2\n").unwrap();
    refused(&sweep(&a, &plain, &["--resume"]), &["has no sidecar"]);
    assert_eq!(std::fs::read(&plain).unwrap(), b"my,own\n1,2\n");
    assert!(!sibling(&plain, ".partial").exists() && !sibling(&plain, ".progress.toml").exists());
    // Nothing to protect: an absent or empty file starts the sweep.
    let empty = d.path().join("empty.csv");
    std::fs::write(&empty, "").unwrap();
    ok(&sweep(&a, &empty, &["--resume"]));
    ok(&sweep(&a, &d.path().join("new.csv"), &["--resume"]));
    // A plain -o replaces: that is what it asks for.
    ok(&sweep(&b, &done, &[]));
    assert_ne!(std::fs::read(&done).unwrap(), before[0].clone().unwrap());
}

/// Item 1's class: no command writes over the bookkeeping of another output: the `.partial`
/// rows of an unfinished sweep, its journal, or an output's sidecar. Each is refused, naming
/// the output it belongs to, and the unfinished sweep then resumes to the whole output.
#[test]
fn no_output_replaces_an_unfinished_sweeps_rows_or_a_sidecar() {
    let d = tempdir();
    let (a, b) = (d.path().join("a.toml"), d.path().join("b.toml"));
    std::fs::write(&a, A).unwrap();
    std::fs::write(&b, A.replace("0.04]", "0.05]")).unwrap();
    let whole = d.path().join("whole.csv");
    ok(&sweep(&a, &whole, &[]));
    let whole_text = std::fs::read(&whole).unwrap();
    let cut = d.path().join("cut.csv");
    crate::support::cli::interrupt(&a, whole_text.len(), &cut, 0.5);
    let (partial, journal) = (sibling(&cut, ".partial"), sibling(&cut, ".progress.toml"));
    let refs = [partial.as_path(), journal.as_path()];
    let before = snapshot(&refs);
    refused(
        &sweep(&b, &partial, &[]),
        &["is the .partial of", "unfinished sweep keeps its rows"],
    );
    refused(
        &pound(&[
            "fragility",
            s(&whole),
            "--threshold",
            "0",
            "--edp",
            "impacts",
            "-o",
            s(&partial),
        ]),
        &["unfinished sweep keeps its rows"],
    );
    refused(
        &pound(&["merge", s(&whole), "-o", s(&partial)]),
        &["unfinished sweep keeps its rows"],
    );
    // `merge -o OUT` where OUT's sweep is unfinished: refused as every writer refuses, its
    // `.partial` kept (it was replaced without a word, the journal left vouching for nothing).
    refused(
        &pound(&["merge", s(&whole), "-o", s(&cut)]),
        &["holds the rows of an unfinished sweep", "--resume"],
    );
    refused(
        &pound(&["bench", "-o", s(&journal)]),
        &["is the journal of an unfinished sweep"],
    );
    let sidecar = sibling(&whole, ".meta.toml");
    let sidecar_text = std::fs::read(&sidecar).unwrap();
    refused(
        &pound(&["bench", "-o", s(&sidecar)]),
        &["is the sidecar of"],
    );
    assert_eq!(snapshot(&refs), before, "the unfinished sweep was touched");
    assert_eq!(std::fs::read(&sidecar).unwrap(), sidecar_text);
    ok(&sweep(&a, &cut, &["--resume"]));
    assert_eq!(std::fs::read(&cut).unwrap(), whole_text);
}

/// 360 runs of a 1,000 s record, slow enough on one thread (about 2 s) to be killed
/// mid-sweep: with a 10 s record the sweep took 60 ms, and a loaded machine that left the
/// watching thread asleep that long saw it finish before the kill.
fn long_sweep(dir: &Path) -> PathBuf {
    let cfg = dir.join("long.toml");
    std::fs::write(
        &cfg,
        A.replace("duration_s = 3.0", "duration_s = 1000.0")
            .replace(
                "gap_m = [0.0, 0.005, 0.01, 0.02, 0.03, 0.04]",
                "gap_m = { from = 0.0, to = 0.05, n = 30 }",
            )
            .replace(
                "period_s = [0.3, 0.6]",
                "period_s = [0.3, 0.4, 0.5, 0.6, 0.7, 0.8]",
            ),
    )
    .unwrap();
    cfg
}

fn rows_in(path: &Path) -> usize {
    std::fs::read(path)
        .map(|b| b.iter().filter(|&&c| c == b'\n').count().saturating_sub(1))
        .unwrap_or(0)
}

fn journal_done(journal: &Path) -> Option<u64> {
    let text = std::fs::read_to_string(journal).ok()?;
    let line = text.lines().find(|l| l.starts_with("done = "))?;
    line["done = ".len()..].parse().ok()
}

/// Item 8: the journal is committed after the first chunk and then by time (here an hour), not
/// after every chunk: a sweep killed (SIGKILL) with many chunks written has a journal that
/// vouches for the first chunk only, and `--resume` truncates the rest and ends with the
/// uninterrupted output, byte for byte. Before the fix the journal counted every chunk.
#[test]
fn journal_commits_by_time_and_a_killed_sweep_resumes_exactly() {
    let d = tempdir();
    let cfg = long_sweep(d.path());
    let whole = d.path().join("whole.csv");
    ok(&sweep(&cfg, &whole, &[]));
    let out = d.path().join("killed.csv");
    let (partial, journal) = (sibling(&out, ".partial"), sibling(&out, ".progress.toml"));
    let mut child = Command::new(env!("CARGO_BIN_EXE_pound"))
        .args([
            "sweep",
            s(&cfg),
            "-o",
            s(&out),
            "--backend",
            "cpu",
            "--threads",
            "1",
            "--chunk",
            "1",
        ])
        .env("POUND_COMMIT_S", "3600")
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while rows_in(&partial) < 6 && start.elapsed() < Duration::from_secs(120) {
        assert!(
            child.try_wait().unwrap().is_none(),
            "finished before the kill"
        );
        std::thread::sleep(Duration::from_millis(2));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    assert!(!out.exists(), "finished before the kill");
    assert!(rows_in(&partial) >= 6);
    assert_eq!(
        journal_done(&journal),
        Some(1),
        "the journal vouches for the first chunk only"
    );
    let r = sweep(&cfg, &out, &["--resume"]);
    ok(&r);
    assert!(err(&r).contains("1 runs already on disk"), "{}", err(&r));
    assert_eq!(std::fs::read(&out).unwrap(), std::fs::read(&whole).unwrap());
    assert!(!journal.exists() && !partial.exists());
    // A write that fails (a file-size limit) commits every chunk written whole before it.
    let cut = d.path().join("cut.csv");
    let limit = std::fs::metadata(&whole).unwrap().len() / 3;
    let r = pound_with_file_limit_env(
        &[
            "sweep",
            s(&cfg),
            "-o",
            s(&cut),
            "--backend",
            "cpu",
            "--threads",
            "1",
            "--chunk",
            "4",
        ],
        limit,
        // Commits by time never due: only the failed write's commit keeps the rows.
        &[("POUND_COMMIT_S", "3600")],
    );
    assert!(!r.status.success());
    let done = journal_done(&sibling(&cut, ".progress.toml")).unwrap();
    assert!(done > 4, "only {done} runs kept after the failed write");
    ok(&sweep(&cfg, &cut, &["--resume"]));
    assert_eq!(std::fs::read(&cut).unwrap(), std::fs::read(&whole).unwrap());
}

/// Item 10: a GPU sweep (the software adapter here) that ends 0 has its output in place, its
/// sidecar, its summary line and nothing beside it; one whose write fails ends non-zero with the
/// error and the `.partial` named, its journal vouching for the chunks written, and `--resume`
/// on the GPU ends with the uninterrupted output.
#[test]
fn a_gpu_sweep_ends_with_its_output_or_a_resumable_error() {
    if ctx().is_none() {
        return;
    }
    let d = tempdir();
    let cfg = d.path().join("a.toml");
    std::fs::write(&cfg, A).unwrap();
    let gpu = |out: &Path, extra: &[&str]| {
        let mut args = vec![
            "sweep",
            s(&cfg),
            "-o",
            s(out),
            "--backend",
            "gpu",
            "--chunk",
            "4",
        ];
        args.extend_from_slice(extra);
        pound(&args)
    };
    let whole = d.path().join("whole.csv");
    let r = gpu(&whole, &[]);
    ok(&r);
    assert!(
        err(&r).contains(&format!("-> {} (24 rows)", whole.display())),
        "no summary line: {}",
        err(&r)
    );
    assert!(sibling(&whole, ".meta.toml").exists());
    assert!(!sibling(&whole, ".partial").exists() && !sibling(&whole, ".progress.toml").exists());
    let limit = std::fs::metadata(&whole).unwrap().len() / 2;
    let cut = d.path().join("cut.csv");
    let r = pound_with_file_limit(
        &[
            "sweep",
            s(&cfg),
            "-o",
            s(&cut),
            "--backend",
            "gpu",
            "--chunk",
            "4",
        ],
        limit,
    );
    let e = err(&r);
    assert!(!r.status.success(), "rc 0 after a failed write: {e}");
    assert!(
        e.contains("error:") && e.contains(&format!("{}.partial", cut.display())),
        "{e}"
    );
    assert!(!cut.exists());
    let done = journal_done(&sibling(&cut, ".progress.toml")).expect("a journal");
    assert!(done >= 4, "{done}");
    let r = gpu(&cut, &["--resume"]);
    ok(&r);
    assert!(err(&r).contains(&format!("{done} runs already on disk")));
    assert_eq!(std::fs::read(&cut).unwrap(), std::fs::read(&whole).unwrap());
}
