//! Harmonic bases: time grid, synthesis, projection, and the weighted Gram matrix that makes
//! the generalised Jacobian cheap.
//!
//! The system never touches trigonometric tables directly: everything in time goes through a
//! [`Basis`]. [`CosineBasis`] is the paper's constant + cosine basis; [`SineCosineBasis`]
//! adds the sines, for motions that are not even in time (with a phase condition,
//! [`crate::system::PhaseLocked`]).

mod even;
mod full;

use crate::error::{OverBudget, SettingsError};
use even::{Buffers, EvenTransform};
pub use full::SineCosineBasis;
use std::cell::Cell;
use std::fmt::Debug;
use std::sync::Arc;

/// The memory budget of one request, in bytes: 4 GiB.
///
/// Sizes given by the user (harmonics and samples of a basis, values of a grid, time steps
/// and cells of a march) are checked against it before anything is allocated, so that a
/// request beyond it is a typed error (a `TooLarge` variant carrying an [`OverBudget`])
/// rather than an arithmetic overflow or an aborted allocation. On targets whose address
/// space is smaller, the budget is `isize::MAX` bytes instead (the most a `Vec` can hold).
pub const MEMORY_BUDGET_BYTES: u64 = 4 << 30;

/// Bytes of one `f64`.
const DOUBLE_BYTES: f64 = std::mem::size_of::<f64>() as f64;

/// Checks that `doubles` values of type `f64` fit in the memory budget
/// ([`MEMORY_BUDGET_BYTES`]); `what` names the request in the error.
///
/// `doubles` is a float so that a product of sizes cannot overflow before it is checked:
/// pass `a as f64 * b as f64`, not `a * b`. NaN counts as over the budget.
///
/// ```
/// use nonsmooth_modes::fourier::{check_memory, MEMORY_BUDGET_BYTES};
///
/// assert!(check_memory("a small buffer", 1e6).is_ok());
/// let err = check_memory("a Gram matrix of 100001 coefficients", 100_001f64 * 100_001f64)
///     .unwrap_err();
/// assert_eq!(err.budget_bytes, MEMORY_BUDGET_BYTES);
/// assert!(err.requested_bytes > 8e10);
/// ```
///
/// # Errors
/// [`OverBudget`] with the bytes requested and the budget. It converts into the `TooLarge`
/// variant of [`SettingsError`], [`ContinuationError`](crate::ContinuationError) and
/// [`VerifyError`](crate::verify::VerifyError) (and into [`crate::Error`]) with `?`.
pub fn check_memory(what: &'static str, doubles: f64) -> Result<(), OverBudget> {
    let error = over_budget(what, doubles);
    if error.requested_bytes <= error.budget_bytes as f64 {
        Ok(())
    } else {
        Err(error)
    }
}

/// The error of a request of `doubles` values of type `f64` against the budget.
fn over_budget(what: &'static str, doubles: f64) -> OverBudget {
    OverBudget {
        what,
        requested_bytes: doubles * DOUBLE_BYTES,
        budget_bytes: MEMORY_BUDGET_BYTES.min(isize::MAX as u64),
    }
}

/// Doubles per time sample that a [`CosineBasis`] implies besides its Gram matrix: an upper
/// estimate of its sine and cosine tables, the FFT plan and scratch (Bluestein's algorithm
/// for a prime size pads to a power of two above `2 N`), the folded buffers and one period
/// of samples held by the caller.
const BASIS_DOUBLES_PER_SAMPLE: f64 = 16.0;

/// The fundamental angular frequency `Omega = 2 pi / T` of a motion of period `T`: the
/// frequency at which a basis's `2 pi`-periodic functions `phi_i(Omega t)` repeat every `T`.
///
/// The crate's one conversion from a period to a frequency, and [`period_of_frequency`]
/// the one back (the same formula): each quantity along a computation is kept as the
/// continuation parameter holds it and the other derived once from it, never converted
/// back and forth (a round trip `T -> Omega -> T` may move `T` by one unit in the last
/// place). Both are `2 pi / v` rounded once, so `2.0 * PI / v` and `TAU / v` give the same
/// bits.
///
/// ```
/// use nonsmooth_modes::fourier::{frequency_of_period, period_of_frequency};
/// use std::f64::consts::PI;
///
/// assert_eq!(frequency_of_period(2.0), PI);
/// assert_eq!(period_of_frequency(PI), 2.0);
/// ```
pub const fn frequency_of_period(period: f64) -> f64 {
    2.0 * std::f64::consts::PI / period
}

