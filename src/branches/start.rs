//! Where a branch starts: the guesses of the energy and the period backbones alike (the
//! grazing seed of a linear mode at a few frequencies and amplitudes, with the motions of
//! floating bars added where the system has any), the start they lead to, and the walk back
//! along the branch of an arclength backbone whose start lies beyond the asked frequency.

use crate::branches::escape::{EscapingArclength, StallEscape};
use crate::branches::tether::tethered_start;
use crate::continuation::{
    Arclength, ArclengthOptions, Branch, ContinuationProblem, Event, Point, Rejection, Step,
};
use crate::error::{ContinuationError, Error, SettingsError};
use crate::fourier::Basis;
use crate::modal::drift::check_held;
use crate::modal::energy::energy;
use crate::modal::linear::{branch_seed, grazing_energy, open_mode, seed_from_mode};
use crate::solve::{NonlinearSolver, SmoothingHomotopy};
use crate::system::{BarSystem, HarmonicBalanceSettings, NonsmoothSystem};

pub(crate) use crate::branches::guesses::StartGuesses;
pub use crate::branches::guesses::{
    CLOSE_START_RATIOS, FLOATING_AMPLITUDES, FLOATING_RATIOS, RIGID_AMPLITUDES, START_AMPLITUDES,
    START_RATIOS,
};
use std::ops::ControlFlow;

/// What the solves of a start search came to: how many were tried, reached a solution the
/// search refused (the state of rest) or did not converge, and the highest frequency tried.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Tally {
    pub attempts: usize,
    pub refused: usize,
    pub failed: usize,
    pub up_to: f64,
}

impl Tally {
    /// The error of a search that found nothing, at the asked frequency `omega`.
    pub(crate) fn not_found(&self, omega: f64) -> SettingsError {
        SettingsError::StartNotFound {
            omega,
            up_to: self.up_to.max(omega),
            attempts: self.attempts,
            at_rest: self.refused,
            failed: self.failed,
        }
    }
}

/// The first of `guesses` that one of `solvers` (tried in turn on each guess) takes at
/// `omega` to a solution that `accept` takes; `tally` counts the solves.
pub(crate) fn first_solution(
    problem: &mut NonsmoothSystem,
    solvers: &[&dyn NonlinearSolver],
    guesses: impl IntoIterator<Item = Vec<f64>>,
    (omega, tally): (f64, &mut Tally),
    mut accept: impl FnMut(&mut NonsmoothSystem, &[f64]) -> bool,
) -> Option<Vec<f64>> {
    tally.up_to = tally.up_to.max(omega);
    for guess in guesses {
        for solver in solvers {
            let mut x = guess.clone();
            problem.set_parameter(omega);
            tally.attempts += 1;
            if solver.solve(problem, &mut x).is_err() {
                tally.failed += 1;
            } else if accept(problem, &x) {
                return Some(x);
            } else {
                tally.refused += 1;
            }
        }
    }
    None
}

/// The guess of a period backbone's first step at `omega`: the grazing seed where `solver`
/// takes it to a motion of energy above `floor` (the paper's three systems), else the first
/// such solution from the guesses of [`StartGuesses`] around the seed, at `omega` and then at
/// the higher frequencies of [`START_RATIOS`](crate::branches::START_RATIOS) (relative to the
/// first), walked back to `omega` in a few steps (as far as they converge). A seed that only
/// grazes can slide to rest (a floating bar resting against an obstacle, or an obstacle
/// whose grazing the rounding leaves just open), a slightly larger one cannot. At each
/// frequency every guess is solved by `solver` first, and only if none is accepted again
/// inside a [`SmoothingHomotopy`] (which costs several solves). On a system with floating
/// bars the guesses include the closing ones ([`StartGuesses::closing`]), and where none is
/// accepted the start is searched at half the harmonics and lifted ([`search_coarse`]). A
/// search that fails says what its solves came to. Returns the guess and the frequency it
/// was last solved at (`omega` for the seed).
///
/// # Errors
/// [`SettingsError::StartNotFound`] with what the solves came to, if no guess is accepted.
pub(crate) fn usable_start<S: NonlinearSolver>(
    problem: &mut NonsmoothSystem,
    solver: &S,
    (seed, subharmonic): (Vec<f64>, usize),
    omega: f64,
    floor: f64,
) -> Result<(Vec<f64>, f64), SettingsError> {
    let (system, basis) = (problem.system().clone(), problem.basis().clone());
    let above_rest_at = |at: f64| {
        let (system, basis) = (&system, &basis);
        move |_: &mut NonsmoothSystem, x: &[f64]| energy(system, basis, x, at) > floor
    };
    let mut tally = Tally::default();
    let only = [seed.clone()];
    if first_solution(
        problem,
        &[solver],
        only,
        (omega, &mut tally),
        above_rest_at(omega),
    )
    .is_some()
    {
        return Ok((seed, omega));
    }
    // The guesses need the rigid-body modes (an SVD): only a seed that slid to rest pays.
    let guesses = StartGuesses::new(&system);
    let homotopy = SmoothingHomotopy::new(solver);
    let mut found = search_guesses(
        problem,
        solver,
        (&guesses, (&seed, subharmonic)),
        omega,
        (floor, &mut tally),
    );
    if found.is_none() && guesses.floating() {
        found = search_coarse(
            problem,
            solver,
            (&seed, subharmonic),
            omega,
            (floor, &mut tally),
        );
    }
    let Some((mut x, from)) = found else {
        return Err(tally.not_found(omega));
    };
    // Walk the solution back to `omega` in a few steps, each from the last.
    const WALK: usize = 8;
    let solvers: [&dyn NonlinearSolver; 2] = [solver, &homotopy];
    let mut reached = from;
    for k in 1..=WALK {
        let at = from + (omega - from) * k as f64 / WALK as f64;
        let last = [x.clone()];
        match first_solution(problem, &solvers, last, (at, &mut tally), above_rest_at(at)) {
            Some(y) => (x, reached) = (y, at),
            None => break,
        }
    }
    Ok((x, reached))
}

