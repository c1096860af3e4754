//! Every shared record parses, with the NPTS, dt and PGA that `shared/records/SOURCES.md` lists;
//! malformed files give errors with file and line; the synthetic generator is deterministic.

use crate::support::cli::{fails_with, pound_in, s};
use crate::support::ok;
use crate::support::{records_dir, tempdir};
use pounding::record::{
    read_record, synthetic, Format, ReadOptions, RecordError, SyntheticSpec, Units, G,
};

struct Expect {
    file: &'static str,
    opts: ReadOptions,
    npts: usize,
    dt: f64,
    t0: f64,
    pga_g: f64,
    peak_t: f64,
}

fn opts(format: Format, units: Option<Units>, dt: Option<f64>, skip: usize) -> ReadOptions {
    ReadOptions {
        format,
        units,
        dt,
        skip_lines: skip,
    }
}

/// The SOURCES.md summary table (PGA in g to 4 decimals, peak time to 0.01 s).
fn table() -> Vec<Expect> {
    let auto = || opts(Format::Auto, None, None, 0);
    vec![
        Expect {
            file: "elcentro1940_ns_I-ELC180_peer2000.AT2",
            opts: auto(),
            npts: 4000,
            dt: 0.01,
            t0: 0.0,
            pga_g: 0.3129,
            peak_t: 2.15,
        },
        Expect {
            file: "elcentro1940_ns_RSN6_I-ELC180.AT2",
            opts: auto(),
            npts: 5372,
            dt: 0.01,
            t0: 0.0,
            pga_g: 0.2808,
            peak_t: 2.18,
        },
        Expect {
            file: "elcentro1940_ns_peknold_0.02s.AT2",
            opts: auto(),
            npts: 1559,
            dt: 0.02,
            t0: 0.0,
            pga_g: 0.3188,
            peak_t: 2.02,
        },
        Expect {
            file: "elcentro1940_ns_peknold_twocol_crlf.dat",
            opts: auto(),
            npts: 1560,
            dt: 0.02,
            t0: 0.0,
            pga_g: 0.3188,
            peak_t: 2.02,
        },
        Expect {
            file: "kobe1995_jma_ns_RSN1106_KJM000.AT2",
            opts: auto(),
            npts: 7500,
            dt: 0.02,
            t0: 0.0,
            pga_g: 0.8342,
            peak_t: 8.52,
        },
        Expect {
            file: "kobe1995_jma_ns_cms2_KOBE_NS.txt",
            opts: opts(Format::Values, Some(Units::CmPerS2), Some(0.02), 3),
            npts: 2567,
            dt: 0.02,
            t0: 0.0,
            pga_g: 0.8342,
            peak_t: 4.82,
        },
        Expect {
            file: "lomaprieta1989_corralitos_ns_RSN753_CLS000.AT2",
            opts: auto(),
            npts: 7995,
            dt: 0.005,
            t0: 0.0,
            pga_g: 0.6447,
            peak_t: 2.62,
        },
        Expect {
            file: "sanfernando1971_pacoima_RSN77_PUL164.AT2",
            opts: auto(),
            npts: 4172,
            dt: 0.01,
            t0: 0.0,
            pga_g: 1.2190,
            peak_t: 7.75,
        },
        Expect {
            file: "sanfernando1971_pacoima_RSN77_PUL254_timeacc.csv",
            opts: auto(),
            npts: 4172,
            dt: 0.01,
            t0: 0.01,
            pga_g: 1.2383,
            peak_t: 8.53,
        },
        Expect {
            file: "tabas1978_tabas_L1_RSN143_TAB-L1_timeacc.csv",
            opts: auto(),
            npts: 1650,
            dt: 0.02,
            t0: 0.02,
            pga_g: 0.8540,
            peak_t: 10.52,
        },
        Expect {
            file: "tabas1978_tabas_T1_RSN143_TAB-T1_timeacc.csv",
            opts: auto(),
            npts: 1650,
            dt: 0.02,
            t0: 0.02,
            pga_g: 0.8618,
            peak_t: 11.06,
        },
        Expect {
            file: "tabas1978_FN_opensees_tabasFN.txt",
            opts: opts(Format::Auto, None, Some(0.02), 0),
            npts: 2500,
            dt: 0.02,
            t0: 0.0,
            pga_g: 0.8999,
            peak_t: 10.50,
        },
        Expect {
            file: "tabas1978_FP_opensees_tabasFP.txt",
            opts: opts(Format::Auto, None, Some(0.02), 0),
            npts: 2500,
            dt: 0.02,
            t0: 0.0,
            pga_g: 0.9772,
            peak_t: 11.02,
        },
        Expect {
            file: "borrego1968_elcentro9_BM68elc.acc",
            opts: opts(Format::Auto, None, Some(0.01), 0),
            npts: 4000,
            dt: 0.01,
            t0: 0.0,
            pga_g: 0.0567,
            peak_t: 15.04,
        },
    ]
}

