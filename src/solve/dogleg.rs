//! Powell's hybrid trust-region dogleg method.

use super::newton::Stagnation;
use super::{
    check_positive, norm, residual_scale, with_workspace, Iteration, NonlinearSolver, Problem,
    SolveInfo, SolveMonitor, Workspace,
};
use crate::error::SolveError;

/// Options of [`Dogleg`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DoglegOptions {
    /// Converged when `|F|_2 <= tolerance * problem.residual_scale()` (default `1e-9`).
    pub tolerance: f64,
    /// Iteration budget (default 100).
    pub max_iterations: usize,
    /// Initial radius as a multiple of `max(|x|_2, residual_scale)` (default 1, as MINPACK's
    /// `factor = 100` on a scaled norm is for unscaled problems too aggressive).
    pub initial_radius: f64,
    /// Smallest radius, relative to `max(|x|_2, residual_scale)`, before giving up
    /// (default `1e-13`).
    pub min_radius: f64,
}

impl Default for DoglegOptions {
    fn default() -> Self {
        Self {
            tolerance: 1e-9,
            max_iterations: 100,
            initial_radius: 1.0,
            min_radius: 1e-13,
        }
    }
}

impl DoglegOptions {
    /// Checks the options (what [`Dogleg::new`] requires).
    ///
    /// # Errors
    /// [`SolveError::InvalidOption`] for a non-positive or non-finite tolerance, initial
    /// radius or minimum radius.
    pub fn validate(&self) -> Result<(), SolveError> {
        check_positive("tolerance", self.tolerance)?;
        check_positive("initial_radius", self.initial_radius)?;
        check_positive("min_radius", self.min_radius)?;
        Ok(())
    }
}

/// Powell's hybrid method: inside a trust region of radius `Delta`, take the Newton step if
/// it fits, else the dogleg path from the Cauchy point towards it; grow or shrink `Delta` by
/// the ratio of actual to predicted decrease of `|F|^2`. The paper's solver (Matlab's
/// `fsolve`), here with the analytic generalised Jacobian instead of finite differences.
///
/// It gives up with [`SolveError::Stagnated`] when its residual norm has not dropped by 1 %
/// over [`Dogleg::STALL_WINDOW`] iterations ([`Dogleg::STALL_RATIO`]), as MINPACK's `hybrd` gives up when ten
/// iterations make no progress: accepted steps that creep along a valley of `|F|`, or that
/// only trade rounding errors once `|F|` has reached its floor, would otherwise go on for as
/// long as `max_iterations` allows (forever with `usize::MAX` and a tolerance below what
/// `f64` can reach, such as `1e-300`). A solve that converges cuts its residual far faster.
///
/// Reference: M. J. D. Powell, "A hybrid method for nonlinear equations", in Numerical
/// Methods for Nonlinear Algebraic Equations, Gordon and Breach, 1970, pp. 87–114; J. J. Moré,
/// B. S. Garbow, K. E. Hillstrom, "User guide for MINPACK-1", Argonne ANL-80-74, 1980
/// (`hybrd`'s test on the progress of the last ten iterations).
///
/// Built by [`Dogleg::new`], which validates the options, or by `Default` (the default
/// options); the options are private, so no solver holds options that `new` would reject
/// (a minimum radius that is zero or NaN would never give up):
///
/// ```compile_fail,E0451
/// use nonsmooth_modes::solve::{Dogleg, DoglegOptions};
///
/// let options = DoglegOptions { min_radius: 0.0, ..Default::default() };
/// let solver = Dogleg { options };
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Dogleg {
    options: DoglegOptions,
}

impl Dogleg {
    /// Iterations over which the solver must cut its residual norm by
    /// [`Dogleg::STALL_RATIO`], or give up with [`SolveError::Stagnated`].
    pub const STALL_WINDOW: usize = 10;

    /// The factor by which the solver must cut its residual norm every
    /// [`Dogleg::STALL_WINDOW`] iterations: 0.99, a cut of 1 %.
    pub const STALL_RATIO: f64 = 0.99;

    /// A solver with the given options.
    ///
    /// # Errors
    /// The error of [`DoglegOptions::validate`].
    pub fn new(options: DoglegOptions) -> Result<Self, SolveError> {
        options.validate()?;
        Ok(Self { options })
    }

    /// Its options.
    pub fn options(&self) -> &DoglegOptions {
        &self.options
    }
}

