//! Exact nonsmooth modes: branches of periodic orbits of the exact one-period map of the
//! time-domain integrator, continued in the period, with a Floquet verdict at every point.
//!
//! # Why
//!
//! Harmonic balance truncates: its strain jumps carry a Gibbs oscillation, so its points are
//! only near periodic orbits of the exact map, and correcting each one on its own
//! ([`stability`](crate::stability)) converges where the truncation happens to be mild. An
//! exact branch corrects **one** harmonic-balance point (the seed) and then continues the
//! exact orbit itself: each point starts from the previous exact orbit, so the corrector
//! starts within the step's change of the motion, not within the truncation's error.
//!
//! # Through the request
//!
//! [`Request::with_exact`](crate::branches::Request::with_exact) asks
//! [`compute`] for the exact branch of the run's mode over its period
//! grid: the harmonic-balance points come first (they seed it), and the branch is
//! [`ModeBranches::exact`](crate::branches::ModeBranches::exact), beside them. A refinement
//! of the request rather than a method of its own, because it needs a harmonic-balance run
//! (any method) to seed it, and because the two answers are worth comparing point by point
//! ([`ExactPoint::harmonic_balance_distance`]). Its points are [`BackbonePoint`](crate::branches::BackbonePoint)s
//! ([`ExactPoint::point`]), so what reads a backbone reads them. [`exact_branch`] gives the
//! branch alone, [`exact_branch_from`] from a run already there.
//!
//! ```no_run
//! use nonsmooth_modes::branches::{compute, Request};
//! use nonsmooth_modes::exact::ExactOptions;
//! use nonsmooth_modes::reference::clamped_bar_with_obstacle;
//!
//! let system = clamped_bar_with_obstacle(1e-3)?;
//! let run = compute(&system, &Request::new(1).with_exact(ExactOptions::default()))?;
//! if let Some(Ok(exact)) = &run.exact {
//!     for p in &exact.points {
//!         let verdict = p.point.stability.as_ref().map(|s| s.as_ref().map(|f| f.verdict));
//!         println!("T = {}: E/E_g = {}, {verdict:?}", p.point.period, p.point.energy_normalized);
//!     }
//! }
//! # Ok::<(), nonsmooth_modes::Error>(())
//! ```
//!
//! # The map and its grid
//!
//! The map is [`stability`](crate::stability)'s `P_T: X(0) -> X(T)` in the same coordinates
//! (cell means of `c u_x` and `u_t`, free end displacements), at an instant where every
//! contact is open. The whole branch uses **one grid** ([`ExactOptions::stability`]'s
//! `cells_per_travel` is a minimum): the cell count is the smallest from that minimum to
//! twice it that makes every requested period a whole number of steps, so that the
//! coordinates never change along the branch (the monodromy of one point is the corrector's
//! matrix at the next) and no period ends with a fractional step (which would project the
//! waves onto the cells and blur the multipliers). Where no count makes them whole, the
//! periods are rounded to whole steps ([`ExactPoint::requested_period`] keeps the grid's);
//! the clamped bar's grid `3.95 -> 3.05` is whole at 200 cells, the free–free bar's
//! `1.975 -> 1.525` at 400. A finer count is tried only where its matrices stay within the
//! limits of [`stability`](crate::stability). [`ExactOptions::for_request`] chooses the
//! minimum a system can afford: 200 cells per shortest travel time, or fewer where bars of
//! longer travel times would make the matrices too large.
//!
//! # Predictor and corrector
//!
//! The period is the continuation parameter; the energy is measured on the orbit found. The
//! predictor is the secant through the last two orbits in `(X, T)` (the previous orbit alone
//! after a seed or a gap). The corrector takes Levenberg–Marquardt steps of
//! `(M - I) d = X - P_T(X)` within a trust radius, with `M` the **previous orbit's
//! monodromy**, factored once (a chord method): each step costs one march instead of the
//! `2 n` of a fresh matrix. Where a step does not halve the defect, `M` is recomputed at the
//! current state (at most [`ExactOptions::refreshes`] times per point). The step has no
//! component along the null direction of `M - I`, the time shift (so no phase condition is
//! needed), and the trust radius damps it first along the small singular values: the family
//! direction and the waves that free flight carries nearly back onto themselves over the
//! period, a continuum with no gap where a cutoff could tell them from real directions;
//! moving far along them would change the motion rather than correct it. A point counts when its defect
//! `|P(X) - X| / |X|` is at most [`RESOLVED_DEFECT`](crate::stability::RESOLVED_DEFECT).
//!
//! The section drifts along the orbit from point to point (the steps have no phase
//! condition); where its smallest gap falls below a quarter of the law's gap, the state is
//! moved to the widest-open instant of its orbit again before its monodromy is computed.
//!
//! # Events: another family, a lost branch
//!
//! A corrected orbit whose energy leaves the predicted energy (the secant's; without a
//! secant, the previous energy times harmonic balance's ratio between the two periods) by
//! more than the predicted change plus [`ExactOptions::max_energy_jump`] (by more than
//! [`ExactOptions::first_step_jump`] where nothing predicts a change) has jumped onto another
//! family of periodic orbits (they meet at branch points, and at a fixed period the map has
//! several near one another): it is corrected once more from the previous orbit with a fresh
//! matrix. If it still jumps, or the correction fails, a step over more than one step of the
//! grid is **halved** (an orbit at the whole number of steps half-way, not reported, then on
//! from it). Otherwise the branch is **lost** at that period and reseeded from the
//! harmonic-balance point there (a new [`BackbonePoint::branch`](crate::branches::BackbonePoint::branch) index and an
//! [`Event::Jump`](crate::continuation::Event::Jump) on its first point); where that fails
//! too, the period is skipped with its reason ([`ExactBranch::skipped`]).
//!
//! The walk goes in segments: a seed at the first period whose harmonic-balance point
//! corrects to an orbit within the seed bounds of
//! [`StabilityOptions`](crate::stability::StabilityOptions) (energy and displacement,
//! [`ExactOptions::seed_attempts`] tries), the walk back from it to the segment's first
//! period, then forward until [`ExactOptions::max_lost`] periods in a row are skipped; the
//! next segment is sought after them. [`ExactBranch::end`] says why the last one ended
//! ([`ExactEnd::Lost`], [`ExactEnd::NoSeed`]); every point found is kept.
//!
//! # Where the grid's map has no periodic orbit
//!
//! The march is exact for the cells' piecewise-constant waves, but an impact between two
//! steps of the grid puts a breakpoint inside a cell, and the map returns the cell means of
//! the state after the period: they remove the energy of what is finer than a cell (the
//! march conserves it otherwise). An orbit of the map must then lose nothing, so its impacts
//! must fall on the steps. The exact families of the clamped bar and of the free–free bar
//! between walls do, on a grid that makes their period a whole number of steps. A spring end
//! or bars of other travel times put the impacts anywhere, and the corrector stalls at a
//! defect no step can lower: such a failure is
//! [`UnresolvedReason::OffGrid`](crate::stability::UnresolvedReason::OffGrid), with the
//! share of the energy the cell means remove (on the Robin bar's seeds, `4e-4`). This is
//! what keeps the Robin bar and the paper's two-bar configuration without an exact branch:
//! what would give them one is a section whose coordinates keep the breakpoints, not a
//! better corrector.
//!
//! # The verdict
//!
//! One monodromy per point, at the corrected orbit: its eigenvalues give the verdict exactly
//! as [`floquet_of_state`](crate::stability::floquet_of_state) does (trivial pair,
//! tolerance, the grid's damping on periods of an odd number of steps; no other
//! differences' steps: each costs a monodromy), and its factored `M - I` is the next point's
//! corrector.
//! Where the integrator merged wave pieces over the period (incommensurate travel times,
//! chattering), the energy removed is reported ([`ExactPoint::removed_energy`]) and the point
//! gets a verdict only below [`ExactOptions::max_removed_energy`]
//! ([`UnresolvedReason::Merged`](crate::stability::UnresolvedReason::Merged) beyond).
//!
//! # Cost
//!
//! Per point: one monodromy (`2 n` marches of a period, parallel with the `parallel`
//! feature), its eigenvalues and one singular value decomposition, a few single marches for
//! the chord steps, and a fresh monodromy where the chord stalls. The seed costs a shooting
//! correction (several monodromies).

