//! Panels into a file: a grid of panels as SVG or PNG by the file's extension, its size and
//! resolution bounded before anything is drawn.

use super::draw::draw;
use super::panel::{Panel, PlotError};
use image::ImageEncoder;
use plotters::prelude::*;
use std::path::Path;

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
    save_sized(path, panels, cols, PANEL)
}

/// A panel's size in pixels unless given.
pub const PANEL: (u32, u32) = (640, 480);

/// The sizes a panel may take, px.
pub const PANEL_SIZES: std::ops::RangeInclusive<u32> = 320..=4000;

/// [`save`] with each panel `size` pixels wide and high.
pub fn save_sized(
    path: &Path,
    panels: &[Panel],
    cols: usize,
    size: (u32, u32),
) -> Result<(), PlotError> {
    save_at(path, panels, cols, size, BASE_DPI)
}

/// The resolution a panel's `size` is given at: 96 dots per inch, a screen's.
pub const BASE_DPI: u32 = 96;

/// The resolutions a PNG may be drawn at, dots per inch.
pub const DPIS: std::ops::RangeInclusive<u32> = 48..=600;

/// [`save_sized`] with a PNG drawn at `dpi`: `size` (at [`BASE_DPI`]) times `dpi / 96` pixels,
/// its text, marks and margins scaled alike, so the figure looks the same at a finer
/// resolution. An SVG is drawn at `size` whatever `dpi` (it has no resolution).
pub fn save_at(
    path: &Path,
    panels: &[Panel],
    cols: usize,
    size: (u32, u32),
    dpi: u32,
) -> Result<(), PlotError> {
    let png = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("png"));
    let size = (
        size.0.clamp(*PANEL_SIZES.start(), *PANEL_SIZES.end()),
        size.1.clamp(*PANEL_SIZES.start(), *PANEL_SIZES.end()),
    );
    if png {
        let dpi = dpi.clamp(*DPIS.start(), *DPIS.end());
        let scale = dpi as f64 / BASE_DPI as f64;
        check_pixels(panels.len(), cols, size, dpi).map_err(|message| PlotError {
            path: path.into(),
            message,
        })?;
        self::png(path, panels, cols, size, scale)
    } else {
        svg(path, panels, cols, size)
    }
}

/// The pixels of a PNG of `n` panels, `cols` a row, each `size` at `dpi`, within
/// [`crate::plan::limits::MAX_FIGURE_PIXELS`]: checked before the image is allocated. Err: the
/// product, the bound and what gets under it.
pub fn check_pixels(n: usize, cols: usize, size: (u32, u32), dpi: u32) -> Result<(), String> {
    use crate::plan::limits::{MAX_FIGURE_PIXELS, WHY_FIGURE_PIXELS};
    let cols = cols.clamp(1, n.max(1));
    let rows = n.div_ceil(cols).max(1);
    let scaled = |v: u32| (v as f64 * dpi as f64 / BASE_DPI as f64).round() as u64;
    let (w, h) = (scaled(size.0) * cols as u64, scaled(size.1) * rows as u64);
    if w * h <= MAX_FIGURE_PIXELS {
        return Ok(());
    }
    // The largest dpi at which this figure fits, for the message.
    let fits = (BASE_DPI as f64
        * (MAX_FIGURE_PIXELS as f64 / (size.0 as f64 * cols as f64 * size.1 as f64 * rows as f64))
            .sqrt())
    .floor();
    Err(format!(
        "{n} panel(s), {cols} a row, of {}x{} px (--size) at {dpi} dpi (--dpi) make a {w}x{h} PNG, {:.0} megapixels: over the bound of {} megapixels a figure ({WHY_FIGURE_PIXELS}). Lower --size or --dpi (at this size, {} dpi or less), or draw an SVG",
        size.0,
        size.1,
        (w * h) as f64 / 1e6,
        MAX_FIGURE_PIXELS / 1_000_000,
        match fits as u32 {
            d if d >= *DPIS.start() => format!("{d}"),
            _ => "no resolution fits; a smaller --size".to_string(),
        }
    ))
}

fn grid(panels: &[Panel], cols: usize, size: (u32, u32)) -> (usize, usize, (u32, u32)) {
    let cols = cols.clamp(1, panels.len().max(1));
    let rows = panels.len().div_ceil(cols).max(1);
    (rows, cols, (size.0 * cols as u32, size.1 * rows as u32))
}

fn draw_all<DB: DrawingBackend>(
    root: DrawingArea<DB, plotters::coord::Shift>,
    panels: &[Panel],
    rows: usize,
    cols: usize,
    scale: f64,
) -> Result<(), String> {
    let e = |e: &dyn std::fmt::Display| e.to_string();
    root.fill(&WHITE).map_err(|x| e(&x))?;
    for (area, p) in root.split_evenly((rows, cols)).iter().zip(panels) {
        draw(area, p, scale)?;
    }
    root.present().map_err(|x| e(&x))
}

/// [`save_sized`] as SVG whatever the name.
pub fn svg(path: &Path, panels: &[Panel], cols: usize, size: (u32, u32)) -> Result<(), PlotError> {
    let fail = |message: String| PlotError {
        path: path.into(),
        message,
    };
    register_font().map_err(fail)?;
    let (rows, cols, size) = grid(panels, cols, size);
    let mut text = String::new();
    draw_all(
        SVGBackend::with_string(&mut text, size).into_drawing_area(),
        panels,
        rows,
        cols,
        1.0,
    )
    .map_err(fail)?;
    crate::io::atomic::write_atomic(path, text.as_bytes()).map_err(|e| fail(e.to_string()))
}

/// [`save_sized`] as PNG whatever the name.
pub fn png(
    path: &Path,
    panels: &[Panel],
    cols: usize,
    size: (u32, u32),
    scale: f64,
) -> Result<(), PlotError> {
    let fail = |message: String| PlotError {
        path: path.into(),
        message,
    };
    register_font().map_err(fail)?;
    let scaled = |v: u32| (v as f64 * scale).round() as u32;
    let (rows, cols, size) = grid(panels, cols, (scaled(size.0), scaled(size.1)));
    let mut pixels = vec![0u8; size.0 as usize * size.1 as usize * 3];
    draw_all(
        BitMapBackend::with_buffer(&mut pixels, size).into_drawing_area(),
        panels,
        rows,
        cols,
        scale,
    )
    .map_err(fail)?;
    let mut bytes = Vec::new();
    image::codecs::png::PngEncoder::new(&mut bytes)
        .write_image(&pixels, size.0, size.1, image::ColorType::Rgb8)
        .map_err(|e| fail(e.to_string()))?;
    crate::io::atomic::write_atomic(path, &bytes).map_err(|e| fail(e.to_string()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pixels_are_bounded_before_drawing() {
        assert!(check_pixels(6, 3, (640, 480), 300).is_ok());
        let e = check_pixels(6, 3, (4000, 4000), 600).unwrap_err();
        assert!(
            e.contains("75000x50000") && e.contains("100 megapixels"),
            "{e}"
        );
        assert!(check_pixels(1, 1, (4000, 4000), 96).is_ok());
    }
}
