//! The shape shared by the continuation drivers: what a step did, why a run ended, the branch
//! it returns, and the observers that watch it.
//!
//! Every driver offers three ways in:
//! - `step()`, returning a [`Step`]: the caller owns the loop;
//! - `Iterator<Item = Result<Point, ContinuationError>>`: the accepted points, then the error
//!   of a run that failed ([`EndReason::error`]), then `None`;
//! - `run(&mut observer)`, returning a [`Branch`] whose [`Branch::end`] is always set; the
//!   [`Observer`] (a closure works) sees every step, accepted or rejected, and can stop the run.

use super::Point;
use crate::error::{ContinuationError, SolveError};
use crate::solve::{at_rest, Problem};
use std::ops::ControlFlow;

/// What one call of a driver's `step()` did.
#[derive(Debug, Clone, PartialEq)]
pub enum Step {
    /// A point joined the branch.
    Accepted(Point),
    /// A step was tried and did not join the branch, which stays at its last point.
    Rejected(Rejection),
    /// The run is over; every later call returns the same reason.
    Finished(EndReason),
}

impl Step {
    /// The point this step reports: the accepted point, or where the solver stopped in a
    /// rejected step when the driver reports it (`converged == false`); `None` otherwise.
    pub fn point(&self) -> Option<&Point> {
        match self {
            Self::Accepted(p) => Some(p),
            Self::Rejected(r) => r.point.as_ref(),
            Self::Finished(_) => None,
        }
    }
}

/// A step that did not join the branch.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Rejection {
    /// Step number the step would have had.
    pub step: usize,
    /// Parameter value tried (the predicted one, or the corrected one when the corrector
    /// converged).
    pub parameter: f64,
    /// Step tried: the parameter increment for natural-parameter runs, the arclength `ds`
    /// for pseudo-arclength runs.
    pub step_size: f64,
    /// Why.
    pub reason: RejectReason,
    /// Where the solver stopped, as a point with `converged == false` (natural-parameter
    /// runs report it; pseudo-arclength runs retry with a smaller step instead).
    pub point: Option<Point>,
}

/// Why a step was rejected.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[non_exhaustive]
pub enum RejectReason {
    /// The solver (corrector) failed.
    Solver(SolveError),
    /// The corrected point is far from the prediction.
    Jump {
        /// `|y - y_p|_W / ds`.
        ratio: f64,
    },
    /// The tangent turned too sharply.
    Turn {
        /// Angle between successive tangents, radians.
        angle: f64,
    },
    /// The bordered Jacobian for the tangent is singular.
    SingularTangent,
    /// The driver's acceptance test (`with_acceptance`) refused the converged point.
    NotAccepted,
}

/// Why a run ended.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[non_exhaustive]
pub enum EndReason {
    /// Every requested parameter value was visited (natural-parameter runs).
    Completed,
    /// The largest number of accepted points was reached.
    MaxSteps,
    /// The corrected parameter left the allowed range (the point is not kept).
    ParameterOutOfRange {
        /// The parameter value reached.
        parameter: f64,
    },
    /// The step fell below its minimum.
    StepBelowMinimum {
        /// The last rejection.
        last: Box<Rejection>,
    },
    /// More steps were rejected than the run allows
    /// ([`ArclengthOptions::max_rejections`](super::ArclengthOptions::max_rejections)).
    TooManyRejections {
        /// Rejected steps, the last one included.
        rejections: usize,
        /// The last rejection.
        last: Box<Rejection>,
    },
    /// The observer returned `ControlFlow::Break`.
    StoppedByObserver,
    /// The branch is lost: too many consecutive failed steps (natural-parameter runs), or
    /// every attempt to leave a stall failed (a strategy on top of a driver, such as the
    /// backbone's [`StallEscape`](crate::branches::StallEscape)).
    Stalled {
        /// Consecutive failures, or attempts.
        failures: usize,
        /// Parameter value where the run stalled.
        parameter: f64,
    },
    /// A run asked to switch branches at a branch point could not
    /// ([`Arclength::switch_branch`](crate::continuation::Arclength::switch_branch)).
    SwitchFailed {
        /// Why.
        #[cfg_attr(feature = "serde", serde(serialize_with = "crate::error::display"))]
        error: Box<ContinuationError>,
    },
}

