//! Per-harmonic linear rows and observables, written in the Helmholtz unknowns.
//!
//! For one harmonic of angular frequency `omega`, each bar `b` has two unknowns `(A_b, B_b)`
//! (see [`crate::bem`]). Every condition row and every law observable is a linear form in these
//! `2 n_bars` unknowns; [`HarmonicRows`] holds them as dense rows, with their derivatives in
//! `omega`.

use crate::bar::{End, EndRef};
use crate::bc::{LinearRows, Observable, Quantity, Term};
use crate::bem::{end_indices, HelmholtzMap};
use crate::linalg::svd_small;
use crate::system::BarSystem;

/// Weights `(w_u, w_p)` such that `quantity = w_u u + w_p p` at an end with outward normal `n`
/// on a bar of axial stiffness `EA` (`u` displacement, `p = n u_x` outward strain).
pub fn quantity_weights(quantity: Quantity, end: End, stiffness: f64) -> (f64, f64) {
    let n = end.normal();
    match quantity {
        Quantity::Displacement => (1.0, 0.0),
        Quantity::OutwardDisplacement => (n, 0.0),
        Quantity::Strain => (0.0, n),
        Quantity::OutwardStrain => (0.0, 1.0),
        Quantity::ContactForce => (0.0, -stiffness * n),
    }
}

/// Weights `(w_u, w_x)` such that `quantity = w_u u + w_x u_x` at an end (the form of
/// [`quantity_weights`] in the strain `u_x` rather than the outward strain `p = n u_x`).
pub fn quantity_weights_in_strain(quantity: Quantity, end: End, stiffness: f64) -> (f64, f64) {
    let (wu, wp) = quantity_weights(quantity, end, stiffness);
    (wu, wp * end.normal())
}

/// Adds `term` to a dense row over the `2 n_bars` Helmholtz unknowns, and its derivative in
/// `omega` to `d_row`.
fn add_term(
    term: &Term,
    maps: &[HelmholtzMap],
    stiffness: f64,
    row: &mut [f64],
    d_row: &mut [f64],
) {
    let b = term.end.bar.index();
    let (wu, wp) = quantity_weights(term.quantity, term.end.end, stiffness);
    let (iu, ip) = end_indices(term.end.end);
    let map = &maps[b];
    for j in 0..2 {
        let value = wu * map.rows[iu][j] + wp * map.rows[ip][j];
        let d_value = wu * map.d_omega[iu][j] + wp * map.d_omega[ip][j];
        row[2 * b + j] += term.coefficient * value;
        d_row[2 * b + j] += term.d_coefficient * value + term.coefficient * d_value;
    }
}

/// Linear rows and law observables of one harmonic.
#[derive(Debug, PartialEq)]
pub struct HarmonicRows {
    unknowns: usize,
    linear_count: usize,
    linear: Vec<f64>,
    d_linear: Vec<f64>,
    gap: Vec<f64>,
    d_gap: Vec<f64>,
    force: Vec<f64>,
    d_force: Vec<f64>,
    regularised: bool,
}

/// A copy that reuses the storage of the rows it overwrites ([`Clone::clone_from`]): the rows
/// of every harmonic are copied at each frequency a shared copy serves.
impl Clone for HarmonicRows {
    fn clone(&self) -> Self {
        Self {
            unknowns: self.unknowns,
            linear_count: self.linear_count,
            linear: self.linear.clone(),
            d_linear: self.d_linear.clone(),
            gap: self.gap.clone(),
            d_gap: self.d_gap.clone(),
            force: self.force.clone(),
            d_force: self.d_force.clone(),
            regularised: self.regularised,
        }
    }

    fn clone_from(&mut self, source: &Self) {
        self.unknowns = source.unknowns;
        self.linear_count = source.linear_count;
        self.linear.clone_from(&source.linear);
        self.d_linear.clone_from(&source.d_linear);
        self.gap.clone_from(&source.gap);
        self.d_gap.clone_from(&source.d_gap);
        self.force.clone_from(&source.force);
        self.d_force.clone_from(&source.d_force);
        self.regularised = source.regularised;
    }
}

/// Inputs of [`HarmonicRows::rebuild`] kept between frequencies: the laws' observables (fixed
/// for a system) and the per-frequency maps and condition rows, so that rebuilding the rows
/// of every harmonic at a new `Omega` does not allocate.
#[derive(Debug, Clone, Default)]
pub(crate) struct RowsScratch {
    observables: Vec<(Observable, Observable)>,
    maps: Vec<HelmholtzMap>,
    rows: LinearRows,
}

