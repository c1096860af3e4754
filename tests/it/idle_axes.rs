//! Issue 65, items 2 and 5: an axis that cannot change a run is refused, naming it (a building
//! alone with a leftover `[contact]` repeated every run with the same physics and dropped its
//! gap list), and `pound gap` takes a config without its contact and gap axes.

use crate::support::{ok, pound, table, tempdir};
use pounding::plan::config::load_text;
use pounding::plan::Plan;
use std::path::Path;

const STOREYS3: &str =
    "storeys = 3\nstorey_height_m = 3.0\nmass_kg = 2.0e5\nperiod_s = 0.5\ndamping_ratio = 0.05\n";
const RECORD: &str =
    "[[record]]\nsynthetic = { seed = 1, duration_s = 2.0 }\n\n[intensity]\npga_g = [0.2, 0.4]\n";

fn load(text: &str) -> Result<Plan, String> {
    load_text(text, Path::new("t.toml")).map_err(|e| e.to_string())
}

/// The error of a config that must be refused, with every piece `expected` in it.
fn refused(text: &str, expected: &[&str]) -> String {
    let e = match load(text) {
        Ok(p) => panic!("accepted ({} runs):\n{text}", p.len()),
        Err(e) => e,
    };
    for x in expected {
        assert!(e.contains(x), "`{x}` not in: {e}");
    }
    e
}

fn alone(contact: &str) -> String {
    format!("[[building]]\n{STOREYS3}\n{contact}\n{RECORD}")
}

/// A row of `buildings` (each its `[[building]]` body), the contact and the sections after.
fn row(buildings: &[&str], rest: &str) -> String {
    let mut t: String = buildings
        .iter()
        .map(|b| format!("[[building]]\n{b}\n"))
        .collect();
    t.push_str(rest);
    t.push('\n');
    t.push_str(RECORD);
    t
}

