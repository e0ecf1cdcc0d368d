//! Labels of points on a line panel (the lettered points of a paper's figure): each is set
//! beside its point, on a white ground, in the first of a ring of places around the point
//! where it stays in the plot, covers no earlier label nor the legend, and lies nearer its own
//! point than any other labelled point (two close points' labels must not read swapped). A
//! label set farther than the first ring is tied to its point by a thin leader line.

use super::canvas::{draw_err, Area, PlotError, FONT};
use super::place::{text_width, PixelBox};
use super::types::Annotation;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

/// Font size of a point label, in pixels.
const TEXT: f64 = 15.0;
/// Height of a label's box.
const HEIGHT: f64 = 18.0;
/// Gap between a point and its label's box in the first ring.
const GAP: f64 = 7.0;

/// A label and where it was set.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Placed<'a> {
    pub text: &'a str,
    pub point: (f64, f64),
    pub at: PixelBox,
    pub leader: bool,
}

/// Places every annotation whose point `pixel` maps into `plot`, avoiding the boxes in
/// `taken` (which the placed labels join).
pub(super) fn place<'a>(
    notes: &'a [Annotation],
    pixel: impl Fn((f64, f64)) -> Option<(f64, f64)>,
    plot: &PixelBox,
    taken: &mut Vec<PixelBox>,
) -> Vec<Placed<'a>> {
    let mut out = Vec::with_capacity(notes.len());
    let points: Vec<(f64, f64)> = (notes.iter())
        .filter_map(|n| pixel(n.at).filter(|&p| plot.contains(p)))
        .collect();
    for n in notes {
        let Some(p) = pixel(n.at).filter(|&p| plot.contains(p)) else {
            continue;
        };
        let own = |b: &PixelBox| {
            let d = distance(b, p);
            points.iter().all(|&q| q == p || distance(b, q) >= d)
        };
        let w = text_width(&n.text, TEXT) + 6.0;
        let candidates = (1..=4).flat_map(|ring| {
            let d = GAP + (ring - 1) as f64 * HEIGHT;
            [
                (d, -d - HEIGHT),
                (-d - w, -d - HEIGHT),
                (d, d),
                (-d - w, d),
                (d + 2.0, -0.5 * HEIGHT),
                (-d - w - 2.0, -0.5 * HEIGHT),
                (-0.5 * w, -d - HEIGHT - 2.0),
                (-0.5 * w, d + 2.0),
            ]
            .map(move |(dx, dy)| (ring, PixelBox::at(p.0 + dx, p.1 + dy, w, HEIGHT)))
        });
        // The first place that is free and nearest its own point; failing that, the first
        // free one; failing that, the first inside the plot.
        let (mut first_inside, mut first_free, mut chosen) = (None, None, None);
        for (ring, b) in candidates.filter(|(_, b)| b.within(plot)) {
            first_inside.get_or_insert((ring, b));
            if !taken.iter().any(|t| t.meets(&b)) {
                first_free.get_or_insert((ring, b));
                if own(&b) {
                    chosen = Some((ring, b));
                    break;
                }
            }
        }
        if let Some((ring, at)) = chosen.or(first_free).or(first_inside) {
            taken.push(at);
            out.push(Placed {
                text: &n.text,
                point: p,
                at,
                leader: ring > 1,
            });
        }
    }
    out
}

/// The distance from `point` to the nearest point of the box `b`.
fn distance(b: &PixelBox, point: (f64, f64)) -> f64 {
    let dx = (b.x0 - point.0).max(point.0 - b.x1).max(0.0);
    let dy = (b.y0 - point.1).max(point.1 - b.y1).max(0.0);
    dx.hypot(dy)
}

/// Draws placed labels on `area` (screen coordinates): leader line, white ground, bold text.
pub(super) fn draw(area: &Area<'_>, placed: &[Placed<'_>]) -> Result<(), PlotError> {
    let screen = area.use_screen_coord();
    let px = |v: f64| v.round() as i32;
    let style = TextStyle::from((FONT, TEXT).into_font().style(FontStyle::Bold))
        .pos(Pos::new(HPos::Center, VPos::Center))
        .color(&BLACK);
    for l in placed {
        let b = l.at;
        let centre = (0.5 * (b.x0 + b.x1), 0.5 * (b.y0 + b.y1));
        if l.leader {
            // From the point to the nearest point of the box.
            let near = (l.point.0.clamp(b.x0, b.x1), l.point.1.clamp(b.y0, b.y1));
            screen
                .draw(&PathElement::new(
                    vec![(px(l.point.0), px(l.point.1)), (px(near.0), px(near.1))],
                    RGBColor(60, 60, 60).stroke_width(1),
                ))
                .map_err(draw_err)?;
        }
        screen
            .draw(&Rectangle::new(
                [(px(b.x0), px(b.y0)), (px(b.x1), px(b.y1))],
                WHITE.mix(0.85).filled(),
            ))
            .map_err(draw_err)?;
        screen
            .draw(&Text::new(
                l.text,
                (px(centre.0), px(centre.1)),
                style.clone(),
            ))
            .map_err(draw_err)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn note(x: f64, y: f64, text: &str) -> Annotation {
        Annotation {
            at: (x, y),
            text: text.into(),
        }
    }

    #[test]
    fn labels_of_close_points_do_not_overlap() {
        let plot = PixelBox::at(0.0, 0.0, 400.0, 300.0);
        let notes: Vec<_> = ["a", "b", "c", "d", "e"]
            .iter()
            .map(|t| note(200.0, 150.0, t))
            .collect();
        let mut taken = Vec::new();
        let placed = place(&notes, Some, &plot, &mut taken);
        assert_eq!(placed.len(), 5);
        for (i, a) in placed.iter().enumerate() {
            assert!(a.at.within(&plot));
            for b in &placed[i + 1..] {
                assert!(!a.at.meets(&b.at), "{} and {} overlap", a.text, b.text);
            }
        }
    }

    /// Two points a few pixels apart on a line: each label lies nearer its own point than
    /// the other's, so that they do not read swapped.
    #[test]
    fn labels_of_neighbours_lie_nearer_their_own_points() {
        let plot = PixelBox::at(0.0, 0.0, 400.0, 300.0);
        for gap in [4.0, 8.0, 15.0, 30.0] {
            let notes = [note(200.0, 150.0, "g"), note(200.0 + gap, 148.0, "f")];
            let placed = place(&notes, Some, &plot, &mut Vec::new());
            assert_eq!(placed.len(), 2);
            for (a, b) in [(&placed[0], &placed[1]), (&placed[1], &placed[0])] {
                assert!(
                    distance(&a.at, a.point) <= distance(&a.at, b.point),
                    "gap {gap}: {} lies nearer {}",
                    a.text,
                    b.text
                );
            }
            assert!(!placed[0].at.meets(&placed[1].at));
        }
    }

    #[test]
    fn labels_stay_in_the_plot_and_off_taken_boxes() {
        let plot = PixelBox::at(0.0, 0.0, 400.0, 300.0);
        let legend = PixelBox::at(0.0, 0.0, 120.0, 60.0);
        let mut taken = vec![legend];
        let notes = [note(5.0, 5.0, "corner"), note(500.0, 5.0, "outside")];
        let placed = place(&notes, Some, &plot, &mut taken);
        assert_eq!(placed.len(), 1, "a point off the plot has no label");
        assert!(placed[0].at.within(&plot));
        assert!(!placed[0].at.meets(&legend));
    }
}
