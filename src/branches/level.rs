//! Nonsmooth modes at a prescribed energy: the harmonic-balance system with the frequency as
//! an unknown and the energy as the parameter.
//!
//! The unknowns are `y = (x, Omega)`, the frequency last as the parameter of every bordered
//! system ([`augmented`]), and the equations
//!
//! ```text
//! F(x; Omega) = 0                         harmonic balance (NonsmoothSystem)
//! s (E(x; Omega) / (lambda E_g) - 1) = 0  the energy level lambda = E / E_g
//! ```
//!
//! with `s` the residual scale of `F`. The state of rest has `E = 0` and is no solution
//! at any level `lambda > 0`: a branch continued in `lambda` cannot collapse to it, which a
//! branch continued in the period can. The price is the truncated system's internal
//! resonances, spikes that have no other side in the energy (`docs/assemblies.md`).
//!
//! The Jacobian is `F`'s bordered by the column `dF/dOmega` and the row
//! `s (dE/dx, dE/dOmega) / (lambda E_g)`; its structured solve is the bordering algorithm on
//! `F`'s condensed solve.

use crate::continuation::{augmented, fill_bordered, solve_bordered, ContinuationProblem};
use crate::error::{ContinuationError, Error};
use crate::fourier::{Basis, CosineBasis};
use crate::linalg::DenseMatrix;
use crate::modal::energy::{energy, energy_frequency_derivative, energy_gradient};
use crate::solve::{Problem, SingularStep, Structured};
use crate::system::NonsmoothSystem;

/// A [`NonsmoothSystem`] at a prescribed energy level `lambda = E / E_g`: a
/// [`ContinuationProblem`] in `lambda` whose unknowns are `y = (x, Omega)` (the system's
/// unknowns, then the fundamental frequency: [`augmented::split`] and [`augmented::join`]
/// read and write them).
#[derive(Debug, Clone)]
pub struct EnergyLevel<B: Basis = CosineBasis> {
    inner: NonsmoothSystem<B>,
    grazing_energy: f64,
    level: f64,
    scratch: Scratch,
}

/// Storage of the Jacobian's blocks and of the bordering solve.
#[derive(Debug, Clone, Default)]
struct Scratch {
    jacobian: DenseMatrix,
    df: Vec<f64>,
    gradient: Vec<f64>,
    columns: Vec<f64>,
}

impl<B: Basis> EnergyLevel<B> {
    /// `inner` at the energy level `lambda = 1`, energies normalised by `grazing_energy`.
    ///
    /// # Errors
    /// [`ContinuationError::InvalidOption`] if `grazing_energy` is not positive and finite.
    pub fn new(inner: NonsmoothSystem<B>, grazing_energy: f64) -> Result<Self, Error> {
        if !(grazing_energy.is_finite() && grazing_energy > 0.0) {
            return Err(ContinuationError::InvalidOption {
                what: "grazing energy",
                value: grazing_energy,
            }
            .into());
        }
        Ok(Self {
            inner,
            grazing_energy,
            level: 1.0,
            scratch: Scratch::default(),
        })
    }

    /// The harmonic-balance system (at the frequency of the last evaluation).
    pub fn inner(&self) -> &NonsmoothSystem<B> {
        &self.inner
    }

    /// The harmonic-balance system, mutably.
    pub fn inner_mut(&mut self) -> &mut NonsmoothSystem<B> {
        &mut self.inner
    }

    /// The energy `E_g` that levels are relative to.
    pub fn grazing_energy(&self) -> f64 {
        self.grazing_energy
    }

    /// The prescribed energy `lambda E_g`.
    fn target(&self) -> f64 {
        self.level * self.grazing_energy
    }

