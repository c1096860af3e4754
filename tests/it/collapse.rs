//! P-Delta and collapse (issue 48, physics.md section 10) through the config and the sweep:
//! keys checked by name, P-Delta off (or without gravity) the sweep without it, collapsed runs
//! ended, reported and counted apart, and the GPU's rows agreeing with the CPU's.

use crate::support::cli::stderr;
use crate::support::{ok, pound, table, tempdir};

/// A yielding 3-storey frame with P-Delta (a leaning column: twice its floors' weight) beside
/// an elastic 3-storey building, 6 s of a synthetic record at 5 intensities.
const FRAME: &str = r#"
[run]
tail_s = 2.0

[[building]]
storeys = 3
storey_height_m = 3.5
mass_kg = 3.0e5
period_s = 0.8
damping_ratio = 0.05
yield_drift_ratio = 0.005
post_yield_ratio = 0.02
p_delta = true
gravity_mass_ratio = 2.0
gap_right_m = [0.02]

[[building]]
storeys = 3
storey_height_m = 3.5
mass_kg = 2.5e5
period_s = 0.3
damping_ratio = 0.05

[contact]
law = "linear"
k_n_per_m = 1e9

[[record]]
synthetic = { seed = 3, duration_s = 6.0, dt_s = 0.01, pga_g = 0.4 }

[intensity]
pga_g = [0.2, 0.6, 1.0, 1.5, 2.0]
"#;

fn sweep(dir: &std::path::Path, name: &str, config: &str, extra: &[&str]) -> std::process::Output {
    let cfg = dir.join(format!("{name}.toml"));
    std::fs::write(&cfg, config).unwrap();
    let out = dir.join(format!("{name}.csv"));
    let mut args = vec!["sweep", cfg.to_str().unwrap(), "-o", out.to_str().unwrap()];
    args.extend(extra);
    pound(&args)
}

/// Each key's error names it and what it expects; a building unstable under gravity alone is
/// named with its storey and period.
#[test]
fn p_delta_and_collapse_keys_are_checked_by_name() {
    let dir = tempdir();
    let refused = |name: &str, config: String, words: &[&str]| {
        let o = sweep(dir.path(), name, &config, &[]);
        assert!(!o.status.success(), "{name}: accepted");
        let said = stderr(&o);
        for w in words {
            assert!(said.contains(w), "{name}: `{w}` not in {said}");
        }
    };
    refused(
        "ratio-alone",
        FRAME.replace("p_delta = true\n", ""),
        &[
            "building[0].gravity_mass_ratio",
            "applies with p_delta = true",
        ],
    );
    refused(
        "ratio-high",
        FRAME.replace("gravity_mass_ratio = 2.0", "gravity_mass_ratio = 11"),
        &[
            "building[0].gravity_mass_ratio",
            "11 is out of range",
            "<= 10",
        ],
    );
    refused(
        "ratio-negative",
        FRAME.replace("gravity_mass_ratio = 2.0", "gravity_mass_ratio = -1"),
        &["building[0].gravity_mass_ratio", "-1 is out of range"],
    );
    // theta grows with the period squared: 0.054 at 0.8 s (the frame's, as the sweep
    // reports), so about 1.03 at 3.5 s.
    refused(
        "unstable",
        FRAME.replace("period_s = 0.8", "period_s = [0.8, 3.5]"),
        &[
            "building[0].p_delta",
            "storey 1 is unstable under gravity alone at period_s = 3.5",
            "stability coefficient",
        ],
    );
    for bad in ["0", "1.5", "-0.1", "\"never\""] {
        refused(
            &format!("limit-{}", bad.trim_matches('"')),
            FRAME.replace(
                "tail_s = 2.0",
                &format!("tail_s = 2.0\ncollapse_drift_ratio = {bad}"),
            ),
            &[
                "run.collapse_drift_ratio",
                "expected a drift ratio > 0 and <= 1",
                "\"none\"",
            ],
        );
    }
    let pair = std::fs::read_to_string("configs/quickstart.toml").unwrap();
    let pair = if pair.contains("[run]") {
        pair.replace("[run]", "[run]\ncollapse_drift_ratio = 0.1")
    } else {
        format!("[run]\ncollapse_drift_ratio = 0.1\n{pair}")
    };
    refused(
        "pair",
        pair,
        &[
            "run.collapse_drift_ratio",
            "no storey height",
            "[[building]]",
        ],
    );
}

