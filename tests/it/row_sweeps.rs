//! Sweeps of rows of multi-storey buildings through the output protocol the pair's sweeps use:
//! `--resume`, `--shard` and `pound merge`, Parquet, `--aggregate`, and `[sample]`.

use crate::scenes::ROW_CONFIG;
use crate::scenes::STOREYS3;
use crate::support::cli::interrupt;
use crate::support::cli::s;
use crate::support::run::{ok, pound};
use crate::support::tempdir;
use std::path::Path;

/// `pound sweep CFG -o OUT --backend cpu EXTRA...`
fn sweep(cfg: &Path, out: &Path, extra: &[&str]) -> std::process::Output {
    let mut args = vec!["sweep", s(cfg), "-o", s(out), "--backend", "cpu"];
    args.extend_from_slice(extra);
    pound(&args)
}

fn rows_of(path: &Path) -> (Vec<String>, Vec<Vec<String>>) {
    let mut rd = csv::Reader::from_path(path).unwrap();
    let header = rd.headers().unwrap().iter().map(String::from).collect();
    let rows = rd
        .records()
        .map(|r| r.unwrap().iter().map(String::from).collect())
        .collect();
    (header, rows)
}

/// An interrupted row sweep resumes to the uninterrupted file, byte for byte; three shards
/// merge to it; Parquet holds its values, typed.
#[test]
fn row_sweeps_resume_shard_merge_and_write_parquet() {
    use parquet::file::reader::{FileReader, SerializedFileReader};
    let dir = tempdir();
    let cfg = dir.path().join("row.toml");
    std::fs::write(&cfg, ROW_CONFIG).unwrap();
    let full = dir.path().join("full.csv");
    ok(&sweep(&cfg, &full, &["--threads", "2"]));
    let whole = std::fs::read(&full).unwrap();

    // Cut off by a file-size limit halfway, as a full disk or a kill leaves it.
    let cut = dir.path().join("cut.csv");
    interrupt(&cfg, whole.len(), &cut, 0.5);
    let journal = pounding::io::provenance::progress_path(&cut);
    assert!(journal.exists() && !cut.exists());
    // A fresh sweep may not overwrite the unfinished one; a resume finishes it.
    let refused = sweep(&cfg, &cut, &[]);
    assert!(!refused.status.success());
    assert!(String::from_utf8_lossy(&refused.stderr).contains("--resume"));
    let r = sweep(&cfg, &cut, &["--resume", "--threads", "2"]);
    ok(&r);
    assert!(
        String::from_utf8_lossy(&r.stderr).contains("runs already on disk"),
        "{}",
        String::from_utf8_lossy(&r.stderr)
    );
    assert_eq!(std::fs::read(&cut).unwrap(), whole);
    assert!(!journal.exists());
    // A resume of another config is refused by its fingerprint.
    let other = dir.path().join("other.toml");
    std::fs::write(&other, ROW_CONFIG.replace("e = 0.6", "e = 0.7")).unwrap();
    let cut2 = dir.path().join("cut2.csv");
    interrupt(&cfg, whole.len(), &cut2, 0.5);
    let r = sweep(&other, &cut2, &["--resume"]);
    assert!(!r.status.success());
    assert!(
        String::from_utf8_lossy(&r.stderr).contains("the config"),
        "{}",
        String::from_utf8_lossy(&r.stderr)
    );

    // Shards tile the plan and merge to the whole.
    let mut parts = Vec::new();
    for i in 0..3 {
        let p = dir.path().join(format!("s{i}.csv"));
        ok(&sweep(&cfg, &p, &["--shard", &format!("{i}/3")]));
        parts.push(p);
    }
    let merged = dir.path().join("merged.csv");
    let mut args = vec!["merge"];
    args.extend(parts.iter().map(|p| s(p)));
    args.extend(["-o", s(&merged)]);
    ok(&pound(&args));
    assert_eq!(std::fs::read(&merged).unwrap(), whole);

    // Parquet: the CSV's cells, with counts and storey numbers as integers.
    let pq = dir.path().join("row.parquet");
    ok(&sweep(&cfg, &pq, &["--format", "parquet"]));
    let (header, rows) = rows_of(&full);
    let reader = SerializedFileReader::new(std::fs::File::open(&pq).unwrap()).unwrap();
    assert_eq!(
        reader.metadata().file_metadata().num_rows() as usize,
        rows.len()
    );
    let mut ints = 0;
    for (row, cells) in reader.get_row_iter(None).unwrap().zip(&rows) {
        let row = row.unwrap();
        for ((name, field), cell) in row.get_column_iter().zip(cells) {
            let i = header.iter().position(|h| h == name).unwrap();
            assert_eq!(&header[i], name);
            let text = match field {
                parquet::record::Field::Null => String::new(),
                parquet::record::Field::Str(s) => s.clone(),
                parquet::record::Field::Long(v) => {
                    ints += 1;
                    v.to_string()
                }
                parquet::record::Field::Double(v) => v.to_string(),
                other => panic!("{name}: unexpected {other:?}"),
            };
            match (text.parse::<f64>(), cell.parse::<f64>()) {
                (Ok(a), Ok(b)) => assert_eq!(a, b, "{name}"),
                _ => assert_eq!(&text, cell, "{name}"),
            }
        }
    }
    // run, impacts, substeps, 3 storeys, 3 x 2 storey and floor numbers, 5 levels' impacts,
    // 3 buildings' collapse flags (their collapse storeys are empty: null).
    assert_eq!(ints, rows.len() * 20);
}

