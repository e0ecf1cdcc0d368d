//! Checks of a motion of a [`NonsmoothSystem`]: its frequency against the discretization's
//! range and its unknowns, shared by the post-processing and the branch methods.

use crate::check::check_frequency_named;
use crate::check::check_length;
use crate::check::check_unknowns_finite;
use crate::error::SettingsError;
use crate::fourier::Basis;
use crate::system::NonsmoothSystem;

/// Checks a fundamental frequency of `problem`:
/// [`check_frequency`](crate::check::check_frequency), and at most
/// [`Discretization::max_frequency`](crate::system::Discretization::max_frequency)
/// ([`SettingsError::FrequencyTooLarge`]).
pub(crate) fn check_frequency_of<B: Basis>(
    problem: &NonsmoothSystem<B>,
    omega: f64,
) -> Result<f64, SettingsError> {
    let max = problem.description().max_frequency();
    check_frequency_named("fundamental frequency", omega, max)
}

/// Checks a motion `x` of `problem` at `omega`: the length of `x`
/// ([`SettingsError::Length`]), the frequency ([`check_frequency_of`]) and finite unknowns
/// ([`SettingsError::NotPositive`] naming "unknowns (finite)").
pub(crate) fn check_motion<B: Basis>(
    problem: &NonsmoothSystem<B>,
    x: &[f64],
    omega: f64,
) -> Result<(), SettingsError> {
    check_length(x, problem.dimension())?;
    check_frequency_of(problem, omega)?;
    check_unknowns_finite(x)
}
