//! Figures read back: the legend box covers no plotted point, every legend entry has its own
//! colour-and-marker (a fitted curve shares its points'), and no series is drawn in yellow.

use crate::support::table;
use crate::support::{ok, pound, tempdir};
use std::path::Path;

/// The numbers in `attr="..."` of an SVG element.
fn attr(element: &str, name: &str) -> Option<String> {
    let at = element.find(&format!(" {name}=\""))? + name.len() + 3;
    let rest = &element[at..];
    Some(rest[..rest.find('"')?].to_string())
}

/// The elements of an SVG, as text, in document order.
fn elements(svg: &str) -> Vec<&str> {
    svg.split('<').filter(|e| !e.starts_with('/')).collect()
}

/// Where a drawn mark sits: a circle's centre, every vertex of a polygon, or every vertex of a
/// coloured polyline and points along its segments (the mesh and the axes are grey or black
/// polylines of width 1).
fn vertices(e: &str) -> Vec<(f64, f64)> {
    let num = |s: String| s.parse::<f64>().unwrap();
    if e.starts_with("circle") {
        return vec![(num(attr(e, "cx").unwrap()), num(attr(e, "cy").unwrap()))];
    }
    let data_line = e.starts_with("polyline") && attr(e, "stroke-width").is_some_and(|w| w != "1");
    if e.starts_with("polygon") || data_line {
        let corners: Vec<(f64, f64)> = attr(e, "points")
            .unwrap()
            .split_whitespace()
            .map(|p| {
                let (x, y) = p.split_once(',').unwrap();
                (num(x.into()), num(y.into()))
            })
            .collect();
        if !data_line {
            return corners;
        }
        let mut along = corners.clone();
        for w in corners.windows(2) {
            along.extend((1..8).map(|k| {
                let f = k as f64 / 8.0;
                (
                    w[0].0 + f * (w[1].0 - w[0].0),
                    w[0].1 + f * (w[1].1 - w[0].1),
                )
            }));
        }
        return along;
    }
    Vec::new()
}

/// What a figure shows: the legend's box (x0, y0, x1, y1), the marks drawn before it and the
/// legend's glyphs (kind and colour).
struct Figure {
    legend: (f64, f64, f64, f64),
    marks: Vec<(f64, f64)>,
    glyphs: Vec<(String, String)>,
}

fn read(svg: &str) -> Figure {
    let els = elements(svg);
    let at = els
        .iter()
        .position(|e| e.starts_with("rect") && attr(e, "fill").as_deref() == Some("none"))
        .expect("a legend");
    let n = |k: &str| attr(els[at], k).unwrap().parse::<f64>().unwrap();
    let (x, y, w, h) = (n("x"), n("y"), n("width"), n("height"));
    let marks = els[..at].iter().flat_map(|e| vertices(e)).collect();
    let mut glyphs = Vec::new();
    let mut lines = 0;
    for e in &els[at + 1..] {
        if !["circle", "polygon", "line"]
            .iter()
            .any(|k| e.starts_with(k))
        {
            continue;
        }
        let kind = e.split_whitespace().next().unwrap();
        // A cross is drawn as two lines: one glyph.
        if kind == "line" {
            lines += 1;
            if lines % 2 == 0 {
                continue;
            }
        }
        let color = attr(e, "fill")
            .filter(|f| f != "none")
            .or_else(|| attr(e, "stroke"))
            .unwrap();
        let ring = kind == "circle" && attr(e, "fill").as_deref() == Some("none");
        glyphs.push((format!("{kind}{}", if ring { " ring" } else { "" }), color));
    }
    Figure {
        legend: (x, y, x + w, y + h),
        marks,
        glyphs,
    }
}

