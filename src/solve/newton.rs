//! Semismooth Newton with a backtracking line search.

use super::{
    check_positive, residual_scale, with_workspace, Iteration, NonlinearSolver, Problem, SolveInfo,
    SolveMonitor, Workspace,
};
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
    /// Stagnation window `K` (default 0: off; values above 63 count as 63; 15 in
    /// [`NewtonOptions::fail_fast`]): give up with
    /// [`SolveError::Stagnated`] when, after `K` or more iterations, the residual norm is not
    /// below `stall_ratio` times its value `K` iterations earlier. On nonsmooth problems a
    /// start outside every solution's basin makes Newton wander between kinks with tiny steps
    /// until the budget runs out; in continuation such a step is skipped anyway, and its
    /// line searches can dominate a backbone's time (`docs/performance.md`).
    pub stall_window: usize,
    /// Least decrease factor over [`NewtonOptions::stall_window`] iterations (default 0.5,
    /// in `(0, 1]`).
    pub stall_ratio: f64,
    /// Plateau window (default 0: off; 4 in [`NewtonOptions::fail_fast`]): a second, short
    /// stagnation test with its own ratio, failing with [`SolveError::Stagnated`] too. A
    /// hopeless start typically drops its residual fast, then creeps along a plateau with
    /// line searches of ever shorter steps; a solve that converges never spends four
    /// iterations on a plateau first (`docs/performance.md`).
    pub plateau_window: usize,
    /// Least decrease factor over [`NewtonOptions::plateau_window`] iterations (default 0.98,
    /// in `(0, 1]`).
    pub plateau_ratio: f64,
    /// Budget of residual evaluations per solve, line-search trials included (default
    /// `usize::MAX`: none; 80 in [`NewtonOptions::fail_fast`]): give up with
    /// [`SolveError::EvaluationBudget`] when a line search has spent it. A hopeless start
    /// spends its time in long line searches at tiny steps, while a solve from a converged
    /// neighbour needs few evaluations (`docs/performance.md` has the measured counts).
    pub max_evaluations: usize,
}

impl Default for NewtonOptions {
    fn default() -> Self {
        Self {
            tolerance: 1e-9,
            max_iterations: 50,
            armijo: 1e-4,
            min_step: 1e-10,
            stall_window: 0,
            stall_ratio: 0.5,
            plateau_window: 0,
            plateau_ratio: 0.98,
            max_evaluations: usize::MAX,
        }
    }
}

impl NewtonOptions {
    /// Checks the options (what [`SemismoothNewton::new`] requires).
    ///
    /// # Errors
    /// [`SolveError::InvalidOption`] for a non-positive or non-finite tolerance, Armijo
    /// constant or minimum step, a stagnation or plateau ratio outside `(0, 1]`, or a zero
    /// evaluation budget.
    pub fn validate(&self) -> Result<(), SolveError> {
        check_positive("tolerance", self.tolerance)?;
        check_positive("armijo", self.armijo)?;
        check_positive("min_step", self.min_step)?;
        check_positive("stall_ratio", self.stall_ratio)?;
        check_positive("plateau_ratio", self.plateau_ratio)?;
        if self.max_evaluations == 0 {
            return Err(SolveError::InvalidOption {
                what: "max_evaluations",
                value: 0.0,
            });
        }
        for (what, ratio) in [
            ("stall_ratio (at most 1)", self.stall_ratio),
            ("plateau_ratio (at most 1)", self.plateau_ratio),
        ] {
            if ratio > 1.0 {
                return Err(SolveError::InvalidOption { what, value: ratio });
            }
        }
        Ok(())
    }

    /// Settings for sequential continuation on a fine grid, where each step starts from a
    /// converged neighbour and a failed step is simply skipped: the line search gives up at
    /// step length `1e-4` (instead of `1e-10`), the stagnation test is on
    /// (`stall_window = 15`, `stall_ratio = 0.5`) and so is the plateau test
    /// (`plateau_window = 4`, `plateau_ratio = 0.98`). A start that needs steps shorter than
    /// `1e-4`, fifteen iterations to halve its residual or four to cut it by 2 % is outside
    /// every solution's basin in practice, and so is one that has spent 80 residual
    /// evaluations ([`NewtonOptions::max_evaluations`]); the default settings spend most of a
    /// backbone's time proving it (`docs/performance.md` compares the two on the clamped
    /// bar's backbone: about the same converged steps in much less time). Not for far starts
    /// (a seed, the jumps of [`crate::branches::StallEscape`]): those can need a slow
    /// first phase before converging.
    pub fn fail_fast() -> Self {
        Self {
            min_step: 1e-4,
            stall_window: 15,
            stall_ratio: 0.5,
            plateau_window: 4,
            plateau_ratio: 0.98,
            max_evaluations: 80,
            ..Self::default()
        }
    }
}

