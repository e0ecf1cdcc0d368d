//! Backbone curves: a nonsmooth-mode branch computed by sequential continuation in the
//! period, with energies normalised by the first grazing energy.

use crate::continuation::{PeriodParametrised, Point, Predictor, Sequential, SequentialOptions};
use crate::error::{ContinuationError, Error};
use crate::modal::energy::energy;
use crate::modal::linear::{branch_seed, grazing_energy};
use crate::solve::NonlinearSolver;
use crate::system::{BarSystem, HarmonicBalance, NonsmoothSystem};
use std::f64::consts::PI;
use std::ops::ControlFlow;

/// `steps` equispaced periods from `start` to `end` (both included).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PeriodGrid {
    /// First period `T0`.
    pub start: f64,
    /// Last period `T1`.
    pub end: f64,
    /// Number of periods (at least 2).
    pub steps: usize,
}

impl Default for PeriodGrid {
    /// The paper's grid for the first mode of the clamped bar: `T` from 3.95 to 3.05 in 181
    /// steps.
    fn default() -> Self {
        Self {
            start: 3.95,
            end: 3.05,
            steps: 181,
        }
    }
}

/// Options of [`backbone`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BackboneOptions {
    /// Periods to visit (default [`PeriodGrid::default`]).
    pub grid: PeriodGrid,
    /// Linear mode the branch starts from (1-based, default 1).
    pub mode: usize,
    /// Period multiple `k` of the seed (NSM `mode` sub `k`; default 1).
    pub subharmonic: usize,
    /// Predictor of the sequential driver (default constant).
    pub predictor: Predictor,
    /// Consecutive failures before the run stops (default 40).
    pub max_consecutive_failures: usize,
    /// Converged points with `E < trivial_energy * E_g` count as collapsed to rest and are
    /// not accepted (default `1e-6`).
    pub trivial_energy: f64,
}

impl Default for BackboneOptions {
    fn default() -> Self {
        Self {
            grid: PeriodGrid::default(),
            mode: 1,
            subharmonic: 1,
            predictor: Predictor::Constant,
            max_consecutive_failures: 40,
            trivial_energy: 1e-6,
        }
    }
}

/// One point of a backbone.
#[derive(Debug, Clone, PartialEq)]
pub struct BackbonePoint {
    /// Step number.
    pub step: usize,
    /// Period `T`.
    pub period: f64,
    /// Fundamental angular frequency `Omega = 2 pi / T`.
    pub omega: f64,
    /// Energy `E` (formulation §7).
    pub energy: f64,
    /// `E / E_g`.
    pub energy_normalized: f64,
    /// The solver converged to a motion that touches (not the state of rest).
    pub converged: bool,
    /// `|F|_2` at the returned unknowns.
    pub residual_norm: f64,
    /// Solver iterations.
    pub iterations: usize,
    /// The unknowns (layout of [`NonsmoothSystem`]).
    pub x: Vec<f64>,
}

/// Computes a backbone with the constant + cosine basis: seeds the branch from the linear mode
/// at the first period and continues sequentially in the period, handing each point to
/// `observer` (which may stop the run). Returns the first grazing energy `E_g` used for
/// normalisation.
///
/// # Errors
/// Invalid settings or options, a failed seed, or a stalled run.
pub fn backbone_with<S: NonlinearSolver>(
    system: &BarSystem,
    settings: HarmonicBalance,
    options: &BackboneOptions,
    solver: S,
    mut observer: impl FnMut(&BackbonePoint) -> ControlFlow<()>,
) -> Result<f64, Error> {
    let mut problem = NonsmoothSystem::new(system, settings)?;
    let grid = options.grid;
    for v in [grid.start, grid.end] {
        if !(v.is_finite() && v > 0.0) {
            return Err(ContinuationError::InvalidOption {
                what: "period",
                value: v,
            }
            .into());
        }
    }
    if !(options.trivial_energy.is_finite() && options.trivial_energy >= 0.0) {
        return Err(ContinuationError::InvalidOption {
            what: "trivial_energy",
            value: options.trivial_energy,
        }
        .into());
    }
    let values = Sequential::<PeriodParametrised<NonsmoothSystem>, S>::linspace(
        grid.start, grid.end, grid.steps,
    )?;
    let (e_g, _) = grazing_energy(system)?;
    let start = branch_seed(&mut problem, options.mode, options.subharmonic, 2.0 * PI / grid.start)?;
    let basis = problem.basis().clone();
    let seq_options = SequentialOptions {
        predictor: options.predictor,
        max_consecutive_failures: options.max_consecutive_failures,
    };
    let floor = options.trivial_energy * e_g;
    let accept_system = system.clone();
    let accept_basis = basis.clone();
    let mut driver = Sequential::new(PeriodParametrised(problem), solver, start, values, seq_options)?
        .with_acceptance(move |x, period| {
            energy(&accept_system, &accept_basis, x, 2.0 * PI / period) > floor
        });
    driver.run(|p: &Point| {
        let omega = 2.0 * PI / p.lambda;
        let e = energy(system, &basis, &p.x, omega);
        observer(&BackbonePoint {
            step: p.step,
            period: p.lambda,
            omega,
            energy: e,
            energy_normalized: e / e_g,
            converged: p.converged,
            residual_norm: p.residual_norm,
            iterations: p.iterations,
            x: p.x.clone(),
        })
    })?;
    Ok(e_g)
}

/// [`backbone_with`] collecting every point.
///
/// # Errors
/// See [`backbone_with`].
pub fn backbone<S: NonlinearSolver>(
    system: &BarSystem,
    settings: HarmonicBalance,
    options: &BackboneOptions,
    solver: S,
) -> Result<Vec<BackbonePoint>, Error> {
    let mut points = Vec::new();
    backbone_with(system, settings, options, solver, |p| {
        points.push(p.clone());
        ControlFlow::Continue(())
    })?;
    Ok(points)
}

