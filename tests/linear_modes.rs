//! Linear modal analysis against independently computed frequencies (formulation §8), to 1e-8.

use nonsmooth_modes::bar::Bar;
use nonsmooth_modes::modal::{branch_seed, natural_frequencies, ContactState};
use nonsmooth_modes::reference::{
    clamped_bar_with_obstacle, robin_bar_with_obstacle, two_bars_in_contact,
};
use nonsmooth_modes::system::{HarmonicBalanceSettings, NonsmoothSystem};
use nonsmooth_modes::{Error, SettingsError};
use proptest::prelude::*;
use std::f64::consts::PI;

/// Roots of `f` on `(0, hi)` by sign changes on a fine grid and bisection to rounding.
fn roots(f: impl Fn(f64) -> f64, hi: f64) -> Vec<f64> {
    let n = 200_000;
    let h = hi / n as f64;
    let mut out = Vec::new();
    for i in 1..n {
        let (a, b) = (i as f64 * h, (i + 1) as f64 * h);
        let (fa, fb) = (f(a), f(b));
        // Skip the poles of tan: a sign change through infinity has a huge jump.
        if fa.signum() != fb.signum() && (fa - fb).abs() < 1.0 {
            let (mut lo, mut hi_) = (a, b);
            for _ in 0..200 {
                let mid = 0.5 * (lo + hi_);
                if f(mid).signum() == f(lo).signum() {
                    lo = mid;
                } else {
                    hi_ = mid;
                }
            }
            out.push(0.5 * (lo + hi_));
        }
    }
    out
}

fn computed(system: &nonsmooth_modes::system::BarSystem, state: ContactState, hi: f64) -> Vec<f64> {
    natural_frequencies(system, state, hi)
        .unwrap()
        .iter()
        .flat_map(|m| std::iter::repeat_n(m.omega, m.shapes.len()))
        .collect()
}

fn assert_close(got: &[f64], want: &[f64], tol: f64) {
    assert_eq!(got.len(), want.len(), "got {got:?}, want {want:?}");
    for (g, w) in got.iter().zip(want) {
        assert!((g - w).abs() <= tol * w, "got {g}, want {w}");
    }
}

#[test]
fn robin_frequencies_to_1e8() {
    let system = robin_bar_with_obstacle(0.5, 1e-3).unwrap();
    // Robin-free: omega sin(omega) - k cos(omega) = 0 (omega tan omega = k without poles).
    let open = roots(|w| w * w.sin() - 0.5 * w.cos(), 12.0);
    // Robin-clamped: omega cos(omega) + k sin(omega) = 0.
    let closed = roots(|w| w * w.cos() + 0.5 * w.sin(), 12.0);
    assert_close(&computed(&system, ContactState::Open, 12.0), &open, 1e-8);
    assert_close(
        &computed(&system, ContactState::Closed, 12.0),
        &closed,
        1e-8,
    );
    // The ratios the paper discusses: omega_2 / omega_1 = 5.04 (the paper prints 5.09).
    assert!((open[1] / open[0] - 5.0397).abs() < 1e-4);
}

#[test]
fn clamped_and_two_bar_frequencies_to_1e8() {
    let clamped = clamped_bar_with_obstacle(1e-3).unwrap();
    let free: Vec<f64> = (1..=6).map(|i| (2 * i - 1) as f64 * PI / 2.0).collect();
    assert_close(&computed(&clamped, ContactState::Open, 18.0), &free, 1e-8);
    let fixed: Vec<f64> = (1..=5).map(|i| i as f64 * PI).collect();
    assert_close(
        &computed(&clamped, ContactState::Closed, 17.0),
        &fixed,
        1e-8,
    );
    // The paper's triplets: bar 2 (l, c) contributes (2i - 1) pi c / (2 l) when open.
    for (l, c, alpha) in [(0.95, 1.0, 1.0), (3.8, 4.0, 4.0), (0.95, 2.0, 1.0)] {
        let system = two_bars_in_contact(Bar::new(l, c, alpha).unwrap(), 1e-3).unwrap();
        let mut want: Vec<f64> = (1..=8)
            .flat_map(|i| {
                let n = (2 * i - 1) as f64;
                [n * PI / 2.0, n * PI * c / (2.0 * l)]
            })
            .filter(|w| *w < 18.0)
            .collect();
        want.sort_by(f64::total_cmp);
        assert_close(&computed(&system, ContactState::Open, 18.0), &want, 1e-8);
    }
}

#[test]
fn a_mode_beyond_the_searched_range_is_a_typed_error() {
    // A single clamped bar has modes at (2i - 1) pi / 2: mode 10^6 is far beyond the search.
    let system = clamped_bar_with_obstacle(1e-3).unwrap();
    let mut problem = NonsmoothSystem::new(&system, HarmonicBalanceSettings::default()).unwrap();
    match branch_seed(&mut problem, 1_000_000, 1, 1.6) {
        Err(Error::Settings(SettingsError::ModeNotFound { mode, omega_max })) => {
            assert_eq!(mode, 1_000_000);
            assert!(omega_max > 0.0 && omega_max.is_finite());
        }
        other => panic!("{other:?}"),
    }
    assert!(matches!(
        natural_frequencies(&system, ContactState::Open, 0.0),
        Err(SettingsError::NotPositive { .. })
    ));
}

