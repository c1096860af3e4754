//! Drawing one panel onto a `plotters` area: styles, markers, ticks, the title, the legend's
//! place and the notes.

use super::panel::{Panel, Series};
use super::units::engineering;
use plotters::prelude::*;

/// Okabe & Ito's colour-blind-safe palette, without its yellow (unreadable on white).
const PALETTE: [RGBColor; 7] = [
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(230, 159, 0),
    RGBColor(86, 180, 233),
    RGBColor(0, 0, 0),
];

/// Marker shapes, cycled with a period prime to the palette's: colour and marker together tell
/// 28 styles apart.
const MARKERS: usize = 4;

/// Scatter series of more points than this are drawn translucent (thousands of points hide
/// each other, and a series drawn last would hide those before it).
const DENSE: usize = 400;

/// Samples along each segment of a line that the legend must not cover.
const LINE_SAMPLES: usize = 16;

/// Lines of more points than this are smooth curves: no markers on their points.
pub const SMOOTH: usize = 40;

/// A marker of kind `k` at `at`: a filled circle, a triangle, a cross or a ring.
fn marker<DB: DrawingBackend, C: Clone + 'static>(
    k: usize,
    at: C,
    color: RGBAColor,
    scale: f64,
) -> DynElement<'static, DB, C> {
    let px = |v: u32| (v as f64 * scale).round().max(1.0) as u32;
    match k % MARKERS {
        0 => Circle::new(at, px(3), color.filled()).into_dyn(),
        1 => TriangleMarker::new(at, px(4), color.filled()).into_dyn(),
        2 => Cross::new(at, px(4), color.stroke_width(px(2))).into_dyn(),
        _ => Circle::new(at, px(4), color.stroke_width(px(2))).into_dyn(),
    }
}

/// A title's lines and font size for a panel `width` px wide: one line at 18 px where it fits;
/// else one line at the largest size down to 14 px at which it does; else its words wrapped
/// into lines at 14 px (a word longer than the panel stands on a line of its own). `measure`
/// gives a text's width at a size (at the panel's own scale, as `scale`).
fn fit_title(
    title: &str,
    width: f64,
    scale: f64,
    measure: impl Fn(&str, f64) -> f64,
) -> (Vec<String>, f64) {
    for size in [18.0, 17.0, 16.0, 15.0, 14.0] {
        if measure(title, size * scale) <= width {
            return (vec![title.to_string()], size * scale);
        }
    }
    let size = 14.0 * scale;
    (wrap(title, width, size, measure), size)
}

/// `text`'s words in lines at most `width` wide at font size `size` (a word wider than that
/// stands on a line of its own).
fn wrap(text: &str, width: f64, size: f64, measure: impl Fn(&str, f64) -> f64) -> Vec<String> {
    let mut lines: Vec<String> = Vec::new();
    for word in text.split_whitespace() {
        match lines.last_mut() {
            Some(line) if measure(&format!("{line} {word}"), size) <= width => {
                line.push(' ');
                line.push_str(word);
            }
            _ => lines.push(word.to_string()),
        }
    }
    lines
}

/// Draw the collapse marker on `area`, centred on its pixel `(x, y)`: a square crossed, as a
/// run that collapsed is marked apart from the points of the runs that did not (its value is
/// its peak before the collapse).
fn collapse_marker<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    (x, y): (i32, i32),
    color: RGBAColor,
    scale: f64,
) -> Result<(), String> {
    // Larger than the other markers and thin-lined, so that its cross reads at 96 dpi.
    let r = (5.0 * scale).round().max(1.0) as i32;
    let width = scale.round().max(1.0) as u32;
    let style = color.stroke_width(width);
    let e = |e: &dyn std::fmt::Display| e.to_string();
    // Each stroke a segment of its own: a path that turns at the corners joins badly (mitre
    // spikes where a diagonal meets a side; sides lost in the bitmap), and an SVG
    // rectangle drops the stroke's width. The top and bottom run on by half the width, to
    // close the corners.
    let h = (width / 2) as i32;
    let strokes = [
        [(-r - h, -r), (r + h, -r)],
        [(-r - h, r), (r + h, r)],
        [(-r, -r), (-r, r)],
        [(r, -r), (r, r)],
        [(-r, -r), (r, r)],
        [(-r, r), (r, -r)],
    ];
    for [a, b] in strokes {
        area.draw(&PathElement::new(
            vec![(x + a.0, y + a.1), (x + b.0, y + b.1)],
            style,
        ))
        .map_err(|x| e(&x))?;
    }
    Ok(())
}

