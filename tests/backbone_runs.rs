//! A backbone run keeps everything it computed: a run that stalls returns its points, each
//! with its status, and the reason it ended.

use nonsmooth_modes::branches::{
    compute, AutoChoice, BackboneOptions, Method, ModeBranches, PeriodGrid, PointStatus, Request,
};
use nonsmooth_modes::continuation::EndReason;
use nonsmooth_modes::reference::clamped_bar_with_obstacle;
use nonsmooth_modes::solve::Solver;
use nonsmooth_modes::system::{BarSystem, HarmonicBalanceSettings};
use nonsmooth_modes::{ContinuationError, Error, SettingsError};

/// The period grid `options` with the full semismooth Newton (the solver these runs have
/// always used).
fn grid_run(
    system: &BarSystem,
    settings: HarmonicBalanceSettings,
    options: BackboneOptions,
) -> Result<ModeBranches, Error> {
    let method = Method::PeriodGrid(options);
    let request = Request::for_method(method)
        .settings(settings)
        .solver(Solver::default());
    compute(system, &request)
}

/// The paper's grid of the clamped bar (its derived grid, written out).
const PAPER_GRID: PeriodGrid = PeriodGrid {
    start: 3.95,
    end: 3.05,
    steps: 181,
};

/// A grid on which no branch can be entered is refused with what the start search tried,
/// not run as points at rest: the clamped bar on periods near `T = 9`, more than twice its
/// linear period, where no nonsmooth mode of the first family exists and no harmonic of the
/// truncated system resonates.
#[test]
fn a_grid_without_a_branch_is_refused_with_what_was_tried() {
    let system = clamped_bar_with_obstacle(1e-3).unwrap();
    let grid = PeriodGrid {
        start: 9.1,
        end: 8.9,
        steps: 30,
    };
    let options = BackboneOptions::on_grid(grid, 1, 1);
    let settings = HarmonicBalanceSettings {
        harmonics: 10,
        ..Default::default()
    };
    match grid_run(&system, settings, options) {
        Err(Error::Settings(SettingsError::StartNotFound {
            omega,
            up_to,
            attempts,
            at_rest,
            failed,
        })) => {
            assert!((omega - 2.0 * std::f64::consts::PI / 9.1).abs() < 1e-12);
            assert!(up_to > omega);
            assert!(attempts > 1);
            assert_eq!(at_rest + failed, attempts);
        }
        other => panic!("{other:?}"),
    }
}

/// A run that stalls returns every point it computed, each with its status, and ends with
/// `Stalled` after `max_consecutive_failures` failures: the clamped bar's first family on a
/// grid that runs past `T = 3`, where its energy `8 / (pi^2 (T - 3)^2)` blows up and the
/// family ends.
#[test]
fn a_stalled_run_keeps_its_points_and_says_why() {
    let system = clamped_bar_with_obstacle(1e-3).unwrap();
    let grid = PeriodGrid {
        start: 3.5,
        end: 2.5,
        steps: 41,
    };
    let options = BackboneOptions {
        max_consecutive_failures: 6,
        ..BackboneOptions::on_grid(grid, 1, 1)
    };
    let settings = HarmonicBalanceSettings {
        harmonics: 10,
        ..Default::default()
    };
    let run = grid_run(&system, settings, options).unwrap();
    match (&run.end, run.error()) {
        (EndReason::Stalled { failures, .. }, Some(ContinuationError::Stalled { .. })) => {
            assert_eq!(*failures, 6);
        }
        other => panic!("{other:?}"),
    }
    assert!(run.converged().count() >= 5);
    assert!(run.points.len() < 41);
    for p in &run.points {
        assert_eq!(p.converged(), p.status == PointStatus::Converged);
        assert!(p.x.iter().all(|v| v.is_finite()));
    }
    // The last points are the failures that stalled it.
    assert!(run.points.iter().rev().take(6).all(|p| !p.converged()));
    assert!(run.grazing_energy > 0.0);
}

