//! Pseudo-arclength continuation with step-size control and event detection.
//!
//! The branch is followed in `y = (x, lambda)` (the [`augmented`] layout, parameter last)
//! with the scaled inner product
//! `<a, b>_W = sum_i a_i b_i / s_x^2 + a_lambda b_lambda / s_lambda^2`, so that a step `ds`
//! measures the relative change of the whole state (end values are of the order of the gap
//! `g0` while `Omega` is of order 1). From an accepted point `y_k` with unit tangent `t_k`:
//!
//! 1. **predict** `y_p = y_k + ds t_k` (tangent from the bordered Jacobian, or secant);
//! 2. **correct** with any [`NonlinearSolver`] on the bordered system
//!    `F(x, lambda) = 0`, `<t_k, y - y_p>_W = 0`;
//! 3. **control** the step: a converged corrector that needed at most `fast_iterations`
//!    grows `ds` (up to `ds_max`); a failed one, a jump (`|y - y_p|_W > jump_ratio ds`) or a
//!    turn of the tangent sharper than `max_turn` halves it and retries from `y_k`, which is
//!    never modified; below `ds_min` the run ends.
//!
//! The run ends when the parameter leaves `parameter_range`, after `max_steps` accepted
//! points, when the step falls below `ds_min`, or after more than `max_rejections` rejected
//! steps ([`EndReason`]). The driver follows the branch wherever it goes; strategies that
//! leave it (a jump past a stall of a harmonic-balance backbone,
//! [`StallEscape`](crate::branches::StallEscape)) are written on top of its public methods: a
//! fixed-parameter solve ([`Arclength::solve_at`]) and a restart from the solution found
//! ([`Arclength::restart_from`]), which keeps the driver's scale, counters and acceptance test.
//!
//! Events are reported on accepted points: folds (the parameter component of the tangent
//! changes sign), jumps that could not be refined away, and grazing (the problem's active
//! set, see [`Structured::active_set`], appears or disappears).
//!
//! Reference: E. L. Allgower and K. Georg, *Introduction to Numerical Continuation Methods*,
//! SIAM Classics in Applied Mathematics 45 (2003), chapter 2.

mod bordered;
mod bracket;
mod branching;
mod options;
mod resume;

pub use options::{ArclengthOptions, ArclengthScale, TangentPredictor};

use super::augmented;
use super::driver::{next_point, run_with, Admission};
use super::{
    Branch, ContinuationProblem, EndReason, Event, Observer, Point, RejectReason, Rejection, Step,
};
use crate::error::{ContinuationError, SolveError};
use crate::linalg::{DenseMatrix, Lu};
use crate::solve::{NonlinearSolver, Problem, SolveInfo, Structured, PIVOT_TOLERANCE};
use bordered::{BorderScratch, Bordered, Metric};
use bracket::Bracket;

/// Pseudo-arclength continuation driver, generic over the problem and the corrector.
pub struct Arclength<'a, P, S> {
    problem: P,
    solver: S,
    options: ArclengthOptions,
    metric: Metric,
    y: Vec<f64>,
    tangent: Vec<f64>,
    previous: Option<Vec<f64>>,
    active: Option<Vec<usize>>,
    ds: f64,
    accepted: usize,
    /// The corrected start, handed out by the first step.
    start: Option<Point>,
    finished: Option<EndReason>,
    /// Whether the iterator has handed out the end.
    done: bool,
    /// Rejected steps so far.
    rejections: usize,
    /// What joins the branch: the acceptance test and the state of rest.
    admission: Admission<'a>,
    border: BorderScratch,
    /// The sign of `det [J, F_lambda; t^T W]` at the current point (`None` when not watched
    /// or exactly singular).
    orientation: Option<f64>,
    /// The last accepted step, when it crossed a branch point.
    bracket: Option<Bracket>,
}

