//! Sizes and numeric ranges at the edges of `usize` and `f64`: harmonics, samples, steps,
//! frequencies, time steps and gaps from zero and subnormals up to `usize::MAX`, `f64::MAX`,
//! infinity and NaN. Every call either returns a typed error or an `Ok` whose numbers are
//! all finite; none panics or aborts on an allocation. The errors carry the numbers that
//! explain them.

use nonsmooth_modes::branches::{
    compute, BackboneOptions, Method, ModeBranches, PeriodGrid, Request,
};
use nonsmooth_modes::continuation::linspace;
use nonsmooth_modes::error::OverBudget;
use nonsmooth_modes::fourier::{check_memory, Basis, CosineBasis, MEMORY_BUDGET_BYTES};
use nonsmooth_modes::modal::MIN_FREQUENCY;
use nonsmooth_modes::modal::{branch_seed, diagnose, grazing_energy, law_history};
use nonsmooth_modes::reference::{
    clamped_bar_with_obstacle, robin_bar_with_obstacle, two_bars_in_contact, ClampedFirstMode,
};
use nonsmooth_modes::solve::{SemismoothNewton, Solver};
use nonsmooth_modes::system::{
    BarSystem, HarmonicBalanceSettings, NonsmoothSystem, ParameterFamily, COMPLEMENTARITY_RANGE,
};
use nonsmooth_modes::verify::{
    periodicity_check, periodicity_of_state, Grid, Model, PeriodicityOptions, State, VerifyError,
};
use nonsmooth_modes::{ContinuationError, Error, SettingsError, Solution};
use proptest::prelude::*;
use std::f64::consts::PI;

const GAP: f64 = 1e-3;
/// Few harmonics: the properties are about ranges, not accuracy.
const HARMONICS: usize = 4;

fn settings() -> HarmonicBalanceSettings {
    HarmonicBalanceSettings {
        harmonics: HARMONICS,
        ..Default::default()
    }
}

fn clamped() -> BarSystem {
    clamped_bar_with_obstacle(GAP).unwrap()
}

/// A motion of the clamped bar with `HARMONICS` harmonics (the exact mode, truncated).
fn motion() -> Vec<f64> {
    ClampedFirstMode::new(GAP, 3.6).unknowns(HARMONICS)
}

fn config() -> ProptestConfig {
    ProptestConfig {
        cases: 256,
        ..ProptestConfig::default()
    }
}

/// Sizes that are either small or from `2^40` to `usize::MAX`. The sizes in between are
/// valid but allocate up to the memory budget (the limits are tested on their own).
fn small_or_huge_size() -> impl Strategy<Value = usize> {
    prop_oneof![
        0usize..64,
        (40u32..64).prop_map(|e| 1usize << e),
        (1usize << 40)..=usize::MAX,
        Just(usize::MAX),
    ]
}

/// Special values of `f64`: zeros, infinities, NaN, the extremes.
fn special() -> impl Strategy<Value = f64> {
    prop_oneof![
        Just(0.0),
        Just(-0.0),
        Just(f64::NAN),
        Just(f64::INFINITY),
        Just(f64::NEG_INFINITY),
        Just(f64::MAX),
        Just(-f64::MAX),
        Just(f64::MIN_POSITIVE),
        Just(MIN_FREQUENCY),
        Just(f64::from_bits(1)),
    ]
}

/// Positive subnormals.
fn subnormal() -> impl Strategy<Value = f64> {
    (1u64..1 << 52).prop_map(f64::from_bits)
}

/// `10^e` for `e` uniform in `exponents`.
fn log_uniform(exponents: std::ops::Range<f64>) -> impl Strategy<Value = f64> {
    exponents.prop_map(|e| 10f64.powf(e))
}

/// Every kind of frequency: special values, subnormals, and positive and negative values
/// log-uniform over the whole range of `f64`.
fn any_frequency() -> impl Strategy<Value = f64> {
    prop_oneof![
        special(),
        subnormal(),
        log_uniform(-324.0..308.25),
        log_uniform(-308.0..308.25).prop_map(|v| -v),
    ]
}

/// Values of `f64` out of a slow window: the special values, subnormals, negative values,
/// tiny ones `10^e` with `e < tiny` and `10^e` with `e >= ordinary` up to `f64::MAX`.
fn outside_window(tiny: f64, ordinary: f64) -> impl Strategy<Value = f64> {
    prop_oneof![
        special(),
        subnormal(),
        log_uniform(-324.0..tiny),
        log_uniform(ordinary..308.25),
        log_uniform(-308.0..308.25).prop_map(|v| -v),
    ]
}

/// Frequencies for a time-domain march: tiny ones (whose march exceeds the memory budget)
/// and ordinary to huge ones (short marches), and every invalid value. The frequencies in
/// between are valid and march for millions of steps, too long for a property test.
fn march_frequency() -> impl Strategy<Value = f64> {
    outside_window(-8.0, -0.3)
}

