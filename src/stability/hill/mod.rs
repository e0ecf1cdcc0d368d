//! Hill's method on the harmonic-balance equations: the Floquet exponents of the truncated
//! system, as a cross-check of the exact one-period map of [`floquet`](super::floquet).
//!
//! # The Hill problem of a bar system
//!
//! Perturb a harmonic-balance point `u*` by `e^{lambda t} q(t)` with `q` a trigonometric
//! polynomial of the point's `m` harmonics and complex coefficients. Its component
//! `e^{s t} U(x)` with `s = lambda +- i n Omega` solves the wave equation when
//! `U'' + kappa U = 0` with `kappa = -s^2 / c^2`: the Helmholtz map of the bars at a complex
//! wave number, the one of damped waves ([`crate::forced::waves::DampedMap`], entire in
//! `kappa`). The linear conditions hold for each component. The unilateral laws are
//! linearised in time: their generalised gradients `w_gap(t)`, `w_force(t)` at the point
//! multiply the perturbation's gap and force, and the Galerkin projection gives the Gram
//! matrices `G(w)` of the point's own Jacobian, whatever `lambda`. In the full Fourier basis
//! (coefficients `X_c`, `X_s` of each harmonic, now complex), a row `a(kappa)` of harmonic
//! `n` acts as
//!
//! ```text
//! cosine row:  P X_c + E X_s,     sine row:  P X_s - E X_c,
//! P = (a(kappa+) + a(kappa-)) / 2,     E = -i (a(kappa+) - a(kappa-)) / 2,
//! ```
//!
//! with `kappa+-` the wave numbers of `s = lambda +- i n Omega`. At `lambda = 0` this is the
//! point's Jacobian (`P = a`, `E = 0`); with `lambda` it is the **Hill matrix** `H(lambda)`,
//! and the Floquet exponents of the truncated system are the `lambda` where it is singular.
//! Its entries are entire in `lambda` but not polynomial (`cos(kl)`, `sin(kl)/k`): a
//! **nonlinear** eigenvalue problem, not the quadratic one of a spatially discretised model.
//!
//! # The search
//!
//! Only exponents with `Re lambda > delta = ln(1 + tolerance) / T` decide the verdict (a
//! multiplier `e^{lambda T}` beyond the tolerance), and `lambda + i k Omega` describes the
//! same multiplier, so the search covers the box `delta < Re lambda <= ln(max_modulus) / T`,
//! `|Im lambda| <= Omega / 2` (and a margin). Shifts `lambda_0` on a grid of spacing
//! `h = Omega / shifts_per_frequency` over it linearise `H(lambda_0) + eps H'(lambda_0)`:
//! `eps = -1 / theta` for the eigenvalues `theta` of `H(lambda_0)^-1 H'(lambda_0)` (dense,
//! `faer`). Those within `0.75 h` of the shift (the disks cover the grid's cells) are
//! candidates, and each is refined by inverse iteration for nonlinear
//! eigenproblems (`u = H(lambda)^-1 H'(lambda) v`, `lambda <- lambda - w^H v / w^H u`,
//! quadratically convergent). The first column of cells reaches the imaginary axis, where
//! the truncated free waves put many exponents: they are refined too, since one of them is
//! the trivial exponent and the others must be told from small instabilities.
//! Exponents found beyond twice the box's right edge are dropped.
//!
//! # What it is and is not
//!
//! The exponents are those of the **truncated** equations at the point: they differ from
//! the exact map's where truncation matters. The time shift of the motion is an exponent 0
//! only up to the sampling of the laws ([`HillSpectrum::time_shift_residual`] measures it),
//! and with the family direction it forms a Jordan block that this perturbation splits by
//! its square root ([`HillSpectrum::trivial_distance`]): that pair is left out of the
//! verdict. On the paper's systems the truncated equations have exponents with positive
//! real parts at most points, where the exact map finds the motion stable, and more
//! harmonics do not remove them: Hill's error bounds assume smooth motions, and a motion
//! with impacts is not one. The crate's verdicts are the exact map's. The search is
//! a grid of local linearisations, so an exponent may be missed where `H` varies much
//! within a cell (many bars of very different travel times); it reports how many shifts it
//! used and where it stopped ([`HillSpectrum::search_modulus`]). `docs/validation.md`
//! compares its verdicts with the exact map's.

mod matrix;

