//! Exact branches (`nonsmooth_modes::exact`): the clamped bar's and the free–free bar's
//! branches against their exact families, verdicts against the grid and the gap, and bad
//! input. Checks that can fail: the families are closed forms, not recorded results.

use nonsmooth_modes::bar::Bar;
use nonsmooth_modes::branches::{compute, BackboneOptions, Method, PeriodGrid, Request};
use nonsmooth_modes::exact::{exact_branch, ExactBranch, ExactEnd, ExactOptions};
use nonsmooth_modes::io::assembly::Assembly;
use nonsmooth_modes::reference::{
    clamped_bar_with_obstacle, two_bars_in_contact, ClampedFirstMode,
};
use nonsmooth_modes::stability::{StabilityError, StabilityOptions, Verdict};
use nonsmooth_modes::system::BarSystem;
use nonsmooth_modes::{Error, SettingsError};
use std::f64::consts::PI;

/// The period-grid request of NSM 1 of `system` over `start -> end` in `steps` periods.
fn request(system: &BarSystem, start: f64, end: f64, steps: usize) -> Request {
    let grid = BackboneOptions {
        grid: PeriodGrid { start, end, steps },
        ..BackboneOptions::for_mode(system, 1, 1).unwrap()
    };
    Request::new(1).method(Method::PeriodGrid(grid))
}

fn options(cells: f64) -> ExactOptions {
    ExactOptions {
        stability: StabilityOptions {
            cells_per_travel: cells,
            ..StabilityOptions::default()
        },
        ..ExactOptions::default()
    }
}

/// The verdict of every point, `None` where unresolved.
fn verdicts(branch: &ExactBranch) -> Vec<(usize, Option<bool>)> {
    branch
        .points
        .iter()
        .map(|p| {
            let f = p.point.stability.as_ref().unwrap().as_ref().unwrap();
            (p.point.step, f.verdict.stable())
        })
        .collect()
}

/// Every point carries its multipliers, and a verdict or the reason there is none; the
/// share of the `steps` grid periods with a point within 0.5 % of `family(T)` (in `E / E_g`,
/// at the point's own period).
fn share_within(branch: &ExactBranch, steps: usize, family: impl Fn(f64) -> f64) -> f64 {
    for p in &branch.points {
        let f = p.point.stability.as_ref().unwrap().as_ref().unwrap();
        assert_eq!(
            f.verdict == Verdict::Unresolved,
            f.unresolved.is_some(),
            "T = {}: {f:?}",
            p.point.period
        );
        assert!(p.point.energy.is_finite() && p.removed_energy.is_finite());
        // Periodic in the time domain too: the cell means of the coordinates repeat to
        // `1e-8`, the waves themselves (breakpoints inside cells included) to `1e-5`.
        let report = p.point.time_domain.unwrap();
        assert!(report.defect < 1e-5, "T = {}: {report:?}", p.point.period);
        assert!(report.displacement_defect < 1e-8, "{report:?}");
    }
    let close = branch
        .points
        .iter()
        .filter(|p| {
            let exact = family(p.point.period);
            (p.point.energy_normalized / exact - 1.0).abs() <= 5e-3
        })
        .count();
    close as f64 / steps as f64
}

/// The clamped bar: at least 90 % of the grid's periods have an exact point within 0.5 % of
/// the exact family `E / E_g = 8 / (pi^2 (T - 3)^2)`, with one contact per period.
#[test]
fn clamped_branch_follows_the_exact_family() {
    let system = clamped_bar_with_obstacle(1e-3).unwrap();
    let steps = 31;
    let branch = exact_branch(
        &system,
        &request(&system, 3.95, 3.80, steps),
        &options(200.0),
    )
    .unwrap();
    let share = share_within(&branch, steps, |t| {
        ClampedFirstMode::new(1e-3, t).energy_normalized()
    });
    assert!(share >= 0.9, "{share}: {:?}", branch.skipped);
    assert!(branch.points.iter().all(|p| p.contacts == vec![1]));
    every_point_has_a_verdict(&branch);
}

/// At least 95 % of the points have a verdict (every other one its reason, checked by
/// [`share_within`]); those the grid damps (periods of an odd number of steps) say by how
/// much, within the bound.
fn every_point_has_a_verdict(branch: &ExactBranch) {
    let resolved = verdicts(branch).iter().filter(|v| v.1.is_some()).count();
    assert!(
        resolved as f64 >= 0.95 * branch.points.len() as f64,
        "{:?}",
        verdicts(branch)
    );
    let bound = StabilityOptions::default().max_damping;
    for p in &branch.points {
        let f = p.point.stability.as_ref().unwrap().as_ref().unwrap();
        assert!(f.damping.is_none_or(|d| d > 0.0 && d <= bound), "{f:?}");
    }
}

/// The free–free bar between two walls: its first family is the clamped bar's at half
/// length, `E / E_g = 8 / (pi^2 (2 T - 3)^2)`.
#[test]
fn free_free_branch_follows_the_exact_family() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/examples/assemblies/free_free_walls.toml"
    );
    let system = Assembly::from_path(path).unwrap().into_system();
    let steps = 31;
    let branch = exact_branch(
        &system,
        &request(&system, 1.975, 1.825, steps),
        &options(200.0),
    )
    .unwrap();
    let share = share_within(&branch, steps, |t| {
        8.0 / (PI * PI * (2.0 * t - 3.0).powi(2))
    });
    assert!(share >= 0.9, "{share}: {:?}", branch.skipped);
    assert!(branch.points.iter().all(|p| p.contacts == vec![1, 1]));
    every_point_has_a_verdict(&branch);
}

