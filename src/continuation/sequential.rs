//! Sequential (natural-parameter) continuation.

use super::driver::{next_point, run_with, Admission};
use super::{
    Branch, ContinuationProblem, EndReason, Observer, Point, RejectReason, Rejection, Step,
};
use crate::error::{BadRange, ContinuationError, RangeDefect, SolveError};
use crate::solve::{failed_point, NonlinearSolver, SolveInfo};
use std::collections::VecDeque;

/// How the next starting guess is formed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Predictor {
    /// The last converged solution (default; the paper's choice).
    #[default]
    Constant,
    /// Linear extrapolation through the last two converged solutions (secant).
    Secant,
}

/// How a step of the [`Sequential`] driver chooses among the solutions reached from its
/// starts.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Selection {
    /// Solve from the prediction; if that fails, from up to
    /// [`SequentialOptions::retry_depth`] earlier converged points in turn, the most recent
    /// first, and keep the first accepted solution. A successful retry drops the points it
    /// stepped over from the history (default).
    #[default]
    FirstConverged,
    /// Solve from the prediction and from each of up to [`SequentialOptions::retry_depth`]
    /// earlier converged points, and keep the accepted solution with the lowest measure
    /// ([`Sequential::with_measure`]; a NaN measure ranks last, ties keep the most recent
    /// start). The history is a rolling window of the last converged points: a retry does
    /// not drop the points it stepped over.
    ///
    /// Why: the first converged start is not always the right one. Near an internal
    /// resonance of a truncated system the last point can lead to a solution carrying extra
    /// energy in a resonant harmonic (a spike, or a neighbouring branch) while an earlier
    /// point leads back to the backbone; with the energy as measure the start that reaches
    /// the lowest energy is the one still on the backbone. The cost: every step solves from
    /// all its starts, about `retry_depth` extra solves per step (see
    /// [`BackboneOptions::selection`](crate::branches::BackboneOptions::selection) for the
    /// measured trade-off on the clamped bar). Without a measure it is
    /// [`Selection::FirstConverged`].
    LowestMeasure,
}

/// Options of the [`Sequential`] driver.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SequentialOptions {
    /// Predictor (default [`Predictor::Constant`]).
    pub predictor: Predictor,
    /// End the run with [`EndReason::Stalled`] after this many consecutive failed steps
    /// (default 40; `usize::MAX` never stops).
    pub max_consecutive_failures: usize,
    /// When a step fails from the prediction, solve it again from up to `retry_depth` earlier
    /// converged points, the most recent first (default 1: the point before the last; 0 is the
    /// paper's plain sequential continuation). Near an internal resonance the last point can
    /// be a resonance spike of the truncated system whose neighbourhood holds no solution at
    /// the next parameter, while an earlier point still leads back to the backbone. A
    /// successful retry drops the points it stepped over from the driver's history (not with
    /// [`Selection::LowestMeasure`], which also uses these points as starts of every step).
    pub retry_depth: usize,
    /// How a step chooses among its starts' solutions (default
    /// [`Selection::FirstConverged`]).
    pub selection: Selection,
}

impl Default for SequentialOptions {
    fn default() -> Self {
        Self {
            predictor: Predictor::Constant,
            max_consecutive_failures: 40,
            retry_depth: 1,
            selection: Selection::FirstConverged,
        }
    }
}

/// Sequential continuation over a fixed list of parameter values: at each value, solve
/// `F(x, lambda) = 0` from the predicted guess (and, if that fails and
/// [`SequentialOptions::retry_depth`] allows, from earlier converged points; with
/// [`Selection::LowestMeasure`] and a measure, from all of them, keeping the lowest measure).
/// Failed steps are reported ([`Step::Rejected`], with the solver's last iterate as a point)
/// and skipped; the next step starts again from the last converged solution.
pub struct Sequential<'a, P, S> {
    pub(super) problem: P,
    pub(super) solver: S,
    values: Vec<f64>,
    options: SequentialOptions,
    next: usize,
    last: Vec<f64>,
    last_lambda: f64,
    /// Converged points before `last`, the most recent first (at most `max(retry_depth, 1)`).
    pub(super) history: VecDeque<(Vec<f64>, f64)>,
    failures: usize,
    /// Why the run ended, once it has.
    finished: Option<EndReason>,
    /// Whether the iterator has handed out the end.
    done: bool,
    /// What joins the branch: the acceptance test and the state of rest.
    pub(super) admission: Admission<'a>,
    measure: Option<Measure<'a>>,
}

