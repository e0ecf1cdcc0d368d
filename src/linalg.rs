//! A small dense matrix type for public signatures, and the factorisations the crate needs,
//! done by `faer` inside (faer's types never appear in the public API).

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::lu::partial_pivoting::factor;
use faer::linalg::triangular_solve;
use faer::{Mat, MatMut, MatRef, Par};
use std::cell::RefCell;
use std::ops::{Index, IndexMut};

mod staircase;
pub(crate) use staircase::{Staircase, StaircaseLu};

/// The entries of an `nrows x ncols` matrix.
///
/// # Panics
/// If their number overflows `usize`.
fn entries(nrows: usize, ncols: usize) -> usize {
    nrows
        .checked_mul(ncols)
        .expect("DenseMatrix: nrows x ncols overflows usize")
}

/// A dense, column-major `f64` matrix.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct DenseMatrix {
    nrows: usize,
    ncols: usize,
    data: Vec<f64>,
}

impl DenseMatrix {
    /// A matrix of zeros.
    ///
    /// # Panics
    /// If `nrows x ncols` overflows `usize` (or does not fit in memory).
    pub fn zeros(nrows: usize, ncols: usize) -> Self {
        Self {
            nrows,
            ncols,
            data: vec![0.0; entries(nrows, ncols)],
        }
    }

    /// Number of rows.
    pub fn nrows(&self) -> usize {
        self.nrows
    }

    /// Number of columns.
    pub fn ncols(&self) -> usize {
        self.ncols
    }

    /// Sets every entry to zero.
    pub fn fill_zero(&mut self) {
        self.data.fill(0.0);
    }

    /// Resizes to `nrows x ncols`, all zero.
    ///
    /// # Panics
    /// If `nrows x ncols` overflows `usize` (or does not fit in memory).
    pub fn reset(&mut self, nrows: usize, ncols: usize) {
        let len = entries(nrows, ncols);
        self.nrows = nrows;
        self.ncols = ncols;
        self.data.clear();
        self.data.resize(len, 0.0);
    }

    /// Column `j` as a mutable slice.
    ///
    /// # Panics
    /// If `j >= ncols`.
    pub fn column_mut(&mut self, j: usize) -> &mut [f64] {
        assert!(j < self.ncols, "column index in range");
        let n = self.nrows;
        &mut self.data[j * n..(j + 1) * n]
    }

    /// Column `j` as a slice (the storage is column-major).
    ///
    /// # Panics
    /// If `j >= ncols`.
    pub fn column(&self, j: usize) -> &[f64] {
        assert!(j < self.ncols, "column index in range");
        &self.data[j * self.nrows..(j + 1) * self.nrows]
    }

    /// `y = A x`.
    ///
    /// # Panics
    /// If `x.len() != ncols` or `y.len() != nrows`.
    pub fn mul_vec(&self, x: &[f64], y: &mut [f64]) {
        assert_eq!(x.len(), self.ncols);
        assert_eq!(y.len(), self.nrows);
        y.fill(0.0);
        for (j, &xj) in x.iter().enumerate() {
            if xj != 0.0 {
                for (yi, a) in y.iter_mut().zip(self.column(j)) {
                    *yi += a * xj;
                }
            }
        }
    }

    /// `y = A^T x`.
    ///
    /// # Panics
    /// If `x.len() != nrows` or `y.len() != ncols`.
    pub fn mul_transpose_vec(&self, x: &[f64], y: &mut [f64]) {
        assert_eq!(x.len(), self.nrows);
        assert_eq!(y.len(), self.ncols);
        for (j, yj) in y.iter_mut().enumerate() {
            *yj = self.column(j).iter().zip(x).map(|(a, b)| a * b).sum();
        }
    }

    /// Whether every entry is finite.
    pub fn is_finite(&self) -> bool {
        self.data.iter().all(|v| v.is_finite())
    }
}

impl Index<(usize, usize)> for DenseMatrix {
    type Output = f64;
    fn index(&self, (i, j): (usize, usize)) -> &f64 {
        assert!(i < self.nrows && j < self.ncols, "matrix index in range");
        &self.data[j * self.nrows + i]
    }
}

