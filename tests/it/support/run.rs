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
    pound_with_file_limit_env(args, limit, &[])
}

/// [`pound_with_file_limit`] with `env` set for the run.
pub fn pound_with_file_limit_env(
    args: &[&str],
    limit: u64,
    env: &[(&str, &str)],
) -> std::process::Output {
    use std::os::unix::process::CommandExt;
    let mut cmd = std::process::Command::new(env!("CARGO_BIN_EXE_pound"));
    cmd.args(args).envs(env.iter().copied());
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

/// `pound sweep CONFIG -o OUT --backend cpu EXTRA...`.
pub fn sweep_cpu(
    cfg: &std::path::Path,
    out: &std::path::Path,
    extra: &[&str],
) -> std::process::Output {
    let mut args = vec![
        "sweep",
        cfg.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--backend",
        "cpu",
    ];
    args.extend_from_slice(extra);
    pound(&args)
}

/// A CSV as its rows, keyed by column name.
pub fn table(path: &std::path::Path) -> Vec<std::collections::HashMap<String, String>> {
    let mut rd = csv::Reader::from_path(path).unwrap();
    let header: Vec<String> = rd.headers().unwrap().iter().map(String::from).collect();
    rd.records()
        .map(|r| {
            header
                .iter()
                .cloned()
                .zip(r.unwrap().iter().map(String::from))
                .collect()
        })
        .collect()
}