#[test]
fn every_shared_record_matches_sources() {
    let dir = records_dir();
    let table = table();
    // Every data file in the directory is covered by the table.
    let mut files: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|f| f != "SOURCES.md")
        .collect();
    files.sort();
    let mut listed: Vec<String> = table.iter().map(|e| e.file.to_string()).collect();
    listed.sort();
    assert_eq!(files, listed, "records directory and SOURCES table differ");
    for e in &table {
        let r = read_record(&dir.join(e.file), &e.opts).unwrap_or_else(|err| panic!("{err}"));
        let pga = r.pga();
        assert_eq!(r.npts(), e.npts, "{}", e.file);
        assert!((r.dt - e.dt).abs() < 1e-9, "{}: dt {}", e.file, r.dt);
        assert!((r.t0 - e.t0).abs() < 1e-9, "{}: t0 {}", e.file, r.t0);
        assert!(
            (pga.value / G - e.pga_g).abs() < 6e-5,
            "{}: PGA {} g",
            e.file,
            pga.value / G
        );
        assert!(
            (pga.time - e.peak_t).abs() < 0.006,
            "{}: peak at {}",
            e.file,
            pga.time
        );
    }
}

/// KOBE_NS (cm/s^2) and the KJM000 AT2 (g) are the same record: same PGA in m/s^2.
#[test]
fn units_convert_to_si() {
    let dir = records_dir();
    let cms = read_record(
        &dir.join("kobe1995_jma_ns_cms2_KOBE_NS.txt"),
        &opts(Format::Values, Some(Units::CmPerS2), Some(0.02), 3),
    )
    .unwrap();
    let at2 = read_record(
        &dir.join("kobe1995_jma_ns_RSN1106_KJM000.AT2"),
        &ReadOptions::default(),
    )
    .unwrap();
    assert!(
        (cms.pga().value - 8.1802).abs() < 1e-3,
        "{}",
        cms.pga().value
    );
    assert!((cms.pga().value - at2.pga().value).abs() / at2.pga().value < 2e-3);
}

/// The CR LF two-column Peknold copy equals the AT2 copy except its documented sign typo at row
/// 1048 and one trailing zero.
#[test]
fn crlf_two_column_matches_at2_copy() {
    let dir = records_dir();
    let a = read_record(
        &dir.join("elcentro1940_ns_peknold_0.02s.AT2"),
        &ReadOptions::default(),
    )
    .unwrap();
    let b = read_record(
        &dir.join("elcentro1940_ns_peknold_twocol_crlf.dat"),
        &ReadOptions::default(),
    )
    .unwrap();
    let differ: Vec<usize> = (0..a.npts())
        .filter(|&i| (a.accel[i] - b.accel[i]).abs() > 1e-12)
        .collect();
    assert_eq!(differ, vec![1047]);
    assert_eq!(b.accel[1559], 0.0);
}

fn write(dir: &std::path::Path, name: &str, text: &str) -> std::path::PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

#[test]
fn at2_quirks_parse() {
    let d = tempdir();
    // CR CR LF, header on line 7 after a marker, trailer text, Fortran numbers.
    let text = "PEER\r\r\nX\r\r\nACCELERATION IN UNITS OF G\r\r\na\r\r\nb\r\r\n*** Begin data ***\r\r\nNPTS= 5, DT= .0100 SEC,  0 POLE\r\r\n  .1E-01  -.2E-01\r\r\n\r\r\n  .3E-01 1.0D-02 -0.5\r\r\n*** End Data ***\r\r\n";
    let r = read_record(&write(d.path(), "q.AT2", text), &ReadOptions::default()).unwrap();
    assert_eq!(r.npts(), 5);
    assert_eq!(r.dt, 0.01);
    assert!((r.accel[4] + 0.5 * G).abs() < 1e-12);
}

