//! Per-bar FD-BEM identities (formulation §2) on exact Helmholtz solutions, property-tested
//! with the crate's exported strategies.
#![cfg(feature = "proptest")]

use nonsmooth_modes::bar::Bar;
use nonsmooth_modes::bem::{
    boundary_rows, interior_displacement, interior_strain, EndValues, HelmholtzMap,
};
use nonsmooth_modes::strategies::{bar, frequency, helmholtz_coefficients};
use proptest::prelude::*;

/// `sin(k x) / k`, equal to `x` at `k = 0`, computed without the crate.
fn sin_over_k(k: f64, x: f64) -> f64 {
    if k == 0.0 {
        x
    } else {
        (k * x).sin() / k
    }
}

/// `u(x) = A cos(kx) + B sin(kx)/k` and `u_x(x)`, by hand.
fn exact(bar: &Bar, omega: f64, a: f64, b: f64, x: f64) -> (f64, f64) {
    let k = omega / bar.wave_speed();
    let u = a * (k * x).cos() + b * sin_over_k(k, x);
    let ux = -a * k * (k * x).sin() + b * (k * x).cos();
    (u, ux)
}

/// End values `(u(0), p(0), u(l), p(l))` by hand, `p` the outward strain.
fn hand_end_values(bar: &Bar, omega: f64, a: f64, b: f64) -> EndValues {
    let l = bar.length();
    let (u0, ux0) = exact(bar, omega, a, b, 0.0);
    let (ul, uxl) = exact(bar, omega, a, b, l);
    EndValues {
        u0,
        p0: -ux0,
        ul,
        pl: uxl,
    }
}

fn row_residual(row: &[f64; 4], ends: &EndValues) -> (f64, f64) {
    let e = ends.to_array();
    let r = row.iter().zip(e).map(|(x, y)| x * y).sum::<f64>();
    let scale = row.iter().zip(e).map(|(x, y)| (x * y).abs()).sum::<f64>();
    (r, scale)
}

fn config() -> ProptestConfig {
    ProptestConfig {
        cases: 256,
        failure_persistence: None,
        ..ProptestConfig::default()
    }
}

