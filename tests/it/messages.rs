//! Messages say what the file and the numbers say (issue 65, item 5): a derived number is shown
//! as the value it stands for, not to its last rounding ulp.

use crate::scenes::{row, STOREYS2, STOREYS3};
use crate::support::cli::{fails_with, s, sweep, warns, write};
use crate::support::{ok, pound, records_dir, tempdir};

/// A time-value CSV's dt is a difference of two times (0.04 - 0.02 leaves 0.019999999999999997):
/// `record info` shows 0.02 s, as the file's time column says.
#[test]
fn record_info_shows_a_time_columns_dt_as_the_file_gives_it() {
    let f = records_dir().join("tabas1978_tabas_L1_RSN143_TAB-L1_timeacc.csv");
    let text = ok(&pound(&["record", "info", f.to_str().unwrap()]));
    assert!(text.contains("dt        0.02 s\n"), "{text}");
    assert!(text.contains("t0        0.02 s\n"), "{text}");
    // A two-column file written here: dt 0.1 from times 0.1, 0.2, 0.3 (0.2 - 0.1 and
    // 0.30000000000000004 - 0.2 are not 0.1 in binary).
    let d = tempdir();
    let two = d.path().join("two.dat");
    std::fs::write(&two, "0.1 0.0\n0.2 0.5\n0.3 -0.2\n0.4 0.1\n").unwrap();
    let text = ok(&pound(&["record", "info", two.to_str().unwrap()]));
    assert!(text.contains("dt        0.1 s\n"), "{text}");
}

/// A spectrum's damping is shown in per cent as typed: 0.07 is 7 %, not 7.000000000000001 %.
#[test]
fn spectrum_names_its_damping_in_per_cent_as_typed() {
    let f = records_dir().join("elcentro1940_ns_I-ELC180_peer2000.AT2");
    let d = tempdir();
    let out = d.path().join("s.csv");
    let r = pound(&[
        "record",
        "spectrum",
        f.to_str().unwrap(),
        "--damping",
        "0.07",
        "-o",
        out.to_str().unwrap(),
    ]);
    let text = ok(&r);
    assert!(
        text.contains("(") && text.contains("7 % damping)"),
        "{text}"
    );
}

/// An IDA over one curve says its fractiles are that curve's demands (all three equal), not a
/// spread across records.
#[test]
fn an_ida_of_one_curve_says_its_fractiles_have_no_spread() {
    let d = tempdir();
    let table = d.path().join("one.csv");
    let mut t = String::from("record,pga_g,status,b1_peak_drift_ratio\n");
    for (l, pga) in [0.2, 0.4, 0.6].iter().enumerate() {
        t.push_str(&format!("only,{pga},ok,{}\n", 0.003 * (l + 1) as f64));
    }
    std::fs::write(&table, t).unwrap();
    let out = d.path().join("ida.csv");
    let r = pound(&[
        "ida",
        table.to_str().unwrap(),
        "--edp",
        "b1_peak_drift_ratio",
        "-o",
        out.to_str().unwrap(),
    ]);
    let said = format!(
        "{}{}",
        String::from_utf8_lossy(&r.stdout),
        String::from_utf8_lossy(&r.stderr)
    );
    assert!(r.status.success(), "{said}");
    assert!(said.contains("notice: one curve (only)"), "{said}");
}

/// A key a law needs that the config leaves out is called missing, not "empty".
#[test]
fn a_missing_contact_key_is_called_missing() {
    let d = tempdir();
    let cfg = d.path().join("nobeta.toml");
    std::fs::write(
        &cfg,
        r#"
[building1]
mass_kg = 1.0e5
period_s = 0.3
damping_ratio = 0.05
[building2]
mass_kg = 1.0e5
period_s = 0.6
damping_ratio = 0.05
[contact]
law = "hertz"
gap_m = 0.01
[[record]]
synthetic = { seed = 1, duration_s = 2.0 }
"#,
    )
    .unwrap();
    let r = pound(&["sweep", cfg.to_str().unwrap(), "-o", "-"]);
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(!r.status.success(), "{err}");
    assert!(
        err.contains("contact.beta_n_per_m1_5: is missing or empty"),
        "{err}"
    );
}

/// Class 9: messages give the bound or the fact, not a generic complaint.
#[test]
fn messages_name_the_bound_and_the_fact() {
    let d = tempdir();
    let cfg = write(d.path(), "row.toml", &row(STOREYS3, STOREYS2, ""));
    fails_with(
        &pound(&[
            "gap",
            s(&cfg),
            "-o",
            s(&d.path().join("g.csv")),
            "--gaps",
            "0:1e9:1",
        ]),
        "expected at most 10000",
    );
    let zero = write(
        d.path(),
        "zero.AT2",
        "PEER\nx\nUNITS OF G\nNPTS=   0, DT= .0000 SEC\n0.1 0.2\n",
    );
    fails_with(&pound(&["record", "info", s(&zero)]), "NPTS = 0 and DT = 0");
    let reference = write(
        d.path(),
        "ref.toml",
        &row(STOREYS3, STOREYS2, "")
            .replace("tail_s = 0.5", "tail_s = 0.5\nscheme = \"reference\""),
    );
    fails_with(
        &pound(&[
            "sweep",
            s(&reference),
            "--target-error",
            "1e-2",
            "-o",
            s(&d.path().join("r.csv")),
        ]),
        "(run.tol)",
    );
    let spc = write(
        d.path(),
        "spc.toml",
        &row(STOREYS3, STOREYS2, "")
            .replace("tail_s = 0.5", "tail_s = 0.5\nsubsteps_per_contact = 32"),
    );
    warns(
        &sweep(&spc, &d.path().join("s.csv"), &["--target-error", "1e-2"]),
        "overrides the config's run.substeps_per_contact = 32",
    );
    let results = d.path().join("s.csv");
    warns(
        &pound(&[
            "plot",
            s(&results),
            "--x",
            "gap_1_2_m",
            "--y",
            "b1_peak_roof_m",
            "--log-x",
            "-o",
            s(&d.path().join("p.svg")),
        ]),
        "points left out: a value <= 0 on a log axis",
    );
    let huge = write(
        d.path(),
        "huge.toml",
        &row(STOREYS3, STOREYS2, "").replace("tail_s = 0.5", "tail_s = 1e300"),
    );
    let o = pound(&["sweep", s(&huge), "-o", s(&d.path().join("h.csv"))]);
    fails_with(&o, "1e300 is out of range");
    // The storey bound is documented.
    let doc = std::fs::read_to_string("docs/multistorey.md").unwrap();
    assert!(doc.contains(&format!(
        "{} storeys",
        pounding::physics::shear::MAX_STOREYS
    )));
}
