//! Backbones in the full Fourier basis: constant, cosines and sines, with a phase condition.
//!
//! The paper's cosine basis keeps only motions that are even in time. In the full basis
//! ([`SineCosineBasis`]) a branch is continued in the period on the [`PhaseLocked`] system,
//! whose phase reference moves to each accepted point. Every even solution of the cosine
//! basis is one of the full basis (its sines solve to zero), so a branch started from a
//! cosine point ([`to_full_basis`]) reproduces the cosine backbone; a start with sines
//! follows motions the cosine basis cannot hold. [`FullBasisPoint::asymmetry`] tells the
//! two apart.

use crate::branches::backbone::Taken;
use crate::branches::point::{BackbonePoint, PointStatus, Timescale};
use crate::branches::request::Request;
use crate::branches::result::Annotator;
use crate::continuation::{
    EndReason, PeriodParametrised, Rejection, Sequential, SequentialOptions, Step,
};
use crate::error::{Error, SettingsError};
use crate::fourier::{frequency_of_period, Basis, SineCosineBasis};
use crate::modal::full_basis::share_about;
use crate::modal::full_basis::symmetry_instant_of;
use crate::modal::{branch_seed, energy, grazing_energy, open_mode};
use crate::system::{BarSystem, HarmonicBalanceSettings, NonsmoothSystem, PhaseLocked};
use std::cell::RefCell;
use std::ops::ControlFlow;

pub use crate::modal::full_basis::{
    asymmetry, shift_origin, symmetry_instant, to_full_basis, with_harmonics,
};

/// Energies below this fraction of `E_g` are the state of rest, which is no point of a
/// backbone (it solves the equations at every period).
const REST: f64 = 1e-6;

/// One converged point of a branch in the full basis: the point as every backbone reports it
/// (its unknowns in the layout of [`NonsmoothSystem`] with a [`SineCosineBasis`]; its
/// energy at `t = 0`, kinetic and potential, since with sines velocities need not vanish
/// there; its character, label and time-domain check where the request asks), and how far
/// the motion is from even in time.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct FullBasisPoint {
    /// The point, annotated as [`compute`](crate::branches::compute) annotates its points.
    pub point: BackbonePoint,
    /// The unfolding unknown `mu` of the phase-locked system: of the order of the solver's
    /// tolerance on a solution of the harmonic balance itself.
    pub unfolding: f64,
    /// The share of the sines in the state, `|x_sin|^2 / |x|^2`: 0 for a motion even in
    /// time about `t = 0`.
    pub sine_share: f64,
    /// How far the motion is from even in time about any instant: the smallest share of
    /// the sines over the time shifts of the state ([`asymmetry`]). 0 for an even motion,
    /// whatever its phase; a motion the cosine basis cannot hold has it well above the
    /// rounding level.
    pub asymmetry: f64,
}

/// A branch in the full basis: its converged points and why it ended.
#[derive(Debug, Clone, PartialEq)]
pub struct FullBasisBranch {
    /// The converged points, in the order of the grid.
    pub points: Vec<FullBasisPoint>,
    /// The steps that did not join the branch (the solver failed, or reached the state of
    /// rest), with their periods and reasons.
    pub rejected: Vec<Rejection>,
    /// Why the run ended.
    pub end: EndReason,
}

/// The harmonic-balance system of `system` in the full basis with `settings`' harmonics,
/// samples, complementarity parameter and kink blend (the harmonic selection of
/// [`HarmonicBalanceSettings::resonance_band`] is a cosine-basis setting and is not used).
///
/// # Errors
/// As [`SineCosineBasis::new`] and [`NonsmoothSystem::with_basis`].
pub fn full_basis_system(
    system: &BarSystem,
    settings: &HarmonicBalanceSettings,
) -> Result<NonsmoothSystem<SineCosineBasis>, Error> {
    let basis = SineCosineBasis::new(settings.harmonics, settings.samples_per_harmonic)?;
    let mut problem = NonsmoothSystem::with_basis(system, basis, settings.complementarity)?;
    problem.set_kink_blend(settings.kink_blend)?;
    Ok(problem)
}