/// One solve of a step: where it ended, how, and from which start.
pub(super) struct Attempt {
    pub x: Vec<f64>,
    pub result: Result<SolveInfo, SolveError>,
    /// Whether the acceptance test took the solution.
    pub accepted: bool,
    /// `None` for the prediction, `Some(d)` for the start `history[d]`.
    pub from_history: Option<usize>,
}

impl Attempt {
    /// Whether the solve converged to a solution the driver accepts.
    pub fn joins(&self) -> bool {
        self.result.is_ok() && self.accepted
    }
}

/// A scalar ranking accepted solutions `(x, lambda)` for [`Selection::LowestMeasure`].
type Measure<'a> = Box<dyn FnMut(&[f64], f64) -> f64 + 'a>;

impl<'a, P: ContinuationProblem, S: NonlinearSolver> Sequential<'a, P, S> {
    /// A driver visiting `values` in order from the guess `start`.
    ///
    /// # Errors
    /// [`ContinuationError::InvalidOption`] for an empty or non-finite list, or one whose
    /// step between two successive values overflows; [`ContinuationError::Range`]
    /// ([`RangeDefect::Empty`]) for several values all equal; [`ContinuationError::Dimension`]
    /// for a wrong-sized start.
    pub fn new(
        problem: P,
        solver: S,
        start: Vec<f64>,
        values: Vec<f64>,
        options: SequentialOptions,
    ) -> Result<Self, ContinuationError> {
        if values.is_empty() {
            return Err(ContinuationError::InvalidOption {
                what: "number of parameter values",
                value: 0.0,
            });
        }
        if let Some(v) = values.iter().find(|v| !v.is_finite()) {
            return Err(ContinuationError::InvalidOption {
                what: "parameter value",
                value: *v,
            });
        }
        // Each point reports its step `lambda - previous lambda`: finite values near
        // `±f64::MAX` whose difference overflows would give infinite step sizes.
        if let Some(w) = values.windows(2).find(|w| !(w[1] - w[0]).is_finite()) {
            return Err(ContinuationError::InvalidOption {
                what: "parameter value (its step from the previous one overflows)",
                value: w[1],
            });
        }
        // Several values, all equal: every step would compute the same point again.
        let last = values[values.len() - 1];
        if values.len() >= 2 && values.iter().all(|&v| v == values[0]) {
            let given = (values[0], last, values.len());
            return Err(bad_grid("parameter values", given, RangeDefect::Empty));
        }
        if start.len() != problem.dimension() {
            return Err(ContinuationError::Dimension {
                got: start.len(),
                expected: problem.dimension(),
            });
        }
        Ok(Self {
            last_lambda: values[0],
            problem,
            solver,
            values,
            options,
            next: 0,
            last: start,
            history: VecDeque::new(),
            failures: 0,
            finished: None,
            done: false,
            admission: Admission::default(),
            measure: None,
        })
    }

    /// Adds a test a converged solution must pass to join the branch (for instance "not the
    /// state of rest"). A rejected point is reported with `converged = false` and no error,
    /// and counts as a failure. The test may borrow from the caller (the system it measures
    /// energies with): it lives as long as the driver's lifetime `'a`.
    pub fn with_acceptance(mut self, accept: impl FnMut(&[f64], f64) -> bool + 'a) -> Self {
        self.admission.test = Some(Box::new(accept));
        self
    }

    /// Lets solutions at the problem's state of rest join the branch. By default a problem
    /// that knows its rest state ([`Structured::at_rest`](crate::solve::Structured::at_rest):
    /// every harmonic-balance system of this crate) has such solutions refused, as failed
    /// steps ([`RejectReason::NotAccepted`]): rest solves the equations of every unforced
    /// mode, and a run that slides to it has left its branch. A caller whose own acceptance
    /// test decides (the backbones' energy floor) or who studies the approach to rest opts
    /// out here.
    pub fn with_rest_accepted(mut self) -> Self {
        self.admission.rest = true;
        self
    }

