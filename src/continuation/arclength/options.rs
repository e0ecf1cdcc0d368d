//! Options of the pseudo-arclength driver: steps, range, predictor, norm scales, step control,
//! and their validation.

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
    /// [`Structured::state_weights`] (an energy norm for harmonic balance; all 1 if it
    /// has none), so that `ds` is the relative change of the state; and
    /// `s_lambda = |lambda_0|` (or 1 when `lambda_0 = 0`) (default).
    #[default]
    Automatic,
    /// Fixed scales `(s_x, s_lambda)`: `|y|^2 = |x|_2^2 / s_x^2 + lambda^2 / s_lambda^2`.
    Fixed(f64, f64),
}

/// Automatic escape from stalls (see the module documentation). Distances are relative to the
/// parameter scale `s_lambda`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StallEscape {
    /// Accepted points over which progress is measured (default 20).
    pub window: usize,
    /// Least progress of the parameter over the window, relative (default `2e-3`).
    pub min_progress: f64,
    /// First jump beyond the stalled parameter, relative (default `2e-3`); doubled on each
    /// failed attempt.
    pub jump: f64,
    /// Attempts before the run ends with [`EndReason::Stalled`] (default 6).
    pub max_attempts: usize,
    /// A jump is accepted only if the new state's norm is at most this multiple of the norm
    /// of the point it started from (default 2).
    pub max_norm_ratio: f64,
}

impl Default for StallEscape {
    fn default() -> Self {
        Self {
            window: 20,
            min_progress: 2e-3,
            jump: 2e-3,
            max_attempts: 6,
            max_norm_ratio: 2.0,
        }
    }
}

/// Options of [`Arclength`](super::Arclength). Every field documents its default.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ArclengthOptions {
    /// Initial step `ds` (default `0.02`).
    pub ds: f64,
    /// Smallest step before the run ends with [`EndReason::StepBelowMinimum`] (default `1e-5`).
    pub ds_min: f64,
    /// Largest step (default `0.2`).
    pub ds_max: f64,
    /// Accepted points before [`EndReason::MaxSteps`] (default 2000).
    pub max_steps: usize,
    /// The run ends with [`EndReason::ParameterOutOfRange`] when `lambda` leaves
    /// `[lo, hi]` (default unbounded).
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
    /// Automatic escape from stalls (default `None`: follow the branch wherever it goes).
    pub escape: Option<StallEscape>,
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
            escape: None,
        }
    }
}

impl ArclengthOptions {
    /// Checks the options.
    ///
    /// # Errors
    /// [`ContinuationError::InvalidOption`] for non-finite or non-positive steps,
    /// `ds_min > ds_max`, `ds` outside `[ds_min, ds_max]`, an empty or NaN range, a zero
    /// direction, factors out of range or non-positive fixed scales.
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
        let (lo, hi) = self.parameter_range;
        if lo.is_nan() || hi.is_nan() || lo >= hi {
            return bad("parameter_range (empty)", hi - lo);
        }
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
        if let Some(e) = self.escape {
            if e.window < 2 || e.max_attempts == 0 {
                return bad(
                    "escape window/attempts",
                    e.window.min(e.max_attempts) as f64,
                );
            }
            for (what, v) in [
                ("escape min_progress", e.min_progress),
                ("escape jump", e.jump),
                ("escape max_norm_ratio", e.max_norm_ratio),
            ] {
                if !(v.is_finite() && v > 0.0) {
                    return bad(what, v);
                }
            }
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
