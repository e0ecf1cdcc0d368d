//! The points of a backbone and what a backbone run returns: every point it computed, each
//! with its status, and the reason it ended. A run that stalls or is stopped keeps its points.

pub use crate::status::PointStatus;

use crate::branches::continuity::OnBranch;
use crate::continuation::{Event, Point};
use crate::error::{Error, SettingsError};
use crate::fourier::{frequency_of_period, period_of_frequency, Basis};
use crate::modal::{Character, Label};
use crate::solution::Solution;
use crate::solve::SolveInfo;
use crate::stability::{Floquet, HillSpectrum, StabilityError};
use crate::system::NonsmoothSystem;
use crate::verify::{PeriodicityReport, VerifyError};
use std::fmt;

/// One point of a backbone.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[non_exhaustive]
pub struct BackbonePoint {
    /// Step number.
    pub step: usize,
    /// Period `T`.
    pub period: f64,
    /// Fundamental angular frequency `Omega = 2 pi / T`.
    pub omega: f64,
    /// Energy `E` (formulation §7).
    pub energy: f64,
    /// `E / E_g`.
    pub energy_normalized: f64,
    /// What became of the step: converged, solver failed (with its error), or collapsed to
    /// the state of rest.
    pub status: PointStatus,
    /// `|F|_2` at the returned unknowns.
    pub residual_norm: f64,
    /// Solver iterations.
    pub iterations: usize,
    /// The unknowns (layout of [`NonsmoothSystem`]).
    pub x: Vec<f64>,
    /// Step used to reach the point (period increment, or arclength `ds`).
    pub step_size: f64,
    /// Events detected there (folds, jumps, grazing).
    pub events: Vec<Event>,
    /// Index of the branch the point lies on within its run: 0 for the branch the run
    /// started on, one more after each jump (a stall escape, a switch at a branch point).
    pub branch: usize,
    /// The report of the time-domain check of a converged point, where one was asked
    /// ([`Request::check`](crate::branches::Request::check)) and could run.
    pub time_domain: Option<PeriodicityReport>,
    /// What became of the time-domain check of a converged point, where one was asked:
    /// passed, failed, unchecked (a condition without a time-domain form) or not run (and
    /// why).
    pub check: Option<CheckOutcome>,
    /// What a converged point's motion is like: contacts and grazings per period, energy
    /// shares by bar and harmonic, dominant harmonic and linear modes.
    pub character: Option<Character>,
    /// Which branch of the mode a converged point lies on: skeleton, internal resonance,
    /// subharmonic, off the branch its run followed, or unverified ([`Label`]).
    pub label: Option<Label>,
    /// The Floquet multipliers of a converged point and its verdict, where they were asked
    /// ([`Request::stability`](crate::branches::Request::stability)), or why they could not
    /// be computed.
    #[cfg_attr(
        feature = "serde",
        serde(serialize_with = "crate::stability::serialize_outcome")
    )]
    pub stability: Option<Result<Floquet, StabilityError>>,
    /// The Hill exponents of a converged point and their verdict, where they were asked
    /// ([`Request::hill`](crate::branches::Request::hill)): the stability of the truncated
    /// harmonic-balance equations, a cross-check of [`BackbonePoint::stability`].
    #[cfg_attr(
        feature = "serde",
        serde(serialize_with = "crate::stability::serialize_outcome")
    )]
    pub hill: Option<Result<HillSpectrum, Error>>,
}

impl BackbonePoint {
    /// Whether the solver converged to a motion that touches (not the state of rest), with a
    /// finite energy: `status == PointStatus::Converged`. Derived from
    /// [`BackbonePoint::status`], so that the two cannot disagree.
    pub fn converged(&self) -> bool {
        self.status == PointStatus::Converged
    }

    /// A motion `x` solved at the fixed frequency `omega` (not continued: step 0, no step
    /// size, no events, branch 0, nothing annotated), as a converged point with its energy
    /// `energy` normalised by the grazing energy `e_g`, and the solver's report `solved`. A
    /// point whose energy or `E / E_g` is not finite is [`PointStatus::NonFiniteEnergy`].
    pub fn solved(x: Vec<f64>, omega: f64, energy: f64, e_g: f64, solved: &SolveInfo) -> Self {
        let energy_normalized = energy / e_g;
        Self {
            energy,
            energy_normalized,
            status: PointStatus::Converged.with_energy(energy, energy_normalized),
            residual_norm: solved.residual_norm,
            iterations: solved.iterations,
            ..Self::unannotated(Timescale::of_frequency(omega), x)
        }
    }

