//! Nonlinear solvers for square nonsmooth systems `F(x) = 0`.
//!
//! Both solvers use the problem's generalised Jacobian (an element of Clarke's generalised
//! Jacobian where `F` has kinks) and report what happened in a [`SolveInfo`] or a typed
//! [`SolveError`].
//!
//! | solver | step | globalisation |
//! |---|---|---|
//! | [`SemismoothNewton`] (default) | `J dx = -F` | backtracking (Armijo) on `|F|^2 / 2` |
//! | [`Dogleg`] | Powell's dogleg between Newton and Cauchy steps | trust region |
//!
//! A problem is three methods ([`Problem`]: dimension, residual, Jacobian). What a problem can
//! do beyond them (solve with its Jacobian without forming it densely, evaluate the residual
//! cheaply along a ray, smooth its kinks, weigh its unknowns, report its active set, state the
//! scale of its residual) is one capability object, [`Structured`], reached through
//! [`Problem::structure`]: an adapter that wraps a problem forwards that one accessor and so
//! keeps every capability of the problem it wraps.

mod choice;
mod dogleg;
mod homotopy;
mod newton;

pub use choice::Solver;
pub use dogleg::{Dogleg, DoglegOptions};
pub use homotopy::SmoothingHomotopy;
pub use newton::{NewtonOptions, SemismoothNewton};

use crate::error::SolveError;
use crate::linalg::{DenseMatrix, Lu};
use std::cell::Cell;
use std::ops::ControlFlow;

/// A square system `F(x) = 0` with a generalised Jacobian.
///
/// Only the three required methods are needed to solve it; optional capabilities come through
/// [`Problem::structure`].
pub trait Problem {
    /// Number of unknowns (and equations).
    fn dimension(&self) -> usize;

    /// Writes `F(x)` into `f`.
    fn residual(&mut self, x: &[f64], f: &mut [f64]);

    /// Writes a generalised Jacobian `J(x)` into `jac` (resized to `n x n` by the callee).
    fn jacobian(&mut self, x: &[f64], jac: &mut DenseMatrix);

    /// The problem's optional capabilities (`None` by default: a plain problem). Adapters
    /// forward this one accessor.
    fn structure(&mut self) -> Option<&mut dyn Structured> {
        None
    }
}

/// Optional capabilities of a [`Problem`], each with a default that means "not available".
///
/// Solvers and drivers use a capability when [`Problem::structure`] offers it and fall back to
/// the plain methods otherwise; results agree to rounding either way.
pub trait Structured {
    /// Typical magnitude of the residual's entries: tolerances are relative to it (1 by
    /// default).
    fn residual_scale(&self) -> f64 {
        1.0
    }

    /// Solves `J(x) z = r` for `columns` right-hand sides stored one after the other in `rhs`
    /// (each of the problem's dimension), in place, exploiting the problem's structure instead
    /// of factorising the dense Jacobian. `None` (the default): no structured solve here, the
    /// caller factorises [`Problem::jacobian`]; `Some(Err(..))`: the structured matrix is
    /// singular.
    fn solve_jacobian(
        &mut self,
        x: &[f64],
        rhs: &mut [f64],
        columns: usize,
    ) -> Option<Result<(), SingularStep>> {
        let _ = (x, rhs, columns);
        None
    }

    /// A line search's evaluation: writes `x + t dx` into `trial` and `F(x + t dx)` into `f`,
    /// and returns `true`; `false` (the default) if the problem has no cheaper way than
    /// forming the point and calling [`Problem::residual`]. (Harmonic balance: the time
    /// samples are affine in `t`, so a whole line search needs one synthesis.)
    fn residual_along(
        &mut self,
        x: &[f64],
        dx: &[f64],
        t: f64,
        trial: &mut [f64],
        f: &mut [f64],
    ) -> bool {
        let _ = (x, dx, t, trial, f);
        false
    }

    /// Sets a smoothing `eps >= 0` of the problem's nonsmooth terms (`eps = 0`: the original
    /// problem) and returns whether the problem supports it (`false` by default). Used by
    /// [`SmoothingHomotopy`].
    fn set_smoothing(&mut self, smoothing: f64) -> bool {
        let _ = smoothing;
        false
    }

    /// Diagonal weights `w_i` of a natural norm `sum_i w_i x_i^2` of the unknowns (for
    /// harmonic balance, an energy norm at the current frequency). Arclength continuation
    /// scales its norm with them; `None` (default) means all weights 1.
    fn state_weights(&mut self) -> Option<Vec<f64>> {
        None
    }

