//! `pound trace`: one run of a sweep, whole, of a pair or a row. Its row is the sweep's row for
//! that run, byte for byte (the same integrator, run alone), and its time history stays within
//! the run's peaks.

use crate::support::{ok, pound, tempdir};

const PAIR: &str = r#"
[building1]
mass_kg = 1.0e5
period_s = [0.3, 0.5]
damping_ratio = 0.05

[building2]
mass_kg = 2.0e5
period_s = 0.9
damping_ratio = 0.05

[contact]
law = ["nonlinear_viscoelastic", "linear"]
formula = "exact"
e = 0.65
beta_n_per_m1_5 = 2.75e9
k_n_per_m = 1.0e9
gap_m = [0.0, 0.005, 0.01, 0.02]

[[record]]
synthetic = { seed = 5, duration_s = 6.0, dt_s = 0.01 }

[intensity]
pga_g = 0.4
"#;

/// `pound sweep` of `cfg` on the CPU into `dir`: the CSV's text.
fn sweep(dir: &std::path::Path, cfg: &std::path::Path) -> String {
    let results = dir.join("sweep.csv");
    ok(&pound(&[
        "sweep",
        cfg.to_str().unwrap(),
        "-o",
        results.to_str().unwrap(),
        "--backend",
        "cpu",
    ]));
    std::fs::read_to_string(&results).unwrap()
}

/// `pound trace` of run `run` of `cfg` into `dir`, with its plot: what it printed, and the
/// trace's CSV.
fn trace(dir: &std::path::Path, cfg: &std::path::Path, run: usize) -> (String, String) {
    let out = dir.join(format!("trace-{run}.csv"));
    let said = ok(&pound(&[
        "trace",
        cfg.to_str().unwrap(),
        "--run",
        &run.to_string(),
        "-o",
        out.to_str().unwrap(),
        "--plot",
        dir.join(format!("trace-{run}.svg")).to_str().unwrap(),
    ]));
    (said, std::fs::read_to_string(&out).unwrap())
}

/// The cell of column `name` in a CSV `line` under the header line `head`.
fn cell<'a>(head: &str, line: &'a str, name: &str) -> &'a str {
    let c = head
        .split(',')
        .position(|c| c == name)
        .unwrap_or_else(|| panic!("{name} in {head}"));
    line.split(',').nth(c).unwrap()
}

#[test]
fn a_trace_reproduces_its_sweep_row_and_stays_within_its_peaks() {
    let dir = tempdir();
    let s = |p: &std::path::Path| p.to_str().unwrap().to_string();
    let cfg = dir.path().join("pair.toml");
    std::fs::write(&cfg, PAIR).unwrap();
    let text = sweep(dir.path(), &cfg);
    let lines: Vec<&str> = text.lines().collect();
    let cell = |line: &str, name: &str| -> f64 { cell(lines[0], line, name).parse().unwrap() };
    // Every run of the sweep that pounds (16 runs, several with many impacts).
    let pounding: Vec<usize> = (1..lines.len())
        .filter(|&i| cell(lines[i], "impacts") > 0.0)
        .collect();
    assert!(pounding.len() >= 4, "{pounding:?}");
    for &i in pounding.iter().step_by(3) {
        let run = i - 1;
        let (said, trace) = trace(dir.path(), &cfg, run);
        let said: Vec<&str> = said.lines().collect();
        assert_eq!(said, [lines[0], lines[i]], "run {run}: the sweep's row");
        let mut rows = trace.lines();
        let th: Vec<&str> = rows.next().unwrap().split(',').collect();
        let at = |name: &str| th.iter().position(|c| *c == name).unwrap();
        let (mut u1, mut force, mut contact) = (0.0f64, 0.0f64, 0usize);
        for r in rows {
            let c: Vec<&str> = r.split(',').collect();
            u1 = u1.max(c[at("u1_m")].parse::<f64>().unwrap().abs());
            force = force.max(c[at("force_n")].parse().unwrap());
            contact += (c[at("mode")] != "free") as usize;
        }
        let (peak_u1, peak_force) = (cell(lines[i], "peak_u1_m"), cell(lines[i], "peak_force_n"));
        // Samples at record steps and events: within the located peaks, and close below them.
        assert!(
            u1 <= peak_u1 * (1.0 + 1e-12) && u1 > 0.95 * peak_u1,
            "run {run}: {u1} against {peak_u1}"
        );
        assert!(
            force > 0.0 && force <= peak_force * (1.0 + 1e-12),
            "run {run}: {force} against {peak_force}"
        );
        assert!(contact > 0, "run {run}: samples in contact");
    }
    // A run past the sweep is refused.
    let bad = pound(&[
        "trace",
        &s(&cfg),
        "--run",
        "16",
        "-o",
        &s(&dir.path().join("x.csv")),
    ]);
    assert!(!bad.status.success());
    assert!(String::from_utf8_lossy(&bad.stderr).contains("the sweep has 16 runs"));
}

