//! Floquet multipliers of a monodromy matrix, and what they say.

use super::monodromy::Monodromy;
use super::shooting::Corrected;
use crate::error::StabilityError;
use crate::verdict::Crossing;
use crate::verdict::Verdict;

/// A Floquet multiplier `mu = re + i im`.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Multiplier {
    /// Real part.
    pub re: f64,
    /// Imaginary part.
    pub im: f64,
}

impl Multiplier {
    /// `|mu|`.
    pub fn modulus(&self) -> f64 {
        self.re.hypot(self.im)
    }

    /// `|mu - 1|`.
    fn distance_to_one(&self) -> f64 {
        (self.re - 1.0).hypot(self.im)
    }
}

/// The multipliers of a point and the verdict.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Floquet {
    /// The physical multipliers, largest modulus first.
    pub multipliers: Vec<Multiplier>,
    /// `max |mu|`, as computed.
    pub max_modulus: f64,
    /// The largest modulus with every multiplier within the tolerance of the unit circle
    /// counted as on it: exactly 1 for a stable point (a conservative motion has
    /// multipliers on the circle; the grid's projection pulls some inward and the
    /// differences' error splits the multiple multiplier 1 by up to about the square root
    /// of that error), `max |mu|` otherwise. Of an unresolved point it means nothing (the
    /// monodromy of a state that is not periodic has moduli such as `sqrt 2` or the golden
    /// ratio, from the order of its events): writers leave it out.
    pub max_multiplier: f64,
    /// Stable when every multiplier lies within
    /// [`StabilityOptions::tolerance`](super::StabilityOptions::tolerance) of the unit circle
    /// or inside it, unresolved when the state is not a periodic orbit near the point or the
    /// trivial pair is not found (and not explained by the grid's damping,
    /// [`Floquet::damping`]).
    pub verdict: Verdict,
    /// Why the verdict is [`Verdict::Unresolved`]: `Some` exactly then.
    pub unresolved: Option<UnresolvedReason>,
    /// The larger `|mu - 1|` of the two multipliers nearest 1: the trivial pair of the time
    /// shift and the family direction (a Jordan block at 1), which an error `e` of the matrix
    /// splits by about `sqrt(e)`. When the pair is found, it is set to exactly 1 in
    /// [`Floquet::multipliers`].
    pub trivial_distance: f64,
    /// Where the pair lies beyond the tolerance: the size of the perturbation of the
    /// monodromy matrix that makes it the double multiplier 1, `|(mu_1 + mu_2) / 2 - 1| +
    /// |mu_1 - mu_2| sin(theta) / 2` with `theta` the angle between the two eigenvectors
    /// (Wilkinson's estimate of the distance to a double eigenvalue, within a factor 2; see the
    /// [module docs](super#the-trivial-pair)). The pair is found when this is within the
    /// tolerance: the error that splits it is then no larger than the error the verdict
    /// allows every other multiplier. `None` where the pair lies within the tolerance, where
    /// the state is not periodic, or where the grid's damping explains the miss
    /// ([`Floquet::damping`]).
    pub trivial_perturbation: Option<f64>,
    /// Where the trivial pair is missed only because the grid damps the directions next to
    /// the time shift (a period of an odd number of steps; see the
    /// [module docs](super#the-trivial-pair)): `1 - |mu|` of the multiplier nearest 1 after
    /// the time shift, at most
    /// [`StabilityOptions::max_damping`](super::StabilityOptions::max_damping). The verdict
    /// is then stable (nothing lies outside the circle) for growth faster than this per
    /// period; slower growth would be hidden. `None` where the pair is found.
    pub damping: Option<f64>,
    /// Rows of the monodromy matrix.
    pub dimension: usize,
    /// The time step of the grid.
    pub dt: f64,
    /// The period of the one-period map. For a harmonic-balance point
    /// ([`floquet`](super::floquet)), the point's own rounded to a whole number of steps of a grid
    /// chosen to make the rounding small (`|change| < 1e-4` of the period on the clamped
    /// bar at 200 cells).
    pub period: f64,
    /// How periodic the state was on the grid before its correction: `|P(X) - X| / |X|` in
    /// coordinates.
    pub initial_defect: f64,
    /// `|P(X) - X| / |X|` at the state whose multipliers these are, after the correction.
    /// The multipliers describe a motion only where this is small.
    pub periodicity_defect: f64,
    /// `|X - X0| / |X0|`: how far the correction moved the state from the point's own.
    pub correction: f64,
    /// `max |u - u0| / max |u0|` over the nodes: how far the correction moved the
    /// displacement (the state norm also counts the strain's Gibbs oscillation, which
    /// decays only like `m^-1/2` with the harmonics).
    pub displacement_correction: f64,
    /// `(E - E0) / E0`: how far the correction moved the energy (on the grid).
    pub energy_correction: f64,
}

