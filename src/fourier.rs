//! Harmonic bases: time grid, synthesis, projection, and the weighted Gram matrix that makes
//! the generalised Jacobian cheap.
//!
//! The system never touches trigonometric tables directly: everything in time goes through a
//! [`Basis`]. [`CosineBasis`] is the paper's constant + cosine basis; a sine + cosine basis
//! (odd motions, with a phase condition) fits the same trait.

use crate::error::SettingsError;
use std::f64::consts::PI;
use std::fmt::Debug;

/// A finite real basis of `2 pi`-periodic functions `phi_i(theta)`, with a grid of `N`
/// equispaced samples `theta_k = 2 pi k / N` on which residuals are projected (Riemann sum).
pub trait Basis: Debug + Clone + Send + Sync {
    /// Number of coefficients of one signal.
    fn len(&self) -> usize;

    /// Whether the basis is empty (never, for a validated basis).
    fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Highest harmonic number `m`.
    fn harmonics(&self) -> usize;

    /// Harmonic number of coefficient `i` (0 for the constant).
    fn harmonic(&self, i: usize) -> usize;

    /// Number of time samples `N` per period.
    fn samples(&self) -> usize;

    /// `phi_i(theta)` for every `i`, written into `out` (length `len()`).
    fn functions_at(&self, theta: f64, out: &mut [f64]);

    /// `d phi_i / d theta` for every `i`, written into `out`.
    fn derivatives_at(&self, theta: f64, out: &mut [f64]);

    /// `s_k = sum_i c_i phi_i(theta_k)` for `k = 0..N`.
    fn synthesize(&self, coefficients: &[f64], samples: &mut [f64]);

    /// The Galerkin projection `R_j = (2/N) sum_k psi_j(theta_k) r_k`, where `psi_j` is the
    /// test function of coefficient `j` (for the cosine basis `psi_j = cos(j theta)`).
    fn project(&self, samples: &[f64], coefficients: &mut [f64]);

    /// `G[j][i] = (2/N) sum_k psi_j(theta_k) w_k phi_i(theta_k)`, row-major `len x len`: the
    /// projection of `w * phi_i`, i.e. the Jacobian block of a pointwise law with weight `w`.
    fn weighted_gram(&self, weights: &[f64], gram: &mut [f64]);
}

/// Constant + cosine basis: `s(theta) = c_0 / 2 + sum_{n=1..m} c_n cos(n theta)`
/// (formulation §4). Time-even motions only; the phase is fixed by symmetry.
///
/// Samples: `N = n_h m` per period (`n_h >= 3`, so that `2m < N` and the discrete products of
/// two cosines are exactly orthogonal).
#[derive(Debug, Clone, PartialEq)]
pub struct CosineBasis {
    harmonics: usize,
    samples: usize,
    /// `cos(2 pi q / N)` for `q = 0..N`: every `cos(n theta_k)` is an entry of it.
    table: Vec<f64>,
}

impl CosineBasis {
    /// `m` harmonics and `n_h` samples per harmonic.
    ///
    /// # Errors
    /// [`SettingsError::ZeroHarmonics`] if `m = 0`; [`SettingsError::TooFewSamples`] if
    /// `n_h < 3`.
    pub fn new(harmonics: usize, samples_per_harmonic: usize) -> Result<Self, SettingsError> {
        if harmonics == 0 {
            return Err(SettingsError::ZeroHarmonics);
        }
        if samples_per_harmonic < 3 {
            return Err(SettingsError::TooFewSamples {
                got: samples_per_harmonic,
                min: 3,
            });
        }
        let n = harmonics * samples_per_harmonic;
        let table = (0..n).map(|q| (2.0 * PI * q as f64 / n as f64).cos()).collect();
        Ok(Self {
            harmonics,
            samples: n,
            table,
        })
    }

