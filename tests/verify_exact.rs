//! The integrator against exact solutions: the first nonsmooth mode of the clamped bar (both
//! signs of the gap), a linear mode, and typed errors on bad input.

use nonsmooth_modes::bar::Bar;
use nonsmooth_modes::reference::{
    clamped_bar_with_obstacle, two_bars_in_contact, ClampedFirstMode,
};
use nonsmooth_modes::verify::{
    clamped_first_mode, march, periodicity_of_state, BarCells, Grid, Integrator, MarchOptions,
    Model, PeriodicityOptions, State, VerifyError,
};
use std::f64::consts::PI;

const DT: f64 = 1.0 / 400.0;

/// Marches the exact mode over one period and checks every recorded end value against the
/// closed form of formulation §9.
fn check_exact_mode(gap: f64, period: f64) {
    let initial = clamped_first_mode(gap, period, DT).unwrap();
    let report = periodicity_of_state(&initial, period, &PeriodicityOptions::default()).unwrap();
    // Acceptance: below 1e-6; the scheme is exact, so it is at rounding.
    assert!(
        report.defect < 1e-11,
        "T = {period}, g0 = {gap}: defect {:e}",
        report.defect
    );
    assert!(
        report.energy_drift < 1e-12,
        "energy drift {:e}",
        report.energy_drift
    );
    assert!(report.max_penetration <= 1e-15 * gap.abs());
    assert!(report.min_contact_force >= 0.0);
    let exact = ClampedFirstMode::new(gap, period);
    assert!((report.initial_energy / exact.energy() - 1.0).abs() < 1e-12);

    let trajectory = march(&initial, period, &MarchOptions::default()).unwrap();
    let end = &trajectory.ends[1];
    let contact = &trajectory.contacts[0];
    for (k, &t) in trajectory.times.iter().enumerate() {
        let err = (end.displacement[k] - exact.end_displacement(t)).abs();
        assert!(err < 1e-12 * gap.abs(), "t = {t}: u(1) off by {err:e}");
        assert!(contact.gap[k] >= -1e-15 * gap.abs());
        if k > 0 {
            // Step mean of the rectangular force pulse; its edges fall on the grid here.
            let mid = 0.5 * (trajectory.times[k - 1] + t);
            let f = exact.contact_force(mid);
            assert!(
                (contact.force[k - 1] - f).abs() < 1e-9 * f.abs().max(1.0),
                "t = {t}"
            );
        }
    }
}

#[test]
fn exact_first_mode_returns_after_one_period() {
    for period in [3.2, 3.5, 3.8] {
        check_exact_mode(0.1, period);
        check_exact_mode(1e-3, period);
    }
}

#[test]
fn exact_first_mode_with_negative_gap_returns_after_one_period() {
    // A bar pressed into the obstacle: g0 < 0, T in (2, 3).
    for period in [2.2, 2.5, 2.8] {
        check_exact_mode(-0.1, period);
    }
}

#[test]
fn exact_mode_energy_is_constant_over_ten_periods() {
    let initial = clamped_first_mode(0.05, 3.3, DT).unwrap();
    let t = march(&initial, 33.0, &MarchOptions::default()).unwrap();
    assert!(t.energy_drift < 1e-12, "{:e}", t.energy_drift);
    let back = t.final_state.distance(&initial).unwrap() / initial.norm();
    assert!(back < 1e-10, "{back:e}");
}

#[test]
fn linear_clamped_free_mode_returns_to_rounding() {
    // Obstacle far away: the gap never closes, T = 4 for the unit clamped-free bar.
    let system = clamped_bar_with_obstacle(10.0).unwrap();
    let model = Model::from_system(&system).unwrap();
    let grid = Grid::new(&model, DT).unwrap();
    let amplitude = 0.01;
    let initial = State::from_fields(&model, &grid, |_, x| {
        (amplitude * (0.5 * PI * x).sin(), 0.0)
    })
    .unwrap();
    let report = periodicity_of_state(&initial, 4.0, &PeriodicityOptions::default()).unwrap();
    assert!(report.defect < 1e-13, "{:e}", report.defect);
    let t = march(&initial, 4.0, &MarchOptions::default()).unwrap();
    for (k, time) in t.times.iter().enumerate() {
        // Nodal values are transported exactly: the end follows cos(pi t / 2).
        let exact = amplitude * (0.5 * PI * time).cos();
        assert!((t.ends[1].displacement[k] - exact).abs() < 1e-14);
    }
    assert_eq!(t.contacts[0].force.iter().copied().fold(0.0, f64::max), 0.0);
}

