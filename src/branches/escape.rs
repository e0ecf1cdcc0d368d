//! Escape from stalls of a pseudo-arclength backbone.
//!
//! Near internal resonances a truncated harmonic-balance branch can turn into an (almost)
//! vertical branch whose energy grows without bound at fixed parameter; the paper abandoned
//! arclength continuation for this reason. [`EscapingArclength`] runs an [`Arclength`]
//! driver and watches its accepted points: when the parameter has not progressed by
//! `min_progress` in the run's direction over `window` of them, or when the step falls below
//! its minimum, it jumps. From the recent point of least state norm (resonant branches carry
//! more energy than the backbone they leave) and from the most advanced point reached, it
//! solves at fixed parameter a little beyond the most advanced parameter
//! ([`Arclength::solve_at`]), doubling the distance while the solves fail or land on a state
//! more than `max_norm_ratio` times larger than their start (a distance that passes the end
//! of the parameter range is tried at the end itself, once); it then continues from there
//! ([`Arclength::restart_from`]) and reports [`Event::Jump`] on that point. The run ends with
//! [`EndReason::Stalled`] when every attempt fails.

use crate::continuation::{
    next_point, run_with, Arclength, Branch, ContinuationProblem, EndReason, Event, Observer,
    Point, Step,
};
use crate::error::ContinuationError;
use crate::solve::NonlinearSolver;
use std::collections::VecDeque;

/// When and how [`EscapingArclength`] jumps past a stall (see the module documentation).
/// Distances are relative to the driver's parameter scale
/// ([`Arclength::parameter_scale`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StallEscape {
    /// Accepted points over which progress is measured (default 20).
    pub window: usize,
    /// Least progress of the parameter over the window, relative (default `2e-3`).
    pub min_progress: f64,
    /// First jump beyond the most advanced parameter, relative (default `2e-3`); doubled on
    /// each failed attempt.
    pub jump: f64,
    /// Attempts before the run ends with [`EndReason::Stalled`] (default 6).
    pub max_attempts: usize,
    /// A jump is accepted only if the new state's norm ([`Arclength::norm`]) is at most this
    /// multiple of the norm of the point it started from (default 2).
    pub max_norm_ratio: f64,
}

impl Default for StallEscape {
    fn default() -> Self {
        Self {
            window: 20,
            min_progress: 2e-3,
            jump: 2e-3,
            max_attempts: 6,
            max_norm_ratio: 2.0,
        }
    }
}

impl StallEscape {
    /// Checks the options.
    ///
    /// # Errors
    /// [`ContinuationError::InvalidOption`] for a window shorter than 2, no attempts, or a
    /// non-finite or non-positive distance or ratio.
    pub fn validate(&self) -> Result<(), ContinuationError> {
        let bad = |what, value| Err(ContinuationError::InvalidOption { what, value });
        if self.window < 2 || self.max_attempts == 0 {
            return bad(
                "escape window/attempts",
                self.window.min(self.max_attempts) as f64,
            );
        }
        for (what, v) in [
            ("escape min_progress", self.min_progress),
            ("escape jump", self.jump),
            ("escape max_norm_ratio", self.max_norm_ratio),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return bad(what, v);
            }
        }
        Ok(())
    }
}

/// A pseudo-arclength run that jumps past stalls ([`StallEscape`]), with the driver's
/// shape: `step()`, `run(&mut observer)` and an iterator of points.
///
/// The driver's points pass through unchanged, except the one that completes a stalled
/// window: it is replaced by the point the jump lands on, numbered as the next step, with
/// `step_size` the parameter distance jumped, an [`Event::Jump`] whose ratio is the
/// distance jumped over the driver's step size, and `iterations` those of the fixed-parameter
/// solve plus the correction. The driver's starting point (step 0) does not count towards the
/// window.
pub struct EscapingArclength<'a, P, S> {
    driver: Arclength<'a, P, S>,
    escape: StallEscape,
    /// Recent accepted points `(lambda, x)`, at most `2 window` of them.
    history: VecDeque<(f64, Vec<f64>)>,
    /// The most advanced accepted point in the run's direction.
    frontier: Option<(f64, Vec<f64>)>,
    finished: Option<EndReason>,
    /// Whether the iterator has handed out the end.
    done: bool,
}

