//! Linear modes of the system with every contact open or closed, and its rigid-body modes.
//!
//! With every unilateral law replaced by a linear row (open: zero contact force; closed: zero
//! gap motion), one harmonic of angular frequency `omega` has a square matrix `D(omega)` in
//! the Helmholtz unknowns. Natural frequencies are the `omega` where it is singular; they are
//! located as minima of `sigma_min(D) / sigma_max(D)` on a scan of step `pi c / (200 l)` (which also finds double
//! roots, where `det D` does not change sign) and refined by golden-section search. They are
//! documented for users in [`crate::modal::linear`], which re-exports them with the grazing
//! energy and the branch seeds built on them.

use crate::error::SettingsError;
use crate::linalg::determinant_sign_small;
use crate::linalg::singular_values_small;
use crate::linalg::svd_small;
use crate::system::rows::dot;
use crate::system::rows::HarmonicRows;
use crate::system::rows::RowsScratch;
use crate::system::spectra::ScanKey;
use crate::system::BarSystem;

/// Which linear state the unilateral conditions take.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ContactState {
    /// Every contact open: zero contact force.
    Open,
    /// Every contact closed: the gap does not move.
    Closed,
}

/// A natural frequency with its mode shapes.
#[derive(Debug, Clone, PartialEq)]
pub struct LinearMode {
    /// Angular frequency `omega`.
    pub omega: f64,
    /// Orthonormal basis of the mode shapes, each in Helmholtz unknowns `(A_b, B_b)` per bar
    /// (more than one where the frequency is repeated, e.g. two identical bars).
    pub shapes: Vec<Vec<f64>>,
}

/// The linear system of one harmonic in `state`, rebuilt at each frequency in the same
/// storage: a scan evaluates it at thousands of frequencies.
struct StateMatrix<'a> {
    system: &'a BarSystem,
    state: ContactState,
    rows: HarmonicRows,
    scratch: RowsScratch,
    /// Row-major, `n x n`.
    matrix: Vec<f64>,
    singular: Vec<f64>,
    /// Scratch copies of the matrix for the singular values and the elimination.
    work: Vec<f64>,
    elimination: Vec<f64>,
}

impl<'a> StateMatrix<'a> {
    fn new(system: &'a BarSystem, state: ContactState) -> Self {
        Self {
            system,
            state,
            rows: HarmonicRows::new(system, 0.0),
            scratch: RowsScratch::default(),
            matrix: Vec::new(),
            singular: Vec::new(),
            work: Vec::new(),
            elimination: Vec::new(),
        }
    }

    /// The row-major square matrix at `omega` and its size.
    fn at(&mut self, omega: f64) -> (&[f64], usize) {
        let (system, rows) = (self.system, &mut self.rows);
        rows.rebuild(system, omega, &mut self.scratch);
        let n = rows.unknowns();
        self.matrix.clear();
        for r in 0..rows.linear_count() {
            self.matrix.extend_from_slice(rows.linear_row(r));
        }
        for l in 0..system.contact_count() {
            self.matrix.extend_from_slice(match self.state {
                ContactState::Open => rows.force_row(l),
                ContactState::Closed => rows.gap_row(l),
            });
        }
        // Scale each row to unit norm so that the singular-value ratio measures degeneracy,
        // not the growth of `k sin(kl)` entries with frequency.
        for row in self.matrix.chunks_mut(n) {
            let s = dot(row, row).sqrt();
            if s > 0.0 {
                row.iter_mut().for_each(|v| *v /= s);
            }
        }
        (&self.matrix, n)
    }

    /// `sigma_min / sigma_max` of the matrix at `omega`: zero where it is singular.
    fn singularity(&mut self, omega: f64) -> f64 {
        let n = self.at(omega).1;
        self.ratio(n)
    }

    /// The sign of the determinant of the (row-scaled) matrix at `omega`, `0` where a pivot
    /// vanishes. It changes at every root of odd multiplicity however narrow the root's dip
    /// in [`StateMatrix::singularity`]: a bar much softer than its partner enters the
    /// matrix only through rows where it weighs little, and its partner's roots dip below
    /// that floor over less than a scan step.
    fn determinant_sign(&mut self, omega: f64) -> f64 {
        let n = self.at(omega).1;
        determinant_sign_small(&self.matrix, n, &mut self.elimination)
    }

    /// Both [`StateMatrix::singularity`] and [`StateMatrix::determinant_sign`] at `omega`,
    /// from one assembly of the matrix: a scan sample.
    fn sample(&mut self, omega: f64) -> (f64, f64) {
        let n = self.at(omega).1;
        let sign = determinant_sign_small(&self.matrix, n, &mut self.elimination);
        (self.ratio(n), sign)
    }

