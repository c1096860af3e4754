//! Shared helpers: temp dirs, a diffing text comparison, records dir, scene builders.

use pounding::contact::{Contact, LawKind};
use pounding::cpu::Scheme;
use pounding::model::RunOutput;
use pounding::model::{Oscillator, Pair};
use pounding::plan::{Plan, RunSpec};
use std::path::PathBuf;

/// The real-records directory (`POUND_RECORDS_DIR`, default `../shared/records`). Tests that need
/// it fail, never skip, when it is missing: CI has it beside the clone.
pub fn records_dir() -> PathBuf {
    let d = pounding::config::records_dir();
    assert!(
        d.join("SOURCES.md").is_file(),
        "records directory {} not found (set POUND_RECORDS_DIR)",
        d.display()
    );
    d
}

pub fn tempdir() -> tempfile::TempDir {
    tempfile::Builder::new()
        .prefix("pound-test-")
        .tempdir()
        .expect("temp dir")
}

/// Assert two texts are equal, showing the first differing lines on failure.
pub fn assert_same_text(label: &str, a: &str, b: &str) {
    if a == b {
        return;
    }
    let (la, lb): (Vec<&str>, Vec<&str>) = (a.lines().collect(), b.lines().collect());
    let mut diff = String::new();
    let mut shown = 0;
    for i in 0..la.len().max(lb.len()) {
        let (x, y) = (
            la.get(i).copied().unwrap_or("<none>"),
            lb.get(i).copied().unwrap_or("<none>"),
        );
        if x != y {
            diff.push_str(&format!("line {}:\n  - {x}\n  + {y}\n", i + 1));
            shown += 1;
            if shown == 10 {
                break;
            }
        }
    }
    panic!(
        "{label}: texts differ ({} vs {} lines)\n{diff}",
        la.len(),
        lb.len()
    );
}

/// Relative difference with a floor.
pub fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs().max(1e-300)
}

/// Two SDOF buildings with a contact law.
pub fn pair(
    law: LawKind,
    stiffness: f64,
    damping: f64,
    (m1, t1, xi1): (f64, f64, f64),
    (m2, t2, xi2): (f64, f64, f64),
    gap: f64,
) -> Pair {
    let b1 = Oscillator::from_period(m1, t1, xi1);
    let b2 = Oscillator::from_period(m2, t2, xi2);
    Pair {
        b1,
        b2,
        gap,
        contact: Contact::new(law, stiffness, damping, Pair::m_eff(&b1, &b2)),
    }
}

/// Every run of `plan` with `scheme`, in run order.
pub fn collect(plan: &Plan, scheme: &Scheme, chunk: usize) -> Vec<(RunSpec, RunOutput)> {
    let mut rows = Vec::new();
    let sink = |c: &[(RunSpec, RunOutput)]| -> Result<(), ()> {
        rows.extend_from_slice(c);
        Ok(())
    };
    pounding::sweep::run(plan, scheme, chunk, sink, |_| {}).unwrap();
    rows
}

/// Run `pound ARGS` under a file-size limit of `limit` bytes (SIGXFSZ ignored), so a write past
/// it fails as on a full disk: a sweep stops with its finished chunks in `OUT.partial`.
pub fn pound_with_file_limit(args: &[&str], limit: u64) -> std::process::Output {
    use std::os::unix::process::CommandExt;
    let mut cmd = std::process::Command::new(env!("CARGO_BIN_EXE_pound"));
    cmd.args(args);
    // SAFETY: only async-signal-safe calls between fork and exec.
    unsafe {
        cmd.pre_exec(move || {
            libc::signal(libc::SIGXFSZ, libc::SIG_IGN);
            let r = libc::rlimit {
                rlim_cur: limit,
                rlim_max: limit,
            };
            if libc::setrlimit(libc::RLIMIT_FSIZE, &r) != 0 {
                return Err(std::io::Error::last_os_error());
            }
            Ok(())
        });
    }
    cmd.output().expect("run pound")
}