/// A start for motions that are not even in time: the grazing seed of the first linear
/// mode on harmonic 1 (a cosine, [`branch_seed`]) plus `ratio` times that of linear mode
/// `mode` on the sine of the harmonic `n` nearest its frequency (`n Omega ~ omega_mode`):
/// two modes in quadrature, at the fundamental frequency `omega`. Returns the start and `n`.
///
/// # Errors
/// As [`branch_seed`] and [`open_mode`]; [`SettingsError::HarmonicOutOfRange`] when `n` is
/// 0 or beyond the basis; [`SettingsError::NotFinite`] for a `ratio` that is not finite, and
/// [`SettingsError::NonFiniteResult`] for one so large that the start overflows.
pub fn quadrature_start(
    problem: &mut NonsmoothSystem<SineCosineBasis>,
    mode: usize,
    ratio: f64,
    omega: f64,
) -> Result<(Vec<f64>, usize), Error> {
    if !ratio.is_finite() {
        return Err(SettingsError::NotFinite {
            what: "quadrature ratio",
            value: ratio,
        }
        .into());
    }
    let m = problem.basis().harmonics();
    let n = (open_mode(problem.system(), mode)?.omega / omega).round();
    if !(n >= 1.0 && n <= m as f64) {
        return Err(SettingsError::HarmonicOutOfRange {
            subharmonic: if n.is_finite() && n >= 0.0 {
                n as usize
            } else {
                0
            },
            harmonics: m,
        }
        .into());
    }
    let n = n as usize;
    let mut start = branch_seed(problem, 1, 1, omega)?;
    let other = branch_seed(problem, mode, n, omega)?;
    let per = other.len() / (2 * m + 1);
    let (cosine, sine) = (n * per, (m + n) * per);
    for k in 0..per {
        start[sine + k] += ratio * other[cosine + k];
    }
    // A finite ratio so large that the sum overflows starts nothing.
    if start.iter().any(|v| !v.is_finite()) {
        return Err(SettingsError::NonFiniteResult {
            what: "quadrature start",
            omega,
        }
        .into());
    }
    Ok((start, n))
}

/// Continues a branch of `system` in the full basis over `periods`, natural-parameter, from
/// `start` (a full-basis state near the branch at `periods[0]`: [`to_full_basis`] of a
/// cosine point, or a state with sines). The phase is locked to the start, then to each
/// accepted point. Points at rest (`E < 1e-6 E_g`) or with an energy that is not finite are
/// rejected.
///
/// `request` gives the harmonic-balance settings, the solver (full semismooth Newton when
/// it names none) and what each converged point gets, as in
/// [`compute`](crate::branches::compute): its character and label, the time-domain check
/// of [`Request::check`] and the multipliers of [`Request::stability`]. Its method is not
/// used: the periods are the grid. The harmonic selection of
/// [`HarmonicBalanceSettings::resonance_band`] is a cosine-basis setting and is not used.
///
/// # Errors
/// Bad settings, a system without contact, a start of the wrong length or one that does not
/// move ([`PhaseLocked::new`]), an invalid grid ([`Sequential::new`]). A run that stops
/// part-way returns its points and [`FullBasisBranch::end`].
pub fn full_basis_branch(
    system: &BarSystem,
    request: &Request,
    start: &[f64],
    periods: Vec<f64>,
) -> Result<FullBasisBranch, Error> {
    let inner = full_basis_system(system, &request.settings)?;
    let harmonics = inner.basis().harmonics();
    let first = periods.first().copied().unwrap_or(f64::NAN);
    let observer = |_: &BackbonePoint| ControlFlow::Continue(());
    let mut annotator = Annotator::new(inner.clone(), request, observer);
    let locked = PhaseLocked::new(inner, start, frequency_of_period(first))?;
    let (e_g, _) = grazing_energy(system)?;
    let basis = locked.inner().basis().clone();
    let n = locked.inner().dimension();
    // The acceptance test computes each converged point's energy; the accepted point reuses
    // it. The state of rest, or an energy beyond the range of numbers, is no point of a
    // branch.
    let taken = RefCell::new(Taken::default());
    let in_motion = |y: &[f64], period: f64| {
        let time = Timescale::of_period(period);
        let e = energy(system, &basis, &y[..n], time.omega);
        taken.borrow_mut().keep(y, time, e);
        e.is_finite() && e >= REST * e_g
    };
    let solver = request.solver.unwrap_or_default();
    let mut driver = Sequential::new(
        PeriodParametrised::new(locked),
        solver,
        PhaseLocked::lift(start),
        periods,
        SequentialOptions::default(),
    )?
    // `in_motion` decides what counts as rest.
    .with_rest_accepted()
    .with_acceptance(in_motion);
    let (mut measures, mut rejected) = (Vec::new(), Vec::new());
    let end = loop {
        match driver.step() {
            Step::Accepted(p) => {
                let known = taken.borrow().time_and_energy(&p.x, p.parameter);
                let (time, e) = known.unwrap_or_else(|| {
                    let time = Timescale::of_period(p.parameter);
                    (time, energy(system, &basis, &p.x[..n], time.omega))
                });
                let x = &p.x[..n];
                // The accepted point moves, or it would have been at rest.
                let _ = driver
                    .problem_mut()
                    .inner_mut()
                    .set_reference(x, time.omega);
                measures.push((
                    PhaseLocked::unfolding(&p.x),
                    share_about(x, harmonics, 0.0),
                    symmetry_instant_of(x, harmonics).1,
                ));
                let point = BackbonePoint::from_parts(&p, (x, time), e, e_g, PointStatus::of(&p));
                let _ = annotator.point(point);
            }
            Step::Rejected(r) => rejected.push(r),
            Step::Finished(end) => break end,
        }
    };
    let points = (annotator.into_points().into_iter().zip(measures))
        .map(
            |(point, (unfolding, sine_share, asymmetry))| FullBasisPoint {
                point,
                unfolding,
                sine_share,
                asymmetry,
            },
        )
        .collect();
    Ok(FullBasisBranch {
        points,
        rejected,
        end,
    })
}
