//! Floquet stability of computed modes, from the exact one-period map of the time-domain
//! integrator.
//!
//! # The map
//!
//! The integrator of [`verify`](crate::verify) advances the two characteristic waves of
//! every bar exactly; on its grid (a time step `dt`, `N_b` cells per bar) a state is the cell
//! means of `u_x` and `u_t` and the displacement `u(0)` of every bar. The one-period map
//! `P: X(0) -> X(T)` (the final waves projected back onto the cells) is **piecewise linear**:
//! linear while the sequence of impacts and releases keeps its order, with impact instants
//! that move continuously with the state. A periodic motion is a fixed point `P(X*) = X*`,
//! and its **monodromy matrix** `M = dP/dX (X*)` decides whether small perturbations grow:
//! the motion is (spectrally) stable when every eigenvalue `mu` of `M`, its Floquet
//! multipliers, has `|mu| <= 1`.
//!
//! `M` is computed column by column by central differences, `(P(X* + h e_j) - P(X* - h e_j))
//! / 2h`, with one step `h = 10^-4 |X*|_inf` for every coordinate. The coordinates are all
//! velocities (`u_t`, `c u_x`, `c u(0) / l`), so one step suits them all; with a step
//! proportional to the state, `M` is the same for a state and its gap scaled together (the
//! map is positively homogeneous of degree 1 in both). Inside a region where the order of the
//! contact events does not change, the differences are exact up to rounding and the
//! second-order change of the impact instants; a step that moves an event across a cell
//! boundary changes the map's piece only by `O(h)`. The multipliers are the eigenvalues of
//! the dense `M` (`faer`).
//!
//! # What a conservative autonomous system implies
//!
//! - The time shift of the motion is a fixed direction of `M`: `M X*' = X*'`, a multiplier 1.
//!   The family direction adds a Jordan block at 1; numerically the pair splits by about the
//!   square root of the differences' error ([`Floquet::trivial_distance`] reports the nearest;
//!   see [the trivial pair](#the-trivial-pair)).
//! - The map is symplectic, so multipliers come in pairs `mu`, `1 / conj(mu)`: an unstable
//!   motion has `|mu| > 1` and `1 / |mu|` both. No conservative motion has every multiplier
//!   strictly inside the circle, hence `max |mu| >= 1` (up to the differences' error).
//! - The grid's cell means are an `L2` projection: where breakpoints of the waves fall inside
//!   cells (impacts, incommensurate travel times) they pull multipliers slightly **inward**,
//!   never outward. A commensurate grid is preferred ([`Grid::nearest`]) so that free flight
//!   is an exact permutation of the cells, whose multipliers lie on the unit circle.
//! - A clamped end keeps its displacement: a clamped left end's `u(0)` is no coordinate,
//!   and a clamped right end's invariant displacement adds one exact multiplier 1, which is
//!   removed (the nearest to 1) before the verdict.
//!
//! # Which state: a periodic orbit of the map, near the point
//!
//! The multipliers describe a motion only at a fixed point of `P`. A harmonic-balance point
//! is not one: its strain jumps carry a Gibbs oscillation whose `L2` norm decays only like
//! `m^-1/2`, so its state misses periodicity by 10 to 30 % in the state norm at `m = 20`
//! on the clamped bar, while its displacement is within a few per cent. So the state is
//! first moved to an instant where every contact is open (where the smallest relative gap
//! is largest over one period: at an instant of closed contact the state sits on the
//! constraint `g = 0`, where `P` is not differentiable), then **corrected** by Newton
//! iterations on `P(X) - X = 0`, with `M` recomputed at each iterate
//! ([`StabilityOptions::corrections`]). Each step is the **minimum-norm** solution of
//! `(M - I) d = X - P(X)` over the singular values above `1e-4` of the largest: `M - I` is
//! singular along the time shift and nearly so along the family direction and, on a
//! commensurate grid, along every wave that free flight carries back onto itself over the
//! period; a step that moves along them changes the motion instead of correcting it (the
//! minimum-norm step is orthogonal to the time shift, so no phase condition is needed).
//! The verdict counts only when the corrected state is periodic (`|P(X) - X| <= 1e-8 |X|`,
//! [`RESOLVED_DEFECT`]), its displacement within
//! [`StabilityOptions::max_displacement_correction`] and its energy within
//! [`StabilityOptions::max_energy_correction`] of the point's own (a harmonic-balance point's
//! energy is accurate where its state is not: at a fixed period the exact map has several
//! periodic orbits near the point, and one with 10 % more energy in high harmonics is
//! another motion), and the trivial pair found ([below](#the-trivial-pair); where the
//! differences miss it, an event with singular timing, such as a grazing impact, or the
//! grid's projection makes them inaccurate for every multiplier): otherwise the point is [`Verdict::Unresolved`], with the
//! multipliers of its own state when the correction failed.
//!
//! # Why there is no verdict
//!
//! An unresolved point says why in [`Floquet::unresolved`], an [`UnresolvedReason`] with the
//! numbers, checked in this order:
//!
//! - [`UnresolvedReason::NotPeriodic`]: the correction ended above [`RESOLVED_DEFECT`]
//!   (the defect, and the iterations taken of those allowed: fewer means it stalled, no
//!   step along the Newton direction decreasing the defect);
//! - [`UnresolvedReason::OffGrid`] instead where that state's period ends with waves finer
//!   than a cell: its impacts fall between the grid's steps, the cell means the map returns
//!   remove a share of the energy (given), and so its defect cannot reach the bound. The
//!   clamped bar's and the free–free bar's families impact on the steps of a grid that makes
//!   their period whole; a spring end, or bars of other travel times, put the impacts
//!   anywhere (the Robin bar's points all end here);
//! - [`UnresolvedReason::EnergyMoved`], [`UnresolvedReason::DisplacementMoved`]: the
//!   periodic orbit reached is another motion (the change and the bound);
//! - [`UnresolvedReason::TrivialPairMissing`]: the pair's distance from 1, the perturbation
//!   of `M` it implies and the tolerance (below).
//!
//! Where the multipliers cannot be computed at all, [`floquet`] returns the
//! [`StabilityError`] instead (a grid over [`MAX_DIMENSION`] rows, marches over
//! [`MAX_MARCH_STEPS`] steps, a state at rest, a march or a decomposition that fails). Each
//! reason's `Display` is one sentence without commas. The multipliers of an unresolved point
//! are kept for inspection, but its [`Floquet::max_multiplier`] means nothing: the
//! monodromy of a state that is not periodic has moduli such as `sqrt 2`, the golden ratio
//! or 2, set by the order of its events, not by the motion.
//!
//! # The trivial pair
//!
//! The time shift and the family direction make 1 a double multiplier with a Jordan block:
//! in an orthonormal basis of their invariant subspace `M` acts as `[[1, c], [0, 1]]`, `c`
//! the change of phase per period along the family. An error `E` of the computed matrix moves
//! the pair to `1 + tr(E) / 2 +- sqrt(c e_21)`: its mean by the error, its split by the
//! square root. The pair lying within the tolerance of 1 is then too strict a test: an
//! error of `1e-6` that leaves every simple multiplier accurate to the tolerance `1e-3`
//! already splits a pair with `c = 1` by `1e-3`. What the split does tell is the error,
//! through the eigenvectors: those of the perturbed block, `(1, +-sqrt(e_21 / c))`, close up
//! as the error vanishes. With `theta` the angle between the two eigenvectors,
//!
//! `delta = |(mu_1 + mu_2) / 2 - 1| + |mu_1 - mu_2| sin(theta) / 2`
//!
//! is Wilkinson's estimate of the distance from `M` to a matrix with the double multiplier 1
//! (`|mu_1 - mu_2| / (kappa_1 + kappa_2)`, with the condition numbers `kappa = 1 / sin(theta)`
//! of the pair, plus the move of their mean to 1): `2 e_21` for the perturbed Jordan block,
//! whatever `c`, and `s` for two simple multipliers `1 +- s` with orthogonal eigenvectors. The
//! pair is found when it lies within the tolerance of 1 or when `delta` does
//! ([`Floquet::trivial_perturbation`]): the error it implies is then no larger than the
//! error the verdict allows every other multiplier. A pair that is not a split double
//! multiplier (its eigenvectors far apart, `delta` close to the distance) means an error of
//! the map near 1 of about its distance, which no verdict at the tolerance survives. On the
//! clamped bar at `T = 3.945` (200 cells) the three steps of the differences put the family's
//! multiplier at `0.978`, `0.971` and `0.986` (the time shift's within `3e-4` of 1), with
//! `sin(theta) = 0.5` to `0.8` and its neighbours pulled inward alike (`0.983 +- 0.020 i`,
//! `0.981 +- 0.036 i`, ...): the multipliers near 1 change by `1.5e-2` with the step, and
//! `delta = 1.1e-2` says as much.
//!
//! On a period of an **odd number of steps** that error is mostly damping: the multipliers
//! next to the time shift are pulled inside the circle, by `2e-2` to `7e-2` on the clamped
//! bar and the free–free bar at 200 cells (on a period of an even number of steps they stay
//! on it; at 400 cells the clamped bar's `T = 3.945` is an even number of steps and its pair
//! is found). Where the time shift is found, the rest of the pair lies inside the circle by
//! at most [`StabilityOptions::max_damping`] and no multiplier lies outside
//! `1 + tolerance`, the verdict is stable and [`Floquet::damping`] gives that damping `d`:
//! the grid's error near 1, within which growth slower than `d` per period would not show.
//! Where a multiplier lies outside the circle as well (the same error can push one out, to
//! `1.005` on one orbit of the clamped bar's `T = 3.945`), the point stays unresolved.
//!
//! The verdict is **stable** when `max |mu| <= 1 + tolerance`
//! ([`StabilityOptions::tolerance`]).
//!
//! # Cost
//!
//! `2 n` marches of one period for `n` coordinates and a dense eigenvalue problem
//! (`O(n^3)`) per monodromy, one more monodromy and a singular value decomposition per
//! correction. `n` is about twice the
//! number of cells, [`StabilityOptions::cells_per_travel`] per shortest travel time
//! `l_b / c_b`; matrices of more than [`MAX_DIMENSION`] rows are refused
//! ([`StabilityError::TooLarge`]), and so are points whose marches would take more than
//! [`MAX_MARCH_STEPS`] time steps ([`StabilityError::TooCostly`]). The clamped bar at 200
//! cells takes about 0.2 s per monodromy (`cargo bench --bench stability`).

