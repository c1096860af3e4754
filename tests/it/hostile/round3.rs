//! Hostile pass, round 3 (issue 47): the newer commands keep the promises the older ones keep.
//! One test per class, named after it.

use crate::support::{ok, pound, table, tempdir};
use pounding::plan::config::load_text;
use std::path::Path;

/// `base` (TOML lines) with `extra`'s lines after it, less the base's lines whose key `extra`
/// gives or drops (a line `-key`).
fn with(base: &[&str], extra: &str) -> String {
    let key = |line: &str| line.split('=').next().unwrap_or("").trim().to_string();
    let given = |line: &str| {
        extra
            .lines()
            .any(|l| key(l) == key(line) || l.strip_prefix('-') == Some(key(line).as_str()))
    };
    let mut lines: Vec<&str> = base.iter().copied().filter(|l| !given(l)).collect();
    lines.extend(extra.lines().filter(|l| !l.starts_with('-')));
    lines.join("\n")
}

/// A row of two 2-storey buildings with `b0`, `b1` added to (or replacing keys of) each
/// building's keys, `contact` to the contact's, and `tail` at the end.
fn row_config(b0: &str, b1: &str, contact: &str, tail: &str) -> String {
    let building = |period: &'static str| {
        [
            "storeys = 2",
            "storey_height_m = 3.0",
            "mass_kg = 3.0e5",
            period,
            "damping_ratio = 0.05",
        ]
    };
    format!(
        "[[building]]\n{}\n\n[[building]]\n{}\n\n[contact]\n{}\n\n[[record]]\nsynthetic = {{ seed = 1, duration_s = 1.0, dt_s = 0.01, pga_g = 0.3 }}\n{tail}\n",
        with(&building("period_s = 0.4"), b0),
        with(&building("period_s = 0.3"), b1),
        with(&["law = \"linear\"", "k_n_per_m = 1e9", "gap_m = 0.01"], contact),
    )
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

/// The shipped yielding row's sweep (6 runs, CPU) into `dir`/runs.csv: results to study.
fn yielding_runs(dir: &Path) -> std::path::PathBuf {
    let runs = dir.join("runs.csv");
    ok(&pound(&[
        "sweep",
        concat!(env!("CARGO_MANIFEST_DIR"), "/configs/inelastic-row.toml"),
        "--backend",
        "cpu",
        "-o",
        runs.to_str().unwrap(),
    ]));
    runs
}

/// Class 1, an input destroyed: a damage-state file, as the results and the config are, is
/// refused as an output, also through a symbolic link (`fragility -o states.toml` wrote its CSV
/// over the file, rc 0), and an output whose extension names another format (`-o x.toml` for
/// CSV) is refused as `.svg` for CSV is; the file is left as it was.
#[test]
fn an_input_is_never_an_output() {
    let dir = tempdir();
    let d = dir.path();
    let runs = yielding_runs(d);
    let states = d.join("states.toml");
    let text = "name = \"t\"\nsource = \"drawn\"\n[[state]]\nname = \"light\"\nlimit = 0.004\n[[state]]\nname = \"heavy\"\nlimit = 0.02\n";
    std::fs::write(&states, text).unwrap();
    #[cfg(unix)]
    std::os::unix::fs::symlink(&states, d.join("link.csv")).unwrap();
    let s = |p: &Path| p.to_str().unwrap().to_string();
    let fragility = |limits: &[&str], output: &str| {
        let mut args = vec![
            "fragility".to_string(),
            s(&runs),
            "--edp".into(),
            "b1_peak_drift_ratio".into(),
        ];
        args.extend(limits.iter().map(|x| x.to_string()));
        args.extend(["-o".to_string(), s(&d.join(output))]);
        let refs: Vec<&str> = args.iter().map(String::as_str).collect();
        pound(&refs)
    };
    let mut cases = vec![
        (
            fragility(&["--damage-states", &s(&states)], "states.toml"),
            "damage-state file",
        ),
        (
            fragility(&["--threshold", "0.01"], "x.toml"),
            "a .toml name",
        ),
    ];
    #[cfg(unix)]
    cases.push((
        fragility(&["--damage-states", &s(&states)], "link.csv"),
        "damage-state file",
    ));
    for (o, needle) in cases {
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "rc 0: {err}");
        assert!(err.contains(needle), "expected `{needle}` in: {err}");
    }
    assert_eq!(std::fs::read_to_string(&states).unwrap(), text);
    assert!(!d.join("x.toml").exists());
    // The same file as a damage-state set is read, and a CSV next to it is written.
    ok(&fragility(&["--damage-states", &s(&states)], "states.csv"));
}

