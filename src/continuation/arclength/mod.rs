//! Pseudo-arclength continuation with step-size control and event detection.
//!
//! The branch is followed in `y = (x, lambda)` with the scaled inner product
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
//! **Stalls.** Near internal resonances a truncated harmonic-balance branch can turn into an
//! (almost) vertical branch whose energy grows without bound at fixed parameter; the paper
//! abandoned arclength continuation for this reason. With [`StallEscape`] set, a run whose
//! parameter has not progressed by `min_progress` in the requested direction over `window`
//! accepted points jumps: from the recent point of smallest state norm (resonant branches
//! carry more energy than the backbone they leave) it solves at fixed parameter a little
//! beyond the most advanced parameter reached, doubling the distance while the solve fails or
//! lands on a state more than `max_norm_ratio` times larger; it then restarts the tangent
//! there and reports [`Event::Jump`] on that point. Without it, the run follows the
//! branch wherever it goes.
//!
//! Events are reported on accepted points: folds (the parameter component of the tangent
//! changes sign), jumps that could not be refined away, and grazing (the problem's active
//! set, see [`Structured::active_set`], appears or disappears).
//!
//! Reference: E. L. Allgower and K. Georg, *Introduction to Numerical Continuation Methods*,
//! SIAM Classics in Applied Mathematics 45 (2003), chapter 2.

mod bordered;
mod options;

pub use options::{ArclengthOptions, ArclengthScale, StallEscape, TangentPredictor};

use super::driver::{next_point, run_with, Acceptance};
use super::{
    Branch, ContinuationProblem, EndReason, Event, Observer, Point, RejectReason, Rejection, Step,
};
use crate::error::ContinuationError;
use crate::linalg::{DenseMatrix, Lu};
use crate::solve::{NonlinearSolver, Problem, SolveInfo, Structured, PIVOT_TOLERANCE};
use bordered::{BorderScratch, Bordered, Metric};

/// Pseudo-arclength continuation driver, generic over the problem and the corrector.
pub struct Arclength<P, S> {
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
    history: std::collections::VecDeque<(f64, Vec<f64>)>,
    frontier: Option<(f64, Vec<f64>)>,
    accept: Option<Acceptance>,
    border: BorderScratch,
}

