//! Linear modes of the system with every contact open or closed, the first grazing energy
//! `E_g`, and branch seeds.
//!
//! With every unilateral law replaced by a linear row (open: zero contact force; closed: zero
//! gap motion), one harmonic of angular frequency `omega` has a square matrix `D(omega)` in
//! the Helmholtz unknowns. Natural frequencies are the `omega` where it is singular; they are
//! located as minima of `sigma_min(D) / sigma_max(D)` on a scan of step `pi c / (200 l)` (which also finds double
//! roots, where `det D` does not change sign) and refined by golden-section search.

pub use crate::system::linear::{
    natural_frequencies, open_mode, rigid_body_modes, ContactState, LinearMode, MAX_SCAN,
};

use crate::error::{Error, SettingsError, SolveError};
use crate::fourier::{Basis, CosineBasis};
use crate::linalg::{DenseMatrix, Lu};
use crate::modal::energy::{energy_of, Conditions};
use crate::system::inputs::check_frequency_of;
use crate::system::rows::{dot, HarmonicRows};
use crate::system::{BarSystem, NonsmoothSystem};

/// Potential energy at maximum displacement of the motion `shape cos(omega t)`, its contacts
/// open: the unilateral conditions' stored energies are left out.
fn shape_energy(system: &BarSystem, omega: f64, shape: &[f64]) -> f64 {
    let basis = CosineBasis::new(1, 3).expect("valid basis");
    let mut x = vec![0.0; shape.len()];
    x.extend_from_slice(shape);
    energy_of(system, &basis, &x, (omega, 0.0), Conditions::Linear)
}

/// The first linear grazing energy `E_g` and the first open-contact mode: the least energy of
/// a motion in the first mode's eigenspace whose amplitude just closes a contact gap
/// (formulation §7). For a simple mode this is the mode scaled so that its first contact
/// grazes; `E_g = min_l g0_l^2 / (c_l^T Q^-1 c_l)` with `Q` the energy form and `c_l` the gap
/// motion of law `l` on the eigenspace.
///
/// Clamped bar: `pi^2 g0^2 / 16`; Robin bar `k_s = 0.5`: `0.185515 g0^2`.
///
/// # Errors
/// [`SettingsError::NoContact`], [`SettingsError::NoGrazing`] or a failed mode search;
/// [`SettingsError::GrazingEnergyOutOfRange`] if `E_g` is not a positive, finite, normal
/// number (gaps below about `1e-154` or above about `1e154` for unit bars: `g0^2` underflows
/// or overflows), naming the law that sets it.
pub fn grazing_energy(system: &BarSystem) -> Result<(f64, LinearMode), SettingsError> {
    if system.contact_count() == 0 {
        return Err(SettingsError::NoContact);
    }
    let mode = open_mode(system, 1)?;
    Ok((grazing_energy_of(system, &mode)?, mode))
}

/// The grazing energy of the linear mode `mode` (of the open-contact system): the least
/// energy of a motion in its eigenspace whose amplitude just closes a contact gap, as in
/// [`grazing_energy`], which is that of the first mode. The nonsmooth mode that emanates
/// from `mode` leaves the linear family at this energy.
///
/// # Errors
/// As [`grazing_energy`].
pub fn grazing_energy_of(system: &BarSystem, mode: &LinearMode) -> Result<f64, SettingsError> {
    if system.contact_count() == 0 {
        return Err(SettingsError::NoContact);
    }
    let d = mode.shapes.len();
    let e: Vec<f64> = mode
        .shapes
        .iter()
        .map(|s| shape_energy(system, mode.omega, s))
        .collect();
    let mut q = DenseMatrix::zeros(d, d);
    for i in 0..d {
        q[(i, i)] = e[i];
        for j in 0..i {
            let sum: Vec<f64> = mode.shapes[i]
                .iter()
                .zip(&mode.shapes[j])
                .map(|(a, b)| a + b)
                .collect();
            let qij = 0.5 * (shape_energy(system, mode.omega, &sum) - e[i] - e[j]);
            q[(i, j)] = qij;
            q[(j, i)] = qij;
        }
    }
    let lu = Lu::factor(&q, 1e-12).map_err(|_| SettingsError::NoGrazing { omega: mode.omega })?;
    let rows = HarmonicRows::new(system, mode.omega);
    // The least energy over the laws that the mode moves: (energy, law, gap).
    let mut best: Option<(f64, usize, f64)> = None;
    for (l, law) in system.laws().enumerate() {
        let g0 = law.gap().offset;
        let c: Vec<f64> = mode
            .shapes
            .iter()
            .map(|s| dot(rows.gap_row(l), s))
            .collect();
        let mut y = c.clone();
        lu.solve_in_place(&mut y);
        let ctqc = dot(&c, &y);
        if ctqc > 1e-300 {
            let energy = g0 * g0 / ctqc;
            if best.is_none_or(|(e, _, _)| energy < e) {
                best = Some((energy, l, g0));
            }
        }
    }
    match best {
        None => Err(SettingsError::NoGrazing { omega: mode.omega }),
        Some((energy, _, _)) if energy.is_normal() => Ok(energy),
        Some((energy, law, gap)) => {
            Err(SettingsError::GrazingEnergyOutOfRange { law, gap, energy })
        }
    }
}

