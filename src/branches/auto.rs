//! What [`Method::Auto`] runs, and how it judges its runs before they are shown: the period
//! grid or pseudo-arclength from the searched start, the run from the tethered start on a
//! system with floating bars, and the run lifted from half the harmonics where these fall
//! short.

use crate::branches::backbone::{ArclengthBackboneOptions, BackboneOptions};
use crate::branches::lift::lifted_run;
use crate::branches::plan::{quiet_run, Plan, QuietRun};
use crate::branches::request::{AutoChoice, Method, Request};
use crate::branches::start::{
    backbone_start, tethered_backbone_start, BackboneStart, MIN_COARSE_HARMONICS,
};
use crate::error::{Error, SettingsError};
use crate::fourier::{frequency_of_period, period_of_frequency};
use crate::system::{BarSystem, HarmonicBalanceSettings, NonsmoothSystem};

/// A judged run of [`Method::Auto`]: its points (annotated, not yet shown), the method
/// that ran, why, and the problem its points solve.
pub(crate) type AutoRun = (QuietRun, Method, Option<AutoChoice>, NonsmoothSystem);

/// What [`Method::Auto`] returns for `request` on `system` over the period grid `given`
/// (`None`: the system's own), as [`compute`](crate::branches::compute) documents it: the
/// run from the searched start (and, with floating bars, the one from the tethered start)
/// and, where the better of them falls short (fewer good points than half the grid's
/// steps) and half the harmonics are at least [`MIN_COARSE_HARMONICS`], the run of `Auto`
/// at half the harmonics lifted to the request's ([`lift`](crate::branches::lift)): the run with more
/// good points is kept.
///
/// # Errors
/// See [`compute`](crate::branches::compute).
pub(crate) fn judged_auto(
    system: &BarSystem,
    request: &Request,
    given: Option<BackboneOptions>,
    problem: NonsmoothSystem,
) -> Result<AutoRun, Error> {
    let (mode, order) = (request.mode, request.subharmonic);
    let grid = BackboneOptions {
        mode,
        subharmonic: order,
        ..given.map_or_else(|| BackboneOptions::for_mode(system, mode, order), Ok)?
    };
    let direct = direct_run(system, request, grid, problem.clone());
    // Only a run that fell short, or a start that was not found, is worth a coarser run.
    let direct_good = match &direct {
        Ok((run, ..)) if run.falls_short_of(grid.grid.steps) => run.good(),
        Err(Error::Settings(SettingsError::StartNotFound { .. })) => 0,
        _ => return direct,
    };
    let harmonics = request.settings.harmonics / 2;
    if harmonics < MIN_COARSE_HARMONICS.max(order) {
        return direct;
    }
    let coarse = Request {
        settings: HarmonicBalanceSettings {
            harmonics,
            ..request.settings
        },
        // The lifted points get the multipliers the request asks; the coarse ones need none.
        stability: None,
        hill: None,
        ..request.clone()
    };
    let Ok(coarse_problem) = NonsmoothSystem::new(system, coarse.settings) else {
        return direct;
    };
    let Ok((run, method, _, _)) = judged_auto(system, &coarse, given, coarse_problem) else {
        return direct;
    };
    let floor = grid.trivial_energy * run.e_g;
    let coarse = (&run.points[..], run.e_g, floor);
    let (lifted, problem) = lifted_run(coarse, (run.end, run.rejected), request, problem);
    let lifted_good = lifted.good();
    if lifted_good <= direct_good {
        return direct;
    }
    let choice = AutoChoice::Lifted {
        harmonics,
        good: lifted_good,
        direct_good,
    };
    Ok((lifted, method, Some(choice), problem))
}

/// What [`Method::Auto`] runs on `system` at the request's harmonics over the period grid
/// `grid`: the run from the searched start and, with floating bars, the one from the
/// tethered start, each judged; the one with more good points is kept.
fn direct_run(
    system: &BarSystem,
    request: &Request,
    grid: BackboneOptions,
    problem: NonsmoothSystem,
) -> Result<AutoRun, Error> {
    let (plan, method, auto, tethered) = resolve(system, request, grid)?;
    let Some((grid, start)) = tethered else {
        return judged_run(system, request, (plan, method, auto), problem);
    };
    let searched = judged_run(system, request, (plan, method, auto), problem.clone());
    let plan = Plan::Grid(grid, Some(start));
    let entered = Some(AutoChoice::EnteredAtGridStart);
    let tied = judged_run(
        system,
        request,
        (plan, Method::PeriodGrid(grid), entered),
        problem,
    );
    Ok(match (searched, tied) {
        (Ok(a), Ok(b)) if b.0.good() <= a.0.good() => a,
        (Ok(a), Err(_)) => a,
        (Err(e), Err(_)) => return Err(e),
        (searched, Ok((run, method, _, problem))) => {
            let searched_good = searched.map_or(0, |a| a.0.good());
            let choice = AutoChoice::Tethered {
                good: run.good(),
                searched_good,
            };
            (run, method, Some(choice), problem)
        }
    })
}

