//! SVG plots from plain data (feature `plot`).
//!
//! Plotting knows nothing about bars or solvers: it draws [`Series`](crate::plot::Series) of `(x, y)` points,
//! space-time maps of a field ([`SpaceTimeField`](crate::plot::SpaceTimeField)) and displacement snapshots of bars, laid out
//! as [`Panel`](crate::plot::Panel)s of a [`Figure`](crate::plot::Figure). The figure is written as an SVG file by [`render_svg`](crate::plot::render_svg); the
//! one-panel helpers [`plot_backbone`](crate::plot::plot_backbone), [`plot_space_time`](crate::plot::plot_space_time), [`plot_snapshots`](crate::plot::plot_snapshots),
//! [`plot_histories`](crate::plot::plot_histories) and [`plot_xy`](crate::plot::plot_xy) cover the usual cases, and the `*_panel` builders let a
//! caller compose several views in one figure.
//!
//! The backend is `plotters`' SVG backend without font rendering: text is emitted as SVG
//! `<text>` elements and laid out with an estimated glyph width, so nothing beyond the crate
//! itself is needed to build.
//!
//! Non-finite values break lines (a `NaN` between two points leaves a gap), and points that a
//! logarithmic axis cannot show (`<= 0`) are skipped. Every failure is a [`PlotError`](crate::plot::PlotError).
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

use plotters::chart::SeriesAnno;
use plotters::coord::combinators::{LogCoord, WithKeyPoints};
use plotters::coord::ranged1d::ValueFormatter;
use plotters::coord::CoordTranslate;
use plotters::prelude::*;
use std::path::Path;
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

