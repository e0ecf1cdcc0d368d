//! Continuation in the number of harmonics: the points of a run at `m'` harmonics lifted to
//! `m > m'` harmonics and solved there, each at its own frequency.
//!
//! The truncated equations at `m` harmonics have internal resonances wherever a harmonic
//! `k <= m` of the motion meets a linear frequency; the coarser truncation has fewer of them
//! in the way of a branch, so that its continuation can pass where the finer one stalls or
//! jumps. The coefficients `0..=m'` of both layouts coincide
//! ([`Layout`](crate::system::Layout)), so a coarse point is a guess at `m` with its higher
//! harmonics zero, and the solve at `m` adds what the coarse truncation missed.

use crate::branches::backbone::TRIVIAL_ENERGY;
use crate::branches::plan::QuietRun;
use crate::branches::point::{BackbonePoint, PointStatus};
use crate::branches::request::Request;
use crate::branches::result::{Annotator, ModeBranches};
use crate::continuation::{ContinuationProblem, EndReason, Event};
use crate::error::{Error, SettingsError};
use crate::fourier::Basis;
use crate::modal::energy;
use crate::solve::{norm, NonlinearSolver, Problem, SmoothingHomotopy, SolveInfo, Solver};
use crate::system::NonsmoothSystem;
use std::ops::ControlFlow;

/// `run` lifted to the harmonics of `request`: every converged point of `run` (a result of
/// [`compute`](crate::branches::compute) or of a lift) lifted to
/// `request.settings.harmonics` harmonics, its higher harmonics zero, and solved there at
/// its own frequency, by the request's solver (full Newton by default) and then inside a
/// [`SmoothingHomotopy`], from the lifted point and then from the solution of the point
/// before it on the same branch. The points are annotated as the request asks (character,
/// label, time-domain check, multipliers) and keep the run's steps, branches and jumps; a
/// point that no solve takes to a motion (energy above [`TRIVIAL_ENERGY`] `E_g`) holds its
/// lifted guess, with the last failure as its status. The result keeps the run's method,
/// [`Method::Auto`](crate::branches::Method::Auto)'s choice and end reason; the request's
/// method is not used. This is continuation in the number of harmonics, point by point:
/// [`Method::Auto`](crate::branches::Method::Auto) uses it where its runs fall short
/// ([`AutoChoice::Lifted`](crate::branches::AutoChoice::Lifted)); a convergence study in `m`
/// can chain it.
///
/// # Errors
/// Invalid settings, and [`SettingsError::LiftToFewerHarmonics`] for a request with fewer
/// harmonics than the run.
///
/// # Example
/// ```
/// use nonsmooth_modes::branches::{compute, lift, Request};
/// use nonsmooth_modes::reference::clamped_bar_with_obstacle;
///
/// let system = clamped_bar_with_obstacle(1e-3)?;
/// let coarse = compute(&system, &Request::new(1).harmonics(10))?;
/// let fine = lift(&coarse, &Request::new(1).harmonics(20))?;
/// assert_eq!(fine.points.len(), coarse.converged().count());
/// assert!(fine.converged().count() > 100);
/// # Ok::<(), nonsmooth_modes::Error>(())
/// ```
pub fn lift(run: &ModeBranches, request: &Request) -> Result<ModeBranches, Error> {
    let (from, to) = (
        run.problem().basis().harmonics(),
        request.settings.harmonics,
    );
    if to < from {
        return Err(SettingsError::LiftToFewerHarmonics { from, to }.into());
    }
    let problem = NonsmoothSystem::new(run.problem().system(), request.settings)?;
    let floor = TRIVIAL_ENERGY * run.grazing_energy;
    let coarse = (&run.points[..], run.grazing_energy, floor);
    let (lifted, problem) = lifted_run(
        coarse,
        (run.end.clone(), run.rejected_steps),
        request,
        problem,
    );
    let quiet = |_: &BackbonePoint| ControlFlow::Continue(());
    let mut annotator = Annotator::new(problem, request, quiet);
    let end = annotator.replay(lifted.points, lifted.end);
    Ok(annotator.finish((run.method, run.auto), lifted.e_g, end, lifted.rejected))
}

