//! Per-harmonic condensation of the linear rows (formulation §5), for the structured Newton
//! step of [`NonsmoothSystem`](crate::system::NonsmoothSystem).
//!
//! The `r x n` linear rows `L` of a harmonic (full row rank) split its `n = 2 n_bars`
//! unknowns into a particular part fixed by the rows and `c = n - r` free directions (one per
//! contact): `dx = L^+ g + Z b` solves `L dx = g` for any `b`, with `Z` an orthonormal basis of
//! the null space of `L` and `L^+` its pseudo-inverse. Both come from a Householder QR of
//! `L^T = Q R`: `Z` is the last `c` columns of `Q` and `L^+ = Q_1 R_1^{-T}`. They are computed
//! once per harmonic and frequency, at fixed `Omega`, so no smoothness in `Omega` is needed.

use crate::system::rows::HarmonicRows;

/// Null basis and pseudo-inverse of one harmonic's linear rows.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Condensed {
    /// `Z`, `n x c` column-major.
    pub null: Vec<f64>,
    /// `L^+`, `n x r` column-major.
    pub pinv: Vec<f64>,
}

/// Relative threshold on the diagonal of `R` below which the rows count as dependent.
const RANK_TOLERANCE: f64 = 1e-12;

/// `Z` and `L^+` of the rows of `rows`, or `None` if they are not of full row rank.
pub(crate) fn condense(rows: &HarmonicRows) -> Option<Condensed> {
    let (n, r) = (rows.unknowns(), rows.linear_count());
    // a = L^T, n x r column-major: column j is row j of L.
    let mut a: Vec<f64> = (0..r).flat_map(|j| rows.linear_row(j).to_vec()).collect();
    let mut reflectors: Vec<(Vec<f64>, f64)> = Vec::with_capacity(r);
    for j in 0..r {
        let x = &a[j * n + j..(j + 1) * n];
        let norm = x.iter().map(|v| v * v).sum::<f64>().sqrt();
        let alpha = if x[0] >= 0.0 { -norm } else { norm };
        let mut v = x.to_vec();
        v[0] -= alpha;
        let vv = v.iter().map(|t| t * t).sum::<f64>();
        let beta = if vv > 0.0 { 2.0 / vv } else { 0.0 };
        for k in j..r {
            let col = &mut a[k * n + j..(k + 1) * n];
            let s = beta * v.iter().zip(col.iter()).map(|(p, q)| p * q).sum::<f64>();
            col.iter_mut().zip(&v).for_each(|(c, p)| *c -= s * p);
        }
        reflectors.push((v, beta));
    }
    // R_1: the upper r x r block of the reduced a.
    let diag_max = (0..r).map(|j| a[j * n + j].abs()).fold(0.0, f64::max);
    // `>` is false for NaN too.
    if !(0..r).all(|j| a[j * n + j].abs() > RANK_TOLERANCE * diag_max) {
        return None;
    }
    // Q = H_0 H_1 ... H_{r-1}, applied to the identity from the last reflector on.
    let mut q = vec![0.0; n * n];
    for i in 0..n {
        q[i * n + i] = 1.0;
    }
    for (j, (v, beta)) in reflectors.iter().enumerate().rev() {
        for k in 0..n {
            let col = &mut q[k * n + j..(k + 1) * n];
            let s = beta * v.iter().zip(col.iter()).map(|(p, c)| p * c).sum::<f64>();
            col.iter_mut().zip(v).for_each(|(c, p)| *c -= s * p);
        }
    }
    let null = q[r * n..].to_vec();
    // Y = R_1^{-T} by forward substitution (R_1^T is lower triangular), then L^+ = Q_1 Y.
    let r1 = |i: usize, j: usize| a[j * n + i];
    let mut y = vec![0.0; r * r]; // column-major r x r
    for k in 0..r {
        for i in 0..r {
            let mut s = if i == k { 1.0 } else { 0.0 };
            for m in 0..i {
                s -= r1(m, i) * y[k * r + m];
            }
            y[k * r + i] = s / r1(i, i);
        }
    }
    let mut pinv = vec![0.0; n * r];
    for k in 0..r {
        for m in 0..r {
            let ymk = y[k * r + m];
            if ymk != 0.0 {
                for i in 0..n {
                    pinv[k * n + i] += q[m * n + i] * ymk;
                }
            }
        }
    }
    Some(Condensed { null, pinv })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bar::Bar;
    use crate::reference::two_bars_in_contact;

    #[test]
    fn null_basis_and_pseudo_inverse_of_two_bar_rows() {
        let system = two_bars_in_contact(Bar::new(0.95, 1.3, 2.0).unwrap(), 1e-3).unwrap();
        for omega in [0.0, 0.7, 3.1, 9.4] {
            let rows = HarmonicRows::new(&system, omega);
            let (n, r) = (rows.unknowns(), rows.linear_count());
            let c = condense(&rows).unwrap();
            assert_eq!(c.null.len(), n * (n - r));
            for k in 0..r {
                let row = rows.linear_row(k);
                // L Z = 0.
                for z in c.null.chunks(n) {
                    let v: f64 = row.iter().zip(z).map(|(a, b)| a * b).sum();
                    assert!(v.abs() < 1e-12, "L Z = {v} at omega {omega}");
                }
                // L L^+ = I.
                for (m, col) in c.pinv.chunks(n).enumerate() {
                    let v: f64 = row.iter().zip(col).map(|(a, b)| a * b).sum();
                    let want = if m == k { 1.0 } else { 0.0 };
                    assert!((v - want).abs() < 1e-12, "L L+ = {v} at omega {omega}");
                }
            }
        }
    }
}
