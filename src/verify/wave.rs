//! One characteristic wave of one bar: a piecewise-constant function of the clock (in steps)
//! at which each of its parts reaches the end it is travelling to.

use std::collections::VecDeque;

/// Pieces shorter than this (in steps) are always merged into their predecessor by a
/// length-weighted mean (which keeps the integral, hence the displacements). They only arise
/// when an impact instant falls within rounding of an existing breakpoint, or from the
/// rounding of clocks; the energy changed by such a merge is below `1e-10 dt (Delta value)^2`.
pub(crate) const TINY: f64 = 1e-10;

/// A piece `[start, end)` of a wave with constant `value`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Piece {
    pub start: f64,
    pub end: f64,
    pub value: f64,
}

/// A running sum with Neumaier's compensation: its error stays at a few roundings of the
/// largest partial sum however many terms are added and removed.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Sum {
    sum: f64,
    compensation: f64,
}

impl Sum {
    pub fn add(&mut self, x: f64) {
        let t = self.sum + x;
        if self.sum.abs() >= x.abs() {
            self.compensation += (self.sum - t) + x;
        } else {
            self.compensation += (x - t) + self.sum;
        }
        self.sum = t;
    }

    pub fn value(&self) -> f64 {
        self.sum + self.compensation
    }
}

/// How a wave keeps its number of pieces bounded (see [`Wave::push_until`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Resolution {
    /// Number of pieces from which short pieces are merged.
    pub cap: usize,
    /// Pieces shorter than this (clock units) are merged once the wave holds `cap` pieces.
    pub min_piece: f64,
}

/// Piecewise-constant function on `[front, end)`: piece `k` covers
/// `[starts[k], starts[k + 1])`, the last one `[starts[last], end)`.
///
/// Alongside the pieces it keeps the running integral of its square (so that the energy of a
/// march costs nothing per step) and the integral of the square its merges have removed.
#[derive(Debug, Clone)]
pub(crate) struct Wave {
    starts: VecDeque<f64>,
    values: VecDeque<f64>,
    end: f64,
    resolution: Resolution,
    /// `int w^2` over the pieces, updated as they come and go.
    square: Sum,
    /// `sum_k int (w - P_k w)^2` over the merges `k` so far (clock units times squared
    /// values): the part of `int w^2` the merges have removed.
    removed: f64,
}

/// Waves are equal when their pieces are (whatever their histories).
impl PartialEq for Wave {
    fn eq(&self, other: &Self) -> bool {
        self.starts == other.starts && self.values == other.values && self.end == other.end
    }
}

impl Wave {
    /// An empty wave starting at clock `origin`, never merging beyond [`TINY`].
    #[cfg(test)]
    pub fn new(origin: f64) -> Self {
        Self::with_resolution(
            origin,
            Resolution {
                cap: usize::MAX,
                min_piece: TINY,
            },
        )
    }

    /// An empty wave starting at clock `origin` that merges as `resolution` says.
    pub fn with_resolution(origin: f64, resolution: Resolution) -> Self {
        Self {
            starts: VecDeque::new(),
            values: VecDeque::new(),
            end: origin,
            resolution,
            square: Sum::default(),
            removed: 0.0,
        }
    }

    /// Sets how the wave keeps its number of pieces bounded from now on.
    pub fn set_resolution(&mut self, resolution: Resolution) {
        self.resolution = resolution;
    }

    /// Number of pieces.
    pub fn len(&self) -> usize {
        self.starts.len()
    }

    /// `int w^2` over the whole wave (clock units), kept up to date by every change.
    pub fn square(&self) -> f64 {
        self.square.value()
    }

    /// `int w^2` removed by the merges so far.
    pub fn removed(&self) -> f64 {
        self.removed
    }