/// The eigenvalues of `monodromy`, largest modulus first.
pub(crate) fn eigenvalues(monodromy: &Monodromy) -> Result<Vec<Multiplier>, StabilityError> {
    let n = monodromy.nrows();
    let values = monodromy
        .eigenvalues()
        .map_err(|_| StabilityError::NoEigenvalues { dimension: n })?;
    let mut multipliers: Vec<Multiplier> = values
        .iter()
        .map(|z| Multiplier { re: z.re, im: z.im })
        .collect();
    multipliers.sort_by(|a, b| b.modulus().total_cmp(&a.modulus()));
    Ok(multipliers)
}

/// The indices of `multipliers`, nearest 1 first.
fn nearest_one(multipliers: &[Multiplier]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..multipliers.len()).collect();
    order.sort_by(|&a, &b| {
        let (a, b) = (&multipliers[a], &multipliers[b]);
        a.distance_to_one().total_cmp(&b.distance_to_one())
    });
    order
}

/// Removes the `count` multipliers nearest 1 (exact invariants of the coordinates, not of
/// the motion).
pub(crate) fn remove_nearest_one(multipliers: &mut Vec<Multiplier>, count: usize) {
    let mut removed: Vec<usize> = nearest_one(multipliers).into_iter().take(count).collect();
    removed.sort_unstable_by(|a, b| b.cmp(a));
    for i in removed {
        multipliers.remove(i);
    }
}

/// How nearly the two multipliers nearest 1 are the double multiplier 1 of the time shift
/// and the family direction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct TrivialPair {
    /// The larger `|mu - 1|` of the two (`inf` without two).
    pub distance: f64,
    /// The size of the perturbation of the monodromy matrix that makes the pair the double
    /// multiplier 1 ([`pair_perturbation`]); computed only where `distance` exceeds the
    /// tolerance (`None` otherwise, or without two multipliers).
    pub perturbation: Option<f64>,
}

impl TrivialPair {
    /// How far the pair is from the double multiplier 1: the smaller of its distance and the
    /// perturbation.
    pub(crate) fn miss(&self) -> f64 {
        self.perturbation
            .map_or(self.distance, |p| p.min(self.distance))
    }

    /// Whether the pair is found at `tolerance`.
    pub(crate) fn found(&self, tolerance: f64) -> bool {
        self.miss() <= tolerance
    }
}

/// The trivial pair of `multipliers` (the eigenvalues of `monodromy` without its `spurious`
/// exact multipliers 1), with the perturbation computed when `refine` and the pair lies
/// farther than `tolerance` from 1.
pub(crate) fn trivial_pair(
    monodromy: &Monodromy,
    multipliers: &[Multiplier],
    spurious: usize,
    tolerance: f64,
    refine: bool,
) -> Result<TrivialPair, StabilityError> {
    let distance = nearest_one(multipliers)
        .get(1)
        .map_or(f64::INFINITY, |&i| multipliers[i].distance_to_one());
    let perturbation = if refine && distance > tolerance && distance.is_finite() {
        pair_perturbation(monodromy, spurious)?
    } else {
        None
    };
    Ok(TrivialPair {
        distance,
        perturbation,
    })
}

