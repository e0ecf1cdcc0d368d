//! From bars and conditions to the harmonic-balance equations.
//!
//! - [`assembly`]: the builder and the validated [`BarSystem`].
//! - [`family`]: continuation in any scalar parameter of the system.
//! - [`Layout`]: where each unknown lives.
//! - [`rows`]: per-harmonic linear rows and observables in the Helmholtz unknowns `(A, B)`.
//! - [`problem`]: the square nonsmooth system `F(x; Omega) = 0`, its generalised Jacobian and
//!   `dF/dOmega`.

pub mod assembly;
mod condense;
pub mod family;
pub(crate) mod inputs;
mod layout;
pub(crate) mod linear;
mod phase;
pub(crate) use phase::shift_of;
pub mod problem;
pub mod rows;
pub(crate) mod spectra;

pub use assembly::{AssemblyBuilder, BarSystem};
pub use family::{ParameterFamily, SystemFamily};
pub use layout::Layout;
pub use phase::PhaseLocked;
pub use problem::{
    Discretization, HarmonicBalanceSettings, NonsmoothSystem, COMPLEMENTARITY_RANGE, MAX_OFFSET,
    MAX_PHASE, RESONANCE_BAND, REST_AMPLITUDE,
};
