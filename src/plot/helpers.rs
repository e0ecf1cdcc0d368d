//! The panel builders of backbones, space-time maps and time histories, and the one-call
//! helpers that write a single panel (or a generic `(x, y)` plot) as an SVG file.

use super::snapshots::{snapshots_panel, PlacedBar};
use super::types::{
    Figure, LineKind, LinePanel, MapPanel, Marker, Panel, Rgb, Series, SpaceTimeField, PALETTE,
};
use super::{render_svg, PlotError};
use std::path::Path;

/// Axis label of normalised frequencies.
pub const FREQUENCY_LABEL: &str = "Ω/ω₁";
/// Axis label of normalised energies.
pub const ENERGY_LABEL: &str = "E/E_g";

/// A backbone panel: `E/E_g` (logarithmic) against `Omega/omega_1` for several labelled
/// branches, each with markers in its own colour, and an optional exact curve drawn as a
/// black line.
pub fn backbone_panel(
    title: impl Into<String>,
    branches: &[Series],
    exact: Option<&[(f64, f64)]>,
) -> LinePanel {
    let markers = [
        Marker::Circle,
        Marker::Square,
        Marker::Triangle,
        Marker::Ring,
        Marker::Cross,
    ];
    let mut series: Vec<Series> = branches
        .iter()
        .enumerate()
        .map(|(i, b)| {
            let mut b = b.clone();
            if b.marker.is_none() && b.line == LineKind::None {
                b.marker = Some(markers[i % markers.len()]);
            }
            b.color.get_or_insert(PALETTE[i % PALETTE.len()]);
            b
        })
        .collect();
    if let Some(e) = exact {
        series.push(
            Series::line("exact 8/(π²(T − 3)²)", e.to_vec())
                .with_color(Rgb::BLACK)
                .with_size(1),
        );
    }
    LinePanel {
        y_log: true,
        series,
        ..LinePanel::new(title, FREQUENCY_LABEL, ENERGY_LABEL)
    }
}

/// A space-time colour map of one bar's displacement: position horizontally, time
/// vertically, `u` in a diverging colour scale.
///
/// # Errors
/// [`PlotError::InvalidData`] if the field's lengths do not match.
pub fn space_time_panel(
    title: impl Into<String>,
    field: &SpaceTimeField,
    value_label: impl Into<String>,
) -> Result<MapPanel, PlotError> {
    field.check("space-time field")?;
    Ok(MapPanel {
        title: title.into(),
        x_label: "x".into(),
        y_label: "t".into(),
        value_label: value_label.into(),
        x: field.position.clone(),
        y: field.time.clone(),
        values: field.values.clone(),
        diverging: true,
        overlay: Vec::new(),
    })
}

/// Time histories: several named series sampled at the same instants.
///
/// # Errors
/// [`PlotError::InvalidData`] if a series' length differs from `time`'s.
pub fn histories_panel(
    title: impl Into<String>,
    time: &[f64],
    series: &[(&str, &[f64])],
) -> Result<LinePanel, PlotError> {
    let mut out = Vec::with_capacity(series.len());
    for (name, values) in series {
        if values.len() != time.len() {
            return Err(PlotError::InvalidData {
                what: "history",
                reason: format!(
                    "series `{name}` has {} values for {} instants",
                    values.len(),
                    time.len()
                ),
            });
        }
        out.push(Series::from_columns(*name, time, values));
    }
    Ok(LinePanel {
        series: out,
        ..LinePanel::new(title, "t", "")
    })
}

/// Writes `panel` alone as an SVG figure at `path`.
fn single(path: impl AsRef<Path>, panel: impl Into<Panel>) -> Result<(), PlotError> {
    render_svg(path, &Figure::new("", 1, vec![panel.into()]))
}

/// Writes a backbone plot (see [`backbone_panel`]) to `path`.
///
/// # Errors
/// See [`render_svg`].
pub fn plot_backbone(
    path: impl AsRef<Path>,
    title: &str,
    branches: &[Series],
    exact: Option<&[(f64, f64)]>,
) -> Result<(), PlotError> {
    single(path, backbone_panel(title, branches, exact))
}

/// Writes a space-time map of one bar's displacement (see [`space_time_panel`]) to `path`.
///
/// # Errors
/// See [`space_time_panel`] and [`render_svg`].
pub fn plot_space_time(
    path: impl AsRef<Path>,
    title: &str,
    field: &SpaceTimeField,
) -> Result<(), PlotError> {
    single(path, space_time_panel(title, field, "u")?)
}

/// Writes displacement snapshots of bars (see [`snapshots_panel`]) to `path`.
///
/// # Errors
/// See [`snapshots_panel`] and [`render_svg`].
pub fn plot_snapshots(
    path: impl AsRef<Path>,
    title: &str,
    bars: &[PlacedBar<'_>],
    instants: usize,
    guides: &[f64],
) -> Result<(), PlotError> {
    single(path, snapshots_panel(title, bars, instants, guides)?)
}

/// Writes time histories (see [`histories_panel`]) to `path`.
///
/// # Errors
/// See [`histories_panel`] and [`render_svg`].
pub fn plot_histories(
    path: impl AsRef<Path>,
    title: &str,
    time: &[f64],
    series: &[(&str, &[f64])],
) -> Result<(), PlotError> {
    single(path, histories_panel(title, time, series)?)
}

/// Writes a generic `(x, y)` line plot with optional logarithmic axes to `path`.
///
/// # Errors
/// See [`render_svg`].
#[allow(clippy::too_many_arguments)]
pub fn plot_xy(
    path: impl AsRef<Path>,
    title: &str,
    x_label: &str,
    y_label: &str,
    x_log: bool,
    y_log: bool,
    series: &[Series],
) -> Result<(), PlotError> {
    single(
        path,
        LinePanel {
            x_log,
            y_log,
            series: series.to_vec(),
            ..LinePanel::new(title, x_label, y_label)
        },
    )
}
