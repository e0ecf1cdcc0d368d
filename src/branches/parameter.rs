//! A point of a nonsmooth mode continued in a system parameter (gap, spring stiffness,
//! stiffness ratio, a length...) at its fixed fundamental frequency.
//!
//! The family of systems is any [`SystemFamily`] (a closure `f64 -> Result<BarSystem, _>`);
//! the continuation is natural-parameter over given values or pseudo-arclength inside a
//! range. Every point reaches the observer as a [`BackbonePoint`] at the fixed frequency, its
//! energy normalised by the grazing energy of the system at that parameter value.

use crate::branches::backbone::TRIVIAL_ENERGY;
use crate::branches::continuity::{Sample, Splitter};
use crate::branches::point::{BackbonePoint, PointStatus};
use crate::continuation::{
    Arclength, ArclengthOptions, Branch, EndReason, Point, Sequential, SequentialOptions, Step,
};
use crate::error::{BadRange, ContinuationError, Error, RangeDefect};
use crate::modal::energy::energy;
use crate::modal::linear::grazing_energy;
use crate::modal::Label;
use crate::solve::NonlinearSolver;
use crate::system::{HarmonicBalanceSettings, NonsmoothSystem, ParameterFamily, SystemFamily};
use std::ops::ControlFlow;

/// How [`parameter_branch`] steps through the parameter.
#[derive(Debug, Clone, PartialEq)]
pub enum ParameterSteps {
    /// Natural-parameter continuation over `values` (the first is solved from the start
    /// point); failed steps reach the observer as points that are not [`BackbonePoint::converged`].
    Values(Vec<f64>, SequentialOptions),
    /// Pseudo-arclength continuation from the start value inside
    /// [`ArclengthOptions::parameter_range`], in [`ArclengthOptions::direction`].
    Arclength(ArclengthOptions),
}