/// A run that completes says so; its statuses agree with `converged`, and the failed steps
/// of the clamped bar at m = 20 are solver failures carrying the solver's error.
#[test]
fn a_completed_run_reports_each_step_status() {
    let system = clamped_bar_with_obstacle(1e-3).unwrap();
    let run = grid_run(
        &system,
        HarmonicBalanceSettings::default(),
        BackboneOptions::on_grid(PAPER_GRID, 1, 1),
    )
    .unwrap();
    assert_eq!(run.end, EndReason::Completed);
    assert_eq!(run.error(), None);
    assert_eq!(run.points.len(), 181);
    for p in &run.points {
        assert_eq!(p.converged(), p.status == PointStatus::Converged);
        if let PointStatus::SolverFailed(e) = &p.status {
            assert!(!e.to_string().is_empty());
        }
    }
    assert!(run.converged().count() >= 170);
}

/// A start search that finds nothing stops after a bounded number of solves and says what
/// they came to: a chain of three unequal bars held only by contacts (walls at both outer
/// ends), whose first family does not leave its grazing point. At most two solves (plain,
/// then in the smoothing homotopy) per guess: the seed at each frequency and amplitude, and
/// with each bar's rigid-body motion added at each of the rigid amplitudes. The search is
/// that of the period grid at the first period of the system's grid, `0.9875` of its linear
/// period; the grid then run from the unsolved seed converges nowhere either, and the run
/// is refused with the search's error. `Method::Auto` also reaches a start through the
/// tethered system (the contacts tied by springs lowered to zero), and keeps that run.
#[test]
fn a_failed_start_search_is_bounded_and_says_why() {
    use nonsmooth_modes::bar::Bar;
    use nonsmooth_modes::branches::{
        linear_period, FLOATING_AMPLITUDES, FLOATING_RATIOS, RIGID_AMPLITUDES, START_AMPLITUDES,
        START_RATIOS,
    };
    use nonsmooth_modes::system::AssemblyBuilder;
    let mut b = AssemblyBuilder::new();
    let bars = [(1.0, 1.0, 1.0), (1.3, 0.8, 1.5), (0.7, 1.2, 0.9)];
    let ids: Vec<_> = bars
        .iter()
        .map(|&(l, c, k)| b.add_bar(Bar::new(l, c, k).unwrap()))
        .collect();
    b.signorini(ids[0].left(), 1e-3).unwrap();
    b.contact(ids[0].right(), ids[1].left(), 1e-3).unwrap();
    b.contact(ids[1].right(), ids[2].left(), 1e-3).unwrap();
    b.signorini(ids[2].right(), 1e-3).unwrap();
    let system = b.build().unwrap();
    let settings = HarmonicBalanceSettings {
        harmonics: 8,
        ..Default::default()
    };
    let omega = 2.0 * std::f64::consts::PI / (linear_period(&system, 1, 1).unwrap() * 0.9875);
    let ratios = START_RATIOS.len() + FLOATING_RATIOS.len();
    let amplitudes = START_AMPLITUDES.len() + FLOATING_AMPLITUDES.len();
    // Each guess around the seed, each with each rigid-body mode added, and the closing
    // guesses: the four gaps are closed by the seed and the three rigid-body modes in one way
    // (one subset of four laws), at each ratio and amplitude.
    let closing = ratios * amplitudes;
    let guesses = ratios * amplitudes * (1 + bars.len() * RIGID_AMPLITUDES.len()) + closing;
    let grid = BackboneOptions::for_mode(&system, 1, 1).unwrap();
    let request = Request {
        settings,
        solver: Some(Solver::default()),
        ..Request::new(1).method(Method::PeriodGrid(grid))
    };
    match compute(&system, &request) {
        Err(Error::Settings(SettingsError::StartNotFound {
            attempts,
            at_rest,
            failed,
            up_to,
            ..
        })) => {
            assert!(
                attempts <= 1 + 2 * guesses,
                "{attempts} > 1 + 2 x {guesses}"
            );
            assert_eq!(at_rest + failed, attempts);
            assert!(up_to > omega);
        }
        other => panic!("{other:?}"),
    }
    let auto = Request {
        method: Method::Auto(None),
        ..request
    };
    let run = compute(&system, &auto).unwrap();
    assert!(
        matches!(
            run.auto,
            Some(AutoChoice::Tethered {
                searched_good: 0,
                ..
            })
        ),
        "{:?}",
        run.auto
    );
    assert!(run.converged().count() > 0);
}

