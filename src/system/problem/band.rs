//! The Newton step of assemblies with several contacts: a staircase LU of the whole Jacobian.
//!
//! The condensed step of `step.rs` leaves a dense matrix of size `len * n_contacts`: its null
//! directions `Z_i` (from a QR of all of a harmonic's rows) move every bar, so each law row
//! meets every contact's unknowns and the LU costs `(len n_contacts)^3 / 3`, cubic in the
//! size of the assembly. But every row of the Jacobian involves few bars: a linear row (a
//! boundary condition, a contact's force balance) the bars of its ends, a law's rows the bars
//! its gap and force are read on. With the unknowns taken bar by bar (block `b`: the `2 len`
//! Helmholtz coefficients `(A, B)` of bar `b`, harmonic after harmonic) each row has its
//! nonzeros in the blocks of the bars it involves. For a chain, where contact `l` joins bars
//! `l` and `l + 1`, every row spans at most two neighbouring blocks: the Jacobian is a
//! staircase ([`crate::linalg::Staircase`]) whose LU with partial pivoting works on windows
//! of `3 len` rows and `4 len` columns, one per bar, at a cost linear in the number of bars.
//!
//! It is the LU of the same Jacobian as the dense fallback's (`Problem::jacobian`), with the
//! same pivot tolerance, so the steps agree with it to rounding; unlike the condensed step it
//! needs neither a null basis nor its regularity. It is used for two contacts or more where
//! its multiply-adds are fewer than the condensed LU's ([`worth_it`]); systems with one contact
//! keep the condensed step.

use super::discretization::Discretization;
use super::state::{Frequency, Samples};
use crate::fourier::Basis;
use crate::linalg::{Staircase, StaircaseLu};
use crate::solve::{SingularStep, PIVOT_TOLERANCE};

/// Whether the staircase LU of shape `shape` takes fewer multiply-adds than the condensed LU
/// of `d`, `(len n_contacts)^3 / 3`. The staircase's windows are smaller matrices, on which
/// faer's kernels run slower, but it needs no condensation at a new frequency: on chains at
/// `m = 20` the measured times cross where the counts do, between 7 and 8 bars
/// (`benches/chain.rs`, `docs/performance.md`).
fn worth_it<B: Basis>(d: &Discretization<B>, shape: &Staircase) -> bool {
    let condensed = (d.basis().len() * d.laws) as f64;
    shape.flops() < condensed.powi(3) / 3.0
}

/// Storage of the staircase step: the factors and one solution in bar-by-bar order.
#[derive(Debug, Clone, Default)]
pub(super) struct Banded {
    lu: StaircaseLu,
    solution: Vec<f64>,
    /// Take the staircase wherever there is one, whatever it costs (tests).
    always: bool,
}

impl Banded {
    /// Solves `J(x) z = r` in place for the `columns` right-hand sides stored one after the
    /// other in `rhs`, at the frequency of `at` and with the law samples of `samples` (those
    /// of `x`). `None` where the Jacobian is not a staircase
    /// ([`staircase_of`](super::staircase::staircase_of)) or its LU
    /// costs more than the condensed one.
    pub(super) fn solve<B: Basis>(
        &mut self,
        (d, at): (&Discretization<B>, &mut Frequency),
        samples: &mut Samples,
        rhs: &mut [f64],
        columns: usize,
    ) -> Option<Result<(), SingularStep>> {
        if !at.prepare_staircase(d) {
            return None;
        }
        let at = &*at;
        let shape = at.staircase()?;
        if !(self.always || worth_it(d, shape)) {
            return None;
        }
        for l in 0..d.laws {
            samples.form_grams(d, l);
        }
        let fill = |row: usize, first: usize, out: &mut [f64]| {
            fill_row((d, at), samples, (row, first), out)
        };
        if let Err(p) = self.lu.factor(shape, fill, PIVOT_TOLERANCE) {
            return Some(Err(SingularStep {
                pivot: p.pivot,
                ratio: p.ratio,
            }));
        }
        let (len, bars, n) = (d.basis().len(), d.unknowns / 2, d.dimension());
        self.solution.resize(n, 0.0);
        for column in rhs.chunks_exact_mut(n).take(columns) {
            self.lu.solve(shape, column, &mut self.solution);
            // Bar by bar (block b, entry 2 i + which) to the layout (coefficient by coefficient).
            for (b, block) in self.solution.chunks_exact(2 * len).enumerate() {
                for (i, pair) in block.chunks_exact(2).enumerate() {
                    let at = (i * bars + b) * 2;
                    column[at..at + 2].copy_from_slice(pair);
                }
            }
        }
        Some(Ok(()))
    }
}

