//! Per-harmonic rows of a damped system: the condition rows and law observables of
//! [`crate::system::HarmonicRows`], with the bars' damped (complex) Helmholtz maps.
//!
//! A complex row `a` acting on the complex amplitude `Z = X_c - i X_s` of one harmonic
//! (`X_c`, `X_s` the unknowns of its cosine and its sine) gives two real rows:
//! `Re(a Z) = a_r X_c + a_i X_s` (the cosine's) and `-Im(a Z) = a_r X_s - a_i X_c` (the
//! sine's), since `Re(Z e^{i n theta}) = X_c cos(n theta) + X_s sin(n theta)`. Both are
//! `a_r x_self + sigma a_i x_partner` with `sigma = +1` for a cosine and `-1` for a sine:
//! [`real_form`].

use crate::bar::EndRef;
use crate::bc::{LinearRows, Observable, Term};
use crate::bem::end_indices;
use crate::forced::waves::{squared_wavenumber, DampedMap};
use crate::system::rows::quantity_weights;
use crate::system::BarSystem;
use num_complex::Complex64;

/// Dense complex rows over the `2 n_bars` Helmholtz unknowns of one harmonic, with their
/// derivatives in a parameter: the fundamental frequency `Omega` for a forced system, the
/// Floquet exponent for a Hill matrix.
#[derive(Debug, Clone, Default)]
pub(crate) struct Block {
    width: usize,
    values: Vec<Complex64>,
    d_omega: Vec<Complex64>,
}

impl Block {
    fn zeros(rows: usize, width: usize) -> Self {
        let zero = Complex64::new(0.0, 0.0);
        Self {
            width,
            values: vec![zero; rows * width],
            d_omega: vec![zero; rows * width],
        }
    }

    /// Row `r`: its values and their derivative.
    pub(crate) fn row(&self, r: usize) -> (&[Complex64], &[Complex64]) {
        let range = r * self.width..(r + 1) * self.width;
        (&self.values[range.clone()], &self.d_omega[range])
    }
}

/// The rows of harmonic `n` of a damped system at one fundamental frequency.
#[derive(Debug, Clone, Default)]
pub(crate) struct DampedRows {
    pub(crate) linear: Block,
    pub(crate) gap: Block,
    pub(crate) force: Block,
}

/// Adds `term` (at harmonic `n`) to the complex row `row`, and its derivative to `d_row`
/// (through each bar's `d kappa` in `maps`, and through the term's coefficient as a
/// function of `n Omega`).
fn add_term(
    term: &Term,
    n: usize,
    maps: &[(DampedMap, Complex64)],
    stiffness: f64,
    row: &mut [Complex64],
    d_row: &mut [Complex64],
) {
    let b = term.end.bar.index();
    let (wu, wp) = quantity_weights(term.quantity, term.end.end, stiffness);
    let (iu, ip) = end_indices(term.end.end);
    let (map, d_kappa) = &maps[b];
    for j in 0..2 {
        let value = map.rows[iu][j] * wu + map.rows[ip][j] * wp;
        let d_value = (map.d_kappa[iu][j] * wu + map.d_kappa[ip][j] * wp) * d_kappa;
        row[2 * b + j] += value * term.coefficient;
        // The coefficient depends on the harmonic's frequency n Omega.
        d_row[2 * b + j] += value * (n as f64 * term.d_coefficient) + d_value * term.coefficient;
    }
}

/// A block of `terms_of`'s rows at harmonic `n`.
fn block<'t>(
    terms_of: impl ExactSizeIterator<Item = &'t [Term]>,
    n: usize,
    maps: &[(DampedMap, Complex64)],
    system: &BarSystem,
) -> Block {
    let width = system.unknowns_per_harmonic();
    let mut out = Block::zeros(terms_of.len(), width);
    for (r, terms) in terms_of.enumerate() {
        let range = r * width..(r + 1) * width;
        for t in terms {
            add_term(
                t,
                n,
                maps,
                system.stiffness_at(t.end),
                &mut out.values[range.clone()],
                &mut out.d_omega[range.clone()],
            );
        }
    }
    out
}

impl DampedRows {
    /// The rows of harmonic `n` of `system` at fundamental frequency `omega`, with damping
    /// `damping[b]` in bar `b`; `laws` are the observables `(gap, force)` of its laws.
    pub(crate) fn new(
        system: &BarSystem,
        laws: &[(Observable, Observable)],
        n: usize,
        omega: f64,
        damping: &[f64],
    ) -> Self {
        let kappas: Vec<_> = (system.bars().iter().zip(damping))
            .map(|(bar, &eta)| squared_wavenumber(bar, n, omega, eta))
            .collect();
        Self::at_wavenumbers(system, laws, n, omega, &kappas)
    }

    /// The rows of harmonic `n` of `system` (its conditions at fundamental frequency
    /// `omega`) with bar `b` at the squared wave number `kappas[b].0`, whose derivative in
    /// the rows' parameter is `kappas[b].1`.
    pub(crate) fn at_wavenumbers(
        system: &BarSystem,
        laws: &[(Observable, Observable)],
        n: usize,
        omega: f64,
        kappas: &[(Complex64, Complex64)],
    ) -> Self {
        let maps: Vec<(DampedMap, Complex64)> = (system.bars().iter().zip(kappas))
            .map(|(bar, &(kappa, d_kappa))| (DampedMap::new(bar.length(), kappa), d_kappa))
            .collect();
        let stiffness = |e: EndRef| system.stiffness_at(e);
        let mut rows = LinearRows::new();
        for condition in system.conditions() {
            condition.linear_rows(n as f64 * omega, &stiffness, &mut rows);
        }
        Self {
            linear: block((0..rows.len()).map(|i| rows.row(i)), n, &maps, system),
            gap: block(
                laws.iter().map(|(g, _)| g.terms.as_slice()),
                n,
                &maps,
                system,
            ),
            force: block(
                laws.iter().map(|(_, f)| f.terms.as_slice()),
                n,
                &maps,
                system,
            ),
        }
    }
}

/// `a_r . x_self + sigma a_i . x_partner` (module docs); `x_partner` is `None` for the
/// constant, whose rows are real.
pub(super) fn real_form(row: &[Complex64], x_self: &[f64], partner: Option<(&[f64], f64)>) -> f64 {
    let own: f64 = row.iter().zip(x_self).map(|(a, x)| a.re * x).sum();
    match partner {
        Some((x, sigma)) => own + sigma * row.iter().zip(x).map(|(a, x)| a.im * x).sum::<f64>(),
        None => own,
    }
}
