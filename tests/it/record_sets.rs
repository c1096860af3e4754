//! Record sets: a folder of PEER NGA-West2 downloads run through its `_SearchResults.csv`
//! (`[[record]] set = "DIR"`), and `pound record info DIR`. The folder is built in a temporary
//! directory from the shared records, under the names a PEER download gives them.

use crate::support::cli::{s, sweep, write};
use crate::support::run::{ok, pound};
use crate::support::{csv_column, records_dir, tempdir};
use std::path::Path;

/// A search's results as PEER writes them: criteria first, the metadata block with its
/// leading-space header and quoted names, a line of commas and the notes after.
const RESULTS: &str = r#" -- Summary of GMDApp Search Criteria --,,,,
Spectrum Model:,ASCE 7-16,,,

 -- Summary of Metadata of Selected Records --,,,,,,,,,,,,,,,,,,,,
 Result ID, Record Sequence Number, Scale Factor, Tp, D5-75 (sec), D5-95 (sec), Arias Intensity (m/sec), Earthquake Name, Year, Station Name, Magnitude, Mechanism, Rjb (km), Rrup (km), Vs30 (m/sec), Lowest Usable Frequency (Hz), Horizontal-1 Acc. Filename, Horizontal-2 Acc. Filename, Vertical Acc. Filename
1, 6, 1.2500, ---, 7.8, 24.2, 1.8," ""Imperial Valley-02""", 1940," ""El Centro Array #9""", 6.95," strike slip", 6.09, 6.09, 213.44, 0.1, RSN6_IMPVALL.I_I-ELC180.AT2, RSN6_IMPVALL.I_I-ELC270.AT2, ---
2, 1106, 0.8000, ---, 3.6, 8.4, 8.4," ""Kobe_ Japan""", 1995," ""KJMA""", 6.9," strike slip", 0.94, 0.96, 312, 0.13, RSN1106_KOBE_KJM000.AT2, RSN1106_KOBE_KJM090.AT2, ---
,,,,,,,,,,,,,,,,,,,,
These records were obtained from the NGA-West2 On-Line Ground-Motion Database Tool,,,,
"#;

/// The set's files: shared records under the names the search lists.
const FILES: [(&str, &str); 4] = [
    (
        "elcentro1940_ns_RSN6_I-ELC180.AT2",
        "RSN6_IMPVALL.I_I-ELC180.AT2",
    ),
    (
        "elcentro1940_ns_I-ELC180_peer2000.AT2",
        "RSN6_IMPVALL.I_I-ELC270.AT2",
    ),
    (
        "kobe1995_jma_ns_RSN1106_KJM000.AT2",
        "RSN1106_KOBE_KJM000.AT2",
    ),
    (
        "lomaprieta1989_corralitos_ns_RSN753_CLS000.AT2",
        "RSN1106_KOBE_KJM090.AT2",
    ),
];

/// The set in `dir`/`name` with `results` as its search results.
fn make_set(dir: &Path, name: &str, results: &str) -> std::path::PathBuf {
    let set = dir.join(name);
    std::fs::create_dir_all(&set).unwrap();
    for (from, to) in FILES {
        std::fs::copy(records_dir().join(from), set.join(to)).unwrap();
    }
    write(&set, "_SearchResults.csv", results);
    set
}

/// A pair under `records` (TOML) at a scale of 1.
fn config(records: &str) -> String {
    format!(
        r#"
[building1]
period_s = 0.5
mass_kg = 1.0e5
damping_ratio = 0.05

[building2]
period_s = 1.0
mass_kg = 2.0e5
damping_ratio = 0.05

[contact]
law = "linear"
k_n_per_m = 1e8
gap_m = 0.02

{records}

[intensity]
scale = 1.0
"#
    )
}

