//! Periodicity of harmonic-balance points: the clamped bar (against the truncated exact
//! solution) and the paper's two-bar check (its Fig. 16).

use nonsmooth_modes::bar::Bar;
use nonsmooth_modes::branches::{
    compute, BackboneOptions, BackbonePoint, Method, PeriodGrid, Request,
};
use nonsmooth_modes::modal::energy;
use nonsmooth_modes::reference::{
    clamped_bar_with_obstacle, two_bars_in_contact, ClampedFirstMode,
};
use nonsmooth_modes::solve::Solver;
use nonsmooth_modes::system::{BarSystem, HarmonicBalanceSettings};
use nonsmooth_modes::verify::{periodicity_check, PeriodicityOptions, State, VerifyError};
use std::f64::consts::PI;

const GAP: f64 = 1e-3;

/// The cosine series of the exact first mode of the clamped bar truncated at `m` harmonics,
/// in the unknowns' layout of the harmonic-balance system: per harmonic `(A, B)` with
/// `u(x) = A cos(kx) + B sin(kx)/k`, `A = u(0) = 0`, `B = u(1) k / sin(k)`.
fn truncated_exact(period: f64, m: usize) -> (Vec<f64>, f64) {
    let exact = ClampedFirstMode::new(GAP, period);
    let omega = 2.0 * PI / period;
    let mut x = vec![0.0; 2 * (m + 1)];
    x[1] = 2.0 * exact.displacement_mean();
    for j in 1..=m {
        let k = j as f64 * omega;
        x[2 * j + 1] = exact.displacement_harmonic(j) * k / k.sin();
    }
    (x, omega)
}

/// The points of the period grid `grid` of NSM 1 of `system`, with the full semismooth
/// Newton.
fn grid_points(
    system: &BarSystem,
    settings: HarmonicBalanceSettings,
    grid: PeriodGrid,
) -> Vec<BackbonePoint> {
    let request = Request {
        settings,
        method: Method::PeriodGrid(BackboneOptions::on_grid(grid, 1, 1)),
        solver: Some(Solver::default()),
        ..Request::new(1)
    };
    compute(system, &request).unwrap().points
}

#[test]
fn truncated_exact_solution_defect_decays_with_harmonics() {
    let system = clamped_bar_with_obstacle(GAP).unwrap();
    let options = PeriodicityOptions::default();
    let mut reports = Vec::new();
    for m in [20, 80] {
        let (x, omega) = truncated_exact(3.65, m);
        let basis = HarmonicBalanceSettings {
            harmonics: m,
            ..Default::default()
        }
        .cosine_basis()
        .unwrap();
        reports.push(periodicity_check(&system, &basis, &x, omega, &options).unwrap());
    }
    let (r20, r80) = (reports[0], reports[1]);
    // Strain and velocity jumps: the energy-norm defect decays like m^(-1/2), the displacement
    // defect like 1/m.
    assert!(r20.defect > 0.1 && r20.defect < 0.25, "{r20:?}");
    let energy_ratio = r80.defect / r20.defect;
    assert!(energy_ratio > 0.4 && energy_ratio < 0.65, "{energy_ratio}");
    assert!(r20.displacement_defect < 0.04, "{r20:?}");
    let displacement_ratio = r80.displacement_defect / r20.displacement_defect;
    assert!(
        displacement_ratio > 0.2 && displacement_ratio < 0.3,
        "{displacement_ratio}"
    );
    for r in reports {
        assert!(r.energy_drift < 1e-12);
        assert!(r.min_contact_force >= 0.0);
        assert!(r.max_penetration <= r.initial_penetration + 1e-15);
    }
}

