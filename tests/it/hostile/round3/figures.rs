//! Hostile pass, round 3 (issue 47), classes 4, 5, 14 and the long title of 9: a figure's labels,
//! ticks, axes and titles say what it shows, and what it costs is bounded before it is drawn.

use crate::support::{pound, tempdir};
use std::path::Path;

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn refused(out: &std::process::Output, said: &[&str]) {
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "refused, not crashed: {err}");
    for s in said {
        assert!(err.contains(s), "`{s}` in: {err}");
    }
}

/// Class 5, resources: a figure's pixels are bounded before it is drawn. Six panels of
/// 4000x4000 at 600 dpi, each flag within its bounds, asked for 11 GB and aborted (rc 134).
#[test]
fn a_figure_costs_a_bounded_number_of_pixels() {
    let dir = tempdir();
    let png = dir.path().join("big.png");
    let out = pound(&[
        "trace",
        "configs/inelastic-row.toml",
        "--run",
        "5",
        "-o",
        s(&dir.path().join("t.csv")),
        "--plot",
        s(&png),
        "--size",
        "4000x4000",
        "--dpi",
        "600",
    ]);
    refused(&out, &["pixels", "--size", "--dpi"]);
    assert!(!png.exists());
}
