//! A way in: every `pound init` template runs as is, and `pound columns` gives every column of
//! every shipped config a unit and a meaning.

use crate::support::{ok, pound, tempdir};

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