/// The points of a coarse run `(points, E_g, floor)` lifted to `problem`'s harmonics
/// ([`lifted_points`]) and annotated as `request` asks, as a run that ended as the coarse
/// one did (`end`, with its rejected steps); gives the problem back.
pub(crate) fn lifted_run(
    (points, e_g, floor): (&[BackbonePoint], f64, f64),
    (end, rejected): (EndReason, usize),
    request: &Request,
    mut problem: NonsmoothSystem,
) -> (QuietRun, NonsmoothSystem) {
    let solver = request.solver.unwrap_or_default();
    let points = lifted_points(points, &mut problem, &solver, (e_g, floor));
    let quiet = |_: &BackbonePoint| ControlFlow::Continue(());
    let mut annotator = Annotator::unchecked(problem, request, quiet);
    for point in points {
        // A quiet observer never stops the run.
        let _ = annotator.point(point);
    }
    let (points, problem) = annotator.into_parts();
    let run = QuietRun::new(points, (e_g, end, rejected), &problem);
    (run, problem)
}

/// Each converged point of `points` (a run on `problem`'s system at fewer harmonics), lifted
/// to `problem`'s harmonics and solved there at its frequency: by `solver`, then by `solver`
/// inside a [`SmoothingHomotopy`], from the lifted point, then from the solution of the point
/// before it on the same branch. A solution of energy at most `floor` is the state of rest;
/// energies are normalised by `e_g`. The points keep their step, step size, branch and jumps
/// (the folds and grazings found on the coarse truncation are not carried over); a point
/// that no solve takes to a motion holds its lifted guess, with the last failure.
pub(crate) fn lifted_points(
    points: &[BackbonePoint],
    problem: &mut NonsmoothSystem,
    solver: &Solver,
    (e_g, floor): (f64, f64),
) -> Vec<BackbonePoint> {
    let homotopy = SmoothingHomotopy::new(solver);
    let solvers: [&dyn NonlinearSolver; 2] = [solver, &homotopy];
    let mut before: Option<(usize, Vec<f64>)> = None;
    let mut lifted = Vec::new();
    for coarse in points.iter().filter(|p| p.converged()) {
        let mut guess = vec![0.0; problem.dimension()];
        let shared = coarse.x.len().min(guess.len());
        guess[..shared].copy_from_slice(&coarse.x[..shared]);
        let neighbour = before.take().filter(|(branch, _)| *branch == coarse.branch);
        problem.set_parameter(coarse.omega);
        let guesses = std::iter::once(guess.clone()).chain(neighbour.map(|(_, x)| x));
        let solved = solve_first(problem, &solvers, guesses, (coarse.omega, floor));
        let (x, status, (iterations, residual_norm), energy) = match solved {
            Ok((x, info, energy)) => {
                let solve = (info.iterations, info.residual_norm);
                (x, PointStatus::Converged, solve, energy)
            }
            Err(status) => {
                let energy = energy(problem.system(), problem.basis(), &guess, coarse.omega);
                // The solver's norm is of its last iterate: the guess kept needs its own.
                let mut residual = vec![0.0; guess.len()];
                problem.residual(&guess, &mut residual);
                (guess, status, (0, norm(&residual)), energy)
            }
        };
        let status = status.with_energy(energy, energy / e_g);
        let converged = status == PointStatus::Converged;
        if converged {
            before = Some((coarse.branch, x.clone()));
        }
        let jumps = coarse
            .events
            .iter()
            .filter(|e| matches!(e, Event::Jump { .. }));
        lifted.push(BackbonePoint {
            step: coarse.step,
            period: coarse.period,
            omega: coarse.omega,
            energy,
            energy_normalized: energy / e_g,
            status,
            residual_norm,
            iterations,
            x,
            step_size: coarse.step_size,
            events: jumps.cloned().collect(),
            branch: coarse.branch,
            time_domain: None,
            check: None,
            character: None,
            label: None,
            stability: None,
            hill: None,
        });
    }
    lifted
}

