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
use crate::fourier::{check_memory, frequency_of_period, Basis, SineCosineBasis};
use crate::modal::diagnostics::reserve_exact;
use crate::modal::{branch_seed, energy, grazing_energy, open_mode};
use crate::system::{BarSystem, HarmonicBalanceSettings, NonsmoothSystem, PhaseLocked};
use std::cell::RefCell;
use std::f64::consts::TAU;
use std::ops::ControlFlow;

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

/// The unknowns per coefficient of a state of `len` values in a basis of `blocks`
/// coefficients per unknown (`m + 1` cosine, `2 m + 1` full), with `blocks` given wide so
/// that it cannot overflow. A state holds at least one unknown: an empty one, or one whose
/// length is not a whole number of blocks, was written for another basis.
fn unknowns_per_coefficient(
    what: &'static str,
    len: usize,
    (harmonics, blocks): (usize, u128),
) -> Result<usize, SettingsError> {
    if harmonics == 0 {
        return Err(SettingsError::ZeroHarmonics);
    }
    let len_wide = len as u128;
    if len == 0 || len_wide % blocks != 0 {
        return Err(SettingsError::StateLayout {
            what,
            got: len,
            harmonics,
            coefficients: blocks,
        });
    }
    // `len_wide / blocks <= len`, which is a `usize`.
    Ok((len_wide / blocks) as usize)
}

/// The unknowns per coefficient of the full-basis state `x` of `harmonics` harmonics, its
/// values checked finite.
fn full_layout(x: &[f64], harmonics: usize) -> Result<usize, SettingsError> {
    let per = unknowns_per_coefficient(
        "full-basis state",
        x.len(),
        (harmonics, 2 * harmonics as u128 + 1),
    )?;
    check_finite(x)?;
    Ok(per)
}

/// [`SettingsError::NotFinite`] quoting the first value of `x` that is NaN or infinite.
fn check_finite(x: &[f64]) -> Result<(), SettingsError> {
    match x.iter().find(|v| !v.is_finite()) {
        Some(&value) => Err(SettingsError::NotFinite {
            what: "state coefficient",
            value,
        }),
        None => Ok(()),
    }
}

/// A vector of `per (2 to + 1)` zeros, the size checked against the memory budget first
/// (`to` may be any count: the product is taken in floating point) and the allocation
/// refused with a typed error rather than aborted.
fn full_zeros(per: usize, to: usize) -> Result<Vec<f64>, SettingsError> {
    let doubles = per as f64 * (2.0 * to as f64 + 1.0);
    check_memory("a full-basis state", doubles)?;
    // Within the budget, so within `usize`.
    let n = per * (2 * to + 1);
    let mut y = reserve_exact("a full-basis state", n)?;
    y.resize(n, 0.0);
    Ok(y)
}

/// A state of the cosine basis with `harmonics` harmonics as one of the full basis: the
/// cosine coefficients first, then zero sines (both layouts are coefficient-major).
///
/// # Errors
/// [`SettingsError::ZeroHarmonics`] for no harmonics; [`SettingsError::StateLayout`] when
/// `x` is empty or its length is not a multiple of `harmonics + 1`;
/// [`SettingsError::NotFinite`] for a value of `x` that is not finite;
/// [`SettingsError::TooLarge`] or [`SettingsError::AllocationFailed`] for a result beyond
/// the memory budget or refused by the allocator.
pub fn to_full_basis(x: &[f64], harmonics: usize) -> Result<Vec<f64>, SettingsError> {
    let per = unknowns_per_coefficient(
        "cosine-basis state",
        x.len(),
        (harmonics, harmonics as u128 + 1),
    )?;
    check_finite(x)?;
    let mut y = full_zeros(per, harmonics)?;
    y[..x.len()].copy_from_slice(x);
    Ok(y)
}

