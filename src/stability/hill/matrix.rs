//! The Hill matrix `H(lambda)` of a harmonic-balance point and its derivative in `lambda`
//! (the mathematics is in the [parent module](super)).

use crate::bc::{LinearRows, Observable};
use crate::error::{Error, StabilityError};
use crate::forced::rows::{Block, DampedRows};
use crate::forced::ForcedSystem;
use crate::fourier::{Basis, SineCosineBasis};
use crate::system::BarSystem;
use faer::{c64, Mat};

/// What `H(lambda)` needs of a point: the system, its laws' observables and the Gram
/// matrices of their generalised gradients at the point (which do not depend on `lambda`).
#[derive(Debug, Clone)]
pub(super) struct HillMatrix {
    system: BarSystem,
    observables: Vec<(Observable, Observable)>,
    /// `(G(w_gap), G(w_force))` of each law at the point.
    grams: Vec<(Vec<f64>, Vec<f64>)>,
    basis: SineCosineBasis,
    /// Unknowns per coefficient (`2 n_bars`).
    unknowns: usize,
    /// Linear rows per coefficient.
    linear_count: usize,
    omega: f64,
}

impl HillMatrix {
    /// The Hill matrix of the full-basis state `x` of `free` (at its frequency `omega`).
    ///
    /// # Errors
    /// [`StabilityError::HillUnsupported`] for a condition whose rows depend on the
    /// frequency (an end mass): the exponent would enter them too.
    pub(super) fn new(free: &ForcedSystem, x: &[f64], omega: f64) -> Result<Self, Error> {
        let system = free.system().clone();
        check_frequency_independent(&system, omega)?;
        let unknowns = system.unknowns_per_harmonic();
        Ok(Self {
            observables: free.observables().to_vec(),
            grams: free.law_gram_pairs(x),
            basis: free.basis().clone(),
            unknowns,
            linear_count: unknowns - system.contact_count(),
            omega,
            system,
        })
    }

    /// The share of `v`'s squared norm on the coefficients of harmonics above `3 m / 4`.
    pub(super) fn high_harmonic_share(&self, v: &faer::Col<c64>) -> f64 {
        let (u, m) = (self.unknowns, self.basis.harmonics());
        let (mut high, mut total) = (0.0, 0.0);
        for i in 0..self.basis.len() {
            let (n, _) = self.coefficient(i);
            let w: f64 = (0..u).map(|k| v[i * u + k].norm_sqr()).sum();
            total += w;
            if 4 * n > 3 * m {
                high += w;
            }
        }
        if total > 0.0 {
            high / total
        } else {
            0.0
        }
    }

    /// Rows (and columns) of `H`.
    pub(super) fn dimension(&self) -> usize {
        self.basis.len() * self.unknowns
    }

    /// `H(lambda)` and `dH/dlambda`.
    pub(super) fn at(&self, lambda: c64) -> (Mat<c64>, Mat<c64>) {
        let (len, rc, dim) = (self.basis.len(), self.linear_count, self.dimension());
        let mut out = (Mat::<c64>::zeros(dim, dim), Mat::<c64>::zeros(dim, dim));
        let rows: Vec<(DampedRows, DampedRows)> = (0..=self.basis.harmonics())
            .map(|n| (self.rows(n, lambda, 1.0), self.rows(n, lambda, -1.0)))
            .collect();
        for i in 0..len {
            let (n, partner) = self.coefficient(i);
            let (plus, minus) = &rows[n];
            for r in 0..rc {
                let pair = (&plus.linear, &minus.linear, r);
                self.add(&mut out, i * rc + r, (i, partner), pair, 1.0);
            }
        }
        let base = len * rc;
        for (l, (gram_gap, gram_force)) in self.grams.iter().enumerate() {
            for i in 0..len {
                let (n, partner) = self.coefficient(i);
                let (plus, minus) = &rows[n];
                for j in 0..len {
                    let target = base + l * len + j;
                    let (wg, wf) = (gram_gap[j * len + i], gram_force[j * len + i]);
                    if wg != 0.0 {
                        self.add(
                            &mut out,
                            target,
                            (i, partner),
                            (&plus.gap, &minus.gap, l),
                            wg,
                        );
                    }
                    if wf != 0.0 {
                        let pair = (&plus.force, &minus.force, l);
                        self.add(&mut out, target, (i, partner), pair, wf);
                    }
                }
            }
        }
        out
    }

    /// The rows of harmonic `n` for the exponent `lambda + sign i n Omega`: each bar at
    /// `kappa = -s^2 / c^2`, with `d kappa / d lambda = -2 s / c^2`.
    fn rows(&self, n: usize, lambda: c64, sign: f64) -> DampedRows {
        let s = lambda + c64::new(0.0, sign * n as f64 * self.omega);
        let kappas: Vec<(c64, c64)> = (self.system.bars().iter())
            .map(|bar| {
                let c2 = bar.wave_speed() * bar.wave_speed();
                (-s * s / c2, -2.0 * s / c2)
            })
            .collect();
        DampedRows::at_wavenumbers(&self.system, &self.observables, n, self.omega, &kappas)
    }

    /// The harmonic of coefficient `i` and its partner ([`SineCosineBasis::partner`]).
    fn coefficient(&self, i: usize) -> (usize, Option<(usize, f64)>) {
        (self.basis.harmonic(i), self.basis.partner(i))
    }

