//! Line and scatter plots (`plotters`): panels of named series, as SVG or PNG by the file's
//! extension. Text is measured (and in PNG drawn) with a font built into the binary, so no font
//! files are needed. Log axes plot `log10` of the values and say so in the axis label.

use image::ImageEncoder;
use plotters::prelude::*;
use std::path::{Path, PathBuf};

#[derive(Debug, thiserror::Error)]
#[error("{}: cannot draw the plot: {message}", path.display())]
pub struct PlotError {
    pub path: PathBuf,
    pub message: String,
}

/// One series: a name for the legend and its points.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    pub name: String,
    pub points: Vec<(f64, f64)>,
    /// Markers only (no line).
    pub scatter: bool,
    // An empty name draws a thin grey line with no legend entry (one of many, as IDA curves).
}

/// One chart.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Panel {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub log_x: bool,
    pub log_y: bool,
    pub series: Vec<Series>,
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

/// Text is drawn with DejaVu Sans compiled into the binary (the `dejavu` crate), so plots need
/// no font files on the machine.
fn register_font() -> Result<(), String> {
    static DONE: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    let ok = *DONE.get_or_init(|| {
        plotters::style::register_font("sans-serif", FontStyle::Normal, dejavu::sans::regular())
            .is_ok()
    });
    if ok {
        Ok(())
    } else {
        Err("the built-in font did not load".into())
    }
}

/// Draw `panels` in a grid of `cols` columns into `path`: SVG, or PNG for a `.png` name
/// (written whole, then renamed into place).
pub fn save(path: &Path, panels: &[Panel], cols: usize) -> Result<(), PlotError> {
    let png = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("png"));
    if png {
        self::png(path, panels, cols)
    } else {
        svg(path, panels, cols)
    }
}

fn grid(panels: &[Panel], cols: usize) -> (usize, usize, (u32, u32)) {
    let cols = cols.clamp(1, panels.len().max(1));
    let rows = panels.len().div_ceil(cols).max(1);
    (rows, cols, (640 * cols as u32, 480 * rows as u32))
}

fn draw_all<DB: DrawingBackend>(
    root: DrawingArea<DB, plotters::coord::Shift>,
    panels: &[Panel],
    rows: usize,
    cols: usize,
) -> Result<(), String> {
    let e = |e: &dyn std::fmt::Display| e.to_string();
    root.fill(&WHITE).map_err(|x| e(&x))?;
    for (area, p) in root.split_evenly((rows, cols)).iter().zip(panels) {
        draw(area, p)?;
    }
    root.present().map_err(|x| e(&x))
}

/// [`save`] as SVG whatever the name.
pub fn svg(path: &Path, panels: &[Panel], cols: usize) -> Result<(), PlotError> {
    let fail = |message: String| PlotError {
        path: path.into(),
        message,
    };
    register_font().map_err(fail)?;
    let (rows, cols, size) = grid(panels, cols);
    let mut text = String::new();
    draw_all(
        SVGBackend::with_string(&mut text, size).into_drawing_area(),
        panels,
        rows,
        cols,
    )
    .map_err(fail)?;
    crate::io::atomic::write_atomic(path, text.as_bytes()).map_err(|e| fail(e.to_string()))
}

/// [`save`] as PNG whatever the name.
pub fn png(path: &Path, panels: &[Panel], cols: usize) -> Result<(), PlotError> {
    let fail = |message: String| PlotError {
        path: path.into(),
        message,
    };
    register_font().map_err(fail)?;
    let (rows, cols, size) = grid(panels, cols);
    let mut pixels = vec![0u8; size.0 as usize * size.1 as usize * 3];
    draw_all(
        BitMapBackend::with_buffer(&mut pixels, size).into_drawing_area(),
        panels,
        rows,
        cols,
    )
    .map_err(fail)?;
    let mut bytes = Vec::new();
    image::codecs::png::PngEncoder::new(&mut bytes)
        .write_image(&pixels, size.0, size.1, image::ColorType::Rgb8)
        .map_err(|e| fail(e.to_string()))?;
    crate::io::atomic::write_atomic(path, &bytes).map_err(|e| fail(e.to_string()))
}

fn draw<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    p: &Panel,
) -> Result<(), String> {
    let e = |e: &dyn std::fmt::Display| e.to_string();
    let tx = |x: f64| if p.log_x { x.log10() } else { x };
    let ty = |y: f64| if p.log_y { y.log10() } else { y };
    let pts = |s: &Series| -> Vec<(f64, f64)> {
        s.points
            .iter()
            .map(|&(x, y)| (tx(x), ty(y)))
            .filter(|(x, y)| x.is_finite() && y.is_finite())
            .collect()
    };
    let all: Vec<(f64, f64)> = p.series.iter().flat_map(pts).collect();
    let (x0, x1) = range(all.iter().map(|q| q.0));
    let (y0, y1) = range(all.iter().map(|q| q.1));
    let label = |l: &str, log: bool| {
        if log {
            format!("log10 {l}")
        } else {
            l.to_string()
        }
    };
    let mut chart = ChartBuilder::on(area)
        .caption(&p.title, ("sans-serif", 18))
        .margin(10)
        .x_label_area_size(40)
        .y_label_area_size(75)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(|x| e(&x))?;
    chart
        .configure_mesh()
        .x_desc(label(&p.x_label, p.log_x))
        .y_desc(label(&p.y_label, p.log_y))
        .x_label_formatter(&|v| tick(*v))
        .y_label_formatter(&|v| tick(*v))
        .draw()
        .map_err(|x| e(&x))?;
    for (i, s) in p.series.iter().enumerate() {
        let color = Palette99::pick(i).to_rgba();
        let data = pts(s);
        if s.name.is_empty() {
            // Unnamed: a background line (one of many), thin and grey, with no legend entry.
            chart
                .draw_series(LineSeries::new(
                    data,
                    RGBColor(175, 175, 175).stroke_width(1),
                ))
                .map_err(|x| e(&x))?;
        } else if s.scatter {
            chart
                .draw_series(data.into_iter().map(|q| Circle::new(q, 3, color.filled())))
                .map_err(|x| e(&x))?
                .label(&s.name)
                .legend(move |(x, y)| Circle::new((x + 8, y), 3, color.filled()));
        } else {
            chart
                .draw_series(LineSeries::new(data, color.stroke_width(2)))
                .map_err(|x| e(&x))?
                .label(&s.name)
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], color));
        }
    }
    if p.series.len() > 1 {
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperLeft)
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .draw()
            .map_err(|x| e(&x))?;
    }
    Ok(())
}
