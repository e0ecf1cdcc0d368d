//! [`Method::Auto`](crate::branches::Method::Auto) on the paper's equations and under
//! harmonic selection, side by side: the run whose skeleton covers more of the period grid
//! is returned ([`SelectionJudgement`]).
//!
//! # Why
//! The truncated equations at `m` harmonics have internal resonances wherever a harmonic
//! meets a linear frequency; their number grows with `m`, and so does the share of the
//! skeleton they spoil (`docs/validation.md`, "Convergence in the number of harmonics").
//! Harmonic selection ([`RESONANCE_BAND`]) removes them, so that the skeleton converges in
//! `m` on a bar with an obstacle; on assemblies whose natural frequencies are dense it can
//! drop harmonics the motion needs (`docs/assemblies.md`). Neither run is better on every
//! system, so `Auto` runs both and keeps the one with more grid periods covered by converged
//! points of the mode's own branch: points labelled as internal resonances or off the branch
//! and failed steps do not count, and an arclength run that visits one period many times
//! counts it once. It is a proxy, which on both exact families keeps the more accurate run
//! at every `m`. The time-domain check does not enter it, asked or not: both runs follow the
//! same branch, and the check does not grade their accuracy ([`crate::branches::judge`]).

use crate::branches::auto::{judged_auto, AutoRun};
use crate::branches::backbone::{BackboneOptions, PeriodGrid};
use crate::branches::point::BackbonePoint;
use crate::branches::request::{Request, SelectionJudgement};
use crate::error::Error;
use crate::modal::Label;
use crate::system::{BarSystem, HarmonicBalanceSettings, NonsmoothSystem, RESONANCE_BAND};

/// [`judged_auto`] for `request`, and, where the request keeps every harmonic (band 0) and
/// asks for the mode's own branch (order 1), also for the same request under harmonic
/// selection of band [`RESONANCE_BAND`]; the run covering more grid periods with good
/// skeleton points is returned, with the judgement, its points without the multipliers and
/// Hill exponents the request asks (the caller's annotator adds them to the run kept). The
/// two runs share the cores the request allows: with [`Request::speculation`], the selected
/// run goes to a second thread.
///
/// # Errors
/// Those of [`judged_auto`] on the paper's equations, where the run under selection fails
/// too.
pub(crate) fn judged_with_selection(
    system: &BarSystem,
    request: &Request,
    given: Option<BackboneOptions>,
    problem: NonsmoothSystem,
) -> Result<(AutoRun, Option<SelectionJudgement>), Error> {
    if request.settings.resonance_band != 0.0 || request.subharmonic != 1 {
        return Ok((judged_auto(system, request, given, problem)?, None));
    }
    // Only the run kept needs the multipliers: they are added as its points are shown.
    let judged = Request {
        stability: None,
        hill: None,
        ..request.clone()
    };
    let selected = Request {
        settings: HarmonicBalanceSettings {
            resonance_band: RESONANCE_BAND,
            ..request.settings
        },
        ..judged.clone()
    };
    // The system's grid is derived once, for both runs and the judgement.
    let given = match given {
        Some(options) => options,
        None => BackboneOptions::for_mode(system, request.mode, request.subharmonic)?,
    };
    let grid = given.grid;
    let full = |problem| judged_auto(system, &judged, Some(given), problem);
    let Ok(selected_problem) = NonsmoothSystem::new(system, selected.settings) else {
        return Ok((full(problem)?, None));
    };
    let held = |problem| judged_auto(system, &selected, Some(given), problem);
    let (full, held) = if request.speculation.is_some() {
        std::thread::scope(|scope| {
            let worker = scope.spawn(|| held(selected_problem));
            let full = full(problem);
            // A panic of the worker is a bug of the crate: it surfaces as one.
            let held = worker
                .join()
                .unwrap_or_else(|p| std::panic::resume_unwind(p));
            (full, held)
        })
    } else {
        (full(problem), held(selected_problem))
    };
    let covered = |run: &Result<AutoRun, Error>| {
        run.as_ref()
            .map_or(0, |(run, ..)| covered_periods(&run.points, &grid))
    };
    let judgement = SelectionJudgement {
        width: RESONANCE_BAND,
        covered_selected: covered(&held),
        covered_full: covered(&full),
        steps: grid.steps,
    };
    // A failed run covers no period, so the run kept failed only if both did.
    let kept = if judgement.selected() { held } else { full }?;
    Ok((kept, Some(judgement)))
}

/// The periods of `grid` that a good point ([`BackbonePoint::is_good`]) labelled
/// [`Label::Skeleton`] lies within half a grid step of.
pub(crate) fn covered_periods(points: &[BackbonePoint], grid: &PeriodGrid) -> usize {
    let steps = grid.steps;
    if steps < 2 {
        return 0;
    }
    let h = (grid.end - grid.start) / (steps - 1) as f64;
    let mut covered = vec![false; steps];
    for p in points {
        if !(p.is_good() && p.label == Some(Label::Skeleton)) {
            continue;
        }
        let j = ((p.period - grid.start) / h).round();
        if (0.0..steps as f64).contains(&j) {
            covered[j as usize] = true;
        }
    }
    covered.iter().filter(|&&c| c).count()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn point(period: f64, label: Option<Label>, converged: bool) -> BackbonePoint {
        BackbonePoint::for_test(0, period, label, converged)
    }

    #[test]
    fn a_period_is_covered_once_and_only_by_good_skeleton_points() {
        let grid = PeriodGrid {
            start: 4.0,
            end: 3.0,
            steps: 11,
        };
        let h5 = Label::InternalResonance {
            harmonic: 5,
            mode: 3,
            omega: 7.8,
        };
        let points = [
            point(4.0, Some(Label::Skeleton), true),
            point(3.96, Some(Label::Skeleton), true),
            point(3.9, Some(Label::Skeleton), true),
            point(3.8, Some(h5), true),
            point(3.7, Some(Label::Unverified), true),
            point(3.6, Some(Label::Skeleton), false),
            point(3.0, Some(Label::Skeleton), true),
            point(2.9, Some(Label::Skeleton), true),
        ];
        // 4.0 and 3.96 share the first period; 2.9 lies past the grid's end.
        assert_eq!(covered_periods(&points, &grid), 3);
    }
}
