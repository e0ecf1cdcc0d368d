//! The seeded random numbers of the suite and the draws of one case's inputs, each written,
//! named, into the case's log.

use nonsmooth_modes::fourier::MEMORY_BUDGET_BYTES;
use std::fmt::{Debug, Write as _};
use std::ops::RangeInclusive;
use std::sync::{Arc, Mutex};

/// SplitMix64 (Steele, Lea, Flood 2014): tiny, fast, and the same on every platform.
pub(crate) struct SplitMix(pub(crate) u64);

impl SplitMix {
    pub(crate) fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in `0..n` (`n > 0`).
    pub(crate) fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }

    /// Uniform in `[0, 1)`.
    pub(crate) fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }

    fn chance(&mut self, p: f64) -> bool {
        self.unit() < p
    }
}

/// Values of `f64` at the edges: zeros, a negative, subnormals, tiny and huge, the extremes,
/// infinities and NaN.
const EDGE_REALS: [f64; 14] = [
    0.0,
    -0.0,
    -1.0,
    f64::MIN_POSITIVE,
    5e-324,
    1e-310,
    1e-300,
    1e300,
    f64::MAX,
    -f64::MAX,
    f64::INFINITY,
    f64::NEG_INFINITY,
    f64::NAN,
    -1e-300,
];

/// Sizes at the edges: none, one, and sizes no memory holds.
const EDGE_SIZES: [usize; 5] = [0, 1, 1 << 40, usize::MAX - 1, usize::MAX];

/// Tolerances below what `f64` can reach relative to a problem's scale: a quarter of the
/// machine epsilon, tiny, subnormal (`2.2e-309`, the independent run's) and the least
/// positive `f64`.
pub(crate) const FLOOR_TOLERANCES: [f64; 5] = [f64::EPSILON / 4.0, 1e-20, 1e-300, 2.2e-309, 5e-324];

/// The largest count of a request of `per_unit` doubles per unit that fits in the memory
/// budget ([`MEMORY_BUDGET_BYTES`]).
pub(crate) fn budget_count(per_unit: f64) -> usize {
    (MEMORY_BUDGET_BYTES as f64 / 8.0 / per_unit).floor() as usize
}

/// Draws the inputs of one case and writes each, named, into a log shared with the harness
/// (which prints it when the case fails, even if it never returns).
pub(crate) struct Draw {
    pub(crate) rng: SplitMix,
    pub(crate) log: Arc<Mutex<String>>,
    /// Probability of an edge value instead of a valid one.
    pub(crate) edge: f64,
}

impl Draw {
    fn note(&self, name: &str, value: impl Debug) {
        let mut log = self.log.lock().unwrap_or_else(|e| e.into_inner());
        let _ = write!(log, "{name}={value:?} ");
    }

    /// A real: valid (log-uniform in `valid` when it spans decades and is positive, uniform
    /// otherwise) or, with probability `self.edge`, one of [`EDGE_REALS`].
    pub(crate) fn real(&mut self, name: &str, valid: RangeInclusive<f64>) -> f64 {
        let v = if self.rng.chance(self.edge) {
            EDGE_REALS[self.rng.below(EDGE_REALS.len() as u64) as usize]
        } else {
            let (lo, hi) = (*valid.start(), *valid.end());
            let u = self.rng.unit();
            if lo > 0.0 && hi / lo > 100.0 {
                lo * (hi / lo).powf(u)
            } else {
                lo + (hi - lo) * u
            }
        };
        self.note(name, v);
        v
    }

    /// A size: uniform in `valid` or, with probability `self.edge`, one of [`EDGE_SIZES`].
    pub(crate) fn size(&mut self, name: &str, valid: RangeInclusive<usize>) -> usize {
        let v = if self.rng.chance(self.edge) {
            EDGE_SIZES[self.rng.below(EDGE_SIZES.len() as u64) as usize]
        } else {
            let (lo, hi) = (*valid.start(), *valid.end());
            lo + self.rng.below((hi - lo + 1) as u64) as usize
        };
        self.note(name, v);
        v
    }

    /// A size, or with probability `self.edge / 4` one just past the memory budget of a
    /// request of `per_unit` doubles per unit ([`budget_count`]): one more, or twice the
    /// count. (Sizes just under it allocate up to 4 GiB and take minutes; they are run under
    /// a memory limit by `tests/independent_run.rs`, and every history returned here is
    /// checked to hold exactly what the budget counted.)
    pub(crate) fn size_or_budget(
        &mut self,
        name: &str,
        valid: RangeInclusive<usize>,
        per_unit: f64,
    ) -> usize {
        if !self.rng.chance(self.edge / 4.0) {
            return self.size(name, valid);
        }
        let max = budget_count(per_unit);
        let v = if self.rng.chance(0.5) {
            max + 1
        } else {
            2 * max
        };
        self.note(name, v);
        v
    }

    /// A tolerance: valid, or with probability `self.edge / 2` one of [`FLOOR_TOLERANCES`].
    pub(crate) fn tolerance(&mut self, name: &str, valid: RangeInclusive<f64>) -> f64 {
        if self.rng.chance(self.edge / 2.0) {
            return self.pick(name, &FLOOR_TOLERANCES);
        }
        self.real(name, valid)
    }

    pub(crate) fn flag(&mut self, name: &str, p: f64) -> bool {
        let v = self.rng.chance(p);
        self.note(name, v);
        v
    }

    /// One of `valid` or, with probability `self.edge`, one of `bad`.
    pub(crate) fn choice<T: Copy + Debug>(&mut self, name: &str, valid: &[T], bad: &[T]) -> T {
        let from = if self.rng.chance(self.edge) {
            bad
        } else {
            valid
        };
        self.pick(name, from)
    }

    pub(crate) fn pick<T: Copy + Debug>(&mut self, name: &str, choices: &[T]) -> T {
        let v = choices[self.rng.below(choices.len() as u64) as usize];
        self.note(name, v);
        v
    }
}
