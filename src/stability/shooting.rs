//! Correction of a state to a periodic orbit of the one-period map (shooting).

use super::coordinates::Coordinates;
use super::monodromy::{Monodromy, PeriodMap};
use crate::error::StabilityError;
use crate::solve::norm;
use crate::verify::State;
use faer::Mat;

/// Singular values of the correction's matrix below this fraction of the largest are not
/// inverted. Their directions are those `M - I` (nearly) annihilates besides the time shift:
/// the family direction, and waves that free flight carries back onto themselves over the
/// period (on a commensurate grid, every wave whose period divides it). Moving along them
/// does not reduce the defect; it changes the motion. Their singular values are the
/// differences' error, the marches' rounding over the step (`1e-14 / 1e-4 = 1e-10` of the
/// largest); a direction the map only weakly couples is real and must be inverted (the
/// free–free bar between walls stalls at a defect of `2.4e-6` with a cutoff of `1e-4`, and
/// converges with this one).
const SINGULAR_CUTOFF: f64 = 1e-7;

/// Singular values below this fraction of the largest are rounding: the directions `M - I`
/// annihilates exactly (the time shift, and the exact invariants of the coordinates).
const NUMERICAL_RANK: f64 = 1e-12;

/// A state corrected towards `P(X) = X`.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Corrected {
    /// The corrected coordinates.
    pub x: Vec<f64>,
    /// `|P(x) - x| / |x|` before the correction.
    pub initial_defect: f64,
    /// `|P(x) - x| / |x|` after.
    pub defect: f64,
    /// `(E(x) - E(x0)) / E(x0)`: how far the correction moved the energy.
    pub energy_change: f64,
    /// `|x - x0| / |x0|`: how far the correction moved the state.
    pub shift: f64,
    /// `max |u - u0| / max |u0|` over the nodes: how far it moved the displacement.
    pub displacement_shift: f64,
    /// Newton iterations taken.
    pub iterations: usize,
}

/// The minimum-norm solution of `a d = b` over the singular values of `a` above
/// [`SINGULAR_CUTOFF`] of the largest, with the decomposition kept: a chord corrector solves
/// many right-hand sides with one matrix.
#[derive(Debug, Clone)]
pub(crate) struct PseudoInverse {
    u: faer::Mat<f64>,
    v: faer::Mat<f64>,
    /// The singular values above rounding ([`NUMERICAL_RANK`]).
    s: Vec<f64>,
    /// The largest singular value.
    largest: f64,
}

impl Corrected {
    /// The state `x`, reached from `base` (of energy `base_energy`) in the `coordinates` of
    /// `template`'s grid, with how far that moved it and its defects before and after.
    pub(crate) fn measured(
        (coordinates, template): (&Coordinates, &State),
        (x, base, base_energy): (Vec<f64>, &[f64], f64),
        (initial_defect, defect, iterations): (f64, f64, usize),
    ) -> Result<Self, StabilityError> {
        let change: Vec<f64> = x.iter().zip(base).map(|(a, b)| a - b).collect();
        let reached = coordinates.energy(template, &x)?;
        Ok(Self {
            shift: norm(&change) / norm(base),
            displacement_shift: coordinates.displacement_distance(&x, base),
            energy_change: (reached - base_energy) / base_energy,
            x,
            initial_defect,
            defect,
            iterations,
        })
    }
}

impl PseudoInverse {
    /// The truncated pseudo-inverse of `a`.
    pub(crate) fn new(a: &Mat<f64>) -> Result<Self, StabilityError> {
        let svd = a.thin_svd().map_err(|_| StabilityError::NoSingularValues {
            dimension: a.nrows(),
        })?;
        let (u, s, v) = (svd.U(), svd.S(), svd.V());
        let largest = (0..s.dim()).map(|k| s[k]).fold(0.0, f64::max);
        let kept: Vec<usize> = (0..s.dim())
            .filter(|&k| s[k] > NUMERICAL_RANK * largest)
            .collect();
        Ok(Self {
            u: Mat::from_fn(a.nrows(), kept.len(), |i, k| u[(i, kept[k])]),
            v: Mat::from_fn(a.ncols(), kept.len(), |j, k| v[(j, kept[k])]),
            s: kept.iter().map(|&k| s[k]).collect(),
            largest,
        })
    }

    /// `u_k . b` for every kept singular value.
    fn coefficients(&self, b: &[f64]) -> Vec<f64> {
        (0..self.s.len())
            .map(|k| (0..self.u.nrows()).map(|i| self.u[(i, k)] * b[i]).sum())
            .collect()
    }

    /// `sum_k w_k v_k`.
    fn combine(&self, weights: &[f64]) -> Vec<f64> {
        let mut d = vec![0.0; self.v.nrows()];
        for (k, w) in weights.iter().enumerate() {
            for (j, dj) in d.iter_mut().enumerate() {
                *dj += w * self.v[(j, k)];
            }
        }
        d
    }