/// The period `T = 2 pi / Omega` of a motion of fundamental angular frequency `Omega`: the
/// inverse of [`frequency_of_period`] (the same formula, rounded once).
pub const fn period_of_frequency(omega: f64) -> f64 {
    2.0 * std::f64::consts::PI / omega
}

/// A finite real basis of `2 pi`-periodic functions `phi_i(theta)`, with a grid of `N`
/// equispaced samples `theta_k = 2 pi k / N` on which residuals are projected (Riemann sum).
///
/// # Folded grid
/// When every function of the basis has a symmetry on the grid (the cosine basis is even:
/// `s(theta_(N-k)) = s(theta_k)`), its signals take only `S < N` distinct values, at the
/// first `S` grid points. Pointwise laws then need evaluating only there, and the transforms
/// can exploit the symmetry: the `*_folded` methods work on those `S` samples, each standing
/// for [`Basis::multiplicity`] grid instants. A basis without symmetry keeps the defaults
/// (`S = N`, every multiplicity 1, the folded methods are the full ones).
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
    ///
    /// # Panics
    /// If `out.len() != self.len()`. The lengths of the slices given to the methods of a
    /// basis are the caller's contract (they run in hot loops and return no `Result`): an
    /// implementation may panic when they are wrong, as [`CosineBasis`] does. The typed
    /// errors of the crate are raised at its user-facing entry points, which size these
    /// slices themselves.
    fn functions_at(&self, theta: f64, out: &mut [f64]);

    /// `d phi_i / d theta` for every `i`, written into `out`.
    ///
    /// # Panics
    /// If `out.len() != self.len()` (see [`Basis::functions_at`]).
    fn derivatives_at(&self, theta: f64, out: &mut [f64]);

    /// `s_k = sum_i c_i phi_i(theta_k)` for `k = 0..N`.
    ///
    /// # Panics
    /// If `coefficients.len() != self.len()` or `samples.len() != self.samples()` (see
    /// [`Basis::functions_at`]).
    fn synthesize(&self, coefficients: &[f64], samples: &mut [f64]);

    /// The Galerkin projection `R_j = (2/N) sum_k psi_j(theta_k) r_k`, where `psi_j` is the
    /// test function of coefficient `j` (for the cosine basis `psi_j = cos(j theta)`).
    ///
    /// # Panics
    /// If `samples.len() != self.samples()` or `coefficients.len() != self.len()` (see
    /// [`Basis::functions_at`]).
    fn project(&self, samples: &[f64], coefficients: &mut [f64]);

    /// `G[j][i] = (2/N) sum_k psi_j(theta_k) w_k phi_i(theta_k)`, row-major `len x len`: the
    /// projection of `w * phi_i`, i.e. the Jacobian block of a pointwise law with weight `w`.
    ///
    /// # Panics
    /// If `weights.len() != self.samples()` or `gram.len() != self.len()^2` (see
    /// [`Basis::functions_at`]).
    fn weighted_gram(&self, weights: &[f64], gram: &mut [f64]);

    /// Number `S` of folded samples: the grid points `theta_0..theta_S` at which every
    /// signal of the basis takes all its values. `N` by default.
    fn folded_samples(&self) -> usize {
        self.samples()
    }

    /// Number of grid instants that folded sample `k` stands for (1 by default). They sum
    /// to `N`. Meaningful for `k < S` only.
    fn multiplicity(&self, k: usize) -> usize {
        let _ = k;
        1
    }

    /// The folded sample whose value instant `k` of the full grid (`k < N`) takes, for
    /// every signal of the basis: `k` itself by default.
    fn folded_index(&self, k: usize) -> usize {
        k
    }

    /// [`Basis::synthesize`] at the `S` folded samples only.
    ///
    /// # Panics
    /// If `coefficients.len() != self.len()` or `samples.len() != self.folded_samples()`
    /// (see [`Basis::functions_at`]).
    fn synthesize_folded(&self, coefficients: &[f64], samples: &mut [f64]) {
        self.synthesize(coefficients, samples);
    }

    /// [`Basis::project`] of the signal with the symmetry of the basis whose folded samples
    /// are `samples`: `R_j = (2/N) sum_k mult_k psi_j(theta_k) r_k` over `k = 0..S`.
    ///
    /// # Panics
    /// If `samples.len() != self.folded_samples()` or `coefficients.len() != self.len()`
    /// (see [`Basis::functions_at`]).
    fn project_folded(&self, samples: &[f64], coefficients: &mut [f64]) {
        self.project(samples, coefficients);
    }

    /// [`Basis::weighted_gram`] of the weight with the symmetry of the basis whose folded
    /// samples are `weights`.
    ///
    /// # Panics
    /// If `weights.len() != self.folded_samples()` or `gram.len() != self.len()^2` (see
    /// [`Basis::functions_at`]).
    fn weighted_gram_folded(&self, weights: &[f64], gram: &mut [f64]) {
        self.weighted_gram(weights, gram);
    }
}

