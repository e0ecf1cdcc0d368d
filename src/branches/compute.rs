//! The one call: a branch of a system's nonsmooth mode from a [`Request`], whatever the method.

use crate::branches::backbone::BackboneObserver;
use crate::branches::beside::run_plan_beside;
use crate::branches::plan::asked;
use crate::branches::point::BackbonePoint;
use crate::branches::request::Request;
use crate::branches::result::{Annotator, ModeBranches};
use crate::branches::selected::judged_with_selection;
use crate::error::{Error, SettingsError};
use crate::exact::from_run::{exact_branch_from, period_grid};
use crate::system::{BarSystem, NonsmoothSystem};
use std::ops::ControlFlow;

/// Computes the branch of NSM `request.mode` sub `request.subharmonic` of `system` by
/// `request.method`, and returns every point computed, each with its status, branch index,
/// character and label ([`ModeBranches`]).
///
/// # Method::Auto
/// - Order `K >= 2`: a genuine subharmonic over the system's period grid
///   ([`BackboneOptions::for_mode`](crate::branches::BackboneOptions::for_mode)).
/// - Otherwise the start of the branch is searched at the first period of the system's grid
///   (the grazing seed of linear mode `i`, solved; where it slides to rest, a search over
///   amplitudes, frequencies and rigid-body motions). Where the branch is entered there, the
///   period grid runs from that start; where it is entered only at a higher frequency (a
///   floating bar that must be pushed hard enough to shuttle within a period),
///   pseudo-arclength from the grid's first period walks the branch back and follows it
///   through its folds ([`ArclengthBackboneOptions::over_grid`](crate::branches::ArclengthBackboneOptions::over_grid)).
/// - A period grid is judged before its points are shown: where it stalls or fewer than
///   half its steps are good (its converged points, scaled by the share of a sample of
///   [`JUDGE_SAMPLES`](crate::branches::JUDGE_SAMPLES) of them that passes the time-domain
///   check), as where its branch saturates at a period inside the grid or it walks the
///   truncated system's resonances, pseudo-arclength over the grid's range is run too, and
///   the run with more good points is returned ([`AutoChoice::GridFellShort`](crate::branches::AutoChoice::GridFellShort) when it is
///   arclength; the other run's points are not returned).
/// - On a system with floating bars the start is also reached from the tethered system (the
///   laws next to a floating bar tied by springs, lowered to zero on the way to the grid's
///   first frequency), and the period grid from it is run too (judged as above, arclength
///   then starting from the same start): the run with more good points is returned
///   ([`AutoChoice::Tethered`](crate::branches::AutoChoice::Tethered) when it is the tethered one).
/// - Where the run kept has fewer good points than half the grid's steps and half the
///   request's harmonics are at least
///   [`MIN_COARSE_HARMONICS`](crate::branches::MIN_COARSE_HARMONICS), `Auto` runs at half
///   the harmonics (itself as here, so down to that bound), and every converged point of
///   that run is lifted to the request's harmonics (the higher harmonics zero) and solved
///   there at its own frequency: continuation in the number of harmonics. A coarser
///   truncation has fewer internal resonances in the way of the branch, and the finer one
///   corrects what it misses. The run with more good points is returned
///   ([`AutoChoice::Lifted`](crate::branches::AutoChoice::Lifted) when it is the lifted
///   one).
///
/// - Where the request keeps every harmonic (a band of 0, the default) and asks for the
///   mode's own branch (order 1), all of the above runs twice: on the paper's equations and
///   under harmonic selection of band
///   [`RESONANCE_BAND`](crate::system::RESONANCE_BAND), on two threads when the request
///   allows a second core ([`Request::speculation`]). The run whose converged skeleton
///   points cover more periods of the grid
///   is returned, a tie keeping the selected equations ([`ModeBranches::selection`]): the
///   selection removes the truncation's internal resonances, so that the skeleton converges
///   in `m` (`docs/theory.md`, "Harmonic selection"), but on assemblies with dense natural
///   frequencies it can drop harmonics the motion needs. [`ModeBranches::problem`] gives
///   the equations the points solve.
///
/// The choice is [`ModeBranches::auto`]. `Auto`'s points reach an observer
/// ([`compute_observed`]) once its runs are judged. The judge is the same whether the
/// request asks for the time-domain check or not, so the check only annotates the points
/// returned (it runs on the run kept, and labels the points that fail it
/// [`Label::Unverified`](crate::modal::Label::Unverified)); on chains with a floating bar
/// the judge's sample is what tells a start whose points are motions of the bars.
///
/// # Errors
/// Only when no point was computed: invalid settings or options, no linear mode `i`, an
/// assembly with a bar nothing holds
/// ([`SettingsError::Unconfined`](crate::SettingsError::Unconfined)), a method whose options
/// name another mode or order than the request
/// ([`SettingsError::MethodDisagrees`](crate::SettingsError::MethodDisagrees)), a period or
/// energy grid that is empty, a single point, with a period or level that is not positive
/// and finite, or a falling energy grid ([`SettingsError::Range`](crate::SettingsError::Range),
/// quoting the grid as given, whatever the method, [`Method::Auto`](crate::branches::Method::Auto)
/// included), or no start and no
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
/// ([`EndReason::StoppedByObserver`](crate::continuation::EndReason::StoppedByObserver)),
/// which keeps its points.
///
/// # Errors
/// See [`compute`].
pub fn compute_observed(
    system: &BarSystem,
    request: &Request,
    observer: impl BackboneObserver,
) -> Result<ModeBranches, Error> {
    if let Some((mode, order)) = request.method.mode_and_order() {
        if (mode, order) != (request.mode, request.subharmonic) {
            return Err(SettingsError::MethodDisagrees {
                request_mode: request.mode,
                request_order: request.subharmonic,
                method_mode: mode,
                method_order: order,
            }
            .into());
        }
    }
    request.method.validate_grid()?;
    if let Some(options) = &request.exact {
        period_grid(system, request)?
            .validate()
            .map_err(SettingsError::from)?;
        options.check()?;
    }
    let problem = NonsmoothSystem::new(system, request.settings)?;
    let (plan, method) = match asked(request) {
        Ok(planned) => planned,
        Err(given) => {
            // Auto's runs are judged before they are shown.
            let ((run, method, auto, problem), selection) =
                judged_with_selection(system, request, given, problem)?;
            let mut annotator = Annotator::new(problem, request, observer);
            let end = annotator.replay(run.points, run.end);
            let mut result = annotator.finish((method, auto), run.e_g, end, run.rejected);
            result.selection = selection;
            return Ok(with_exact(system, request, result));
        }
    };
    let mut annotator = Annotator::new(problem, request, observer);
    let solver = request.solver_for(&method)?;
    let (e_g, end, rejected) = run_plan_beside(system, request, (plan, solver), &mut annotator)?;
    let result = annotator.finish((method, None), e_g, end, rejected);
    Ok(with_exact(system, request, result))
}

