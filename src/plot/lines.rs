//! Line panels: linear or logarithmic axes, guide lines, series drawn as lines and markers,
//! the legend and the point labels. The run drawing ([`draw_run`]) also serves the overlays of
//! colour maps.

use super::annotate;
use super::axes::{axis_range, axis_tick, clip_segments, finite_range, log_axis, segments, shown};
use super::canvas::{draw_err, panel_builder, Area, PlotError, FONT};
use super::legend::{
    draw_legend, fixed_box, free_box, least_covered_box, legend_size, Entry, INSET,
};
use super::place::{Drawn, PixelBox};
use super::types::{LegendPosition, LineKind, LinePanel, Marker, Series, PALETTE};
use plotters::coord::ranged1d::{AsRangedCoord, ValueFormatter};
use plotters::coord::CoordTranslate;
use plotters::prelude::*;

/// Draws a line panel on `area`.
pub(super) fn draw_line_panel(area: &Area<'_>, panel: &LinePanel) -> Result<(), PlotError> {
    // The data range of one axis counts the points whose other coordinate can be shown.
    let all = || panel.series.iter().flat_map(|s| s.points.iter());
    let xd = finite_range(
        all().filter(|p| shown(p.1, panel.y_log)).map(|p| p.0),
        panel.x_log,
    );
    let yd = finite_range(
        all().filter(|p| shown(p.0, panel.x_log)).map(|p| p.1),
        panel.y_log,
    );
    let xr = axis_range(panel.x_range, xd, panel.x_log, "horizontal range")?;
    let yr = axis_range(panel.y_range, yd, panel.y_log, "vertical range")?;
    let lines = Lines::of(panel, xr, yr);
    match (panel.x_log, panel.y_log) {
        (false, false) => fill_lines(area, || xr.0..xr.1, || yr.0..yr.1, &lines),
        (true, false) => fill_lines(area, || log_axis(xr), || yr.0..yr.1, &lines),
        (false, true) => fill_lines(area, || xr.0..xr.1, || log_axis(yr), &lines),
        (true, true) => fill_lines(area, || log_axis(xr), || log_axis(yr), &lines),
    }
}

/// A line panel ready to draw: its ranges, and each series' colour and runs of points within
/// the ranges.
struct Lines<'a> {
    panel: &'a LinePanel,
    xr: (f64, f64),
    yr: (f64, f64),
    drawn: Vec<SeriesRuns<'a>>,
}

/// A series, its colour, and its runs of points within the panel's ranges.
struct SeriesRuns<'a> {
    series: &'a Series,
    color: RGBColor,
    runs: Vec<Vec<(f64, f64)>>,
}

impl<'a> Lines<'a> {
    fn of(panel: &'a LinePanel, xr: (f64, f64), yr: (f64, f64)) -> Self {
        let drawn = panel
            .series
            .iter()
            .enumerate()
            .map(|(i, s)| {
                let color = s.color.unwrap_or(PALETTE[i % PALETTE.len()]).color();
                let runs = clip_segments(segments(&s.points, panel.x_log, panel.y_log), xr, yr);
                SeriesRuns {
                    series: s,
                    color,
                    runs,
                }
            })
            .collect();
        Self {
            panel,
            xr,
            yr,
            drawn,
        }
    }

    /// The legend rows: labelled series with something drawn.
    fn entries(&self) -> Vec<Entry<'a>> {
        self.drawn
            .iter()
            .filter(|d| !d.series.label.is_empty() && !d.runs.is_empty())
            .map(|d| Entry {
                series: d.series,
                color: d.color,
            })
            .collect()
    }

    /// What the series draw, in the pixels of `pixel`.
    fn drawn_pixels(&self, pixel: impl Fn(&(f64, f64)) -> (i32, i32)) -> Drawn {
        let mut d = Drawn::default();
        let to = |p: &(f64, f64)| {
            let (x, y) = pixel(p);
            (f64::from(x), f64::from(y))
        };
        for SeriesRuns {
            series: s, runs, ..
        } in &self.drawn
        {
            for run in runs {
                if s.marker.is_some() {
                    let r = f64::from(s.size.max(1));
                    d.points.extend(run.iter().map(|p| (to(p), r)));
                }
                if s.line != LineKind::None {
                    d.segments
                        .extend(run.windows(2).map(|w| (to(&w[0]), to(&w[1]))));
                }
            }
        }
        d
    }
}

/// The plotting rectangle of a chart, in screen pixels.
fn plot_box<DB: DrawingBackend, CT: CoordTranslate>(chart: &ChartContext<'_, DB, CT>) -> PixelBox {
    let (x, y) = chart.plotting_area().get_pixel_range();
    PixelBox {
        x0: f64::from(x.start),
        y0: f64::from(y.start),
        x1: f64::from(x.end),
        y1: f64::from(y.end),
    }
}

