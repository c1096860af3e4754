//! A way in: every `pound init` template runs as is, and `pound columns` gives every column of
//! every shipped config a unit and a meaning.

use crate::scenes::{row_config, Scene, CHEAP_SWEEP};
use crate::support::cli::{refused, s, stderr, sweep};
use crate::support::{ok, pound, tempdir};
use pounding::plan::config::load_text;
use std::path::Path;
use std::process::Command;

#[test]
fn every_template_runs_as_is() {
    let dir = tempdir();
    for (kind, command) in [
        ("pair", "sweep"),
        ("row", "sweep"),
        ("fragility", "sweep"),
        ("gap", "gap"),
        ("inelastic", "sweep"),
    ] {
        let out = pound(&["init", kind]);
        let text = ok(&out);
        assert!(text.starts_with('#'), "{kind}: a commented config");
        assert!(String::from_utf8_lossy(&out.stderr).contains("# then: pound"));
        let cfg = dir.path().join(format!("{kind}.toml"));
        std::fs::write(&cfg, &text).unwrap();
        let csv = dir.path().join(format!("{kind}.csv"));
        let run = pound(&[command, cfg.to_str().unwrap(), "-o", csv.to_str().unwrap()]);
        ok(&run);
        let rows = std::fs::read_to_string(&csv).unwrap().lines().count();
        assert!(rows > 100, "{kind}: {rows} lines");
    }
}

#[test]
fn every_column_of_every_shipped_config_has_a_meaning() {
    let records = pounding::plan::config::records_dir();
    let mut configs: Vec<_> = std::fs::read_dir("configs")
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    configs.sort();
    assert!(configs.len() >= 10);
    for cfg in configs {
        let text = std::fs::read_to_string(&cfg).unwrap();
        let header = pounding::plan::config::columns_of(&text, &cfg).unwrap();
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_pound"))
            .args(["columns", cfg.to_str().unwrap()])
            .env("POUND_RECORDS_DIR", &records)
            .output()
            .unwrap();
        let table = ok(&out);
        assert_eq!(table.lines().count(), header.len() + 2, "{}", cfg.display());
        for (line, c) in table.lines().skip(2).zip(&header) {
            let cells: Vec<&str> = line.split('|').map(str::trim).collect();
            assert_eq!(cells[1], format!("`{c}`"));
            assert!(!cells[2].is_empty() && cells[3].len() > 3, "{line}");
        }
    }
    // Without a config: the pair's columns.
    let table = ok(&pound(&["columns"]));
    assert!(table.contains("| `peak_u1_m` | m | largest displacement of building 1"));
}

/// Class 8: no window-system noise, `auto` passes software adapters by and says so, ranges
/// that would drop or mangle values are refused.
#[test]
fn quiet_starts_and_honest_defaults() {
    let sc = Scene::new();
    let o = sc.path("g.csv");
    let r = Command::new(env!("CARGO_BIN_EXE_pound"))
        .args(["sweep", s(&sc.cfg), "-o", s(&o), "--backend", "gpu"])
        .env_remove("XDG_RUNTIME_DIR")
        .env_remove("WAYLAND_DISPLAY")
        .output()
        .unwrap();
    let err = stderr(&r);
    ok(&r);
    assert!(!err.contains("XDG_RUNTIME_DIR"), "{err}");
    // On CI's only adapter (lavapipe, a software one) auto runs on the CPU and says why.
    let info = pounding::engine::gpu::context::adapters();
    if info
        .iter()
        .all(|a| a.info.device_type == wgpu::DeviceType::Cpu)
    {
        let r = pound(&["sweep", s(&sc.cfg), "-o", s(&o)]);
        let err = stderr(&r);
        ok(&r);
        assert!(
            err.contains("is a software one") && err.contains("CPU, "),
            "{err}"
        );
    }
    let bad = |from: &str, to: &str, needle: &str| {
        let p = sc.path("b.toml");
        std::fs::write(&p, CHEAP_SWEEP.replace(from, to)).unwrap();
        refused(&sweep(&p, &o, &[]), needle, None);
    };
    bad(
        "gap_m = [0.0, 0.01, 0.03]",
        "gap_m = { from = 0.0, to = 0.1, n = 1 }",
        "to = 0.1 would be ignored",
    );
    bad(
        "gap_m = [0.0, 0.01, 0.03]",
        "gap_m = { from = 0.0, to = 0.1, step = 1e-300 }",
        "step = 1e-300 gives 1.000e299 points",
    );
}