fn draw_err<E: std::fmt::Display>(e: E) -> PlotError {
    PlotError::Draw(e.to_string())
}

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

    fn color(self) -> RGBColor {
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
    /// Upper left corner (default).
    #[default]
    UpperLeft,
    /// Upper right corner.
    UpperRight,
    /// Lower left corner.
    LowerLeft,
    /// Lower right corner.
    LowerRight,
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
    fn check(&self, what: &'static str) -> Result<(), PlotError> {
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

    fn row(&self, k: usize) -> &[f64] {
        let nx = self.position.len();
        &self.values[k * nx..(k + 1) * nx]
    }
}

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

fn finite_range<I: Iterator<Item = f64>>(values: I, log: bool) -> Option<(f64, f64)> {
    let mut lo = f64::INFINITY;
    let mut hi = f64::NEG_INFINITY;
    for v in values {
        if v.is_finite() && (!log || v > 0.0) {
            lo = lo.min(v);
            hi = hi.max(v);
        }
    }
    (lo <= hi).then_some((lo, hi))
}

/// Padded range for an axis: 4% either side (a factor on a log axis), widened if degenerate.
fn padded((lo, hi): (f64, f64), log: bool) -> (f64, f64) {
    if log {
        let (l, h) = (lo.log10(), hi.log10());
        let pad = if h - l < 1e-9 { 0.5 } else { 0.04 * (h - l) };
        (10f64.powf(l - pad), 10f64.powf(h + pad))
    } else {
        let span = hi - lo;
        let pad = if span <= 1e-300 * lo.abs().max(1.0) || span == 0.0 {
            if lo == 0.0 {
                1.0
            } else {
                0.1 * lo.abs()
            }
        } else {
            0.04 * span
        };
        (lo - pad, hi + pad)
    }
}

fn axis_range(
    fixed: Option<(f64, f64)>,
    data: Option<(f64, f64)>,
    log: bool,
    what: &'static str,
) -> Result<(f64, f64), PlotError> {
    if let Some((lo, hi)) = fixed {
        let ok = lo.is_finite() && hi.is_finite() && lo < hi && (!log || lo > 0.0);
        if !ok {
            return Err(PlotError::InvalidData {
                what,
                reason: format!("bad fixed range [{lo}, {hi}] (log axis: {log})"),
            });
        }
        return Ok((lo, hi));
    }
    Ok(match data {
        Some(r) => padded(r, log),
        None if log => (1.0, 10.0),
        None => (0.0, 1.0),
    })
}

/// Short tick label: plain for moderate magnitudes, scientific otherwise.
fn tick(v: f64) -> String {
    let a = v.abs();
    if a == 0.0 {
        "0".into()
    } else if !(1e-3..1e4).contains(&a) {
        let s = format!("{v:.1e}");
        s.replace(".0e", "e")
    } else {
        let s = format!("{v:.4}");
        let s = s.trim_end_matches('0').trim_end_matches('.');
        s.to_string()
    }
}

fn log_tick(v: f64) -> String {
    let e = v.log10();
    if (e - e.round()).abs() < 1e-6 {
        let e = e.round() as i32;
        if (-2..=3).contains(&e) {
            tick(10f64.powi(e))
        } else {
            format!("1e{e}")
        }
    } else {
        tick(v)
    }
}

/// Splits a series into runs of points the axes can show.
fn segments(points: &[(f64, f64)], x_log: bool, y_log: bool) -> Vec<Vec<(f64, f64)>> {
    let mut out = Vec::new();
    let mut run = Vec::new();
    for &(x, y) in points {
        let ok = x.is_finite() && y.is_finite() && (!x_log || x > 0.0) && (!y_log || y > 0.0);
        if ok {
            run.push((x, y));
        } else if !run.is_empty() {
            out.push(std::mem::take(&mut run));
        }
    }
    if !run.is_empty() {
        out.push(run);
    }
    out
}

/// Clips `(x, y)` runs to a rectangle in the axes' own (log or linear) measure, so that
/// curves extending outside a fixed range do not spill over the frame.
fn clip_segments(
    runs: Vec<Vec<(f64, f64)>>,
    xr: (f64, f64),
    yr: (f64, f64),
) -> Vec<Vec<(f64, f64)>> {
    let inside = |&(x, y): &(f64, f64)| x >= xr.0 && x <= xr.1 && y >= yr.0 && y <= yr.1;
    let mut out = Vec::new();
    for run in runs {
        let mut cur: Vec<(f64, f64)> = Vec::new();
        for (i, p) in run.iter().enumerate() {
            let keep = inside(p)
                || (i > 0 && inside(&run[i - 1]))
                || (i + 1 < run.len() && inside(&run[i + 1]));
            if keep {
                cur.push(*p);
            } else if !cur.is_empty() {
                out.push(std::mem::take(&mut cur));
            }
        }
        if !cur.is_empty() {
            out.push(cur);
        }
    }
    out
}

/// Bold (labelled) and light tick values of a logarithmic axis on `[lo, hi]`: every
/// integer mantissa within about a decade, 1-2-5 up to three decades, decades beyond (every
/// other decade past eight).
fn log_ticks(lo: f64, hi: f64) -> (Vec<f64>, Vec<f64>) {
    let decades = (hi / lo).log10();
    let bold_mantissas: &[f64] = if decades < 1.2 {
        &[1.0, 1.5, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0]
    } else if decades < 3.0 {
        &[1.0, 2.0, 5.0]
    } else {
        &[1.0]
    };
    let every = if decades > 8.0 { 2 } else { 1 };
    let (e0, e1) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
    let (mut bold, mut light) = (Vec::new(), Vec::new());
    for e in e0..=e1 {
        let base = 10f64.powi(e);
        for k in 1..10 {
            let v = base * k as f64;
            if v >= lo && v <= hi && decades < 8.0 {
                light.push(v);
            }
        }
        if e.rem_euclid(every) == 0 {
            for &m in bold_mantissas {
                let v = base * m;
                if v >= lo * (1.0 - 1e-12) && v <= hi * (1.0 + 1e-12) {
                    bold.push(v);
                }
            }
        }
    }
    (bold, light)
}

fn log_axis((lo, hi): (f64, f64)) -> WithKeyPoints<LogCoord<f64>> {
    let (bold, light) = log_ticks(lo, hi);
    (lo..hi)
        .log_scale()
        .with_key_points(bold)
        .with_light_points(light)
}

type Area<'a> = DrawingArea<SVGBackend<'a>, plotters::coord::Shift>;

const FONT: &str = "sans-serif";

fn draw_line_panel(area: &Area<'_>, panel: &LinePanel) -> Result<(), PlotError> {
    let all = || panel.series.iter().flat_map(|s| s.points.iter());
    let xd = finite_range(
        all()
            .filter(|p| p.1.is_finite() && (!panel.y_log || p.1 > 0.0))
            .map(|p| p.0),
        panel.x_log,
    );
    let yd = finite_range(
        all()
            .filter(|p| p.0.is_finite() && (!panel.x_log || p.0 > 0.0))
            .map(|p| p.1),
        panel.y_log,
    );
    let xr = axis_range(panel.x_range, xd, panel.x_log, "horizontal range")?;
    let yr = axis_range(panel.y_range, yd, panel.y_log, "vertical range")?;
    let mut builder = ChartBuilder::on(area);
    builder
        .margin(12)
        .x_label_area_size(46)
        .y_label_area_size(78);
    if !panel.title.is_empty() {
        builder.caption(&panel.title, (FONT, 20));
    }
    match (panel.x_log, panel.y_log) {
        (false, false) => fill_lines(
            builder
                .build_cartesian_2d(xr.0..xr.1, yr.0..yr.1)
                .map_err(draw_err)?,
            panel,
            xr,
            yr,
        ),
        (true, false) => fill_lines(
            builder
                .build_cartesian_2d(log_axis(xr), yr.0..yr.1)
                .map_err(draw_err)?,
            panel,
            xr,
            yr,
        ),
        (false, true) => fill_lines(
            builder
                .build_cartesian_2d(xr.0..xr.1, log_axis(yr))
                .map_err(draw_err)?,
            panel,
            xr,
            yr,
        ),
        (true, true) => fill_lines(
            builder
                .build_cartesian_2d(log_axis(xr), log_axis(yr))
                .map_err(draw_err)?,
            panel,
            xr,
            yr,
        ),
    }
}

fn fill_lines<'a, 'b: 'a, X, Y>(
    mut chart: ChartContext<'a, SVGBackend<'b>, Cartesian2d<X, Y>>,
    panel: &LinePanel,
    xr: (f64, f64),
    yr: (f64, f64),
) -> Result<(), PlotError>
where
    X: Ranged<ValueType = f64> + ValueFormatter<f64>,
    Y: Ranged<ValueType = f64> + ValueFormatter<f64>,
{
    // On linear axes, a tick within rounding of zero is zero (not `-1.4e-17`).
    let snap = |v: f64, (lo, hi): (f64, f64)| if v.abs() < 1e-9 * (hi - lo) { 0.0 } else { v };
    let xf = |v: &f64| {
        if panel.x_log {
            log_tick(*v)
        } else {
            tick(snap(*v, xr))
        }
    };
    let yf = |v: &f64| {
        if panel.y_log {
            log_tick(*v)
        } else {
            tick(snap(*v, yr))
        }
    };
    chart
        .configure_mesh()
        .x_desc(panel.x_label.as_str())
        .y_desc(panel.y_label.as_str())
        .x_labels(8)
        .y_labels(8)
        .x_label_formatter(&xf)
        .y_label_formatter(&yf)
        .label_style((FONT, 14))
        .axis_desc_style((FONT, 16))
        .light_line_style(RGBColor(238, 238, 238))
        .bold_line_style(RGBColor(215, 215, 215))
        .draw()
        .map_err(draw_err)?;
    let guide = ShapeStyle {
        color: RGBColor(120, 120, 120).to_rgba(),
        filled: false,
        stroke_width: 1,
    };
    for &g in &panel.x_guides {
        if g.is_finite() && g >= xr.0 && g <= xr.1 {
            chart
                .draw_series(DashedLineSeries::new(
                    vec![(g, yr.0), (g, yr.1)],
                    6,
                    4,
                    guide,
                ))
                .map_err(draw_err)?;
        }
    }
    for &g in &panel.y_guides {
        if g.is_finite() && g >= yr.0 && g <= yr.1 {
            chart
                .draw_series(DashedLineSeries::new(
                    vec![(xr.0, g), (xr.1, g)],
                    6,
                    4,
                    guide,
                ))
                .map_err(draw_err)?;
        }
    }
    let mut any_label = false;
    for (i, s) in panel.series.iter().enumerate() {
        let color = s.color.unwrap_or(PALETTE[i % PALETTE.len()]).color();
        let width = s.size.max(1);
        let stroke = ShapeStyle {
            color: color.to_rgba(),
            filled: false,
            stroke_width: width,
        };
        let runs = clip_segments(segments(&s.points, panel.x_log, panel.y_log), xr, yr);
        let mut legend_drawn = false;
        for run in &runs {
            match s.line {
                LineKind::None => {}
                LineKind::Solid => {
                    let anno = chart
                        .draw_series(LineSeries::new(run.iter().cloned(), stroke))
                        .map_err(draw_err)?;
                    if !s.label.is_empty() && !legend_drawn {
                        set_legend(anno, s, color);
                        legend_drawn = true;
                    }
                }
                LineKind::Dashed => {
                    let anno = chart
                        .draw_series(DashedLineSeries::new(run.iter().cloned(), 8, 5, stroke))
                        .map_err(draw_err)?;
                    if !s.label.is_empty() && !legend_drawn {
                        set_legend(anno, s, color);
                        legend_drawn = true;
                    }
                }
            }
            if let Some(m) = s.marker {
                let anno = draw_markers(&mut chart, run, m, s.size.max(1) as i32, color)?;
                if !s.label.is_empty() && !legend_drawn {
                    set_legend(anno, s, color);
                    legend_drawn = true;
                }
            }
        }
        any_label |= legend_drawn;
    }
    let position = match panel.legend {
        LegendPosition::Hidden => None,
        LegendPosition::UpperLeft => Some(SeriesLabelPosition::UpperLeft),
        LegendPosition::UpperRight => Some(SeriesLabelPosition::UpperRight),
        LegendPosition::LowerLeft => Some(SeriesLabelPosition::LowerLeft),
        LegendPosition::LowerRight => Some(SeriesLabelPosition::LowerRight),
    };
    if let (true, Some(position)) = (any_label, position) {
        chart
            .configure_series_labels()
            .position(position)
            .label_font((FONT, 14))
            .background_style(WHITE.mix(0.85))
            .border_style(RGBColor(160, 160, 160))
            .draw()
            .map_err(draw_err)?;
    }
    Ok(())
}

