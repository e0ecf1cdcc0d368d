//! The full Fourier basis: constant, cosines and sines, for motions that are not even in time.

use super::{checked_samples, constant_half, with_buffers, Basis};
use crate::error::SettingsError;
use num_complex::Complex;
use realfft::{ComplexToReal, RealFftPlanner, RealToComplex};
use std::cell::Cell;
use std::fmt::Debug;
use std::sync::Arc;

/// Constant + cosine + sine basis:
/// `s(theta) = c_0 / 2 + sum_{n=1..m} (c_n cos(n theta) + s_n sin(n theta))`, coefficients
/// ordered `(c_0, c_1, .., c_m, s_1, .., s_m)`.
///
/// The cosine coefficients come first, so a [`CosineBasis`](super::CosineBasis) vector
/// (`m + 1` values per signal) is the leading part of one of this basis with zero sines.
/// Test functions are the basis functions without the constant's `1/2`:
/// `R_j = (2/N) sum_k psi_j(theta_k) r_k` with `psi_j = cos(j theta)` or `sin(j theta)`.
///
/// The basis has no symmetry on the grid, so its folded methods are the full ones
/// (`S = N`). Every transform is one real FFT of size `N = n_h m`: a synthesis is the
/// inverse transform of the half spectrum `X_n = (c_n - i s_n) / 2`, a projection reads
/// `(2/N) (Re Y_j, -Im Y_j)` from the forward transform `Y` of the samples, and the weighted
/// Gram matrix is filled from the moments `sigma_l = (2/N) sum_k w_k cos(l theta_k)` and
/// `tau_l = (2/N) sum_k w_k sin(l theta_k)`, `l = 0..2m`, by the product formulas
///
/// ```text
/// cos j cos i = (cos(j-i) + cos(j+i)) / 2     sin j sin i = (cos(j-i) - cos(j+i)) / 2
/// sin j cos i = (sin(j+i) + sin(j-i)) / 2     cos j sin i = (sin(i+j) + sin(i-j)) / 2
/// ```
///
/// A basis with sines is invariant under time shifts, which the cosine basis removes by
/// symmetry: a problem in it needs a phase condition ([`crate::system::PhaseLocked`]).
#[derive(Clone)]
pub struct SineCosineBasis {
    harmonics: usize,
    samples: usize,
    forward: Arc<dyn RealToComplex<f64>>,
    inverse: Arc<dyn ComplexToReal<f64>>,
}

impl Debug for SineCosineBasis {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SineCosineBasis")
            .field("harmonics", &self.harmonics)
            .field("samples", &self.samples)
            .finish_non_exhaustive()
    }
}

/// Two bases are equal when they have the same harmonics and samples (the FFT plans follow).
impl PartialEq for SineCosineBasis {
    fn eq(&self, other: &Self) -> bool {
        self.harmonics == other.harmonics && self.samples == other.samples
    }
}

impl SineCosineBasis {
    /// `m` harmonics and `n_h` samples per harmonic (`N = n_h m` samples).
    ///
    /// The basis implies a Gram matrix of `(2m + 1)^2` doubles for each pointwise law and
    /// about 16 doubles per time sample; together they must fit in
    /// [`MEMORY_BUDGET_BYTES`](super::MEMORY_BUDGET_BYTES).
    ///
    /// # Errors
    /// [`SettingsError::ZeroHarmonics`] if `m = 0`; [`SettingsError::TooFewSamples`] if
    /// `n_h < 3` (the discrete products of two harmonics are orthogonal only for `2m < N`);
    /// [`SettingsError::TooLarge`] if the basis does not fit in the budget.
    pub fn new(harmonics: usize, samples_per_harmonic: usize) -> Result<Self, SettingsError> {
        let what = "a sine-cosine basis (its Gram matrix, tables and FFT buffers)";
        let n = checked_samples(
            what,
            harmonics,
            samples_per_harmonic,
            2.0 * harmonics as f64 + 1.0,
        )?;
        let mut planner = RealFftPlanner::<f64>::new();
        Ok(Self {
            harmonics,
            samples: n,
            forward: planner.plan_fft_forward(n),
            inverse: planner.plan_fft_inverse(n),
        })
    }

    /// The length contract of a slice of coefficients.
    fn assert_coefficients(&self, len: usize) {
        assert_eq!(len, self.len(), "one value per coefficient");
    }

    /// The length contract of a period of samples.
    fn assert_samples(&self, len: usize) {
        assert_eq!(len, self.samples, "one period of samples");
    }