pub(crate) mod coordinates;
mod floquet;
pub mod hill;
mod judge;
pub(crate) mod monodromy;
pub(crate) mod shooting;

pub use crate::error::StabilityError;
pub use crate::verdict::{Crossing, Verdict};
pub use floquet::{Floquet, Multiplier, UnresolvedReason};
pub use hill::{
    hill, Exponent, HillOptions, HillSpectrum, HillUnresolved, HILL_RESIDUAL, MAX_HILL_DIMENSION,
    MIN_ALIGNMENT,
};

use crate::bar::shortest_travel_time;
use crate::fourier::{period_of_frequency, Basis};
use crate::system::BarSystem;
use crate::verify::{
    advance, check_fundamental_frequency, march, Condition, Grid, MarchOptions, Model,
    SpringUpdate, State, VerifyError,
};
use coordinates::Coordinates;
pub(crate) use judge::{correction_failure_on, judge};
use monodromy::PeriodMap;

/// The most rows of a monodromy matrix: its eigenvalues then take seconds and its storage
/// `8 n^2` bytes (200 MiB).
pub const MAX_DIMENSION: usize = 2000;

/// The most time steps the marches of one point's multipliers may take in all (about 20 s;
/// the 200-cell clamped bar takes `5e6`).
pub const MAX_MARCH_STEPS: f64 = 5e7;