/// Constant + cosine basis: `s(theta) = c_0 / 2 + sum_{n=1..m} c_n cos(n theta)`
/// (formulation §4). Time-even motions only; the phase is fixed by symmetry.
///
/// Samples: `N = n_h m` per period (`n_h >= 3`, so that `2m < N` and the discrete products of
/// two cosines are exactly orthogonal).
///
/// Every signal is even, so it lives on the `S = floor(N/2) + 1` folded samples
/// `theta_0..theta_(N/2)`. Synthesis, projection and the weighted Gram matrix are all
/// full-period cosine sums of an even sequence (a type-I DCT), computed for even `N` from one
/// real FFT of size `N/2` (`O(N log N)`, a quarter of the work of the `O(m N)` direct sums at
/// `m = 4`, far less above), planned once when the basis is built and shared by its clones.
/// The full-grid methods fold their input (its odd part does not reach any cosine) or
/// unfold their output. The scratch buffers are thread-local and reused, so none of the
/// methods allocates after the first call on a thread.
#[derive(Clone)]
pub struct CosineBasis {
    harmonics: usize,
    samples: usize,
    transform: Arc<EvenTransform>,
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

/// Reused buffers: a folded signal, its cosine sums, the Gram moments and the transform's.
struct Scratch {
    folded: Vec<f64>,
    sums: Vec<f64>,
    moments: Vec<f64>,
    transform: Buffers,
}

impl Scratch {
    /// Empty buffers (they grow on first use).
    const fn new() -> Self {
        Self {
            folded: Vec::new(),
            sums: Vec::new(),
            moments: Vec::new(),
            transform: Buffers::new(),
        }
    }
}

thread_local! {
    static SCRATCH: Cell<Scratch> = const { Cell::new(Scratch::new()) };
}

impl Default for Scratch {
    fn default() -> Self {
        Self::new()
    }
}

/// Runs `f` with this thread's buffers (a fresh set if they are already in use).
fn with_scratch<R>(f: impl FnOnce(&mut Scratch) -> R) -> R {
    with_buffers(&SCRATCH, f)
}

/// Runs `f` with this thread's buffers held in `key` (a fresh set if they are already in
/// use, as in a nested call), then puts them back: transforms reuse them and allocate
/// nothing after their first call on a thread.
fn with_buffers<S: Default, R>(
    key: &'static std::thread::LocalKey<Cell<S>>,
    f: impl FnOnce(&mut S) -> R,
) -> R {
    key.with(|cell| {
        let mut buffers = cell.take();
        let result = f(&mut buffers);
        cell.set(buffers);
        result
    })
}

impl CosineBasis {
    /// `m` harmonics and `n_h` samples per harmonic.
    ///
    /// The basis implies a Gram matrix of `(m + 1)^2` doubles for each pointwise law and
    /// about 16 doubles per time sample (`N = n_h m`) of tables, FFT buffers and samples;
    /// together they must fit in [`MEMORY_BUDGET_BYTES`] (for `n_h = 30` that allows up to
    /// about 23 000 harmonics).
    ///
    /// # Errors
    /// [`SettingsError::ZeroHarmonics`] if `m = 0`; [`SettingsError::TooFewSamples`] if
    /// `n_h < 3`; [`SettingsError::TooLarge`] if the basis does not fit in the budget (the
    /// error carries the bytes it would need).
    pub fn new(harmonics: usize, samples_per_harmonic: usize) -> Result<Self, SettingsError> {
        let what = "a cosine basis (its Gram matrix, tables and FFT buffers)";
        let n = checked_samples(
            what,
            harmonics,
            samples_per_harmonic,
            harmonics as f64 + 1.0,
        )?;
        Ok(Self {
            harmonics,
            samples: n,
            transform: Arc::new(EvenTransform::new(n)),
        })
    }

    /// The length contract of a slice of coefficients.
    fn assert_coefficients(&self, len: usize) {
        assert_eq!(len, self.len(), "one value per coefficient");
    }

