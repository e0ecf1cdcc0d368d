//! Pixel boxes of text and where they may go: the estimated size of a text, and whether a
//! box meets the data drawn on a panel. Legends and point labels are placed with these, so
//! that neither covers a curve nor each other.

/// A rectangle in pixels, `x0 <= x1`, `y0 <= y1` (the vertical axis points down).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct PixelBox {
    pub x0: f64,
    pub y0: f64,
    pub x1: f64,
    pub y1: f64,
}

impl PixelBox {
    /// The box of width `w` and height `h` whose upper left corner is `(x, y)`.
    pub fn at(x: f64, y: f64, w: f64, h: f64) -> Self {
        Self {
            x0: x,
            y0: y,
            x1: x + w,
            y1: y + h,
        }
    }

    /// The box grown by `m` pixels on every side.
    pub fn grown(self, m: f64) -> Self {
        Self {
            x0: self.x0 - m,
            y0: self.y0 - m,
            x1: self.x1 + m,
            y1: self.y1 + m,
        }
    }

    /// Whether `(x, y)` lies in the box.
    pub fn contains(&self, (x, y): (f64, f64)) -> bool {
        x >= self.x0 && x <= self.x1 && y >= self.y0 && y <= self.y1
    }

    /// Whether the box lies entirely within `outer`.
    pub fn within(&self, outer: &PixelBox) -> bool {
        self.x0 >= outer.x0 && self.x1 <= outer.x1 && self.y0 >= outer.y0 && self.y1 <= outer.y1
    }

    /// Whether the two boxes share any point.
    pub fn meets(&self, other: &PixelBox) -> bool {
        self.x0 <= other.x1 && other.x0 <= self.x1 && self.y0 <= other.y1 && other.y0 <= self.y1
    }

    /// Whether the segment from `a` to `b` passes through the box (Liang–Barsky clipping:
    /// the segment's parameter interval inside each slab must overlap).
    pub fn crossed_by(&self, a: (f64, f64), b: (f64, f64)) -> bool {
        let (dx, dy) = (b.0 - a.0, b.1 - a.1);
        let (mut t0, mut t1) = (0.0f64, 1.0f64);
        for (p, q) in [
            (-dx, a.0 - self.x0),
            (dx, self.x1 - a.0),
            (-dy, a.1 - self.y0),
            (dy, self.y1 - a.1),
        ] {
            if p == 0.0 {
                if q < 0.0 {
                    return false;
                }
            } else {
                let t = q / p;
                if p < 0.0 {
                    t0 = t0.max(t);
                } else {
                    t1 = t1.min(t);
                }
            }
        }
        t0 <= t1
    }
}

/// What a panel has drawn, in pixels: the points of its markers (with their radius) and the
/// segments of its lines.
#[derive(Debug, Clone, Default)]
pub(super) struct Drawn {
    pub points: Vec<((f64, f64), f64)>,
    pub segments: Vec<((f64, f64), (f64, f64))>,
}

impl Drawn {
    /// Whether `b` meets anything drawn.
    pub fn meets(&self, b: &PixelBox) -> bool {
        self.points.iter().any(|&(p, r)| b.grown(r).contains(p))
            || self.segments.iter().any(|&(p, q)| b.crossed_by(p, q))
    }

    /// How many drawn points and segments `b` meets.
    pub fn count_meeting(&self, b: &PixelBox) -> usize {
        self.points
            .iter()
            .filter(|&&(p, r)| b.grown(r).contains(p))
            .count()
            + self
                .segments
                .iter()
                .filter(|&&(p, q)| b.crossed_by(p, q))
                .count()
    }
}

/// Estimated width in pixels of `text` at font size `size`: 0.57 em per character, a little
/// above the mean advance of common sans-serif fonts in mixed text (DejaVu Sans: about
/// 0.55 em), so that estimated boxes err on the large side.
pub(super) fn text_width(text: &str, size: f64) -> f64 {
    0.57 * size * text.chars().count() as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn segments_cross_boxes_only_where_they_pass() {
        let b = PixelBox::at(10.0, 10.0, 10.0, 10.0);
        assert!(b.crossed_by((0.0, 15.0), (30.0, 15.0)));
        assert!(b.crossed_by((12.0, 12.0), (13.0, 13.0)));
        assert!(!b.crossed_by((0.0, 0.0), (30.0, 5.0)));
        assert!(!b.crossed_by((0.0, 25.0), (5.0, 0.0)));
        assert!(b.crossed_by((15.0, 0.0), (15.0, 30.0)));
        assert!(!b.crossed_by((25.0, 0.0), (25.0, 30.0)));
    }

    #[test]
    fn drawn_points_count_with_their_radius() {
        let b = PixelBox::at(0.0, 0.0, 10.0, 10.0);
        let near = Drawn {
            points: vec![((12.0, 5.0), 3.0)],
            ..Drawn::default()
        };
        let far = Drawn {
            points: vec![((14.0, 5.0), 3.0)],
            ..Drawn::default()
        };
        assert!(near.meets(&b));
        assert!(!far.meets(&b));
        assert!(b.within(&b.grown(1.0)) && !b.grown(1.0).within(&b));
        assert!(b.meets(&PixelBox::at(10.0, 10.0, 5.0, 5.0)));
    }
}
