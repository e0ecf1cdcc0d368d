//! Displacement, velocity and strain fields of a harmonic-balance solution anywhere in a bar.

use crate::bem::sinc_given_sine;
use crate::fourier::Basis;
use crate::system::{BarSystem, Layout};

/// Displacement `u`, velocity `u_t` and strain `u_x` at one point and instant.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct FieldValue {
    /// Displacement `u`.
    pub displacement: f64,
    /// Velocity `u_t`.
    pub velocity: f64,
    /// Strain `u_x`.
    pub strain: f64,
}

/// Evaluates the fields of the solution `x` (layout of
/// [`NonsmoothSystem`](crate::system::NonsmoothSystem)) at fundamental frequency `omega`:
/// `u(x, theta) = sum_i phi_i(theta) (A_i cos(k_i x) + B_i sin(k_i x)/k_i)`,
/// `k_i = n_i omega / c`, `theta = omega t`.
#[derive(Debug, Clone)]
pub struct FieldEvaluator<'a, B: Basis> {
    system: &'a BarSystem,
    basis: &'a B,
    x: &'a [f64],
    omega: f64,
}

impl<'a, B: Basis> FieldEvaluator<'a, B> {
    /// An evaluator for the solution `x` at `omega`.
    ///
    /// # Panics
    /// If `x.len() != basis.len() * 2 * n_bars`.
    pub fn new(system: &'a BarSystem, basis: &'a B, x: &'a [f64], omega: f64) -> Self {
        let expected = basis.len().saturating_mul(system.unknowns_per_harmonic());
        assert_eq!(
            x.len(),
            expected,
            "FieldEvaluator: the unknowns have the wrong length"
        );
        Self {
            system,
            basis,
            x,
            omega,
        }
    }

    /// Fields of bar `bar` at position `position` (in `[0, l]`) and phase `theta`.
    ///
    /// # Panics
    /// If `bar` is out of range.
    pub fn at(&self, bar: usize, position: f64, theta: f64) -> FieldValue {
        let len = self.basis.len();
        let mut phi = vec![0.0; len];
        let mut dphi = vec![0.0; len];
        self.basis.functions_at(theta, &mut phi);
        self.basis.derivatives_at(theta, &mut dphi);
        self.with_functions(bar, position, &phi, &dphi)
    }

    /// Fields at `position` with the basis functions and their derivatives at the wanted
    /// phase already evaluated (for loops over many positions at one instant).
    pub fn with_functions(
        &self,
        bar: usize,
        position: f64,
        phi: &[f64],
        dphi: &[f64],
    ) -> FieldValue {
        let b = &self.system.bars()[bar];
        let layout = Layout::of(self.system);
        let mut v = FieldValue::default();
        for i in 0..self.basis.len() {
            let k = b.wavenumber(self.basis.harmonic(i) as f64 * self.omega);
            let (a, bb) = layout.pair(self.x, i, bar);
            let (s, c) = (k * position).sin_cos();
            let u = a * c + bb * position * sinc_given_sine(k * position, s);
            let ux = -a * k * s + bb * c;
            v.displacement += phi[i] * u;
            v.strain += phi[i] * ux;
            v.velocity += self.omega * dphi[i] * u;
        }
        v
    }
}