/// Time steps for a grid: tiny steps (cells beyond the budget) and ordinary to huge ones,
/// and every invalid value. Steps between `1e-8` and `1e-2` are valid but slow.
fn time_step() -> impl Strategy<Value = f64> {
    outside_window(-8.5, -2.0)
}

fn all_finite<'a>(values: impl IntoIterator<Item = &'a f64>) -> bool {
    values.into_iter().all(|v| v.is_finite())
}

/// NSM 1 of `system` with [`settings`] by `method`, with the full semismooth Newton.
fn run_with_newton(system: &BarSystem, method: Method) -> Result<ModeBranches, Error> {
    let request = Request {
        settings: settings(),
        method,
        solver: Some(Solver::Newton(SemismoothNewton::default())),
        ..Request::new(1)
    };
    compute(system, &request)
}

proptest! {
    #![proptest_config(config())]

    /// Any harmonics and samples: a basis whose `N = m n_h` is exact, or a typed error.
    #[test]
    fn cosine_basis_sizes(m in small_or_huge_size(), nh in small_or_huge_size()) {
        match CosineBasis::new(m, nh) {
            Ok(basis) => {
                prop_assert_eq!(basis.samples(), m * nh);
                prop_assert_eq!(basis.len(), m + 1);
            }
            Err(SettingsError::TooLarge(e)) => {
                prop_assert!(e.requested_bytes > e.budget_bytes as f64);
                prop_assert!(m >= 1 << 40 || nh >= 1 << 40);
            }
            Err(SettingsError::ZeroHarmonics) => prop_assert_eq!(m, 0),
            Err(SettingsError::TooFewSamples { got, min }) => {
                prop_assert_eq!((got, min), (nh, 3));
            }
            Err(e) => prop_assert!(false, "unexpected error {e:?}"),
        }
    }

    /// Any number of values and any ends: the values, all finite, or a typed error.
    #[test]
    fn linspace_sizes(
        start in prop_oneof![special(), log_uniform(-300.0..308.25), any::<f64>()],
        end in prop_oneof![special(), log_uniform(-300.0..308.25).prop_map(|v| -v), any::<f64>()],
        steps in small_or_huge_size(),
    ) {
        match linspace(start, end, steps) {
            Ok(values) => {
                prop_assert_eq!(values.len(), steps);
                prop_assert!(all_finite(&values), "{start} {end} {steps}: {values:?}");
                prop_assert_eq!(values[0], start);
            }
            Err(ContinuationError::TooLarge(e)) => {
                prop_assert!(steps > 1 << 29);
                prop_assert_eq!(e.requested_bytes, 8.0 * steps as f64);
            }
            Err(ContinuationError::Range(_)) => {
                prop_assert!(steps < 2 || !start.is_finite() || !end.is_finite());
            }
            Err(e) => prop_assert!(false, "unexpected error {e:?}"),
        }
    }

    /// A backbone over a period grid of `2^30` steps or more fails before it starts.
    #[test]
    fn period_grids_beyond_the_budget(steps in (1usize << 30)..=usize::MAX) {
        let options = BackboneOptions::on_grid(PeriodGrid { start: 3.9, end: 3.1, steps }, 1, 1);
        let result = run_with_newton(&clamped(), Method::PeriodGrid(options));
        prop_assert!(
            matches!(result, Err(Error::Continuation(ContinuationError::TooLarge(_)))),
            "{result:?}"
        );
    }

    /// Post-processing at any frequency: finite answers or a typed error.
    #[test]
    fn post_processing_frequencies(omega in any_frequency(), refinement in 0usize..4) {
        let system = clamped();
        let problem = NonsmoothSystem::new(&system, settings()).unwrap();
        let x = motion();
        if let Ok(h) = law_history(&problem, &x, omega, 0, 16) {
            prop_assert!(all_finite(h.time.iter().chain(&h.gap).chain(&h.force).chain(&h.residual)));
        }
        if let Ok(d) = diagnose(&problem, &x, omega, refinement) {
            prop_assert!(all_finite(&d.residual_norm));
            prop_assert!(d.max_penetration.is_finite() && d.min_contact_force.is_finite());
            prop_assert!(d.energy_drift.is_finite());
        }
        let below = !(omega.is_finite() && omega >= MIN_FREQUENCY);
        match Solution::new(&problem, &x, omega) {
            Ok(s) => {
                prop_assert!(!below);
                prop_assert!(s.period().is_finite());
                if let Ok(h) = s.end_history(system.bar_id(0).unwrap().right(), 8) {
                    prop_assert!(all_finite(h.time.iter().chain(&h.displacement).chain(&h.strain)));
                }
                if let Ok(g) = s.displacement_grid(0, 3, 4) {
                    prop_assert!(all_finite(g.time.iter().chain(&g.displacement)));
                }
            }
            Err(SettingsError::NotPositive { value, .. }) => {
                prop_assert!(omega.is_nan() || omega <= 0.0 || omega.is_infinite());
                prop_assert!(value.to_bits() == omega.to_bits());
            }
            Err(SettingsError::FrequencyTooSmall { omega: o, min, .. }) => {
                prop_assert_eq!(o, omega);
                prop_assert_eq!(min, MIN_FREQUENCY);
                prop_assert!(omega > 0.0 && omega < MIN_FREQUENCY);
            }
            Err(SettingsError::FrequencyTooLarge { omega: o, max, .. }) => {
                prop_assert_eq!(o, omega);
                prop_assert_eq!(max, problem.description().max_frequency());
                prop_assert!(omega > max);
            }
            Err(e) => prop_assert!(false, "unexpected error {e:?}"),
        }
        if below || omega > problem.description().max_frequency() {
            prop_assert!(law_history(&problem, &x, omega, 0, 16).is_err());
            prop_assert!(diagnose(&problem, &x, omega, refinement.max(1)).is_err());
            prop_assert!(ParameterFamily::new(clamped_bar_with_obstacle, settings(), omega).is_err());
        }
        let mut seeded = NonsmoothSystem::new(&system, settings()).unwrap();
        if let Ok(seed) = branch_seed(&mut seeded, 1, 1, omega) {
            prop_assert!(!below);
            prop_assert!(all_finite(&seed));
        }
    }

    /// The periodicity check at any frequency: a finite report or a typed error, never an
    /// allocation of one entry per step beyond the budget.
    #[test]
    fn periodicity_frequencies(omega in march_frequency(), periods in 1usize..3) {
        let system = clamped();
        let basis = settings().cosine_basis().unwrap();
        let options = PeriodicityOptions { dt: 0.05, periods, ..Default::default() };
        match periodicity_check(&system, &basis, &motion(), omega, &options) {
            Ok(r) => {
                prop_assert!(omega >= MIN_FREQUENCY);
                prop_assert!(all_finite(&[
                    r.period, r.dt, r.defect, r.initial_norm, r.displacement_defect,
                    r.initial_energy, r.energy_drift, r.initial_penetration, r.max_penetration,
                ]));
            }
            Err(VerifyError::TooLarge(e)) => {
                prop_assert!(e.requested_bytes > e.budget_bytes as f64);
            }
            Err(VerifyError::InvalidParameter { .. } | VerifyError::NonFinite { .. }) => {}
            Err(e) => prop_assert!(false, "unexpected error {e:?}"),
        }
    }

    /// `2^40` periods or more of an ordinary frequency: the march is over the budget. (Huge
    /// frequencies would make such marches valid but long.)
    #[test]
    fn periodicity_periods(omega in 0.5f64..1e3, periods in (1usize << 40)..=usize::MAX) {
        let system = clamped();
        let basis = settings().cosine_basis().unwrap();
        let options = PeriodicityOptions { dt: 0.05, periods, ..Default::default() };
        let result = periodicity_check(&system, &basis, &motion(), omega, &options);
        prop_assert!(matches!(result, Err(VerifyError::TooLarge(_))), "{result:?}");
    }

    /// Any time step, with or without adjusting the grid: a finite report or a typed error.
    #[test]
    fn periodicity_time_steps(dt in time_step(), adjust_grid in any::<bool>()) {
        let system = clamped();
        let basis = settings().cosine_basis().unwrap();
        let options = PeriodicityOptions { dt, adjust_grid, ..Default::default() };
        match periodicity_check(&system, &basis, &motion(), 2.0 * PI / 3.6, &options) {
            Ok(r) => {
                prop_assert!(all_finite(&[r.defect, r.dt, r.energy_drift, r.max_penetration]));
            }
            Err(
                VerifyError::TooLarge(_)
                | VerifyError::InvalidTimeStep { .. }
                | VerifyError::NonMatchingGrid { .. }
                | VerifyError::NoAdmissibleGrid { .. },
            ) => {}
            Err(e) => prop_assert!(false, "unexpected error {e:?}"),
        }
        let model = Model::from_system(&system).unwrap();
        for grid in [Grid::new(&model, dt), Grid::nearest(&model, dt)].into_iter().flatten() {
            prop_assert!(grid.dt().is_finite() && grid.dt() > 0.0);
        }
    }

    /// Any gap: a positive, finite, normal `E_g`, or a typed error naming the gap.
    #[test]
    fn grazing_energy_gaps(
        gap in prop_oneof![log_uniform(-300.0..300.0), special(), subnormal()],
        robin in any::<bool>(),
    ) {
        let system = if robin {
            robin_bar_with_obstacle(0.5, gap)
        } else {
            clamped_bar_with_obstacle(gap)
        };
        let Ok(system) = system else {
            prop_assert!(!(gap > 0.0 && gap.is_finite()));
            return Ok(());
        };
        match grazing_energy(&system) {
            Ok((e_g, _)) => prop_assert!(e_g.is_normal() && e_g > 0.0, "{gap}: {e_g}"),
            Err(SettingsError::GrazingEnergyOutOfRange { law, gap: g, energy }) => {
                prop_assert_eq!(law, 0);
                prop_assert_eq!(g, gap);
                prop_assert!(!(energy.is_normal() && energy > 0.0));
                prop_assert!(!(1e-150..=1e150).contains(&gap));
            }
            Err(e) => prop_assert!(false, "unexpected error {e:?}"),
        }
    }
}