    /// Whether `x` is the problem's state of rest (no motion), where the problem knows it
    /// (`None` by default). Continuation drivers refuse a point at rest unless told otherwise
    /// ([`Sequential::with_rest_accepted`](crate::continuation::Sequential::with_rest_accepted),
    /// [`Arclength::with_rest_accepted`](crate::continuation::Arclength::with_rest_accepted)):
    /// rest solves the equations of every unforced mode, and a run that slides to it has
    /// left its branch.
    fn at_rest(&mut self, x: &[f64]) -> Option<bool> {
        let _ = x;
        None
    }

    /// For nonsmooth problems: the size of the active set of each unilateral law at `x` (for
    /// harmonic balance, the number of time samples in contact). Continuation drivers report
    /// a grazing event when one appears or vanishes. `None` by default.
    fn active_set(&mut self, x: &[f64]) -> Option<Vec<usize>> {
        let _ = x;
        None
    }
}

/// Whether `x` is the state of rest of `problem`, as far as it knows ([`Structured::at_rest`];
/// `false` where it does not).
pub fn at_rest(problem: &mut (impl Problem + ?Sized), x: &[f64]) -> bool {
    problem.structure().and_then(|s| s.at_rest(x)) == Some(true)
}

/// [`Structured::residual_scale`] of a problem (1 without structure).
pub fn residual_scale(problem: &mut (impl Problem + ?Sized)) -> f64 {
    problem.structure().map_or(1.0, |s| s.residual_scale())
}

impl<P: Problem + ?Sized> Problem for &mut P {
    fn dimension(&self) -> usize {
        (**self).dimension()
    }
    fn residual(&mut self, x: &[f64], f: &mut [f64]) {
        (**self).residual(x, f)
    }
    fn jacobian(&mut self, x: &[f64], jac: &mut DenseMatrix) {
        (**self).jacobian(x, jac)
    }
    fn structure(&mut self) -> Option<&mut dyn Structured> {
        (**self).structure()
    }
}

/// A singular (structured) matrix met by [`Structured::solve_jacobian`]: the smallest pivot
/// of its LU and its ratio to the largest, as in [`SolveError::SingularJacobian`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SingularStep {
    /// Index of the smallest pivot.
    pub pivot: usize,
    /// `|u_pivot| / max |u_jj|`.
    pub ratio: f64,
}

/// What a successful solve did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolveInfo {
    /// Iterations (Jacobian factorisations).
    pub iterations: usize,
    /// Final residual norm `|F(x)|_2`.
    pub residual_norm: f64,
    /// Residual evaluations.
    pub residual_evaluations: usize,
    /// Jacobian evaluations.
    pub jacobian_evaluations: usize,
}

/// Watches a solve from outside: told of every residual evaluation, it may cancel the solve
/// ([`SolveError::Cancelled`]). `()` watches nothing.
pub trait SolveMonitor {
    /// Called after each residual evaluation with the number made so far;
    /// `ControlFlow::Break` cancels the solve.
    fn evaluated(&mut self, evaluations: usize) -> ControlFlow<()>;
}

impl SolveMonitor for () {
    fn evaluated(&mut self, _: usize) -> ControlFlow<()> {
        ControlFlow::Continue(())
    }
}

/// A solver of square nonsmooth systems. Object safe: continuation drivers take a generic
/// `S: NonlinearSolver`, and `&S` is one too, so a solver chosen at run time
/// (`Box<dyn NonlinearSolver>`) is passed as `&*boxed`.
pub trait NonlinearSolver {
    /// Solves `F(x) = 0` starting from `x`, telling `monitor` of every residual evaluation;
    /// on success `x` holds the solution, on failure the last iterate. A solver that cannot
    /// be interrupted may ignore the monitor.
    ///
    /// # Errors
    /// See [`SolveError`]; [`SolveError::Cancelled`] when the monitor cancels.
    fn solve_monitored(
        &self,
        problem: &mut dyn Problem,
        x: &mut [f64],
        monitor: &mut dyn SolveMonitor,
    ) -> Result<SolveInfo, SolveError>;

    /// [`NonlinearSolver::solve_monitored`] with no monitor.
    ///
    /// # Errors
    /// See [`SolveError`].
    fn solve(&self, problem: &mut dyn Problem, x: &mut [f64]) -> Result<SolveInfo, SolveError> {
        self.solve_monitored(problem, x, &mut ())
    }

    /// The absolute tolerance on `|F|_2` this solver uses for `problem` (so that callers can
    /// judge a point with the same yardstick).
    fn tolerance(&self, problem: &mut dyn Problem) -> f64;
}

impl<S: NonlinearSolver + ?Sized> NonlinearSolver for &S {
    fn solve_monitored(
        &self,
        problem: &mut dyn Problem,
        x: &mut [f64],
        monitor: &mut dyn SolveMonitor,
    ) -> Result<SolveInfo, SolveError> {
        (**self).solve_monitored(problem, x, monitor)
    }
    fn tolerance(&self, problem: &mut dyn Problem) -> f64 {
        (**self).tolerance(problem)
    }
}