impl EndReason {
    /// The error of a run that ended by failing (`Stalled`, `StepBelowMinimum`,
    /// `TooManyRejections`); `None` for a run that ended as asked.
    pub fn error(&self) -> Option<ContinuationError> {
        match self {
            Self::Stalled {
                failures,
                parameter,
            } => Some(ContinuationError::Stalled {
                failures: *failures,
                parameter: *parameter,
            }),
            Self::StepBelowMinimum { last } => Some(ContinuationError::StepBelowMinimum {
                step_size: last.step_size,
                parameter: last.parameter,
            }),
            Self::TooManyRejections { rejections, last } => {
                Some(ContinuationError::TooManyRejections {
                    rejections: *rejections,
                    parameter: last.parameter,
                })
            }
            Self::SwitchFailed { error } => Some((**error).clone()),
            _ => None,
        }
    }
}

/// The points of a run with how it ended.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Branch {
    /// Accepted points in order.
    pub points: Vec<Point>,
    /// Number of rejected steps.
    pub rejections: usize,
    /// Why the run ended.
    pub end: EndReason,
}

impl Branch {
    /// Points carrying an event of the given kind (by predicate).
    pub fn with_event(
        &self,
        mut which: impl FnMut(&super::Event) -> bool,
    ) -> impl Iterator<Item = &Point> {
        self.points
            .iter()
            .filter(move |p| p.events.iter().any(&mut which))
    }
}

/// Watches a run step by step; `ControlFlow::Break` stops it (the run then ends with
/// [`EndReason::StoppedByObserver`]). Any closure `FnMut(&Step) -> ControlFlow<()>` is one.
pub trait Observer {
    /// Called with every step's outcome, the final one included.
    fn observe(&mut self, step: &Step) -> ControlFlow<()>;
}

impl<F: FnMut(&Step) -> ControlFlow<()>> Observer for F {
    fn observe(&mut self, step: &Step) -> ControlFlow<()> {
        self(step)
    }
}

/// A test that a converged solution `(x, lambda)` belongs to the branch. It lives as long as
/// the driver's lifetime `'a`, so it may borrow what the caller owns (the system, a judge).
pub(super) type Acceptance<'a> = Box<dyn FnMut(&[f64], f64) -> bool + 'a>;

/// What a driver lets join its branch: not the problem's state of rest
/// ([`Structured::at_rest`](crate::solve::Structured::at_rest)) unless `rest` allows it, and
/// what the caller's acceptance test (if any) takes. One for every driver, so that they refuse
/// alike.
#[derive(Default)]
pub(super) struct Admission<'a> {
    /// The caller's test (`with_acceptance`).
    pub(super) test: Option<Acceptance<'a>>,
    /// Whether the state of rest may join (`with_rest_accepted`).
    pub(super) rest: bool,
}

impl Admission<'_> {
    /// Whether the converged solution `x` at `lambda` of `problem` joins the branch.
    pub(super) fn admits(&mut self, problem: &mut impl Problem, x: &[f64], lambda: f64) -> bool {
        if !self.rest && at_rest(problem, x) {
            return false;
        }
        self.test.as_mut().is_none_or(|test| test(x, lambda))
    }
}

/// Steps `driver` with `step` until the run ends or `observer` stops it, collecting the
/// branch. `stop` records an observer's stop in the driver, so that later steps report it.
pub(crate) fn run_with<D>(
    driver: &mut D,
    mut step: impl FnMut(&mut D) -> Step,
    stop: impl FnOnce(&mut D),
    observer: &mut (impl Observer + ?Sized),
) -> Branch {
    let (mut points, mut rejections) = (Vec::new(), 0);
    loop {
        let outcome = step(driver);
        let stopped = observer.observe(&outcome).is_break();
        match outcome {
            Step::Accepted(p) => points.push(p),
            Step::Rejected(_) => rejections += 1,
            Step::Finished(end) => {
                return Branch {
                    points,
                    rejections,
                    end,
                }
            }
        }
        if stopped {
            stop(driver);
            return Branch {
                points,
                rejections,
                end: EndReason::StoppedByObserver,
            };
        }
    }
}

/// The next item of a driver's iterator, stepping `driver` with `step`: the next accepted
/// point, the error of a run that failed, or `None` at the end. The flag `done` of the
/// driver is set once the end has been handed out.
pub(crate) fn next_point<D>(
    driver: &mut D,
    done: fn(&mut D) -> &mut bool,
    step: fn(&mut D) -> Step,
) -> Option<Result<Point, ContinuationError>> {
    if *done(driver) {
        return None;
    }
    loop {
        match step(driver) {
            Step::Accepted(p) => return Some(Ok(p)),
            Step::Rejected(_) => continue,
            Step::Finished(end) => {
                *done(driver) = true;
                return end.error().map(Err);
            }
        }
    }
}
