//! Backbones parametrised by energy ([`EnergyLevel`], [`Method::Energy`]) and the robust
//! start of the period backbone, on the clamped bar and on a free-free bar between two walls
//! (whose exact first family is the clamped bar's at half length).

use nonsmooth_modes::bar::Bar;
use nonsmooth_modes::branches::{
    compute, compute_observed, ArclengthBackboneOptions, AutoChoice, BackboneOptions,
    BackbonePoint, EnergyBackboneOptions, EnergyGrid, EnergyLevel, Method, ModeBranches,
    PeriodGrid, PointStatus, Request, CLOSE_START_RATIOS, FLOATING_RETRY_DEPTH, START_RATIOS,
};
use nonsmooth_modes::continuation::{augmented, geomspace, ContinuationProblem};
use nonsmooth_modes::linalg::DenseMatrix;
use nonsmooth_modes::modal::{branch_seed, energy, grazing_energy};
use nonsmooth_modes::reference::{clamped_bar_with_obstacle, robin_bar_with_obstacle};
use nonsmooth_modes::solve::{Problem, Solver, Structured};
use nonsmooth_modes::system::{
    AssemblyBuilder, BarSystem, HarmonicBalanceSettings, NonsmoothSystem,
};
use nonsmooth_modes::{ContinuationError, Error, SettingsError};
use proptest::prelude::*;
use std::f64::consts::PI;
use std::ops::ControlFlow;

const GAP: f64 = 1e-3;

fn settings(harmonics: usize) -> HarmonicBalanceSettings {
    HarmonicBalanceSettings {
        harmonics,
        ..Default::default()
    }
}

/// NSM 1 of `system` with `harmonics` harmonics by `method`, with the full semismooth Newton
/// (the solver these runs have always used).
fn request(harmonics: usize, method: Method) -> Request {
    Request {
        solver: Some(Solver::default()),
        ..Request::new(1).harmonics(harmonics).method(method)
    }
}

/// The paper's grid of the clamped bar (its derived grid, written out).
const PAPER_GRID: PeriodGrid = PeriodGrid {
    start: 3.95,
    end: 3.05,
    steps: 181,
};

/// A unit free-free bar between two rigid walls, gap `GAP` each side.
fn free_free_between_walls() -> BarSystem {
    let mut b = AssemblyBuilder::new();
    let bar = b.add_bar(Bar::unit());
    b.signorini(bar.left(), GAP).unwrap();
    b.signorini(bar.right(), GAP).unwrap();
    b.build().unwrap()
}

/// The exact first family of the free-free bar between walls: `E/E_g = 8 / (pi^2 (2T - 3)^2)`
/// for `T` in `(1.5, 2)`.
fn free_free_exact(period: f64) -> f64 {
    8.0 / (PI * PI * (2.0 * period - 3.0).powi(2))
}

/// The exact first family of the clamped bar: `E/E_g = 8 / (pi^2 (T - 3)^2)`.
fn clamped_exact(period: f64) -> f64 {
    8.0 / (PI * PI * (period - 3.0).powi(2))
}

/// An energy-level problem of `system` at level `level` and a point `y = (x, Omega)` whose
/// contact penetrates, with a deterministic perturbation of every unknown.
fn level_problem_and_point(system: &BarSystem, level: f64) -> (EnergyLevel, Vec<f64>) {
    let mut problem = NonsmoothSystem::new(system, settings(6)).unwrap();
    let (e_g, _) = grazing_energy(system).unwrap();
    let omega = 1.02 * 2.0 * PI / 4.0;
    let seed = branch_seed(&mut problem, 1, 1, omega).unwrap();
    let x: Vec<f64> = (seed.iter().enumerate())
        .map(|(i, s)| 1.4 * s + 1e-5 * (((7 * i) % 11) as f64 - 5.0))
        .collect();
    let y = augmented::join(x, omega);
    let mut level_problem = EnergyLevel::new(problem, e_g).unwrap();
    level_problem.set_parameter(level);
    (level_problem, y)
}