fn set_legend<'a, DB: DrawingBackend + 'a>(
    anno: &mut SeriesAnno<'a, DB>,
    s: &Series,
    color: RGBColor,
) {
    anno.label(s.label.as_str());
    let stroke = ShapeStyle {
        color: color.to_rgba(),
        filled: false,
        stroke_width: 2,
    };
    match (s.line, s.marker) {
        (LineKind::None, Some(m)) => {
            let fill = color.filled();
            match m {
                Marker::Circle => anno.legend(move |(x, y)| Circle::new((x + 10, y), 4, fill)),
                Marker::Ring => anno.legend(move |(x, y)| Circle::new((x + 10, y), 4, stroke)),
                Marker::Square => anno
                    .legend(move |(x, y)| Rectangle::new([(x + 6, y - 4), (x + 14, y + 4)], fill)),
                Marker::Triangle => {
                    anno.legend(move |(x, y)| TriangleMarker::new((x + 10, y), 5, fill))
                }
                Marker::Cross => anno.legend(move |(x, y)| Cross::new((x + 10, y), 4, stroke)),
            };
        }
        (LineKind::Dashed, _) => {
            anno.legend(move |(x, y)| {
                EmptyElement::at((x, y))
                    + PathElement::new(vec![(0, 0), (5, 0)], stroke)
                    + PathElement::new(vec![(8, 0), (13, 0)], stroke)
                    + PathElement::new(vec![(16, 0), (21, 0)], stroke)
            });
        }
        _ => {
            anno.legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 22, y)], stroke));
        }
    }
}

