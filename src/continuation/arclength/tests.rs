//! Unit tests of the pseudo-arclength driver on small problems of their own.

use super::*;
use crate::solve::SemismoothNewton;

/// `F(x, lambda) = x^2 + lambda^2 - 1`: a circle with folds at `lambda = +-1`.
struct Circle {
    lambda: f64,
}

impl Problem for Circle {
    fn dimension(&self) -> usize {
        1
    }
    fn residual(&mut self, x: &[f64], f: &mut [f64]) {
        f[0] = x[0] * x[0] + self.lambda * self.lambda - 1.0;
    }
    fn jacobian(&mut self, x: &[f64], jac: &mut DenseMatrix) {
        jac.reset(1, 1);
        jac[(0, 0)] = 2.0 * x[0];
    }
}

impl ContinuationProblem for Circle {
    fn parameter(&self) -> f64 {
        self.lambda
    }
    fn set_parameter(&mut self, lambda: f64) {
        self.lambda = lambda;
    }
    fn parameter_derivative(&mut self, _: &[f64], df: &mut [f64]) {
        df[0] = 2.0 * self.lambda;
    }
}

/// A driver on the circle from `x = 0.9` at `lambda = 0` (corrected to `x = 1`).
fn on_the_circle(options: ArclengthOptions) -> Arclength<'static, Circle, SemismoothNewton> {
    Arclength::new(
        Circle { lambda: 0.0 },
        SemismoothNewton::default(),
        vec![0.9],
        0.0,
        options,
    )
    .unwrap()
}

#[test]
fn passes_the_fold_of_a_circle_and_comes_back() {
    let options = ArclengthOptions {
        ds: 0.05,
        ds_max: 0.1,
        max_steps: 400,
        parameter_range: (-0.5, 2.0),
        scale: ArclengthScale::Fixed(1.0, 1.0),
        ..Default::default()
    };
    let mut driver = on_the_circle(options);
    let branch = driver.run(&mut crate::continuation::quiet);
    // Leaves through lambda < -0.5 on the lower half after turning at lambda = 1.
    assert!(matches!(branch.end, EndReason::ParameterOutOfRange { parameter } if parameter < -0.5));
    assert_eq!(branch.points[0].step, 0);
    assert!(
        (branch.points[0].x[0] - 1.0).abs() < 1e-9,
        "the corrected start"
    );
    let folds: Vec<_> = branch
        .with_event(|e| matches!(e, Event::Fold { .. }))
        .collect();
    assert_eq!(folds.len(), 1);
    assert_eq!(
        branch
            .with_event(|e| matches!(e, Event::BranchPoint { .. }))
            .count(),
        0,
        "a fold is not a branch point"
    );
    assert!(folds[0].parameter > 0.95);
    assert!(
        branch.points.iter().any(|p| p.x[0] < -0.5),
        "came back on the other side"
    );
    for p in &branch.points {
        assert!((p.x[0].powi(2) + p.parameter.powi(2) - 1.0).abs() < 1e-9);
    }
    // Arclength steps match the geometry: consecutive points are ds apart (chord ~ arc).
    for w in branch.points.windows(2) {
        let chord =
            ((w[1].x[0] - w[0].x[0]).powi(2) + (w[1].parameter - w[0].parameter).powi(2)).sqrt();
        assert!((chord - w[1].step_size).abs() < 0.01 * w[1].step_size + 1e-3);
    }
}

#[test]
fn observer_stops_and_secant_works() {
    let options = ArclengthOptions {
        predictor: TangentPredictor::Secant,
        scale: ArclengthScale::Fixed(1.0, 1.0),
        ..Default::default()
    };
    let mut driver = on_the_circle(options);
    let mut seen = 0;
    let branch = driver.run(&mut |o: &Step| {
        seen += usize::from(matches!(o, Step::Accepted(_)));
        if seen == 5 {
            std::ops::ControlFlow::Break(())
        } else {
            std::ops::ControlFlow::Continue(())
        }
    });
    assert_eq!(branch.points.len(), 5);
    assert_eq!(branch.end, EndReason::StoppedByObserver);
    assert!(matches!(
        driver.step(),
        Step::Finished(EndReason::StoppedByObserver)
    ));
    // The iterator ends at once, without an error.
    assert!(driver.next().is_none());
}

/// Solves the problem itself (the start) but never the bordered corrector system.
struct StartOnly;

impl NonlinearSolver for StartOnly {
    fn solve_monitored(
        &self,
        problem: &mut dyn Problem,
        x: &mut [f64],
        monitor: &mut dyn crate::solve::SolveMonitor,
    ) -> Result<SolveInfo, SolveError> {
        if problem.dimension() == 1 {
            SemismoothNewton::default().solve_monitored(problem, x, monitor)
        } else {
            Err(SolveError::MaxIterations {
                iterations: 0,
                residual_norm: 1.0,
                tolerance: 0.0,
            })
        }
    }
    fn tolerance(&self, problem: &mut dyn Problem) -> f64 {
        SemismoothNewton::default().tolerance(problem)
    }
}