/// The first solution of `problem` (its parameter set) that one of `solvers`, tried in turn
/// on each of `guesses`, reaches with an energy above `floor` at `omega`: the solution, what
/// its solve took and its energy; or the status of the last
/// failure.
fn solve_first(
    problem: &mut NonsmoothSystem,
    solvers: &[&dyn NonlinearSolver],
    guesses: impl IntoIterator<Item = Vec<f64>>,
    (omega, floor): (f64, f64),
) -> Result<(Vec<f64>, SolveInfo, f64), PointStatus> {
    let mut failure = None;
    for guess in guesses {
        for solver in solvers {
            let mut x = guess.clone();
            match solver.solve(problem, &mut x) {
                Ok(info) => {
                    let e = energy(problem.system(), problem.basis(), &x, omega);
                    if e > floor {
                        return Ok((x, info, e));
                    }
                    failure = Some(PointStatus::CollapsedToRest);
                }
                Err(e) => failure = Some(PointStatus::SolverFailed(e)),
            }
        }
    }
    // Without a guess nothing was solved: the point is refused.
    Err(failure.unwrap_or(PointStatus::Rejected))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::branches::backbone::{backbone_with, BackboneOptions, PeriodGrid};
    use crate::reference::clamped_bar_with_obstacle;
    use crate::system::HarmonicBalanceSettings;

    /// A run of the clamped bar.
    struct Run {
        points: Vec<BackbonePoint>,
        grazing_energy: f64,
        problem: NonsmoothSystem,
    }

    impl Run {
        fn converged(&self) -> impl Iterator<Item = &BackbonePoint> {
            self.points.iter().filter(|p| p.converged())
        }
    }

    /// The clamped bar's period grid over `3.9 -> 3.5` at `harmonics`.
    fn clamped_run(harmonics: usize) -> (Run, BackboneOptions) {
        let system = clamped_bar_with_obstacle(1e-3).unwrap();
        let grid = BackboneOptions {
            grid: PeriodGrid {
                start: 3.9,
                end: 3.5,
                steps: 5,
            },
            ..BackboneOptions::for_mode(&system, 1, 1).unwrap()
        };
        let settings = HarmonicBalanceSettings {
            harmonics,
            ..HarmonicBalanceSettings::default()
        };
        let mut points = Vec::new();
        let see = |p| {
            points.push(p);
            ControlFlow::Continue(())
        };
        let (grazing_energy, _) =
            backbone_with(&system, settings, &grid, Solver::default(), see).unwrap();
        let problem = NonsmoothSystem::new(&system, settings).unwrap();
        let run = Run {
            points,
            grazing_energy,
            problem,
        };
        (run, grid)
    }

    /// The clamped bar's points at 10 harmonics, lifted to 20, are the points the grid at
    /// 20 harmonics finds at the same periods; a jump is carried over with its branch, a
    /// fold is not, and a point that did not converge is not lifted.
    #[test]
    fn lifted_points_are_the_finer_runs_points() {
        let ((coarse, grid), (fine, _)) = (clamped_run(10), clamped_run(20));
        let mut points = coarse.points.clone();
        points[2].events = vec![Event::Jump { ratio: 9.0 }, Event::Fold { parameter: 1.0 }];
        points[2].branch = 1;
        let mut failed = points[4].clone();
        failed.status = PointStatus::Rejected;
        points.push(failed);
        let mut problem = fine.problem.clone();
        let e_g = coarse.grazing_energy;
        let floor = grid.trivial_energy * e_g;
        let lifted = lifted_points(&points, &mut problem, &Solver::default(), (e_g, floor));
        assert_eq!(lifted.len(), 5);
        assert_eq!(fine.converged().count(), 5);
        for (l, f) in lifted.iter().zip(fine.converged()) {
            assert!(l.converged(), "step {} converged", l.step);
            assert_eq!((l.period, l.omega), (f.period, f.omega));
            assert!((l.energy - f.energy).abs() <= 1e-8 * f.energy);
            assert!((l.energy_normalized - l.energy / e_g).abs() <= 1e-15 * l.energy_normalized);
            let gap = l.x.iter().zip(&f.x).map(|(a, b)| (a - b).abs());
            let scale = f.x.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
            assert!(gap.fold(0.0, f64::max) <= 1e-8 * scale);
        }
        assert_eq!(lifted[2].events, vec![Event::Jump { ratio: 9.0 }]);
        assert_eq!(lifted[2].branch, 1);
        assert!(lifted
            .iter()
            .all(|p| p.label.is_none() && p.residual_norm.is_finite()));
    }

    /// A point that no solve takes to a motion keeps its lifted guess, finite, and says why.
    #[test]
    fn a_point_that_does_not_solve_keeps_its_guess() {
        let ((coarse, _), (fine, _)) = (clamped_run(10), clamped_run(20));
        let mut problem = fine.problem.clone();
        let e_g = coarse.grazing_energy;
        // Every motion lies below an infinite floor: each solve collapses "to rest".
        let points = &coarse.points[..1];
        let lifted = lifted_points(points, &mut problem, &Solver::default(), (e_g, f64::MAX));
        assert_eq!(lifted[0].status, PointStatus::CollapsedToRest);
        assert!(!lifted[0].converged());
        let n = points[0].x.len();
        assert_eq!(lifted[0].x[..n], points[0].x[..]);
        assert!(lifted[0].x[n..].iter().all(|&v| v == 0.0));
        assert!(lifted[0].residual_norm.is_finite() && lifted[0].residual_norm > 0.0);
    }
}
