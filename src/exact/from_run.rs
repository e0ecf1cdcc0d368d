//! An exact branch from a harmonic-balance run that is already there: its seeds, grid and
//! walk.

use super::options::ExactOptions;
use super::types::ExactBranch;
use super::walk::{Seed, Walker};
use crate::branches::backbone::{BackboneOptions, PeriodGrid};
use crate::branches::point::BackbonePoint;
use crate::branches::request::{Method, Request};
use crate::branches::result::ModeBranches;
use crate::continuation::linspace;
use crate::error::{Error, SettingsError};
use crate::stability::{StabilityError, MAX_MARCH_STEPS};
use crate::system::BarSystem;
use crate::verify::{Model, State};

/// The period grid of `request`: its method's, or the system's default for the mode
/// ([`BackboneOptions::for_mode`]) where the method carries none (arclength, energy).
pub(crate) fn period_grid(system: &BarSystem, request: &Request) -> Result<PeriodGrid, Error> {
    Ok(match request.method {
        Method::Auto(Some(o)) | Method::PeriodGrid(o) | Method::GenuineSubharmonic(o) => o.grid,
        _ => BackboneOptions::for_mode(system, request.mode, request.subharmonic)?.grid,
    })
}

/// The exact branch over `grid`, seeded by the converged points of the harmonic-balance run
/// `run` (the point nearest each grid period, within half a step). See the
/// [module docs](crate::exact).
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
    let branch = super::grid::branch_grid(&model, &requested, options.stability.cells_per_travel)?;
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
