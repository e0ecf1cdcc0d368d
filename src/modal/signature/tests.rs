use super::*;
use crate::bar::Bar;
use crate::branches::{compute, BackboneOptions, Method, PeriodGrid, Request};
use crate::continuation::ContinuationProblem;
use crate::fourier::CosineBasis;
use crate::modal::energy::energy_at;
use crate::reference::{clamped_bar_with_obstacle, two_bars_in_contact, ClampedFirstMode};
use crate::solve::Structured;
use crate::system::HarmonicBalanceSettings;
use proptest::prelude::*;
use std::f64::consts::PI;

const HARMONICS: usize = 12;

/// The clamped bar, its cosine basis with [`HARMONICS`] harmonics, and the exact first mode
/// at `T = 3.6` as unknowns, at its frequency.
fn clamped_exact() -> (BarSystem, CosineBasis, Vec<f64>, f64) {
    let system = clamped_bar_with_obstacle(1e-3).unwrap();
    let basis = CosineBasis::new(HARMONICS, 30).unwrap();
    let x = ClampedFirstMode::new(1e-3, 3.6).unknowns(HARMONICS);
    (system, basis, x, 2.0 * PI / 3.6)
}

/// Two bars of different lengths, speeds and stiffnesses in contact, and `len` coefficients
/// of theirs moving arbitrarily with amplitude `scale`.
fn two_bars_moving(len: usize, scale: f64) -> (BarSystem, Vec<f64>) {
    let second = Bar::new(0.8, 1.3, 2.5).unwrap();
    let two = two_bars_in_contact(second, 1e-3).unwrap();
    let wiggle = |i: usize| scale * (((7 * i) % 11) as f64 - 5.0);
    (two, (0..len * 4).map(wiggle).collect())
}

/// `x` with the harmonics for which `keep(n)` is false set to zero (one bar).
fn only(x: &[f64], keep: impl Fn(usize) -> bool) -> Vec<f64> {
    let mut y = x.to_vec();
    for (n, pair) in y.chunks_mut(2).enumerate() {
        if !keep(n) {
            pair.fill(0.0);
        }
    }
    y
}

#[test]
fn periodic_runs_count_wrapping_runs_once() {
    let (t, f) = (true, false);
    assert_eq!(periodic_runs(&[]), 0);
    assert_eq!(periodic_runs(&[f, f, f]), 0);
    assert_eq!(periodic_runs(&[t, t, t]), 1);
    assert_eq!(periodic_runs(&[t, f, f, t]), 1);
    assert_eq!(periodic_runs(&[f, t, t, f]), 1);
    assert_eq!(periodic_runs(&[t, f, t, f]), 2);
    assert_eq!(periodic_runs(&[t, f, t, f, f, t, t]), 2);
}

/// The harmonic energies add up to the time average of the instantaneous energy of
/// [`energy_at`] (no ground spring: the bars' energy is all of it), on one bar and on two
/// bars of different lengths, speeds and stiffnesses, for any unknowns.
#[test]
fn harmonic_energies_sum_to_the_time_averaged_energy() {
    let (clamped, basis, exact, omega) = clamped_exact();
    let (two, arbitrary) = two_bars_moving(basis.len(), 1e-4);
    for (system, x) in [(&clamped, &exact), (&two, &arbitrary)] {
        let energies = harmonic_energies(system, &basis, x, omega).unwrap();
        assert_eq!(energies.len(), HARMONICS + 1);
        assert!(energies.iter().all(|e| *e >= 0.0));
        let phases = 2 * HARMONICS + 2;
        let average = (0..phases)
            .map(|q| {
                energy_at(
                    system,
                    &basis,
                    x,
                    omega,
                    2.0 * PI * q as f64 / phases as f64,
                )
            })
            .sum::<f64>()
            / phases as f64;
        let total: f64 = energies.iter().sum();
        assert!(
            (total / average - 1.0).abs() < 1e-10,
            "{total} vs {average}"
        );
    }
}

