//! What IMK storeys add to a sweep's outputs (issue 67, item 3): each IMK building's weakest
//! strength ratio and its capped storeys (`bk_strength_ratio`, `bk_capped_storeys`), each IMK
//! storey's own (`bk_sj_strength_ratio`, `bk_sj_capped`) where `--columns` asks for one, their
//! meanings in `pound columns`, and an IMK storey's drift, force and branch in `pound trace`.
//! A bilinear building has none of them.

use crate::support::{ok, pound, sweep_cpu, table, tempdir};
use std::collections::HashMap;
use std::path::Path;

/// Storey height, m; yield drift ratio, post-yield ratio and IMK theta_p of building 1's storeys.
const H: f64 = 3.5;
const THETA_Y: f64 = 0.005;
const B: f64 = 0.03;
const THETA_P: f64 = 0.01;

/// A 3-storey IMK frame (`rule`) beside a 2-storey bilinear building, one gap, three intensities
/// (the strongest takes the frame well past capping).
fn config(rule: &str) -> String {
    format!(
        r#"
[run]
tail_s = 1.0

[[building]]
storeys = 3
storey_height_m = {H}
mass_kg = 3.0e5
period_s = 0.6
damping_ratio = 0.05
yield_drift_ratio = {THETA_Y}
post_yield_ratio = {B}
hysteresis = "{rule}"
plastic_drift_ratio = {THETA_P}
post_capping_drift_ratio = 0.08
residual_strength_ratio = 0.2
energy_capacity_ratio = 30
gap_right_m = 0.01

[[building]]
storeys = 2
storey_height_m = 3.5
mass_kg = 2.0e5
period_s = 0.3
damping_ratio = 0.05
yield_drift_ratio = 0.004
post_yield_ratio = 0.02

[contact]
law = "nonlinear_viscoelastic"
formula = "ebrahimi"
e = 0.65
beta_n_per_m1_5 = 2.75e9

[[record]]
synthetic = {{ seed = 11, duration_s = 6.0, dt_s = 0.01, pga_g = 0.35 }}

[intensity]
pga_g = [0.1, 0.5, 1.2]
"#
    )
}

/// The config with building 1's storeys bilinear: no IMK keys.
fn bilinear() -> String {
    let text = config("bilinear");
    (text.lines())
        .filter(|l| {
            ![
                "hysteresis",
                "plastic_drift_ratio",
                "post_capping",
                "residual_strength",
                "energy_capacity",
            ]
            .iter()
            .any(|k| l.starts_with(k))
        })
        .collect::<Vec<_>>()
        .join("\n")
}

fn write(dir: &Path, name: &str, text: &str) -> std::path::PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

fn header(path: &Path) -> Vec<String> {
    let text = std::fs::read_to_string(path).unwrap();
    text.lines()
        .next()
        .unwrap()
        .split(',')
        .map(String::from)
        .collect()
}

fn num(row: &HashMap<String, String>, c: &str) -> f64 {
    row[c]
        .parse()
        .unwrap_or_else(|_| panic!("{c}: {:?}", row[c]))
}