    /// Sets the measure [`Selection::LowestMeasure`] minimises over a step's accepted
    /// solutions (for a backbone, the energy). It is called once per accepted solution, right
    /// after the acceptance test took it (so it may reuse what the test computed), and only
    /// with [`Selection::LowestMeasure`]. A NaN measure ranks last. Like the acceptance test,
    /// it may borrow from the caller for the driver's lifetime `'a`.
    pub fn with_measure(mut self, measure: impl FnMut(&[f64], f64) -> f64 + 'a) -> Self {
        self.measure = Some(Box::new(measure));
        self
    }

    /// Whether steps keep the lowest-measure solution ([`Selection::LowestMeasure`] with a
    /// measure) rather than the first accepted one.
    pub(super) fn selects_lowest(&self) -> bool {
        self.options.selection == Selection::LowestMeasure && self.measure.is_some()
    }

    /// The measure of an accepted solution, NaN (or no measure) ranked last.
    fn measure_of(&mut self, x: &[f64], lambda: f64) -> f64 {
        match self.measure.as_mut().map(|m| m(x, lambda)) {
            Some(v) if !v.is_nan() => v,
            _ => f64::INFINITY,
        }
    }

    /// The problem (for post-processing between steps).
    pub fn problem_mut(&mut self) -> &mut P {
        &mut self.problem
    }

    /// The last converged solution (or the start) and its parameter.
    pub fn last_converged(&self) -> (&[f64], f64) {
        (&self.last, self.last_lambda)
    }

    pub(super) fn predict(&self, lambda: f64) -> Vec<f64> {
        match (self.options.predictor, self.history.front()) {
            (Predictor::Secant, Some((prev, prev_lambda))) if *prev_lambda != self.last_lambda => {
                let s = (lambda - self.last_lambda) / (self.last_lambda - prev_lambda);
                self.last
                    .iter()
                    .zip(prev)
                    .map(|(a, b)| a + s * (a - b))
                    .collect()
            }
            _ => self.last.clone(),
        }
    }

    /// Parameter of the grid value before `step` (the step itself for the first one).
    fn last_lambda_before(&self, step: usize) -> f64 {
        self.values[step.saturating_sub(1)]
    }

    /// Whether a solve's outcome joins the branch: it converged and the driver's
    /// [`Admission`] takes the solution.
    pub(super) fn admits(
        &mut self,
        result: &Result<SolveInfo, SolveError>,
        x: &[f64],
        lambda: f64,
    ) -> bool {
        result.is_ok() && self.admission.admits(&mut self.problem, x, lambda)
    }

    /// Solves at `lambda` from `x` with the driver's own problem; returns the solver's result
    /// and whether the acceptance test (if any) took the solution.
    pub(super) fn attempt(
        &mut self,
        lambda: f64,
        x: &mut [f64],
    ) -> (Result<SolveInfo, SolveError>, bool) {
        self.problem.set_parameter(lambda);
        let result = self.solver.solve(&mut self.problem, x);
        let accepted = self.admits(&result, x, lambda);
        (result, accepted)
    }

    /// Solves at `lambda` from `x`, the start `from_history` (see [`Attempt`]).
    fn attempt_from(
        &mut self,
        lambda: f64,
        mut x: Vec<f64>,
        from_history: Option<usize>,
    ) -> Attempt {
        let (result, accepted) = self.attempt(lambda, &mut x);
        Attempt {
            x,
            result,
            accepted,
            from_history,
        }
    }

    /// The index and value of the next parameter, advancing the driver; the end reason when
    /// the values are exhausted or the run has ended.
    pub(super) fn next_value(&mut self) -> Result<(usize, f64), EndReason> {
        if let Some(end) = &self.finished {
            return Err(end.clone());
        }
        let Some(&lambda) = self.values.get(self.next) else {
            self.finished = Some(EndReason::Completed);
            return Err(EndReason::Completed);
        };
        self.next += 1;
        Ok((self.next - 1, lambda))
    }

    /// The number of earlier converged points a failed step may be retried from.
    pub(super) fn retry_count(&self) -> usize {
        self.options.retry_depth.min(self.history.len())
    }

    /// The start of retry `d`: the converged point `d + 1` places before the last.
    fn retry_start(&self, d: usize) -> Vec<f64> {
        self.history[d].0.clone()
    }