/// Bar by bar, the harmonic energies add up to the system's, and a bar at rest carries none:
/// with bar 2's unknowns zeroed, bar 1 carries all of them.
#[test]
fn harmonic_energies_split_by_bar() {
    let (_, basis, _, omega) = clamped_exact();
    let second = Bar::new(0.8, 1.3, 2.5).unwrap();
    let two = two_bars_in_contact(second, 1e-3).unwrap();
    let mut x: Vec<f64> = (0..basis.len() * 4)
        .map(|i| 1e-4 * (((7 * i) % 11) as f64 - 5.0))
        .collect();
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * a.abs().max(b.abs()).max(1e-300);
    let total = harmonic_energies(&two, &basis, &x, omega).unwrap();
    let by_bar = harmonic_energies_by_bar(&two, &basis, &x, omega).unwrap();
    assert_eq!(by_bar.len(), 2);
    for (n, e) in total.iter().enumerate() {
        assert!(close(by_bar[0][n] + by_bar[1][n], *e), "harmonic {n}");
    }
    assert!(by_bar[1].iter().sum::<f64>() > 0.0);
    // Unknowns per harmonic: bar 1's (A, B), then bar 2's.
    x.chunks_mut(4).for_each(|c| (c[2], c[3]) = (0.0, 0.0));
    let by_bar = harmonic_energies_by_bar(&two, &basis, &x, omega).unwrap();
    let total = harmonic_energies(&two, &basis, &x, omega).unwrap();
    assert!(by_bar[1].iter().all(|e| *e == 0.0));
    assert!(by_bar[0].iter().zip(&total).all(|(a, b)| close(*a, *b)));
}

#[test]
fn share_is_zero_on_multiples_of_k_and_one_off_them() {
    let (system, basis, x, omega) = clamped_exact();
    let share = |x: &[f64], k| subharmonic_share(&system, &basis, x, omega, k).unwrap();
    let threes = only(&x, |n| n % 3 == 0);
    assert_eq!(share(&threes, 3), 0.0);
    assert_eq!(share(&x, 1), 0.0);
    let first = only(&x, |n| n == 1);
    assert_eq!(share(&first, 1), 0.0);
    for k in 2..5 {
        assert_eq!(share(&first, k), 1.0);
    }
    // The exact mode has energy on every harmonic: some of it off the multiples of 3.
    let s = share(&x, 3);
    assert!(s > 0.0 && s < 1.0, "{s}");
    // At rest there is no energy, hence none outside the multiples of k.
    assert_eq!(share(&vec![0.0; x.len()], 2), 0.0);
}

#[test]
fn two_harmonics_of_equal_energy_share_one_half() {
    let (system, basis, x, omega) = clamped_exact();
    let energies = harmonic_energies(&system, &basis, &x, omega).unwrap();
    // Harmonic 2 scaled to the energy of harmonic 1 (energies are quadratic in x).
    let scale = (energies[1] / energies[2]).sqrt();
    let mut y = only(&x, |n| n == 1 || n == 2);
    y[4..6].iter_mut().for_each(|v| *v *= scale);
    let share = subharmonic_share(&system, &basis, &y, omega, 2).unwrap();
    assert!((share - 0.5).abs() < 1e-12, "{share}");
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// The share depends on the shape of the motion, not its amplitude.
    #[test]
    fn share_is_invariant_under_scaling(scale in -1e6..1e6_f64, k in 1..6_usize) {
        prop_assume!(scale.abs() > 1e-6);
        let (system, basis, x, omega) = clamped_exact();
        let scaled: Vec<f64> = x.iter().map(|v| scale * v).collect();
        let a = subharmonic_share(&system, &basis, &x, omega, k).unwrap();
        let b = subharmonic_share(&system, &basis, &scaled, omega, k).unwrap();
        prop_assert!((0.0..=1.0).contains(&b));
        prop_assert!((a - b).abs() < 1e-12, "{} vs {}", a, b);
    }
}

#[test]
fn share_rejects_bad_input_with_typed_errors() {
    let (system, basis, x, omega) = clamped_exact();
    let share = |x: &[f64], omega, k| subharmonic_share(&system, &basis, x, omega, k);
    assert!(matches!(
        share(&x, omega, 0),
        Err(SettingsError::ZeroIndex { value: 0, .. })
    ));
    assert!(matches!(
        share(&x[1..], omega, 2),
        Err(SettingsError::Length { .. })
    ));
    for bad in [f64::NAN, 0.0, -1.0, f64::INFINITY] {
        assert!(matches!(
            share(&x, bad, 2),
            Err(SettingsError::NotPositive { .. })
        ));
    }
    let mut nan = x.clone();
    nan[3] = f64::NAN;
    assert!(matches!(
        share(&nan, omega, 2),
        Err(SettingsError::NotPositive { .. })
    ));
    let mut huge = x.clone();
    huge[3] = 1e300;
    assert!(matches!(
        share(&huge, omega, 2),
        Err(SettingsError::NonFiniteResult { .. })
    ));
}