/// A row's trace: its row is the sweep's byte for byte (the buildings that stand still through
/// a record step of substeps are sampled by their exact free steps, without changing the run),
/// and every floor's and level's samples stay within and close below the row's located peaks.
#[test]
fn a_row_trace_reproduces_its_sweep_row_and_stays_within_its_peaks() {
    let dir = tempdir();
    let cfg = dir.path().join("row.toml");
    std::fs::write(&cfg, crate::scenes::ROW_CONFIG).unwrap();
    let text = sweep(dir.path(), &cfg);
    let lines: Vec<&str> = text.lines().collect();
    let cell = |line: &str, name: &str| -> f64 { cell(lines[0], line, name).parse().unwrap() };
    let levels: Vec<&str> = lines[0]
        .split(',')
        .filter_map(|c| c.strip_suffix("_peak_force_n"))
        .filter(|c| c.starts_with("level_"))
        .collect();
    assert!(levels.len() >= 4, "{levels:?}");
    let mut checked_levels = 0;
    for i in 1..lines.len() {
        let run = i - 1;
        let (said, trace) = trace(dir.path(), &cfg, run);
        let said: Vec<&str> = said.lines().collect();
        assert_eq!(said, [lines[0], lines[i]], "run {run}: the sweep's row");
        let mut rows = trace.lines();
        let th: Vec<String> = rows.next().unwrap().split(',').map(String::from).collect();
        let at = |name: &str| {
            th.iter()
                .position(|c| c == name)
                .unwrap_or_else(|| panic!("{name} in {th:?}"))
        };
        let samples: Vec<Vec<String>> = rows
            .map(|r| r.split(',').map(String::from).collect())
            .collect();
        let max_of = |name: &str| -> f64 {
            samples
                .iter()
                .map(|c| c[at(name)].parse::<f64>().unwrap().abs())
                .fold(0.0, f64::max)
        };
        // Each building's roof: within its located peak, and close below it.
        for (b, roof) in [(1, 2), (2, 4), (3, 3)] {
            let peak = cell(lines[i], &format!("b{b}_peak_roof_m"));
            let sampled = max_of(&format!("b{b}_f{roof}_u_m"));
            assert!(
                sampled <= peak * (1.0 + 1e-12) && sampled > 0.9 * peak,
                "run {run}, building {b}: {sampled} against {peak}"
            );
        }
        // Each level that pounds: samples in contact, forces within its peak.
        for l in &levels {
            let peak = cell(lines[i], &format!("{l}_peak_force_n"));
            let sampled = max_of(&format!("{l}_force_n"));
            assert!(
                sampled <= peak * (1.0 + 1e-12),
                "run {run}, {l}: {sampled} > {peak}"
            );
            let contact = samples
                .iter()
                .filter(|c| c[at(&format!("{l}_mode"))] != "free")
                .count();
            if cell(lines[i], &format!("{l}_impacts")) > 0.0 {
                assert!(
                    sampled > 0.0 && contact > 0,
                    "run {run}, {l}: no contact sampled"
                );
                checked_levels += 1;
            } else {
                assert_eq!((sampled, contact), (0.0, 0), "run {run}, {l}");
            }
        }
    }
    assert!(checked_levels >= 4, "{checked_levels} levels that pound");
}