    /// The point as a [`Solution`] of `problem` (the problem the backbone was computed for),
    /// to ask it for fields, histories, diagnostics and the time-domain check.
    ///
    /// # Errors
    /// See [`Solution::new`]: a point whose unknowns do not fit `problem`.
    pub fn solution<'a, B: Basis>(
        &'a self,
        problem: &'a NonsmoothSystem<B>,
    ) -> Result<Solution<'a, B>, SettingsError> {
        Solution::new(problem, &self.x, self.omega)
    }

    /// The backbone view of a continuation point at fundamental frequency `omega` (its period
    /// derived from it), with its energy `energy` and the grazing energy `e_g` used for
    /// normalisation.
    pub fn from_point(p: &Point, omega: f64, energy: f64, e_g: f64) -> Self {
        let time = Timescale::of_frequency(omega);
        Self::from_parts(p, (&p.x, time), energy, e_g, PointStatus::of(p))
    }

    /// The backbone view of a continuation point whose unknowns, `x` at the period and
    /// frequency `time`, are given apart from it (a point of an energy-level problem holds
    /// `(x, Omega)`), with its status. Its unknowns are copied once, here: the point stays
    /// the driver's. A converged point whose energy or `E / E_g` is not finite becomes
    /// [`PointStatus::NonFiniteEnergy`], not converged.
    pub(crate) fn from_parts(
        p: &Point,
        (x, time): (&[f64], Timescale),
        energy: f64,
        e_g: f64,
        status: PointStatus,
    ) -> Self {
        let energy_normalized = energy / e_g;
        let status = status.with_energy(energy, energy_normalized);
        Self {
            step: p.step,
            energy,
            energy_normalized,
            status,
            residual_norm: p.residual_norm,
            iterations: p.iterations,
            step_size: p.step_size,
            events: p.events.clone(),
            ..Self::unannotated(time, x.to_vec())
        }
    }

    /// The motion `x` at `time` before any solve or annotation: step 0, no energy (NaN), not
    /// converged, no step, events, branch index or annotations; the constructors fill in what
    /// they know.
    fn unannotated(time: Timescale, x: Vec<f64>) -> Self {
        Self {
            step: 0,
            period: time.period,
            omega: time.omega,
            energy: f64::NAN,
            energy_normalized: f64::NAN,
            status: PointStatus::Rejected,
            residual_norm: f64::NAN,
            iterations: 0,
            x,
            step_size: 0.0,
            events: Vec::new(),
            branch: 0,
            time_domain: None,
            check: None,
            character: None,
            label: None,
            stability: None,
            hill: None,
        }
    }
}

/// A point whose label reads as its branch's own (skeleton, subharmonic, or none yet) becomes
/// [`Label::OffBranch`] when it turns out a spike; a check that failed it keeps
/// [`Label::Unverified`].
impl OnBranch for BackbonePoint {
    fn set_branch(&mut self, branch: usize) {
        self.branch = branch;
    }

    fn push_event(&mut self, event: Event) {
        self.events.push(event);
    }

    fn jumped(&self) -> bool {
        self.events.iter().any(|e| matches!(e, Event::Jump { .. }))
    }

    fn left_branch(&mut self, ratio: f64) {
        if self.label != Some(Label::Unverified) {
            self.label = Some(Label::OffBranch { ratio });
        }
    }
}

#[cfg(test)]
impl BackbonePoint {
    /// A point of unit energy at step `step` and period `period`, with `label`, converged
    /// or collapsed to rest (for tests of what reads labels and periods).
    pub(crate) fn for_test(
        step: usize,
        period: f64,
        label: Option<crate::modal::Label>,
        converged: bool,
    ) -> Self {
        Self {
            step,
            period,
            omega: 1.0,
            x: vec![0.0],
            energy: 1.0,
            energy_normalized: 1.0,
            status: if converged {
                PointStatus::Converged
            } else {
                PointStatus::CollapsedToRest
            },
            residual_norm: 0.0,
            iterations: 1,
            step_size: 0.01,
            events: Vec::new(),
            branch: 0,
            time_domain: None,
            check: None,
            character: None,
            label,
            stability: None,
            hill: None,
        }
    }
}