/// The bordered Jacobian (harmonic balance, `dF/dOmega`, the energy row) against central
/// differences of the residual, where no time sample changes branch over the difference.
#[test]
fn energy_level_jacobian_matches_finite_differences() {
    for system in [
        clamped_bar_with_obstacle(GAP).unwrap(),
        robin_bar_with_obstacle(0.5, GAP).unwrap(),
    ] {
        let (mut problem, y) = level_problem_and_point(&system, 1.3);
        let n = problem.dimension();
        let mut jac = DenseMatrix::zeros(n, n);
        problem.jacobian(&y, &mut jac);
        let mut f0 = vec![0.0; n];
        problem.residual(&y, &mut f0);
        let (mut up, mut down) = (vec![0.0; n], vec![0.0; n]);
        let mut worst: f64 = 0.0;
        let mut size: f64 = 0.0;
        for j in 0..n {
            let h = 1e-7 * y[j].abs().max(1e-6);
            let mut probe = y.clone();
            probe[j] += h;
            problem.residual(&probe, &mut up);
            probe[j] -= 2.0 * h;
            problem.residual(&probe, &mut down);
            for i in 0..n {
                let fd = (up[i] - down[i]) / (2.0 * h);
                worst = worst.max((fd - jac[(i, j)]).abs());
                size = size.max(jac[(i, j)].abs());
            }
        }
        assert!(worst <= 1e-5 * size, "worst {worst:e} of {size:e}");
    }
}

/// Below the first internal resonance of the truncated system, every point of the energy
/// backbone meets its energy level, touches, and follows the exact family within 8 %
/// (`m = 20`; the period grid's points there are as far off, the error of the truncation).
#[test]
fn energy_backbone_of_the_clamped_bar_follows_the_exact_family_to_the_first_resonance() {
    let system = clamped_bar_with_obstacle(GAP).unwrap();
    let options = EnergyBackboneOptions {
        levels: EnergyGrid {
            start: 1.0,
            end: 1.15,
            steps: 6,
        },
        ..EnergyBackboneOptions::for_mode(&system, 1, 1).unwrap()
    };
    let run = compute(&system, &request(20, Method::Energy(options))).unwrap();
    assert!(run.error().is_none(), "{:?}", run.end);
    assert!(
        run.converged().count() >= 6,
        "{} points",
        run.converged().count()
    );
    for p in run.converged() {
        assert_eq!(p.status, PointStatus::Converged);
        let exact = clamped_exact(p.period);
        assert!(
            (p.energy_normalized / exact - 1.0).abs() < 0.08,
            "T = {}: E/E_g {} vs exact {exact}",
            p.period,
            p.energy_normalized
        );
    }
    // Each point after the start sits on its level: the energy row is solved.
    let levels: Vec<f64> = run
        .converged()
        .skip(1)
        .map(|p| p.energy_normalized)
        .collect();
    let grid = geomspace(1.0, 1.15, 6).unwrap();
    assert_eq!(levels.len(), grid.len());
    for (got, want) in levels.iter().zip(grid) {
        assert!((got - want).abs() < 1e-9 * want, "{got} vs {want}");
    }
}

#[test]
fn energy_levels_must_be_positive() {
    let system = clamped_bar_with_obstacle(GAP).unwrap();
    for (start, end) in [(0.0, 2.0), (1.0, f64::NAN), (-1.0, 3.0)] {
        let options = EnergyBackboneOptions {
            levels: EnergyGrid {
                start,
                end,
                steps: 5,
            },
            ..EnergyBackboneOptions::for_mode(&system, 1, 1).unwrap()
        };
        let run = compute(&system, &request(8, Method::Energy(options)));
        assert!(
            matches!(
                &run,
                Err(Error::Settings(SettingsError::Range(r))) if r.what == "energy grid"
            ),
            "{start}..{end}: {run:?}"
        );
    }
    let problem = NonsmoothSystem::new(&system, settings(4)).unwrap();
    assert!(EnergyLevel::new(problem, f64::NAN).is_err());
}

/// `augmented::split` reads the layout of an energy-level problem's unknowns.
#[test]
fn energy_level_unknowns_end_with_the_frequency() {
    let system = clamped_bar_with_obstacle(GAP).unwrap();
    let (problem, y) = level_problem_and_point(&system, 1.0);
    let (x, omega) = augmented::split(&y).unwrap();
    assert_eq!(x.len() + 1, problem.dimension());
    assert_eq!(omega, y[y.len() - 1]);
    let e = energy(&system, problem.inner().basis(), x, omega);
    assert!(e > 0.0);
}