#[test]
fn linear_two_bar_motion_returns_to_rounding() {
    // Bar 2 with l = 0.5, c = 0.5, EA = 3: same clamped-free period 4 as bar 1; contact open.
    let system = two_bars_in_contact(Bar::new(0.5, 0.5, 3.0).unwrap(), 5.0).unwrap();
    let model = Model::from_system(&system).unwrap();
    let grid = Grid::new(&model, 0.01).unwrap();
    let initial = State::from_fields(&model, &grid, |b, x| {
        let l = if b == 0 { 1.0 } else { 0.5 };
        let s = 0.5 * PI * x / l;
        (
            0.02 * s.sin() + 0.01 * (3.0 * s).sin(),
            0.03 * (5.0 * s).sin(),
        )
    })
    .unwrap();
    let report = periodicity_of_state(&initial, 4.0, &PeriodicityOptions::default()).unwrap();
    assert!(report.defect < 1e-13, "{:e}", report.defect);
    assert!(report.energy_drift < 1e-13);
}

#[test]
fn partial_steps_compose() {
    // Two half steps equal one full step.
    let initial = clamped_first_mode(0.1, 3.45, DT).unwrap();
    let mut a = Integrator::new(initial.clone(), MarchOptions::default());
    let mut b = Integrator::new(initial, MarchOptions::default());
    for _ in 0..700 {
        a.step();
        b.advance(0.5).unwrap();
        b.advance(0.5).unwrap();
    }
    let d = a.state().distance(b.state()).unwrap() / a.state().norm();
    assert!(d < 1e-12, "{d:e}");
    assert!(matches!(
        b.advance(0.0),
        Err(VerifyError::InvalidParameter { .. })
    ));
    assert!(matches!(
        b.advance(1.5),
        Err(VerifyError::InvalidParameter { .. })
    ));
}

#[test]
fn bad_inputs_give_typed_errors() {
    let two = two_bars_in_contact(Bar::new(0.95, 1.0, 1.0).unwrap(), 0.1).unwrap();
    let model = Model::from_system(&two).unwrap();
    // Any step up to the shorter travel time (0.95) is a grid; a longer one is refused.
    assert!(!Grid::new(&model, 0.007).unwrap().is_commensurate());
    assert!(matches!(
        Grid::new(&model, 0.96),
        Err(VerifyError::NonMatchingGrid { bar: 1, .. })
    ));
    for dt in [0.0, -0.01, f64::NAN, f64::INFINITY] {
        assert!(matches!(
            Grid::new(&model, dt),
            Err(VerifyError::InvalidTimeStep { .. })
        ));
    }
    let grid = Grid::new(&model, 0.01).unwrap();
    let cells = |n: usize, v: f64| BarCells {
        left_displacement: 0.0,
        strain: vec![0.0; n],
        velocity: vec![v; n],
    };
    assert!(matches!(
        State::from_cells(&model, &grid, &[cells(100, 0.0), cells(95, f64::NAN)]),
        Err(VerifyError::NonFinite {
            what: "velocity",
            bar: 1,
            ..
        })
    ));
    assert!(matches!(
        State::from_cells(&model, &grid, &[cells(100, 0.0), cells(94, 0.0)]),
        Err(VerifyError::Length {
            bar: 1,
            expected: 95,
            ..
        })
    ));
    assert!(matches!(
        State::from_cells(&model, &grid, &[cells(100, 0.0)]),
        Err(VerifyError::BarCount {
            got: 1,
            expected: 2
        })
    ));
    // A grid of another model.
    let one = Model::clamped_bar_with_obstacle(0.1).unwrap();
    let other = Grid::new(&one, 0.01).unwrap();
    assert!(State::from_cells(&model, &other, &[cells(100, 0.0), cells(95, 0.0)]).is_err());
    let s = State::from_cells(&model, &grid, &[cells(100, 0.0), cells(95, 0.0)]).unwrap();
    let r = State::from_cells(&one, &other, &[cells(100, 0.0)]).unwrap();
    assert_eq!(s.distance(&r), Err(VerifyError::MismatchedStates));
    assert!(matches!(
        march(&s, f64::NAN, &MarchOptions::default()),
        Err(VerifyError::InvalidParameter { .. })
    ));
    assert!(matches!(
        periodicity_of_state(&s, -1.0, &PeriodicityOptions::default()),
        Err(VerifyError::InvalidParameter { .. })
    ));
    assert!(matches!(
        clamped_first_mode(0.1, 2.5, DT),
        Err(VerifyError::InvalidParameter { .. })
    ));
}

#[test]
fn marches_compose_across_partial_steps() {
    // 1.2345 then 2.0655 time units (493.8 + 826.2 steps) make one period T = 3.3.
    let initial = clamped_first_mode(0.1, 3.3, DT).unwrap();
    let first = march(&initial, 1.2345, &MarchOptions::default()).unwrap();
    assert!((first.times.last().unwrap() - 1.2345).abs() < 1e-12);
    let second = march(&first.final_state, 3.3 - 1.2345, &MarchOptions::default()).unwrap();
    let back = second.final_state.distance(&initial).unwrap() / initial.norm();
    assert!(back < 1e-10, "{back:e}");
    assert!(second.energy_drift < 1e-12);
    // The crate-wide error converts from the integrator's.
    let e: nonsmooth_modes::Error = VerifyError::InvalidTimeStep { dt: 0.0 }.into();
    assert!(e.to_string().contains("time step"));
}