/// Counts what an arclength backbone's observer sees.
#[derive(Default)]
struct Seen {
    points: usize,
    rejected: usize,
}

impl nonsmooth_modes::branches::BackboneObserver for &mut Seen {
    fn point(&mut self, _: &nonsmooth_modes::branches::BackbonePoint) -> std::ops::ControlFlow<()> {
        self.points += 1;
        std::ops::ControlFlow::Continue(())
    }
    fn rejected(
        &mut self,
        _: &nonsmooth_modes::continuation::Rejection,
    ) -> std::ops::ControlFlow<()> {
        self.rejected += 1;
        std::ops::ControlFlow::Continue(())
    }
}

/// The reliability reproducer of an observer that missed steps: an arclength backbone whose
/// start lies beyond the asked period first walks back to it, and the walk's rejected steps
/// were counted in `rejected_steps` but never handed to `BackboneObserver::rejected`. On the
/// contact chain (whose start converges only at a higher frequency) with the library's
/// default options, the observer now sees every point and every rejection counted.
#[test]
fn an_arclength_observer_sees_every_rejection_counted() {
    use nonsmooth_modes::branches::{compute_observed, ArclengthBackboneOptions};
    let system = nonsmooth_modes::reference::contact_chain(3, 1e-3, 0.5).unwrap();
    let options = ArclengthBackboneOptions::for_mode(&system, 1, 1).unwrap();
    let request =
        Request::for_method(Method::Arclength(options)).settings(HarmonicBalanceSettings {
            harmonics: 10,
            ..Default::default()
        });
    let mut seen = Seen::default();
    let run = compute_observed(&system, &request, &mut seen).unwrap();
    eprintln!(
        "{} points, {} rejected, end {:?}; seen {} and {}",
        run.points.len(),
        run.rejected_steps,
        run.end,
        seen.points,
        seen.rejected
    );
    assert_eq!(seen.points, run.points.len());
    assert_eq!(seen.rejected, run.rejected_steps);
    // The walk back ran: the first point lies at the asked period's end of the range.
    assert!(run.points.len() > 1);
}

/// The reliability reproducer of `Method::Auto`'s unbounded arclength: a request of 6 steps
/// returned 274 to 304 points from the driver's default budget. On the contact chain, where
/// Auto enters the branch at a shorter period and runs pseudo-arclength over the grid's
/// range, its steps and rejections are now at most 4 per grid step (the walk back to the
/// first period within the same), whatever it chooses.
#[test]
fn auto_keeps_its_arclength_within_the_grids_steps() {
    let system = nonsmooth_modes::reference::contact_chain(3, 1e-3, 0.5).unwrap();
    let mut grid = BackboneOptions::for_mode(&system, 1, 1).unwrap();
    grid.grid.steps = 6;
    let request = Request::for_method(Method::Auto(Some(grid))).settings(HarmonicBalanceSettings {
        harmonics: 10,
        ..Default::default()
    });
    let run = compute(&system, &request).unwrap();
    eprintln!(
        "{} points by {}, {:?}, end {:?}",
        run.points.len(),
        run.method.name(),
        run.auto,
        run.end
    );
    if let Method::Arclength(options) = run.method {
        assert!(options.arclength.max_steps <= 24, "{options:?}");
        assert!(options.arclength.max_rejections <= 24, "{options:?}");
    }
    // The run and the walk back, 24 steps each, and the start.
    assert!(
        run.points.len() <= 2 * 24 + 1,
        "{} points",
        run.points.len()
    );
}