/// A set runs each record's horizontal components, labelled by RSN and component; each run is
/// the run of its file given by `path =` under that name, to the byte, with the search's
/// metadata after every other column (a pair's and a row's); with `search_scale` each record
/// is scaled by its search's factor (PGA 1.25 and 0.8 times).
#[test]
fn a_set_runs_each_listed_component_as_its_file_would() {
    let dir = tempdir();
    let set = make_set(dir.path(), "peer", RESULTS);
    // Config `text` written as NAME.toml, swept into NAME.csv: its config, output and rows.
    let swept = |name: &str, text: &str| {
        let cfg = write(dir.path(), &format!("{name}.toml"), text);
        let out = dir.path().join(format!("{name}.csv"));
        ok(&sweep(&cfg, &out, &[]));
        let rows = std::fs::read_to_string(&out).unwrap();
        (cfg, out, rows)
    };
    let (cfg, out, text) = swept("set", &config("[[record]]\nset = \"peer\""));
    let labels = ["RSN6_H1", "RSN6_H2", "RSN1106_H1", "RSN1106_H2"];
    assert_eq!(csv_column(&text, "record"), labels);
    // The same runs, each file named by hand.
    let by_hand: String = FILES
        .iter()
        .zip(labels)
        .map(|((_, file), label)| {
            format!(
                "[[record]]\npath = \"{}\"\nname = \"{label}\"\n",
                s(&set.join(file))
            )
        })
        .collect();
    let (_, _, hand) = swept("hand", &config(&by_hand));
    // Every column but the set's metadata, which the set's runs carry after all others.
    let meta = pounding::plan::columns::RECORD_META;
    let without_meta = |t: &str| -> String {
        t.lines()
            .map(|l| {
                let cells: Vec<&str> = l.split(',').collect();
                cells[..cells.len() - meta.len()].join(",")
            })
            .collect::<Vec<_>>()
            .join("\n")
    };
    assert_eq!(without_meta(&text), hand.trim_end());
    assert_eq!(csv_column(&text, "record_rsn"), ["6", "6", "1106", "1106"]);
    assert_eq!(
        csv_column(&text, "record_component"),
        ["H1", "H2", "H1", "H2"]
    );
    assert_eq!(csv_column(&text, "record_event")[2], "Kobe_ Japan");
    assert_eq!(csv_column(&text, "record_magnitude")[0], "6.95");
    assert_eq!(csv_column(&text, "record_rjb_km")[2], "0.94");
    assert_eq!(csv_column(&text, "record_rrup_km")[2], "0.96");
    assert_eq!(csv_column(&text, "record_vs30_m_s")[0], "213.44");
    // The set's files are inputs: an output over its search results is refused.
    let results = set.join("_SearchResults.csv");
    let o = sweep(&cfg, &results, &[]);
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("would destroy it"));
    assert_eq!(std::fs::read_to_string(&results).unwrap(), RESULTS);
    // The metadata is part of the sweep: a search that now says otherwise is another sweep.
    write(
        &set,
        "_SearchResults.csv",
        &RESULTS.replace(" 6.95,", " 7.1,"),
    );
    let o = sweep(&cfg, &out, &["--resume"]);
    assert!(!o.status.success());
    assert!(
        String::from_utf8_lossy(&o.stderr).contains("differs from the sweep that wrote it"),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    write(&set, "_SearchResults.csv", RESULTS);
    // A row's runs carry them too.
    let row = config("[[record]]\nset = \"peer\"\ncomponents = [\"H2\"]")
        .replace(
            "[building1]",
            "[[building]]\nstoreys = 1\nstorey_height_m = 3.0",
        )
        .replace(
            "[building2]",
            "[[building]]\nstoreys = 1\nstorey_height_m = 3.0",
        );
    let (_, _, rows) = swept("row", &row);
    assert_eq!(csv_column(&rows, "record"), ["RSN6_H2", "RSN1106_H2"]);
    assert_eq!(csv_column(&rows, "record_rsn"), ["6", "1106"]);
    assert_eq!(csv_column(&rows, "record_component"), ["H2", "H2"]);
    // At the search's scale factors.
    let (_, _, scaled) = swept(
        "scaled",
        &config("[[record]]\nset = \"peer\"\nsearch_scale = true\ncomponents = [\"H1\"]"),
    );
    assert_eq!(csv_column(&scaled, "record"), ["RSN6_H1", "RSN1106_H1"]);
    let pga = |t: &str| -> Vec<f64> {
        csv_column(t, "pga_g")
            .iter()
            .map(|x| x.parse().unwrap())
            .collect()
    };
    // The search's factor is the runs' scale factor (at [intensity] scale = 1).
    assert_eq!(csv_column(&scaled, "scale_factor"), ["1.25", "0.8"]);
    let (plain, scaled) = (pga(&text), pga(&scaled));
    for (i, f) in [(0, 1.25), (2, 0.8)] {
        let j = i / 2;
        assert!(
            (scaled[j] - f * plain[i]).abs() <= 1e-12 * plain[i],
            "{}: {} vs {f} x {}",
            labels[i],
            scaled[j],
            plain[i]
        );
    }
}

