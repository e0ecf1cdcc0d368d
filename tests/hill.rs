//! Hill's method on the harmonic-balance equations (`nonsmooth_modes::stability::hill`):
//! checks that can fail, on a motion that never touches and on bad input (gap homogeneity
//! on harmonic-balance points is in `tests/stability.rs`, beside the exact map's).

use nonsmooth_modes::bar::{Bar, EndRef};
use nonsmooth_modes::bc::{BoundaryCondition, LinearRows, Quantity, Term};
use nonsmooth_modes::error::{Error, SettingsError, StabilityError};
use nonsmooth_modes::modal::{branch_seed, open_mode};
use nonsmooth_modes::reference::{clamped_bar_with_obstacle, robin_bar_with_obstacle};
use nonsmooth_modes::stability::{hill, HillOptions, HillUnresolved, Verdict, HILL_RESIDUAL};
use nonsmooth_modes::system::{AssemblyBuilder, HarmonicBalanceSettings, NonsmoothSystem};

fn settings(harmonics: usize) -> HarmonicBalanceSettings {
    HarmonicBalanceSettings {
        harmonics,
        ..HarmonicBalanceSettings::default()
    }
}

/// Half the grazing seed of the Robin bar's first linear mode never reaches the obstacle:
/// a linear motion, whose exponents all lie on the imaginary axis. Nothing is found beyond
/// the tolerance, the trivial exponent is 0 to rounding, and the verdict is stable.
#[test]
fn a_motion_without_contact_is_stable_with_its_trivial_exponent() {
    let system = robin_bar_with_obstacle(0.5, 1e-3).unwrap();
    let omega = open_mode(&system, 1).unwrap().omega;
    let mut problem = NonsmoothSystem::new(&system, settings(10)).unwrap();
    let seed = branch_seed(&mut problem, 1, 1, omega).unwrap();
    let x: Vec<f64> = seed.iter().map(|v| 0.5 * v).collect();
    let h = hill(&system, settings(10), &x, omega, &HillOptions::default()).unwrap();
    assert_eq!(h.verdict, Verdict::Stable, "{h:?}");
    assert!(h.exponents.is_empty() && h.max_multiplier == 1.0, "{h:?}");
    assert!(h.residual < 1e-12, "{}", h.residual);
    assert!(h.trivial_distance.is_some_and(|d| d < 1e-8), "{h:?}");
    assert!(h.time_shift_residual < 1e-12, "{}", h.time_shift_residual);
    assert_eq!(h.unresolved, None);
}

/// The same motion with its unknowns perturbed no longer solves the equations: no verdict,
/// and the reason gives the residual against the bound.
#[test]
fn a_point_that_misses_the_equations_says_so() {
    let system = robin_bar_with_obstacle(0.5, 1e-3).unwrap();
    let omega = open_mode(&system, 1).unwrap().omega;
    let mut problem = NonsmoothSystem::new(&system, settings(10)).unwrap();
    let seed = branch_seed(&mut problem, 1, 1, omega).unwrap();
    let x: Vec<f64> = (seed.iter().enumerate())
        .map(|(i, v)| 0.5 * v + if i == 3 { 1e-3 } else { 0.0 })
        .collect();
    let h = hill(&system, settings(10), &x, omega, &HillOptions::default()).unwrap();
    assert_eq!(h.verdict, Verdict::Unresolved, "{h:?}");
    match h.unresolved {
        Some(HillUnresolved::Residual { residual, bound }) => {
            assert!(
                residual > bound && bound == HILL_RESIDUAL,
                "{residual} {bound}"
            );
            assert_eq!(residual, h.residual);
        }
        other => panic!("{other:?}"),
    }
    assert!(h.unresolved.unwrap().to_string().contains("misses"));
}

/// A condition whose rows depend on the frequency (an end mass, `-M omega^2 u`) cannot be
/// given the exponent: a typed error naming it.
#[test]
fn a_frequency_dependent_condition_is_refused() {
    #[derive(Debug)]
    struct EndMass(EndRef);
    impl BoundaryCondition for EndMass {
        fn name(&self) -> String {
            "end mass".into()
        }
        fn ends(&self) -> Vec<EndRef> {
            vec![self.0]
        }
        fn linear_rows(&self, omega: f64, _: &dyn Fn(EndRef) -> f64, rows: &mut LinearRows) {
            rows.push(&[
                Term::new(self.0, Quantity::ContactForce, 1.0),
                Term {
                    end: self.0,
                    quantity: Quantity::Displacement,
                    coefficient: -0.1 * omega * omega,
                    d_coefficient: -0.2 * omega,
                },
            ]);
        }
    }
    let mut b = AssemblyBuilder::new();
    let bar = b.add_bar(Bar::unit());
    b.add_condition(EndMass(bar.left())).unwrap();
    b.signorini(bar.right(), 1e-3).unwrap();
    let system = b.build().unwrap();
    let x = vec![0.0; 2 * 11];
    let error = hill(&system, settings(10), &x, 1.5, &HillOptions::default()).unwrap_err();
    assert!(
        matches!(error, Error::Stability(StabilityError::HillUnsupported { ref condition }) if condition == "end mass"),
        "{error}"
    );
}

/// Bad options, frequencies and states are typed errors with their numbers.
#[test]
fn bad_input_is_a_typed_error() {
    let system = clamped_bar_with_obstacle(1e-3).unwrap();
    let x = vec![0.0; 2 * 11];
    let run = |x: &[f64], omega: f64, options: HillOptions| {
        hill(&system, settings(10), x, omega, &options)
    };
    let ok = HillOptions::default();
    for bad in [
        HillOptions {
            tolerance: -1.0,
            ..ok
        },
        HillOptions {
            tolerance: f64::NAN,
            ..ok
        },
        HillOptions {
            max_modulus: 1.0,
            ..ok
        },
        HillOptions {
            max_modulus: f64::INFINITY,
            ..ok
        },
        HillOptions {
            shifts_per_frequency: 0,
            ..ok
        },
        HillOptions {
            shifts_per_frequency: 33,
            ..ok
        },
        HillOptions {
            max_modulus: 1e7,
            ..ok
        },
    ] {
        assert!(
            matches!(
                run(&x, 1.5, bad),
                Err(Error::Stability(StabilityError::InvalidOption { .. }))
            ),
            "{bad:?}"
        );
    }
    for omega in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        assert!(matches!(
            run(&x, omega, ok),
            Err(Error::Settings(SettingsError::NotPositive { .. }))
        ));
    }
    assert!(matches!(
        run(&x[..5], 1.5, ok),
        Err(Error::Settings(SettingsError::Length { got: 5, .. }))
    ));
    let mut nan = x.clone();
    nan[3] = f64::NAN;
    assert!(matches!(
        run(&nan, 1.5, ok),
        Err(Error::Settings(SettingsError::NotFinite { .. }))
    ));
    assert!(matches!(
        hill(&system, settings(0), &x, 1.5, &ok),
        Err(Error::Settings(_))
    ));
    assert!(matches!(
        hill(&system, settings(500), &x, 1.5, &ok),
        Err(Error::Stability(StabilityError::HillTooLarge {
            dimension: 2002,
            ..
        }))
    ));
    let mut b = AssemblyBuilder::new();
    let bar = b.add_bar(Bar::unit());
    b.dirichlet(bar.left()).unwrap();
    b.neumann(bar.right()).unwrap();
    let linear = b.build().unwrap();
    assert!(matches!(
        hill(&linear, settings(10), &x, 1.5, &ok),
        Err(Error::Settings(SettingsError::NoContact))
    ));
}
