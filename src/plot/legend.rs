//! The legend of a line panel: its size, where it goes, and its drawing.
//!
//! [`LegendPosition::Auto`] puts the legend in the first corner (or edge middle) of the plot
//! where it meets no drawn point or line; when every place is taken, the legend goes outside
//! the plot, on its right or below it (the line panel lays out the strip). A legend therefore
//! covers data only when its caller fixed its position, or when it is too large for a strip
//! beside or below the plot ([`least_covered_box`]).

use super::canvas::{draw_err, Area, PlotError, FONT};
use super::place::{text_width, Drawn, PixelBox};
use super::types::{LegendPosition, LineKind, Marker, Series};
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

/// Font size of legend text, in pixels.
const TEXT: f64 = 14.0;
/// Height of one legend row.
const ROW: f64 = 20.0;
/// Inner margin of the legend box.
const PAD: f64 = 6.0;
/// Width of the line or marker sample before each label.
const SAMPLE: f64 = 24.0;
/// Distance between the legend box and the plot's frame.
pub(super) const INSET: f64 = 8.0;

/// One legend row: a series and the colour it is drawn in.
pub(super) struct Entry<'a> {
    pub series: &'a Series,
    pub color: RGBColor,
}

/// Width and height of the legend box of `entries`.
pub(super) fn legend_size(entries: &[Entry<'_>]) -> (f64, f64) {
    let text = entries
        .iter()
        .map(|e| text_width(&e.series.label, TEXT))
        .fold(0.0, f64::max);
    (
        2.0 * PAD + SAMPLE + 6.0 + text,
        2.0 * PAD + ROW * entries.len() as f64,
    )
}

/// The box of a legend of size `(w, h)` at a fixed `position` inside `plot`; `None` for
/// [`LegendPosition::Hidden`], [`LegendPosition::Auto`] and [`LegendPosition::Outside`].
pub(super) fn fixed_box(
    position: LegendPosition,
    plot: &PixelBox,
    (w, h): (f64, f64),
) -> Option<PixelBox> {
    let left = plot.x0 + INSET;
    let right = plot.x1 - INSET - w;
    let middle = 0.5 * (plot.x0 + plot.x1 - w);
    let top = plot.y0 + INSET;
    let bottom = plot.y1 - INSET - h;
    let (x, y) = match position {
        LegendPosition::UpperLeft => (left, top),
        LegendPosition::UpperRight => (right, top),
        LegendPosition::LowerLeft => (left, bottom),
        LegendPosition::LowerRight => (right, bottom),
        LegendPosition::UpperMiddle => (middle, top),
        LegendPosition::LowerMiddle => (middle, bottom),
        LegendPosition::Auto | LegendPosition::Outside | LegendPosition::Hidden => return None,
    };
    Some(PixelBox::at(x, y, w, h))
}

/// The first place inside `plot` where a legend of `size` meets nothing `drawn`: the four
/// corners, then the middles of the upper and lower edges. `None` if every place is taken or
/// the legend does not fit.
pub(super) fn free_box(plot: &PixelBox, size: (f64, f64), drawn: &Drawn) -> Option<PixelBox> {
    PLACES
        .into_iter()
        .filter_map(|p| fixed_box(p, plot, size))
        .find(|b| b.within(plot) && !drawn.meets(&b.grown(2.0)))
}

/// The places an automatic legend tries inside the plot, in order.
const PLACES: [LegendPosition; 6] = [
    LegendPosition::UpperLeft,
    LegendPosition::UpperRight,
    LegendPosition::LowerRight,
    LegendPosition::LowerLeft,
    LegendPosition::UpperMiddle,
    LegendPosition::LowerMiddle,
];

/// The place inside `plot` where a legend of `size` meets the fewest drawn points and
/// segments (the places of [`free_box`], in its order on a tie); `None` if the legend does not
/// fit. For a legend that has no free place and no room beside the plot either.
pub(super) fn least_covered_box(
    plot: &PixelBox,
    size: (f64, f64),
    drawn: &Drawn,
) -> Option<PixelBox> {
    PLACES
        .into_iter()
        .filter_map(|p| fixed_box(p, plot, size))
        .filter(|b| b.within(plot))
        .min_by_key(|b| drawn.count_meeting(&b.grown(2.0)))
}

/// Draws the legend of `entries` in box `b` (screen coordinates) on `area`.
pub(super) fn draw_legend(
    area: &Area<'_>,
    b: &PixelBox,
    entries: &[Entry<'_>],
) -> Result<(), PlotError> {
    let screen = area.use_screen_coord();
    let px = |v: f64| v.round() as i32;
    screen
        .draw(&Rectangle::new(
            [(px(b.x0), px(b.y0)), (px(b.x1), px(b.y1))],
            WHITE.mix(0.9).filled(),
        ))
        .map_err(draw_err)?;
    screen
        .draw(&Rectangle::new(
            [(px(b.x0), px(b.y0)), (px(b.x1), px(b.y1))],
            RGBColor(160, 160, 160).stroke_width(1),
        ))
        .map_err(draw_err)?;
    for (i, e) in entries.iter().enumerate() {
        let y = px(b.y0 + PAD + ROW * (i as f64 + 0.5));
        let x = px(b.x0 + PAD);
        draw_sample(&screen, (x, y), e)?;
        let style = TextStyle::from((FONT, TEXT).into_font())
            .pos(Pos::new(HPos::Left, VPos::Center))
            .color(&BLACK);
        screen
            .draw(&Text::new(
                e.series.label.as_str(),
                (x + px(SAMPLE + 6.0), y),
                style,
            ))
            .map_err(draw_err)?;
    }
    Ok(())
}

/// Draws the sample of entry `e` (its line, its marker, or both) starting at `(x, y)`.
fn draw_sample(screen: &Area<'_>, (x, y): (i32, i32), e: &Entry<'_>) -> Result<(), PlotError> {
    let s = e.series;
    let stroke = e.color.stroke_width(s.size.clamp(1, 3));
    let w = SAMPLE as i32;
    let dashes: &[(i32, i32)] = match s.line {
        LineKind::None => &[],
        LineKind::Solid => &[(0, w)],
        LineKind::Dashed => &[(0, 6), (9, 15), (18, w)],
    };
    for &(a, b) in dashes {
        screen
            .draw(&PathElement::new(vec![(x + a, y), (x + b, y)], stroke))
            .map_err(draw_err)?;
    }
    let Some(m) = s.marker else {
        return Ok(());
    };
    let (c, r) = ((x + w / 2, y), (s.size as i32).clamp(3, 6));
    let fill = e.color.filled();
    let ring = e.color.stroke_width(1);
    match m {
        Marker::Circle => screen.draw(&Circle::new(c, r, fill)),
        Marker::Ring => screen.draw(&Circle::new(c, r, ring.stroke_width(2))),
        Marker::Square => screen.draw(&Rectangle::new(
            [(c.0 - r, c.1 - r), (c.0 + r, c.1 + r)],
            fill,
        )),
        Marker::Triangle => screen.draw(&TriangleMarker::new(c, r + 1, fill)),
        Marker::Cross => screen.draw(&Cross::new(c, r, e.color.stroke_width(2))),
    }
    .map_err(draw_err)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_free_box_avoids_what_is_drawn() {
        let plot = PixelBox::at(0.0, 0.0, 400.0, 300.0);
        let size = (100.0, 50.0);
        let empty = Drawn::default();
        let first = free_box(&plot, size, &empty).unwrap();
        assert_eq!(
            first,
            fixed_box(LegendPosition::UpperLeft, &plot, size).unwrap()
        );
        // A line along the whole upper edge leaves the lower right corner.
        let upper = Drawn {
            segments: vec![((0.0, 20.0), (400.0, 30.0))],
            ..Drawn::default()
        };
        let b = free_box(&plot, size, &upper).unwrap();
        assert_eq!(
            b,
            fixed_box(LegendPosition::LowerRight, &plot, size).unwrap()
        );
        assert!(!upper.meets(&b));
        // Lines along both edges leave no place.
        let both = Drawn {
            segments: vec![((0.0, 20.0), (400.0, 30.0)), ((0.0, 280.0), (400.0, 270.0))],
            ..Drawn::default()
        };
        assert!(free_box(&plot, size, &both).is_none());
        // A legend larger than the plot has no place.
        assert!(free_box(&plot, (500.0, 50.0), &empty).is_none());
        // With every place taken, the least covered one: the lower edge's line is crossed
        // once by each lower box, the upper edge's by each upper box, and a point more lies
        // in the upper left corner.
        let mut crowded = both.clone();
        crowded.points.push(((20.0, 20.0), 1.0));
        let b = least_covered_box(&plot, size, &crowded).unwrap();
        assert_eq!(
            b,
            fixed_box(LegendPosition::UpperRight, &plot, size).unwrap()
        );
    }
}