/// The size of the perturbation of `monodromy` that makes its two multipliers nearest 1
/// (after the `spurious` exact ones) the double multiplier 1, to within a factor 2:
///
/// `|(mu_1 + mu_2) / 2 - 1| + |mu_1 - mu_2| sin(theta) / 2`,
///
/// `theta` the angle between their eigenvectors. The second term is Wilkinson's estimate
/// `|mu_1 - mu_2| / (kappa_1 + kappa_2)` of the distance to the nearest matrix with a double
/// eigenvalue, with the pair's condition numbers `kappa = 1 / sin(theta)` in its invariant
/// subspace; the first moves the double eigenvalue to 1. For a Jordan block `[[1, c], [0, 1]]`
/// perturbed by `e` below the diagonal, the multipliers are `1 +- sqrt(c e)` and the
/// eigenvectors `(1, +-sqrt(e / c))`, so `sin(theta) ~ 2 sqrt(e / c)` and the estimate is
/// `2 e`, whatever the coupling `c`: the split is the square root of the error, the estimate
/// the error itself. For two simple multipliers `1 +- s` with orthogonal eigenvectors it is
/// `s`. `None` without two multipliers.
fn pair_perturbation(
    monodromy: &Monodromy,
    spurious: usize,
) -> Result<Option<f64>, StabilityError> {
    let n = monodromy.nrows();
    let eigen = monodromy
        .eigen()
        .map_err(|_| StabilityError::NoEigenvalues { dimension: n })?;
    let (values, vectors) = (eigen.S().column_vector(), eigen.U());
    let all: Vec<Multiplier> = values
        .iter()
        .map(|z| Multiplier { re: z.re, im: z.im })
        .collect();
    let Some(&[a, b]) = nearest_one(&all).get(spurious..spurious + 2) else {
        return Ok(None);
    };
    let sin = sine_between(
        (0..n)
            .map(|i| vectors[(i, a)])
            .map(|z| (z.re, z.im))
            .collect(),
        (0..n)
            .map(|i| vectors[(i, b)])
            .map(|z| (z.re, z.im))
            .collect(),
    );
    let (mu, nu) = (all[a], all[b]);
    let mean = (0.5 * (mu.re + nu.re) - 1.0).hypot(0.5 * (mu.im + nu.im));
    let split = (mu.re - nu.re).hypot(mu.im - nu.im);
    let perturbation = mean + 0.5 * split * sin;
    Ok(perturbation.is_finite().then_some(perturbation))
}

/// The sine of the angle between the complex vectors `x` and `y` (pairs `(re, im)`): the
/// norm of `y`'s part orthogonal to `x` over `|y|`, computed as a vector so that a small
/// angle keeps its digits (`sqrt(1 - cos^2)` would lose half of them).
fn sine_between(x: Vec<(f64, f64)>, y: Vec<(f64, f64)>) -> f64 {
    let norm = |v: &[(f64, f64)]| v.iter().map(|(re, im)| re * re + im * im).sum::<f64>();
    let (xx, yy) = (norm(&x), norm(&y));
    if xx == 0.0 || yy == 0.0 {
        return 1.0;
    }
    // conj(x) . y / |x|^2
    let (c_re, c_im) = x.iter().zip(&y).fold((0.0, 0.0), |(re, im), (a, b)| {
        (re + a.0 * b.0 + a.1 * b.1, im + a.0 * b.1 - a.1 * b.0)
    });
    let (c_re, c_im) = (c_re / xx, c_im / xx);
    let orthogonal: Vec<(f64, f64)> = x
        .iter()
        .zip(&y)
        .map(|(a, b)| {
            (
                b.0 - (c_re * a.0 - c_im * a.1),
                b.1 - (c_re * a.1 + c_im * a.0),
            )
        })
        .collect();
    (norm(&orthogonal) / yy).sqrt().min(1.0)
}

/// Sets the two multipliers nearest 1 to exactly 1 (the trivial pair, found), keeping the
/// list sorted by decreasing modulus.
fn snap_trivial_pair(multipliers: &mut [Multiplier]) {
    if let [first, second, ..] = nearest_one(multipliers)[..] {
        for i in [first, second] {
            multipliers[i] = Multiplier { re: 1.0, im: 0.0 };
        }
        multipliers.sort_by(|a, b| b.modulus().total_cmp(&a.modulus()));
    }
}

/// The grid's damping of the neutral directions, where it is all that keeps the trivial pair
/// from 1: the multiplier nearest 1 (the time shift) lies within `tolerance` of it, the next
/// lies inside the circle, and none lies outside `1 + tolerance`. Then `1 - |mu_2|`.
///
/// On a period of an odd number of steps the grid damps the family direction and the waves
/// near it (the clamped bar's `T = 3.945` at 200 cells: the time shift at `1 - 2e-5`, then
/// `0.978`, `0.976 +- 0.019 i`, ...), where a period of an even number of steps keeps them on
/// the circle. The damping is the grid's error near 1: growth slower than it would not show,
/// so a stable verdict stands for growth faster than it.
pub(crate) fn grid_damping(multipliers: &[Multiplier], tolerance: f64) -> Option<f64> {
    let order = nearest_one(multipliers);
    let (&shift, &next) = (order.first()?, order.get(1)?);
    let outside = multipliers.iter().any(|mu| mu.modulus() > 1.0 + tolerance);
    let inward = multipliers[next].modulus() < 1.0;
    (multipliers[shift].distance_to_one() <= tolerance && inward && !outside)
        .then(|| 1.0 - multipliers[next].modulus())
}