/// Writes `count` dense rows (and their derivatives in `omega`) over `unknowns` Helmholtz
/// unknowns into `v` and `d`, row `r` from the terms `terms_of(r)`.
fn fill_dense<'t>(
    terms_of: impl Iterator<Item = &'t [Term]>,
    count: usize,
    unknowns: usize,
    maps: &[HelmholtzMap],
    system: &BarSystem,
    (v, d): (&mut Vec<f64>, &mut Vec<f64>),
) {
    v.clear();
    v.resize(count * unknowns, 0.0);
    d.clear();
    d.resize(count * unknowns, 0.0);
    for (r, terms) in terms_of.enumerate() {
        let (row, d_row) = (
            &mut v[r * unknowns..(r + 1) * unknowns],
            &mut d[r * unknowns..(r + 1) * unknowns],
        );
        for t in terms {
            add_term(t, maps, system.stiffness_at(t.end), row, d_row);
        }
    }
}

impl HarmonicRows {
    /// Rows of `system` for the harmonic of angular frequency `omega` (0 for the constant).
    pub fn new(system: &BarSystem, omega: f64) -> Self {
        let mut rows = Self {
            unknowns: 0,
            linear_count: 0,
            linear: Vec::new(),
            d_linear: Vec::new(),
            gap: Vec::new(),
            d_gap: Vec::new(),
            force: Vec::new(),
            d_force: Vec::new(),
            regularised: false,
        };
        rows.rebuild(system, omega, &mut RowsScratch::default());
        rows
    }

    /// Rebuilds these rows for `system` at `omega` in place (as [`HarmonicRows::new`]),
    /// reusing their storage and `scratch`.
    pub(crate) fn rebuild(&mut self, system: &BarSystem, omega: f64, scratch: &mut RowsScratch) {
        if scratch.observables.len() != system.contact_count() {
            scratch.observables = system.laws().map(|l| (l.gap(), l.force())).collect();
        }
        let RowsScratch {
            observables,
            maps,
            rows,
        } = scratch;
        maps.clear();
        maps.extend(
            system
                .bars()
                .iter()
                .map(|bar| HelmholtzMap::new(bar, omega)),
        );
        let unknowns = system.unknowns_per_harmonic();
        let stiffness = |e: EndRef| system.stiffness_at(e);
        rows.clear();
        for condition in system.conditions() {
            condition.linear_rows(omega, &stiffness, rows);
        }
        let count = rows.len();
        fill_dense(
            (0..count).map(|i| rows.row(i)),
            count,
            unknowns,
            maps,
            system,
            (&mut self.linear, &mut self.d_linear),
        );
        let laws = observables.len();
        fill_dense(
            observables.iter().map(|(g, _)| g.terms.as_slice()),
            laws,
            unknowns,
            maps,
            system,
            (&mut self.gap, &mut self.d_gap),
        );
        fill_dense(
            observables.iter().map(|(_, f)| f.terms.as_slice()),
            laws,
            unknowns,
            maps,
            system,
            (&mut self.force, &mut self.d_force),
        );
        self.unknowns = unknowns;
        self.linear_count = count;
        self.regularised = false;
    }

    /// Number of unknowns `2 n_bars`.
    pub fn unknowns(&self) -> usize {
        self.unknowns
    }

    /// Number of linear rows (`2 n_bars - n_contacts` for a validated system).
    pub fn linear_count(&self) -> usize {
        self.linear_count
    }

    /// Linear row `r` (length `unknowns()`).
    ///
    /// # Panics
    /// If there is no row `r` (the same for the other row accessors: `r` or `l` at or beyond
    /// the number of rows or laws).
    pub fn linear_row(&self, r: usize) -> &[f64] {
        row(&self.linear, r, self.unknowns)
    }

    /// Derivative of linear row `r` in `omega`.
    pub fn linear_row_derivative(&self, r: usize) -> &[f64] {
        row(&self.d_linear, r, self.unknowns)
    }

    /// Linear part of the gap of law `l` (the offset is applied in time).
    pub fn gap_row(&self, l: usize) -> &[f64] {
        row(&self.gap, l, self.unknowns)
    }