/// Records every call of an arclength backbone's observer, which stops the run at the first
/// rejected step.
#[derive(Default)]
struct StopAtFirstRejection {
    calls: Vec<&'static str>,
    points: Vec<nonsmooth_modes::branches::BackbonePoint>,
}

impl nonsmooth_modes::branches::BackboneObserver for &mut StopAtFirstRejection {
    fn point(&mut self, p: &nonsmooth_modes::branches::BackbonePoint) -> std::ops::ControlFlow<()> {
        self.calls.push("point");
        self.points.push(p.clone());
        std::ops::ControlFlow::Continue(())
    }
    fn rejected(
        &mut self,
        _: &nonsmooth_modes::continuation::Rejection,
    ) -> std::ops::ControlFlow<()> {
        self.calls.push("rejected");
        std::ops::ControlFlow::Break(())
    }
}

/// The stress suite's finding (case 4941 of the default seed, inputs as drawn): an observer
/// that stops an arclength backbone at its first rejected step, while a point was held as a
/// possible spike, was then shown that point; the run said `StoppedByObserver` although the
/// observer's last answer was to go on. An observer that has stopped is not called again,
/// and the run's points are those it saw.
#[test]
fn an_observer_that_stops_on_a_rejection_is_not_called_again() {
    use nonsmooth_modes::branches::{compute_observed, ArclengthBackboneOptions, StallEscape};
    use nonsmooth_modes::continuation::{ArclengthOptions, ArclengthScale, TangentPredictor};
    use nonsmooth_modes::solve::{Dogleg, DoglegOptions};
    let system = clamped_bar_with_obstacle(0.00010811265993992226).unwrap();
    let ds_max = 0.3836144297016708;
    let arclength = ArclengthOptions {
        ds: 0.03367528456678734_f64.min(ds_max),
        ds_min: 2.8896994861669082e-5,
        ds_max,
        max_steps: 7,
        parameter_range: (1.1087981864354337, 2.5563170360189047),
        direction: -1.0,
        predictor: TangentPredictor::Tangent,
        scale: ArclengthScale::Automatic,
        fast_iterations: 2,
        growth: 1.3670840591659206,
        shrink: 0.9,
        jump_ratio: 0.5123090625699462,
        max_turn: 2.760804042368901,
        max_rejections: 20,
        branch_points: true,
    };
    let options = ArclengthBackboneOptions {
        start_period: 3.4926567040475662,
        omega_range: (1.5314368229206208, 2.2996806013633053),
        mode: 2,
        subharmonic: 1,
        arclength,
        escape: Some(StallEscape {
            window: 6,
            min_progress: 0.04370157627158541,
            jump: 0.005414569756419893,
            max_attempts: 1,
            max_norm_ratio: 3.972210294899639,
        }),
        trivial_energy: 0.0008283180787236014,
        switch: None,
    };
    let solver = Dogleg::new(DoglegOptions {
        tolerance: 2.56777836333579e-10,
        max_iterations: usize::MAX,
        initial_radius: 2.006106841075849,
        min_radius: 3.1042709275971484e-5,
    })
    .unwrap();
    let request = Request {
        settings: HarmonicBalanceSettings {
            harmonics: 3,
            samples_per_harmonic: 4,
            complementarity: 0.13369673726781137,
            ..Default::default()
        },
        method: Method::Arclength(options),
        solver: Some(Solver::Dogleg(solver)),
        ..Request::new(2).subharmonic(1)
    };
    let mut observer = StopAtFirstRejection::default();
    let run = compute_observed(&system, &request, &mut observer).unwrap();
    eprintln!("{:?}; end {:?}", observer.calls, run.end);
    if let Some(k) = observer.calls.iter().position(|c| *c == "rejected") {
        assert_eq!(k + 1, observer.calls.len(), "{:?}", observer.calls);
        assert_eq!(run.end, EndReason::StoppedByObserver);
    } else {
        assert_ne!(run.end, EndReason::StoppedByObserver);
    }
    assert_eq!(observer.points, run.points);
}
