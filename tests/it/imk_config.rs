//! IMK storeys from a config (issue 67, physics.md section 13): `hysteresis` and the IMK keys
//! decoded into each run's `Yielding::deterioration` (a number, a list per storey, an axis),
//! each bound and missing key refused with its key named, swept keys as sweep dimensions and
//! parameter columns, and a bilinear building left with no deterioration. The physics of the
//! IMK storey is tested with the solver; these test the plan.

use crate::support::{ok, pound, sweep_cpu, table, tempdir};
use pounding::physics::shear::{Deterioration, ImkRule};
use pounding::plan::row::RowPlan;
use std::path::Path;

/// Two buildings: a 2-storey one whose strength is a yield drift of 0.005, whose IMK keys
/// `imk` gives, and a one-storey bilinear one with a yield force. One record, two gaps.
fn config(imk: &str) -> String {
    format!(
        r#"
[[building]]
storeys = 2
storey_height_m = 3.5
mass_kg = 4.0e5
period_s = 0.6
damping_ratio = 0.05
yield_drift_ratio = 0.005
post_yield_ratio = 0.02
{imk}
gap_right_m = [0.01, 0.02]

[[building]]
storeys = 1
storey_height_m = 3.5
mass_kg = 2.0e5
period_s = 0.3
damping_ratio = 0.05
yield_force_n = 1e6

[contact]
law = "nonlinear_viscoelastic"
formula = "ebrahimi"
e = 0.65
beta_n_per_m1_5 = 2.75e9

[[record]]
synthetic = {{ seed = 11, duration_s = 2.0, dt_s = 0.01, pga_g = 0.35 }}
"#
    )
}

fn plan(text: &str) -> RowPlan {
    pounding::plan::config::load_row_text(text, Path::new("imk.toml")).unwrap()
}

/// The storeys of building `b` in run `i` of `plan`, as the solver gets them.
fn deterioration(plan: &RowPlan, i: u64, b: usize) -> Option<Deterioration> {
    let row = plan.row(&plan.run(i));
    row.buildings[b].yielding.clone()?.deterioration
}

/// The error `pound sweep` gives for `text`, which must name every one of `expect`.
fn fails(text: &str, expect: &[&str]) {
    let dir = tempdir();
    let cfg = dir.path().join("bad.toml");
    std::fs::write(&cfg, text).unwrap();
    let out = pound(&["sweep", cfg.to_str().unwrap(), "-o", "/dev/null"]);
    assert!(!out.status.success(), "{text}");
    let err = String::from_utf8_lossy(&out.stderr);
    for e in expect {
        assert!(err.contains(e), "{e:?} not in {err}");
    }
}

const IMK: &str = "hysteresis = \"imk_peak_oriented\"
plastic_drift_ratio = 0.03
post_capping_drift_ratio = [0.1, 0.12]";

/// A bilinear building (`hysteresis` absent or `"bilinear"`) has no deterioration and the
/// plan of its config is the plan without the key; an IMK one has its values, the defaults
/// (`kappa` 0, no ultimate drift, no cyclic deterioration) where keys are left out.
#[test]
fn keys_reach_the_storeys() {
    let bilinear = plan(&config(""));
    assert_eq!(deterioration(&bilinear, 0, 0), None);
    assert_eq!(deterioration(&bilinear, 0, 1), None);
    let said = plan(&config("hysteresis = \"bilinear\""));
    assert_eq!(
        format!("{:?}", said.yielding),
        format!("{:?}", bilinear.yielding)
    );
    assert_eq!(deterioration(&said, 0, 0), None);

    let imk = plan(&config(IMK));
    assert_eq!(
        deterioration(&imk, 0, 0),
        Some(Deterioration {
            rule: ImkRule::PeakOriented,
            plastic: vec![0.03, 0.03],
            post_capping: vec![0.1, 0.12],
            residual: vec![0.0, 0.0],
            ultimate: vec![f64::INFINITY, f64::INFINITY],
            energy: None,
        })
    );
    assert_eq!(deterioration(&imk, 0, 1), None);
    assert_eq!(imk.len(), bilinear.len());

    let all = plan(&config(
        "hysteresis = \"imk_bilinear\"
plastic_drift_ratio = [0.03, 0.02]
post_capping_drift_ratio = 0.1
residual_strength_ratio = [0.2, 0.1]
ultimate_drift_ratio = [0.1, 0.08]
energy_capacity_ratio = [50, 80]",
    ));
    let d = deterioration(&all, 1, 0).unwrap();
    assert_eq!(d.rule, ImkRule::Bilinear);
    assert_eq!(d.plastic, vec![0.03, 0.02]);
    assert_eq!(d.post_capping, vec![0.1, 0.1]);
    assert_eq!(d.residual, vec![0.2, 0.1]);
    assert_eq!(d.ultimate, vec![0.1, 0.08]);
    assert_eq!(d.energy, Some(vec![50.0, 80.0]));

    // A strength from a yield force or a base-shear coefficient takes IMK storeys too.
    let forced = config(IMK)
        .replace("yield_drift_ratio = 0.005", "yield_force_n = [2e6, 1.5e6]")
        .replace(
            "post_capping_drift_ratio = [0.1, 0.12]",
            "post_capping_drift_ratio = 0.1\nultimate_drift_ratio = 0.05",
        );
    let d = deterioration(&plan(&forced), 0, 0).unwrap();
    assert_eq!(d.ultimate, vec![0.05, 0.05]);
    let shear = forced.replace(
        "yield_force_n = [2e6, 1.5e6]",
        "yield_base_shear_coefficient = [0.1, 0.2]",
    );
    let p = plan(&shear);
    assert_eq!(p.len(), 2 * 2);
    assert!(deterioration(&p, 3, 0).is_some());
}