#[test]
fn malformed_records_name_file_and_line() {
    let d = tempdir();
    let cases: Vec<(&str, &str, ReadOptions, &str)> = vec![
        (
            "short.AT2",
            "h\nh\nh\nNPTS= 4, DT= .01 SEC\n 1.0 2.0\n 3.0\n",
            ReadOptions::default(),
            "short.AT2:6: the header says NPTS = 4 but the data end after 3 values",
        ),
        (
            "bad.AT2",
            "h\nh\nh\nNPTS= 3, DT= .01 SEC\n 1.0 2.0x 3.0\n",
            ReadOptions::default(),
            "bad.AT2:5: expected numbers, found `2.0x`",
        ),
        (
            "long.AT2",
            "h\nh\nh\nNPTS= 2, DT= .01 SEC\n 1.0 2.0 3.0\n",
            ReadOptions::default(),
            "long.AT2:5: more values than the header's NPTS = 2",
        ),
        (
            "nodt.txt",
            "1.0\n2.0\n",
            ReadOptions::default(),
            "nodt.txt: this file has no NPTS/DT header and no time column",
        ),
        (
            "vals.txt",
            "1.0\n2.0\nfoo\n",
            ReadOptions {
                dt: Some(0.01),
                ..Default::default()
            },
            "vals.txt:3: expected an acceleration value, found `foo`",
        ),
        (
            "gap.csv",
            "0.0,1\n0.01,2\n0.02,3\n0.05,4\n",
            ReadOptions::default(),
            "gap.csv:4: time 0.05 breaks the uniform step",
        ),
        (
            "cols.csv",
            "0.0,1\n0.01,2\n0.02,3\n0.03,3,4\n",
            ReadOptions::default(),
            "cols.csv:4: expected 2 columns (time, acceleration), found 3",
        ),
        (
            "negdt.txt",
            "1\n2\n",
            ReadOptions {
                dt: Some(-0.1),
                ..Default::default()
            },
            "negdt.txt: dt must be a positive number of seconds, got -0.1",
        ),
        (
            "nan.txt",
            "1\nnan\n",
            ReadOptions {
                dt: Some(0.01),
                ..Default::default()
            },
            "nan.txt:2: expected an acceleration value, found `nan`",
        ),
        (
            "hdr.AT2",
            "x\ny\n",
            ReadOptions {
                format: Format::At2,
                ..Default::default()
            },
            "hdr.AT2:3: expected a PEER AT2 header line with NPTS and DT",
        ),
    ];
    for (name, text, o, want) in cases {
        let e: RecordError = read_record(&write(d.path(), name, text), &o).unwrap_err();
        let msg = e
            .to_string()
            .replace(&format!("{}/", d.path().display()), "");
        assert!(
            msg.starts_with(want),
            "{name}: got `{msg}`, want `{want}...`"
        );
    }
    let missing = read_record(&d.path().join("nope.AT2"), &ReadOptions::default()).unwrap_err();
    assert!(
        missing.to_string().contains("nope.AT2: cannot read"),
        "{missing}"
    );
}

#[test]
fn synthetic_is_deterministic_and_scaled() {
    let spec = SyntheticSpec::default();
    let a = synthetic(&spec).unwrap();
    let b = synthetic(&spec).unwrap();
    assert_eq!(a, b);
    assert_eq!(a.npts(), 2000);
    assert!((a.pga().value - 0.35 * G).abs() < 1e-12);
    let c = synthetic(&SyntheticSpec {
        seed: 2,
        ..spec.clone()
    })
    .unwrap();
    assert_ne!(a.accel, c.accel);
    // A bit-level fingerprint: the generator uses only IEEE-exact operations, so this sum is the
    // same on every platform (it changes only if the generator changes).
    let fp = a
        .accel
        .iter()
        .fold(0u64, |h, x| h.rotate_left(5) ^ x.to_bits());
    let fp2 = b
        .accel
        .iter()
        .fold(0u64, |h, x| h.rotate_left(5) ^ x.to_bits());
    assert_eq!(fp, fp2);
    // A Kanai-Tajimi process with zeta_g = 0.6 is broad-band around fg = 2.5 Hz: zero crossings
    // per second well above 2 fg's lower reach, well below the 50 Hz Nyquist rate of white noise.
    let crossings = a.accel.windows(2).filter(|w| w[0] * w[1] < 0.0).count() as f64 / 20.0;
    assert!((4.0..30.0).contains(&crossings), "{crossings} crossings/s");
    let bad = synthetic(&SyntheticSpec { dt: 0.0, ..spec }).unwrap_err();
    assert!(
        bad.to_string()
            .contains("synthetic.dt_s must be a positive number"),
        "{bad}"
    );
}

