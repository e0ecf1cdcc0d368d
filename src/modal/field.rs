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

    /// Displacement and velocity at `position`, as [`FieldEvaluator::with_functions`] gives
    /// them, with `cos` and `sin` of `k_n x` for every harmonic `n` from one `sin_cos` of the
    /// fundamental's angle by the angle-addition recurrence, and the wavenumbers of
    /// `prepared` ([`FieldEvaluator::wavenumbers`]; `table` is scratch). The initial state of
    /// a time-domain march evaluates the fields at four points per cell, where a `sin_cos`
    /// per harmonic and point was most of the march's cost; the recurrence departs from the
    /// direct values by rounding only (a few ulps per harmonic).
    pub(crate) fn displacement_and_velocity(
        &self,
        (bar, position): (usize, f64),
        (phi, dphi): (&[f64], &[f64]),
        (prepared, table): (&Wavenumbers, &mut Vec<(f64, f64)>),
    ) -> (f64, f64) {
        let layout = Layout::of(self.system);
        let (s1, c1) = (prepared.fundamental[bar] * position).sin_cos();
        table.clear();
        table.push((0.0, 1.0));
        for n in 1..=prepared.top {
            let (s, c) = table[n - 1];
            table.push((s * c1 + c * s1, c * c1 - s * s1));
        }
        let (mut displacement, mut velocity) = (0.0, 0.0);
        let ks = &prepared.by_bar[bar];
        for (i, &(k, inverse)) in ks.iter().enumerate() {
            let (a, bb) = layout.pair(self.x, i, bar);
            let (s, c) = table[self.basis.harmonic(i)];
            let z = k * position;
            // `position sin(z) / z`, as `sinc_given_sine` gives it, without the division.
            let sinc_x = if z.abs() < 1e-2 {
                position * sinc_given_sine(z, s)
            } else {
                s * inverse
            };
            let u = a * c + bb * sinc_x;
            displacement += phi[i] * u;
            velocity += self.omega * dphi[i] * u;
        }
        (displacement, velocity)
    }

    /// The wavenumbers of every bar and basis function at this evaluator's frequency, for
    /// [`FieldEvaluator::displacement_and_velocity`].
    pub(crate) fn wavenumbers(&self) -> Wavenumbers {
        let bars = self.system.bars();
        Wavenumbers {
            top: (0..self.basis.len())
                .map(|i| self.basis.harmonic(i))
                .max()
                .unwrap_or(0),
            fundamental: bars.iter().map(|b| b.wavenumber(self.omega)).collect(),
            by_bar: bars
                .iter()
                .map(|b| {
                    (0..self.basis.len())
                        .map(|i| {
                            let k = b.wavenumber(self.basis.harmonic(i) as f64 * self.omega);
                            (k, 1.0 / k)
                        })
                        .collect()
                })
                .collect(),
        }
    }
}

/// Per bar, the wavenumber `k_i` of each basis function and its inverse, the fundamental's,
/// and the highest harmonic (see [`FieldEvaluator::wavenumbers`]).
#[derive(Debug, Clone)]
pub(crate) struct Wavenumbers {
    top: usize,
    fundamental: Vec<f64>,
    by_bar: Vec<Vec<(f64, f64)>>,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bar::Bar;
    use crate::fourier::{CosineBasis, SineCosineBasis};
    use crate::reference::two_bars_in_contact;

    /// The recurrence of [`FieldEvaluator::displacement_and_velocity`] gives the direct
    /// fields to rounding, for every harmonic of a basis of 80 and a bar of several
    /// wavelengths.
    fn agree<B: Basis>(basis: &B) {
        let system = two_bars_in_contact(Bar::new(0.95, 1.3, 2.0).unwrap(), 1e-3).unwrap();
        let n = basis.len() * system.unknowns_per_harmonic();
        let x: Vec<f64> = (0..n)
            .map(|i| ((i * 7919) % 97) as f64 / 97.0 - 0.5)
            .collect();
        let omega = 2.3;
        let fields = FieldEvaluator::new(&system, basis, &x, omega);
        let (mut phi, mut dphi) = (vec![0.0; basis.len()], vec![0.0; basis.len()]);
        basis.functions_at(0.7, &mut phi);
        basis.derivatives_at(0.7, &mut dphi);
        let (ks, mut table) = (fields.wavenumbers(), Vec::new());
        for bar in 0..2 {
            let length = system.bars()[bar].length();
            for j in 0..=40 {
                let p = length * j as f64 / 40.0;
                let direct = fields.with_functions(bar, p, &phi, &dphi);
                let (u, v) =
                    fields.displacement_and_velocity((bar, p), (&phi, &dphi), (&ks, &mut table));
                let scale = x.iter().map(|v| v.abs()).sum::<f64>() * omega * 80.0;
                assert!(
                    (u - direct.displacement).abs() <= 1e-12 * scale,
                    "{u} {direct:?}"
                );
                assert!(
                    (v - direct.velocity).abs() <= 1e-12 * scale,
                    "{v} {direct:?}"
                );
            }
        }
    }

    #[test]
    fn the_recurrence_gives_the_direct_fields_to_rounding() {
        agree(&CosineBasis::new(80, 30).unwrap());
        agree(&SineCosineBasis::new(20, 30).unwrap());
    }
}
