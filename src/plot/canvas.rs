//! What every panel draws on: the error of the plotting functions, the SVG drawing area, the
//! font and the chart builder of a panel.

use plotters::prelude::*;
use thiserror::Error;

/// Errors of the plotting functions.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum PlotError {
    /// The drawing backend failed (typically an I/O error writing the file).
    #[error("drawing failed: {0}")]
    Draw(String),
    /// The data cannot be drawn as asked (mismatched lengths, empty grids, bad layout).
    #[error("invalid plot data: {what}: {reason}")]
    InvalidData {
        /// Which input.
        what: &'static str,
        /// What is wrong with it.
        reason: String,
    },
}

pub(super) fn draw_err<E: std::fmt::Display>(e: E) -> PlotError {
    PlotError::Draw(e.to_string())
}

/// A drawing area of the SVG backend: the whole figure or one panel of it.
pub(super) type Area<'a> = DrawingArea<SVGBackend<'a>, plotters::coord::Shift>;

/// Font family of every text element.
pub(super) const FONT: &str = "sans-serif";

/// The chart builder of a panel on `area`: 12-pixel margins, 46 pixels of labels under the
/// horizontal axis and `y_label_area` pixels left of the vertical one, and `title` (if not
/// empty) above.
pub(super) fn panel_builder<'a, 'b>(
    area: &'a Area<'b>,
    title: &str,
    y_label_area: u32,
) -> ChartBuilder<'a, 'static, SVGBackend<'b>> {
    let mut builder = ChartBuilder::on(area);
    builder
        .margin(12)
        .x_label_area_size(46)
        .y_label_area_size(y_label_area);
    if !title.is_empty() {
        builder.caption(title, (FONT, 20));
    }
    builder
}
