//! The corrector of an exact branch: chord steps with the latest factored monodromy, a fresh
//! one only where they stall.

use crate::solve::norm;
use crate::stability::monodromy::PeriodMap;
use crate::stability::shooting::{line_step, residual, PseudoInverse};
use crate::stability::StabilityError;

/// A chord step must divide the defect by at least this, or the matrix is refreshed: the map
/// is linear between events, so a matrix of the right piece converges in one or two steps.
const CONTRACTION: f64 = 0.5;

/// Limits of one correction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Limits {
    /// Steps in all (chord and Newton).
    pub iterations: usize,
    /// Fresh monodromies.
    pub refreshes: usize,
    /// The differences' step relative to the state.
    pub relative_step: f64,
    /// The defect `|P(x) - x| / |x|` at which the correction stops.
    pub tolerance: f64,
    /// The largest norm of a step (the trust radius it starts from).
    pub max_step: f64,
}

/// Where a correction ended.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Outcome {
    pub x: Vec<f64>,
    /// `|P(x) - x| / |x|` at the start.
    pub initial_defect: f64,
    /// `|P(x) - x| / |x|` at the end.
    pub defect: f64,
    /// Steps taken.
    pub iterations: usize,
    /// Fresh monodromies computed.
    pub refreshes: usize,
}

/// Corrects `x0` towards `P(x) = x` by steps `(M - I) d = x - P(x)`, with `M`
/// the monodromy factored in `jacobian` (the previous orbit's, or `None`). Where a step does
/// not contract the defect by [`CONTRACTION`], `M` is recomputed at the current state (at
/// most `limits.refreshes` times); `jacobian` holds the last matrix used. Steps are
/// Levenberg–Marquardt steps within a trust radius, at most `limits.max_step`: near a point
/// the map has other periodic orbits, and a long step from a prediction in another piece of
/// the map lands on one of them. Where a fresh matrix's step fails, the radius shrinks.
pub(crate) fn correct(
    map: &PeriodMap,
    x0: &[f64],
    jacobian: &mut Option<PseudoInverse>,
    limits: &Limits,
) -> Result<Outcome, StabilityError> {
    let mut x = x0.to_vec();
    let (mut r, mut trial_r) = (Vec::new(), Vec::new());
    let mut defect = residual(map, &x, &mut r)? / norm(&x);
    let initial_defect = defect;
    let (mut iterations, mut refreshes) = (0, 0);
    // Whether the matrix was computed at the current state: a step it cannot take ends.
    let mut fresh = false;
    let mut stale = false;
    // The trust radius: a fresh matrix whose step fails is tried again within a quarter of
    // it (the step turns towards the steepest descent of the defect), and a step that
    // succeeds restores it.
    let mut radius = limits.max_step;
    while defect > limits.tolerance && iterations < limits.iterations {
        if jacobian.is_none() || stale {
            if refreshes >= limits.refreshes {
                break;
            }
            let monodromy = map.monodromy(&x, limits.relative_step)?;
            *jacobian = Some(PseudoInverse::of_monodromy(&monodromy)?);
            (refreshes, fresh) = (refreshes + 1, true);
        }
        let Some(inverse) = jacobian.as_ref() else {
            break;
        };
        let rhs: Vec<f64> = r.iter().map(|v| -v).collect();
        let d = inverse.solve_within(&rhs, radius);
        iterations += 1;
        match line_step(map, &x, &d, defect, &mut trial_r)? {
            Some((next, next_defect)) => {
                stale = next_defect > CONTRACTION * defect;
                (x, defect, fresh, radius) = (next, next_defect, false, limits.max_step);
                std::mem::swap(&mut r, &mut trial_r);
            }
            None if fresh => {
                radius = radius.min(norm(&d)) / 4.0;
                if radius <= limits.tolerance * norm(&x) {
                    break;
                }
            }
            None => stale = true,
        }
    }
    Ok(Outcome {
        x,
        initial_defect,
        defect,
        iterations,
        refreshes,
    })
}
