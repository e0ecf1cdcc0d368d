//! What makes a motion a point of an energy backbone, and the solves at fixed frequency
//! that start a branch and jump its internal resonances.

use crate::branches::point::{BackbonePoint, PointStatus, Timescale};
use crate::branches::start::{
    first_solution, StartGuesses, Tally, CLOSE_START_RATIOS, RIGID_AMPLITUDES,
};
use crate::continuation::ContinuationProblem;
use crate::error::{Error, SettingsError};
use crate::fourier::period_of_frequency;
use crate::modal::energy::energy;
use crate::modal::linear::{seed_from_mode, LinearMode};
use crate::modal::signature::harmonic_energies;
use crate::solve::{failed_point, NonlinearSolver, SmoothingHomotopy, Structured};
use crate::system::NonsmoothSystem;
use std::ops::ControlFlow;

/// Most steps of a walk across internal resonances in the period
/// ([`Method::Energy`](crate::branches::Method::Energy)):
/// `T_a (1 - j / 800)` for `j = 1..=200` below the last accepted period `T_a` (steps of
/// the paper's period grid, over a quarter of `T_a`).
pub const ESCAPE_PERIODS: usize = 200;

/// Steady steps in a row that end a walk across an internal resonance.
pub const CALM_STEPS: usize = 2;

/// Energies below this fraction of `E_g` are the state of rest.
const REST: f64 = 1e-6;

/// Largest share of the energy added from one accepted point to the next that a harmonic
/// other than the branch's own may take: more is a harmonic running into resonance.
pub const MARGINAL_SHARE: f64 = 0.5;

/// The acceptance test of an energy backbone and its fixed-frequency solves, on its own
/// copy of the harmonic-balance system.
#[derive(Debug, Clone)]
pub(super) struct Judge {
    problem: NonsmoothSystem,
    grazing_energy: f64,
    subharmonic: usize,
    /// The time-averaged energy per harmonic of the last accepted point.
    reference: Option<Vec<f64>>,
    /// The slope of the period in the energy along the branch ([`Slopes`]).
    slopes: Slopes,
}

/// The last accepted `(T, ln E)` of an energy backbone and the slopes
/// `|dT / d ln E|` of its last [`SLOPE_MEMORY`] steps. Along a hardening backbone the
/// period falls steadily as the energy grows, and the slope changes slowly from step to
/// step; on the flank of an internal resonance's spike the period stalls, the slope
/// collapsing geometrically, step after step.
#[derive(Debug, Clone, Default)]
struct Slopes {
    last: Option<(f64, f64)>,
    chord_taken: bool,
    recent: std::collections::VecDeque<f64>,
}

/// Steps whose slopes `|dT / d ln E|` an energy backbone compares a new step with.
pub const SLOPE_MEMORY: usize = 5;

/// A step whose slope `|dT / d ln E|` falls below this fraction of the largest of the last
/// [`SLOPE_MEMORY`] is a period that stalls: the flank of a spike.
pub const SLOPE_COLLAPSE: f64 = 0.5;

impl Slopes {
    /// Whether the step to `(period, level)` keeps the period falling at a rate comparable
    /// to the last steps'; if so it is remembered.
    fn step(&mut self, period: f64, level: f64) -> bool {
        let here = (period, level.ln());
        let Some((t, l)) = self.last else {
            self.last = Some(here);
            return true;
        };
        let slope = (here.0 - t) / (here.1 - l);
        let largest = self.recent.iter().fold(0.0f64, |m, s| m.max(*s));
        if !(slope < 0.0 && -slope >= SLOPE_COLLAPSE * largest) {
            return false;
        }
        // The step from a segment's start (the branch's start, or the end of a walk) spans
        // more than a grid step: its slope is a chord, checked for its sign only.
        if self.chord_taken {
            if self.recent.len() == SLOPE_MEMORY {
                self.recent.pop_front();
            }
            self.recent.push_back(-slope);
        }
        self.chord_taken = true;
        self.last = Some(here);
        true
    }
}

impl Judge {
    pub(super) fn new(problem: NonsmoothSystem, grazing_energy: f64, subharmonic: usize) -> Self {
        Self {
            problem,
            grazing_energy,
            subharmonic,
            reference: None,
            slopes: Slopes::default(),
        }
    }

    /// Forgets the last accepted point: the next one is judged on its own.
    pub(super) fn forget_reference(&mut self) {
        self.reference = None;
        self.slopes = Slopes::default();
    }

    /// Makes `x` at `omega` the last accepted point.
    pub(super) fn set_reference(&mut self, x: &[f64], omega: f64) {
        self.reference =
            harmonic_energies(self.problem.system(), self.problem.basis(), x, omega).ok();
    }

