//! Harmonic selection: the harmonic-balance equations without the harmonics that sit on a
//! linear resonance ([`HarmonicBalanceSettings::resonance_band`](super::HarmonicBalanceSettings::resonance_band)).
//!
//! # Why
//! The truncated complementarity law is satisfied only in a weighted sense: the residual it
//! leaves in each harmonic is of the order of `R^(m) = O(1/m)` (the paper's eq. (32) and
//! Fig. 5). Harmonic `n` of a bar answers a forcing of its frequency `n Omega` through its
//! dynamic stiffness, which vanishes at every natural frequency `omega_k` of the open or the
//! closed contact: the answer is amplified by about `1 / |1 - n Omega / omega_k|`. Where that
//! amplification reaches `m / c`, the truncation error it amplifies is of order one, and the
//! truncated equations have solutions (internal resonances of the truncation) that are not
//! near the motions of the bars. The exact families carry every harmonic with an amplitude
//! that decays like `1/n^2`, so leaving out a few harmonics costs little, while keeping them
//! costs the branch.
//!
//! Leaving a harmonic out costs its genuine content, of relative amplitude about `1/n^2`,
//! while what it removes is an error of the truncation's order `1/m`: the trade pays only for
//! `n^2 >= m`. Below that, a harmonic is part of the motion the truncation resolves (harmonic
//! 4 holds about 5 % of the clamped bar's energy), and dropping it moves the whole point: on
//! the clamped bar, every harmonic `4 j` meets a natural frequency at once near `T = 3.2`, and
//! holding them at zero put seven grid points 20 to 23 % below the exact family at `m = 20`.
//!
//! # What
//! At the fundamental frequency `Omega`, harmonic `n >= 2` with `n^2 >= m` is *dropped* when
//! `|n Omega / omega_k - 1| < c / m` for a natural frequency `omega_k > 0` of the system with
//! every contact open or every contact closed ([`ContactState`]). A dropped
//! harmonic's unknowns are held at zero: its equations (linear rows and law projections) are
//! replaced by the rows `x_i = 0`, and the other equations see it as zero. The constant and
//! the fundamental are never dropped. The set changes with `Omega`; the problem keeps its
//! dimension, so continuation drivers follow it unchanged. While a harmonic is dropped, the
//! condensed Newton step (`step.rs`) leaves its null directions out of the reduced matrix and
//! sets its unknowns from its own rows; the staircase step of chains, which solves every
//! harmonic's equations, gives way to it.

use super::discretization::Discretization;
use crate::error::SettingsError;
use crate::fourier::Basis;
use crate::linalg::DenseMatrix;
use crate::system::linear::natural_frequencies_covering;
use crate::system::linear::ContactState;
use crate::system::linear::Resolution;
use crate::system::BarSystem;

/// The layout of a harmonic-balance problem that a selection edits: unknowns per
/// coefficient, linear rows per coefficient, basis coefficients and laws (the equations are
/// every coefficient's linear rows, then each law's projections).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Shape {
    pub(crate) per: usize,
    pub(crate) linear: usize,
    pub(crate) len: usize,
    pub(crate) laws: usize,
}

impl Shape {
    fn dimension(self) -> usize {
        self.len * self.per
    }
}

impl<B: Basis> From<&Discretization<B>> for Shape {
    fn from(d: &Discretization<B>) -> Self {
        Self {
            per: d.unknowns,
            linear: d.linear_count,
            len: d.basis().len(),
            laws: d.laws,
        }
    }
}

/// The selection state of a problem: the band, the natural frequencies it is measured from,
/// and the coefficients dropped at the current frequency.
#[derive(Debug, Clone)]
pub(crate) struct Selection {
    /// The width `c` of the relative band `c / m`.
    pub(crate) width: f64,
    /// Open- and closed-contact natural frequencies up to `covered`, ascending.
    natural: Vec<f64>,
    covered: f64,
    /// Basis coefficients dropped at the current frequency, ascending.
    dropped: Vec<usize>,
    /// Scratch for `x` with the dropped unknowns zeroed.
    masked: Vec<f64>,
    /// Whether harmonics with `n^2 < m` may be dropped ([`Selection::dropping_low_harmonics`]).
    low_harmonics: bool,
}

