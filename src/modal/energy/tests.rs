//! Tests of the closed-form energy: a straightforward pairwise implementation (one struct and
//! one branch per pair) as the oracle of the SIMD-friendly row sums, and a quadrature of the
//! fields as the oracle of both.

use super::*;
use crate::bar::Bar;
use crate::fourier::CosineBasis;
use crate::modal::field::FieldEvaluator;
use crate::system::AssemblyBuilder;

/// [`energy_at`] pair by pair.
fn pairwise_energy_at<B: Basis>(
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
            let (a, bi) = Layout::of(system).pair(x, i, b);
            OracleHarmonic::new(bar, basis.harmonic(i) as f64 * omega, a, bi)
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
    let displacement = |e: EndRef, q: Quantity| {
        assert_eq!(
            q,
            Quantity::Displacement,
            "the oracle's conditions are Robin springs"
        );
        match e.end {
            End::Left => end_u[e.bar.index()][0],
            End::Right => end_u[e.bar.index()][1],
        }
    };
    total
        + system
            .conditions()
            .map(|c| c.stored_energy(&displacement))
            .sum::<f64>()
}

/// One harmonic of one bar with its boundary values.
struct OracleHarmonic {
    k: f64,
    a: f64,
    b: f64,
    /// `u(0), u'(0), u(l), u'(l)`.
    u0: f64,
    d0: f64,
    ul: f64,
    dl: f64,
}

