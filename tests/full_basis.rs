//! The full Fourier basis (constant + cosines + sines, with a phase condition) holds every
//! even motion of the cosine basis: on the paper's three systems its backbones equal the
//! cosine ones, a time shift of a solution is a solution, and its points pass the
//! time-domain check.

use nonsmooth_modes::branches::{
    asymmetry, compute, full_basis_branch, full_basis_system, quadrature_start, shift_origin,
    symmetry_instant, to_full_basis, with_harmonics, BackboneOptions, BackbonePoint,
    FullBasisBranch, Method, Request, TimeDomainCheck,
};
use nonsmooth_modes::fourier::{frequency_of_period, CosineBasis};
use nonsmooth_modes::modal::{energy_at, Label};
use nonsmooth_modes::reference::{
    clamped_bar_with_obstacle, paper_second_bar, robin_bar_with_obstacle, two_bars_in_contact,
};
use nonsmooth_modes::solve::Solver;
use nonsmooth_modes::system::{BarSystem, HarmonicBalanceSettings};
use nonsmooth_modes::verify::{periodicity_check, PeriodicityOptions};
use nonsmooth_modes::{Error, SettingsError};
use std::f64::consts::PI;

const M: usize = 20;

fn settings() -> HarmonicBalanceSettings {
    HarmonicBalanceSettings {
        harmonics: M,
        ..Default::default()
    }
}

/// The cosine backbone of NSM1 on the system's derived grid, and the full-basis branch
/// started from its first converged point over the same periods.
fn both(system: &BarSystem) -> (Vec<BackbonePoint>, FullBasisBranch) {
    let options = BackboneOptions::for_mode(system, 1, 1).unwrap();
    let request = Request::for_method(Method::PeriodGrid(options))
        .settings(settings())
        .solver(Solver::default());
    let run = compute(system, &request).unwrap();
    let first = run.points.iter().find(|p| p.converged()).unwrap().clone();
    let periods = (run.points.iter())
        .filter(|p| p.step >= first.step)
        .map(|p| p.period)
        .collect();
    let start = to_full_basis(&first.x, M).unwrap();
    let full = full_basis_branch(
        system,
        &Request::new(1).settings(settings()),
        &start,
        periods,
    );
    (run.points, full.unwrap())
}

/// On the clamped bar, the Robin bar and the two-bar configuration 1, the full basis
/// converges at the cosine backbone's periods to the same energies (1e-8 relative), with
/// sines and unfolding at rounding level.
#[test]
fn the_full_basis_reproduces_the_papers_cosine_backbones() {
    let two_bar = paper_second_bar(0.95, 1.0, 1.0).unwrap();
    let systems = [
        ("clamped", clamped_bar_with_obstacle(1e-3).unwrap()),
        ("robin", robin_bar_with_obstacle(0.5, 1e-3).unwrap()),
        ("two-bar", two_bars_in_contact(two_bar, 1e-3).unwrap()),
    ];
    for (name, system) in systems {
        let (cosine, full) = both(&system);
        let converged = cosine.iter().filter(|p| p.converged()).count();
        let mut common = 0;
        for q in &full.points {
            let Some(p) = cosine
                .iter()
                .find(|p| p.converged() && p.period == q.point.period)
            else {
                continue;
            };
            common += 1;
            let relative = (q.point.energy - p.energy).abs() / p.energy;
            assert!(
                relative < 1e-8,
                "{name} T = {}: cosine E = {:e}, full E = {:e}",
                q.point.period,
                p.energy,
                q.point.energy
            );
            assert!(q.sine_share < 1e-16, "{name}: sines {:e}", q.sine_share);
            assert!(q.asymmetry < 1e-16, "{name}: asymmetry {:e}", q.asymmetry);
        }
        assert!(
            common * 10 >= converged * 9,
            "{name}: {common} common steps of {converged} converged cosine points"
        );
    }
}

