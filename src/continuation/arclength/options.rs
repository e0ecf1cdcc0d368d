//! Options of the pseudo-arclength driver: steps, range, predictor, norm scales, step control,
//! and their validation.

use crate::continuation::range::{Direction, Ends, Range};
#[cfg(doc)]
use crate::continuation::EndReason;
use crate::error::ContinuationError;

/// How the predictor direction is formed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum TangentPredictor {
    /// Tangent of the branch from the bordered Jacobian `[J, F_lambda; t_k^T W]` (default).
    #[default]
    Tangent,
    /// Normalised secant through the last two accepted points (tangent for the first step).
    Secant,
}

/// Scales `(s_x, s_lambda)` of the arclength norm.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum ArclengthScale {
    /// `|x|^2 = sum_i w_i x_i^2 / sum_i w_i x0_i^2` with the problem's
    /// [`Structured::state_weights`](crate::solve::Structured::state_weights) (an energy
    /// norm for harmonic balance; all 1 if it has none), so that `ds` is the relative change of the state; and
    /// `s_lambda = |lambda_0|` (or 1 when `lambda_0 = 0`) (default).
    #[default]
    Automatic,
    /// Fixed scales `(s_x, s_lambda)`: `|y|^2 = |x|_2^2 / s_x^2 + lambda^2 / s_lambda^2`.
    Fixed(f64, f64),
}

/// Options of [`Arclength`](super::Arclength). Every field documents its default.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ArclengthOptions {
    /// Initial step `ds` (default `0.02`).
    pub ds: f64,
    /// Smallest step before the run ends with [`EndReason::StepBelowMinimum`] (default
    /// `1e-5`).
    pub ds_min: f64,
    /// Largest step (default `0.2`).
    pub ds_max: f64,
    /// Accepted points before [`EndReason::MaxSteps`] (default 2000).
    pub max_steps: usize,
    /// The run ends with [`EndReason::ParameterOutOfRange`] when `lambda` leaves `[lo, hi]`,
    /// `lo < hi` (default unbounded; infinite bounds are allowed, NaN is not).
    pub parameter_range: (f64, f64),
    /// Initial direction of `lambda`: `+1` or `-1` (default `+1`).
    pub direction: f64,
    /// Predictor (default tangent).
    pub predictor: TangentPredictor,
    /// Norm scales (default automatic).
    pub scale: ArclengthScale,
    /// Corrector iterations at or below which `ds` grows (default 3).
    pub fast_iterations: usize,
    /// Growth factor of `ds` after a fast corrector (default 1.5).
    pub growth: f64,
    /// Shrink factor of `ds` after a rejection (default 0.5).
    pub shrink: f64,
    /// A corrected point farther than `jump_ratio * ds` from its prediction is a jump
    /// (default 2).
    pub jump_ratio: f64,
    /// Largest angle in radians between successive tangents (default `pi/4`).
    pub max_turn: f64,
    /// Rejected steps a run may take; one more ends it with
    /// [`EndReason::TooManyRejections`] (default 10 000). Consecutive rejections are
    /// bounded by `ds_min` (with the default steps and factors, at most 15 halvings of `ds`
    /// from `ds_max`), but a `shrink` close to 1 takes millions of them, each a corrector
    /// solve, to get there; this bounds the whole run's.
    pub max_rejections: usize,
    /// Watch the sign of `det [J, F_lambda; t^T W]` along the branch and report a
    /// [`Event::BranchPoint`](crate::continuation::Event::BranchPoint) where it changes
    /// (default `true`). It costs one dense factorisation of the bordered Jacobian per
    /// accepted point, `O(n^3)` in the problem's dimension `n`; turn it off for large
    /// problems whose branch points do not matter.
    pub branch_points: bool,
}

impl Default for ArclengthOptions {
    fn default() -> Self {
        Self {
            ds: 0.02,
            ds_min: 1e-5,
            ds_max: 0.2,
            max_steps: 2000,
            parameter_range: (f64::NEG_INFINITY, f64::INFINITY),
            direction: 1.0,
            predictor: TangentPredictor::Tangent,
            scale: ArclengthScale::Automatic,
            fast_iterations: 3,
            growth: 1.5,
            shrink: 0.5,
            jump_ratio: 2.0,
            max_turn: std::f64::consts::FRAC_PI_4,
            max_rejections: 10_000,
            branch_points: true,
        }
    }
}

