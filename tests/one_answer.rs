//! One answer per request: asking to see the time-domain check annotates the points a
//! request returns, it does not change them. `Method::Auto` judges its runs without the check
//! and checks the run it keeps, so that the same request with and without
//! [`Request::checked`] returns the same points.

use nonsmooth_modes::bar::Bar;
use nonsmooth_modes::branches::{compute, ModeBranches, Request, TimeDomainCheck};
use nonsmooth_modes::reference::clamped_bar_with_obstacle;
use nonsmooth_modes::system::{AssemblyBuilder, BarSystem};

/// A bar clamped on the left, in contact at gap `gap` with a second bar held on the right
/// by a ground spring of stiffness `k`: the user's assembly of the issue this guards.
fn clamped_contact_spring(first: Bar, second: Bar, gap: f64, k: f64) -> BarSystem {
    let mut b = AssemblyBuilder::new();
    let (one, two) = (b.add_bar(first), b.add_bar(second));
    b.dirichlet(one.left()).expect("an end");
    b.contact(one.right(), two.left(), gap).expect("a contact");
    b.robin(two.right(), k).expect("a spring");
    b.build().expect("a system")
}

/// The converged points as `(period, energy)`.
fn converged(run: &ModeBranches) -> Vec<(f64, f64)> {
    run.converged().map(|p| (p.period, p.energy)).collect()
}

/// The same request with and without the check: the same converged points (periods and
/// energies equal to `1e-12`), each of the checked run's converged points with a check.
fn same_answer(system: &BarSystem, request: &Request) {
    let plain = compute(system, request).expect("a run");
    let checked = request.clone().checked(TimeDomainCheck::for_system(system));
    let seen = compute(system, &checked).expect("a checked run");
    let (a, b) = (converged(&plain), converged(&seen));
    assert_eq!(a.len(), b.len(), "{system:?}");
    for ((ta, ea), (tb, eb)) in a.iter().zip(&b) {
        assert!((ta - tb).abs() <= 1e-12 * ta.abs(), "{ta} vs {tb}");
        assert!((ea - eb).abs() <= 1e-12 * ea.abs(), "{ea} vs {eb} at {ta}");
    }
    assert_eq!(plain.method.name(), seen.method.name());
    assert!(seen.converged().all(|p| p.check.is_some()));
    assert!(plain.converged().all(|p| p.check.is_none()));
}

#[test]
fn the_check_annotates_the_clamped_bar() {
    let system = clamped_bar_with_obstacle(1e-3).expect("a system");
    same_answer(&system, &Request::new(1).harmonics(12));
}

/// Generated assemblies (a 64-bit linear congruential draw, so the run does not depend on
/// the machine): lengths, speeds and stiffnesses over a factor of 6, springs over two
/// decades.
#[test]
fn the_check_annotates_generated_assemblies() {
    let mut state = 0x5eed_0a5e_u64;
    let mut draw = |lo: f64, hi: f64| {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        lo + (hi - lo) * ((state >> 11) as f64 / (1u64 << 53) as f64)
    };
    for _ in 0..4 {
        let mut bar = || Bar::new(draw(0.5, 3.0), draw(0.5, 3.0), draw(0.5, 3.0)).expect("a bar");
        let (first, second) = (bar(), bar());
        let k = 10f64.powf(draw(-1.0, 1.0));
        let system = clamped_contact_spring(first, second, 1e-3, k);
        same_answer(&system, &Request::new(1).harmonics(8));
    }
}