    /// Appends `[end, until)` with `value` (nothing if `until <= end`).
    ///
    /// The new part is merged into the last piece (their length-weighted mean, which keeps the
    /// integral of the wave: an `L2` projection onto one constant) when the values are equal
    /// to rounding, when either is shorter than [`TINY`], or, once the wave holds
    /// `resolution.cap` pieces, when either is shorter than `resolution.min_piece`. In the
    /// last case every piece added but the last is at least `min_piece` long, so the wave
    /// never holds more than `cap + span / min_piece + 2` pieces over a span of `span` clock
    /// units. The squared wave each merge removes, `h1 h2 / (h1 + h2) (v1 - v2)^2`, is added
    /// to [`Wave::removed`].
    pub fn push_until(&mut self, until: f64, value: f64) {
        let length = until - self.end;
        if length <= 0.0 {
            return;
        }
        if let (Some(&last_start), Some(last)) = (self.starts.back(), self.values.back_mut()) {
            let last_length = self.end - last_start;
            let same = (*last - value).abs() <= 4.0 * f64::EPSILON * last.abs().max(value.abs());
            let short = if self.starts.len() >= self.resolution.cap {
                self.resolution.min_piece
            } else {
                TINY
            };
            if same || length < short || last_length < short {
                let total = last_length + length;
                let mean = (last_length * *last + length * value) / total;
                let jump = *last - value;
                let removed = last_length * length / total * jump * jump;
                self.square
                    .add(total * mean * mean - last_length * *last * *last);
                self.removed += removed;
                *last = mean;
                self.end = until;
                return;
            }
        }
        self.square.add(length * value * value);
        self.starts.push_back(self.end);
        self.values.push_back(value);
        self.end = until;
    }

    /// Removes the part before `until` and appends it to `out` as pieces, in order.
    /// Stops at [`Wave::end`] if `until` lies beyond it.
    pub fn take_until(&mut self, until: f64, out: &mut Vec<Piece>) {
        while let (Some(&start), Some(&value)) = (self.starts.front(), self.values.front()) {
            let next = self.starts.get(1).copied().unwrap_or(self.end);
            if next <= until {
                out.push(Piece {
                    start,
                    end: next,
                    value,
                });
                self.square.add(-(next - start) * value * value);
                self.starts.pop_front();
                self.values.pop_front();
            } else {
                if until > start {
                    out.push(Piece {
                        start,
                        end: until,
                        value,
                    });
                    self.square.add(-(until - start) * value * value);
                    self.starts[0] = until;
                }
                return;
            }
        }
    }

    /// The pieces overlapping `[a, b)`, clipped to it.
    pub fn pieces_in(&self, a: f64, b: f64) -> impl Iterator<Item = Piece> + '_ {
        let first = self.starts.partition_point(|&s| s <= a).saturating_sub(1);
        (first..self.starts.len())
            .map(move |k| Piece {
                start: self.starts[k],
                end: self.starts.get(k + 1).copied().unwrap_or(self.end),
                value: self.values[k],
            })
            .take_while(move |p| p.start < b)
            .filter_map(move |p| {
                let (s, e) = (p.start.max(a), p.end.min(b));
                (e > s).then_some(Piece {
                    start: s,
                    end: e,
                    value: p.value,
                })
            })
    }

    /// `(int_a^b f, int_a^b f^2)` in clock units.
    pub fn moments(&self, a: f64, b: f64) -> (f64, f64) {
        self.pieces_in(a, b).fold((0.0, 0.0), |(m1, m2), p| {
            let h = p.end - p.start;
            (m1 + h * p.value, m2 + h * p.value * p.value)
        })
    }
}

