//! Branch points of the pseudo-arclength driver: the sign of the bordered Jacobian's
//! determinant along the branch, and the switch onto the branch that crosses it.
//!
//! With the tangent `t` oriented along the branch, `det [J, F_lambda; t^T W]` keeps its sign
//! through regular points and folds, and changes it at a simple branch point, where the
//! kernel of `[J, F_lambda]` is two-dimensional: `t` and the crossing branch's direction
//! `phi` (Allgower and Georg, chapter 8). Near the branch point the bordered matrix has a
//! small eigenvalue whose eigenvector is close to `phi`; inverse iteration finds it.

use super::bordered::Bordered;
use super::Arclength;
use crate::continuation::ContinuationProblem;
use crate::continuation::Point;
use crate::error::ContinuationError;
use crate::linalg::{DenseMatrix, Lu};
use crate::solve::{NonlinearSolver, Problem};

/// Inverse iterations for the crossing branch's direction: the bordered matrix's smallest
/// eigenvalue is much smaller than the others near a branch point, so a few suffice.
const INVERSE_ITERATIONS: usize = 8;

impl<P: ContinuationProblem, S: NonlinearSolver> Arclength<'_, P, S> {
    /// The dense bordered matrix `[J, F_lambda; s t^T W]` at `y` (`s > 0` the residual scale).
    fn bordered_matrix(&mut self, y: &[f64], tangent: &[f64]) -> DenseMatrix {
        let mut matrix = DenseMatrix::default();
        Bordered::new(
            &mut self.problem,
            (tangent, y),
            &self.metric,
            &mut self.border,
        )
        .jacobian(y, &mut matrix);
        matrix
    }

    /// The sign of `det [J, F_lambda; t^T W]` at `y`, where the option
    /// [`branch_points`](super::ArclengthOptions::branch_points) asks for it and the matrix is
    /// not exactly singular.
    pub(super) fn orientation_at(&mut self, y: &[f64], tangent: &[f64]) -> Option<f64> {
        if !self.options.branch_points {
            return None;
        }
        let matrix = self.bordered_matrix(y, tangent);
        Lu::factor(&matrix, 0.0)
            .ok()
            .map(|lu| lu.determinant_sign())
    }

    /// The unit direction (in the scaled norm) of the branch crossing at `y` with tangent
    /// `tangent`, `W`-orthogonal to it: inverse iteration on the bordered matrix.
    fn crossing_direction(&mut self, y: &[f64], tangent: &[f64]) -> Option<Vec<f64>> {
        let matrix = self.bordered_matrix(y, tangent);
        let lu = Lu::factor(&matrix, 0.0).ok()?;
        let metric = &self.metric;
        let orthogonal = |v: &mut Vec<f64>| {
            let along = metric.dot(tangent, v);
            v.iter_mut().zip(tangent).for_each(|(a, t)| *a -= along * t);
            let len = metric.norm(v);
            (len.is_finite() && len > 0.0).then(|| v.iter_mut().for_each(|a| *a /= len))
        };
        // A fixed start with a component along every unknown.
        let mut v: Vec<f64> = (0..y.len())
            .map(|i| 1.0 + 0.1 * ((7 * i) % 5) as f64)
            .collect();
        orthogonal(&mut v)?;
        for _ in 0..INVERSE_ITERATIONS {
            lu.solve_in_place(&mut v);
            orthogonal(&mut v)?;
        }
        Some(v)
    }

    /// Switches onto the branch that crosses the current one at the branch point reported on
    /// the last accepted point ([`Event::BranchPoint`](crate::continuation::Event::BranchPoint)),
    /// on the side `side` (`+1` or `-1`) of its direction.
    ///
    /// The branch point is estimated at the midpoint `y_b` of the last step; the crossing
    /// branch's direction `phi` is the bordered matrix's near-null vector there, made
    /// `W`-orthogonal to the tangent. The corrector solves `F = 0` on the hyperplane
    /// `<phi, y - y_p>_W = 0` through `y_p = y_b + side h phi`, with `h` the length of the
    /// last step: the old branch runs along the tangent, so the solution there is on the
    /// new one. The point becomes the current one, numbered as the next step, with the
    /// tangent oriented along `side phi` and the step size `h`; the acceptance test applies
    /// from the next step on, as after [`Arclength::restart_from`].
    ///
    /// # Errors
    /// [`ContinuationError::NoBranchPoint`] when the last accepted point reported none (or
    /// the branch was already switched there), [`ContinuationError::InvalidOption`] for a
    /// `side` other than `+-1`, [`ContinuationError::SingularTangent`] when no direction or
    /// tangent is found, and [`ContinuationError::BranchSwitch`] when the corrector fails.
    /// The driver is then unchanged, and the other side can still be tried.
    pub fn switch_branch(&mut self, side: f64) -> Result<Point, ContinuationError> {
        let n = self.problem.dimension();
        let Some(bracket) = self.bracket.clone() else {
            return Err(ContinuationError::NoBranchPoint {
                parameter: self.y[n],
            });
        };
        if !(side == 1.0 || side == -1.0) {
            return Err(ContinuationError::InvalidOption {
                what: "side (must be +1 or -1)",
                value: side,
            });
        }
        let base: Vec<f64> = (bracket.before.iter().zip(&bracket.after))
            .map(|(a, b)| 0.5 * (a + b))
            .collect();
        let step: Vec<f64> = (bracket.after.iter().zip(&bracket.before))
            .map(|(a, b)| a - b)
            .collect();
        let h = self
            .metric
            .norm(&step)
            .clamp(self.options.ds_min, self.options.ds_max);
        let singular = ContinuationError::SingularTangent { lambda: base[n] };
        let mut direction = self
            .crossing_direction(&base, &bracket.tangent)
            .ok_or(singular.clone())?;
        direction.iter_mut().for_each(|d| *d *= side);
        let (_, y, solved) = self.predict_and_correct(&base, &direction, h);
        let info = solved.map_err(|error| ContinuationError::BranchSwitch {
            parameter: base[n],
            error,
        })?;
        let tangent = self.tangent_at(&y, &direction).ok_or(singular)?;
        self.orientation = self.orientation_at(&y, &tangent);
        self.previous = None;
        self.y = y;
        self.tangent = tangent;
        self.active = self.active_set();
        self.bracket = None;
        self.accepted += 1;
        self.ds = h;
        self.start = None;
        self.finished = None;
        self.done = false;
        let mut point = self.point(self.accepted, &info, Vec::new());
        point.step_size = h;
        Ok(point)
    }
}