impl ArclengthOptions {
    /// Checks the options.
    ///
    /// # Errors
    /// [`ContinuationError::Range`] for a `parameter_range` that is empty, reversed or has a
    /// NaN end (its bounds may be infinite); [`ContinuationError::InvalidOption`] for
    /// non-finite or non-positive steps, `ds_min > ds_max`, `ds` outside `[ds_min, ds_max]`,
    /// a zero direction, factors out of range or non-positive fixed scales.
    pub fn validate(&self) -> Result<(), ContinuationError> {
        let bad = |what, value| Err(ContinuationError::InvalidOption { what, value });
        for (what, v) in [
            ("ds", self.ds),
            ("ds_min", self.ds_min),
            ("ds_max", self.ds_max),
            ("jump_ratio", self.jump_ratio),
            ("max_turn", self.max_turn),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return bad(what, v);
            }
        }
        if self.ds_min > self.ds_max {
            return bad("ds_min (greater than ds_max)", self.ds_min);
        }
        if self.ds < self.ds_min || self.ds > self.ds_max {
            return bad("ds (outside [ds_min, ds_max])", self.ds);
        }
        Range::bounds("parameter range", self.parameter_range)
            .check(Ends::NotNan, Direction::Rising)?;
        if !(self.direction == 1.0 || self.direction == -1.0) {
            return bad("direction (must be +1 or -1)", self.direction);
        }
        if !(self.growth.is_finite() && self.growth >= 1.0) {
            return bad("growth (at least 1)", self.growth);
        }
        if !(self.shrink > 0.0 && self.shrink < 1.0) {
            return bad("shrink (in (0, 1))", self.shrink);
        }
        if self.max_steps == 0 {
            return bad("max_steps", 0.0);
        }
        if let ArclengthScale::Fixed(a, b) = self.scale {
            for v in [a, b] {
                if !(v.is_finite() && v > 0.0) {
                    return bad("scale", v);
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::error::RangeDefect;

    #[test]
    fn rejects_bad_options() {
        let bad = [
            ArclengthOptions {
                ds_min: 1.0,
                ds_max: 0.1,
                ds: 0.5,
                ..Default::default()
            },
            ArclengthOptions {
                ds: f64::NAN,
                ..Default::default()
            },
            ArclengthOptions {
                direction: 0.0,
                ..Default::default()
            },
            ArclengthOptions {
                max_steps: 0,
                ..Default::default()
            },
            ArclengthOptions {
                scale: ArclengthScale::Fixed(0.0, 1.0),
                ..Default::default()
            },
            ArclengthOptions {
                shrink: 1.0,
                ..Default::default()
            },
            ArclengthOptions {
                growth: 0.5,
                ..Default::default()
            },
        ];
        for o in bad {
            assert!(
                matches!(o.validate(), Err(ContinuationError::InvalidOption { .. })),
                "{o:?}"
            );
        }
        assert!(ArclengthOptions::default().validate().is_ok());
        for (range, defect) in [
            ((1.0, 1.0), RangeDefect::Empty),
            ((2.0, 1.0), RangeDefect::Reversed),
            ((f64::NAN, 1.0), RangeDefect::NotFinite),
        ] {
            let o = ArclengthOptions {
                parameter_range: range,
                ..Default::default()
            };
            match o.validate() {
                Err(ContinuationError::Range(r)) => {
                    assert_eq!(r.defect, defect);
                    assert_eq!(r.start.to_bits(), range.0.to_bits());
                    assert_eq!(r.end, range.1);
                }
                other => panic!("{range:?}: {other:?}"),
            }
        }
        let none_allowed = ArclengthOptions {
            max_rejections: 0,
            ..Default::default()
        };
        assert!(none_allowed.validate().is_ok());
    }
}
