//! Mechanical energy of a harmonic-balance solution (formulation §7), in closed form from
//! boundary values.
//!
//! Each harmonic of a bar is a Helmholtz solution `u_i = A_i cos(k_i x) + B_i sin(k_i x)/k_i`,
//! so `u_i'' = -k_i^2 u_i` and Green's identity turns the integrals of products into boundary
//! terms:
//!
//! ```text
//! (k_i^2 - k_j^2) int u_i u_j dx = [u_i u_j' - u_j u_i']_0^l          (k_i != k_j)
//! int u_i' u_j' dx = [u_i u_j']_0^l + k_j^2 int u_i u_j dx
//! ```
//!
//! and the diagonal terms (`k_i = k_j`) have elementary closed forms. The energy of a motion is
//! then a quadratic form in the harmonics: `O(m^2)` flops per bar, no quadrature.

use crate::bar::{Bar, End, EndRef};
use crate::bem::sinc;
use crate::fourier::Basis;
use crate::system::BarSystem;

/// Energy `E = sum_b EA_b/2 int (u_t^2/c_b^2 + u_x^2) dx + energy stored in conditions`,
/// evaluated at `t = 0` (phase `theta = 0`) for the solution `x` of a system with basis
/// `basis` at fundamental frequency `omega`. With the cosine basis velocities vanish at
/// `t = 0` and `E` is the potential energy there.
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
    let nb = system.bars().len();
    let mut phi = vec![0.0; len];
    let mut dphi = vec![0.0; len];
    basis.functions_at(theta, &mut phi);
    basis.derivatives_at(theta, &mut dphi);
    let mut total = 0.0;
    let mut end_u = vec![[0.0; 2]; nb];
    let mut harmonics = Vec::with_capacity(len);
    for (b, bar) in system.bars().iter().enumerate() {
        harmonics.clear();
        harmonics.extend((0..len).map(|i| {
            let j = (i * nb + b) * 2;
            Harmonic::new(bar, basis.harmonic(i) as f64 * omega, x[j], x[j + 1])
        }));
        let c2 = bar.wave_speed() * bar.wave_speed();
        let (mut strain, mut kinetic) = (0.0, 0.0);
        for i in 0..len {
            let (wi, vi) = (phi[i], omega * dphi[i]);
            if wi == 0.0 && vi == 0.0 {
                continue;
            }
            for j in 0..=i {
                let (wj, vj) = (phi[j], omega * dphi[j]);
                if wi * wj == 0.0 && vi * vj == 0.0 {
                    continue;
                }
                let (int_uu, int_dd) = pair_integrals(&harmonics[i], &harmonics[j], bar.length());
                let twice = if i == j { 1.0 } else { 2.0 };
                strain += twice * wi * wj * int_dd;
                kinetic += twice * vi * vj * int_uu;
            }
        }
        total += 0.5 * bar.stiffness() * (strain + kinetic / c2);
        end_u[b] = [
            harmonics.iter().zip(&phi).map(|(h, w)| w * h.u0).sum(),
            harmonics.iter().zip(&phi).map(|(h, w)| w * h.ul).sum(),
        ];
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

/// One harmonic of one bar with its boundary values.
struct Harmonic {
    k: f64,
    a: f64,
    b: f64,
    /// `u(0), u'(0), u(l), u'(l)`.
    u0: f64,
    d0: f64,
    ul: f64,
    dl: f64,
}

impl Harmonic {
    fn new(bar: &Bar, omega: f64, a: f64, b: f64) -> Self {
        let k = bar.wavenumber(omega);
        let l = bar.length();
        let (s, c) = (k * l).sin_cos();
        Self {
            k,
            a,
            b,
            u0: a,
            d0: b,
            ul: a * c + b * l * sinc(k * l),
            dl: -a * k * s + b * c,
        }
    }
}

/// `(1 - sinc z) / z^2`, accurate near `z = 0`.
fn one_minus_sinc_over_z2(z: f64) -> f64 {
    if z.abs() < 1e-2 {
        let z2 = z * z;
        1.0 / 6.0 - z2 / 120.0 + z2 * z2 / 5040.0
    } else {
        (1.0 - sinc(z)) / (z * z)
    }
}

/// `(int u_i u_j dx, int u_i' u_j' dx)` over `[0, l]`.
fn pair_integrals(hi: &Harmonic, hj: &Harmonic, l: f64) -> (f64, f64) {
    if hi.k == hj.k {
        // int sin^2(kx) = l/2 - sin(2kl)/(4k) = k^2 l^3 g(2kl) * 2, int cos^2 = l - that,
        // int sin cos = sin^2(kl)/(2k), with g(z) = (1 - sinc z)/z^2.
        let k = hi.k;
        let sin2_over_k2 = 2.0 * l * l * l * one_minus_sinc_over_z2(2.0 * k * l);
        let cos2 = l - k * k * sin2_over_k2;
        let sc_over_k = 0.5 * (l * sinc(k * l)).powi(2);
        let (a1, b1, a2, b2) = (hi.a, hi.b, hj.a, hj.b);
        let int_uu = a1 * a2 * cos2 + b1 * b2 * sin2_over_k2 + (a1 * b2 + a2 * b1) * sc_over_k;
        let int_dd = a1 * a2 * k.powi(4) * sin2_over_k2 + b1 * b2 * cos2
            - (a1 * b2 + a2 * b1) * k * k * sc_over_k;
        (int_uu, int_dd)
    } else {
        let bracket_ij = hi.ul * hj.dl - hi.u0 * hj.d0;
        let bracket_ji = hj.ul * hi.dl - hj.u0 * hi.d0;
        let int_uu = (bracket_ij - bracket_ji) / (hi.k * hi.k - hj.k * hj.k);
        (int_uu, bracket_ij + hj.k * hj.k * int_uu)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bar::Bar;
    use crate::fourier::CosineBasis;
    use crate::modal::field::FieldEvaluator;
    use crate::system::AssemblyBuilder;

    /// Composite Gauss–Legendre quadrature of the energy density: the oracle.
    fn quadrature_energy(
        system: &BarSystem,
        basis: &CosineBasis,
        x: &[f64],
        omega: f64,
        theta: f64,
    ) -> f64 {
        let gx = [
            0.183_434_642_495_649_8,
            0.525_532_409_916_329,
            0.796_666_477_413_626_7,
            0.960_289_856_497_536_3,
        ];
        let gw = [
            0.362_683_783_378_362,
            0.313_706_645_877_887_3,
            0.222_381_034_453_374_5,
            0.101_228_536_290_376_3,
        ];
        let fields = FieldEvaluator::new(system, basis, x, omega);
        let mut total = 0.0;
        for (b, bar) in system.bars().iter().enumerate() {
            let panels = 400;
            let h = bar.length() / panels as f64;
            for p in 0..panels {
                let mid = (p as f64 + 0.5) * h;
                for (x_, w) in gx.iter().zip(gw) {
                    for xp in [mid - 0.5 * h * x_, mid + 0.5 * h * x_] {
                        let v = fields.at(b, xp, theta);
                        total +=
                            w * 0.5 * h * crate::bem::energy_density(bar, v.velocity, v.strain);
                    }
                }
            }
        }
        let f = |e: EndRef| {
            let bar = system.bar(e.bar);
            let pos = if e.end == End::Left {
                0.0
            } else {
                bar.length()
            };
            fields.at(e.bar.index(), pos, theta).displacement
        };
        total
            + system
                .conditions()
                .map(|c| c.stored_energy(&f))
                .sum::<f64>()
    }

    #[test]
    fn closed_form_matches_quadrature_at_any_phase() {
        let mut builder = AssemblyBuilder::new();
        let one = builder.add_bar(Bar::new(1.0, 1.0, 1.0).unwrap());
        let two = builder.add_bar(Bar::new(0.7, 1.9, 2.5).unwrap());
        builder
            .robin(one.left(), 0.8)
            .unwrap()
            .dirichlet(two.left())
            .contact(one.right(), two.right(), 1e-3)
            .unwrap();
        let system = builder.build().unwrap();
        let basis = CosineBasis::new(9, 4).unwrap();
        let x: Vec<f64> = (0..basis.len() * 4)
            .map(|i| 1e-3 * (((i * 37) % 11) as f64 - 5.0) / (1.0 + i as f64))
            .collect();
        for (omega, theta) in [(1.3, 0.0), (0.4, 0.9), (2.7, 2.0)] {
            let exact = quadrature_energy(&system, &basis, &x, omega, theta);
            let fast = energy_at(&system, &basis, &x, omega, theta);
            assert!((fast / exact - 1.0).abs() < 1e-10, "{fast} vs {exact}");
        }
    }

    #[test]
    fn small_wavenumber_series_is_continuous() {
        for z in [0.0099_f64, 0.0101] {
            let direct = if z == 0.0 {
                1.0 / 6.0
            } else {
                (1.0 - z.sin() / z) / (z * z)
            };
            assert!((one_minus_sinc_over_z2(z) - direct).abs() < 1e-9);
        }
    }
}
