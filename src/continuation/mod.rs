//! Numerical continuation of solution families `F(x, lambda) = 0`.
//!
//! The drivers know nothing about bars: they see a [`ContinuationProblem`] (residual,
//! Jacobian in `x`, derivative in `lambda`) and a [`NonlinearSolver`](crate::solve::NonlinearSolver).
//! [`NonsmoothSystem`](crate::system::NonsmoothSystem) is one in `lambda = Omega`;
//! [`PeriodParametrised`] turns any problem in a frequency into one in the period.
//!
//! Three ways in, for the [`Sequential`] driver: [`Sequential::step`] (the caller owns the
//! loop), `Iterator<Item = Point>`, and [`Sequential::run`] with an observer closure that can
//! stop the run.

mod arclength;
mod progress;
mod sequential;
mod speculative;

pub use arclength::{
    Arclength, ArclengthOptions, ArclengthOutcome, ArclengthScale, Branch, EndReason, RejectReason,
    Rejection, StallEscape, TangentPredictor,
};
pub use progress::{quiet, Progress};
pub use sequential::{linspace, Predictor, Selection, Sequential, SequentialOptions, StepOutcome};
pub use speculative::{Speculation, SpeculationStats};

use crate::error::SolveError;
use crate::linalg::DenseMatrix;
use crate::solve::{point_on_ray, Problem, SingularStep};

/// A family of square systems `F(x, lambda) = 0` in one scalar parameter.
pub trait ContinuationProblem {
    /// Number of unknowns `x` (and equations).
    fn dimension(&self) -> usize;

    /// `F(x, lambda)` into `f`.
    fn residual(&mut self, x: &[f64], lambda: f64, f: &mut [f64]);

    /// Generalised Jacobian `dF/dx` into `jac` (resized by the callee).
    fn jacobian(&mut self, x: &[f64], lambda: f64, jac: &mut DenseMatrix);

    /// `x + t dx` into `trial` and `F(x + t dx, lambda)` into `f` (see
    /// [`Problem::residual_along`]); the default forms the point and calls `residual`.
    fn residual_along(
        &mut self,
        x: &[f64],
        dx: &[f64],
        t: f64,
        lambda: f64,
        trial: &mut [f64],
        f: &mut [f64],
    ) {
        point_on_ray(x, dx, t, trial);
        self.residual(trial, lambda, f);
    }

    /// `dF/dlambda` at fixed `x` into `df`.
    fn parameter_derivative(&mut self, x: &[f64], lambda: f64, df: &mut [f64]);

    /// Typical magnitude of residual entries (see [`Problem::residual_scale`]).
    fn residual_scale(&self) -> f64 {
        1.0
    }

    /// Diagonal weights `w_i` of a natural norm `sum_i w_i x_i^2` of the unknowns at
    /// parameter `lambda` (for harmonic balance, an energy norm). The arclength drivers use it
    /// for their scaled norm; `None` (default) means all weights 1.
    fn state_weights(&mut self, lambda: f64) -> Option<Vec<f64>> {
        let _ = lambda;
        None
    }

    /// A structured Newton step at parameter `lambda` (see [`Problem::newton_step`]); `None`
    /// by default.
    fn newton_step(
        &mut self,
        x: &[f64],
        lambda: f64,
        f: &[f64],
        dx: &mut [f64],
    ) -> Option<Result<(), SingularStep>> {
        let _ = (x, lambda, f, dx);
        None
    }

    /// Sets the smoothing of the nonsmooth terms (see [`Problem::set_smoothing`]); returns
    /// whether the problem supports it (`false` by default).
    fn set_smoothing(&mut self, smoothing: f64) -> bool {
        let _ = smoothing;
        false
    }

    /// For nonsmooth problems: the size of the active set of each unilateral law at
    /// `(x, lambda)` (for harmonic balance, the number of time samples in contact). Drivers
    /// report a grazing event when one of these appears or vanishes. `None` by default.
    fn active_set(&mut self, x: &[f64], lambda: f64) -> Option<Vec<usize>> {
        let _ = (x, lambda);
        None
    }
}

impl<P: ContinuationProblem + ?Sized> ContinuationProblem for &mut P {
    fn dimension(&self) -> usize {
        (**self).dimension()
    }
    fn residual(&mut self, x: &[f64], lambda: f64, f: &mut [f64]) {
        (**self).residual(x, lambda, f)
    }
    fn residual_along(
        &mut self,
        x: &[f64],
        dx: &[f64],
        t: f64,
        lambda: f64,
        trial: &mut [f64],
        f: &mut [f64],
    ) {
        (**self).residual_along(x, dx, t, lambda, trial, f)
    }
    fn jacobian(&mut self, x: &[f64], lambda: f64, jac: &mut DenseMatrix) {
        (**self).jacobian(x, lambda, jac)
    }
    fn parameter_derivative(&mut self, x: &[f64], lambda: f64, df: &mut [f64]) {
        (**self).parameter_derivative(x, lambda, df)
    }
    fn residual_scale(&self) -> f64 {
        (**self).residual_scale()
    }
    fn active_set(&mut self, x: &[f64], lambda: f64) -> Option<Vec<usize>> {
        (**self).active_set(x, lambda)
    }
    fn state_weights(&mut self, lambda: f64) -> Option<Vec<f64>> {
        (**self).state_weights(lambda)
    }
    fn set_smoothing(&mut self, smoothing: f64) -> bool {
        (**self).set_smoothing(smoothing)
    }
    fn newton_step(
        &mut self,
        x: &[f64],
        lambda: f64,
        f: &[f64],
        dx: &mut [f64],
    ) -> Option<Result<(), SingularStep>> {
        (**self).newton_step(x, lambda, f, dx)
    }
}