fn check(path: &Path, entries: usize, shared: usize) {
    let svg = std::fs::read_to_string(path).unwrap();
    let Figure {
        legend: (x0, y0, x1, y1),
        marks,
        glyphs,
    } = read(&svg);
    assert!(!marks.is_empty());
    for (x, y) in &marks {
        assert!(
            !(x0..=x1).contains(x) || !(y0..=y1).contains(y),
            "{}: a mark at ({x}, {y}) under the legend ({x0}, {y0})-({x1}, {y1})",
            path.display()
        );
    }
    let mut distinct = glyphs.clone();
    distinct.sort();
    distinct.dedup();
    assert!(glyphs.len() >= entries, "{}: {glyphs:?}", path.display());
    assert_eq!(
        distinct.len(),
        glyphs.len() - shared,
        "{}: {glyphs:?}",
        path.display()
    );
    assert!(
        !svg.contains("#F0E442") && !svg.contains("#FFFF00"),
        "no yellow"
    );
}

/// `pound sweep configs/quickstart.toml` into `dir`: the results' path.
fn quickstart(dir: &Path) -> std::path::PathBuf {
    let results = dir.join("q.csv");
    ok(&pound(&[
        "sweep",
        "configs/quickstart.toml",
        "-o",
        results.to_str().unwrap(),
    ]));
    results
}

