//! A law's gap over one period of a forced state.

use crate::error::SettingsError;
use crate::forced::ForcedSystem;
use crate::fourier::Basis;
use crate::solve::Problem;

impl ForcedSystem {
    /// The gap samples of law `l` over one period at `x` (the basis' `N` instants).
    ///
    /// # Errors
    /// [`SettingsError::IndexOutOfRange`] for a law `l` the system does not have;
    /// [`SettingsError::Length`] for an `x` that is not a state of the system;
    /// [`SettingsError::NonFiniteResult`] for a history that overflows (a state near the ends
    /// of `f64`).
    pub fn gap_history(&self, x: &[f64], l: usize) -> Result<Vec<f64>, SettingsError> {
        let count = self.offsets.len();
        if l >= count {
            let (what, index) = ("unilateral law", l);
            return Err(SettingsError::IndexOutOfRange { what, index, count });
        }
        let expected = self.dimension();
        if x.len() != expected {
            let (what, got) = ("forced state", x.len());
            return Err(SettingsError::Length {
                what,
                got,
                expected,
            });
        }
        let mut gap = vec![0.0; self.basis.samples()];
        self.basis
            .synthesize(&self.observable(x, l, true, false), &mut gap);
        gap.iter_mut().for_each(|v| *v += self.offsets[l].0);
        // A state near the ends of `f64` (the open response to an amplitude of `f64::MAX`)
        // overflows the synthesis.
        if gap.iter().any(|v| !v.is_finite()) {
            return Err(SettingsError::NonFiniteResult {
                what: "gap history",
                omega: self.omega,
            });
        }
        Ok(gap)
    }
}