#[test]
fn too_large_basis_says_how_much_memory_it_needs() {
    let e = CosineBasis::new(100_000, 3).unwrap_err();
    assert!(matches!(e, SettingsError::TooLarge { .. }));
    let message = e.to_string();
    for part in [
        "cosine basis",
        "8.004e10 bytes",
        "74.5 GiB",
        "4294967296 bytes",
        "4.0 GiB",
    ] {
        assert!(message.contains(part), "{part} not in {message}");
    }
    // A product that overflows `usize` is reported in bytes too.
    let message = CosineBasis::new(usize::MAX, usize::MAX)
        .unwrap_err()
        .to_string();
    assert!(message.contains("4.628e40 bytes"), "{message}");
    assert!(message.contains("(3.8e16 YiB)"), "{message}");
}

#[test]
fn too_large_grid_of_values_says_how_much_memory_it_needs() {
    let e = linspace(3.9, 3.1, usize::MAX).unwrap_err();
    assert!(matches!(e, ContinuationError::TooLarge(_)));
    let message = e.to_string();
    assert!(message.contains("1.476e20 bytes (128.0 EiB)"), "{message}");
    let message = linspace(3.9, 3.1, 1 << 40).unwrap_err().to_string();
    assert!(message.contains("8.796e12 bytes (8.0 TiB)"), "{message}");
    // The budget holds `2^29` values, not one more.
    let e = linspace(3.9, 3.1, (1 << 29) + 1).unwrap_err();
    assert!(e.to_string().contains("4.295e9 bytes (4.0 GiB)"), "{e}");
}