/// The case: a building alone with a leftover `[contact]` of laws, formulas and `e`
/// ran each run 7 times with the same physics, and dropped its gap list.
#[test]
fn a_building_alone_refuses_contact_axes() {
    let cfg = alone(
        "[contact]\nlaw = [\"linear\", \"kelvin_voigt\", \"hunt_crossley\"]\nformula = [\"anagnostopoulos\", \"exact\"]\ne = [0.5, 0.7]\nk_n_per_m = 1e9\nbeta_n_per_m1_5 = 1e10\ngap_m = [0.01, 0.02]\n",
    );
    refused(
        &cfg,
        &[
            "contact.law, contact.formula, contact.e, contact.gap_m:",
            "a building alone has no contact",
            "would repeat each run 7 times with the same physics",
            "add a second [[building]]",
        ],
    );
    // One axis alone, and the binary: refused before any run, nothing written.
    let d = tempdir();
    let path = d.path().join("alone.toml");
    std::fs::write(
        &path,
        alone("[contact]\nlaw = \"linear\"\nk_n_per_m = [1e8, 1e9, 1e10]\ngap_m = 0.01\n"),
    )
    .unwrap();
    let out_csv = d.path().join("out.csv");
    let out = pound(&[
        "sweep",
        path.to_str().unwrap(),
        "-o",
        out_csv.to_str().unwrap(),
        "--backend",
        "cpu",
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{err}");
    assert!(
        err.contains("contact.k_n_per_m: a building alone has no contact: this axis would repeat each run 3 times"),
        "{err}"
    );
    assert!(!out_csv.exists());
}

/// A gap list with one building was dropped without a word: refused. Single values are a
/// leftover, not an axis: accepted with the right notice (it said "every pair has its own
/// gap_right_m"), the runs those of the building without `[contact]`.
#[test]
fn a_building_alone_refuses_a_gap_list_and_names_a_leftover_contact() {
    refused(
        &alone("[contact]\nlaw = \"linear\"\nk_n_per_m = 1e9\ngap_m = [0.01, 0.02]\n"),
        &[
            "contact.gap_m: a building alone has no contact: this axis cannot change a run",
            "remove it or add a second [[building]]",
        ],
    );
    let leftover = load(&alone(
        "[contact]\nlaw = \"kelvin_voigt\"\nformula = \"exact\"\ne = 0.6\nk_n_per_m = 1e9\ngap_m = 0.01\n",
    ))
    .unwrap();
    let bare = load(&alone("")).unwrap();
    assert_eq!(leftover.len(), bare.len());
    let w = leftover.input_warnings();
    assert!(
        w.iter()
            .any(|w| w == "[contact] is ignored: a building alone has no contact"),
        "{w:?}"
    );
    assert!(!w.iter().any(|w| w.contains("gap_right_m")), "{w:?}");
}

/// Sampled contact values of a building alone: each sample repeated every run.
#[test]
fn a_building_alone_refuses_sampled_contact_values() {
    let sample = |contact: &str, key: &str| {
        alone(&format!(
            "[contact]\nlaw = \"linear\"\n{contact}\n[sample]\nn = 4\nseed = 1\n[[sample.axis]]\nkey = \"{key}\"\ndist = \"uniform\"\nmin = 0.01\nmax = 0.02\n"
        ))
    };
    refused(
        &sample("", "contact.k_n_per_m"),
        &[
            "sample.axis[0] (contact.k_n_per_m): a building alone has no contact",
            "would repeat each run 4 times",
        ],
    );
    // It said "every gap is given per building (gap_right_m)".
    refused(
        &sample("k_n_per_m = 1e9", "contact.gap_m"),
        &["sample.axis[0] (contact.gap_m): a building alone has no contact"],
    );
}

/// A contact axis that none of the laws given takes was dropped without a word, a sampled one
/// repeated every run: refused, naming the laws that take it. Where some law takes it, it
/// varies that law's runs only, as before.
#[test]
fn contact_axes_no_law_takes_are_refused() {
    let pair = |contact: &str| {
        format!("[building1]\nmass_kg = 1e5\nperiod_s = 0.5\ndamping_ratio = 0.05\n[building2]\nmass_kg = 1e5\nperiod_s = 0.8\ndamping_ratio = 0.05\n[contact]\ngap_m = [0.0, 0.01]\n{contact}\n{RECORD}")
    };
    refused(
        &pair("law = [\"linear\", \"hertz\"]\nk_n_per_m = 1e9\nbeta_n_per_m1_5 = 1e10\ne = [0.5, 0.7]"),
        &["contact.e: 2 values, but none of the laws given (linear, hertz) takes a coefficient of restitution e", "cannot change a run"],
    );
    refused(
        &pair("law = \"hunt_crossley\"\nbeta_n_per_m1_5 = 1e10\ne = 0.6\nformula = [\"anagnostopoulos\", \"exact\"]"),
        &["contact.formula: 2 values, but none of the laws given (hunt_crossley) takes a restitution formula"],
    );
    refused(
        &pair("law = \"hertz\"\nbeta_n_per_m1_5 = 1e10\nk_n_per_m = [1e8, 1e9]"),
        &["contact.k_n_per_m: 2 values, but none of the laws given (hertz) takes k"],
    );
    refused(
        &pair("law = \"linear\"\nk_n_per_m = 1e9\nbeta_n_per_m1_5 = [1e9, 1e10]"),
        &["contact.beta_n_per_m1_5: 2 values, but none of the laws given (linear) takes beta"],
    );
    refused(
        &pair("law = \"linear\"\nk_n_per_m = 1e9\n\n[sample]\nn = 3\nseed = 2\n[[sample.axis]]\nkey = \"contact.beta_n_per_m1_5\"\ndist = \"uniform\"\nmin = 1e9\nmax = 1e10"),
        &["sample.axis[0] (contact.beta_n_per_m1_5): is sampled, but none of the laws given (linear) takes beta"],
    );
    // A row's contact too.
    refused(
        &row(
            &[STOREYS3, STOREYS3],
            "[contact]\nlaw = \"linear\"\nk_n_per_m = 1e9\ne = [0.5, 0.7]\ngap_m = 0.01",
        ),
        &["contact.e: 2 values, but none of the laws given (linear)"],
    );
    // Taken by one law of two: its runs vary, the other's do not (2 gaps x 2 intensities x
    // (1 + 2) contact runs).
    let p = load(&pair(
        "law = [\"linear\", \"kelvin_voigt\"]\nformula = \"exact\"\nk_n_per_m = 1e9\ne = [0.5, 0.7]",
    ))
    .unwrap();
    assert_eq!(p.len(), 2 * 2 * 3);
}

/// Buildings that share no contact level (no common floor elevation, floor/column contact
/// turned off) never touch: their gap axis, or every contact axis where no pair touches,
/// would repeat each run.
#[test]
fn axes_of_pairs_that_never_touch_are_refused() {
    let low = "storeys = 2\nstorey_height_m = 3.0\nmass_kg = 2.0e5\nperiod_s = 0.4\ndamping_ratio = 0.05\n";
    let off = "storeys = 2\nstorey_height_m = 3.5\nmass_kg = 2.0e5\nperiod_s = 0.5\ndamping_ratio = 0.05\n";
    let levels = "[levels]\nfloor_column = false\n";
    refused(
        &row(
            &[low, off],
            &format!(
                "{levels}[contact]\nlaw = \"linear\"\nk_n_per_m = 1e9\ngap_m = [0.0, 0.01, 0.02]"
            ),
        ),
        &[
            "contact.gap_m: no two neighbours share a contact level",
            "would repeat each run 3 times",
        ],
    );
    refused(
        &row(
            &[low, off],
            &format!("{levels}[contact]\nlaw = [\"linear\", \"kelvin_voigt\"]\nformula = \"exact\"\ne = 0.6\nk_n_per_m = 1e9\ngap_m = 0.01"),
        ),
        &["contact.law: no two neighbours share a contact level", "would repeat each run 2 times"],
    );
    // Three buildings: 1 and 2 touch, 2 and 3 never do. The gap of 1-2 varies runs; 2-3's
    // would repeat them.
    let gapped =
        |g: &str| format!("{low}gap_right_m = [0.0, 0.01]\n[[building]]\n{low}gap_right_m = {g}");
    refused(
        &row(
            &[&gapped("[0.0, 0.02]"), off],
            &format!("{levels}[contact]\nlaw = \"linear\"\nk_n_per_m = 1e9"),
        ),
        &[
            "building[1].gap_right_m: buildings 2 and 3 share no contact level",
            "would repeat each run 2 times",
        ],
    );
    let p = load(&row(
        &[&gapped("0.02"), off],
        &format!("{levels}[contact]\nlaw = \"linear\"\nk_n_per_m = 1e9"),
    ))
    .unwrap();
    assert_eq!(p.len(), 2 * 2);
}

/// A row's `contact.gap_m` list where every pair has its own `gap_right_m` was dropped with a
/// warning: refused (one value keeps the warning: `row_sweeps::a_shared_gap_means_one_gap`).
#[test]
fn a_shared_gap_list_no_pair_reads_is_refused() {
    refused(
        &row(
            &[&format!("{STOREYS3}gap_right_m = 0.01"), STOREYS3],
            "[contact]\nlaw = \"linear\"\nk_n_per_m = 1e9\ngap_m = [0.0, 0.02]",
        ),
        &["contact.gap_m: every pair has its own gap_right_m, so no pair reads contact.gap_m: this axis cannot change a run"],
    );
}

/// Two records of the same accelerations under two labels, and a range whose points round to
/// one value, repeat runs with the same physics.
#[test]
fn repeated_motions_and_coinciding_points_are_refused() {
    let cfg = format!(
        "[[building]]\n{STOREYS3}\n[[building]]\n{STOREYS3}\n[contact]\nlaw = \"linear\"\nk_n_per_m = 1e9\ngap_m = 0.01\n\n[[record]]\nname = \"a\"\nsynthetic = {{ seed = 1, duration_s = 2.0 }}\n[[record]]\nname = \"b\"\nsynthetic = {{ seed = 1, duration_s = 2.0 }}\n"
    );
    refused(
        &cfg,
        &["record[1]: `b` holds the same accelerations (same dt and start) as record[0] `a`"],
    );
    assert!(load(&cfg.replacen("seed = 1", "seed = 2", 1)).is_ok());
    refused(
        &row(
            &[STOREYS3, STOREYS3],
            "[contact]\nlaw = \"linear\"\nk_n_per_m = 1e9\ngap_m = { from = 0.01, to = 0.0100000000001, n = 3 }",
        ),
        &["contact.gap_m: gives 0.0100000000001 twice (its points are closer than 12 significant digits)"],
    );
}

/// `pound gap` runs a config without its contact and gap axes: a row (or pair) config with
/// neither is taken (it wanted a `gap_right_m` it then ignored), its table the same as with
/// them; a gap axis given is where the probability of pounding is counted, as before.
#[test]
fn pound_gap_takes_a_config_without_contact_and_gaps() {
    let d = tempdir();
    let tall = "storeys = 3\nstorey_height_m = 3.0\nmass_kg = 2.0e5\nperiod_s = [0.6, 0.8]\ndamping_ratio = 0.05\n";
    let cases = [
        ("row", format!("[[building]]\n{STOREYS3}\n[[building]]\n{tall}\n"), "[contact]\nlaw = \"hertz\"\nbeta_n_per_m1_5 = 1e10\n"),
        ("pair", "[building1]\nmass_kg = 1e5\nperiod_s = 0.5\ndamping_ratio = 0.05\n[building2]\nmass_kg = 1e5\nperiod_s = [0.6, 0.9]\ndamping_ratio = 0.05\n".to_string(), "[contact]\nlaw = \"hertz\"\nbeta_n_per_m1_5 = 1e10\n"),
    ];
    for (name, body, contact) in cases {
        let bare = d.path().join(format!("{name}-bare.toml"));
        let with = d.path().join(format!("{name}-with.toml"));
        let gapped = d.path().join(format!("{name}-gapped.toml"));
        std::fs::write(&bare, format!("{body}\n{RECORD}")).unwrap();
        std::fs::write(&with, format!("{body}\n{contact}gap_m = 0.01\n{RECORD}")).unwrap();
        std::fs::write(
            &gapped,
            format!("{body}\n{contact}gap_m = [0.0, 0.005, 0.5]\n{RECORD}"),
        )
        .unwrap();
        let gap = |cfg: &Path, tag: &str| {
            let csv = d.path().join(format!("{name}-{tag}.csv"));
            let curve = d.path().join(format!("{name}-{tag}-curve.csv"));
            ok(&pound(&[
                "gap",
                cfg.to_str().unwrap(),
                "-o",
                csv.to_str().unwrap(),
                "--curve",
                curve.to_str().unwrap(),
            ]));
            (std::fs::read(&csv).unwrap(), table(&curve))
        };
        let (a, curve) = gap(&bare, "bare");
        let (b, _) = gap(&with, "with");
        assert!(a == b, "{name}: the gap tables differ");
        // Counted at 21 round gaps, not at the unused placeholder.
        assert!(curve.len() > 2 * 3, "{name}: {} points", curve.len());
        let (_, counted) = gap(&gapped, "gapped");
        let mut at: Vec<String> = counted.iter().map(|r| r["gap_m"].clone()).collect();
        at.sort();
        at.dedup();
        assert_eq!(at, ["0", "0.005", "0.5"], "{name}");
        // A sweep needs them, and says which.
        let out = pound(&["sweep", bare.to_str().unwrap(), "-o", "/dev/null"]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success());
        assert!(err.contains("contact: missing"), "{name}: {err}");
    }
}
