//! Validation of model parameters, shared by bars, boundary conditions and the assembly
//! builder, and the checks of a motion's frequency, length and finiteness that need no
//! system, shared by every entry point so that each refuses the same inputs with the same
//! errors.

use crate::error::ModelError;
use crate::error::SettingsError;
use crate::fourier::frequency_of_period;

/// Checks that `value` is strictly positive and finite; the error names the parameter `what`
/// and carries the rejected value.
pub(crate) fn positive(what: &'static str, value: f64) -> Result<f64, ModelError> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(ModelError::NotPositive { what, value })
    }
}

/// The smallest fundamental frequency `Omega` accepted by the post-processing (about
/// `3.5e-308`): `2 pi / f64::MAX`, rounded up so that the period `2 pi / Omega` is finite.
/// It is a normal `f64`, so every frequency at or above it is too (a subnormal one has lost
/// precision).
pub const MIN_FREQUENCY: f64 = frequency_of_period(f64::MAX) * (1.0 + 4.0 * f64::EPSILON);

/// Checks a fundamental frequency: positive and finite ([`SettingsError::NotPositive`]) and
/// at least [`MIN_FREQUENCY`] ([`SettingsError::FrequencyTooSmall`]).
pub(crate) fn check_frequency(omega: f64) -> Result<f64, SettingsError> {
    check_frequency_named("fundamental frequency", omega, f64::INFINITY)
}

/// Checks a frequency named `what`: positive and finite ([`SettingsError::NotPositive`]), at
/// least [`MIN_FREQUENCY`] ([`SettingsError::FrequencyTooSmall`]) and at most `max`
/// ([`SettingsError::FrequencyTooLarge`]).
pub(crate) fn check_frequency_named(
    what: &'static str,
    omega: f64,
    max: f64,
) -> Result<f64, SettingsError> {
    if !(omega.is_finite() && omega > 0.0) {
        Err(SettingsError::NotPositive { what, value: omega })
    } else if omega < MIN_FREQUENCY {
        Err(SettingsError::FrequencyTooSmall {
            what,
            omega,
            min: MIN_FREQUENCY,
        })
    } else if omega > max {
        Err(SettingsError::FrequencyTooLarge { what, omega, max })
    } else {
        Ok(omega)
    }
}

/// Checks that the unknowns `x` have length `expected` ([`SettingsError::Length`]).
pub(crate) fn check_length(x: &[f64], expected: usize) -> Result<(), SettingsError> {
    if x.len() == expected {
        Ok(())
    } else {
        Err(SettingsError::Length {
            what: "unknowns",
            got: x.len(),
            expected,
        })
    }
}

/// Checks that the unknowns `x` are finite ([`SettingsError::NotPositive`] naming
/// "unknowns (finite)").
pub(crate) fn check_unknowns_finite(x: &[f64]) -> Result<(), SettingsError> {
    match x.iter().find(|v| !v.is_finite()) {
        Some(v) => Err(SettingsError::NotPositive {
            what: "unknowns (finite)",
            value: *v,
        }),
        None => Ok(()),
    }
}

/// Checks that every value of `values` is finite: [`SettingsError::NonFiniteResult`]
/// naming `what` otherwise.
pub(crate) fn check_finite<'v>(
    what: &'static str,
    omega: f64,
    values: impl IntoIterator<Item = &'v f64>,
) -> Result<(), SettingsError> {
    if values.into_iter().all(|v| v.is_finite()) {
        Ok(())
    } else {
        Err(SettingsError::NonFiniteResult { what, omega })
    }
}
