//! The exported proptest strategies draw admissible values in their documented ranges, and
//! their systems are usable by the harmonic-balance machinery.
#![cfg(feature = "proptest")]

use nonsmooth_modes::modal::branch_seed;
use nonsmooth_modes::strategies::{
    bar, clamped_system, frequency, gap, helmholtz_coefficients, period_in_first_family,
    robin_system, two_bar_system,
};
use nonsmooth_modes::system::{HarmonicBalanceSettings, NonsmoothSystem};
use proptest::prelude::*;
use proptest::strategy::ValueTree;
use proptest::test_runner::TestRunner;

fn config() -> ProptestConfig {
    ProptestConfig {
        cases: 64,
        failure_persistence: None,
        ..ProptestConfig::default()
    }
}

proptest! {
    #![proptest_config(config())]

    #[test]
    fn scalar_strategies_stay_in_range(
        b in bar(), w in frequency(), (a, c) in helmholtz_coefficients(), g in gap(),
        t in period_in_first_family(),
    ) {
        prop_assert!((0.2..=5.0).contains(&b.length()));
        prop_assert!((0.2..=5.0).contains(&b.wave_speed()));
        prop_assert!((0.1..=10.0).contains(&b.stiffness()));
        prop_assert!((0.0..=50.0).contains(&w));
        prop_assert!((-1.0..=1.0).contains(&a) && (-1.0..=1.0).contains(&c));
        prop_assert!((1e-4..=1e-1).contains(&g));
        prop_assert!(t > 3.0 && t < 4.0);
    }

    #[test]
    fn system_strategies_build_contact_systems(
        systems in (clamped_system(), robin_system(), two_bar_system())
    ) {
        let (clamped, robin, two) = systems;
        for (system, bars) in [(clamped, 1), (robin, 1), (two, 2)] {
            prop_assert_eq!(system.bars().len(), bars);
            prop_assert_eq!(system.contact_count(), 1);
            let gap = system.laws().next().unwrap().gap().offset;
            prop_assert!((1e-4..=1e-1).contains(&gap));
            let settings = HarmonicBalanceSettings { harmonics: 4, ..Default::default() };
            let mut problem = NonsmoothSystem::new(&system, settings).unwrap();
            let seed = branch_seed(&mut problem, 1, 1, 1.0).unwrap();
            prop_assert!(seed.iter().all(|v| v.is_finite()));
            prop_assert!(seed.iter().any(|v| *v != 0.0));
        }
    }
}

/// `frequency()` does hit the zero-frequency branch.
#[test]
fn frequency_strategy_draws_zero() {
    let mut runner = TestRunner::deterministic();
    let strategy = frequency();
    let zeros = (0..200)
        .filter(|_| strategy.new_tree(&mut runner).unwrap().current() == 0.0)
        .count();
    assert!(zeros >= 5, "{zeros} zeros in 200 draws");
}