#[test]
fn a_shrink_close_to_one_ends_at_the_rejection_bound() {
    // Every step fails: with `shrink = 0.9999999` the step would take ~7.6e7 rejections
    // to fall below `ds_min`; the default bound ends the run after 10 000.
    let options = ArclengthOptions {
        shrink: 0.9999999,
        scale: ArclengthScale::Fixed(1.0, 1.0),
        ..Default::default()
    };
    let mut driver =
        Arclength::new(Circle { lambda: 0.0 }, StartOnly, vec![0.9], 0.0, options).unwrap();
    let branch = driver.run(&mut crate::continuation::quiet);
    assert_eq!(branch.points.len(), 1, "the start only");
    assert_eq!(branch.rejections, 10_000);
    assert_eq!(driver.rejections(), 10_001);
    let EndReason::TooManyRejections { rejections, last } = &branch.end else {
        panic!("{:?}", branch.end);
    };
    assert_eq!(*rejections, 10_001);
    assert!(matches!(last.reason, RejectReason::Solver(_)));
    assert!(matches!(
        branch.end.error(),
        Some(ContinuationError::TooManyRejections {
            rejections: 10_001,
            ..
        })
    ));
    // An explicit bound; the iterator ends with the error.
    let options = ArclengthOptions {
        max_rejections: 3,
        ..options
    };
    let driver =
        Arclength::new(Circle { lambda: 0.0 }, StartOnly, vec![0.9], 0.0, options).unwrap();
    let items: Vec<_> = driver.collect();
    assert_eq!(items.len(), 2);
    assert!(items[0].is_ok());
    assert!(matches!(
        items[1],
        Err(ContinuationError::TooManyRejections { rejections: 4, .. })
    ));
}

#[test]
fn restart_from_continues_the_branch_elsewhere_with_the_same_scale() {
    let options = ArclengthOptions {
        ds: 0.05,
        ds_max: 0.1,
        max_steps: 6,
        parameter_range: (-0.5, 2.0),
        ..Default::default()
    };
    let mut driver = on_the_circle(options);
    let start = driver.state()[0];
    assert!((driver.norm(&[start]) - 1.0).abs() < 1e-12, "|x0|_W = 1");
    let scale = (driver.norm(&[1.0]), driver.parameter_scale());
    assert_eq!(scale.1, 1.0);
    let mut seen = 0;
    let branch = driver.run(&mut |step: &Step| {
        seen += usize::from(matches!(step, Step::Accepted(_)));
        if seen == 4 {
            std::ops::ControlFlow::Break(())
        } else {
            std::ops::ControlFlow::Continue(())
        }
    });
    assert_eq!(branch.end, EndReason::StoppedByObserver);
    let last = branch.points.last().unwrap();
    assert_eq!(last.step, 3);
    assert_eq!(driver.state()[..1], last.x[..]);
    assert_eq!(driver.state()[1], last.parameter);
    // Errors leave the driver as it was.
    assert!(matches!(
        driver.restart_from(vec![0.0, 0.0], 0.5),
        Err(ContinuationError::Dimension { .. })
    ));
    assert!(matches!(
        driver.restart_from(vec![0.5], 1.5),
        Err(ContinuationError::Start(_))
    ));
    assert_eq!(driver.state()[1], last.parameter);
    // A fixed-parameter solve on the lower half, then the branch goes on from there.
    let mut x = vec![-0.5];
    let info = driver.solve_at(&mut x, 0.6).unwrap();
    assert!(info.residual_norm < 1e-8 && (x[0] + 0.8).abs() < 1e-8);
    assert!(driver.accepts(&x, 0.6));
    let point = driver.restart_from(x, 0.6).unwrap();
    assert_eq!(point.step, last.step + 1);
    assert_eq!((point.step_size, point.iterations), (0.0, 0));
    assert_eq!(driver.step_size(), options.ds);
    assert_eq!(
        (driver.norm(&[1.0]), driver.parameter_scale()),
        scale,
        "the scale is kept"
    );
    // The tangent follows the options' direction: lambda grows on the lower half.
    assert!(driver.tangent()[1] > 0.0);
    // The driver had finished (stopped); it runs again, and the restart counted towards
    // `max_steps = 6`.
    let Step::Accepted(next) = driver.step() else {
        panic!("a step after the restart");
    };
    assert_eq!(next.step, point.step + 1);
    assert!(next.parameter > 0.6 && next.x[0] < 0.0);
    let rest = driver.run(&mut crate::continuation::quiet);
    assert_eq!(rest.points.len(), 1);
    assert_eq!(rest.end, EndReason::MaxSteps);
    let next = &rest.points[0];
    let (problem, _) = driver.into_parts();
    assert_eq!(problem.parameter(), next.parameter);
}

