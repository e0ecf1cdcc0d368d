//! Smoothing homotopy around any solver, for starts where the nonsmooth problem is hard.

use super::{residual_scale, NonlinearSolver, Problem, SolveInfo, SolveMonitor};
use crate::error::SolveError;

/// Tries `inner` on the nonsmooth problem; if it fails and the problem supports smoothing
/// ([`Structured::set_smoothing`](super::Structured::set_smoothing)), solves again from the same start a sequence of smoothed
/// problems with decreasing smoothing `eps_i = levels[i] * residual_scale`, each from the
/// previous solution, and finishes on the nonsmooth problem (`eps = 0`). For unilateral contact
/// the smoothing replaces `min(lambda, a_c g)` by `(a + b - sqrt((a - b)^2 + 4 eps^2)) / 2`,
/// which makes the Jacobian continuous and the first solves robust; the path of smoothed
/// solutions leads to a nonsmooth solution near the start.
///
/// The problem is always left unsmoothed on return. On failure the error of the first
/// (nonsmooth) attempt is returned, with `x` the last iterate of that attempt.
///
/// Reference: C. Kanzow, "Some noninterior continuation methods for linear complementarity
/// problems", SIAM J. Matrix Anal. Appl. 17 (1996) 851–868.
#[derive(Debug, Clone, PartialEq)]
pub struct SmoothingHomotopy<S> {
    /// The solver used at every level.
    pub inner: S,
    /// Smoothing levels relative to the problem's residual scale, decreasing (default
    /// `[3e-2, 3e-3, 3e-4, 3e-5]`).
    pub levels: Vec<f64>,
}

impl<S> SmoothingHomotopy<S> {
    /// The homotopy around `inner` with the default levels.
    pub fn new(inner: S) -> Self {
        Self {
            inner,
            levels: vec![3e-2, 3e-3, 3e-4, 3e-5],
        }
    }
}

impl<S: Default> Default for SmoothingHomotopy<S> {
    fn default() -> Self {
        Self::new(S::default())
    }
}

impl<S: NonlinearSolver> NonlinearSolver for SmoothingHomotopy<S> {
    fn tolerance(&self, problem: &mut dyn Problem) -> f64 {
        self.inner.tolerance(problem)
    }

    fn solve_monitored(
        &self,
        problem: &mut dyn Problem,
        x: &mut [f64],
        monitor: &mut dyn SolveMonitor,
    ) -> Result<SolveInfo, SolveError> {
        let start = x.to_vec();
        let first = match self.inner.solve_monitored(problem, x, monitor) {
            Ok(info) => return Ok(info),
            Err(e @ SolveError::Cancelled { .. }) => return Err(e),
            Err(e) => e,
        };
        if self.levels.is_empty() || !set_smoothing(problem, 0.0) {
            return Err(first);
        }
        let failed = x.to_vec();
        let scale = residual_scale(problem);
        x.copy_from_slice(&start);
        let mut total = SolveInfo {
            iterations: 0,
            residual_norm: f64::NAN,
            residual_evaluations: 0,
            jacobian_evaluations: 0,
        };
        let levels = self
            .levels
            .iter()
            .map(|l| l * scale)
            .chain(std::iter::once(0.0));
        for eps in levels {
            set_smoothing(problem, eps);
            match self.inner.solve_monitored(problem, x, monitor) {
                Ok(info) => {
                    total.iterations += info.iterations;
                    total.residual_evaluations += info.residual_evaluations;
                    total.jacobian_evaluations += info.jacobian_evaluations;
                    total.residual_norm = info.residual_norm;
                }
                Err(e) => {
                    set_smoothing(problem, 0.0);
                    if let SolveError::Cancelled { .. } = e {
                        return Err(e);
                    }
                    x.copy_from_slice(&failed);
                    return Err(first);
                }
            }
        }
        set_smoothing(problem, 0.0);
        Ok(total)
    }
}

/// [`Structured::set_smoothing`](super::Structured::set_smoothing) of a problem (`false`
/// without structure).
fn set_smoothing(problem: &mut dyn Problem, smoothing: f64) -> bool {
    problem
        .structure()
        .is_some_and(|s| s.set_smoothing(smoothing))
}
