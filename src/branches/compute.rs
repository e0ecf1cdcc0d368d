//! The one call: a branch of a system's nonsmooth mode from a [`Request`], whatever the method.

use crate::branches::backbone::{
    arclength_backbone_observed, backbone_from, backbone_speculative_with, backbone_with,
    ArclengthBackboneOptions, BackboneObserver, BackboneOptions, PointSink,
};
use crate::branches::energy_backbone::{energy_backbone_with, EnergyBackboneOptions};
use crate::branches::point::BackbonePoint;
use crate::branches::request::{AutoChoice, Method, Request};
use crate::branches::result::{Annotator, ModeBranches};
use crate::branches::start::{backbone_start, tethered_backbone_start, BackboneStart};
use crate::branches::subharmonic::genuine_subharmonic_backbone_with;
use crate::continuation::{EndReason, Rejection};
use crate::error::{Error, SettingsError};
use crate::fourier::{frequency_of_period, period_of_frequency};
use crate::modal::Label;
use crate::solve::Solver;
use crate::system::{BarSystem, NonsmoothSystem};
use std::ops::ControlFlow;

/// Computes the branch of NSM `request.mode` sub `request.subharmonic` of `system` by
/// `request.method`, and returns every point computed, each with its status, branch index,
/// character and label ([`ModeBranches`]).
///
/// # Method::Auto
/// - Order `K >= 2`: a genuine subharmonic over the system's period grid
///   ([`BackboneOptions::for_mode`]).
/// - Otherwise the start of the branch is searched at the first period of the system's grid
///   (the grazing seed of linear mode `i`, solved; where it slides to rest, a search over
///   amplitudes, frequencies and rigid-body motions). Where the branch is entered there, the
///   period grid runs from that start; where it is entered only at a higher frequency (a
///   floating bar that must be pushed hard enough to shuttle within a period),
///   pseudo-arclength from the grid's first period walks the branch back and follows it
///   through its folds ([`ArclengthBackboneOptions::over_grid`]).
/// - A period grid is judged before its points are shown: where it stalls or fewer than
///   half its steps are good (converged and, when the request asks for a time-domain check,
///   verified), as where its branch saturates at a period inside the grid or it walks the
///   truncated system's resonances, pseudo-arclength over the grid's range is run too, and
///   the run with more good points is returned ([`AutoChoice::GridFellShort`] when it is
///   arclength; the other run's points are not returned).
/// - On a system with floating bars the start is also reached from the tethered system (the
///   laws next to a floating bar tied by springs, lowered to zero on the way to the grid's
///   first frequency), and the period grid from it is run too (judged as above, arclength
///   then starting from the same start): the run with more good points is returned
///   ([`AutoChoice::Tethered`] when it is the tethered one).
///
/// The choice is [`ModeBranches::auto`].
///
/// # Errors
/// Only when no point was computed: invalid settings or options, no linear mode `i`, an
/// assembly with a bar nothing holds
/// ([`SettingsError::Unconfined`](crate::SettingsError::Unconfined)), or no start and no
/// converged step ([`SettingsError::StartNotFound`](crate::SettingsError::StartNotFound),
/// which says what was tried). A run that stalls or fails part-way returns its points with
/// its end reason ([`ModeBranches::end`]).
///
/// # Example
/// ```
/// use nonsmooth_modes::branches::{compute, Request};
/// use nonsmooth_modes::reference::clamped_bar_with_obstacle;
///
/// let system = clamped_bar_with_obstacle(1e-3)?;
/// let run = compute(&system, &Request::new(1).harmonics(10))?;
/// assert!(run.converged().count() > 100);
/// println!("{:?} by {}", run.end, run.method.name());
/// # Ok::<(), nonsmooth_modes::Error>(())
/// ```
pub fn compute(system: &BarSystem, request: &Request) -> Result<ModeBranches, Error> {
    compute_observed(system, request, |_: &BackbonePoint| {
        ControlFlow::Continue(())
    })
}

