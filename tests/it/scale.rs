//! Scale and reliability (issue 6): shards merge to the unsharded sweep, a killed sweep resumes
//! to the same output, and resuming or merging outputs of different sweeps is refused.

use crate::support::{assert_same_text, tempdir};
use crate::support::{ok, pound};
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::Duration;

/// Two records of different lengths, so cost-balanced shards differ in run count.
const SWEEP: &str = r#"
[run]
tail_s = 1.0

[building1]
mass_kg = 1.0e5
period_s = [0.3, 0.5, 0.7]
damping_ratio = 0.05

[building2]
mass_kg = 1.0e5
period_s = [0.4, 0.9]
damping_ratio = 0.05

[contact]
law = ["nonlinear_viscoelastic", "kelvin_voigt"]
formula = "exact"
e = [0.5, 0.8]
k_n_per_m = 1e9
beta_n_per_m1_5 = 2.75e9
gap_m = { from = 0.0, to = 0.03, n = 4 }

[[record]]
synthetic = { seed = 1, duration_s = 4.0 }

[[record]]
path = "long.txt"
format = "values"
dt_s = 0.01
units = "g"
"#;

fn setup(dir: &Path) -> std::path::PathBuf {
    // A 16 s record: four times the synthetic one's cost per run.
    let long: Vec<String> = (0..1600)
        .map(|i| {
            format!(
                "{}",
                0.3 * (i as f64 * 0.05).sin() * (i as f64 * 0.0021).cos()
            )
        })
        .collect();
    std::fs::write(dir.join("long.txt"), long.join("\n")).unwrap();
    let cfg = dir.join("sweep.toml");
    std::fs::write(&cfg, SWEEP).unwrap();
    cfg
}

fn sweep(cfg: &Path, out: &Path, extra: &[&str]) -> std::process::Output {
    crate::support::sweep_cpu(cfg, out, extra)
}

/// `pound sweep` on the CPU, started in the background (to be killed).
fn spawn(cfg: &Path, out: &Path, extra: &[&str]) -> std::process::Child {
    Command::new(env!("CARGO_BIN_EXE_pound"))
        .args(["sweep", cfg.to_str().unwrap(), "-o", out.to_str().unwrap()])
        .args(["--backend", "cpu", "--threads", "1"])
        .args(extra)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap()
}