use super::floquet::Multiplier;
use crate::check::check_finite;
use crate::continuation::ContinuationProblem;
use crate::error::{Error, SettingsError, StabilityError};
use crate::forced::ForcedSystem;
use crate::fourier::{period_of_frequency, Basis};
use crate::solve::{Problem, Structured};
use crate::system::inputs::check_frequency_of;
use crate::system::{shift_of, BarSystem, HarmonicBalanceSettings, NonsmoothSystem};
use crate::verdict::Crossing;
use crate::verdict::Verdict;
use faer::linalg::solvers::Solve;
use faer::{c64, Col};
use matrix::HillMatrix;

/// Iterations of the inverse iteration that refines one candidate exponent.
const REFINE_ITERATIONS: usize = 15;

/// The least alignment `|v^H x'| / (|v| |x'|)` with the time shift of the eigenvector of the
/// trivial exponent: a free wave that happens to lie near 0 is nearly orthogonal to it.
pub const MIN_ALIGNMENT: f64 = 0.5;

/// The radius, in shift spacings `h`, within which a shift's linearisation predicts
/// exponents: above `1 / sqrt 2`, so that the disks cover the grid's cells.
const TRUST_RADIUS: f64 = 0.75;

/// Candidates within this many shift spacings of an exponent already refined are taken
/// for it: the linearisation predicts an exponent to about `0.01 h` from a shift `h` away.
const SAME_EXPONENT: f64 = 0.01;

/// Relative change of an exponent (to `Omega`) at which its refinement stops.
const REFINE_TOLERANCE: f64 = 1e-11;

/// The largest residual of the point in the full harmonic-balance system (relative to
/// the largest gap at rest) for which its Hill exponents describe it: a point computed
/// with a harmonic selection or a kink blend, or stopped early, does not solve it.
pub const HILL_RESIDUAL: f64 = 1e-6;

/// The most rows of a Hill matrix: each shift of the search solves a dense eigenvalue
/// problem of this size (about 0.1 s at 400 rows), and the search takes dozens.
pub const MAX_HILL_DIMENSION: usize = 400;

/// Options of [`hill`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HillOptions {
    /// How far outside the unit circle a multiplier may lie and the point still count as
    /// stable (default `1e-3`, as [`StabilityOptions::tolerance`](super::StabilityOptions::tolerance)).
    pub tolerance: f64,
    /// The largest multiplier modulus searched for (default 100, at most `1e6`): the box's
    /// right edge is `ln(max_modulus) / T`.
    pub max_modulus: f64,
    /// Shifts per fundamental frequency `Omega` along each side of the box (default 8, at
    /// most 32). The search takes about `shifts^2 ln(max_modulus) / 2 pi` shifts (54 by
    /// default), each a dense eigenvalue problem of the matrix's size.
    pub shifts_per_frequency: usize,
}

impl Default for HillOptions {
    fn default() -> Self {
        Self {
            tolerance: 1e-3,
            max_modulus: 100.0,
            shifts_per_frequency: 8,
        }
    }
}

impl HillOptions {
    fn check(&self) -> Result<(), StabilityError> {
        let invalid = |what, expected, value| StabilityError::InvalidOption {
            what,
            expected,
            value,
        };
        if !(self.tolerance.is_finite() && self.tolerance > 0.0) {
            return Err(invalid("tolerance", "positive and finite", self.tolerance));
        }
        if !(self.max_modulus > 1.0 + self.tolerance && self.max_modulus <= 1e6) {
            return Err(invalid(
                "max_modulus",
                "above 1 + tolerance and at most 1e6",
                self.max_modulus,
            ));
        }
        if !(1..=32).contains(&self.shifts_per_frequency) {
            return Err(invalid(
                "shifts_per_frequency",
                "between 1 and 32",
                self.shifts_per_frequency as f64,
            ));
        }
        Ok(())
    }
}

/// A Floquet exponent `lambda = re + i im`.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Exponent {
    /// Real part: the growth rate.
    pub re: f64,
    /// Imaginary part, in `(-Omega / 2, Omega / 2]`.
    pub im: f64,
    /// The share of its eigenvector's squared norm on harmonics above `3 m / 4` (of the
    /// copy the search refined): near 1, the exponent lives where the truncation acts.
    pub high_harmonic_share: f64,
}