/// The first of the guesses of `guesses` around `seed` that `solver` (and then `solver`
/// inside a [`SmoothingHomotopy`]) takes to a motion of energy above `floor`, at the
/// frequencies of [`StartGuesses::ratios`] relative to `omega`'s [`START_RATIOS`] in turn.
/// Returns the solution and its frequency; `tally` counts the solves.
fn search_guesses<S: NonlinearSolver>(
    problem: &mut NonsmoothSystem,
    solver: &S,
    (guesses, (seed, subharmonic)): (&StartGuesses, (&[f64], usize)),
    omega: f64,
    (floor, tally): (f64, &mut Tally),
) -> Option<(Vec<f64>, f64)> {
    let (system, basis) = (problem.system().clone(), problem.basis().clone());
    let above_rest_at = |at: f64| {
        let (system, basis) = (&system, &basis);
        move |_: &mut NonsmoothSystem, x: &[f64]| energy(system, basis, x, at) > floor
    };
    let homotopy = SmoothingHomotopy::new(solver);
    guesses.ratios().into_iter().find_map(|r| {
        let at = omega * r / START_RATIOS[0];
        let tries = guesses.around(problem, (seed, subharmonic), at, &RIGID_AMPLITUDES);
        first_solution(
            problem,
            &[solver],
            tries,
            (at, &mut *tally),
            above_rest_at(at),
        )
        .or_else(|| {
            let tries = guesses.around(problem, (seed, subharmonic), at, &RIGID_AMPLITUDES);
            first_solution(
                problem,
                &[&homotopy],
                tries,
                (at, &mut *tally),
                above_rest_at(at),
            )
        })
        .map(|x| (x, at))
    })
}

/// Fewest harmonics of a coarse truncation whose solutions are lifted to more harmonics:
/// the start search at half the harmonics on a system with floating bars, and the run of
/// [`Method::Auto`](crate::branches::Method::Auto) at half the harmonics where its runs fall
/// short ([`compute`](crate::branches::compute)). Below them the truncated motion is too
/// coarse to be lifted.
pub const MIN_COARSE_HARMONICS: usize = 10;

