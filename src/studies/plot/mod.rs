//! Line and scatter plots (`plotters`): panels of named series, as SVG or PNG by the file's
//! extension. Text is measured (and in PNG drawn) with a font built into the binary, so no font
//! files are needed. Log axes are drawn in `log10` of the values and labelled with the values,
//! a label at each power of ten.

mod draw;
mod panel;
mod save;
mod units;

pub use draw::SMOOTH;
pub use panel::{Notes, Panel, PlotError, Series};
pub use save::{
    check_pixels, png, save, save_at, save_sized, svg, BASE_DPI, DPIS, PANEL, PANEL_SIZES,
};
pub use units::{relabel, rescale, unit_of, Axis};
