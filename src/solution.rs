//! A computed periodic motion as one value: the harmonic-balance problem it solves, its
//! unknowns and its fundamental frequency, with the post-processing questions as methods.
//!
//! ```
//! use nonsmooth_modes::continuation::ContinuationProblem;
//! use nonsmooth_modes::fourier::frequency_of_period;
//! use nonsmooth_modes::modal::branch_seed;
//! use nonsmooth_modes::reference::clamped_bar_with_obstacle;
//! use nonsmooth_modes::solution::Solution;
//! use nonsmooth_modes::solve::{NonlinearSolver, SemismoothNewton};
//! use nonsmooth_modes::system::{HarmonicBalanceSettings, NonsmoothSystem};
//!
//! let system = clamped_bar_with_obstacle(1e-3)?;
//! let settings = HarmonicBalanceSettings { harmonics: 10, ..Default::default() };
//! let mut problem = NonsmoothSystem::new(&system, settings)?;
//! let omega = frequency_of_period(3.6);
//! let mut x = branch_seed(&mut problem, 1, 1, omega)?;
//! problem.set_parameter(omega);
//! SemismoothNewton::default().solve(&mut problem, &mut x)?;
//! let mode = Solution::new(&problem, &x, omega)?;
//! assert!(mode.energy_normalized()? > 1.0);
//! let tip = mode.field().at(0, 1.0, 0.0);
//! assert!((tip.displacement - 1e-3).abs() < 1e-4); // at the obstacle at t = 0
//! # Ok::<(), nonsmooth_modes::Error>(())
//! ```

use crate::bar::EndRef;
use crate::check::check_finite;
use crate::error::SettingsError;
use crate::fourier::{period_of_frequency, Basis, CosineBasis};
use crate::modal::diagnostics::{
    checked_displacement_grid, checked_end_history, diagnose, law_history, EndHistory, FieldGrid,
    LawHistory, PointDiagnostics,
};
use crate::modal::energy::energy_at;
use crate::modal::field::FieldEvaluator;
use crate::modal::linear::grazing_energy;
use crate::modal::signature::{contact_intervals, subharmonic_share};
use crate::system::inputs::check_motion;
use crate::system::{BarSystem, NonsmoothSystem};
use crate::verify::{periodicity_check, PeriodicityOptions, PeriodicityReport, VerifyError};

/// A periodic motion `x` of `problem` at fundamental frequency `omega` (borrowed: build one
/// from a branch point whenever a question is to be asked).
#[derive(Debug, Clone, Copy)]
pub struct Solution<'a, B: Basis = CosineBasis> {
    problem: &'a NonsmoothSystem<B>,
    x: &'a [f64],
    omega: f64,
}

impl<'a, B: Basis> Solution<'a, B> {
    /// The motion `x` of `problem` at `omega`.
    ///
    /// # Errors
    /// [`SettingsError::Length`] if `x` does not have the problem's dimension,
    /// [`SettingsError::NotPositive`] for a non-positive or non-finite `omega` or unknowns
    /// that are not finite, and [`SettingsError::FrequencyTooSmall`] for an `omega` below
    /// [`MIN_FREQUENCY`](crate::modal::MIN_FREQUENCY) (subnormal, or with an
    /// infinite period).
    pub fn new(
        problem: &'a NonsmoothSystem<B>,
        x: &'a [f64],
        omega: f64,
    ) -> Result<Self, SettingsError> {
        check_motion(problem, x, omega)?;
        Ok(Self { problem, x, omega })
    }

