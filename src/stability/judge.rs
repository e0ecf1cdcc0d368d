//! The verdict of a corrected state from its monodromy: shared by [`floquet_of_state`] and
//! the exact branches of [`crate::exact`], which correct their states themselves.
//!
//! [`STEP_FACTORS`]: super::STEP_FACTORS
//!
//! [`floquet_of_state`]: super::floquet_of_state

use super::floquet::{self, MapShape, Multiplier, TrivialPair};
use super::monodromy::{Monodromy, PeriodMap};
use super::shooting::Corrected;
use super::{Floquet, StabilityError, StabilityOptions, UnresolvedReason, RESOLVED_DEFECT};

/// Why the correction `corrected` does not count, in the order of the checks: its state is
/// not periodic (defect above [`RESOLVED_DEFECT`]), or the periodic orbit it reached has
/// another energy or displacement than the point's (beyond
/// [`StabilityOptions::max_energy_correction`] and
/// [`StabilityOptions::max_displacement_correction`]). `None` when it counts.
pub(crate) fn correction_failure(
    corrected: &Corrected,
    options: &StabilityOptions,
) -> Option<UnresolvedReason> {
    let periodic = corrected.defect <= RESOLVED_DEFECT;
    let energy_kept = corrected.energy_change.abs() <= options.max_energy_correction;
    let displacement_kept = corrected.displacement_shift <= options.max_displacement_correction;
    if !periodic {
        Some(UnresolvedReason::NotPeriodic {
            defect: corrected.defect,
            bound: RESOLVED_DEFECT,
            iterations: corrected.iterations,
            corrections: options.corrections,
        })
    } else if !energy_kept {
        Some(UnresolvedReason::EnergyMoved {
            change: corrected.energy_change,
            bound: options.max_energy_correction,
        })
    } else if !displacement_kept {
        Some(UnresolvedReason::DisplacementMoved {
            change: corrected.displacement_shift,
            bound: options.max_displacement_correction,
        })
    } else {
        None
    }
}

/// [`correction_failure`], with a state that is not periodic because the grid cannot hold
/// its period's waves named [`UnresolvedReason::OffGrid`]: where the share of the energy the
/// cell means remove after one period of the best state puts its defect (energy norm) above
/// [`RESOLVED_DEFECT`] whatever the correction does next. One march of `map`.
pub(crate) fn correction_failure_on(
    map: &PeriodMap,
    corrected: &Corrected,
    options: &StabilityOptions,
) -> Result<Option<UnresolvedReason>, StabilityError> {
    let failure = correction_failure(corrected, options);
    let Some(UnresolvedReason::NotPeriodic { defect, bound, .. }) = failure else {
        return Ok(failure);
    };
    let projected = map.projected_share(&corrected.x)?;
    let floor = 1.0 - (1.0 - projected.min(1.0)).sqrt();
    Ok(if floor > bound {
        Some(UnresolvedReason::OffGrid {
            defect,
            projected,
            bound,
        })
    } else {
        failure
    })
}

/// The multipliers and verdict of the state `corrected` of `map`, from `monodromy` (at the
/// corrected state where `failure` is `None`, at the point's own state otherwise), without
/// the `spurious` exact multipliers 1 of the coordinates. Where the trivial pair is missed,
/// the differences are retried with the steps `retries` (relative to the options' step; the
/// shooting correction's are [`STEP_FACTORS`]) and the best pair kept.
pub(crate) fn judge(
    map: &PeriodMap,
    corrected: &Corrected,
    monodromy: &Monodromy,
    failure: Option<UnresolvedReason>,
    options: &StabilityOptions,
    retries: &[f64],
) -> Result<Floquet, StabilityError> {
    let spurious = map.coordinates.spurious_unit_multipliers();
    let periodic = failure.is_none();
    let assess = |monodromy: &Monodromy| -> Result<(Vec<Multiplier>, TrivialPair), StabilityError> {
        let mut multipliers = floquet::eigenvalues(monodromy)?;
        floquet::remove_nearest_one(&mut multipliers, spurious);
        // A miss the grid's damping explains needs no perturbation (an eigenvector problem).
        let damped = floquet::grid_damping(&multipliers, options.tolerance)
            .is_some_and(|d| d <= options.max_damping);
        let pair = floquet::trivial_pair(
            monodromy,
            &multipliers,
            spurious,
            options.tolerance,
            periodic && !damped,
        )?;
        Ok((multipliers, pair))
    };
    let (mut multipliers, mut pair) = assess(monodromy)?;
    // The differences must reproduce the known multiplier 1 of the time shift. Where they
    // miss it, a step that adds or removes a near-grazing impact made them inaccurate: a
    // ten times larger step steps over it, a ten times smaller one stays within the piece.
    if periodic {
        for factor in retries {
            if pair.found(options.tolerance) {
                break;
            }
            let other = map.monodromy(&corrected.x, factor * options.relative_step)?;
            let other = assess(&other)?;
            if other.1.miss() < pair.miss() {
                (multipliers, pair) = other;
            }
        }
    }
    let shape = MapShape {
        dimension: map.coordinates.len(),
        dt: map.template.grid().dt(),
        period: map.period,
    };
    finite(floquet::verdict(
        multipliers,
        (options.tolerance, options.max_damping),
        pair,
        failure,
        corrected,
        shape,
    ))
}

/// `floquet`, or [`StabilityError::NonFiniteResult`] naming its first number that is NaN or
/// infinite. A state scaled towards the ends of `f64` (by `1e300` or `1e-300`) has norms and
/// energies that overflow or underflow, and its defects and corrections come out NaN: no
/// verdict, unresolved or not, can be drawn from them.
fn finite(floquet: Floquet) -> Result<Floquet, StabilityError> {
    let numbers = [
        ("initial periodicity defect", floquet.initial_defect),
        ("periodicity defect", floquet.periodicity_defect),
        ("correction", floquet.correction),
        ("displacement correction", floquet.displacement_correction),
        ("energy correction", floquet.energy_correction),
        ("largest multiplier modulus", floquet.max_modulus),
    ];
    match numbers.into_iter().find(|(_, v)| !v.is_finite()) {
        Some((what, value)) => Err(StabilityError::NonFiniteResult { what, value }),
        None => Ok(floquet),
    }
}