/// The size of the map whose multipliers are judged: rows of the matrix, time step, period.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct MapShape {
    pub dimension: usize,
    pub dt: f64,
    pub period: f64,
}

/// The verdict of `multipliers` (largest modulus first) at `tolerance`, for a state
/// `corrected` towards a periodic orbit, with its trivial pair `pair`. `failure` is why the
/// correction does not count (`None` when it reached a periodic orbit near the point). The
/// verdict is resolved only when the correction counts and the trivial pair is found: where
/// the differences cannot find it, they are not accurate enough for the others either (an
/// event whose timing is singular, such as a grazing impact).
///
/// A pair missed only inward, by at most `max_damping`, is the grid's damping
/// ([`grid_damping`]): the verdict is then stable where nothing lies outside the circle, and
/// [`Floquet::damping`] says by how much the grid damps.
pub(crate) fn verdict(
    mut multipliers: Vec<Multiplier>,
    (tolerance, max_damping): (f64, f64),
    pair: TrivialPair,
    failure: Option<UnresolvedReason>,
    corrected: &Corrected,
    shape: MapShape,
) -> Floquet {
    let found = pair.found(tolerance);
    let damping = match (&failure, found) {
        (None, false) => grid_damping(&multipliers, tolerance).filter(|d| *d <= max_damping),
        _ => None,
    };
    let unresolved = failure.or_else(|| {
        (!found && damping.is_none()).then(|| UnresolvedReason::TrivialPairMissing {
            distance: pair.distance,
            perturbation: pair.perturbation.unwrap_or(pair.distance),
            tolerance,
        })
    });
    if found && unresolved.is_none() {
        snap_trivial_pair(&mut multipliers);
    }
    let max_modulus = multipliers.first().map_or(0.0, Multiplier::modulus);
    let verdict = match multipliers.first() {
        _ if unresolved.is_some() => Verdict::Unresolved,
        Some(mu) if mu.modulus() > 1.0 + tolerance => {
            Verdict::Unstable(if mu.im.abs() > tolerance * mu.modulus() {
                Crossing::ComplexPair
            } else if mu.re > 0.0 {
                Crossing::ThroughPlusOne
            } else {
                Crossing::ThroughMinusOne
            })
        }
        _ => Verdict::Stable,
    };
    Floquet {
        multipliers,
        max_modulus,
        max_multiplier: if max_modulus <= 1.0 + tolerance {
            1.0
        } else {
            max_modulus
        },
        verdict,
        unresolved,
        trivial_distance: pair.distance,
        trivial_perturbation: pair.perturbation,
        damping,
        dimension: shape.dimension,
        dt: shape.dt,
        initial_defect: corrected.initial_defect,
        periodicity_defect: corrected.defect,
        correction: corrected.shift,
        displacement_correction: corrected.displacement_shift,
        energy_correction: corrected.energy_change,
        period: shape.period,
    }
}