/// Class 3, units ignored: damage-state limits in one unit are refused on a column in another,
/// both named (`--edp peak_force_n --damage-states hazus-c1l-high` read drift-ratio limits as
/// newtons, rc 0, four identical curves); a file may give its limits' unit, and then reads on
/// a column in that unit.
#[test]
fn limits_and_columns_agree_on_units() {
    let dir = tempdir();
    let d = dir.path();
    let runs = yielding_runs(d);
    let forces = d.join("forces.toml");
    std::fs::write(
        &forces,
        "unit = \"N\"\n[[state]]\nname = \"light\"\nlimit = 1e6\n[[state]]\nname = \"heavy\"\nlimit = 3e6\n",
    )
    .unwrap();
    let s = |p: &Path| p.to_str().unwrap().to_string();
    let run = |edp: &str, states: &str, out: &str| {
        pound(&[
            "fragility",
            &s(&runs),
            "--edp",
            edp,
            "--damage-states",
            states,
            "-o",
            &s(&d.join(out)),
        ])
    };
    for (o, needles) in [
        (
            run("peak_force_n", "hazus-c1l-high", "a.csv"),
            ["in m/m", "peak_force_n is in N"],
        ),
        (
            run("b1_peak_drift_ratio", &s(&forces), "b.csv"),
            ["in N", "b1_peak_drift_ratio is in m/m"],
        ),
    ] {
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "rc 0: {err}");
        for n in needles {
            assert!(err.contains(n), "expected `{n}` in: {err}");
        }
    }
    assert!(!d.join("a.csv").exists() && !d.join("b.csv").exists());
    ok(&run("peak_force_n", &s(&forces), "c.csv"));
    ok(&run("b1_peak_drift_ratio", "hazus-c1l-high", "d.csv"));
}

/// Class 12, a fit the grid biases: `pound gap` fits the probability of pounding to the runs'
/// required gaps themselves, so the gaps it is counted at (the default, a coarse and a fine
/// grid) do not move the fit, and the median is the maximum-likelihood lognormal's of the
/// required gaps the CSV holds (the runs whose floors never close counted apart). It fitted
/// counts at the grid's gaps: the median moved with the grid.
#[test]
fn a_gap_fit_does_not_depend_on_the_grid() {
    let dir = tempdir();
    let config = concat!(env!("CARGO_MANIFEST_DIR"), "/configs/gap-example.toml");
    let fitted_line = |grid: Option<&str>| {
        let out = dir.path().join("gaps.csv");
        let mut args = vec!["gap", config, "-o", out.to_str().unwrap()];
        if let Some(g) = grid {
            args.extend(["--gaps", g]);
        }
        let text = ok(&pound(&args));
        let line = text
            .lines()
            .find(|l| l.starts_with("| 1-2 | PGA 0.35 g |"))
            .unwrap_or_else(|| panic!("no fitted line in:\n{text}"))
            .to_string();
        (line, table(&out))
    };
    let (default, rows) = fitted_line(None);
    for grid in ["0:0.5:0.1", "0:0.5:0.001", "0.03,0.2"] {
        assert_eq!(fitted_line(Some(grid)).0, default, "--gaps {grid}");
    }
    // The maximum-likelihood lognormal of the required gaps above 0.
    let required: Vec<f64> = rows
        .iter()
        .map(|r| r["required_gap_m"].parse().unwrap())
        .collect();
    let logs: Vec<f64> = required
        .iter()
        .filter(|&&r| r > 0.0)
        .map(|r| r.ln())
        .collect();
    let mean = logs.iter().sum::<f64>() / logs.len() as f64;
    let beta = (logs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / logs.len() as f64).sqrt();
    assert!(
        logs.len() > 2 && logs.len() < required.len(),
        "some runs never close"
    );
    let cells: Vec<&str> = default.split('|').map(str::trim).collect();
    assert_eq!(cells[3], required.len().to_string(), "{default}");
    assert_eq!(cells[4], logs.len().to_string(), "{default}");
    assert_eq!(cells[5], format!("{:.2} mm", mean.exp() * 1e3), "{default}");
    assert_eq!(cells[6], format!("{beta:.3}"), "{default}");
}