/// The Hill exponents of a point and the verdict they give.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct HillSpectrum {
    /// The exponents found with `Re lambda` beyond the tolerance (`Re lambda T > ln(1 +
    /// tolerance)`), but the trivial pair, largest real part first.
    pub exponents: Vec<Exponent>,
    /// Their multipliers `e^{lambda T}`, in the same order.
    pub multipliers: Vec<Multiplier>,
    /// The largest multiplier modulus, 1 when no exponent lies beyond the tolerance.
    pub max_multiplier: f64,
    /// Stable when no exponent but the trivial pair lies beyond the tolerance; unresolved
    /// when the point does not solve the full harmonic-balance system (its residual above
    /// [`HILL_RESIDUAL`]) or the trivial exponent was not found
    /// ([`HillSpectrum::trivial_distance`]).
    pub verdict: Verdict,
    /// `max |e^{+-lambda T} - 1|` of the trivial exponent: the one within `h / 4` of 0 whose
    /// eigenvector is most nearly the time shift (at least [`MIN_ALIGNMENT`]). With the
    /// family direction it forms a Jordan block at 0, which the sampling of the laws splits
    /// into a pair `+- sigma` by about the square root of the perturbation (a simple
    /// exponent moves by the perturbation itself). The pair is left out of the verdict;
    /// `None` when no such exponent was found, and the verdict is then unresolved.
    pub trivial_distance: Option<f64>,
    /// Why there is no verdict (`None` where there is one).
    pub unresolved: Option<HillUnresolved>,
    /// `|H(0) x'| / (|H(0)|_F |x'|)` with `x'` the time derivative of the point: how nearly
    /// the time shift is an exponent 0 of the truncated system (exactly only for shifts by
    /// whole samples of the laws).
    pub time_shift_residual: f64,
    /// `max |F(x)|` over the largest gap at rest: the point's residual in the full
    /// harmonic-balance system (no selection, no kink blend).
    pub residual: f64,
    /// The multiplier modulus up to which the search looked (`max_modulus`).
    pub search_modulus: f64,
    /// Shifts of the search.
    pub shifts: usize,
    /// Candidates refined by inverse iteration.
    pub refined: usize,
    /// Rows of `H`.
    pub dimension: usize,
}

/// Why Hill's method gives a point no verdict ([`HillSpectrum::unresolved`]).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[non_exhaustive]
pub enum HillUnresolved {
    /// The point does not solve the full harmonic-balance system (no selection, no kink
    /// blend): its residual `max |F(x)|` over the largest gap is above the bound
    /// [`HILL_RESIDUAL`], so the exponents are those of another system.
    Residual {
        /// The point's residual.
        residual: f64,
        /// The bound.
        bound: f64,
    },
    /// No exponent near 0 has an eigenvector aligned with the time shift to
    /// [`MIN_ALIGNMENT`]: the trivial pair, which the verdict leaves out, was not found.
    TrivialMissing {
        /// The best alignment found (0 where no exponent lies near 0).
        best_alignment: f64,
        /// The alignment needed.
        needed: f64,
    },
}

/// One sentence without commas (a CSV cell).
impl std::fmt::Display for HillUnresolved {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Residual { residual, bound } => write!(
                f,
                "the point misses the full harmonic-balance system by {residual:.3e} (bound {bound:.1e})"
            ),
            Self::TrivialMissing {
                best_alignment,
                needed,
            } => write!(
                f,
                "no exponent near 0 follows the time shift (best alignment {best_alignment:.3} of {needed})"
            ),
        }
    }
}