proptest! {
    #![proptest_config(config())]

    #[test]
    fn exact_solutions_satisfy_the_boundary_rows(
        b in bar(), omega in frequency(), (ca, cb) in helmholtz_coefficients()
    ) {
        let ends = hand_end_values(&b, omega, ca, cb);
        for row in boundary_rows(&b, omega) {
            let (r, scale) = row_residual(&row, &ends);
            prop_assert!(
                r.abs() <= 1e-10 * scale.max(1e-300),
                "bar {b:?} omega {omega} (A, B) = ({ca}, {cb}): row {row:?} residual {r:e} (scale {scale:e})"
            );
        }
    }

    #[test]
    fn interior_representation_reproduces_the_field(
        b in bar(), omega in frequency(), (ca, cb) in helmholtz_coefficients(),
        fractions in proptest::collection::vec(0.0..=1.0_f64, 8)
    ) {
        let ends = hand_end_values(&b, omega, ca, cb);
        let l = b.length();
        let k = omega / b.wave_speed();
        let scale_u = ends.u0.abs() + ends.ul.abs() + (ends.p0.abs() + ends.pl.abs()) * l
            + ca.abs() + cb.abs() * l;
        let scale_ux = k * (ends.u0.abs() + ends.ul.abs()) + ends.p0.abs() + ends.pl.abs()
            + k * ca.abs() + cb.abs();
        for f in fractions.into_iter().chain([0.0, 1.0]) {
            let x = f * l;
            let (u, ux) = exact(&b, omega, ca, cb, x);
            let u_bem = interior_displacement(&b, omega, &ends, x);
            let ux_bem = interior_strain(&b, omega, &ends, x);
            prop_assert!(
                (u - u_bem).abs() <= 1e-10 * scale_u,
                "bar {b:?} omega {omega} x {x}: u {u} from ends {u_bem}"
            );
            prop_assert!(
                (ux - ux_bem).abs() <= 1e-10 * scale_ux.max(1e-300),
                "bar {b:?} omega {omega} x {x}: u_x {ux} from ends {ux_bem}"
            );
        }
    }

    #[test]
    fn helmholtz_map_gives_the_hand_end_values(
        b in bar(), omega in frequency(), (ca, cb) in helmholtz_coefficients()
    ) {
        let hand = hand_end_values(&b, omega, ca, cb).to_array();
        let map = HelmholtzMap::new(&b, omega).end_values(ca, cb).to_array();
        let k = omega / b.wave_speed();
        let scale = (1.0 + k) * (ca.abs() + cb.abs() * b.length().max(1.0));
        for (name, (h, m)) in ["u(0)", "p(0)", "u(l)", "p(l)"].iter().zip(hand.iter().zip(map)) {
            prop_assert!(
                (h - m).abs() <= 1e-12 * scale,
                "bar {b:?} omega {omega} (A, B) = ({ca}, {cb}): {name} by hand {h}, by map {m}"
            );
        }
    }

    #[test]
    fn helmholtz_map_derivative_matches_central_differences(
        b in bar(), omega in frequency()
    ) {
        let h = 1e-6;
        let map = HelmholtzMap::new(&b, omega);
        let plus = HelmholtzMap::new(&b, omega + h);
        let minus = HelmholtzMap::new(&b, omega - h);
        let (l, c) = (b.length(), b.wave_speed());
        let z = omega * l / c;
        // Bound on the size of any entry's derivative (d/domega of cos, sin/k, k sin).
        let scale = (1.0 + z + l + l * l) / c;
        for i in 0..4 {
            for j in 0..2 {
                let fd = (plus.rows[i][j] - minus.rows[i][j]) / (2.0 * h);
                let d = map.d_omega[i][j];
                prop_assert!(
                    (fd - d).abs() <= 1e-6 * scale,
                    "bar {b:?} omega {omega}: entry ({i}, {j}) analytic {d}, finite difference {fd}"
                );
            }
        }
    }

    #[test]
    fn zero_frequency_limit_is_continuous(
        b in bar(), (ca, cb) in helmholtz_coefficients(), x_fraction in 0.0..=1.0_f64
    ) {
        let tiny = 1e-9;
        let l = b.length();
        let close = |p: f64, q: f64, what: &str| -> Result<(), TestCaseError> {
            prop_assert!(
                (p - q).abs() <= 1e-8 * (1.0 + p.abs()),
                "bar {b:?}: {what} at omega = 0 is {p}, at omega = {tiny} is {q}"
            );
            Ok(())
        };
        let (r0, r1) = (boundary_rows(&b, 0.0), boundary_rows(&b, tiny));
        for (row0, row1) in r0.iter().zip(&r1) {
            for (p, q) in row0.iter().zip(row1) {
                close(*p, *q, "boundary row entry")?;
            }
        }
        let (m0, m1) = (HelmholtzMap::new(&b, 0.0), HelmholtzMap::new(&b, tiny));
        // The derivatives move by omega times a second derivative of order (l/c)^2 (1 + l),
        // up to ~4e3 for the slowest, longest bars: compare them a thousand times closer to 0.
        let m2 = HelmholtzMap::new(&b, 1e-3 * tiny);
        for i in 0..4 {
            for j in 0..2 {
                close(m0.rows[i][j], m1.rows[i][j], "map entry")?;
                close(m0.d_omega[i][j], m2.d_omega[i][j], "map derivative")?;
            }
        }
        let (e0, e1) = (m0.end_values(ca, cb), m1.end_values(ca, cb));
        let x = x_fraction * l;
        close(
            interior_displacement(&b, 0.0, &e0, x),
            interior_displacement(&b, tiny, &e1, x),
            "interior displacement",
        )?;
        close(
            interior_strain(&b, 0.0, &e0, x),
            interior_strain(&b, tiny, &e1, x),
            "interior strain",
        )?;
        // At omega = 0 the field is A + B x: a uniform static strain.
        prop_assert!((e0.pl - cb).abs() <= 1e-14 && (e0.p0 + cb).abs() <= 1e-14);
        prop_assert!((e0.ul - (ca + cb * l)).abs() <= 1e-13 * (1.0 + l));
    }
}