/// `--aggregate` of a row sweep: per group of a building's parameter, the run counts, the
/// `--exceed` counts of a drift ratio and of a level's impacts, and each output's max and mean
/// are those of the rows the full sweep writes.
#[test]
fn row_summaries_count_what_the_rows_say() {
    let dir = tempdir();
    let cfg = dir.path().join("row.toml");
    std::fs::write(&cfg, ROW_CONFIG).unwrap();
    let full = dir.path().join("full.csv");
    ok(&sweep(&cfg, &full, &[]));
    let (header, rows) = rows_of(&full);
    let col = |name: &str| header.iter().position(|h| h == name).unwrap();
    let (mass, drift, level) = (
        col("b1_mass_kg"),
        col("b2_peak_drift_ratio"),
        col("level_b1f1_b2f1_impacts"),
    );
    let value = |r: &Vec<String>, i: usize| r[i].parse::<f64>().unwrap();
    let mut drifts: Vec<f64> = rows.iter().map(|r| value(r, drift)).collect();
    drifts.sort_by(f64::total_cmp);
    let threshold = drifts[drifts.len() / 2];
    let summary = dir.path().join("summary.csv");
    ok(&sweep(
        &cfg,
        &summary,
        &[
            "--aggregate",
            "b1_mass_kg",
            "--exceed",
            &format!("b2_peak_drift_ratio={threshold}"),
            "--exceed",
            "level_b1f1_b2f1_impacts=0",
        ],
    ));
    let (sh, groups) = rows_of(&summary);
    let scol = |name: &str| sh.iter().position(|h| h == name).unwrap();
    assert_eq!(groups.len(), 2, "two masses of building 1");
    let mut pounded_somewhere = 0;
    for g in &groups {
        let members: Vec<&Vec<String>> = rows.iter().filter(|r| r[mass] == g[0]).collect();
        let count = |pred: &dyn Fn(&Vec<String>) -> bool| {
            members.iter().filter(|r| pred(r)).count().to_string()
        };
        assert_eq!(g[scol("runs")], members.len().to_string());
        assert_eq!(g[scol("failures")], "0");
        assert_eq!(
            g[scol(&format!("exceed_b2_peak_drift_ratio>{threshold}"))],
            count(&|r| value(r, drift) > threshold)
        );
        let hit = &g[scol("exceed_level_b1f1_b2f1_impacts>0")];
        assert_eq!(*hit, count(&|r| value(r, level) > 0.0));
        pounded_somewhere += hit.parse::<usize>().unwrap();
        for out in ["b2_peak_drift_ratio", "b1_peak_accel_m_s2", "peak_force_n"] {
            let xs: Vec<f64> = members.iter().map(|r| value(r, col(out)).abs()).collect();
            let max = xs.iter().copied().fold(0.0, f64::max);
            let mean = xs.iter().sum::<f64>() / xs.len() as f64;
            assert_eq!(value(g, scol(&format!("{out}_max"))), max, "{out}");
            let m = value(g, scol(&format!("{out}_mean")));
            assert!((m - mean).abs() <= 1e-12 * mean.abs(), "{out}: {m} {mean}");
        }
    }
    assert!(pounded_somewhere > 0, "level 1 must pound in some runs");
    // A column that is not a parameter of this row is refused with the row's own columns.
    let r = sweep(&cfg, &dir.path().join("bad.csv"), &["--aggregate", "t1_s"]);
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(!r.status.success());
    assert!(
        err.contains("`t1_s` is not a swept-parameter column") && err.contains("b2_t1_s"),
        "{err}"
    );
}

