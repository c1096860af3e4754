//! Line plots as SVG (`plotters`): panels of named series. Text is left to the SVG viewer, so
//! no font files are needed. Log axes plot `log10` of the values and say so in the axis label.

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

fn range(v: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = v
        .filter(|x| x.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
            (a.min(x), b.max(x))
        });
    if !lo.is_finite() {
        return (0.0, 1.0);
    }
    let pad = if hi > lo {
        0.04 * (hi - lo)
    } else {
        0.5 * lo.abs().max(1e-12)
    };
    (lo - pad, hi + pad)
}

/// Draw `panels` in a grid of `cols` columns into an SVG file at `path` (written whole, then
/// renamed into place).
pub fn svg(path: &Path, panels: &[Panel], cols: usize) -> Result<(), PlotError> {
    let fail = |e: &dyn std::fmt::Display| PlotError {
        path: path.into(),
        message: e.to_string(),
    };
    let cols = cols.clamp(1, panels.len().max(1));
    let rows = panels.len().div_ceil(cols).max(1);
    let mut text = String::new();
    {
        let root = SVGBackend::with_string(&mut text, (480 * cols as u32, 360 * rows as u32))
            .into_drawing_area();
        root.fill(&WHITE).map_err(|e| fail(&e))?;
        for (area, p) in root.split_evenly((rows, cols)).iter().zip(panels) {
            draw(area, p).map_err(|e| fail(&e))?;
        }
        root.present().map_err(|e| fail(&e))?;
    }
    crate::output::write_atomic(path, text.as_bytes()).map_err(|e| fail(&e))
}

type Area<'a> = DrawingArea<SVGBackend<'a>, plotters::coord::Shift>;

fn draw(area: &Area, p: &Panel) -> Result<(), String> {
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
        .y_label_area_size(60)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(|x| e(&x))?;
    chart
        .configure_mesh()
        .x_desc(label(&p.x_label, p.log_x))
        .y_desc(label(&p.y_label, p.log_y))
        .draw()
        .map_err(|x| e(&x))?;
    for (i, s) in p.series.iter().enumerate() {
        let color = Palette99::pick(i).to_rgba();
        let data = pts(s);
        if s.scatter {
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