/// Class 2, a panic: every column that any plan can write has a meaning (`pound columns` and
/// the plots read them from the one table), over plans generated with every kind of grid axis
/// and every `[sample]` key of a row, strengths swept and sampled among them. It panicked on
/// a swept or sampled strength (`b1_yield_base_shear_coefficient`).
#[test]
fn every_column_of_every_plan_has_a_meaning() {
    // Each building's strength as a value, a list, a range; each other key as a list.
    let strengths = [
        "yield_drift_ratio = 0.004",
        "yield_drift_ratio = [0.003, 0.005]",
        "yield_drift_ratio = { from = 0.003, to = 0.006, n = 2 }",
        "yield_base_shear_coefficient = 0.15",
        "yield_base_shear_coefficient = [0.1, 0.2]",
    ];
    let building_axes = [
        "period_s = [0.3, 0.5]",
        "mass_kg = [2e5, 3e5]",
        "damping_ratio = [0.02, 0.05]",
        "gap_right_m = [0.0, 0.01]",
    ];
    let contact_axes = [
        "gap_m = [0.0, 0.01]",
        "law = \"kelvin_voigt\"\ne = [0.5, 0.8]\nformula = \"anagnostopoulos\"",
        "k_n_per_m = [1e9, 2e9]",
    ];
    let mut configs = Vec::new();
    for s in strengths {
        for a in building_axes {
            configs.push(row_config(
                &format!("{s}\n{a}"),
                "yield_drift_ratio = 0.004",
                "",
                "",
            ));
        }
        configs.push(row_config(s, s, "", "[intensity]\npga_g = [0.2, 0.4]"));
    }
    for c in contact_axes {
        configs.push(row_config("yield_drift_ratio = 0.004", "", c, ""));
    }
    // Every `[sample]` key of a row of two.
    let sampled = [
        ("building[0].mass_kg", 2e5, 3e5),
        ("building[1].period_s", 0.2, 0.4),
        ("building[0].damping_ratio", 0.02, 0.05),
        ("building[0].gap_right_m", 0.0, 0.02),
        ("contact.k_n_per_m", 1e9, 2e9),
        ("building[0].yield_drift_ratio", 0.003, 0.006),
        ("building[1].yield_base_shear_coefficient", 0.1, 0.2),
    ];
    for (key, min, max) in sampled {
        // The sampled key leaves the grid.
        let name = key.rsplit('.').next().unwrap();
        let (mut b0, mut b1, mut contact) = (
            "yield_drift_ratio = 0.004".to_string(),
            "yield_drift_ratio = 0.004".to_string(),
            String::new(),
        );
        if key.contains("base_shear") {
            b1 = format!("-yield_drift_ratio\n-{name}");
        } else if key.starts_with("building[0]") {
            b0 = format!("{b0}\n-{name}");
        } else if key.starts_with("building[1]") {
            b1 = format!("{b1}\n-{name}");
        } else {
            contact = format!("-{name}");
        }
        if key.contains("yield_drift_ratio") {
            b0 = format!("-{name}");
        }
        let tail = format!(
            "[sample]\nn = 3\nseed = 1\n[[sample.axis]]\nkey = \"{key}\"\ndist = \"uniform\"\nmin = {min}\nmax = {max}\n"
        );
        configs.push(row_config(&b0, &b1, &contact, &tail));
    }
    let mut checked = 0;
    for text in &configs {
        let plan =
            load_text(text, Path::new("generated.toml")).unwrap_or_else(|e| panic!("{e}\n{text}"));
        for column in plan.header() {
            assert!(
                pounding::plan::meaning::meaning(&column).is_some(),
                "column {column} has no meaning\n{text}"
            );
            checked += 1;
        }
    }
    assert!(checked > 0 && configs.len() >= 30, "{checked} columns");
    // And through the command, where it panicked.
    let dir = tempdir();
    let cfg = dir.path().join("swept.toml");
    let swept = configs
        .iter()
        .find(|c| c.contains("yield_base_shear_coefficient = [0.1, 0.2]"))
        .unwrap();
    std::fs::write(&cfg, swept).unwrap();
    let table = ok(&pound(&["columns", cfg.to_str().unwrap()]));
    assert!(table.contains("b1_yield_base_shear_coefficient"), "{table}");
}
