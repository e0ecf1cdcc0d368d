//! Line panels: linear or logarithmic axes, guide lines, series drawn as lines and markers,
//! and the legend. The run drawing ([`draw_run`]) also serves the overlays of colour maps.

use super::axes::{axis_range, axis_tick, clip_segments, finite_range, log_axis, segments, shown};
use super::types::{LegendPosition, LineKind, LinePanel, Marker, Series, PALETTE};
use super::{draw_err, panel_builder, Area, PlotError, FONT};
use plotters::chart::SeriesAnno;
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
    let b = &mut panel_builder(area, &panel.title, 78);
    match (panel.x_log, panel.y_log) {
        (false, false) => fill_lines(b, xr.0..xr.1, yr.0..yr.1, panel, xr, yr),
        (true, false) => fill_lines(b, log_axis(xr), yr.0..yr.1, panel, xr, yr),
        (false, true) => fill_lines(b, xr.0..xr.1, log_axis(yr), panel, xr, yr),
        (true, true) => fill_lines(b, log_axis(xr), log_axis(yr), panel, xr, yr),
    }
}

/// Builds the chart of axes `x_spec` and `y_spec` (of ranges `xr` and `yr`) and draws the
/// mesh, the guides, the series and the legend of `panel` on it.
fn fill_lines<X, Y>(
    builder: &mut ChartBuilder<'_, '_, SVGBackend<'_>>,
    x_spec: X,
    y_spec: Y,
    panel: &LinePanel,
    xr: (f64, f64),
    yr: (f64, f64),
) -> Result<(), PlotError>
where
    X: AsRangedCoord<Value = f64>,
    Y: AsRangedCoord<Value = f64>,
    X::CoordDescType: ValueFormatter<f64>,
    Y::CoordDescType: ValueFormatter<f64>,
{
    let mut chart = builder
        .build_cartesian_2d(x_spec, y_spec)
        .map_err(draw_err)?;
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
    let mut any_label = false;
    for (i, s) in panel.series.iter().enumerate() {
        let color = s.color.unwrap_or(PALETTE[i % PALETTE.len()]).color();
        let mut legend_drawn = false;
        for run in clip_segments(segments(&s.points, panel.x_log, panel.y_log), xr, yr) {
            let legend = !s.label.is_empty() && !legend_drawn;
            legend_drawn |= draw_run(&mut chart, &run, s, color, legend)?;
        }
        any_label |= legend_drawn;
    }
    let position = match panel.legend {
        LegendPosition::Hidden => None,
        LegendPosition::UpperLeft => Some(SeriesLabelPosition::UpperLeft),
        LegendPosition::UpperRight => Some(SeriesLabelPosition::UpperRight),
        LegendPosition::LowerLeft => Some(SeriesLabelPosition::LowerLeft),
        LegendPosition::LowerRight => Some(SeriesLabelPosition::LowerRight),
        LegendPosition::UpperMiddle => Some(SeriesLabelPosition::UpperMiddle),
        LegendPosition::LowerMiddle => Some(SeriesLabelPosition::LowerMiddle),
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

/// Draws one run of points of `s` in `color`: its line (if any), then its markers (if any).
/// With `legend`, the first of them drawn carries the legend entry of `s`; returns whether
/// one did.
pub(super) fn draw_run<'a, DB, CT>(
    chart: &mut ChartContext<'a, DB, CT>,
    run: &[(f64, f64)],
    s: &Series,
    color: RGBColor,
    legend: bool,
) -> Result<bool, PlotError>
where
    DB: DrawingBackend + 'a,
    CT: CoordTranslate<From = (f64, f64)>,
{
    let stroke = color.stroke_width(s.size.max(1));
    let points = run.iter().cloned();
    let line = match s.line {
        LineKind::None => None,
        LineKind::Solid => Some(chart.draw_series(LineSeries::new(points, stroke))),
        LineKind::Dashed => Some(chart.draw_series(DashedLineSeries::new(points, 8, 5, stroke))),
    };
    let mut labelled = false;
    if let Some(anno) = line {
        let anno = anno.map_err(draw_err)?;
        if legend {
            set_legend(anno, s, color);
            labelled = true;
        }
    }
    if let Some(m) = s.marker {
        let anno = draw_markers(chart, run, m, s.size.max(1) as i32, color)?;
        if legend && !labelled {
            set_legend(anno, s, color);
            labelled = true;
        }
    }
    Ok(labelled)
}

/// Sets the legend entry of `s` on `anno`: its marker alone for a series without a line, a
/// short dashed or solid line otherwise.
fn set_legend<'a, DB: DrawingBackend + 'a>(
    anno: &mut SeriesAnno<'a, DB>,
    s: &Series,
    color: RGBColor,
) {
    anno.label(s.label.as_str());
    let stroke = color.stroke_width(2);
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

/// Draws marker `m` of radius `r` at every point of `run`.
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
    .map_err(draw_err)
}