/// A continuation problem frozen at one parameter value: a [`Problem`] for the solvers.
#[derive(Debug)]
pub struct AtParameter<'a, P: ?Sized> {
    /// The family.
    pub problem: &'a mut P,
    /// The frozen parameter.
    pub lambda: f64,
}

impl<P: ContinuationProblem + ?Sized> Problem for AtParameter<'_, P> {
    fn dimension(&self) -> usize {
        self.problem.dimension()
    }
    fn set_smoothing(&mut self, smoothing: f64) -> bool {
        self.problem.set_smoothing(smoothing)
    }
    fn newton_step(
        &mut self,
        x: &[f64],
        f: &[f64],
        dx: &mut [f64],
    ) -> Option<Result<(), SingularStep>> {
        self.problem.newton_step(x, self.lambda, f, dx)
    }
    fn residual(&mut self, x: &[f64], f: &mut [f64]) {
        self.problem.residual(x, self.lambda, f)
    }
    fn residual_along(&mut self, x: &[f64], dx: &[f64], t: f64, trial: &mut [f64], f: &mut [f64]) {
        self.problem.residual_along(x, dx, t, self.lambda, trial, f)
    }
    fn jacobian(&mut self, x: &[f64], jac: &mut DenseMatrix) {
        self.problem.jacobian(x, self.lambda, jac)
    }
    fn residual_scale(&self) -> f64 {
        self.problem.residual_scale()
    }
}

/// A problem in an angular frequency `Omega`, continued in the period `T = 2 pi / Omega`
/// instead (chain rule `dF/dT = -(2 pi / T^2) dF/dOmega`).
#[derive(Debug, Clone)]
pub struct PeriodParametrised<P>(pub P);

fn omega_of(period: f64) -> f64 {
    2.0 * std::f64::consts::PI / period
}

impl<P: ContinuationProblem> ContinuationProblem for PeriodParametrised<P> {
    fn dimension(&self) -> usize {
        self.0.dimension()
    }
    fn residual(&mut self, x: &[f64], period: f64, f: &mut [f64]) {
        self.0.residual(x, omega_of(period), f)
    }
    fn residual_along(
        &mut self,
        x: &[f64],
        dx: &[f64],
        t: f64,
        period: f64,
        trial: &mut [f64],
        f: &mut [f64],
    ) {
        self.0.residual_along(x, dx, t, omega_of(period), trial, f)
    }
    fn jacobian(&mut self, x: &[f64], period: f64, jac: &mut DenseMatrix) {
        self.0.jacobian(x, omega_of(period), jac)
    }
    fn parameter_derivative(&mut self, x: &[f64], period: f64, df: &mut [f64]) {
        self.0.parameter_derivative(x, omega_of(period), df);
        let chain = -2.0 * std::f64::consts::PI / (period * period);
        df.iter_mut().for_each(|v| *v *= chain);
    }
    fn residual_scale(&self) -> f64 {
        self.0.residual_scale()
    }
    fn active_set(&mut self, x: &[f64], period: f64) -> Option<Vec<usize>> {
        self.0.active_set(x, omega_of(period))
    }
    fn state_weights(&mut self, period: f64) -> Option<Vec<f64>> {
        self.0.state_weights(omega_of(period))
    }
    fn set_smoothing(&mut self, smoothing: f64) -> bool {
        self.0.set_smoothing(smoothing)
    }
    fn newton_step(
        &mut self,
        x: &[f64],
        period: f64,
        f: &[f64],
        dx: &mut [f64],
    ) -> Option<Result<(), SingularStep>> {
        self.0.newton_step(x, omega_of(period), f, dx)
    }
}

/// One point of a branch.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Point {
    /// Step number (0-based).
    pub step: usize,
    /// Parameter value.
    pub lambda: f64,
    /// Solution (the last iterate when the step failed).
    pub x: Vec<f64>,
    /// `|F(x, lambda)|_2`.
    pub residual_norm: f64,
    /// Solver iterations.
    pub iterations: usize,
    /// Whether the solver met its tolerance.
    pub converged: bool,
    /// Why the solver failed, if it did (`None` with `converged == false`: the solver
    /// converged but the driver's acceptance test rejected the solution).
    pub error: Option<SolveError>,
    /// Step used to reach the point: the parameter increment for sequential runs, the
    /// arclength `ds` for pseudo-arclength runs (0 for a starting point).
    pub step_size: f64,
    /// Events detected on the way to this point.
    pub events: Vec<Event>,
}

/// Something that happened along a branch, reported on the point where it was detected.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub enum Event {
    /// Turning point: the parameter component of the tangent changed sign.
    Fold {
        /// Parameter at the point after the fold.
        lambda: f64,
    },
    /// The corrected point is far from its prediction even at the smallest step.
    Jump {
        /// Distance to the prediction over the step size.
        ratio: f64,
    },
    /// The active set of a unilateral law appeared (`contact == true`) or vanished.
    Grazing {
        /// Law index.
        law: usize,
        /// Whether the contact is active after the event.
        contact: bool,
    },
}

impl Event {
    /// A short label for tables: `fold`, `jump`, `grazing+`, `grazing-`.
    pub fn label(&self) -> &'static str {
        match self {
            Event::Fold { .. } => "fold",
            Event::Jump { .. } => "jump",
            Event::Grazing { contact: true, .. } => "grazing+",
            Event::Grazing { contact: false, .. } => "grazing-",
        }
    }
}