impl<'a, P: ContinuationProblem, S: NonlinearSolver> Arclength<'a, P, S> {
    /// Starts from a solution `x0` at `lambda0` (it is corrected at fixed `lambda0` first;
    /// the first [`Arclength::step`] returns that corrected start as step 0).
    ///
    /// # Errors
    /// Invalid options, a wrong-sized `x0`, a start where the solver fails
    /// ([`ContinuationError::Start`]) or a singular bordered Jacobian there.
    pub fn new(
        mut problem: P,
        solver: S,
        x0: Vec<f64>,
        lambda0: f64,
        options: ArclengthOptions,
    ) -> Result<Self, ContinuationError> {
        options.validate()?;
        let n = problem.dimension();
        check_start(&x0, n, lambda0, "starting parameter")?;
        let mut x = x0;
        problem.set_parameter(lambda0);
        let info = solver
            .solve(&mut problem, &mut x)
            .map_err(ContinuationError::Start)?;
        let metric = match options.scale {
            ArclengthScale::Automatic => {
                let raw = problem
                    .structure()
                    .and_then(|s| s.state_weights())
                    .filter(|w| w.len() == n && w.iter().all(|v| v.is_finite() && *v > 0.0))
                    .unwrap_or_else(|| vec![1.0; n]);
                let sx2 = (0..n).map(|i| raw[i] * x[i] * x[i]).sum::<f64>();
                let sx2 = if sx2 > 0.0 {
                    sx2
                } else {
                    raw.iter().sum::<f64>()
                };
                let sl = if lambda0 != 0.0 { lambda0.abs() } else { 1.0 };
                Metric {
                    x_w: raw.iter().map(|w| w / sx2).collect(),
                    lambda_w: 1.0 / (sl * sl),
                }
            }
            ArclengthScale::Fixed(a, b) => Metric {
                x_w: vec![1.0 / (a * a); n],
                lambda_w: 1.0 / (b * b),
            },
        };
        let y = augmented::join(x, lambda0);
        let mut seed = vec![0.0; n + 1];
        seed[n] = options.direction;
        let mut driver = Self {
            problem,
            solver,
            ds: options.ds,
            options,
            metric,
            tangent: Vec::new(),
            y,
            previous: None,
            active: None,
            accepted: 0,
            start: None,
            finished: None,
            done: false,
            rejections: 0,
            admission: Admission::default(),
            border: BorderScratch::default(),
            orientation: None,
            bracket: None,
        };
        let y = driver.y.clone();
        driver.tangent = driver
            .tangent_at(&y, &seed)
            .ok_or(ContinuationError::SingularTangent { lambda: lambda0 })?;
        driver.orientation = driver.orientation_at(&y, &driver.tangent.clone());
        driver.active = driver.active_set();
        driver.start = Some(driver.point(0, &info, Vec::new()));
        Ok(driver)
    }

    /// Lets points at the problem's state of rest join the branch, which a problem that knows
    /// it ([`Structured::at_rest`](crate::solve::Structured::at_rest)) has refused by default
    /// ([`RejectReason::NotAccepted`]), as
    /// [`Sequential::with_rest_accepted`](crate::continuation::Sequential::with_rest_accepted)
    /// says.
    pub fn with_rest_accepted(mut self) -> Self {
        self.admission.rest = true;
        self
    }

    /// Adds a test every accepted point must pass (for instance "not the state of rest"); a
    /// failing corrected point is rejected like a solver failure. The test may borrow from
    /// the caller (the system it measures energies with) for the driver's lifetime `'a`.
    pub fn with_acceptance(mut self, accept: impl FnMut(&[f64], f64) -> bool + 'a) -> Self {
        self.admission.test = Some(Box::new(accept));
        self
    }

    /// Restarts from a stored point of a branch (e.g. after changing options or direction).
    ///
    /// # Errors
    /// As [`Arclength::new`].
    pub fn restart(
        problem: P,
        solver: S,
        point: &Point,
        options: ArclengthOptions,
    ) -> Result<Self, ContinuationError> {
        Self::new(problem, solver, point.x.clone(), point.parameter, options)
    }

    /// The problem.
    pub fn problem_mut(&mut self) -> &mut P {
        &mut self.problem
    }

    /// The problem and the solver, giving up the driver.
    pub fn into_parts(self) -> (P, S) {
        (self.problem, self.solver)
    }

    /// The options the driver runs with.
    pub fn options(&self) -> &ArclengthOptions {
        &self.options
    }

    /// The current point `y = (x, lambda)` ([`augmented`] layout): the last accepted point
    /// (the corrected start before any step). Rejected steps never change it.
    pub fn state(&self) -> &[f64] {
        &self.y
    }

