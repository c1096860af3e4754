//! What a plot shows: panels of named series and their notes, and the error of drawing one.

use std::path::PathBuf;

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
    /// Series with the same style share colour and marker (a fitted curve and the points it
    /// fits); None: a style of its own. An empty name draws a thin grey line with no legend
    /// entry (one of many, as IDA curves). Series of one style and one name are one entry in
    /// the legend (a line drawn in pieces, as an IDA curve and its flatline).
    pub style: Option<usize>,
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
    /// Values the y axis shows whatever the data (a probability's 0 and 1, so that its axis
    /// does not start at 0.82); None: the data's range.
    pub y_span: Option<(f64, f64)>,
    /// What the panel says beside its series; empty (the default): nothing, and the panel is
    /// drawn as it was before notes were added, bit for bit.
    pub notes: Notes,
}

/// What a panel says beside its series: the runs a figure left out or marked apart (`pound
/// plot`'s collapsed runs), where a reader would otherwise take the points drawn for all.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Notes {
    /// Paragraphs set small under the plot, each wrapped to the panel's width.
    pub caption: Vec<String>,
    /// x values the axis shows whatever the data, each drawn as a thin vertical line with its
    /// text along it (an intensity at which every run collapsed: `all 80 collapsed`), so that
    /// they do not vanish from the axis.
    pub x_marks: Vec<(f64, String)>,
    /// Points drawn with the collapse marker (a crossed square), each in the colour of the
    /// series it belongs to (its index in [`Panel::series`]), and listed once in the legend
    /// as `collapsed_name`.
    pub collapsed: Vec<(usize, (f64, f64))>,
    pub collapsed_name: String,
}

impl Notes {
    pub fn is_empty(&self) -> bool {
        self.caption.is_empty() && self.x_marks.is_empty() && self.collapsed.is_empty()
    }
}