/// Builds the chart of axes `x_spec()` and `y_spec()` and draws the mesh, the guides, the
/// series, the legend and the point labels of `lines` on it. An automatic legend that finds
/// no free place in the plot takes a strip on the right of `area`, found on a scratch chart
/// of the same size before the real one is laid out.
fn fill_lines<X, Y>(
    area: &Area<'_>,
    x_spec: impl Fn() -> X,
    y_spec: impl Fn() -> Y,
    lines: &Lines<'_>,
) -> Result<(), PlotError>
where
    X: AsRangedCoord<Value = f64>,
    Y: AsRangedCoord<Value = f64>,
    X::CoordDescType: ValueFormatter<f64>,
    Y::CoordDescType: ValueFormatter<f64>,
{
    let panel = lines.panel;
    let entries = lines.entries();
    let size = legend_size(&entries);
    // An automatic legend's free place, if it has one, found on a scratch chart of the same
    // size: the real chart is built once the legend's place is known.
    let (outside, free) = match panel.legend {
        _ if entries.is_empty() => (false, None),
        LegendPosition::Outside => (true, None),
        LegendPosition::Auto => {
            let free = free_place(area, lines, size, x_spec(), y_spec())?;
            (free.is_none(), free)
        }
        _ => (false, None),
    };
    let side = outside.then(|| strip_side(area, size)).flatten();
    let (chart_area, legend_area) = match side {
        Some(StripSide::Right) => {
            let (w, _) = area.dim_in_pixel();
            let (a, b) = area.split_horizontally(w - strip_width(size));
            (a, Some((b, StripSide::Right)))
        }
        Some(StripSide::Below) => {
            let (_, h) = area.dim_in_pixel();
            let (a, b) = area.split_vertically(h - strip_height(size));
            (a, Some((b, StripSide::Below)))
        }
        None => (area.clone(), None),
    };
    let mut chart = panel_builder(&chart_area, &panel.title, Y_LABEL_AREA)
        .build_cartesian_2d(x_spec(), y_spec())
        .map_err(draw_err)?;
    let (xr, yr) = (lines.xr, lines.yr);
    let xf = |v: &f64| axis_tick(*v, panel.x_log, xr);
    let yf = |v: &f64| axis_tick(*v, panel.y_log, yr);
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
    let guide = RGBColor(120, 120, 120).stroke_width(1);
    let within = |g: f64, (lo, hi): (f64, f64)| g.is_finite() && g >= lo && g <= hi;
    let vertical = panel
        .x_guides
        .iter()
        .filter(|&&g| within(g, xr))
        .map(|&g| [(g, yr.0), (g, yr.1)]);
    let horizontal = panel
        .y_guides
        .iter()
        .filter(|&&g| within(g, yr))
        .map(|&g| [(xr.0, g), (xr.1, g)]);
    for ends in vertical.chain(horizontal) {
        chart
            .draw_series(DashedLineSeries::new(ends, 6, 4, guide))
            .map_err(draw_err)?;
    }
    for d in &lines.drawn {
        for run in &d.runs {
            draw_run(&mut chart, run, d.series, d.color)?;
        }
    }
    let plot = plot_box(&chart);
    let legend_box = match (&legend_area, panel.legend) {
        _ if entries.is_empty() => None,
        (Some((strip, side)), _) => {
            let (x, y) = strip.get_base_pixel();
            let (x, y) = (f64::from(x), f64::from(y));
            Some(match side {
                StripSide::Right => PixelBox::at(x + INSET, plot.y0.max(y), size.0, size.1),
                StripSide::Below => PixelBox::at(plot.x0, y + 0.5 * INSET, size.0, size.1),
            })
        }
        // The chart fills `area` here, as the scratch chart did: its free place holds.
        (None, LegendPosition::Auto | LegendPosition::Outside) => free.or_else(|| {
            let drawn = lines.drawn_pixels(|p| chart.backend_coord(p));
            least_covered_box(&plot, size, &drawn)
        }),
        (None, position) => fixed_box(position, &plot, size),
    };
    let mut taken: Vec<PixelBox> = legend_box.iter().cloned().collect();
    let placed = annotate::place(
        &panel.annotations,
        |p| {
            let shown_here = shown(p.0, panel.x_log)
                && shown(p.1, panel.y_log)
                && within(p.0, xr)
                && within(p.1, yr);
            shown_here.then(|| {
                let (x, y) = chart.backend_coord(&p);
                (f64::from(x), f64::from(y))
            })
        },
        &plot,
        &mut taken,
    );
    annotate::draw(area, &placed)?;
    if let Some(b) = legend_box {
        draw_legend(area, &b, &entries)?;
    }
    Ok(())
}

/// Which side of a panel a legend strip takes when the legend has no free place in the plot.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum StripSide {
    Right,
    Below,
}