#[test]
fn too_large_marches_and_grids_say_how_much_memory_they_need() {
    let system = clamped();
    let basis = settings().cosine_basis().unwrap();
    let options = PeriodicityOptions::default();
    // Omega = 1e-6: 2.5e9 steps of dt = 1/400, 8 doubles each.
    let e = periodicity_check(&system, &basis, &motion(), 1e-6, &options).unwrap_err();
    let VerifyError::TooLarge(over) = &e else {
        panic!("expected TooLarge, got {e:?}");
    };
    let steps = (2.0 * PI / 1e-6 * 400.0).floor() + 1.0;
    assert_eq!(over.requested_bytes, steps * 8.0 * 8.0);
    assert!(e.to_string().contains("1.608e11 bytes (149.8 GiB)"), "{e}");
    // 1e11 cells of dt = 1e-11, 41 doubles each (the waves at their largest included).
    let model = Model::from_system(&system).unwrap();
    let e = Grid::new(&model, 1e-11).unwrap_err();
    assert!(e.to_string().contains("3.280e13 bytes (29.8 TiB)"), "{e}");
    // A subnormal step with adjust_grid: the cells overflow, reported as infinite.
    let e = Grid::nearest(&model, 1e-320).unwrap_err();
    assert!(e.to_string().contains("needs inf bytes"), "{e}");
    // Periods that overflow the march.
    let state = State::from_harmonic_balance(&system, &basis, &motion(), 1.7, 0.0, 0.01).unwrap();
    let many = PeriodicityOptions {
        periods: usize::MAX,
        ..options
    };
    assert!(matches!(
        periodicity_of_state(&state, 3.7, &many),
        Err(VerifyError::TooLarge(_))
    ));
}

#[test]
fn over_budget_converts_into_every_error() {
    let over = check_memory("a test request", 1e12).unwrap_err();
    assert_eq!(
        over,
        OverBudget {
            what: "a test request",
            requested_bytes: 8e12,
            budget_bytes: MEMORY_BUDGET_BYTES,
        }
    );
    assert_eq!(
        over.to_string(),
        "a test request needs 8.000e12 bytes (7.3 TiB), more than the memory budget of 4294967296 bytes (4.0 GiB)"
    );
    let error: Error = over.into();
    assert_eq!(error, Error::Settings(SettingsError::TooLarge(over)));
    assert_eq!(error.to_string(), over.to_string());
    assert_eq!(
        VerifyError::from(over).to_string(),
        ContinuationError::from(over).to_string()
    );
}