    /// Rejected steps so far (the one that ended a run past
    /// [`ArclengthOptions::max_rejections`] included).
    pub fn rejections(&self) -> usize {
        self.rejections
    }

    /// The scaled norm `|v|_W` of the step control: `v = (x, lambda)` with the problem's
    /// dimension plus one entries, or a state `x` alone (its `x` part). Under
    /// [`ArclengthScale::Automatic`] the corrected start has `|x0|_W = 1` (unless it is 0).
    pub fn norm(&self, v: &[f64]) -> f64 {
        self.metric.norm(v)
    }

    /// The parameter scale `s_lambda` of [`Arclength::norm`]: `|(0, lambda)|_W =
    /// |lambda| / s_lambda`.
    pub fn parameter_scale(&self) -> f64 {
        1.0 / self.metric.lambda_w.sqrt()
    }

    /// Solves `F(x, lambda) = 0` at the fixed parameter `lambda` from `x` (updated in place)
    /// with the driver's problem and solver. The branch is unchanged; a solution can become
    /// its next point through [`Arclength::restart_from`].
    ///
    /// # Errors
    /// The solver's.
    pub fn solve_at(&mut self, x: &mut [f64], lambda: f64) -> Result<SolveInfo, SolveError> {
        self.problem.set_parameter(lambda);
        self.solver.solve(&mut self.problem, x)
    }

    /// Whether the state `x` at `lambda` may join the branch: not at the problem's state of
    /// rest (unless [`Arclength::with_rest_accepted`]) and taken by the acceptance test
    /// ([`Arclength::with_acceptance`]; `true` without a test). The problem is not moved to
    /// `lambda`.
    pub fn accepts(&mut self, x: &[f64], lambda: f64) -> bool {
        self.admission.admits(&mut self.problem, x, lambda)
    }

    /// Continues the branch from another solution `x` at `lambda` (one found by
    /// [`Arclength::solve_at`], for instance): `x` is corrected at fixed `lambda`, the tangent
    /// there is oriented along [`ArclengthOptions::direction`] in `lambda`, and the point
    /// becomes the current one, numbered as the next step (it counts towards `max_steps`),
    /// with no events and `step_size = 0`. The step size goes back to `options.ds` and the
    /// secant history is forgotten; the scale of the norm, the counts of accepted and
    /// rejected steps and the acceptance test (not applied to this point) are kept, and a
    /// driver that had finished runs again. Unlike [`Arclength::restart`], which builds a
    /// driver with a scale of its own, the steps that follow are measured as before.
    ///
    /// # Errors
    /// A wrong-sized `x` or a non-finite `lambda`, a failed correction
    /// ([`ContinuationError::Start`]) or a singular bordered Jacobian; the driver is then
    /// unchanged.
    pub fn restart_from(&mut self, x: Vec<f64>, lambda: f64) -> Result<Point, ContinuationError> {
        let n = self.problem.dimension();
        check_start(&x, n, lambda, "restart parameter")?;
        let mut x = x;
        let info = self
            .solve_at(&mut x, lambda)
            .map_err(ContinuationError::Start)?;
        let y = augmented::join(x, lambda);
        let mut seed = vec![0.0; n + 1];
        seed[n] = self.options.direction;
        let tangent = self
            .tangent_at(&y, &seed)
            .ok_or(ContinuationError::SingularTangent { lambda })?;
        Ok(self.adopt(y, tangent, &info, Vec::new()))
    }

    /// Current step size.
    pub fn step_size(&self) -> f64 {
        self.ds
    }

    /// Current unit tangent `(dx, dlambda)` in the scaled norm.
    pub fn tangent(&self) -> &[f64] {
        &self.tangent
    }

    /// The active sets of the problem at the current point.
    fn active_set(&mut self) -> Option<Vec<usize>> {
        let (x, lambda) = augmented::split(&self.y)?;
        self.problem.set_parameter(lambda);
        self.problem.structure().and_then(|s| s.active_set(x))
    }