/// A seed from the mode that `grazing_energy` returns equals the seed that searches the mode
/// again; a mode without shape or of the wrong size is refused with a typed error.
#[test]
fn seed_from_a_known_mode_equals_the_searched_seed() {
    use nonsmooth_modes::modal::{grazing_energy, seed_from_mode, LinearMode};
    use nonsmooth_modes::SolveError;
    for system in [
        clamped_bar_with_obstacle(1e-3).unwrap(),
        robin_bar_with_obstacle(0.5, 1e-3).unwrap(),
        two_bars_in_contact(Bar::new(0.95, 1.0, 1.0).unwrap(), 1e-3).unwrap(),
    ] {
        let mut problem =
            NonsmoothSystem::new(&system, HarmonicBalanceSettings::default()).unwrap();
        let (_, first) = grazing_energy(&system).unwrap();
        for (subharmonic, omega) in [(1, 0.9 * first.omega), (3, 2.9 * first.omega)] {
            let searched = branch_seed(&mut problem, 1, subharmonic, omega).unwrap();
            let known = seed_from_mode(&mut problem, &first, subharmonic, omega).unwrap();
            assert_eq!(searched, known);
        }
        let empty = LinearMode {
            omega: first.omega,
            shapes: Vec::new(),
        };
        assert!(matches!(
            seed_from_mode(&mut problem, &empty, 1, first.omega),
            Err(Error::Settings(SettingsError::NoGrazing { .. }))
        ));
        let short = LinearMode {
            omega: first.omega,
            shapes: vec![vec![1.0]],
        };
        assert!(matches!(
            seed_from_mode(&mut problem, &short, 1, first.omega),
            Err(Error::Solve(SolveError::Dimension { got: 1, .. }))
        ));
    }
}

/// Rigid-body modes: none for a clamped bar; one (a translation) for a free-free bar between
/// two walls while its contacts are open, none once they close; one for the middle bar of a
/// chain held only by contacts; two for two free bars touching only each other. Each shape
/// is a translation: `B = 0` (no strain) in every bar's affine field `A + B x`.
#[test]
fn rigid_body_modes_with_their_multiplicity() {
    use nonsmooth_modes::modal::rigid_body_modes;
    use nonsmooth_modes::system::AssemblyBuilder;
    let count = |system: &nonsmooth_modes::system::BarSystem, state| {
        rigid_body_modes(system, state).map_or(0, |m| {
            assert_eq!(m.omega, 0.0);
            for shape in &m.shapes {
                for pair in shape.chunks(2) {
                    assert!(pair[1].abs() < 1e-12, "a strained rigid mode: {shape:?}");
                }
            }
            m.shapes.len()
        })
    };
    let clamped = clamped_bar_with_obstacle(1e-3).unwrap();
    assert_eq!(count(&clamped, ContactState::Open), 0);

    let mut b = AssemblyBuilder::new();
    let bar = b.add_bar(Bar::unit());
    b.signorini(bar.left(), 1e-3)
        .unwrap()
        .signorini(bar.right(), 1e-3)
        .unwrap();
    let walls = b.build().unwrap();
    assert_eq!(count(&walls, ContactState::Open), 1);
    assert_eq!(count(&walls, ContactState::Closed), 0);

    let chain = nonsmooth_modes::reference::contact_chain(3, 1e-3, 0.5).unwrap();
    assert_eq!(count(&chain, ContactState::Open), 1);
    assert_eq!(count(&chain, ContactState::Closed), 0);

    let mut b = AssemblyBuilder::new();
    let (one, two) = (b.add_bar(Bar::unit()), b.add_bar(Bar::unit()));
    b.neumann(one.left())
        .unwrap()
        .contact(one.right(), two.left(), 1e-3)
        .unwrap()
        .neumann(two.right())
        .unwrap();
    let floating = b.build().unwrap();
    assert_eq!(count(&floating, ContactState::Open), 2);
    // Closed, the two bars move together: one translation.
    assert_eq!(count(&floating, ContactState::Closed), 1);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Two bars in contact, open: the spectrum is both bars' clamped-free spectra, whatever
    /// their stiffness ratio, from a partner 10^4 times softer to 10^4 times stiffer. A much
    /// softer partner enters the open-contact matrix only through the force balance, where it
    /// weighs little: the roots of the stiffer bar then dip below that floor over less than a
    /// scan step, and are found by the determinant's change of sign.
    #[test]
    fn open_two_bar_spectrum_at_any_stiffness_ratio(
        l in 0.3f64..4.0,
        c in 0.3f64..4.0,
        decades in -4.0f64..4.0,
    ) {
        let ea = 10f64.powf(decades);
        let system = two_bars_in_contact(Bar::new(l, c, ea).unwrap(), 1e-3).unwrap();
        let hi = 12.0;
        let count = (hi * l / (PI * c)).ceil() as usize + 8;
        let mut want: Vec<f64> = (1..=count)
            .flat_map(|i| {
                let n = (2 * i - 1) as f64;
                [n * PI / 2.0, n * PI * c / (2.0 * l)]
            })
            .filter(|w| *w < hi)
            .collect();
        want.sort_by(f64::total_cmp);
        // Distinct frequencies closer than about two scan steps (`pi min(c/l) / 200` each)
        // merge, as `natural_frequencies` documents.
        let step = PI * (c / l).min(1.0) / 200.0;
        prop_assume!(want.windows(2).all(|w| w[1] - w[0] > 3.0 * step));
        let got = computed(&system, ContactState::Open, hi);
        prop_assert_eq!(got.len(), want.len(), "EA_2 = {}: got {:?}, want {:?}", ea, got, want);
        for (g, w) in got.iter().zip(&want) {
            prop_assert!((g - w).abs() <= 1e-8 * w, "EA_2 = {}: got {}, want {}", ea, g, w);
        }
    }
}