/// What became of the time-domain check of a converged point
/// ([`BackbonePoint::check`]). Only [`CheckOutcome::Failed`] makes the point
/// [`Label::Unverified`]; the others keep the label its harmonic content gives.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[non_exhaustive]
pub enum CheckOutcome {
    /// Marched: the displacement defect ([`BackbonePoint::time_domain`]) is within the
    /// check's tolerance.
    Passed,
    /// Marched: the displacement defect exceeds the tolerance. The point is not a motion of
    /// the bars to tolerance.
    Failed,
    /// Not marched: condition `condition` declares no time-domain form
    /// ([`BoundaryCondition::time_domain_form`](crate::bc::BoundaryCondition::time_domain_form)),
    /// so the law in time is unknown. Nothing was checked, nothing failed.
    Unchecked {
        /// Name of the condition.
        condition: String,
    },
    /// Not marched: the march would take `steps` time steps, over the check's budget
    /// [`TimeDomainCheck::max_steps`](crate::branches::TimeDomainCheck::max_steps).
    OverBudget {
        /// Steps of the march.
        steps: f64,
        /// The budget.
        max_steps: f64,
    },
    /// The march could not run or complete (its cost or memory bound, a state it cannot
    /// build): the error.
    NotRun(
        #[cfg_attr(feature = "serde", serde(serialize_with = "crate::error::display"))] VerifyError,
    ),
}

impl CheckOutcome {
    /// `Some(passed)` where the point was marched, `None` where it was not: the `verified`
    /// argument of [`label`](crate::modal::label).
    pub fn verified(&self) -> Option<bool> {
        match self {
            CheckOutcome::Passed => Some(true),
            CheckOutcome::Failed => Some(false),
            _ => None,
        }
    }

    /// Why a point was not marched, `None` where it was.
    pub fn reason(&self) -> Option<String> {
        match self {
            CheckOutcome::Passed | CheckOutcome::Failed => None,
            CheckOutcome::Unchecked { condition } => Some(format!(
                "condition `{condition}` declares no time-domain form"
            )),
            CheckOutcome::OverBudget { steps, max_steps } => Some(format!(
                "its march would take {steps:.3e} steps, over the check's budget of {max_steps:.3e}"
            )),
            CheckOutcome::NotRun(error) => Some(error.to_string()),
        }
    }
}

/// CSV-safe words: `passed`, `failed`, `unchecked`, `over-budget`, `not-run`.
impl fmt::Display for CheckOutcome {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            CheckOutcome::Passed => "passed",
            CheckOutcome::Failed => "failed",
            CheckOutcome::Unchecked { .. } => "unchecked",
            CheckOutcome::OverBudget { .. } => "over-budget",
            CheckOutcome::NotRun(_) => "not-run",
        })
    }
}

impl BackbonePoint {
    /// Whether a run may count the point as good: converged, and its time-domain check, if
    /// one was asked, did not fail and was not prevented from running. An unchecked point
    /// (a condition without a time-domain form) counts: there is no law in time to hold it
    /// against.
    pub(crate) fn is_good(&self) -> bool {
        self.converged()
            && !matches!(
                self.check,
                Some(
                    CheckOutcome::Failed
                        | CheckOutcome::OverBudget { .. }
                        | CheckOutcome::NotRun(_)
                )
            )
            && self.label != Some(Label::Unverified)
    }
}

/// The period `T` and fundamental frequency `Omega` of a point: the one its driver holds as
/// its parameter, kept as it is, and the other derived from it once
/// ([`frequency_of_period`], [`period_of_frequency`]): a point's period and frequency never
/// come from a round trip `T -> Omega -> T`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Timescale {
    /// Period `T`.
    pub period: f64,
    /// Fundamental angular frequency `Omega = 2 pi / T`.
    pub omega: f64,
}

impl Timescale {
    /// The time scale of a driver continuing in the period (a period grid).
    pub(crate) fn of_period(period: f64) -> Self {
        let omega = frequency_of_period(period);
        Self { period, omega }
    }

    /// The time scale of a driver continuing in the frequency (pseudo-arclength, an energy
    /// level, a system parameter at fixed frequency).
    pub(crate) fn of_frequency(omega: f64) -> Self {
        let period = period_of_frequency(omega);
        Self { period, omega }
    }
}