mod corrector;
pub(crate) mod from_run;
mod grid;
pub(crate) mod options;
mod point;
pub(crate) mod types;
mod walk;

pub use from_run::exact_branch_from;
pub(crate) use from_run::period_grid;
pub use options::ExactOptions;
pub use types::{ExactBranch, ExactEnd, ExactPoint, LossReason, Skipped};

use crate::branches::{compute, Request};
use crate::error::{Error, SettingsError};
use crate::system::BarSystem;

/// The exact branch of `request`'s mode over its period grid, alone: the harmonic-balance run
/// of `request` ([`compute`], without its stability, Hill exponents and exact branch), then
/// [`exact_branch_from`] it. [`Request::with_exact`] asks [`compute`] for the same branch
/// beside the harmonic-balance points.
///
/// # Errors
/// A bad grid ([`SettingsError::Range`]) or options
/// ([`StabilityError::InvalidOption`](crate::stability::StabilityError::InvalidOption))
/// before anything is computed; those of [`compute`]; those of [`exact_branch_from`].
pub fn exact_branch(
    system: &BarSystem,
    request: &Request,
    options: &ExactOptions,
) -> Result<ExactBranch, Error> {
    let grid = period_grid(system, request)?;
    grid.validate().map_err(SettingsError::from)?;
    options.check()?;
    let harmonic_balance = Request {
        stability: None,
        hill: None,
        exact: None,
        ..request.clone()
    };
    exact_branch_from(&compute(system, &harmonic_balance)?, &grid, options)
}