fn draw_markers<'c, 'b, DB, CT>(
    chart: &'c mut ChartContext<'b, DB, CT>,
    run: &[(f64, f64)],
    m: Marker,
    r: i32,
    color: RGBColor,
) -> Result<&'c mut SeriesAnno<'b, DB>, PlotError>
where
    DB: DrawingBackend + 'b,
    CT: CoordTranslate<From = (f64, f64)>,
{
    let fill = color.filled();
    let stroke = ShapeStyle {
        color: color.to_rgba(),
        filled: false,
        stroke_width: 1,
    };
    let pts = run.iter().cloned();
    match m {
        Marker::Circle => chart.draw_series(pts.map(|p| Circle::new(p, r, fill))),
        Marker::Ring => chart.draw_series(pts.map(|p| Circle::new(p, r, stroke))),
        Marker::Square => chart.draw_series(
            pts.map(|p| EmptyElement::at(p) + Rectangle::new([(-r, -r), (r, r)], fill)),
        ),
        Marker::Triangle => chart.draw_series(pts.map(|p| TriangleMarker::new(p, r + 1, fill))),
        Marker::Cross => chart.draw_series(pts.map(|p| Cross::new(p, r, stroke.stroke_width(2)))),
    }
    .map_err(draw_err)
}

/// Colour of a normalised value: diverging blue–white–red on `s in [-1, 1]`, or a sequential
/// dark-blue–teal–yellow scale on `s in [0, 1]`.
fn colormap(s: f64, diverging: bool) -> Rgb {
    if diverging {
        let (blue, white, red) = (Rgb(40, 70, 170), Rgb(250, 250, 250), Rgb(180, 25, 30));
        if s < 0.0 {
            white.mix(blue, -s)
        } else {
            white.mix(red, s)
        }
    } else {
        let stops = [
            Rgb(50, 20, 90),
            Rgb(40, 100, 150),
            Rgb(30, 160, 130),
            Rgb(150, 205, 60),
            Rgb(250, 230, 40),
        ];
        let s = s.clamp(0.0, 1.0) * (stops.len() - 1) as f64;
        let i = (s.floor() as usize).min(stops.len() - 2);
        stops[i].mix(stops[i + 1], s - i as f64)
    }
}