/// A shift by whole grid steps leaves the sampled equations invariant: the phase locks to
/// the shifted start, which solves them as it is, with sines but even about another
/// instant. Any other shift is a symmetry of the exact problem only: the solver lands on a
/// neighbouring solution of the sampled one, even to the grid's resolution, as periodic in
/// the time-domain check as the unshifted motion.
#[test]
fn a_shifted_motion_is_the_same_motion() {
    let system = clamped_bar_with_obstacle(1e-3).unwrap();
    let (cosine, _) = both(&system);
    let p = cosine
        .iter()
        .find(|p| p.converged() && p.period < 3.6)
        .unwrap();
    let even = to_full_basis(&p.x, M).unwrap();
    let samples = settings().samples_per_harmonic * M;
    let on_grid = 2.0 * PI * 7.0 / samples as f64;
    let solve = |phi: f64| {
        let start = shift_origin(&even, M, phi).unwrap();
        let run = full_basis_branch(
            &system,
            &Request::new(1).settings(settings()),
            &start,
            vec![p.period],
        );
        (start, run.unwrap().points.remove(0))
    };

    let (start, q) = solve(on_grid);
    let size = start.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    for (a, b) in q.point.x.iter().zip(&start) {
        assert!((a - b).abs() < 1e-9 * size, "{a:e} vs {b:e}");
    }
    assert!(q.sine_share > 1e-3, "sines {:e}", q.sine_share);
    assert!(q.asymmetry < 1e-14, "asymmetry {:e}", q.asymmetry);
    assert!(q.unfolding.abs() < 1e-12, "mu {:e}", q.unfolding);
    let omega = frequency_of_period(p.period);
    let moved = energy_at(
        &system,
        &CosineBasis::new(M, 30).unwrap(),
        &p.x,
        omega,
        on_grid,
    );
    assert!(
        (q.point.energy - moved).abs() < 1e-10 * moved,
        "{:e} vs {moved:e}",
        q.point.energy
    );

    let (_, q) = solve(0.7);
    assert!(q.asymmetry < 1e-5, "asymmetry {:e}", q.asymmetry);
    assert!((q.point.energy_normalized / p.energy_normalized - 1.0).abs() < 0.01);
    let full = full_basis_system(&system, &settings()).unwrap();
    let options = PeriodicityOptions::default();
    let check = |x: &[f64]| periodicity_check(&system, full.basis(), x, omega, &options).unwrap();
    let (shifted, unshifted) = (check(&q.point.x), check(&even));
    assert!(
        shifted.displacement_defect <= 2.0 * unshifted.displacement_defect + 1e-3,
        "shifted {:e} vs even {:e}",
        shifted.displacement_defect,
        unshifted.displacement_defect
    );
}

/// The clamped bar has periodic motions that are not even in time: from seeds that put
/// modes 2 to 4 in quadrature with mode 1 at `T = 3.089` (a period of the paper's grid,
/// `linspace(3.95, 3.05, 24)`), some solve to motions whose smallest sine share over the
/// time shifts is above 1 %, which stay that asymmetric with twice the harmonics and pass
/// the time-domain check there (`examples/odd_motions.rs` searches more widely).
#[test]
fn the_clamped_bar_has_motions_that_are_not_even() {
    let system = clamped_bar_with_obstacle(1e-3).unwrap();
    let period = 3.95 - 22.0 * (3.95 - 3.05) / 23.0;
    let omega = frequency_of_period(period);
    let mut full = full_basis_system(&system, &settings()).unwrap();
    let lifted = HarmonicBalanceSettings {
        harmonics: 2 * M,
        ..settings()
    };
    let check = TimeDomainCheck::for_system(&system);
    let checked = Request::new(1).settings(lifted).checked(check);
    let mut found = 0;
    for mode in 2..=4 {
        for ratio in [0.1, 0.3, 1.0, 3.0] {
            let (start, _) = quadrature_start(&mut full, mode, ratio, omega).unwrap();
            let run = full_basis_branch(
                &system,
                &Request::new(1).settings(settings()),
                &start,
                vec![period],
            );
            let Some(p) = run.unwrap().points.pop() else {
                continue;
            };
            if p.asymmetry < 1e-2 {
                continue;
            }
            let start = with_harmonics(&p.point.x, M, 2 * M).unwrap();
            let run = full_basis_branch(&system, &checked, &start, vec![period]);
            let Some(q) = run.unwrap().points.pop() else {
                continue;
            };
            let report = q.point.time_domain.expect("the check ran");
            if q.asymmetry > 1e-2 && report.displacement_defect < check.max_displacement_defect {
                found += 1;
            }
        }
    }
    assert!(found > 0, "no motion that is not even at T = {period}");
}

