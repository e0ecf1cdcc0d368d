//! Semismooth Newton with a backtracking line search.

use super::{check_positive, Iteration, NonlinearSolver, Problem, SolveInfo};
use crate::error::SolveError;

/// Options of [`SemismoothNewton`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NewtonOptions {
    /// Converged when `|F|_2 <= tolerance * problem.residual_scale()` (default `1e-9`).
    pub tolerance: f64,
    /// Iteration budget (default 50).
    pub max_iterations: usize,
    /// Armijo constant `c` of the test `|F(x + t dx)|^2 <= (1 - 2 c t) |F(x)|^2`
    /// (default `1e-4`).
    pub armijo: f64,
    /// Smallest step length tried before the line search gives up (default `1e-10`).
    pub min_step: f64,
}

impl Default for NewtonOptions {
    fn default() -> Self {
        Self {
            tolerance: 1e-9,
            max_iterations: 50,
            armijo: 1e-4,
            min_step: 1e-10,
        }
    }
}

/// Semismooth Newton: `J(x) dx = -F(x)` with `J` a generalised Jacobian, then halve the step
/// until the merit `|F|^2 / 2` decreases enough (Armijo). Converges locally superlinearly on
/// semismooth systems; on harmonic-balance complementarity it usually stops in 1 to 3
/// iterations per continuation step, once the contact set is right.
///
/// Reference: L. Qi and J. Sun, "A nonsmooth version of Newton's method", Mathematical
/// Programming 58 (1993) 353–367.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SemismoothNewton {
    /// Options.
    pub options: NewtonOptions,
}

impl SemismoothNewton {
    /// A solver with the given options.
    ///
    /// # Errors
    /// [`SolveError::InvalidOption`] for a non-positive or non-finite tolerance, Armijo
    /// constant or minimum step.
    pub fn new(options: NewtonOptions) -> Result<Self, SolveError> {
        check_positive("tolerance", options.tolerance)?;
        check_positive("armijo", options.armijo)?;
        check_positive("min_step", options.min_step)?;
        Ok(Self { options })
    }
}

impl NonlinearSolver for SemismoothNewton {
    fn tolerance(&self, problem: &dyn Problem) -> f64 {
        self.options.tolerance * problem.residual_scale()
    }

    fn solve(&self, problem: &mut dyn Problem, x: &mut [f64]) -> Result<SolveInfo, SolveError> {
        let o = &self.options;
        let tol = self.tolerance(problem);
        let mut it = Iteration::new(problem, x)?;
        let n = x.len();
        let mut dx = vec![0.0; n];
        let mut trial = vec![0.0; n];
        let mut f_trial = vec![0.0; n];
        let mut r = it.residual(x, 0)?;
        for iteration in 0..o.max_iterations {
            if r <= tol {
                return Ok(it.info(iteration, r));
            }
            let lu = it.factor_jacobian(x, iteration)?;
            for (d, f) in dx.iter_mut().zip(&it.f) {
                *d = -f;
            }
            lu.solve_in_place(&mut dx);
            let mut t = 1.0;
            loop {
                for ((xt, xi), d) in trial.iter_mut().zip(x.iter()).zip(&dx) {
                    *xt = xi + t * d;
                }
                let rt = it.residual_into(&trial, &mut f_trial, iteration)?;
                if rt * rt <= (1.0 - 2.0 * o.armijo * t) * r * r || rt <= tol {
                    x.copy_from_slice(&trial);
                    std::mem::swap(&mut it.f, &mut f_trial);
                    r = rt;
                    break;
                }
                t *= 0.5;
                if t < o.min_step {
                    return Err(SolveError::LineSearch {
                        iteration,
                        residual_norm: r,
                        step: t,
                    });
                }
            }
        }
        if r <= tol {
            return Ok(it.info(o.max_iterations, r));
        }
        Err(SolveError::MaxIterations {
            iterations: o.max_iterations,
            residual_norm: r,
            tolerance: tol,
        })
    }
}