/// The free-free bar between walls: its grazing seed slides to a rigid-body rest against a
/// wall at every period, so the period backbone starts from a seed that penetrates a little
/// at a slightly higher frequency, walked back to the grid's start. With the system's default
/// options (`BackboneOptions::for_mode`: a second retry, the clamped bar's defaults otherwise),
/// at `m = 20` and `m = 40` at least 90 % of its points converge, none at rest, and at least
/// 45 % of them lie within 5 % of the exact family (half at `m = 20`).
#[test]
fn free_free_bar_between_walls_has_a_period_backbone() {
    let system = free_free_between_walls();
    let options = BackboneOptions::for_mode(&system, 1, 1).unwrap();
    assert!((options.grid.start - 1.975).abs() < 1e-12);
    assert_eq!(options.retry_depth, FLOATING_RETRY_DEPTH);
    let clamped = clamped_bar_with_obstacle(GAP).unwrap();
    assert_eq!(
        BackboneOptions::for_mode(&clamped, 1, 1).unwrap(),
        BackboneOptions::on_grid(PAPER_GRID, 1, 1)
    );
    for (m, on_branch_share) in [(20, 0.5), (40, 0.45)] {
        let run = compute(&system, &request(m, Method::PeriodGrid(options))).unwrap();
        let converged: Vec<_> = run.converged().collect();
        assert!(
            converged.len() * 10 >= run.points.len() * 9,
            "m = {m}: {} of {}",
            converged.len(),
            run.points.len()
        );
        let on_branch = converged
            .iter()
            .filter(|p| (p.energy_normalized / free_free_exact(p.period) - 1.0).abs() < 0.05)
            .count();
        assert!(
            on_branch as f64 >= on_branch_share * converged.len() as f64,
            "m = {m}: {on_branch} of {}",
            converged.len()
        );
        assert!(converged.iter().all(|p| p.energy_normalized > 0.5));
    }
}

/// Over the whole default range (`E/E_g` from 1 to 300), the energy backbone of the clamped
/// bar follows the exact family as well as the period grid does: the fraction of its
/// converged points within 5 % of the exact energy is at least the period grid's less 5
/// points (`m = 20`), and no converged point sits at rest.
#[test]
fn energy_backbone_of_the_clamped_bar_is_as_faithful_as_the_period_grid() {
    let system = clamped_bar_with_obstacle(GAP).unwrap();
    let within = |points: Vec<(f64, f64)>| {
        let good = points
            .iter()
            .filter(|(t, e)| *t > 3.0 && (e / clamped_exact(*t) - 1.0).abs() < 0.05)
            .count();
        good as f64 / points.len() as f64
    };
    let energy_options = EnergyBackboneOptions::for_mode(&system, 1, 1).unwrap();
    let by_energy = compute(&system, &request(20, Method::Energy(energy_options))).unwrap();
    let grid = BackboneOptions::on_grid(PAPER_GRID, 1, 1);
    let by_period = compute(&system, &request(20, Method::PeriodGrid(grid))).unwrap();
    let points = |run: &ModeBranches| {
        run.converged()
            .map(|p| (p.period, p.energy_normalized))
            .collect::<Vec<_>>()
    };
    let (e, p) = (points(&by_energy), points(&by_period));
    assert!(e.len() >= 150, "{} converged points", e.len());
    assert!(e.iter().all(|(_, level)| *level > 0.5));
    let (fe, fp) = (within(e), within(p));
    assert!(
        fe >= fp - 0.05,
        "within 5 %: energy {fe:.3}, period {fp:.3}"
    );
}

/// The three-bar chain (bar 2 held only by its contacts): its start adds the floating bar's
/// rigid-body motion to the seed of the last bar's mode. The energy backbone starts, and its
/// converged points are motions in which the floating bar touches both neighbours.
#[test]
fn the_chain_with_a_floating_bar_starts_and_its_points_touch_both_contacts() {
    let system = nonsmooth_modes::reference::contact_chain(3, GAP, 0.5).unwrap();
    let options = EnergyBackboneOptions::for_mode(&system, 1, 1).unwrap();
    let run = compute(&system, &request(20, Method::Energy(options))).unwrap();
    let converged: Vec<_> = run.converged().cloned().collect();
    assert!(converged.len() >= 50, "{} converged", converged.len());
    assert_every_contact_touches(&system, &converged);
}