/// Where the search at the problem's harmonics `m` found nothing on a system with floating
/// bars: the start searched at `m / 2` harmonics (as [`usable_start`] does, itself down to
/// [`MIN_COARSE_HARMONICS`]), its solution lifted to `m` harmonics (the higher harmonics
/// zero) and solved there at the frequency it was found at, by `solver` and then inside a
/// [`SmoothingHomotopy`]. The more harmonics, the narrower the basin of a floating bar's
/// motion around the closing guesses; the coarse solution lies in it. Returns the solution
/// at `m` harmonics and its frequency, if the lifted solve is accepted (energy above
/// `floor`); `tally` counts the solves at both levels.
fn search_coarse<S: NonlinearSolver>(
    problem: &mut NonsmoothSystem,
    solver: &S,
    (seed, subharmonic): (&[f64], usize),
    omega: f64,
    (floor, tally): (f64, &mut Tally),
) -> Option<(Vec<f64>, f64)> {
    let basis = problem.basis().clone();
    let harmonics = basis.harmonics() / 2;
    if harmonics < MIN_COARSE_HARMONICS.max(subharmonic) {
        return None;
    }
    let settings = HarmonicBalanceSettings {
        harmonics,
        samples_per_harmonic: basis.samples() / basis.harmonics(),
        complementarity: problem.complementarity(),
        kink_blend: problem.description().kink_blend(),
        resonance_band: problem.resonance_band().min(harmonics as f64),
    };
    let system = problem.system().clone();
    let mut coarse = NonsmoothSystem::new(&system, settings).ok()?;
    // Coefficients `0..=harmonics` come first in both layouts.
    let len = coarse.dimension();
    let truncated = seed[..len].to_vec();
    let result = usable_start(&mut coarse, solver, (truncated, subharmonic), omega, floor);
    let (y, at) = match result {
        Ok(found) => found,
        Err(SettingsError::StartNotFound {
            up_to,
            attempts,
            at_rest,
            failed,
            ..
        }) => {
            tally.attempts += attempts;
            tally.refused += at_rest;
            tally.failed += failed;
            tally.up_to = tally.up_to.max(up_to);
            return None;
        }
        Err(_) => return None,
    };
    // A coarse seed that needs no search is the full seed's truncation: not a new guess.
    if at == omega && y == seed[..len] {
        return None;
    }
    let mut lifted = vec![0.0; problem.dimension()];
    lifted[..len].copy_from_slice(&y);
    let above_rest = |_: &mut NonsmoothSystem, x: &[f64]| energy(&system, &basis, x, at) > floor;
    let homotopy = SmoothingHomotopy::new(solver);
    let solvers: [&dyn NonlinearSolver; 2] = [solver, &homotopy];
    first_solution(problem, &solvers, [lifted], (at, tally), above_rest).map(|x| (x, at))
}

/// The first grazing energy `E_g` of the problem's system and the seed of NSM `mode` sub
/// `subharmonic` at `omega`, reusing the first linear mode (found for `E_g`) when `mode == 1`.
pub(crate) fn grazing_and_seed(
    problem: &mut NonsmoothSystem,
    mode: usize,
    subharmonic: usize,
    omega: f64,
) -> Result<(f64, Vec<f64>), Error> {
    check_held(problem.system())?;
    let (e_g, first_mode) = grazing_energy(problem.system())?;
    let seed = if mode == 1 {
        seed_from_mode(problem, &first_mode, subharmonic, omega)?
    } else {
        branch_seed(problem, mode, subharmonic, omega)?
    };
    Ok((e_g, seed))
}

/// The fraction of `E_g` below which a backbone's point counts as at rest, checked: finite
/// and not negative.
pub(crate) fn check_trivial_energy(trivial_energy: f64) -> Result<f64, ContinuationError> {
    if trivial_energy.is_finite() && trivial_energy >= 0.0 {
        Ok(trivial_energy)
    } else {
        Err(ContinuationError::InvalidOption {
            what: "trivial_energy",
            value: trivial_energy,
        })
    }
}

/// Where a backbone's branch starts: a guess and the frequency it was last solved at.
#[derive(Debug, Clone, PartialEq)]
pub struct BackboneStart {
    /// The unknowns of the start (for a system without a floating bar: the grazing seed,
    /// unsolved).
    pub x: Vec<f64>,
    /// The frequency `Omega` of the start: the asked one, or a higher one where a floating
    /// bar's branch could be entered only there.
    pub omega: f64,
}

impl BackboneStart {
    /// Whether the branch could be entered only away from the asked frequency `omega` (more
    /// than `1e-9` relative): a family that does not leave the grazing point there, as on an
    /// assembly whose floating bar must be pushed hard enough to shuttle within a period.
    pub fn moved_from(&self, omega: f64) -> bool {
        (self.omega - omega).abs() > 1e-9 * omega.abs()
    }

    /// The unsolved grazing seed of NSM `mode` sub `subharmonic` at `omega`: where a start
    /// search failed, a period grid may still enter its branch further on from it.
    pub(crate) fn seed(
        system: &BarSystem,
        settings: HarmonicBalanceSettings,
        (mode, subharmonic): (usize, usize),
        omega: f64,
    ) -> Result<Self, Error> {
        let mut problem = NonsmoothSystem::new(system, settings)?;
        let (_, x) = grazing_and_seed(&mut problem, mode, subharmonic, omega)?;
        Ok(Self { x, omega })
    }
}

