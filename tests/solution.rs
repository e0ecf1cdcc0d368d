//! A backbone point as a `Solution`: its answers are those of the free functions, against the
//! exact first mode where one is known, and bad requests are typed errors.

use nonsmooth_modes::bar::Bar;
use nonsmooth_modes::branches::{
    compute, BackboneOptions, BackbonePoint, Method, PeriodGrid, Request,
};
use nonsmooth_modes::modal::{energy, grazing_energy};
use nonsmooth_modes::reference::{
    clamped_bar_with_obstacle, two_bars_in_contact, ClampedFirstMode,
};
use nonsmooth_modes::solve::Solver;
use nonsmooth_modes::system::{BarSystem, HarmonicBalanceSettings, NonsmoothSystem};
use nonsmooth_modes::verify::PeriodicityOptions;
use nonsmooth_modes::{SettingsError, Solution};

fn settings() -> HarmonicBalanceSettings {
    HarmonicBalanceSettings {
        harmonics: 20,
        ..Default::default()
    }
}

/// The converged points of a short backbone of `system` from `T = 3.93` to `3.63`.
fn points(system: &BarSystem) -> Vec<BackbonePoint> {
    let grid = PeriodGrid {
        start: 3.93,
        end: 3.63,
        steps: 7,
    };
    let request = Request {
        settings: settings(),
        method: Method::PeriodGrid(BackboneOptions::on_grid(grid, 1, 1)),
        solver: Some(Solver::default()),
        ..Request::new(1)
    };
    let all = compute(system, &request).unwrap().points;
    all.into_iter().filter(|p| p.converged()).collect()
}

#[test]
fn a_clamped_point_answers_like_the_exact_mode() {
    let system = clamped_bar_with_obstacle(1e-3).unwrap();
    let problem = NonsmoothSystem::new(&system, settings()).unwrap();
    let (e_g, _) = grazing_energy(&system).unwrap();
    let pts = points(&system);
    assert!(pts.len() >= 5);
    let mut close = 0;
    for p in &pts {
        let mode = p.solution(&problem).unwrap();
        assert_eq!(mode.omega(), p.omega);
        assert!((mode.period() - p.period).abs() < 1e-12);
        assert_eq!(
            mode.energy(),
            Ok(energy(&system, problem.basis(), &p.x, p.omega))
        );
        assert!(
            (mode.energy().unwrap() / e_g - p.energy_normalized).abs()
                <= 1e-12 * p.energy_normalized
        );
        let normalized = mode.energy_normalized().unwrap();
        assert!((normalized / p.energy_normalized - 1.0).abs() < 1e-12);
        let exact = ClampedFirstMode::new(1e-3, p.period).energy_normalized();
        close += usize::from((normalized / exact - 1.0).abs() < 0.1);
        // The tip sits at the obstacle at t = 0 (middle of the contact phase).
        let tip = mode.field().at(0, 1.0, 0.0);
        assert!((tip.displacement / 1e-3 - 1.0).abs() < 0.05, "{tip:?}");
        // Histories: the end at the obstacle never goes far past it, the law's gap stays
        // nearly non-negative, and the diagnostics see a small penetration.
        let end = system.bar_id(0).unwrap().right();
        let history = mode.end_history(end, 64).unwrap();
        assert_eq!(history.time.len(), 64);
        assert!(history.displacement.iter().all(|u| *u <= 1.05e-3));
        let law = mode.law_history(0, 64).unwrap();
        assert!(law.gap.iter().all(|g| *g >= -5e-5), "{:?}", law.gap);
        let d = mode.diagnose(4).unwrap();
        assert!(d.max_penetration < 5e-5);
        let grid = mode.displacement_grid(0, 11, 8).unwrap();
        assert_eq!(grid.displacement.len(), 88);
    }
    // All but internal resonances of the truncated system are within 10 % of the exact
    // energy.
    assert!(close + 1 >= pts.len(), "{close} of {}", pts.len());
    // The time-domain march comes back close to the start (at m = 20 the energy-norm defect
    // of a truncated exact motion is 0.1 to 0.25, its displacement defect under 0.04).
    let report = pts[2]
        .solution(&problem)
        .unwrap()
        .periodicity_check(&PeriodicityOptions::default())
        .unwrap();
    assert!(report.displacement_defect < 0.04, "{report:?}");
    assert!(report.defect < 0.25, "{report:?}");
}

#[test]
fn bad_requests_are_typed_errors() {
    let system = two_bars_in_contact(Bar::new(0.95, 1.0, 1.0).unwrap(), 1e-3).unwrap();
    let problem = NonsmoothSystem::new(&system, settings()).unwrap();
    let n = problem.dimension();
    let x = vec![0.0; n];
    assert!(matches!(
        Solution::new(&problem, &x[1..], 1.0),
        Err(SettingsError::Length { .. })
    ));
    for omega in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        assert!(matches!(
            Solution::new(&problem, &x, omega),
            Err(SettingsError::NotPositive { .. })
        ));
    }
    let mut bad = x.clone();
    bad[3] = f64::NAN;
    assert!(Solution::new(&problem, &bad, 1.0).is_err());
    let rest = Solution::new(&problem, &x, 1.0).unwrap();
    assert_eq!(rest.energy(), Ok(0.0));
    assert!(matches!(
        rest.displacement_grid(2, 3, 3),
        Err(SettingsError::IndexOutOfRange {
            index: 2,
            count: 2,
            ..
        })
    ));
    assert!(rest.law_history(1, 8).is_err());
    assert!(rest.diagnose(0).is_err());
    // A point of another problem does not fit.
    let clamped = clamped_bar_with_obstacle(1e-3).unwrap();
    let p = &points(&clamped)[0];
    assert!(matches!(
        p.solution(&problem),
        Err(SettingsError::Length { .. })
    ));
}