/// Every point of `points` (`m = 20`) has at least one contact interval per period at every
/// law and lies above the grazing energy.
fn assert_every_contact_touches(system: &BarSystem, points: &[BackbonePoint]) {
    let mut problem = NonsmoothSystem::new(system, settings(20)).unwrap();
    for p in points {
        assert!(
            p.energy_normalized > 1.0,
            "step {}: {}",
            p.step,
            p.energy_normalized
        );
        let intervals =
            nonsmooth_modes::modal::contact_intervals(&mut problem, &p.x, p.omega).unwrap();
        assert!(
            intervals.iter().all(|&n| n >= 1),
            "step {}: {intervals:?}",
            p.step
        );
    }
}

/// The chain's branch cannot be entered at the period grid's first period: its start is found
/// at a higher frequency only (`Method::Auto` says so and runs pseudo-arclength, which begins
/// with the start, a solution), while the branches of the clamped bar and of the free-free bar
/// between walls are entered where asked (and run on the period grid).
#[test]
fn the_chains_start_lies_above_the_grids_first_frequency() {
    let auto = request(20, Method::Auto(None));
    let chain = nonsmooth_modes::reference::contact_chain(3, GAP, 0.5).unwrap();
    let omega = 2.0 * PI / PeriodGrid::for_mode(&chain, 1, 1).unwrap().start;
    let run = compute(&chain, &auto).unwrap();
    let entered_at = match run.auto {
        Some(AutoChoice::EnteredAtShorterPeriod { entered_at }) => entered_at,
        other => panic!("{other:?}"),
    };
    let start_omega = 2.0 * PI / entered_at;
    assert!(start_omega > omega, "{start_omega} {omega}");
    assert!(
        matches!(run.method, Method::Arclength(_)),
        "{:?}",
        run.method
    );
    // The start is a point of the run, and a solution.
    let start = run
        .points
        .iter()
        .find(|p| (p.omega - start_omega).abs() <= 1e-12 * start_omega)
        .unwrap_or_else(|| panic!("no point at the start, Omega = {start_omega}"));
    // The equations the run solved: Auto may have kept them under harmonic selection.
    let mut problem = run.problem().clone();
    problem.set_parameter(start.omega);
    let mut f = vec![0.0; start.x.len()];
    problem.residual(&start.x, &mut f);
    let tolerance = 1e-9 * problem.residual_scale();
    assert!(f.iter().map(|v| v * v).sum::<f64>().sqrt() <= tolerance);
    // The other systems' choice is made before their first point: stop there.
    let first_point_only = |_: &BackbonePoint| ControlFlow::Break(());
    for system in [
        clamped_bar_with_obstacle(GAP).unwrap(),
        free_free_between_walls(),
    ] {
        let run = compute_observed(&system, &auto, first_point_only).unwrap();
        assert_eq!(run.auto, Some(AutoChoice::EnteredAtGridStart));
        assert!(matches!(run.method, Method::PeriodGrid(_)));
    }
    // A start frequency that is not positive is refused (the old start search's
    // `NotPositive`; through a request the frequency is the seed period of the options).
    let options = ArclengthBackboneOptions {
        start_period: -1.0,
        ..ArclengthBackboneOptions::for_mode(&chain, 1, 1).unwrap()
    };
    assert!(matches!(
        compute(&chain, &request(20, Method::Arclength(options))),
        Err(Error::Continuation(ContinuationError::InvalidOption { value, .. })) if value == -1.0
    ));
    // A floor that is not a number is refused before any start search.
    let options = BackboneOptions {
        trivial_energy: f64::NAN,
        ..BackboneOptions::for_mode(&chain, 1, 1).unwrap()
    };
    assert!(matches!(
        compute(&chain, &request(20, Method::PeriodGrid(options))),
        Err(Error::Continuation(ContinuationError::InvalidOption {
            what: "trivial_energy",
            ..
        }))
    ));
}