impl IndexMut<(usize, usize)> for DenseMatrix {
    fn index_mut(&mut self, (i, j): (usize, usize)) -> &mut f64 {
        assert!(i < self.nrows && j < self.ncols, "matrix index in range");
        &mut self.data[j * self.nrows + i]
    }
}

/// Where an LU factorisation found a pivot too small to trust.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct SmallPivot {
    pub pivot: usize,
    pub ratio: f64,
}

/// LU factorisation with partial pivoting of a square matrix, with a pivot check
/// (faer's LU does not report singularity).
///
/// The factors, the permutation and faer's scratch memory live in the value and are reused:
/// [`Lu::refactor`] of a matrix of the same (or a smaller) size and [`Lu::solve_in_place`]
/// allocate nothing. Factorisation and solves are done in place by faer's
/// `lu_in_place` and triangular solves, sequentially (`Par::Seq`), so results do not depend on
/// the number of threads.
#[derive(Default)]
pub(crate) struct Lu {
    n: usize,
    /// `L` (strictly lower part, unit diagonal implied) and `U` (upper part), column-major.
    factors: Vec<f64>,
    perm: Vec<usize>,
    perm_inv: Vec<usize>,
    /// faer's scratch for `lu_in_place`, sized for `scratch_n` unknowns.
    scratch: Option<MemBuffer>,
    scratch_n: usize,
    /// The permuted right-hand side of a solve.
    rhs: RefCell<Vec<f64>>,
}

impl Clone for Lu {
    /// The factors and permutation; faer's scratch memory is made anew on the next
    /// factorisation.
    fn clone(&self) -> Self {
        Self {
            n: self.n,
            factors: self.factors.clone(),
            perm: self.perm.clone(),
            perm_inv: self.perm_inv.clone(),
            scratch: None,
            scratch_n: 0,
            rhs: self.rhs.clone(),
        }
    }
}

impl std::fmt::Debug for Lu {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Lu")
            .field("n", &self.n)
            .finish_non_exhaustive()
    }
}

impl Lu {
    /// Factorises `a`; fails when `min |u_ii| <= tol * max |u_jj|`.
    pub fn factor(a: &DenseMatrix, tol: f64) -> Result<Self, SmallPivot> {
        let mut lu = Self::default();
        lu.refactor(a, tol)?;
        Ok(lu)
    }

    /// Factorises `a` into the storage of `self` (no allocation when `a` is no larger than
    /// the matrices factorised before); fails when `min |u_ii| <= tol * max |u_jj|`, leaving
    /// `self` unusable for solves until the next successful factorisation.
    ///
    /// # Panics
    /// If `a` is not square.
    pub fn refactor(&mut self, a: &DenseMatrix, tol: f64) -> Result<(), SmallPivot> {
        assert_eq!(a.nrows, a.ncols, "LU of a non-square matrix");
        self.n = a.nrows;
        self.factors.clear();
        self.factors.extend_from_slice(&a.data);
        self.factor_stored(tol)
    }

    /// The column-major storage of an `n x n` matrix to be factorised by
    /// [`Lu::factor_stored`]: a caller that assembles its matrix here saves the copy of
    /// [`Lu::refactor`]. The contents are unspecified until written.
    pub(crate) fn storage(&mut self, n: usize) -> &mut [f64] {
        self.n = n;
        self.factors.resize(n * n, 0.0);
        &mut self.factors
    }