/// Continues the motion `x` at fundamental frequency `omega` of the system
/// `family.build(value)` in the family's parameter, at fixed `omega`, handing every point
/// (with the parameter value it was computed at) to `observer`, which may stop the run.
///
/// Returns the branch (its points carry the parameter in [`Point::parameter`]) with the
/// reason it ended: a run that stalls returns what it computed, with
/// [`EndReason::Stalled`](crate::continuation::EndReason::Stalled).
///
/// A converged point whose energy `E` or `E / E_g` is not finite reaches the observer as
/// [`PointStatus::NonFiniteEnergy`] (not converged), the non-finite number left in
/// it: a parameter value whose system has no grazing energy (a gap whose `E_g` underflows or
/// overflows,
/// [`SettingsError::GrazingEnergyOutOfRange`](crate::SettingsError::GrazingEnergyOutOfRange),
/// gives `energy_normalized = NaN`), or one whose motion's energy leaves the range of `f64`
/// (a bar length near `f64::MAX`). A converged point below the backbones' trivial-energy floor
/// ([`BackboneOptions::trivial_energy`](crate::branches::BackboneOptions::trivial_energy) times
/// `E_g` at its parameter) is the state of rest, not a point of the branch: it reaches the
/// observer as [`PointStatus::CollapsedToRest`] (not converged).
///
/// Branches are continuous or split, as in [`compute`](crate::branches::compute)'s runs
/// ([`JUMP_RATIO`](crate::branches::JUMP_RATIO),
/// [`SPIKE_ENERGY`](crate::branches::SPIKE_ENERGY)): a converged point that does not continue
/// the branch (its state far from the secant of the last two in the parameter, measured in
/// the energy weights of the start's system, or a one-point spike of `E / E_g`) is labelled
/// [`Label::OffBranch`] and opens a new [`BackbonePoint::branch`] index with
/// [`Event::LeftBranch`](crate::continuation::Event::LeftBranch), and the first point back
/// another with [`Event::Rejoined`](crate::continuation::Event::Rejoined); a jump of the
/// driver opens one too. A point held as a possible spike reaches the observer once the next
/// converged point has said whether it came back.
///
/// # Errors
/// A family that rejects `value`, a system at `value` without grazing energy, invalid
/// settings or options, or a start where the solver fails ([`ContinuationError::Start`],
/// arclength only). Values that do not begin at `value` are refused
/// ([`ContinuationError::InvalidOption`]), and so are several values all the same or an
/// arclength range that is empty, reversed or has a NaN end ([`ContinuationError::Range`],
/// quoting them): the run would have nowhere to go.
pub fn parameter_branch<F, S>(
    family: F,
    settings: HarmonicBalanceSettings,
    (x, omega): (Vec<f64>, f64),
    value: f64,
    steps: ParameterSteps,
    solver: S,
    mut observer: impl FnMut(f64, &BackbonePoint) -> ControlFlow<()>,
) -> Result<Branch, Error>
where
    F: SystemFamily + Clone,
    S: NonlinearSolver,
{
    if let ParameterSteps::Values(values, _) = &steps {
        check_values(values, value)?;
    }
    let basis = settings.cosine_basis()?;
    let floor = TRIVIAL_ENERGY;
    let problem = ParameterFamily::at(family.clone(), settings, omega, value)?;
    // Energies are normalised by `E_g`: a start without one is refused, as by `backbone`.
    let start = family.build(value)?;
    grazing_energy(&start)?;
    // The continuity test's norm: the energy weights of the start's system.
    let (weights, per) = {
        let description = NonsmoothSystem::new(&start, settings)?;
        let description = description.description();
        (description.state_weights(omega), description.unknowns)
    };
    let mut splitter = Splitter::<BackbonePoint, f64>::default();
    let mut stopped = false;
    // Shows the points released to the observer, up to the one at which it stops the run.
    let mut show = |released: &mut dyn Iterator<Item = (BackbonePoint, f64)>| {
        for (point, parameter) in released {
            if !stopped && observer(parameter, &point).is_break() {
                stopped = true;
            }
        }
        if stopped {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    };
    // The point in the frame of the system at its parameter value; a value the family
    // rejects is skipped (it is not a point of the branch).
    let mut report = |p: &Point| {
        let Ok(system) = family.build(p.parameter) else {
            return ControlFlow::Continue(());
        };
        let e = energy(&system, &basis, &p.x, omega);
        let e_g = grazing_energy(&system).map_or(f64::NAN, |g| g.0);
        let mut point = BackbonePoint::from_point(p, omega, e, e_g);
        if point.converged() && e_g.is_finite() && e <= floor * e_g {
            point.status = PointStatus::CollapsedToRest;
        }
        splitter.enter(&mut point);
        if point.converged() {
            let sample = Sample {
                period: p.parameter,
                energy: point.energy_normalized,
                x: p.x.clone(),
                held: Vec::new(),
            };
            if let Some(ratio) = splitter.judge(&mut point, sample, &weights, per) {
                point.label = Some(Label::OffBranch { ratio });
            }
        }
        splitter.push(point, p.parameter);
        show(&mut splitter.release())
    };
    let mut see = |step: &Step| step.point().map_or(ControlFlow::Continue(()), &mut report);
    // The energy floor above decides what counts as rest, and says so in the status.
    let mut branch = match steps {
        ParameterSteps::Values(values, options) => {
            Sequential::new(problem, solver, x, values, options)?
                .with_rest_accepted()
                .run(&mut see)
        }
        ParameterSteps::Arclength(options) => Arclength::new(problem, solver, x, value, options)?
            .with_rest_accepted()
            .run(&mut see),
    };
    // A point held until the run ended: an observer that stops there stops the run.
    if show(&mut splitter.flush()).is_break() {
        branch.end = EndReason::StoppedByObserver;
    }
    Ok(branch)
}

/// Checks the values of a natural-parameter run from the start's `value` before anything is
/// computed: they begin at `value` ([`ContinuationError::InvalidOption`]), and several values
/// that are all the same are an empty range, each step the same point
/// ([`ContinuationError::Range`]).
fn check_values(values: &[f64], value: f64) -> Result<(), ContinuationError> {
    if values.first() != Some(&value) {
        return Err(ContinuationError::InvalidOption {
            what: "first parameter value (must be the start's)",
            value: values.first().copied().unwrap_or(f64::NAN),
        });
    }
    if values.len() >= 2 && values.iter().all(|v| *v == value) {
        return Err(BadRange {
            what: "parameter values",
            start: value,
            end: value,
            steps: Some(values.len()),
            defect: RangeDefect::Empty,
        }
        .into());
    }
    Ok(())
}