/// A converged point of the clamped bar's first nonsmooth mode hits the obstacle once per
/// period, for about the exact contact time `4 - T` (at `m = 10` the truncated motion grazes
/// the obstacle a little before and after the exact contact: 31 samples for 24), and counts
/// the samples of the solver's active set.
#[test]
fn the_clamped_bar_touches_once_per_period() {
    let system = clamped_bar_with_obstacle(1e-3).unwrap();
    let settings = HarmonicBalanceSettings {
        harmonics: 10,
        ..Default::default()
    };
    let grid = PeriodGrid {
        start: 3.9,
        end: 3.7,
        steps: 5,
    };
    let request = Request {
        settings,
        method: Method::PeriodGrid(BackboneOptions::on_grid(grid, 1, 1)),
        ..Request::new(1)
    };
    let run = compute(&system, &request).unwrap();
    let p = run.points.iter().rev().find(|p| p.converged()).unwrap();
    let mut problem = NonsmoothSystem::new(&system, settings).unwrap();
    assert_eq!(
        contact_intervals(&mut problem, &p.x, p.omega).unwrap(),
        vec![1]
    );
    let contact = contact_samples(&mut problem, &p.x, p.omega).unwrap();
    let in_contact = contact[0].iter().filter(|c| **c).count();
    let samples = problem.basis().samples() as f64;
    let expected = samples * ClampedFirstMode::new(1e-3, p.period).contact_duration() / p.period;
    assert!(
        (in_contact as f64 - expected).abs() <= 0.35 * expected,
        "{in_contact} vs {expected}"
    );
    problem.set_parameter(p.omega);
    assert_eq!(problem.active_set(&p.x), Some(vec![in_contact]));
    // At rest the bar never reaches the obstacle.
    let rest = vec![0.0; p.x.len()];
    assert_eq!(
        contact_intervals(&mut problem, &rest, p.omega).unwrap(),
        vec![0]
    );
}

#[test]
fn contact_intervals_reject_bad_input() {
    let system = clamped_bar_with_obstacle(1e-3).unwrap();
    let mut problem = NonsmoothSystem::new(&system, HarmonicBalanceSettings::default()).unwrap();
    let x = vec![0.0; problem.dimension()];
    assert!(matches!(
        contact_intervals(&mut problem, &x[1..], 1.0),
        Err(SettingsError::Length { .. })
    ));
    assert!(matches!(
        contact_intervals(&mut problem, &x, f64::NAN),
        Err(SettingsError::NotPositive { .. })
    ));
}

/// The contact and gap samples, taken on the folded grid and spread over the period, are
/// those of the laws sampled at every instant of a full-grid synthesis, bit for bit: on the
/// clamped bar's exact mode (in contact over part of the period) and on two bars moving
/// arbitrarily, with an even and an odd number of samples.
#[test]
fn folded_contact_samples_are_those_of_the_full_grid() {
    let (clamped, _, exact, omega) = clamped_exact();
    let (two, arbitrary) = two_bars_moving(HARMONICS + 1, 1e-3);
    for samples_per_harmonic in [30, 7] {
        let settings = HarmonicBalanceSettings {
            harmonics: HARMONICS,
            samples_per_harmonic,
            ..Default::default()
        };
        for (system, x) in [(&clamped, &exact), (&two, &arbitrary)] {
            let mut problem = NonsmoothSystem::new(system, settings).unwrap();
            let described = contact_and_gap_samples(&mut problem, x, omega).unwrap();
            let a_c = problem.complementarity();
            let mut touched = 0;
            for (l, (law, (contact, gap))) in system.laws().zip(&described).enumerate() {
                let g = problem.gap_history(x, omega, l);
                let f = problem.force_history(x, omega, l);
                let [mut values, mut d_gap, mut d_force] = [0; 3].map(|_| vec![0.0; g.len()]);
                let out = LawSamples {
                    values: &mut values,
                    d_gap: &mut d_gap,
                    d_force: &mut d_force,
                };
                law.sample(&g, &f, a_c, 0.0, out);
                let expected: Vec<bool> = d_gap.iter().map(|w| *w != 0.0).collect();
                assert_eq!(gap, &g);
                assert_eq!(contact, &expected);
                touched += expected.iter().filter(|c| **c).count();
            }
            assert!(touched > 0, "some sample in contact");
        }
    }
}