#[test]
fn tiny_frequencies_are_rejected_with_the_limit() {
    let system = clamped();
    let problem = NonsmoothSystem::new(&system, settings()).unwrap();
    let x = motion();
    let e = Solution::new(&problem, &x, 1e-310).unwrap_err();
    assert_eq!(
        e,
        SettingsError::FrequencyTooSmall {
            what: "fundamental frequency",
            omega: 1e-310,
            min: MIN_FREQUENCY,
        }
    );
    let message = e.to_string();
    assert!(message.contains("1e-310"), "{message}");
    assert!(message.contains("3.495137843790463e-308"), "{message}");
    assert!((2.0 * PI / MIN_FREQUENCY).is_finite());
    assert!(MIN_FREQUENCY.is_normal());
    assert!(Solution::new(&problem, &x, MIN_FREQUENCY).is_ok());
    // Zero and negative frequencies keep their error.
    for omega in [0.0, -1.0, f64::NAN] {
        assert!(matches!(
            Solution::new(&problem, &x, omega),
            Err(SettingsError::NotPositive { .. })
        ));
        assert!(matches!(
            diagnose(&problem, &x, omega, 8),
            Err(SettingsError::NotPositive { .. })
        ));
        assert!(matches!(
            law_history(&problem, &x, omega, 0, 8),
            Err(SettingsError::NotPositive { .. })
        ));
    }
    for omega in [1e-310, 3e-308] {
        assert!(matches!(
            diagnose(&problem, &x, omega, 8),
            Err(SettingsError::FrequencyTooSmall { .. })
        ));
        assert!(matches!(
            ParameterFamily::new(clamped_bar_with_obstacle, settings(), omega),
            Err(Error::Settings(SettingsError::FrequencyTooSmall { .. }))
        ));
        let mut seeded = NonsmoothSystem::new(&system, settings()).unwrap();
        assert!(matches!(
            branch_seed(&mut seeded, 1, 1, omega),
            Err(Error::Settings(SettingsError::FrequencyTooSmall { .. }))
        ));
        let basis = settings().cosine_basis().unwrap();
        assert!(matches!(
            periodicity_check(&system, &basis, &x, omega, &PeriodicityOptions::default()),
            Err(VerifyError::InvalidParameter { .. })
        ));
    }
}

#[test]
fn grazing_energy_out_of_range_names_the_gap() {
    let e = grazing_energy(&clamped_bar_with_obstacle(1e-300).unwrap()).unwrap_err();
    assert!(matches!(
        e,
        SettingsError::GrazingEnergyOutOfRange { law: 0, gap, energy } if gap == 1e-300 && energy == 0.0
    ));
    let message = e.to_string();
    assert!(message.contains("law 0 (gap 1e-300)"), "{message}");
    // Subnormal: positive but it has lost precision.
    let e = grazing_energy(&clamped_bar_with_obstacle(1e-155).unwrap()).unwrap_err();
    assert!(e.to_string().contains("gap 1e-155"), "{e}");
    // Overflow.
    let e = grazing_energy(&clamped_bar_with_obstacle(1e160).unwrap()).unwrap_err();
    assert!(e.to_string().contains("is inf"), "{e}");
    // Within range, the value of the formula `pi^2 g0^2 / 16`.
    let (e_g, _) = grazing_energy(&clamped_bar_with_obstacle(1e-150).unwrap()).unwrap();
    assert!((e_g / (PI * PI * 1e-300 / 16.0) - 1.0).abs() < 1e-9);
}

#[test]
fn non_finite_results_name_the_quantity_and_the_frequency() {
    let system = clamped();
    let settings = HarmonicBalanceSettings {
        complementarity: 1e100,
        ..settings()
    };
    let problem = NonsmoothSystem::new(&system, settings).unwrap();
    // Finite unknowns whose law values `a_c g` overflow.
    let x: Vec<f64> = motion().iter().map(|v| v / GAP * 1e300).collect();
    let omega = 2.0;
    let e = law_history(&problem, &x, omega, 0, 8).unwrap_err();
    assert_eq!(
        e.to_string(),
        "a value of a law history is not finite at omega = 2e0"
    );
    assert!(matches!(
        diagnose(&problem, &x, omega, 8),
        Err(SettingsError::NonFiniteResult { omega: o, .. }) if o == omega
    ));
}

#[test]
fn huge_post_processing_sizes_are_typed_errors() {
    let system = clamped();
    let problem = NonsmoothSystem::new(&system, settings()).unwrap();
    let x = motion();
    let solution = Solution::new(&problem, &x, 1.7).unwrap();
    let end = system.bar_id(0).unwrap().right();
    for samples in [1 << 40, usize::MAX] {
        assert!(matches!(
            solution.end_history(end, samples),
            Err(SettingsError::TooLarge(_))
        ));
        assert!(matches!(
            solution.law_history(0, samples),
            Err(SettingsError::TooLarge(_))
        ));
        assert!(matches!(
            solution.displacement_grid(0, samples, samples),
            Err(SettingsError::TooLarge(_))
        ));
        assert!(matches!(
            solution.diagnose(samples),
            Err(SettingsError::TooLarge(_))
        ));
    }
    assert!(solution.diagnose(8).is_ok());
}

/// The energy of a motion stays finite down to the smallest frequencies: where the wave
/// numbers' squares underflow to zero, equal squares take the diagonal integrals (no division
/// by `k_i^2 - k_j^2 = 0`).
#[test]
fn energy_is_finite_at_tiny_frequencies() {
    let system = clamped_bar_with_obstacle(1e-3).unwrap();
    let basis = CosineBasis::new(8, 30).unwrap();
    let n = basis.len() * system.unknowns_per_harmonic();
    let x: Vec<f64> = (0..n).map(|i| 1e-4 * ((i % 5) as f64 - 2.0)).collect();
    let reference = nonsmooth_modes::modal::energy(&system, &basis, &x, 1e-100);
    assert!(reference.is_finite() && reference > 0.0);
    for omega in [1e-160, 1e-200, 1e-300] {
        let e = nonsmooth_modes::modal::energy(&system, &basis, &x, omega);
        assert!(
            (e / reference - 1.0).abs() < 1e-12,
            "omega {omega:e}: {e:e} vs {reference:e}"
        );
    }
}