    /// Retries from `history[from..]` while `attempt` has not joined the branch.
    pub(super) fn retry_from(&mut self, lambda: f64, from: usize, attempt: Attempt) -> Attempt {
        let mut attempt = attempt;
        for d in from..self.retry_count() {
            if attempt.joins() {
                break;
            }
            let retried = self.attempt_from(lambda, self.retry_start(d), Some(d));
            if retried.joins() {
                attempt = retried;
            }
        }
        attempt
    }

    /// Solves from every retry start after `first` (the prediction's attempt) and keeps the
    /// accepted solution of lowest measure ([`Selection::LowestMeasure`]); strict comparison,
    /// so ties keep the most recent start. `first` stands if nothing joins the branch.
    fn lowest_from(&mut self, lambda: f64, first: Attempt) -> Attempt {
        let mut best = first.joins().then(|| self.measure_of(&first.x, lambda));
        let mut chosen = first;
        for d in 0..self.retry_count() {
            let retried = self.attempt_from(lambda, self.retry_start(d), Some(d));
            if retried.joins() {
                let value = self.measure_of(&retried.x, lambda);
                if best.is_none_or(|b| value < b) {
                    best = Some(value);
                    chosen = retried;
                }
            }
        }
        chosen
    }

    /// Solves at the next parameter value.
    pub fn step(&mut self) -> Step {
        let (step, lambda) = match self.next_value() {
            Ok(next) => next,
            Err(end) => return Step::Finished(end),
        };
        let prediction = self.predict(lambda);
        let first = self.attempt_from(lambda, prediction, None);
        let chosen = if self.selects_lowest() {
            self.lowest_from(lambda, first)
        } else {
            self.retry_from(lambda, 0, first)
        };
        self.conclude(step, lambda, chosen)
    }

    /// Records the outcome of the step at `lambda`: on success the point joins the branch
    /// (and the history), on failure the failure count grows (and the run ends once it
    /// reaches [`SequentialOptions::max_consecutive_failures`]). With
    /// [`Selection::FirstConverged`] a retry from `history[d]` drops the `d` points it stepped
    /// over; with [`Selection::LowestMeasure`] the history is a rolling window of the last
    /// converged points.
    pub(super) fn conclude(&mut self, step: usize, lambda: f64, chosen: Attempt) -> Step {
        let Attempt {
            x,
            result,
            accepted,
            from_history,
        } = chosen;
        match result {
            Ok(info) if accepted => {
                self.failures = 0;
                let last = std::mem::replace(&mut self.last, x.clone());
                match from_history {
                    // Drop the points stepped over; the start used heads the history.
                    Some(d) if !self.selects_lowest() => drop(self.history.drain(..d)),
                    _ => {
                        self.history.push_front((last, self.last_lambda));
                        self.history.truncate(self.options.retry_depth.max(1));
                    }
                }
                self.last_lambda = lambda;
                Step::Accepted(Point {
                    step,
                    parameter: lambda,
                    x,
                    residual_norm: info.residual_norm,
                    iterations: info.iterations,
                    converged: true,
                    error: None,
                    step_size: lambda - self.last_lambda_before(step),
                    events: Vec::new(),
                })
            }
            other => {
                let (error, solved) = match other {
                    Ok(info) => (None, Some(info)),
                    Err(e) => (Some(e), None),
                };
                self.failures += 1;
                self.problem.set_parameter(lambda);
                // A solve that diverged reports the last converged solution (at `lambda`).
                let (x, residual_norm) = failed_point(&mut self.problem, x, &self.last);
                let iterations = match (&error, solved) {
                    (_, Some(info)) => info.iterations,
                    (Some(SolveError::MaxIterations { iterations, .. }), _) => *iterations,
                    (
                        Some(
                            SolveError::LineSearch { iteration, .. }
                            | SolveError::SingularJacobian { iteration, .. }
                            | SolveError::TrustRegion { iteration, .. }
                            | SolveError::Stagnated { iteration, .. }
                            | SolveError::EvaluationBudget { iteration, .. }
                            | SolveError::NonFinite { iteration, .. }
                            | SolveError::Cancelled { iteration, .. },
                        ),
                        _,
                    ) => *iteration,
                    _ => 0,
                };
                let step_size = lambda - self.last_lambda;
                let reason = match &error {
                    Some(e) => RejectReason::Solver(e.clone()),
                    None => RejectReason::NotAccepted,
                };
                let point = Point {
                    step,
                    parameter: lambda,
                    x,
                    residual_norm,
                    iterations,
                    converged: false,
                    error,
                    step_size,
                    events: Vec::new(),
                };
                if self.failures >= self.options.max_consecutive_failures {
                    self.finished = Some(EndReason::Stalled {
                        failures: self.failures,
                        parameter: lambda,
                    });
                }
                Step::Rejected(Rejection {
                    step,
                    parameter: lambda,
                    step_size,
                    reason,
                    point: Some(point),
                })
            }
        }
    }

