//! An exact branch from a harmonic-balance run that is already there: its seeds, grid and
//! walk.

use super::grid::{affordable, branch_grid, cost};
use super::options::ExactOptions;
use super::types::ExactBranch;
use super::walk::{Seed, Walker};
use crate::branches::backbone::{BackboneOptions, PeriodGrid};
use crate::branches::point::BackbonePoint;
use crate::branches::request::{Method, Request};
use crate::branches::result::ModeBranches;
use crate::continuation::linspace;
use crate::error::{Error, SettingsError};
use crate::stability::{StabilityError, MAX_DIMENSION, MAX_MARCH_STEPS};
use crate::system::BarSystem;
use crate::verify::{Grid, Model, State};

/// The period grid of `request`: its method's, or the system's default for the mode
/// ([`BackboneOptions::for_mode`]) where the method carries none (arclength, energy).
pub(crate) fn period_grid(system: &BarSystem, request: &Request) -> Result<PeriodGrid, Error> {
    Ok(match request.method {
        Method::Auto(Some(o)) | Method::PeriodGrid(o) | Method::GenuineSubharmonic(o) => o.grid,
        _ => BackboneOptions::for_mode(system, request.mode, request.subharmonic)?.grid,
    })
}

/// The fewest cells per shortest travel time [`ExactOptions::for_request`] goes down to.
const MIN_CELLS: f64 = 8.0;

impl ExactOptions {
    /// The default options with a grid `system` can afford over `request`'s period grid: 200
    /// cells per shortest travel time, or fewer where the bars of longer travel times would
    /// make the monodromy larger than [`MAX_DIMENSION`](crate::stability::MAX_DIMENSION) rows
    /// or its marches longer than [`MAX_MARCH_STEPS`] (the cost grows like the square of the
    /// cells), down to 8. A branch on fewer cells resolves shorter waves less well: its
    /// verdicts carry their grid ([`Floquet::dt`](crate::stability::Floquet::dt),
    /// [`Floquet::dimension`](crate::stability::Floquet::dimension)).
    ///
    /// # Errors
    /// Those of [`BackboneOptions::for_mode`] for a request without a grid, and of the
    /// integrator's model for a system it cannot march.
    pub fn for_request(system: &BarSystem, request: &Request) -> Result<Self, Error> {
        let grid = period_grid(system, request)?;
        let longest = grid.start.max(grid.end);
        let model = Model::from_system(system)?;
        let mut options = Self::default();
        let passes = options.refreshes.max(options.stability.corrections);
        let travel = crate::bar::shortest_travel_time(model.bars());
        let mut cells = options.stability.cells_per_travel;
        // The cost is about quadratic in the cells: a few shrinks settle it.
        for _ in 0..8 {
            let g = Grid::nearest_or_new(&model, travel / cells)?;
            let (n, steps) = cost(&model, &g, longest, passes);
            let shrink = (MAX_DIMENSION as f64 / n as f64).min((MAX_MARCH_STEPS / steps).sqrt());
            if shrink >= 1.0 || shrink.is_nan() || cells <= MIN_CELLS {
                break;
            }
            cells = (0.95 * cells * shrink).floor().max(MIN_CELLS);
        }
        options.stability.cells_per_travel = cells;
        Ok(options)
    }
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
    let longest = requested.iter().fold(0.0f64, |m, t| m.max(*t));
    let passes = options.refreshes.max(options.stability.corrections);
    let fits = |grid: &Grid| affordable(cost(&model, grid, longest, passes));
    let cells = options.stability.cells_per_travel;
    let branch = branch_grid(&model, &requested, cells, &fits)?;
    let dt = branch.grid.dt();
    let coordinates = crate::stability::coordinates::Coordinates::new(&model, &branch.grid);
    crate::stability::check_dimension(&coordinates, options.stability.cells_per_travel)?;
    let longest = branch.periods.iter().fold(0.0f64, |m, t| m.max(*t));
    let steps = cost(&model, &branch.grid, longest, passes).1;
    if steps.is_nan() || steps > MAX_MARCH_STEPS {
        return Err(StabilityError::TooCostly {
            steps,
            dimension: coordinates.len(),
            corrections: passes,
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
                .filter(|p| p.converged() && (p.period - t).abs() <= half_step)
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