/// `p_delta = false`, and P-Delta with no gravity load (`gravity_mass_ratio = 0`), are the
/// sweep without P-Delta, cell for cell (the latter adds its stability coefficient, 0).
#[test]
fn p_delta_off_or_weightless_is_the_sweep_without_it() {
    let dir = tempdir();
    let without = FRAME.replace("p_delta = true\ngravity_mass_ratio = 2.0\n", "");
    ok(&sweep(dir.path(), "without", &without, &[]));
    ok(&sweep(
        dir.path(),
        "off",
        &FRAME.replace(
            "p_delta = true\ngravity_mass_ratio = 2.0\n",
            "p_delta = false\n",
        ),
        &[],
    ));
    ok(&sweep(
        dir.path(),
        "weightless",
        &FRAME.replace("gravity_mass_ratio = 2.0", "gravity_mass_ratio = 0"),
        &[],
    ));
    let read = |n: &str| std::fs::read_to_string(dir.path().join(format!("{n}.csv"))).unwrap();
    assert_eq!(read("off"), read("without"));
    let (base, zero) = (
        table(&dir.path().join("without.csv")),
        table(&dir.path().join("weightless.csv")),
    );
    assert_eq!(base.len(), 5);
    for (a, b) in base.iter().zip(&zero) {
        assert_eq!(b["b1_stability_coefficient"], "0");
        for (k, v) in a {
            assert_eq!(&b[k], v, "{k}");
        }
        assert_eq!(b.len(), a.len() + 1);
    }
    // With its gravity the frame leans: it drifts further, and the strong runs collapse.
    ok(&sweep(dir.path(), "leaning", FRAME, &[]));
    let leaning = table(&dir.path().join("leaning.csv"));
    let f = |r: &std::collections::HashMap<String, String>, c: &str| r[c].parse::<f64>().unwrap();
    assert!(f(&leaning[0], "b1_peak_drift_ratio") > f(&base[0], "b1_peak_drift_ratio"));
    assert!(f(&leaning[0], "b1_stability_coefficient") > 0.05);
}