/// The start of the backbone of NSM `mode` sub `subharmonic` at frequency `omega`, as the
/// period and arclength backbones find it: the grazing seed of the linear mode; for a system
/// with a bar held only by contacts (a rigid-body mode) the first motion of energy above
/// `trivial_energy * E_g` reached from the guesses of [`START_RATIOS`] x
/// [`START_AMPLITUDES`] (with [`FLOATING_RATIOS`], [`FLOATING_AMPLITUDES`] and the rigid-body
/// motions of [`RIGID_AMPLITUDES`] added), walked back towards `omega` as far as it
/// converges. [`BackboneStart::moved_from`] tells whether it got back to `omega`: where it
/// did not, a period grid from `omega` starts off its branch, and pseudo-arclength
/// ([`crate::branches::arclength_backbone`], which walks the branch back to `omega`) is the
/// backbone to use.
///
/// # Errors
/// Invalid settings, no linear mode `mode`, a `trivial_energy` that is negative or not
/// finite, a non-positive or non-finite `omega`.
pub(crate) fn backbone_start<S: NonlinearSolver>(
    system: &BarSystem,
    settings: HarmonicBalanceSettings,
    (mode, subharmonic): (usize, usize),
    omega: f64,
    trivial_energy: f64,
    solver: &S,
) -> Result<BackboneStart, Error> {
    let mut problem = NonsmoothSystem::new(system, settings)?;
    check_trivial_energy(trivial_energy)?;
    crate::system::inputs::check_frequency_of(&problem, omega)?;
    let (e_g, seed) = grazing_and_seed(&mut problem, mode, subharmonic, omega)?;
    let (x, omega) = usable_start(
        &mut problem,
        solver,
        (seed, subharmonic),
        omega,
        trivial_energy * e_g,
    )?;
    Ok(BackboneStart { x, omega })
}

/// The start of the backbone of NSM `mode` sub `subharmonic` at `omega` reached from the
/// tethered system ([`tethered_start`]) on a system with floating bars; `None` on a held
/// system, or where the homotopy does not reach `omega` with a motion of energy above
/// `trivial_energy * E_g`.
pub(crate) fn tethered_backbone_start<S: NonlinearSolver>(
    system: &BarSystem,
    settings: HarmonicBalanceSettings,
    (mode, subharmonic): (usize, usize),
    (omega, trivial_energy): (f64, f64),
    solver: &S,
) -> Option<BackboneStart> {
    let guesses = StartGuesses::new(system);
    if !guesses.floating() {
        return None;
    }
    // The first linear mode is the one `E_g` is found from: not searched twice.
    let (e_g, first) = grazing_energy(system).ok()?;
    let original = if mode == 1 {
        first
    } else {
        open_mode(system, mode).ok()?
    };
    let laws = guesses.touched_laws();
    let x = tethered_start(
        (system, settings),
        solver,
        (&original, subharmonic),
        (omega, &laws),
        trivial_energy * e_g,
    )?;
    Some(BackboneStart { x, omega })
}

