//! Cosine sums of even signals from their folded samples.
//!
//! A signal of the cosine basis is even on the grid `theta_k = 2 pi k / N`: `x_(N-k) = x_k`,
//! so its `S = floor(N/2) + 1` folded samples `x_0..x_S` determine it. Synthesis, projection
//! and the Gram moments all reduce to the full-period cosine sums
//!
//! `C_l = sum_(k=0..N) x_k cos(2 pi l k / N)`, `l = 0..S`,
//!
//! of an even sequence: a type-I discrete cosine transform. For even `N = 2M` it is computed
//! from a real FFT of length `M` (half the length of the FFT of the unfolded signal) with the
//! classical folding (Cooley, Lewis and Welch): with `y_k = (x_k + x_(M-k)) - 2 sin(pi k / M)
//! (x_k - x_(M-k))`, `k = 0..M`, and `Y = FFT(y)`,
//!
//! - `C_(2l) = Re Y_l`,
//! - `C_(2l+1) = C_(2l-1) - Im Y_l`, from `C_1 = x_0 - x_M + 2 sum_(k=1..M) x_k cos(pi k / M)`.
//!
//! The first holds because the odd part of `y` about `M/2` is orthogonal to the cosines of
//! even order; the second because `2 sin(a) sin(2la) = cos((2l-1)a) - cos((2l+1)a)`. For odd
//! `N` there is no such folding; the signal is unfolded and goes through a real FFT of size
//! `N`.

use crate::linalg::dot_lanes;
use num_complex::Complex;
use realfft::{RealFftPlanner, RealToComplex};
use std::f64::consts::PI;
use std::sync::Arc;

/// The planned transform of one grid size `N`, shared by the clones of a basis.
pub(super) struct EvenTransform {
    samples: usize,
    kind: Kind,
}

enum Kind {
    /// `N = 2M`: type-I DCT of length `M + 1` through a real FFT of length `M`, with the
    /// tables `sin(pi k / M)` and `cos(pi k / M)`, `k = 0..M`.
    Half {
        fft: Arc<dyn RealToComplex<f64>>,
        sin: Vec<f64>,
        cos: Vec<f64>,
    },
    /// `N` odd: real FFT of the unfolded signal.
    Full { fft: Arc<dyn RealToComplex<f64>> },
}

/// Reused buffers of one transform: the FFT input, its half spectrum and the FFT's scratch.
pub(super) struct Buffers {
    real: Vec<f64>,
    spectrum: Vec<Complex<f64>>,
    fft: Vec<Complex<f64>>,
}

impl Buffers {
    /// Empty buffers (they grow on first use).
    pub(super) const fn new() -> Self {
        Self {
            real: Vec::new(),
            spectrum: Vec::new(),
            fft: Vec::new(),
        }
    }
}

impl EvenTransform {
    /// Plans the transform of the grid of `samples >= 2` points.
    pub(super) fn new(samples: usize) -> Self {
        let mut planner = RealFftPlanner::<f64>::new();
        let kind = if samples % 2 == 0 {
            let half = samples / 2;
            let angle = |k: usize| PI * k as f64 / half as f64;
            Kind::Half {
                fft: planner.plan_fft_forward(half),
                sin: (0..half).map(|k| angle(k).sin()).collect(),
                cos: (0..half).map(|k| angle(k).cos()).collect(),
            }
        } else {
            Kind::Full {
                fft: planner.plan_fft_forward(samples),
            }
        };
        Self { samples, kind }
    }

    /// The number of folded samples `S = floor(N/2) + 1`.
    pub(super) fn folded_len(&self) -> usize {
        self.samples / 2 + 1
    }