    /// `(2/N) sum_k w_k cos(l theta_k)` for `l = 0..=2m`.
    fn cosine_moments(&self, weights: &[f64], out: &mut [f64]) {
        let n = self.samples;
        let scale = 2.0 / n as f64;
        for (l, o) in out.iter_mut().enumerate() {
            let mut q = 0;
            let mut acc = 0.0;
            for &w in weights {
                acc += w * self.table[q];
                q += l;
                if q >= n {
                    q -= n;
                }
            }
            *o = scale * acc;
        }
    }
}

/// Weight of coefficient `i` in the synthesis: `1/2` for the constant term, 1 otherwise.
fn constant_half(i: usize) -> f64 {
    if i == 0 {
        0.5
    } else {
        1.0
    }
}

impl Basis for CosineBasis {
    fn len(&self) -> usize {
        self.harmonics + 1
    }
    fn harmonics(&self) -> usize {
        self.harmonics
    }
    fn harmonic(&self, i: usize) -> usize {
        i
    }
    fn samples(&self) -> usize {
        self.samples
    }
    fn functions_at(&self, theta: f64, out: &mut [f64]) {
        for (i, o) in out.iter_mut().enumerate() {
            *o = constant_half(i) * (i as f64 * theta).cos();
        }
    }
    fn derivatives_at(&self, theta: f64, out: &mut [f64]) {
        for (i, o) in out.iter_mut().enumerate() {
            *o = -(i as f64) * (i as f64 * theta).sin();
        }
    }
    fn synthesize(&self, coefficients: &[f64], samples: &mut [f64]) {
        let n = self.samples;
        samples.fill(0.5 * coefficients[0]);
        for (i, &c) in coefficients.iter().enumerate().skip(1) {
            if c == 0.0 {
                continue;
            }
            let mut q = 0;
            for s in samples.iter_mut() {
                *s += c * self.table[q];
                q += i;
                if q >= n {
                    q -= n;
                }
            }
        }
    }
    fn project(&self, samples: &[f64], coefficients: &mut [f64]) {
        self.cosine_moments(samples, coefficients);
    }
    fn weighted_gram(&self, weights: &[f64], gram: &mut [f64]) {
        let len = self.len();
        let mut sigma = vec![0.0; 2 * self.harmonics + 1];
        self.cosine_moments(weights, &mut sigma);
        // (2/N) sum w cos(j t) cos(i t) = (sigma_|j-i| + sigma_(j+i)) / 2: Toeplitz + Hankel.
        for j in 0..len {
            for i in 0..len {
                gram[j * len + i] = constant_half(i) * 0.5 * (sigma[j.abs_diff(i)] + sigma[j + i]);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn synthesis_then_projection_is_identity() {
        let b = CosineBasis::new(5, 4).unwrap();
        let c = [0.3, -1.0, 0.5, 0.0, 2.0, -0.25];
        let mut s = vec![0.0; b.samples()];
        b.synthesize(&c, &mut s);
        let mut back = [0.0; 6];
        b.project(&s, &mut back);
        for (x, y) in c.iter().zip(back) {
            assert!((x - y).abs() < 1e-13);
        }
    }

    #[test]
    fn gram_matches_direct_sum() {
        let b = CosineBasis::new(4, 3).unwrap();
        let n = b.samples();
        let w: Vec<f64> = (0..n).map(|k| ((k * 7) % 5) as f64 - 1.5).collect();
        let mut g = vec![0.0; 25];
        b.weighted_gram(&w, &mut g);
        let mut phi = [0.0; 5];
        for j in 0..5 {
            for i in 0..5 {
                let mut acc = 0.0;
                for (k, wk) in w.iter().enumerate() {
                    let t = 2.0 * PI * k as f64 / n as f64;
                    b.functions_at(t, &mut phi);
                    acc += (j as f64 * t).cos() * wk * phi[i];
                }
                assert!((g[j * 5 + i] - 2.0 / n as f64 * acc).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn rejects_bad_settings() {
        assert_eq!(CosineBasis::new(0, 30), Err(SettingsError::ZeroHarmonics));
        assert!(matches!(
            CosineBasis::new(3, 2),
            Err(SettingsError::TooFewSamples { got: 2, min: 3 })
        ));
    }
}