/// A yielding row's trace carries each yielding storey's drift, plastic drift, shear and
/// hysteretic energy, and they end where the sweep's row says: the storeys' hysteretic energies
/// add up to the building's, the largest plastic drift at the end is the residual drift (where
/// the run settled), no sampled drift passes the peak drift, and every sample's shear is the
/// storey's elastic force on its elastic drift `d - p` (one stiffness for every sample), with
/// its back drift within the yield band. The plot draws the hysteresis loop and the energy.
#[test]
fn a_yielding_row_trace_ends_at_its_sweep_rows_storey_outputs() {
    let dir = tempdir();
    let cfg = std::path::Path::new("configs/inelastic-row.toml");
    let text = sweep(dir.path(), cfg);
    let lines: Vec<&str> = text.lines().collect();
    let cell = |line: &str, name: &str| cell(lines[0], line, name).to_string();
    let mut yielded = 0;
    for (run, &line) in lines[1..].iter().enumerate() {
        let (said, trace) = trace(dir.path(), cfg, run);
        assert_eq!(
            said.lines().nth(1),
            Some(line),
            "run {run}: the sweep's row"
        );
        let mut rows = trace.lines();
        let th: Vec<&str> = rows.next().unwrap().split(',').collect();
        let samples: Vec<Vec<f64>> = rows
            .map(|r| {
                r.split(',')
                    .map(|c| c.parse().unwrap_or(f64::NAN))
                    .collect()
            })
            .collect();
        let at = |name: &str| {
            th.iter()
                .position(|c| *c == name)
                .unwrap_or_else(|| panic!("{name} in {th:?}"))
        };
        // Building 1 yields (six storeys); building 2 is elastic and has no storey columns.
        assert!(!th.iter().any(|c| c.starts_with("b2_s")), "{th:?}");
        let last = samples.last().unwrap();
        let storey = |j: usize, what: &str| at(&format!("b1_s{j}_{what}"));
        let energy: f64 = (1..=6)
            .map(|j| last[storey(j, "hysteretic_energy_j")])
            .sum();
        let said_energy: f64 = cell(line, "b1_hysteretic_energy_j").parse().unwrap();
        assert!(
            (energy - said_energy).abs() <= 1e-12 * said_energy.abs().max(1.0),
            "run {run}: {energy} against {said_energy}"
        );
        if said_energy > 0.0 {
            yielded += 1;
        }
        let residual = (1..=6)
            .map(|j| last[storey(j, "plastic_drift_ratio")].abs())
            .fold(0.0, f64::max);
        if let Ok(said) = cell(line, "b1_residual_drift_ratio").parse::<f64>() {
            assert!(
                (residual - said).abs() <= 1e-12 * said.max(1e-3),
                "run {run}: residual {residual} against {said}"
            );
        }
        let peak: f64 = cell(line, "b1_peak_drift_ratio").parse().unwrap();
        for j in 1..=6 {
            let (d, p, f) = (
                storey(j, "drift_ratio"),
                storey(j, "plastic_drift_ratio"),
                storey(j, "shear_n"),
            );
            let sampled = samples.iter().map(|s| s[d].abs()).fold(0.0, f64::max);
            assert!(sampled <= peak * (1.0 + 1e-12), "run {run} storey {j}");
            // One stiffness per storey: shear / (d - p) is the same at every sample.
            let k: Vec<f64> = samples
                .iter()
                .filter(|s| (s[d] - s[p]).abs() > 1e-4)
                .map(|s| s[f] / (s[d] - s[p]))
                .collect();
            assert!(
                !k.is_empty(),
                "run {run} storey {j}: no elastic drift sampled"
            );
            let (lo, hi) = k
                .iter()
                .fold((f64::MAX, f64::MIN), |(a, b), &x| (a.min(x), b.max(x)));
            assert!(
                lo > 0.0 && hi / lo < 1.0 + 1e-9,
                "run {run} storey {j}: {lo} to {hi}"
            );
            // Within the band: the back drift `d - p / (1 - b)` at most the yield drift ratio.
            let band = samples
                .iter()
                .map(|s| (s[d] - s[p] / (1.0 - 0.03)).abs())
                .fold(0.0, f64::max);
            assert!(band <= 0.005 * (1.0 + 1e-6), "run {run} storey {j}: {band}");
        }
        let svg = std::fs::read_to_string(dir.path().join(format!("trace-{run}.svg"))).unwrap();
        assert!(svg.contains("Storey shear against drift") && svg.contains("Hysteretic energy"));
    }
    assert!(yielded >= 3, "{yielded} runs yielded");
}

/// A row of two one-storey buildings, which the sweep runs on the pair's kernel: its trace is
/// that kernel's run too, its row the sweep's byte for byte, its samples in the row's form
/// within the row's peaks; a run the sweep gives the row kernel (it nears the collapse limit)
/// is traced there.
#[test]
fn a_row_of_two_traces_on_the_pair_kernel_as_its_sweep_runs() {
    let dir = tempdir();
    let text = std::fs::read_to_string("configs/row-of-two.toml")
        .unwrap()
        .replace("n = 30 }", "n = 3 }")
        .replace("to = 0.6, n = 40 }", "to = 1.2, n = 3 }")
        .replace("[[building]]\nstoreys = 1\nstorey_height_m = 3.5\nmass_kg = 4.0e5", "[run]\ncollapse_drift_ratio = 0.02\n\n[[building]]\nstoreys = 1\nstorey_height_m = 3.5\nmass_kg = 4.0e5");
    let cfg = dir.path().join("row-of-two.toml");
    std::fs::write(&cfg, &text).unwrap();
    let sweep_text = sweep(dir.path(), &cfg);
    let lines: Vec<&str> = sweep_text.lines().collect();
    assert_eq!(lines.len(), 10);
    let mut statuses = std::collections::BTreeSet::new();
    for i in 1..lines.len() {
        let run = i - 1;
        let (said, trace) = trace(dir.path(), &cfg, run);
        let said: Vec<&str> = said.lines().collect();
        assert_eq!(said, [lines[0], lines[i]], "run {run}: the sweep's row");
        statuses.insert(cell(lines[0], lines[i], "status").to_string());
        let mut rows = trace.lines();
        let th: Vec<&str> = rows.next().unwrap().split(',').collect();
        let samples: Vec<Vec<&str>> = rows.map(|r| r.split(',').collect()).collect();
        for b in [1, 2] {
            let col = th
                .iter()
                .position(|c| *c == format!("b{b}_f1_u_m"))
                .unwrap();
            let sampled = samples
                .iter()
                .map(|c| c[col].parse::<f64>().unwrap().abs())
                .fold(0.0, f64::max);
            let peak: f64 = cell(lines[0], lines[i], &format!("b{b}_peak_roof_m"))
                .parse()
                .unwrap();
            assert!(
                sampled <= peak * (1.0 + 1e-12) && sampled > 0.9 * peak,
                "run {run}, building {b}: {sampled} against {peak}"
            );
        }
    }
    assert_eq!(
        statuses.into_iter().collect::<Vec<_>>(),
        ["collapsed", "ok"],
        "runs on both kernels"
    );
}