/// The periodicity defect `|P(X) - X| / |X|` at which the correction stops: the rounding of
/// one period's march is about `1e-14` of the state.
pub const PERIODIC_DEFECT: f64 = 1e-11;

/// The other steps of the differences, relative to [`StabilityOptions::relative_step`], tried
/// in turn when the trivial pair is not found within the tolerance.
pub(crate) const STEP_FACTORS: [f64; 2] = [10.0, 0.1];

/// The largest periodicity defect of a corrected state whose multipliers count
/// ([`Verdict::Unresolved`] beyond).
pub const RESOLVED_DEFECT: f64 = 1e-8;

/// Options of [`floquet`] and [`floquet_of_state`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StabilityOptions {
    /// Cells across the bar of shortest travel time `l_b / c_b` (the grid's step is that
    /// travel time over this; default 200). The matrix has about `2 sum_b N_b` rows.
    pub cells_per_travel: f64,
    /// The differences' step relative to the state's largest coordinate (default `1e-4`:
    /// the map is linear between events, so a large step loses nothing there and keeps the
    /// rounding of the marches, about `1e-14` of the state, far below it).
    pub relative_step: f64,
    /// How far outside the unit circle a multiplier may lie and the point still count as
    /// stable (default `1e-3`): above the error of the differences, which splits the Jordan
    /// block at 1 by up to `2e-5` on the exact clamped family (`tests/stability.rs`).
    pub tolerance: f64,
    /// Update of ground springs: [`SpringUpdate::Midpoint`] by default, which conserves
    /// energy exactly, so that the grid adds no damping that would read as stability.
    pub spring: SpringUpdate,
    /// Newton iterations that correct the state to a periodic orbit of the grid's map before
    /// its multipliers are computed (default 8; 0: none). A harmonic-balance point is only
    /// near one, and the multipliers of a state that is not periodic describe no motion.
    pub corrections: usize,
    /// The largest change of displacement, `max |u - u0| / max |u0|`, by which the
    /// correction may move the point's state (default `0.05`, the time-domain check's
    /// bound): beyond, the periodic orbit found is another motion, and the verdict is
    /// [`Verdict::Unresolved`].
    pub max_displacement_correction: f64,
    /// The largest relative change of energy, `|E - E0| / E0`, by which the correction may
    /// move the point's state (default `0.05`). The energy of a harmonic-balance point is
    /// accurate where its state is not (the strain's Gibbs oscillation), so a periodic orbit
    /// with another energy is another motion, even with nearly the same displacement: at a
    /// fixed period, the correction can add energy in high harmonics. Beyond, the verdict is
    /// [`Verdict::Unresolved`].
    pub max_energy_correction: f64,
    /// The largest damping of the directions next to the time shift that a verdict accepts
    /// as the grid's (default `0.1`; see [`Floquet::damping`]): a stable verdict then hides
    /// growth slower than this per period. Where the damping is larger, or `0`, a missed
    /// trivial pair leaves the point unresolved.
    pub max_damping: f64,
}

