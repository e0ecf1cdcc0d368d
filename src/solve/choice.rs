//! One of the crate's solvers, chosen at run time: a plain value that can be copied into a
//! request, a sweep job or the thread of a speculative retry.

use crate::error::SolveError;
use crate::solve::{Dogleg, NonlinearSolver, Problem, SemismoothNewton, SolveInfo, SolveMonitor};

/// A solver chosen per run (so that one sweep can mix solvers).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Solver {
    /// [`SemismoothNewton`] (the default).
    Newton(SemismoothNewton),
    /// Powell's [`Dogleg`].
    Dogleg(Dogleg),
}

impl Default for Solver {
    fn default() -> Self {
        Self::Newton(SemismoothNewton::default())
    }
}

impl NonlinearSolver for Solver {
    fn solve_monitored(
        &self,
        problem: &mut dyn Problem,
        x: &mut [f64],
        monitor: &mut dyn SolveMonitor,
    ) -> Result<SolveInfo, SolveError> {
        match self {
            Self::Newton(s) => s.solve_monitored(problem, x, monitor),
            Self::Dogleg(s) => s.solve_monitored(problem, x, monitor),
        }
    }

    fn tolerance(&self, problem: &mut dyn Problem) -> f64 {
        match self {
            Self::Newton(s) => s.tolerance(problem),
            Self::Dogleg(s) => s.tolerance(problem),
        }
    }
}
