//! Displacement snapshots of one or more bars in a common frame: where each bar sits
//! ([`Placement`], [`PlacedBar`]) and the line panel of its profiles at a few instants.

use super::axes::tick;
use super::canvas::PlotError;
use super::types::{LegendPosition, LinePanel, Rgb, Series, SpaceTimeField};

/// How a bar is drawn in the common frame of a snapshot plot.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Placement {
    /// Common-frame position of the bar's own `x = 0`.
    pub origin: f64,
    /// The bar points the other way: position `origin - x`, displacement drawn as `-u`.
    pub mirrored: bool,
}

/// One bar of a snapshot plot: its field and where it sits.
#[derive(Debug, Clone, PartialEq)]
pub struct PlacedBar<'a> {
    /// Name in the legend (e.g. "bar 1").
    pub name: &'a str,
    /// The displacement field.
    pub field: &'a SpaceTimeField,
    /// Placement in the common frame.
    pub placement: Placement,
}

/// The colour of instant `s in [0, 1]` of a snapshot plot: indigo, blue, cyan, green,
/// yellow-green, amber, orange, crimson. Eight instants get eight hues a reader tells apart,
/// still ordered from cool (early) to warm (late); every colour is dark enough to read on
/// white.
pub fn instant_colour(s: f64) -> Rgb {
    let stops = [
        Rgb(45, 30, 120),
        Rgb(40, 90, 200),
        Rgb(0, 160, 200),
        Rgb(0, 150, 100),
        Rgb(120, 170, 20),
        Rgb(225, 155, 0),
        Rgb(220, 80, 20),
        Rgb(160, 20, 60),
    ];
    Rgb::along(&stops, s)
}

/// Snapshots of the displacement of one or more bars at `instants` instants evenly picked
/// from their time grids, in a common frame: bar positions along the horizontal axis (a
/// mirrored bar faces the other, as the paper's Fig. 3), displacements vertically (a mirrored
/// bar's drawn as `-u`, i.e. in the common frame's direction), one colour per instant from
/// [`instant_colour`] (blue at `t = 0`, red at the last instant), and dashed guides at `guides`
/// (e.g. the contact interface).
///
/// # Errors
/// [`PlotError::InvalidData`] for no bar, zero instants, or a field whose lengths do not match.
pub fn snapshots_panel(
    title: impl Into<String>,
    bars: &[PlacedBar<'_>],
    instants: usize,
    guides: &[f64],
) -> Result<LinePanel, PlotError> {
    if bars.is_empty() || instants == 0 {
        return Err(PlotError::InvalidData {
            what: "snapshots",
            reason: format!("{} bars, {instants} instants", bars.len()),
        });
    }
    for b in bars {
        b.field.check("snapshot field")?;
    }
    let mut series = Vec::new();
    for s in 0..instants {
        let color = instant_colour(s as f64 / (instants.max(2) - 1) as f64);
        for (bi, b) in bars.iter().enumerate() {
            let nt = b.field.time.len();
            let k = (s * nt / instants).min(nt - 1);
            let sign = if b.placement.mirrored { -1.0 } else { 1.0 };
            let points = b
                .field
                .position
                .iter()
                .zip(b.field.row(k))
                .map(|(&x, &u)| (b.placement.origin + sign * x, sign * u))
                .collect();
            let label = if bi == 0 {
                format!("t = {}", tick(b.field.time[k]))
            } else {
                String::new()
            };
            let mut line = Series::line(label, points).with_color(color);
            if bi % 2 == 1 {
                line = line.dashed();
            }
            series.push(line);
        }
    }
    let names: Vec<&str> = bars.iter().map(|b| b.name).collect();
    let y_label = if bars.iter().any(|b| b.placement.mirrored) {
        format!(
            "displacement ({}: solid, dashed; mirrored as −u)",
            names.join(", ")
        )
    } else {
        "displacement u".to_string()
    };
    Ok(LinePanel {
        series,
        x_guides: guides.to_vec(),
        legend: if instants <= 8 {
            LegendPosition::Auto
        } else {
            LegendPosition::Hidden
        },
        ..LinePanel::new(title, "position", y_label)
    })
}
