//! `pound`: the command-line front end: parse, dispatch, exit code. Each command is a module of
//! `cli/`; the work is done by the `pounding` library.

use clap::Parser;

mod cli;

#[derive(Parser)]
#[command(
    name = "pound",
    version,
    about = "Earthquake-induced pounding between adjacent buildings, in large sweeps"
)]
struct Pound {
    #[command(subcommand)]
    cmd: cli::Cmd,
}

fn main() -> std::process::ExitCode {
    // Like other command-line tools, end quietly when a reader such as `head` closes the pipe
    // (Rust ignores SIGPIPE, and printing to a closed pipe then panics). An interrupted sweep
    // keeps its finished chunks for --resume.
    #[cfg(unix)]
    // SAFETY: restoring the default disposition of one signal before any thread starts.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    // Mesa's software Vulkan driver probes for a Wayland display and prints "XDG_RUNTIME_DIR is
    // invalid" twice when there is none. Without XDG_RUNTIME_DIR no Wayland display can be
    // reached anyway; an absolute WAYLAND_DISPLAY that does not exist makes the probe fail
    // quietly. Set here, before any thread starts.
    if std::env::var_os("XDG_RUNTIME_DIR").is_none()
        && std::env::var_os("WAYLAND_DISPLAY").is_none()
    {
        std::env::set_var("WAYLAND_DISPLAY", "/nonexistent/pound-compute-only");
    }
    match run(Pound::parse().cmd) {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            // The cause chain on one line; no backtrace, whatever RUST_BACKTRACE says.
            pounding::note(format_args!("error: {e:#}"));
            std::process::ExitCode::FAILURE
        }
    }
}

/// One command, run.
fn run(cmd: cli::Cmd) -> anyhow::Result<()> {
    use cli::Cmd;
    match cmd {
        Cmd::Sweep(a) => cli::sweep::run(a),
        Cmd::Gpu { cmd } => cli::gpu::run(cmd),
        Cmd::Bench(a) => cli::bench::run(a),
        Cmd::Accuracy(a) => cli::accuracy::run(a),
        Cmd::Formulas(a) => cli::formulas::run(a),
        Cmd::Plot(a) => cli::plot::run(a),
        Cmd::Fragility(a) => cli::fragility::run(a),
        Cmd::Ida(a) => cli::ida::run(a),
        Cmd::Demands(a) => cli::demands::run(a),
        Cmd::Gap(a) => cli::gap::run(a),
        Cmd::Merge(a) => cli::merge::run(a),
        Cmd::Paper => cli::paper::run(),
        Cmd::Restitution(a) => cli::restitution::run(a),
        Cmd::Hysteresis(a) => cli::hysteresis::run(a),
        Cmd::Trace(a) => cli::trace::run(a),
        Cmd::Record { cmd } => cli::record::run(cmd),
        Cmd::Init(a) => cli::start::init(a),
        Cmd::Columns(a) => cli::start::columns(a),
    }
}
