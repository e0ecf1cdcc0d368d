//! A period-grid run whose driver steps on a second thread while the caller's thread
//! annotates the points it has handed over ([`run_plan_beside`]).
//!
//! # Why
//! Describing and labelling a converged point (its contact and gap samples over the period,
//! its energy shares, the natural frequencies its label names; the time-domain check and the
//! multipliers where the request asks them) and the user's observer take about a quarter of
//! a 181-step run on the paper's equations at `m = 20`. None of it feeds back into the
//! steps: the driver needs only whether the observer stopped. So the driver runs ahead on a
//! thread of its own and the annotator follows on the caller's thread, which keeps the
//! observer (which need not be `Send`). The points, their annotations and the order in
//! which the observer sees them are those of [`run_plan`]; an observer that stops the run
//! stops the driver at the next point it hands over, and the points computed past the stop
//! are dropped unseen, as [`run_plan`] never computes them.

use crate::branches::backbone::{backbone_speculative_with, BackboneObserver};
use crate::branches::plan::{run_plan, Plan};
use crate::branches::point::BackbonePoint;
use crate::branches::request::Request;
use crate::branches::result::Annotator;
use crate::continuation::EndReason;
use crate::error::Error;
use crate::solve::Solver;
use crate::system::BarSystem;
use std::ops::ControlFlow;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;

/// [`run_plan`], with a period grid that searches its own start driven on a second thread
/// beside the annotation of its points, where the request allows a second thread
/// ([`Request::speculation`]); other plans and requests run as [`run_plan`] runs them.
///
/// # Errors
/// Those of [`run_plan`].
pub(crate) fn run_plan_beside<O: BackboneObserver>(
    system: &BarSystem,
    request: &Request,
    (plan, solver): (Plan, Solver),
    annotator: &mut Annotator<O>,
) -> Result<(f64, EndReason, usize), Error> {
    let (Plan::Grid(options, None), Some(speculation)) = (&plan, request.speculation) else {
        return run_plan(system, request, plan, solver, annotator);
    };
    let (options, settings) = (*options, request.settings);
    let stopped = &AtomicBool::new(false);
    let (to_annotator, points) = mpsc::channel::<BackbonePoint>();
    let driven = std::thread::scope(|scope| {
        let driver = scope.spawn(|| {
            let hand_over = move |point: BackbonePoint| {
                if stopped.load(Ordering::Acquire) {
                    return ControlFlow::Break(());
                }
                // The receiver lives until the driver is joined.
                let _ = to_annotator.send(point);
                ControlFlow::Continue(())
            };
            backbone_speculative_with(system, settings, &options, speculation, solver, hand_over)
        });
        for point in &points {
            if annotator.point(point).is_break() {
                stopped.store(true, Ordering::Release);
                break;
            }
        }
        // A panic of the driver is a bug of the crate: it surfaces as one.
        driver
            .join()
            .unwrap_or_else(|p| std::panic::resume_unwind(p))
    });
    let (e_g, end) = driven?;
    let end = if annotator.stopped() {
        EndReason::StoppedByObserver
    } else {
        end
    };
    Ok((e_g, end, 0))
}

#[cfg(test)]
mod tests {
    use crate::branches::{compute_observed, BackboneOptions, Method, PeriodGrid, Request};
    use crate::branches::{BackbonePoint, ModeBranches};
    use crate::continuation::{EndReason, Speculation};
    use crate::reference::clamped_bar_with_obstacle;
    use crate::system::HarmonicBalanceSettings;
    use std::ops::ControlFlow;

    /// A period-grid run annotated beside its driver gives the points, labels and end of
    /// the run on one thread, and shows them to the observer in the same order; an observer
    /// that stops the run at its fifth point stops it there in both, with that end.
    #[test]
    fn annotating_beside_the_driver_changes_nothing() {
        let system = clamped_bar_with_obstacle(1e-3).unwrap();
        let grid = PeriodGrid {
            start: 3.9,
            end: 3.3,
            steps: 25,
        };
        let request = Request {
            settings: HarmonicBalanceSettings {
                harmonics: 16,
                ..Default::default()
            },
            method: Method::PeriodGrid(BackboneOptions::on_grid(grid, 1, 1)),
            ..Request::new(1)
        };
        let run = |speculation: Option<Speculation>, stop_at: usize| {
            let mut seen = Vec::new();
            let observer = |p: &BackbonePoint| {
                seen.push(p.period);
                if seen.len() == stop_at {
                    ControlFlow::Break(())
                } else {
                    ControlFlow::Continue(())
                }
            };
            let request = Request {
                speculation,
                ..request.clone()
            };
            let result: ModeBranches = compute_observed(&system, &request, observer).unwrap();
            (result, seen)
        };
        for stop_at in [0, 5] {
            let (one, seen_one) = run(None, stop_at);
            let (beside, seen_beside) = run(Some(Speculation::default()), stop_at);
            assert_eq!(one.points, beside.points);
            assert_eq!(one.end, beside.end);
            assert_eq!(seen_one, seen_beside);
            let labelled = one.points.iter().filter(|p| p.label.is_some()).count();
            assert!(labelled > 0, "labelled points");
            if stop_at > 0 {
                assert_eq!(one.end, EndReason::StoppedByObserver);
                assert_eq!(one.points.len(), stop_at);
            } else {
                assert_eq!(one.points.len(), grid.steps);
            }
        }
    }
}