/// The Hill exponents of the harmonic-balance point `x` of `system` at fundamental
/// frequency `omega`, computed with `settings` (its harmonics, samples and complementarity
/// parameter). `x` is a state of the cosine basis or of the full basis (see the
/// [module docs](self)).
///
/// # Errors
/// - [`StabilityError::InvalidOption`] for options out of range;
/// - [`SettingsError`] for bad settings, a system without contact, a frequency out of the
///   discretization's range, a state of the wrong length, not finite, or so large that its
///   residual overflows ([`SettingsError::NonFiniteResult`]);
/// - [`StabilityError::HillUnsupported`] for a condition whose rows depend on the frequency;
/// - [`StabilityError::HillTooLarge`] for a matrix of more than [`MAX_HILL_DIMENSION`] rows;
/// - [`StabilityError::NoEigenvalues`] when the dense generalized eigenvalue problem fails.
pub fn hill(
    system: &BarSystem,
    settings: HarmonicBalanceSettings,
    x: &[f64],
    omega: f64,
    options: &HillOptions,
) -> Result<HillSpectrum, Error> {
    options.check()?;
    let rows = (2 * settings.harmonics as u128 + 1) * system.unknowns_per_harmonic() as u128;
    if rows > MAX_HILL_DIMENSION as u128 {
        return Err(StabilityError::HillTooLarge {
            dimension: rows,
            limit: MAX_HILL_DIMENSION,
        }
        .into());
    }
    check_frequency_of(&NonsmoothSystem::new(system, settings)?, omega)?;
    let mut free = ForcedSystem::free(system, settings)?;
    let m = free.basis().harmonics();
    let full = full_state(x, m, free.dimension())?;
    free.set_parameter(omega);
    let mut f = vec![0.0; full.len()];
    free.residual(&full, &mut f);
    let residual = f.iter().fold(0.0, |a: f64, v| a.max(v.abs())) / free.residual_scale();
    // A state too large for `f64` (finite, but its residual overflows).
    check_finite("Hill: the point's residual", omega, [&residual])?;
    let matrix = HillMatrix::new(&free, &full, omega)?;
    let period = period_of_frequency(omega);
    let search = Search::new(&matrix, options, omega, period);
    let found = search.run()?;
    let multiplier = |e: &c64| {
        let mu = (e * period).exp();
        Multiplier {
            re: mu.re,
            im: mu.im,
        }
    };
    // The trivial exponent: the one near 0 whose eigenvector is most nearly the time shift
    // `x'`. With the family direction it forms a Jordan block at 0, which the sampling of
    // the laws splits into a pair `+- sigma`: by the square root of the perturbation, where
    // a simple exponent moves by the perturbation itself. The pair never counts.
    // Of the state scaled to a largest coefficient of 1: only its direction matters, and a
    // state near the top of `f64` would overflow.
    let largest = full.iter().fold(0.0, |a: f64, v| a.max(v.abs()));
    let unit: Vec<f64> = full
        .iter()
        .map(|v| v / largest.max(f64::MIN_POSITIVE))
        .collect();
    let dx = shift_of(&unit, m, unit.len() / (2 * m + 1));
    let best = (found.near_zero.iter())
        .map(|(e, v)| (e, alignment(v, &dx)))
        .max_by(|a, b| a.1.total_cmp(&b.1));
    let trivial = best.filter(|(_, a)| *a >= MIN_ALIGNMENT);
    let trivial_distance = trivial.map(|(e, _)| {
        let away = |z: c64| ((z * period).exp() - 1.0).norm();
        away(*e).max(away(-e))
    });
    let unresolved = if residual.is_nan() || residual > HILL_RESIDUAL {
        Some(HillUnresolved::Residual {
            residual,
            bound: HILL_RESIDUAL,
        })
    } else if trivial.is_none() {
        Some(HillUnresolved::TrivialMissing {
            best_alignment: best.map_or(0.0, |(_, a)| a),
            needed: MIN_ALIGNMENT,
        })
    } else {
        None
    };
    let resolved = unresolved.is_none();
    let is_trivial = |e: &c64| {
        trivial.is_some_and(|(t, _)| {
            let near = |z: c64| (e - z).norm() <= 1e-6 * omega;
            near(*t) || near(-t) || near(t.conj()) || near(-t.conj())
        })
    };
    let mut beyond: Vec<(c64, f64)> = (found.all.iter())
        .filter(|(e, _)| e.re > search.delta && !is_trivial(e))
        .copied()
        .collect();
    beyond.sort_by(|a, b| b.0.re.total_cmp(&a.0.re));
    let multipliers: Vec<Multiplier> = beyond.iter().map(|(e, _)| multiplier(e)).collect();
    let largest = multipliers
        .iter()
        .map(Multiplier::modulus)
        .fold(1.0, f64::max);
    let verdict = match multipliers.first() {
        _ if !resolved => Verdict::Unresolved,
        None => Verdict::Stable,
        Some(mu) => Verdict::Unstable(crossing(mu, options.tolerance)),
    };
    let exponents = (beyond.iter())
        .map(|&(e, high_harmonic_share)| Exponent {
            re: e.re,
            im: e.im,
            high_harmonic_share,
        })
        .collect();
    Ok(HillSpectrum {
        exponents,
        multipliers,
        max_multiplier: largest,
        verdict,
        trivial_distance,
        unresolved,
        time_shift_residual: time_shift_residual(&matrix, &dx),
        residual,
        search_modulus: options.max_modulus,
        shifts: found.shifts,
        refined: found.refined,
        dimension: matrix.dimension(),
    })
}