/// A run whose storey reaches the collapse drift ratio ends there: status `collapsed`, its
/// time, building and storey, the peak drift ratio the limit, no residual drift. Sweeps count
/// collapsed runs apart from failures, `--aggregate` as exceeding every threshold; with
/// `collapse_drift_ratio = "none"` the same runs go on past it, with a warning.
#[test]
fn collapsed_runs_end_at_the_limit_and_are_counted_apart() {
    let dir = tempdir();
    let o = sweep(dir.path(), "frame", FRAME, &[]);
    ok(&o);
    let rows = table(&dir.path().join("frame.csv"));
    let collapsed: Vec<_> = rows.iter().filter(|r| r["status"] == "collapsed").collect();
    assert!(
        !collapsed.is_empty() && collapsed.len() < rows.len(),
        "the test needs runs that collapse and runs that do not"
    );
    for r in &rows {
        let drift: f64 = r["b1_peak_drift_ratio"].parse().unwrap();
        if r["status"] == "collapsed" {
            let t: f64 = r["collapse_time_s"].parse().unwrap();
            assert!(t > 0.0 && t < 8.0, "{t}");
            assert_eq!(r["collapse_building"], "1");
            assert!((1..=3).contains(&r["collapse_storey"].parse::<u32>().unwrap()));
            assert!((drift - 0.1).abs() < 1e-9, "{drift}");
            assert_eq!(r["b1_residual_drift_ratio"], "");
            // No residual, so no storey of it.
            assert_eq!(r["b1_residual_storey"], "");
        } else {
            assert_eq!(r["status"], "ok");
            assert!(drift < 0.1);
            assert_eq!(r["collapse_time_s"], "");
            assert_eq!(r["collapse_storey"], "");
        }
    }
    let said = stderr(&o);
    assert!(
        said.contains(&format!("{} collapsed, 0 failures", collapsed.len())),
        "{said}"
    );
    assert!(!said.contains("past a drift ratio"), "{said}");
    // The summary: collapsed counted per group and in every --exceed; statistics over the
    // runs that stand.
    let summary = dir.path().join("summary.csv");
    ok(&pound(&[
        "sweep",
        dir.path().join("frame.toml").to_str().unwrap(),
        "--aggregate",
        "gap_1_2_m",
        "--exceed",
        "b1_peak_drift_ratio=0.05",
        "-o",
        summary.to_str().unwrap(),
    ]));
    let s = &table(&summary)[0];
    assert_eq!(s["runs"], "5");
    assert_eq!(s["failures"], "0");
    assert_eq!(s["collapsed"], collapsed.len().to_string());
    let past_5 = rows
        .iter()
        .filter(|r| r["b1_peak_drift_ratio"].parse::<f64>().unwrap() > 0.05)
        .count();
    assert_eq!(s["exceed_b1_peak_drift_ratio>0.05"], past_5.to_string());
    let standing_max = rows
        .iter()
        .filter(|r| r["status"] == "ok")
        .map(|r| r["b1_peak_drift_ratio"].parse::<f64>().unwrap())
        .fold(0.0, f64::max);
    let max: f64 = s["b1_peak_drift_ratio_max"].parse().unwrap();
    assert!(
        (max - standing_max).abs() < 1e-12 * standing_max,
        "{max} {standing_max}"
    );
    // No collapse criterion: the runs go on, and the end-of-sweep warning counts them.
    let o = sweep(
        dir.path(),
        "none",
        &FRAME.replace(
            "tail_s = 2.0",
            "tail_s = 2.0\ncollapse_drift_ratio = \"none\"",
        ),
        &[],
    );
    ok(&o);
    let none = table(&dir.path().join("none.csv"));
    assert!(none.iter().all(|r| r["status"] == "ok"));
    assert!(!none[0].contains_key("collapse_time_s"));
    let past = none
        .iter()
        .filter(|r| r["b1_peak_drift_ratio"].parse::<f64>().unwrap() > 0.1)
        .count();
    assert!(past >= collapsed.len());
    assert!(
        stderr(&o).contains(&format!(
            "warning: {past} runs have a storey past a drift ratio of 0.1 without collapsing"
        )),
        "{}",
        stderr(&o)
    );
    // A lower limit collapses more runs, sooner.
    ok(&sweep(
        dir.path(),
        "low",
        &FRAME.replace("tail_s = 2.0", "tail_s = 2.0\ncollapse_drift_ratio = 0.05"),
        &[],
    ));
    let low = table(&dir.path().join("low.csv"));
    for (a, b) in rows.iter().zip(&low) {
        if a["status"] == "collapsed" {
            assert_eq!(b["status"], "collapsed");
            let (ta, tb): (f64, f64) = (
                a["collapse_time_s"].parse().unwrap(),
                b["collapse_time_s"].parse().unwrap(),
            );
            assert!(tb < ta, "{tb} {ta}");
        }
    }
    assert!(low.iter().filter(|r| r["status"] == "collapsed").count() >= collapsed.len());
}

