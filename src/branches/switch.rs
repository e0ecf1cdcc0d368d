//! Switching an arclength backbone onto the branch that crosses it at a branch point.

use crate::branches::EscapingArclength;
use crate::continuation::{
    Arclength, Branch, ContinuationProblem, EndReason, Event, Observer, Point, Step,
};
use crate::error::ContinuationError;
use crate::solve::NonlinearSolver;
use std::ops::ControlFlow;

/// Where an arclength backbone leaves its branch: at its `branch_point`-th
/// [`Event::BranchPoint`] (counted from 1), onto the crossing branch on side `side` (`+1` or
/// `-1`) of its direction ([`Arclength::switch_branch`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SwitchAt {
    /// Which branch point, counted from 1 along the run.
    pub branch_point: usize,
    /// Side of the crossing branch: `+1` or `-1`.
    pub side: f64,
}

/// The arclength driver of a backbone, with or without the stall escape.
pub(crate) enum Runner<'a, P, S> {
    Plain(Arclength<'a, P, S>),
    Escaping(EscapingArclength<'a, P, S>),
}

impl<P: ContinuationProblem, S: NonlinearSolver> Runner<'_, P, S> {
    fn run(&mut self, observer: &mut (impl Observer + ?Sized)) -> Branch {
        match self {
            Self::Plain(d) => d.run(observer),
            Self::Escaping(d) => d.run(observer),
        }
    }

    fn switch_branch(&mut self, side: f64) -> Result<Point, ContinuationError> {
        match self {
            Self::Plain(d) => d.switch_branch(side),
            Self::Escaping(d) => d.switch_branch(side),
        }
    }

    /// Runs to the end, switching branches once as `switch` asks. The observer sees every
    /// step, the switched point included; the branch returned holds the points of both
    /// branches. A switch that fails ends the run with [`EndReason::SwitchFailed`].
    pub(crate) fn run_switching(
        &mut self,
        switch: Option<SwitchAt>,
        observer: &mut dyn FnMut(&Step) -> ControlFlow<()>,
    ) -> Result<Branch, ContinuationError> {
        if let Some(at) = switch {
            if at.branch_point == 0 {
                return Err(ContinuationError::InvalidOption {
                    what: "switch branch point (counted from 1)",
                    value: 0.0,
                });
            }
            if !(at.side == 1.0 || at.side == -1.0) {
                return Err(ContinuationError::InvalidOption {
                    what: "switch side (must be +1 or -1)",
                    value: at.side,
                });
            }
        }
        let target = switch.map_or(0, |at| at.branch_point);
        let (mut seen, mut reached) = (0, false);
        let mut first = self.run(&mut |step: &Step| {
            let flow = observer(step);
            if let Step::Accepted(p) = step {
                if p.events
                    .iter()
                    .any(|e| matches!(e, Event::BranchPoint { .. }))
                {
                    seen += 1;
                    if seen == target && flow.is_continue() {
                        reached = true;
                        return ControlFlow::Break(());
                    }
                }
            }
            flow
        });
        let Some(at) = switch.filter(|_| reached) else {
            return Ok(first);
        };
        match self.switch_branch(at.side) {
            Ok(point) => {
                let step = Step::Accepted(point);
                let flow = observer(&step);
                if let Step::Accepted(point) = step {
                    first.points.push(point);
                }
                if flow.is_break() {
                    first.end = EndReason::StoppedByObserver;
                    return Ok(first);
                }
                let rest = self.run(&mut |step: &Step| observer(step));
                first.points.extend(rest.points);
                first.rejections += rest.rejections;
                first.end = rest.end;
            }
            Err(error) => {
                first.end = EndReason::SwitchFailed {
                    error: Box::new(error),
                }
            }
        }
        Ok(first)
    }
}