    /// The prediction `y_p = from + h direction` and the corrector's solution of `F = 0` on
    /// the hyperplane `<direction, y - y_p>_W = 0` through it (its last iterate on failure).
    fn predict_and_correct(
        &mut self,
        from: &[f64],
        direction: &[f64],
        h: f64,
    ) -> (Vec<f64>, Vec<f64>, Result<SolveInfo, SolveError>) {
        let predicted: Vec<f64> = (from.iter().zip(direction))
            .map(|(y, t)| y + h * t)
            .collect();
        let mut y = predicted.clone();
        let mut bordered = Bordered::new(
            &mut self.problem,
            (direction, &predicted),
            &self.metric,
            &mut self.border,
        );
        let result = self.solver.solve(&mut bordered, &mut y);
        (predicted, y, result)
    }

    /// Unit tangent at `y` oriented along `reference` (`<t, reference>_W > 0`).
    fn tangent_at(&mut self, y: &[f64], reference: &[f64]) -> Option<Vec<f64>> {
        let n = self.problem.dimension();
        // The bordered Jacobian with `reference` as border: its solution for `e_n` is the
        // tangent (up to scale) oriented along `reference`.
        let mut t = vec![0.0; n + 1];
        t[n] = 1.0;
        let mut bordered = Bordered::new(
            &mut self.problem,
            (reference, y),
            &self.metric,
            &mut self.border,
        );
        let structured = bordered
            .solve_jacobian(y, &mut t, 1)
            .is_some_and(|r| r.is_ok());
        if !structured {
            let mut b = DenseMatrix::default();
            bordered.jacobian(y, &mut b);
            let lu = Lu::factor(&b, PIVOT_TOLERANCE).ok()?;
            t.fill(0.0);
            t[n] = 1.0;
            lu.solve_in_place(&mut t);
        }
        let len = self.metric.norm(&t);
        if !(len.is_finite() && len > 0.0) {
            return None;
        }
        t.iter_mut().for_each(|v| *v /= len);
        Some(t)
    }

    fn point(&mut self, step: usize, info: &SolveInfo, events: Vec<Event>) -> Point {
        let n = self.problem.dimension();
        Point {
            step,
            parameter: self.y[n],
            x: self.y[..n].to_vec(),
            residual_norm: info.residual_norm,
            iterations: info.iterations,
            converged: true,
            error: None,
            step_size: self.ds,
            events,
        }
    }

    fn reject(&mut self, lambda: f64, reason: RejectReason) -> Step {
        let rejection = Rejection {
            step: self.accepted + 1,
            parameter: lambda,
            step_size: self.ds,
            reason,
            point: None,
        };
        self.rejections += 1;
        self.ds *= self.options.shrink;
        let end = if self.ds < self.options.ds_min {
            EndReason::StepBelowMinimum {
                last: Box::new(rejection),
            }
        } else if self.rejections > self.options.max_rejections {
            EndReason::TooManyRejections {
                rejections: self.rejections,
                last: Box::new(rejection),
            }
        } else {
            return Step::Rejected(rejection);
        };
        self.finished = Some(end.clone());
        Step::Finished(end)
    }

