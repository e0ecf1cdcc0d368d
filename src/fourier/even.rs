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

    /// The cosine sums `C_l`, `l = 0..S`, of the even signal whose folded samples are
    /// `folded`, into `sums` (both of length `S`).
    pub(super) fn cosine_sums(&self, folded: &[f64], sums: &mut [f64], buffers: &mut Buffers) {
        let len = self.folded_len();
        assert_eq!(folded.len(), len, "one folded period of samples");
        assert_eq!(sums.len(), len, "one folded period of sums");
        let Buffers {
            real,
            spectrum,
            fft: scratch,
        } = buffers;
        match &self.kind {
            Kind::Half { fft, sin, cos } => {
                let half = len - 1;
                let x = folded;
                real.clear();
                real.extend((0..half).map(|k| {
                    let (a, b) = (x[k], x[half - k]);
                    (a + b) - 2.0 * sin[k] * (a - b)
                }));
                run(fft.as_ref(), real, spectrum, scratch);
                let interior: f64 = x[1..half].iter().zip(&cos[1..]).map(|(a, c)| a * c).sum();
                let mut odd = x[0] - x[half] + 2.0 * interior;
                sums[0] = spectrum[0].re;
                // Bin l gives C_(2l) and carries C_(2l-1) to C_(2l+1) (l <= M/2).
                for (l, y) in spectrum.iter().enumerate().skip(1) {
                    sums[2 * l - 1] = odd;
                    sums[2 * l] = y.re;
                    odd -= y.im;
                }
                if half % 2 == 1 {
                    // M odd: the last sum is odd and follows the last bin.
                    sums[half] = odd;
                }
            }
            Kind::Full { fft } => {
                real.clear();
                real.extend_from_slice(folded);
                real.extend(folded[1..].iter().rev());
                run(fft.as_ref(), real, spectrum, scratch);
                for (s, y) in sums.iter_mut().zip(spectrum.iter()) {
                    *s = y.re;
                }
            }
        }
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