/// `pound record info DIR` tabulates the set under the labels a sweep gives its runs, with
/// the search's metadata, and each file's PGA as `record info FILE` reads it.
#[test]
fn record_info_of_a_set_tabulates_its_records() {
    let dir = tempdir();
    let set = make_set(dir.path(), "peer", RESULTS);
    let table = ok(&pound(&["record", "info", s(&set)]));
    assert_eq!(
        csv_column(&table, "record"),
        ["RSN6_H1", "RSN6_H2", "RSN1106_H1", "RSN1106_H2"]
    );
    assert_eq!(
        csv_column(&table, "event"),
        [
            "Imperial Valley-02",
            "Imperial Valley-02",
            "Kobe_ Japan",
            "Kobe_ Japan"
        ]
    );
    assert_eq!(csv_column(&table, "magnitude")[2], "6.9");
    assert_eq!(csv_column(&table, "rrup_km")[3], "0.96");
    assert_eq!(csv_column(&table, "scale_factor")[0], "1.25");
    let one = ok(&pound(&["record", "info", s(&set.join(FILES[2].1))]));
    let pga_line = one.lines().find(|l| l.starts_with("pga ")).unwrap();
    let pga: f64 = csv_column(&table, "pga_g")[2].parse().unwrap();
    let shown: f64 = pga_line.split_whitespace().nth(1).unwrap().parse().unwrap();
    assert!((pga - shown).abs() <= 5e-5, "{pga} vs {pga_line}");
}

/// A set that cannot run is refused before any run, naming the file, line or key: a listed
/// file that is not in the folder, a component the search has none of, a typo in
/// components, a name given to a set, a search without the block.
#[test]
fn a_broken_set_is_refused_by_file_line_and_key() {
    let dir = tempdir();
    make_set(dir.path(), "peer", RESULTS);
    let missing = RESULTS.replace("RSN1106_KOBE_KJM090.AT2", "RSN1106_KOBE_KJM999.AT2");
    make_set(dir.path(), "missing", &missing);
    make_set(dir.path(), "none", "Result ID, RSN\n1, 6\n");
    make_set(
        dir.path(),
        "comma",
        &RESULTS.replace("\" \"\"Kobe_ Japan\"\"\"", " Kobe, Japan"),
    );
    std::fs::create_dir_all(dir.path().join("bare")).unwrap();
    for (records, needles) in [
        (
            "set = \"missing\"",
            vec!["_SearchResults.csv:7", "RSN1106_KOBE_KJM999.AT2", "H2"],
        ),
        (
            "set = \"peer\"\ncomponents = [\"V\"]",
            vec!["record[0].components", "RSN 6 has no V file", "line 6"],
        ),
        (
            "set = \"peer\"\ncomponents = [\"H3\"]",
            vec!["`H3`", "\"H1\", \"H2\", \"V\""],
        ),
        (
            "set = \"peer\"\nname = \"x\"",
            vec!["record[0].name", "RSN6_H1"],
        ),
        (
            "set = \"peer\"\nfile = \"x.AT2\"",
            vec!["exactly one of file, path, synthetic or set"],
        ),
        (
            "file = \"x.AT2\"\nsearch_scale = true",
            vec!["record[0].search_scale", "record set"],
        ),
        (
            "set = \"none\"",
            vec!["Summary of Metadata of Selected Records"],
        ),
        ("set = \"\"", vec!["record[0].set", "is empty"]),
        (
            "set = \"comma\"",
            vec!["_SearchResults.csv:7", "unquoted comma"],
        ),
        ("set = \"bare\"", vec!["no _SearchResults.csv in it"]),
        ("set = \"nowhere\"", vec!["nowhere", "no such folder"]),
        // A set's factors where a target scales each record to itself.
        (
            "set = \"peer\"\nsearch_scale = true\n# target",
            vec!["record[0].search_scale", "intensity.pga_g target replaces"],
        ),
        // A record of a set is named by its entry and its label.
        (
            "set = \"peer\"\nwindow_s = [0.0, 45.0]",
            vec!["record[0] (RSN6_H2): window_s"],
        ),
        (
            "set = \"peer\"\n[[record]]\nset = \"peer\"\ncomponents = [\"H2\"]",
            vec![
                "record[1] (RSN6_H2)",
                "as record[0] (RSN6_H2) is",
                "one record set only",
            ],
        ),
    ] {
        let mut text = config(&format!("[[record]]\n{records}"));
        if records.ends_with("# target") {
            text = text.replace("scale = 1.0", "pga_g = 0.3");
        }
        let cfg = write(dir.path(), "bad.toml", &text);
        let out = dir.path().join("bad.csv");
        let o = sweep(&cfg, &out, &[]);
        let err = String::from_utf8_lossy(&o.stderr).to_string();
        assert!(!o.status.success(), "{records}: accepted");
        assert!(!err.contains("panicked"), "{records}: {err}");
        for n in needles {
            assert!(err.contains(n), "{records}: `{n}` not in: {err}");
        }
        assert!(!out.exists(), "{records}: wrote {}", out.display());
    }
}