/// Bad requests are typed errors: a start of the wrong length or at rest, no periods, no
/// harmonics.
#[test]
fn bad_requests_are_typed_errors() {
    let system = clamped_bar_with_obstacle(1e-3).unwrap();
    let full = full_basis_system(&system, &settings()).unwrap();
    let n = full.dimension();
    let run = |start: &[f64], periods: Vec<f64>, s: &HarmonicBalanceSettings| {
        full_basis_branch(&system, &Request::new(1).settings(*s), start, periods)
    };
    assert!(matches!(
        run(&vec![1e-4; n - 1], vec![3.5], &settings()),
        Err(Error::Settings(SettingsError::Length { .. }))
    ));
    assert!(matches!(
        run(&vec![0.0; n], vec![3.5], &settings()),
        Err(Error::Settings(SettingsError::StillReference { .. }))
    ));
    assert!(run(&vec![1e-4; n], vec![], &settings()).is_err());
    assert!(run(&vec![1e-4; n], vec![f64::NAN], &settings()).is_err());
    let none = HarmonicBalanceSettings {
        harmonics: 0,
        ..settings()
    };
    assert!(matches!(
        run(&vec![1e-4; n], vec![3.5], &none),
        Err(Error::Settings(SettingsError::ZeroHarmonics))
    ));
}

/// A full-basis point is annotated as `compute` annotates its points: asked for, the
/// time-domain check runs on it, and its label is the cosine point's (an even motion is the
/// same motion in either basis, so both checks march the same initial state).
#[test]
fn full_basis_points_are_checked_and_labelled_as_the_cosine_ones() {
    let system = clamped_bar_with_obstacle(1e-3).unwrap();
    let mut options = BackboneOptions::for_mode(&system, 1, 1).unwrap();
    options.grid = nonsmooth_modes::branches::PeriodGrid {
        start: 3.9,
        end: 3.5,
        steps: 5,
    };
    let request = Request::for_method(Method::PeriodGrid(options))
        .settings(settings())
        .solver(Solver::default())
        .checked(TimeDomainCheck::for_system(&system));
    let cosine = compute(&system, &request).unwrap();
    let first = cosine.points.iter().find(|p| p.converged()).unwrap();
    let periods = (cosine.points.iter())
        .filter(|p| p.step >= first.step)
        .map(|p| p.period)
        .collect();
    let start = to_full_basis(&first.x, M).unwrap();
    let full = full_basis_branch(&system, &request, &start, periods).unwrap();
    assert!(!full.points.is_empty());
    for q in &full.points {
        let p = (cosine.points.iter())
            .find(|p| p.period == q.point.period)
            .unwrap();
        assert_eq!(q.point.label, p.label, "T = {}", p.period);
        assert_eq!(q.point.label, Some(Label::Skeleton), "T = {}", p.period);
        let (a, b) = (q.point.time_domain.unwrap(), p.time_domain.unwrap());
        assert!(
            (a.displacement_defect - b.displacement_defect).abs() < 1e-9,
            "{a:?} vs {b:?}"
        );
    }
}

