//! One characteristic wave of one bar: a piecewise-constant function of the clock (in steps)
//! at which each of its parts reaches the end it is travelling to.

use std::collections::VecDeque;

/// Pieces shorter than this (in steps) are merged into their predecessor by a length-weighted
/// mean (which keeps the integral, hence the displacements). They only arise when an impact
/// instant falls within rounding of an existing breakpoint; the energy changed by a merge is
/// below `1e-10 dt (Delta value)^2`, far below rounding of the total.
pub(crate) const TINY: f64 = 1e-10;

/// A piece `[start, end)` of a wave with constant `value`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Piece {
    pub start: f64,
    pub end: f64,
    pub value: f64,
}

/// Piecewise-constant function on `[front, end)`: piece `k` covers
/// `[starts[k], starts[k + 1])`, the last one `[starts[last], end)`.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Wave {
    starts: VecDeque<f64>,
    values: VecDeque<f64>,
    end: f64,
}

impl Wave {
    /// An empty wave starting at clock `origin`.
    pub fn new(origin: f64) -> Self {
        Self {
            starts: VecDeque::new(),
            values: VecDeque::new(),
            end: origin,
        }
    }

    /// Number of pieces.
    pub fn len(&self) -> usize {
        self.starts.len()
    }

    /// Appends `[end, until)` with `value` (nothing if `until <= end`).
    pub fn push_until(&mut self, until: f64, value: f64) {
        let length = until - self.end;
        if length <= 0.0 {
            return;
        }
        if let (Some(&last_start), Some(last)) = (self.starts.back(), self.values.back_mut()) {
            let last_length = self.end - last_start;
            let same = (*last - value).abs() <= 4.0 * f64::EPSILON * last.abs().max(value.abs());
            if same || length < TINY || last_length < TINY {
                *last = (last_length * *last + length * value) / (last_length + length);
                self.end = until;
                return;
            }
        }
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
                self.starts.pop_front();
                self.values.pop_front();
            } else {
                if until > start {
                    out.push(Piece {
                        start,
                        end: until,
                        value,
                    });
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
    }
}