#[test]
fn shards_merge_to_the_unsharded_sweep() {
    let d = tempdir();
    let cfg = setup(d.path());
    let all = d.path().join("all.csv");
    ok(&sweep(&cfg, &all, &[]));
    let mut shards = Vec::new();
    let mut counts = Vec::new();
    for i in 0..3 {
        let out = d.path().join(format!("shard{i}.csv"));
        ok(&sweep(&cfg, &out, &["--shard", &format!("{i}/3")]));
        counts.push(std::fs::read_to_string(&out).unwrap().lines().count() - 1);
        shards.push(out);
    }
    // 192 runs: record 1 (4 s) and record 2 (16 s) alternate in blocks, so equal cost is not
    // equal count.
    assert_eq!(counts.iter().sum::<usize>(), 192, "{counts:?}");
    assert!(counts.iter().any(|&c| c != 64), "{counts:?}");
    let merged = d.path().join("merged.csv");
    let args: Vec<&str> = ["merge", "-o", merged.to_str().unwrap()]
        .into_iter()
        .chain([2, 0, 1].map(|i| shards[i].to_str().unwrap()))
        .collect();
    ok(&pound(&args));
    assert_same_text(
        "merged shards vs one sweep",
        &std::fs::read_to_string(&merged).unwrap(),
        &std::fs::read_to_string(&all).unwrap(),
    );
    // A missing shard, a repeated one, and a shard of another sweep are refused.
    let missing = pound(&[
        "merge",
        "-o",
        "x.csv",
        shards[0].to_str().unwrap(),
        shards[2].to_str().unwrap(),
    ]);
    assert!(String::from_utf8_lossy(&missing.stderr).contains("are in no input"));
    let twice = pound(&[
        "merge",
        "-o",
        "x.csv",
        shards[0].to_str().unwrap(),
        shards[1].to_str().unwrap(),
        shards[1].to_str().unwrap(),
        shards[2].to_str().unwrap(),
    ]);
    assert!(String::from_utf8_lossy(&twice.stderr).contains("also in another input"));
    std::fs::write(&cfg, SWEEP.replace("e = [0.5, 0.8]", "e = [0.5, 0.7]")).unwrap();
    let other = d.path().join("other.csv");
    ok(&sweep(&cfg, &other, &["--shard", "1/3"]));
    let mixed = pound(&[
        "merge",
        "-o",
        "x.csv",
        shards[0].to_str().unwrap(),
        other.to_str().unwrap(),
        shards[2].to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&mixed.stderr);
    assert!(
        err.contains("the config (the validated plan) differs"),
        "{err}"
    );
    assert!(!d.path().join("x.csv").exists());
}

/// Kill a real sweep (SIGKILL) at several moments, resume each time, and end with exactly the
/// output of an uninterrupted sweep; each resume computes only what is not on disk.
#[test]
fn killed_sweep_resumes_to_identical_output() {
    let d = tempdir();
    let cfg = setup(d.path());
    // Four times the runs of the other tests, so there is time to kill it.
    std::fs::write(&cfg, SWEEP.replace("to = 0.03, n = 4", "to = 0.03, n = 16")).unwrap();
    let whole = d.path().join("whole.csv");
    let t = std::time::Instant::now();
    ok(&sweep(&cfg, &whole, &["--threads", "1"]));
    let full = t.elapsed().as_secs_f64();
    let out = d.path().join("killed.csv");
    let progress = d.path().join("killed.csv.progress.toml");
    let mut kills = 0;
    // Kill points as fractions of an uninterrupted sweep's time, so they land inside the sweep
    // on a fast machine or a slow one.
    for (k, f) in [0.1, 0.3, 0.2, 0.35, 0.15, 0.25].into_iter().enumerate() {
        let ms = (f * full * 1000.0) as u64;
        let extra: &[&str] = if k > 0 {
            &["--chunk", "2", "--resume"]
        } else {
            &["--chunk", "2"]
        };
        let mut child = spawn(&cfg, &out, extra);
        std::thread::sleep(Duration::from_millis(ms));
        if child.try_wait().unwrap().is_none() {
            child.kill().unwrap();
            kills += 1;
        }
        child.wait().unwrap();
        if out.exists() {
            break;
        }
    }
    assert!(
        kills >= 2,
        "the sweep finished before it could be killed twice"
    );
    let done_before = std::fs::read_to_string(&progress).ok().and_then(|t| {
        t.lines()
            .find(|l| l.starts_with("done = "))
            .map(String::from)
    });
    let r = sweep(&cfg, &out, &["--resume"]);
    let err = String::from_utf8_lossy(&r.stderr).to_string();
    ok(&r);
    if let Some(line) = done_before {
        let n: u64 = line["done = ".len()..].parse().unwrap();
        if n > 0 {
            assert!(err.contains(&format!("{n} runs already on disk")), "{err}");
        }
    }
    assert_same_text(
        "resumed vs uninterrupted",
        &std::fs::read_to_string(&out).unwrap(),
        &std::fs::read_to_string(&whole).unwrap(),
    );
    assert!(!progress.exists());
    let again = sweep(&cfg, &out, &["--resume"]);
    assert!(String::from_utf8_lossy(&again.stderr).contains("already complete"));
}

/// Resuming after the config or a record changed is refused and names what changed; a sweep
/// that is not resumed does not overwrite finished work.
#[test]
fn resume_refuses_a_different_sweep() {
    let d = tempdir();
    let cfg = setup(d.path());
    let out = d.path().join("r.csv");
    // Leave an unfinished output: kill the sweep once its journal holds a finished run
    // (waiting for it rather than a fixed time, which a loaded machine can outlast before the
    // first chunk; a journal of 0 runs blocks nothing).
    let mut child = spawn(&cfg, &out, &["--chunk", "1"]);
    let journal = d.path().join("r.csv.progress.toml");
    let start = std::time::Instant::now();
    let holds_a_run = || {
        std::fs::read_to_string(&journal).is_ok_and(|t| {
            t.lines()
                .any(|l| l.starts_with("done = ") && l != "done = 0")
        })
    };
    while !holds_a_run() && start.elapsed() < Duration::from_secs(30) {
        std::thread::sleep(Duration::from_millis(2));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    assert!(d.path().join("r.csv.progress.toml").exists() && !out.exists());
    let fresh = sweep(&cfg, &out, &[]);
    assert!(!fresh.status.success());
    assert!(String::from_utf8_lossy(&fresh.stderr).contains("rerun with --resume"));
    std::fs::write(
        &cfg,
        SWEEP.replace(
            "gap_m = { from = 0.0, to = 0.03, n = 4 }",
            "gap_m = [0.0, 0.01, 0.02, 0.035]",
        ),
    )
    .unwrap();
    let e = sweep(&cfg, &out, &["--resume"]);
    let err = String::from_utf8_lossy(&e.stderr);
    assert!(
        !e.status.success() && err.contains("the config (the validated plan) differs"),
        "{err}"
    );
    std::fs::write(&cfg, SWEEP).unwrap();
    let long = std::fs::read_to_string(d.path().join("long.txt")).unwrap();
    std::fs::write(d.path().join("long.txt"), long.replacen('0', "1", 1)).unwrap();
    let e = sweep(&cfg, &out, &["--resume"]);
    let err = String::from_utf8_lossy(&e.stderr);
    assert!(
        !e.status.success() && err.contains("the records (their content) differs"),
        "{err}"
    );
    std::fs::write(d.path().join("long.txt"), long).unwrap();
    let e = sweep(&cfg, &out, &["--resume", "--shard", "0/2"]);
    assert!(String::from_utf8_lossy(&e.stderr).contains("the shard"));
    ok(&sweep(&cfg, &out, &["--resume"]));
}

/// The Slurm example, run as local processes (`examples/slurm/local.sh`: the array tasks, then
/// the merge job), gives the unsharded sweep row for row.
#[test]
fn slurm_example_runs_locally() {
    let d = tempdir();
    let cfg = setup(d.path());
    let prefix = d.path().join("out").join("sweep");
    let r = Command::new("bash")
        .arg(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/examples/slurm/local.sh"
        ))
        .args([cfg.to_str().unwrap(), prefix.to_str().unwrap(), "3"])
        .env("POUND", env!("CARGO_BIN_EXE_pound"))
        .output()
        .unwrap();
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let all = d.path().join("all.csv");
    ok(&sweep(&cfg, &all, &[]));
    assert_same_text(
        "slurm example vs one sweep",
        &std::fs::read_to_string(d.path().join("out").join("sweep.csv")).unwrap(),
        &std::fs::read_to_string(&all).unwrap(),
    );
}

/// `--aggregate` writes one row per group, and its counts, maxima and means equal those of the
/// per-run CSV of the same sweep; quantiles are within the sketch's 1 %.
#[test]
fn aggregate_matches_the_per_run_output() {
    let d = tempdir();
    let cfg = setup(d.path());
    let runs = d.path().join("runs.csv");
    ok(&sweep(&cfg, &runs, &[]));
    let agg = d.path().join("agg.csv");
    ok(&sweep(
        &cfg,
        &agg,
        &[
            "--aggregate",
            "record,law",
            "--exceed",
            "peak_force_n=1e6",
            "--exceed",
            "impacts=0",
        ],
    ));
    let mut r = csv::Reader::from_path(&runs).unwrap();
    let h = r.headers().unwrap().clone();
    let col = |n: &str| h.iter().position(|c| c == n).unwrap();
    let all: Vec<csv::StringRecord> = r.records().map(|x| x.unwrap()).collect();
    let mut a = csv::Reader::from_path(&agg).unwrap();
    let ah = a.headers().unwrap().clone();
    let groups: Vec<csv::StringRecord> = a.records().map(|x| x.unwrap()).collect();
    assert_eq!(groups.len(), 4, "2 records x 2 laws");
    for g in &groups {
        let get = |n: &str| -> f64 { g[ah.iter().position(|c| c == n).unwrap()].parse().unwrap() };
        let rows: Vec<&csv::StringRecord> = all
            .iter()
            .filter(|x| x[col("record")] == g[0] && x[col("law")] == g[1])
            .collect();
        let f: Vec<f64> = rows
            .iter()
            .map(|x| x[col("peak_force_n")].parse().unwrap())
            .collect();
        assert_eq!(get("runs") as usize, rows.len());
        assert_eq!(
            get("exceed_peak_force_n>1000000") as usize,
            f.iter().filter(|&&x| x > 1e6).count()
        );
        let pounded = rows
            .iter()
            .filter(|x| x[col("impacts")].parse::<u32>().unwrap() > 0)
            .count();
        assert_eq!(get("exceed_impacts>0") as usize, pounded);
        assert_eq!(
            get("peak_force_n_max"),
            f.iter().cloned().fold(0.0, f64::max)
        );
        let mean = f.iter().sum::<f64>() / f.len() as f64;
        assert!((get("peak_force_n_mean") - mean).abs() <= 1e-12 * mean);
        let mut s = f.clone();
        s.sort_by(f64::total_cmp);
        let p90 = s[(0.9 * (s.len() - 1) as f64).round() as usize];
        assert!((get("peak_force_n_p90") - p90).abs() <= 0.01 * p90, "{g:?}");
    }
    assert!(std::fs::metadata(&agg).unwrap().len() < 10_000);
    // On the GPU the fold runs on the device: the same groups and counts.
    if crate::support::ctx().is_some() {
        let gagg = d.path().join("gpu-agg.csv");
        let out = pound(&[
            "sweep",
            cfg.to_str().unwrap(),
            "-o",
            gagg.to_str().unwrap(),
            "--backend",
            "gpu",
            "--precision",
            "f64",
            "--aggregate",
            "record,law",
        ]);
        ok(&out);
        assert!(String::from_utf8_lossy(&out.stderr).contains("aggregated on the device"));
        let mut g = csv::Reader::from_path(&gagg).unwrap();
        let gh = g.headers().unwrap().clone();
        let grows: Vec<csv::StringRecord> = g.records().map(|x| x.unwrap()).collect();
        assert_eq!(grows.len(), groups.len());
        for (a, b) in grows.iter().zip(&groups) {
            let at = |r: &csv::StringRecord, h: &csv::StringRecord, n: &str| {
                r[h.iter().position(|c| c == n).unwrap()].to_string()
            };
            for n in ["record", "law", "runs", "failures"] {
                assert_eq!(at(a, &gh, n), at(b, &ah, n), "{n}");
            }
        }
    }
    for (by, what) in [("gap", "`gap`"), ("impacts", "`impacts`")] {
        let bad = sweep(&cfg, &agg, &["--aggregate", by]);
        let err = String::from_utf8_lossy(&bad.stderr);
        assert!(
            err.contains(&format!("{what} is not a swept-parameter column")),
            "{err}"
        );
    }
}

/// `--format parquet` holds the CSV's values, typed (an empty cell is a null), with the plan
/// fingerprint in its metadata; `--columns` keeps `run` and the named columns, in CSV and
/// Parquet alike.
#[test]
fn parquet_and_columns_hold_the_csv_values() {
    use parquet::file::reader::{FileReader, SerializedFileReader};
    let d = tempdir();
    let cfg = setup(d.path());
    let csv_out = d.path().join("runs.csv");
    ok(&sweep(&cfg, &csv_out, &[]));
    let pq = d.path().join("runs.parquet");
    ok(&sweep(&cfg, &pq, &["--format", "parquet"]));
    let reader = SerializedFileReader::new(std::fs::File::open(&pq).unwrap()).unwrap();
    let md = reader.metadata().file_metadata();
    let kv = md.key_value_metadata().unwrap();
    let plan_fp = kv
        .iter()
        .find(|k| k.key == "pound.fingerprint.plan")
        .and_then(|k| k.value.clone())
        .unwrap();
    let sidecar = std::fs::read_to_string(d.path().join("runs.parquet.meta.toml")).unwrap();
    assert!(
        sidecar.contains(&format!("plan = \"{plan_fp}\"")),
        "{sidecar}"
    );
    // Every column's unit, as `pound columns` gives it, in one JSON object.
    let units = (kv.iter().find(|k| k.key == "units"))
        .and_then(|k| k.value.clone())
        .unwrap();
    for (name, unit) in [("peak_force_n", "N"), ("gap_m", "m"), ("run", "-")] {
        assert!(units.contains(&format!("\"{name}\":\"{unit}\"")), "{units}");
    }
    let mut r = csv::Reader::from_path(&csv_out).unwrap();
    let header: Vec<String> = r.headers().unwrap().iter().map(String::from).collect();
    let rows: Vec<csv::StringRecord> = r.records().map(|x| x.unwrap()).collect();
    assert_eq!(md.num_rows() as usize, rows.len());
    for (row, rec) in reader.get_row_iter(None).unwrap().zip(&rows) {
        let row = row.unwrap();
        for ((name, field), cell) in row.get_column_iter().zip(rec.iter()) {
            let i = header.iter().position(|h| h == name).unwrap();
            assert_eq!(&header[i], name);
            let text = match field {
                parquet::record::Field::Null => String::new(),
                parquet::record::Field::Str(s) => s.clone(),
                parquet::record::Field::Long(v) => v.to_string(),
                parquet::record::Field::Double(v) => v.to_string(),
                other => panic!("{name}: unexpected {other:?}"),
            };
            if let (Ok(a), Ok(b)) = (text.parse::<f64>(), cell.parse::<f64>()) {
                assert_eq!(a, b, "{name}");
            } else {
                assert_eq!(text, cell, "{name}");
            }
        }
    }
    let some = d.path().join("some.csv");
    ok(&sweep(&cfg, &some, &["--columns", "gap_m,peak_force_n"]));
    let text = std::fs::read_to_string(&some).unwrap();
    assert_eq!(text.lines().next().unwrap(), "run,gap_m,peak_force_n");
    assert_eq!(text.lines().count(), rows.len() + 1);
    let bad = sweep(&cfg, &some, &["--columns", "gap"]);
    assert!(String::from_utf8_lossy(&bad.stderr).contains("`gap` is not a column"));
}

/// An output that cannot be created is a clear error naming it, and leaves nothing behind.
#[test]
fn unwritable_output_is_a_clear_error() {
    let d = tempdir();
    let cfg = setup(d.path());
    let out = d.path().join("no-such-dir").join("runs.csv");
    let r = sweep(&cfg, &out, &[]);
    assert!(!r.status.success());
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(
        err.contains("cannot be created") && err.contains("no-such-dir"),
        "{err}"
    );
    assert!(!d.path().join("no-such-dir").exists());
}

/// A record file that changes while a sweep runs ends the sweep with an error naming the
/// record; the output does not appear under its final name (the rows computed from the content
/// read at the start stay in the `.partial` file).
#[test]
fn record_changed_during_a_sweep_is_an_error() {
    let d = tempdir();
    let cfg = setup(d.path());
    std::fs::write(&cfg, SWEEP.replace("to = 0.03, n = 4", "to = 0.03, n = 64")).unwrap();
    let out = d.path().join("o.csv");
    let mut child = Command::new(env!("CARGO_BIN_EXE_pound"))
        .args(["sweep", cfg.to_str().unwrap(), "-o", out.to_str().unwrap()])
        .args(["--backend", "cpu", "--threads", "1"])
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Change the record once the first rows are on disk, i.e. mid-sweep.
    let progress = d.path().join("o.csv.progress.toml");
    while !std::fs::read_to_string(&progress).is_ok_and(|t| !t.contains("done = 0\n")) {
        if child.try_wait().unwrap().is_some() {
            break;
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    let long = d.path().join("long.txt");
    let mut text = std::fs::read_to_string(&long).unwrap();
    text.push_str("\n0.5");
    std::fs::write(&long, text).unwrap();
    let r = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(
        !r.status.success(),
        "the sweep ended before the record changed: {err}"
    );
    assert!(
        err.contains("record `long` changed on disk during the sweep"),
        "{err}"
    );
    assert!(!out.exists());
    assert!(d.path().join("o.csv.partial").exists());
}

/// A full disk (`OUT.partial` pointing at `/dev/full`, where every write fails with ENOSPC) is a
/// clear error for every output kind, and nothing is left under the final name, not even the
/// sidecar.
#[test]
fn full_disk_is_a_clear_error_with_nothing_left_behind() {
    assert!(Path::new("/dev/full").exists(), "/dev/full is needed");
    let d = tempdir();
    let cfg = setup(d.path());
    for (name, extra) in [
        ("runs.csv", &[][..]),
        ("runs.parquet", &["--format", "parquet"][..]),
        ("summary.csv", &["--aggregate", "record"][..]),
    ] {
        let out = d.path().join(name);
        std::os::unix::fs::symlink("/dev/full", d.path().join(format!("{name}.partial"))).unwrap();
        let r = sweep(&cfg, &out, extra);
        let err = String::from_utf8_lossy(&r.stderr);
        assert!(!r.status.success(), "{name}");
        assert!(err.contains("No space left on device"), "{name}: {err}");
        assert!(
            err.contains(name),
            "{name}: the error names the file: {err}"
        );
        assert!(!out.exists(), "{name}");
        assert!(
            !d.path().join(format!("{name}.meta.toml")).exists(),
            "{name}"
        );
        // Only CSV keeps its `.partial` (it resumes); an unfinished Parquet file or summary
        // cannot be continued and is removed.
        let partial = d.path().join(format!("{name}.partial"));
        assert_eq!(
            partial.symlink_metadata().is_ok(),
            extra.is_empty(),
            "{name}"
        );
    }
}

/// A disk that fills in the middle of a sweep (a file-size limit, so writes past it fail) keeps
/// every finished chunk; once there is room again, `--resume` completes the output, identical to
/// an uninterrupted sweep.
#[test]
fn disk_filling_mid_sweep_keeps_finished_rows_and_resumes() {
    let d = tempdir();
    let cfg = setup(d.path());
    let whole = d.path().join("whole.csv");
    ok(&sweep(&cfg, &whole, &[]));
    let size = std::fs::metadata(&whole).unwrap().len();
    let out = d.path().join("out.csv");
    let limit = size / 3;
    let r = crate::support::pound_with_file_limit(
        &[
            "sweep",
            cfg.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--backend",
            "cpu",
            "--chunk",
            "4",
        ],
        limit,
    );
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(!r.status.success());
    assert!(err.contains("out.csv.partial"), "{err}");
    assert!(err.contains("File too large"), "{err}");
    assert!(!out.exists());
    // What is on disk is a prefix of the full output, cut at the last finished chunk.
    let partial = std::fs::read_to_string(d.path().join("out.csv.partial")).unwrap();
    let full = std::fs::read_to_string(&whole).unwrap();
    assert!(partial.len() as u64 <= limit && partial.len() > 100);
    assert!(full.starts_with(&partial));
    let resumed = sweep(&cfg, &out, &["--resume"]);
    ok(&resumed);
    assert_same_text(
        "resumed after a full disk",
        &std::fs::read_to_string(&out).unwrap(),
        &full,
    );
}