/// The row's config with `[sample]` instead of some grid axes.
pub(crate) fn sampled_config() -> String {
    ROW_CONFIG
        .replacen("period_s = 0.25\n", "", 1)
        .replacen("gap_m = 0.008\n", "", 1)
        .replacen("beta_n_per_m1_5 = 2.75e9\n", "", 1)
        .replacen("mass_kg = 2e5\nperiod_s = 0.3", "period_s = 0.3", 1)
        + r#"
[sample]
n = 5
seed = 11
[[sample.axis]]
key = "building[0].period_s"
dist = "uniform"
min = 0.2
max = 0.35
[[sample.axis]]
key = "contact.gap_m"
dist = "lognormal"
median = 0.006
beta = 0.4
max = 0.03
[[sample.axis]]
key = "building[2].mass_kg"
dist = "normal"
mean = 2e5
sd = 3e4
min = 1e5
[[sample.axis]]
key = "contact.beta_n_per_m1_5"
dist = "uniform"
min = 1e9
max = 4e9
"#
}

/// `[sample]` on a row: each run takes the values drawn for its sample (the pair's generator,
/// so the same seed draws the same points), the shared gap goes where no `gap_right_m` is
/// given, the sample number is written; bad sample keys name the key.
#[test]
fn sampled_rows_take_the_drawn_values() {
    use pounding::plan::sample::{draw, Dist, Method};
    let dir = tempdir();
    let cfg = dir.path().join("sampled.toml");
    let text = sampled_config();
    std::fs::write(&cfg, &text).unwrap();
    let plan = pounding::plan::config::load_row_text(&text, &cfg).unwrap();
    // 2 laws x 5 samples x 2 masses x 2 gaps (building 1's) x 2 periods (building 2's).
    assert_eq!(plan.len(), 80);
    let drawn = draw(
        Method::LatinHypercube,
        5,
        &[
            Dist::Uniform {
                min: 0.2,
                max: 0.35,
            },
            Dist::LogNormal {
                median: 0.006,
                beta: 0.4,
                min: f64::NEG_INFINITY,
                max: 0.03,
            },
            Dist::Normal {
                mean: 2e5,
                sd: 3e4,
                min: 1e5,
                max: f64::INFINITY,
            },
            Dist::Uniform { min: 1e9, max: 4e9 },
        ],
        11,
    );
    let out = dir.path().join("sampled.csv");
    ok(&sweep(&cfg, &out, &[]));
    let (header, rows) = rows_of(&out);
    assert_eq!(rows.len(), 80);
    let col = |name: &str| header.iter().position(|h| h == name).unwrap();
    let mut seen = [false; 5];
    for (i, r) in rows.iter().enumerate() {
        let spec = plan.run(i as u64);
        let k: usize = r[col("sample")].parse().unwrap();
        assert_eq!(spec.sample, Some(k));
        seen[k] = true;
        let p = &drawn[k];
        let cell = |name: &str| r[col(name)].parse::<f64>().unwrap();
        assert_eq!(cell("b1_t1_s"), p[0], "run {i}");
        // Building 1 gives its own gap; the shared one is the gap between buildings 2 and 3.
        assert!([0.005, 0.01].contains(&cell("gap_1_2_m")));
        assert_eq!(cell("gap_2_3_m"), p[1], "run {i}");
        assert_eq!(cell("b3_mass_kg"), p[2], "run {i}");
        // The sampled beta is that of Hertz-type laws (both laws here are).
        assert_eq!(cell("beta_n_per_m1_5"), p[3], "run {i}");
        assert_eq!(spec.contact.stiffness, p[3]);
    }
    assert!(seen.iter().all(|&x| x), "every sample is run");

    // Errors name the key and say what was expected.
    let cases = [
        (
            text.replacen(
                "[[building]]\nstoreys = 2\n",
                "[[building]]\nstoreys = 2\nperiod_s = 0.25\n",
                1,
            ),
            "building[0].period_s",
            "is sampled under [sample]",
        ),
        (
            text.replace("building[2].mass_kg", "building[3].mass_kg"),
            "sample.axis[2].key",
            "building[2].mass_kg",
        ),
        (
            text.replace("median = 0.006", "median = -0.006"),
            "sample.axis[1]",
            "median > 0",
        ),
        (
            text.replace("min = 0.2\nmax = 0.35", "min = -0.2\nmax = 0.35"),
            "sample.axis[0] (building[0].period_s)",
            "a period >= 1e-4 s",
        ),
        (
            text.replace(
                "key = \"contact.gap_m\"",
                "key = \"building[2].gap_right_m\"",
            ),
            "building[2].gap_right_m",
            "expected one of",
        ),
    ];
    for (bad, key, what) in cases {
        let f = dir.path().join("bad.toml");
        std::fs::write(&f, &bad).unwrap();
        let r = sweep(&f, &dir.path().join("bad.csv"), &[]);
        let err = String::from_utf8_lossy(&r.stderr);
        assert!(!r.status.success(), "{key}");
        assert!(
            err.contains("bad.toml") && err.contains(key) && err.contains(what),
            "{key}: {err}"
        );
    }
}