/// The map is positively homogeneous in the state and the gap: a gap twice as large gives
/// the same verdicts and four times the energies, point by point.
#[test]
fn gap_scales_out() {
    let small = clamped_bar_with_obstacle(1e-3).unwrap();
    let large = clamped_bar_with_obstacle(2e-3).unwrap();
    let run = |system: &BarSystem| {
        exact_branch(system, &request(system, 3.70, 3.66, 9), &options(200.0)).unwrap()
    };
    let (a, b) = (run(&small), run(&large));
    assert!(!a.points.is_empty());
    assert_eq!(verdicts(&a), verdicts(&b));
    for (p, q) in a.points.iter().zip(&b.points) {
        let ratio = q.point.energy / p.point.energy;
        assert!(
            (ratio - 4.0).abs() < 1e-6,
            "T = {}: {ratio}",
            p.point.period
        );
    }
}

/// Verdicts on 200 and 400 cells per travel time agree on at least 95 % of the points
/// resolved on both (about 30 s: the 400-cell matrices cost eight times as much).
#[test]
fn verdicts_do_not_depend_on_the_grid() {
    let system = clamped_bar_with_obstacle(1e-3).unwrap();
    let request = request(&system, 3.60, 3.55, 11);
    let coarse = exact_branch(&system, &request, &options(200.0)).unwrap();
    let fine = exact_branch(&system, &request, &options(400.0)).unwrap();
    every_point_has_a_verdict(&coarse);
    every_point_has_a_verdict(&fine);
    let fine = verdicts(&fine);
    let both: Vec<_> = verdicts(&coarse)
        .into_iter()
        .filter_map(|(step, v)| {
            let w = fine.iter().find(|f| f.0 == step)?.1;
            Some((v?, w?))
        })
        .collect();
    assert!(!both.is_empty());
    let agree = both.iter().filter(|(v, w)| v == w).count();
    assert!(agree as f64 >= 0.95 * both.len() as f64, "{both:?}");
}

/// The request's exact branch is `exact_branch`'s, beside the harmonic-balance points it was
/// seeded from; bad options are refused before anything runs.
#[test]
fn the_request_carries_the_exact_branch() {
    let system = clamped_bar_with_obstacle(1e-3).unwrap();
    let base = request(&system, 3.90, 3.88, 5);
    let alone = exact_branch(&system, &base, &options(100.0)).unwrap();
    let run = compute(&system, &base.clone().with_exact(options(100.0))).unwrap();
    assert_eq!(run.points.len(), 5);
    match run.exact {
        Some(Ok(exact)) => assert_eq!(exact, alone),
        other => panic!("{other:?}"),
    }
    let bad = ExactOptions {
        max_lost: 0,
        ..ExactOptions::default()
    };
    match compute(&system, &base.with_exact(bad)) {
        Err(Error::Stability(StabilityError::InvalidOption { what, .. })) => {
            assert_eq!(what, "max_lost")
        }
        other => panic!("{other:?}"),
    }
}

/// The options a system can afford: the clamped bar keeps 200 cells per travel time; with a
/// second bar eight times as long, 200 cells per shortest travel time are refused as too
/// large, and `for_request` takes fewer.
#[test]
fn the_default_grid_is_one_the_system_can_afford() {
    let clamped = clamped_bar_with_obstacle(1e-3).unwrap();
    let short = request(&clamped, 3.95, 3.90, 3);
    let options = ExactOptions::for_request(&clamped, &short).unwrap();
    assert_eq!(options.stability.cells_per_travel, 200.0);
    let long = two_bars_in_contact(Bar::new(8.0, 1.0, 1.0).unwrap(), 1e-3).unwrap();
    let grid = BackboneOptions::for_mode(&long, 1, 1).unwrap().grid;
    let run = request(&long, grid.start, grid.end, 3).harmonics(4);
    let options = ExactOptions::for_request(&long, &run).unwrap();
    let cells = options.stability.cells_per_travel;
    assert!((8.0..200.0).contains(&cells), "{cells}");
    match exact_branch(&long, &run, &ExactOptions::default()) {
        Err(Error::Stability(
            StabilityError::TooLarge { .. } | StabilityError::TooCostly { .. },
        )) => {}
        other => panic!("{:?}", other.map(|b| b.points.len())),
    }
}

/// Bad input is a typed error before anything runs; a seed that cannot be corrected is a
/// typed end, with no point.
#[test]
fn bad_input_and_bad_seeds_say_why() {
    let system = clamped_bar_with_obstacle(1e-3).unwrap();
    let bad_grid = request(&system, 3.5, 3.5, 11);
    let e = exact_branch(&system, &bad_grid, &options(200.0)).unwrap_err();
    assert!(matches!(e, Error::Settings(SettingsError::Range(_))), "{e}");
    let nan = ExactOptions {
        max_energy_jump: f64::NAN,
        ..ExactOptions::default()
    };
    let e = exact_branch(&system, &request(&system, 3.9, 3.8, 3), &nan).unwrap_err();
    assert!(
        matches!(e, Error::Stability(StabilityError::InvalidOption { what, .. }) if what == "max_energy_jump"),
        "{e}"
    );
    // One harmonic cannot carry the strain jump: its states are far from every periodic
    // orbit of the map with their energy.
    let one_harmonic = request(&system, 3.5, 3.45, 3).harmonics(1);
    let seeds = ExactOptions {
        seed_attempts: 2,
        ..options(100.0)
    };
    let branch = exact_branch(&system, &one_harmonic, &seeds).unwrap();
    match branch.end {
        ExactEnd::NoSeed { attempts, .. } => {
            assert!(attempts <= 2 && branch.points.is_empty(), "{branch:?}")
        }
        other => panic!("{other:?}: {} points", branch.points.len()),
    }
}