    /// The forward transform `Y_l = sum_k x_k exp(-i l theta_k)`, `l = 0..=N/2`, scaled by
    /// `2/N` into `buffers.spectrum`: `(sigma_l, -tau_l)` of the moments of `x`.
    fn scaled_spectrum(&self, x: &[f64], buffers: &mut Buffers) {
        let Buffers {
            real,
            spectrum,
            fft,
        } = buffers;
        real.clear();
        real.extend_from_slice(x);
        spectrum.resize(self.samples / 2 + 1, Complex::default());
        fft.resize(self.forward.get_scratch_len(), Complex::default());
        self.forward
            .process_with_scratch(real, spectrum, fft)
            .expect("buffers sized by the plan");
        let scale = 2.0 / self.samples as f64;
        spectrum.iter_mut().for_each(|y| *y *= scale);
    }

    /// The moment `(sigma_l, tau_l)`, `|l| <= 2m`, from the scaled spectrum (above `N/2`,
    /// `Y_l = conj(Y_(N-l))`; `tau_(-l) = -tau_l`).
    fn moment(&self, spectrum: &[Complex<f64>], l: isize) -> (f64, f64) {
        let n = self.samples;
        let sign = l.signum() as f64;
        let l = l.unsigned_abs() % n;
        let (sigma, tau) = if l <= n / 2 {
            (spectrum[l].re, -spectrum[l].im)
        } else {
            (spectrum[n - l].re, spectrum[n - l].im)
        };
        (sigma, sign * tau)
    }
}

/// Reused buffers of the transforms: a period of samples, a half spectrum and the FFT's
/// scratch.
#[derive(Default)]
struct Buffers {
    real: Vec<f64>,
    spectrum: Vec<Complex<f64>>,
    fft: Vec<Complex<f64>>,
}

thread_local! {
    static BUFFERS: Cell<Buffers> = Cell::new(Buffers::default());
}

impl SineCosineBasis {
    /// The partner of coefficient `i` (the sine of a cosine, the cosine of a sine) with the
    /// sign `sigma` its term takes in a row that couples them (`+1` on a cosine's row, `-1`
    /// on a sine's); `None` for the constant.
    pub(crate) fn partner(&self, i: usize) -> Option<(usize, f64)> {
        let m = self.harmonics;
        match i {
            0 => None,
            i if i <= m => Some((m + i, 1.0)),
            i => Some((i - m, -1.0)),
        }
    }
}