/// The legend's corners, in the order they are tried.
const CORNERS: [SeriesLabelPosition; 4] = [
    SeriesLabelPosition::UpperLeft,
    SeriesLabelPosition::UpperRight,
    SeriesLabelPosition::LowerRight,
    SeriesLabelPosition::LowerLeft,
];

/// Where the legend goes: the first corner whose box (estimated from the entries' text, as
/// fractions `w`, `h` of the plot area) covers no point; None where each would, and the legend
/// goes beside the plot (raising the y range to make room would run a probability axis to 2).
fn legend_place(
    points: &[(f64, f64)],
    x: (f64, f64),
    y: (f64, f64),
    w: f64,
    h: f64,
) -> Option<SeriesLabelPosition> {
    let inside = |(fx0, fx1): (f64, f64), (fy0, fy1): (f64, f64)| {
        points.iter().any(|&(px, py)| {
            let (u, v) = ((px - x.0) / (x.1 - x.0), (py - y.0) / (y.1 - y.0));
            (fx0..=fx1).contains(&u) && (fy0..=fy1).contains(&v)
        })
    };
    for (i, c) in CORNERS.into_iter().enumerate() {
        let fx = if i == 0 || i == 3 {
            (0.0, w)
        } else {
            (1.0 - w, 1.0)
        };
        let fy = if i < 2 { (1.0 - h, 1.0) } else { (0.0, h) };
        if !inside(fx, fy) {
            return Some(c);
        }
    }
    None
}

/// The label of the power of ten `10^k`: `0.01` to `1000` plainly, else `1e-5`, `1e6`.
fn decade(k: i32) -> String {
    if (-2..=3).contains(&k) {
        tick(10f64.powi(k))
    } else {
        format!("1e{k}")
    }
}

/// A short tick label: plain for moderate magnitudes, else `1.2e6`.
fn tick(v: f64) -> String {
    let a = v.abs();
    if a == 0.0 || (1e-3..1e4).contains(&a) {
        let s = format!("{v:.4}");
        let s = s.trim_end_matches('0').trim_end_matches('.');
        if s == "-0" {
            "0".into()
        } else {
            s.into()
        }
    } else {
        let s = format!("{v:.2e}");
        match s.split_once('e') {
            Some((m, x)) => format!("{}e{x}", m.trim_end_matches('0').trim_end_matches('.')),
            None => s,
        }
    }
}

/// A linear axis's tick label for `v` on an axis from `lo` to `hi`: a tick at 0 reached by
/// float steps (-2.78e-17, 1.73e-18) reads 0, as any within a billionth of the span does.
fn linear_tick(v: f64, lo: f64, hi: f64) -> String {
    if v.abs() <= (hi - lo).abs() * 1e-9 {
        "0".to_string()
    } else {
        tick(v)
    }
}

fn range(v: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = v
        .filter(|x| x.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
            (a.min(x), b.max(x))
        });
    if !lo.is_finite() {
        return (0.0, 1.0);
    }
    // One value: half of it either side, or a unit either side of 0 (not +-5e-13).
    let pad = if hi > lo {
        0.04 * (hi - lo)
    } else if lo == 0.0 {
        1.0
    } else {
        0.5 * lo.abs()
    };
    (lo - pad, hi + pad)
}

