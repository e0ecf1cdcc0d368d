//! Frequency-domain boundary identities of one bar (formulation §2): pure functions.
//!
//! Fourier-transforming `u_tt = c^2 u_xx` in time gives the Helmholtz equation
//! `u'' + k^2 u = 0`, `k = omega / c`. Its solutions are `u(x) = A cos(kx) + B sin(kx)/k`,
//! entire functions of `k` (at `k = 0`: `A + B x`). The crate uses `(A, B)` as the unknowns of
//! each bar and harmonic: every end value is a combination of `cos(kl)`, `sin(kl)/k` and
//! `k sin(kl)` with no division by a trigonometric function, so nothing has a pole at a natural
//! frequency.
//!
//! End values follow the crate convention: `u(0), u(l)` are displacements, `p(0) = -u_x(0)`
//! and `p(l) = u_x(l)` are outward strains.

use crate::bar::{Bar, End};

/// `sin(z)/z`, accurate near `z = 0`.
pub fn sinc(z: f64) -> f64 {
    if z.abs() < 1e-2 {
        let z2 = z * z;
        1.0 - z2 / 6.0 * (1.0 - z2 / 20.0 * (1.0 - z2 / 42.0 * (1.0 - z2 / 72.0)))
    } else {
        z.sin() / z
    }
}

/// [`sinc`] of `z` given `sin z` already computed (with its cosine, by `sin_cos`).
pub(crate) fn sinc_given_sine(z: f64, sin_z: f64) -> f64 {
    if z.abs() < 1e-2 {
        sinc(z)
    } else {
        sin_z / z
    }
}

/// Derivative of [`sinc`]: `(z cos z - sin z) / z^2`, accurate near `z = 0`.
pub fn sinc_derivative(z: f64) -> f64 {
    if z.abs() < 1e-2 {
        let z2 = z * z;
        -z / 3.0 * (1.0 - z2 / 10.0 * (1.0 - z2 / 28.0 * (1.0 - z2 / 54.0)))
    } else {
        (z * z.cos() - z.sin()) / (z * z)
    }
}

/// `S(k) = sin(k l) / k` (equal to `l` at `k = 0`).
fn sin_over_k(k: f64, l: f64) -> f64 {
    l * sinc(k * l)
}

/// End values `(u(0), p(0), u(l), p(l))` of one harmonic of a bar.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct EndValues {
    /// Displacement at `x = 0`.
    pub u0: f64,
    /// Outward strain at `x = 0` (`-u_x(0)`).
    pub p0: f64,
    /// Displacement at `x = l`.
    pub ul: f64,
    /// Outward strain at `x = l` (`u_x(l)`).
    pub pl: f64,
}

impl EndValues {
    /// Displacement and outward strain at one end.
    pub fn at(&self, end: End) -> (f64, f64) {
        match end {
            End::Left => (self.u0, self.p0),
            End::Right => (self.ul, self.pl),
        }
    }

    /// As an array `[u0, p0, ul, pl]`.
    pub fn to_array(self) -> [f64; 4] {
        [self.u0, self.p0, self.ul, self.pl]
    }
}

/// Indices, in the end values `[u(0), p(0), u(l), p(l)]` (and the rows of the maps that give
/// them, [`HelmholtzMap`]), of the displacement and the outward strain at `end`.
pub(crate) fn end_indices(end: End) -> (usize, usize) {
    match end {
        End::Left => (0, 1),
        End::Right => (2, 3),
    }
}

/// The two FD-BEM rows of a bar at angular frequency `omega`, divided by `k` so that they stay
/// finite at `omega = 0`. They act on `[u(0), p(0), u(l), p(l)]` and vanish on every exact
/// Helmholtz solution:
///
/// ```text
/// [ 1          0      -cos(kl)   S(k) ]
/// [ -cos(kl)   S(k)    1         0    ]      S(k) = sin(kl)/k
/// ```
pub fn boundary_rows(bar: &Bar, omega: f64) -> [[f64; 4]; 2] {
    let k = bar.wavenumber(omega);
    let l = bar.length();
    let c = (k * l).cos();
    let s = sin_over_k(k, l);
    [[1.0, 0.0, -c, s], [-c, s, 1.0, 0.0]]
}

/// The linear map from the Helmholtz coefficients `(A, B)` of `u(x) = A cos(kx) + B sin(kx)/k`
/// to the end values, as a 4x2 matrix with rows `u(0), p(0), u(l), p(l)`, and its derivative
/// with respect to `omega`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HelmholtzMap {
    /// `rows[i] = [d value_i / dA, d value_i / dB]`.
    pub rows: [[f64; 2]; 4],
    /// Derivative of `rows` with respect to `omega`.
    pub d_omega: [[f64; 2]; 4],
}