impl<P: ContinuationProblem, S: NonlinearSolver> Arclength<P, S> {
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
        if x0.len() != n {
            return Err(ContinuationError::Dimension {
                got: x0.len(),
                expected: n,
            });
        }
        if !lambda0.is_finite() {
            return Err(ContinuationError::InvalidOption {
                what: "starting parameter",
                value: lambda0,
            });
        }
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
        let mut y = x;
        y.push(lambda0);
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
            history: Default::default(),
            frontier: None,
            accept: None,
            border: BorderScratch::default(),
        };
        driver.tangent = driver
            .tangent_at(&driver.y.clone(), &seed)
            .ok_or(ContinuationError::SingularTangent { lambda: lambda0 })?;
        driver.active = driver.active_set();
        driver.start = Some(driver.point(0, &info, Vec::new()));
        Ok(driver)
    }

    /// Adds a test every accepted point must pass (for instance "not the state of rest"); a
    /// failing corrected point is rejected like a solver failure.
    pub fn with_acceptance(mut self, accept: impl FnMut(&[f64], f64) -> bool + 'static) -> Self {
        self.accept = Some(Box::new(accept));
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
        let n = self.problem.dimension();
        self.problem.set_parameter(self.y[n]);
        let x = &self.y[..n];
        self.problem.structure().and_then(|s| s.active_set(x))
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
        self.ds *= self.options.shrink;
        if self.ds < self.options.ds_min {
            if let Some(escape) = self.options.escape {
                if self.history.len() > 1 {
                    return self.escape(&escape, self.y[self.y.len() - 1]);
                }
            }
            let end = EndReason::StepBelowMinimum {
                last: Box::new(rejection),
            };
            self.finished = Some(end.clone());
            return Step::Finished(end);
        }
        Step::Rejected(rejection)
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
        let direction = match (self.options.predictor, &self.previous) {
            (TangentPredictor::Secant, Some(prev)) => {
                let mut d: Vec<f64> = self.y.iter().zip(prev).map(|(a, b)| a - b).collect();
                let len = self.metric.norm(&d);
                d.iter_mut().for_each(|v| *v /= len);
                d
            }
            _ => self.tangent.clone(),
        };
        let predicted: Vec<f64> = self
            .y
            .iter()
            .zip(&direction)
            .map(|(y, t)| y + self.ds * t)
            .collect();
        let mut y = predicted.clone();
        let result = {
            let mut bordered = Bordered::new(
                &mut self.problem,
                (&direction, &predicted),
                &self.metric,
                &mut self.border,
            );
            self.solver.solve(&mut bordered, &mut y)
        };
        let info = match result {
            Ok(info) => info,
            Err(e) => return self.reject(predicted[n], RejectReason::Solver(e)),
        };
        if let Some(accept) = self.accept.as_mut() {
            if !accept(&y[..n], y[n]) {
                return self.reject(y[n], RejectReason::NotAccepted);
            }
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
        self.problem.set_parameter(y[n]);
        let active = self.problem.structure().and_then(|s| s.active_set(&y[..n]));
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
        if let Some(escape) = self.options.escape {
            let dir = self.options.direction;
            if self
                .frontier
                .as_ref()
                .is_none_or(|(l, _)| dir * self.y[n] > dir * l)
            {
                self.frontier = Some((self.y[n], self.y[..n].to_vec()));
            }
            self.history.push_back((self.y[n], self.y[..n].to_vec()));
            if self.history.len() > 2 * escape.window {
                self.history.pop_front();
            }
            if self.is_stalled(&escape) {
                return self.escape(&escape, point.parameter);
            }
        }
        Step::Accepted(point)
    }

    /// Parameter scale `s_lambda`.
    fn lambda_scale(&self) -> f64 {
        1.0 / self.metric.lambda_w.sqrt()
    }

    /// Whether the last `window` accepted points made less than `min_progress` progress.
    fn is_stalled(&self, escape: &StallEscape) -> bool {
        let h = &self.history;
        if h.len() <= escape.window {
            return false;
        }
        let now = h[h.len() - 1].0;
        let then = h[h.len() - 1 - escape.window].0;
        self.options.direction * (now - then) < escape.min_progress * self.lambda_scale()
    }

    /// Jumps past a stall: see [`StallEscape`].
    fn escape(&mut self, escape: &StallEscape, now: f64) -> Step {
        let n = self.problem.dimension();
        let dir = self.options.direction;
        let scale = self.lambda_scale();
        // Anchors: the recent point of least state norm (the backbone below a resonant
        // branch) and the most advanced point ever accepted (the frontier).
        let mut anchors: Vec<(f64, Vec<f64>)> = self
            .history
            .iter()
            .min_by(|a, b| self.metric.norm(&a.1).total_cmp(&self.metric.norm(&b.1)))
            .into_iter()
            .cloned()
            .collect();
        anchors.extend(self.frontier.clone());
        let ahead = anchors
            .iter()
            .chain(self.history.iter())
            .map(|(l, _)| dir * l)
            .fold(f64::NEG_INFINITY, f64::max);
        let mut distance = escape.jump * scale;
        for _ in 0..escape.max_attempts {
            // `ahead` and `distance` are in progress coordinates `dir * lambda`.
            let target = dir * (ahead + distance);
            let (lo, hi) = self.options.parameter_range;
            if target < lo || target > hi {
                let end = EndReason::ParameterOutOfRange { parameter: target };
                self.finished = Some(end.clone());
                return Step::Finished(end);
            }
            for from in &anchors {
                let from_norm = self.metric.norm(&from.1);
                let mut x = from.1.clone();
                self.problem.set_parameter(target);
                let solved = self.solver.solve(&mut self.problem, &mut x);
                let accepted = solved.is_ok()
                    && self.metric.norm(&x) <= escape.max_norm_ratio * from_norm
                    && self.accept.as_mut().is_none_or(|accept| accept(&x, target));
                if let (Ok(info), true) = (solved, accepted) {
                    let mut y = x;
                    y.push(target);
                    let mut seed = vec![0.0; n + 1];
                    seed[n] = dir;
                    if let Some(t) = self.tangent_at(&y, &seed) {
                        let jump: Vec<f64> = y.iter().zip(&self.y).map(|(a, b)| a - b).collect();
                        let ratio = self.metric.norm(&jump) / self.ds;
                        self.previous = None;
                        self.y = y;
                        self.tangent = t;
                        self.history.clear();
                        self.history.push_back((target, self.y[..n].to_vec()));
                        self.active = self.active_set();
                        self.accepted += 1;
                        self.ds = self.options.ds;
                        let mut point =
                            self.point(self.accepted, &info, vec![Event::Jump { ratio }]);
                        point.step_size = target - now;
                        return Step::Accepted(point);
                    }
                }
            }
            distance *= 2.0;
        }
        let end = EndReason::Stalled {
            failures: escape.max_attempts,
            parameter: now,
        };
        self.finished = Some(end.clone());
        Step::Finished(end)
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

impl<P: ContinuationProblem, S: NonlinearSolver> Iterator for Arclength<P, S> {
    type Item = Result<Point, ContinuationError>;

    /// The accepted points (rejections are retried internally); then, if the run failed
    /// ([`EndReason::error`]), its error; then `None`.
    fn next(&mut self) -> Option<Self::Item> {
        let mut done = self.done;
        let item = next_point(&mut done, || self.step());
        self.done = done;
        item
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solve::SemismoothNewton;

    /// `F(x, lambda) = x^2 + lambda^2 - 1`: a circle with folds at `lambda = +-1`.
    struct Circle {
        lambda: f64,
    }

    impl Problem for Circle {
        fn dimension(&self) -> usize {
            1
        }
        fn residual(&mut self, x: &[f64], f: &mut [f64]) {
            f[0] = x[0] * x[0] + self.lambda * self.lambda - 1.0;
        }
        fn jacobian(&mut self, x: &[f64], jac: &mut DenseMatrix) {
            jac.reset(1, 1);
            jac[(0, 0)] = 2.0 * x[0];
        }
    }

    impl ContinuationProblem for Circle {
        fn parameter(&self) -> f64 {
            self.lambda
        }
        fn set_parameter(&mut self, lambda: f64) {
            self.lambda = lambda;
        }
        fn parameter_derivative(&mut self, _: &[f64], df: &mut [f64]) {
            df[0] = 2.0 * self.lambda;
        }
    }

    #[test]
    fn passes_the_fold_of_a_circle_and_comes_back() {
        let options = ArclengthOptions {
            ds: 0.05,
            ds_max: 0.1,
            max_steps: 400,
            parameter_range: (-0.5, 2.0),
            scale: ArclengthScale::Fixed(1.0, 1.0),
            ..Default::default()
        };
        let mut driver = Arclength::new(
            Circle { lambda: 0.0 },
            SemismoothNewton::default(),
            vec![0.9],
            0.0,
            options,
        )
        .unwrap();
        let branch = driver.run(&mut crate::continuation::quiet);
        // Leaves through lambda < -0.5 on the lower half after turning at lambda = 1.
        assert!(
            matches!(branch.end, EndReason::ParameterOutOfRange { parameter } if parameter < -0.5)
        );
        assert_eq!(branch.points[0].step, 0);
        assert!(
            (branch.points[0].x[0] - 1.0).abs() < 1e-9,
            "the corrected start"
        );
        let folds: Vec<_> = branch
            .with_event(|e| matches!(e, Event::Fold { .. }))
            .collect();
        assert_eq!(folds.len(), 1);
        assert!(folds[0].parameter > 0.95);
        assert!(
            branch.points.iter().any(|p| p.x[0] < -0.5),
            "came back on the other side"
        );
        for p in &branch.points {
            assert!((p.x[0].powi(2) + p.parameter.powi(2) - 1.0).abs() < 1e-9);
        }
        // Arclength steps match the geometry: consecutive points are ds apart (chord ~ arc).
        for w in branch.points.windows(2) {
            let chord = ((w[1].x[0] - w[0].x[0]).powi(2)
                + (w[1].parameter - w[0].parameter).powi(2))
            .sqrt();
            assert!((chord - w[1].step_size).abs() < 0.01 * w[1].step_size + 1e-3);
        }
    }

    #[test]
    fn observer_stops_and_secant_works() {
        let options = ArclengthOptions {
            predictor: TangentPredictor::Secant,
            scale: ArclengthScale::Fixed(1.0, 1.0),
            ..Default::default()
        };
        let mut driver = Arclength::new(
            Circle { lambda: 0.0 },
            SemismoothNewton::default(),
            vec![1.0],
            0.0,
            options,
        )
        .unwrap();
        let mut seen = 0;
        let branch = driver.run(&mut |o: &Step| {
            seen += usize::from(matches!(o, Step::Accepted(_)));
            if seen == 5 {
                std::ops::ControlFlow::Break(())
            } else {
                std::ops::ControlFlow::Continue(())
            }
        });
        assert_eq!(branch.points.len(), 5);
        assert_eq!(branch.end, EndReason::StoppedByObserver);
        assert!(matches!(
            driver.step(),
            Step::Finished(EndReason::StoppedByObserver)
        ));
        // The iterator ends at once, without an error.
        assert!(driver.next().is_none());
    }

    #[test]
    fn rejects_bad_options() {
        let bad = [
            ArclengthOptions {
                ds_min: 1.0,
                ds_max: 0.1,
                ds: 0.5,
                ..Default::default()
            },
            ArclengthOptions {
                ds: f64::NAN,
                ..Default::default()
            },
            ArclengthOptions {
                parameter_range: (1.0, 1.0),
                ..Default::default()
            },
            ArclengthOptions {
                parameter_range: (f64::NAN, 1.0),
                ..Default::default()
            },
            ArclengthOptions {
                direction: 0.0,
                ..Default::default()
            },
            ArclengthOptions {
                max_steps: 0,
                ..Default::default()
            },
            ArclengthOptions {
                scale: ArclengthScale::Fixed(0.0, 1.0),
                ..Default::default()
            },
        ];
        for o in bad {
            assert!(matches!(
                Arclength::new(
                    Circle { lambda: 0.0 },
                    SemismoothNewton::default(),
                    vec![1.0],
                    0.0,
                    o
                ),
                Err(ContinuationError::InvalidOption { .. })
            ));
        }
    }
}
