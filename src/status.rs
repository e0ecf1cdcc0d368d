//! What became of a step of a run, shared by the backbones of [`crate::branches`] and the
//! forced responses of [`crate::forced`], which re-export or name it: a step's status and the
//! consecutive failures after which a period grid stops.

use crate::continuation::Point;
use crate::error::SolveError;

/// Consecutive failed steps after which a period grid stops, stalled (the default
/// [`BackboneOptions::max_consecutive_failures`](
/// crate::branches::BackboneOptions::max_consecutive_failures)).
pub const MAX_CONSECUTIVE_FAILURES: usize = 40;

/// What became of one step of a backbone.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[non_exhaustive]
pub enum PointStatus {
    /// The solver converged to a motion of the branch.
    Converged,
    /// The solver failed; the point holds its last iterate.
    SolverFailed(SolveError),
    /// The solver converged to a motion whose energy is below the backbone's trivial-energy
    /// floor ([`BackboneOptions::trivial_energy`](crate::branches::BackboneOptions::trivial_energy)
    /// times `E_g`): the state of rest, which is not a point of the branch.
    CollapsedToRest,
    /// The solver converged to a motion the backbone's acceptance test refuses (an
    /// energy-level backbone refuses a frequency that is not positive or beyond the
    /// problem's [`max_frequency`](crate::system::Discretization::max_frequency)).
    Rejected,
    /// The solver converged, but the motion's energy `E` or its normalisation `E / E_g` is
    /// not finite (NaN or infinite, left in the point): the energy of the motion leaves the
    /// range of `f64` (a bar length or frequency near the limits of what the constructors
    /// accept), or the system at a parameter value of
    /// [`parameter_branch`](crate::branches::parameter_branch) has no grazing energy `E_g`
    /// ([`SettingsError::GrazingEnergyOutOfRange`](
    /// crate::error::SettingsError::GrazingEnergyOutOfRange)). A point without a finite
    /// energy is not a point of the backbone.
    NonFiniteEnergy,
}

impl PointStatus {
    /// The status of a point of energy `energy` and `E / E_g` `energy_normalized`: a
    /// converged one whose energy is not finite is [`PointStatus::NonFiniteEnergy`].
    pub(crate) fn with_energy(self, energy: f64, energy_normalized: f64) -> Self {
        match self {
            Self::Converged if !(energy.is_finite() && energy_normalized.is_finite()) => {
                Self::NonFiniteEnergy
            }
            status => status,
        }
    }

    /// The status of a continuation point of a backbone, whose acceptance test is the
    /// trivial-energy floor.
    pub fn of(point: &Point) -> Self {
        Self::refused_as(point, Self::CollapsedToRest)
    }

    /// The status of a continuation point, `refused` where the acceptance test refused a
    /// converged solution.
    pub(crate) fn refused_as(point: &Point, refused: Self) -> Self {
        match (&point.error, point.converged) {
            (_, true) => Self::Converged,
            (Some(e), false) => Self::SolverFailed(e.clone()),
            (None, false) => refused,
        }
    }

    /// A short label for tables: `converged`, `solver-failed`, `collapsed-to-rest`,
    /// `rejected` or `non-finite-energy`.
    pub fn label(&self) -> &'static str {
        match self {
            Self::Converged => "converged",
            Self::SolverFailed(_) => "solver-failed",
            Self::CollapsedToRest => "collapsed-to-rest",
            Self::Rejected => "rejected",
            Self::NonFiniteEnergy => "non-finite-energy",
        }
    }
}