impl NonlinearSolver for Dogleg {
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
        let scale = residual_scale(problem);
        let mut it = Iteration::new(problem, monitor, x)?;
        let reference = norm(x).max(scale);
        let mut radius = o.initial_radius * reference;
        with_workspace(x.len(), |ws| {
            let Workspace {
                f,
                f_trial,
                trial,
                dx: newton,
                grad,
                jg,
                step,
                jp,
                jac,
                lu,
            } = ws;
            let mut r = it.residual_into(x, f, 0)?;
            let mut progress = Stagnation::new(Self::STALL_WINDOW, Self::STALL_RATIO);
            for iteration in 0..o.max_iterations {
                if r <= tol {
                    return Ok(it.info(iteration, r));
                }
                progress.check(iteration, r)?;
                let factored = it.factor_jacobian(x, jac, lu, iteration);
                // A singular Jacobian still allows Cauchy steps; a non-finite one does not.
                if let Err(e @ SolveError::NonFinite { .. }) = factored {
                    return Err(e);
                }
                // Steepest-descent direction of |F|^2/2: g = J^T F.
                jac.mul_transpose_vec(f, grad);
                jac.mul_vec(grad, jg);
                let g2 = grad.iter().map(|v| v * v).sum::<f64>();
                let jg2 = jg.iter().map(|v| v * v).sum::<f64>();
                let cauchy_length = if jg2 > 0.0 { g2 / jg2 } else { 0.0 };
                let have_newton = match &factored {
                    Ok(()) => {
                        for (d, fi) in newton.iter_mut().zip(f.iter()) {
                            *d = -fi;
                        }
                        lu.solve_in_place(newton);
                        newton.iter().all(|v| v.is_finite())
                    }
                    Err(_) => false,
                };
                loop {
                    dogleg_step(newton, have_newton, grad, cauchy_length, radius, step);
                    for ((xt, xi), d) in trial.iter_mut().zip(x.iter()).zip(step.iter()) {
                        *xt = xi + d;
                    }
                    let rt = it.residual_into(trial, f_trial, iteration)?;
                    jac.mul_vec(step, jp);
                    // Reductions of |F|^2 relative to r^2, so that residuals up to the
                    // largest finite ones do not overflow when squared.
                    let predicted_r2 = f
                        .iter()
                        .zip(jp.iter())
                        .map(|(f, d)| ((f + d) / r).powi(2))
                        .sum::<f64>();
                    let predicted = 1.0 - predicted_r2;
                    let actual = 1.0 - (rt / r).powi(2);
                    let ratio = if predicted > 0.0 {
                        actual / predicted
                    } else {
                        -1.0
                    };
                    let length = norm(step);
                    // A step or a radius that is not finite cannot shrink to a decision.
                    if !(length.is_finite() && radius.is_finite() && actual.is_finite()) {
                        return Err(SolveError::NonFinite {
                            what: "dogleg step",
                            iteration,
                        });
                    }
                    if ratio < 0.25 {
                        radius = 0.5 * length.min(radius);
                    } else if ratio > 0.75 {
                        radius = radius.max(2.0 * length);
                    }
                    if actual > 0.0 && (ratio > 1e-4 || rt <= tol) {
                        x.copy_from_slice(trial);
                        std::mem::swap(f, f_trial);
                        r = rt;
                        break;
                    }
                    // A radius of zero (a zero-length step, or a minimum radius that
                    // underflows relative to a tiny `reference`) cannot shrink below it.
                    if radius < o.min_radius * reference || radius == 0.0 {
                        factored?;
                        return Err(SolveError::TrustRegion {
                            iteration,
                            radius,
                            residual_norm: r,
                        });
                    }
                }
            }
            it.exhausted(o.max_iterations, r, tol)
        })
    }
}

/// The dogleg step of length at most `radius`.
fn dogleg_step(
    newton: &[f64],
    have_newton: bool,
    grad: &[f64],
    cauchy_length: f64,
    radius: f64,
    step: &mut [f64],
) {
    let gnorm = norm(grad);
    if have_newton && norm(newton) <= radius {
        step.copy_from_slice(newton);
        return;
    }
    let cauchy_norm = cauchy_length * gnorm;
    if !have_newton || cauchy_norm >= radius || gnorm == 0.0 {
        let s = if gnorm > 0.0 { radius / gnorm } else { 0.0 };
        let s = if have_newton || cauchy_norm >= radius {
            s
        } else {
            cauchy_length
        };
        for (d, g) in step.iter_mut().zip(grad) {
            *d = -s * g;
        }
        return;
    }
    // Point on the segment from the Cauchy point c = -cauchy_length g towards the Newton
    // point with |p| = radius (no allocation: c and n - c are formed on the fly).
    let cauchy = |g: &f64| -cauchy_length * g;
    let (mut a, mut b, mut cc) = (0.0, 0.0, 0.0);
    for (n, g) in newton.iter().zip(grad) {
        let c = cauchy(g);
        let d = n - c;
        a += d * d;
        b += c * d;
        cc += c * c;
    }
    let b = 2.0 * b;
    let cc = cc - radius * radius;
    let tau = if a > 0.0 {
        (-b + (b * b - 4.0 * a * cc).max(0.0).sqrt()) / (2.0 * a)
    } else {
        0.0
    };
    for ((s, n), g) in step.iter_mut().zip(newton).zip(grad) {
        let c = cauchy(g);
        *s = c + tau * (n - c);
    }
}