    /// Factorises in place the matrix written into [`Lu::storage`]; fails like
    /// [`Lu::refactor`].
    pub(crate) fn factor_stored(&mut self, tol: f64) -> Result<(), SmallPivot> {
        let n = self.n;
        assert_eq!(self.factors.len(), n * n, "storage of an n x n matrix");
        self.perm.resize(n, 0);
        self.perm_inv.resize(n, 0);
        if self.scratch.is_none() || self.scratch_n < n {
            let req = factor::lu_in_place_scratch::<usize, f64>(n, n, Par::Seq, Default::default());
            self.scratch = Some(MemBuffer::new(req));
            self.scratch_n = n;
        }
        let buffer = self.scratch.as_mut().expect("scratch allocated above");
        let _ = factor::lu_in_place(
            MatMut::from_column_major_slice_mut(&mut self.factors, n, n),
            &mut self.perm,
            &mut self.perm_inv,
            Par::Seq,
            MemStack::new(buffer),
            Default::default(),
        );
        let mut max = 0.0_f64;
        let mut min = f64::INFINITY;
        let mut at = 0;
        for i in 0..n {
            let d = self.factors[i * n + i].abs();
            max = max.max(d);
            if d < min {
                min = d;
                at = i;
            }
        }
        // NaN pivots fail the comparison, hence count as too small.
        let trusted = min > tol * max && max.is_finite();
        if n > 0 && !trusted {
            return Err(SmallPivot {
                pivot: at,
                ratio: if max > 0.0 { min / max } else { 0.0 },
            });
        }
        Ok(())
    }

    /// The sign of `det A` (`+1` or `-1`) of the factorised matrix: the signs of `U`'s pivots
    /// times the parity of the row permutation (`P A = L U`, `det P = +-1`). Continuation
    /// drivers watch it along a branch: it changes at a simple branch point.
    pub(crate) fn determinant_sign(&self) -> f64 {
        let n = self.n;
        let mut sign = 1.0;
        for i in 0..n {
            if self.factors[i * n + i] < 0.0 {
                sign = -sign;
            }
        }
        // A permutation is odd when `n` minus its number of cycles is odd.
        let mut seen = vec![false; n];
        let mut cycles = 0;
        for start in 0..n {
            if !seen[start] {
                cycles += 1;
                let mut i = start;
                while !seen[i] {
                    seen[i] = true;
                    i = self.perm[i];
                }
            }
        }
        if (n - cycles) % 2 == 1 {
            sign = -sign;
        }
        sign
    }

    /// Solves `A x = b` in place (no allocation once a right-hand side of this size has been
    /// solved).
    ///
    /// # Panics
    /// If `b.len()` is not the size of the factorised matrix.
    pub fn solve_in_place(&self, b: &mut [f64]) {
        let n = self.n;
        assert_eq!(b.len(), n, "right-hand side length");
        let mut rhs = self.rhs.borrow_mut();
        rhs.clear();
        rhs.extend(self.perm.iter().map(|&p| b[p]));
        b.copy_from_slice(&rhs);
        let factors = MatRef::from_column_major_slice(&self.factors, n, n);
        let mut x = MatMut::from_column_major_slice_mut(b, n, 1);
        triangular_solve::solve_unit_lower_triangular_in_place(factors, x.as_mut(), Par::Seq);
        triangular_solve::solve_upper_triangular_in_place(factors, x, Par::Seq);
    }

    /// Solves `A^T x = b` in place, `A` the factorised matrix. With `P A = L U`,
    /// `A^T = U^T L^T P`: two triangular solves on the transposed factors, then `x = P^T v`.
    /// A caller that can write `A^T` more cheaply than `A` (contiguously) factorises it and
    /// solves with this.
    ///
    /// # Panics
    /// If `b.len()` is not the size of the factorised matrix.
    pub fn solve_transpose_in_place(&self, b: &mut [f64]) {
        let n = self.n;
        assert_eq!(b.len(), n, "right-hand side length");
        let factors = MatRef::from_column_major_slice(&self.factors, n, n).transpose();
        {
            let mut x = MatMut::from_column_major_slice_mut(b, n, 1);
            triangular_solve::solve_lower_triangular_in_place(factors, x.as_mut(), Par::Seq);
            triangular_solve::solve_unit_upper_triangular_in_place(factors, x, Par::Seq);
        }
        let mut rhs = self.rhs.borrow_mut();
        rhs.clear();
        rhs.extend_from_slice(b);
        for (&p, v) in self.perm.iter().zip(rhs.iter()) {
            b[p] = *v;
        }
    }
}