    /// `E / E_g` of `x` at `omega`.
    pub(super) fn level(&self, x: &[f64], omega: f64) -> f64 {
        energy(self.problem.system(), self.problem.basis(), x, omega) / self.grazing_energy
    }

    /// Whether the converged motion `x` at `omega` is a point of the branch
    /// ([`acceptable`], and its period falls with the energy as along the last steps,
    /// [`Slopes`]); if so it becomes the last accepted point.
    pub(super) fn accepts(&mut self, x: &[f64], omega: f64) -> bool {
        let judge = (self.grazing_energy, self.subharmonic);
        let verdict = acceptable(
            &mut self.problem,
            judge,
            self.reference.as_deref(),
            x,
            omega,
        );
        let Some((energies, level)) = verdict else {
            return false;
        };
        let accepted = self.slopes.step(period_of_frequency(omega), level);
        if accepted {
            self.reference = Some(energies);
        }
        accepted
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
        let reference = self.reference.clone();
        let mut tally = Tally::default();
        first_solution(
            &mut self.problem,
            solvers,
            guesses,
            (omega, &mut tally),
            |p, x| acceptable(p, judge, reference.as_deref(), x, omega).is_some(),
        )
    }

    /// The first point of the branch of `linear`: a nonsmooth mode at a fixed frequency just
    /// above the linear mode's (closing a gap stiffens the system), from its grazing seed
    /// ([`seed_from_mode`]).
    ///
    /// The grazing point itself is a poor start: there the linear rows are singular (and,
    /// for a spectrum of commensurate frequencies such as the clamped bar's, a family of
    /// linear motions of the same period meets the branch), and Newton's method in
    /// `(x, Omega)` slides along that family. At a fixed frequency off the linear one the
    /// only linear motion is rest. The guesses of [`StartGuesses`] are tried in turn, each
    /// with `solver` and then with it inside a [`SmoothingHomotopy`].
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
        let guesses = StartGuesses::new(self.problem.system());
        let ratios: Vec<f64> = guesses
            .ratios()
            .into_iter()
            .chain(CLOSE_START_RATIOS)
            .collect();
        for &ratio in &ratios {
            let omega = ratio * linear.omega / self.subharmonic as f64;
            let seed = seed_from_mode(&mut self.problem, linear, self.subharmonic, omega)?;
            let tries = guesses.around(
                &self.problem,
                (&seed, self.subharmonic),
                omega,
                &RIGID_AMPLITUDES,
            );
            if let Some(x) = self.solve_at(&solvers, tries, omega) {
                return Ok((x, omega));
            }
        }
        Err(SettingsError::NoStart {
            omega: linear.omega,
            attempts: guesses.per_frequency() * ratios.len() * solvers.len(),
        }
        .into())
    }

    /// Walks a spike of an internal resonance in the period, as a period grid does: from
    /// the last accepted point `(x, omega)`, periods `T_a (1 - j / 800)` (the paper's grid
    /// step), `j = 1..=`[`ESCAPE_PERIODS`], each solved from the last solution. Every step
    /// is handed to `see` as a backbone point (converged or not: a point of the branch in
    /// the period's parametrisation), which may stop the walk. The walk ends at the first
    /// converged step past the spike: a motion the energy backbone accepts, of higher
    /// energy than the start, ending [`CALM_STEPS`] steps in a row each of higher energy
    /// than the step before and whose added energy no single other harmonic takes more than
    /// [`MARGINAL_SHARE`] of (off the spike's flanks). Returns that point, not handed to
    /// `see`: the energy backbone resumes from it.
    pub(super) fn walk<S: NonlinearSolver>(
        &mut self,
        solver: &S,
        (x, omega): (&[f64], f64),
        last_level: f64,
        mut see: impl FnMut(BackbonePoint) -> ControlFlow<()>,
    ) -> Walk {
        let judge = (self.grazing_energy, self.subharmonic);
        let start = self.level(x, omega);
        // The walk steps in the period: each step's frequency is derived from its period once.
        let period = period_of_frequency(omega);
        let mut last = (x.to_vec(), start);
        let mut energies = self.reference.clone();
        let mut calm = 0;
        for j in 1..=ESCAPE_PERIODS {
            let time = Timescale::of_period(period * (1.0 - j as f64 / 800.0));
            let omega = time.omega;
            let mut y = last.0.clone();
            self.problem.set_parameter(omega);
            let solved = solver.solve(&mut self.problem, &mut y);
            // A diverged solve reports the last accepted motion.
            let residual_norm = match &solved {
                Ok(info) => info.residual_norm,
                Err(_) => {
                    let (at, norm) = failed_point(&mut self.problem, y, &last.0);
                    y = at;
                    norm
                }
            };
            let level = self.level(&y, omega);
            let verdict = solved
                .as_ref()
                .ok()
                .and_then(|_| acceptable(&mut self.problem, judge, None, &y, omega));
            let status = match (&solved, &verdict) {
                (Err(e), _) => PointStatus::SolverFailed(e.clone()),
                (Ok(_), None) => PointStatus::Rejected,
                (Ok(_), Some(_)) => PointStatus::Converged,
            };
            let steady = verdict.as_ref().is_some_and(|(now, _)| {
                energies
                    .as_deref()
                    .is_some_and(|before| steady_growth(before, now, self.subharmonic))
            });
            calm = if steady && level > last.1 {
                calm + 1
            } else {
                0
            };
            if calm >= CALM_STEPS && level > start {
                // The energy backbone goes on from here, and reports it as its next point.
                return Walk::Resume(y, omega);
            }
            let point = BackbonePoint {
                step: 0,
                period: time.period,
                omega,
                energy: level * self.grazing_energy,
                energy_normalized: level,
                status,
                residual_norm,
                iterations: solved.as_ref().map_or(0, |i| i.iterations),
                x: y.clone(),
                step_size: -period / 800.0,
                events: Vec::new(),
                branch: 0,
                time_domain: None,
                check: None,
                character: None,
                label: None,
                stability: None,
                hill: None,
            };
            if see(point).is_break() {
                return Walk::Stopped;
            }
            if let Some((now, _)) = verdict {
                if level > last_level {
                    return Walk::Beyond;
                }
                last = (y, level);
                energies = Some(now);
            }
        }
        Walk::Lost
    }
}