impl Default for StabilityOptions {
    fn default() -> Self {
        Self {
            cells_per_travel: 200.0,
            relative_step: 1e-4,
            tolerance: 1e-3,
            spring: SpringUpdate::Midpoint,
            corrections: 8,
            max_displacement_correction: 0.05,
            max_energy_correction: 0.05,
            max_damping: 0.1,
        }
    }
}

impl StabilityOptions {
    pub(crate) fn check(&self) -> Result<(), StabilityError> {
        let checks = [
            (
                "cells_per_travel",
                "finite and at least 1",
                self.cells_per_travel,
                self.cells_per_travel >= 1.0,
            ),
            (
                "relative_step",
                "positive and below 1",
                self.relative_step,
                self.relative_step > 0.0 && self.relative_step < 1.0,
            ),
            (
                "tolerance",
                "finite and non-negative",
                self.tolerance,
                self.tolerance >= 0.0,
            ),
            (
                "max_displacement_correction",
                "finite and non-negative",
                self.max_displacement_correction,
                self.max_displacement_correction >= 0.0,
            ),
            (
                "max_energy_correction",
                "finite and non-negative",
                self.max_energy_correction,
                self.max_energy_correction >= 0.0,
            ),
            (
                "max_damping",
                "between 0 and 1",
                self.max_damping,
                (0.0..=1.0).contains(&self.max_damping),
            ),
        ];
        for (what, expected, value, ok) in checks {
            if !(ok && value.is_finite()) {
                return Err(StabilityError::InvalidOption {
                    what,
                    expected,
                    value,
                });
            }
        }
        Ok(())
    }

