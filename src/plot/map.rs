//! Colour-map panels: the colour scales, the cell edges of a grid, the map with its overlay
//! curves, and the colour bar beside it.

use super::axes::{clip_segments, finite_range, padded, segments, tick};
use super::canvas::{draw_err, panel_builder, Area, PlotError, FONT};
use super::lines::draw_run;
use super::types::{MapPanel, Rgb, PALETTE};
use plotters::prelude::*;

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
        Rgb::along(&stops, s)
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

/// Far edge of cell `i` of edges `e`, reaching a little into the next cell (drawn later) so
/// that anti-aliasing leaves no seams; the last cell ends at its own edge.
fn overlapping_end(e: &[f64], i: usize) -> f64 {
    if i + 2 < e.len() {
        e[i + 1] + 0.2 * (e[i + 2] - e[i + 1])
    } else {
        e[i + 1]
    }
}

/// Checks the grid of `panel`: non-empty, one value per cell, finite ascending coordinates.
fn check_grid(panel: &MapPanel) -> Result<(), PlotError> {
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
    Ok(())
}

/// Draws a colour-map panel on `area`: the map on the left, its colour bar on the right.
pub(super) fn draw_map_panel(area: &Area<'_>, panel: &MapPanel) -> Result<(), PlotError> {
    check_grid(panel)?;
    let (nx, ny) = (panel.x.len(), panel.y.len());
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
    let (xr, yr) = ((ex[0], ex[nx]), (ey[0], ey[ny]));
    let mut chart = panel_builder(&main, &panel.title, 70)
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
                Rectangle::new(
                    [
                        (ex[i], ey[j]),
                        (overlapping_end(&ex, i), overlapping_end(&ey, j)),
                    ],
                    colormap(normalise(v), panel.diverging).color().filled(),
                )
            })
        }))
        .map_err(draw_err)?;
    for (i, s) in panel.overlay.iter().enumerate() {
        let color = s.color.unwrap_or(if i == 0 {
            Rgb::BLACK
        } else {
            PALETTE[i % PALETTE.len()]
        });
        for run in clip_segments(segments(&s.points, false, false), xr, yr) {
            draw_run(&mut chart, &run, s, color.color())?;
        }
    }
    draw_colour_bar(&bar, panel, (vlo, vhi), normalise)
}

/// Draws the colour bar of `panel` on `area`: the colour scale over the values `[vlo, vhi]`
/// (mapped to the scale by `normalise`), with ticks on its right.
fn draw_colour_bar(
    area: &Area<'_>,
    panel: &MapPanel,
    (vlo, vhi): (f64, f64),
    normalise: impl Fn(f64) -> f64,
) -> Result<(), PlotError> {
    let mut cb = ChartBuilder::on(area);
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn colormap_ends() {
        assert_eq!(colormap(0.0, true), Rgb(250, 250, 250));
        assert_eq!(colormap(1.0, true), Rgb(180, 25, 30));
        assert_eq!(colormap(-1.0, true), Rgb(40, 70, 170));
        assert_eq!(colormap(1.0, false), Rgb(250, 230, 40));
    }

    #[test]
    fn edges_are_midpoints_extrapolated_at_the_ends() {
        assert_eq!(edges(&[0.0, 1.0, 3.0]), vec![-0.5, 0.5, 2.0, 4.0]);
        assert_eq!(edges(&[2.0]), vec![1.5, 2.5]);
        let e = [0.0, 1.0, 3.0];
        assert!((overlapping_end(&e, 0) - 1.4).abs() < 1e-15);
        assert_eq!(overlapping_end(&e, 1), 3.0);
    }
}
