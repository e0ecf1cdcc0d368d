//! What makes a motion a point of an energy backbone, and the solves at fixed frequency
//! that start a branch and jump its internal resonances.

use crate::continuation::ContinuationProblem;
use crate::error::{Error, SettingsError};
use crate::modal::energy::energy;
use crate::modal::linear::{seed_from_mode, LinearMode};
use crate::modal::signature::harmonic_energies;
use crate::solve::{NonlinearSolver, SmoothingHomotopy, Structured};
use crate::system::NonsmoothSystem;
use std::f64::consts::PI;

/// Frequencies of the start, relative to the linear mode's: `80/79`, `40/39` and `20/19`
/// (periods `79/80`, `39/40` and `19/20` of the mode's, the first of them the period
/// grid's first, [`crate::modal::PeriodGrid::for_mode`]).
pub const START_RATIOS: [f64; 3] = [80.0 / 79.0, 40.0 / 39.0, 20.0 / 19.0];

/// Amplitudes of the start, relative to the grazing seed's: a seed that only grazes can
/// slide to a rigid-body motion resting against an obstacle (a floating bar), one that
/// slightly penetrates cannot.
pub const START_AMPLITUDES: [f64; 3] = [1.0, 1.01, 1.1];

/// Periods tried to jump an internal resonance: `T_a (1 - j / 800)` for `j = 1..=16`
/// below the last accepted period `T_a` (steps of the paper's period grid, over 2 % of
/// `T_a`).
pub const ESCAPE_PERIODS: usize = 16;

/// Energies below this fraction of `E_g` are the state of rest.
const REST: f64 = 1e-6;

/// The acceptance test of an energy backbone and its fixed-frequency solves, on its own
/// copy of the harmonic-balance system.
#[derive(Debug, Clone)]
pub(super) struct Judge {
    problem: NonsmoothSystem,
    grazing_energy: f64,
    subharmonic: usize,
}

impl Judge {
    pub(super) fn new(problem: NonsmoothSystem, grazing_energy: f64, subharmonic: usize) -> Self {
        Self {
            problem,
            grazing_energy,
            subharmonic,
        }
    }

    /// `E / E_g` of `x` at `omega`.
    pub(super) fn level(&self, x: &[f64], omega: f64) -> f64 {
        energy(self.problem.system(), self.problem.basis(), x, omega) / self.grazing_energy
    }

    /// Whether the converged motion `x` at `omega` is a point of the branch
    /// ([`acceptable`]).
    pub(super) fn accepts(&mut self, x: &[f64], omega: f64) -> bool {
        acceptable(
            &mut self.problem,
            (self.grazing_energy, self.subharmonic),
            x,
            omega,
        )
    }

    /// The first accepted solution at fixed `omega` from one of `guesses`, each solved by
    /// `solvers` in turn.
    fn solve_at(
        &mut self,
        solvers: &[&dyn NonlinearSolver],
        guesses: impl IntoIterator<Item = Vec<f64>>,
        omega: f64,
    ) -> Option<Vec<f64>> {
        let judge = (self.grazing_energy, self.subharmonic);
        first_solution(&mut self.problem, solvers, guesses, omega, |p, x| {
            acceptable(p, judge, x, omega)
        })
    }

    /// The first point of the branch of `linear`: a nonsmooth mode at a fixed frequency just
    /// above the linear mode's (closing a gap stiffens the system), from its grazing seed
    /// ([`seed_from_mode`]).
    ///
    /// The grazing point itself is a poor start: there the linear rows are singular (and,
    /// for a spectrum of commensurate frequencies such as the clamped bar's, a family of
    /// linear motions of the same period meets the branch), and Newton's method in
    /// `(x, Omega)` slides along that family. At a fixed frequency off the linear one the
    /// only linear motion is rest. The frequencies of [`START_RATIOS`] and amplitudes of
    /// [`START_AMPLITUDES`] are tried in turn, each with `solver` and then with it inside a
    /// [`SmoothingHomotopy`].
    ///
    /// # Errors
    /// A failed seed, or [`SettingsError::NoStart`] if no attempt is accepted.
    pub(super) fn start<S: NonlinearSolver>(
        &mut self,
        solver: &S,
        linear: &LinearMode,
    ) -> Result<(Vec<f64>, f64), Error> {
        let homotopy = SmoothingHomotopy::new(solver);
        let solvers: [&dyn NonlinearSolver; 2] = [solver, &homotopy];
        for ratio in START_RATIOS {
            let omega = ratio * linear.omega / self.subharmonic as f64;
            let seed = seed_from_mode(&mut self.problem, linear, self.subharmonic, omega)?;
            if let Some(x) = self.solve_at(&solvers, amplified(&seed), omega) {
                return Ok((x, omega));
            }
        }
        Err(SettingsError::NoStart {
            omega: linear.omega,
            attempts: START_RATIOS.len() * START_AMPLITUDES.len() * solvers.len(),
        }
        .into())
    }