    /// Adds `scale` times row `r` of the pair of blocks `(plus, minus)` (the rows at the
    /// exponents `lambda +- i n Omega`), acting on coefficient `i` and its partner, to row
    /// `target` of `H` and `dH/dlambda`.
    fn add(
        &self,
        (h, dh): &mut (Mat<c64>, Mat<c64>),
        target: usize,
        (i, partner): (usize, Option<(usize, f64)>),
        (plus, minus, r): (&Block, &Block, usize),
        scale: f64,
    ) {
        let u = self.unknowns;
        let ((p, dp), (q, dq)) = (plus.row(r), minus.row(r));
        for k in 0..u {
            let (own, cross) = split(p[k], q[k]);
            let (d_own, d_cross) = split(dp[k], dq[k]);
            h[(target, i * u + k)] += own * scale;
            dh[(target, i * u + k)] += d_own * scale;
            if let Some((j, sigma)) = partner {
                h[(target, j * u + k)] += cross * (sigma * scale);
                dh[(target, j * u + k)] += d_cross * (sigma * scale);
            }
        }
    }
}

/// The coefficients `(P, E)` of a row pair `(a+, a-)`: `P = (a+ + a-) / 2` on the
/// coefficient itself and `E = -i (a+ - a-) / 2` on its partner.
fn split(plus: c64, minus: c64) -> (c64, c64) {
    let half = 0.5;
    ((plus + minus) * half, (plus - minus) * c64::new(0.0, -half))
}

/// Refuses conditions whose linear rows or observables depend on the frequency.
fn check_frequency_independent(system: &BarSystem, omega: f64) -> Result<(), StabilityError> {
    let stiffness = |e| system.stiffness_at(e);
    for condition in system.conditions() {
        let mut rows = LinearRows::new();
        condition.linear_rows(omega, &stiffness, &mut rows);
        let mut terms = (0..rows.len()).flat_map(|i| rows.row(i).iter());
        let law_terms = condition.unilateral().into_iter().flat_map(|law| {
            let (gap, force) = (law.gap(), law.force());
            gap.terms.into_iter().chain(force.terms)
        });
        let dependent = terms.any(|t| t.d_coefficient != 0.0)
            || law_terms.into_iter().any(|t| t.d_coefficient != 0.0);
        if dependent {
            return Err(StabilityError::HillUnsupported {
                condition: condition.name(),
            });
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::branches::to_full_basis;
    use crate::continuation::ContinuationProblem;
    use crate::fourier::frequency_of_period;
    use crate::linalg::DenseMatrix;
    use crate::reference::{clamped_bar_with_obstacle, ClampedFirstMode};
    use crate::solve::Problem;
    use crate::system::HarmonicBalanceSettings;

    /// The clamped bar's exact first mode at `T = 3.5` as a full-basis state of 12
    /// harmonics with a quarter-period shift (sines and cosines both non-zero), the free
    /// system at its frequency and the Hill matrix there.
    fn setup() -> (ForcedSystem, Vec<f64>, HillMatrix) {
        let m = 12;
        let system = clamped_bar_with_obstacle(1e-3).unwrap();
        let settings = HarmonicBalanceSettings {
            harmonics: m,
            ..HarmonicBalanceSettings::default()
        };
        let omega = frequency_of_period(3.5);
        let x = to_full_basis(&ClampedFirstMode::new(1e-3, 3.5).unknowns(m), m).unwrap();
        let x = crate::branches::shift_origin(&x, m, 0.37).unwrap();
        let mut free = ForcedSystem::free(&system, settings).unwrap();
        free.set_parameter(omega);
        let matrix = HillMatrix::new(&free, &x, omega).unwrap();
        (free, x, matrix)
    }

    /// At `lambda = 0` the Hill matrix is the real Jacobian of the harmonic-balance system.
    #[test]
    fn at_zero_it_is_the_jacobian() {
        let (mut free, x, matrix) = setup();
        let n = free.dimension();
        let mut jac = DenseMatrix::zeros(n, n);
        free.jacobian(&x, &mut jac);
        let (h, _) = matrix.at(c64::new(0.0, 0.0));
        let scale = (0..n)
            .flat_map(|i| (0..n).map(move |j| (i, j)))
            .fold(0.0f64, |a, (i, j)| a.max(jac[(i, j)].abs()));
        for i in 0..n {
            for j in 0..n {
                let d = (h[(i, j)] - c64::new(jac[(i, j)], 0.0)).norm();
                assert!(
                    d <= 1e-12 * scale,
                    "({i}, {j}): {} vs {}",
                    h[(i, j)],
                    jac[(i, j)]
                );
            }
        }
    }

    /// `dH/dlambda` agrees with central differences at a complex exponent.
    #[test]
    fn derivative_matches_differences() {
        let (_, _, matrix) = setup();
        for lambda in [
            c64::new(0.03, 0.41),
            c64::new(-0.2, -0.9),
            c64::new(1e-3, 0.0),
        ] {
            let (_, dh) = matrix.at(lambda);
            let step = 1e-6;
            for direction in [c64::new(1.0, 0.0), c64::new(0.0, 1.0)] {
                let (hp, _) = matrix.at(lambda + direction * step);
                let (hm, _) = matrix.at(lambda - direction * step);
                let n = dh.nrows();
                let mut worst = 0.0f64;
                let mut scale = 0.0f64;
                for i in 0..n {
                    for j in 0..n {
                        let fd = (hp[(i, j)] - hm[(i, j)]) / (direction * (2.0 * step));
                        worst = worst.max((fd - dh[(i, j)]).norm());
                        scale = scale.max(dh[(i, j)].norm());
                    }
                }
                assert!(worst <= 1e-6 * scale, "lambda {lambda}: {worst} of {scale}");
            }
        }
    }
}
