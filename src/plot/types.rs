//! The data a figure is made of: colours, series of points and how they are drawn, line and
//! map panels, the figure that lays them out, and the space-time field of one bar.

use super::canvas::PlotError;
use plotters::style::RGBColor;

/// An RGB colour.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Rgb(pub u8, pub u8, pub u8);

/// Colours given to series in order when they set none: green, red, gold, blue, purple,
/// orange, teal, grey (the paper colours NSM1 green, NSM2 red and subharmonics yellow).
pub const PALETTE: [Rgb; 8] = [
    Rgb(0, 150, 60),
    Rgb(210, 30, 40),
    Rgb(225, 170, 0),
    Rgb(30, 90, 200),
    Rgb(140, 60, 170),
    Rgb(240, 120, 20),
    Rgb(0, 150, 160),
    Rgb(110, 110, 110),
];

impl Rgb {
    /// Black.
    pub const BLACK: Rgb = Rgb(0, 0, 0);
    /// White.
    pub const WHITE: Rgb = Rgb(255, 255, 255);

    /// The same colour for the drawing backend.
    pub(super) fn color(self) -> RGBColor {
        RGBColor(self.0, self.1, self.2)
    }

    /// Linear blend `(1 - s) self + s other`, `s` clamped to `[0, 1]`.
    pub fn mix(self, other: Rgb, s: f64) -> Rgb {
        let s = if s.is_finite() {
            s.clamp(0.0, 1.0)
        } else {
            0.0
        };
        let m = |a: u8, b: u8| (a as f64 + (b as f64 - a as f64) * s).round() as u8;
        Rgb(m(self.0, other.0), m(self.1, other.1), m(self.2, other.2))
    }

    /// The colour at `s in [0, 1]` of the scale through `stops`, evenly spaced (at least two),
    /// blended linearly between neighbours; `s` is clamped, and a non-finite `s` is 0.
    pub(super) fn along(stops: &[Rgb], s: f64) -> Rgb {
        let s = if s.is_finite() {
            s.clamp(0.0, 1.0)
        } else {
            0.0
        };
        let s = s * (stops.len() - 1) as f64;
        let i = (s.floor() as usize).min(stops.len() - 2);
        stops[i].mix(stops[i + 1], s - i as f64)
    }
}

/// How the points of a series are joined.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LineKind {
    /// Not joined (markers only).
    None,
    /// Solid line.
    #[default]
    Solid,
    /// Dashed line.
    Dashed,
}

/// Marker drawn at each point.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Marker {
    /// Filled circle.
    Circle,
    /// Hollow circle.
    Ring,
    /// Filled square.
    Square,
    /// Filled triangle.
    Triangle,
    /// Cross.
    Cross,
}

/// One named curve or cloud of points.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// Legend entry (empty: not in the legend).
    pub label: String,
    /// The points `(x, y)`; non-finite values break the line.
    pub points: Vec<(f64, f64)>,
    /// Colour (default: the panel's next [`PALETTE`] entry).
    pub color: Option<Rgb>,
    /// How points are joined.
    pub line: LineKind,
    /// Marker at each point.
    pub marker: Option<Marker>,
    /// Line width / marker radius in pixels (default 2 / 3).
    pub size: u32,
}

impl Series {
    /// A solid line.
    pub fn line(label: impl Into<String>, points: Vec<(f64, f64)>) -> Self {
        Self {
            label: label.into(),
            points,
            color: None,
            line: LineKind::Solid,
            marker: None,
            size: 2,
        }
    }

    /// Filled circles, not joined.
    pub fn markers(label: impl Into<String>, points: Vec<(f64, f64)>) -> Self {
        Self {
            line: LineKind::None,
            marker: Some(Marker::Circle),
            size: 3,
            ..Self::line(label, points)
        }
    }

    /// A line from two columns of equal length (the extra values of the longer are ignored).
    pub fn from_columns(label: impl Into<String>, x: &[f64], y: &[f64]) -> Self {
        Self::line(label, x.iter().cloned().zip(y.iter().cloned()).collect())
    }

    /// The same series in colour `color`.
    pub fn with_color(mut self, color: Rgb) -> Self {
        self.color = Some(color);
        self
    }

    /// The same series with a dashed line.
    pub fn dashed(mut self) -> Self {
        self.line = LineKind::Dashed;
        self
    }

    /// The same series with marker `marker`.
    pub fn with_marker(mut self, marker: Marker) -> Self {
        self.marker = Some(marker);
        self
    }

    /// The same series with line width / marker radius `size`.
    pub fn with_size(mut self, size: u32) -> Self {
        self.size = size;
        self
    }
}

/// Where the legend of a line panel goes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LegendPosition {
    /// The first corner (then the middle of the upper or lower edge) of the plot where the
    /// legend meets no drawn point or line, else outside the plot: on its right, or below it
    /// when a strip on the right would take half the panel (default). Only a legend too large
    /// for either strip is set inside, where it covers the fewest points.
    #[default]
    Auto,
    /// Outside the plot: on its right, or below it when a strip on the right would take half
    /// the panel.
    Outside,
    /// Upper left corner.
    UpperLeft,
    /// Upper right corner.
    UpperRight,
    /// Lower left corner.
    LowerLeft,
    /// Lower right corner.
    LowerRight,
    /// Middle of the upper edge (for data in both upper corners).
    UpperMiddle,
    /// Middle of the lower edge.
    LowerMiddle,
    /// No legend.
    Hidden,
}