/// Why a point's multipliers give no verdict ([`Verdict::Unresolved`]), with the numbers
/// that decided it. Its `Display` is one sentence without commas, fit for a CSV cell.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[non_exhaustive]
pub enum UnresolvedReason {
    /// The correction did not reach a periodic orbit of the grid's map: the defect
    /// `|P(X) - X| / |X|` of the best state stayed above the bound. The multipliers are
    /// those of the point's own state.
    NotPeriodic {
        /// The defect of the best state reached.
        defect: f64,
        /// [`RESOLVED_DEFECT`](super::RESOLVED_DEFECT).
        bound: f64,
        /// Newton iterations that decreased the defect.
        iterations: usize,
        /// The iterations allowed
        /// ([`StabilityOptions::corrections`](super::StabilityOptions::corrections)): fewer
        /// taken means that no step along the Newton direction decreased the defect.
        corrections: usize,
    },
    /// The correction ended above the bound at a state whose period ends with waves finer
    /// than the grid's cells: impacts between the grid's instants put breakpoints inside
    /// cells, and the cell means the map returns remove their energy (the march itself
    /// conserves it). A state that loses the share `projected` of its energy over a period
    /// has a defect of at least `1 - sqrt(1 - projected)` in the energy norm, so no correction
    /// of it reaches the bound: the grid's map has no periodic orbit there, and finer cells
    /// lower the loss (about in proportion to the step).
    OffGrid {
        /// The defect of the best state reached.
        defect: f64,
        /// The share of its energy the cell means at the end of its period remove.
        projected: f64,
        /// [`RESOLVED_DEFECT`](super::RESOLVED_DEFECT).
        bound: f64,
    },
    /// The periodic orbit reached has another energy than the point: another motion.
    EnergyMoved {
        /// `(E - E0) / E0`.
        change: f64,
        /// [`StabilityOptions::max_energy_correction`](super::StabilityOptions::max_energy_correction).
        bound: f64,
    },
    /// The periodic orbit reached has another displacement than the point: another motion.
    DisplacementMoved {
        /// `max |u - u0| / max |u0|`.
        change: f64,
        /// [`StabilityOptions::max_displacement_correction`](super::StabilityOptions::max_displacement_correction).
        bound: f64,
    },
    /// The differences did not find the double multiplier 1 of the time shift and the family
    /// direction (with any of the steps tried): a perturbation larger than the tolerance
    /// separates the pair from it, so the other multipliers are not accurate to the
    /// tolerance either.
    TrivialPairMissing {
        /// The larger `|mu - 1|` of the pair.
        distance: f64,
        /// The perturbation of the monodromy matrix that makes the pair the double
        /// multiplier 1 ([`Floquet::trivial_perturbation`]).
        perturbation: f64,
        /// [`StabilityOptions::tolerance`](super::StabilityOptions::tolerance).
        tolerance: f64,
    },
    /// The integrator merged wave pieces over the period (incommensurate travel times,
    /// chattering) and removed more energy than the bound: the map is blurred by about the
    /// square root of that share of the state, more than a verdict at the tolerance allows.
    Merged {
        /// The energy removed over one period, relative to the motion's.
        removed: f64,
        /// The bound ([`ExactOptions::max_removed_energy`](crate::exact::ExactOptions::max_removed_energy)).
        bound: f64,
    },
}

impl std::fmt::Display for UnresolvedReason {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            UnresolvedReason::NotPeriodic {
                defect,
                bound,
                iterations,
                corrections,
            } if iterations < corrections => write!(
                f,
                "no periodic orbit of the grid's map: the correction stalled at defect \
                 {defect:.1e} after {iterations} of {corrections} iterations (bound {bound:.0e})"
            ),
            UnresolvedReason::NotPeriodic {
                defect,
                bound,
                corrections,
                ..
            } => write!(
                f,
                "no periodic orbit of the grid's map: defect {defect:.1e} after all \
                 {corrections} correction iterations (bound {bound:.0e})"
            ),
            UnresolvedReason::OffGrid {
                defect,
                projected,
                bound,
            } => write!(
                f,
                "no periodic orbit of the grid's map: impacts between its steps leave waves \
                 finer than a cell whose means remove {projected:.1e} of the energy each period \
                 (defect {defect:.1e} for a bound of {bound:.0e})"
            ),
            UnresolvedReason::EnergyMoved { change, bound } => write!(
                f,
                "the periodic orbit reached has {:.1} % {} energy than the point (bound {:.1} %)",
                100.0 * change.abs(),
                if change < 0.0 { "less" } else { "more" },
                100.0 * bound
            ),
            UnresolvedReason::DisplacementMoved { change, bound } => write!(
                f,
                "the periodic orbit reached moves the displacement by {:.1} % (bound {:.1} %)",
                100.0 * change,
                100.0 * bound
            ),
            UnresolvedReason::TrivialPairMissing {
                distance,
                perturbation,
                tolerance,
            } => write!(
                f,
                "the trivial multiplier pair lies {distance:.1e} from 1 and is a perturbation \
                 of {perturbation:.1e} from the double multiplier 1 (tolerance {tolerance:.1e})"
            ),
            UnresolvedReason::Merged { removed, bound } => write!(
                f,
                "the integrator's merges removed {removed:.1e} of the energy over the period \
                 (bound {bound:.1e})"
            ),
        }
    }
}

#[cfg(test)]
mod tests;