    /// A point past an internal resonance: the first accepted solution of higher energy
    /// than the last accepted point `(x, omega)`, at the periods of [`ESCAPE_PERIODS`] below
    /// its period, each solved from `x`.
    pub(super) fn escape<S: NonlinearSolver>(
        &mut self,
        solver: &S,
        (x, omega): (&[f64], f64),
    ) -> Option<(Vec<f64>, f64)> {
        let level = self.level(x, omega);
        let period = 2.0 * PI / omega;
        let solvers: [&dyn NonlinearSolver; 1] = [solver];
        (1..=ESCAPE_PERIODS).find_map(|j| {
            let omega = 2.0 * PI / (period * (1.0 - j as f64 / 800.0));
            self.solve_at(&solvers, [x.to_vec()], omega)
                .filter(|x| self.level(x, omega) > level)
                .map(|x| (x, omega))
        })
    }
}

/// Whether the converged motion `x` at `omega` of `problem` is a point of an energy
/// backbone of NSM sub `subharmonic` with grazing energy `e_g`: a positive frequency within
/// the problem's range, an energy above rest, a contact at some time sample (a motion
/// without contact is a linear one: a resonant harmonic of the truncated system, or a
/// floating bar moved out of reach), and harmonic `subharmonic` carrying more
/// time-averaged energy than any other (else the motion sits on an internal resonance of
/// the truncated system).
fn acceptable(
    problem: &mut NonsmoothSystem,
    (e_g, subharmonic): (f64, usize),
    x: &[f64],
    omega: f64,
) -> bool {
    let (system, basis) = (problem.system(), problem.basis());
    let dominant = || {
        let energies = harmonic_energies(system, basis, x, omega).ok()?;
        (0..energies.len()).max_by(|&a, &b| energies[a].total_cmp(&energies[b]))
    };
    omega.is_finite()
        && omega > 0.0
        && omega <= problem.description().max_frequency()
        && energy(system, basis, x, omega) > REST * e_g
        && dominant() == Some(subharmonic)
        && touches(problem, x, omega)
}

/// Whether `x` at `omega` is in contact at some time sample of some law.
fn touches(problem: &mut NonsmoothSystem, x: &[f64], omega: f64) -> bool {
    problem.set_parameter(omega);
    problem
        .active_set(x)
        .is_some_and(|active| active.iter().any(|&a| a > 0))
}

/// The guesses `a s` of a seed `s` for the amplitudes `a` of [`START_AMPLITUDES`].
pub(crate) fn amplified(seed: &[f64]) -> impl Iterator<Item = Vec<f64>> + '_ {
    START_AMPLITUDES
        .into_iter()
        .map(move |a| seed.iter().map(|v| a * v).collect())
}

/// The first of `guesses` that one of `solvers` (tried in turn on each guess) takes at
/// `omega` to a solution that `accept` takes.
pub(crate) fn first_solution(
    problem: &mut NonsmoothSystem,
    solvers: &[&dyn NonlinearSolver],
    guesses: impl IntoIterator<Item = Vec<f64>>,
    omega: f64,
    mut accept: impl FnMut(&mut NonsmoothSystem, &[f64]) -> bool,
) -> Option<Vec<f64>> {
    for guess in guesses {
        for solver in solvers {
            let mut x = guess.clone();
            problem.set_parameter(omega);
            if solver.solve(problem, &mut x).is_ok() && accept(problem, &x) {
                return Some(x);
            }
        }
    }
    None
}
