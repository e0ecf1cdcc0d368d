//! How branches of nonsmooth modes are found: backbones in the period, by pseudo-arclength
//! (with the stall escape and branch switching), in the energy level, genuine subharmonics,
//! branches in a system parameter; their starts and defaults derived from the system; and
//! what a run returns.

mod auto;
pub(crate) mod backbone;
mod beside;
pub(crate) mod compute;
mod continuity;
mod convergence;
mod defaults;
mod energy_backbone;
mod escape;
mod full_basis;
mod groups;
mod guesses;
mod judge;
mod level;
mod lift;
mod parameter;
mod plan;
pub(crate) mod point;
pub(crate) mod request;
pub(crate) mod result;
mod selected;
mod start;
mod subharmonic;
mod switch;
mod tether;

pub use backbone::{
    ArclengthBackboneOptions, BackboneObserver, BackboneOptions, PeriodGrid,
    MAX_CONSECUTIVE_FAILURES, TRIVIAL_ENERGY,
};
pub use compute::{compute, compute_observed};
pub use continuity::{JUMP_RATIO, SPIKE_ENERGY, SPIKE_SPREAD};
pub use convergence::convergence_study;
pub use defaults::{linear_period, FLOATING_RETRY_DEPTH};
pub use energy_backbone::{
    EnergyBackboneOptions, EnergyGrid, CALM_STEPS, ESCAPE_AFTER, ESCAPE_PERIODS, MARGINAL_SHARE,
    SLOPE_COLLAPSE, SLOPE_MEMORY,
};
pub use escape::{EscapingArclength, StallEscape};
pub use full_basis::{
    asymmetry, full_basis_branch, full_basis_system, quadrature_start, shift_origin,
    symmetry_instant, to_full_basis, with_harmonics, FullBasisBranch, FullBasisPoint,
};
pub use groups::{group_by_label, PointGroup};
pub use judge::{JUDGE_CELLS_PER_TRAVEL, JUDGE_SAMPLES};
pub use level::EnergyLevel;
pub use lift::lift;
pub use parameter::{parameter_branch, ParameterSteps};
pub use point::{BackbonePoint, CheckOutcome, PointStatus};
pub use request::{AutoChoice, Method, Request, SelectionJudgement, TimeDomainCheck};
pub use result::ModeBranches;
pub use start::{
    BackboneStart, CLOSE_START_RATIOS, FLOATING_AMPLITUDES, FLOATING_RATIOS, MIN_COARSE_HARMONICS,
    RIGID_AMPLITUDES, START_AMPLITUDES, START_RATIOS,
};
pub use subharmonic::{leave_subspace, symmetry_breaking_direction, GENUINE_SHARE, NUDGES};
pub use switch::SwitchAt;