    /// The length contract of a Gram matrix.
    fn assert_gram(&self, len: usize) {
        assert_eq!(
            len,
            self.len() * self.len(),
            "a square matrix of coefficients"
        );
    }

    /// The even part `(x_k + x_(N-k)) / 2` of the full-period samples `x`, folded, into
    /// `scratch.folded`: the only part any cosine sees.
    fn fold(&self, x: &[f64], scratch: &mut Scratch) {
        let n = self.samples;
        assert_eq!(x.len(), n, "one period of samples");
        scratch.folded.clear();
        scratch
            .folded
            .extend((0..=n / 2).map(|k| 0.5 * (x[k] + x[(n - k) % n])));
    }

    /// The cosine sums `C_l = sum_k x_k cos(l theta_k)` (full period, `l = 0..count`,
    /// `count <= S`) of the even signal with folded samples `folded`, into `scratch.sums`.
    fn cosine_sums(&self, folded: &[f64], count: usize, scratch: &mut Scratch) {
        let Scratch {
            sums, transform, ..
        } = scratch;
        sums.resize(count, 0.0);
        self.transform.cosine_sums(folded, sums, transform);
    }

    /// [`Self::cosine_sums`] of the signal in `scratch.folded` (left there).
    fn cosine_sums_of_scratch(&self, count: usize, scratch: &mut Scratch) {
        let Scratch {
            folded,
            sums,
            transform,
            ..
        } = scratch;
        sums.resize(count, 0.0);
        self.transform.cosine_sums(folded, sums, transform);
    }

    /// How many cosine sums the Gram moments `sigma_0..sigma_2m` read: `C_l = C_(N-l)`
    /// serves the moments above `N/2`.
    fn moment_sums(&self) -> usize {
        (2 * self.harmonics).min(self.samples / 2) + 1
    }

    /// Synthesis into `scratch.sums`: the cosine sums of the even coefficient sequence
    /// `(c_0, c_1, .., c_m, 0, .., 0, c_m, .., c_1) / 2`, whose folded half is
    /// `(c_0 .. c_m) / 2` followed by zeros.
    fn synthesize_into_sums(&self, coefficients: &[f64], scratch: &mut Scratch) {
        scratch.folded.clear();
        let halves = coefficients.iter().take(self.len()).map(|c| 0.5 * c);
        scratch.folded.extend(halves);
        self.cosine_sums_of_scratch(self.folded_samples(), scratch);
    }

    /// `R_j = (2/N) C_j` for the coefficients, from `scratch.sums`.
    fn project_sums(&self, coefficients: &mut [f64], scratch: &Scratch) {
        let scale = 2.0 / self.samples as f64;
        for (o, c) in coefficients.iter_mut().zip(&scratch.sums) {
            *o = scale * c;
        }
    }

