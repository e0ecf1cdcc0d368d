//! The bordering algorithm: a system `J` extended by one column and one row, solved with
//! `J`'s own structured solve.

use crate::continuation::ContinuationProblem;
use crate::linalg::DenseMatrix;
use crate::solve::{SingularStep, PIVOT_TOLERANCE};

/// Solves `[J, b; c^T, d] (z, zeta) = (r, rho)` in place for `columns` right-hand sides of
/// length `n + 1` stored one after the other in `rhs`, where `J = dF/dx` and
/// `b = dF/dlambda` are those of `problem` at `x` (its current parameter) and `border(i)`
/// gives `c_i` for `i < n` and `d` for `i = n`.
///
/// `J a = r` and `J b' = b` are solved in one structured call, then
/// `zeta = (rho - c.a) / (d - c.b')` and `z = a - zeta b'`. `None` where `J` has no
/// structured solve, is singular (at a fold of the family, where the bordered matrix is
/// regular), or the pivot `d - c.b'` vanishes to `PIVOT_TOLERANCE` relative to its terms:
/// the caller then factorises the dense bordered matrix. `buffer` is scratch storage.
pub(crate) fn solve_bordered<P: ContinuationProblem + ?Sized>(
    problem: &mut P,
    x: &[f64],
    (rhs, columns): (&mut [f64], usize),
    border: impl Fn(usize) -> f64,
    buffer: &mut Vec<f64>,
) -> Option<Result<(), SingularStep>> {
    let n = problem.dimension();
    buffer.clear();
    for column in rhs.chunks_exact(n + 1).take(columns) {
        buffer.extend_from_slice(&column[..n]);
    }
    buffer.resize((columns + 1) * n, 0.0);
    problem.parameter_derivative(x, &mut buffer[columns * n..]);
    let solved = problem
        .structure()
        .and_then(|s| s.solve_jacobian(x, buffer, columns + 1));
    if !matches!(solved, Some(Ok(()))) {
        return None;
    }
    let b = &buffer[columns * n..];
    let cb: f64 = (0..n).map(|i| border(i) * b[i]).sum();
    let pivot = border(n) - cb;
    let size = border(n).abs() + cb.abs();
    if !(pivot.is_finite() && pivot.abs() > PIVOT_TOLERANCE * size) {
        return None;
    }
    for (column, a) in rhs.chunks_exact_mut(n + 1).zip(buffer.chunks_exact(n)) {
        let ca: f64 = (0..n).map(|i| border(i) * a[i]).sum();
        let zeta = (column[n] - ca) / pivot;
        for i in 0..n {
            column[i] = a[i] - zeta * b[i];
        }
        column[n] = zeta;
    }
    Some(Ok(()))
}

/// The dense bordered matrix `[J, b; c^T, d]` into `jac` (resized to `n + 1`), from `J`
/// (`inner`, `n x n`), the column `b` and the row `border(i)` (`c_i` for `i < n`, `d` for
/// `i = n`): the fallback of [`solve_bordered`] and the Jacobian of a bordered problem.
pub(crate) fn fill_bordered(
    jac: &mut DenseMatrix,
    inner: &DenseMatrix,
    column: &[f64],
    border: impl Fn(usize) -> f64,
) {
    let n = column.len();
    jac.reset(n + 1, n + 1);
    for j in 0..n {
        for i in 0..n {
            jac[(i, j)] = inner[(i, j)];
        }
    }
    for (i, b) in column.iter().enumerate() {
        jac[(i, n)] = *b;
    }
    for i in 0..=n {
        jac[(n, i)] = border(i);
    }
}
