//! SVG plots of backbones, space-time fields, bar snapshots and time histories, from plain
//! data (feature `plot`).
//!
//! Plotting knows nothing about bars or solvers: it draws [`Series`] of `(x, y)` points,
//! space-time maps of a field ([`SpaceTimeField`]) and displacement snapshots of bars, laid
//! out as [`Panel`]s of a [`Figure`]. The figure is written as an SVG file by [`render_svg`];
//! the one-panel helpers [`plot_backbone`], [`plot_space_time`], [`plot_snapshots`],
//! [`plot_histories`] and [`plot_xy`] cover the usual cases, and the `*_panel` builders let a
//! caller compose several views in one figure.
//!
//! The backend is `plotters`' SVG backend without font rendering: text is emitted as SVG
//! `<text>` elements and laid out with an estimated glyph width, so nothing beyond the crate
//! itself is needed to build.
//!
//! Non-finite values break lines (a `NaN` between two points leaves a gap), and points that a
//! logarithmic axis cannot show (`<= 0`) are skipped. Every failure is a [`PlotError`].
//!
//! ```no_run
//! use nonsmooth_modes::plot::{plot_backbone, Series};
//!
//! let exact: Vec<(f64, f64)> = (0..50)
//!     .map(|i| {
//!         let t = 3.95 - 0.018 * i as f64;
//!         (4.0 / t, 8.0 / (std::f64::consts::PI.powi(2) * (t - 3.0).powi(2)))
//!     })
//!     .collect();
//! let branch = Series::markers("NSM1, m = 20", exact.iter().step_by(5).cloned().collect());
//! plot_backbone("backbone.svg", "First NSM", &[branch], Some(&exact))?;
//! # Ok::<(), nonsmooth_modes::plot::PlotError>(())
//! ```

// Split by plot kind: the error and what every panel draws on (`canvas`), the data types
// (`types`), axis ranges and ticks (`axes`), line panels (`lines`), colour maps (`map`), bar
// snapshots (`snapshots`), and the panel builders with the one-call helpers (`helpers`).
// Everything public is re-exported here.
mod annotate;
mod axes;
mod canvas;
mod helpers;
mod legend;
mod lines;
mod map;
mod place;
mod snapshots;
mod stability;
mod svg;
mod types;

pub use canvas::PlotError;
pub use helpers::{
    backbone_panel, histories_panel, plot_backbone, plot_histories, plot_snapshots,
    plot_space_time, plot_xy, space_time_panel, ENERGY_LABEL, FREQUENCY_LABEL,
};
pub use snapshots::{instant_colour, snapshots_panel, PlacedBar, Placement};
pub use stability::stability_series;
pub use types::{
    Annotation, Figure, LegendPosition, LineKind, LinePanel, MapPanel, Marker, Panel, Rgb, Series,
    SpaceTimeField, PALETTE,
};

use canvas::draw_err;
use canvas::FONT;
use plotters::prelude::*;
use std::path::Path;

/// Writes `figure` as an SVG file at `path`.
///
/// # Errors
/// [`PlotError::InvalidData`] for a figure without panels, zero columns, a zero panel size or
/// inconsistent panel data; [`PlotError::Draw`] if drawing or writing the file fails.
pub fn render_svg(path: impl AsRef<Path>, figure: &Figure) -> Result<(), PlotError> {
    if figure.panels.is_empty() || figure.columns == 0 {
        return Err(PlotError::InvalidData {
            what: "figure",
            reason: format!(
                "{} panels on {} columns",
                figure.panels.len(),
                figure.columns
            ),
        });
    }
    let (pw, ph) = figure.panel_size;
    if pw < 50 || ph < 50 {
        return Err(PlotError::InvalidData {
            what: "panel size",
            reason: format!("{pw} x {ph} pixels is too small"),
        });
    }
    let columns = figure.columns.min(figure.panels.len());
    let rows = figure.panels.len().div_ceil(columns);
    let header = if figure.title.is_empty() { 0 } else { 40 };
    let size = (pw * columns as u32, ph * rows as u32 + header);
    let mut text = String::new();
    {
        let root = SVGBackend::with_string(&mut text, size).into_drawing_area();
        root.fill(&WHITE).map_err(draw_err)?;
        let body = if figure.title.is_empty() {
            root.clone()
        } else {
            root.titled(&figure.title, (FONT, 24)).map_err(draw_err)?
        };
        let areas = body.split_evenly((rows, columns));
        for (panel, area) in figure.panels.iter().zip(&areas) {
            match panel {
                Panel::Lines(p) => lines::draw_line_panel(area, p)?,
                Panel::Map(p) => map::draw_map_panel(area, p)?,
            }
        }
        root.present().map_err(draw_err)?;
    }
    std::fs::write(path.as_ref(), svg::portable_text(&text))
        .map_err(|e| PlotError::Draw(format!("writing {}: {e}", path.as_ref().display())))
}