/// How a walk across an internal resonance ended.
pub(super) enum Walk {
    /// Past the spike at this motion and frequency.
    Resume(Vec<f64>, f64),
    /// The observer stopped it.
    Stopped,
    /// It reached an accepted point beyond the last level asked for.
    Beyond,
    /// No acceptable step past the spike within [`ESCAPE_PERIODS`] steps.
    Lost,
}

/// Whether the time-averaged energies per harmonic grew from `before` to `after` as along a
/// backbone: the total grew, and no harmonic other than `own` took more than
/// [`MARGINAL_SHARE`] of the energy added (on an internal resonance's spike one harmonic
/// takes nearly all of it).
fn steady_growth(before: &[f64], after: &[f64], own: usize) -> bool {
    let added = after.iter().sum::<f64>() - before.iter().sum::<f64>();
    added > 0.0
        && (after.iter().zip(before).enumerate())
            .all(|(n, (a, b))| n == own || a - b <= MARGINAL_SHARE * added)
}

/// Whether the converged motion `x` at `omega` of `problem` is a point of an energy
/// backbone of NSM sub `subharmonic` with grazing energy `e_g`, after the accepted point
/// whose time-averaged energies per harmonic are `reference`; if so, its own and its level
/// `E / E_g`. The tests:
///
/// - a positive frequency within the problem's range and an energy above rest;
/// - a contact at some time sample: a motion without contact is a linear one (a resonant
///   harmonic of the truncated system, or a floating bar moved out of reach);
/// - harmonic `subharmonic` carries the most time-averaged energy, and no other harmonic
///   takes more than [`MARGINAL_SHARE`] of the energy added since `reference`: along a
///   backbone the harmonics grow together, while a harmonic of the truncated system
///   running into resonance with a linear mode (an internal resonance) takes nearly all
///   the energy added, on a spike that rises without bound.
fn acceptable(
    problem: &mut NonsmoothSystem,
    (e_g, subharmonic): (f64, usize),
    reference: Option<&[f64]>,
    x: &[f64],
    omega: f64,
) -> Option<(Vec<f64>, f64)> {
    let (system, basis) = (problem.system(), problem.basis());
    let level = energy(system, basis, x, omega) / e_g;
    if !(omega.is_finite()
        && omega > 0.0
        && omega <= problem.description().max_frequency()
        && level > REST)
    {
        return None;
    }
    let energies = harmonic_energies(system, basis, x, omega).ok()?;
    let dominant = (0..energies.len()).max_by(|&a, &b| energies[a].total_cmp(&energies[b]));
    let steady = reference.is_none_or(|r| steady_growth(r, &energies, subharmonic));
    (dominant == Some(subharmonic) && steady && touches(problem, x, omega))
        .then_some((energies, level))
}

/// Whether `x` at `omega` is in contact at some time sample of some law.
fn touches(problem: &mut NonsmoothSystem, x: &[f64], omega: f64) -> bool {
    problem.set_parameter(omega);
    problem
        .active_set(x)
        .is_some_and(|active| active.iter().any(|&a| a > 0))
}
