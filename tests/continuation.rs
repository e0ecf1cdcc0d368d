//! Continuation drivers on the paper's systems (issue: pseudo-arclength, parameters, loops).

use nonsmooth_modes::branches::{
    compute, ArclengthBackboneOptions, BackboneOptions, BackbonePoint, Method, PeriodGrid, Request,
};
use nonsmooth_modes::continuation::{
    Arclength, ArclengthOptions, ContinuationProblem, EndReason, Event, PeriodParametrised, Point,
    Sequential, Speculative, Step,
};
use nonsmooth_modes::modal::{branch_seed, energy};
use nonsmooth_modes::reference::{
    clamped_bar_with_obstacle, robin_bar_with_obstacle, ClampedFirstMode,
};
use nonsmooth_modes::solve::{residual_scale, Problem, SemismoothNewton, Solver};
use nonsmooth_modes::system::{HarmonicBalanceSettings, NonsmoothSystem, ParameterFamily};
use std::f64::consts::PI;
use std::ops::ControlFlow;

fn run_backbone(
    system: &nonsmooth_modes::system::BarSystem,
    harmonics: usize,
    options: &ArclengthBackboneOptions,
) -> (Vec<BackbonePoint>, EndReason) {
    let request = Request {
        method: Method::Arclength(*options),
        solver: Some(Solver::default()),
        ..Request::new(options.mode).harmonics(harmonics)
    };
    let run = compute(system, &request).unwrap();
    (run.points, run.end)
}

/// Every accepted point satisfies the corrector's tolerance on `|F|` at its own `Omega`.
fn assert_all_converged(
    system: &nonsmooth_modes::system::BarSystem,
    harmonics: usize,
    points: &[BackbonePoint],
) {
    let settings = HarmonicBalanceSettings {
        harmonics,
        ..Default::default()
    };
    let mut problem = NonsmoothSystem::new(system, settings).unwrap();
    let tolerance = 1e-9 * residual_scale(&mut problem);
    let mut f = vec![0.0; problem.dimension()];
    for p in points {
        assert!(p.converged());
        problem.set_parameter(p.omega);
        problem.residual(&p.x, &mut f);
        let r = f.iter().map(|v| v * v).sum::<f64>().sqrt();
        assert!(r <= tolerance, "residual {r:e} at T = {}", p.period);
    }
}

#[test]
fn clamped_bar_arclength_reaches_short_periods_without_manual_restarts() {
    let system = clamped_bar_with_obstacle(1e-3).unwrap();
    for m in [20, 40] {
        let options = ArclengthBackboneOptions::for_mode(&system, 1, 1).unwrap();
        let (points, end) = run_backbone(&system, m, &options);
        let shortest = points
            .iter()
            .map(|p| p.period)
            .fold(f64::INFINITY, f64::min);
        assert!(shortest <= 3.1, "m = {m}: stopped at T = {shortest}");
        assert!(
            matches!(end, EndReason::ParameterOutOfRange { .. }),
            "m = {m}: {end:?}"
        );
        assert_all_converged(&system, m, &points);
        // A good share of the points lie on the exact backbone (the rest are resonances).
        let close = points
            .iter()
            .filter(|p| {
                let exact = ClampedFirstMode::new(1e-3, p.period).energy_normalized();
                (p.energy_normalized / exact - 1.0).abs() < 0.05
            })
            .count();
        assert!(close >= 100, "m = {m}: only {close} points within 5%");
    }
}

#[test]
fn robin_bar_arclength_crosses_the_figure_10_range() {
    let system = robin_bar_with_obstacle(0.5, 1e-3).unwrap();
    let options =
        ArclengthBackboneOptions::seeded_at(9.5, (2.0 * PI / 9.55, 2.0 * PI / 6.6), (1, 1));
    let (points, end) = run_backbone(&system, 20, &options);
    assert!(matches!(end, EndReason::ParameterOutOfRange { .. }));
    assert!(points.iter().any(|p| p.period < 6.7));
    assert_all_converged(&system, 20, &points);
}

