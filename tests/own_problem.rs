//! A problem of a downstream crate's own (not harmonic balance) through both continuation
//! drivers, and an observer of its own: the solver-facing traits are usable from outside.
//!
//! The problem is the cusp normal form `F(x, lambda) = x^3 - x - lambda = 0`, whose branch has
//! two folds, at `x = +-1/sqrt(3)`, `lambda = -+2 / (3 sqrt(3))`: an S whose upper and lower
//! sheets both run to `lambda = -infinity`.

use nonsmooth_modes::continuation::{
    Arclength, ArclengthOptions, ArclengthScale, ContinuationProblem, EndReason, Event, Observer,
    Sequential, SequentialOptions, Step,
};
use nonsmooth_modes::linalg::DenseMatrix;
use nonsmooth_modes::solve::{Problem, SemismoothNewton, SolveMonitor, Structured};
use std::ops::ControlFlow;

/// `x^3 - x - lambda` with an analytic Jacobian; it offers one capability (a residual scale)
/// to show the accessor.
#[derive(Debug, Clone, Default)]
struct Cusp {
    lambda: f64,
}

impl Problem for Cusp {
    fn dimension(&self) -> usize {
        1
    }
    fn residual(&mut self, x: &[f64], f: &mut [f64]) {
        f[0] = x[0].powi(3) - x[0] - self.lambda;
    }
    fn jacobian(&mut self, x: &[f64], jac: &mut DenseMatrix) {
        jac.reset(1, 1);
        jac[(0, 0)] = 3.0 * x[0] * x[0] - 1.0;
    }
    fn structure(&mut self) -> Option<&mut dyn Structured> {
        Some(self)
    }
}

impl Structured for Cusp {
    fn residual_scale(&self) -> f64 {
        1.0
    }
}

impl ContinuationProblem for Cusp {
    fn parameter(&self) -> f64 {
        self.lambda
    }
    fn set_parameter(&mut self, lambda: f64) {
        self.lambda = lambda;
    }
    fn parameter_derivative(&mut self, _: &[f64], df: &mut [f64]) {
        df[0] = -1.0;
    }
}

/// An observer of our own: counts what it sees and stops after `limit` accepted points.
#[derive(Debug, Default)]
struct Tally {
    accepted: usize,
    rejected: usize,
    ended: Option<EndReason>,
    limit: Option<usize>,
}

impl Observer for Tally {
    fn observe(&mut self, step: &Step) -> ControlFlow<()> {
        match step {
            Step::Accepted(_) => self.accepted += 1,
            Step::Rejected(_) => self.rejected += 1,
            Step::Finished(end) => self.ended = Some(end.clone()),
        }
        match self.limit {
            Some(limit) if self.accepted >= limit => ControlFlow::Break(()),
            _ => ControlFlow::Continue(()),
        }
    }
}

fn on_branch(x: f64, lambda: f64) -> bool {
    (x.powi(3) - x - lambda).abs() < 1e-9
}

#[test]
fn sequential_follows_the_upper_sheet_and_loses_it_past_the_fold() {
    // From x = 1.5 at lambda = 1.875 down in lambda: the upper sheet exists for
    // lambda > -2 / (3 sqrt 3) = -0.385; below, Newton jumps to the lower sheet.
    let values: Vec<f64> = (0..=20).map(|i| 1.875 - 0.125 * i as f64).collect();
    let mut driver = Sequential::new(
        Cusp::default(),
        SemismoothNewton::default(),
        vec![1.5],
        values.clone(),
        SequentialOptions::default(),
    )
    .unwrap();
    let mut tally = Tally::default();
    let branch = driver.run(&mut tally);
    assert_eq!(branch.end, EndReason::Completed);
    assert_eq!(tally.ended, Some(EndReason::Completed));
    assert_eq!(tally.accepted, branch.points.len());
    assert_eq!(tally.rejected, branch.rejections);
    assert_eq!(branch.points.len() + branch.rejections, values.len());
    for p in &branch.points {
        assert!(on_branch(p.x[0], p.parameter));
    }
    // Upper sheet while it exists, the lower one after the fold.
    let upper = branch.points.iter().filter(|p| p.parameter > -0.38);
    assert!(upper.clone().all(|p| p.x[0] > 0.57), "upper sheet");
    let last = branch.points.last().unwrap();
    assert!(last.parameter < -0.38 && last.x[0] < -1.0, "{last:?}");
    // The iterator gives the same points.
    let mut again = Sequential::new(
        Cusp::default(),
        SemismoothNewton::default(),
        vec![1.5],
        values,
        SequentialOptions::default(),
    )
    .unwrap();
    let iterated: Vec<_> = again.by_ref().map(Result::unwrap).collect();
    assert_eq!(iterated, branch.points);
    assert!(again.next().is_none());
}