    /// `sigma_min / sigma_max` of the `n x n` matrix assembled last.
    fn ratio(&mut self, n: usize) -> f64 {
        self.singular.resize(n, 0.0);
        singular_values_small(&self.matrix, (n, n), &mut self.singular, &mut self.work);
        self.singular[n - 1] / self.singular[0]
    }
}

/// Row-major square matrix of the linear system in `state` at `omega`.
fn state_matrix(system: &BarSystem, omega: f64, state: ContactState) -> (Vec<f64>, usize) {
    let mut matrix = StateMatrix::new(system, state);
    let (m, n) = matrix.at(omega);
    (m.to_vec(), n)
}

/// `sigma_min / sigma_max` of `D(omega)`: zero where it is singular.
fn singularity(system: &BarSystem, omega: f64, state: ContactState) -> f64 {
    StateMatrix::new(system, state).singularity(omega)
}

/// Largest number of scan samples of [`natural_frequencies`] (about 1000 modes of one bar).
pub const MAX_SCAN: usize = 200_000;

/// Natural frequencies in `(0, omega_max]` of the linear system in `state`, ascending, each
/// refined to about `1e-13` relative, with its mode shapes.
///
/// # Errors
/// [`SettingsError::NotPositive`] if `omega_max` is not positive and finite;
/// [`SettingsError::ScanTooLong`] beyond [`MAX_SCAN`] samples.
pub fn natural_frequencies(
    system: &BarSystem,
    state: ContactState,
    omega_max: f64,
) -> Result<Vec<LinearMode>, SettingsError> {
    let omegas = natural_frequency_values(system, state, omega_max, Resolution::FULL)?;
    Ok(omegas
        .into_iter()
        .map(|omega| LinearMode {
            omega,
            shapes: null_vectors(system, omega, state),
        })
        .collect())
}

/// How finely natural frequencies are located: scan samples per spacing `pi c / l` of the
/// shortest-period bar, and the relative width at which the golden-section refinement stops.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Resolution {
    pub per_spacing: f64,
    pub tolerance: f64,
}

impl Resolution {
    /// [`natural_frequencies`]'s: 200 samples per spacing, refined to `1e-15`.
    pub(crate) const FULL: Self = Self {
        per_spacing: 200.0,
        tolerance: 1e-15,
    };
    /// What naming the modes of labels needs: a quarter of the samples (distinct frequencies
    /// closer than about 4 % of a spacing count as one, and the numbers above them are one
    /// apart from a fine scan's) and `1e-10` relative.
    pub(crate) const LABELS: Self = Self {
        per_spacing: 50.0,
        tolerance: 1e-10,
    };

    /// The key of a scan of `state` at this resolution among the system's scans.
    fn key(self, state: ContactState) -> ScanKey {
        let tag = match state {
            ContactState::Open => 0,
            ContactState::Closed => 1,
        };
        (tag, self.per_spacing, self.tolerance)
    }
}

/// The frequencies of [`natural_frequencies`] without their shapes, located to
/// `resolution`.
///
/// # Errors
/// See [`natural_frequencies`].
pub(crate) fn natural_frequency_values(
    system: &BarSystem,
    state: ContactState,
    omega_max: f64,
    resolution: Resolution,
) -> Result<Vec<f64>, SettingsError> {
    if !(omega_max.is_finite() && omega_max > 0.0) {
        return Err(SettingsError::NotPositive {
            what: "upper frequency",
            value: omega_max,
        });
    }
    // Scan step: 1/per_spacing of the smallest spacing pi c / l of one bar's spectrum; distinct roots
    // closer than about two steps would merge (repeated roots are found with multiplicity).
    let spacing = system
        .bars()
        .iter()
        .map(|b| std::f64::consts::PI * b.wave_speed() / b.length())
        .fold(f64::INFINITY, f64::min);
    let h = spacing / resolution.per_spacing;
    let samples = omega_max / h;
    if samples > MAX_SCAN as f64 {
        return Err(SettingsError::ScanTooLong {
            omega_max,
            samples: samples.min(usize::MAX as f64) as usize,
            limit: MAX_SCAN,
        });
    }
    let key = resolution.key(state);
    if let Some(values) = system.spectra().exact(key, omega_max) {
        return Ok(values);
    }
    let modes = scan(system, state, (omega_max, h), resolution);
    system.spectra().keep(key, omega_max, &modes);
    Ok(modes)
}