#[test]
fn legends_cover_no_point_and_styles_are_distinct() {
    let dir = tempdir();
    let s = |p: &Path| p.to_str().unwrap().to_string();
    // Peak force against the gap, one line per period of building 2 (five series).
    let results = quickstart(dir.path());
    let plot = dir.path().join("q.svg");
    ok(&pound(&[
        "plot",
        &s(&results),
        "--x",
        "gap_m",
        "--y",
        "peak_force_n",
        "--series",
        "t2_s",
        "-o",
        &s(&plot),
    ]));
    check(&plot, 5, 0);
    // The filter in the caption; a title and a size of one's own.
    let w = dir.path().join("w.svg");
    ok(&pound(&[
        "plot",
        &s(&results),
        "--x",
        "gap_m",
        "--y",
        "peak_force_n",
        "--series",
        "formula",
        "--where",
        "t2_s=0.4",
        "--size",
        "1000x600",
        "-o",
        &s(&w),
    ]));
    let svg = std::fs::read_to_string(&w).unwrap();
    assert!(
        svg.contains("where period, building 2 = 0.4 s"),
        "the filter in the caption, in words"
    );
    assert!(svg.contains("width=\"1000\" height=\"600\""));
    check(&w, 3, 0);
    // A small panel: the legend's box is a larger share of it, and no line may pass under it
    // (the box was sized for 640x480 and a line crossed it).
    let small = dir.path().join("small.svg");
    ok(&pound(&[
        "plot",
        &s(&results),
        "--x",
        "gap_m",
        "--y",
        "peak_force_n",
        "--series",
        "formula",
        "--size",
        "400x320",
        "-o",
        &s(&small),
    ]));
    check(&small, 3, 0);
    ok(&pound(&[
        "plot",
        &s(&results),
        "--x",
        "gap_m",
        "--y",
        "peak_force_n",
        "--title",
        "Fig. 3",
        "-o",
        &s(&w),
    ]));
    assert!(std::fs::read_to_string(&w).unwrap().contains("Fig. 3"));
    let bad = pound(&[
        "plot",
        &s(&results),
        "--x",
        "gap_m",
        "--y",
        "peak_force_n",
        "--size",
        "10x10",
    ]);
    assert!(!bad.status.success());
    assert!(String::from_utf8_lossy(&bad.stderr).contains("WIDTHxHEIGHT"));
    // Fragility curves fill the corners (0 at the low left, near 1 at the top right): three
    // thresholds, each its points and its curve in one style.
    let runs = dir.path().join("fr.csv");
    ok(&pound(&[
        "sweep",
        "configs/fragility-example.toml",
        "-o",
        &s(&runs),
    ]));
    let f = dir.path().join("f.svg");
    ok(&pound(&[
        "fragility",
        &s(&runs),
        "--edp",
        "peak_force_n",
        "--threshold",
        "0,1e6,3e6",
        "-o",
        &s(&dir.path().join("f.csv")),
        "--plot",
        &s(&f),
    ]));
    let svg = std::fs::read_to_string(&f).unwrap();
    let glyphs = read(&svg).glyphs;
    assert_eq!(glyphs.len(), 6, "{glyphs:?}");
    check(&f, 6, 3);
    // The curves leave no corner free: the legend sits beside the plot, and the probability
    // axis is labelled up to 1 and no further.
    let ticks: Vec<f64> = svg
        .split("<text")
        .filter(|t| t.contains("text-anchor=\"end\""))
        .filter_map(|t| t.split('>').nth(1)?.split('<').next()?.trim().parse().ok())
        .collect();
    assert!(ticks.contains(&1.0), "{ticks:?}");
    assert!(ticks.iter().all(|&v| v <= 1.0), "{ticks:?}");
    // Every command that plots takes --title and --size: one panel's title replaced, several
    // panels' first title led by it, each panel the size asked.
    let titled = dir.path().join("titled.svg");
    ok(&pound(&[
        "fragility",
        &s(&runs),
        "--edp",
        "impacts",
        "--threshold",
        "0",
        "-o",
        &s(&dir.path().join("t.csv")),
        "--plot",
        &s(&titled),
        "--title",
        "Fig. 7",
        "--size",
        "900x700",
        "--x-label",
        "Peak ground acceleration, PGA (g)",
        "--y-label",
        "Probability of any impact",
    ]));
    let t = std::fs::read_to_string(&titled).unwrap();
    assert!(
        t.contains("Fig. 7") && !t.contains("against PGA"),
        "title replaced"
    );
    assert!(
        t.contains("Peak ground acceleration, PGA (g)") && t.contains("Probability of any impact"),
        "axis labels of one's own"
    );
    assert!(t.contains("width=\"900\" height=\"700\""));
    let panels = dir.path().join("panels.svg");
    ok(&pound(&[
        "restitution",
        "--e",
        "0.5,0.8",
        "-o",
        &s(&dir.path().join("r.csv")),
        "--plot",
        &s(&panels),
        "--title",
        "Fig. 8",
        "--size",
        "400x360",
    ]));
    let t = std::fs::read_to_string(&panels).unwrap();
    assert!(
        t.contains("Fig. 8: "),
        "the first panel's title led by the figure's"
    );
    assert!(
        t.contains("width=\"1600\" height=\"720\""),
        "two rows of four 400x360 panels"
    );
    // Thresholds in engineering units, the EDP and the IM in words.
    for said in [
        "1 MN: observed",
        "3 MN: fit",
        "P(peak force &gt; threshold) against PGA",
    ] {
        assert!(svg.contains(said), "{said}");
    }
    // A log axis is labelled with values, one at each power of ten it spans.
    let lg = dir.path().join("log.svg");
    ok(&pound(&[
        "plot",
        &s(&runs),
        "--x",
        "pga_g",
        "--y",
        "peak_force_n",
        "--log-y",
        "--agg",
        "max",
        "-o",
        &s(&lg),
    ]));
    let svg = std::fs::read_to_string(&lg).unwrap();
    let y_ticks: Vec<f64> = svg
        .split("<text")
        .filter(|t| t.contains("text-anchor=\"end\""))
        .map(|t| {
            t.split('>')
                .nth(1)
                .unwrap()
                .trim()
                .split('<')
                .next()
                .unwrap()
                .trim()
        })
        .map(|t| t.parse::<f64>().unwrap_or_else(|_| panic!("tick `{t}`")))
        .collect();
    assert!(
        y_ticks.iter().all(|&v| v > 0.0),
        "values, not their logs: {y_ticks:?}"
    );
    let decades = y_ticks
        .iter()
        .filter(|v| (v.log10() - v.log10().round()).abs() < 1e-12)
        .count();
    assert!(decades >= 2, "{y_ticks:?}");
    assert!(svg.contains("log scale") && !svg.contains("log10"));
}