#[test]
fn arclength_passes_both_folds_and_an_observer_can_stop_it() {
    let options = ArclengthOptions {
        ds: 0.05,
        ds_max: 0.1,
        direction: -1.0,
        parameter_range: (-1.0, 2.0),
        scale: ArclengthScale::Fixed(1.0, 1.0),
        ..Default::default()
    };
    let driver = || {
        Arclength::new(
            Cusp::default(),
            SemismoothNewton::default(),
            vec![1.5],
            1.875,
            options,
        )
        .unwrap()
    };
    let mut tally = Tally::default();
    let branch = driver().run(&mut tally);
    assert!(
        matches!(branch.end, EndReason::ParameterOutOfRange { parameter } if parameter < -1.0),
        "{:?}",
        branch.end
    );
    assert_eq!(tally.ended, Some(branch.end.clone()));
    let folds: Vec<f64> = branch
        .with_event(|e| matches!(e, Event::Fold { .. }))
        .map(|p| p.parameter)
        .collect();
    assert_eq!(folds.len(), 2, "{folds:?}");
    let fold = 2.0 / (3.0 * 3f64.sqrt());
    assert!((folds[0] + fold).abs() < 0.05 && (folds[1] - fold).abs() < 0.05);
    for p in &branch.points {
        assert!(on_branch(p.x[0], p.parameter));
    }
    // Our observer stops the run after 7 accepted points (the start included).
    let mut stopping = Tally {
        limit: Some(7),
        ..Default::default()
    };
    let mut run = driver();
    let stopped = run.run(&mut stopping);
    assert_eq!(stopped.points.len(), 7);
    assert_eq!(stopped.end, EndReason::StoppedByObserver);
    assert!(matches!(
        run.step(),
        Step::Finished(EndReason::StoppedByObserver)
    ));
}

/// A solver of our own that honours the monitor: one Newton step at a time, each residual
/// evaluation reported.
struct Plain;

impl nonsmooth_modes::solve::NonlinearSolver for Plain {
    fn solve_monitored(
        &self,
        problem: &mut dyn Problem,
        x: &mut [f64],
        monitor: &mut dyn SolveMonitor,
    ) -> Result<nonsmooth_modes::solve::SolveInfo, nonsmooth_modes::SolveError> {
        let (mut f, mut jac) = (vec![0.0; x.len()], DenseMatrix::zeros(1, 1));
        for iteration in 0..50 {
            problem.residual(x, &mut f);
            if monitor.evaluated(iteration + 1).is_break() {
                return Err(nonsmooth_modes::SolveError::Cancelled {
                    iteration,
                    evaluations: iteration + 1,
                });
            }
            if f[0].abs() < 1e-12 {
                return Ok(nonsmooth_modes::solve::SolveInfo {
                    iterations: iteration,
                    residual_norm: f[0].abs(),
                    residual_evaluations: iteration + 1,
                    jacobian_evaluations: iteration,
                });
            }
            problem.jacobian(x, &mut jac);
            x[0] -= f[0] / jac[(0, 0)];
        }
        Err(nonsmooth_modes::SolveError::MaxIterations {
            iterations: 50,
            residual_norm: f[0].abs(),
            tolerance: 1e-12,
        })
    }
    fn tolerance(&self, _: &mut dyn Problem) -> f64 {
        1e-12
    }
}

#[test]
fn our_solver_drives_both_drivers() {
    let values: Vec<f64> = (0..=8).map(|i| 1.875 - 0.125 * i as f64).collect();
    let mut sequential = Sequential::new(
        Cusp::default(),
        Plain,
        vec![1.5],
        values,
        SequentialOptions::default(),
    )
    .unwrap();
    let points: Vec<_> = sequential.by_ref().map(Result::unwrap).collect();
    assert_eq!(points.len(), 9);
    assert!(points.iter().all(|p| on_branch(p.x[0], p.parameter)));
    let options = ArclengthOptions {
        max_steps: 10,
        scale: ArclengthScale::Fixed(1.0, 1.0),
        ..Default::default()
    };
    // A solver chosen at run time drives them through a reference.
    let boxed: Box<dyn nonsmooth_modes::solve::NonlinearSolver> = Box::new(Plain);
    let mut arclength =
        Arclength::new(Cusp::default(), &*boxed, vec![1.5], 1.875, options).unwrap();
    let branch = arclength.run(&mut nonsmooth_modes::continuation::quiet);
    assert_eq!(branch.end, EndReason::MaxSteps);
    assert_eq!(branch.points.len(), 11);
    assert!(branch.points.iter().all(|p| on_branch(p.x[0], p.parameter)));
}