/// A problem whose Gram matrices, reduced matrix or dense Jacobian exceed the memory budget is
/// a typed error that says how much it needs, before anything is allocated; the paper's sizes
/// build.
#[test]
fn problems_beyond_the_budget_are_typed_errors() {
    let two = two_bars_in_contact(
        nonsmooth_modes::bar::Bar::new(0.95, 1.0, 1.0).unwrap(),
        1e-3,
    )
    .unwrap();
    for harmonics in [20, 80, 640] {
        let settings = HarmonicBalanceSettings {
            harmonics,
            ..Default::default()
        };
        assert!(
            NonsmoothSystem::new(&two, settings).is_ok(),
            "m = {harmonics}"
        );
    }
    // 20 000 harmonics fit the basis alone but not the problem of two bars (its dense
    // Jacobian has 80 000^2 entries).
    let settings = HarmonicBalanceSettings {
        harmonics: 20_000,
        samples_per_harmonic: 4,
        ..Default::default()
    };
    assert!(settings.cosine_basis().is_ok());
    match NonsmoothSystem::new(&two, settings) {
        Err(Error::Settings(SettingsError::TooLarge(over))) => {
            assert!(over.requested_bytes > over.budget_bytes as f64);
            assert!(
                over.to_string().contains("harmonic-balance problem"),
                "{over}"
            );
        }
        other => panic!("{:?}", other.map(|p| p.dimension())),
    }
}

/// At huge frequencies the energy of a fixed motion grows as `Omega^2` (its strain energy is
/// `(k A)^2`-sized, `k = j Omega / c`) and `modal::energy` stays finite while that fits in an
/// `f64` (from `Omega ~ 1e150` it does not: the low-level function returns the number as
/// computed, `Solution` refuses such frequencies).
#[test]
fn energy_is_finite_up_to_huge_frequencies() {
    let system = clamped();
    let basis = CosineBasis::new(HARMONICS, 30).unwrap();
    let x: Vec<f64> = (0..basis.len() * system.unknowns_per_harmonic())
        .map(|i| 1e-4 * ((i % 5) as f64 - 2.0))
        .collect();
    let energy = |omega: f64| nonsmooth_modes::modal::energy(&system, &basis, &x, omega);
    let base = energy(1e10);
    for e in [40, 80, 120, 150] {
        let omega = 10f64.powi(e);
        let ratio = energy(omega) / base / (omega / 1e10).powi(2);
        assert!((ratio - 1.0).abs() < 1e-9, "omega 1e{e}: ratio {ratio}");
    }
    let problem = NonsmoothSystem::new(&system, settings()).unwrap();
    let mode = Solution::new(&problem, &x, 1.0).unwrap();
    for theta in [f64::NAN, f64::INFINITY] {
        assert!(matches!(
            mode.energy_at(theta),
            Err(SettingsError::NotFinite { .. })
        ));
    }
}

/// `modal::energy` is a low-level function with a documented length contract: it panics,
/// with a message, on unknowns of the wrong length (`Solution::new` returns
/// `SettingsError::Length` instead).
#[test]
#[should_panic(expected = "modal::energy: the unknowns have the wrong length")]
fn energy_of_unknowns_of_the_wrong_length_panics_as_documented() {
    let system = clamped();
    let basis = CosineBasis::new(HARMONICS, 30).unwrap();
    let x = vec![0.0; basis.len() * system.unknowns_per_harmonic() + 1];
    nonsmooth_modes::modal::energy(&system, &basis, &x, 1.0);
}

/// The complementarity parameter is accepted on `COMPLEMENTARITY_RANGE`, where the residual
/// and Jacobian of a motion are finite at both ends; beyond, a typed error names the range.
#[test]
fn complementarity_parameters_keep_the_residual_finite_or_are_rejected() {
    use nonsmooth_modes::continuation::ContinuationProblem;
    use nonsmooth_modes::linalg::DenseMatrix;
    use nonsmooth_modes::solve::Problem;
    let (min, max) = COMPLEMENTARITY_RANGE;
    let system = clamped();
    let x = motion();
    for a_c in [min, 1e-3, 4.0, 1e3, max] {
        let settings = HarmonicBalanceSettings {
            complementarity: a_c,
            ..settings()
        };
        let mut problem = NonsmoothSystem::new(&system, settings).unwrap();
        problem.set_parameter(2.0 * PI / 3.6);
        let mut f = vec![0.0; x.len()];
        problem.residual(&x, &mut f);
        let mut jac = DenseMatrix::zeros(x.len(), x.len());
        problem.jacobian(&x, &mut jac);
        assert!(all_finite(&f), "a_c {a_c:e}: residual {f:?}");
        assert!(jac.is_finite(), "a_c {a_c:e}: Jacobian");
    }
    for a_c in [min / 2.0, 1e-300, 5e-324, max * 2.0, 1e300, f64::MAX] {
        let settings = HarmonicBalanceSettings {
            complementarity: a_c,
            ..settings()
        };
        match NonsmoothSystem::new(&system, settings) {
            Err(Error::Settings(SettingsError::OutOfRange {
                value,
                min: lo,
                max: hi,
                ..
            })) => assert_eq!((value, lo, hi), (a_c, min, max)),
            other => panic!("a_c {a_c:e}: {:?}", other.map(|p| p.dimension())),
        }
    }
}