/// Cell edges of a grid of centres (midpoints, extrapolated at both ends).
fn edges(c: &[f64]) -> Vec<f64> {
    let n = c.len();
    if n == 1 {
        return vec![c[0] - 0.5, c[0] + 0.5];
    }
    let mut e = Vec::with_capacity(n + 1);
    e.push(c[0] - 0.5 * (c[1] - c[0]));
    for i in 0..n - 1 {
        e.push(0.5 * (c[i] + c[i + 1]));
    }
    e.push(c[n - 1] + 0.5 * (c[n - 1] - c[n - 2]));
    e
}

fn draw_map_panel(area: &Area<'_>, panel: &MapPanel) -> Result<(), PlotError> {
    let (nx, ny) = (panel.x.len(), panel.y.len());
    if nx == 0 || ny == 0 || panel.values.len() != nx * ny {
        return Err(PlotError::InvalidData {
            what: "map values",
            reason: format!(
                "{} values for a {nx} x {ny} grid (both must be non-empty)",
                panel.values.len()
            ),
        });
    }
    for (what, axis) in [("map abscissae", &panel.x), ("map ordinates", &panel.y)] {
        let ok = axis.iter().all(|v| v.is_finite()) && axis.windows(2).all(|w| w[0] < w[1]);
        if !ok {
            return Err(PlotError::InvalidData {
                what,
                reason: "must be finite and strictly ascending".into(),
            });
        }
    }
    let (ex, ey) = (edges(&panel.x), edges(&panel.y));
    let (vlo, vhi) = finite_range(panel.values.iter().cloned(), false).unwrap_or((0.0, 1.0));
    let (vlo, vhi) = if panel.diverging {
        let a = vlo.abs().max(vhi.abs()).max(1e-300);
        (-a, a)
    } else if vhi > vlo {
        (vlo, vhi)
    } else {
        padded((vlo, vhi), false)
    };
    let normalise = |v: f64| {
        if panel.diverging {
            v / vhi
        } else {
            (v - vlo) / (vhi - vlo)
        }
    };
    let (w, _) = area.dim_in_pixel();
    let (main, bar) = area.split_horizontally(w.saturating_sub(110).max(1));
    let mut builder = ChartBuilder::on(&main);
    builder
        .margin(12)
        .x_label_area_size(46)
        .y_label_area_size(70);
    if !panel.title.is_empty() {
        builder.caption(&panel.title, (FONT, 20));
    }
    let (xr, yr) = ((ex[0], ex[nx]), (ey[0], ey[ny]));
    let mut chart = builder
        .build_cartesian_2d(xr.0..xr.1, yr.0..yr.1)
        .map_err(draw_err)?;
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc(panel.x_label.as_str())
        .y_desc(panel.y_label.as_str())
        .x_labels(8)
        .y_labels(8)
        .x_label_formatter(&|v| tick(*v))
        .y_label_formatter(&|v| tick(*v))
        .label_style((FONT, 14))
        .axis_desc_style((FONT, 16))
        .draw()
        .map_err(draw_err)?;
    let cells = (0..ny).flat_map(|j| (0..nx).map(move |i| (i, j)));
    chart
        .draw_series(cells.filter_map(|(i, j)| {
            let v = panel.values[j * nx + i];
            v.is_finite().then(|| {
                // Overlap the next cells a little (they are drawn later) so that
                // anti-aliasing leaves no seams.
                let x1 = if i + 1 < nx {
                    ex[i + 1] + 0.2 * (ex[i + 2] - ex[i + 1])
                } else {
                    ex[i + 1]
                };
                let y1 = if j + 1 < ny {
                    ey[j + 1] + 0.2 * (ey[j + 2] - ey[j + 1])
                } else {
                    ey[j + 1]
                };
                Rectangle::new(
                    [(ex[i], ey[j]), (x1, y1)],
                    colormap(normalise(v), panel.diverging).color().filled(),
                )
            })
        }))
        .map_err(draw_err)?;
    for (i, s) in panel.overlay.iter().enumerate() {
        let color = s
            .color
            .unwrap_or(if i == 0 { Rgb::BLACK } else { PALETTE[i] });
        let stroke = ShapeStyle {
            color: color.color().to_rgba(),
            filled: false,
            stroke_width: s.size.max(1),
        };
        for run in clip_segments(segments(&s.points, false, false), xr, yr) {
            match s.line {
                LineKind::Dashed => {
                    chart
                        .draw_series(DashedLineSeries::new(run.iter().cloned(), 8, 5, stroke))
                        .map_err(draw_err)?;
                }
                LineKind::Solid => {
                    chart
                        .draw_series(LineSeries::new(run.iter().cloned(), stroke))
                        .map_err(draw_err)?;
                }
                LineKind::None => {}
            }
            if let Some(m) = s.marker {
                draw_markers(&mut chart, &run, m, s.size.max(1) as i32, color.color())?;
            }
        }
    }
    // Colour bar.
    let mut cb = ChartBuilder::on(&bar);
    cb.margin_top(if panel.title.is_empty() { 12 } else { 14 })
        .margin_bottom(58)
        .margin_right(8)
        .y_label_area_size(0)
        .right_y_label_area_size(64)
        .caption(panel.value_label.as_str(), (FONT, 15));
    let mut cbar = cb
        .build_cartesian_2d(0.0..1.0, vlo..vhi)
        .map_err(draw_err)?
        .set_secondary_coord(0.0..1.0, vlo..vhi);
    cbar.configure_mesh()
        .disable_mesh()
        .disable_x_axis()
        .disable_y_axis()
        .draw()
        .map_err(draw_err)?;
    cbar.configure_secondary_axes()
        .y_labels(6)
        .y_label_formatter(&|v| tick(*v))
        .label_style((FONT, 12))
        .axis_desc_style((FONT, 14))
        .draw()
        .map_err(draw_err)?;
    let strips = 64;
    cbar.draw_series((0..strips).map(|k| {
        let a = vlo + (vhi - vlo) * k as f64 / strips as f64;
        let b = vlo + (vhi - vlo) * (k as f64 + 1.3).min(strips as f64) / strips as f64;
        Rectangle::new(
            [(0.0, a), (1.0, b)],
            colormap(normalise(0.5 * (a + b)), panel.diverging)
                .color()
                .filled(),
        )
    }))
    .map_err(draw_err)?;
    Ok(())
}

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
    let root = SVGBackend::new(path.as_ref(), size).into_drawing_area();
    root.fill(&WHITE).map_err(draw_err)?;
    let body = if figure.title.is_empty() {
        root.clone()
    } else {
        root.titled(&figure.title, (FONT, 24)).map_err(draw_err)?
    };
    let areas = body.split_evenly((rows, columns));
    for (panel, area) in figure.panels.iter().zip(&areas) {
        match panel {
            Panel::Lines(p) => draw_line_panel(area, p)?,
            Panel::Map(p) => draw_map_panel(area, p)?,
        }
    }
    root.present().map_err(draw_err)?;
    Ok(())
}