/// [`compute`], handing each point (annotated as in the result) and each rejected
/// arclength step to `observer` as it comes; the observer may stop the run
/// ([`EndReason::StoppedByObserver`]), which keeps its points.
///
/// # Errors
/// See [`compute`].
pub fn compute_observed(
    system: &BarSystem,
    request: &Request,
    observer: impl BackboneObserver,
) -> Result<ModeBranches, Error> {
    let problem = NonsmoothSystem::new(system, request.settings)?;
    let (plan, method, auto, tethered) = resolve(system, request)?;
    let judged = matches!(
        (&plan, auto),
        (Plan::Grid(..), Some(AutoChoice::EnteredAtGridStart))
    );
    if !judged && tethered.is_none() {
        let mut annotator = Annotator::new(problem, request, observer);
        let solver = request.solver_for(&method)?;
        let (e_g, end, rejected) = run_plan(system, request, plan, solver, &mut annotator)?;
        return Ok(annotator.finish((method, auto), e_g, end, rejected));
    }
    // Auto's runs are judged before they are shown.
    let (run, method, auto, problem) = match tethered {
        None => judged_run(system, request, (plan, method, auto), problem)?,
        Some((grid, start)) => {
            let searched = judged_run(system, request, (plan, method, auto), problem.clone());
            let plan = Plan::Grid(grid, Some(start));
            let entered = Some(AutoChoice::EnteredAtGridStart);
            let tied = judged_run(
                system,
                request,
                (plan, Method::PeriodGrid(grid), entered),
                problem,
            );
            match (searched, tied) {
                (Ok(a), Ok(b)) if b.0.good <= a.0.good => a,
                (Ok(a), Err(_)) => a,
                (Err(e), Err(_)) => return Err(e),
                (searched, Ok((run, method, _, problem))) => {
                    let searched_good = searched.map_or(0, |a| a.0.good);
                    let choice = AutoChoice::Tethered {
                        good: run.good,
                        searched_good,
                    };
                    (run, method, Some(choice), problem)
                }
            }
        }
    };
    let mut annotator = Annotator::new(problem, request, observer);
    let end = annotator.replay(run.points, run.end);
    Ok(annotator.finish((method, auto), run.e_g, end, run.rejected))
}

