//! The structured Newton step: the linear rows condensed away (formulation §5).
//!
//! Per basis coefficient `i`, the harmonic's linear rows `L_i` leave a null space spanned by
//! `Z_i` (one direction per contact) and have a pseudo-inverse `L_i^+`. A solution of
//! `J z = r` is `z_i = L_i^+ r_lin,i + Z_i b_i`, where only the law block
//! `(N Z) b = r_law - N z_p` remains: a dense LU of size `len * n_contacts` instead of
//! `len * 2 n_bars` (8 times cheaper for one bar, 64 for two). `N` is the law block of the
//! Jacobian, `G(w_gap) * gap_rows + G(w_force) * force_rows`.
//!
//! The factorisation is made once per call and serves every right-hand side of the call
//! (the bordered systems of arclength continuation solve two).

use super::discretization::Discretization;
use super::state::{Frequency, Samples};
use crate::fourier::Basis;
use crate::linalg::{dot_lanes, Lu};
use crate::solve::SingularStep;
use crate::system::rows::dot;

/// Relative pivot threshold of the reduced LU. Stricter than the dense LU's (`1e-13`): the
/// reduced matrix has fewer, better scaled unknowns, so near-singular steps (a harmonic on a
/// part's natural frequency while the contact is open) show larger relative pivots, and with
/// `1e-13` they slip through and derail two-bar branches that the dense path steps over.
const REDUCED_PIVOT_TOLERANCE: f64 = 1e-10;

/// Storage of the structured step: the reduced matrix, its LU and vectors.
#[derive(Debug, Clone, Default)]
pub(super) struct Reduced {
    /// LU of the transposed reduced matrix, assembled in its storage.
    lu: Lu,
    /// A copy of one right-hand side (the solution overwrites it).
    column: Vec<f64>,
    rhs: Vec<f64>,
    /// Gap and force rows times the null directions, per law: `len * c` each.
    gap_z: Vec<f64>,
    force_z: Vec<f64>,
    gap_p: Vec<f64>,
    force_p: Vec<f64>,
}

impl Reduced {
    /// Solves `J(x) z = r` in place for the `columns` right-hand sides stored one after the
    /// other in `rhs`, at the frequency of `at` and with the law samples of `samples`, which
    /// the caller has made those of `x`. `dropped` lists the coefficients the harmonic
    /// selection holds at zero, ascending: their equations are `z_i = r_i` and no other
    /// equation sees them (`selection.rs`), so their null directions leave the reduced
    /// matrix and their law rows there become rows of the identity. `None` where a
    /// harmonic's rows are rank-deficient (the caller falls back to the dense Jacobian).
    pub(super) fn solve<B: Basis>(
        &mut self,
        (d, at): (&Discretization<B>, &mut Frequency),
        samples: &mut Samples,
        (rhs, columns): (&mut [f64], usize),
        dropped: &[usize],
    ) -> Option<Result<(), SingularStep>> {
        if !at.condense() {
            return None;
        }
        let at = &*at;
        let factored = self.factor((d, at), samples, dropped);
        if factored.is_ok() {
            for column in rhs.chunks_exact_mut(d.dimension()).take(columns) {
                self.solve_one((d, at), samples, column, dropped);
            }
        }
        Some(factored)
    }

