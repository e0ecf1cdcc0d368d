//! Continuation in any scalar parameter of a bar system (gap, spring stiffness, stiffness
//! ratio, a length...) at fixed fundamental frequency.
//!
//! A [`SystemFamily`] maps a parameter value to a bar system (the "lens" of
//! BifurcationKit.jl); [`ParameterFamily`] turns it into a
//! [`ContinuationProblem`] in that parameter. Any closure
//! `Fn(f64) -> Result<BarSystem, ModelError>` is a family:
//!
//! ```
//! use nonsmooth_modes::reference::clamped_bar_with_obstacle;
//! use nonsmooth_modes::system::{HarmonicBalanceSettings, ParameterFamily};
//!
//! let in_gap = ParameterFamily::new(clamped_bar_with_obstacle, HarmonicBalanceSettings::default(), 1.8)?;
//! # Ok::<(), nonsmooth_modes::Error>(())
//! ```

use crate::continuation::ContinuationProblem;
use crate::error::{Error, ModelError};
use crate::linalg::DenseMatrix;
use crate::solve::{Problem, Structured};
use crate::system::inputs::check_frequency_of;
use crate::system::{BarSystem, HarmonicBalanceSettings, NonsmoothSystem};

/// A one-parameter family of bar systems.
pub trait SystemFamily {
    /// The system at parameter `value`.
    ///
    /// # Errors
    /// When `value` is not admissible (e.g. a negative gap).
    fn build(&self, value: f64) -> Result<BarSystem, ModelError>;
}

impl<F: Fn(f64) -> Result<BarSystem, ModelError>> SystemFamily for F {
    fn build(&self, value: f64) -> Result<BarSystem, ModelError> {
        self(value)
    }
}

/// Harmonic balance at fixed `Omega` as a continuation problem in a family's parameter.
///
/// `dF/dlambda` is a central difference of the residual in the parameter with relative step
/// `1e-6` (the family is arbitrary user code); `dF/dx` stays analytic, and the system at the
/// current parameter lends its [`Structured`] capabilities (the condensed Newton step among
/// them). Where a parameter value is not admissible, residual and Jacobian are NaN, which the
/// solvers report as [`SolveError::NonFinite`](crate::SolveError::NonFinite), so a
/// continuation step that leaves the admissible set is rejected rather than silently wrong.
pub struct ParameterFamily<F> {
    family: F,
    settings: HarmonicBalanceSettings,
    omega: f64,
    value: f64,
    /// The system at `value` (`None` where the family rejects it).
    current: Option<NonsmoothSystem>,
    dimension: usize,
}

impl<F: SystemFamily> ParameterFamily<F> {
    /// The family `family` under `settings` at fundamental frequency `omega`.
    ///
    /// The dimension is taken from the system at parameter 1, where the family starts; use
    /// [`ParameterFamily::at`] to start at another value.
    ///
    /// # Errors
    /// An `omega` that is not positive and finite or is below
    /// [`MIN_FREQUENCY`](crate::modal::MIN_FREQUENCY), invalid settings, or a
    /// family that fails at the probe value.
    pub fn new(family: F, settings: HarmonicBalanceSettings, omega: f64) -> Result<Self, Error> {
        Self::at(family, settings, omega, 1.0)
    }

    /// As [`ParameterFamily::new`], starting at parameter `value`.
    ///
    /// # Errors
    /// See [`ParameterFamily::new`].
    pub fn at(
        family: F,
        settings: HarmonicBalanceSettings,
        omega: f64,
        value: f64,
    ) -> Result<Self, Error> {
        let mut system = NonsmoothSystem::new(&family.build(value)?, settings)?;
        check_frequency_of(&system, omega)?;
        system.set_parameter(omega);
        Ok(Self {
            dimension: system.dimension(),
            current: Some(system),
            value,
            family,
            settings,
            omega,
        })
    }

    /// The fixed fundamental frequency.
    pub fn omega(&self) -> f64 {
        self.omega
    }

    /// The harmonic-balance system at the current parameter (None where the family rejects
    /// it).
    pub fn system(&mut self) -> Option<&mut NonsmoothSystem> {
        self.current.as_mut()
    }

    /// The harmonic-balance system at `value` at the family's frequency, or `None` where the
    /// family rejects `value` or changes the dimension there.
    fn build(&self, value: f64) -> Option<NonsmoothSystem> {
        let mut system = self
            .family
            .build(value)
            .ok()
            .and_then(|s| NonsmoothSystem::new(&s, self.settings).ok())
            .filter(|s| s.dimension() == self.dimension)?;
        system.set_parameter(self.omega);
        Some(system)
    }
}

/// `F(x)` of `system` into `f`, or NaN where there is no system.
fn residual_or_nan(system: Option<&mut NonsmoothSystem>, x: &[f64], f: &mut [f64]) {
    match system {
        Some(s) => s.residual(x, f),
        None => f.fill(f64::NAN),
    }
}

impl<F: SystemFamily> Problem for ParameterFamily<F> {
    fn dimension(&self) -> usize {
        self.dimension
    }

    fn residual(&mut self, x: &[f64], f: &mut [f64]) {
        residual_or_nan(self.current.as_mut(), x, f);
    }

    fn jacobian(&mut self, x: &[f64], jac: &mut DenseMatrix) {
        let n = self.dimension;
        match self.current.as_mut() {
            Some(s) => s.jacobian(x, jac),
            None => {
                jac.reset(n, n);
                jac[(0, 0)] = f64::NAN;
            }
        }
    }

    fn structure(&mut self) -> Option<&mut dyn Structured> {
        self.current.as_mut().map(|s| s as &mut dyn Structured)
    }
}

impl<F: SystemFamily> ContinuationProblem for ParameterFamily<F> {
    fn parameter(&self) -> f64 {
        self.value
    }

    fn set_parameter(&mut self, value: f64) {
        if value != self.value || self.current.is_none() {
            self.current = self.build(value);
            self.value = value;
        }
    }

    fn parameter_derivative(&mut self, x: &[f64], df: &mut [f64]) {
        let lambda = self.value;
        let h = 1e-6 * lambda.abs().max(1e-300);
        let mut minus = vec![0.0; df.len()];
        residual_or_nan(self.build(lambda + h).as_mut(), x, df);
        residual_or_nan(self.build(lambda - h).as_mut(), x, &mut minus);
        for (d, m) in df.iter_mut().zip(&minus) {
            *d = (*d - m) / (2.0 * h);
        }
    }
}