/// A run of `plan` whose points are kept to be judged. A period grid that Auto chose because
/// its branch is entered at the grid's first period gives way to pseudo-arclength over its
/// range where it falls short ([`grid_fell_short`]) and arclength does better.
fn judged_run(
    system: &BarSystem,
    request: &Request,
    (plan, method, auto): (Plan, Method, Option<AutoChoice>),
    problem: NonsmoothSystem,
) -> Result<AutoRun, Error> {
    // The arclength fallback starts where the grid did when its start was found beforehand.
    let fallback = match (&plan, auto) {
        (Plan::Grid(options, start), Some(AutoChoice::EnteredAtGridStart)) => {
            Some((*options, start.clone()))
        }
        _ => None,
    };
    let solver = request.solver_for(&method)?;
    let (grid, problem) = quiet_run(system, request, (plan, solver), problem)?;
    let Some((options, start)) = fallback else {
        return Ok((grid, method, auto, problem));
    };
    let steps = options.grid.steps;
    if !grid_fell_short(&grid, steps) {
        return Ok((grid, method, auto, problem));
    }
    let arclength = within_grid_budget(&options);
    let other = Method::Arclength(arclength);
    let solver = request.solver_for(&other)?;
    let plan = Plan::Arclength(arclength, start);
    let (run, problem) = quiet_run(system, request, (plan, solver), problem)?;
    let good = grid.good();
    Ok(if run.good() > good {
        (
            run,
            other,
            Some(AutoChoice::GridFellShort { good, steps }),
            problem,
        )
    } else {
        (grid, method, auto, problem)
    })
}

/// Steps, and rejected steps, that an arclength run of [`Method::Auto`] may take per step of
/// the grid it stands in for.
const ARCLENGTH_STEPS_PER_GRID_STEP: usize = 4;

/// The pseudo-arclength options [`Method::Auto`] runs over `grid`'s range
/// ([`ArclengthBackboneOptions::over_grid`]) within the grid's budget: at most
/// [`ARCLENGTH_STEPS_PER_GRID_STEP`] steps and as many rejected steps per grid step (the
/// walk back to the grid's first period keeps within the same). The driver's defaults
/// (2,000 steps) let a request of 6 steps return about 300 points, each then given the
/// multipliers the request asks; the default grid of 181 steps allows 724.
fn within_grid_budget(grid: &BackboneOptions) -> ArclengthBackboneOptions {
    let mut options = ArclengthBackboneOptions::over_grid(grid);
    let budget = (grid.grid.steps).saturating_mul(ARCLENGTH_STEPS_PER_GRID_STEP);
    options.arclength.max_steps = options.arclength.max_steps.min(budget);
    options.arclength.max_rejections = options.arclength.max_rejections.min(budget);
    options
}

/// Whether the run of a period grid of `steps` steps falls short of a backbone: it stalled,
/// or fewer than half its steps are good ([`QuietRun::good`]: its branch left the grid's
/// range, or the grid walks the truncated system's resonances). A stalled run needs no
/// march of the judge's sample to tell.
fn grid_fell_short(grid: &QuietRun, steps: usize) -> bool {
    grid.end.error().is_some() || grid.falls_short_of(steps)
}

/// What [`Method::Auto`] runs at the request's harmonics: the plan, the method it stands
/// for (as the result records it), why, and on a system with floating bars the period grid
/// from the tethered start, the other run it judges.
type Resolved = (
    Plan,
    Method,
    Option<AutoChoice>,
    Option<(BackboneOptions, BackboneStart)>,
);

/// What [`Method::Auto`] runs on `system` over the period grid `grid`
/// ([`compute`](crate::branches::compute)).
fn resolve(
    system: &BarSystem,
    request: &Request,
    grid: BackboneOptions,
) -> Result<Resolved, Error> {
    let (mode, order) = (request.mode, request.subharmonic);
    if order >= 2 {
        let choice = Some(AutoChoice::Subharmonic);
        return Ok((
            Plan::Genuine(grid),
            Method::GenuineSubharmonic(grid),
            choice,
            None,
        ));
    }
    let first = frequency_of_period(grid.grid.start);
    let solver = request.solver_for(&Method::PeriodGrid(grid))?;
    let settings = request.settings;
    let floor = grid.trivial_energy;
    let tethered =
        tethered_backbone_start(system, settings, (mode, order), (first, floor), &solver)
            .map(|start| (grid, start));
    let start = match backbone_start(system, settings, (mode, order), first, floor, &solver) {
        Ok(start) => start,
        Err(not_found @ Error::Settings(SettingsError::StartNotFound { .. })) => {
            let seed = BackboneStart::seed(system, settings, (mode, order), first)?;
            let choice = Some(AutoChoice::NoStartFound);
            return Ok((
                Plan::FromSeed(grid, seed, not_found),
                Method::PeriodGrid(grid),
                choice,
                tethered,
            ));
        }
        Err(e) => return Err(e),
    };
    if !start.moved_from(first) {
        let choice = Some(AutoChoice::EnteredAtGridStart);
        return Ok((
            Plan::Grid(grid, Some(start)),
            Method::PeriodGrid(grid),
            choice,
            tethered,
        ));
    }
    let options = within_grid_budget(&grid);
    let entered_at = period_of_frequency(start.omega);
    Ok((
        Plan::Arclength(options, None),
        Method::Arclength(options),
        Some(AutoChoice::EnteredAtShorterPeriod { entered_at }),
        tethered,
    ))
}