impl<'a, P: ContinuationProblem, S: NonlinearSolver> EscapingArclength<'a, P, S> {
    /// Runs `driver` (its options, acceptance test and progress so far) with `escape`.
    ///
    /// # Errors
    /// Invalid `escape` options ([`StallEscape::validate`]).
    pub fn new(
        driver: Arclength<'a, P, S>,
        escape: StallEscape,
    ) -> Result<Self, ContinuationError> {
        escape.validate()?;
        Ok(Self {
            driver,
            escape,
            history: VecDeque::new(),
            frontier: None,
            finished: None,
            done: false,
        })
    }

    /// The driver.
    pub fn driver(&self) -> &Arclength<'a, P, S> {
        &self.driver
    }

    /// The driver, giving up the escape.
    pub fn into_driver(self) -> Arclength<'a, P, S> {
        self.driver
    }

    /// Switches the driver onto the branch crossing at the branch point reported on the last
    /// accepted point ([`Arclength::switch_branch`]); the stall window starts anew from the
    /// switched point, and a run that had ended runs again.
    ///
    /// # Errors
    /// Those of [`Arclength::switch_branch`]; the run is then unchanged.
    pub fn switch_branch(&mut self, side: f64) -> Result<Point, ContinuationError> {
        let point = self.driver.switch_branch(side)?;
        self.history.clear();
        self.frontier = None;
        self.record(&point);
        self.finished = None;
        self.done = false;
        Ok(point)
    }

    /// One step of the driver, or a jump past a stall.
    pub fn step(&mut self) -> Step {
        if let Some(end) = &self.finished {
            return Step::Finished(end.clone());
        }
        match self.driver.step() {
            Step::Accepted(p) if p.step > 0 => {
                self.record(&p);
                if self.is_stalled() {
                    self.escape(p.parameter)
                } else {
                    Step::Accepted(p)
                }
            }
            Step::Finished(EndReason::StepBelowMinimum { .. }) if self.history.len() > 1 => {
                self.escape(self.parameter())
            }
            Step::Finished(end) => {
                self.finished = Some(end.clone());
                Step::Finished(end)
            }
            other => other,
        }
    }

    /// Runs until the end, handing every step (the start, accepted points, jumps and
    /// rejections) to `observer`, which may stop the run; returns the branch.
    pub fn run(&mut self, observer: &mut (impl Observer + ?Sized)) -> Branch {
        run_with(
            self,
            Self::step,
            |d| d.finished = Some(EndReason::StoppedByObserver),
            observer,
        )
    }

    /// The driver's current parameter.
    fn parameter(&self) -> f64 {
        self.driver.state().last().copied().unwrap_or(f64::NAN)
    }

    /// Notes an accepted point in the history and the frontier.
    fn record(&mut self, p: &Point) {
        let dir = self.driver.options().direction;
        if self
            .frontier
            .as_ref()
            .is_none_or(|(l, _)| dir * p.parameter > dir * l)
        {
            self.frontier = Some((p.parameter, p.x.clone()));
        }
        self.history.push_back((p.parameter, p.x.clone()));
        // `saturating_mul`: a window near `usize::MAX` must not overflow.
        if self.history.len() > self.escape.window.saturating_mul(2) {
            self.history.pop_front();
        }
    }

    /// Whether the last `window` accepted points made less than `min_progress` progress.
    fn is_stalled(&self) -> bool {
        let (h, window) = (&self.history, self.escape.window);
        if h.len() <= window {
            return false;
        }
        let now = h[h.len() - 1].0;
        let then = h[h.len() - 1 - window].0;
        self.driver.options().direction * (now - then)
            < self.escape.min_progress * self.driver.parameter_scale()
    }

    /// Jumps past a stall at parameter `now`: see [`StallEscape`].
    fn escape(&mut self, now: f64) -> Step {
        let escape = self.escape;
        let driver = &mut self.driver;
        let dir = driver.options().direction;
        let (lo, hi) = driver.options().parameter_range;
        // Anchors: the recent point of least state norm (the backbone below a resonant
        // branch) and the most advanced point ever accepted (the frontier).
        let mut anchors: Vec<(f64, Vec<f64>)> = self
            .history
            .iter()
            .min_by(|a, b| driver.norm(&a.1).total_cmp(&driver.norm(&b.1)))
            .into_iter()
            .cloned()
            .collect();
        anchors.extend(self.frontier.clone());
        let ahead = anchors
            .iter()
            .chain(self.history.iter())
            .map(|(l, _)| dir * l)
            .fold(f64::NEG_INFINITY, f64::max);
        let mut distance = escape.jump * driver.parameter_scale();
        for _ in 0..escape.max_attempts {
            // `ahead` and `distance` are in progress coordinates `dir * lambda`. A jump past
            // the end of the range is tried once at the end itself.
            let beyond = dir * (ahead + distance);
            let target = beyond.clamp(lo, hi);
            let last = target != beyond;
            for (_, from) in &anchors {
                let mut x = from.clone();
                let Ok(info) = driver.solve_at(&mut x, target) else {
                    continue;
                };
                if driver.norm(&x) > escape.max_norm_ratio * driver.norm(from)
                    || !driver.accepts(&x, target)
                {
                    continue;
                }
                let ratio = {
                    let jump: Vec<f64> = x
                        .iter()
                        .chain([&target])
                        .zip(driver.state())
                        .map(|(a, b)| a - b)
                        .collect();
                    driver.norm(&jump) / driver.step_size()
                };
                if let Ok(mut point) = driver.restart_from(x, target) {
                    self.history.clear();
                    self.history.push_back((target, point.x.clone()));
                    point.iterations += info.iterations;
                    point.step_size = target - now;
                    point.events.push(Event::Jump { ratio });
                    return Step::Accepted(point);
                }
            }
            if last {
                return self.finish(EndReason::ParameterOutOfRange { parameter: beyond });
            }
            distance *= 2.0;
        }
        self.finish(EndReason::Stalled {
            failures: escape.max_attempts,
            parameter: now,
        })
    }

    /// Ends the run with `end`.
    fn finish(&mut self, end: EndReason) -> Step {
        self.finished = Some(end.clone());
        Step::Finished(end)
    }
}

