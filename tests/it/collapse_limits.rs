//! Nothing mixes limits: every `[run]` key that changes a run is in the plan's fingerprint, so a
//! resume or a merge across a change is refused, naming the key and both values; a storey that
//! leans hard under gravity is named before any run; every list of statuses names `collapsed`.

use crate::scenes::ROW_CONFIG;
use crate::support::cli::interrupt;
use crate::support::cli::s;
use crate::support::run::{ok, pound, sweep_cpu};
use crate::support::tempdir;
use pounding::io::provenance::{Fingerprint, Settings};
use pounding::plan::config::load_text;
use pounding::plan::Plan;
use std::path::Path;

fn err(o: &std::process::Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// ROW_CONFIG (16 runs) with `[run]` keys `run` (TOML lines).
fn row_with(run: &str) -> String {
    format!("{ROW_CONFIG}\n[run]\n{run}\n")
}

/// A pair config with `[run]` keys `run`.
fn pair_with(run: &str) -> String {
    format!(
        "[building1]\nmass_kg = 1.0e5\nperiod_s = 0.3\ndamping_ratio = 0.05\n\
         [building2]\nmass_kg = 1.0e5\nperiod_s = 0.9\ndamping_ratio = 0.05\n\
         [contact]\nlaw = \"linear\"\nk_n_per_m = 1e9\ngap_m = 0.0\n\
         [[record]]\nsynthetic = {{ seed = 1, duration_s = 1.0 }}\n[run]\n{run}\n"
    )
}

fn plan_of(text: &str) -> Plan {
    load_text(text, Path::new("limits.toml")).unwrap()
}

/// The keys a refusal names between `here` and `there` (recorded in `name`).
fn named(here: &Plan, there: &Plan, name: &str) -> Vec<String> {
    Settings::of_plan(here).differing(&Settings::of_plan(there), name)
}

/// Every key `[run]` takes, as the config reader lists them when it refuses an unknown one (so
/// a key added to `[run]` joins the test below, or fails it).
fn run_keys() -> Vec<String> {
    let e = load_text(&row_with("nope = 1"), Path::new("limits.toml"))
        .unwrap_err()
        .to_string();
    let list = &e[e.find("expected one of").expect(&e)..];
    let keys: Vec<String> = list
        .split('`')
        .skip(1)
        .step_by(2)
        .map(String::from)
        .collect();
    assert!(keys.len() >= 6, "{e}");
    keys
}

/// Each `[run]` key changes the fingerprint where it changes the runs, and the sidecar's
/// settings name it with both values; a change to no key changes neither. Checked on a row and,
/// for the keys a pair takes, on a pair.
#[test]
fn every_run_key_is_in_the_fingerprint() {
    // (key, the base `[run]`, the base with the key changed)
    let cases: [(&str, &str, &str); 9] = [
        ("scheme", "", "scheme = \"reference\""),
        (
            "substeps_per_contact",
            "substeps_per_contact = 16",
            "substeps_per_contact = 24",
        ),
        (
            "tol",
            "scheme = \"reference\"",
            "scheme = \"reference\"\ntol = 1e-6",
        ),
        (
            "tol",
            "scheme = \"reference\"\ntol = 1e-7",
            "scheme = \"reference\"\ntol = 1e-5",
        ),
        ("tail_s", "", "tail_s = 2.5"),
        ("energy", "", "energy = true"),
        ("collapse_drift_ratio", "", "collapse_drift_ratio = 0.05"),
        (
            "collapse_drift_ratio",
            "collapse_drift_ratio = 0.1",
            "collapse_drift_ratio = \"none\"",
        ),
        (
            "collapse_drift_ratio",
            "collapse_drift_ratio = 0.03",
            "collapse_drift_ratio = 0.1",
        ),
    ];
    for key in run_keys() {
        assert!(
            cases.iter().any(|c| c.0 == key),
            "[run] {key} is not tested: add it to the cases"
        );
    }
    for (key, base, changed) in cases {
        let scenes: Vec<fn(&str) -> String> = if key == "collapse_drift_ratio" {
            vec![row_with]
        } else {
            vec![row_with, pair_with]
        };
        for scene in scenes {
            let (a, b) = (plan_of(&scene(base)), plan_of(&scene(changed)));
            assert_ne!(
                Fingerprint::of_plan(&a).plan,
                Fingerprint::of_plan(&b).plan,
                "[run] {key}: `{base}` and `{changed}` hash alike"
            );
            let said = named(&b, &a, "X");
            assert!(
                said.iter().any(|w| w.starts_with(&format!("[run] {key}: "))
                    && w.contains(" here, ")
                    && w.ends_with(" in X")),
                "[run] {key}: {said:?}"
            );
            // The same config twice: the same fingerprint, nothing named.
            assert_eq!(
                Fingerprint::of_plan(&b),
                Fingerprint::of_plan(&plan_of(&scene(changed)))
            );
            assert!(named(&b, &plan_of(&scene(changed)), "X").is_empty());
        }
    }
    // The default limit written out is the default: the same runs, the same fingerprint.
    assert_eq!(
        Fingerprint::of_plan(&plan_of(&row_with(""))),
        Fingerprint::of_plan(&plan_of(&row_with("collapse_drift_ratio = 0.10")))
    );
    let said = named(
        &plan_of(&row_with("collapse_drift_ratio = 0.05")),
        &plan_of(&row_with("")),
        "OUT.meta.toml",
    );
    assert_eq!(
        said,
        ["[run] collapse_drift_ratio: 0.05 here, 0.1 in OUT.meta.toml"]
    );
}

/// Configs that use no changed key keep the fingerprint they had before the collapse limit was
/// hashed (`--resume` of their sweeps goes on): the plan hashes of commit 5941f15, printed by
/// `Fingerprint::of_plan` there.
#[test]
fn fingerprints_of_configs_at_the_defaults_are_unchanged() {
    for (text, before) in [
        (ROW_CONFIG.to_string(), "06849034577a046f9b3f3c8fa12168ad"),
        (pair_with(""), "797cd5410850e66ec6661ce98c8346fd"),
    ] {
        assert_eq!(Fingerprint::of_plan(&plan_of(&text)).plan, before, "{text}");
    }
}

/// Two layouts of equal gap values are two sets of runs: `contact.gap_m` one axis that both
/// pairs of a row of three share (2 gap values, 2 runs per scene) against `gap_right_m` per pair
/// (2 x 2). They hashed alike; a sampled `contact.gap_m` beside a pair's own `gap_right_m` at
/// the grid's placeholder alike too, whichever pair took the sample.
#[test]
fn gap_layouts_are_in_the_fingerprint() {
    let building = |gap: &str| {
        format!(
            "[[building]]\nstoreys = 1\nstorey_height_m = 3.0\nmass_kg = 2e5\nperiod_s = 0.3\ndamping_ratio = 0.05\n{gap}\n"
        )
    };
    let tail = "[[record]]\nsynthetic = { seed = 4, duration_s = 1.0, dt_s = 0.01, pga_g = 0.4 }\n";
    let contact = |gap: &str| format!("[contact]\nlaw = \"linear\"\nk_n_per_m = 1e9\n{gap}\n");
    let shared = format!(
        "{}{}{}{}{tail}",
        building(""),
        building(""),
        building(""),
        contact("gap_m = [0.01, 0.02]")
    );
    let own = format!(
        "{}{}{}{}{tail}",
        building("gap_right_m = [0.01, 0.02]"),
        building("gap_right_m = [0.01, 0.02]"),
        building(""),
        contact("")
    );
    let (a, b) = (plan_of(&shared), plan_of(&own));
    assert_eq!((a.len(), b.len()), (2, 4));
    assert_ne!(Fingerprint::of_plan(&a).plan, Fingerprint::of_plan(&b).plan);
    assert!(named(&a, &b, "X").iter().any(|w| w.starts_with("the gaps")));

    let sample = "[sample]\nn = 4\nseed = 3\n[[sample.axis]]\nkey = \"contact.gap_m\"\ndist = \"uniform\"\nmin = 0.0\nmax = 0.05\n";
    let sampled = |first: &str, second: &str| {
        format!(
            "{}{}{}{}{tail}{sample}",
            building(first),
            building(second),
            building(""),
            contact("")
        )
    };
    let (c, d) = (
        plan_of(&sampled("", "gap_right_m = 0.5")),
        plan_of(&sampled("gap_right_m = 0.5", "")),
    );
    assert_ne!(Fingerprint::of_plan(&c).plan, Fingerprint::of_plan(&d).plan);
    // The same runs: one gap sampled, the other 0.5 m, in another order.
    let gaps = |p: &Plan| match p {
        Plan::Row(r) => (0..r.len()).map(|i| r.run(i).gaps).collect::<Vec<_>>(),
        _ => unreachable!(),
    };
    assert_ne!(gaps(&c), gaps(&d));
}

/// A resume after `[run] collapse_drift_ratio` changed from 0.1 to 0.05 is refused, naming the
/// key and both values, and leaves the unfinished output as it was: the old limit's resume then
/// finishes it to the uninterrupted file, byte for byte.
#[test]
fn a_resume_across_a_changed_collapse_limit_is_refused() {
    let dir = tempdir();
    let (old, new) = (dir.path().join("old.toml"), dir.path().join("new.toml"));
    std::fs::write(&old, row_with("collapse_drift_ratio = 0.1")).unwrap();
    std::fs::write(&new, row_with("collapse_drift_ratio = 0.05")).unwrap();
    let full = dir.path().join("full.csv");
    ok(&sweep_cpu(&old, &full, &[]));
    let whole = std::fs::read(&full).unwrap();

    let cut = dir.path().join("cut.csv");
    interrupt(&old, whole.len(), &cut, 0.5);
    let partial = pounding::io::atomic::partial_path(&cut);
    let journal = pounding::io::provenance::progress_path(&cut);
    let (rows, progress) = (
        std::fs::read(&partial).unwrap(),
        std::fs::read(&journal).unwrap(),
    );
    let r = sweep_cpu(&new, &cut, &["--resume"]);
    assert!(!r.status.success(), "resumed across the limit: {}", err(&r));
    let want = format!(
        "[run] collapse_drift_ratio: 0.05 here, 0.1 in {}",
        journal.display()
    );
    assert!(err(&r).contains(&want), "{}", err(&r));
    assert!(err(&r).contains("cannot resume"), "{}", err(&r));
    assert!(!cut.exists());
    assert_eq!(std::fs::read(&partial).unwrap(), rows);
    assert_eq!(std::fs::read(&journal).unwrap(), progress);

    ok(&sweep_cpu(&old, &cut, &["--resume"]));
    assert_eq!(std::fs::read(&cut).unwrap(), whole);
}

/// Shards of one plan at limits 0.1 and 0.03 do not merge: the refusal names the key and both
/// values, and no output appears. Shards at one limit do.
#[test]
fn shards_at_two_collapse_limits_do_not_merge() {
    let dir = tempdir();
    let (a, b) = (dir.path().join("a.toml"), dir.path().join("b.toml"));
    std::fs::write(&a, row_with("collapse_drift_ratio = 0.1")).unwrap();
    std::fs::write(&b, row_with("collapse_drift_ratio = 0.03")).unwrap();
    let shard = |cfg: &Path, i: usize| {
        let out = dir.path().join(format!(
            "{}-{i}.csv",
            cfg.file_stem().unwrap().to_str().unwrap()
        ));
        ok(&sweep_cpu(cfg, &out, &["--shard", &format!("{i}/2")]));
        out
    };
    let (a0, a1, b1) = (shard(&a, 0), shard(&a, 1), shard(&b, 1));
    let merged = dir.path().join("merged.csv");
    for (inputs, here, there) in [([&a0, &b1], "0.03", "0.1"), ([&b1, &a0], "0.1", "0.03")] {
        let r = pound(&["merge", s(inputs[0]), s(inputs[1]), "-o", s(&merged)]);
        assert!(!r.status.success(), "merged two limits: {}", err(&r));
        let want = format!(
            "[run] collapse_drift_ratio: {here} here, {there} in {}",
            pounding::io::provenance::meta_path(inputs[0]).display()
        );
        assert!(err(&r).contains(&want), "{}", err(&r));
        assert!(err(&r).contains("not shards of one sweep"), "{}", err(&r));
        assert!(!merged.exists());
    }
    ok(&pound(&["merge", s(&a0), s(&a1), "-o", s(&merged)]));
    let full = dir.path().join("full.csv");
    ok(&sweep_cpu(&a, &full, &[]));
    assert_eq!(
        std::fs::read(&merged).unwrap(),
        std::fs::read(&full).unwrap()
    );
}

/// A P-Delta storey whose stability coefficient passes 0.1 is named before any run, with its
/// building, storey and value: one storey of 3 m at T = 0.5 s carrying 9 times its floor's
/// weight has `theta = g r T^2 / (4 pi^2 h)` = 0.186 (k = m (2 pi / T)^2). A building below
/// 0.1 is not named.
#[test]
fn a_storey_past_a_stability_coefficient_of_a_tenth_is_named() {
    let dir = tempdir();
    let cfg = dir.path().join("leaning.toml");
    let text = "[[building]]\nstoreys = 1\nstorey_height_m = 3.0\nmass_kg = 2e5\nperiod_s = [0.3, 0.5]\ndamping_ratio = 0.05\np_delta = true\ngravity_mass_ratio = 9.0\ngap_right_m = 0.05\n\
        [[building]]\nstoreys = 3\nstorey_height_m = 3.0\nmass_kg = 2e5\nperiod_s = 0.4\ndamping_ratio = 0.05\np_delta = true\n\
        [contact]\nlaw = \"linear\"\nk_n_per_m = 1e9\n\
        [[record]]\nsynthetic = { seed = 4, duration_s = 1.0, dt_s = 0.01, pga_g = 0.1 }\n";
    std::fs::write(&cfg, text).unwrap();
    let theta = pounding::record::G * 9.0 * 0.25 / (4.0 * std::f64::consts::PI.powi(2) * 3.0);
    let plan = plan_of(text);
    let named: Vec<String> = plan
        .input_warnings()
        .into_iter()
        .filter(|w| w.contains("stability coefficient"))
        .collect();
    assert_eq!(named.len(), 1, "{named:?}");
    for part in [
        "building 1 ".to_string(),
        "storey 1 ".into(),
        format!("{theta:.3}"),
        "period_s = 0.5".into(),
    ] {
        assert!(named[0].contains(&part), "`{part}` in {}", named[0]);
    }
    // The sweep says it, and its column agrees at that period.
    let out = dir.path().join("leaning.csv");
    let r = sweep_cpu(&cfg, &out, &[]);
    ok(&r);
    assert!(
        err(&r).contains(&format!("warning: {}: {}", cfg.display(), named[0])),
        "{}",
        err(&r)
    );
    let column: f64 = crate::support::run::table(&out)
        .iter()
        .find(|row| row["b1_t1_s"] == "0.5")
        .unwrap()["b1_stability_coefficient"]
        .parse()
        .unwrap();
    assert!((column - theta).abs() < 1e-9 * theta, "{column} {theta}");
}

/// Every status a run can end with: the match fails to compile when one is added.
fn every_status() -> Vec<&'static str> {
    use pounding::physics::model::Status;
    [
        Status::Ok,
        Status::NonFinite,
        Status::StepLimit,
        Status::Collapsed,
    ]
    .iter()
    .map(|s| {
        match s {
            Status::Ok | Status::NonFinite | Status::StepLimit | Status::Collapsed => {}
        }
        s.key()
    })
    .collect()
}

/// `pound columns` of a row with a collapse limit names every status the `status` column may
/// hold, `collapsed` among them; so does the README's table of columns.
#[test]
fn every_list_of_statuses_names_collapsed() {
    let dir = tempdir();
    let cfg = dir.path().join("row.toml");
    std::fs::write(&cfg, row_with("collapse_drift_ratio = 0.05")).unwrap();
    let table = ok(&pound(&["columns", s(&cfg)]));
    let line = table
        .lines()
        .find(|l| l.starts_with("| `status` |"))
        .expect("a status row");
    let readme = std::fs::read_to_string("README.md").unwrap();
    let in_readme = readme
        .lines()
        .find(|l| l.starts_with("| `status` |"))
        .expect("README names the status column");
    for status in every_status() {
        assert!(
            line.contains(status),
            "pound columns: {status} not in {line}"
        );
        assert!(
            in_readme.contains(&format!("`{status}`")),
            "README: {status} not in {in_readme}"
        );
    }
}