    /// Derivative of [`HarmonicRows::gap_row`] in `omega`.
    pub fn gap_row_derivative(&self, l: usize) -> &[f64] {
        row(&self.d_gap, l, self.unknowns)
    }

    /// Contact force of law `l` as a row.
    pub fn force_row(&self, l: usize) -> &[f64] {
        row(&self.force, l, self.unknowns)
    }

    /// Derivative of [`HarmonicRows::force_row`] in `omega`.
    pub fn force_row_derivative(&self, l: usize) -> &[f64] {
        row(&self.d_force, l, self.unknowns)
    }

    /// Whether [`HarmonicRows::regularise`] replaced the linear rows.
    pub fn is_regularised(&self) -> bool {
        self.regularised
    }

    /// Residuals of the linear rows for the unknowns `x` (length `unknowns()`).
    pub fn linear_residuals(&self, x: &[f64], out: &mut [f64]) {
        for (r, o) in out.iter_mut().enumerate().take(self.linear_count) {
            *o = dot(self.linear_row(r), x);
        }
    }

    /// Handles a harmonic that sits on a natural frequency of two parts at once
    /// (formulation §5): the linear rows lose rank and a motion appears that no contact sees
    /// (zero gap and zero force). When the smallest singular value of the rows falls below
    /// `tolerance` times the largest, the rows are replaced by their numerically independent
    /// part plus one row per invisible direction pinning it to zero, so that the unknown count
    /// stays fixed and the Jacobian stays regular. Derivatives of replaced rows are set to
    /// zero. Returns whether it acted.
    pub fn regularise(&mut self, tolerance: f64) -> bool {
        let (n, r) = (self.unknowns, self.linear_count);
        if r == 0 || hadamard_ratio(&self.linear, r, n) > HADAMARD_SCREEN {
            return false;
        }
        let (s, v) = svd_small(&self.linear, r, n);
        let smax = s.iter().cloned().fold(0.0, f64::max);
        let rank = s.iter().filter(|&&x| x > tolerance * smax).count();
        if rank == r || !s.iter().all(|x| x.is_finite()) {
            return false;
        }
        // Null space of the rows: columns rank..n of v.
        let null: Vec<Vec<f64>> = (rank..n)
            .map(|j| (0..n).map(|i| v[(i, j)]).collect())
            .collect();
        let laws = self.gap.len() / n;
        let mut seen = vec![0.0; 2 * laws * null.len()];
        for l in 0..laws {
            for (c, z) in null.iter().enumerate() {
                seen[(2 * l) * null.len() + c] = dot(self.gap_row(l), z);
                seen[(2 * l + 1) * null.len() + c] = dot(self.force_row(l), z);
            }
        }
        let (t, w) = svd_small(&seen, 2 * laws, null.len());
        let tmax = t.iter().cloned().fold(0.0, f64::max).max(f64::MIN_POSITIVE);
        let seen_rank = t.iter().filter(|&&x| x > tolerance * tmax).count();
        let invisible: Vec<Vec<f64>> = (seen_rank..null.len())
            .map(|j| {
                (0..n)
                    .map(|i| (0..null.len()).map(|c| null[c][i] * w[(c, j)]).sum())
                    .collect()
            })
            .collect();
        if rank + invisible.len() != r {
            return false;
        }
        let mut rows = Vec::with_capacity(r * n);
        for (i, sigma) in s.iter().enumerate().take(rank) {
            rows.extend((0..n).map(|k| sigma * v[(k, i)]));
        }
        for z in &invisible {
            rows.extend(z.iter().map(|zi| smax * zi));
        }
        self.linear = rows;
        self.d_linear.fill(0.0);
        self.regularised = true;
        true
    }
}

/// Rows whose Hadamard ratio exceeds this are of full rank: no SVD needed. A rank loss with
/// relative singular value `s` gives a ratio of order `s^2`, far below it.
const HADAMARD_SCREEN: f64 = 1e-12;

/// Rows (four bars) up to which [`hadamard_ratio`] keeps its storage on the stack.
const SMALL_ROWS: usize = 8;