/// An IMK key given as a range table is a sweep dimension (innermost after the building's
/// strength, in the keys' order) and a parameter column `bk_<key>`; each run's storeys take
/// its value, every storey alike.
#[test]
fn axes_sweep_and_are_columns() {
    let text = config(
        "hysteresis = \"imk_bilinear\"
plastic_drift_ratio = { from = 0.02, to = 0.04, n = 3 }
post_capping_drift_ratio = { from = 0.1, to = 0.2, n = 2 }
residual_strength_ratio = { from = 0.0, to = 0.2, n = 2 }
ultimate_drift_ratio = { from = 0.3, to = 0.4, n = 2 }
energy_capacity_ratio = { from = 20, to = 100, n = 3 }",
    );
    let p = plan(&text);
    assert_eq!(p.len(), 2 * 3 * 2 * 2 * 2 * 3);
    let last = deterioration(&p, p.len() - 1, 0).unwrap();
    assert_eq!(last.plastic, vec![0.04, 0.04]);
    assert_eq!(last.post_capping, vec![0.2, 0.2]);
    assert_eq!(last.residual, vec![0.2, 0.2]);
    assert_eq!(last.ultimate, vec![0.4, 0.4]);
    assert_eq!(last.energy, Some(vec![100.0, 100.0]));
    let second = deterioration(&p, 1, 0).unwrap();
    assert_eq!(second.energy, Some(vec![60.0, 60.0]));
    assert_eq!(second.plastic, vec![0.02, 0.02]);

    let dir = tempdir();
    let cfg = dir.path().join("swept.toml");
    let swept = config(
        "hysteresis = \"imk_peak_oriented\"
plastic_drift_ratio = { from = 0.02, to = 0.04, n = 3 }
post_capping_drift_ratio = 0.1
energy_capacity_ratio = { from = 20, to = 100, n = 3 }",
    );
    std::fs::write(&cfg, &swept).unwrap();
    let out = dir.path().join("swept.csv");
    ok(&sweep_cpu(&cfg, &out, &[]));
    let rows = table(&out);
    assert_eq!(rows.len(), 2 * 3 * 3);
    let pairs: Vec<(String, String)> = rows
        .iter()
        .map(|r| {
            (
                r["b1_plastic_drift_ratio"].clone(),
                r["b1_energy_capacity_ratio"].clone(),
            )
        })
        .collect();
    assert_eq!(pairs[0], ("0.02".into(), "20".into()));
    assert_eq!(pairs[1], ("0.02".into(), "60".into()));
    assert_eq!(pairs[8], ("0.04".into(), "100".into()));
    let header = std::fs::read_to_string(&out).unwrap();
    let header = header.lines().next().unwrap();
    assert!(
        header.contains("b1_xi,b1_plastic_drift_ratio,b1_energy_capacity_ratio,b2_storeys"),
        "{header}"
    );
    assert!(!header.contains("post_capping_drift_ratio"), "{header}");
    // `pound columns` explains them.
    let cols = pound(&["columns", cfg.to_str().unwrap()]);
    ok(&cols);
    let text = String::from_utf8_lossy(&cols.stdout);
    assert!(
        text.contains("`b1_plastic_drift_ratio` | m/m | IMK theta_p"),
        "{text}"
    );
    assert!(
        text.contains("`b1_energy_capacity_ratio` | - | IMK gamma"),
        "{text}"
    );
}

