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
#[derive(Debug, Clone, PartialEq, Default)]
pub(crate) struct Condensed {
    /// `Z`, `n x c` column-major.
    pub null: Vec<f64>,
    /// `L^+`, `n x r` column-major.
    pub pinv: Vec<f64>,
}

/// Working storage of [`condense_into`], reused across harmonics and frequencies.
#[derive(Debug, Clone, Default)]
pub(crate) struct CondenseScratch {
    /// `L^T` reduced in place to `R`, `n x r` column-major.
    a: Vec<f64>,
    /// Householder vectors, `n` entries each (zero above the diagonal).
    reflectors: Vec<f64>,
    betas: Vec<f64>,
    /// `Q`, `n x n` column-major.
    q: Vec<f64>,
    /// `R_1^{-T}`, `r x r` column-major.
    y: Vec<f64>,
}

/// Relative threshold on the diagonal of `R` below which the rows count as dependent.
const RANK_TOLERANCE: f64 = 1e-12;

/// `Z` and `L^+` of the rows of `rows`, or `None` if they are not of full row rank.
#[cfg(test)]
pub(crate) fn condense(rows: &HarmonicRows) -> Option<Condensed> {
    let mut out = Condensed::default();
    condense_into(rows, &mut out, &mut CondenseScratch::default()).then_some(out)
}

/// [`condense`] into reused storage: writes `Z` and `L^+` into `out` and returns `true`, or
/// returns `false` if the rows are not of full row rank.
pub(crate) fn condense_into(
    rows: &HarmonicRows,
    out: &mut Condensed,
    scratch: &mut CondenseScratch,
) -> bool {
    let (n, r) = (rows.unknowns(), rows.linear_count());
    let CondenseScratch {
        a,
        reflectors,
        betas,
        q,
        y,
    } = scratch;
    // a = L^T, n x r column-major: column j is row j of L.
    a.clear();
    for j in 0..r {
        a.extend_from_slice(rows.linear_row(j));
    }
    reflectors.clear();
    reflectors.resize(n * r, 0.0);
    betas.clear();
    for j in 0..r {
        let x = &a[j * n + j..(j + 1) * n];
        let norm = x.iter().map(|v| v * v).sum::<f64>().sqrt();
        let alpha = if x[0] >= 0.0 { -norm } else { norm };
        let v = &mut reflectors[j * n + j..(j + 1) * n];
        v.copy_from_slice(x);
        v[0] -= alpha;
        let vv = v.iter().map(|t| t * t).sum::<f64>();
        let beta = if vv > 0.0 { 2.0 / vv } else { 0.0 };
        for k in j..r {
            let col = &mut a[k * n + j..(k + 1) * n];
            let s = beta * v.iter().zip(col.iter()).map(|(p, q)| p * q).sum::<f64>();
            col.iter_mut().zip(v.iter()).for_each(|(c, p)| *c -= s * p);
        }
        betas.push(beta);
    }
    // R_1: the upper r x r block of the reduced a.
    let diag_max = (0..r).map(|j| a[j * n + j].abs()).fold(0.0, f64::max);
    // `>` is false for NaN too.
    if !(0..r).all(|j| a[j * n + j].abs() > RANK_TOLERANCE * diag_max) {
        return false;
    }
    // Q = H_0 H_1 ... H_{r-1}, applied to the identity from the last reflector on.
    q.clear();
    q.resize(n * n, 0.0);
    for i in 0..n {
        q[i * n + i] = 1.0;
    }
    for (j, beta) in betas.iter().enumerate().rev() {
        let v = &reflectors[j * n + j..(j + 1) * n];
        for k in 0..n {
            let col = &mut q[k * n + j..(k + 1) * n];
            let s = beta * v.iter().zip(col.iter()).map(|(p, c)| p * c).sum::<f64>();
            col.iter_mut().zip(v).for_each(|(c, p)| *c -= s * p);
        }
    }
    out.null.clear();
    out.null.extend_from_slice(&q[r * n..]);
    // Y = R_1^{-T} by forward substitution (R_1^T is lower triangular), then L^+ = Q_1 Y.
    let r1 = |i: usize, j: usize| a[j * n + i];
    y.clear();
    y.resize(r * r, 0.0);
    for k in 0..r {
        for i in 0..r {
            let mut s = if i == k { 1.0 } else { 0.0 };
            for m in 0..i {
                s -= r1(m, i) * y[k * r + m];
            }
            y[k * r + i] = s / r1(i, i);
        }
    }
    out.pinv.clear();
    out.pinv.resize(n * r, 0.0);
    for k in 0..r {
        for m in 0..r {
            let ymk = y[k * r + m];
            if ymk != 0.0 {
                for i in 0..n {
                    out.pinv[k * n + i] += q[m * n + i] * ymk;
                }
            }
        }
    }
    true
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
