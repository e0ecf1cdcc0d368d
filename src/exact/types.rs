//! What an exact branch is made of: its points, skipped periods and end.

use crate::branches::BackbonePoint;
use crate::stability::{StabilityError, UnresolvedReason};

/// One point of an exact branch: a [`BackbonePoint`] (its `x` is empty: the motion is no
/// harmonic-balance solution; its `time_domain` is the orbit's own periodicity report, its
/// `stability` the verdict of its monodromy, its `label` that of the harmonic-balance point
/// its segment was seeded from) and what only an exact point has.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct ExactPoint {
    /// The point; its `period` is the map's, a whole number of grid steps.
    pub point: BackbonePoint,
    /// The period of the requested grid it stands for.
    pub requested_period: f64,
    /// `(E - E_hb) / E_hb` against the converged harmonic-balance point at the same grid
    /// period (`None` where there is none).
    pub harmonic_balance_distance: Option<f64>,
    /// Energy the integrator's merges removed over one period, relative to the motion's.
    pub removed_energy: f64,
    /// Contact intervals per period of each unilateral condition (model order).
    pub contacts: Vec<usize>,
    /// Whether the point was corrected from a harmonic-balance point (a seed or a reseed)
    /// rather than continued.
    pub seeded: bool,
}

/// Why a period has no exact point, or why a seed failed.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[non_exhaustive]
pub enum LossReason {
    /// No converged harmonic-balance point at the period to seed from.
    NoHarmonicBalancePoint,
    /// The correction did not reach a periodic orbit near the start (its reason, with the
    /// numbers).
    Correction(UnresolvedReason),
    /// The orbit found jumped: its energy left the prediction by `change` (relative to the
    /// previous energy), more than `allowed`.
    Jump {
        /// `|E - E_predicted| / E_previous`.
        change: f64,
        /// The bound at that step.
        allowed: f64,
    },
    /// The walk back from a segment's seed was lost before it reached this period.
    Unreached,
    /// The map could not be marched or its matrices decomposed.
    Error(
        #[cfg_attr(feature = "serde", serde(serialize_with = "crate::error::display"))]
        StabilityError,
    ),
}

impl std::fmt::Display for LossReason {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::NoHarmonicBalancePoint => f.write_str("no converged harmonic-balance point"),
            Self::Correction(reason) => write!(f, "{reason}"),
            Self::Jump { change, allowed } => write!(
                f,
                "the orbit found left the prediction by {:.2} % of the energy (allowed {:.2} %)",
                100.0 * change,
                100.0 * allowed
            ),
            Self::Unreached => f.write_str("the walk back from the next seed was lost before it"),
            Self::Error(e) => write!(f, "{e}"),
        }
    }
}

/// A requested period without an exact point.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Skipped {
    /// The map's period.
    pub period: f64,
    /// Why, after the reseed failed.
    pub reason: LossReason,
}

/// Why an exact branch ended.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[non_exhaustive]
pub enum ExactEnd {
    /// The last segment reached the grid's last period (periods may be
    /// [`ExactBranch::skipped`], with their reasons).
    Completed,
    /// No harmonic-balance point corrected to a seed: `attempts` were tried, the last
    /// failing for `last`.
    NoSeed {
        /// Points tried.
        attempts: usize,
        /// Why the last one failed.
        last: LossReason,
    },
    /// The branch was lost at `period` and could not be reseeded at it or the periods after
    /// it (`attempts` in a row): the walk in that direction stopped there.
    Lost {
        /// The last period tried.
        period: f64,
        /// Consecutive periods skipped.
        attempts: usize,
        /// Why the last one was skipped.
        last: LossReason,
    },
}

/// An exact branch: its points in grid order, the periods it skipped and why it ended.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct ExactBranch {
    /// The first grazing energy `E_g` the energies are normalised by.
    pub grazing_energy: f64,
    /// The time step of the branch's grid.
    pub dt: f64,
    /// Rows of each monodromy matrix.
    pub dimension: usize,
    /// The points, in the order of the grid.
    pub points: Vec<ExactPoint>,
    /// The periods without a point, and why.
    pub skipped: Vec<Skipped>,
    /// Why the walk ended.
    pub end: ExactEnd,
}
