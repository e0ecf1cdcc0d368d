//! LU with partial pivoting of a staircase matrix, at a cost linear in its number of blocks.
//!
//! The columns of a square matrix of size `n = blocks * block` come in `blocks` blocks of
//! `block` columns, and each row has its nonzeros in a run of consecutive blocks
//! `first..=last`. Taken in the order of their first block, the rows form a staircase: the
//! columns of block `b` meet only the rows whose first block is at most `b`. Gaussian
//! elimination with partial pivoting then proceeds block by block on a dense window:
//!
//! - step `b` holds the rows left over from step `b - 1` (updated) and the rows whose first
//!   block is `b`, over the columns of blocks `b..=last(b)` (`last(b)`: the largest last block
//!   of any row seen so far);
//! - it factorises the panel of block `b`'s columns, `P [A_1; A_2] = [L_11; L_21] U_11`, with
//!   the pivots chosen among all the window's rows, forms `U_12 = L_11^{-1} (P A)_top` and the
//!   update `S = (P A)_bottom - L_21 U_12` of the other columns;
//! - the rows of `S` are the rows left over for step `b + 1`.
//!
//! Rows outside the window have zeros in block `b`'s columns, so the pivots are those partial
//! pivoting would choose on the whole matrix (up to ties): this is `P A Q = L U` of the matrix
//! with its columns in block order, as stable as a dense LU, and a solution agrees with a dense
//! solve to rounding. With windows of `r` rows and `w` columns the cost is
//! `sum_b (r k^2 / 2 + k^2 w / 2 + r k w)` multiply-adds (`k = block`): linear in `blocks` when
//! the windows stay bounded, against `n^3 / 3` for a dense LU.

use super::SmallPivot;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::lu::partial_pivoting::factor;
use faer::linalg::matmul::matmul;
use faer::linalg::triangular_solve;
use faer::{Accum, MatMut, MatRef, Par};

/// The shape of a staircase matrix (see the module docs): the order in which the rows enter
/// the elimination and the window of each step.
#[derive(Debug, Clone, PartialEq, Default)]
pub(crate) struct Staircase {
    /// Columns per block.
    block: usize,
    /// Row indices by first block (stable in the row index).
    rows: Vec<usize>,
    /// `rows[starts[b]..starts[b + 1]]` enter at step `b`.
    starts: Vec<usize>,
    /// The last block of step `b`'s window.
    last: Vec<usize>,
}

impl Staircase {
    /// The shape of the `n x n` matrix (`n = blocks * block`) whose row `i` has its nonzeros in
    /// the blocks `spans[i].0..=spans[i].1`. `None` if `spans` does not have `n` entries, a
    /// span is empty or out of range, or the matrix is singular by its shape alone: the
    /// columns of blocks `0..=b` meet fewer than `(b + 1) * block` rows.
    pub(crate) fn new(block: usize, blocks: usize, spans: &[(usize, usize)]) -> Option<Self> {
        if block == 0 || spans.len() != blocks.checked_mul(block)? {
            return None;
        }
        if spans.iter().any(|&(f, l)| f > l || l >= blocks) {
            return None;
        }
        let mut starts = vec![0; blocks + 1];
        for &(first, _) in spans {
            starts[first + 1] += 1;
        }
        for b in 0..blocks {
            starts[b + 1] += starts[b];
        }
        let mut next = starts.clone();
        let mut rows = vec![0; spans.len()];
        let mut last = vec![0; blocks];
        let mut reach = 0;
        for (row, &(first, l)) in spans.iter().enumerate() {
            rows[next[first]] = row;
            next[first] += 1;
            last[first] = last[first].max(l);
        }
        for (b, last) in last.iter_mut().enumerate() {
            reach = reach.max(*last).max(b);
            *last = reach;
            if starts[b + 1] < (b + 1) * block {
                return None;
            }
        }
        Some(Self {
            block,
            rows,
            starts,
            last,
        })
    }

    /// Number of column blocks.
    pub(crate) fn blocks(&self) -> usize {
        self.last.len()
    }

    /// Columns per block.
    pub(crate) fn block(&self) -> usize {
        self.block
    }