/// The natural frequencies of [`natural_frequency_values`] up to some bound at or above
/// `omega_max`, with that bound: a scan of the system already run up to a higher one where
/// there is one ([`Spectra::covering`](crate::system::spectra::Spectra::covering): its values
/// below `omega_max` less a few scan steps are the same), else a new scan up to `omega_max`.
///
/// # Errors
/// See [`natural_frequencies`].
pub(crate) fn natural_frequencies_covering(
    system: &BarSystem,
    state: ContactState,
    omega_max: f64,
    resolution: Resolution,
) -> Result<(f64, Vec<f64>), SettingsError> {
    if omega_max.is_finite() && omega_max > 0.0 {
        if let Some(found) = system.spectra().covering(resolution.key(state), omega_max) {
            return Ok(found);
        }
    }
    natural_frequency_values(system, state, omega_max, resolution).map(|v| (omega_max, v))
}

/// The scan of [`natural_frequency_values`] up to `omega_max` with step `h`, its arguments
/// checked. What earlier scans of the system at this resolution computed is read from its
/// [`ScanMemo`](crate::system::spectra::ScanMemo) and what this one adds is kept there: a scan that extends an earlier one
/// (the labels' scans, as a run's frequency grows) samples and refines only beyond it.
fn scan(
    system: &BarSystem,
    state: ContactState,
    (omega_max, h): (f64, f64),
    resolution: Resolution,
) -> Vec<f64> {
    let samples = omega_max / h;
    let steps = samples.ceil() as usize + 1;
    let key = resolution.key(state);
    let mut memo = system.spectra().memo(key);
    let mut matrix = StateMatrix::new(system, state);
    let at = |i: usize| (i as f64 + 0.5) * h;
    for i in memo.samples.len()..=steps {
        memo.samples.push(matrix.sample(at(i)));
    }
    let (values, signs): (Vec<f64>, Vec<f64>) = memo.samples[..=steps].iter().copied().unzip();
    let mut modes = Vec::new();
    for i in 1..values.len() - 1 {
        if values[i] <= values[i - 1] && values[i] < values[i + 1] {
            let (omega, ratio) = *memo.minima.entry(i).or_insert_with(|| {
                let (lo, hi) = ((i as f64 - 0.5) * h, (i as f64 + 1.5) * h);
                let tolerance = resolution.tolerance;
                let omega = golden_minimum(|w| matrix.singularity(w), (lo, hi), tolerance);
                (omega, matrix.singularity(omega))
            });
            if omega > omega_max || ratio > 1e-8 {
                continue;
            }
            modes.push(omega);
        }
    }
    // Roots whose dip the samples stepped over: a change of the determinant's sign between
    // two samples that no minimum above accounts for (none within two steps: closer ones
    // merge anyway), located by bisection on the sign.
    let from_minima = modes.len();
    for i in 0..values.len() - 1 {
        // The minima come in ascending order: the first at or above `at(i) - 2h`.
        let k = modes[..from_minima].partition_point(|&m| m < at(i) - 2.0 * h);
        let known = modes[..from_minima]
            .get(k)
            .is_some_and(|&m| m <= at(i + 1) + 2.0 * h);
        if signs[i] * signs[i + 1] < 0.0 && !known {
            let (omega, ratio) = *memo.crossings.entry(i).or_insert_with(|| {
                let sign = |w| matrix.determinant_sign(w);
                let omega = sign_change(sign, (at(i), at(i + 1)), signs[i]);
                (omega, matrix.singularity(omega))
            });
            if omega <= omega_max && ratio <= 1e-8 {
                modes.push(omega);
            }
        }
    }
    system.spectra().keep_memo(key, memo);
    modes.sort_by(f64::total_cmp);
    modes
}