    /// The Levenberg–Marquardt step of `a d = b` within `radius`: the minimum-norm solution
    /// over every singular value where it is no longer than `radius`, otherwise
    /// `d(mu) = sum_k s_k (u_k . b) / (s_k^2 + mu^2) v_k` with `|d(mu)| = radius`. The
    /// damping `mu` shortens the step along the small singular values first: near a
    /// periodic orbit `M - I` has a continuum of them (the waves whose multipliers lie near
    /// 1), with no gap below which a direction could be called null, so a fixed cutoff
    /// either drops directions the correction needs or takes long steps along them.
    pub(crate) fn solve_within(&self, b: &[f64], radius: f64) -> Vec<f64> {
        let c = self.coefficients(b);
        let length = |mu: f64| -> f64 {
            self.s
                .iter()
                .zip(&c)
                .map(|(s, c)| (s * c / (s * s + mu * mu)).powi(2))
                .sum::<f64>()
                .sqrt()
        };
        let mu = if length(0.0) <= radius || !radius.is_finite() {
            0.0
        } else {
            // `|d(mu)|` falls from `|d(0)| > radius` to 0: bisect on a log scale between
            // rounding of the smallest kept value and far above the largest.
            let (mut low, mut high) = (NUMERICAL_RANK * self.largest, 1e8 * self.largest);
            for _ in 0..100 {
                let mid = (low * high).sqrt();
                if length(mid) > radius {
                    low = mid;
                } else {
                    high = mid;
                }
                if high <= low * (1.0 + 1e-6) {
                    break;
                }
            }
            high
        };
        let weights: Vec<f64> = self
            .s
            .iter()
            .zip(&c)
            .map(|(s, c)| s * c / (s * s + mu * mu))
            .collect();
        self.combine(&weights)
    }

    /// `M - I` of a monodromy, pseudo-inverted.
    pub(crate) fn of_monodromy(monodromy: &Monodromy) -> Result<Self, StabilityError> {
        let n = monodromy.nrows();
        let identity = |i: usize, j: usize| if i == j { 1.0 } else { 0.0 };
        Self::new(&Mat::<f64>::from_fn(n, n, |i, j| {
            monodromy[(i, j)] - identity(i, j)
        }))
    }

    /// `d` without its components along the right singular vectors of singular values at or
    /// below [`SINGULAR_CUTOFF`]: the directions `a` annihilates to rounding (the time shift,
    /// and the waves that return onto themselves over the period), along which nothing
    /// fixes a step.
    pub(crate) fn without_null_directions(&self, d: &[f64]) -> Vec<f64> {
        let weights: Vec<f64> = (0..self.s.len())
            .map(|k| match self.s[k] > SINGULAR_CUTOFF * self.largest {
                true => (0..self.v.nrows()).map(|j| self.v[(j, k)] * d[j]).sum(),
                false => 0.0,
            })
            .collect();
        self.combine(&weights)
    }

    /// The minimum-norm `d` of `a d = b` over the singular values above [`SINGULAR_CUTOFF`].
    pub(crate) fn solve(&self, b: &[f64]) -> Vec<f64> {
        let weights: Vec<f64> = self
            .s
            .iter()
            .zip(self.coefficients(b))
            .map(|(s, c)| {
                if *s > SINGULAR_CUTOFF * self.largest {
                    c / s
                } else {
                    0.0
                }
            })
            .collect();
        self.combine(&weights)
    }
}

/// `|P(x) - x|` and the residual `P(x) - x` itself.
pub(crate) fn residual(
    map: &PeriodMap,
    x: &[f64],
    out: &mut Vec<f64>,
) -> Result<f64, StabilityError> {
    map.apply(x, out)?;
    for (r, a) in out.iter_mut().zip(x) {
        *r -= a;
    }
    Ok(norm(out))
}

/// The step `x + a d` of the first `a` in `1, 1/2, 1/4, 1/8` whose relative defect
/// `|P - I| / |x|` is below `defect`, with that defect (its residual in `r`); `None` when
/// none is.
pub(crate) fn line_step(
    map: &PeriodMap,
    x: &[f64],
    d: &[f64],
    defect: f64,
    r: &mut Vec<f64>,
) -> Result<Option<(Vec<f64>, f64)>, StabilityError> {
    let mut a = 1.0;
    for _ in 0..4 {
        let trial: Vec<f64> = x.iter().zip(d).map(|(x, d)| x + a * d).collect();
        if trial.iter().all(|v| v.is_finite()) {
            let trial_defect = residual(map, &trial, r)? / norm(&trial);
            if trial_defect < defect {
                return Ok(Some((trial, trial_defect)));
            }
        }
        a *= 0.5;
    }
    Ok(None)
}