/// Finite unknowns whose energy overflows (a seed scaled to `1e300`): `Solution` accepts
/// them, and its normalised energy and the periodicity check return typed errors naming the
/// quantity instead of `Ok(NaN)` (found by `tests/stress/`).
#[test]
fn overflowing_motions_are_typed_errors() {
    let system = clamped();
    let problem = NonsmoothSystem::new(&system, settings()).unwrap();
    let x: Vec<f64> = motion().iter().map(|v| v * 1e300 / GAP).collect();
    assert!(x.iter().all(|v| v.is_finite()));
    let omega = 2.0 * PI / 3.6;
    let solution = Solution::new(&problem, &x, omega).unwrap();
    for result in [solution.energy(), solution.energy_normalized()] {
        match result {
            Err(SettingsError::NonFiniteResult { what, omega: o }) => {
                assert_eq!((what, o), ("energy", omega));
            }
            other => panic!("{other:?}"),
        }
    }
    let options = PeriodicityOptions {
        dt: 0.05,
        ..Default::default()
    };
    match solution.periodicity_check(&options) {
        Err(e @ VerifyError::NonFiniteResult { value, .. }) => {
            assert!(!value.is_finite());
            assert!(
                e.to_string()
                    .contains("of the periodicity check is not finite"),
                "{e}"
            );
        }
        other => panic!("{other:?}"),
    }
    // The same motion at an ordinary size still checks.
    let small: Vec<f64> = x.iter().map(|v| v * 1e-300).collect();
    let solution = Solution::new(&problem, &small, omega).unwrap();
    assert!(solution.energy_normalized().unwrap().is_finite());
    assert!(solution.periodicity_check(&options).is_ok());
}

/// Parameter values near `±f64::MAX` whose step overflows are refused by the sequential
/// driver (each point reports its step, which would be infinite), and a parameter branch
/// from a system without grazing energy is refused like a backbone (found by
/// `tests/stress/`).
#[test]
fn overflowing_steps_and_missing_grazing_energy_are_typed_errors() {
    use nonsmooth_modes::branches::{parameter_branch, ParameterSteps};
    use nonsmooth_modes::continuation::{Sequential, SequentialOptions};
    let problem = NonsmoothSystem::new(&clamped(), settings()).unwrap();
    let start = motion();
    match Sequential::new(
        problem,
        SemismoothNewton::default(),
        start.clone(),
        vec![1.0, -f64::MAX, f64::MAX],
        SequentialOptions::default(),
    ) {
        Err(ContinuationError::InvalidOption { what, value }) => {
            assert_eq!(value, f64::MAX);
            assert!(what.contains("overflows"), "{what}");
        }
        other => panic!("{:?}", other.map(|_| ())),
    }
    let steps = ParameterSteps::Values(vec![1e-300, 1e-3], Default::default());
    let result = parameter_branch(
        clamped_bar_with_obstacle,
        settings(),
        (start, 2.0 * PI / 3.6),
        1e-300,
        steps,
        SemismoothNewton::default(),
        |_, _| std::ops::ControlFlow::Continue(()),
    );
    assert!(
        matches!(
            result,
            Err(Error::Settings(SettingsError::GrazingEnergyOutOfRange { gap, .. })) if gap == 1e-300
        ),
        "{result:?}"
    );
}

