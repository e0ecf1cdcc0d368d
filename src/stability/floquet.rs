//! Floquet multipliers of a monodromy matrix, and what they say.

use super::monodromy::Monodromy;
use super::shooting::Corrected;
use crate::error::StabilityError;

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

/// Where a multiplier outside the unit circle sits: how it left the circle along a branch.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Crossing {
    /// Real and positive: it left through `+1` (a fold of the family or a symmetry-breaking
    /// branch point).
    ThroughPlusOne,
    /// Real and negative: it left through `-1` (a period-doubling).
    ThroughMinusOne,
    /// A complex pair (a Neimark–Sacker or, in a conservative system, Krein collision).
    ComplexPair,
}

impl Crossing {
    /// `+1`, `-1` or `complex`.
    pub fn name(&self) -> &'static str {
        match self {
            Crossing::ThroughPlusOne => "+1",
            Crossing::ThroughMinusOne => "-1",
            Crossing::ComplexPair => "complex",
        }
    }
}

/// What the multipliers say about a motion.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Verdict {
    /// Every multiplier lies inside the unit circle or within the tolerance outside it.
    Stable,
    /// A multiplier lies outside, where the crossing says.
    Unstable(Crossing),
    /// The state could not be corrected to a periodic orbit of the grid's map near the
    /// point's own motion: the multipliers (still reported) describe no motion of the point.
    Unresolved,
}

impl Verdict {
    /// `Some(true)` when stable, `Some(false)` when unstable, `None` when unresolved.
    pub fn stable(&self) -> Option<bool> {
        match self {
            Verdict::Stable => Some(true),
            Verdict::Unstable(_) => Some(false),
            Verdict::Unresolved => None,
        }
    }

    /// `stable`, `unstable` or `unresolved`.
    pub fn name(&self) -> &'static str {
        match self {
            Verdict::Stable => "stable",
            Verdict::Unstable(_) => "unstable",
            Verdict::Unresolved => "unresolved",
        }
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
    /// of that error), `max |mu|` otherwise.
    pub max_multiplier: f64,
    /// Stable when every multiplier lies within
    /// [`StabilityOptions::tolerance`](super::StabilityOptions::tolerance) of the unit circle
    /// or inside it, unresolved when the state is not a periodic orbit near the point.
    pub verdict: Verdict,
    /// The larger `|mu - 1|` of the two multipliers nearest 1: the trivial pair of the time
    /// shift and the family direction (a Jordan block at 1), which the differences' error
    /// splits by about its square root. Within the tolerance, the pair is set to exactly 1 in
    /// [`Floquet::multipliers`].
    pub trivial_distance: f64,
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

/// The larger `|mu - 1|` of the two multipliers nearest 1 (`inf` without two).
pub(crate) fn trivial_pair_distance(multipliers: &[Multiplier]) -> f64 {
    nearest_one(multipliers)
        .get(1)
        .map_or(f64::INFINITY, |&i| multipliers[i].distance_to_one())
}

/// Sets the two multipliers nearest 1 to exactly 1 when both lie within `tolerance` of it:
/// the time shift and the family direction of a conservative autonomous system make 1 a
/// double multiplier (a Jordan block), which the differences' error `e` splits by about
/// `sqrt(e)`, so that the computed pair carries no information beyond that error. Returns
/// the larger of their distances to 1 (`inf` without two multipliers), and keeps the list
/// sorted by decreasing modulus.
fn snap_trivial_pair(multipliers: &mut [Multiplier], tolerance: f64) -> f64 {
    let [first, second, ..] = nearest_one(multipliers)[..] else {
        return f64::INFINITY;
    };
    let distance = multipliers[second].distance_to_one();
    if distance <= tolerance {
        for i in [first, second] {
            multipliers[i] = Multiplier { re: 1.0, im: 0.0 };
        }
        multipliers.sort_by(|a, b| b.modulus().total_cmp(&a.modulus()));
    }
    distance
}

/// The verdict of `multipliers` (largest modulus first) at `tolerance`, for a state
/// `corrected` to a periodic orbit (`periodic` when the correction succeeded). The verdict
/// is resolved only when the state is periodic and the trivial pair is found within
/// `tolerance`: where the differences cannot find it, they are not accurate enough for the
/// others either (an event whose timing is singular, such as a grazing impact).
pub(crate) fn verdict(
    mut multipliers: Vec<Multiplier>,
    tolerance: f64,
    dimension: usize,
    dt: f64,
    period: f64,
    corrected: &Corrected,
    periodic: bool,
) -> Floquet {
    let trivial_distance = snap_trivial_pair(&mut multipliers, tolerance);
    let resolved = periodic && trivial_distance <= tolerance;
    let max_modulus = multipliers.first().map_or(0.0, Multiplier::modulus);
    let verdict = match multipliers.first() {
        _ if !resolved => Verdict::Unresolved,
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
        trivial_distance,
        dimension,
        dt,
        initial_defect: corrected.initial_defect,
        periodicity_defect: corrected.defect,
        correction: corrected.shift,
        displacement_correction: corrected.displacement_shift,
        energy_correction: corrected.energy_change,
        period,
    }
}