/// A swept strength and swept IMK keys cross; the sweep with IMK storeys differs in its
/// fingerprint from the bilinear one (a resume cannot mix them).
#[test]
fn strength_and_imk_axes_cross_and_are_fingerprinted() {
    let text = config(
        "hysteresis = \"imk_bilinear\"
plastic_drift_ratio = 0.03
post_capping_drift_ratio = 0.1
energy_capacity_ratio = { from = 20, to = 100, n = 3 }",
    )
    .replace(
        "yield_drift_ratio = 0.005",
        "yield_drift_ratio = { from = 0.004, to = 0.006, n = 2 }",
    );
    let p = plan(&text);
    assert_eq!(p.len(), 2 * 2 * 3);
    let names: Vec<&str> = p.swept_names(0);
    assert_eq!(names, ["yield_drift_ratio", "energy_capacity_ratio"]);
    let run = p.run(4);
    assert_eq!(p.swept_values(0, &run), [Some(0.006), Some(60.0)]);

    let fp = |t: &str| {
        let plan = pounding::plan::config::load_text(t, Path::new("imk.toml")).unwrap();
        pounding::io::provenance::Fingerprint::of_plan(&plan).plan
    };
    let bilinear = config("");
    assert_eq!(fp(&bilinear), fp(&config("hysteresis = \"bilinear\"")));
    assert_ne!(fp(&bilinear), fp(&config(IMK)));
    assert_ne!(
        fp(&config(IMK)),
        fp(&config(&IMK.replace("imk_peak_oriented", "imk_bilinear")))
    );
}