/// The point of `(lo, hi)` where `sign` (`sign_lo` at `lo`, the opposite at `hi`) changes,
/// by bisection to the resolution of `f64`.
fn sign_change(
    mut sign: impl FnMut(f64) -> f64,
    (mut lo, mut hi): (f64, f64),
    sign_lo: f64,
) -> f64 {
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        let s = sign(mid);
        if s == 0.0 {
            return mid;
        }
        if s == sign_lo {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// The rigid-body modes of the linear system in `state`: the motions at zero frequency, one
/// shape per independent rigid motion (a bar held only by contacts translates freely while
/// they are open), or `None` if the system has none. [`natural_frequencies`] lists the modes
/// of positive frequency only; nonsmooth modes are numbered from those.
///
/// At `omega = 0` each bar's field is affine, `u = A + B x`; a rigid-body mode is an affine
/// field per bar that satisfies every condition row (and, in `state`, the contact rows).
pub fn rigid_body_modes(system: &BarSystem, state: ContactState) -> Option<LinearMode> {
    (singularity(system, 0.0, state) <= 1e-8).then(|| LinearMode {
        omega: 0.0,
        shapes: null_vectors(system, 0.0, state),
    })
}

fn golden_minimum(
    mut f: impl FnMut(f64) -> f64,
    (mut a, mut b): (f64, f64),
    tolerance: f64,
) -> f64 {
    let g = 0.5 * (5f64.sqrt() - 1.0);
    let (mut c, mut d) = (b - g * (b - a), a + g * (b - a));
    let (mut fc, mut fd) = (f(c), f(d));
    while (b - a) > tolerance * b.abs().max(1.0) {
        if fc < fd {
            b = d;
            d = c;
            fd = fc;
            c = b - g * (b - a);
            fc = f(c);
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + g * (b - a);
            fd = f(d);
        }
        if c >= d {
            break;
        }
    }
    0.5 * (a + b)
}

/// Orthonormal null vectors of `D(omega)` (singular values below `1e-6` of the largest).
/// Largest `sigma_j / sigma_max` of a mode shape's singular value at a located natural
/// frequency. Located roots reach about `1e-14`; a partner `10^4` times softer than its bar
/// leaves a second singular value near `1e-6` at the bar's roots, which is no second shape.
const NULL_RATIO: f64 = 1e-9;

fn null_vectors(system: &BarSystem, omega: f64, state: ContactState) -> Vec<Vec<f64>> {
    let (m, n) = state_matrix(system, omega, state);
    let (s, v) = svd_small(&m, n, n);
    (0..n)
        .filter(|&j| s[j] <= NULL_RATIO * s[0])
        .map(|j| (0..n).map(|i| v[(i, j)]).collect())
        .collect()
}

/// The `mode`-th natural frequency of the open-contact system (1-based) with its shapes: the
/// linear mode that [`branch_seed`](crate::modal::branch_seed) seeds NSM `mode` from. It is searched below growing
/// bounds (up to 32 times `(mode + 1) pi c / l` of the bar with the lowest `pi c / l`).
///
/// # Errors
/// [`SettingsError::ZeroIndex`] for `mode = 0`; [`SettingsError::ModeNotFound`] if the search
/// ends without it.
pub fn open_mode(system: &BarSystem, mode: usize) -> Result<LinearMode, SettingsError> {
    if mode == 0 {
        return Err(SettingsError::ZeroIndex {
            what: "mode number",
            value: 0,
        });
    }
    let base = system
        .bars()
        .iter()
        .map(|b| std::f64::consts::PI * b.wave_speed() / b.length())
        .fold(f64::INFINITY, f64::min);
    let mut omega_max = base * (mode as f64 + 1.0);
    for _ in 0..6 {
        let modes = match natural_frequencies(system, ContactState::Open, omega_max) {
            Ok(modes) => modes,
            Err(SettingsError::ScanTooLong { .. }) => break,
            Err(e) => return Err(e),
        };
        if let Some(m) = modes.into_iter().nth(mode - 1) {
            return Ok(m);
        }
        omega_max *= 2.0;
    }
    Err(SettingsError::ModeNotFound { mode, omega_max })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bar::Bar;
    use crate::reference::{clamped_bar_with_obstacle, two_bars_in_contact};

    /// A scan that extends an earlier scan of its system (reading the samples and roots it
    /// kept) finds, bit for bit, what a scan of a new system up to the same bound finds, and
    /// so does a shorter scan after them: on one bar and on two, open and closed, at both
    /// resolutions.
    #[test]
    fn scans_that_extend_earlier_ones_find_what_new_scans_find() {
        let one = || clamped_bar_with_obstacle(1e-3).unwrap();
        let two = || two_bars_in_contact(Bar::new(0.8, 1.3, 2.5).unwrap(), 1e-3).unwrap();
        let states = [ContactState::Open, ContactState::Closed];
        for (build, state) in [one, two].into_iter().flat_map(|b| states.map(|s| (b, s))) {
            for resolution in [Resolution::LABELS, Resolution::FULL] {
                let grown = build();
                let values = |system: &BarSystem, bound: f64| {
                    natural_frequency_values(system, state, bound, resolution).unwrap()
                };
                values(&grown, 9.0);
                let fresh = values(&build(), 23.0);
                assert!(fresh.len() >= 5, "{fresh:?}");
                assert_eq!(values(&grown, 23.0), fresh);
                assert_eq!(values(&grown, 15.5), values(&build(), 15.5));
            }
        }
    }
}
