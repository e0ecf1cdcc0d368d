//! Derivatives of the energy of [`super::energy`]: the gradient in the unknowns, in closed
//! form, and the derivative in the frequency. They are the border row of the energy-level
//! problem ([`crate::branches::EnergyLevel`]), which fixes `E(x; Omega)` and solves for
//! `(x, Omega)`.
//!
//! For one bar the strain part of the energy is `EA/2 sum_ij w_i w_j int u_i' u_j' dx`, a
//! quadratic form in the harmonics' Helmholtz coefficients `(a_i, b_i)`. Its derivative in
//! `a_i` is `EA w_i sum_j w_j int e_i' u_j' dx` with `e_i = cos(k_i x)` the harmonic of
//! unit `a_i`, and the same with `e_i = sin(k_i x)/k_i` for `b_i`: one row of pair
//! integrals per unknown, by the same Green identities as the energy, `O(m^2)` per bar.
//! The kinetic part is alike with `v_i` and `int e_i u_j dx / c^2`. The conditions' stored
//! energies are functions of the bars' end values, which are linear in the unknowns; their
//! derivatives in the end values are taken by central differences (exact, to rounding, for
//! the quadratic energies of springs).

use super::{
    energy, green, stored_energy, time_weights, Conditions, Diagonal, Harmonic, Harmonics, LANES,
};
use crate::fourier::Basis;
use crate::system::{BarSystem, Layout};

/// Relative step of the central differences of the stored energies in the end values and
/// of the energy in the frequency.
const RELATIVE_STEP: f64 = 1e-5;

/// The energy `E(x; omega)` of [`energy`] (at `t = 0`), returned, and its gradient in the
/// unknowns `dE/dx`, written into `gradient`.
///
/// # Panics
/// If `x` or `gradient` does not have the length of the system's unknowns (as [`energy`]).
pub fn energy_gradient<B: Basis>(
    system: &BarSystem,
    basis: &B,
    x: &[f64],
    omega: f64,
    gradient: &mut [f64],
) -> f64 {
    let e = energy(system, basis, x, omega);
    assert_eq!(
        gradient.len(),
        x.len(),
        "modal::energy_gradient: the gradient has the wrong length"
    );
    let len = basis.len();
    let nb = system.bars().len();
    let layout = Layout::of(system);
    let mut weights = vec![0.0; 2 * len];
    let (w, v) = weights.split_at_mut(len);
    time_weights(basis, (omega, 0.0), w, v);
    let mut harmonics = Harmonics::new(len);
    let mut ends = vec![0.0; 4 * nb];
    // Unit harmonics of each unknown, kept for the chain rule of the stored energies.
    let mut units = Vec::with_capacity(nb * len);
    for (b, bar) in system.bars().iter().enumerate() {
        harmonics.fill(bar, basis, x, (b, layout), omega, (w, v));
        ends[4 * b..4 * b + 4].copy_from_slice(&harmonics.end_values());
        let c2 = bar.wave_speed() * bar.wave_speed();
        for i in 0..len {
            let hi = harmonics.get(i);
            let pair = unit_harmonics(&hi, harmonics.l);
            let diagonal = Diagonal::new(hi.k, harmonics.l, hi.sinc_kl);
            for (which, unit) in pair.iter().enumerate() {
                let (strain, kinetic) = harmonics.row_with(unit, &diagonal);
                gradient[layout.index(i, b, which)] =
                    bar.stiffness() * (hi.w * strain + hi.v * kinetic / c2);
            }
            units.push(pair);
        }
    }
    let by_end = stored_energy_gradient(system, &ends);
    if by_end.iter().any(|&g| g != 0.0) {
        for b in 0..nb {
            let g = &by_end[4 * b..4 * b + 4];
            for i in 0..len {
                let w = w[i];
                for (which, unit) in units[b * len + i].iter().enumerate() {
                    let d = g[0] * unit.a + g[1] * unit.b + g[2] * unit.ul + g[3] * unit.dl;
                    gradient[layout.index(i, b, which)] += w * d;
                }
            }
        }
    }
    e
}

/// `dE/dOmega` at fixed unknowns, by a central difference of relative step
/// [`RELATIVE_STEP`] (the energy is smooth in `Omega` through the wave numbers
/// `k = n Omega / c`).
pub(crate) fn energy_frequency_derivative<B: Basis>(
    system: &BarSystem,
    basis: &B,
    x: &[f64],
    omega: f64,
) -> f64 {
    let h = RELATIVE_STEP * omega.abs().max(f64::MIN_POSITIVE);
    (energy(system, basis, x, omega + h) - energy(system, basis, x, omega - h)) / (2.0 * h)
}

/// The harmonics of unit `a` (`cos(kx)`) and unit `b` (`sin(kx)/k`) at the wave number and
/// time weights of `h`, on a bar of length `l`.
fn unit_harmonics(h: &Harmonic, l: f64) -> [Harmonic; 2] {
    let (s, c) = (h.k * l).sin_cos();
    [
        Harmonic {
            a: 1.0,
            b: 0.0,
            ul: c,
            dl: -h.k * s,
            ..*h
        },
        Harmonic {
            a: 0.0,
            b: 1.0,
            ul: l * h.sinc_kl,
            dl: c,
            ..*h
        },
    ]
}

