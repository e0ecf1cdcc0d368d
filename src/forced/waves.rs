//! Damped waves in one bar: the Helmholtz map of [`crate::bem`] at a complex wave number.
//!
//! With viscous damping `u_tt + eta u_t = c^2 u_xx`, the harmonic `Re(U(x) e^{i n Omega t})`
//! solves `U'' + kappa U = 0` with the complex `kappa = k^2 = (n^2 Omega^2 - i eta n Omega) /
//! c^2`. As without damping, `U(x) = A cos(kx) + B sin(kx)/k`, and every end value is a
//! combination of `cos(kl)`, `S = sin(kl)/k` and `-k sin(kl) = -kappa S`: even functions of
//! `k`, hence entire functions of `kappa` (no branch to choose, no pole at a natural
//! frequency).

use crate::bar::Bar;
use num_complex::Complex64;

/// Terms kept in the power series of [`sinc`] and [`cubic`] near `z = 0`.
const SERIES_TERMS: usize = 12;

/// Below this `|z|` the power series are used: their truncation error is below `0.5^24 / 25!`,
/// and the closed forms lose digits to cancellation there.
const SERIES_RADIUS: f64 = 0.5;

/// `sin(z) / z` for complex `z`.
fn sinc(z: Complex64) -> Complex64 {
    if z.norm() < SERIES_RADIUS {
        // sum (-1)^j z^{2j} / (2j+1)!
        let z2 = z * z;
        let (mut term, mut sum) = (Complex64::new(1.0, 0.0), Complex64::new(1.0, 0.0));
        for j in 1..SERIES_TERMS {
            term = -term * z2 / ((2 * j) * (2 * j + 1)) as f64;
            sum += term;
        }
        sum
    } else {
        z.sin() / z
    }
}

/// `(z cos z - sin z) / z^3` for complex `z` (`-1/3` at 0).
fn cubic(z: Complex64) -> Complex64 {
    if z.norm() < SERIES_RADIUS {
        // sum_{j >= 1} (-1)^j 2j / (2j+1)! z^{2j-2}
        let z2 = z * z;
        let mut factorial = 6.0; // (2j+1)! at j = 1
        let (mut power, mut sum) = (Complex64::new(1.0, 0.0), Complex64::new(0.0, 0.0));
        for j in 1..SERIES_TERMS {
            let sign = if j % 2 == 1 { -1.0 } else { 1.0 };
            sum += power * (sign * (2 * j) as f64 / factorial);
            power *= z2;
            factorial *= ((2 * j + 2) * (2 * j + 3)) as f64;
        }
        sum
    } else {
        (z * z.cos() - z.sin()) / (z * z * z)
    }
}

/// `kappa = k^2` of harmonic `n` of bar `bar` at fundamental frequency `omega` with damping
/// `eta`, and its derivative in `omega`.
pub fn squared_wavenumber(bar: &Bar, n: usize, omega: f64, eta: f64) -> (Complex64, Complex64) {
    let (n, c2) = (n as f64, bar.wave_speed() * bar.wave_speed());
    let kappa = Complex64::new(n * n * omega * omega, -eta * n * omega) / c2;
    let d_kappa = Complex64::new(2.0 * n * n * omega, -eta * n) / c2;
    (kappa, d_kappa)
}

/// The map from `(A, B)` to the end values `u(0), p(0), u(l), p(l)` (rows, as
/// [`crate::bem::HelmholtzMap`]) at squared wave number `kappa`, with its derivative in
/// `kappa`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DampedMap {
    /// `rows[i] = [d value_i / dA, d value_i / dB]`.
    pub rows: [[Complex64; 2]; 4],
    /// Derivative of `rows` in `kappa`.
    pub d_kappa: [[Complex64; 2]; 4],
}

