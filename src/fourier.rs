//! Harmonic bases: time grid, synthesis, projection, and the weighted Gram matrix that makes
//! the generalised Jacobian cheap.
//!
//! The system never touches trigonometric tables directly: everything in time goes through a
//! [`Basis`]. [`CosineBasis`] is the paper's constant + cosine basis; a sine + cosine basis
//! (odd motions, with a phase condition) fits the same trait.

use crate::error::SettingsError;
use num_complex::Complex;
use realfft::{ComplexToReal, RealFftPlanner, RealToComplex};
use std::cell::Cell;
use std::fmt::Debug;
use std::sync::Arc;

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
///
/// Synthesis, projection and the weighted Gram matrix go through one real FFT of size `N`
/// each (`O(N log N)` instead of the `O(m N)` direct sums), planned once when the basis is
/// built and shared by its clones. The FFT scratch buffers are thread-local and reused, so
/// none of the three allocates after the first call on a thread.
#[derive(Clone)]
pub struct CosineBasis {
    harmonics: usize,
    samples: usize,
    plans: Plans,
}

/// Forward and inverse real FFTs of size `N`, planned once.
#[derive(Clone)]
struct Plans {
    forward: Arc<dyn RealToComplex<f64>>,
    inverse: Arc<dyn ComplexToReal<f64>>,
}

impl Debug for CosineBasis {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("CosineBasis")
            .field("harmonics", &self.harmonics)
            .field("samples", &self.samples)
            .finish_non_exhaustive()
    }
}

/// Two bases are equal when they have the same harmonics and samples (the FFT plans follow).
impl PartialEq for CosineBasis {
    fn eq(&self, other: &Self) -> bool {
        self.harmonics == other.harmonics && self.samples == other.samples
    }
}

/// Reused buffers of the FFTs: a real signal, its half spectrum and the FFT's own scratch.
#[derive(Default)]
struct Scratch {
    real: Vec<f64>,
    spectrum: Vec<Complex<f64>>,
    fft: Vec<Complex<f64>>,
}

thread_local! {
    static SCRATCH: Cell<Scratch> = const {
        Cell::new(Scratch {
            real: Vec::new(),
            spectrum: Vec::new(),
            fft: Vec::new(),
        })
    };
}

/// Runs `f` with this thread's FFT buffers (a fresh set if they are already in use).
fn with_scratch<R>(f: impl FnOnce(&mut Scratch) -> R) -> R {
    SCRATCH.with(|cell| {
        let mut scratch = cell.take();
        let result = f(&mut scratch);
        cell.set(scratch);
        result
    })
}

