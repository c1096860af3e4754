//! A figure's labels, ticks, axes and titles say what it shows, and what it costs is bounded
//! before it is drawn (issue 47's classes 4, 5, 14 and the long title of 9).

use crate::support::cli::s;
use crate::support::{ok, pound, tempdir};
use std::path::Path;

/// An SVG's texts in document order, each with its element's attributes.
fn texts(svg: &str) -> Vec<(String, String)> {
    svg.split("<text")
        .skip(1)
        .filter_map(|t| {
            let (attrs, rest) = t.split_once('>')?;
            let body = rest.split('<').next()?.trim().replace("&gt;", ">");
            Some((attrs.to_string(), body))
        })
        .collect()
}

/// The y tick labels (right-aligned numbers) of the panel whose title starts with `title`:
/// those after its title, up to the first text after them that is not a number.
fn y_ticks(svg: &str, title: &str) -> Vec<f64> {
    let all = texts(svg);
    let from = all
        .iter()
        .position(|(_, t)| t.starts_with(title))
        .unwrap_or_else(|| panic!("no panel `{title}`"));
    let mut ticks = Vec::new();
    for (attrs, t) in &all[from + 1..] {
        match t.parse::<f64>() {
            Ok(v) if attrs.contains("text-anchor=\"end\"") => ticks.push(v),
            Ok(_) => {}
            Err(_) if ticks.is_empty() => {}
            Err(_) => break,
        }
    }
    ticks
}

/// Every number printed in a figure: none is a float step's residue of 0 (`-2.78e-17`).
fn no_residue_of_zero(svg: &str, what: &str) {
    for (_, t) in texts(svg) {
        if let Ok(v) = t.parse::<f64>() {
            assert!(v == 0.0 || v.abs() > 1e-9, "{what}: a tick `{t}`");
        }
    }
}

fn column(csv: &Path, name: &str) -> Vec<f64> {
    let text = std::fs::read_to_string(csv).unwrap();
    let mut lines = text.lines();
    let at = lines
        .next()
        .unwrap()
        .split(',')
        .position(|h| h == name)
        .unwrap();
    lines
        .filter_map(|l| l.split(',').nth(at)?.parse().ok())
        .collect()
}

fn refused(out: &std::process::Output, said: &[&str]) {
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "refused, not crashed: {err}");
    for s in said {
        assert!(err.contains(s), "`{s}` in: {err}");
    }
}

