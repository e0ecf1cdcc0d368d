//! Mechanical energy of a harmonic-balance solution (formulation §7).

use crate::bar::{Bar, End, EndRef};
use crate::fourier::Basis;
use crate::modal::field::{FieldEvaluator, FieldValue};
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

/// Energy `E = sum_b EA_b/2 int (u_t^2/c_b^2 + u_x^2) dx + energy stored in conditions`,
/// evaluated at `t = 0` (phase `theta = 0`) for the solution `x` of a system with basis
/// `basis` at fundamental frequency `omega`. With the cosine basis velocities vanish at
/// `t = 0` and `E` is the potential energy there. Integrals use 8-point Gauss–Legendre panels
/// no longer than a quarter of the shortest wavelength present.
pub fn energy<B: Basis>(system: &BarSystem, basis: &B, x: &[f64], omega: f64) -> f64 {
    energy_at(system, basis, x, omega, 0.0)
}

/// The energy of [`energy`] at phase `theta = Omega t` instead of `t = 0`. The exact periodic
/// motion keeps it constant; a truncated one drifts by the work of its complementarity
/// residual, which [`crate::modal::diagnostics`] reports.
pub fn energy_at<B: Basis>(
    system: &BarSystem,
    basis: &B,
    x: &[f64],
    omega: f64,
    theta: f64,
) -> f64 {
    let len = basis.len();
    let mut phi = vec![0.0; len];
    let mut dphi = vec![0.0; len];
    basis.functions_at(theta, &mut phi);
    basis.derivatives_at(theta, &mut dphi);
    let fields = FieldEvaluator::new(system, basis, x, omega);
    let mut total = 0.0;
    let mut end_u = vec![[0.0; 2]; system.bars().len()];
    for (b, bar) in system.bars().iter().enumerate() {
        let field = |xp: f64| fields.with_functions(b, xp, &phi, &dphi);
        total += integrate_density(bar, basis.harmonics() as f64 * omega, &field);
        end_u[b] = [field(0.0).displacement, field(bar.length()).displacement];
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
fn integrate_density(bar: &Bar, omega_max: f64, field: &dyn Fn(f64) -> FieldValue) -> f64 {
    let l = bar.length();
    let k = bar.wavenumber(omega_max);
    let panels = ((k * l / (0.5 * std::f64::consts::PI)).ceil() as usize).max(4);
    let h = l / panels as f64;
    let mut acc = 0.0;
    for p in 0..panels {
        let mid = (p as f64 + 0.5) * h;
        for (gx, gw) in GAUSS_X.iter().zip(GAUSS_W) {
            for xp in [mid - 0.5 * h * gx, mid + 0.5 * h * gx] {
                let v = field(xp);
                acc += gw * 0.5 * h * crate::bem::energy_density(bar, v.velocity, v.strain);
            }
        }
    }
    acc
}
