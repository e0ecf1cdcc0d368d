//! Mechanical energy of a harmonic-balance solution (formulation §7).

use crate::bar::{Bar, End, EndRef};
use crate::bem::sinc;
use crate::fourier::Basis;
use crate::system::BarSystem;

/// Gauss–Legendre nodes and weights on `[-1, 1]`, 8 points.
const GAUSS_X: [f64; 4] = [
    0.183_434_642_495_649_8,
    0.525_532_409_916_329,
    0.796_666_477_413_626_7,
    0.960_289_856_497_536_3,
];
const GAUSS_W: [f64; 4] = [
    0.362_683_783_378_362,
    0.313_706_645_877_887_3,
    0.222_381_034_453_374_5,
    0.101_228_536_290_376_3,
];

/// The Helmholtz coefficients `(A_i, B_i)` of bar `bar` for every basis coefficient `i`.
///
/// # Panics
/// If `x` is shorter than `basis.len() * 2 n_bars`.
pub fn helmholtz_coefficients(x: &[f64], n_bars: usize, bar: usize, len: usize) -> Vec<(f64, f64)> {
    (0..len)
        .map(|i| {
            let k = (i * n_bars + bar) * 2;
            (x[k], x[k + 1])
        })
        .collect()
}

/// Displacement and strain of `u = A cos(kx) + B sin(kx)/k` at `x`.
fn mode_values(a: f64, b: f64, k: f64, x: f64) -> (f64, f64) {
    let (s, c) = (k * x).sin_cos();
    (a * c + b * x * sinc(k * x), -a * k * s + b * c)
}

/// Energy `E = sum_b EA_b/2 int (u_t^2/c_b^2 + u_x^2) dx + energy stored in conditions`,
/// evaluated at `t = 0` (phase `theta = 0`) for the solution `x` of a system with basis
/// `basis` at fundamental frequency `omega`. With the cosine basis velocities vanish at
/// `t = 0` and `E` is the potential energy there. Integrals use 8-point Gauss–Legendre panels
/// no longer than a quarter of the shortest wavelength present.
pub fn energy<B: Basis>(system: &BarSystem, basis: &B, x: &[f64], omega: f64) -> f64 {
    let len = basis.len();
    let nb = system.bars().len();
    let mut phi = vec![0.0; len];
    let mut dphi = vec![0.0; len];
    basis.functions_at(0.0, &mut phi);
    basis.derivatives_at(0.0, &mut dphi);
    let mut total = 0.0;
    let mut end_u = vec![[0.0; 2]; nb];
    for (b, bar) in system.bars().iter().enumerate() {
        let coefs = helmholtz_coefficients(x, nb, b, len);
        let field = |xp: f64| {
            let (mut u, mut ut, mut ux) = (0.0, 0.0, 0.0);
            for (i, &(a, bb)) in coefs.iter().enumerate() {
                let k = bar.wavenumber(basis.harmonic(i) as f64 * omega);
                let (ui, uxi) = mode_values(a, bb, k, xp);
                u += phi[i] * ui;
                ux += phi[i] * uxi;
                ut += omega * dphi[i] * ui;
            }
            (u, ut, ux)
        };
        total += integrate_density(bar, basis.harmonics() as f64 * omega, &field);
        end_u[b] = [field(0.0).0, field(bar.length()).0];
    }
    let displacement = |e: EndRef| match e.end {
        End::Left => end_u[e.bar.index()][0],
        End::Right => end_u[e.bar.index()][1],
    };
    total
        + system
            .conditions()
            .map(|c| c.stored_energy(&displacement))
            .sum::<f64>()
}

/// `int_0^l EA/2 (u_t^2/c^2 + u_x^2) dx` for a field with angular frequencies up to
/// `omega_max`.
fn integrate_density(bar: &Bar, omega_max: f64, field: &dyn Fn(f64) -> (f64, f64, f64)) -> f64 {
    let l = bar.length();
    let k = bar.wavenumber(omega_max);
    let panels = ((k * l / (0.5 * std::f64::consts::PI)).ceil() as usize).max(4);
    let h = l / panels as f64;
    let mut acc = 0.0;
    for p in 0..panels {
        let mid = (p as f64 + 0.5) * h;
        for (gx, gw) in GAUSS_X.iter().zip(GAUSS_W) {
            for xp in [mid - 0.5 * h * gx, mid + 0.5 * h * gx] {
                let (_, ut, ux) = field(xp);
                acc += gw * 0.5 * h * crate::bem::energy_density(bar, ut, ux);
            }
        }
    }
    acc
}
