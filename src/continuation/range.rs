//! The checks of a range given by its ends, shared by every entry point that takes one (period
//! and energy grids, forcing frequencies, a continuation's parameter range and values), so
//! that each refuses the same defects with the same [`BadRange`], quoting the range as given.

use crate::error::{BadRange, RangeDefect};

/// What the ends of a range may be.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Ends {
    /// Positive and finite: periods, frequencies, energy levels.
    Positive,
    /// Any number but NaN: a continuation's bounds, which may be infinite (unbounded).
    NotNan,
}

/// Whether the range has a direction.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Direction {
    /// It may run either way (a period grid runs from long periods to short ones or back).
    Either,
    /// It must rise from its start to its end (a range `(lo, hi)`).
    Rising,
}

/// A range `what` from `start` to `end` (with `steps` values for a grid) whose ends are
/// `ends` and whose direction is `direction`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Range {
    pub what: &'static str,
    pub start: f64,
    pub end: f64,
    pub steps: Option<usize>,
}

impl Range {
    /// A grid of `steps` values from `start` to `end`.
    pub fn grid(what: &'static str, start: f64, end: f64, steps: usize) -> Self {
        Self {
            what,
            start,
            end,
            steps: Some(steps),
        }
    }

    /// A range `(lo, hi)`.
    pub fn bounds(what: &'static str, (lo, hi): (f64, f64)) -> Self {
        Self {
            what,
            start: lo,
            end: hi,
            steps: None,
        }
    }

    /// Checks the range: its ends (not finite, not positive), its steps (fewer than 2), its
    /// ends equal (empty), its direction (reversed), in that order, so that the first defect
    /// a user would fix is the one reported.
    ///
    /// # Errors
    /// [`BadRange`] with the first defect found.
    pub fn check(self, ends: Ends, direction: Direction) -> Result<(), BadRange> {
        let defect = |defect| BadRange {
            what: self.what,
            start: self.start,
            end: self.end,
            steps: self.steps,
            defect,
        };
        let (a, b) = (self.start, self.end);
        let finite = match ends {
            Ends::Positive => a.is_finite() && b.is_finite(),
            Ends::NotNan => !(a.is_nan() || b.is_nan()),
        };
        if !finite {
            return Err(defect(RangeDefect::NotFinite));
        }
        if ends == Ends::Positive && !(a > 0.0 && b > 0.0) {
            return Err(defect(RangeDefect::NotPositive));
        }
        if self.steps.is_some_and(|steps| steps < 2) {
            return Err(defect(RangeDefect::SinglePoint));
        }
        if a == b {
            return Err(defect(RangeDefect::Empty));
        }
        if direction == Direction::Rising && a > b {
            return Err(defect(RangeDefect::Reversed));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each defect is found, the first a user would fix reported, and the range quoted.
    #[test]
    fn defects_in_order() {
        let grid = |a, b, steps| Range::grid("period grid", a, b, steps);
        let defect = |r: Range, ends, direction| r.check(ends, direction).unwrap_err().defect;
        let (pos, either) = (Ends::Positive, Direction::Either);
        assert_eq!(
            defect(grid(f64::NAN, -1.0, 1), pos, either),
            RangeDefect::NotFinite
        );
        assert_eq!(
            defect(grid(-1.0, 3.0, 1), pos, either),
            RangeDefect::NotPositive
        );
        assert_eq!(
            defect(grid(3.5, 3.5, 1), pos, either),
            RangeDefect::SinglePoint
        );
        assert_eq!(defect(grid(3.5, 3.5, 181), pos, either), RangeDefect::Empty);
        assert!(grid(3.95, 3.05, 181).check(pos, either).is_ok());
        let rising = Direction::Rising;
        let bounds = |lo, hi| Range::bounds("parameter range", (lo, hi));
        assert_eq!(
            defect(bounds(2.0, 1.0), Ends::NotNan, rising),
            RangeDefect::Reversed
        );
        assert!(bounds(f64::NEG_INFINITY, f64::INFINITY)
            .check(Ends::NotNan, rising)
            .is_ok());
        assert_eq!(
            defect(bounds(f64::INFINITY, f64::INFINITY), Ends::NotNan, rising),
            RangeDefect::Empty
        );
        let message = grid(3.5, 3.5, 181)
            .check(pos, either)
            .unwrap_err()
            .to_string();
        assert!(
            message.contains("from 3.5 to 3.5 in 181 steps is empty"),
            "{message}"
        );
    }
}