/// Relative pivot threshold of the LU factorisations.
pub(crate) const PIVOT_TOLERANCE: f64 = 1e-13;

/// `out = x + t dx`: a line search's trial point.
pub(crate) fn point_on_ray(x: &[f64], dx: &[f64], t: f64, out: &mut [f64]) {
    for ((p, a), d) in out.iter_mut().zip(x).zip(dx) {
        *p = a + t * d;
    }
}

/// Where a failed solve leaves a point, with its residual norm: the solver's last iterate
/// `x`, or `fallback` (the last converged solution) when the iterate's residual is not finite
/// (a solve that diverged), so that a reported point never carries a NaN norm.
pub(crate) fn failed_point(
    problem: &mut (impl Problem + ?Sized),
    x: Vec<f64>,
    fallback: &[f64],
) -> (Vec<f64>, f64) {
    let mut f = vec![0.0; x.len()];
    problem.residual(&x, &mut f);
    if norm(&f).is_finite() {
        return (x, norm(&f));
    }
    problem.residual(fallback, &mut f);
    (fallback.to_vec(), norm(&f))
}

/// The Euclidean norm, finite whenever the entries are: the plain sum of squares, and when it
/// overflows (entries beyond about `1e154`) the sum rescaled by the largest entry. Bit for bit
/// the plain formula wherever that is finite.
pub(crate) fn norm(v: &[f64]) -> f64 {
    let plain = v.iter().map(|x| x * x).sum::<f64>().sqrt();
    if plain.is_finite() {
        return plain;
    }
    let scale = v.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
    if !scale.is_finite() {
        // An infinite entry (or NaN, which `max` skips but the plain sum kept).
        return if v.iter().any(|x| x.is_nan()) {
            f64::NAN
        } else {
            f64::INFINITY
        };
    }
    scale
        * v.iter()
            .map(|x| (x / scale) * (x / scale))
            .sum::<f64>()
            .sqrt()
}

/// Buffers of one solve. They live in a thread-local cache between solves, so that a
/// continuation run allocates them once per thread (and again only when the dimension grows).
#[derive(Debug)]
pub(crate) struct Workspace {
    pub f: Vec<f64>,
    pub f_trial: Vec<f64>,
    pub trial: Vec<f64>,
    pub dx: Vec<f64>,
    pub grad: Vec<f64>,
    pub jg: Vec<f64>,
    pub step: Vec<f64>,
    pub jp: Vec<f64>,
    pub jac: DenseMatrix,
    pub lu: Lu,
}

impl Workspace {
    fn new() -> Self {
        Self {
            f: Vec::new(),
            f_trial: Vec::new(),
            trial: Vec::new(),
            dx: Vec::new(),
            grad: Vec::new(),
            jg: Vec::new(),
            step: Vec::new(),
            jp: Vec::new(),
            jac: DenseMatrix::zeros(0, 0),
            lu: Lu::default(),
        }
    }

    /// Zeroes every vector at length `n` (keeping capacity).
    fn prepare(&mut self, n: usize) {
        for v in [
            &mut self.f,
            &mut self.f_trial,
            &mut self.trial,
            &mut self.dx,
            &mut self.grad,
            &mut self.jg,
            &mut self.step,
            &mut self.jp,
        ] {
            v.clear();
            v.resize(n, 0.0);
        }
    }
}

thread_local! {
    static WORKSPACE: Cell<Option<Box<Workspace>>> = const { Cell::new(None) };
}

/// Runs `f` with this thread's solver buffers sized for `n` unknowns. A solve started from
/// inside another (a problem whose residual solves something) gets fresh buffers.
pub(crate) fn with_workspace<R>(n: usize, f: impl FnOnce(&mut Workspace) -> R) -> R {
    let mut ws = WORKSPACE
        .with(Cell::take)
        .unwrap_or_else(|| Box::new(Workspace::new()));
    ws.prepare(n);
    let result = f(&mut ws);
    WORKSPACE.with(|cell| cell.set(Some(ws)));
    result
}

/// Shared state of an iteration: the problem, its monitor and counters.
pub(crate) struct Iteration<'p> {
    pub problem: &'p mut dyn Problem,
    monitor: &'p mut dyn SolveMonitor,
    pub residuals: usize,
    pub jacobians: usize,
}

impl<'p> Iteration<'p> {
    pub fn new(
        problem: &'p mut dyn Problem,
        monitor: &'p mut dyn SolveMonitor,
        x: &[f64],
    ) -> Result<Self, SolveError> {
        let n = problem.dimension();
        if x.len() != n {
            return Err(SolveError::Dimension {
                got: x.len(),
                expected: n,
            });
        }
        if !x.iter().all(|v| v.is_finite()) {
            return Err(SolveError::NonFinite {
                what: "initial guess",
                iteration: 0,
            });
        }
        Ok(Self {
            problem,
            monitor,
            residuals: 0,
            jacobians: 0,
        })
    }

