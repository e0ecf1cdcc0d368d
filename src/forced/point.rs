//! One point of a response curve, measured on the forced system.

use crate::continuation::{ContinuationProblem, Point};
use crate::forced::ForcedSystem;
use crate::status::PointStatus;

/// One point of a response curve.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct ResponsePoint {
    /// Step number.
    pub step: usize,
    /// Forcing frequency `Omega`.
    pub omega: f64,
    /// Largest closure of the first law's gap over the period divided by its gap at rest
    /// ([`ForcedSystem::amplitude`]).
    pub amplitude: f64,
    /// Mechanical energy averaged over the period ([`ForcedSystem::average_energy`]).
    pub energy: f64,
    /// `energy / E_g`, `E_g` the first grazing energy of the undamped system.
    pub energy_normalized: f64,
    /// `status == PointStatus::Converged`.
    pub converged: bool,
    /// Converged, solver failed, or a non-finite energy.
    pub status: PointStatus,
    /// How far the motion is from the contact laws between the samples
    /// ([`ForcedSystem::contact_defect`]).
    pub contact_defect: f64,
    /// Whether the curve turns back in frequency at this point (arclength runs): the extreme
    /// in frequency from which the curve comes back by more than a grid step of the request,
    /// along another branch than the one it came by.
    pub fold: bool,
    /// The harmonics the harmonic selection held at zero at this point
    /// ([`HarmonicBalanceSettings::resonance_band`](crate::system::HarmonicBalanceSettings::resonance_band); empty without it).
    pub dropped_harmonics: Vec<usize>,
    /// `|F|_2`.
    pub residual_norm: f64,
    /// Solver iterations.
    pub iterations: usize,
    /// The unknowns (layout of [`ForcedSystem`]).
    pub x: Vec<f64>,
}

/// `p`, step `step` of the curve, measured on `problem` (moved to its frequency).
pub(super) fn measured(
    problem: &mut ForcedSystem,
    step: usize,
    p: &Point,
    e_g: f64,
) -> ResponsePoint {
    problem.set_parameter(p.parameter);
    let energy = problem.average_energy(&p.x);
    let energy_normalized = energy / e_g;
    let status = match &p.error {
        Some(e) => PointStatus::SolverFailed(e.clone()),
        None if p.converged => PointStatus::Converged.with_energy(energy, energy_normalized),
        None => PointStatus::Rejected,
    };
    ResponsePoint {
        step,
        omega: p.parameter,
        amplitude: problem.amplitude(&p.x),
        energy,
        energy_normalized,
        converged: status == PointStatus::Converged,
        status,
        contact_defect: problem.contact_defect(&p.x),
        fold: false,
        dropped_harmonics: problem.dropped_harmonics(),
        residual_norm: p.residual_norm,
        iterations: p.iterations,
        x: p.x.clone(),
    }
}