/// Class 6, silent drops: `pound plot` says how many rows it left out and why, by reason in
/// the table of meanings' words (a residual drift is empty where the run did not settle), and
/// names a series of which every row was left out. It left out empty values without a word, so
/// a whole series vanished.
#[test]
fn every_row_left_out_is_counted() {
    let dir = tempdir();
    let results = dir.path().join("runs.csv");
    std::fs::write(
        &results,
        "run,record,pga_g,b1_residual_drift_ratio,b1_first_impact_s,status\n\
         0,quiet,0.2,0.001,,ok\n\
         1,quiet,0.4,0.002,,ok\n\
         2,strong,0.2,,1.5,ok\n\
         3,strong,0.4,,1.2,ok\n\
         4,quiet,0.6,0.003,,step_limit\n\
         5,quiet,,0.004,,ok\n\
         6,quiet,0.8,inf,,ok\n",
    )
    .unwrap();
    let plot = dir.path().join("p.svg");
    let out = pound(&[
        "plot",
        results.to_str().unwrap(),
        "--x",
        "pga_g",
        "--y",
        "b1_residual_drift_ratio",
        "--by",
        "record",
        "-o",
        plot.to_str().unwrap(),
    ]);
    ok(&out);
    let err = String::from_utf8_lossy(&out.stderr);
    for said in [
        "1 rows left out: runs whose status is not ok",
        "1 rows left out: values that are not finite",
        "1 rows left out: pga_g is empty",
        "2 rows left out: b1_residual_drift_ratio is empty (where the run did not settle)",
        "no series drawn for record = strong: every one of its rows was left out",
    ] {
        assert!(err.contains(said), "missing `{said}` in:\n{err}");
    }
    // The first impact is empty where the run did not pound.
    let out = pound(&[
        "plot",
        results.to_str().unwrap(),
        "--x",
        "pga_g",
        "--y",
        "b1_first_impact_s",
        "-o",
        plot.to_str().unwrap(),
    ]);
    ok(&out);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("3 rows left out: b1_first_impact_s is empty"),
        "{err}"
    );
}

/// Class 6 where it arises in filters and series: a scaled PGA computed per record
/// (`0.19999999999999998`, `0.20000000000000004`) is one value to `--where` and `--by`, as it
/// is one level to `pound fragility`. `--where pga_g=0.2` silently dropped a record's rows, and
/// `--by pga_g` drew twelve series for eight levels.
#[test]
fn one_value_computed_per_record_is_one_value() {
    let dir = tempdir();
    let runs = dir.path().join("runs.csv");
    ok(&pound(&[
        "sweep",
        "configs/fragility-example.toml",
        "-o",
        runs.to_str().unwrap(),
    ]));
    let rows = table(&runs);
    let pga: Vec<f64> = rows.iter().map(|r| r["pga_g"].parse().unwrap()).collect();
    let at = |v: f64| pga.iter().filter(|p| (*p / v - 1.0).abs() < 1e-9).count();
    assert!(
        pga.iter()
            .any(|&p| p != 0.2 && (p / 0.2 - 1.0).abs() < 1e-9),
        "the test needs a PGA of 0.2 g computed inexactly"
    );
    let levels = {
        let mut l: Vec<String> = pga.iter().map(|p| format!("{p:.9}")).collect();
        l.sort();
        l.dedup();
        l.len()
    };
    let r = runs.to_str().unwrap();
    let fit = |filter: &str| {
        let out = pound(&[
            "fragility",
            r,
            "--im",
            "pga_g",
            "--edp",
            "peak_force_n",
            "--threshold",
            "1e6",
            "--where",
            filter,
            "-o",
            dir.path().join("f.csv").to_str().unwrap(),
        ]);
        ok(&out).lines().next().unwrap_or("").to_string()
    };
    assert!(fit("pga_g=0.2").starts_with(&format!("{} runs at 1 levels", at(0.2))));
    let below = pga.iter().filter(|p| **p < 0.2 * (1.0 + 1e-9)).count();
    assert!(
        fit("pga_g<=0.2").starts_with(&format!("{below} runs at")),
        "{}",
        fit("pga_g<=0.2")
    );
    let plot = pound(&[
        "plot",
        r,
        "--x",
        "gap_m",
        "--y",
        "peak_force_n",
        "--by",
        "pga_g",
        "-o",
        dir.path().join("p.svg").to_str().unwrap(),
    ]);
    ok(&plot);
    let said = String::from_utf8_lossy(&plot.stderr);
    assert!(
        said.contains(&format!("{levels} series,")),
        "{levels} levels: {said}"
    );
}