/// The GPU row kernel runs P-Delta buildings as the CPU does: a yielding frame whose Rayleigh
/// damping on `K0` couples its modes (its storeys lean unequally) settles about the static
/// drifts gravity holds, with the CPU's impacts, peaks and residual drifts; a run that reaches
/// the collapse limit is run again on the CPU, which ends it there: the CPU's row exactly.
#[test]
fn the_gpu_runs_p_delta_as_the_cpu_and_hands_collapses_to_the_cpu() {
    if crate::support::gpu::ctx().is_none() {
        return;
    }
    let dir = tempdir();
    // A yielding 2-storey P-Delta frame (Rayleigh) beside a 1-storey building (small enough
    // for lavapipe's loop limit).
    let leaning = FRAME
        .replace(
            "storeys = 3\nstorey_height_m = 3.5\nmass_kg = 3.0e5",
            "storeys = 2\nstorey_height_m = 3.5\nmass_kg = 3.0e5",
        )
        .replace(
            "storeys = 3\nstorey_height_m = 3.5\nmass_kg = 2.5e5",
            "storeys = 1\nstorey_height_m = 3.5\nmass_kg = 2.5e5",
        )
        .replace("duration_s = 6.0", "duration_s = 4.0")
        .replace("pga_g = [0.2, 0.6, 1.0, 1.5, 2.0]", "pga_g = [0.3, 0.6]");
    ok(&sweep(
        dir.path(),
        "lean-cpu",
        &leaning,
        &["--backend", "cpu"],
    ));
    ok(&sweep(
        dir.path(),
        "lean-gpu",
        &leaning,
        &["--backend", "gpu", "--precision", "f64"],
    ));
    let (cpu, gpu) = (
        table(&dir.path().join("lean-cpu.csv")),
        table(&dir.path().join("lean-gpu.csv")),
    );
    assert_eq!(cpu.len(), gpu.len());
    let mut standing = 0;
    for (c, g) in cpu.iter().zip(&gpu) {
        assert_eq!(c["status"], g["status"]);
        assert_eq!(c["impacts"], g["impacts"]);
        if c["status"] == "collapsed" {
            assert_eq!(c, g, "a collapse is the CPU's run");
            continue;
        }
        assert_eq!(c["status"], "ok");
        standing += 1;
        assert!(c["impacts"].parse::<u64>().unwrap() > 0, "the runs pound");
        let residual: f64 = c["b1_residual_drift_ratio"].parse().unwrap();
        assert!(residual.abs() > 1e-4, "the frame yields: {residual}");
        for k in [
            "b1_peak_drift_ratio",
            "b1_residual_drift_ratio",
            "b1_peak_ductility",
            "b1_peak_roof_m",
            "b2_peak_roof_m",
            "peak_force_n",
        ] {
            let (a, b): (f64, f64) = (c[k].parse().unwrap(), g[k].parse().unwrap());
            assert!((a - b).abs() <= 1e-6 * a.abs(), "{k}: {a} {b}");
        }
    }
    assert!(standing > 0, "the test needs a run that stands");
    // An elastic 2-storey P-Delta frame beside a 1-storey building; a low collapse limit
    // (0.5 % drift) that the strong run reaches.
    let elastic = FRAME
        .replace("yield_drift_ratio = 0.005\npost_yield_ratio = 0.02\n", "")
        .replace(
            "storeys = 3\nstorey_height_m = 3.5\nmass_kg = 2.5e5",
            "storeys = 1\nstorey_height_m = 3.5\nmass_kg = 2.5e5",
        )
        .replace(
            "storeys = 3\nstorey_height_m = 3.5\nmass_kg = 3.0e5",
            "storeys = 2\nstorey_height_m = 3.5\nmass_kg = 3.0e5",
        )
        .replace("tail_s = 2.0", "tail_s = 1.0\ncollapse_drift_ratio = 0.005")
        .replace(
            "period_s = 0.8\ndamping_ratio = 0.05",
            "period_s = 0.8\ndamping_ratio = 0.05\ndamping = \"modal\"",
        )
        .replace("duration_s = 6.0", "duration_s = 4.0")
        .replace("pga_g = [0.2, 0.6, 1.0, 1.5, 2.0]", "pga_g = [0.02, 1.0]");
    ok(&sweep(dir.path(), "cpu", &elastic, &["--backend", "cpu"]));
    ok(&sweep(
        dir.path(),
        "gpu",
        &elastic,
        &["--backend", "gpu", "--precision", "f64"],
    ));
    let (cpu, gpu) = (
        table(&dir.path().join("cpu.csv")),
        table(&dir.path().join("gpu.csv")),
    );
    assert_eq!(cpu[0]["status"], "ok", "the test needs a run that stands");
    assert_eq!(cpu[1]["status"], "collapsed", "the test needs a collapse");
    assert_eq!(cpu[1], gpu[1], "a collapse is the CPU's run");
    assert_eq!(gpu[0]["status"], "ok");
    assert!(cpu[0]["b1_stability_coefficient"].parse::<f64>().unwrap() > 0.01);
    for c in [
        "b1_peak_drift_ratio",
        "b1_peak_roof_m",
        "b2_peak_roof_m",
        "peak_force_n",
    ] {
        let (a, b): (f64, f64) = (cpu[0][c].parse().unwrap(), gpu[0][c].parse().unwrap());
        assert!((a - b).abs() <= 1e-5 * a.abs(), "{c}: {a} {b}");
    }
}