/// The gap study of one pair of fixed periods draws each record's runs in a column of its own
/// (the record on a linear axis, the period ratio in the axis label), where a grid of periods
/// draws them against the period ratio on a log axis (a single ratio made one vertical line),
/// its rules' hundreds of points translucent.
#[test]
fn a_gap_study_of_one_pair_is_drawn_against_the_record() {
    let dir = tempdir();
    let s = |p: &Path| p.to_str().unwrap().to_string();
    let template = ok(&pound(&["init", "gap"]));
    let grid = "period_s = { from = 0.2, to = 1.5, n = 8 }";
    assert_eq!(template.matches(grid).count(), 2, "{template}");
    let draw = |name: &str, text: &str| {
        let cfg = dir.path().join(format!("{name}.toml"));
        std::fs::write(&cfg, text).unwrap();
        let svg = dir.path().join(format!("{name}.svg"));
        ok(&pound(&[
            "gap",
            &s(&cfg),
            "-o",
            &s(&dir.path().join(format!("{name}.csv"))),
            "--plot",
            &s(&svg),
        ]));
        std::fs::read_to_string(&svg).unwrap()
    };
    let one = draw(
        "one",
        &template
            .replacen(grid, "period_s = 0.5", 1)
            .replacen(grid, "period_s = 0.8", 1),
    );
    assert!(
        one.contains("record, 1 to 5 as in the legend (T2 / T1 = 1.600)"),
        "the record on the x axis"
    );
    assert!(!one.contains("log scale"), "no log axis for one ratio");
    // A grid of 10 x 10 periods on five records: 500 runs, each a point of every rule's
    // series, drawn translucent (three opaque series of 500 points hid one another).
    let many = draw("many", &template.replace("n = 8 }", "n = 10 }"));
    assert!(many.contains("T2 / T1 (fundamental periods), log scale"));
    assert!(!many.contains("record, 1 to"));
    let translucent = many.matches("opacity=\"0.35\"").count();
    assert!(translucent >= 3 * 500, "{translucent} translucent marks");
}

/// The title's lines: text set larger than the axes' (whose text is 12 px, 9.68 in the SVG's
/// points), and their size.
fn title_lines(svg: &str) -> Vec<(String, f64)> {
    svg.split("<text")
        .skip(1)
        .filter_map(|e| {
            let size: f64 = attr(e, "font-size")?.parse().ok()?;
            let text = e[e.find('>')? + 1..e.find('<')?].trim().to_string();
            (size > 10.5).then_some((text, size))
        })
        .collect()
}

/// A title too long for its panel is wrapped (plotters set it on one line and clipped it at
/// both sides): every word is kept, in order, and on a wide panel the same title is one line
/// at the full size.
#[test]
fn a_long_title_is_wrapped_on_a_narrow_panel() {
    let dir = tempdir();
    let s = |p: &Path| p.to_str().unwrap().to_string();
    let results = quickstart(dir.path());
    let title = "Peak pounding force against the separation gap, the largest over every other parameter of the sweep";
    let draw = |size: &str| {
        let plot = dir.path().join(format!("{size}.svg"));
        ok(&pound(&[
            "plot",
            &s(&results),
            "--x",
            "gap_m",
            "--y",
            "peak_force_n",
            "--title",
            title,
            "--size",
            size,
            "-o",
            &s(&plot),
        ]));
        title_lines(&std::fs::read_to_string(&plot).unwrap())
    };
    let wide = draw("1400x500");
    assert_eq!(wide.len(), 1, "{wide:?}");
    assert_eq!(wide[0].0, title);
    let narrow = draw("400x320");
    assert!(narrow.len() >= 2, "{narrow:?}");
    let joined: Vec<&str> = narrow.iter().map(|l| l.0.as_str()).collect();
    assert_eq!(joined.join(" "), title);
    assert!(narrow.iter().all(|l| l.1 < wide[0].1), "{narrow:?} smaller");
}