/// Whether harmonic `n` of a basis of `m` harmonics may be dropped: never the constant or
/// the fundamental, and, unless `low` says otherwise, only where its genuine content
/// (`~ 1/n^2`) is below the truncation's error (`~ 1/m`), `n^2 >= m` (module docs).
fn droppable(n: usize, m: usize, low: bool) -> bool {
    n >= 2 && (low || n.saturating_mul(n) >= m)
}

impl Selection {
    /// The selection of band `width / m` for `m` harmonics (`None` for a zero width: no
    /// selection).
    ///
    /// # Errors
    /// [`SettingsError::OutOfRange`] for a width that is not finite, negative or above `m`.
    pub(crate) fn for_band(width: f64, m: usize) -> Result<Option<Self>, SettingsError> {
        if !(width.is_finite() && (0.0..=m as f64).contains(&width)) {
            return Err(SettingsError::OutOfRange {
                what: "resonance band",
                value: width,
                min: 0.0,
                max: m as f64,
            });
        }
        Ok(Self::new(width))
    }

    /// The selection of band `width / m` (`None` for a zero width: no selection).
    fn new(width: f64) -> Option<Self> {
        (width > 0.0).then(|| Self {
            width,
            natural: Vec::new(),
            covered: 0.0,
            dropped: Vec::new(),
            masked: Vec::new(),
            low_harmonics: false,
        })
    }

    /// The same selection, which may also drop the harmonics `2 <= n < sqrt(m)`: for a
    /// forced response, whose motion near the linear resonance it sweeps through is the
    /// forcing's harmonic 1 with little else. There every harmonic of a bar whose natural
    /// frequencies are multiples of the first meets one at once, and the sweep up the
    /// resonance passes only with them held (`tests/forced.rs`, the peak on the backbone).
    pub(crate) fn dropping_low_harmonics(mut self) -> Self {
        self.low_harmonics = true;
        self
    }

    /// Whether a harmonic is dropped at the current frequency.
    pub(crate) fn active(&self) -> bool {
        !self.dropped.is_empty()
    }

    /// The basis coefficients dropped at the current frequency, ascending.
    pub(crate) fn dropped(&self) -> &[usize] {
        &self.dropped
    }

    /// Drops the coefficients `dropped` (ascending, from [`Selection::dropped`]) until the
    /// next [`Selection::select`].
    pub(crate) fn set_dropped(&mut self, dropped: Vec<usize>) {
        self.dropped = dropped;
    }

    /// The harmonics dropped at the current frequency, ascending, each once (a full basis
    /// drops a harmonic's cosine and sine together).
    pub(crate) fn dropped_harmonics<B: Basis>(&self, basis: &B) -> Vec<usize> {
        let mut harmonics: Vec<usize> = self.dropped.iter().map(|&i| basis.harmonic(i)).collect();
        harmonics.sort_unstable();
        harmonics.dedup();
        harmonics
    }

    /// Recomputes the dropped coefficients at `omega`, extending the natural frequencies when
    /// `omega` needs higher ones.
    pub(crate) fn select<B: Basis>(&mut self, (system, basis): (&BarSystem, &B), omega: f64) {
        self.dropped = self.dropped_at((system, basis), omega);
    }