#[test]
fn clamped_bar_harmonic_balance_point_is_as_periodic_as_the_truncated_exact_mode() {
    let system = clamped_bar_with_obstacle(GAP).unwrap();
    let settings = HarmonicBalanceSettings {
        harmonics: 20,
        ..Default::default()
    };
    let grid = PeriodGrid {
        start: 3.95,
        end: 3.65,
        steps: 7,
    };
    let points = grid_points(&system, settings, grid);
    let point = points.last().unwrap();
    assert!(point.converged());
    // This point is within 1% of the exact energy (away from internal resonances).
    let exact = ClampedFirstMode::new(GAP, point.period).energy_normalized();
    assert!((point.energy_normalized / exact - 1.0).abs() < 0.01);
    let basis = settings.cosine_basis().unwrap();
    let check = PeriodicityOptions::default();
    let report = periodicity_check(&system, &basis, &point.x, point.omega, &check).unwrap();
    let (x, omega) = truncated_exact(point.period, 20);
    let reference = periodicity_check(&system, &basis, &x, omega, &check).unwrap();
    assert!(report.displacement_defect < 0.03, "{report:?}");
    assert!(
        report.defect < 1.2 * reference.defect,
        "{report:?} vs {reference:?}"
    );
    assert!(report.energy_drift < 1e-12);
    assert!(report.min_contact_force >= 0.0);
    // The state built from the fields carries the harmonic-balance energy.
    let state =
        State::from_harmonic_balance(&system, &basis, &point.x, point.omega, 0.0, 0.0025).unwrap();
    let e = energy(&system, &basis, &point.x, point.omega);
    assert!(
        (state.energy() / e - 1.0).abs() < 1e-3,
        "{} vs {e}",
        state.energy()
    );
}

#[test]
fn two_bar_check_of_the_paper_figure_16() {
    // Configuration 1 (l = 0.95, c = 1, EA ratio 1), a point of the first-mode backbone,
    // dt = 0.01: bar 1 has 100 cells, bar 2 has 95.
    let system = two_bars_in_contact(Bar::new(0.95, 1.0, 1.0).unwrap(), GAP).unwrap();
    let settings = HarmonicBalanceSettings {
        harmonics: 20,
        ..Default::default()
    };
    let grid = PeriodGrid {
        start: 3.79,
        end: 3.65,
        steps: 15,
    };
    let points = grid_points(&system, settings, grid);
    let point = points.last().unwrap();
    assert!(point.converged() && (point.period - 3.65).abs() < 1e-12);
    let basis = settings.cosine_basis().unwrap();
    let check = PeriodicityOptions {
        dt: 0.01,
        ..Default::default()
    };
    let report = periodicity_check(&system, &basis, &point.x, point.omega, &check).unwrap();
    // The paper: "less than 2%".
    assert!(report.displacement_defect < 0.02, "{report:?}");
    assert!(report.defect < 0.2, "{report:?}");
    assert!(report.energy_drift < 1e-12);
    assert!(report.min_contact_force >= 0.0);
    assert!(report.max_penetration <= report.initial_penetration + 1e-15);
    // A step that does not fit bar 2 (237.5 steps) is checked as it is, or adjusted to a
    // commensurate one on request; both say the same.
    let odd = PeriodicityOptions {
        dt: 0.004,
        ..Default::default()
    };
    let r = periodicity_check(&system, &basis, &point.x, point.omega, &odd).unwrap();
    assert!(r.dt == 0.004 && r.displacement_defect < 0.02, "{r:?}");
    assert!(r.energy_drift <= r.projected_energy + 1e-12, "{r:?}");
    let adjusted = PeriodicityOptions {
        adjust_grid: true,
        ..odd
    };
    let a = periodicity_check(&system, &basis, &point.x, point.omega, &adjusted).unwrap();
    assert!(
        (a.dt - 1.0 / 260.0).abs() < 1e-15 && a.displacement_defect < 0.02,
        "{a:?}"
    );
    assert!(
        (r.defect - a.defect).abs() < 0.1 * a.defect,
        "{r:?} vs {a:?}"
    );
    // A step longer than bar 2's travel time is refused.
    let long = PeriodicityOptions { dt: 1.0, ..odd };
    assert!(matches!(
        periodicity_check(&system, &basis, &point.x, point.omega, &long),
        Err(VerifyError::NonMatchingGrid { bar: 1, .. })
    ));
    // Wrong-length and NaN unknowns.
    assert!(matches!(
        periodicity_check(&system, &basis, &point.x[1..], point.omega, &check),
        Err(VerifyError::Length { .. })
    ));
    let mut nan = point.x.clone();
    nan[3] = f64::NAN;
    assert!(matches!(
        periodicity_check(&system, &basis, &nan, point.omega, &check),
        Err(VerifyError::NonFinite { .. })
    ));
}