/// `pound record spectrum`: Sa of a step record (a value file) against the closed form of the
/// first overshoot, through the reader and its units; the default periods; bounds refused.
#[test]
fn spectrum_of_a_step_is_the_first_overshoot() {
    let d = crate::support::tempdir();
    // 2 m/s^2 held for 10 s, written in cm/s2.
    let rec = d.path().join("step.txt");
    std::fs::write(&rec, vec!["200.0"; 1000].join("\n")).unwrap();
    let out = d.path().join("s.csv");
    let run = |periods: &str| {
        crate::support::pound(&[
            "record",
            "spectrum",
            rec.to_str().unwrap(),
            "--dt",
            "0.01",
            "--units",
            "cm/s2",
            "--periods",
            periods,
            "--damping",
            "0.05",
            "-o",
            out.to_str().unwrap(),
        ])
    };
    crate::support::ok(&run("0.1,0.5,1.3"));
    let csv = std::fs::read_to_string(&out).unwrap();
    let xi: f64 = 0.05;
    let want = 2.0 * (1.0 + (-xi * std::f64::consts::PI / (1.0 - xi * xi).sqrt()).exp());
    let rows: Vec<&str> = csv.lines().skip(1).collect();
    assert_eq!(rows.len(), 3, "{csv}");
    for row in rows {
        let sa: f64 = row.split(',').nth(2).unwrap().parse().unwrap();
        assert!(((sa - want) / want).abs() < 1e-10, "{row}: {sa} vs {want}");
    }
    std::fs::remove_file(&out).unwrap();
    crate::support::ok(&run("0.05:4:100"));
    let csv = std::fs::read_to_string(&out).unwrap();
    assert_eq!(csv.lines().count(), 101);
    assert!(csv.lines().nth(1).unwrap().starts_with("0.05,"));
    assert!(csv.lines().last().unwrap().starts_with("4,"));
    for (bad, why) in [
        ("0.05:4:0", "expected 1 to 10000"),
        ("1e-9,1", "out of range"),
        ("4:0.05:10", "0 < FROM < TO"),
    ] {
        let o = run(bad);
        assert!(!o.status.success());
        let e = String::from_utf8_lossy(&o.stderr);
        assert!(e.contains(why), "{bad}: {e}");
    }
}

/// Class 8: `file =` records of a config in a checkout beside `shared/records` are found
/// from any working directory; a missing one says where it looked and how to point elsewhere.
#[test]
fn records_resolve_from_the_config() {
    let d = tempdir();
    let recs = d.path().join("shared/records");
    std::fs::create_dir_all(&recs).unwrap();
    let v: Vec<String> = (0..300)
        .map(|i| format!("{:.5}", 0.2 * (i as f64 * 0.1).sin()))
        .collect();
    std::fs::write(recs.join("r.txt"), v.join("\n")).unwrap();
    let proj = d.path().join("checkout/configs");
    std::fs::create_dir_all(&proj).unwrap();
    let body = "[building1]\nmass_kg = 1e5\nperiod_s = 0.5\ndamping_ratio = 0.05\n[building2]\nmass_kg = 1e5\nperiod_s = 0.3\ndamping_ratio = 0.05\n[contact]\nlaw = \"linear\"\nk_n_per_m = 1e9\ngap_m = 0.01\n[[record]]\nfile = \"FILE\"\ndt_s = 0.01\n";
    let cfg = write(&proj, "c.toml", &body.replace("FILE", "r.txt"));
    let elsewhere = tempdir();
    ok(&pound_in(
        elsewhere.path(),
        &[
            "sweep",
            s(&cfg),
            "-o",
            s(&d.path().join("o.csv")),
            "--backend",
            "cpu",
        ],
    ));
    let missing = write(&proj, "m.toml", &body.replace("FILE", "nope.txt"));
    let o = pound_in(
        elsewhere.path(),
        &[
            "sweep",
            s(&missing),
            "-o",
            s(&d.path().join("m.csv")),
            "--backend",
            "cpu",
        ],
    );
    fails_with(&o, "no such record in");
    fails_with(&o, "POUND_RECORDS_DIR");
}
