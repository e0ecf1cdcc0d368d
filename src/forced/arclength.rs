//! A response curve followed by pseudo-arclength through its folds.
//!
//! The harmonic selection switches harmonics on and off at fixed frequencies; a corrector
//! whose iterates cross such a frequency meets equations that jump, and the step size
//! collapses there. So the selection is held while each step is corrected, and moved between
//! points: where an accepted point lies in another band than the one held, the point is solved
//! again with the selection of its frequency ([`leap`]) and the curve goes on from there in
//! the same direction ([`Arclength::continue_from`]). A move that fails keeps the held
//! selection until the next point. A run whose step collapses (a kink of the contact laws,
//! where the semismooth corrector stalls a little above its tolerance however small the
//! step) moves on the same way before it gives up, and a run that comes back to a point it
//! already passed ends there ([`EndReason::Stalled`]): it would go round the same loop again.

use crate::continuation::{
    Arclength, ArclengthOptions, ContinuationProblem, EndReason, Point, Step,
};
use crate::error::Error;
use crate::forced::folds::folds;
use crate::forced::leap::{leap, Driver, LEAP_STEPS};
use crate::forced::point::{measured, ResponsePoint};
use crate::forced::ForcedSystem;
use crate::solve::Solver;

/// The points of an arclength run, its rejected steps and why it ended.
pub(super) struct Traced {
    pub(super) points: Vec<ResponsePoint>,
    pub(super) rejections: usize,
    pub(super) end: EndReason,
    /// Where a sweep left its branch (none on an arclength run).
    pub(super) jumps: Vec<f64>,
}

/// Follows the curve from `start` at the low end of `options.parameter_range`, measuring
/// every point with the selection it was solved with (energies over `e_g`). `step` is the
/// grid step in frequency of a sweep of as many steps: how far a point may move on at a time
/// ([`leap`]), and the resolution of the folds.
///
/// # Errors
/// As [`Arclength::new`].
pub(super) fn trace(
    problem: &mut ForcedSystem,
    solver: &Solver,
    start: Vec<f64>,
    options: ArclengthOptions,
    (e_g, step): (f64, f64),
) -> Result<Traced, Error> {
    problem.hold_selection(true);
    let traced = run(problem, solver, start, options, (e_g, step));
    problem.hold_selection(false);
    traced
}

fn run(
    problem: &mut ForcedSystem,
    solver: &Solver,
    start: Vec<f64>,
    options: ArclengthOptions,
    (e_g, step): (f64, f64),
) -> Result<Traced, Error> {
    let lo = options.parameter_range.0;
    let mut driver: Driver<'_, '_> = Arclength::new(&mut *problem, solver, start, lo, options)?;
    let mut points = Vec::new();
    // The last point kept and its tangent, `(x, Omega)` each.
    let mut last = (driver.state().to_vec(), driver.tangent().to_vec());
    let end = loop {
        let p = match driver.step() {
            Step::Accepted(p) if !reversed(&driver, &last.1) => settled(&mut driver, p, step),
            Step::Rejected(_) => continue,
            // A step that turned back on itself (accepted at the smallest step) or collapsed:
            // a kink of the laws or a band edge; the curve moves on past it.
            Step::Accepted(_) | Step::Finished(EndReason::StepBelowMinimum { .. }) => {
                let held = driver.problem_mut().dropped_coefficients();
                let (y, tangent) = &last;
                let (x, omega) = (&y[..y.len() - 1], y[y.len() - 1]);
                match leap(&mut driver, (x, omega, tangent), &held, (step, 1)) {
                    Some(q) => q,
                    None => {
                        break EndReason::Stalled {
                            failures: LEAP_STEPS,
                            parameter: omega,
                        }
                    }
                }
            }
            Step::Finished(end) => break end,
        };
        last = (driver.state().to_vec(), driver.tangent().to_vec());
        let point = measured(driver.problem_mut(), points.len(), &p, e_g);
        if let Some(earlier) = revisited(&points, &point) {
            break EndReason::Stalled {
                failures: points.len() - earlier,
                parameter: point.omega,
            };
        }
        points.push(point);
    };
    let omegas: Vec<f64> = points.iter().map(|p| p.omega).collect();
    let energies: Vec<f64> = points.iter().map(|p| p.energy).collect();
    for i in folds(&omegas, &energies, step) {
        points[i].fold = true;
    }
    let rejections = driver.rejections();
    Ok(Traced {
        points,
        rejections,
        end,
        jumps: Vec::new(),
    })
}

/// Points back from the newest that a run repeating itself may have left since it was at a
/// point: a leap solved again at the same frequency lands on it once more.
const RECENT: usize = 3;

/// The index of an earlier point, older than the last [`RECENT`], that `p` repeats (its
/// frequency and energy to `1e-9` relative): the run came back to where it was and, being
/// deterministic, would go round the same loop again.
fn revisited(points: &[ResponsePoint], p: &ResponsePoint) -> Option<usize> {
    let same = |a: f64, b: f64| (a - b).abs() <= 1e-9 * a.abs().max(b.abs());
    let older = points.len().saturating_sub(RECENT);
    (points[..older].iter()).position(|q| same(q.omega, p.omega) && same(q.energy, p.energy))
}

/// Whether the driver's tangent points back against `before` (an angle over 90 degrees in
/// the driver's norm): the curve reversed, where a fold turns it smoothly.
fn reversed(driver: &Driver<'_, '_>, before: &[f64]) -> bool {
    let sum: Vec<f64> = (driver.tangent().iter().zip(before))
        .map(|(a, b)| a + b)
        .collect();
    // Unit tangents: |a + b|^2 = 2 + 2 cos.
    driver.norm(&sum) < std::f64::consts::SQRT_2
}

/// `p`, solved again with the selection of its frequency when that differs from the one held
/// ([`leap`]).
fn settled(driver: &mut Driver<'_, '_>, p: Point, step: f64) -> Point {
    let problem = driver.problem_mut();
    problem.set_parameter(p.parameter);
    if !problem.selection_moved() {
        return p;
    }
    let held = problem.dropped_coefficients();
    let tangent = driver.tangent().to_vec();
    leap(driver, (&p.x, p.parameter, &tangent), &held, (step, 0)).unwrap_or(p)
}