    /// The leading cosine sums `C_l`, `l = 0..sums.len()` (at most `S`), of the even signal
    /// whose leading folded samples are `folded` (at most `S`; the others are zero), into
    /// `sums`. A short signal (a synthesis from `m + 1 << S` coefficients) costs less before
    /// the FFT; asking for fewer sums shortens the recurrence of the odd ones after it.
    pub(super) fn cosine_sums(&self, folded: &[f64], sums: &mut [f64], buffers: &mut Buffers) {
        let len = self.folded_len();
        assert!(folded.len() <= len, "at most one folded period of samples");
        assert!(sums.len() <= len, "at most one folded period of sums");
        let Buffers {
            real,
            spectrum,
            fft: scratch,
        } = buffers;
        match &self.kind {
            Kind::Half { fft, sin, cos } => {
                let half = len - 1;
                let x = folded;
                fold_for_half_length(x, half, sin, real);
                run(fft.as_ref(), real, spectrum, scratch);
                let at = |k: usize| x.get(k).copied().unwrap_or(0.0);
                let interior = &x[1.min(x.len())..x.len().min(half)];
                let mut odd =
                    at(0) - at(half) + 2.0 * dot_lanes(interior, &cos[1..interior.len() + 1]);
                let Some((first, rest)) = sums.split_first_mut() else {
                    return;
                };
                *first = spectrum[0].re;
                // Bin l gives C_(2l) and carries C_(2l-1) to C_(2l+1) (l <= M/2).
                let mut pairs = rest.chunks_exact_mut(2);
                for (pair, y) in pairs.by_ref().zip(&spectrum[1..]) {
                    pair[0] = odd;
                    pair[1] = y.re;
                    odd -= y.im;
                }
                if let [last] = pairs.into_remainder() {
                    // An even count of sums ends on an odd one, carried past the last pair.
                    *last = odd;
                }
            }
            Kind::Full { fft } => {
                // Unfolded: x_0..x_S, then the mirror x_(S-1)..x_1 (N = 2S - 1), zero-padded.
                real.clear();
                real.extend_from_slice(folded);
                real.resize(len, 0.0);
                real.extend_from_within(1..len);
                real[len..].reverse();
                run(fft.as_ref(), real, spectrum, scratch);
                for (s, y) in sums.iter_mut().zip(spectrum.iter()) {
                    *s = y.re;
                }
            }
        }
    }
}

/// `y_k = (x_k + x_(M-k)) - 2 sin(pi k / M) (x_k - x_(M-k))`, `k = 0..M`, into `real`, for
/// the leading folded samples `x` (zero beyond).
fn fold_for_half_length(x: &[f64], half: usize, sin: &[f64], real: &mut Vec<f64>) {
    real.resize(half, 0.0);
    if x.len() == half + 1 {
        // Full signal: the mirror runs x_M, x_(M-1), .., x_1.
        let pairs = x[..half].iter().zip(x[1..].iter().rev());
        for ((y, (&a, &b)), &s) in real.iter_mut().zip(pairs).zip(sin) {
            *y = (a + b) - 2.0 * s * (a - b);
        }
        return;
    }
    // x_k vanishes from k = len on, x_(M-k) up to k = M - len.
    let lead = x.len().min(half);
    for k in 0..lead {
        let (a, b) = (x[k], if half - k < x.len() { x[half - k] } else { 0.0 });
        real[k] = (a + b) - 2.0 * sin[k] * (a - b);
    }
    // Only the samples between the two ends vanish (a short synthesis: most of them); the
    // ends are written above and below.
    let tail = (half + 1 - x.len()).max(lead).min(half);
    real[lead..tail].fill(0.0);
    for k in tail..half {
        real[k] = x[half - k] * (1.0 + 2.0 * sin[k]);
    }
}

/// One forward real FFT of `real` into `spectrum`, with reused scratch.
fn run(
    fft: &dyn RealToComplex<f64>,
    real: &mut [f64],
    spectrum: &mut Vec<Complex<f64>>,
    scratch: &mut Vec<Complex<f64>>,
) {
    spectrum.resize(real.len() / 2 + 1, Complex::default());
    scratch.resize(fft.get_scratch_len(), Complex::default());
    fft.process_with_scratch(real, spectrum, scratch)
        .expect("FFT buffer lengths match the plan");
}