impl HelmholtzMap {
    /// The map for `bar` at angular frequency `omega` (any real value, including 0).
    pub fn new(bar: &Bar, omega: f64) -> Self {
        let c = bar.wave_speed();
        let l = bar.length();
        let k = omega / c;
        let z = k * l;
        let (sz, cz) = z.sin_cos();
        let s = l * sinc(z);
        // d/dk of cos(kl), sin(kl)/k, -k sin(kl) and cos(kl); then chain dk/domega = 1/c.
        let d_cos = -l * sz;
        let d_s = l * l * sinc_derivative(z);
        let d_mksin = -sz - z * cz;
        let rows = [[1.0, 0.0], [0.0, -1.0], [cz, s], [-k * sz, cz]];
        let d_omega = [
            [0.0, 0.0],
            [0.0, 0.0],
            [d_cos / c, d_s / c],
            [d_mksin / c, d_cos / c],
        ];
        Self { rows, d_omega }
    }

    /// End values of the harmonic with coefficients `(a, b)`.
    pub fn end_values(&self, a: f64, b: f64) -> EndValues {
        let v = |r: [f64; 2]| r[0] * a + r[1] * b;
        EndValues {
            u0: v(self.rows[0]),
            p0: v(self.rows[1]),
            ul: v(self.rows[2]),
            pl: v(self.rows[3]),
        }
    }
}

/// Displacement `u(x)` of one harmonic inside the bar from its four end values (the boundary
/// integral equation, formulation §2, with the paper's sign slip in eq. (16) corrected):
///
/// `2 u(x) = u(0) cos(kx) + u(l) cos(k(l-x)) - (p(0) sin(kx) + p(l) sin(k(l-x))) / k`.
pub fn interior_displacement(bar: &Bar, omega: f64, ends: &EndValues, x: f64) -> f64 {
    let k = bar.wavenumber(omega);
    let l = bar.length();
    let y = l - x;
    0.5 * (ends.u0 * (k * x).cos() + ends.ul * (k * y).cos()
        - ends.p0 * sin_over_k(k, x)
        - ends.pl * sin_over_k(k, y))
}

/// Strain `u_x(x)` of one harmonic inside the bar from its end values (derivative of
/// [`interior_displacement`]).
pub fn interior_strain(bar: &Bar, omega: f64, ends: &EndValues, x: f64) -> f64 {
    let k = bar.wavenumber(omega);
    let l = bar.length();
    let y = l - x;
    0.5 * (-ends.u0 * k * (k * x).sin() + ends.ul * k * (k * y).sin() - ends.p0 * (k * x).cos()
        + ends.pl * (k * y).cos())
}

/// Helmholtz coefficients `(A, B)` of a harmonic from its end values at `x = 0`
/// (`A = u(0)`, `B = -p(0)`).
pub fn coefficients_from_left(ends: &EndValues) -> (f64, f64) {
    (ends.u0, -ends.p0)
}

/// Energy density `EA/2 (u_t^2 / c^2 + u_x^2)` of a bar at a point with velocity `u_t` and
/// strain `u_x`.
pub fn energy_density(bar: &Bar, velocity: f64, strain: f64) -> f64 {
    let c = bar.wave_speed();
    0.5 * bar.stiffness() * (velocity * velocity / (c * c) + strain * strain)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sinc_series_matches_closed_form_near_switch() {
        for z in [0.009_f64, 0.0099, 0.011, 0.02] {
            assert!((sinc(z) - z.sin() / z).abs() < 1e-14);
            let d = (z * z.cos() - z.sin()) / (z * z);
            assert!((sinc_derivative(z) - d).abs() < 1e-9);
        }
        assert_eq!(sinc(0.0), 1.0);
        assert_eq!(sinc_derivative(0.0), 0.0);
    }

    #[test]
    fn helmholtz_map_satisfies_boundary_rows() {
        let bar = Bar::new(0.95, 1.3, 2.0).unwrap();
        for omega in [0.0, 0.3, 1.7, 9.2] {
            let map = HelmholtzMap::new(&bar, omega);
            let ev = map.end_values(0.7, -1.1).to_array();
            for row in boundary_rows(&bar, omega) {
                let r: f64 = row.iter().zip(ev).map(|(a, b)| a * b).sum();
                assert!(r.abs() < 1e-13, "omega {omega}: {r}");
            }
        }
    }
}
