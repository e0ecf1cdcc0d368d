//! Numerical continuation of solution families `F(x, lambda) = 0`.
//!
//! The drivers know nothing about bars: they see a [`ContinuationProblem`] (a
//! [`Problem`] at its current parameter, plus the parameter and the derivative in it) and a
//! [`NonlinearSolver`](crate::solve::NonlinearSolver).
//! [`NonsmoothSystem`](crate::system::NonsmoothSystem) is one in `lambda = Omega`;
//! [`PeriodParametrised`] turns any problem in a frequency into one in the period.
//!
//! Both drivers, natural-parameter ([`Sequential`]) and pseudo-arclength ([`Arclength`]),
//! have one shape: `step()` returns a [`Step`] (the caller owns the loop); as an
//! `Iterator<Item = Result<Point, ContinuationError>>` they yield the accepted points and
//! then the error of a run that failed; `run(&mut observer)` returns a [`Branch`] whose end
//! reason is always set, and the [`Observer`] (any closure `FnMut(&Step) -> ControlFlow<()>`)
//! sees every step, accepted or rejected, and may stop the run.
//!
//! Bordered systems (the pseudo-arclength corrector, an
//! [`EnergyLevel`](crate::branches::EnergyLevel)) store their unknowns as `y = (x, parameter)`,
//! the parameter last: [`augmented`] reads and writes that layout.
//!
//! [`ContinuationError`]: crate::ContinuationError

mod arclength;
pub mod augmented;
mod bordering;
mod driver;
mod progress;
mod range;
mod sequential;
mod speculative;

pub use arclength::{Arclength, ArclengthOptions, ArclengthScale, TangentPredictor};
pub(crate) use bordering::{fill_bordered, solve_bordered};
pub(crate) use driver::{next_point, run_with};
pub use driver::{Branch, EndReason, Observer, RejectReason, Rejection, Step};
pub use progress::{quiet, Progress};
pub(crate) use range::{Direction, Ends, Range};
pub use sequential::{geomspace, linspace, Predictor, Selection, Sequential, SequentialOptions};
pub use speculative::{Speculation, SpeculationStats, Speculative};

use crate::error::SolveError;
use crate::fourier::{frequency_of_period, period_of_frequency};
use crate::linalg::DenseMatrix;
use crate::solve::{Problem, Structured};
use crate::verdict::Crossing;
use crate::verdict::Verdict;

/// A family of square systems `F(x, lambda) = 0` in one scalar parameter: a [`Problem`] at
/// its current parameter, plus the parameter and the derivative in it.
///
/// Drivers set the parameter, then solve the problem as it is; an adapter that changes the
/// parameter (the period for a frequency, [`PeriodParametrised`]) forwards the problem and
/// its [`Problem::structure`] unchanged.
pub trait ContinuationProblem: Problem {
    /// The current parameter `lambda`.
    fn parameter(&self) -> f64;

    /// Moves the problem to parameter `lambda` (cheap when it does not change). A value the
    /// problem cannot take makes its residual non-finite, which solvers report as
    /// [`SolveError::NonFinite`].
    fn set_parameter(&mut self, lambda: f64);

    /// `dF/dlambda` at fixed `x` and the current parameter into `df`.
    fn parameter_derivative(&mut self, x: &[f64], df: &mut [f64]);
}

impl<P: ContinuationProblem + ?Sized> ContinuationProblem for &mut P {
    fn parameter(&self) -> f64 {
        (**self).parameter()
    }
    fn set_parameter(&mut self, lambda: f64) {
        (**self).set_parameter(lambda)
    }
    fn parameter_derivative(&mut self, x: &[f64], df: &mut [f64]) {
        (**self).parameter_derivative(x, df)
    }
}

/// A problem in an angular frequency `Omega`, continued in the period `T = 2 pi / Omega`
/// instead (chain rule `dF/dT = -(2 pi / T^2) dF/dOmega`). The parameter of its points is the
/// period, and the frequency of the problem is derived from it once per parameter
/// ([`frequency_of_period`]).
#[derive(Debug, Clone)]
pub struct PeriodParametrised<P> {
    inner: P,
    period: f64,
}

impl<P: ContinuationProblem> PeriodParametrised<P> {
    /// `inner` continued in the period (starting at the period of its current frequency).
    pub fn new(inner: P) -> Self {
        let period = period_of_frequency(inner.parameter());
        Self { inner, period }
    }

    /// The problem in the frequency.
    pub fn inner(&self) -> &P {
        &self.inner
    }

    /// The problem in the frequency, mutably (its frequency is the current period's).
    pub fn inner_mut(&mut self) -> &mut P {
        &mut self.inner
    }

    /// The problem in the frequency.
    pub fn into_inner(self) -> P {
        self.inner
    }
}

impl<P: ContinuationProblem> Problem for PeriodParametrised<P> {
    fn dimension(&self) -> usize {
        self.inner.dimension()
    }
    fn residual(&mut self, x: &[f64], f: &mut [f64]) {
        self.inner.residual(x, f)
    }
    fn jacobian(&mut self, x: &[f64], jac: &mut DenseMatrix) {
        self.inner.jacobian(x, jac)
    }
    fn structure(&mut self) -> Option<&mut dyn Structured> {
        self.inner.structure()
    }
}