/// A `[[building]]` list of one is a scene (the no-pounding baseline): no `[contact]` needed,
/// no gap or level columns, the same motion as the building beside a neighbour too far to
/// touch; the gap study refuses it by name, and two buildings still need `[contact]`.
#[test]
fn a_building_alone_is_a_scene() {
    let dir = tempdir();
    let frame_end = FRAME
        .find("[[building]]\nstoreys = 3\nstorey_height_m = 3.5\nmass_kg = 2.5e5")
        .unwrap();
    let record_at = FRAME.find("[[record]]").unwrap();
    let alone = format!(
        "{}{}",
        &FRAME[..frame_end].replace("gap_right_m = [0.02]\n", ""),
        &FRAME[record_at..]
    );
    assert!(!alone.contains("[contact]"));
    let o = sweep(dir.path(), "alone", &alone, &[]);
    ok(&o);
    assert!(
        stderr(&o)
            .contains("one building alone (3 storeys; yielding storeys in building 1; P-Delta)"),
        "{}",
        stderr(&o)
    );
    let far = FRAME.replace("gap_right_m = [0.02]", "gap_right_m = [100.0]");
    ok(&sweep(dir.path(), "far", &far, &[]));
    let (a, f) = (
        table(&dir.path().join("alone.csv")),
        table(&dir.path().join("far.csv")),
    );
    assert_eq!(a.len(), 5);
    assert!(!a[0].contains_key("gap_1_2_m") && !a[0].contains_key("b2_peak_roof_m"));
    assert!(a.iter().any(|r| r["status"] == "collapsed"));
    for (x, y) in a.iter().zip(&f) {
        assert_eq!(x["status"], y["status"]);
        assert_eq!(x["impacts"], "0");
        assert_eq!(x["contact_time_s"], "0");
        for c in [
            "b1_peak_drift_ratio",
            "b1_peak_roof_m",
            "collapse_time_s",
            "b1_residual_drift_ratio",
        ] {
            if x[c].is_empty() {
                assert!(y[c].is_empty(), "{c}");
                continue;
            }
            let (p, q): (f64, f64) = (x[c].parse().unwrap(), y[c].parse().unwrap());
            assert!(
                (p - q).abs() <= 1e-4 * p.abs(),
                "{c}: alone {p}, beside a far neighbour {q}"
            );
        }
    }
    let cfg = dir.path().join("alone.toml");
    let g = pound(&[
        "gap",
        cfg.to_str().unwrap(),
        "-o",
        dir.path().join("g.csv").to_str().unwrap(),
    ]);
    assert!(!g.status.success());
    assert!(
        stderr(&g).contains("one building stands alone"),
        "{}",
        stderr(&g)
    );
    let contact_at = FRAME.find("[contact]").unwrap();
    let no_contact = format!("{}{}", &FRAME[..contact_at], &FRAME[record_at..]);
    let o = sweep(dir.path(), "two", &no_contact, &[]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("contact: missing"), "{}", stderr(&o));
}

/// The README's worked example says how many runs collapse beside the neighbour and alone:
/// what the two sweeps give now.
#[test]
fn the_readme_counts_the_collapses_its_commands_give() {
    let dir = tempdir();
    let mut counts = Vec::new();
    for c in ["collapse-ida", "collapse-ida-alone"] {
        let out = dir.path().join(format!("{c}.csv"));
        ok(&pound(&[
            "sweep",
            &format!("configs/{c}.toml"),
            "-o",
            out.to_str().unwrap(),
        ]));
        let rows = table(&out);
        assert_eq!(rows.len(), 50);
        counts.push(rows.iter().filter(|r| r["status"] == "collapsed").count());
    }
    let readme = std::fs::read_to_string("README.md").unwrap();
    let said = format!("(50 runs each, {} and {} collapse)", counts[0], counts[1]);
    assert!(readme.contains(&said), "README.md does not say `{said}`");
}
