//! Modal post-processing: energy and its normalisation, linear modes of the open-contact
//! system, branch seeds, backbones, branches in a system parameter, and the signature of a
//! point for reports (subharmonic share, contact intervals per period).

mod backbone;
mod character;
mod defaults;
pub mod diagnostics;
mod drift;
pub mod energy;
mod energy_backbone;
mod escape;
pub mod field;
mod level;
pub mod linear;
mod parameter;
mod point;
pub mod signature;
mod start;
mod subharmonic;
mod switch;

pub use backbone::{
    arclength_backbone, arclength_backbone_observed, backbone, backbone_from,
    backbone_speculative_with, backbone_with, ArclengthBackboneOptions, BackboneObserver,
    BackboneOptions, PeriodGrid,
};
pub use character::{character, label, nearest_mode, Character, Label, GRAZING_TOLERANCE};
pub use defaults::{linear_period, FLOATING_RETRY_DEPTH};
pub use diagnostics::{
    convergence_study, diagnose, displacement_grid, end_history, law_history, PointDiagnostics,
};
pub use drift::{check_held, drifting_bars};
pub use energy::{energy, energy_at, energy_gradient};
pub use energy_backbone::{
    energy_backbone, energy_backbone_with, EnergyBackboneOptions, EnergyGrid, CALM_STEPS,
    ESCAPE_AFTER, ESCAPE_PERIODS, MARGINAL_SHARE, SLOPE_COLLAPSE, SLOPE_MEMORY,
};
pub use escape::{EscapingArclength, StallEscape};
pub use field::{FieldEvaluator, FieldValue};
pub use level::{split_frequency, EnergyLevel};
pub use linear::{
    branch_seed, grazing_energy, grazing_energy_of, natural_frequencies, open_mode,
    rigid_body_modes, seed_from_mode, ContactState, LinearMode,
};
pub use parameter::{parameter_branch, ParameterSteps};
pub use point::{Backbone, BackbonePoint, PointStatus};
pub use signature::{
    contact_intervals, harmonic_energies, harmonic_energies_by_bar, subharmonic_share,
};
pub use start::{
    backbone_start, BackboneStart, FLOATING_AMPLITUDES, FLOATING_RATIOS, RIGID_AMPLITUDES,
    START_AMPLITUDES, START_RATIOS,
};
pub use subharmonic::{
    genuine_subharmonic_backbone, genuine_subharmonic_backbone_with, leave_subspace,
    symmetry_breaking_direction, GENUINE_SHARE, NUDGES,
};
pub use switch::SwitchAt;