    /// The rows of step `b`: those in `rows` that enter it, and the window's width in columns.
    fn step(&self, b: usize) -> (&[usize], usize) {
        let entering = &self.rows[self.starts[b]..self.starts[b + 1]];
        (entering, (self.last[b] + 1 - b) * self.block)
    }

    /// The multiply-adds of a factorisation (see the module docs), to compare with the
    /// `n^3 / 3` of a dense LU.
    pub(crate) fn flops(&self) -> f64 {
        let k = self.block as f64;
        let mut carried = 0.0;
        let mut total = 0.0;
        for b in 0..self.blocks() {
            let (entering, width) = self.step(b);
            let (r, w) = (carried + entering.len() as f64, width as f64);
            total += r * k * k / 2.0 + k * k * (w - k) / 2.0 + (r - k) * k * (w - k);
            carried = r - k;
        }
        total
    }
}

/// Where step `b`'s window and permutation live.
#[derive(Debug, Clone, Copy, Default)]
struct Step {
    /// Offset of the window in [`StaircaseLu::windows`].
    window: usize,
    /// Offset of the permutation in [`StaircaseLu::perms`].
    perm: usize,
    /// Rows of the window: carried from the previous step, then entering.
    rows: usize,
    carried: usize,
    /// Columns of the window.
    width: usize,
}

/// The factors of a [`Staircase`] matrix, kept for any number of solves. Storage is reused
/// from one factorisation to the next.
#[derive(Debug, Clone, Default)]
pub(crate) struct StaircaseLu {
    steps: Vec<Step>,
    /// Each step's window after its elimination, column-major: `[L_11 \ U_11; L_21]` in the
    /// first `block` columns, `[U_12; S]` in the others.
    windows: Vec<f64>,
    /// Each step's row permutation: row `i` of the factors is row `perm[i]` of the window.
    perms: Vec<usize>,
    perm_inv: Vec<usize>,
    /// One row of a window (filling) or one column (permuting), and a solve's vectors.
    scratch: Vec<f64>,
    carry: Vec<f64>,
}

impl StaircaseLu {
    /// Factorises the matrix of shape `shape` whose row `row` restricted to the blocks
    /// `first..` is written by `fill(row, first, out)` into `out` (zeroed, one entry per column
    /// of the blocks `first..=last`, in order). Fails when `min |u_ii| <= tolerance max |u_jj|`
    /// (as [`super::Lu`]), leaving the factors unusable until the next success.
    pub(crate) fn factor(
        &mut self,
        shape: &Staircase,
        mut fill: impl FnMut(usize, usize, &mut [f64]),
        tolerance: f64,
    ) -> Result<(), SmallPivot> {
        let k = shape.block();
        self.layout(shape);
        let req = factor::lu_in_place_scratch::<usize, f64>(k, k, Par::Seq, Default::default());
        let mut buffer = MemBuffer::new(req);
        let (mut max, mut min, mut at) = (0.0_f64, f64::INFINITY, 0);
        for b in 0..shape.blocks() {
            let step = self.steps[b];
            let (done, rest) = self.windows.split_at_mut(step.window);
            let window = &mut rest[..step.rows * step.width];
            // The rows left over by the previous step, then the entering ones.
            if let Some(prev) = b.checked_sub(1).map(|p| self.steps[p]) {
                let previous = &done[prev.window..prev.window + prev.rows * prev.width];
                for c in 0..step.width {
                    let column = &mut window[c * step.rows..c * step.rows + step.carried];
                    match previous.get((k + c) * prev.rows..(k + c + 1) * prev.rows) {
                        Some(from) => column.copy_from_slice(&from[k..]),
                        None => column.fill(0.0),
                    }
                }
            }
            let (entering, _) = shape.step(b);
            for (j, &row) in entering.iter().enumerate() {
                self.scratch.clear();
                self.scratch.resize(step.width, 0.0);
                fill(row, b, &mut self.scratch);
                for (c, &v) in self.scratch.iter().enumerate() {
                    window[c * step.rows + step.carried + j] = v;
                }
            }
            let perm = &mut self.perms[step.perm..step.perm + step.rows];
            self.perm_inv.resize(step.rows, 0);
            {
                let panel =
                    MatMut::from_column_major_slice_mut(&mut window[..step.rows * k], step.rows, k);
                let _ = factor::lu_in_place(
                    panel,
                    perm,
                    &mut self.perm_inv,
                    Par::Seq,
                    MemStack::new(&mut buffer),
                    Default::default(),
                );
            }
            for j in 0..k {
                let d = window[j * step.rows + j].abs();
                max = max.max(d);
                if d < min {
                    (min, at) = (d, b * k + j);
                }
            }
            // The other columns: permuted like the panel, then U_12 and the update S.
            for column in window[k * step.rows..].chunks_exact_mut(step.rows) {
                self.scratch.clear();
                self.scratch.extend(perm.iter().map(|&p| column[p]));
                column.copy_from_slice(&self.scratch);
            }
            let whole = MatMut::from_column_major_slice_mut(window, step.rows, step.width);
            let (panel, trailing) = whole.split_at_col_mut(k);
            let (l11, l21) = panel.split_at_row_mut(k);
            let (mut u12, s) = trailing.split_at_row_mut(k);
            triangular_solve::solve_unit_lower_triangular_in_place(
                l11.as_ref(),
                u12.as_mut(),
                Par::Seq,
            );
            matmul(s, Accum::Add, l21.as_ref(), u12.as_ref(), -1.0, Par::Seq);
        }
        // NaN pivots fail the comparison, hence count as too small.
        if shape.blocks() > 0 && !(min > tolerance * max && max.is_finite()) {
            return Err(SmallPivot {
                pivot: at,
                ratio: if max > 0.0 { min / max } else { 0.0 },
            });
        }
        Ok(())
    }