/// One panel, its text, marks and margins `scale` times their size at [`BASE_DPI`].
pub(super) fn draw<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    p: &Panel,
    scale: f64,
) -> Result<(), String> {
    let px = |v: u32| (v as f64 * scale).round().max(1.0) as u32;
    let e = |e: &dyn std::fmt::Display| e.to_string();
    // Linear axes in engineering units: forces in kN or MN, small lengths in mm.
    let notes = &p.notes;
    let biggest = |f: fn(&(f64, f64)) -> f64| {
        p.series
            .iter()
            .flat_map(|s| s.points.iter().map(f))
            .chain(notes.collapsed.iter().map(|(_, q)| f(q)))
            .chain(notes.x_marks.iter().map(|&(x, _)| f(&(x, 0.0))))
            .filter(|v| v.is_finite())
            .fold(0.0f64, |m, v| m.max(v.abs()))
    };
    let (x_label, fx) = engineering(&p.x_label, biggest(|q| q.0), p.log_x);
    let (y_label, fy) = engineering(&p.y_label, biggest(|q| q.1), p.log_y);
    let tx = |x: f64| if p.log_x { x.log10() } else { x * fx };
    let ty = |y: f64| if p.log_y { y.log10() } else { y * fy };
    let pts = |s: &Series| -> Vec<(f64, f64)> {
        s.points
            .iter()
            .map(|&(x, y)| (tx(x), ty(y)))
            .filter(|(x, y)| x.is_finite() && y.is_finite())
            .collect()
    };
    // The collapsed runs' points, each with its series, where they can be drawn.
    let collapsed: Vec<(usize, (f64, f64))> = notes
        .collapsed
        .iter()
        .map(|&(i, (x, y))| (i, (tx(x), ty(y))))
        .filter(|(_, (x, y))| x.is_finite() && y.is_finite())
        .collect();
    let x_marks: Vec<(f64, &str)> = notes
        .x_marks
        .iter()
        .map(|(x, t)| (tx(*x), t.as_str()))
        .filter(|(x, _)| x.is_finite())
        .collect();
    let all: Vec<(f64, f64)> = p
        .series
        .iter()
        .flat_map(pts)
        .chain(collapsed.iter().map(|c| c.1))
        .collect();
    let (x0, x1) = range(all.iter().map(|q| q.0).chain(x_marks.iter().map(|m| m.0)));
    let span = p.y_span.iter().flat_map(|&(a, b)| [ty(a), ty(b)]);
    let (y0, y1) = range(all.iter().map(|q| q.1).chain(span));
    // A series is a legend entry where it has a name, unless an earlier one of its style and
    // name has it already.
    let listed: Vec<bool> = {
        let mut seen = std::collections::HashSet::new();
        p.series
            .iter()
            .map(|s| !s.name.is_empty() && s.style.is_none_or(|k| seen.insert((k, &s.name))))
            .collect()
    };
    let entry = |i: usize| listed[i];
    let mut named: Vec<&str> = (0..p.series.len())
        .filter(|&i| entry(i))
        .map(|i| p.series[i].name.as_str())
        .collect();
    if !collapsed.is_empty() {
        named.push(&notes.collapsed_name);
    }
    // The legend box as a share of the plot area (the panel less about 105 x 100 px of axis
    // labels, caption and margins: 535 x 380 px in a 640 x 480 panel): 7 px a character at
    // the legend's 12 px font, 40 px of marker and margins; 20 px a line.
    let longest = named.iter().map(|s| s.chars().count()).max().unwrap_or(0);
    let (panel_w, panel_h) = area.dim_in_pixel();
    // A title too wide for the panel is set smaller, or wrapped: plotters would clip it.
    let measure = |text: &str, size: f64| {
        area.estimate_text_size(text, &("sans-serif", size).into_text_style(area))
            .map_or(f64::INFINITY, |(w, _)| w as f64)
    };
    let (mut title, title_size) = fit_title(
        &p.title,
        panel_w as f64 - 2.0 * px(10) as f64,
        scale,
        measure,
    );
    let title_style = ("sans-serif", title_size).into_text_style(area);
    let line_h = area
        .estimate_text_size("Ag", &title_style)
        .map_or(0, |(_, h)| h) as f64;
    // A title of more lines than fit a third of the panel is cut after them, its last line
    // ending in an ellipsis: the plot keeps the rest of the panel (it was drawn over the title).
    let most = (panel_h as f64 / 3.0 / (line_h * 1.4)).floor().max(1.0) as usize;
    if title.len() > most {
        title.truncate(most);
        let last = title.last_mut().expect("a line");
        while measure(&format!("{last} …"), title_size) > panel_w as f64 - 2.0 * px(10) as f64 {
            match last.rfind(' ') {
                Some(k) => last.truncate(k),
                None => break,
            }
        }
        last.push_str(" …");
    }
    // The caption: its paragraphs wrapped to the panel's width at 11 px, at most a quarter of
    // the panel's height (the last line kept ends in an ellipsis).
    let caption_size = 11.0 * scale;
    let caption_w = panel_w as f64 - 2.0 * px(10) as f64;
    let mut caption: Vec<String> = notes
        .caption
        .iter()
        .flat_map(|c| wrap(c, caption_w, caption_size, measure))
        .collect();
    let caption_line = (caption_size * 1.3).ceil();
    let most = (panel_h as f64 / 4.0 / caption_line).floor().max(1.0) as usize;
    if caption.len() > most {
        caption.truncate(most);
        let last = caption.last_mut().expect("a line");
        while measure(&format!("{last} …"), caption_size) > caption_w {
            match last.rfind(' ') {
                Some(k) => last.truncate(k),
                None => break,
            }
        }
        last.push_str(" …");
    }
    let caption_h = if caption.is_empty() {
        0
    } else {
        (caption.len() as f64 * caption_line).ceil() as u32 + px(4)
    };
    let plot_w = (panel_w as f64 - 105.0 * scale).max(1.0);
    let plot_h = (panel_h as f64
        - 100.0 * scale
        - (title.len() as f64 - 1.0) * line_h * 1.4
        - caption_h as f64)
        .max(1.0);
    let (w, h) = (
        (longest as f64 * 7.0 + 40.0) * scale / plot_w,
        (named.len() as f64 * 20.0 + 20.0) * scale / plot_h,
    );
    let corner = if named.len() > 1 {
        // What the legend must not cover: every point, and the lines between the points of a
        // line series (sampled along each segment).
        let mut occupied = all.clone();
        for s in p.series.iter().filter(|s| !s.scatter) {
            for pair in pts(s).windows(2) {
                let ((ax, ay), (bx, by)) = (pair[0], pair[1]);
                occupied.extend((1..LINE_SAMPLES).map(|k| {
                    let f = k as f64 / LINE_SAMPLES as f64;
                    (ax + f * (bx - ax), ay + f * (by - ay))
                }));
            }
        }
        // A marked x value's line and its text, from the foot of the plot to the top.
        for &(x, _) in &x_marks {
            occupied.extend((0..=LINE_SAMPLES).map(|k| {
                let f = k as f64 / LINE_SAMPLES as f64;
                (x, y0 + f * (y1 - y0))
            }));
        }
        legend_place(&occupied, (x0, x1), (y0, y1), w, h)
    } else {
        None
    };
    // A legend that would cover data in every corner goes beside the plot, in a margin kept
    // for it: to the right where it takes at most 40 % of the panel's width, else below.
    let legend_font = 12.0 * scale;
    // A legend drawn by hand: its box's width and height.
    let box_size = || {
        let widest = named
            .iter()
            .map(|s| measure(s, legend_font))
            .fold(0.0, f64::max);
        (
            (widest + 40.0 * scale).ceil() as i32,
            ((named.len() as f64 * 20.0 + 10.0) * scale).ceil() as i32,
        )
    };
    let outside = (named.len() > 1 && corner.is_none()).then(|| {
        let size = box_size();
        let right = size.0 as f64 + px(20) as f64 <= 0.4 * panel_w as f64;
        (right, size)
    });
    let label = |l: &str, log: bool| {
        if log {
            format!("{l}, log scale")
        } else {
            l.to_string()
        }
    };
    // A log axis is drawn in log10 of the values, labelled with the values themselves: with
    // one label per decade where it spans two or more, each at a power of ten.
    let ticks = |lo: f64, hi: f64, log: bool| {
        if log {
            ((hi - lo).floor() as usize + 1).clamp(3, 12)
        } else {
            10
        }
    };
    let log_tick = |v: f64| {
        let k = v.round();
        if (v - k).abs() < 1e-9 {
            decade(k as i32)
        } else {
            // Between decades: the value to two significant digits.
            let x = 10f64.powf(v);
            let unit = 10f64.powf(x.log10().floor() - 1.0);
            tick((x / unit).round() * unit)
        }
    };
    let fmt_x = |v: &f64| {
        if p.log_x {
            log_tick(*v)
        } else {
            linear_tick(*v, x0, x1)
        }
    };
    let fmt_y = |v: &f64| {
        if p.log_y {
            log_tick(*v)
        } else {
            linear_tick(*v, y0, y1)
        }
    };
    // One line goes through plotters' caption; wrapped lines are set one under the other in
    // the panel's margin, and the chart is built below them. So is one line where the legend
    // stands beside the plot: plotters centres a caption over what the margins leave, and a
    // title fitted to the panel's width would run off its left edge.
    let below_title;
    let mut builder = match &title[..] {
        [line] if outside.is_none() => {
            let mut b = ChartBuilder::on(area);
            b.caption(line, title_style.clone()).margin(px(10));
            b
        }
        lines => {
            let mut rest = area.margin(px(10), px(10), px(10), px(10));
            for line in lines {
                rest = rest.titled(line, title_style.clone()).map_err(|x| e(&x))?;
            }
            below_title = rest;
            ChartBuilder::on(&below_title)
        }
    };
    match outside {
        Some((true, (w, _))) => builder.margin_right(w as u32 + px(20)),
        Some((false, (_, h))) => builder.margin_bottom(h as u32 + px(20)),
        None => &mut builder,
    };
    if caption_h > 0 {
        // The caption goes under the chart, above the panel's bottom margin (the one-line
        // title's builder keeps that margin itself; the others' area is inside it).
        let below = match (outside, &title[..]) {
            (Some((false, (_, h))), _) => h as u32 + px(20),
            (None, [_]) => px(10),
            _ => 0,
        };
        builder.margin_bottom(below + caption_h);
    }
    let mut chart = builder
        .x_label_area_size(px(40))
        .y_label_area_size(px(75))
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(|x| e(&x))?;
    let mut mesh = chart.configure_mesh();
    mesh.x_desc(label(&x_label, p.log_x))
        .y_desc(label(&y_label, p.log_y))
        .x_labels(ticks(x0, x1, p.log_x))
        .y_labels(ticks(y0, y1, p.log_y))
        .x_label_formatter(&fmt_x)
        .y_label_formatter(&fmt_y);
    if scale != 1.0 {
        // At the base resolution the mesh keeps plotters' own text sizes.
        mesh.label_style(("sans-serif", 12.0 * scale))
            .axis_desc_style(("sans-serif", 12.0 * scale))
            .bold_line_style(BLACK.mix(0.2).stroke_width(px(1)))
            .light_line_style(BLACK.mix(0.05).stroke_width(px(1)));
    }
    mesh.draw().map_err(|x| e(&x))?;
    // Each marked x value: a thin line across the plot, and its text along it, reading
    // upwards from the foot of the plot just right of the line.
    for &(x, text) in &x_marks {
        chart
            .draw_series(LineSeries::new(
                [(x, y0), (x, y1)],
                RGBColor(120, 120, 120).stroke_width(px(1)),
            ))
            .map_err(|x| e(&x))?;
        let font = ("sans-serif", 11.0 * scale)
            .into_font()
            .transform(FontTransform::Rotate270)
            .color(&RGBColor(60, 60, 60));
        let at = (px(3) as i32, -(px(6) as i32));
        chart
            .draw_series(std::iter::once(
                EmptyElement::at((x, y0)) + Text::new(text.to_string(), at, font),
            ))
            .map_err(|x| e(&x))?;
    }
    // Style slots in order of first appearance: a curve and its points share one.
    let mut slots: Vec<usize> = Vec::new();
    // Legend entries: a name, its style slot (None: the collapse marker) and its colour.
    let mut entries: Vec<(&str, Option<usize>, RGBAColor)> = Vec::new();
    // Each series' colour, for its collapsed runs' markers.
    let mut colors: Vec<RGBAColor> = Vec::with_capacity(p.series.len());
    for (i, s) in p.series.iter().enumerate() {
        let slot = {
            let key = s.style.unwrap_or(usize::MAX - i);
            match slots.iter().position(|k| *k == key) {
                Some(n) => n,
                None => {
                    slots.push(key);
                    slots.len() - 1
                }
            }
        };
        let color = PALETTE[slot % PALETTE.len()].to_rgba();
        colors.push(color);
        let listed = entry(i);
        if listed {
            entries.push((&s.name, Some(slot), color));
        }
        let data = pts(s);
        if s.name.is_empty() {
            // Unnamed: a background line (one of many), thin and grey, with no legend entry.
            chart
                .draw_series(LineSeries::new(
                    data,
                    RGBColor(175, 175, 175).stroke_width(px(1)),
                ))
                .map_err(|x| e(&x))?;
        } else if s.scatter {
            let fill = if data.len() > DENSE {
                color.mix(0.35)
            } else {
                color
            };
            let drawn = chart
                .draw_series(data.into_iter().map(|q| marker(slot, q, fill, scale)))
                .map_err(|x| e(&x))?;
            if listed {
                drawn
                    .label(&s.name)
                    .legend(move |(x, y)| marker(slot, (x + px(8) as i32, y), color, scale));
            }
        } else {
            // Markers on the points of a line of data, so that it reads without its colour
            // too; a smooth curve (a fit) takes none, which would pass for observations.
            let marks: Vec<(f64, f64)> = if data.len() <= SMOOTH {
                data.clone()
            } else {
                Vec::new()
            };
            let drawn = chart
                .draw_series(LineSeries::new(data, color.stroke_width(px(2))))
                .map_err(|x| e(&x))?;
            if listed {
                drawn
                    .label(&s.name)
                    .legend(move |(x, y)| marker(slot, (x + px(8) as i32, y), color, scale));
            }
            chart
                .draw_series(marks.into_iter().map(|q| marker(slot, q, color, scale)))
                .map_err(|x| e(&x))?;
        }
    }
    let (xs, ys) = chart.plotting_area().get_pixel_range();
    let (bx, by) = area.get_base_pixel();
    if !collapsed.is_empty() {
        // Over the series, in the panel's pixels: each in its series' colour, one legend
        // entry in black.
        let black = BLACK.to_rgba();
        for &(i, q) in &collapsed {
            let (x, y) = chart.backend_coord(&q);
            let color = colors.get(i).copied().unwrap_or(black);
            collapse_marker(area, (x - bx, y - by), color, scale)?;
        }
        entries.push((&notes.collapsed_name, None, black));
    }
    // The legend drawn by hand, its box's corner and size: beside the plot, or in the corner
    // chosen where collapsed runs are marked (plotters' legend takes one element an entry,
    // and the collapse marker is three).
    let by_hand = match (outside, &corner) {
        (Some((true, (w, h))), _) => {
            Some(((panel_w as i32 - px(10) as i32 - w, ys.start - by), (w, h)))
        }
        (Some((false, (w, h))), _) => Some((
            (
                xs.start - bx,
                panel_h as i32 - px(10) as i32 - caption_h as i32 - h,
            ),
            (w, h),
        )),
        (None, Some(c)) if !collapsed.is_empty() => {
            let (w, h) = box_size();
            let m = px(5) as i32;
            let left = matches!(
                c,
                SeriesLabelPosition::UpperLeft | SeriesLabelPosition::LowerLeft
            );
            let upper = matches!(
                c,
                SeriesLabelPosition::UpperLeft | SeriesLabelPosition::UpperRight
            );
            let x = if left {
                xs.start - bx + m
            } else {
                xs.end - bx - m - w
            };
            let y = if upper {
                ys.start - by + m
            } else {
                ys.end - by - m - h
            };
            Some(((x, y), (w, h)))
        }
        _ => None,
    };
    if let Some(((x, y), (w, h))) = by_hand {
        let corners = [(x, y), (x + w, y + h)];
        area.draw(&Rectangle::new(corners, WHITE.mix(0.85).filled()))
            .map_err(|x| e(&x))?;
        area.draw(&Rectangle::new(corners, BLACK.stroke_width(px(1))))
            .map_err(|x| e(&x))?;
        let font = ("sans-serif", legend_font).into_text_style(area).pos(
            plotters::style::text_anchor::Pos::new(
                plotters::style::text_anchor::HPos::Left,
                plotters::style::text_anchor::VPos::Center,
            ),
        );
        for (k, (name, slot, color)) in entries.iter().enumerate() {
            let at = y + ((k as f64 * 20.0 + 15.0) * scale).round() as i32;
            let glyph = (x + px(14) as i32, at);
            match slot {
                Some(slot) => area
                    .draw(&marker::<DB, (i32, i32)>(*slot, glyph, *color, scale))
                    .map_err(|x| e(&x))?,
                None => collapse_marker(area, glyph, *color, scale)?,
            }
            area.draw(&Text::new(*name, (x + px(28) as i32, at), font.clone()))
                .map_err(|x| e(&x))?;
        }
    } else if let Some(corner) = corner {
        let mut legend = chart.configure_series_labels();
        legend
            .position(corner)
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK);
        if scale != 1.0 {
            legend
                .label_font(("sans-serif", 12.0 * scale))
                .margin(px(5))
                .legend_area_size(px(30));
        }
        legend.draw().map_err(|x| e(&x))?;
    }
    // The caption, at the foot of the panel.
    let font = ("sans-serif", caption_size)
        .into_font()
        .color(&RGBColor(40, 40, 40));
    let top = panel_h as i32 - px(10) as i32 - caption_h as i32 + px(4) as i32;
    for (k, line) in caption.iter().enumerate() {
        let at = (px(10) as i32, top + (k as f64 * caption_line) as i32);
        area.draw(&Text::new(line.as_str(), at, font.clone()))
            .map_err(|x| e(&x))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decades_read_as_values() {
        let labels: Vec<String> = (-5..=6).map(decade).collect();
        assert_eq!(
            labels,
            [
                "1e-5", "1e-4", "1e-3", "0.01", "0.1", "1", "10", "100", "1000", "1e4", "1e5",
                "1e6"
            ]
        );
    }

    /// A title is set at 18 px where it fits, smaller down to 14 px, then wrapped at 14 px by
    /// words (measured here at 0.5 px a character per px of size).
    #[test]
    fn titles_shrink_then_wrap() {
        let measure = |t: &str, size: f64| t.chars().count() as f64 * size * 0.5;
        let fit = |t: &str, w: f64| fit_title(t, w, 1.0, measure);
        assert_eq!(fit("abcd", 36.0), (vec!["abcd".to_string()], 18.0));
        assert_eq!(fit("abcd", 30.0), (vec!["abcd".to_string()], 15.0));
        let (lines, size) = fit("aa bb cc dd", 40.0);
        assert_eq!((lines.join("|"), size), ("aa bb|cc dd".to_string(), 14.0));
        // A word wider than the panel stands alone.
        let (lines, _) = fit("a verylongword b", 40.0);
        assert_eq!(lines, ["a", "verylongword", "b"]);
    }

    #[test]
    fn a_tick_at_zero_reads_zero() {
        assert_eq!(linear_tick(-2.78e-17, -0.2, 0.06), "0");
        assert_eq!(linear_tick(1.73e-18, -0.04, 1.04), "0");
        assert_eq!(linear_tick(1e-6, 0.0, 1e-4), "1e-6");
        assert_eq!(linear_tick(0.05, -0.2, 0.06), "0.05");
    }
}