impl<P: ContinuationProblem, S: NonlinearSolver> Iterator for EscapingArclength<'_, P, S> {
    type Item = Result<Point, ContinuationError>;

    /// The accepted points, jumps included; then, if the run failed
    /// ([`EndReason::error`]), its error; then `None`.
    fn next(&mut self) -> Option<Self::Item> {
        next_point(self, |d| &mut d.done, Self::step)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::continuation::{ArclengthOptions, ArclengthScale};
    use crate::linalg::DenseMatrix;
    use crate::solve::{Problem, SemismoothNewton};

    /// `F(x, lambda) = (x - lambda)(lambda - 1) - 1e-2`: below `lambda = 1` the branch from
    /// `x = lambda` dives to `x = -inf` as `lambda -> 1` (a stall); above it another branch
    /// comes down from `x = +inf` to `x = lambda`.
    struct Hyperbola {
        lambda: f64,
    }

    impl Problem for Hyperbola {
        fn dimension(&self) -> usize {
            1
        }
        fn residual(&mut self, x: &[f64], f: &mut [f64]) {
            f[0] = (x[0] - self.lambda) * (self.lambda - 1.0) - 1e-2;
        }
        fn jacobian(&mut self, _: &[f64], jac: &mut DenseMatrix) {
            jac.reset(1, 1);
            jac[(0, 0)] = self.lambda - 1.0;
        }
    }

    impl ContinuationProblem for Hyperbola {
        fn parameter(&self) -> f64 {
            self.lambda
        }
        fn set_parameter(&mut self, lambda: f64) {
            self.lambda = lambda;
        }
        fn parameter_derivative(&mut self, x: &[f64], df: &mut [f64]) {
            df[0] = x[0] + 1.0 - 2.0 * self.lambda;
        }
    }

    fn driver(max_steps: usize) -> Arclength<'static, Hyperbola, SemismoothNewton> {
        driver_to(1.5, max_steps)
    }

    /// The driver on the hyperbola inside `[-1, hi]`.
    fn driver_to(hi: f64, max_steps: usize) -> Arclength<'static, Hyperbola, SemismoothNewton> {
        let options = ArclengthOptions {
            parameter_range: (-1.0, hi),
            scale: ArclengthScale::Fixed(1.0, 1.0),
            ds_max: 0.05,
            max_steps,
            ..Default::default()
        };
        Arclength::new(
            Hyperbola { lambda: 0.5 },
            SemismoothNewton::default(),
            vec![0.48],
            0.5,
            options,
        )
        .unwrap()
    }

    #[test]
    fn jumps_past_a_vertical_branch() {
        let mut run = EscapingArclength::new(driver(2000), StallEscape::default()).unwrap();
        let branch = run.run(&mut crate::continuation::quiet);
        assert!(
            matches!(branch.end, EndReason::ParameterOutOfRange { parameter } if parameter > 1.5)
        );
        let jumps: Vec<usize> = (0..branch.points.len())
            .filter(|&i| {
                let events = &branch.points[i].events;
                events.iter().any(|e| matches!(e, Event::Jump { .. }))
            })
            .collect();
        assert_eq!(jumps.len(), 1, "one jump");
        let (before, jump) = (&branch.points[jumps[0] - 1], &branch.points[jumps[0]]);
        assert!(
            before.parameter < 1.0 && jump.parameter > 1.0,
            "across the gap"
        );
        // The point that completed the stalled window is replaced by the jump.
        assert_eq!(jump.step, before.step + 2);
        assert!(jump.step_size > 0.0 && jump.step_size < 0.02);
        // The landed state is at most twice as large as the frontier it started from.
        assert!(jump.x[0].abs() <= 2.0 * before.x[0].abs());
        let mut problem = Hyperbola { lambda: 0.0 };
        let mut f = [0.0];
        for p in &branch.points {
            problem.set_parameter(p.parameter);
            problem.residual(&p.x, &mut f);
            assert!(f[0].abs() < 1e-9, "on the curve");
        }
        // The generic driver follows the vertical branch and never gets past it.
        let plain = driver(200).run(&mut crate::continuation::quiet);
        assert_eq!(plain.end, EndReason::MaxSteps);
        assert!(plain.points.iter().all(|p| p.parameter < 1.0));
        let n = jumps[0] - 1;
        assert_eq!(
            plain.points[..n],
            branch.points[..n],
            "the same points before it"
        );
    }

    /// Where the range ends between two of the doubling jump distances (here the jumps
    /// before it land too far out on the branch above `lambda = 1`, the one after it leaves
    /// the range), the jump is tried at the range's end and lands there: the branch is not
    /// given up before its end.
    #[test]
    fn a_jump_past_the_range_is_tried_at_its_end() {
        let hi = 1.0042;
        let mut run = EscapingArclength::new(driver_to(hi, 2000), StallEscape::default()).unwrap();
        let branch = run.run(&mut crate::continuation::quiet);
        let last = branch.points.last().unwrap();
        assert_eq!(last.parameter, hi, "{:?}", branch.end);
        assert!(last.events.iter().any(|e| matches!(e, Event::Jump { .. })));
        let mut f = [0.0];
        Hyperbola { lambda: hi }.residual(&last.x, &mut f);
        assert!(f[0].abs() < 1e-9, "on the curve: {}", f[0]);
        assert!(
            matches!(branch.end, EndReason::ParameterOutOfRange { parameter } if parameter > hi),
            "{:?}",
            branch.end
        );
    }

    #[test]
    fn ends_stalled_when_every_jump_fails() {
        let escape = StallEscape {
            max_norm_ratio: 1e-3,
            ..Default::default()
        };
        let run = EscapingArclength::new(driver(2000), escape).unwrap();
        let items: Vec<_> = run.collect();
        let last = items.last().unwrap();
        assert!(
            matches!(
                last,
                Err(ContinuationError::Stalled { failures: 6, parameter }) if *parameter < 1.0
            ),
            "{last:?}"
        );
        assert!(items[..items.len() - 1].iter().all(Result::is_ok));
    }

    #[test]
    fn rejects_bad_options() {
        for escape in [
            StallEscape {
                window: 1,
                ..Default::default()
            },
            StallEscape {
                max_attempts: 0,
                ..Default::default()
            },
            StallEscape {
                jump: f64::NAN,
                ..Default::default()
            },
            StallEscape {
                max_norm_ratio: 0.0,
                ..Default::default()
            },
        ] {
            assert!(matches!(
                EscapingArclength::new(driver(10), escape),
                Err(ContinuationError::InvalidOption { .. })
            ));
        }
    }
}
