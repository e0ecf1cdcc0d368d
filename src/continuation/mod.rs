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

mod sequential;

pub use sequential::{Predictor, Sequential, SequentialOptions, StepOutcome};

use crate::error::SolveError;
use crate::linalg::DenseMatrix;
use crate::solve::Problem;

/// A family of square systems `F(x, lambda) = 0` in one scalar parameter.
pub trait ContinuationProblem {
    /// Number of unknowns `x` (and equations).
    fn dimension(&self) -> usize;

    /// `F(x, lambda)` into `f`.
    fn residual(&mut self, x: &[f64], lambda: f64, f: &mut [f64]);

    /// Generalised Jacobian `dF/dx` into `jac` (resized by the callee).
    fn jacobian(&mut self, x: &[f64], lambda: f64, jac: &mut DenseMatrix);

    /// `dF/dlambda` at fixed `x` into `df`.
    fn parameter_derivative(&mut self, x: &[f64], lambda: f64, df: &mut [f64]);

    /// Typical magnitude of residual entries (see [`Problem::residual_scale`]).
    fn residual_scale(&self) -> f64 {
        1.0
    }
}

impl<P: ContinuationProblem + ?Sized> ContinuationProblem for &mut P {
    fn dimension(&self) -> usize {
        (**self).dimension()
    }
    fn residual(&mut self, x: &[f64], lambda: f64, f: &mut [f64]) {
        (**self).residual(x, lambda, f)
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
    fn residual(&mut self, x: &[f64], f: &mut [f64]) {
        self.problem.residual(x, self.lambda, f)
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
}

/// One point of a branch.
#[derive(Debug, Clone, PartialEq)]
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
}