impl Basis for SineCosineBasis {
    fn len(&self) -> usize {
        2 * self.harmonics + 1
    }
    fn harmonics(&self) -> usize {
        self.harmonics
    }
    fn harmonic(&self, i: usize) -> usize {
        if i <= self.harmonics {
            i
        } else {
            i - self.harmonics
        }
    }
    fn samples(&self) -> usize {
        self.samples
    }
    fn functions_at(&self, theta: f64, out: &mut [f64]) {
        self.assert_coefficients(out.len());
        let m = self.harmonics;
        let (cosines, sines) = out.split_at_mut(m + 1);
        for (i, o) in cosines.iter_mut().enumerate() {
            *o = constant_half(i) * (i as f64 * theta).cos();
        }
        for (i, o) in sines.iter_mut().enumerate() {
            *o = ((i + 1) as f64 * theta).sin();
        }
    }
    fn derivatives_at(&self, theta: f64, out: &mut [f64]) {
        self.assert_coefficients(out.len());
        let m = self.harmonics;
        let (cosines, sines) = out.split_at_mut(m + 1);
        for (i, o) in cosines.iter_mut().enumerate() {
            *o = -(i as f64) * (i as f64 * theta).sin();
        }
        for (i, o) in sines.iter_mut().enumerate() {
            let n = (i + 1) as f64;
            *o = n * (n * theta).cos();
        }
    }
    fn synthesize(&self, coefficients: &[f64], samples: &mut [f64]) {
        self.assert_coefficients(coefficients.len());
        self.assert_samples(samples.len());
        let m = self.harmonics;
        with_buffers(&BUFFERS, |b| {
            let Buffers { spectrum, fft, .. } = b;
            spectrum.clear();
            spectrum.resize(self.samples / 2 + 1, Complex::default());
            spectrum[0] = Complex::new(0.5 * coefficients[0], 0.0);
            for n in 1..=m {
                spectrum[n] = Complex::new(0.5 * coefficients[n], -0.5 * coefficients[m + n]);
            }
            fft.resize(self.inverse.get_scratch_len(), Complex::default());
            // `x_k = sum_n X_n exp(i n theta_k)` over the whole spectrum: the Hermitian half
            // counts twice, which the halves above undo.
            self.inverse
                .process_with_scratch(spectrum, samples, fft)
                .expect("a half spectrum with real ends (2m < N)");
        });
    }
    fn project(&self, samples: &[f64], coefficients: &mut [f64]) {
        self.assert_samples(samples.len());
        self.assert_coefficients(coefficients.len());
        let m = self.harmonics;
        with_buffers(&BUFFERS, |b| {
            self.scaled_spectrum(samples, b);
            let (cosines, sines) = coefficients.split_at_mut(m + 1);
            for (c, y) in cosines.iter_mut().zip(&b.spectrum) {
                *c = y.re;
            }
            for (s, y) in sines.iter_mut().zip(&b.spectrum[1..]) {
                *s = -y.im;
            }
        });
    }
    fn weighted_gram(&self, weights: &[f64], gram: &mut [f64]) {
        self.assert_samples(weights.len());
        let len = self.len();
        assert_eq!(gram.len(), len * len, "a square matrix of coefficients");
        let m = self.harmonics as isize;
        with_buffers(&BUFFERS, |b| {
            self.scaled_spectrum(weights, b);
            let sigma = |l: isize| self.moment(&b.spectrum, l).0;
            let tau = |l: isize| self.moment(&b.spectrum, l).1;
            // (sine?, harmonic) of coefficient i.
            let kind = |i: usize| {
                let i = i as isize;
                if i <= m {
                    (false, i)
                } else {
                    (true, i - m)
                }
            };
            for (j, row) in gram.chunks_exact_mut(len).enumerate() {
                let (test_sine, a) = kind(j);
                for (i, g) in row.iter_mut().enumerate() {
                    let (sine, b) = kind(i);
                    let value = match (test_sine, sine) {
                        (false, false) => 0.5 * (sigma(a - b) + sigma(a + b)),
                        (true, true) => 0.5 * (sigma(a - b) - sigma(a + b)),
                        (true, false) => 0.5 * (tau(a + b) + tau(a - b)),
                        (false, true) => 0.5 * (tau(b + a) + tau(b - a)),
                    };
                    *g = constant_half(i) * value;
                }
            }
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fourier::CosineBasis;
    use std::f64::consts::PI;

    /// `(m, n_h)`: odd and even `N`, `n_h = 3` (moments alias above `N/2`).
    const SIZES: [(usize, usize); 6] = [(1, 3), (2, 4), (5, 3), (7, 3), (8, 4), (20, 30)];

    /// A fixed-seed sequence in `[-1, 1)`.
    fn values(seed: u64, n: usize) -> Vec<f64> {
        let mut state = seed;
        (0..n)
            .map(|_| {
                state = state
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                (state >> 11) as f64 / (1u64 << 52) as f64 - 1.0
            })
            .collect()
    }

    fn theta(b: &SineCosineBasis, k: usize) -> f64 {
        2.0 * PI * k as f64 / b.samples() as f64
    }

    /// The test function of coefficient `j`.
    fn psi(b: &SineCosineBasis, j: usize, t: f64) -> f64 {
        let m = b.harmonics();
        if j <= m {
            (j as f64 * t).cos()
        } else {
            ((j - m) as f64 * t).sin()
        }
    }

    fn close(a: &[f64], b: &[f64], tolerance: f64, what: &str) {
        assert_eq!(a.len(), b.len());
        for (k, (x, y)) in a.iter().zip(b).enumerate() {
            assert!((x - y).abs() <= tolerance, "{what}[{k}]: {x} vs {y}");
        }
    }

    #[test]
    fn transforms_match_direct_sums() {
        for (seed, (m, nh)) in SIZES.into_iter().enumerate() {
            let b = SineCosineBasis::new(m, nh).unwrap();
            let (n, len) = (b.samples(), b.len());
            let c = values(seed as u64, len);
            let mut fast = vec![f64::NAN; n];
            b.synthesize(&c, &mut fast);
            let mut phi = vec![0.0; len];
            let direct: Vec<f64> = (0..n)
                .map(|k| {
                    b.functions_at(theta(&b, k), &mut phi);
                    phi.iter().zip(&c).map(|(p, c)| p * c).sum()
                })
                .collect();
            close(&fast, &direct, 1e-12 * len as f64, "synthesis");

            let r = values(100 + seed as u64, n);
            let mut projected = vec![f64::NAN; len];
            b.project(&r, &mut projected);
            let direct: Vec<f64> = (0..len)
                .map(|j| {
                    let sum: f64 = (0..n).map(|k| psi(&b, j, theta(&b, k)) * r[k]).sum();
                    2.0 / n as f64 * sum
                })
                .collect();
            close(&projected, &direct, 1e-12, "projection");

            let mut gram = vec![f64::NAN; len * len];
            b.weighted_gram(&r, &mut gram);
            for j in 0..len {
                for i in 0..len {
                    let sum: f64 = (0..n)
                        .map(|k| {
                            let t = theta(&b, k);
                            b.functions_at(t, &mut phi);
                            psi(&b, j, t) * r[k] * phi[i]
                        })
                        .sum();
                    let direct = 2.0 / n as f64 * sum;
                    let fast = gram[j * len + i];
                    assert!(
                        (fast - direct).abs() <= 1e-12,
                        "gram[{j}][{i}]: {fast} vs {direct}"
                    );
                }
            }
        }
    }

    /// Projection inverts synthesis, and a unit weight's Gram matrix is the identity.
    #[test]
    fn synthesis_then_projection_is_identity() {
        for (seed, (m, nh)) in SIZES.into_iter().enumerate() {
            let b = SineCosineBasis::new(m, nh).unwrap();
            let c = values(7 + seed as u64, b.len());
            let mut s = vec![0.0; b.samples()];
            b.synthesize(&c, &mut s);
            let mut back = vec![0.0; b.len()];
            b.project(&s, &mut back);
            close(&back, &c, 1e-13, "round trip");
            let mut gram = vec![0.0; b.len() * b.len()];
            b.weighted_gram(&vec![1.0; b.samples()], &mut gram);
            for j in 0..b.len() {
                for i in 0..b.len() {
                    let expected = if i == j { 1.0 } else { 0.0 };
                    assert!((gram[j * b.len() + i] - expected).abs() < 1e-13);
                }
            }
        }
    }

    /// The derivatives are those of the functions (central differences).
    #[test]
    fn derivatives_are_those_of_the_functions() {
        let b = SineCosineBasis::new(6, 3).unwrap();
        let (h, len) = (1e-6, b.len());
        let (mut plus, mut minus, mut d) = (vec![0.0; len], vec![0.0; len], vec![0.0; len]);
        for t in [0.0, 0.3, 2.0, 5.9] {
            b.functions_at(t + h, &mut plus);
            b.functions_at(t - h, &mut minus);
            b.derivatives_at(t, &mut d);
            for i in 0..len {
                let fd = (plus[i] - minus[i]) / (2.0 * h);
                assert!((fd - d[i]).abs() < 1e-7 * (1.0 + d[i].abs()), "{i} at {t}");
            }
        }
    }

    /// A cosine vector, padded with zero sines, synthesises the same samples in both bases,
    /// and its sines project to zero: the cosine basis is this one's even part.
    #[test]
    fn the_cosine_basis_is_the_even_part() {
        let (m, nh) = (9, 5);
        let (full, even) = (
            SineCosineBasis::new(m, nh).unwrap(),
            CosineBasis::new(m, nh).unwrap(),
        );
        let c = values(3, m + 1);
        let mut padded = c.clone();
        padded.resize(full.len(), 0.0);
        let (mut a, mut b) = (vec![0.0; full.samples()], vec![0.0; full.samples()]);
        full.synthesize(&padded, &mut a);
        even.synthesize(&c, &mut b);
        close(&a, &b, 1e-13, "even synthesis");
        let mut p = vec![f64::NAN; full.len()];
        full.project(&a, &mut p);
        close(&p[m + 1..], &vec![0.0; m], 1e-13, "sines of an even signal");
        assert_eq!(full.harmonic(m + 1), 1);
        assert_eq!(full.harmonic(2 * m), m);
    }

    #[test]
    fn rejects_bad_settings() {
        assert_eq!(
            SineCosineBasis::new(0, 30),
            Err(SettingsError::ZeroHarmonics)
        );
        assert!(matches!(
            SineCosineBasis::new(3, 2),
            Err(SettingsError::TooFewSamples { got: 2, min: 3 })
        ));
        assert!(matches!(
            SineCosineBasis::new(100_000, 3),
            Err(SettingsError::TooLarge(_))
        ));
        assert!(matches!(
            SineCosineBasis::new(usize::MAX, usize::MAX),
            Err(SettingsError::TooLarge(_))
        ));
    }
}
