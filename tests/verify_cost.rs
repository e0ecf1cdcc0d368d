//! The cost of the time-domain check is bounded (issue 26, finding 3): a periodicity check at
//! `Omega = max_frequency` over `usize::MAX` periods, whose impacts once made the waves' pieces
//! grow without bound (4.7 s, then 69 s, then hours), either ends in seconds with a report of
//! what the merges removed, or is refused at once with the cost it would have.

use nonsmooth_modes::bar::Bar;
use nonsmooth_modes::reference::{two_bars_in_contact, ClampedFirstMode};
use nonsmooth_modes::system::{HarmonicBalanceSettings, NonsmoothSystem};
use nonsmooth_modes::verify::{
    periodicity_check, Grid, Integrator, MarchOptions, PeriodicityOptions, PeriodicityReport,
    State, VerifyError, MAX_MARCH_WORK,
};
use std::time::{Duration, Instant};

/// The paper's two-bar system, a motion at ten times the truncated clamped mode's size (it
/// hits the contact), its settings and its largest frequency.
fn setup(
    harmonics: usize,
) -> (
    nonsmooth_modes::system::BarSystem,
    HarmonicBalanceSettings,
    Vec<f64>,
    f64,
) {
    let system = two_bars_in_contact(Bar::new(0.95, 1.0, 1.0).unwrap(), 1e-3).unwrap();
    let settings = HarmonicBalanceSettings {
        harmonics,
        ..Default::default()
    };
    let problem = NonsmoothSystem::new(&system, settings).unwrap();
    let omega = problem.description().max_frequency();
    let mut x = ClampedFirstMode::new(1e-3, 3.6).unknowns(harmonics);
    x.resize(problem.dimension(), 0.0);
    x.iter_mut().for_each(|v| *v *= 10.0);
    (system, settings, x, omega)
}

/// The periodicity check at the largest frequency over `usize::MAX` periods of `dt = 0.05`:
/// its result, how long it took, and the frequency.
fn check_at_the_top(harmonics: usize) -> (Result<PeriodicityReport, VerifyError>, Duration, f64) {
    let (system, settings, x, omega) = setup(harmonics);
    let basis = settings.cosine_basis().unwrap();
    let options = PeriodicityOptions {
        dt: 0.05,
        periods: usize::MAX,
        ..Default::default()
    };
    let start = Instant::now();
    let result = periodicity_check(&system, &basis, &x, omega, &options);
    (result, start.elapsed(), omega)
}

#[test]
fn check_at_the_largest_frequency_over_huge_periods_is_refused_at_once() {
    // 8 harmonics: 2^64 periods of 1.1e-14 are 2.1e5 time units, 4.1e6 steps of 0.05.
    let (result, elapsed, omega) = check_at_the_top(8);
    assert!(elapsed < Duration::from_secs(1), "{elapsed:?}");
    let e = result.unwrap_err();
    let VerifyError::TooCostly {
        steps,
        per_step,
        work,
        limit,
    } = e
    else {
        panic!("expected TooCostly, got {e:?}");
    };
    assert!((steps - 2.0 * std::f64::consts::PI / omega * 2f64.powi(64) / 0.05).abs() < 2.0);
    assert!(work > limit && limit == MAX_MARCH_WORK as f64);
    assert!(per_step > 0.0 && per_step < 40.0, "{per_step}");
    let message = e.to_string();
    assert!(message.contains("wave-piece operations"), "{message}");
}

#[test]
fn check_at_the_largest_frequency_over_huge_periods_ends_in_seconds() {
    // 4 harmonics: 1.0e5 time units, 2.1e6 steps, within the limit.
    let (result, elapsed, _) = check_at_the_top(4);
    let r = result.unwrap();
    eprintln!("2.1e6 steps in {elapsed:?}: {r:?}");
    // A few seconds in release on a 2-core machine (the march is linear in its steps).
    assert!(elapsed < Duration::from_secs(120), "{elapsed:?}");
    for v in [
        r.defect,
        r.displacement_defect,
        r.energy_drift,
        r.projected_energy,
        r.projection_error,
    ] {
        assert!(v.is_finite());
    }
    // The motion is rough at the scale of a cell (its harmonics are far above what the grid
    // resolves): the merges remove most of its energy, and the report says so.
    assert!(r.projected_energy > 0.1, "{r:?}");
    assert!(r.energy_drift <= r.projected_energy + 1e-9, "{r:?}");
    assert!(r.min_contact_force >= 0.0);
}

#[test]
fn pieces_stay_bounded_and_steps_stay_cheap() {
    let (system, settings, x, omega) = setup(4);
    let basis = settings.cosine_basis().unwrap();
    let state = State::from_harmonic_balance(&system, &basis, &x, omega, 0.0, 0.05).unwrap();
    let grid: Grid = state.grid().clone();
    let bound: usize = (0..grid.bars()).map(|b| 2 * grid.max_pieces(b)).sum();
    let e0 = state.energy();
    let mut integrator = Integrator::new(state, MarchOptions::default());
    let mut removed = 0.0;
    let mut largest = 0;
    for _ in 0..100_000 {
        removed += integrator.step().projected_energy;
        largest = largest.max(integrator.state().pieces());
    }
    // Before the bound, the pieces grew past 10^6 within 40 000 steps.
    assert!(largest <= bound, "{largest} > {bound}");
    let e1 = integrator.state().energy();
    assert!(
        (e1 + removed - e0).abs() < 1e-10 * e0,
        "{e0} {e1} {removed}"
    );
}