    /// One predictor–corrector attempt (the first call returns the corrected start).
    pub fn step(&mut self) -> Step {
        if let Some(start) = self.start.take() {
            return Step::Accepted(start);
        }
        if let Some(end) = &self.finished {
            return Step::Finished(end.clone());
        }
        if self.accepted >= self.options.max_steps {
            self.finished = Some(EndReason::MaxSteps);
            return Step::Finished(EndReason::MaxSteps);
        }
        let n = self.problem.dimension();
        let secant = match (self.options.predictor, &self.previous) {
            (TangentPredictor::Secant, Some(prev)) => {
                let mut d: Vec<f64> = self.y.iter().zip(prev).map(|(a, b)| a - b).collect();
                let len = self.metric.norm(&d);
                // Two equal points (a step far below rounding) have no secant.
                (len > 0.0 && len.is_finite()).then(|| {
                    d.iter_mut().for_each(|v| *v /= len);
                    d
                })
            }
            _ => None,
        };
        let direction = secant.unwrap_or_else(|| self.tangent.clone());
        // The corrector does not read the current point: lend it out instead of copying it.
        let from = std::mem::take(&mut self.y);
        let (predicted, y, result) = self.predict_and_correct(&from, &direction, self.ds);
        self.y = from;
        let info = match result {
            Ok(info) => info,
            Err(e) => return self.reject(predicted[n], RejectReason::Solver(e)),
        };
        if !self.accepts(&y[..n], y[n]) {
            return self.reject(y[n], RejectReason::NotAccepted);
        }
        let distance: Vec<f64> = y.iter().zip(&predicted).map(|(a, b)| a - b).collect();
        let ratio = self.metric.norm(&distance) / self.ds;
        let at_floor = self.ds * self.options.shrink < self.options.ds_min;
        let mut events = Vec::new();
        if ratio > self.options.jump_ratio {
            if !at_floor {
                return self.reject(y[n], RejectReason::Jump { ratio });
            }
            events.push(Event::Jump { ratio });
        }
        let Some(tangent) = self.tangent_at(&y, &direction) else {
            return self.reject(y[n], RejectReason::SingularTangent);
        };
        let cos = (0..=n)
            .map(|i| tangent[i] * self.tangent[i] * self.metric.weight(i))
            .sum::<f64>()
            .clamp(-1.0, 1.0);
        let angle = cos.acos();
        if angle > self.options.max_turn && !at_floor {
            return self.reject(y[n], RejectReason::Turn { angle });
        }
        let (lo, hi) = self.options.parameter_range;
        if y[n] < lo || y[n] > hi {
            let end = EndReason::ParameterOutOfRange { parameter: y[n] };
            self.finished = Some(end.clone());
            return Step::Finished(end);
        }
        if tangent[n] * self.tangent[n] < 0.0 {
            events.push(Event::Fold { parameter: y[n] });
        }
        let orientation = self.orientation_at(&y, &tangent);
        self.problem.set_parameter(y[n]);
        let active = self.problem.structure().and_then(|s| s.active_set(&y[..n]));
        let same_active = match (&self.active, &active) {
            (Some(old), Some(new)) => old == new,
            _ => true,
        };
        let crossed = matches!((self.orientation, orientation), (Some(a), Some(b)) if a != b);
        self.bracket = (crossed && same_active).then(|| Bracket::new(&self.y, &y, &tangent));
        if self.bracket.is_some() {
            events.push(Event::BranchPoint { parameter: y[n] });
        }
        self.orientation = orientation;
        if let (Some(old), Some(new)) = (&self.active, &active) {
            for (law, (a, b)) in old.iter().zip(new).enumerate() {
                if (*a == 0) != (*b == 0) {
                    events.push(Event::Grazing {
                        law,
                        contact: *b > 0,
                    });
                }
            }
        }
        self.active = active;
        self.previous = Some(std::mem::replace(&mut self.y, y));
        self.tangent = tangent;
        self.accepted += 1;
        let step_used = self.ds;
        if info.iterations <= self.options.fast_iterations {
            self.ds = (self.ds * self.options.growth).min(self.options.ds_max);
        }
        let mut point = self.point(self.accepted, &info, events);
        point.step_size = step_used;
        Step::Accepted(point)
    }

    /// Runs until the end, handing every step (the start, accepted points and rejections) to
    /// `observer`, which may stop the run; returns the branch.
    pub fn run(&mut self, observer: &mut (impl Observer + ?Sized)) -> Branch {
        run_with(
            self,
            Self::step,
            |d| d.finished = Some(EndReason::StoppedByObserver),
            observer,
        )
    }
}

/// Checks a starting state `x` of a problem of dimension `n` at parameter `lambda`, named
/// `what` in the error.
fn check_start(
    x: &[f64],
    n: usize,
    lambda: f64,
    what: &'static str,
) -> Result<(), ContinuationError> {
    if x.len() != n {
        return Err(ContinuationError::Dimension {
            got: x.len(),
            expected: n,
        });
    }
    if !lambda.is_finite() {
        return Err(ContinuationError::InvalidOption {
            what,
            value: lambda,
        });
    }
    Ok(())
}

impl<P: ContinuationProblem, S: NonlinearSolver> Iterator for Arclength<'_, P, S> {
    type Item = Result<Point, ContinuationError>;

    /// The accepted points (rejections are retried internally); then, if the run failed
    /// ([`EndReason::error`]), its error; then `None`.
    fn next(&mut self) -> Option<Self::Item> {
        next_point(self, |d| &mut d.done, Self::step)
    }
}

#[cfg(test)]
mod tests;