/// A threshold whose curve cannot be fitted says why in a few words in its legend entry (the
/// table gives the whole reason): the entry fits its legend box, where the whole reason ran
/// past the box and out of the figure.
#[test]
fn a_failed_fit_is_named_briefly_in_the_legend() {
    let dir = tempdir();
    let s = |p: &Path| p.to_str().unwrap().to_string();
    // Every threshold's counts separate perfectly: none exceed below one intensity, all above.
    let runs = dir.path().join("sep.csv");
    std::fs::write(
        &runs,
        "run,status,pga_g,peak_force_n\n0,ok,0.1,0\n1,ok,0.1,0\n2,ok,0.2,5e5\n3,ok,0.2,2e6\n\
         4,ok,0.3,2e6\n5,ok,0.3,3e6\n6,ok,0.4,3e6\n7,ok,0.4,4e6\n",
    )
    .unwrap();
    let svg = dir.path().join("sep.svg");
    let out = ok(&pound(&[
        "fragility",
        &s(&runs),
        "--edp",
        "peak_force_n",
        "--threshold",
        "0,1e6,3.5e6",
        "-o",
        &s(&dir.path().join("f.csv")),
        "--plot",
        &s(&svg),
    ]));
    assert!(out.contains("the counts separate perfectly (all below one intensity"));
    let text = std::fs::read_to_string(&svg).unwrap();
    let entries: Vec<&str> = text
        .lines()
        .filter(|l| l.contains("observed"))
        .map(str::trim)
        .collect();
    assert_eq!(entries.len(), 3, "{entries:?}");
    assert!(entries
        .iter()
        .all(|e| e.ends_with(": observed (no fit: counts separate perfectly)")));
    // The legend's box, which plotters sizes to its longest entry, ends inside the plot area
    // (the area ends 10 px from the 640 px figure's edge): the whole reason's entry filled the
    // area and its text ran on out of the figure.
    let els = elements(&text);
    let legend = els
        .iter()
        .find(|e| e.starts_with("rect") && attr(e, "fill").as_deref() == Some("none"))
        .expect("a legend");
    let n = |k: &str| -> f64 { attr(legend, k).unwrap().parse().unwrap() };
    assert!(
        n("x") + n("width") < 630.0,
        "legend from {} wide {}",
        n("x"),
        n("width")
    );
}

/// Class 6, silent drops: `pound plot` says how many rows it left out and why, by reason in
/// the table of meanings' words (a residual drift is empty where the run did not settle), and
/// names a series of which every row was left out. It left out empty values without a word, so
/// a whole series vanished.
#[test]
fn every_row_left_out_is_counted() {
    let dir = tempdir();
    let results = dir.path().join("runs.csv");
    std::fs::write(
        &results,
        "run,record,pga_g,b1_residual_drift_ratio,b1_first_impact_s,status\n\
         0,quiet,0.2,0.001,,ok\n\
         1,quiet,0.4,0.002,,ok\n\
         2,strong,0.2,,1.5,ok\n\
         3,strong,0.4,,1.2,ok\n\
         4,quiet,0.6,0.003,,step_limit\n\
         5,quiet,,0.004,,ok\n\
         6,quiet,0.8,inf,,ok\n",
    )
    .unwrap();
    let plot = dir.path().join("p.svg");
    let out = pound(&[
        "plot",
        results.to_str().unwrap(),
        "--x",
        "pga_g",
        "--y",
        "b1_residual_drift_ratio",
        "--series",
        "record",
        "-o",
        plot.to_str().unwrap(),
    ]);
    ok(&out);
    let err = String::from_utf8_lossy(&out.stderr);
    for said in [
        "1 rows left out: runs whose status is not ok",
        "1 rows left out: values that are not finite",
        "1 rows left out: pga_g is empty",
        "2 rows left out: b1_residual_drift_ratio is empty (where the run did not settle)",
        "no series drawn for record = strong: every one of its rows was left out",
    ] {
        assert!(err.contains(said), "missing `{said}` in:\n{err}");
    }
    // The first impact is empty where the run did not pound.
    let out = pound(&[
        "plot",
        results.to_str().unwrap(),
        "--x",
        "pga_g",
        "--y",
        "b1_first_impact_s",
        "-o",
        plot.to_str().unwrap(),
    ]);
    ok(&out);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("3 rows left out: b1_first_impact_s is empty"),
        "{err}"
    );
}