    /// The problem the motion solves.
    pub fn problem(&self) -> &'a NonsmoothSystem<B> {
        self.problem
    }

    /// The bar system.
    pub fn system(&self) -> &'a BarSystem {
        self.problem.system()
    }

    /// The unknowns (layout of [`NonsmoothSystem`]).
    pub fn unknowns(&self) -> &'a [f64] {
        self.x
    }

    /// The fundamental angular frequency `Omega`.
    pub fn omega(&self) -> f64 {
        self.omega
    }

    /// The period `T = 2 pi / Omega`.
    pub fn period(&self) -> f64 {
        period_of_frequency(self.omega)
    }

    /// The mechanical energy `E` at `t = 0` (formulation §7).
    ///
    /// # Errors
    /// [`SettingsError::NonFiniteResult`] if it exceeds the range of `f64` (a huge motion or
    /// frequency: the strain energy grows as `(k A)^2`, `k = j Omega / c`).
    pub fn energy(&self) -> Result<f64, SettingsError> {
        self.energy_at(0.0)
    }

    /// The energy at phase `theta = Omega t` (constant for an exact motion).
    ///
    /// # Errors
    /// As [`Solution::energy`]; [`SettingsError::NotFinite`] for a non-finite `theta`.
    pub fn energy_at(&self, theta: f64) -> Result<f64, SettingsError> {
        if !theta.is_finite() {
            return Err(SettingsError::NotFinite {
                what: "phase theta",
                value: theta,
            });
        }
        let e = energy_at(
            self.system(),
            self.problem.basis(),
            self.x,
            self.omega,
            theta,
        );
        check_finite("energy", self.omega, [&e])?;
        Ok(e)
    }

    /// `E / E_g`, with `E_g` the system's first grazing energy
    /// ([`grazing_energy`]: a linear modal analysis per call; divide [`Solution::energy`] by a
    /// stored `E_g` in loops).
    ///
    /// # Errors
    /// See [`grazing_energy`] and [`Solution::energy`]; [`SettingsError::NonFiniteResult`] if
    /// `E / E_g` is not finite.
    pub fn energy_normalized(&self) -> Result<f64, SettingsError> {
        let (e_g, _) = grazing_energy(self.system())?;
        let normalized = self.energy()? / e_g;
        check_finite("the normalised energy E / E_g", self.omega, [&normalized])?;
        Ok(normalized)
    }

    /// Displacement, velocity and strain anywhere in any bar.
    pub fn field(&self) -> FieldEvaluator<'a, B> {
        FieldEvaluator::new(self.system(), self.problem.basis(), self.x, self.omega)
    }

    /// Histories of one bar end over a period on `samples` instants.
    ///
    /// # Errors
    /// [`SettingsError::IndexOutOfRange`] if `end` names a bar the system does not have;
    /// [`SettingsError::TooLarge`] if the `4 samples` values do not fit in the memory budget
    /// ([`MEMORY_BUDGET_BYTES`](crate::fourier::MEMORY_BUDGET_BYTES)), and
    /// [`SettingsError::AllocationFailed`] if they do but the allocator refuses them;
    /// [`SettingsError::NonFiniteResult`] if a value comes out NaN or infinite.
    pub fn end_history(&self, end: EndRef, samples: usize) -> Result<EndHistory, SettingsError> {
        checked_end_history(
            self.system(),
            self.problem.basis(),
            (self.x, self.omega),
            end,
            samples,
        )
    }

    /// `u(x, t)` of bar `bar` on `positions x instants` points over a period.
    ///
    /// # Errors
    /// [`SettingsError::IndexOutOfRange`] if there is no bar `bar`;
    /// [`SettingsError::TooLarge`] if the `positions instants` values (with the axes) do not
    /// fit in the memory budget
    /// ([`MEMORY_BUDGET_BYTES`](crate::fourier::MEMORY_BUDGET_BYTES)), and
    /// [`SettingsError::AllocationFailed`] if they do but the allocator refuses them;
    /// [`SettingsError::NonFiniteResult`] if a value comes out NaN or infinite.
    pub fn displacement_grid(
        &self,
        bar: usize,
        positions: usize,
        instants: usize,
    ) -> Result<FieldGrid, SettingsError> {
        checked_displacement_grid(
            self.system(),
            self.problem.basis(),
            (self.x, self.omega),
            bar,
            (positions, instants),
        )
    }

    /// Gap, force and pointwise residual of unilateral law `law` over a period.
    ///
    /// # Errors
    /// See [`law_history`].
    pub fn law_history(&self, law: usize, samples: usize) -> Result<LawHistory, SettingsError> {
        law_history(self.problem, self.x, self.omega, law, samples)
    }

    /// Residual norms `R^(m)`, penetration, tensile force and energy drift.
    ///
    /// # Errors
    /// See [`diagnose`].
    pub fn diagnose(&self, refinement: usize) -> Result<PointDiagnostics, SettingsError> {
        diagnose(self.problem, self.x, self.omega, refinement)
    }

    /// The share of the bars' time-averaged energy carried by the harmonics that are not
    /// multiples of `k` (0 for a motion on the multiples of `k` alone).
    ///
    /// # Errors
    /// See [`subharmonic_share`].
    pub fn subharmonic_share(&self, k: usize) -> Result<f64, SettingsError> {
        subharmonic_share(self.system(), self.problem.basis(), self.x, self.omega, k)
    }

    /// The number of contact intervals per period of each unilateral law.
    ///
    /// It samples the laws with a copy of the problem (the solution only borrows it); in a
    /// loop over many points, call [`contact_intervals`] with a problem of your own.
    ///
    /// # Errors
    /// See [`contact_intervals`].
    pub fn contact_intervals(&self) -> Result<Vec<usize>, SettingsError> {
        contact_intervals(&mut self.problem.clone(), self.x, self.omega)
    }

    /// The exact time-domain march of the motion over its period and the periodicity defect.
    ///
    /// # Errors
    /// See [`periodicity_check`].
    pub fn periodicity_check(
        &self,
        options: &PeriodicityOptions,
    ) -> Result<PeriodicityReport, VerifyError> {
        periodicity_check(
            self.system(),
            self.problem.basis(),
            self.x,
            self.omega,
            options,
        )
    }
}