/// The arguments of a seed that do not depend on the mode.
fn check_seed<B: Basis>(
    problem: &NonsmoothSystem<B>,
    subharmonic: usize,
    omega: f64,
) -> Result<(), Error> {
    if subharmonic == 0 {
        return Err(SettingsError::ZeroIndex {
            what: "subharmonic order",
            value: 0,
        }
        .into());
    }
    check_frequency_of(problem, omega)?;
    let harmonics = problem.basis().harmonics();
    if subharmonic > harmonics {
        return Err(SettingsError::HarmonicOutOfRange {
            subharmonic,
            harmonics,
        }
        .into());
    }
    Ok(())
}

/// A starting guess for the branch "NSM `mode` sub `subharmonic`" at fundamental frequency
/// `omega`: the open-contact linear mode `mode`, placed on harmonic `subharmonic` (its period
/// is `subharmonic` periods of the mode) and scaled so that its first contact just closes at
/// `t = 0`.
///
/// # Errors
/// [`SettingsError::ZeroIndex`] for `mode = 0` or `subharmonic = 0`,
/// [`SettingsError::HarmonicOutOfRange`] if the basis has fewer harmonics, or a failed mode
/// search.
pub fn branch_seed<B: Basis>(
    problem: &mut NonsmoothSystem<B>,
    mode: usize,
    subharmonic: usize,
    omega: f64,
) -> Result<Vec<f64>, Error> {
    check_seed(problem, subharmonic, omega)?;
    let linear = open_mode(problem.system(), mode)?;
    seed_checked(problem, &linear, subharmonic, omega)
}

/// [`branch_seed`] from a linear mode already at hand (the one [`grazing_energy`] returns, for
/// instance), without searching for it again.
///
/// # Errors
/// As [`branch_seed`]; [`SettingsError::NoGrazing`] for a mode without shape.
pub fn seed_from_mode<B: Basis>(
    problem: &mut NonsmoothSystem<B>,
    linear: &LinearMode,
    subharmonic: usize,
    omega: f64,
) -> Result<Vec<f64>, Error> {
    check_seed(problem, subharmonic, omega)?;
    seed_checked(problem, linear, subharmonic, omega)
}

/// [`seed_from_mode`] once `subharmonic` and `omega` have passed [`check_seed`].
fn seed_checked<B: Basis>(
    problem: &mut NonsmoothSystem<B>,
    linear: &LinearMode,
    subharmonic: usize,
    omega: f64,
) -> Result<Vec<f64>, Error> {
    let Some(shape) = linear.shapes.first() else {
        return Err(SettingsError::NoGrazing {
            omega: linear.omega,
        }
        .into());
    };
    let expected = problem.system().unknowns_per_harmonic();
    if shape.len() != expected {
        return Err(SolveError::Dimension {
            got: shape.len(),
            expected,
        }
        .into());
    }
    let laws: Vec<f64> = problem.system().laws().map(|l| l.gap().offset).collect();
    let rows = &problem.rows_at(omega)[subharmonic];
    let mut scale = f64::INFINITY;
    for (l, g0) in laws.iter().enumerate() {
        let delta = dot(rows.gap_row(l), shape);
        if delta.abs() > 1e-300 {
            let s = -g0 / delta;
            if s.abs() < scale.abs() {
                scale = s;
            }
        }
    }
    if !scale.is_finite() {
        return Err(SettingsError::NoGrazing {
            omega: linear.omega,
        }
        .into());
    }
    let mut x = vec![0.0; problem.dimension()];
    add_on_harmonic(problem, shape, subharmonic, scale, &mut x);
    Ok(x)
}

/// Adds `scale shape` (Helmholtz unknowns of one harmonic) to `x` on harmonic `harmonic`,
/// as the motion `scale shape` at `t = 0`.
///
/// # Panics
/// If the basis has no function of `harmonic` that is nonzero at `t = 0` or `shape` is
/// longer than the unknowns of one harmonic (callers check both).
pub(crate) fn add_on_harmonic<B: Basis>(
    problem: &NonsmoothSystem<B>,
    shape: &[f64],
    harmonic: usize,
    scale: f64,
    x: &mut [f64],
) {
    let basis = problem.basis();
    let mut phi = vec![0.0; basis.len()];
    basis.functions_at(0.0, &mut phi);
    let i = (0..basis.len())
        .find(|&i| basis.harmonic(i) == harmonic && phi[i] != 0.0)
        .expect("a basis has a function of each harmonic that is nonzero at t = 0");
    for (c, s) in shape.iter().enumerate() {
        x[problem.index(i, 0, 0) + c] += scale * s / phi[i];
    }
}
