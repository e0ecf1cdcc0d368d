//! The guesses that start a branch, for the energy and the period backbones alike: the grazing seed of a linear mode at a few frequencies
//! and amplitudes, with the motions of floating bars added where the system has any.

use crate::continuation::ContinuationProblem;
use crate::fourier::Basis;
use crate::modal::linear::{add_on_harmonic, rigid_body_modes, ContactState};
use crate::solve::NonlinearSolver;
use crate::system::{BarSystem, NonsmoothSystem};

/// Frequencies of the start, relative to the linear mode's: `80/79`, `40/39` and `20/19`
/// (periods `79/80`, `39/40` and `19/20` of the mode's, the first of them the period
/// grid's first, [`crate::modal::PeriodGrid::for_mode`]).
pub const START_RATIOS: [f64; 3] = [80.0 / 79.0, 40.0 / 39.0, 20.0 / 19.0];

/// Amplitudes of the start, relative to the grazing seed's: a seed that only grazes can
/// slide to a rigid-body motion resting against an obstacle (a floating bar), one that
/// slightly penetrates cannot.
pub const START_AMPLITUDES: [f64; 3] = [1.0, 1.01, 1.1];

/// Further frequencies of the start, relative to the linear mode's, for a system with
/// rigid-body modes: the periodic motions of a bar held only by contacts (it shuttles between
/// its neighbours) lie well above the linear frequency.
pub const FLOATING_RATIOS: [f64; 2] = [1.2, 1.5];

/// Further amplitudes of the start, relative to the grazing seed's, for a system with
/// rigid-body modes.
pub const FLOATING_AMPLITUDES: [f64; 2] = [1.5, 3.0];

/// Amplitudes, in units of the smallest gap, of each rigid-body mode added to the seed (on
/// the seed's harmonic): a floating bar set moving, which the seed of a mode of its
/// neighbours leaves at rest.
pub const RIGID_AMPLITUDES: [f64; 6] = [-2.0, -1.0, -0.5, 0.5, 1.0, 2.0];

/// The guesses of a branch's start for a system: [`START_RATIOS`] x [`START_AMPLITUDES`] of
/// the grazing seed; for a system with rigid-body modes (a bar held only by contacts) also
/// [`FLOATING_RATIOS`] and [`FLOATING_AMPLITUDES`], and each guess with each rigid-body mode
/// added at the amplitudes of [`RIGID_AMPLITUDES`].
#[derive(Debug, Clone)]
pub(crate) struct StartGuesses {
    rigid: Vec<Vec<f64>>,
    gap: f64,
}

impl StartGuesses {
    pub(crate) fn new(system: &BarSystem) -> Self {
        let rigid = rigid_body_modes(system, ContactState::Open).map_or(Vec::new(), |m| m.shapes);
        let gap = system
            .laws()
            .map(|l| l.gap().offset.abs())
            .fold(f64::INFINITY, f64::min);
        Self { rigid, gap }
    }

    /// Whether the system has a bar held only by contacts (a rigid-body mode) and a gap.
    pub(crate) fn floating(&self) -> bool {
        !self.rigid.is_empty() && self.gap.is_finite()
    }

    /// The frequencies to try, relative to the linear mode's.
    pub(crate) fn ratios(&self) -> Vec<f64> {
        let extra = if self.floating() {
            &FLOATING_RATIOS[..]
        } else {
            &[]
        };
        START_RATIOS.iter().chain(extra).copied().collect()
    }

    fn amplitudes(&self) -> Vec<f64> {
        let extra = if self.floating() {
            &FLOATING_AMPLITUDES[..]
        } else {
            &[]
        };
        START_AMPLITUDES.iter().chain(extra).copied().collect()
    }

    /// Guesses tried at all frequencies together.
    pub(crate) fn count(&self) -> usize {
        let per_seed = self.amplitudes().len() * (1 + self.rigid.len() * RIGID_AMPLITUDES.len());
        self.ratios().len() * per_seed
    }

    /// The guesses around `seed` (a seed on harmonic `harmonic`).
    pub(crate) fn around<B: Basis>(
        &self,
        problem: &NonsmoothSystem<B>,
        seed: &[f64],
        harmonic: usize,
    ) -> Vec<Vec<f64>> {
        let mut guesses = Vec::with_capacity(self.count() / self.ratios().len());
        for a in self.amplitudes() {
            let base: Vec<f64> = seed.iter().map(|v| a * v).collect();
            guesses.push(base.clone());
            if !self.floating() {
                continue;
            }
            for shape in &self.rigid {
                for c in RIGID_AMPLITUDES {
                    let mut guess = base.clone();
                    add_on_harmonic(problem, shape, harmonic, c * self.gap, &mut guess);
                    guesses.push(guess);
                }
            }
        }
        guesses
    }
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
