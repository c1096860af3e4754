//! Running `pound` on files and reading what it says: the sweep and study calls the file
//! promises' tests make, and the checks of a refusal or a warning.

use super::run::{ok, pound};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// `p` as the `&str` an argument list takes.
pub fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// `p` with `suffix` appended, as the library names a partial, journal or sidecar.
pub fn sibling(p: &Path, suffix: &str) -> PathBuf {
    pounding::io::atomic::sibling(p, suffix)
}

/// `pound sweep CFG -o OUT --backend cpu EXTRA...`
pub fn sweep(cfg: &Path, out: &Path, extra: &[&str]) -> Output {
    let mut args = vec!["sweep", s(cfg), "-o", s(out), "--backend", "cpu"];
    args.extend_from_slice(extra);
    pound(&args)
}

/// `pound fragility RESULTS --threshold 0 --edp impacts EXTRA...` ("pounds at all").
pub fn fragility(results: &Path, extra: &[&str]) -> Output {
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

/// A command's standard error, as text.
pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Fails with `needle` in its message, and leaves no output and no sidecar under `out`.
pub fn refused(o: &Output, needle: &str, out: Option<&Path>) {
    let err = stderr(o);
    assert!(!o.status.success(), "rc 0 where an error was due: {err}");
    assert!(err.contains(needle), "expected `{needle}` in: {err}");
    assert!(!err.contains("panicked"), "{err}");
    if let Some(out) = out {
        assert!(!out.exists(), "{} exists", out.display());
        assert!(!sibling(out, ".meta.toml").exists());
    }
}

/// `pound ARGS`' standard error, where it fails (without a panic).
pub fn refusal(args: &[&str]) -> String {
    let o = pound(args);
    let err = stderr(&o);
    assert!(
        !o.status.success(),
        "pound {args:?} succeeded: {}",
        String::from_utf8_lossy(&o.stdout)
    );
    assert!(!err.contains("panicked"), "{err}");
    err
}

/// Fails with `needle` in its message, without a panic ([`refused`] with no output to check).
pub fn fails_with(o: &Output, needle: &str) {
    refused(o, needle, None);
}

/// A command's standard output, as text.
pub fn out(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// Succeeds, and says `needle` on stderr.
pub fn warns(o: &Output, needle: &str) {
    let e = stderr(o);
    assert!(o.status.success(), "failed: {e}");
    assert!(e.contains(needle), "expected `{needle}` in: {e}");
}

/// `pound ARGS` run from folder `cwd` with `POUND_RECORDS_DIR` unset.
pub fn pound_in(cwd: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_pound"))
        .args(args)
        .current_dir(cwd)
        .env_remove("POUND_RECORDS_DIR")
        .output()
        .unwrap()
}

/// Writes `text` to `dir`/`name` and gives its path.
pub fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// A sweep of `cfg` into `out` cut off by a file-size limit at `fraction` of the whole output
/// (`whole_len` bytes): it leaves `out.partial` and its journal, as a kill or a full disk does.
pub fn interrupt(cfg: &Path, whole_len: usize, out: &Path, fraction: f64) {
    let limit = (whole_len as f64 * fraction) as u64;
    let r = super::pound_with_file_limit(
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

/// The shipped yielding row's sweep (6 runs, CPU) into `dir`/runs.csv: results to study.
pub fn yielding_runs(dir: &Path) -> std::path::PathBuf {
    let runs = dir.join("runs.csv");
    ok(&pound(&[
        "sweep",
        concat!(env!("CARGO_MANIFEST_DIR"), "/configs/inelastic-row.toml"),
        "--backend",
        "cpu",
        "-o",
        runs.to_str().unwrap(),
    ]));
    runs
}