/// Resizes `v` to `len` without shrinking its capacity.
fn fit<T: Clone + Default>(v: &mut Vec<T>, len: usize) {
    v.resize(len, T::default());
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
        let mut planner = RealFftPlanner::<f64>::new();
        let plans = Plans {
            forward: planner.plan_fft_forward(n),
            inverse: planner.plan_fft_inverse(n),
        };
        Ok(Self {
            harmonics,
            samples: n,
            plans,
        })
    }

    /// The half spectrum `X_l = sum_k x_k exp(-2 pi i l k / N)`, `l = 0..=N/2`, of the
    /// samples `x` into `scratch.spectrum`.
    fn forward(&self, x: &[f64], scratch: &mut Scratch) {
        let n = self.samples;
        assert_eq!(x.len(), n, "one period of samples");
        scratch.real.clear();
        scratch.real.extend_from_slice(x);
        fit(&mut scratch.spectrum, n / 2 + 1);
        fit(&mut scratch.fft, self.plans.forward.get_scratch_len());
        self.plans
            .forward
            .process_with_scratch(&mut scratch.real, &mut scratch.spectrum, &mut scratch.fft)
            .expect("FFT buffer lengths match the plan");
    }

    /// `(2/N) sum_k w_k cos(l theta_k)` for `l = 0..=2m`, into `scratch.real`.
    fn cosine_moments(&self, weights: &[f64], scratch: &mut Scratch) {
        let n = self.samples;
        self.forward(weights, scratch);
        let scale = 2.0 / n as f64;
        let Scratch { real, spectrum, .. } = scratch;
        real.clear();
        // Re X_l = Re X_(N-l) for a real signal: moments above N/2 read the mirror bin.
        real.extend((0..=2 * self.harmonics).map(|l| scale * spectrum[l.min(n - l)].re));
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
        assert_eq!(samples.len(), n, "one period of samples");
        with_scratch(|scratch| {
            // Inverse real FFT of the Hermitian spectrum X_0 = c_0 / 2, X_n = X_(N-n) = c_n / 2
            // (n = 1..m < N/2): x_k = c_0 / 2 + sum_n c_n cos(n theta_k).
            let spectrum = &mut scratch.spectrum;
            spectrum.clear();
            spectrum.resize(n / 2 + 1, Complex::new(0.0, 0.0));
            for (x, &c) in spectrum
                .iter_mut()
                .zip(coefficients.iter().take(self.len()))
            {
                x.re = 0.5 * c;
            }
            fit(&mut scratch.fft, self.plans.inverse.get_scratch_len());
            self.plans
                .inverse
                .process_with_scratch(spectrum, samples, &mut scratch.fft)
                .expect("FFT buffer lengths match the plan");
        });
    }
    fn project(&self, samples: &[f64], coefficients: &mut [f64]) {
        let scale = 2.0 / self.samples as f64;
        with_scratch(|scratch| {
            self.forward(samples, scratch);
            for (o, x) in coefficients.iter_mut().zip(&scratch.spectrum) {
                *o = scale * x.re;
            }
        });
    }
    fn weighted_gram(&self, weights: &[f64], gram: &mut [f64]) {
        let len = self.len();
        with_scratch(|scratch| {
            self.cosine_moments(weights, scratch);
            let sigma = &scratch.real;
            // (2/N) sum w cos(j t) cos(i t) = (sigma_|j-i| + sigma_(j+i)) / 2: Toeplitz + Hankel.
            // Row j: the Toeplitz part reads sigma[j], ..., sigma[1] then sigma[0], sigma[1], ...
            // and the Hankel part sigma[j..j + len]; slices keep the loops free of index math.
            for (j, row) in gram.chunks_exact_mut(len).take(len).enumerate() {
                let (below, above) = row.split_at_mut(j);
                let hankel = &sigma[j..j + len];
                for ((g, t), h) in below.iter_mut().zip(sigma[1..=j].iter().rev()).zip(hankel) {
                    *g = 0.5 * (t + h);
                }
                for ((g, t), h) in above.iter_mut().zip(&sigma[..len - j]).zip(&hankel[j..]) {
                    *g = 0.5 * (t + h);
                }
                row[0] *= constant_half(0);
            }
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    /// The dense path, kept as the oracle of the FFTs: direct sums over the grid.
    mod dense {
        use super::*;

        pub fn synthesize(b: &CosineBasis, c: &[f64]) -> Vec<f64> {
            let n = b.samples();
            (0..n)
                .map(|k| {
                    let t = 2.0 * PI * k as f64 / n as f64;
                    c.iter()
                        .enumerate()
                        .map(|(i, ci)| constant_half(i) * ci * (i as f64 * t).cos())
                        .sum()
                })
                .collect()
        }

        pub fn moment(b: &CosineBasis, w: &[f64], l: usize) -> f64 {
            let n = b.samples();
            let acc: f64 = w
                .iter()
                .enumerate()
                .map(|(k, wk)| wk * (2.0 * PI * ((l * k) % n) as f64 / n as f64).cos())
                .sum();
            2.0 / n as f64 * acc
        }

        pub fn gram(b: &CosineBasis, w: &[f64]) -> Vec<f64> {
            let len = b.len();
            let n = b.samples();
            let mut g = vec![0.0; len * len];
            let mut phi = vec![0.0; len];
            for (k, wk) in w.iter().enumerate() {
                let t = 2.0 * PI * k as f64 / n as f64;
                b.functions_at(t, &mut phi);
                for j in 0..len {
                    let psi = (j as f64 * t).cos();
                    for i in 0..len {
                        g[j * len + i] += 2.0 / n as f64 * psi * wk * phi[i];
                    }
                }
            }
            g
        }
    }

    /// A fixed-seed generator of numbers in `[-1, 1)` (64-bit LCG, top bits).
    struct Lcg(u64);

    impl Lcg {
        fn next(&mut self) -> f64 {
            self.0 = self
                .0
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (self.0 >> 11) as f64 / (1u64 << 52) as f64 - 1.0
        }
        fn vec(&mut self, n: usize) -> Vec<f64> {
            (0..n).map(|_| self.next()).collect()
        }
    }

    /// Sizes covering even and odd `N`, `n_h = 3` (moments above `N/2`) and `n_h = 4`
    /// (`2m = N/2`).
    const SIZES: [(usize, usize); 7] = [(1, 3), (2, 4), (5, 3), (7, 3), (8, 4), (20, 30), (33, 7)];

    fn assert_close(fast: &[f64], slow: &[f64], scale: f64, what: &str) {
        assert_eq!(fast.len(), slow.len());
        for (k, (a, b)) in fast.iter().zip(slow).enumerate() {
            assert!(
                (a - b).abs() <= 1e-13 * scale,
                "{what}[{k}]: fft {a} vs direct {b}"
            );
        }
    }

    #[test]
    fn fft_synthesis_matches_direct_sums() {
        let mut rng = Lcg(0x5eed_0001);
        for (m, nh) in SIZES {
            let b = CosineBasis::new(m, nh).unwrap();
            let c = rng.vec(b.len());
            let mut fast = vec![f64::NAN; b.samples()];
            b.synthesize(&c, &mut fast);
            assert_close(
                &fast,
                &dense::synthesize(&b, &c),
                b.len() as f64,
                "synthesis",
            );
        }
    }

    #[test]
    fn fft_projection_matches_direct_sums() {
        let mut rng = Lcg(0x5eed_0002);
        for (m, nh) in SIZES {
            let b = CosineBasis::new(m, nh).unwrap();
            let r = rng.vec(b.samples());
            let mut fast = vec![f64::NAN; b.len()];
            b.project(&r, &mut fast);
            let slow: Vec<f64> = (0..b.len()).map(|j| dense::moment(&b, &r, j)).collect();
            assert_close(&fast, &slow, 2.0, "projection");
        }
    }

    #[test]
    fn fft_gram_matches_direct_sums() {
        let mut rng = Lcg(0x5eed_0003);
        for (m, nh) in SIZES {
            let b = CosineBasis::new(m, nh).unwrap();
            // a contact indicator (0/1) and a general weight
            let s: Vec<f64> = rng
                .vec(b.samples())
                .iter()
                .map(|v| f64::from(*v > 0.0))
                .collect();
            let w = rng.vec(b.samples());
            for weights in [&s, &w] {
                let mut fast = vec![f64::NAN; b.len() * b.len()];
                b.weighted_gram(weights, &mut fast);
                assert_close(&fast, &dense::gram(&b, weights), 2.0, "gram");
            }
        }
    }

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
    fn clones_share_plans_and_compare_by_size() {
        let a = CosineBasis::new(6, 5).unwrap();
        let b = a.clone();
        assert!(Arc::ptr_eq(&a.plans.forward, &b.plans.forward));
        assert_eq!(a, CosineBasis::new(6, 5).unwrap());
        assert_ne!(a, CosineBasis::new(6, 4).unwrap());
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