    /// The grid of a motion of period `period`, and the period rounded to a whole number of
    /// its steps. The step is the commensurate one nearest to the shortest travel time over
    /// `k` cells (that step itself when none is commensurate), for the `k` between
    /// `cells_per_travel` and a quarter more that brings the period nearest a whole number
    /// of steps: a period that ends between two steps ends with a fractional step, whose
    /// projection onto the cells blurs the map (on the clamped bar, no period of
    /// `785.5` steps gets a verdict where one of `786` does).
    pub(crate) fn grid(&self, model: &Model, period: f64) -> Result<(Grid, f64), StabilityError> {
        let travel = shortest_travel_time(model.bars());
        let first = self.cells_per_travel.ceil() as usize;
        let candidate = |k: usize| -> Result<(Grid, f64, f64), StabilityError> {
            let grid = Grid::nearest_or_new(model, travel / k as f64)?;
            let steps = (period / grid.dt()).round().max(1.0);
            let miss = (period - steps * grid.dt()).abs();
            Ok((grid, steps, miss))
        };
        let mut best = candidate(first)?;
        check_dimension(&Coordinates::new(model, &best.0), self.cells_per_travel)?;
        for k in first + 1..=(1.25 * first as f64).ceil() as usize {
            if best.2 <= 1e-12 * period {
                break;
            }
            let next = candidate(k)?;
            if next.2 < best.2 {
                best = next;
            }
        }
        let (grid, steps, _) = best;
        let period = steps * grid.dt();
        Ok((grid, period))
    }
}

/// The Floquet multipliers of the `period`-periodic motion starting at `initial`, on
/// `initial`'s grid (see the [module docs](self)).
///
/// # Errors
/// [`StabilityError::InvalidOption`] for options out of range; [`StabilityError::TooLarge`]
/// for a grid of more than [`MAX_DIMENSION`] coordinates; [`StabilityError::AtRest`] for a
/// state at rest; [`StabilityError::Verify`] if a march fails (a bad period, a march too
/// costly); [`StabilityError::NonFinite`] and [`StabilityError::NoEigenvalues`] if the
/// matrix or its eigenvalues cannot be computed; [`StabilityError::NonFiniteResult`] when a
/// defect or correction of a state near the ends of `f64` is not finite.
pub fn floquet_of_state(
    initial: &State,
    period: f64,
    options: &StabilityOptions,
) -> Result<Floquet, StabilityError> {
    options.check()?;
    let coordinates = Coordinates::new(initial.model(), initial.grid());
    check_dimension(&coordinates, options.cells_per_travel)?;
    if !(period.is_finite() && period > 0.0) {
        return Err(VerifyError::InvalidParameter {
            what: "period",
            value: period,
        }
        .into());
    }
    let steps = 2.0
        * coordinates.len() as f64
        * (period / initial.grid().dt()).ceil()
        * (1.0 + options.corrections as f64 + STEP_FACTORS.len() as f64);
    if steps.is_nan() || steps > MAX_MARCH_STEPS {
        return Err(StabilityError::TooCostly {
            steps,
            dimension: coordinates.len(),
            corrections: options.corrections,
            limit: MAX_MARCH_STEPS,
        });
    }
    let section = open_section(initial, period, options.spring)?;
    let map = PeriodMap {
        coordinates: &coordinates,
        template: &section,
        period,
        spring: options.spring,
    };
    let mut base = Vec::new();
    coordinates.of_snapshot(&section.snapshot(), &mut base);
    let (corrected, at_corrected, at_base) = map.correct(
        &base,
        options.relative_step,
        options.corrections,
        PERIODIC_DEFECT,
    )?;
    let failure = correction_failure_on(&map, &corrected, options)?;
    // A point whose correction failed keeps the multipliers of its own state: those of a
    // partial correction depend on the path the iterations took.
    let monodromy = match at_corrected {
        Some(at_corrected) if failure.is_none() => at_corrected,
        _ => at_base,
    };
    judge(
        &map,
        &corrected,
        &monodromy,
        failure,
        options,
        &STEP_FACTORS,
    )
}