/// A quadrature start is the first mode's seed on the cosine of harmonic 1 plus the other
/// mode's on the sine of the harmonic nearest its frequency, scaled by the ratio; a harmonic
/// beyond the basis is a typed error.
#[test]
fn a_quadrature_start_puts_the_second_mode_on_a_sine() {
    let system = clamped_bar_with_obstacle(1e-3).unwrap();
    let omega = frequency_of_period(3.9);
    let mut full = full_basis_system(&system, &settings()).unwrap();
    let (unit, n) = quadrature_start(&mut full, 2, 1.0, omega).unwrap();
    let (half, m) = quadrature_start(&mut full, 2, 0.5, omega).unwrap();
    assert_eq!(
        (n, m),
        (3, 3),
        "mode 2 (3 pi / 2) is nearest harmonic 3 at T = 3.9"
    );
    let per = unit.len() / (2 * M + 1);
    let sine = (M + n) * per..(M + n + 1) * per;
    for (i, (a, b)) in unit.iter().zip(&half).enumerate() {
        if sine.contains(&i) {
            assert!((a - 2.0 * b).abs() <= 1e-15 * a.abs(), "{a} vs {b}");
            assert!(a.abs() > 0.0 || b.abs() == 0.0);
        } else {
            assert_eq!(a, b, "coefficient {i} is the first mode's");
        }
    }
    assert!(unit[sine].iter().any(|v| *v != 0.0));
    let few = HarmonicBalanceSettings {
        harmonics: 2,
        ..settings()
    };
    let mut small = full_basis_system(&system, &few).unwrap();
    assert!(matches!(
        quadrature_start(&mut small, 4, 1.0, omega),
        Err(Error::Settings(SettingsError::HarmonicOutOfRange {
            harmonics: 2,
            ..
        }))
    ));
}

/// The reliability reproducers of the full-basis helpers: counts near `usize::MAX` (whose
/// `m + 1` or `2 m + 1` overflowed), a state whose length does not fit its harmonics (a
/// slice panic), 2^40 harmonics (an aborted allocation) and `shift_origin` at `1 << 62`
/// harmonics (a loop that never ended) are typed errors quoting what was given; a state
/// scaled to the ends of `f64` keeps a finite asymmetry, the same as unscaled.
#[test]
fn the_full_basis_helpers_refuse_what_does_not_fit() {
    let layout = |r: Result<Vec<f64>, SettingsError>| match r {
        Err(SettingsError::StateLayout {
            got,
            harmonics,
            coefficients,
            ..
        }) => (got, harmonics, coefficients),
        other => panic!("{other:?}"),
    };
    let x = [1.0, 2.0, 3.0, 4.0, 5.0];
    let max = usize::MAX;
    let wide = max as u128;
    assert_eq!(layout(to_full_basis(&x, max)), (5, max, wide + 1));
    assert_eq!(layout(to_full_basis(&x, 3)), (5, 3, 4));
    assert_eq!(layout(with_harmonics(&x, max, max)), (5, max, 2 * wide + 1));
    // 5 values are no state of 3 harmonics (7 coefficients): the cosines were sliced past
    // the end.
    assert_eq!(layout(with_harmonics(&x, 3, 4)), (5, 3, 7));
    assert_eq!(
        layout(shift_origin(&[], 1 << 62, 0.5)),
        (0, 1 << 62, (1 << 63) + 1)
    );
    assert_eq!(
        layout(shift_origin(&x, 1 << 62, 0.5)),
        (5, 1 << 62, (1 << 63) + 1)
    );
    for r in [
        symmetry_instant(&x, max).map(|(t, s)| vec![t, s]),
        asymmetry(&x[..4], 2).map(|a| vec![a]),
    ] {
        assert!(matches!(r, Err(SettingsError::StateLayout { .. })), "{r:?}");
    }
    assert_eq!(to_full_basis(&x, 0), Err(SettingsError::ZeroHarmonics));
    // One unknown, one harmonic, lifted to 2^40: 17.6 TB, over the budget.
    let one = [1.0, 0.5, 0.25];
    match with_harmonics(&one, 1, 1 << 40) {
        Err(SettingsError::TooLarge(e)) => {
            assert!(e.requested_bytes >= 8.0 * (2.0 * 2f64.powi(40) + 1.0))
        }
        other => panic!("{other:?}"),
    }
    assert_eq!(
        with_harmonics(&one, 2, 1),
        Err(SettingsError::StateLayout {
            what: "full-basis state",
            got: 3,
            harmonics: 2,
            coefficients: 5,
        })
    );
    assert_eq!(
        with_harmonics(&[1.0; 5], 2, 1),
        Err(SettingsError::LiftToFewerHarmonics { from: 2, to: 1 })
    );
    assert_eq!(
        with_harmonics(&one, 1, 2).unwrap(),
        vec![1.0, 0.5, 0.0, 0.25, 0.0]
    );
    assert_eq!(to_full_basis(&[1.0, 0.5], 1).unwrap(), vec![1.0, 0.5, 0.0]);
    for theta in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        match shift_origin(&one, 1, theta) {
            Err(SettingsError::NotFinite { value, .. }) => {
                assert_eq!(value.to_bits(), theta.to_bits())
            }
            other => panic!("{other:?}"),
        }
    }
    match to_full_basis(&[1.0, f64::NAN], 1) {
        Err(SettingsError::NotFinite { value, .. }) => assert!(value.is_nan()),
        other => panic!("{other:?}"),
    }
    // A phase of many turns stays finite: `n theta0` no longer overflows to a NaN sine.
    let far = shift_origin(&one, 1, 1e308).unwrap();
    assert!(far.iter().all(|v| v.is_finite()), "{far:?}");
    // A motion with sines about no instant of symmetry, at the ends of `f64`.
    let odd = [0.1, 1.0, 0.3, 0.5, 0.7];
    let reference = asymmetry(&odd, 2).unwrap();
    assert!(reference > 1e-3 && reference.is_finite(), "{reference}");
    for scale in [1e300, 1e-300, f64::MAX] {
        let scaled: Vec<f64> = odd.iter().map(|v| v * scale).collect();
        let a = asymmetry(&scaled, 2).unwrap();
        assert!(
            (a - reference).abs() <= 1e-9,
            "scale {scale:e}: {a} vs {reference}"
        );
    }
}

