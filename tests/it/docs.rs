//! Words out of date: the numbers the README quotes from its commands are what those commands
//! print now, and the help and docs say what the commands do.

use crate::support::{ok, pound, tempdir};

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