/// A run of `plan` whose points are kept to be judged. A period grid that Auto chose because
/// its branch is entered at the grid's first period gives way to pseudo-arclength over its
/// range where it falls short ([`grid_fell_short`]) and arclength does better.
fn judged_run(
    system: &BarSystem,
    request: &Request,
    (plan, method, auto): (Plan, Method, Option<AutoChoice>),
    problem: NonsmoothSystem,
) -> Result<(QuietRun, Method, Option<AutoChoice>, NonsmoothSystem), Error> {
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
    if !grid_fell_short(grid.good, steps, &grid.end) {
        return Ok((grid, method, auto, problem));
    }
    let arclength = ArclengthBackboneOptions::over_grid(&options);
    let other = Method::Arclength(arclength);
    let solver = request.solver_for(&other)?;
    let plan = Plan::Arclength(arclength, start);
    let (run, problem) = quiet_run(system, request, (plan, solver), problem)?;
    Ok(if run.good > grid.good {
        let good = grid.good;
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

/// Whether a period grid of `steps` steps with `good` good points (converged, and not
/// refuted by a time-domain check where one was asked) that ended with `end` falls short of
/// a backbone: it stalled, or fewer than half its steps are good (its branch left the grid's
/// range, or the grid walks the truncated system's resonances).
fn grid_fell_short(good: usize, steps: usize, end: &EndReason) -> bool {
    end.error().is_some() || 2 * good < steps
}

/// A run whose points were annotated but not yet shown to the user's observer.
struct QuietRun {
    points: Vec<BackbonePoint>,
    e_g: f64,
    end: EndReason,
    rejected: usize,
    /// Converged points not labelled [`Label::Unverified`].
    good: usize,
}

/// Runs `plan` with `solver`, keeping the points annotated on `problem` to be judged; gives
/// the problem back.
fn quiet_run(
    system: &BarSystem,
    request: &Request,
    (plan, solver): (Plan, Solver),
    problem: NonsmoothSystem,
) -> Result<(QuietRun, NonsmoothSystem), Error> {
    let quiet = |_: &BackbonePoint| ControlFlow::Continue(());
    let mut annotator = Annotator::new(problem, request, quiet);
    let (e_g, end, rejected) = run_plan(system, request, plan, solver, &mut annotator)?;
    let (points, problem) = annotator.into_parts();
    let good = (points.iter())
        .filter(|p| p.converged && p.label != Some(Label::Unverified))
        .count();
    let run = QuietRun {
        points,
        e_g,
        end,
        rejected,
        good,
    };
    Ok((run, problem))
}

/// Runs `plan` with `solver`, handing every point to `annotator`; returns `E_g`, the end
/// reason and the rejected steps.
fn run_plan<O: BackboneObserver>(
    system: &BarSystem,
    request: &Request,
    plan: Plan,
    solver: Solver,
    annotator: &mut Annotator<O>,
) -> Result<(f64, EndReason, usize), Error> {
    let settings = request.settings;
    let spec = request.speculation;
    let see = |p: BackbonePoint| annotator.point(p);
    Ok(match plan {
        Plan::Grid(options, Some(start)) => {
            let (e_g, end) = backbone_from(system, settings, &options, start, spec, solver, see)?;
            (e_g, end, 0)
        }
        Plan::Grid(options, None) => {
            let (e_g, end) = match spec {
                Some(spec) => {
                    backbone_speculative_with(system, settings, &options, spec, solver, see)?
                }
                None => backbone_with(system, settings, &options, solver, see)?,
            };
            (e_g, end, 0)
        }
        Plan::Genuine(options) => {
            let (e_g, end) =
                genuine_subharmonic_backbone_with(system, settings, &options, solver, see)?;
            (e_g, end, 0)
        }
        Plan::Energy(options) => {
            let (e_g, end) = energy_backbone_with(system, settings, &options, solver, see)?;
            (e_g, end, 0)
        }
        Plan::Arclength(options, given) => {
            let seen = Forward(annotator);
            let (e_g, branch) =
                arclength_backbone_observed(system, settings, (&options, given), solver, seen)?;
            (e_g, branch.end, branch.rejections)
        }
        Plan::FromSeed(options, start, not_found) => {
            let (e_g, end) = backbone_from(system, settings, &options, start, spec, solver, see)?;
            if annotator.converged() == 0 {
                return Err(not_found);
            }
            (e_g, end, 0)
        }
    })
}

/// A sink that hands what it receives to the annotator (the arclength backbone takes its
/// sink by value).
struct Forward<'a, O>(&'a mut Annotator<O>);

impl<O: BackboneObserver> PointSink for Forward<'_, O> {
    fn point(&mut self, point: BackbonePoint) -> ControlFlow<()> {
        self.0.point(point)
    }
    fn rejected(&mut self, rejection: &Rejection) -> ControlFlow<()> {
        self.0.rejected(rejection)
    }
}

/// What [`compute`] runs for a request: the plan, the method it stands for (as the result
/// records it), for [`Method::Auto`] why, and on a system with floating bars the period grid
/// from the tethered start, the other run Auto judges.
type Resolved = (
    Plan,
    Method,
    Option<AutoChoice>,
    Option<(BackboneOptions, BackboneStart)>,
);

/// What [`compute`] runs: the driver, with its options built from the system and the
/// request's mode and order in them.
enum Plan {
    /// A period grid, from a start found beforehand or searching its own.
    Grid(BackboneOptions, Option<BackboneStart>),
    /// A period grid from the unsolved seed, after a start search that failed with the
    /// error kept: the grid may still enter its branch further on.
    FromSeed(BackboneOptions, BackboneStart, Error),
    Genuine(BackboneOptions),
    Energy(EnergyBackboneOptions),
    /// Pseudo-arclength, from a start found beforehand or searching its own.
    Arclength(ArclengthBackboneOptions, Option<BackboneStart>),
}

/// The plan of `request`, the method it stands for (as the result records it) and, for
/// [`Method::Auto`], why.
///
/// # Errors
/// No linear mode `i` (or an order 0), invalid settings, and the errors of the start search
/// of `Auto` but its failure to find a start.
fn resolve(system: &BarSystem, request: &Request) -> Result<Resolved, Error> {
    let (mode, subharmonic) = (request.mode, request.subharmonic);
    let grid = |o: &BackboneOptions| BackboneOptions {
        mode,
        subharmonic,
        ..*o
    };
    let arclength = |o: &ArclengthBackboneOptions| ArclengthBackboneOptions {
        mode,
        subharmonic,
        ..*o
    };
    let (plan, method) = match &request.method {
        Method::Auto(grid) => return auto(system, request, *grid),
        Method::PeriodGrid(o) => (Plan::Grid(grid(o), None), Method::PeriodGrid(grid(o))),
        Method::GenuineSubharmonic(o) => {
            (Plan::Genuine(grid(o)), Method::GenuineSubharmonic(grid(o)))
        }
        Method::Arclength(o) => (
            Plan::Arclength(arclength(o), None),
            Method::Arclength(arclength(o)),
        ),
        Method::Switch(o, at) => {
            let options = ArclengthBackboneOptions {
                switch: Some(*at),
                ..arclength(o)
            };
            (Plan::Arclength(options, None), Method::Switch(options, *at))
        }
        Method::Energy(o) => {
            let options = EnergyBackboneOptions {
                mode,
                subharmonic,
                ..*o
            };
            (Plan::Energy(options), Method::Energy(options))
        }
    };
    // Only Auto chooses, and only Auto has a tethered run to judge.
    Ok((plan, method, None, None))
}

/// What [`Method::Auto`] runs on `system` from the period grid `given` ([`compute`]).
fn auto(
    system: &BarSystem,
    request: &Request,
    given: Option<BackboneOptions>,
) -> Result<Resolved, Error> {
    let (mode, order) = (request.mode, request.subharmonic);
    let grid = BackboneOptions {
        mode,
        subharmonic: order,
        ..given.map_or_else(|| BackboneOptions::for_mode(system, mode, order), Ok)?
    };
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
    let options = ArclengthBackboneOptions::over_grid(&grid);
    let entered_at = period_of_frequency(start.omega);
    Ok((
        Plan::Arclength(options, None),
        Method::Arclength(options),
        Some(AutoChoice::EnteredAtShorterPeriod { entered_at }),
        tethered,
    ))
}