/// Class 4, labels that contradict the data: a label's unit scales the data to it (`Force
/// (kN)` on forces in N divides them by 1000) or is refused, naming the flag and the quantity's
/// unit; on a figure of several panels a label goes only to the panels whose quantity it fits;
/// a tick at 0 reads 0 (it read `-2.78e-17` on a roof's displacement).
#[test]
fn labels_agree_with_the_data() {
    let dir = tempdir();
    let csv = dir.path().join("x.csv");
    ok(&pound(&[
        "sweep",
        "configs/inelastic-row.toml",
        "-o",
        s(&csv),
    ]));
    let forces = column(&csv, "peak_force_n");
    let (lo, hi) = forces
        .iter()
        .fold((f64::INFINITY, 0.0f64), |(l, h), &f| (l.min(f), h.max(f)));
    let plot = |label: &str, out: &Path| {
        pound(&[
            "plot",
            s(&csv),
            "--x",
            "pga_g",
            "--y",
            "peak_force_n",
            "--y-label",
            label,
            "-o",
            s(out),
        ])
    };
    let kn = dir.path().join("kn.svg");
    ok(&plot("Force (kN)", &kn));
    let svg = std::fs::read_to_string(&kn).unwrap();
    let ticks = y_ticks(&svg, "peak force against");
    assert!(!ticks.is_empty());
    for t in &ticks {
        assert!(
            (lo / 1e3 * 0.8..=hi / 1e3 * 1.2).contains(t),
            "a tick {t} kN for forces of {lo} to {hi} N: {ticks:?}"
        );
    }
    refused(
        &plot("Force (s)", &dir.path().join("s.svg")),
        &["--y-label", "Force (s)", "N"],
    );
    assert!(!dir.path().join("s.svg").exists());
    // A trace's panels: displacements, forces (contact and storey shear), energy.
    let tcsv = dir.path().join("t.csv");
    let trace = |extra: &[&str], out: &Path| {
        let mut args = vec![
            "trace",
            "configs/inelastic-row.toml",
            "--run",
            "5",
            "-o",
            s(&tcsv),
        ];
        args.extend(["--plot", s(out)]);
        args.extend(extra);
        pound(&args)
    };
    let t = dir.path().join("t.svg");
    ok(&trace(&[], &t));
    let plain = std::fs::read_to_string(&t).unwrap();
    no_residue_of_zero(&plain, "a trace");
    ok(&trace(&["--y-label", "force (kN)"], &t));
    let svg = std::fs::read_to_string(&t).unwrap();
    let labels: Vec<String> = texts(&svg).into_iter().map(|(_, t)| t).collect();
    assert_eq!(
        labels.iter().filter(|l| *l == "force (kN)").count(),
        3,
        "the force panels: {labels:?}"
    );
    assert!(labels.iter().any(|l| l.starts_with("displacement (")));
    assert!(labels.iter().any(|l| l.starts_with("hysteretic energy (")));
    // The storey shear, some 5 MN, in kN.
    let shear = y_ticks(&svg, "Storey shear");
    assert!(shear.iter().any(|v| v.abs() >= 1000.0), "{shear:?}");
    refused(
        &trace(&["--y-label", "force (s)"], &dir.path().join("u.svg")),
        &["--y-label", "force (s)", "(m)", "(N)", "(J)"],
    );
    refused(
        &trace(&["--y-label", "response"], &dir.path().join("u.svg")),
        &["--y-label", "response", "unit"],
    );
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

/// Class 14 and the long title of 9, figures that misreport: a probability axis runs from 0 to
/// 1 (not to 2 to make room for a legend, which goes beside the plot; not from 0.82 up); titles
/// name columns in words, as the axes do; a title too long for its panel never covers the plot.
#[test]
fn figures_report_what_they_show() {
    let dir = tempdir();
    // Fragility curves fill the plot: their legend cannot sit inside it.
    let runs = dir.path().join("fr.csv");
    ok(&pound(&[
        "sweep",
        "configs/fragility-example.toml",
        "-o",
        s(&runs),
    ]));
    let f = dir.path().join("f.svg");
    ok(&pound(&[
        "fragility",
        s(&runs),
        "--edp",
        "peak_force_n",
        "--threshold",
        "0,1e6,3e6",
        "-o",
        s(&dir.path().join("f.csv")),
        "--plot",
        s(&f),
    ]));
    let svg = std::fs::read_to_string(&f).unwrap();
    // The plot area's top is where its grid lines end; tick 1 sits at it, not half way down.
    let top = svg
        .split("<line")
        .skip(1)
        .filter(|l| l.contains("opacity"))
        .flat_map(|l| {
            ["y1", "y2"].map(|k| {
                let at = l.find(&format!(" {k}=\"")).unwrap() + 5;
                l[at..].split('"').next().unwrap().parse::<f64>().unwrap()
            })
        })
        .fold(f64::INFINITY, f64::min);
    let at = |v: &str| {
        texts(&svg)
            .into_iter()
            .find(|(a, t)| t == v && a.contains("text-anchor=\"end\""))
            .map(|(a, _)| {
                let i = a.find(" y=\"").unwrap() + 4;
                a[i..].split('"').next().unwrap().parse::<f64>().unwrap()
            })
            .unwrap_or_else(|| panic!("a tick {v}"))
    };
    let (zero, one) = (at("0"), at("1"));
    assert!(
        one - top < 0.1 * (zero - one),
        "the axis runs past 1: top {top}, tick 1 at {one}, tick 0 at {zero}"
    );
    no_residue_of_zero(&svg, "fragility");
    // The probability of pounding where every gap pounds often: from 0, not from 0.82.
    let g = dir.path().join("g.svg");
    ok(&pound(&[
        "gap",
        "configs/gap-example.toml",
        "-o",
        s(&dir.path().join("g.csv")),
        "--plot",
        s(&g),
        "--gaps",
        "0.01,0.02,0.04",
    ]));
    let svg = std::fs::read_to_string(&g).unwrap();
    let p = y_ticks(&svg, "Probability of pounding");
    assert!(p.contains(&0.0) && p.contains(&1.0), "{p:?}");
    no_residue_of_zero(&svg, "gap");
    // Titles in words: pound ida's, and pound plot's --where caption.
    let csv = dir.path().join("x.csv");
    ok(&pound(&[
        "sweep",
        "configs/inelastic-row.toml",
        "-o",
        s(&csv),
    ]));
    let i = dir.path().join("i.svg");
    ok(&pound(&[
        "ida",
        s(&csv),
        "--edp",
        "b1_peak_drift_ratio",
        "--where",
        "gap_1_2_m=0.01",
        "-o",
        s(&dir.path().join("i.csv")),
        "--plot",
        s(&i),
    ]));
    let svg = std::fs::read_to_string(&i).unwrap();
    let title = &texts(&svg)[0].1;
    assert!(
        title.contains("peak drift ratio, building 1")
            && title.contains("where gap 1-2 = 0.01 m")
            && !title.contains('_'),
        "{title}"
    );
    let w = dir.path().join("w.svg");
    ok(&pound(&[
        "plot",
        s(&csv),
        "--x",
        "pga_g",
        "--y",
        "peak_force_n",
        "--where",
        "gap_1_2_m=0.01",
        "-o",
        s(&w),
    ]));
    let svg = std::fs::read_to_string(&w).unwrap();
    let title = &texts(&svg)[0].1;
    assert!(
        title.contains("gap 1-2 = 0.01 m") && !title.contains('_'),
        "{title}"
    );
    // A title of 400 words on a small panel: its lines end above the plot area.
    let long: Vec<String> = (0..400).map(|k| format!("word{k}")).collect();
    let l = dir.path().join("l.svg");
    ok(&pound(&[
        "plot",
        s(&csv),
        "--x",
        "pga_g",
        "--y",
        "peak_force_n",
        "--title",
        &long.join(" "),
        "--size",
        "320x320",
        "-o",
        s(&l),
    ]));
    let svg = std::fs::read_to_string(&l).unwrap();
    let grid_top = svg
        .split("<line")
        .skip(1)
        .filter(|l| l.contains("opacity"))
        .flat_map(|l| {
            ["y1", "y2"].map(|k| {
                let at = l.find(&format!(" {k}=\"")).unwrap() + 5;
                l[at..].split('"').next().unwrap().parse::<f64>().unwrap()
            })
        })
        .fold(f64::INFINITY, f64::min);
    let lowest_title = texts(&svg)
        .into_iter()
        .filter(|(_, t)| t.starts_with("word") || t.ends_with('…'))
        .map(|(a, _)| {
            let i = a.find(" y=\"").unwrap() + 4;
            a[i..].split('"').next().unwrap().parse::<f64>().unwrap()
        })
        .fold(0.0f64, f64::max);
    // A line's `y` is its top; its text is about 11 px high.
    assert!(
        lowest_title + 11.0 < grid_top,
        "a title line at {lowest_title}, the plot from {grid_top}"
    );
    assert!(grid_top < 200.0, "the plot keeps most of its panel");
}
