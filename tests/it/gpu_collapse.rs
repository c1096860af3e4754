//! A collapsing run on the GPU row kernel (issue 64): the kernel has no collapse event, so it
//! ends a run once a building's peak drift ratio reaches the collapse limit and the host runs
//! it again on the CPU. Past the limit a yielding P-Delta storey runs away, its contacts
//! stiffen and its substeps per record step grow without end: in f64 such a run never
//! finished, in f32 it ran until the handoff past 4,096 substeps per step.

use crate::support::{ctx, pound, table, tempdir};
use std::path::Path;
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

/// A yielding 2-storey frame with P-Delta (a leaning column: twice its floors' weight) beside
/// a stiff elastic 2-storey neighbour 20 mm away, floors at the same heights, Hertzian
/// contact; 10 s of a synthetic record at 1 g, which collapses the frame in storey 1 at 2.3 s.
const SCENE: &str = r#"
[run]
tail_s = 2.0
collapse_drift_ratio = 0.10

[[building]]
storeys = 2
storey_height_m = [4.0, 3.5]
mass_kg = 3.0e5
stiffness_profile = [1.0, 0.6]
period_s = 1.0
damping_ratio = 0.05
yield_drift_ratio = 0.006
post_yield_ratio = 0.02
p_delta = true
gravity_mass_ratio = 2.0
gap_right_m = 0.02

[[building]]
storeys = 2
storey_height_m = [4.0, 3.5]
mass_kg = 2.5e5
period_s = 0.3
damping_ratio = 0.05

[contact]
law = "nonlinear_viscoelastic"
formula = "ebrahimi"
e = 0.65
beta_n_per_m1_5 = 2.75e9

[[record]]
synthetic = { seed = 3, duration_s = 10.0, dt_s = 0.01, pga_g = 0.4 }

[intensity]
pga_g = [1.0]
"#;

/// A sweep on lavapipe takes seconds; before the fix the f64 one ran for hours. The bound
/// fails the test instead of hanging it, with room for a slow, busy machine.
const SWEEP_LIMIT: Duration = Duration::from_secs(300);

/// `pound ARGS`, killed and failed past `limit`.
fn pound_within(args: &[&str], limit: Duration) -> Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_pound"))
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("run pound");
    let start = Instant::now();
    while child.try_wait().expect("wait for pound").is_none() {
        if start.elapsed() > limit {
            child.kill().expect("kill pound");
            child.wait().expect("reap pound");
            panic!("pound {} did not finish in {limit:?}", args.join(" "));
        }
        std::thread::sleep(Duration::from_millis(100));
    }
    child.wait_with_output().expect("pound's output")
}

fn sweep_args<'a>(cfg: &'a Path, out: &'a Path, extra: &[&'a str]) -> Vec<&'a str> {
    let mut args = vec!["sweep", cfg.to_str().unwrap(), "-o", out.to_str().unwrap()];
    args.extend_from_slice(extra);
    args
}

/// The collapsing run finishes on the GPU in f64 and in f32 with the CPU's row (status
/// `collapsed`, its time, building and storey), handed to the CPU at the collapse rather than
/// for its substeps (no handoff note).
#[test]
fn a_collapsing_p_delta_run_finishes_on_the_gpu_with_the_cpus_row() {
    if ctx().is_none() {
        return;
    }
    let dir = tempdir();
    let cfg = dir.path().join("collapse.toml");
    std::fs::write(&cfg, SCENE).unwrap();
    let cpu_csv = dir.path().join("cpu.csv");
    let o = pound(&sweep_args(&cfg, &cpu_csv, &["--backend", "cpu"]));
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let cpu = table(&cpu_csv);
    assert_eq!(cpu.len(), 1);
    assert_eq!(cpu[0]["status"], "collapsed", "the test needs a collapse");
    assert_eq!(cpu[0]["collapse_building"], "1");
    for precision in ["f64", "f32"] {
        let gpu_csv = dir.path().join(format!("gpu-{precision}.csv"));
        let extra = ["--backend", "gpu", "--precision", precision];
        let o = pound_within(&sweep_args(&cfg, &gpu_csv, &extra), SWEEP_LIMIT);
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert!(o.status.success(), "{precision}: {stderr}");
        assert!(
            !stderr.contains("RK4 substeps per record step"),
            "{precision}: the kernel ends the run at the collapse, not at the substep handoff: {stderr}"
        );
        let gpu = table(&gpu_csv);
        assert_eq!(gpu, cpu, "{precision}: a collapse is the CPU's run");
    }
}