/// A quadrature start of an infinite or NaN ratio is a typed error quoting it, not a start
/// of infinite or NaN sines.
#[test]
fn a_quadrature_start_refuses_a_ratio_that_is_not_finite() {
    let system = clamped_bar_with_obstacle(1e-3).unwrap();
    let omega = frequency_of_period(3.9);
    let mut full = full_basis_system(&system, &settings()).unwrap();
    for ratio in [f64::INFINITY, f64::NEG_INFINITY, f64::NAN] {
        match quadrature_start(&mut full, 2, ratio, omega) {
            Err(Error::Settings(SettingsError::NotFinite { what, value })) => {
                assert!(what.contains("ratio"), "{what}");
                assert_eq!(value.to_bits(), ratio.to_bits());
            }
            other => panic!("{ratio}: {other:?}"),
        }
    }
}

/// The stress suite's finding (case 7084 of the default seed): a cosine and a sine both near
/// `f64::MAX` rotate past it. A shift whose result stays within range is computed; one whose
/// result passes `f64::MAX` is a typed error, not an infinity in `Ok`.
#[test]
fn a_shift_of_coefficients_near_f64_max_stays_finite_or_is_refused() {
    let max = f64::MAX;
    // A sine alone at `f64::MAX`, turned by `pi / 4`: both parts at `max / sqrt 2`.
    let eighth = shift_origin(&[0.0, 0.0, max], 1, std::f64::consts::FRAC_PI_4).unwrap();
    let half = max * std::f64::consts::FRAC_1_SQRT_2;
    assert!((eighth[1] / half - 1.0).abs() < 1e-12, "{eighth:?}");
    assert!((eighth[2] / half - 1.0).abs() < 1e-12, "{eighth:?}");
    match shift_origin(&[0.0, max, max], 1, -0.6497515618015584) {
        Err(SettingsError::NotFinite { value, .. }) => assert!(value.is_infinite()),
        other => panic!("{other:?}"),
    }
}