/// Class 5 where it arises in a config: a mass no building has (1e170 kg stalled a sweep with
/// no word, for seconds on end) is refused with its bound, for a pair's and a row's buildings,
/// and so is a coefficient of restitution below 0.01.
#[test]
fn a_mass_beyond_any_building_is_refused() {
    for (config, line) in [
        ("configs/quickstart.toml", "mass_kg = 1.0e5"),
        ("configs/inelastic-row.toml", "mass_kg = 3.0e5"),
    ] {
        let text = std::fs::read_to_string(config)
            .unwrap()
            .replacen(line, "mass_kg = 1e170", 1);
        let err = load_text(&text, Path::new(config))
            .expect_err(config)
            .to_string();
        assert!(err.contains("mass_kg") && err.contains("1e12 kg"), "{err}");
    }
    let floors = row_config("-mass_kg\nfloor_masses_kg = [3e5, 1e170]", "", "", "");
    let err = load_text(&floors, Path::new("floors.toml"))
        .expect_err("a floor of 1e170 kg")
        .to_string();
    assert!(
        err.contains("floor_masses_kg[1]") && err.contains("1e12 kg"),
        "{err}"
    );
    // So is an impact all but plastic: the exact damping's search costs as 1/e (a sweep at
    // e = 1e-4 printed nothing for minutes; `pound restitution --e 1e-3` ran as long).
    let text = std::fs::read_to_string("configs/quickstart.toml").unwrap();
    let e_line = text
        .lines()
        .find(|l| l.starts_with("e = "))
        .expect("an e axis");
    let err = load_text(&text.replace(e_line, "e = 1e-4"), Path::new("q.toml"))
        .expect_err("e = 1e-4")
        .to_string();
    assert!(
        err.contains("contact.e") && err.contains("0.01 <= e"),
        "{err}"
    );
    for args in [
        ["restitution", "--e", "0.001"],
        ["formulas", "--e", "0.001"],
    ] {
        let o = pound(&args);
        let said = String::from_utf8_lossy(&o.stderr);
        assert!(
            !o.status.success() && said.contains("0.01 <= e"),
            "{args:?}: {said}"
        );
    }
}

/// Class 14 where a legend stands beside the plot: the title is centred over the whole panel,
/// so one that fits the panel stays in it (plotters centred it over the plot left of the
/// legend, and a long default title ran off the panel's left edge).
#[test]
fn a_title_stands_over_its_panel() {
    let dir = tempdir();
    let runs = dir.path().join("runs.csv");
    ok(&pound(&[
        "sweep",
        "configs/fragility-example.toml",
        "-o",
        runs.to_str().unwrap(),
    ]));
    let svg = dir.path().join("p.svg");
    ok(&pound(&[
        "plot",
        runs.to_str().unwrap(),
        "--x",
        "gap_m",
        "--y",
        "peak_force_n",
        "--by",
        "record",
        "--where",
        "pga_g>=0.5",
        "-o",
        svg.to_str().unwrap(),
    ]));
    let text = std::fs::read_to_string(&svg).unwrap();
    // The first text element is the title; the panel is 640 px wide.
    let title = text.split("<text ").nth(1).expect("a title");
    assert!(title.contains("peak force against gap"), "{title}");
    assert!(
        title.starts_with("x=\"320\""),
        "the title is not centred on the panel: {title}"
    );
}