/// A full-basis state of `harmonics` harmonics written with `to >= harmonics` of them (the
/// added cosines and sines zero), as a start at more harmonics.
///
/// # Errors
/// As [`to_full_basis`] for `x` (its length a multiple of `2 harmonics + 1`) and the
/// result; [`SettingsError::LiftToFewerHarmonics`] for `to < harmonics`.
pub fn with_harmonics(x: &[f64], harmonics: usize, to: usize) -> Result<Vec<f64>, SettingsError> {
    let per = full_layout(x, harmonics)?;
    if to < harmonics {
        return Err(SettingsError::LiftToFewerHarmonics {
            from: harmonics,
            to,
        });
    }
    let mut y = full_zeros(per, to)?;
    // `x` holds `per (2 harmonics + 1)` values, so these products fit in `usize`.
    let (cosines, sines) = x.split_at(per * (harmonics + 1));
    y[..cosines.len()].copy_from_slice(cosines);
    let at = per * (to + 1);
    y[at..at + sines.len()].copy_from_slice(sines);
    Ok(y)
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

/// The coefficients `(c', s')` about `theta0` of `c cos(n theta) + s sin(n theta)`, from
/// `(sin, cos)` of `n theta0`.
fn rotate(c: f64, s: f64, (sin, cos): (f64, f64)) -> (f64, f64) {
    (c * cos + s * sin, s * cos - c * sin)
}

/// The sine share `|x_sin|^2 / |x|^2` of the state shifted to `theta0` (of the state itself
/// at `theta0 = 0`): every harmonic `n` of every signal,
/// `c cos(n theta) + s sin(n theta)`, has the sine `s cos(n theta0) - c sin(n theta0)` about
/// `theta0`. The values are divided by the largest first, so that the squares of a state
/// near the ends of the range of `f64` neither overflow nor underflow.
fn share_about(x: &[f64], harmonics: usize, theta0: f64) -> f64 {
    let per = x.len() / (2 * harmonics + 1);
    let scale = x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    if !(scale > 0.0 && scale.is_finite()) {
        return 0.0;
    }
    let (mut odd, mut all) = (0.0, 0.0);
    for n in 1..=harmonics {
        let turn = (n as f64 * theta0).sin_cos();
        for k in 0..per {
            let (c, s) = (x[n * per + k] / scale, x[(harmonics + n) * per + k] / scale);
            let (_, sine) = rotate(c, s, turn);
            odd += sine * sine;
            all += c * c + s * s;
        }
    }
    all += x[..per].iter().map(|v| (v / scale).powi(2)).sum::<f64>();
    if all > 0.0 {
        odd / all
    } else {
        0.0
    }
}

/// How far a full-basis state is from even in time about any instant: the smallest sine
/// share `|x_sin|^2 / |x|^2` over the shifts of its time origin ([`symmetry_instant`]).
///
/// # Errors
/// As [`symmetry_instant`].
pub fn asymmetry(x: &[f64], harmonics: usize) -> Result<f64, SettingsError> {
    Ok(symmetry_instant(x, harmonics)?.1)
}

/// The phase `theta0` about which a full-basis state is closest to even, and its sine share
/// about it.
///
/// A motion even about `theta0` is even about `theta0 + pi` too, so the search covers
/// `[0, pi)`: a scan of `8 m` instants (the share varies on the scale `pi / m` of the
/// highest harmonic), then a golden-section refinement around the best of them. Each
/// instant costs a pass over `x`: about `8 m x.len()` operations in all (`m` harmonics).
///
/// # Errors
/// [`SettingsError::ZeroHarmonics`] for no harmonics; [`SettingsError::StateLayout`] when
/// `x` is empty or its length is not a multiple of `2 harmonics + 1` (which also bounds the
/// scan by the length of `x`); [`SettingsError::NotFinite`] for a value of `x` that is not
/// finite.
pub fn symmetry_instant(x: &[f64], harmonics: usize) -> Result<(f64, f64), SettingsError> {
    full_layout(x, harmonics)?;
    Ok(symmetry_instant_of(x, harmonics))
}

/// [`symmetry_instant`] of a state whose layout is known to fit `harmonics`.
fn symmetry_instant_of(x: &[f64], harmonics: usize) -> (f64, f64) {
    let scan = 8 * harmonics;
    let h = std::f64::consts::PI / scan as f64;
    let share = |t: f64| share_about(x, harmonics, t);
    let best = (0..scan)
        .map(|k| (k as f64 * h, share(k as f64 * h)))
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map_or(0.0, |(t, _)| t);
    let (mut a, mut b) = (best - h, best + h);
    let ratio = (5f64.sqrt() - 1.0) / 2.0;
    for _ in 0..60 {
        let (c, d) = (b - ratio * (b - a), a + ratio * (b - a));
        if share(c) < share(d) {
            b = d;
        } else {
            a = c;
        }
    }
    [0.5 * (a + b), best]
        .map(|t| (t, share(t)))
        .into_iter()
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .unwrap_or((best, share(best)))
}

/// The full-basis state `x` with its time origin moved to `theta0`: every signal
/// `s(theta)` becomes `s(theta + theta0)`.
///
/// # Errors
/// As [`symmetry_instant`] for `x` and `harmonics`; [`SettingsError::NotFinite`] for a
/// `theta0` that is not finite, or for a shifted coefficient beyond `f64::MAX` (a cosine and
/// a sine both near it).
pub fn shift_origin(x: &[f64], harmonics: usize, theta0: f64) -> Result<Vec<f64>, SettingsError> {
    let per = full_layout(x, harmonics)?;
    if !theta0.is_finite() {
        return Err(SettingsError::NotFinite {
            what: "time origin theta0",
            value: theta0,
        });
    }
    // A phase of many turns is reduced to one, so that `n theta0` stays finite (its sine
    // would be NaN past the range of `f64`); within a turn it is used as given.
    let theta0 = if theta0.abs() <= TAU {
        theta0
    } else {
        theta0.rem_euclid(TAU)
    };
    let mut y = x.to_vec();
    for n in 1..=harmonics {
        let turn = (n as f64 * theta0).sin_cos();
        for k in 0..per {
            let (c, s) = (x[n * per + k], x[(harmonics + n) * per + k]);
            let (c, s) = rotate(c, s, turn);
            // The rotation keeps `|(c, s)|`, up to `sqrt 2` times the larger of the two: past
            // `f64::MAX`, the shifted state has no representation.
            if let Some(value) = [c, s].into_iter().find(|v| !v.is_finite()) {
                return Err(SettingsError::NotFinite {
                    what: "shifted coefficient (its rotation passes f64::MAX)",
                    value,
                });
            }
            (y[n * per + k], y[(harmonics + n) * per + k]) = (c, s);
        }
    }
    Ok(y)
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
