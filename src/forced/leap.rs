//! Moving a response curve on where its corrector cannot follow it: past a frequency where the
//! harmonic selection changes the equations, or past a step that collapsed at a kink of the
//! contact laws. The point is solved again at fixed frequency, then, failing that, from a
//! quarter of a grid step up to [`LEAP_STEPS`] grid steps further along the tangent, as a
//! sweep moves on past a failed value; each solve switches on the harmonics the selection adds
//! one at a time, and keeps those it switched on when a later one does not converge.

use crate::continuation::{Arclength, ContinuationProblem, Event, Point};
use crate::forced::ForcedSystem;
use crate::fourier::Basis;
use crate::solve::Solver;

/// The arclength driver of a response curve.
pub(super) type Driver<'a, 'p> = Arclength<'a, &'p mut ForcedSystem, &'a Solver>;

/// Grid steps in frequency a point may move on.
pub(super) const LEAP_STEPS: usize = 3;

/// The distances tried, in grid steps: from a quarter step, where a kink of the laws just
/// passed leaves the corrector's start close, to [`LEAP_STEPS`].
const LEAP_FRACTIONS: [f64; 5] = [0.25, 0.5, 1.0, 2.0, LEAP_STEPS as f64];

/// The curve continued from `x` at `omega`, where its tangent is `tangent`, with the selection
/// of the frequency reached, held before as `held`: at `omega + k step` along the tangent for
/// `k` of [`LEAP_FRACTIONS`] (and first `k = 0` if `first` is 0), from the tangent's
/// prediction and then from `x` itself. The point found becomes the
/// driver's current one, with [`Event::Jump`] when it moved in frequency; `None` leaves the
/// selection as it was (`held`, at `omega`).
pub(super) fn leap(
    driver: &mut Driver<'_, '_>,
    (x, omega, tangent): (&[f64], f64, &[f64]),
    held: &[usize],
    (step, first): (f64, usize),
) -> Option<Point> {
    let n = x.len();
    // Arclength along the tangent per grid step in frequency, at most the largest step.
    let per_step = (step / tangent[n].abs()).min(driver.options().ds_max);
    let here = (first == 0).then_some(0.0);
    let tries = (here.into_iter().chain(LEAP_FRACTIONS)).flat_map(|k| [(k, true), (k, false)]);
    for (k, predicted) in tries.filter(|&(k, predicted)| k > 0.0 || predicted) {
        let s = k * per_step;
        let at = omega + s * tangent[n];
        let shift = if predicted { s } else { 0.0 };
        let mut y: Vec<f64> = (x.iter().zip(tangent))
            .map(|(x, t)| x + shift * t)
            .collect();
        if !staged(driver, &mut y, at, held) {
            continue;
        }
        let moved: Vec<f64> = (y.iter().zip(x))
            .map(|(a, b)| a - b)
            .chain([at - omega])
            .collect();
        let ratio = driver.norm(&moved) / driver.options().ds;
        if let Ok(mut q) = driver.continue_along(y, at, tangent) {
            if k > 0.0 {
                q.events.push(Event::Jump { ratio });
            }
            return Some(q);
        }
    }
    let problem = driver.problem_mut();
    problem.set_parameter(omega);
    problem.set_dropped_coefficients(held.to_vec());
    None
}

/// Solves at `omega` from `x` (updated) with the selection of `omega`, switching on the
/// harmonics it adds to `held` one at a time, lowest first, each solve starting from the last
/// one's solution: harmonics switched on next to their resonances start from zero, and many
/// at once put Newton's first step far off. Where one does not converge, it and those after
/// it stay dropped and the last solution is kept; `false` if not even `held` converges.
fn staged(driver: &mut Driver<'_, '_>, x: &mut Vec<f64>, omega: f64, held: &[usize]) -> bool {
    let problem = driver.problem_mut();
    problem.set_parameter(omega);
    problem.reselect();
    let target = problem.dropped_coefficients();
    let basis = problem.basis();
    let mut added: Vec<usize> = (held.iter())
        .filter(|i| !target.contains(i))
        .map(|&i| basis.harmonic(i))
        .collect();
    added.sort_unstable();
    added.dedup();
    // The last selection solved, and its solution.
    let mut solved: Option<(Vec<usize>, Vec<f64>)> = None;
    for k in 0..=added.len() {
        // The target's coefficients, and those of the harmonics not added yet.
        let later = &added[k..];
        let problem = driver.problem_mut();
        let basis = problem.basis();
        let mut dropped: Vec<usize> = (held.iter().chain(&target))
            .copied()
            .filter(|&i| target.contains(&i) || later.contains(&basis.harmonic(i)))
            .collect();
        dropped.sort_unstable();
        dropped.dedup();
        problem.set_dropped_coefficients(dropped.clone());
        let mut y = x.clone();
        if driver.solve_at(&mut y, omega).is_err() {
            break;
        }
        *x = y.clone();
        solved = Some((dropped, y));
    }
    // A harmonic that does not converge stays dropped with those after it: the point moves
    // on with the harmonics switched on so far, and the next point tries the rest.
    match solved {
        Some((dropped, y)) => {
            driver.problem_mut().set_dropped_coefficients(dropped);
            *x = y;
            true
        }
        None => false,
    }
}
