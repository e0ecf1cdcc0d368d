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
//! use nonsmooth_modes::system::{HarmonicBalance, ParameterFamily};
//!
//! let in_gap = ParameterFamily::new(clamped_bar_with_obstacle, HarmonicBalance::default(), 1.8)?;
//! # Ok::<(), nonsmooth_modes::Error>(())
//! ```

use crate::continuation::ContinuationProblem;
use crate::error::{Error, ModelError, SettingsError};
use crate::linalg::DenseMatrix;
use crate::solve::point_on_ray;
use crate::system::{BarSystem, HarmonicBalance, NonsmoothSystem};

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
/// `1e-6` (the family is arbitrary user code); `dF/dx` stays analytic. Where a parameter value
/// is not admissible, residual and Jacobian are NaN, which the solvers report as
/// [`SolveError::NonFinite`](crate::SolveError::NonFinite), so a continuation step that
/// leaves the admissible set is rejected rather than silently wrong.
pub struct ParameterFamily<F> {
    family: F,
    settings: HarmonicBalance,
    omega: f64,
    current: Option<(f64, Option<NonsmoothSystem>)>,
    dimension: usize,
    smoothing: f64,
}

impl<F: SystemFamily> ParameterFamily<F> {
    /// The family `family` under `settings` at fundamental frequency `omega`.
    ///
    /// The dimension is taken from the system at parameter 1; use
    /// [`ParameterFamily::at`] to probe another value.
    ///
    /// # Errors
    /// A non-positive `omega`, invalid settings, or a family that fails at the probe value.
    pub fn new(family: F, settings: HarmonicBalance, omega: f64) -> Result<Self, Error> {
        Self::at(family, settings, omega, 1.0)
    }

    /// As [`ParameterFamily::new`], probing the family at `value`.
    ///
    /// # Errors
    /// See [`ParameterFamily::new`].
    pub fn at(family: F, settings: HarmonicBalance, omega: f64, value: f64) -> Result<Self, Error> {
        if !(omega.is_finite() && omega > 0.0) {
            return Err(SettingsError::NotPositive {
                what: "fundamental frequency",
                value: omega,
            }
            .into());
        }
        let system = NonsmoothSystem::new(&family.build(value)?, settings)?;
        Ok(Self {
            dimension: system.dimension(),
            current: Some((value, Some(system))),
            family,
            settings,
            omega,
            smoothing: 0.0,
        })
    }

    /// The fixed fundamental frequency.
    pub fn omega(&self) -> f64 {
        self.omega
    }

    /// The harmonic-balance system at `value` (None where the family rejects it).
    pub fn system_at(&mut self, value: f64) -> Option<&mut NonsmoothSystem> {
        let stale = !matches!(&self.current, Some((v, _)) if *v == value);
        if stale {
            let system = self
                .family
                .build(value)
                .ok()
                .and_then(|s| NonsmoothSystem::new(&s, self.settings).ok())
                .filter(|s| s.dimension() == self.dimension)
                .map(|mut s| {
                    s.set_smoothing(self.smoothing);
                    s
                });
            self.current = Some((value, system));
        }
        self.current.as_mut().and_then(|(_, s)| s.as_mut())
    }
}

impl<F: SystemFamily> ContinuationProblem for ParameterFamily<F> {
    fn dimension(&self) -> usize {
        self.dimension
    }

    fn residual(&mut self, x: &[f64], lambda: f64, f: &mut [f64]) {
        let omega = self.omega;
        match self.system_at(lambda) {
            Some(s) => s.residual(x, omega, f),
            None => f.fill(f64::NAN),
        }
    }

    fn residual_along(
        &mut self,
        x: &[f64],
        dx: &[f64],
        t: f64,
        lambda: f64,
        trial: &mut [f64],
        f: &mut [f64],
    ) {
        let omega = self.omega;
        match self.system_at(lambda) {
            Some(s) => s.residual_along(x, dx, t, omega, trial, f),
            None => {
                point_on_ray(x, dx, t, trial);
                f.fill(f64::NAN);
            }
        }
    }

    fn jacobian(&mut self, x: &[f64], lambda: f64, jac: &mut DenseMatrix) {
        let (omega, n) = (self.omega, self.dimension);
        match self.system_at(lambda) {
            Some(s) => s.jacobian(x, omega, jac),
            None => {
                jac.reset(n, n);
                jac[(0, 0)] = f64::NAN;
            }
        }
    }

    fn parameter_derivative(&mut self, x: &[f64], lambda: f64, df: &mut [f64]) {
        let h = 1e-6 * lambda.abs().max(1e-300);
        let mut minus = vec![0.0; df.len()];
        self.residual(x, lambda + h, df);
        self.residual(x, lambda - h, &mut minus);
        for (d, m) in df.iter_mut().zip(&minus) {
            *d = (*d - m) / (2.0 * h);
        }
        // Leave the cache on `lambda`, where the next residual is evaluated.
        let _ = self.system_at(lambda);
    }

    fn residual_scale(&self) -> f64 {
        match &self.current {
            Some((_, Some(s))) => s.residual_scale(),
            _ => 1.0,
        }
    }

    fn set_smoothing(&mut self, smoothing: f64) -> bool {
        self.smoothing = smoothing.max(0.0);
        if let Some((_, Some(s))) = &mut self.current {
            s.set_smoothing(self.smoothing);
        }
        true
    }

    fn state_weights(&mut self, lambda: f64) -> Option<Vec<f64>> {
        let omega = self.omega;
        self.system_at(lambda).and_then(|s| s.state_weights(omega))
    }

    fn active_set(&mut self, x: &[f64], lambda: f64) -> Option<Vec<usize>> {
        let omega = self.omega;
        self.system_at(lambda).and_then(|s| s.active_set(x, omega))
    }
}