/// Axis label of normalised frequencies.
pub const FREQUENCY_LABEL: &str = "Omega / omega_1";
/// Axis label of normalised energies.
pub const ENERGY_LABEL: &str = "E / E_g";

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
            Series::line("exact 8/(pi^2 (T-3)^2)", e.to_vec())
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

/// Snapshots of the displacement of one or more bars at `instants` instants evenly picked
/// from their time grids, in a common frame: bar positions along the horizontal axis (a
/// mirrored bar faces the other, as the paper's Fig. 3), displacements vertically (a mirrored
/// bar's drawn as `-u`, i.e. in the common frame's direction), one colour per instant shading
/// from blue (`t = 0`) to red (last instant), and dashed guides at `guides` (e.g. the contact
/// interface).
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
    let (early, late) = (Rgb(30, 90, 200), Rgb(210, 30, 40));
    for s in 0..instants {
        let color = early.mix(late, s as f64 / (instants.max(2) - 1) as f64);
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
            "displacement ({}: solid, dashed; mirrored as -u)",
            names.join(", ")
        )
    } else {
        "displacement u".to_string()
    };
    Ok(LinePanel {
        series,
        x_guides: guides.to_vec(),
        legend: if instants <= 8 {
            LegendPosition::UpperLeft
        } else {
            LegendPosition::Hidden
        },
        ..LinePanel::new(title, "position", y_label)
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
        legend: LegendPosition::UpperRight,
        ..LinePanel::new(title, "t", "")
    })
}

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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn segments_break_at_nan_and_nonpositive_on_log_axes() {
        let p = [
            (1.0, 1.0),
            (2.0, f64::NAN),
            (3.0, 3.0),
            (4.0, -1.0),
            (5.0, 5.0),
        ];
        assert_eq!(segments(&p, false, false).len(), 2);
        assert_eq!(segments(&p, false, true).len(), 3);
        assert_eq!(segments(&[(0.0, 1.0), (1.0, 1.0)], true, false)[0].len(), 1);
    }

    #[test]
    fn ranges_are_padded_and_never_degenerate() {
        let (a, b) = axis_range(None, Some((2.0, 2.0)), false, "x").unwrap();
        assert!(a < 2.0 && b > 2.0);
        let (a, b) = axis_range(None, Some((1.0, 100.0)), true, "y").unwrap();
        assert!(a > 0.0 && a < 1.0 && b > 100.0);
        assert!(axis_range(Some((1.0, 0.0)), None, false, "x").is_err());
        assert!(axis_range(Some((0.0, 1.0)), None, true, "x").is_err());
        assert_eq!(axis_range(None, None, true, "y").unwrap(), (1.0, 10.0));
    }

    #[test]
    fn ticks_are_short() {
        assert_eq!(tick(0.5), "0.5");
        assert_eq!(tick(1.0), "1");
        assert_eq!(tick(1e-5), "1e-5");
        assert_eq!(log_tick(1000.0), "1000");
        assert_eq!(log_tick(1e-6), "1e-6");
    }

    #[test]
    fn colormap_ends() {
        assert_eq!(colormap(0.0, true), Rgb(250, 250, 250));
        assert_eq!(colormap(1.0, true), Rgb(180, 25, 30));
        assert_eq!(colormap(-1.0, true), Rgb(40, 70, 170));
        assert_eq!(colormap(1.0, false), Rgb(250, 230, 40));
    }
}