/// `det(L L^T) / prod |r_i|^2` of the `r x n` row-major rows `L`: 1 for orthogonal rows, 0 for
/// dependent ones (Hadamard's inequality), by a Cholesky factorisation of the small Gram
/// matrix. Returns 0 for a zero row or a failed factorisation.
fn hadamard_ratio(rows: &[f64], r: usize, n: usize) -> f64 {
    // Up to `SMALL_ROWS` rows the Gram matrix, the norms and the supports live on the stack:
    // the screen runs for every harmonic at every new frequency.
    let (mut stack, mut heap) = ([0.0; SMALL_ROWS * SMALL_ROWS + SMALL_ROWS], Vec::new());
    let buffer = scratch(&mut stack, &mut heap, r * r + r);
    let (g, norms) = buffer.split_at_mut(r * r);
    let (mut stack, mut heap) = ([(0, n); SMALL_ROWS], Vec::new());
    let supports = scratch(&mut stack, &mut heap, r);
    let row = |i: usize| &rows[i * n..(i + 1) * n];
    // Row `i` is zero outside `supports[i]`. A row involves the bars at its ends only, so in an
    // assembly of many bars most pairs of rows do not overlap: their product is zero without
    // a sum of `n` terms (the terms left out are exact zeros: the sums are the same). Up to
    // `SMALL_ROWS` rows the whole rows are cheaper than finding the supports.
    if r > SMALL_ROWS {
        for (i, s) in supports.iter_mut().enumerate() {
            let nonzero = |v: &f64| *v != 0.0;
            let first = row(i).iter().position(nonzero).unwrap_or(n);
            let last = row(i).iter().rposition(nonzero).map_or(first, |k| k + 1);
            *s = (first, last);
        }
    }
    let product = |i: usize, j: usize| {
        let (from, to) = (
            supports[i].0.max(supports[j].0),
            supports[i].1.min(supports[j].1),
        );
        if from < to {
            dot(&row(i)[from..to], &row(j)[from..to])
        } else {
            0.0
        }
    };
    for (i, v) in norms.iter_mut().enumerate() {
        *v = product(i, i);
    }
    // `v > 0` fails for zero and NaN alike.
    if !norms.iter().all(|&v| v > 0.0) {
        return 0.0;
    }
    // Gram matrix of the normalised rows, factorised in place (lower triangle).
    for i in 0..r {
        for j in 0..=i {
            g[i * r + j] = product(i, j) / (norms[i] * norms[j]).sqrt();
        }
    }
    let mut det = 1.0;
    for j in 0..r {
        let mut d = g[j * r + j];
        for k in 0..j {
            d -= g[j * r + k] * g[j * r + k];
        }
        if d.is_nan() || d <= 0.0 {
            return 0.0;
        }
        det *= d;
        let d = d.sqrt();
        g[j * r + j] = d;
        for i in j + 1..r {
            let mut v = g[i * r + j];
            for k in 0..j {
                v -= g[i * r + k] * g[j * r + k];
            }
            g[i * r + j] = v / d;
        }
    }
    det
}

/// The first `len` values of `stack` when it holds them (no allocation), else `heap` resized
/// to `len` default values: working storage whose small sizes stay off the heap.
fn scratch<'a, T: Copy + Default, const N: usize>(
    stack: &'a mut [T; N],
    heap: &'a mut Vec<T>,
    len: usize,
) -> &'a mut [T] {
    if len <= N {
        &mut stack[..len]
    } else {
        heap.resize(len, T::default());
        heap
    }
}

/// Row `r` of `width` values of the row-major `data`, by arithmetic that cannot wrap (a huge
/// `r` must not land on another row).
///
/// # Panics
/// If `data` has no row `r`.
fn row(data: &[f64], r: usize, width: usize) -> &[f64] {
    let start = r.checked_mul(width);
    let range = start.and_then(|s| Some(s..s.checked_add(width)?));
    range
        .and_then(|range| data.get(range))
        .expect("row or law index in range")
}

#[inline]
pub(crate) fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hadamard_ratio_separates_full_rank_from_dependent_rows() {
        assert!((hadamard_ratio(&[1.0, 0.0, 0.0, 2.0], 2, 2) - 1.0).abs() < 1e-15);
        assert!(hadamard_ratio(&[1.0, 1.0, 2.0, 2.0 + 1e-9], 2, 2) < 1e-15);
        assert_eq!(hadamard_ratio(&[1.0, 1.0, 0.0, 0.0], 2, 2), 0.0);
        let r = hadamard_ratio(&[1.0, 0.0, 1.0, 1.0], 2, 2);
        assert!((r - 0.5).abs() < 1e-15);
    }
}