/// `result` with the exact branch [`Request::exact`] asks for, continued from its points.
fn with_exact(system: &BarSystem, request: &Request, mut result: ModeBranches) -> ModeBranches {
    if let Some(options) = &request.exact {
        let branch = period_grid(system, request)
            .and_then(|grid| exact_branch_from(&result, &grid, options));
        result.exact = Some(branch);
    }
    result
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::branches::{EnergyBackboneOptions, Method};
    use crate::reference::clamped_bar_with_obstacle;

    /// A method whose options name another mode than the request is refused with both
    /// modes, before anything is computed; the request built from the method runs.
    #[test]
    fn a_method_for_another_mode_is_refused() {
        let system = clamped_bar_with_obstacle(1e-3).unwrap();
        let options = EnergyBackboneOptions::for_mode(&system, 2, 1).unwrap();
        let method = Method::Energy(options);
        let mixed = Request::new(1).harmonics(5).method(method);
        match compute(&system, &mixed) {
            Err(Error::Settings(SettingsError::MethodDisagrees {
                request_mode: 1,
                request_order: 1,
                method_mode: 2,
                method_order: 1,
            })) => {}
            other => panic!("{other:?}"),
        }
        let agreed = Request::for_method(method).harmonics(5);
        assert!(compute(&system, &agreed).is_ok());
    }
}