/// Width of a strip on the right holding a legend of `size`.
fn strip_width(size: (f64, f64)) -> u32 {
    (size.0 + 2.0 * INSET).ceil() as u32
}

/// The least height, in pixels, a legend strip below a plot leaves it.
const MIN_PLOT_HEIGHT: u32 = 240;

/// Height of a strip below the plot holding a legend of `size`.
fn strip_height(size: (f64, f64)) -> u32 {
    (size.1 + INSET).ceil() as u32
}

/// The side of `area` a legend strip of `size` takes: the right if it leaves the plot at
/// least half the width, else below if it leaves at least half the height and
/// [`MIN_PLOT_HEIGHT`] (a shorter plot beats a legend over its data, down to a height that
/// still reads); `None` if neither.
fn strip_side(area: &Area<'_>, size: (f64, f64)) -> Option<StripSide> {
    let (w, h) = area.dim_in_pixel();
    if strip_width(size) < w / 2 {
        Some(StripSide::Right)
    } else if strip_height(size) < h / 2 && h - strip_height(size) >= MIN_PLOT_HEIGHT {
        Some(StripSide::Below)
    } else {
        None
    }
}

/// The free place in screen pixels ([`free_box`]) of a legend of `size` in the plot of
/// `lines` laid out on the whole of `area`, found on a scratch chart of the same size.
fn free_place<X, Y>(
    area: &Area<'_>,
    lines: &Lines<'_>,
    size: (f64, f64),
    x_spec: X,
    y_spec: Y,
) -> Result<Option<PixelBox>, PlotError>
where
    X: AsRangedCoord<Value = f64>,
    Y: AsRangedCoord<Value = f64>,
{
    let mut scratch = String::new();
    let root = SVGBackend::with_string(&mut scratch, area.dim_in_pixel()).into_drawing_area();
    let chart = panel_builder(&root, &lines.panel.title, Y_LABEL_AREA)
        .build_cartesian_2d(x_spec, y_spec)
        .map_err(draw_err)?;
    let base = area.get_base_pixel();
    let drawn = lines.drawn_pixels(|p| {
        let (x, y) = chart.backend_coord(p);
        (x + base.0, y + base.1)
    });
    let plot = plot_box(&chart);
    let (dx, dy) = (f64::from(base.0), f64::from(base.1));
    let plot = PixelBox {
        x0: plot.x0 + dx,
        y0: plot.y0 + dy,
        x1: plot.x1 + dx,
        y1: plot.y1 + dy,
    };
    Ok(free_box(&plot, size, &drawn))
}

/// Width of the label area left of a line panel's vertical axis, in pixels.
const Y_LABEL_AREA: u32 = 78;

/// Draws one run of points of `s` in `color`: its line (if any), then its markers (if any).
pub(super) fn draw_run<'a, DB, CT>(
    chart: &mut ChartContext<'a, DB, CT>,
    run: &[(f64, f64)],
    s: &Series,
    color: RGBColor,
) -> Result<(), PlotError>
where
    DB: DrawingBackend + 'a,
    CT: CoordTranslate<From = (f64, f64)>,
{
    let stroke = color.stroke_width(s.size.max(1));
    let points = run.iter().cloned();
    match s.line {
        LineKind::None => {}
        LineKind::Solid => {
            chart
                .draw_series(LineSeries::new(points, stroke))
                .map_err(draw_err)?;
        }
        LineKind::Dashed => {
            chart
                .draw_series(DashedLineSeries::new(points, 8, 5, stroke))
                .map_err(draw_err)?;
        }
    }
    if let Some(m) = s.marker {
        draw_markers(chart, run, m, s.size.max(1) as i32, color)?;
    }
    Ok(())
}

/// Draws marker `m` of radius `r` at every point of `run`.
fn draw_markers<'b, DB, CT>(
    chart: &mut ChartContext<'b, DB, CT>,
    run: &[(f64, f64)],
    m: Marker,
    r: i32,
    color: RGBColor,
) -> Result<(), PlotError>
where
    DB: DrawingBackend + 'b,
    CT: CoordTranslate<From = (f64, f64)>,
{
    let fill = color.filled();
    let stroke = color.stroke_width(1);
    let pts = run.iter().cloned();
    match m {
        Marker::Circle => chart.draw_series(pts.map(|p| Circle::new(p, r, fill))),
        Marker::Ring => chart.draw_series(pts.map(|p| Circle::new(p, r, stroke))),
        Marker::Square => chart.draw_series(
            pts.map(|p| EmptyElement::at(p) + Rectangle::new([(-r, -r), (r, r)], fill)),
        ),
        Marker::Triangle => chart.draw_series(pts.map(|p| TriangleMarker::new(p, r + 1, fill))),
        Marker::Cross => chart.draw_series(pts.map(|p| Cross::new(p, r, color.stroke_width(2)))),
    }
    .map_err(draw_err)?;
    Ok(())
}