impl DampedMap {
    /// The map of a bar of length `l` at squared wave number `kappa`.
    pub fn new(length: f64, kappa: Complex64) -> Self {
        let l = length;
        let z = kappa.sqrt() * l;
        let (cos, s) = (z.cos(), sinc(z) * l);
        let (one, zero) = (Complex64::new(1.0, 0.0), Complex64::new(0.0, 0.0));
        // d cos(kl) / d kappa = -l sin(kl) / (2k) = -l S / 2;
        // dS / d kappa = (l k cos(kl) - sin(kl)) / (2 k^3) = l^3 cubic(z) / 2.
        let d_cos = -0.5 * l * s;
        let d_s = 0.5 * l * l * l * cubic(z);
        let d_strain = -s - kappa * d_s;
        Self {
            rows: [[one, zero], [zero, -one], [cos, s], [-kappa * s, cos]],
            d_kappa: [[zero, zero], [zero, zero], [d_cos, d_s], [d_strain, d_cos]],
        }
    }

    /// `U(x)` and `U'(x)` of the harmonic with coefficients `(a, b)` at `x` in a bar at
    /// squared wave number `kappa` (the map's rows with `l = x`).
    pub fn field(x: f64, kappa: Complex64, a: Complex64, b: Complex64) -> (Complex64, Complex64) {
        let at = Self::new(x, kappa);
        // rows[2] is u(x); rows[3] is u_x(x) (the outward strain at a right end).
        (
            at.rows[2][0] * a + at.rows[2][1] * b,
            at.rows[3][0] * a + at.rows[3][1] * b,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bem::HelmholtzMap;

    #[test]
    fn without_damping_the_map_is_the_real_one() {
        let bar = Bar::new(1.3, 0.8, 2.0).unwrap();
        for omega in [0.0, 0.2, 1.7, 9.3] {
            let (kappa, _) = squared_wavenumber(&bar, 1, omega, 0.0);
            let damped = DampedMap::new(bar.length(), kappa);
            let real = HelmholtzMap::new(&bar, omega);
            for (d, r) in damped.rows.iter().zip(real.rows) {
                for (x, y) in d.iter().zip(r) {
                    assert!((x.re - y).abs() < 1e-13 && x.im.abs() < 1e-13, "{x} {y}");
                }
            }
        }
    }

    #[test]
    fn the_kappa_derivative_matches_finite_differences_across_the_series_switch() {
        let l = 1.1;
        for kappa in [
            Complex64::new(0.01, -0.02),
            Complex64::new(0.2, -0.01),
            Complex64::new(4.0, -0.3),
            Complex64::new(80.0, -2.0),
        ] {
            let map = DampedMap::new(l, kappa);
            let h = 1e-6 * (1.0 + kappa.norm());
            let (plus, minus) = (DampedMap::new(l, kappa + h), DampedMap::new(l, kappa - h));
            for i in 0..4 {
                for j in 0..2 {
                    let fd = (plus.rows[i][j] - minus.rows[i][j]) / (2.0 * h);
                    let err = (fd - map.d_kappa[i][j]).norm();
                    assert!(
                        err < 1e-7 * (1.0 + fd.norm()),
                        "kappa {kappa} ({i},{j}): {err:e}"
                    );
                }
            }
        }
    }

    #[test]
    fn the_field_solves_the_damped_helmholtz_equation() {
        let kappa = Complex64::new(3.0, -0.4);
        let (a, b) = (Complex64::new(0.3, 0.1), Complex64::new(-0.7, 0.2));
        let (x, h) = (0.6, 1e-4);
        let u = |x: f64| DampedMap::field(x, kappa, a, b).0;
        let second = (u(x + h) - 2.0 * u(x) + u(x - h)) / (h * h);
        assert!((second + kappa * u(x)).norm() < 1e-6);
        let slope = (u(x + h) - u(x - h)) / (2.0 * h);
        assert!((slope - DampedMap::field(x, kappa, a, b).1).norm() < 1e-7);
    }
}