/// `int_0^len (f(a0 + y) - g(b0 + y))^2 dy` for two waves (pieces merged exactly).
pub(crate) fn distance_squared(f: &Wave, a0: f64, g: &Wave, b0: f64, len: f64) -> f64 {
    let fp: Vec<Piece> = f.pieces_in(a0, a0 + len).collect();
    let gp: Vec<Piece> = g.pieces_in(b0, b0 + len).collect();
    let (mut i, mut j) = (0, 0);
    let mut y = 0.0;
    let mut acc = 0.0;
    while i < fp.len() && j < gp.len() {
        let fe = fp[i].end - a0;
        let ge = gp[j].end - b0;
        let e = fe.min(ge);
        let d = fp[i].value - gp[j].value;
        acc += (e - y).max(0.0) * d * d;
        y = e;
        if fe <= e {
            i += 1;
        }
        if ge <= e {
            j += 1;
        }
    }
    acc
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn push_take_and_moments() {
        let mut w = Wave::new(0.0);
        w.push_until(1.0, 2.0);
        w.push_until(2.0, 2.0); // merged: same value
        w.push_until(2.5, -1.0);
        w.push_until(2.5 + 1e-12, 7.0); // tiny: merged by weighted mean
        w.push_until(4.0, 3.0);
        assert_eq!(w.len(), 3);
        let (m1, m2) = w.moments(0.5, 3.0);
        assert!((m1 - (1.5 * 2.0 - 0.5 + 0.5 * 3.0)).abs() < 1e-9);
        assert!((m2 - (1.5 * 4.0 + 0.5 + 0.5 * 9.0)).abs() < 1e-9);
        let mut out = Vec::new();
        w.take_until(2.2, &mut out);
        assert_eq!(out.len(), 2);
        assert_eq!(out[1].end, 2.2);
        assert_eq!(w.pieces_in(0.0, 10.0).next().unwrap().start, 2.2);
        let mut v = Wave::new(10.0);
        v.push_until(10.3, -1.0);
        v.push_until(10.5, -1.0);
        v.push_until(10.5 + 1e-12, 5.0);
        v.push_until(12.0, 3.0);
        // w on [2.2, 4.0) vs v on [10.2, 12.0): equal up to the tiny piece.
        assert!(distance_squared(&w, 2.2, &v, 10.2, 1.8) < 1e-9);
        // The running square follows the pieces.
        for wave in [&w, &v] {
            let (_, m2) = wave.moments(f64::NEG_INFINITY, f64::INFINITY);
            assert!(
                (wave.square() - m2).abs() < 1e-12,
                "{} vs {m2}",
                wave.square()
            );
        }
    }

    #[test]
    fn merges_keep_the_integral_and_report_what_they_remove() {
        let resolution = Resolution {
            cap: 4,
            min_piece: 0.25,
        };
        let mut w = Wave::with_resolution(0.0, resolution);
        // Under the cap: short pieces are kept exactly.
        for (k, v) in [1.0, -1.0, 2.0].iter().enumerate() {
            w.push_until(0.1 * (k + 1) as f64, *v);
        }
        assert_eq!(w.len(), 3);
        assert_eq!(w.removed(), 0.0);
        w.push_until(1.0, 0.5);
        assert_eq!(w.len(), 4);
        // At the cap: a piece of 0.1 is merged into the last one (0.7 long, value 0.5).
        w.push_until(1.1, 4.5);
        assert_eq!(w.len(), 4);
        let (m1, m2) = w.moments(0.0, 2.0);
        assert!((m1 - (0.1 - 0.1 + 0.2 + 0.35 + 0.45)).abs() < 1e-12);
        let removed = 0.7 * 0.1 / 0.8 * 16.0;
        assert!((w.removed() - removed).abs() < 1e-12);
        let exact_m2 = 0.1 + 0.1 + 0.4 + 0.7 * 0.25 + 0.1 * 20.25;
        assert!((m2 + removed - exact_m2).abs() < 1e-12);
        assert!((w.square() - m2).abs() < 1e-12);
        // A long piece after a long one is kept; the piece count stays bounded however
        // finely the wave is pushed.
        w.push_until(1.5, 3.0);
        assert_eq!(w.len(), 5);
        let mut out = Vec::new();
        for k in 0..10_000 {
            let s = 1.5 + 0.01 * (k + 1) as f64;
            w.push_until(s, (k as f64).sin());
            w.take_until(s - 3.0, &mut out);
            // Span 3, pieces of at least 0.25 past the cap of 4: at most 4 + 12 + 2.
            assert!(w.len() <= 18, "{}", w.len());
        }
        let (_, m2) = w.moments(f64::NEG_INFINITY, f64::INFINITY);
        assert!((w.square() - m2).abs() < 1e-12 * m2.max(1.0));
        assert!(w.removed() > removed);
    }
}
