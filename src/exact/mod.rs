//! Exact nonsmooth modes: branches of periodic orbits of the exact one-period map of the
//! time-domain integrator, continued in the period, with a Floquet verdict at every point.
//!
//! # Why
//!
//! Harmonic balance truncates: its strain jumps carry a Gibbs oscillation, so its points are
//! only near periodic orbits of the exact map, and correcting each one on its own
//! ([`stability`](crate::stability)) converges where the truncation happens to be mild. An
//! exact branch corrects **one** harmonic-balance point (the seed) and then continues the
//! exact orbit itself: each point starts from the previous exact orbit, so the corrector
//! starts within the step's change of the motion, not within the truncation's error.
//!
//! # The map and its grid
//!
//! The map is [`stability`](crate::stability)'s `P_T: X(0) -> X(T)` in the same coordinates
//! (cell means of `c u_x` and `u_t`, free end displacements), at an instant where every
//! contact is open. The whole branch uses **one grid** ([`ExactOptions::stability`]'s
//! `cells_per_travel` is a minimum): the cell count is the smallest from that minimum to
//! twice it that makes every requested period a whole number of steps, so that the
//! coordinates never change along the branch (the monodromy of one point is the corrector's
//! matrix at the next) and no period ends with a fractional step (which would project the
//! waves onto the cells and blur the multipliers). Where no count makes them whole, the
//! periods are rounded to whole steps ([`ExactPoint::requested_period`] keeps the grid's);
//! the clamped bar's grid `3.95 -> 3.05` is whole at 200 cells, the free–free bar's
//! `1.975 -> 1.525` at 400.
//!
//! # Predictor and corrector
//!
//! The period is the continuation parameter; the energy is measured on the orbit found. The
//! predictor is the secant through the last two orbits in `(X, T)` (the previous orbit alone
//! after a seed or a gap). The corrector takes Levenberg–Marquardt steps of
//! `(M - I) d = X - P_T(X)` within a trust radius, with `M` the **previous orbit's
//! monodromy**, factored once (a chord method): each step costs one march instead of the
//! `2 n` of a fresh matrix. Where a step does not halve the defect, `M` is recomputed at the
//! current state (at most [`ExactOptions::refreshes`] times per point). The step has no
//! component along the null direction of `M - I`, the time shift (so no phase condition is
//! needed), and the trust radius damps it first along the small singular values: the family
//! direction and the waves that free flight carries nearly back onto themselves over the
//! period, a continuum with no gap where a cutoff could tell them from real directions;
//! moving far along them would change the motion rather than correct it. A point counts when its defect
//! `|P(X) - X| / |X|` is at most [`RESOLVED_DEFECT`](crate::stability::RESOLVED_DEFECT).
//!
//! The section drifts along the orbit from point to point (the steps have no phase
//! condition); where its smallest gap falls below a quarter of the law's gap, the state is
//! moved to the widest-open instant of its orbit again before its monodromy is computed.
//!
//! # Events: another family, a lost branch
//!
//! A corrected orbit whose energy leaves the predicted energy (the secant's; without a
//! secant, the previous energy times harmonic balance's ratio between the two periods) by
//! more than the predicted change plus [`ExactOptions::max_energy_jump`] (by more than
//! [`ExactOptions::first_step_jump`] where nothing predicts a change) has jumped onto another
//! family of periodic orbits (they meet at branch points, and at a fixed period the map has
//! several near one another): it is corrected once more from the previous orbit with a fresh
//! matrix. If it still jumps, or the correction fails, a step over more than one step of the
//! grid is **halved** (an orbit at the whole number of steps half-way, not reported, then on
//! from it). Otherwise the branch is **lost** at that period and reseeded from the
//! harmonic-balance point there (a new [`BackbonePoint::branch`] index and an
//! [`Event::Jump`](crate::continuation::Event::Jump) on its first point); where that fails
//! too, the period is skipped with its reason ([`ExactBranch::skipped`]).
//!
//! The walk goes in segments: a seed at the first period whose harmonic-balance point
//! corrects to an orbit within the seed bounds of
//! [`StabilityOptions`](crate::stability::StabilityOptions) (energy and displacement,
//! [`ExactOptions::seed_attempts`] tries), the walk back from it to the segment's first
//! period, then forward until [`ExactOptions::max_lost`] periods in a row are skipped; the
//! next segment is sought after them. [`ExactBranch::end`] says why the last one ended
//! ([`ExactEnd::Lost`], [`ExactEnd::NoSeed`]); every point found is kept.
//!
//! # The verdict
//!
//! One monodromy per point, at the corrected orbit: its eigenvalues give the verdict exactly
//! as [`floquet_of_state`](crate::stability::floquet_of_state) does (trivial pair,
//! tolerance, the grid's damping on periods of an odd number of steps; no other
//! differences' steps: each costs a monodromy), and its factored `M - I` is the next point's
//! corrector.
//! Where the integrator merged wave pieces over the period (incommensurate travel times,
//! chattering), the energy removed is reported ([`ExactPoint::removed_energy`]) and the point
//! gets a verdict only below [`ExactOptions::max_removed_energy`]
//! ([`UnresolvedReason::Merged`](crate::stability::UnresolvedReason::Merged) beyond).
//!
//! # Cost
//!
//! Per point: one monodromy (`2 n` marches of a period, parallel with the `parallel`
//! feature), its eigenvalues and one singular value decomposition, a few single marches for
//! the chord steps, and a fresh monodromy where the chord stalls. The seed costs a shooting
//! correction (several monodromies).