    /// The coefficients the selection drops at `omega` (the current ones are left as they
    /// are), extending the natural frequencies when `omega` needs higher ones.
    pub(crate) fn dropped_at<B: Basis>(
        &mut self,
        (system, basis): (&BarSystem, &B),
        omega: f64,
    ) -> Vec<usize> {
        if !(omega.is_finite() && omega > 0.0) {
            return Vec::new();
        }
        let band = self.width / basis.harmonics().max(1) as f64;
        let needed = (basis.harmonics() as f64 + 1.0) * omega * (1.0 + band);
        if needed > self.covered {
            let bound = 2.0 * needed;
            let mut natural = Vec::new();
            // A scan of the system up to a higher bound, run for another problem on it,
            // serves as well: the selection reads only frequencies below `needed`.
            let mut covered = f64::INFINITY;
            for state in [ContactState::Open, ContactState::Closed] {
                // A scan that cannot run leaves this state out: fewer harmonics dropped.
                match natural_frequencies_covering(system, state, bound, Resolution::FULL) {
                    Ok((reach, values)) => {
                        natural.extend(values.into_iter().filter(|w| *w > 0.0));
                        covered = covered.min(reach);
                    }
                    Err(_) => covered = covered.min(bound),
                }
            }
            natural.sort_by(f64::total_cmp);
            self.natural = natural;
            self.covered = covered;
        }
        let natural = &self.natural;
        (0..basis.len())
            .filter(|&i| {
                let n = basis.harmonic(i);
                droppable(n, basis.harmonics(), self.low_harmonics)
                    && natural
                        .iter()
                        .any(|w| (n as f64 * omega / w - 1.0).abs() < band)
            })
            .collect()
    }

    /// `x` with the dropped unknowns set to zero (the scratch is handed out; give it back with
    /// [`Selection::restore`]).
    pub(crate) fn mask(&mut self, shape: Shape, x: &[f64]) -> Vec<f64> {
        let mut masked = std::mem::take(&mut self.masked);
        masked.clear();
        masked.extend_from_slice(x);
        let per = shape.per;
        for &i in &self.dropped {
            masked[i * per..(i + 1) * per].fill(0.0);
        }
        masked
    }

    /// Takes back the scratch of [`Selection::mask`].
    pub(crate) fn restore(&mut self, masked: Vec<f64>) {
        self.masked = masked;
    }

    /// The pairs (equation row, unknown) of coefficient `i`: its linear rows, then its
    /// projection of each law, in the order of the problem's residual.
    fn rows(shape: Shape, i: usize) -> impl Iterator<Item = (usize, usize)> {
        let Shape {
            per,
            linear,
            len,
            laws,
        } = shape;
        let base = len * linear;
        (0..linear)
            .map(move |r| (i * linear + r, i * per + r))
            .chain((0..laws).map(move |l| (base + l * len + i, i * per + linear + l)))
    }

    /// Replaces the equations of the dropped coefficients by `x_i = 0` in the residual `f`.
    pub(crate) fn residual(&self, shape: Shape, x: &[f64], f: &mut [f64]) {
        for &i in &self.dropped {
            for (r, u) in Self::rows(shape, i) {
                f[r] = x[u];
            }
        }
    }

    /// The Jacobian of [`Selection::residual`] from the full one at the masked point: the
    /// dropped unknowns' columns are zero, their equations' rows those of the identity.
    pub(crate) fn jacobian(&self, shape: Shape, jac: &mut DenseMatrix) {
        let n = shape.dimension();
        let per = shape.per;
        for &i in &self.dropped {
            for c in i * per..(i + 1) * per {
                for r in 0..n {
                    jac[(r, c)] = 0.0;
                }
            }
            for (r, u) in Self::rows(shape, i) {
                for c in 0..n {
                    jac[(r, c)] = 0.0;
                }
                jac[(r, u)] = 1.0;
            }
        }
    }