/// Every bound and missing key is refused naming the key (`building[b].key[i]` for a list)
/// and what was expected.
#[test]
fn bounds_and_missing_keys_are_named() {
    let with = |imk: &str| config(imk);
    fails(
        &with("hysteresis = \"pinched\"\nplastic_drift_ratio = 0.03"),
        &[
            "building[0].hysteresis",
            "`pinched`",
            "bilinear (the default), imk_bilinear or imk_peak_oriented",
        ],
    );
    fails(
        &with("hysteresis = \"imk_bilinear\"\npost_capping_drift_ratio = 0.1"),
        &[
            "building[0].plastic_drift_ratio",
            "missing: IMK storeys (hysteresis = \"imk_bilinear\") need plastic_drift_ratio",
        ],
    );
    fails(
        &with("hysteresis = \"imk_peak_oriented\"\nplastic_drift_ratio = 0.03"),
        &[
            "building[0].post_capping_drift_ratio",
            "missing",
            "need post_capping_drift_ratio",
        ],
    );
    for (key, bad, expected) in [
        ("plastic_drift_ratio", "0", "a drift ratio > 0"),
        ("post_capping_drift_ratio", "-0.1", "a drift ratio > 0"),
        ("residual_strength_ratio", "1", "a ratio >= 0 and < 1"),
        ("residual_strength_ratio", "-0.1", "a ratio >= 0 and < 1"),
        ("ultimate_drift_ratio", "0", "a drift ratio > 0"),
        ("energy_capacity_ratio", "0", "a ratio > 0"),
    ] {
        let mut imk = "hysteresis = \"imk_peak_oriented\"".to_string();
        for (k, v) in [
            ("plastic_drift_ratio", "0.03"),
            ("post_capping_drift_ratio", "0.1"),
        ] {
            if k != key {
                imk += &format!("\n{k} = {v}");
            }
        }
        imk += &format!("\n{key} = [0.2, {bad}]");
        let text = with(&imk);
        fails(
            &text,
            &[&format!("building[0].{key}[1]"), "out of range", expected],
        );
    }
    // An axis value out of range names its index in the axis.
    fails(
        &with(&format!(
            "{IMK}\nenergy_capacity_ratio = {{ from = 0, to = 10, n = 3 }}"
        )),
        &["building[0].energy_capacity_ratio[0]", "a ratio > 0"],
    );
    fails(
        &with(&IMK.replace("[0.1, 0.12]", "[0.1, 0.12, 0.1]")),
        &[
            "building[0].post_capping_drift_ratio",
            "3 values for 2 storeys",
        ],
    );
    // The ultimate drift beyond the capping point theta_y + theta_p (0.005 + 0.03).
    fails(
        &with(&format!("{IMK}\nultimate_drift_ratio = 0.035")),
        &[
            "building[0].ultimate_drift_ratio",
            "0.035 is at or before storey 1's capping point theta_y + theta_p = 0.005 + 0.03",
        ],
    );
    fails(
        &with(&format!("{IMK}\nultimate_drift_ratio = [0.2, 0.02]")),
        &[
            "building[0].ultimate_drift_ratio[1]",
            "storey 2's capping point",
        ],
    );
    // ... at their largest where theta_p is an axis.
    fails(
        &with(
            &(IMK.replace(
                "plastic_drift_ratio = 0.03",
                "plastic_drift_ratio = { from = 0.02, to = 0.06, n = 3 }",
            ) + "\nultimate_drift_ratio = 0.06"),
        ),
        &["building[0].ultimate_drift_ratio", "0.005 + 0.06"],
    );
    // ... beyond theta_p where theta_y follows the run's stiffness.
    fails(
        &with(&format!("{IMK}\nultimate_drift_ratio = 0.03"))
            .replace("yield_drift_ratio = 0.005", "yield_force_n = 1e6"),
        &[
            "building[0].ultimate_drift_ratio",
            "plastic_drift_ratio theta_p = 0.03",
        ],
    );
    // An IMK key without IMK storeys, and IMK storeys without a strength.
    for (imk, key) in [
        ("plastic_drift_ratio = 0.03", "plastic_drift_ratio"),
        (
            "hysteresis = \"bilinear\"\nenergy_capacity_ratio = 50",
            "energy_capacity_ratio",
        ),
    ] {
        fails(
            &with(imk),
            &[
                &format!("building[0].{key}"),
                "applies to IMK storeys only: add hysteresis = \"imk_bilinear\" or \"imk_peak_oriented\"",
                &format!("or remove {key}"),
            ],
        );
    }
    fails(
        &with(IMK)
            .replace("yield_drift_ratio = 0.005", "")
            .replace("post_yield_ratio = 0.02", ""),
        &[
            "building[0].hysteresis",
            "no strength: give yield_drift_ratio, yield_force_n or yield_base_shear_coefficient",
        ],
    );
    fails(
        &with("residual_strength_ratio = 0.1")
            .replace("yield_drift_ratio = 0.005", "")
            .replace("post_yield_ratio = 0.02", ""),
        &["building[0].residual_strength_ratio", "no strength"],
    );
    // A form the keys do not take.
    fails(
        &with(&format!("{IMK}\nenergy_capacity_ratio = \"high\"")),
        &["a number (every storey), a list of numbers (one per storey"],
    );
}