/// The walk back of an arclength backbone whose start `(x, from)` lies beyond the asked
/// frequency `omega` in the run's direction `options.direction`: the branch is followed the
/// other way (with the stall escape, if any) until it leaves the range between `omega` and
/// the far end of `options.parameter_range`. Returns the walk as the first part of the run:
/// its points from the far end back to the one before the start, in the run's direction and
/// numbered from 0 ([`reversed`]), and the walk's rejected steps, each as the walk's
/// observer saw it. The run then goes on from
/// the start, so that the branch between `omega` and `from` is not lost. A start not beyond
/// `omega`, or one the driver cannot start from, has no walk. The walk keeps within the
/// drivers' default step and rejection budgets ([`ArclengthOptions::default`]): the run's
/// observer sees it only once it is over and so cannot stop it.
pub(crate) fn walk_back<S: NonlinearSolver>(
    problem: &NonsmoothSystem,
    solver: &S,
    (x, from): (&[f64], f64),
    omega: f64,
    options: ArclengthOptions,
    (escape, floor): (Option<StallEscape>, f64),
) -> (Vec<Point>, Vec<Rejection>) {
    let direction = options.direction.signum();
    if (from - omega) * direction <= 0.0 {
        return (Vec::new(), Vec::new());
    }
    let (lo, hi) = options.parameter_range;
    // The run's observer sees the walk only once it is over, so it cannot stop it: the walk
    // keeps within the drivers' default budgets even where the run's are unbounded.
    let defaults = ArclengthOptions::default();
    let walk = ArclengthOptions {
        direction: -direction,
        parameter_range: if direction > 0.0 {
            (omega.max(lo), hi)
        } else {
            (lo, omega.min(hi))
        },
        branch_points: false,
        max_steps: options.max_steps.min(defaults.max_steps),
        max_rejections: options.max_rejections.min(defaults.max_rejections),
        ..options
    };
    let (system, basis) = (problem.system(), problem.basis());
    let driver = match Arclength::new(problem.clone(), solver, x.to_vec(), from, walk) {
        // The energy floor decides what counts as rest.
        Ok(driver) => driver
            .with_rest_accepted()
            .with_acceptance(|y, at| energy(system, basis, y, at) > floor),
        Err(_) => return (Vec::new(), Vec::new()),
    };
    // The rejections are kept to be handed to the run's observer, which counts them with
    // the run's own.
    let mut rejections = Vec::new();
    let mut go_on = |step: &Step| {
        if let Step::Rejected(r) = step {
            rejections.push(r.clone());
        }
        ControlFlow::Continue(())
    };
    let mut branch: Branch = match escape {
        Some(escape) => match EscapingArclength::new(driver, escape) {
            Ok(mut escaping) => escaping.run(&mut go_on),
            Err(_) => return (Vec::new(), Vec::new()),
        },
        None => {
            let mut plain = driver;
            plain.run(&mut go_on)
        }
    };
    // The walk's first point is the start, which the run itself begins with.
    if !branch.points.is_empty() {
        branch.points.remove(0);
    }
    (reversed(branch.points), rejections)
}

/// Points of a branch in the opposite order, numbered from 0, each event moved to the point
/// that now follows it (an event is reported on the point after it) with its sense turned:
/// a contact that appeared now vanishes, a fold is at its new point's parameter.
fn reversed(mut points: Vec<Point>) -> Vec<Point> {
    let mut events: Vec<Vec<Event>> = points
        .iter_mut()
        .map(|p| std::mem::take(&mut p.events))
        .collect();
    points.reverse();
    events.reverse();
    for (k, p) in points.iter_mut().enumerate() {
        p.step = k;
        // Point `n - 1 - k` of the old order is now at `k`; the events between it and the
        // old point after it (reported on that one, now at `k - 1`) are now reported on it.
        let moved = if k >= 1 {
            std::mem::take(&mut events[k - 1])
        } else {
            Vec::new()
        };
        p.events = moved
            .into_iter()
            .map(|e| match e {
                Event::Fold { .. } => Event::Fold {
                    parameter: p.parameter,
                },
                Event::BranchPoint { .. } => Event::BranchPoint {
                    parameter: p.parameter,
                },
                Event::Grazing { law, contact } => Event::Grazing {
                    law,
                    contact: !contact,
                },
                other => other,
            })
            .collect();
    }
    points
}

#[cfg(test)]
mod tests {
    use super::*;

    fn point(step: usize, parameter: f64, events: Vec<Event>) -> Point {
        Point {
            step,
            parameter,
            x: vec![parameter],
            residual_norm: 0.0,
            iterations: 1,
            converged: true,
            error: None,
            step_size: 0.1,
            events,
        }
    }

    /// Reversed, the points are renumbered from 0 and each event is reported on the point
    /// that now follows it, in its new sense.
    #[test]
    fn reversed_points_carry_their_events_the_other_way() {
        let appears = Event::Grazing {
            law: 0,
            contact: true,
        };
        let walk = vec![
            point(1, 1.0, Vec::new()),
            point(2, 0.9, vec![appears]),
            point(3, 0.8, vec![Event::Fold { parameter: 0.8 }]),
            point(4, 0.7, vec![Event::Jump { ratio: 5.0 }]),
        ];
        let back = reversed(walk);
        let parameters: Vec<f64> = back.iter().map(|p| p.parameter).collect();
        assert_eq!(parameters, [0.7, 0.8, 0.9, 1.0]);
        assert!(back.iter().enumerate().all(|(k, p)| p.step == k));
        // Between 0.8 and 0.7 (reported on 0.7 going down): now reported on 0.8.
        assert!(back[0].events.is_empty());
        assert_eq!(back[1].events, [Event::Jump { ratio: 5.0 }]);
        assert_eq!(back[2].events, [Event::Fold { parameter: 0.9 }]);
        assert_eq!(
            back[3].events,
            [Event::Grazing {
                law: 0,
                contact: false
            }]
        );
    }
}