#[test]
fn an_imk_sweep_writes_strength_ratios_and_capped_storeys_in_range() {
    let dir = tempdir();
    for rule in ["imk_bilinear", "imk_peak_oriented"] {
        let cfg = write(dir.path(), &format!("{rule}.toml"), &config(rule));
        let out = dir.path().join(format!("{rule}.csv"));
        let mut columns = header_of(&cfg);
        let storey_columns = ["peak_ductility", "strength_ratio", "capped"];
        columns.extend((1..=3).flat_map(|j| storey_columns.map(|c| format!("b1_s{j}_{c}"))));
        ok(&sweep_cpu(&cfg, &out, &[]));
        let h = header(&out);
        // The IMK building's columns follow its yielding ones; the bilinear one has none.
        let at = |c: &str| {
            h.iter()
                .position(|x| x == c)
                .unwrap_or_else(|| panic!("{c}"))
        };
        assert_eq!(at("b1_strength_ratio"), at("b1_yielded_storeys") + 1);
        assert_eq!(at("b1_capped_storeys"), at("b1_yielded_storeys") + 2);
        assert!(h.iter().any(|c| c == "b2_yielded_storeys"));
        assert!(!h
            .iter()
            .any(|c| c.starts_with("b2_") && c.contains("capped")));
        assert!(!h
            .iter()
            .any(|c| c.starts_with("b2_") && c.ends_with("_strength_ratio")));
        // Without `--columns` asking for a storey's, none of the storeys' are written.
        assert!(!h.iter().any(|c| c.starts_with("b1_s1_")));

        // With every storey's columns.
        let each = dir.path().join(format!("{rule}-storeys.csv"));
        ok(&sweep_cpu(&cfg, &each, &["--columns", &columns.join(",")]));
        let h = header(&each);
        assert!(h.iter().any(|c| c == "b1_s3_capped"));
        let rows = table(&each);
        assert_eq!(rows.len(), 3);
        let mut capped_runs = 0;
        for r in &rows {
            assert_eq!(r["status"], "ok", "{rule} {r:?}");
            let ratio = num(r, "b1_strength_ratio");
            assert!((0.0..=1.0).contains(&ratio), "{rule}: {ratio}");
            let capped = &r["b1_capped_storeys"];
            let capped: u32 = capped.parse().unwrap_or_else(|_| panic!("{capped}"));
            assert!(capped <= 3);
            // The building's are gathered from its storeys': the smallest ratio, the count.
            let storey = |j: usize, c: &str| num(r, &format!("b1_s{j}_{c}"));
            let smallest = (1..=3)
                .map(|j| storey(j, "strength_ratio"))
                .fold(1.0, f64::min);
            assert_eq!(ratio, smallest, "{rule}");
            let flags: Vec<f64> = (1..=3).map(|j| storey(j, "capped")).collect();
            assert!(flags.iter().all(|&f| f == 0.0 || f == 1.0), "{flags:?}");
            assert_eq!(flags.iter().sum::<f64>(), capped as f64);
            for j in 1..=3 {
                let s = storey(j, "strength_ratio");
                assert!((0.0..=1.0).contains(&s), "{rule} storey {j}: {s}");
                // A storey that lost strength has left its elastic line; one that kept it all
                // and passed capping cannot have (capping starts the loss of strength).
                if s < 1.0 {
                    assert!(storey(j, "peak_ductility") > 1.0, "{rule} storey {j}");
                }
            }
            capped_runs += (capped > 0) as u32;
        }
        // The weakest shaking stays elastic, the strongest passes capping.
        assert_eq!(num(&rows[0], "b1_strength_ratio"), 1.0, "{rule}");
        assert_eq!(rows[0]["b1_capped_storeys"], "0");
        assert!(num(&rows[2], "b1_capped_storeys") >= 1.0, "{rule}");
        assert!(num(&rows[2], "b1_strength_ratio") < 1.0, "{rule}");
        assert!(capped_runs >= 1);
    }
}

/// The sweep's parameter and status columns as `--columns` would name them.
fn header_of(cfg: &Path) -> Vec<String> {
    let said = ok(&pound(&["columns", cfg.to_str().unwrap()]));
    (said.lines())
        .filter_map(|l| {
            l.strip_prefix("| `")?
                .split_once('`')
                .map(|(c, _)| c.to_string())
        })
        .filter(|c| !c.starts_with("level_"))
        .collect()
}

#[test]
fn a_bilinear_sweep_has_no_imk_columns() {
    let dir = tempdir();
    let cfg = write(dir.path(), "bilinear.toml", &bilinear());
    let out = dir.path().join("bilinear.csv");
    let mut columns = header_of(&cfg);
    columns.push("b1_s1_peak_ductility".into());
    ok(&sweep_cpu(&cfg, &out, &["--columns", &columns.join(",")]));
    let h = header(&out);
    assert!(h.iter().any(|c| c == "b1_yielded_storeys"), "{h:?}");
    assert!(h.iter().any(|c| c == "b1_s1_peak_ductility"), "{h:?}");
    for c in &h {
        assert!(
            !c.ends_with("capped_storeys") && !c.ends_with("_capped"),
            "{c}"
        );
        assert!(!c.ends_with("_strength_ratio"), "{c}");
    }
    // Asking for an IMK column of a bilinear storey names no column it writes.
    let asked = sweep_cpu(&cfg, &out, &["--columns", "run,b1_s1_strength_ratio"]);
    assert!(!asked.status.success());
}