impl OracleHarmonic {
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

/// `(int u_i u_j dx, int u_i' u_j' dx)` over `[0, l]`.
fn pair_integrals(hi: &OracleHarmonic, hj: &OracleHarmonic, l: f64) -> (f64, f64) {
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

/// A deterministic spread of coefficients in `[-1, 1] * scale`, decaying with the index.
pub(super) fn coefficients(n: usize, seed: u64, scale: f64) -> Vec<f64> {
    let mut state = seed;
    (0..n)
        .map(|i| {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            let r = (state >> 11) as f64 / (1u64 << 53) as f64;
            scale * (2.0 * r - 1.0) / (1.0 + 0.1 * i as f64)
        })
        .collect()
}

fn two_bar_system() -> BarSystem {
    crate::reference::two_bars_in_contact(Bar::new(0.7, 1.9, 2.5).unwrap(), 1e-3).unwrap()
}

fn assert_close(fast: f64, slow: f64, what: &str) {
    let scale = slow.abs().max(f64::MIN_POSITIVE);
    assert!(
        (fast - slow).abs() <= 1e-12 * scale,
        "{what}: {fast} vs {slow} (relative {:e})",
        (fast - slow).abs() / scale
    );
}

#[test]
fn row_sums_match_pairwise_formula() {
    let systems = [
        (
            "clamped",
            crate::reference::clamped_bar_with_obstacle(1e-3).unwrap(),
        ),
        (
            "robin",
            crate::reference::robin_bar_with_obstacle(0.5, 1e-3).unwrap(),
        ),
        ("two bars", two_bar_system()),
    ];
    for (name, system) in &systems {
        let nb = system.bars().len();
        for m in [1, 2, 3, 4, 5, 9, 40, 81] {
            let basis = CosineBasis::new(m, 3).unwrap();
            for (seed, (omega, theta)) in [
                (1.3, 0.0),
                (0.4, 0.9),
                (2.7, 2.0),
                (1.6, -0.3),
                (1e-4, 1.1),
                (0.0, 0.7),
            ]
            .into_iter()
            .enumerate()
            {
                let x = coefficients(2 * nb * basis.len(), seed as u64 + 7, 1e-3);
                let fast = energy_at(system, &basis, &x, omega, theta);
                let slow = pairwise_energy_at(system, &basis, &x, omega, theta);
                assert_close(
                    fast,
                    slow,
                    &format!("{name} m={m} omega={omega} theta={theta}"),
                );
            }
        }
    }
}

#[test]
fn exact_clamped_mode_matches_pairwise_formula() {
    let system = crate::reference::clamped_bar_with_obstacle(1e-3).unwrap();
    for m in [10, 40, 160] {
        let basis = CosineBasis::new(m, 3).unwrap();
        for period in [3.1, 3.5, 3.95] {
            let mode = crate::reference::ClampedFirstMode::new(1e-3, period);
            let x = mode.unknowns(m);
            let omega = 2.0 * std::f64::consts::PI / period;
            for theta in [0.0, 0.3] {
                let fast = energy_at(&system, &basis, &x, omega, theta);
                let slow = pairwise_energy_at(&system, &basis, &x, omega, theta);
                assert_close(fast, slow, &format!("m={m} T={period} theta={theta}"));
            }
        }
    }
}

/// Constant + cosine + sine: every harmonic `n >= 1` appears twice, so each row has a pair
/// with equal wavenumbers off the diagonal. Only what `energy_at` reads is implemented.
#[derive(Debug, Clone)]
struct SineCosine(usize);

impl Basis for SineCosine {
    fn len(&self) -> usize {
        2 * self.0 + 1
    }
    fn harmonics(&self) -> usize {
        self.0
    }
    fn harmonic(&self, i: usize) -> usize {
        i.div_ceil(2)
    }
    fn samples(&self) -> usize {
        3 * self.0
    }
    fn functions_at(&self, theta: f64, out: &mut [f64]) {
        for (i, o) in out.iter_mut().enumerate() {
            let n = self.harmonic(i) as f64;
            *o = match i {
                0 => 0.5,
                _ if i % 2 == 1 => (n * theta).cos(),
                _ => (n * theta).sin(),
            };
        }
    }
    fn derivatives_at(&self, theta: f64, out: &mut [f64]) {
        for (i, o) in out.iter_mut().enumerate() {
            let n = self.harmonic(i) as f64;
            *o = match i {
                0 => 0.0,
                _ if i % 2 == 1 => -n * (n * theta).sin(),
                _ => n * (n * theta).cos(),
            };
        }
    }
    fn synthesize(&self, _: &[f64], _: &mut [f64]) {
        unimplemented!()
    }
    fn project(&self, _: &[f64], _: &mut [f64]) {
        unimplemented!()
    }
    fn weighted_gram(&self, _: &[f64], _: &mut [f64]) {
        unimplemented!()
    }
}

#[test]
fn equal_wavenumbers_off_the_diagonal_match_pairwise_formula() {
    let system = two_bar_system();
    for m in [1, 3, 8, 20] {
        let basis = SineCosine(m);
        for (seed, (omega, theta)) in [(1.3, 0.0), (0.9, 0.4), (2.2, 1.7), (0.0, 0.5)]
            .into_iter()
            .enumerate()
        {
            let x = coefficients(4 * basis.len(), seed as u64 + 99, 1e-2);
            let fast = energy_at(&system, &basis, &x, omega, theta);
            let slow = pairwise_energy_at(&system, &basis, &x, omega, theta);
            assert_close(fast, slow, &format!("m={m} omega={omega} theta={theta}"));
        }
    }
}

#[test]
fn sinc_from_sin_is_sinc() {
    for z in [
        0.0, 1e-3, -0.0099, 0.01, -0.0100001, 0.3, 1.0, -2.5, 40.0, 1e3,
    ] {
        assert_eq!(
            sinc_from_sin(z, z.sin()).to_bits(),
            sinc(z).to_bits(),
            "z = {z}"
        );
    }
}

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
                    total += w * 0.5 * h * crate::bem::energy_density(bar, v.velocity, v.strain);
                }
            }
        }
    }
    let f = |e: EndRef, q: Quantity| {
        assert_eq!(
            q,
            Quantity::Displacement,
            "the oracle's conditions are Robin springs"
        );
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
        .unwrap()
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

/// A condition whose stored energy is `scale` times one end quantity: a probe of what
/// [`energy_at`] hands the conditions.
#[derive(Debug)]
struct Probe {
    end: EndRef,
    quantity: Quantity,
    scale: f64,
}

impl crate::bc::BoundaryCondition for Probe {
    fn name(&self) -> String {
        format!("probe of {:?} at {}", self.quantity, self.end)
    }
    fn ends(&self) -> Vec<EndRef> {
        Vec::new()
    }
    fn stored_energy(&self, value: &dyn Fn(EndRef, Quantity) -> f64) -> f64 {
        self.scale * value(self.end, self.quantity)
    }
}

/// The end quantities that conditions read in their stored energy are the fields' at the
/// ends, at any phase: displacement, strain, their outward forms and the contact force.
#[test]
fn conditions_read_the_end_quantities_of_the_fields() {
    let mut builder = AssemblyBuilder::new();
    let bar = builder.add_bar(Bar::new(0.7, 1.9, 2.5).unwrap());
    builder
        .robin(bar.left(), 0.8)
        .unwrap()
        .signorini(bar.right(), 1e-3)
        .unwrap();
    let basis = CosineBasis::new(7, 4).unwrap();
    let x: Vec<f64> = (0..basis.len() * 2)
        .map(|i| 1e-3 * (((i * 37) % 11) as f64 - 5.0) / (1.0 + i as f64))
        .collect();
    let (omega, theta) = (1.3, 0.7);
    let plain = builder.build().unwrap();
    let without = energy_at(&plain, &basis, &x, omega, theta);
    let fields = FieldEvaluator::new(&plain, &basis, &x, omega);
    for (end, position) in [(bar.left(), 0.0), (bar.right(), 0.7)] {
        let at = fields.at(0, position, theta);
        let n = end.end.normal();
        let expected = [
            (Quantity::Displacement, at.displacement),
            (Quantity::OutwardDisplacement, n * at.displacement),
            (Quantity::Strain, at.strain),
            (Quantity::OutwardStrain, n * at.strain),
            (Quantity::ContactForce, -2.5 * at.strain),
        ];
        for (quantity, value) in expected {
            // A probe constrains no end and gives no row, so the builder accepts it.
            let mut probed = builder.clone();
            probed
                .add_condition(Probe {
                    end,
                    quantity,
                    scale: 1e3,
                })
                .unwrap();
            let system = probed.build().unwrap();
            let read = (energy_at(&system, &basis, &x, omega, theta) - without) / 1e3;
            assert!(
                (read - value).abs() <= 1e-12 * (1.0 + value.abs()),
                "{quantity:?} at {end}: read {read:e}, field {value:e}"
            );
        }
    }
}