/// The IMK keys under `[sample]`, as the yield keys: each draw reaches every IMK storey of its
/// run and is the run's parameter column; a sampled key given in the building too, a draw out
/// of its bounds, a sampled key on a bilinear building and a sampled ultimate drift before
/// capping are refused with the key named.
#[test]
fn imk_keys_are_sampled() {
    let sample = |axes: &str| {
        format!(
            "[sample]
method = \"latin_hypercube\"
n = 4
seed = 9
{axes}"
        )
    };
    let theta_p = "[[sample.axis]]
key = \"building[0].plastic_drift_ratio\"
dist = \"uniform\"
min = 0.02
max = 0.05
";
    let gamma = "[[sample.axis]]
key = \"building[0].energy_capacity_ratio\"
dist = \"lognormal\"
median = 60
beta = 0.4
";
    let imk = "hysteresis = \"imk_peak_oriented\"
post_capping_drift_ratio = 0.1";
    let text = format!("{}\n{}", config(imk), sample(&format!("{theta_p}{gamma}")));
    let p = plan(&text);
    // Two gaps crossed with four draws.
    assert_eq!(p.len(), 8);
    let mut drawn = Vec::new();
    for i in 0..p.len() {
        let d = deterioration(&p, i, 0).unwrap();
        let (tp, g) = (d.plastic[0], d.energy.as_ref().unwrap()[0]);
        assert!((0.02..=0.05).contains(&tp), "{tp}");
        assert!(g > 0.0);
        assert_eq!(d.plastic, vec![tp; 2]);
        assert_eq!(d.post_capping, vec![0.1; 2]);
        drawn.push((tp, g));
    }
    drawn.sort_by(|a, b| a.partial_cmp(b).unwrap());
    drawn.dedup();
    assert_eq!(drawn.len(), 4, "{drawn:?}");

    let dir = tempdir();
    let cfg = dir.path().join("sampled.toml");
    std::fs::write(&cfg, &text).unwrap();
    let out = dir.path().join("sampled.csv");
    ok(&sweep_cpu(&cfg, &out, &[]));
    let rows = table(&out);
    assert_eq!(rows.len(), 8);
    for (i, r) in rows.iter().enumerate() {
        let d = deterioration(&p, i as u64, 0).unwrap();
        let tp: f64 = r["b1_plastic_drift_ratio"].parse().unwrap();
        let g: f64 = r["b1_energy_capacity_ratio"].parse().unwrap();
        assert_eq!(tp, d.plastic[0], "run {i}");
        assert_eq!(g, d.energy.unwrap()[0], "run {i}");
        assert!(!r["sample"].is_empty());
    }

    // Given twice.
    let twice = format!(
        "{}\n{}",
        config(&format!("{imk}\nplastic_drift_ratio = 0.03")),
        sample(theta_p)
    );
    fails(&twice, &["plastic_drift_ratio", "sampled under [sample]"]);
    // A draw out of bounds: kappa must be below 1.
    let kappa = "[[sample.axis]]
key = \"building[0].residual_strength_ratio\"
dist = \"uniform\"
min = 0.5
max = 1.5
";
    let bad = format!(
        "{}\n{}",
        config(&format!("{imk}\nplastic_drift_ratio = 0.03")),
        sample(kappa)
    );
    fails(&bad, &["residual_strength_ratio"]);
    // On a bilinear building.
    let bilinear = format!("{}\n{}", config(""), sample(theta_p));
    fails(&bilinear, &["plastic_drift_ratio", "IMK storeys only"]);
    // An ultimate drift drawn at or before capping (0.005 + theta_p, theta_p at least 0.02;
    // the first of four strata of [0.01, 0.03] is below 0.015).
    let ultimate = "[[sample.axis]]
key = \"building[0].ultimate_drift_ratio\"
dist = \"uniform\"
min = 0.01
max = 0.03
";
    let early = format!(
        "{}\n{}",
        config(imk),
        sample(&format!("{theta_p}{ultimate}"))
    );
    fails(&early, &["ultimate_drift_ratio", "capping", "sample"]);
    // Checked draw by draw: a seed whose smallest theta_u lies below the largest capping point
    // of another sample, every sample's own pair beyond capping, is taken, and every run's
    // storeys have theta_u beyond theta_y + theta_p.
    let wide = "[[sample.axis]]
key = \"building[0].ultimate_drift_ratio\"
dist = \"uniform\"
min = 0.02
max = 0.2
";
    let mut taken = 0;
    for seed in 1..40 {
        let text = format!("{}\n{}", config(imk), sample(&format!("{theta_p}{wide}")))
            .replace("seed = 9", &format!("seed = {seed}"));
        let Ok(p) = pounding::plan::config::load_row_text(&text, Path::new("imk.toml")) else {
            continue;
        };
        let runs: Vec<Deterioration> = (0..p.len())
            .map(|i| deterioration(&p, i, 0).unwrap())
            .collect();
        let smallest_u = runs
            .iter()
            .map(|d| d.ultimate[0])
            .fold(f64::INFINITY, f64::min);
        let largest_cap = runs
            .iter()
            .map(|d| 0.005 + d.plastic[0])
            .fold(0.0, f64::max);
        for d in &runs {
            assert!(d.ultimate[0] > 0.005 + d.plastic[0], "seed {seed}: {d:?}");
        }
        if smallest_u <= largest_cap {
            taken += 1;
        }
    }
    assert!(taken > 0, "no seed's draws pair up across the range");
}