    /// The Gram matrix from the cosine sums of the weight in `scratch.sums`: with the moments
    /// `sigma_l = (2/N) C_l` (`C_l = C_(N-l)` above `N/2`),
    /// `(2/N) sum w cos(j t) cos(i t) = (sigma_|j-i| + sigma_(j+i)) / 2`: Toeplitz + Hankel.
    fn gram_from_sums(&self, gram: &mut [f64], scratch: &mut Scratch) {
        let (n, len) = (self.samples, self.len());
        let scale = 2.0 / n as f64;
        let Scratch { sums, moments, .. } = scratch;
        moments.clear();
        moments.extend((0..=2 * self.harmonics).map(|l| scale * sums[l.min(n - l)]));
        let sigma = &*moments;
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
    }
}

/// The number of samples `N = n_h m` of a basis of `m = harmonics` harmonics and `len`
/// coefficients per signal (a float: `m + 1` may not fit in `usize`), checked: at least one
/// harmonic, `n_h >= 3` (the discrete products of two harmonics are orthogonal only for
/// `2m < N`), and its Gram matrix (`len^2` doubles) with [`BASIS_DOUBLES_PER_SAMPLE`]
/// doubles per sample within the memory budget; `what` names the basis in the error.
fn checked_samples(
    what: &'static str,
    harmonics: usize,
    samples_per_harmonic: usize,
    len: f64,
) -> Result<usize, SettingsError> {
    if harmonics == 0 {
        return Err(SettingsError::ZeroHarmonics);
    }
    if samples_per_harmonic < 3 {
        return Err(SettingsError::TooFewSamples {
            got: samples_per_harmonic,
            min: 3,
        });
    }
    // Sizes in floating point first: their products cannot overflow there.
    let samples = harmonics as f64 * samples_per_harmonic as f64;
    let doubles = len * len + BASIS_DOUBLES_PER_SAMPLE * samples;
    check_memory(what, doubles)?;
    // Within the budget `N` fits in `usize`; checked all the same.
    harmonics
        .checked_mul(samples_per_harmonic)
        .ok_or_else(|| over_budget(what, doubles).into())
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
        self.assert_coefficients(out.len());
        for (i, o) in out.iter_mut().enumerate() {
            *o = constant_half(i) * (i as f64 * theta).cos();
        }
    }
    fn derivatives_at(&self, theta: f64, out: &mut [f64]) {
        self.assert_coefficients(out.len());
        for (i, o) in out.iter_mut().enumerate() {
            *o = -(i as f64) * (i as f64 * theta).sin();
        }
    }
    fn synthesize(&self, coefficients: &[f64], samples: &mut [f64]) {
        let n = self.samples;
        self.assert_coefficients(coefficients.len());
        assert_eq!(samples.len(), n, "one period of samples");
        with_scratch(|scratch| {
            self.synthesize_into_sums(coefficients, scratch);
            for (k, s) in samples.iter_mut().enumerate() {
                *s = scratch.sums[k.min(n - k)];
            }
        });
    }
    fn project(&self, samples: &[f64], coefficients: &mut [f64]) {
        self.assert_coefficients(coefficients.len());
        with_scratch(|scratch| {
            self.fold(samples, scratch);
            self.cosine_sums_of_scratch(self.len(), scratch);
            self.project_sums(coefficients, scratch);
        });
    }
    fn weighted_gram(&self, weights: &[f64], gram: &mut [f64]) {
        self.assert_gram(gram.len());
        with_scratch(|scratch| {
            self.fold(weights, scratch);
            self.cosine_sums_of_scratch(self.moment_sums(), scratch);
            self.gram_from_sums(gram, scratch);
        });
    }
    fn folded_samples(&self) -> usize {
        self.samples / 2 + 1
    }
    /// `theta_0` (and `theta_(N/2)` for even `N`) stand for themselves; every other folded
    /// sample also for its mirror `theta_(N-k)`.
    fn multiplicity(&self, k: usize) -> usize {
        if k == 0 || 2 * k == self.samples {
            1
        } else {
            2
        }
    }
    /// The mirror image `N - k` of an instant past the middle.
    fn folded_index(&self, k: usize) -> usize {
        k.min(self.samples - k)
    }
    fn synthesize_folded(&self, coefficients: &[f64], samples: &mut [f64]) {
        self.assert_coefficients(coefficients.len());
        assert_eq!(samples.len(), self.folded_samples(), "one folded period");
        with_scratch(|scratch| {
            self.synthesize_into_sums(coefficients, scratch);
            samples.copy_from_slice(&scratch.sums);
        });
    }
    fn project_folded(&self, samples: &[f64], coefficients: &mut [f64]) {
        assert_eq!(samples.len(), self.folded_samples(), "one folded period");
        self.assert_coefficients(coefficients.len());
        with_scratch(|scratch| {
            self.cosine_sums(samples, self.len(), scratch);
            self.project_sums(coefficients, scratch);
        });
    }
    fn weighted_gram_folded(&self, weights: &[f64], gram: &mut [f64]) {
        assert_eq!(weights.len(), self.folded_samples(), "one folded period");
        self.assert_gram(gram.len());
        with_scratch(|scratch| {
            self.cosine_sums(weights, self.moment_sums(), scratch);
            self.gram_from_sums(gram, scratch);
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
    /// Odd `N` (full-length FFT), even `N` with even and odd `N/2` (half-length DCT).
    const SIZES: [(usize, usize); 9] = [
        (1, 3),
        (2, 4),
        (5, 3),
        (5, 6),
        (3, 10),
        (7, 3),
        (8, 4),
        (20, 30),
        (33, 7),
    ];

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

    /// The folded methods on the first `S` samples agree with the full ones, and the
    /// multiplicities count every grid instant once.
    #[test]
    fn folded_methods_match_the_full_grid() {
        let mut rng = Lcg(0x5eed_0004);
        for (m, nh) in SIZES {
            let b = CosineBasis::new(m, nh).unwrap();
            let (n, s, len) = (b.samples(), b.folded_samples(), b.len());
            assert_eq!(s, n / 2 + 1);
            assert_eq!((0..s).map(|k| b.multiplicity(k)).sum::<usize>(), n);
            let c = rng.vec(len);
            let (mut full, mut folded) = (vec![f64::NAN; n], vec![f64::NAN; s]);
            b.synthesize(&c, &mut full);
            b.synthesize_folded(&c, &mut folded);
            assert_close(&folded, &full[..s], len as f64, "folded synthesis");
            // An even signal on the full grid and its folded samples project alike.
            let even: Vec<f64> = (0..n).map(|k| folded[k.min(n - k)]).collect();
            let (mut p_full, mut p_folded) = (vec![f64::NAN; len], vec![f64::NAN; len]);
            b.project(&even, &mut p_full);
            b.project_folded(&folded, &mut p_folded);
            assert_close(&p_folded, &p_full, len as f64, "folded projection");
            let (mut g_full, mut g_folded) = (vec![f64::NAN; len * len], vec![f64::NAN; len * len]);
            b.weighted_gram(&even, &mut g_full);
            b.weighted_gram_folded(&folded, &mut g_folded);
            assert_close(&g_folded, &g_full, len as f64, "folded gram");
        }
    }

    /// A signal's odd part reaches no cosine: projecting it gives zero.
    #[test]
    fn odd_signals_project_to_zero() {
        let mut rng = Lcg(0x5eed_0005);
        for (m, nh) in SIZES {
            let b = CosineBasis::new(m, nh).unwrap();
            let n = b.samples();
            let half = rng.vec(n);
            let odd: Vec<f64> = (0..n).map(|k| half[k] - half[(n - k) % n]).collect();
            let mut p = vec![f64::NAN; b.len()];
            b.project(&odd, &mut p);
            assert_close(&p, &vec![0.0; b.len()], 2.0, "odd projection");
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
        assert!(Arc::ptr_eq(&a.transform, &b.transform));
        assert_eq!(a, CosineBasis::new(6, 5).unwrap());
        assert_ne!(a, CosineBasis::new(6, 4).unwrap());
    }

    #[test]
    fn sizes_beyond_the_memory_budget_are_typed_errors() {
        let budget = MEMORY_BUDGET_BYTES.min(isize::MAX as u64);
        // m = 1e5: a Gram matrix of 1e10 doubles.
        match CosineBasis::new(100_000, 3) {
            Err(SettingsError::TooLarge(e)) => {
                assert_eq!(e.budget_bytes, budget);
                let gram = 100_001f64 * 100_001f64 * 8.0;
                assert!(e.requested_bytes > gram && e.requested_bytes < 1.01 * gram);
            }
            other => panic!("expected TooLarge, got {other:?}"),
        }
        // m n_h overflows usize: still a number of bytes, not a wrapped product.
        for (m, nh) in [
            (usize::MAX, usize::MAX),
            (2, usize::MAX),
            (usize::MAX / 2, 3),
        ] {
            match CosineBasis::new(m, nh) {
                Err(SettingsError::TooLarge(e)) => {
                    assert!(e.requested_bytes > 1e19, "{e}");
                }
                other => panic!("m = {m}, n_h = {nh}: expected TooLarge, got {other:?}"),
            }
        }
        // The documented limit at n_h = 30.
        assert!(CosineBasis::new(22_900, 30).is_ok());
        assert!(matches!(
            CosineBasis::new(23_000, 30),
            Err(SettingsError::TooLarge(_))
        ));
        assert!(check_memory("x", budget as f64 / 8.0).is_ok());
        assert!(check_memory("x", budget as f64 / 8.0 + 1.0).is_err());
        assert!(check_memory("x", f64::NAN).is_err());
        assert!(check_memory("x", f64::INFINITY).is_err());
    }

    #[test]
    #[should_panic(expected = "one value per coefficient")]
    fn short_coefficients_panic() {
        let b = CosineBasis::new(4, 3).unwrap();
        let mut s = vec![0.0; b.samples()];
        b.synthesize(&[1.0, 2.0], &mut s);
    }

    #[test]
    #[should_panic(expected = "one folded period")]
    fn long_folded_samples_panic() {
        let b = CosineBasis::new(4, 3).unwrap();
        let mut c = vec![0.0; b.len()];
        b.project_folded(&vec![0.0; b.samples()], &mut c);
    }

    #[test]
    #[should_panic(expected = "a square matrix of coefficients")]
    fn short_gram_panics() {
        let b = CosineBasis::new(4, 3).unwrap();
        let mut g = vec![0.0; b.len()];
        b.weighted_gram(&vec![1.0; b.samples()], &mut g);
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