/// Class 6 where it arises in filters and series: a scaled PGA computed per record
/// (`0.19999999999999998`, `0.20000000000000004`) is one value to `--where` and `--by`, as it
/// is one level to `pound fragility`. `--where pga_g=0.2` silently dropped a record's rows, and
/// `--series pga_g` drew twelve series for eight levels.
#[test]
fn one_value_computed_per_record_is_one_value() {
    let dir = tempdir();
    let runs = dir.path().join("runs.csv");
    ok(&pound(&[
        "sweep",
        "configs/fragility-example.toml",
        "-o",
        runs.to_str().unwrap(),
    ]));
    let rows = table(&runs);
    let pga: Vec<f64> = rows.iter().map(|r| r["pga_g"].parse().unwrap()).collect();
    let at = |v: f64| pga.iter().filter(|p| (*p / v - 1.0).abs() < 1e-9).count();
    assert!(
        pga.iter()
            .any(|&p| p != 0.2 && (p / 0.2 - 1.0).abs() < 1e-9),
        "the test needs a PGA of 0.2 g computed inexactly"
    );
    let levels = {
        let mut l: Vec<String> = pga.iter().map(|p| format!("{p:.9}")).collect();
        l.sort();
        l.dedup();
        l.len()
    };
    let r = runs.to_str().unwrap();
    let fit = |filter: &str| {
        let out = pound(&[
            "fragility",
            r,
            "--im",
            "pga_g",
            "--edp",
            "peak_force_n",
            "--threshold",
            "1e6",
            "--where",
            filter,
            "-o",
            dir.path().join("f.csv").to_str().unwrap(),
        ]);
        ok(&out).lines().next().unwrap_or("").to_string()
    };
    assert!(fit("pga_g=0.2").starts_with(&format!("{} runs at 1 levels", at(0.2))));
    let below = pga.iter().filter(|p| **p < 0.2 * (1.0 + 1e-9)).count();
    assert!(
        fit("pga_g<=0.2").starts_with(&format!("{below} runs at")),
        "{}",
        fit("pga_g<=0.2")
    );
    let plot = pound(&[
        "plot",
        r,
        "--x",
        "gap_m",
        "--y",
        "peak_force_n",
        "--series",
        "pga_g",
        "-o",
        dir.path().join("p.svg").to_str().unwrap(),
    ]);
    ok(&plot);
    let said = String::from_utf8_lossy(&plot.stderr);
    assert!(
        said.contains(&format!("{levels} series,")),
        "{levels} levels: {said}"
    );
}

/// Class 14 where a legend stands beside the plot: the title is centred over the whole panel,
/// so one that fits the panel stays in it (plotters centred it over the plot left of the
/// legend, and a long default title ran off the panel's left edge).
#[test]
fn a_title_stands_over_its_panel() {
    let dir = tempdir();
    let runs = dir.path().join("runs.csv");
    ok(&pound(&[
        "sweep",
        "configs/fragility-example.toml",
        "-o",
        runs.to_str().unwrap(),
    ]));
    let svg = dir.path().join("p.svg");
    ok(&pound(&[
        "plot",
        runs.to_str().unwrap(),
        "--x",
        "gap_m",
        "--y",
        "peak_force_n",
        "--series",
        "record",
        "--where",
        "pga_g>=0.5",
        "-o",
        svg.to_str().unwrap(),
    ]));
    let text = std::fs::read_to_string(&svg).unwrap();
    // The first text element is the title; the panel is 640 px wide.
    let title = text.split("<text ").nth(1).expect("a title");
    assert!(title.contains("peak force against gap"), "{title}");
    assert!(
        title.starts_with("x=\"320\""),
        "the title is not centred on the panel: {title}"
    );
}

// What a figure shows: labels, ticks, axes and titles, and what it costs, bounded before it is drawn.
mod labels;