/// The chain's pseudo-arclength backbone starts from the same robust guesses as the period
/// backbone, at the frequency where they converge (the grazing seed meets a singular Jacobian:
/// with every contact open the floating bar's mean position is free), and walks its branch
/// back to the asked start first: the run covers the range from the grid's first period to its
/// last, its steps are numbered in order, every accepted point touches both contacts and none
/// sits at rest.
#[test]
fn the_chains_arclength_backbone_starts_where_its_guesses_converge() {
    let system = nonsmooth_modes::reference::contact_chain(3, GAP, 0.5).unwrap();
    let options = ArclengthBackboneOptions::for_mode(&system, 1, 1).unwrap();
    let grid = PeriodGrid::for_mode(&system, 1, 1).unwrap();
    let mut points = Vec::new();
    let observer = |p: &BackbonePoint| {
        points.push(p.clone());
        ControlFlow::Continue(())
    };
    let run =
        compute_observed(&system, &request(20, Method::Arclength(options)), observer).unwrap();
    assert!(
        points.len() >= 200,
        "{} points, end {:?}",
        points.len(),
        run.end
    );
    let (first, last) = (&points[0], &points[points.len() - 1]);
    let span = grid.start - grid.end;
    assert!(first.period > grid.start - 0.05 * span, "{}", first.period);
    assert!(last.period < grid.end + 0.1 * span, "{}", last.period);
    assert!(points.windows(2).all(|w| w[1].step > w[0].step));
    assert_eq!(run.points, points);
    assert_every_contact_touches(&system, &points);
}

/// NSM `mode` of the unit clamped bar facing a clamped bar 2 of length `l2`, wave speed `c2`
/// and stiffness `ea2` across `GAP`, in the energy from the mode's grazing level, `m = 20`.
fn against_partner(l2: f64, c2: f64, ea2: f64, mode: usize) -> ModeBranches {
    let second = Bar::new(l2, c2, ea2).unwrap();
    let system = nonsmooth_modes::reference::two_bars_in_contact(second, GAP).unwrap();
    let options = EnergyBackboneOptions::for_mode(&system, mode, 1).unwrap();
    let request = Request {
        mode,
        ..request(20, Method::Energy(options))
    };
    compute(&system, &request).unwrap()
}

/// Against a soft partner (the paper's configuration 2, bar 2 four times softer), the first
/// mode of bar 1 (system mode 1) and its second (system mode 3) harden so little that at the
/// usual start frequencies their motions lie far above the grazing seed: the start's closer
/// frequencies ([`CLOSE_START_RATIOS`]) enter both, and every level converges just above the
/// linear frequency.
#[test]
fn a_bar_against_a_soft_partner_starts_near_its_linear_frequency() {
    for (mode, linear) in [(1, PI / 2.0), (3, 1.5 * PI)] {
        let run = against_partner(3.8, 4.0, 0.25, mode);
        let start = run.points.first().expect("a start");
        let ratio = start.omega / linear;
        assert!(
            ratio < START_RATIOS[0]
                && CLOSE_START_RATIOS
                    .iter()
                    .any(|r| (ratio / r - 1.0).abs() < 1e-12),
            "mode {mode}: start at {ratio} times the linear frequency"
        );
        let converged = run.converged().count();
        assert!(
            converged >= 20,
            "mode {mode}: {converged} converged, {:?}",
            run.end
        );
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    /// The first mode of the unit clamped bar against a partner of any length whose first
    /// frequency lies above bar 1's (so that system mode 1 is bar 1's), and softer than it
    /// (`EA_2` from 1/50 to 1/4): the energy backbone starts, and its points harden.
    #[test]
    fn bar_1_against_any_soft_partner_starts(
        l2 in 0.5f64..4.0,
        ratio in 1.3f64..3.0,
        ea2 in 0.02f64..0.25,
    ) {
        let c2 = ratio * l2;
        let run = against_partner(l2, c2, ea2, 1);
        prop_assert!(
            !matches!(run.error(), Some(e) if e.to_string().contains("no start")),
            "{:?}",
            run.end
        );
        let converged: Vec<&BackbonePoint> = run.converged().collect();
        prop_assert!(!converged.is_empty(), "{:?}", run.end);
        for p in converged {
            prop_assert!(p.omega > PI / 2.0, "Omega {} below the linear frequency", p.omega);
        }
    }
}