    /// Runs to the end, handing every step to `observer`, which may stop the run. The
    /// branch holds the converged points; the failed ones were shown to the observer.
    pub fn run(&mut self, observer: &mut (impl Observer + ?Sized)) -> Branch {
        run_with(self, Self::step, Self::stop, observer)
    }

    /// Ends the run at the observer's request.
    pub(super) fn stop(&mut self) {
        self.finished = Some(EndReason::StoppedByObserver);
    }
}

impl<P: ContinuationProblem, S: NonlinearSolver> Iterator for Sequential<'_, P, S> {
    type Item = Result<Point, ContinuationError>;

    /// The converged points; then, if the run stalled, its error; then `None`.
    fn next(&mut self) -> Option<Self::Item> {
        next_point(self, |d| &mut d.done, Self::step)
    }
}

/// `steps` equispaced values from `start` to `end` inclusive (all finite, even where
/// `end - start` overflows).
///
/// # Errors
/// [`ContinuationError::Range`] for non-finite ends or fewer than 2 steps, quoting them;
/// [`ContinuationError::TooLarge`] if the `steps` values do not fit in the memory budget
/// [`MEMORY_BUDGET_BYTES`](crate::fourier::MEMORY_BUDGET_BYTES) (the error carries the bytes
/// they would need).
pub fn linspace(start: f64, end: f64, steps: usize) -> Result<Vec<f64>, ContinuationError> {
    if !(start.is_finite() && end.is_finite()) {
        return Err(bad_grid(
            "grid",
            (start, end, steps),
            RangeDefect::NotFinite,
        ));
    }
    if steps < 2 {
        return Err(bad_grid(
            "grid",
            (start, end, steps),
            RangeDefect::SinglePoint,
        ));
    }
    crate::fourier::check_memory("the values of a grid", steps as f64)?;
    let last = (steps - 1) as f64;
    let h = (end - start) / last;
    let reached = start + h * last;
    if reached.is_finite() && (reached - end).abs() <= 4.0 * f64::EPSILON * end.abs() {
        return Ok((0..steps).map(|i| start + h * i as f64).collect());
    }
    // `end - start` or the last value overflows (ends near `f64::MAX`), or the steps lose
    // `end` to rounding (`1e300 -> 4` would end at 0): interpolate, which ends at `end`
    // exactly and keeps every value between the ends.
    Ok((0..steps)
        .map(|i| {
            let t = i as f64 / last;
            start * (1.0 - t) + end * t
        })
        .collect())
}

/// The grid `what` of `steps` values from `start` to `end`, refused for `defect`.
fn bad_grid(
    what: &'static str,
    (start, end, steps): (f64, f64, usize),
    defect: RangeDefect,
) -> ContinuationError {
    BadRange {
        what,
        start,
        end,
        steps: Some(steps),
        defect,
    }
    .into()
}

/// `steps` values from `start` to `end` (both included, exactly) in geometric progression:
/// equispaced in `ln`, for parameters such as energies that span decades.
///
/// # Errors
/// [`ContinuationError::Range`] for an end that is not positive and finite, or fewer than 2
/// steps, quoting them.
pub fn geomspace(start: f64, end: f64, steps: usize) -> Result<Vec<f64>, ContinuationError> {
    let given = (start, end, steps);
    let defect = if !(start.is_finite() && end.is_finite()) {
        Some(RangeDefect::NotFinite)
    } else if !(start > 0.0 && end > 0.0) {
        Some(RangeDefect::NotPositive)
    } else if steps < 2 {
        Some(RangeDefect::SinglePoint)
    } else {
        None
    };
    if let Some(defect) = defect {
        return Err(bad_grid("geometric grid", given, defect));
    }
    let mut values: Vec<f64> = linspace(start.ln(), end.ln(), steps)?
        .into_iter()
        .map(f64::exp)
        .collect();
    values[0] = start;
    values[steps - 1] = end;
    Ok(values)
}