/// How a multiplier outside the circle sits.
fn crossing(mu: &Multiplier, tolerance: f64) -> Crossing {
    if mu.im.abs() > tolerance * mu.modulus() {
        Crossing::ComplexPair
    } else if mu.re > 0.0 {
        Crossing::ThroughPlusOne
    } else {
        Crossing::ThroughMinusOne
    }
}

/// `x` in the full basis of `m` harmonics (`dimension` unknowns): as given, or a cosine
/// state with zero sines.
fn full_state(x: &[f64], m: usize, dimension: usize) -> Result<Vec<f64>, SettingsError> {
    let per = dimension / (2 * m + 1);
    let state = if x.len() == dimension {
        x.to_vec()
    } else if x.len() == per * (m + 1) {
        crate::modal::full_basis::to_full_basis(x, m)?
    } else {
        return Err(SettingsError::Length {
            what: "state (cosine or full basis)",
            got: x.len(),
            expected: dimension,
        });
    };
    if let Some(v) = state.iter().find(|v| !v.is_finite()) {
        return Err(SettingsError::NotFinite {
            what: "state coefficient",
            value: *v,
        });
    }
    Ok(state)
}

/// `|v^H x'| / (|v| |x'|)`: how nearly `v` is the time shift `x'`.
fn alignment(v: &Col<c64>, dx: &[f64]) -> f64 {
    let (mut dot, mut dx2) = (c64::new(0.0, 0.0), 0.0);
    for (i, d) in dx.iter().enumerate() {
        dot += v[i].conj() * *d;
        dx2 += d * d;
    }
    let v2 = v.squared_norm_l2();
    if v2 > 0.0 && dx2 > 0.0 {
        dot.norm() / (v2 * dx2).sqrt()
    } else {
        0.0
    }
}

/// `|H(0) x'| / (|H(0)|_F |x'|)` for the time derivative `dx` of a point.
fn time_shift_residual(matrix: &HillMatrix, dx: &[f64]) -> f64 {
    let (h, _) = matrix.at(c64::new(0.0, 0.0));
    let (mut out, mut frobenius) = (0.0, 0.0);
    for i in 0..h.nrows() {
        let mut row = 0.0;
        for (j, d) in dx.iter().enumerate() {
            row += h[(i, j)].re * d;
            frobenius += h[(i, j)].norm_sqr();
        }
        out += row * row;
    }
    let norm = dx.iter().map(|v| v * v).sum::<f64>().sqrt();
    if norm == 0.0 {
        0.0
    } else {
        out.sqrt() / (frobenius.sqrt() * norm)
    }
}

/// The exponents a search found, with its effort.
struct Found {
    /// Every exponent refined, folded into the strip (those near 0 included), with the
    /// high-harmonic share of its eigenvector.
    all: Vec<(c64, f64)>,
    /// The exponents within `h / 4` of 0, with their eigenvectors.
    near_zero: Vec<(c64, Col<c64>)>,
    shifts: usize,
    refined: usize,
}

/// The grid of shifts over the box of [`HillOptions`] (module docs).
struct Search<'m> {
    matrix: &'m HillMatrix,
    omega: f64,
    /// Exponents with a real part above this count.
    delta: f64,
    /// The box's right edge.
    rho: f64,
    /// The shifts' spacing.
    h: f64,
}

impl<'m> Search<'m> {
    fn new(matrix: &'m HillMatrix, options: &HillOptions, omega: f64, period: f64) -> Self {
        Self {
            matrix,
            omega,
            delta: options.tolerance.ln_1p() / period,
            rho: options.max_modulus.ln() / period,
            h: omega / options.shifts_per_frequency as f64,
        }
    }

