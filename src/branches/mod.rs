//! How branches of nonsmooth modes are found: backbones in the period, by pseudo-arclength
//! (with the stall escape and branch switching), in the energy level, genuine subharmonics,
//! branches in a system parameter; their starts and defaults derived from the system; and
//! what a run returns.

mod backbone;
mod convergence;
mod defaults;
mod energy_backbone;
mod escape;
mod level;
mod parameter;
mod point;
mod start;
mod subharmonic;
mod switch;

pub use backbone::{
    arclength_backbone, arclength_backbone_observed, backbone, backbone_from,
    backbone_speculative_with, backbone_with, ArclengthBackboneOptions, BackboneObserver,
    BackboneOptions, PeriodGrid,
};
pub use convergence::{convergence_study, ConvergenceEntry};
pub use defaults::{linear_period, FLOATING_RETRY_DEPTH};
pub use energy_backbone::{
    energy_backbone, energy_backbone_with, EnergyBackboneOptions, EnergyGrid, CALM_STEPS,
    ESCAPE_AFTER, ESCAPE_PERIODS, MARGINAL_SHARE, SLOPE_COLLAPSE, SLOPE_MEMORY,
};
pub use escape::{EscapingArclength, StallEscape};
pub use level::{split_frequency, EnergyLevel};
pub use parameter::{parameter_branch, ParameterSteps};
pub use point::{Backbone, BackbonePoint, PointStatus};
pub use start::{
    backbone_start, BackboneStart, FLOATING_AMPLITUDES, FLOATING_RATIOS, RIGID_AMPLITUDES,
    START_AMPLITUDES, START_RATIOS,
};
pub use subharmonic::{
    genuine_subharmonic_backbone, genuine_subharmonic_backbone_with, leave_subspace,
    symmetry_breaking_direction, GENUINE_SHARE, NUDGES,
};
pub use switch::SwitchAt;