/// `--target-error` on a row sweep takes the setting the rows' own calibration gives (the same
/// rows as that setting in the config), records it in the sidecar, and is refused on the GPU in
/// f32, whose error the calibration does not cover; `pound accuracy --target-error` checks it.
#[test]
fn row_target_error_takes_the_rows_calibrated_setting() {
    use pounding::physics::solver::calibration::{for_target_in, Suite};
    let dir = tempdir();
    let cfg = dir.path().join("row.toml");
    std::fs::write(&cfg, ROW_CONFIG).unwrap();
    let chosen = for_target_in(Suite::Rows, 1e-3).unwrap();
    let fixed = dir.path().join("fixed.toml");
    std::fs::write(
        &fixed,
        format!(
            "[run]\nsubsteps_per_contact = {}\n{ROW_CONFIG}",
            chosen.substeps_per_contact
        ),
    )
    .unwrap();
    let (a, b) = (dir.path().join("a.csv"), dir.path().join("b.csv"));
    ok(&sweep(&cfg, &a, &["--target-error", "1e-3"]));
    ok(&sweep(&fixed, &b, &[]));
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
    let default = dir.path().join("default.csv");
    ok(&sweep(&cfg, &default, &[]));
    assert_ne!(
        std::fs::read(&a).unwrap(),
        std::fs::read(&default).unwrap(),
        "the chosen setting is not the default"
    );
    let sidecar = std::fs::read_to_string(pounding::io::provenance::meta_path(&a)).unwrap();
    assert!(
        sidecar.contains("[target_error]")
            && sidecar.contains(&format!("calibrated_p99 = {}", chosen.calibrated_p99)),
        "{sidecar}"
    );
    let r = pound(&[
        "sweep",
        s(&cfg),
        "-o",
        s(&dir.path().join("gpu.csv")),
        "--backend",
        "gpu",
        "--target-error",
        "1e-3",
    ]);
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(
        !r.status.success() && err.contains("--precision f64"),
        "{err}"
    );
    // Below the calibration: refused, naming the rows' suite.
    let r = sweep(&cfg, &dir.path().join("c.csv"), &["--target-error", "1e-9"]);
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(
        !r.status.success() && err.contains("configs/accuracy-rows.toml"),
        "{err}"
    );
}

/// Without `--backend`, a small sweep of rows runs on the CPU, whatever adapter there is, and
/// says why: below 20,000 runs the GPU's kernel build outweighs its speed (BENCHMARKS.md).
#[test]
fn auto_runs_multistorey_rows_on_the_cpu() {
    let dir = tempdir();
    let cfg = dir.path().join("row.toml");
    std::fs::write(&cfg, ROW_CONFIG).unwrap();
    let out = dir.path().join("auto.csv");
    let r = pound(&["sweep", s(&cfg), "-o", s(&out)]);
    ok(&r);
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(
        err.contains("running on the CPU: a row sweep of fewer than 20000 runs"),
        "{err}"
    );
    let meta = std::fs::read_to_string(pounding::io::provenance::meta_path(&out)).unwrap();
    assert!(meta.contains("backend = \"cpu\""), "{meta}");
}