#[test]
fn pound_columns_gives_the_imk_columns_their_meanings() {
    let dir = tempdir();
    let cfg = write(dir.path(), "imk.toml", &config("imk_peak_oriented"));
    let said = ok(&pound(&["columns", cfg.to_str().unwrap()]));
    let line = |c: &str| -> String {
        let key = format!("| `{c}` |");
        (said.lines())
            .find(|l| l.starts_with(&key))
            .unwrap_or_else(|| panic!("{c} in\n{said}"))
            .to_string()
    };
    let ratio = line("b1_strength_ratio");
    assert!(
        ratio.contains("capping strength") && ratio.contains("[0, 1]"),
        "{ratio}"
    );
    let capped = line("b1_capped_storeys");
    assert!(capped.contains("capping point"), "{capped}");
    assert!(!said.contains("b2_strength_ratio") && !said.contains("b2_capped"));
    use pounding::plan::columns::meaning::meaning;
    for c in ["b1_s2_strength_ratio", "b1_s2_capped"] {
        let m = meaning(c).unwrap_or_else(|| panic!("{c}"));
        assert!(m.text.contains("storey 2 of building 1"), "{c}: {}", m.text);
        assert!(pounding::plan::row::RowPlan::asks_storey_columns(c), "{c}");
    }
    assert!(pounding::io::parquet::kind("b1_s2_capped") == pounding::io::parquet::Kind::Int);
    assert!(pounding::io::parquet::kind("b1_capped_storeys") == pounding::io::parquet::Kind::Int);
    assert!(pounding::io::parquet::kind("b1_strength_ratio") == pounding::io::parquet::Kind::Real);
}

/// The initial backbone's force on the side of a positive force at drift `x` (negative: the
/// other side's drift) of a storey of stiffness `k`: the hardening line up to capping, which
/// `IMKBilin` follows wherever a reloading meets it (below the yield drift, even beyond zero
/// drift after a large excursion the other way), held above the residual strength; then the
/// post-capping line down to the residual strength.
fn backbone(k: f64, x: f64) -> f64 {
    let (dy, dp, dpc) = (THETA_Y * H, THETA_P * H, 0.08 * H);
    let fy = k * dy;
    let fcap = fy + B * k * dp;
    let line = if x <= dy + dp {
        fy + B * k * (x - dy)
    } else {
        fcap - fcap / dpc * (x - dy - dp)
    };
    line.max(0.2 * fy)
}

#[test]
fn pound_trace_gives_each_imk_storey_its_drift_force_and_branch() {
    let dir = tempdir();
    let branches = [
        "elastic",
        "unloading",
        "reloading_local",
        "reloading_global",
        "backbone",
        "collapsed",
    ];
    for rule in ["imk_bilinear", "imk_peak_oriented"] {
        let cfg = write(dir.path(), &format!("{rule}.toml"), &config(rule));
        let out = dir.path().join(format!("{rule}-trace.csv"));
        ok(&pound(&[
            "trace",
            cfg.to_str().unwrap(),
            "--run",
            "2",
            "-o",
            out.to_str().unwrap(),
        ]));
        let h = header(&out);
        for j in 1..=3 {
            for c in ["drift_m", "force_n", "branch"] {
                let name = format!("b1_s{j}_{c}");
                assert!(h.contains(&name), "{name}");
            }
        }
        // The bilinear building's storeys have their yielding columns only.
        assert!(h.iter().any(|c| c == "b2_s1_shear_n"));
        assert!(!h
            .iter()
            .any(|c| c.starts_with("b2_") && c.ends_with("_branch")));
        let rows = table(&out);
        assert!(rows.len() > 100);
        for j in 1..=3 {
            let col = |c: &str| format!("b1_s{j}_{c}");
            // The storey's stiffness from its elastic line.
            let k = (rows.iter())
                .find(|r| r[&col("branch")] == "elastic" && num(r, &col("drift_m")) != 0.0)
                .map(|r| num(r, &col("force_n")) / num(r, &col("drift_m")))
                .expect("an elastic sample");
            let fcap = k * THETA_Y * H * (1.0 + B * THETA_P / THETA_Y);
            let mut seen = std::collections::BTreeSet::new();
            for r in &rows {
                let branch = r[&col("branch")].as_str();
                assert!(branches.contains(&branch), "{rule}: {branch}");
                seen.insert(branch.to_string());
                let (d, f) = (num(r, &col("drift_m")), num(r, &col("force_n")));
                // The drift is the drift ratio's; the force the storey's shear.
                assert!((d - num(r, &col("drift_ratio")) * H).abs() <= 1e-12 * H);
                let shear = num(r, &col("shear_n"));
                assert!((f - shear).abs() <= 1e-6 * fcap, "{rule} {f} {shear}");
                // Never above the capping strength, nor beyond the initial backbone on the
                // force's side (deterioration only lowers it).
                assert!(
                    f.abs() <= fcap * (1.0 + 1e-9),
                    "{rule} storey {j}: {f} > {fcap}"
                );
                let bound = backbone(k, d * f.signum());
                assert!(
                    f.abs() <= bound + 1e-6 * fcap,
                    "{rule} storey {j} at {d} m ({branch}): {f} beyond the backbone's {bound}"
                );
            }
            assert!(
                seen.contains("elastic") && seen.contains("unloading"),
                "{seen:?}"
            );
        }
    }
}