/// A panel of lines and markers in `(x, y)`.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct LinePanel {
    /// Caption above the panel.
    pub title: String,
    /// Label of the horizontal axis.
    pub x_label: String,
    /// Label of the vertical axis.
    pub y_label: String,
    /// Logarithmic horizontal axis.
    pub x_log: bool,
    /// Logarithmic vertical axis.
    pub y_log: bool,
    /// Fixed horizontal range (default: the data's, padded).
    pub x_range: Option<(f64, f64)>,
    /// Fixed vertical range (default: the data's, padded).
    pub y_range: Option<(f64, f64)>,
    /// The curves.
    pub series: Vec<Series>,
    /// Dashed grey vertical guide lines at these abscissae.
    pub x_guides: Vec<f64>,
    /// Dashed grey horizontal guide lines at these ordinates.
    pub y_guides: Vec<f64>,
    /// Legend placement.
    pub legend: LegendPosition,
    /// Labels of points (e.g. the lettered points of a paper's figure).
    pub annotations: Vec<Annotation>,
}

/// A text label attached to a point of a line panel. It is drawn beside its point, on a white
/// ground, where it covers neither another label nor the legend; a label set away from its
/// point is tied to it by a leader line.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Annotation {
    /// The point `(x, y)` in the panel's data coordinates.
    pub at: (f64, f64),
    /// The label (e.g. `"b"`).
    pub text: String,
}

impl Annotation {
    /// The label `text` at `(x, y)`.
    pub fn new(at: (f64, f64), text: impl Into<String>) -> Self {
        Self {
            at,
            text: text.into(),
        }
    }
}

impl LinePanel {
    /// An empty panel with a title and axis labels.
    pub fn new(
        title: impl Into<String>,
        x_label: impl Into<String>,
        y_label: impl Into<String>,
    ) -> Self {
        Self {
            title: title.into(),
            x_label: x_label.into(),
            y_label: y_label.into(),
            ..Default::default()
        }
    }
}

/// A colour map of scalar values on a rectilinear grid.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct MapPanel {
    /// Caption above the panel.
    pub title: String,
    /// Label of the horizontal axis.
    pub x_label: String,
    /// Label of the vertical axis.
    pub y_label: String,
    /// Label of the colour bar.
    pub value_label: String,
    /// Abscissae of the grid columns (ascending).
    pub x: Vec<f64>,
    /// Ordinates of the grid rows (ascending).
    pub y: Vec<f64>,
    /// `values[j * x.len() + i]` at `(x[i], y[j])`; non-finite cells are left blank.
    pub values: Vec<f64>,
    /// Colour scale symmetric about zero (blue–white–red) instead of sequential.
    pub diverging: bool,
    /// Curves drawn over the map (e.g. zero level sets), in black unless coloured.
    pub overlay: Vec<Series>,
}

/// One panel of a [`Figure`].
#[derive(Debug, Clone, PartialEq)]
pub enum Panel {
    /// Lines and markers.
    Lines(LinePanel),
    /// A colour map.
    Map(MapPanel),
}

impl From<LinePanel> for Panel {
    fn from(p: LinePanel) -> Self {
        Panel::Lines(p)
    }
}

impl From<MapPanel> for Panel {
    fn from(p: MapPanel) -> Self {
        Panel::Map(p)
    }
}

/// Panels laid out on a grid, row by row.
#[derive(Debug, Clone, PartialEq)]
pub struct Figure {
    /// Title over the whole figure (empty: none).
    pub title: String,
    /// Panels per row (at least 1).
    pub columns: usize,
    /// Size of one panel in pixels.
    pub panel_size: (u32, u32),
    /// The panels.
    pub panels: Vec<Panel>,
}

impl Figure {
    /// A figure of `panels` on `columns` columns, 640 x 440 pixels per panel.
    pub fn new(title: impl Into<String>, columns: usize, panels: Vec<Panel>) -> Self {
        Self {
            title: title.into(),
            columns,
            panel_size: (640, 440),
            panels,
        }
    }
}

/// A scalar field `u(x, t)` of one bar sampled on a space-time grid.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SpaceTimeField {
    /// Positions `x_i` along the bar, in its own coordinate (ascending).
    pub position: Vec<f64>,
    /// Instants `t_k` (ascending).
    pub time: Vec<f64>,
    /// `values[k * position.len() + i] = u(x_i, t_k)`.
    pub values: Vec<f64>,
}

impl SpaceTimeField {
    /// Checks that the grid is non-empty and that there is one value per grid point.
    pub(super) fn check(&self, what: &'static str) -> Result<(), PlotError> {
        let (nx, nt) = (self.position.len(), self.time.len());
        if nx == 0 || nt == 0 {
            return Err(PlotError::InvalidData {
                what,
                reason: format!("empty grid ({nx} positions, {nt} instants)"),
            });
        }
        if self.values.len() != nx * nt {
            return Err(PlotError::InvalidData {
                what,
                reason: format!(
                    "{} values for {nx} positions x {nt} instants",
                    self.values.len()
                ),
            });
        }
        Ok(())
    }

    /// The values `u(x_i, t_k)` at instant `k`.
    pub(super) fn row(&self, k: usize) -> &[f64] {
        let nx = self.position.len();
        &self.values[k * nx..(k + 1) * nx]
    }
}