/// `sum a_k b_k` with four interleaved partial sums: a long dot product is otherwise one
/// chain of dependent additions (latency-bound, not vectorised); this one vectorises.
///
/// # Panics
/// If the lengths differ.
#[inline]
pub(crate) fn dot_lanes(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len(), "dot product of equal lengths");
    let mut lanes = [0.0; 4];
    let (a4, b4) = (a.chunks_exact(4), b.chunks_exact(4));
    let tail: f64 = a4
        .remainder()
        .iter()
        .zip(b4.remainder())
        .map(|(x, y)| x * y)
        .sum();
    for (x, y) in a4.zip(b4) {
        for i in 0..4 {
            lanes[i] += x[i] * y[i];
        }
    }
    (lanes[0] + lanes[1]) + (lanes[2] + lanes[3]) + tail
}

/// Singular values (descending) and right singular vectors (columns of `v`, `ncols x ncols`)
/// of a small matrix given row-major as `nrows x ncols`.
pub(crate) fn svd_small(rows: &[f64], nrows: usize, ncols: usize) -> (Vec<f64>, DenseMatrix) {
    let m = Mat::from_fn(nrows, ncols, |i, j| rows[i * ncols + j]);
    let mut v = DenseMatrix::zeros(ncols, ncols);
    match m.svd() {
        Ok(svd) => {
            let s = svd.S().column_vector();
            let sv: Vec<f64> = (0..nrows.min(ncols)).map(|i| s[i]).collect();
            let vv = svd.V();
            for i in 0..ncols {
                for j in 0..ncols {
                    v[(i, j)] = vv[(i, j)];
                }
            }
            (sv, v)
        }
        Err(_) => (vec![f64::NAN; nrows.min(ncols)], v),
    }
}

/// The sign of the determinant of a small square matrix (row-major `n x n`), `0` where a
/// pivot vanishes, by Gaussian elimination with partial pivoting in `scratch`: for the
/// natural-frequency scan, which asks it of a 2 to 8 column matrix at every sample, without
/// the set-up of a factorisation object.
pub(crate) fn determinant_sign_small(rows: &[f64], n: usize, scratch: &mut Vec<f64>) -> f64 {
    debug_assert_eq!(rows.len(), n * n);
    scratch.clear();
    scratch.extend_from_slice(rows);
    let a = scratch;
    let mut sign = 1.0;
    for k in 0..n {
        let pivot = (k..n)
            .max_by(|&i, &j| a[i * n + k].abs().total_cmp(&a[j * n + k].abs()))
            .unwrap_or(k);
        let p = a[pivot * n + k];
        if p == 0.0 || !p.is_finite() {
            return 0.0;
        }
        if pivot != k {
            for j in 0..n {
                a.swap(k * n + j, pivot * n + j);
            }
            sign = -sign;
        }
        if p < 0.0 {
            sign = -sign;
        }
        for i in k + 1..n {
            let f = a[i * n + k] / p;
            if f != 0.0 {
                for j in k + 1..n {
                    a[i * n + j] -= f * a[k * n + j];
                }
            }
        }
    }
    sign
}