impl Harmonics {
    /// `(sum_j w_j int e' u_j' dx, sum_j v_j int e u_j dx)` over every harmonic `j` of the
    /// bar, for a harmonic `e` at the wave number of `diagonal` (Green's identity where
    /// `k_j != k`, the closed form where they are equal).
    fn row_with(&self, e: &Harmonic, diagonal: &Diagonal) -> (f64, f64) {
        let (mut strain, mut kinetic) = (0.0, 0.0);
        for j in 0..self.len {
            let hj = self.get(j);
            let (int_uu, int_dd) = if hj.k2 == e.k2 {
                diagonal.integrals((e.a, e.b), (hj.a, hj.b))
            } else {
                green(e, &self.blocks[j / LANES], j % LANES)
            };
            strain += hj.w * int_dd;
            kinetic += hj.v * int_uu;
        }
        (strain, kinetic)
    }
}

/// `dE_s / d ends` of the stored energy `E_s` of every condition, by central differences in
/// each end value (`ends[4 b..4 b + 4] = (u(0), u_x(0), u(l_b), u_x(l_b))` of bar `b`).
fn stored_energy_gradient(system: &BarSystem, ends: &[f64]) -> Vec<f64> {
    let mut gradient = vec![0.0; ends.len()];
    let size = ends.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let mut probe = ends.to_vec();
    // Displacement and strain scales differ by a bar's wave number; one step relative to
    // the largest end value serves both for the quadratic energies of linear conditions.
    let h = RELATIVE_STEP * size.max(f64::MIN_POSITIVE);
    for i in 0..ends.len() {
        probe[i] = ends[i] + h;
        let up = stored_energy(system, &probe, Conditions::All);
        probe[i] = ends[i] - h;
        let down = stored_energy(system, &probe, Conditions::All);
        probe[i] = ends[i];
        gradient[i] = (up - down) / (2.0 * h);
    }
    gradient
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bar::Bar;
    use crate::fourier::CosineBasis;
    use crate::modal::energy::tests::coefficients;
    use crate::reference::{contact_chain, robin_bar_with_obstacle, two_bars_in_contact};

    fn systems() -> Vec<BarSystem> {
        vec![
            robin_bar_with_obstacle(0.5, 1e-3).unwrap(),
            two_bars_in_contact(Bar::new(0.7, 1.9, 2.5).unwrap(), 1e-3).unwrap(),
            contact_chain(3, 1e-3, 2.0).unwrap(),
        ]
    }

    /// The energy is quadratic in the unknowns: a central difference of any step is its
    /// directional derivative to rounding, the oracle of the closed-form gradient.
    #[test]
    fn gradient_matches_central_differences() {
        let basis = CosineBasis::new(7, 8).unwrap();
        for (s, system) in systems().iter().enumerate() {
            let n = basis.len() * system.unknowns_per_harmonic();
            for (t, omega) in [0.37, 1.9, 4.4].into_iter().enumerate() {
                let x = coefficients(n, (11 * s + t) as u64, 1e-3);
                let mut gradient = vec![0.0; n];
                let e = energy_gradient(system, &basis, &x, omega, &mut gradient);
                assert_eq!(e, energy(system, &basis, &x, omega));
                let size = gradient.iter().fold(0.0f64, |m, g| m.max(g.abs()));
                for i in 0..n {
                    let h = 1e-4;
                    let mut probe = x.clone();
                    probe[i] += h;
                    let up = energy(system, &basis, &probe, omega);
                    probe[i] -= 2.0 * h;
                    let down = energy(system, &basis, &probe, omega);
                    let fd = (up - down) / (2.0 * h);
                    assert!(
                        (gradient[i] - fd).abs() <= 1e-7 * size,
                        "system {s}, omega {omega}, unknown {i}: {} vs {fd}",
                        gradient[i]
                    );
                }
            }
        }
    }

    #[test]
    fn frequency_derivative_matches_a_finer_difference() {
        let basis = CosineBasis::new(5, 8).unwrap();
        for system in systems() {
            let n = basis.len() * system.unknowns_per_harmonic();
            let x = coefficients(n, 3, 1e-3);
            let omega = 1.3;
            let d = energy_frequency_derivative(&system, &basis, &x, omega);
            let h = 1e-3;
            let e = |w: f64| energy(&system, &basis, &x, w);
            // Fourth-order stencil as the oracle.
            let fd = (e(omega - 2.0 * h) - 8.0 * e(omega - h) + 8.0 * e(omega + h)
                - e(omega + 2.0 * h))
                / (12.0 * h);
            assert!((d - fd).abs() <= 1e-6 * fd.abs(), "{d} vs {fd}");
        }
    }
}
