//! Correction of a state to a periodic orbit of the one-period map (shooting).

use super::monodromy::{Monodromy, PeriodMap};
use crate::error::StabilityError;
use crate::solve::norm;
use faer::linalg::solvers::SolveLstsq;
use faer::Mat;

/// A state corrected towards `P(X) = X`.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Corrected {
    /// The corrected coordinates.
    pub x: Vec<f64>,
    /// `|P(x) - x| / |x|` before the correction.
    pub initial_defect: f64,
    /// `|P(x) - x| / |x|` after.
    pub defect: f64,
    /// `|x - x0| / |x0|`: how far the correction moved the state.
    pub shift: f64,
    /// `max |u - u0| / max |u0|` over the nodes: how far it moved the displacement.
    pub displacement_shift: f64,
    /// Chord iterations taken.
    pub iterations: usize,
}

/// `|P(x) - x|` and the residual `P(x) - x` itself.
fn residual(map: &PeriodMap, x: &[f64], out: &mut Vec<f64>) -> Result<f64, StabilityError> {
    map.apply(x, out)?;
    for (r, a) in out.iter_mut().zip(x) {
        *r -= a;
    }
    Ok(norm(out))
}

impl PeriodMap<'_> {
    /// Newton iterations `x <- x + a d`, `[M - I; w^T] d = [x - P(x); 0]` in the
    /// least-squares sense, with the monodromy `M` at the current state and `w` the direction
    /// of the motion (`X(dt) - X(0)`, which removes the time shift, the kernel of `M - I`).
    /// The map is linear while the order of the contact events holds, so an iteration lands
    /// on the fixed point once the events are in the right order. The step `a` halves until
    /// the defect decreases (three times at most); the iterations stop below `tolerance`,
    /// after `max_iterations`, or when no step decreases the defect. Returns the best state
    /// with the monodromy there (`None` when no iteration moved it), and the monodromy at
    /// `base`.
    pub(crate) fn correct(
        &self,
        base: &[f64],
        relative_step: f64,
        dt: f64,
        max_iterations: usize,
        tolerance: f64,
    ) -> Result<(Corrected, Option<Monodromy>, Monodromy), StabilityError> {
        let x0_norm = norm(base);
        let mut r = Vec::new();
        let initial_defect = residual(self, base, &mut r)? / x0_norm;
        let mut best = Corrected {
            x: base.to_vec(),
            initial_defect,
            defect: initial_defect,
            shift: 0.0,
            displacement_shift: 0.0,
            iterations: 0,
        };
        let at_base = self.monodromy(base, relative_step)?;
        let mut latest: Option<Monodromy> = None;
        let mut trial_r = Vec::new();
        let mut direction = Vec::new();
        for iteration in 1..=max_iterations {
            if best.defect <= tolerance {
                break;
            }
            let x = &best.x;
            let monodromy = latest.as_ref().unwrap_or(&at_base);
            let n = monodromy.nrows();
            self.flow(x, dt, &mut direction)?;
            let bordered = Mat::<f64>::from_fn(n + 1, n, |i, j| {
                if i < n {
                    monodromy[(i, j)] - if i == j { 1.0 } else { 0.0 }
                } else {
                    direction[j] - x[j]
                }
            });
            let rhs = Mat::<f64>::from_fn(n + 1, 1, |i, _| if i < n { -r[i] } else { 0.0 });
            let d = bordered.qr().solve_lstsq(&rhs);
            let mut accepted = None;
            let mut a = 1.0;
            for _ in 0..4 {
                let trial: Vec<f64> = (0..n).map(|i| x[i] + a * d[(i, 0)]).collect();
                if trial.iter().all(|v| v.is_finite()) {
                    let defect = residual(self, &trial, &mut trial_r)? / norm(&trial);
                    if defect < best.defect {
                        accepted = Some((trial, defect));
                        break;
                    }
                }
                a *= 0.5;
            }
            let Some((x, defect)) = accepted else {
                break;
            };
            std::mem::swap(&mut r, &mut trial_r);
            let change: Vec<f64> = x.iter().zip(base).map(|(a, b)| a - b).collect();
            latest = Some(self.monodromy(&x, relative_step)?);
            best = Corrected {
                shift: norm(&change) / x0_norm,
                displacement_shift: self.coordinates.displacement_distance(&x, base),
                x,
                initial_defect,
                defect,
                iterations: iteration,
            };
        }
        Ok((best, latest, at_base))
    }
}