mod corrector;
mod grid;
mod point;
mod types;
mod walk;

pub use types::{ExactBranch, ExactEnd, ExactOptions, ExactPoint, LossReason, Skipped};

use crate::branches::{
    compute, BackboneOptions, BackbonePoint, Method, ModeBranches, PeriodGrid, Request,
};
use crate::continuation::linspace;
use crate::error::{Error, SettingsError};
use crate::stability::{StabilityError, MAX_MARCH_STEPS};
use crate::system::BarSystem;
use crate::verify::{Model, State};
use walk::{Seed, Walker};

/// The period grid of `request`: its method's, or the system's default for the mode
/// ([`BackboneOptions::for_mode`]) where the method carries none (arclength, energy).
fn period_grid(system: &BarSystem, request: &Request) -> Result<PeriodGrid, Error> {
    Ok(match request.method {
        Method::Auto(Some(o)) | Method::PeriodGrid(o) | Method::GenuineSubharmonic(o) => o.grid,
        _ => BackboneOptions::for_mode(system, request.mode, request.subharmonic)?.grid,
    })
}

/// The exact branch of `request`'s mode over its period grid: the harmonic-balance run of
/// `request` ([`compute`], without its stability and Hill exponents), then
/// [`exact_branch_from`] it.
///
/// # Errors
/// A bad grid ([`SettingsError::Range`]) or options ([`StabilityError::InvalidOption`])
/// before anything is computed; those of [`compute`]; those of [`exact_branch_from`].
pub fn exact_branch(
    system: &BarSystem,
    request: &Request,
    options: &ExactOptions,
) -> Result<ExactBranch, Error> {
    let grid = period_grid(system, request)?;
    grid.validate().map_err(SettingsError::from)?;
    options.check()?;
    let harmonic_balance = Request {
        stability: None,
        hill: None,
        ..request.clone()
    };
    exact_branch_from(&compute(system, &harmonic_balance)?, &grid, options)
}

/// The exact branch over `grid`, seeded by the converged points of the harmonic-balance run
/// `run` (the point nearest each grid period, within half a step). See the
/// [module docs](self).
///
/// # Errors
/// [`SettingsError::Range`] for a bad grid; [`StabilityError::InvalidOption`] for bad
/// options; [`StabilityError::TooLarge`] and [`StabilityError::TooCostly`] for a grid whose
/// matrices or marches exceed the limits of [`stability`](crate::stability);
/// [`VerifyError`](crate::verify::VerifyError) for a system the integrator cannot march.
/// A seed or a point that fails is no error: the branch says why
/// ([`ExactBranch::end`], [`ExactBranch::skipped`]).
pub fn exact_branch_from(
    run: &ModeBranches,
    grid: &PeriodGrid,
    options: &ExactOptions,
) -> Result<ExactBranch, Error> {
    grid.validate().map_err(SettingsError::from)?;
    options.check()?;
    let requested = linspace(grid.start, grid.end, grid.steps)?;
    let problem = run.problem();
    let (system, basis) = (problem.system(), problem.basis());
    let model = Model::from_system(system)?;
    let branch = grid::branch_grid(&model, &requested, options.stability.cells_per_travel)?;
    let dt = branch.grid.dt();
    let coordinates = crate::stability::coordinates::Coordinates::new(&model, &branch.grid);
    crate::stability::check_dimension(&coordinates, options.stability.cells_per_travel)?;
    let longest = branch.periods.iter().fold(0.0f64, |m, t| m.max(*t));
    let steps = 2.0
        * coordinates.len() as f64
        * (longest / dt).ceil()
        * (2.0 + options.refreshes.max(options.stability.corrections) as f64);
    if steps.is_nan() || steps > MAX_MARCH_STEPS {
        return Err(StabilityError::TooCostly {
            steps,
            dimension: coordinates.len(),
            corrections: options.refreshes.max(options.stability.corrections),
            limit: MAX_MARCH_STEPS,
        }
        .into());
    }
    let half_step = 0.5 * (grid.end - grid.start).abs() / (grid.steps - 1) as f64;
    let harmonic_balance: Vec<Option<&BackbonePoint>> = requested
        .iter()
        .map(|t| {
            run.points
                .iter()
                .filter(|p| p.converged && (p.period - t).abs() <= half_step)
                .min_by(|a, b| (a.period - t).abs().total_cmp(&(b.period - t).abs()))
        })
        .collect();
    let seeds = |j: usize| -> Option<Result<Seed, StabilityError>> {
        let p = harmonic_balance[j]?;
        Some(
            State::from_harmonic_balance(system, basis, &p.x, p.omega, 0.0, dt)
                .map(|state| Seed {
                    state,
                    label: p.label.clone(),
                })
                .map_err(StabilityError::from),
        )
    };
    // Any state of the grid: the map takes its model and grid.
    let template = coordinates.to_state(&model, &branch.grid, &vec![0.0; coordinates.len()])?;
    let walker = Walker {
        coordinates: &coordinates,
        template: &template,
        periods: &branch.periods,
        requested: &requested,
        harmonic_balance: &harmonic_balance
            .iter()
            .map(|p| p.map(|p| p.energy))
            .collect::<Vec<_>>(),
        seeds: &seeds,
        options,
        grazing_energy: run.grazing_energy,
    };
    let (points, skipped, end) = walker.walk();
    Ok(ExactBranch {
        grazing_energy: run.grazing_energy,
        dt,
        dimension: coordinates.len(),
        points,
        skipped,
        end,
    })
}
