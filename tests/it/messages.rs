//! Messages say what the file and the numbers say (issue 65, item 5): a derived number is shown
//! as the value it stands for, not to its last rounding ulp.

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