    fn run(&self) -> Result<Found, StabilityError> {
        let h = self.h;
        let columns = (self.rho / h).ceil().max(1.0) as usize;
        let rows = (self.omega / h).round() as usize + 1;
        let mut found = Found {
            all: Vec::new(),
            near_zero: Vec::new(),
            shifts: 0,
            refined: 0,
        };
        // Every refined exponent, so that one seen from several shifts is refined once
        // (two within `SAME_EXPONENT h` of each other are taken for one).
        let mut seen: Vec<c64> = Vec::new();
        for a in 0..columns {
            for b in 0..rows {
                let shift = c64::new((a as f64 + 0.5) * h, -0.5 * self.omega + b as f64 * h);
                found.shifts += 1;
                for (prediction, vector) in self.candidates(shift)? {
                    if seen
                        .iter()
                        .any(|s| (s - prediction).norm() < SAME_EXPONENT * h)
                    {
                        continue;
                    }
                    found.refined += 1;
                    let Some((lambda, vector)) = self.refine(prediction, vector) else {
                        continue;
                    };
                    seen.push(lambda);
                    if lambda.re > 2.0 * self.rho {
                        // Beyond the box (a refinement that went far): not searched for.
                        continue;
                    }
                    let folded = self.fold(lambda);
                    let known = |(e, _): &(c64, f64)| (e - folded).norm() < 1e-6 * self.omega;
                    if !found.all.iter().any(known) {
                        found
                            .all
                            .push((folded, self.matrix.high_harmonic_share(&vector)));
                        if folded.norm() < 0.25 * h {
                            found.near_zero.push((folded, vector));
                        }
                    }
                }
            }
        }
        Ok(found)
    }

    /// `lambda` moved by whole `i Omega` into `(-Omega / 2, Omega / 2]`.
    fn fold(&self, lambda: c64) -> c64 {
        let k = (lambda.im / self.omega).round();
        let mut im = lambda.im - k * self.omega;
        if im <= -0.5 * self.omega {
            im += self.omega;
        }
        c64::new(lambda.re, im)
    }

    /// The eigenvalues of the linearisation at `shift` within [`TRUST_RADIUS`] `h` of it
    /// and not left of `Re lambda = -h / 4`, with their eigenvectors. The disks of
    /// neighbouring shifts overlap: an exponent whose prediction from the nearest shift is
    /// off is still predicted from another (taking only each shift's own cell missed
    /// instabilities of 6 of the clamped bar's 40 points).
    fn candidates(&self, shift: c64) -> Result<Vec<(c64, Col<c64>)>, StabilityError> {
        let (h, dh) = self.matrix.at(shift);
        let n = h.nrows();
        // (H + eps H') v = 0  <=>  H^-1 H' v = theta v with eps = -1 / theta; the rows that
        // do not depend on lambda give theta = 0 (no exponent).
        let k = h.partial_piv_lu().solve(&dh);
        if !k.is_all_finite() {
            // The shift is an exponent itself (to rounding): its neighbours find it.
            return Ok(Vec::new());
        }
        let eigen = k
            .eigen()
            .map_err(|_| StabilityError::NoEigenvalues { dimension: n })?;
        let (theta, vectors) = (eigen.S(), eigen.U());
        let mut out = Vec::new();
        let reach = TRUST_RADIUS * self.h;
        for j in 0..n {
            if theta[j].norm() * reach < 1.0 {
                continue;
            }
            let lambda = shift - c64::new(1.0, 0.0) / theta[j];
            if lambda.re > -0.25 * self.h && lambda.is_finite() {
                out.push((lambda, vectors.col(j).to_owned()));
            }
        }
        Ok(out)
    }

    /// Inverse iteration for the nonlinear eigenproblem from `lambda` and `v`; `None` when
    /// it does not converge.
    fn refine(&self, mut lambda: c64, mut v: Col<c64>) -> Option<(c64, Col<c64>)> {
        let w = v.clone();
        let scale = w.squared_norm_l2();
        if scale.is_nan() || scale <= 0.0 {
            return None;
        }
        v /= faer::Scale(c64::new(scale, 0.0));
        for _ in 0..REFINE_ITERATIONS {
            let (h, dh) = self.matrix.at(lambda);
            let rhs = &dh * &v;
            let u = h.partial_piv_lu().solve(&rhs);
            let wu = w.adjoint() * &u;
            let step = c64::new(1.0, 0.0) / wu;
            if !step.is_finite() {
                return lambda.is_finite().then_some((lambda, v));
            }
            lambda -= step;
            v = u * faer::Scale(step);
            if step.norm() <= REFINE_TOLERANCE * self.omega {
                return Some((lambda, v));
            }
        }
        None
    }
}