    /// Moves the inner system to the frequency of `y` and returns `(x, Omega)` (an empty `y`
    /// is no unknowns at a NaN frequency: a non-finite residual).
    fn at<'y>(&mut self, y: &'y [f64]) -> (&'y [f64], f64) {
        let (x, omega) = augmented::split_or_nan(y);
        self.inner.set_parameter(omega);
        (x, omega)
    }

    /// The energy row's weight `s / (lambda E_g)`; NaN for a level that is not positive.
    fn row_scale(&mut self) -> f64 {
        let target = self.target();
        if target.is_finite() && target > 0.0 {
            self.inner.description().residual_scale() / target
        } else {
            f64::NAN
        }
    }

    /// The energy row `r (dE/dx, dE/dOmega)` at `(x, omega)` into `scratch.gradient`
    /// (length `n + 1`), with `r` the [`Self::row_scale`].
    fn border_row(&mut self, x: &[f64], omega: f64) {
        let r = self.row_scale();
        let (system, basis) = (self.inner.system(), self.inner.basis());
        let gradient = &mut self.scratch.gradient;
        gradient.resize(x.len() + 1, 0.0);
        energy_gradient(system, basis, x, omega, &mut gradient[..x.len()]);
        gradient[x.len()] = energy_frequency_derivative(system, basis, x, omega);
        gradient.iter_mut().for_each(|g| *g *= r);
    }
}

impl<B: Basis> Problem for EnergyLevel<B> {
    fn dimension(&self) -> usize {
        self.inner.dimension() + 1
    }

    fn residual(&mut self, y: &[f64], f: &mut [f64]) {
        let (x, omega) = self.at(y);
        let n = x.len();
        self.inner.residual(x, &mut f[..n]);
        let e = energy(self.inner.system(), self.inner.basis(), x, omega);
        f[n] = self.row_scale() * (e - self.target());
    }

    /// `[dF/dx, dF/dOmega; r dE/dx, r dE/dOmega]`, `r = s / (lambda E_g)`.
    fn jacobian(&mut self, y: &[f64], jac: &mut DenseMatrix) {
        let (x, omega) = self.at(y);
        let n = x.len();
        self.border_row(x, omega);
        let Scratch {
            jacobian,
            df,
            gradient,
            ..
        } = &mut self.scratch;
        df.resize(n, 0.0);
        self.inner.jacobian(x, jacobian);
        self.inner.parameter_derivative(x, df);
        fill_bordered(jac, jacobian, df, |i| gradient[i]);
    }

    fn structure(&mut self) -> Option<&mut dyn Structured> {
        Some(self)
    }
}

impl<B: Basis> Structured for EnergyLevel<B> {
    fn residual_scale(&self) -> f64 {
        self.inner.description().residual_scale()
    }

    fn solve_jacobian(
        &mut self,
        y: &[f64],
        rhs: &mut [f64],
        columns: usize,
    ) -> Option<Result<(), SingularStep>> {
        let (x, omega) = self.at(y);
        self.border_row(x, omega);
        let Scratch {
            gradient,
            columns: buffer,
            ..
        } = &mut self.scratch;
        let border = |i: usize| gradient[i];
        solve_bordered(&mut self.inner, x, (rhs, columns), border, buffer)
    }

    fn set_smoothing(&mut self, smoothing: f64) -> bool {
        self.inner.set_smoothing(smoothing)
    }

    fn active_set(&mut self, y: &[f64]) -> Option<Vec<usize>> {
        let (x, _) = self.at(y);
        self.inner.active_set(x)
    }
}

impl<B: Basis> ContinuationProblem for EnergyLevel<B> {
    /// The level `lambda = E / E_g`.
    fn parameter(&self) -> f64 {
        self.level
    }

    fn set_parameter(&mut self, lambda: f64) {
        self.level = lambda;
    }

    /// `d/dlambda` of the energy row, `-s E / (lambda^2 E_g)`; the harmonic-balance rows do
    /// not depend on the level.
    fn parameter_derivative(&mut self, y: &[f64], df: &mut [f64]) {
        let (x, omega) = self.at(y);
        let n = x.len();
        df[..n].iter_mut().for_each(|d| *d = 0.0);
        let e = energy(self.inner.system(), self.inner.basis(), x, omega);
        df[n] = -self.row_scale() * e / self.level;
    }
}