/// Singular values of a small matrix (row-major `nrows x ncols`, `nrows >= ncols`) by
/// one-sided Jacobi rotations (Hestenes), descending, into `out` (length `ncols`).
///
/// No factorisation object, one copy of the matrix in `work` (reused from call to call): for the
/// natural-frequency scan, which
/// asks for `sigma_min / sigma_max` of a 2 to 8 column matrix hundreds of times, this is
/// several times cheaper than a general SVD, and it computes small singular values to high
/// relative accuracy (Demmel and Veselic, SIAM J. Matrix Anal. Appl. 13, 1992).
pub(crate) fn singular_values_small(
    rows: &[f64],
    (nrows, ncols): (usize, usize),
    out: &mut [f64],
    work: &mut Vec<f64>,
) {
    debug_assert!(nrows >= ncols && rows.len() == nrows * ncols && out.len() == ncols);
    work.clear();
    work.extend_from_slice(rows);
    let a = work;
    let col = |a: &[f64], p: usize, q: usize| {
        let (mut alpha, mut beta, mut gamma) = (0.0, 0.0, 0.0);
        for r in a.chunks_exact(ncols) {
            alpha += r[p] * r[p];
            beta += r[q] * r[q];
            gamma += r[p] * r[q];
        }
        (alpha, beta, gamma)
    };
    for _sweep in 0..60 {
        let mut rotated = false;
        for p in 0..ncols {
            for q in p + 1..ncols {
                let (alpha, beta, gamma) = col(a, p, q);
                if gamma == 0.0 || gamma.abs() <= f64::EPSILON * (alpha * beta).sqrt() {
                    continue;
                }
                rotated = true;
                let zeta = (beta - alpha) / (2.0 * gamma);
                let t = zeta.signum() / (zeta.abs() + (1.0 + zeta * zeta).sqrt());
                let c = 1.0 / (1.0 + t * t).sqrt();
                let s = c * t;
                for r in a.chunks_exact_mut(ncols) {
                    let (x, y) = (r[p], r[q]);
                    r[p] = c * x - s * y;
                    r[q] = s * x + c * y;
                }
            }
        }
        if !rotated {
            break;
        }
    }
    for (j, o) in out.iter_mut().enumerate() {
        *o = a
            .chunks_exact(ncols)
            .map(|r| r[j] * r[j])
            .sum::<f64>()
            .sqrt();
    }
    out.sort_by(|x, y| y.total_cmp(x));
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lane_dot_matches_the_plain_sum() {
        for n in 0..11 {
            let a: Vec<f64> = (0..n).map(|i| 1.0 + i as f64).collect();
            let b: Vec<f64> = (0..n).map(|i| 0.5 - i as f64).collect();
            let plain: f64 = a.iter().zip(&b).map(|(x, y)| x * y).sum();
            assert_eq!(dot_lanes(&a, &b), plain, "n = {n}");
        }
    }

    #[test]
    fn lu_solves_and_detects_singularity() {
        let mut a = DenseMatrix::zeros(2, 2);
        a[(0, 0)] = 2.0;
        a[(0, 1)] = 1.0;
        a[(1, 0)] = 1.0;
        a[(1, 1)] = 3.0;
        let lu = Lu::factor(&a, 1e-14).unwrap();
        let mut b = [3.0, 4.0];
        lu.solve_in_place(&mut b);
        assert!((b[0] - 1.0).abs() < 1e-14 && (b[1] - 1.0).abs() < 1e-14);
        a[(1, 1)] = 0.5;
        assert!(Lu::factor(&a, 1e-14).is_err());
    }

    /// `det` by cofactor expansion along the first column (small `n` only).
    fn cofactor_determinant(a: &DenseMatrix) -> f64 {
        let n = a.nrows();
        if n == 1 {
            return a[(0, 0)];
        }
        (0..n)
            .map(|i| {
                let mut minor = DenseMatrix::zeros(n - 1, n - 1);
                for (r, row) in (0..n).filter(|&r| r != i).enumerate() {
                    for c in 1..n {
                        minor[(r, c - 1)] = a[(row, c)];
                    }
                }
                let sign = if i % 2 == 0 { 1.0 } else { -1.0 };
                sign * a[(i, 0)] * cofactor_determinant(&minor)
            })
            .sum()
    }

    #[test]
    fn determinant_sign_matches_the_cofactor_expansion() {
        let mut seed = 0x2545_f491_4f6c_dd1d_u64;
        let mut next = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let (mut negative, mut pivoted) = (0, 0);
        for trial in 0..200 {
            let n = 1 + trial % 6;
            let mut a = DenseMatrix::zeros(n, n);
            for j in 0..n {
                for i in 0..n {
                    a[(i, j)] = next();
                }
            }
            let det = cofactor_determinant(&a);
            let lu = Lu::factor(&a, 0.0).unwrap();
            assert_eq!(lu.determinant_sign(), det.signum(), "n = {n}, det = {det}");
            negative += usize::from(det < 0.0);
            pivoted += usize::from(lu.perm.iter().enumerate().any(|(i, &p)| i != p));
        }
        assert!(
            negative > 50 && pivoted > 100,
            "{negative} negative, {pivoted} pivoted"
        );
    }

    #[test]
    fn transposed_solve_inverts_the_transpose() {
        // A fixed non-symmetric matrix whose LU pivots rows, so the permutation matters.
        let n = 7;
        let mut a = DenseMatrix::zeros(n, n);
        for i in 0..n {
            for j in 0..n {
                a[(i, j)] =
                    ((3 * i + 5 * j * j + 1) % 11) as f64 - 4.5 + if i == j { 0.3 } else { 0.0 };
            }
        }
        let lu = Lu::factor(&a, 1e-14).unwrap();
        assert!(
            lu.perm.iter().enumerate().any(|(i, &p)| i != p),
            "pivoting exercised"
        );
        let x: Vec<f64> = (0..n).map(|i| 1.0 + 0.25 * i as f64).collect();
        let mut b = vec![0.0; n];
        a.mul_transpose_vec(&x, &mut b);
        lu.solve_transpose_in_place(&mut b);
        for (got, want) in b.iter().zip(&x) {
            assert!((got - want).abs() < 1e-12, "{got} vs {want}");
        }
    }

    #[test]
    fn jacobi_singular_values_match_the_svd() {
        // Fixed pseudo-random matrices of the scan's sizes, one nearly singular.
        let mut seed = 0x9e37_79b9_7f4a_7c15_u64;
        let mut next = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        for n in [1, 2, 3, 4, 6, 8] {
            let mut a: Vec<f64> = (0..n * n).map(|_| next()).collect();
            if n > 1 {
                // Row n-1 = row 0 + 1e-9 noise: sigma_min ~ 1e-9.
                for j in 0..n {
                    a[(n - 1) * n + j] = a[j] + 1e-9 * next();
                }
            }
            let (svd, _) = svd_small(&a, n, n);
            let mut jac = vec![0.0; n];
            singular_values_small(&a, (n, n), &mut jac, &mut Vec::new());
            for (s, j) in svd.iter().zip(&jac) {
                assert!(
                    (s - j).abs() <= 1e-13 * svd[0],
                    "n = {n}: {svd:?} vs {jac:?}"
                );
            }
        }
    }

    /// The small elimination's sign of the determinant is the LU's, on random matrices of
    /// the scan's sizes and on their row swaps (which flip it); a zero column gives 0.
    #[test]
    fn small_determinant_sign_matches_the_lu() {
        let mut state = 0x2545_f491_u64;
        let mut next = move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
        };
        let mut work = Vec::new();
        for n in [1, 2, 3, 4, 6, 8] {
            for _ in 0..20 {
                let a: Vec<f64> = (0..n * n).map(|_| next()).collect();
                let mut m = DenseMatrix::zeros(n, n);
                for i in 0..n {
                    for j in 0..n {
                        m.column_mut(j)[i] = a[i * n + j];
                    }
                }
                let want = Lu::factor(&m, 0.0).unwrap().determinant_sign();
                assert_eq!(determinant_sign_small(&a, n, &mut work), want, "n = {n}");
                if n > 1 {
                    let mut swapped = a.clone();
                    for j in 0..n {
                        swapped.swap(j, n + j);
                    }
                    assert_eq!(determinant_sign_small(&swapped, n, &mut work), -want);
                }
            }
        }
        let mut singular = vec![1.0, 0.0, 2.0, 0.0];
        assert_eq!(determinant_sign_small(&singular, 2, &mut work), 0.0);
        singular[1] = f64::NAN;
        assert_eq!(determinant_sign_small(&singular, 2, &mut work), 0.0);
    }

    #[test]
    fn svd_reports_null_direction() {
        // rows (1, 1, 0) and (0, 0, 1): null direction (1, -1, 0)/sqrt 2
        let (s, v) = svd_small(&[1.0, 1.0, 0.0, 0.0, 0.0, 1.0], 2, 3);
        assert_eq!(s.len(), 2);
        let n = [v[(0, 2)], v[(1, 2)], v[(2, 2)]];
        assert!((n[0] + n[1]).abs() < 1e-14 && n[2].abs() < 1e-14);
    }
}
