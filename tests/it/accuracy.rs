//! The speed-against-error study: errors against the reference fall as the fast scheme takes
//! more substeps per contact, on every path, and the outputs are written.

use crate::scenes::{row, STOREYS3};
use crate::support::cli::{fails_with, out, s, stderr as err, write};
use crate::support::ctx;
use crate::support::pound;
use crate::support::tempdir;
use pounding::studies::accuracy::{csv, panels, study};

#[test]
fn errors_fall_with_more_substeps_on_every_path() {
    let plan = pounding::studies::bench::plan(60);
    let points = study(&plan, ctx(), &[8.0, 64.0], 1e-8, |_| {}).unwrap();
    let paths = if ctx().is_some() { 3 } else { 1 };
    assert_eq!(points.len(), 1 + 2 * paths);
    assert_eq!(points[0].path, "reference");
    // Its own truth; a residual at its tolerance.
    assert_eq!(points[0].errors.force_p99, 0.0);
    assert!(points[0].errors.residual_p99 < 1e-8, "{:?}", points[0]);
    let points = &points[1..];
    for p in &points[..paths] {
        let fine = points[paths..].iter().find(|q| q.path == p.path).unwrap();
        assert!(p.runs_per_second > 0.0 && fine.runs_per_second > 0.0);
        // 8x the substeps must cut the median peak-force error severalfold. Measured on this
        // nonlinear viscoelastic sweep: 9x on the CPU (less than RK4's h^4 because the law's
        // delta^(1/4) damping is singular at first touch; on configs/accuracy.toml's mixed
        // laws, 300x).
        assert!(
            fine.errors.force_median * 4.0 < p.errors.force_median,
            "{}: {:?} then {:?}",
            p.path,
            p.errors,
            fine.errors
        );
        assert!(
            fine.errors.force_p99 < 2e-3,
            "{}: {:?}",
            p.path,
            fine.errors
        );
        assert_eq!(fine.errors.failed, 0);
        // The energy residual, the check without a reference, falls with the error (f32
        // rounding puts a floor under it).
        let floor = if p.path == "gpu-f32" { 1e-4 } else { 0.0 };
        assert!(
            fine.errors.residual_median * 4.0 < p.errors.residual_median.max(floor)
                && fine.errors.residual_p99 < 1e-4,
            "{}: {:?} then {:?}",
            p.path,
            p.errors,
            fine.errors
        );
    }
    let d = tempdir();
    let svg = d.path().join("a.svg");
    pounding::studies::plot::svg(&svg, &panels(points), 2, pounding::studies::plot::PANEL).unwrap();
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(text.contains("\ncpu-fast-f64\n") && text.contains("\n99th percentile error\n"));
    // Each setting marked and named in the legend, whatever the number of paths.
    for setting in ["\n8 substeps per contact\n", "\n64 substeps per contact\n"] {
        assert!(text.contains(setting), "{setting} in the legend");
    }
    assert_eq!(csv(points).lines().count(), 1 + points.len());
}

/// Class 2: `--target-error` is met only with evidence: failed runs on either side (here both:
/// floor masses of 1e-30 and 1e12 kg) and zero compared runs are "NOT met" with exit 1; the
/// pair table shows failures; `--tol` has `run.tol`'s bound.
#[test]
fn no_certificate_without_evidence() {
    let d = tempdir();
    let cfg = write(
        d.path(),
        "mass.toml",
        &row(
            "storeys = 3\nstorey_height_m = 3.0\nfloor_masses_kg = [1e-30, 1e5, 1e12]\nperiod_s = 0.4\ndamping_ratio = 0.05",
            STOREYS3,
            "",
        ),
    );
    let acc = d.path().join("acc.csv");
    let o = pound(&["accuracy", s(&cfg), "--target-error", "1e-2", "-o", s(&acc)]);
    // Statistics over zero runs are no figure: `-` in the table, and the study is an error
    // naming why no run could be compared, with nothing written (issue 64).
    fails_with(&o, "no run could be compared");
    assert!(err(&o).contains("of 2 runs, 2 failed"), "{}", err(&o));
    let text = out(&o);
    assert!(!text.contains("(met)"), "{text}");
    assert!(text.contains("| - |"), "{text}");
    assert!(!acc.exists());
    // --tol: the config key's bound, before any run.
    fails_with(
        &pound(&["accuracy", s(&cfg), "--tol", "1e-20", "-o", s(&acc)]),
        "1e-13 < tol < 1e-2",
    );
    // The pair table has a failed column.
    assert!(pounding::studies::accuracy::MARKDOWN_HEADER.contains("| failed |"));
}
