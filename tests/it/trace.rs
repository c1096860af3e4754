//! `pound trace`: one run of a sweep, whole. Its row is the sweep's row for that run, byte for
//! byte (the same integrator, run alone), and its time history stays within the run's peaks.

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

#[test]
fn a_trace_reproduces_its_sweep_row_and_stays_within_its_peaks() {
    let dir = tempdir();
    let s = |p: &std::path::Path| p.to_str().unwrap().to_string();
    let cfg = dir.path().join("pair.toml");
    std::fs::write(&cfg, PAIR).unwrap();
    let results = dir.path().join("sweep.csv");
    ok(&pound(&[
        "sweep",
        &s(&cfg),
        "-o",
        &s(&results),
        "--backend",
        "cpu",
    ]));
    let text = std::fs::read_to_string(&results).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let head: Vec<&str> = lines[0].split(',').collect();
    let col = |name: &str| head.iter().position(|c| *c == name).unwrap();
    let cell = |line: &str, name: &str| -> f64 {
        line.split(',').nth(col(name)).unwrap().parse().unwrap()
    };
    // Every run of the sweep that pounds (16 runs, several with many impacts).
    let pounding: Vec<usize> = (1..lines.len())
        .filter(|&i| cell(lines[i], "impacts") > 0.0)
        .collect();
    assert!(pounding.len() >= 4, "{pounding:?}");
    for &i in pounding.iter().step_by(3) {
        let run = i - 1;
        let out = dir.path().join(format!("trace-{run}.csv"));
        let said = ok(&pound(&[
            "trace",
            &s(&cfg),
            "--run",
            &run.to_string(),
            "-o",
            &s(&out),
            "--plot",
            &s(&dir.path().join(format!("trace-{run}.svg"))),
        ]));
        let said: Vec<&str> = said.lines().collect();
        assert_eq!(said, [lines[0], lines[i]], "run {run}: the sweep's row");
        let trace = std::fs::read_to_string(&out).unwrap();
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
    // A run past the sweep, and a row, are refused.
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
    let row = dir.path().join("row.toml");
    std::fs::write(&row, crate::multistorey::ROW_CONFIG).unwrap();
    let bad = pound(&[
        "trace",
        &s(&row),
        "--run",
        "0",
        "-o",
        &s(&dir.path().join("y.csv")),
    ]);
    assert!(!bad.status.success());
    assert!(String::from_utf8_lossy(&bad.stderr).contains("not traced yet"));
}