    /// Evaluates `F(x)` into `out` and returns its norm, or an error if non-finite.
    pub fn residual_into(
        &mut self,
        x: &[f64],
        out: &mut [f64],
        iteration: usize,
    ) -> Result<f64, SolveError> {
        self.problem.residual(x, out);
        self.counted_norm(out, iteration)
    }

    /// Counts a residual evaluation, tells the monitor, and returns the norm, or an error if
    /// it is not finite or the monitor cancels.
    fn counted_norm(&mut self, f: &[f64], iteration: usize) -> Result<f64, SolveError> {
        self.residuals += 1;
        if self.monitor.evaluated(self.residuals).is_break() {
            return Err(SolveError::Cancelled {
                iteration,
                evaluations: self.residuals,
            });
        }
        let r = norm(f);
        if r.is_finite() {
            Ok(r)
        } else {
            Err(SolveError::NonFinite {
                what: "residual",
                iteration,
            })
        }
    }

    /// `F(x + t dx)` (and the point into `trial`) with its norm, counted and checked like
    /// [`Iteration::residual_into`]; through [`Structured::residual_along`] when the problem
    /// offers it.
    pub fn residual_along_into(
        &mut self,
        (x, dx, t): (&[f64], &[f64], f64),
        trial: &mut [f64],
        out: &mut [f64],
        iteration: usize,
    ) -> Result<f64, SolveError> {
        let along = self
            .problem
            .structure()
            .is_some_and(|s| s.residual_along(x, dx, t, trial, out));
        if !along {
            point_on_ray(x, dx, t, trial);
            self.problem.residual(trial, out);
        }
        self.counted_norm(out, iteration)
    }

    /// Evaluates the Jacobian at `x` into `jac` and factorises it into `lu` (in place, reusing
    /// the storage of both).
    pub fn factor_jacobian(
        &mut self,
        x: &[f64],
        jac: &mut DenseMatrix,
        lu: &mut Lu,
        iteration: usize,
    ) -> Result<(), SolveError> {
        self.problem.jacobian(x, jac);
        self.jacobians += 1;
        if !jac.is_finite() {
            return Err(SolveError::NonFinite {
                what: "Jacobian",
                iteration,
            });
        }
        lu.refactor(jac, PIVOT_TOLERANCE)
            .map_err(|p| SolveError::SingularJacobian {
                iteration,
                pivot: p.pivot,
                ratio: p.ratio,
            })
    }

    /// The Newton direction `dx = -J(x)^-1 f`: by the problem's structured solve when it
    /// offers one, else by a dense LU of its Jacobian (in `jac`, `lu`).
    pub fn newton_direction(
        &mut self,
        (x, f): (&[f64], &[f64]),
        dx: &mut [f64],
        (jac, lu): (&mut DenseMatrix, &mut Lu),
        iteration: usize,
    ) -> Result<(), SolveError> {
        for (d, fi) in dx.iter_mut().zip(f) {
            *d = -fi;
        }
        let structured = self
            .problem
            .structure()
            .and_then(|s| s.solve_jacobian(x, dx, 1));
        match structured {
            Some(Ok(())) => {
                self.jacobians += 1;
                if dx.iter().all(|v| v.is_finite()) {
                    Ok(())
                } else {
                    Err(SolveError::NonFinite {
                        what: "Jacobian",
                        iteration,
                    })
                }
            }
            Some(Err(p)) => Err(SolveError::SingularJacobian {
                iteration,
                pivot: p.pivot,
                ratio: p.ratio,
            }),
            None => {
                // The structured solve may have left partial results: start again from -f.
                for (d, fi) in dx.iter_mut().zip(f) {
                    *d = -fi;
                }
                self.factor_jacobian(x, jac, lu, iteration)?;
                lu.solve_in_place(dx);
                Ok(())
            }
        }
    }

    pub fn info(&self, iterations: usize, residual_norm: f64) -> SolveInfo {
        SolveInfo {
            iterations,
            residual_norm,
            residual_evaluations: self.residuals,
            jacobian_evaluations: self.jacobians,
        }
    }

    /// The outcome once the budget of `iterations` is spent with residual norm `r`.
    pub fn exhausted(
        &self,
        iterations: usize,
        r: f64,
        tolerance: f64,
    ) -> Result<SolveInfo, SolveError> {
        if r <= tolerance {
            Ok(self.info(iterations, r))
        } else {
            Err(SolveError::MaxIterations {
                iterations,
                residual_norm: r,
                tolerance,
            })
        }
    }
}

pub(crate) fn check_positive(what: &'static str, value: f64) -> Result<(), SolveError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(SolveError::InvalidOption { what, value })
    }
}
