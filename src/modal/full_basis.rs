//! States of the full Fourier basis: checks of their layout, the cosine state lifted into
//! it, more harmonics, and how far a state is from even in time. They only read
//! coefficients; [`crate::branches`] re-exports them beside the full-basis branch.

use crate::error::SettingsError;
use crate::fourier::check_memory;
use crate::modal::diagnostics::reserve_exact;
use std::f64::consts::TAU;

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
pub(crate) fn share_about(x: &[f64], harmonics: usize, theta0: f64) -> f64 {
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
pub(crate) fn symmetry_instant_of(x: &[f64], harmonics: usize) -> (f64, f64) {
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