/// Frequencies whose highest harmonic's phase over a bar exceeds `MAX_PHASE` are rejected
/// by the seeds, `Solution`, the backbones and the post-processing, with the problem's own
/// limit; at the limit a motion's numbers are finite.
#[test]
fn huge_frequencies_are_rejected_with_the_problem_limit() {
    use nonsmooth_modes::branches::ArclengthBackboneOptions;
    use nonsmooth_modes::system::MAX_PHASE;
    let system = clamped();
    let mut problem = NonsmoothSystem::new(&system, settings()).unwrap();
    let max = problem.description().max_frequency();
    // The clamped bar is a unit bar: k l = m Omega.
    assert_eq!(max, MAX_PHASE / HARMONICS as f64);
    let x = motion();
    let at_limit = Solution::new(&problem, &x, max).unwrap();
    assert!(at_limit.energy().unwrap().is_finite());
    assert!(branch_seed(&mut problem, 1, 1, max).is_ok());
    let too_large = |result: Result<(), Error>, what: &str| match result {
        Err(Error::Settings(SettingsError::FrequencyTooLarge { omega, max: m, .. })) => {
            assert!(omega > m && m == max, "{what}: {omega:e} vs {m:e}");
        }
        other => panic!("{what}: {other:?}"),
    };
    for omega in [max * 1.01, 1e300, f64::MAX] {
        too_large(
            Solution::new(&problem, &x, omega)
                .map(|_| ())
                .map_err(Error::from),
            "Solution",
        );
        too_large(
            branch_seed(&mut problem, 1, 1, omega).map(|_| ()),
            "branch_seed",
        );
        too_large(
            law_history(&problem, &x, omega, 0, 1)
                .map(|_| ())
                .map_err(Error::from),
            "law_history",
        );
        let grid = PeriodGrid {
            start: 3.9,
            end: 2.0 * PI / omega,
            steps: 3,
        };
        let options = BackboneOptions::on_grid(grid, 1, 1);
        too_large(
            run_with_newton(&system, Method::PeriodGrid(options)).map(|_| ()),
            "backbone",
        );
        let options = ArclengthBackboneOptions {
            omega_range: (1.0, omega),
            ..ArclengthBackboneOptions::for_mode(&system, 1, 1).unwrap()
        };
        too_large(
            run_with_newton(&system, Method::Arclength(options)).map(|_| ()),
            "arclength_backbone",
        );
    }
}

/// A dogleg whose trust radius shrinks to zero (a tiny initial radius and a subnormal minimum
/// radius that underflows relative to a small solution) gives up with a typed error instead
/// of shrinking forever (found by `tests/stress/`, seed `0x1234abcd`, case 2403).
#[test]
fn a_dogleg_whose_radius_reaches_zero_gives_up() {
    use nonsmooth_modes::continuation::ContinuationProblem;
    use nonsmooth_modes::solve::{Dogleg, DoglegOptions, NonlinearSolver};
    use nonsmooth_modes::SolveError;
    let gap = 1.4e-6;
    let system = clamped_bar_with_obstacle(gap).unwrap();
    let settings = HarmonicBalanceSettings {
        harmonics: 1,
        samples_per_harmonic: 31,
        ..Default::default()
    };
    let mut problem = NonsmoothSystem::new(&system, settings).unwrap();
    let omega = 2.0 * PI / 3.6;
    let mut x: Vec<f64> = branch_seed(&mut problem, 1, 1, omega)
        .unwrap()
        .iter()
        .map(|v| 1.7 * v)
        .collect();
    problem.set_parameter(omega);
    let solver = Dogleg::new(DoglegOptions {
        initial_radius: 1e-300,
        min_radius: 5e-324,
        ..Default::default()
    })
    .unwrap();
    match solver.solve(&mut problem, &mut x) {
        Ok(info) => assert!(info.residual_norm.is_finite()),
        Err(SolveError::TrustRegion { radius, .. }) => assert!(radius >= 0.0),
        Err(e) => assert!(!e.to_string().is_empty()),
    }
}

/// A grid whose end is below the rounding of its start (`1e300 -> 4.19`) ends at its end and
/// stays between its ends (the steps alone would end at 0, a period of zero; found by
/// `tests/stress/`, seed `0x1234abcd`, case 20735); ordinary grids keep their steps.
#[test]
fn grids_end_at_their_end_whatever_the_scale_of_their_start() {
    for (start, end) in [
        (1e300, 4.188),
        (4.188, 1e300),
        (-1e300, 1e-3),
        (1e-320, 1e300),
    ] {
        let values = linspace(start, end, 5).unwrap();
        assert_eq!(values[0], start);
        assert_eq!(values[4], end, "{start:e} -> {end:e}: {values:?}");
        let (lo, hi) = (start.min(end), start.max(end));
        assert!(values.iter().all(|v| (lo..=hi).contains(v)), "{values:?}");
    }
    let paper = linspace(3.95, 3.05, 181).unwrap();
    let h = (3.05 - 3.95) / 180.0;
    assert!(paper
        .iter()
        .enumerate()
        .all(|(i, &v)| v == 3.95 + h * i as f64));
}

/// A law whose gap exceeds `MAX_OFFSET` (motions reaching it would have energies beyond
/// `f64`) is refused by the problem with the limit; `1e150` itself builds.
#[test]
fn gaps_beyond_the_offset_limit_are_refused_by_the_problem() {
    use nonsmooth_modes::system::MAX_OFFSET;
    assert!(
        NonsmoothSystem::new(&clamped_bar_with_obstacle(MAX_OFFSET).unwrap(), settings()).is_ok()
    );
    for gap in [1e151, 1e300, f64::MAX] {
        match NonsmoothSystem::new(&clamped_bar_with_obstacle(gap).unwrap(), settings()) {
            Err(Error::Settings(SettingsError::OutOfRange { value, max, .. })) => {
                assert_eq!((value, max), (gap, MAX_OFFSET));
            }
            other => panic!("gap {gap:e}: {:?}", other.map(|p| p.dimension())),
        }
    }
}
