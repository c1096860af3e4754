//! Running the `pound` binary.

use std::process::Command;

pub fn pound(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_pound"))
        .args(args)
        .output()
        .expect("run pound")
}

pub fn ok(out: &std::process::Output) -> String {
    assert!(
        out.status.success(),
        "pound failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout.clone()).unwrap()
}

/// `pound ARGS -o OUT --plot PLOT`; its stdout on success.
pub fn pound_with_outputs(args: &[&str], out: &std::path::Path, plot: &std::path::Path) -> String {
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_pound"))
        .args(args)
        .arg("-o")
        .arg(out)
        .arg("--plot")
        .arg(plot)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    String::from_utf8(o.stdout).unwrap()
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
