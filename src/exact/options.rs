//! The options of an exact branch.

use crate::stability::{StabilityError, StabilityOptions};

/// Options of [`exact_branch`](super::exact_branch).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ExactOptions {
    /// The grid (`cells_per_travel`, a minimum here), differences, tolerance and spring
    /// update of the map, and the seed's correction: `corrections` fresh monodromies at most,
    /// within `max_energy_correction` and `max_displacement_correction` of the
    /// harmonic-balance point.
    pub stability: StabilityOptions,
    /// Corrector steps per point, chord and fresh (default 20).
    pub iterations: usize,
    /// Fresh monodromies per continued point where the chord stalls (default 2).
    pub refreshes: usize,
    /// How far, relative to the previous energy, an orbit's energy may leave the secant's
    /// prediction beyond the predicted change (default `0.02`).
    pub max_energy_jump: f64,
    /// How far, relative, the energy may move in a step without a secant (default `0.25`).
    pub first_step_jump: f64,
    /// Harmonic-balance points tried for the seed (default 8).
    pub seed_attempts: usize,
    /// Consecutive periods skipped before the walk ends (default 3).
    pub max_lost: usize,
    /// The largest energy the integrator's merges may remove over one period, relative to
    /// the motion's, for a verdict (default `1e-6`: the merges then move the state by about
    /// `sqrt(1e-6) = 1e-3` of its norm, the verdict's tolerance).
    pub max_removed_energy: f64,
}

impl Default for ExactOptions {
    fn default() -> Self {
        Self {
            stability: StabilityOptions::default(),
            iterations: 20,
            refreshes: 2,
            max_energy_jump: 0.02,
            first_step_jump: 0.25,
            seed_attempts: 8,
            max_lost: 3,
            max_removed_energy: 1e-6,
        }
    }
}

impl ExactOptions {
    pub(crate) fn check(&self) -> Result<(), StabilityError> {
        self.stability.check()?;
        let checks = [
            ("max_energy_jump", self.max_energy_jump),
            ("first_step_jump", self.first_step_jump),
            ("max_removed_energy", self.max_removed_energy),
        ];
        for (what, value) in checks {
            if !(value.is_finite() && value >= 0.0) {
                return Err(StabilityError::InvalidOption {
                    what,
                    expected: "finite and non-negative",
                    value,
                });
            }
        }
        let counts = [
            ("iterations", self.iterations),
            ("seed_attempts", self.seed_attempts),
            ("max_lost", self.max_lost),
        ];
        for (what, value) in counts {
            if value == 0 {
                return Err(StabilityError::InvalidOption {
                    what,
                    expected: "at least 1",
                    value: 0.0,
                });
            }
        }
        Ok(())
    }
}