/// Row `row` of the Jacobian (in the residual's order) over the bars `first..`, bar by bar,
/// into `out` (zeroed; as many bars as it holds): the entries of
/// [`Problem::jacobian`](crate::solve::Problem::jacobian), by columns in the staircase's order.
fn fill_row<B: Basis>(
    (d, at): (&Discretization<B>, &Frequency),
    samples: &Samples,
    (row, first): (usize, usize),
    out: &mut [f64],
) {
    let (len, rpc) = (d.basis().len(), d.linear_count);
    let block = 2 * len;
    let bars = first..(first + out.len() / block).min(d.unknowns / 2);
    let rows_of = |i: usize| &at.rows[d.basis().harmonic(i)];
    if row < len * rpc {
        let (i, r) = (row / rpc, row % rpc);
        let linear = rows_of(i).linear_row(r);
        for b in bars {
            let to = (b - first) * block + 2 * i;
            out[to..to + 2].copy_from_slice(&linear[2 * b..2 * b + 2]);
        }
        return;
    }
    let (l, j) = ((row - len * rpc) / len, (row - len * rpc) % len);
    let (gram_gap, gram_force) = samples.grams(l, len);
    let (gg, gf) = (
        &gram_gap[j * len..(j + 1) * len],
        &gram_force[j * len..(j + 1) * len],
    );
    for (i, (&g, &f)) in gg.iter().zip(gf).enumerate() {
        if g == 0.0 && f == 0.0 {
            continue;
        }
        let (gap, force) = (rows_of(i).gap_row(l), rows_of(i).force_row(l));
        for b in bars.clone() {
            let to = (b - first) * block + 2 * i;
            for w in 0..2 {
                out[to + w] = g * gap[2 * b + w] + f * force[2 * b + w];
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::{HarmonicBalanceSettings, NonsmoothSystem};
    use super::*;
    use crate::branches::PeriodGrid;
    use crate::continuation::ContinuationProblem;
    use crate::linalg::{DenseMatrix, Lu};
    use crate::modal::branch_seed;
    use crate::reference::contact_chain;
    use crate::solve::{Problem, Structured};

    /// A chain of `bars` bars at `m = 10` at a point where every contact closes over part of
    /// the period: the first mode's seed plus neighbouring bars moving in opposition.
    fn chain_point(bars: usize) -> (NonsmoothSystem, Vec<f64>) {
        let system = contact_chain(bars, 1e-3, 0.5).unwrap();
        let settings = HarmonicBalanceSettings {
            harmonics: 10,
            ..Default::default()
        };
        let mut problem = NonsmoothSystem::new(&system, settings).unwrap();
        let period = PeriodGrid::for_mode(&system, 1, 1).unwrap().start;
        let omega = 2.0 * std::f64::consts::PI / period;
        let mut x = branch_seed(&mut problem, 1, 1, omega).unwrap();
        problem.set_parameter(omega);
        for bar in 0..bars {
            let sign = if bar % 2 == 0 { 1.0 } else { -1.0 };
            x[problem.index(1, bar, 0)] += 3e-3 * sign;
            x[problem.index(2, bar, 1)] -= 1e-3 * sign;
        }
        let n = problem.basis().samples();
        let active = problem.active_set(&x).unwrap();
        assert!(active.iter().all(|&a| a > 0 && a < n), "{active:?}");
        (problem, x)
    }

    /// Two right-hand sides solved by the problem's structured step and by a dense LU of its
    /// Jacobian.
    fn structured_and_dense(problem: &mut NonsmoothSystem, x: &[f64]) -> (Vec<f64>, Vec<f64>) {
        let n = x.len();
        let mut rhs = vec![0.0; 2 * n];
        problem.residual(x, &mut rhs[..n]);
        for (k, v) in rhs[n..].iter_mut().enumerate() {
            *v = ((k * 37) % 11) as f64 - 5.0;
        }
        let mut dense = rhs.clone();
        let mut jac = DenseMatrix::default();
        problem.jacobian(x, &mut jac);
        let lu = Lu::factor(&jac, PIVOT_TOLERANCE).unwrap();
        dense.chunks_exact_mut(n).for_each(|c| lu.solve_in_place(c));
        problem.solve_jacobian(x, &mut rhs, 2).unwrap().unwrap();
        (rhs, dense)
    }

    fn assert_close(a: &[f64], b: &[f64], tolerance: f64) {
        let n = b.len() / 2;
        for (a, b) in a.chunks_exact(n).zip(b.chunks_exact(n)) {
            let size = b.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
            let error = a
                .iter()
                .zip(b)
                .fold(0.0_f64, |m, (x, y)| m.max((x - y).abs()));
            assert!(error <= tolerance * size, "error {error:e} of {size:e}");
        }
    }

    #[test]
    fn staircase_steps_agree_with_the_dense_jacobian() {
        for bars in [3, 5, 8] {
            let (mut problem, x) = chain_point(bars);
            problem.ws.banded.always = true;
            let (structured, dense) = structured_and_dense(&mut problem, &x);
            assert!(problem.ws.frequency.staircase().is_some(), "{bars} bars");
            assert_close(&structured, &dense, 1e-9);
        }
    }

    #[test]
    fn long_chains_take_the_staircase_and_one_contact_does_not() {
        let (mut problem, x) = chain_point(24);
        let (structured, dense) = structured_and_dense(&mut problem, &x);
        let shape = problem.ws.frequency.staircase().expect("a staircase");
        assert!(worth_it(problem.description(), shape));
        assert_close(&structured, &dense, 1e-9);
        // Two bars, one contact: no staircase, the condensed step.
        let (mut problem, x) = chain_point(2);
        problem.ws.banded.always = true;
        structured_and_dense(&mut problem, &x);
        assert!(problem.ws.frequency.staircase().is_none());
    }
}