    /// Zeroes the frequency derivative of the dropped coefficients' equations (`x_i = 0` does
    /// not depend on `Omega`).
    pub(crate) fn parameter_derivative(&self, shape: Shape, df: &mut [f64]) {
        for &i in &self.dropped {
            for (r, _) in Self::rows(shape, i) {
                df[r] = 0.0;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::continuation::ContinuationProblem;
    use crate::linalg::{DenseMatrix, Lu};
    use crate::reference::{clamped_bar_with_obstacle, ClampedFirstMode};
    use crate::solve::{
        residual_scale, NonlinearSolver, Problem, Solver, Structured, PIVOT_TOLERANCE,
    };
    use crate::system::{HarmonicBalanceSettings, NonsmoothSystem};
    use std::f64::consts::PI;

    fn problem(m: usize, width: f64, period: f64) -> NonsmoothSystem {
        let settings = HarmonicBalanceSettings {
            harmonics: m,
            resonance_band: width,
            ..HarmonicBalanceSettings::default()
        };
        let mut p =
            NonsmoothSystem::new(&clamped_bar_with_obstacle(1e-3).unwrap(), settings).unwrap();
        p.set_parameter(2.0 * PI / period);
        p
    }

    #[test]
    fn a_zero_band_keeps_the_full_problem() {
        let (mut full, mut none) = (problem(10, 0.0, 3.5), problem(10, 0.0, 3.5));
        none.set_resonance_band(0.0).unwrap();
        assert!(none.dropped_harmonics().is_empty());
        assert_eq!(none.resonance_band(), 0.0);
        let x = ClampedFirstMode::new(1e-3, 3.5).unknowns(10);
        let (mut a, mut b) = (vec![0.0; x.len()], vec![0.0; x.len()]);
        full.residual(&x, &mut a);
        none.residual(&x, &mut b);
        assert_eq!(a, b);
    }

    #[test]
    fn dropped_harmonics_sit_on_resonances_and_solve_to_zero() {
        let m = 20;
        // T = 3.5: 7 Omega = 4 pi, a natural frequency of the closed contact.
        let mut p = problem(m, 0.5, 3.5);
        let omega = p.parameter();
        let band = 0.5 / m as f64;
        let dropped = p.dropped_harmonics();
        assert!(dropped.contains(&7), "{dropped:?}");
        for &n in &dropped {
            // Clamped–free (open) and clamped–clamped (closed) frequencies of the unit bar.
            let near = (1..200).any(|k| {
                let (open, closed) = ((2 * k - 1) as f64 * PI / 2.0, k as f64 * PI);
                [open, closed]
                    .iter()
                    .any(|w| (n as f64 * omega / w - 1.0).abs() < band)
            });
            assert!(near && n >= 2, "harmonic {n} dropped away from a resonance");
        }
        let mut x = ClampedFirstMode::new(1e-3, 3.5).unknowns(m);
        Solver::default().solve(&mut p, &mut x).unwrap();
        let per = p.dimension() / (m + 1);
        for &n in &dropped {
            assert!(x[n * per..(n + 1) * per].iter().all(|v| *v == 0.0));
        }
        // Tolerances stay relative to the largest gap.
        let mut full = problem(m, 0.0, 3.5);
        assert_eq!(residual_scale(&mut p), residual_scale(&mut full));
    }

    #[test]
    fn the_jacobian_and_the_frequency_derivative_match_finite_differences() {
        let t = 3.5;
        let mut p = problem(8, 0.5, t);
        assert!(!p.dropped_harmonics().is_empty());
        // Away from the law's kinks: a motion scaled into the open contact.
        let x: Vec<f64> = (ClampedFirstMode::new(1e-3, t).unknowns(8).iter())
            .map(|v| 0.3 * v)
            .collect();
        let n = p.dimension();
        let mut jac = DenseMatrix::zeros(n, n);
        p.jacobian(&x, &mut jac);
        let (mut f0, mut f1) = (vec![0.0; n], vec![0.0; n]);
        p.residual(&x, &mut f0);
        let h = 1e-9;
        for c in 0..n {
            let mut y = x.clone();
            y[c] += h;
            p.residual(&y, &mut f1);
            for r in 0..n {
                let fd = (f1[r] - f0[r]) / h;
                assert!(
                    (fd - jac[(r, c)]).abs() < 1e-4 * (1.0 + fd.abs()),
                    "({r}, {c})"
                );
            }
        }
        let mut df = vec![0.0; n];
        p.parameter_derivative(&x, &mut df);
        let omega = p.parameter();
        let dw = 1e-7 * omega;
        let dropped = p.dropped_harmonics();
        p.set_parameter(omega + dw);
        assert_eq!(p.dropped_harmonics(), dropped);
        p.residual(&x, &mut f1);
        for r in 0..n {
            let fd = (f1[r] - f0[r]) / dw;
            assert!((fd - df[r]).abs() < 1e-4 * (1.0 + fd.abs()), "row {r}");
        }
    }

    /// The condensed step with harmonics dropped solves the masked Jacobian's system: two
    /// right-hand sides (the residual and a fixed pattern) against a dense LU, at a point in
    /// contact (the exact motion) and at one in the open contact, on the clamped bar and on
    /// two bars in contact.
    #[test]
    fn the_condensed_step_solves_the_selected_equations() {
        let bars = [
            clamped_bar_with_obstacle(1e-3).unwrap(),
            crate::reference::contact_chain(2, 1e-3, 0.5).unwrap(),
        ];
        for (b, system) in bars.iter().enumerate() {
            for scale in [1.0, 0.3] {
                let settings = HarmonicBalanceSettings {
                    harmonics: 12,
                    resonance_band: 0.5,
                    ..HarmonicBalanceSettings::default()
                };
                let mut p = NonsmoothSystem::new(system, settings).unwrap();
                p.set_parameter(2.0 * PI / 3.5);
                assert!(!p.dropped_harmonics().is_empty());
                let n = p.dimension();
                let x: Vec<f64> = if b == 0 {
                    ClampedFirstMode::new(1e-3, 3.5).unknowns(12)
                } else {
                    (0..n)
                        .map(|k| 1e-4 * (((k * 7) % 5) as f64 - 2.0))
                        .collect()
                };
                let x: Vec<f64> = x.iter().map(|v| scale * v).collect();
                let mut rhs = vec![0.0; 2 * n];
                p.residual(&x, &mut rhs[..n]);
                for (k, v) in rhs[n..].iter_mut().enumerate() {
                    *v = ((k * 37) % 11) as f64 - 5.0;
                }
                let mut dense = rhs.clone();
                let mut jac = DenseMatrix::zeros(n, n);
                p.jacobian(&x, &mut jac);
                let lu = Lu::factor(&jac, PIVOT_TOLERANCE).unwrap();
                dense.chunks_exact_mut(n).for_each(|c| lu.solve_in_place(c));
                let solved = Structured::solve_jacobian(&mut p, &x, &mut rhs, 2);
                assert!(matches!(solved, Some(Ok(()))), "system {b}: {solved:?}");
                for (a, d) in rhs.chunks_exact(n).zip(dense.chunks_exact(n)) {
                    let size = d.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
                    let error = (a.iter().zip(d)).fold(0.0_f64, |m, (u, v)| m.max((u - v).abs()));
                    assert!(
                        error <= 1e-9 * size,
                        "system {b}, scale {scale}: {error:e} of {size:e}"
                    );
                }
            }
        }
    }

    #[test]
    fn bad_bands_are_typed_errors() {
        let mut p = problem(20, 0.0, 3.5);
        for width in [f64::NAN, f64::INFINITY, -0.1, 21.0] {
            assert!(p.set_resonance_band(width).is_err(), "{width}");
        }
        let settings = HarmonicBalanceSettings {
            resonance_band: -1.0,
            ..HarmonicBalanceSettings::default()
        };
        let system = clamped_bar_with_obstacle(1e-3).unwrap();
        assert!(NonsmoothSystem::new(&system, settings).is_err());
    }
}