/// `F(x, lambda) = (x_0 (lambda - x_0^2), x_1 - lambda)`: the branch `x_0 = 0` is crossed at
/// `lambda = 0` by the pitchfork `x_0^2 = lambda`, `x_1 = lambda`.
struct Pitchfork {
    lambda: f64,
}

impl Problem for Pitchfork {
    fn dimension(&self) -> usize {
        2
    }
    fn residual(&mut self, x: &[f64], f: &mut [f64]) {
        f[0] = x[0] * (self.lambda - x[0] * x[0]);
        f[1] = x[1] - self.lambda;
    }
    fn jacobian(&mut self, x: &[f64], jac: &mut DenseMatrix) {
        jac.reset(2, 2);
        jac[(0, 0)] = self.lambda - 3.0 * x[0] * x[0];
        jac[(1, 1)] = 1.0;
    }
}

impl ContinuationProblem for Pitchfork {
    fn parameter(&self) -> f64 {
        self.lambda
    }
    fn set_parameter(&mut self, lambda: f64) {
        self.lambda = lambda;
    }
    fn parameter_derivative(&mut self, x: &[f64], df: &mut [f64]) {
        df[0] = x[0];
        df[1] = -1.0;
    }
}

/// A driver on the trivial branch of [`Pitchfork`] from `lambda = -1`.
fn on_the_trivial_branch(branch_points: bool) -> Arclength<'static, Pitchfork, SemismoothNewton> {
    let options = ArclengthOptions {
        ds: 0.05,
        ds_max: 0.1,
        parameter_range: (-1.5, 1.0),
        scale: ArclengthScale::Fixed(1.0, 1.0),
        branch_points,
        ..Default::default()
    };
    Arclength::new(
        Pitchfork { lambda: -1.0 },
        SemismoothNewton::default(),
        vec![0.0, -1.0],
        -1.0,
        options,
    )
    .unwrap()
}

/// [`on_the_trivial_branch`] stepped until the accepted point that reports the branch point
/// (returned with it).
fn at_the_pitchfork() -> (Arclength<'static, Pitchfork, SemismoothNewton>, Point) {
    let mut driver = on_the_trivial_branch(true);
    for _ in 0..100 {
        match driver.step() {
            Step::Accepted(p) if !p.events.is_empty() => return (driver, p),
            Step::Finished(end) => panic!("ended before the branch point: {end:?}"),
            _ => {}
        }
    }
    panic!("no branch point in 100 steps");
}

#[test]
fn detects_the_pitchfork_and_switches_onto_either_side() {
    let (mut driver, at) = at_the_pitchfork();
    assert!(
        matches!(at.events[..], [Event::BranchPoint { parameter }] if parameter > 0.0 && parameter <= 0.1),
        "{:?}",
        at.events
    );
    assert!(at.x[0].abs() < 1e-12, "still on the trivial branch");
    for side in [1.0, -1.0] {
        let (mut driver, _) = at_the_pitchfork();
        let switched = driver.switch_branch(side).unwrap();
        assert!(switched.x[0] * side > 0.0, "side {side}: {:?}", switched.x);
        assert_eq!(switched.step, at.step + 1);
        let mut points = vec![switched];
        let branch = driver.run(&mut crate::continuation::quiet);
        assert!(matches!(branch.end, EndReason::ParameterOutOfRange { .. }));
        points.extend(branch.points);
        assert!(points.len() > 10);
        for p in &points {
            assert!(p.x[0] * side > 0.0, "stays on its side");
            assert!((p.x[0] * p.x[0] - p.parameter).abs() < 1e-8, "{p:?}");
            assert!((p.x[1] - p.parameter).abs() < 1e-8);
        }
        assert!(points.last().unwrap().parameter > 0.9);
    }
    // Switched once, the bracket is gone; the side must be +-1.
    assert!(matches!(
        driver.switch_branch(0.5),
        Err(ContinuationError::InvalidOption { .. })
    ));
    driver.switch_branch(1.0).unwrap();
    assert!(matches!(
        driver.switch_branch(1.0),
        Err(ContinuationError::NoBranchPoint { .. })
    ));
}

#[test]
fn branch_points_are_not_watched_when_switched_off() {
    let mut driver = on_the_trivial_branch(false);
    let branch = driver.run(&mut crate::continuation::quiet);
    assert!(branch.points.len() > 10);
    assert!(branch
        .points
        .iter()
        .all(|p| p.events.is_empty() && p.x[0] == 0.0));
    assert!(matches!(
        driver.switch_branch(1.0),
        Err(ContinuationError::NoBranchPoint { .. })
    ));
}