    /// Sizes the windows and permutations for `shape`.
    fn layout(&mut self, shape: &Staircase) {
        self.steps.clear();
        let (mut window, mut perm, mut carried) = (0, 0, 0);
        for b in 0..shape.blocks() {
            let (entering, width) = shape.step(b);
            let rows = carried + entering.len();
            self.steps.push(Step {
                window,
                perm,
                rows,
                carried,
                width,
            });
            window += rows * width;
            perm += rows;
            carried = rows - shape.block();
        }
        self.windows.resize(window, 0.0);
        self.perms.resize(perm, 0);
    }

    /// Solves `A x = r` for the factorised matrix of shape `shape`: `r` by row, `x` into
    /// `out` by column (blocks in order).
    ///
    /// # Panics
    /// If `r` or `out` is not of the matrix's size.
    pub(crate) fn solve(&mut self, shape: &Staircase, r: &[f64], out: &mut [f64]) {
        let k = shape.block();
        assert_eq!(
            r.len(),
            out.len(),
            "right-hand side and solution of one size"
        );
        assert_eq!(
            out.len(),
            k * shape.blocks(),
            "solution of the matrix's size"
        );
        self.carry.clear();
        // Forward: y = L^{-1} P r, step by step; the rows left over carry to the next step.
        for (b, step) in self.steps.iter().enumerate() {
            let (entering, _) = shape.step(b);
            self.carry.extend(entering.iter().map(|&row| r[row]));
            let perm = &self.perms[step.perm..step.perm + step.rows];
            self.scratch.clear();
            self.scratch.extend(perm.iter().map(|&p| self.carry[p]));
            let window = &self.windows[step.window..step.window + step.rows * step.width];
            let v = &mut self.scratch;
            for j in 0..k {
                let (vj, column) = (v[j], &window[j * step.rows..(j + 1) * step.rows]);
                for (vi, l) in v[j + 1..].iter_mut().zip(&column[j + 1..]) {
                    *vi -= l * vj;
                }
            }
            out[b * k..(b + 1) * k].copy_from_slice(&v[..k]);
            self.carry.clear();
            self.carry.extend_from_slice(&v[k..]);
        }
        // Backward: x_b = U_11^{-1} (y_b - U_12 x_(b+1..)).
        for (b, step) in self.steps.iter().enumerate().rev() {
            let window = MatRef::from_column_major_slice(
                &self.windows[step.window..step.window + step.rows * step.width],
                step.rows,
                step.width,
            );
            let (head, tail) = out.split_at_mut((b + 1) * k);
            let x = &mut head[b * k..];
            for (c, &xc) in tail[..step.width - k].iter().enumerate() {
                for (i, xi) in x.iter_mut().enumerate() {
                    *xi -= window[(i, k + c)] * xc;
                }
            }
            for j in (0..k).rev() {
                x[j] /= window[(j, j)];
                let xj = x[j];
                for (i, xi) in x[..j].iter_mut().enumerate() {
                    *xi -= window[(i, j)] * xj;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linalg::{DenseMatrix, Lu};

    /// A staircase matrix of `blocks` blocks of 3 columns: a chain of couplings (rows of
    /// blocks `b..=b+1`, as the contacts of a chain of bars), rows in a scrambled order.
    fn chain_matrix(blocks: usize) -> (DenseMatrix, Vec<(usize, usize)>) {
        let k = 3;
        let n = blocks * k;
        // Spans: 2 rows on block 0 alone, then pairs of blocks, then 1 row on the last block.
        let mut spans: Vec<(usize, usize)> = vec![(0, 0); 2];
        for b in 0..blocks - 1 {
            spans.extend([(b, b + 1); 3]);
        }
        spans.push((blocks - 1, blocks - 1));
        assert_eq!(spans.len(), n);
        // Scramble the row order (a permutation: 7 is prime to these n).
        let spans: Vec<_> = (0..n).map(|i| spans[(7 * i + 2) % n]).collect();
        let mut a = DenseMatrix::zeros(n, n);
        for (i, &(first, last)) in spans.iter().enumerate() {
            for c in first * k..(last + 1) * k {
                let hash = (i as f64 * 12.9898 + c as f64 * 78.233).sin() * 43758.5453;
                a[(i, c)] = hash.fract();
            }
        }
        (a, spans)
    }

    fn factor_of(a: &DenseMatrix, shape: &Staircase) -> Result<StaircaseLu, SmallPivot> {
        let k = shape.block();
        let mut lu = StaircaseLu::default();
        let fill = |row: usize, first: usize, out: &mut [f64]| {
            for (c, o) in out.iter_mut().enumerate() {
                *o = a[(row, first * k + c)];
            }
        };
        lu.factor(shape, fill, 1e-13).map(|()| lu)
    }

    #[test]
    fn staircase_solves_agree_with_a_dense_lu() {
        for blocks in [1, 2, 5, 9] {
            let (a, spans) = chain_matrix(blocks);
            let n = a.nrows();
            let shape = Staircase::new(3, blocks, &spans).unwrap();
            let mut lu = factor_of(&a, &shape).unwrap();
            let r: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin()).collect();
            let mut x = vec![0.0; n];
            lu.solve(&shape, &r, &mut x);
            let mut want = r.clone();
            Lu::factor(&a, 1e-13).unwrap().solve_in_place(&mut want);
            let size = want.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
            for (x, w) in x.iter().zip(&want) {
                assert!(
                    (x - w).abs() <= 1e-12 * size,
                    "{x} vs {w} ({blocks} blocks)"
                );
            }
            // Twice from the same factors.
            let mut again = vec![0.0; n];
            lu.solve(&shape, &r, &mut again);
            assert_eq!(again, x);
        }
    }

    #[test]
    fn singular_matrices_and_shapes_are_refused() {
        let (mut a, spans) = chain_matrix(4);
        let shape = Staircase::new(3, 4, &spans).unwrap();
        // Column 4 zeroed: a zero pivot.
        for i in 0..a.nrows() {
            a[(i, 4)] = 0.0;
        }
        assert!(factor_of(&a, &shape).is_err());
        // Too few rows reach the first block, a span out of range, a wrong count.
        let mut late = spans.clone();
        for s in late.iter_mut().filter(|s| s.0 == 0) {
            *s = (1, 1);
        }
        assert_eq!(Staircase::new(3, 4, &late), None);
        let mut wide = spans.clone();
        wide[0] = (0, 4);
        assert_eq!(Staircase::new(3, 4, &wide), None);
        assert_eq!(Staircase::new(3, 4, &spans[1..]), None);
        assert_eq!(Staircase::new(0, 4, &spans), None);
    }

    #[test]
    fn the_cost_is_linear_in_the_number_of_blocks() {
        let flops = |blocks| {
            let (_, spans) = chain_matrix(blocks);
            Staircase::new(3, blocks, &spans).unwrap().flops()
        };
        let (f8, f16) = (flops(8), flops(16));
        assert!(f16 < 2.2 * f8, "{f8} -> {f16}");
    }
}