#[test]
fn gap_continuation_reproduces_the_quadratic_energy_scaling() {
    // The truncated problem is positively homogeneous in the gap: x(s g0) = s x(g0), so
    // E / g0^2 is constant along the branch.
    let settings = HarmonicBalanceSettings::default();
    let system = clamped_bar_with_obstacle(1e-3).unwrap();
    let grid = PeriodGrid {
        start: 3.95,
        end: 3.6,
        steps: 71,
    };
    let request = Request {
        settings,
        method: Method::PeriodGrid(BackboneOptions::on_grid(grid, 1, 1)),
        solver: Some(Solver::default()),
        ..Request::new(1)
    };
    let walk = compute(&system, &request).unwrap().points;
    let gap_to_exact = |p: &&BackbonePoint| {
        (p.energy_normalized / ClampedFirstMode::new(1e-3, p.period).energy_normalized() - 1.0)
            .abs()
    };
    let start = walk
        .iter()
        .filter(|p| p.converged() && p.period < 3.7)
        .min_by(|a, b| gap_to_exact(a).total_cmp(&gap_to_exact(b)))
        .unwrap();
    let (omega, period, x) = (start.omega, start.period, start.x.clone());
    let family = ParameterFamily::at(clamped_bar_with_obstacle, settings, omega, 1e-3).unwrap();
    let solver = SemismoothNewton::default();
    let basis = settings.cosine_basis().unwrap();
    let options = ArclengthOptions {
        parameter_range: (5e-4, 4e-3),
        ..Default::default()
    };
    let mut driver = Arclength::new(family, solver, x, 1e-3, options).unwrap();
    let per_gap2 = |p: &Point| {
        let s = clamped_bar_with_obstacle(p.parameter).unwrap();
        energy(&s, &basis, &p.x, omega) / (p.parameter * p.parameter)
    };
    let branch = driver.run(&mut nonsmooth_modes::continuation::quiet);
    let reference = per_gap2(&branch.points[0]);
    let exact = ClampedFirstMode::new(1.0, period).energy();
    assert!((reference / exact - 1.0).abs() < 0.05);
    assert!(branch.points.len() > 5);
    assert!(branch.points.iter().any(|p| p.parameter > 3.5e-3));
    for p in &branch.points {
        assert!(
            (per_gap2(p) / reference - 1.0).abs() < 1e-8,
            "gap {}",
            p.parameter
        );
    }
}

#[test]
fn iterator_restart_and_reverse_direction() {
    let system = clamped_bar_with_obstacle(1e-3).unwrap();
    let settings = HarmonicBalanceSettings {
        harmonics: 10,
        ..Default::default()
    };
    let mut problem = NonsmoothSystem::new(&system, settings).unwrap();
    let x0 = branch_seed(&mut problem, 1, 1, 2.0 * PI / 3.9).unwrap();
    let options = ArclengthOptions {
        direction: -1.0,
        parameter_range: (3.5, 3.95),
        ..Default::default()
    };
    let driver = Arclength::new(
        PeriodParametrised::new(problem.clone()),
        SemismoothNewton::default(),
        x0,
        3.9,
        options,
    )
    .unwrap();
    let forward: Vec<Point> = driver.take(15).map(Result::unwrap).collect();
    assert_eq!(forward.len(), 15);
    assert!(forward.last().unwrap().parameter < 3.9);
    // Restart from a stored point in the other direction: the period grows again.
    let pivot = &forward[10];
    let mut back = Arclength::restart(
        PeriodParametrised::new(problem),
        SemismoothNewton::default(),
        pivot,
        ArclengthOptions {
            direction: 1.0,
            ..options
        },
    )
    .unwrap();
    let mut grew = false;
    for _ in 0..20 {
        if let Step::Accepted(p) = back.step() {
            grew |= p.parameter > pivot.parameter;
            assert!(p.residual_norm <= 1e-12);
            assert!(p
                .events
                .iter()
                .all(|e| !matches!(e, Event::Jump { .. }) || p.converged));
        }
    }
    assert!(grew);
}

/// `F(x, lambda) = x - s(lambda)` with a spike `s(0.2) = 0.55` between `s(0.1) = 0.1` and
/// `s(0.3) = 0`.
#[derive(Clone, Default)]
struct Spiky {
    lambda: f64,
}

impl Problem for Spiky {
    fn dimension(&self) -> usize {
        1
    }
    fn residual(&mut self, x: &[f64], f: &mut [f64]) {
        let lambda = self.lambda;
        let s = if (lambda - 0.2).abs() < 1e-12 {
            0.55
        } else if (lambda - 0.3).abs() < 1e-12 {
            0.0
        } else {
            lambda
        };
        f[0] = x[0] - s;
    }
    fn jacobian(&mut self, _: &[f64], jac: &mut nonsmooth_modes::linalg::DenseMatrix) {
        jac.reset(1, 1);
        jac[(0, 0)] = 1.0;
    }
}