/// Classes 4 and 5 before any output: a figure that would be refused (a label that
/// contradicts the data, a PNG past its pixel bound) is refused before the command writes
/// anything, so no CSV is left behind (trace, gap, fragility, ida, hysteresis and record
/// spectrum wrote theirs first).
#[test]
fn a_refused_figure_leaves_nothing_behind() {
    let dir = tempdir();
    let runs = dir.path().join("runs.csv");
    ok(&pound(&[
        "sweep",
        "configs/inelastic-row.toml",
        "-o",
        runs.to_str().unwrap(),
    ]));
    let r = runs.to_str().unwrap();
    let record = crate::support::records_dir().join("elcentro1940_ns_I-ELC180_peer2000.AT2");
    let huge = ["--size", "4000x4000", "--dpi", "600"];
    let cases: Vec<(Vec<&str>, &[&str])> = vec![
        (
            vec!["trace", "configs/inelastic-row.toml", "--run", "1"],
            &["--y-label", "whatever"],
        ),
        (
            vec!["trace", "configs/inelastic-row.toml", "--run", "1"],
            &huge,
        ),
        (vec!["gap", "configs/gap-example.toml"], &huge),
        (
            vec![
                "fragility",
                r,
                "--im",
                "pga_g",
                "--edp",
                "b1_peak_drift_ratio",
                "--threshold",
                "0.005",
            ],
            &huge,
        ),
        (
            vec!["ida", r, "--im", "pga_g", "--edp", "b1_peak_drift_ratio"],
            &huge,
        ),
        (vec!["hysteresis", "hertz"], &huge),
        (vec!["record", "spectrum", record.to_str().unwrap()], &huge),
    ];
    for (i, (command, figure)) in cases.into_iter().enumerate() {
        let out = dir.path().join(format!("out-{i}.csv"));
        let plot = dir.path().join(format!("plot-{i}.png"));
        let mut args = command.clone();
        args.extend([
            "-o",
            out.to_str().unwrap(),
            "--plot",
            plot.to_str().unwrap(),
        ]);
        args.extend(figure);
        let o = pound(&args);
        assert!(!o.status.success(), "{args:?}: rc 0");
        assert!(!out.exists(), "{args:?} wrote {}", out.display());
        assert!(!plot.exists(), "{args:?} drew {}", plot.display());
    }
}

/// `n` with a comma every three digits, as the README writes counts (`37,318`).
fn thousands(n: u64) -> String {
    let digits = n.to_string();
    let mut out = String::new();
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i).is_multiple_of(3) {
            out.push(',');
        }
        out.push(c);
    }
    out
}

/// The number before `word` in a sweep's summary line (`2700 runs in ...: 37318 impacts`).
fn count_before(text: &str, word: &str) -> u64 {
    let words: Vec<&str> = text.split_whitespace().collect();
    let at = words
        .windows(2)
        .find(|w| w[1].trim_end_matches(',') == word && w[0].parse::<u64>().is_ok())
        .unwrap_or_else(|| panic!("no count of {word} in:\n{text}"));
    at[0].parse().unwrap()
}