/// One plan's runs from two kernels never meet in one file: shards, or a cut-off sweep, written
/// by a pound that chose another kernel for the scene (a row of two one-storey buildings took
/// the row kernel before it took the pair's) are refused by `pound merge` and `--resume`.
#[test]
fn outputs_of_another_kernel_are_not_merged_or_resumed() {
    let dir = tempdir();
    let cfg = dir.path().join("two.toml");
    let text = std::fs::read_to_string("configs/row-of-two.toml")
        .unwrap()
        .replace("n = 30 }", "n = 6 }");
    std::fs::write(&cfg, text).unwrap();
    let as_row = |meta: &Path| {
        let t = std::fs::read_to_string(meta).unwrap();
        assert!(t.contains("kernel = \"pair\""), "{t}");
        std::fs::write(meta, t.replace("kernel = \"pair\"", "kernel = \"row\"")).unwrap();
    };
    let parts: Vec<_> = (0..2)
        .map(|i| {
            let p = dir.path().join(format!("s{i}.csv"));
            ok(&sweep(&cfg, &p, &["--shard", &format!("{i}/2")]));
            p
        })
        .collect();
    as_row(&pounding::io::atomic::sibling(&parts[1], ".meta.toml"));
    let merged = dir.path().join("merged.csv");
    let r = pound(&["merge", s(&parts[0]), s(&parts[1]), "-o", s(&merged)]);
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(!r.status.success() && err.contains("row kernel"), "{err}");
    assert!(!merged.exists());

    let full = dir.path().join("full.csv");
    ok(&sweep(&cfg, &full, &[]));
    let cut = dir.path().join("cut.csv");
    interrupt(
        &cfg,
        std::fs::metadata(&full).unwrap().len() as usize,
        &cut,
        0.5,
    );
    as_row(&pounding::io::provenance::progress_path(&cut));
    let r = sweep(&cfg, &cut, &["--resume"]);
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(!r.status.success() && err.contains("kernel"), "{err}");
}

/// Class 6: `contact.gap_m` is one gap shared by the pairs it gives, in the grid as under
/// `[sample]`; one value is ignored when every pair has its own (a list refused);
/// `gap_right_m` is a pair's own axis.
#[test]
fn a_shared_gap_means_one_gap() {
    let three = |extra_left: &str| {
        format!(
            "[run]\ntail_s = 0.5\n[[building]]\n{STOREYS3}\n{extra_left}\n[[building]]\n{STOREYS3}\n[[building]]\n{STOREYS3}\n[contact]\nlaw = \"linear\"\nk_n_per_m = 1e9\ngap_m = [0.0, 0.01, 0.02]\n[[record]]\nsynthetic = {{ seed = 1, duration_s = 1.0 }}\n"
        )
    };
    let plan = pounding::plan::config::parse_row(
        &three(""),
        Path::new("t.toml"),
        Path::new("."),
        Path::new("."),
    )
    .unwrap();
    assert_eq!(plan.len(), 3, "one shared axis, not one per pair");
    for i in 0..plan.len() {
        let r = plan.run(i);
        assert_eq!(r.gaps[0], r.gaps[1], "run {i}: {:?}", r.gaps);
    }
    // A pair's own gap_right_m is its own axis, crossed with the shared one.
    let plan = pounding::plan::config::parse_row(
        &three("gap_right_m = [0.05, 0.06]"),
        Path::new("t.toml"),
        Path::new("."),
        Path::new("."),
    )
    .unwrap();
    assert_eq!(plan.len(), 6);
    // Ignored when every pair has its own.
    let all = three("gap_right_m = 0.05")
        .replace(
            &format!("[[building]]\n{STOREYS3}\n[contact]"),
            &format!(
                "[[building]]\n{STOREYS3}\ngap_right_m = 0.0\n[[building]]\n{STOREYS3}\n[contact]"
            ),
        )
        .replacen(
            &format!("[[building]]\n{STOREYS3}\n[[building]]"),
            &format!("[[building]]\n{STOREYS3}\ngap_right_m = 0.01\n[[building]]"),
            1,
        );
    // A list no pair reads would be dropped: refused (`idle_axes`); one value is a leftover.
    let e = pounding::plan::config::parse_row(
        &all,
        Path::new("t.toml"),
        Path::new("."),
        Path::new("."),
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("contact.gap_m: every pair has its own gap_right_m"),
        "{e}"
    );
    let all = all.replace("gap_m = [0.0, 0.01, 0.02]", "gap_m = 0.02");
    let plan = pounding::plan::config::parse_row(
        &all,
        Path::new("t.toml"),
        Path::new("."),
        Path::new("."),
    )
    .unwrap();
    assert!(
        plan.warnings()
            .iter()
            .any(|w| w.contains("contact.gap_m is ignored")),
        "{:?}",
        plan.warnings()
    );
}