impl ContinuationProblem for Spiky {
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

/// A local solver: one exact Newton step when the start is within 0.5 of the solution,
/// otherwise a failure (after `patience`, to let a speculative retry start beside it). It
/// tells its monitor of its one residual evaluation.
#[derive(Clone, Copy, Default)]
struct Local {
    patience: std::time::Duration,
}

impl nonsmooth_modes::solve::NonlinearSolver for Local {
    fn solve_monitored(
        &self,
        problem: &mut dyn nonsmooth_modes::solve::Problem,
        x: &mut [f64],
        monitor: &mut dyn nonsmooth_modes::solve::SolveMonitor,
    ) -> Result<nonsmooth_modes::solve::SolveInfo, nonsmooth_modes::SolveError> {
        let mut f = [0.0];
        problem.residual(x, &mut f);
        if monitor.evaluated(1).is_break() {
            return Err(nonsmooth_modes::SolveError::Cancelled {
                iteration: 0,
                evaluations: 1,
            });
        }
        if f[0].abs() > 0.5 {
            std::thread::sleep(self.patience);
            return Err(nonsmooth_modes::SolveError::MaxIterations {
                iterations: 0,
                residual_norm: f[0].abs(),
                tolerance: 0.0,
            });
        }
        x[0] -= f[0];
        Ok(nonsmooth_modes::solve::SolveInfo {
            iterations: 1,
            residual_norm: 0.0,
            residual_evaluations: 1,
            jacobian_evaluations: 0,
        })
    }
    fn tolerance(&self, _: &mut dyn nonsmooth_modes::solve::Problem) -> f64 {
        0.0
    }
}

/// After a spike, the step that fails from the spike is retried from the point before it, and
/// the branch goes on from there; without the retry it is lost.
#[test]
fn sequential_retry_steps_back_over_a_spike() {
    use nonsmooth_modes::continuation::SequentialOptions;
    let values = vec![0.0, 0.1, 0.2, 0.3, 0.4];
    let run = |retry_depth| {
        let options = SequentialOptions {
            retry_depth,
            ..Default::default()
        };
        let mut driver = Sequential::new(
            Spiky::default(),
            Local::default(),
            vec![0.0],
            values.clone(),
            options,
        )
        .unwrap();
        reported(|| driver.step())
            .into_iter()
            .map(|p| (p.converged, p.x[0]))
            .collect::<Vec<_>>()
    };
    let with = run(1);
    assert_eq!(
        with,
        vec![
            (true, 0.0),
            (true, 0.1),
            (true, 0.55),
            (true, 0.0),
            (true, 0.4)
        ]
    );
    let without = run(0);
    // From the spike 0.55 the solution 0 at lambda = 0.3 is out of reach; then 0.4 is reached
    // again from the spike.
    assert!(!without[3].0);
    assert_eq!(without[4], (true, 0.4));
    assert_eq!(SequentialOptions::default().retry_depth, 1);
}

/// The speculative driver gives the serial points, whether the worker solves the retry (the
/// first attempt fails slowly) or the driver takes it back (it fails at once), and every
/// handed-over retry is accounted for.
#[test]
fn speculative_retries_give_the_serial_points() {
    use nonsmooth_modes::continuation::{SequentialOptions, Speculation};
    let values = vec![0.0, 0.1, 0.2, 0.3, 0.4];
    let driver = |patience| {
        let solver = Local { patience };
        Sequential::new(
            Spiky::default(),
            solver,
            vec![0.0],
            values.clone(),
            SequentialOptions::default(),
        )
        .unwrap()
    };
    let mut serial_driver = driver(Default::default());
    let serial = reported(|| serial_driver.step());
    assert!(!serial.is_empty() && serial.iter().all(|p| p.converged));
    // The iterator yields the same converged points.
    let iterated: Vec<Point> = driver(Default::default()).map(Result::unwrap).collect();
    assert_eq!(iterated, serial);
    let every_step = Speculation {
        after_evaluations: 0,
    };
    for patience_ms in [0, 300] {
        let speculative = driver(std::time::Duration::from_millis(patience_ms));
        let mut points = Vec::new();
        let mut speculative = Speculative::new(speculative, every_step);
        let branch = speculative.run(&mut |step: &Step| {
            if let Step::Accepted(p) = step {
                points.push(p.clone());
            }
            ControlFlow::Continue(())
        });
        assert_eq!(branch.end, EndReason::Completed);
        assert_eq!(points, serial);
        assert_eq!(branch.points, serial);
        let stats = speculative.stats();
        // One job per step with a history (steps 1 to 4); only lambda = 0.3 fails first.
        assert_eq!(stats.launched, 4);
        assert_eq!(stats.cancelled, 3);
        assert_eq!(stats.used + stats.taken_back, 1);
        if patience_ms > 0 {
            // The first attempt failed 0.3 s after handing the retry over.
            assert_eq!(stats.used, 1);
        }
    }
    // A retry never handed over: no job, the serial path.
    let never = driver(Default::default());
    let late = Speculation {
        after_evaluations: usize::MAX,
    };
    let (points, stats) = speculative_points(never, late);
    assert_eq!(points, serial);
    assert_eq!(stats, Default::default());
}

/// The clamped bar's 181-step backbone at m = 40 with the `backbone` example's solver,
/// serial (`speculation = None`) or with speculative retries.
fn clamped_backbone_m40(
    options: &BackboneOptions,
    speculation: Option<nonsmooth_modes::continuation::Speculation>,
) -> Vec<BackbonePoint> {
    use nonsmooth_modes::solve::NewtonOptions;
    let system = clamped_bar_with_obstacle(1e-3).unwrap();
    let solver = SemismoothNewton::new(NewtonOptions::fail_fast()).unwrap();
    let request = Request {
        method: Method::PeriodGrid(*options),
        solver: Some(Solver::Newton(solver)),
        speculation,
        ..Request::new(options.mode).harmonics(40)
    };
    compute(&system, &request).unwrap().points
}

/// The paper's grid of the clamped bar (its derived grid, written out).
const PAPER_GRID: PeriodGrid = PeriodGrid {
    start: 3.95,
    end: 3.05,
    steps: 181,
};

/// The points of `driver` stepped with [`Speculative::step`] to the end, and its stats.
fn speculative_points<P, S>(
    driver: Sequential<'_, P, S>,
    speculation: nonsmooth_modes::continuation::Speculation,
) -> (Vec<Point>, nonsmooth_modes::continuation::SpeculationStats)
where
    P: ContinuationProblem + Clone + Send + 'static,
    S: nonsmooth_modes::solve::NonlinearSolver + Clone + Send + 'static,
{
    let mut speculative = Speculative::new(driver, speculation);
    let points = reported(|| speculative.step());
    (points, speculative.stats())
}

/// On the clamped bar at m = 40 (16 first attempts fail, 5 retries converge) the speculative
/// backbone is the serial one, bit for bit.
#[test]
fn speculative_backbone_is_the_serial_backbone() {
    use nonsmooth_modes::continuation::Speculation;
    let options = BackboneOptions::on_grid(PAPER_GRID, 1, 1);
    let serial = clamped_backbone_m40(&options, None);
    assert_eq!(serial.len(), 181);
    assert!(serial.iter().filter(|p| !p.converged()).count() > 0);
    for after_evaluations in [0, 10] {
        let speculation = Some(Speculation { after_evaluations });
        assert_eq!(clamped_backbone_m40(&options, speculation), serial);
    }
}

/// A branch `x = lambda` with a spike `0.45` at `lambda = 0.1` (where the branch is missing)
/// and a high branch `x = lambda + 0.4` from `lambda = 0.2` on; the residual is `x` minus the
/// solution nearest to `x`.
#[derive(Clone, Default)]
struct TwoBranches {
    lambda: f64,
}

impl Problem for TwoBranches {
    fn dimension(&self) -> usize {
        1
    }
    fn residual(&mut self, x: &[f64], f: &mut [f64]) {
        let lambda = self.lambda;
        let roots: Vec<f64> = if (lambda - 0.1).abs() < 1e-12 {
            vec![0.45]
        } else if lambda > 0.15 {
            vec![lambda, lambda + 0.4]
        } else {
            vec![lambda]
        };
        let nearest = roots
            .into_iter()
            .min_by(|a, b| (x[0] - a).abs().total_cmp(&(x[0] - b).abs()))
            .unwrap();
        f[0] = x[0] - nearest;
    }
    fn jacobian(&mut self, _: &[f64], jac: &mut nonsmooth_modes::linalg::DenseMatrix) {
        jac.reset(1, 1);
        jac[(0, 0)] = 1.0;
    }
}

impl ContinuationProblem for TwoBranches {
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

/// `x` of every point of a run, rounded, with its convergence flag.
fn rounded(points: Vec<Point>) -> Vec<(bool, f64)> {
    points
        .into_iter()
        .map(|p| (p.converged, (p.x[0] * 1e9).round() / 1e9))
        .collect()
}

/// Every point a run reports, converged or failed, in order (what a backbone writes): the
/// accepted points and the solver's last iterates of rejected steps.
fn reported(mut step: impl FnMut() -> Step) -> Vec<Point> {
    std::iter::from_fn(|| match step() {
        Step::Finished(_) => None,
        step => Some(step.point().cloned()),
    })
    .flatten()
    .collect()
}

/// [`reported`] of a driver run with `step`.
fn run_points<P: ContinuationProblem, S: nonsmooth_modes::solve::NonlinearSolver>(
    mut driver: Sequential<'_, P, S>,
) -> Vec<Point> {
    reported(|| driver.step())
}

/// After a spike, the last point leads to the high branch and the point before it back to the
/// low one: `Selection::LowestMeasure` keeps the low branch, `FirstConverged` follows the
/// high one. A NaN measure ranks last, and without a measure the rule is `FirstConverged`.
#[test]
fn sequential_lowest_measure_leaves_a_spike_for_the_low_branch() {
    use nonsmooth_modes::continuation::{Selection, SequentialOptions};
    let values = vec![0.0, 0.1, 0.2, 0.3, 0.4];
    let driver = |selection| {
        let options = SequentialOptions {
            retry_depth: 1,
            selection,
            ..Default::default()
        };
        Sequential::new(
            TwoBranches::default(),
            Local::default(),
            vec![0.0],
            values.clone(),
            options,
        )
        .unwrap()
    };
    let on = |xs: [f64; 5]| xs.iter().map(|&x| (true, x)).collect::<Vec<_>>();
    let high = on([0.0, 0.45, 0.6, 0.7, 0.8]);
    let low = on([0.0, 0.45, 0.2, 0.3, 0.4]);
    let first = rounded(run_points(
        driver(Selection::FirstConverged).with_measure(|x, _| x[0]),
    ));
    assert_eq!(first, high);
    let lowest = rounded(run_points(
        driver(Selection::LowestMeasure).with_measure(|x, _| x[0]),
    ));
    assert_eq!(lowest, low);
    // NaN on the low branch ranks it last.
    let nan_low =
        driver(Selection::LowestMeasure)
            .with_measure(|x, _| if x[0] < 0.5 { f64::NAN } else { x[0] });
    assert_eq!(rounded(run_points(nan_low)), high);
    assert_eq!(rounded(run_points(driver(Selection::LowestMeasure))), high);
    assert_eq!(
        SequentialOptions::default().selection,
        Selection::FirstConverged
    );
}

/// With `Selection::LowestMeasure`, `step_speculative` is `step`: the same points, and no
/// speculative retry.
#[test]
fn speculative_lowest_measure_gives_the_serial_points() {
    use nonsmooth_modes::continuation::{Selection, SequentialOptions, Speculation};
    let values = vec![0.0, 0.1, 0.2, 0.3, 0.4];
    for retry_depth in [1, 2] {
        let driver = || {
            let options = SequentialOptions {
                retry_depth,
                selection: Selection::LowestMeasure,
                ..Default::default()
            };
            let solver = Local {
                patience: std::time::Duration::from_millis(20),
            };
            Sequential::new(
                TwoBranches::default(),
                solver,
                vec![0.0],
                values.clone(),
                options,
            )
            .unwrap()
            .with_measure(|x, _| x[0])
        };
        let serial = run_points(driver());
        let speculative = driver();
        let every_step = Speculation {
            after_evaluations: 0,
        };
        let (points, stats) = speculative_points(speculative, every_step);
        assert_eq!(points, serial);
        assert_eq!(rounded(points)[2], (true, 0.2));
        assert_eq!(stats, Default::default());
    }
}

/// On the clamped bar at m = 40 the lowest-energy backbone is the same with and without
/// speculative retries, and differs from the default one.
#[test]
fn speculative_lowest_energy_backbone_is_the_serial_backbone() {
    use nonsmooth_modes::continuation::{Selection, Speculation};
    let options = |selection| BackboneOptions {
        retry_depth: 2,
        selection,
        ..BackboneOptions::on_grid(PAPER_GRID, 1, 1)
    };
    let lowest = options(Selection::LowestMeasure);
    let serial = clamped_backbone_m40(&lowest, None);
    assert_eq!(serial.len(), 181);
    let speculation = Speculation {
        after_evaluations: 0,
    };
    assert_eq!(clamped_backbone_m40(&lowest, Some(speculation)), serial);
    let first = options(Selection::FirstConverged);
    assert_ne!(clamped_backbone_m40(&first, None), serial);
}