/// Semismooth Newton: `J(x) dx = -F(x)` with `J` a generalised Jacobian, then halve the step
/// until the merit `|F|^2 / 2` decreases enough (Armijo). Converges locally superlinearly on
/// semismooth systems; on harmonic-balance complementarity it usually stops within a few
/// iterations per continuation step, once the contact set is right.
///
/// Reference: L. Qi and J. Sun, "A nonsmooth version of Newton's method", Mathematical
/// Programming 58 (1993) 353–367.
///
/// Built by [`SemismoothNewton::new`], which validates the options, or by `Default` (the
/// default options); the options are private, so no solver holds options that `new` would
/// reject:
///
/// ```compile_fail,E0451
/// use nonsmooth_modes::solve::{NewtonOptions, SemismoothNewton};
///
/// let options = NewtonOptions { min_step: -1.0, ..Default::default() };
/// let solver = SemismoothNewton { options };
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SemismoothNewton {
    options: NewtonOptions,
}

impl SemismoothNewton {
    /// A solver with the given options.
    ///
    /// # Errors
    /// The error of [`NewtonOptions::validate`].
    pub fn new(options: NewtonOptions) -> Result<Self, SolveError> {
        options.validate()?;
        Ok(Self { options })
    }

    /// Its options.
    pub fn options(&self) -> &NewtonOptions {
        &self.options
    }
}

impl NonlinearSolver for SemismoothNewton {
    fn tolerance(&self, problem: &mut dyn Problem) -> f64 {
        self.options.tolerance * residual_scale(problem)
    }

    fn solve_monitored(
        &self,
        problem: &mut dyn Problem,
        x: &mut [f64],
        monitor: &mut dyn SolveMonitor,
    ) -> Result<SolveInfo, SolveError> {
        let o = &self.options;
        let tol = self.tolerance(problem);
        let mut it = Iteration::new(problem, monitor, x)?;
        with_workspace(x.len(), |ws| {
            let Workspace {
                f,
                f_trial,
                trial,
                dx,
                jac,
                lu,
                ..
            } = ws;
            let mut r = it.residual_into(x, f, 0)?;
            let mut history = Stagnation::new(o.stall_window, o.stall_ratio);
            let mut plateau = Stagnation::new(o.plateau_window, o.plateau_ratio);
            for iteration in 0..o.max_iterations {
                if r <= tol {
                    return Ok(it.info(iteration, r));
                }
                history.check(iteration, r)?;
                plateau.check(iteration, r)?;
                it.newton_direction((x, f), dx, (jac, lu), iteration)?;
                let mut t = 1.0;
                loop {
                    let rt = it.residual_along_into((x, dx, t), trial, f_trial, iteration)?;
                    if rt * rt <= (1.0 - 2.0 * o.armijo * t) * r * r || rt <= tol {
                        x.copy_from_slice(trial);
                        std::mem::swap(f, f_trial);
                        r = rt;
                        break;
                    }
                    if it.residuals >= o.max_evaluations {
                        return Err(SolveError::EvaluationBudget {
                            iteration,
                            evaluations: it.residuals,
                            residual_norm: r,
                        });
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
            it.exhausted(o.max_iterations, r, tol)
        })
    }
}

/// The last `window + 1` residual norms, in a ring without allocation (windows are capped at
/// [`Stagnation::CAPACITY`]` - 1`); Newton's stagnation and plateau tests, and the dogleg's
/// stagnation test.
pub(super) struct Stagnation {
    window: usize,
    ratio: f64,
    norms: [f64; Stagnation::CAPACITY],
}

impl Stagnation {
    const CAPACITY: usize = 64;

    pub(super) fn new(window: usize, ratio: f64) -> Self {
        Self {
            window: window.min(Self::CAPACITY - 1),
            ratio,
            norms: [0.0; Self::CAPACITY],
        }
    }

    /// Records `r` at `iteration` and fails if it is not below `ratio` times the norm
    /// `window` iterations earlier.
    pub(super) fn check(&mut self, iteration: usize, r: f64) -> Result<(), SolveError> {
        if self.window == 0 {
            return Ok(());
        }
        let slot = |i: usize| i % (self.window + 1);
        if iteration >= self.window {
            let earlier = self.norms[slot(iteration - self.window)];
            if r > self.ratio * earlier {
                return Err(SolveError::Stagnated {
                    iteration,
                    residual_norm: r,
                    earlier_residual_norm: earlier,
                    window: self.window,
                });
            }
        }
        self.norms[slot(iteration)] = r;
        Ok(())
    }
}