/// Class 15, words out of date: the numbers the README quotes from its commands are what those
/// commands print now (it quoted 37,323 impacts where the sweep gives 37,318), and the help and
/// docs say what the commands do (`pound --help` called `trace` a pair's, docs/inelastic.md
/// said `trace` lacks the storeys it writes, docs/fragility.md called yielding storeys coming).
#[test]
fn quoted_numbers_and_words_are_what_the_commands_give() {
    let readme = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/README.md"))
        .unwrap()
        .replace('\n', " ");
    let says = |text: &str| {
        assert!(
            readme.contains(text),
            "README.md does not say `{text}`, which its command prints now"
        )
    };
    let dir = tempdir();
    let out = |name: &str| dir.path().join(name).to_str().unwrap().to_string();
    let stderr = |o: &std::process::Output| {
        ok(o);
        String::from_utf8_lossy(&o.stderr).to_string()
    };
    // The quickstart: its runs and the CPU's impacts; f32's where an adapter is found.
    let cpu = stderr(&pound(&[
        "sweep",
        "configs/quickstart.toml",
        "--backend",
        "cpu",
        "-o",
        &out("q.csv"),
    ]));
    says(&format!("({} runs", thousands(count_before(&cpu, "runs"))));
    says(&format!(
        "against the CPU's {}",
        thousands(count_before(&cpu, "impacts"))
    ));
    if crate::support::ctx().is_some() {
        let f32 = stderr(&pound(&[
            "sweep",
            "configs/quickstart.toml",
            "--backend",
            "gpu",
            "-o",
            &out("q32.csv"),
        ]));
        says(&format!(
            "f32 on lavapipe finds {} impacts",
            thousands(count_before(&f32, "impacts"))
        ));
    }
    // The fragility example: its runs, and the table the README says it prints, row by row.
    let runs = out("f.csv");
    let sweep = stderr(&pound(&[
        "sweep",
        "configs/fragility-example.toml",
        "-o",
        &runs,
    ]));
    says(&format!(
        "{} runs, about a second",
        thousands(count_before(&sweep, "runs"))
    ));
    let printed = ok(&pound(&[
        "fragility",
        &runs,
        "--im",
        "pga_g",
        "--edp",
        "peak_force_n",
        "--threshold",
        "0,1e6,3e6",
        "-o",
        &out("fr.csv"),
    ]));
    let quoted: Vec<&str> = readme
        .split(" | peak_force_n > | ")
        .nth(1)
        .expect("README quotes the fragility table")
        .split(" ![")
        .next()
        .unwrap()
        .split(" | ")
        .collect();
    let flat = printed.replace('\n', " ");
    let table = quoted.join(" | ");
    assert!(
        flat.contains(&format!("| peak_force_n > | {table}")),
        "README's fragility table is not what the command prints:\n{table}\n---\n{printed}"
    );
    // The gap study's rule summary.
    let gap = ok(&pound(&[
        "gap",
        "configs/gap-study.toml",
        "-o",
        &out("g.csv"),
        "--gaps",
        "0:0.4:0.01",
    ]));
    let rule = |name: &str| -> Vec<String> {
        gap.lines()
            .find(|l| l.starts_with(&format!("| 1-2 | {name} |")))
            .unwrap_or_else(|| panic!("no {name} line in:\n{gap}"))
            .split('|')
            .map(|c| c.trim().to_string())
            .collect()
    };
    let (abs, srss, ddc) = (rule("ABS"), rule("SRSS"), rule("DDC"));
    let share = |r: &[String]| {
        let pct: f64 = r[8]
            .split('(')
            .nth(1)
            .unwrap()
            .trim_end_matches(" %)")
            .parse()
            .unwrap();
        format!("{pct:.0} %")
    };
    let two = |c: &str| format!("{:.2}", c.parse::<f64>().unwrap());
    says(&format!("({} runs, ", thousands(abs[3].parse().unwrap())));
    says(&format!("ABS asks for a median {} times", two(&abs[5])));
    says(&format!(
        "SRSS ({}) and DDC ({})",
        two(&srss[5]),
        two(&ddc[5])
    ));
    says(&format!(
        "are short in {} and {} of the runs",
        share(&srss),
        share(&ddc)
    ));
    // The help and the docs say what the commands do.
    let help = ok(&pound(&["--help"]));
    let trace_line = help
        .lines()
        .find(|l| l.trim_start().starts_with("trace"))
        .unwrap();
    assert!(trace_line.contains("rows"), "{trace_line}");
    let trace = dir.path().join("t.csv");
    ok(&pound(&[
        "trace",
        "configs/inelastic-row.toml",
        "--run",
        "0",
        "-o",
        trace.to_str().unwrap(),
    ]));
    let header = std::fs::read_to_string(&trace).unwrap();
    let inelastic =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/docs/inelastic.md")).unwrap();
    for column in ["b1_s1_plastic_drift_ratio", "b1_s1_hysteretic_energy_j"] {
        assert!(header.lines().next().unwrap().contains(column));
        assert!(
            inelastic.contains(column),
            "docs/inelastic.md does not name {column}"
        );
    }
    assert!(!inelastic.contains("not its storeys' plastic"));
    let fragility =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/docs/fragility.md")).unwrap();
    assert!(!fragility.contains("yielding storeys are issue"));
}

// The remaining classes, one file per area (each file's tests named after their class).
mod figures; // classes 4, 5, 14 and the long title of 9: what a figure shows
mod inputs; // classes 7, 8, 11 and the config and record parts of 9: what a config and a record take
mod studies; // classes 10, 13 and the fragility parts of 8 and 9: what a fit says