/// [`StabilityError::TooLarge`] for more than [`MAX_DIMENSION`] coordinates.
pub(crate) fn check_dimension(
    coordinates: &Coordinates,
    cells_per_travel: f64,
) -> Result<(), StabilityError> {
    if coordinates.len() > MAX_DIMENSION {
        return Err(StabilityError::TooLarge {
            dimension: coordinates.len(),
            cells_per_travel,
            limit: MAX_DIMENSION,
        });
    }
    Ok(())
}

/// The state of the motion from `initial` at the instant of one period where the smallest
/// gap (relative to the law's own gap) is largest: there every contact is open, so the
/// one-period map is differentiable. At an instant of closed contact the state sits on the
/// constraint `g = 0` and its perturbations that penetrate are not motions.
pub(crate) fn open_section(
    initial: &State,
    period: f64,
    spring: SpringUpdate,
) -> Result<State, StabilityError> {
    let options = MarchOptions {
        spring,
        snapshot_every: 0,
    };
    match open_instant(initial, period, spring)? {
        t if t > 0.0 => Ok(advance(initial, t, &options)?),
        _ => Ok(initial.clone()),
    }
}

/// The instant of one period from `initial` where the smallest relative gap is largest.
fn open_instant(initial: &State, period: f64, spring: SpringUpdate) -> Result<f64, StabilityError> {
    let options = MarchOptions {
        spring,
        snapshot_every: 0,
    };
    let trajectory = march(initial, period, &options)?;
    let scales: Vec<f64> = trajectory
        .contacts
        .iter()
        .map(|h| {
            law_gap(initial.model(), h.condition)
                .abs()
                .max(f64::MIN_POSITIVE)
        })
        .collect();
    let widest = (0..trajectory.times.len())
        .map(|k| {
            let smallest = trajectory
                .contacts
                .iter()
                .zip(&scales)
                .map(|(h, s)| h.gap[k] / s)
                .fold(f64::INFINITY, f64::min);
            (k, smallest)
        })
        .max_by(|a, b| a.1.total_cmp(&b.1));
    Ok(match widest {
        Some((k, _)) if !trajectory.contacts.is_empty() => trajectory.times[k],
        _ => 0.0,
    })
}

/// The gap `g0` of condition `index` (0 for a linear condition).
pub(crate) fn law_gap(model: &Model, index: usize) -> f64 {
    match model.conditions()[index] {
        Condition::Obstacle { gap, .. }
        | Condition::CompliantObstacle { gap, .. }
        | Condition::Contact { gap, .. } => gap,
        _ => 0.0,
    }
}

/// The Floquet multipliers of a harmonic-balance point: the solution `x` (layout of
/// [`NonsmoothSystem`](crate::system::NonsmoothSystem), basis `basis`) at fundamental
/// frequency `omega`, started at `t = 0` on the grid of [`StabilityOptions`].
///
/// # Errors
/// As [`floquet_of_state`], and those of [`State::from_harmonic_balance`] and
/// [`Model::from_system`] (a condition the integrator does not model).
pub fn floquet<B: Basis>(
    system: &BarSystem,
    basis: &B,
    x: &[f64],
    omega: f64,
    options: &StabilityOptions,
) -> Result<Floquet, StabilityError> {
    options.check()?;
    check_fundamental_frequency(omega)?;
    let (grid, period) = options.grid(&Model::from_system(system)?, period_of_frequency(omega))?;
    let initial = State::from_harmonic_balance(system, basis, x, omega, 0.0, grid.dt())?;
    floquet_of_state(&initial, period, options)
}

/// Serializes a point's stability outcome: the report ([`Floquet`], [`HillSpectrum`]), or
/// `{"error": message}`.
#[cfg(feature = "serde")]
pub(crate) fn serialize_outcome<S: serde::Serializer, T: serde::Serialize, E: std::fmt::Display>(
    outcome: &Option<Result<T, E>>,
    serializer: S,
) -> Result<S::Ok, S::Error> {
    use serde::ser::SerializeMap;
    match outcome {
        None => serializer.serialize_none(),
        Some(Ok(report)) => serializer.serialize_some(report),
        Some(Err(error)) => {
            let mut map = serializer.serialize_map(Some(1))?;
            map.serialize_entry("error", &error.to_string())?;
            map.end()
        }
    }
}
