//! What a nonsmooth mode is: energy and its normalisation, linear and rigid-body modes of the
//! open-contact system and the seeds they give, fields and time histories of a motion, its
//! signature (harmonic content, contact intervals per period) and diagnostics, and whether an
//! assembly holds every bar. How branches of modes are found is [`crate::branches`].

mod character;
pub mod diagnostics;
pub(crate) mod drift;
pub mod energy;
pub mod field;
pub(crate) mod full_basis;
pub mod linear;
pub mod signature;

pub use crate::check::MIN_FREQUENCY;
pub use character::{character, label, nearest_mode, Character, Label, GRAZING_TOLERANCE};
pub use diagnostics::{diagnose, displacement_grid, end_history, law_history, PointDiagnostics};
pub use drift::{check_held, drifting_bars};
pub use energy::{energy, energy_at, energy_gradient};
pub use field::{FieldEvaluator, FieldValue};
pub use linear::{
    branch_seed, grazing_energy, grazing_energy_of, natural_frequencies, open_mode,
    rigid_body_modes, seed_from_mode, ContactState, LinearMode,
};
pub use signature::{
    contact_intervals, harmonic_energies, harmonic_energies_by_bar, subharmonic_share,
};