impl PeriodMap<'_> {
    /// Newton iterations `x <- x + a d`, `(M - I) d = x - P(x)`, with the monodromy `M` at
    /// the current state. `d` is the minimum-norm solution over the singular values above
    /// [`SINGULAR_CUTOFF`]: the correction moves the state as little as it can, and not
    /// along the directions `M - I` leaves (nearly) singular. The time shift is one of them
    /// (`M X' = X'`), so the step is orthogonal to it without a phase condition; a bordered
    /// phase row, tried, reached orbits of the right energy less often. The map is linear
    /// while the order of the contact events holds, so an iteration lands on the fixed point
    /// once the events are in the right order. The step `a` halves until the defect
    /// decreases (three times at most); the iterations stop below `tolerance`, after
    /// `max_iterations`, or when no step decreases the defect. Returns the best state with
    /// the monodromy there (`None` when no iteration moved it), and the monodromy at `base`.
    pub(crate) fn correct(
        &self,
        base: &[f64],
        relative_step: f64,
        max_iterations: usize,
        tolerance: f64,
    ) -> Result<(Corrected, Option<Monodromy>, Monodromy), StabilityError> {
        let x0_norm = norm(base);
        let energy = self.coordinates.energy(self.template, base)?;
        let mut r = Vec::new();
        let initial_defect = residual(self, base, &mut r)? / x0_norm;
        let mut best = Corrected {
            x: base.to_vec(),
            initial_defect,
            defect: initial_defect,
            energy_change: 0.0,
            shift: 0.0,
            displacement_shift: 0.0,
            iterations: 0,
        };
        let at_base = self.monodromy(base, relative_step)?;
        let mut latest: Option<Monodromy> = None;
        let mut trial_r = Vec::new();
        for iteration in 1..=max_iterations {
            if best.defect <= tolerance {
                break;
            }
            let monodromy = latest.as_ref().unwrap_or(&at_base);
            let rhs: Vec<f64> = r.iter().map(|v| -v).collect();
            let d = PseudoInverse::of_monodromy(monodromy)?.solve(&rhs);
            let Some((x, defect)) = line_step(self, &best.x, &d, best.defect, &mut trial_r)? else {
                break;
            };
            std::mem::swap(&mut r, &mut trial_r);
            latest = Some(self.monodromy(&x, relative_step)?);
            best = Corrected::measured(
                (self.coordinates, self.template),
                (x, base, energy),
                (initial_defect, defect, iteration),
            )?;
        }
        Ok((best, latest, at_base))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A rotated `diag(2, 1e-3, 1e-9)`: the step keeps its components along the first two
    /// right singular vectors, the small one at `1e-3` included, and loses the one below
    /// [`SINGULAR_CUTOFF`], kept by the decomposition but null to rounding.
    #[test]
    fn steps_lose_their_null_directions_only() {
        let (c, s) = (0.6f64, 0.8f64);
        // Columns of `v`: (c, s, 0), (-s, c, 0), (0, 0, 1); `a = diag(sigma) v^T`.
        let sigma = [2.0, 1e-3, 1e-9];
        let v = [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]];
        let a = Mat::<f64>::from_fn(3, 3, |i, j| sigma[i] * v[j][i]);
        let inverse = PseudoInverse::new(&a).unwrap();
        let d = [1.0, 2.0, 3.0];
        let kept = inverse.without_null_directions(&d);
        let expected = [1.0, 2.0, 0.0];
        for (k, e) in kept.iter().zip(expected) {
            assert!((k - e).abs() < 1e-12, "{kept:?}");
        }
    }

    /// `diag(1, 1e-3, 0)`: within a long radius the step is the minimum-norm solution over
    /// the two non-zero singular values; within a short one it has the radius' length, and
    /// the small singular value's component is cut more than the large one's.
    #[test]
    fn the_step_within_a_radius_damps_small_singular_values_first() {
        let a = Mat::<f64>::from_fn(3, 3, |i, j| match (i, j) {
            (0, 0) => 1.0,
            (1, 1) => 1e-3,
            _ => 0.0,
        });
        let inverse = PseudoInverse::new(&a).unwrap();
        let b = [1.0, 1e-3, 5.0];
        let full = inverse.solve_within(&b, 10.0);
        for (d, expected) in full.iter().zip([1.0, 1.0, 0.0]) {
            assert!((d - expected).abs() < 1e-12, "{full:?}");
        }
        let short = inverse.solve_within(&b, 0.5);
        assert!((norm(&short) - 0.5).abs() < 1e-5, "{short:?}");
        assert!(
            short[1].abs() < short[0].abs() && short[2] == 0.0,
            "{short:?}"
        );
        // Below the cutoff, the minimum-norm solve drops a singular value instead.
        let tiny = Mat::<f64>::from_fn(2, 2, |i, j| match (i, j) {
            (0, 0) => 1.0,
            (1, 1) => 1e-9,
            _ => 0.0,
        });
        let cut = PseudoInverse::new(&tiny).unwrap().solve(&[1.0, 1e-9]);
        assert!((cut[0] - 1.0).abs() < 1e-12 && cut[1] == 0.0, "{cut:?}");
    }
}
