//! Continuing a branch after the problem's equations changed under it (a harmonic selection
//! that moved between two points): the point is corrected at its parameter, where the
//! equations changed, and its tangent keeps the direction of travel, which a restart along a
//! fixed direction in the parameter ([`Arclength::restart_from`]) loses past a fold.

use super::{augmented, Arclength, ContinuationError, ContinuationProblem, Event, Point};
use crate::solve::NonlinearSolver;
use crate::solve::SolveInfo;

impl<P: ContinuationProblem, S: NonlinearSolver> Arclength<'_, P, S> {
    /// Continues the branch from `x` at `lambda`: corrected at fixed `lambda`, its tangent
    /// oriented along the current one. The point becomes the current one as with
    /// [`Arclength::restart_from`], and carries [`Event::Fold`] when the parameter component
    /// of the tangent changed sign.
    ///
    /// # Errors
    /// A wrong-sized `x` or a non-finite `lambda`, a failed correction
    /// ([`ContinuationError::Start`]) or a singular bordered Jacobian; the driver is then
    /// unchanged.
    pub fn continue_from(&mut self, x: Vec<f64>, lambda: f64) -> Result<Point, ContinuationError> {
        let direction = self.tangent.clone();
        self.continue_along(x, lambda, &direction)
    }

    /// [`Arclength::continue_from`] with the tangent oriented along `direction` (a tangent of
    /// an earlier point, `(dx, dlambda)`) instead of the current one.
    ///
    /// # Errors
    /// As [`Arclength::continue_from`], and [`ContinuationError::Dimension`] for a
    /// `direction` of another length than `x` and `lambda`.
    pub fn continue_along(
        &mut self,
        x: Vec<f64>,
        lambda: f64,
        direction: &[f64],
    ) -> Result<Point, ContinuationError> {
        let n = self.problem.dimension();
        super::check_start(&x, n, lambda, "continuation parameter")?;
        if direction.len() != n + 1 {
            let (got, expected) = (direction.len(), n + 1);
            return Err(ContinuationError::Dimension { got, expected });
        }
        let mut x = x;
        let info = (self.solve_at(&mut x, lambda)).map_err(ContinuationError::Start)?;
        let y = augmented::join(x, lambda);
        let tangent = self
            .tangent_at(&y, direction)
            .ok_or(ContinuationError::SingularTangent { lambda })?;
        let mut events = Vec::new();
        if tangent[n] * direction[n] < 0.0 {
            events.push(Event::Fold { parameter: lambda });
        }
        Ok(self.adopt(y, tangent, &info, events))
    }

    /// Makes `y` with `tangent` the current point, numbered as the next step, with the
    /// step size back to `options.ds` and no secant history; a finished driver runs again.
    pub(super) fn adopt(
        &mut self,
        y: Vec<f64>,
        tangent: Vec<f64>,
        info: &SolveInfo,
        events: Vec<Event>,
    ) -> Point {
        self.orientation = self.orientation_at(&y, &tangent);
        self.bracket = None;
        self.previous = None;
        self.y = y;
        self.tangent = tangent;
        self.active = self.active_set();
        self.accepted += 1;
        self.ds = self.options.ds;
        self.start = None;
        self.finished = None;
        self.done = false;
        let mut point = self.point(self.accepted, info, events);
        point.step_size = 0.0;
        point
    }
}