    /// Forms every law's Gram matrices and the reduced matrix `N Z` (transposed, in the LU's
    /// storage), and factorises it.
    fn factor<B: Basis>(
        &mut self,
        (d, at): (&Discretization<B>, &Frequency),
        samples: &mut Samples,
        dropped: &[usize],
    ) -> Result<(), SingularStep> {
        let (len, un, rpc) = (d.basis().len(), d.unknowns, d.linear_count);
        let c = un - rpc;
        let size = len * c;
        // Every entry of the transposed reduced matrix is written below, straight into the
        // LU's storage (one column per law row).
        let matrix = self.lu.storage(size);
        self.gap_z.resize(d.laws * len * c, 0.0);
        self.force_z.resize(d.laws * len * c, 0.0);
        for l in 0..d.laws {
            samples.form_grams(d, l);
            let (gram_gap, gram_force) = samples.grams(l, len);
            let zs = l * len * c..(l + 1) * len * c;
            let (gap_z, force_z) = (&mut self.gap_z[zs.clone()], &mut self.force_z[zs]);
            for i in 0..len {
                let h = d.basis().harmonic(i);
                let (null, rows) = (&at.condensed[h].null, &at.rows[h]);
                let (grow, frow) = (rows.gap_row(l), rows.force_row(l));
                for k in 0..c {
                    let z = &null[k * un..(k + 1) * un];
                    gap_z[i * c + k] = dot(grow, z);
                    force_z[i * c + k] = dot(frow, z);
                }
            }
            // A dropped coefficient's null directions are seen by no law row.
            for &i in dropped {
                gap_z[i * c..(i + 1) * c].fill(0.0);
                force_z[i * c..(i + 1) * c].fill(0.0);
            }
            // The transpose is stored (column `l len + j` of the column-major storage is
            // row `j` of the law's block): reads of the row-major Gram matrices and writes
            // are both contiguous.
            for j in 0..len {
                let (gg, gf) = (
                    &gram_gap[j * len..(j + 1) * len],
                    &gram_force[j * len..(j + 1) * len],
                );
                let column = (l * len + j) * size;
                let out = &mut matrix[column..column + size];
                let zs = gap_z.iter().zip(force_z.iter());
                if dropped.binary_search(&j).is_ok() {
                    // The law row of a dropped coefficient: `b_(j, l) = 0` (one null
                    // direction per law, `c` of them).
                    out.fill(0.0);
                    out[j * c + l] = 1.0;
                } else if c == 1 {
                    // One contact (the common case): a plain vectorisable loop.
                    for ((m, (gz, fz)), (g, f)) in out.iter_mut().zip(zs).zip(gg.iter().zip(gf)) {
                        *m = g * gz + f * fz;
                    }
                } else {
                    for (col, (m, (gz, fz))) in out.iter_mut().zip(zs).enumerate() {
                        *m = gg[col / c] * gz + gf[col / c] * fz;
                    }
                }
            }
        }
        self.lu
            .factor_stored(REDUCED_PIVOT_TOLERANCE)
            .map_err(|p| SingularStep {
                pivot: p.pivot,
                ratio: p.ratio,
            })
    }

    /// Overwrites one right-hand side `r` (in the layout of the residual) with the solution
    /// `z` (in the layout of the unknowns), with the factorisation of
    /// [`Self::factor`].
    fn solve_one<B: Basis>(
        &mut self,
        (d, at): (&Discretization<B>, &Frequency),
        samples: &Samples,
        r: &mut [f64],
        dropped: &[usize],
    ) {
        let (len, un, rpc) = (d.basis().len(), d.unknowns, d.linear_count);
        let c = un - rpc;
        let base = len * rpc;
        self.column.clear();
        self.column.extend_from_slice(r);
        let z = r;
        // Particular part from the linear rows.
        for i in 0..len {
            let cd = &at.condensed[d.basis().harmonic(i)];
            let ri = &self.column[i * rpc..(i + 1) * rpc];
            let zi = &mut z[i * un..(i + 1) * un];
            zi.fill(0.0);
            for (row, rr) in ri.iter().enumerate() {
                for (d, p) in zi.iter_mut().zip(&cd.pinv[row * un..(row + 1) * un]) {
                    *d += p * rr;
                }
            }
        }
        self.rhs.clear();
        self.rhs.resize(len * c, 0.0);
        self.gap_p.resize(len, 0.0);
        self.force_p.resize(len, 0.0);
        for l in 0..d.laws {
            for i in 0..len {
                let rows = &at.rows[d.basis().harmonic(i)];
                let zi = &z[i * un..(i + 1) * un];
                self.gap_p[i] = dot(rows.gap_row(l), zi);
                self.force_p[i] = dot(rows.force_row(l), zi);
            }
            for &i in dropped {
                self.gap_p[i] = 0.0;
                self.force_p[i] = 0.0;
            }
            let (gram_gap, gram_force) = samples.grams(l, len);
            for j in 0..len {
                let row = l * len + j;
                let (gg, gf) = (
                    &gram_gap[j * len..(j + 1) * len],
                    &gram_force[j * len..(j + 1) * len],
                );
                self.rhs[row] = self.column[base + row]
                    - dot_lanes(gg, &self.gap_p)
                    - dot_lanes(gf, &self.force_p);
            }
            for &j in dropped {
                self.rhs[l * len + j] = 0.0;
            }
        }
        self.lu.solve_transpose_in_place(&mut self.rhs);
        for i in 0..len {
            let cd = &at.condensed[d.basis().harmonic(i)];
            let zi = &mut z[i * un..(i + 1) * un];
            for k in 0..c {
                let b = self.rhs[i * c + k];
                for (d, n) in zi.iter_mut().zip(&cd.null[k * un..(k + 1) * un]) {
                    *d += b * n;
                }
            }
        }
        // A dropped coefficient solves `z_i = r_i`: its linear rows give its first `rpc`
        // unknowns, its law rows the others.
        for &i in dropped {
            let zi = &mut z[i * un..(i + 1) * un];
            zi[..rpc].copy_from_slice(&self.column[i * rpc..(i + 1) * rpc]);
            for (l, v) in zi[rpc..].iter_mut().enumerate() {
                *v = self.column[base + l * len + i];
            }
        }
    }
}