impl<P: ContinuationProblem> ContinuationProblem for PeriodParametrised<P> {
    fn parameter(&self) -> f64 {
        self.period
    }
    fn set_parameter(&mut self, period: f64) {
        self.period = period;
        self.inner.set_parameter(frequency_of_period(period));
    }
    fn parameter_derivative(&mut self, x: &[f64], df: &mut [f64]) {
        self.inner.parameter_derivative(x, df);
        let chain = -2.0 * std::f64::consts::PI / (self.period * self.period);
        df.iter_mut().for_each(|v| *v *= chain);
    }
}

/// One point of a branch.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Point {
    /// Step number (0-based).
    pub step: usize,
    /// Value of the continuation parameter (the period under [`PeriodParametrised`], the
    /// frequency for a harmonic-balance system, the system parameter of a family).
    pub parameter: f64,
    /// Solution (the last iterate when the step failed; the last converged solution when that
    /// iterate's residual is not finite, as after a diverged solve).
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
#[non_exhaustive]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub enum Event {
    /// Turning point: the parameter component of the tangent changed sign.
    Fold {
        /// Parameter at the point after the fold.
        parameter: f64,
    },
    /// The branch jumped: the corrected point is far from its prediction even at the
    /// smallest step, or a strategy on top of the driver moved it to a solution found at
    /// fixed parameter (the backbone's [`StallEscape`](crate::branches::StallEscape)).
    Jump {
        /// Distance to the prediction (or to the point jumped from) over the step size.
        ratio: f64,
    },
    /// A simple branch point lies between this point and the one before: the sign of
    /// `det [J, F_lambda; t^T W]` (with the tangent `t` oriented along the branch) changed
    /// while every law's active set kept its size. A fold leaves that sign unchanged; a
    /// change of active set can flip it without a branch point (the generalised Jacobian
    /// jumps), so such a change is reported as grazing alone.
    /// [`Arclength::switch_branch`](crate::continuation::Arclength::switch_branch) follows
    /// the other branch.
    BranchPoint {
        /// Parameter at the point after the branch point.
        parameter: f64,
    },
    /// The active set of a unilateral law appeared (`contact == true`) or vanished.
    Grazing {
        /// Law index.
        law: usize,
        /// Whether the contact is active after the event.
        contact: bool,
    },
    /// The point is unstable and the converged point before it on the same branch was
    /// stable ([`stability`](crate::stability)): a multiplier left the unit circle in
    /// between, the way `crossing` says (through `+1`: a fold or symmetry-breaking branch
    /// point; through `-1`: a period-doubling; a complex pair: Neimark–Sacker).
    StabilityLost {
        /// Where the largest multiplier sits now.
        crossing: Crossing,
    },
    /// The point is stable and the converged point before it on the same branch was not.
    StabilityGained {
        /// Where the largest multiplier of the point before sat.
        crossing: Crossing,
    },
    /// The point's harmonic content reads as the branch's own, but it does not continue the
    /// branch its run followed so far: it lies `ratio` times the predicted step from the
    /// secant through the branch's last two points
    /// ([`JUMP_RATIO`](crate::branches::JUMP_RATIO)), or its energy is off the chord of its
    /// neighbours' as a one-point spike ([`SPIKE_ENERGY`](crate::branches::SPIKE_ENERGY),
    /// `ratio` then that of its state). The point opens a new branch index;
    /// reported by [`compute`](crate::branches::compute) on the first point of each
    /// excursion.
    LeftBranch {
        /// Distance to the branch's secant prediction over the predicted step.
        ratio: f64,
    },
    /// The run came back to the branch it left at the last
    /// [`Event::LeftBranch`]: this point continues that branch again, under a new branch
    /// index.
    Rejoined,
}

impl Event {
    /// The event of a point whose verdict is `now` after a point of the same branch whose
    /// verdict was `before`: [`Event::StabilityLost`] or [`Event::StabilityGained`], `None`
    /// where stability did not change.
    pub(crate) fn of_verdicts(before: Verdict, now: Verdict) -> Option<Self> {
        match (before, now) {
            (Verdict::Stable, Verdict::Unstable(crossing)) => {
                Some(Event::StabilityLost { crossing })
            }
            (Verdict::Unstable(crossing), Verdict::Stable) => {
                Some(Event::StabilityGained { crossing })
            }
            _ => None,
        }
    }

    /// A short label for tables: `fold`, `jump`, `branch-point`, `grazing+`, `grazing-`,
    /// `stability-lost`, `stability-gained`, `left-branch`, `rejoined`.
    pub fn label(&self) -> &'static str {
        match self {
            Event::Fold { .. } => "fold",
            Event::Jump { .. } => "jump",
            Event::BranchPoint { .. } => "branch-point",
            Event::Grazing { contact: true, .. } => "grazing+",
            Event::Grazing { contact: false, .. } => "grazing-",
            Event::StabilityLost { .. } => "stability-lost",
            Event::StabilityGained { .. } => "stability-gained",
            Event::LeftBranch { .. } => "left-branch",
            Event::Rejoined => "rejoined",
        }
    }
}
