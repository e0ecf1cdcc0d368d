//! [`proptest`] strategies for property tests of the crate's identities, exported so that a
//! downstream crate can test its own conditions and loops with the same inputs.
//!
//! Enabled by the cargo feature `proptest`. Every strategy draws admissible values only (a
//! `BarSystem` strategy never fails to build), and ranges are wide enough to cover short and
//! long, slow and fast, soft and stiff bars, but bounded so that identities can be checked to a
//! fixed relative tolerance.
//!
//! ```
//! use nonsmooth_modes::bem::{boundary_rows, HelmholtzMap};
//! use nonsmooth_modes::strategies::{bar, frequency, helmholtz_coefficients};
//! use proptest::prelude::*;
//!
//! proptest!(ProptestConfig::with_cases(16), |(b in bar(), w in frequency(), (a, c) in helmholtz_coefficients())| {
//!     let ends = HelmholtzMap::new(&b, w).end_values(a, c).to_array();
//!     for row in boundary_rows(&b, w) {
//!         let r: f64 = row.iter().zip(ends).map(|(x, y)| x * y).sum();
//!         let scale: f64 = row.iter().zip(ends).map(|(x, y)| (x * y).abs()).sum();
//!         prop_assert!(r.abs() <= 1e-10 * scale.max(1e-300));
//!     }
//! });
//! ```

use crate::bar::Bar;
use crate::reference::{clamped_bar_with_obstacle, robin_bar_with_obstacle, two_bars_in_contact};
use crate::system::BarSystem;
use proptest::prelude::*;

/// A bar with length `l in [0.2, 5]`, wave speed `c in [0.2, 5]` and axial stiffness
/// `EA in [0.1, 10]`.
///
/// Serves the per-bar identities of [`crate::bem`]: exact Helmholtz solutions satisfy the
/// boundary rows, the interior representation reproduces them, and the `omega` derivatives of
/// [`crate::bem::HelmholtzMap`] match finite differences, for any bar.
pub fn bar() -> impl Strategy<Value = Bar> {
    (0.2..=5.0_f64, 0.2..=5.0_f64, 0.1..=10.0_f64)
        .prop_map(|(l, c, ea)| Bar::new(l, c, ea).expect("ranges are positive and finite"))
}

/// An angular frequency `omega in [0, 50]`, exactly `0` in about one case out of eight.
///
/// Serves the same identities as [`bar`], including their zero-frequency limit (the rows are
/// written so that `omega = 0`, the constant harmonic, needs no special case).
pub fn frequency() -> impl Strategy<Value = f64> {
    prop_oneof![
        1 => Just(0.0),
        7 => 0.0..=50.0_f64,
    ]
}

/// Helmholtz coefficients `(A, B)` of `u(x) = A cos(kx) + B sin(kx)/k`, each in `[-1, 1]`.
///
/// Serves every identity that holds for all exact solutions of one harmonic (boundary rows,
/// interior displacement and strain, end values of [`crate::bem::HelmholtzMap`]).
pub fn helmholtz_coefficients() -> impl Strategy<Value = (f64, f64)> {
    (-1.0..=1.0_f64, -1.0..=1.0_f64)
}

/// A contact gap `g0 in [1e-4, 1e-1]`.
///
/// Serves scale invariance: every equation is homogeneous of degree one in `(x, g0)`, so
/// results scale with the gap.
pub fn gap() -> impl Strategy<Value = f64> {
    1e-4..=1e-1_f64
}

/// The unit bar clamped at `x = 0` facing a rigid obstacle at a random gap ([`gap`]) at
/// `x = 1` (the paper's Dirichlet–Signorini system).
///
/// Serves identities of the assembled harmonic-balance system (Jacobian against finite
/// differences, condensed rows against the exact first nonsmooth mode of formulation §9).
pub fn clamped_system() -> impl Strategy<Value = BarSystem> {
    gap().prop_map(|g| clamped_bar_with_obstacle(g).expect("admissible gap"))
}

/// The unit bar on a ground spring `k_s in [0.05, 5]` at `x = 0` facing a rigid obstacle at a
/// random gap at `x = 1` (the paper's Robin–Signorini system; the paper uses `k_s = 0.5`).
///
/// Serves the identities of the assembled system with a frequency-independent Robin row.
pub fn robin_system() -> impl Strategy<Value = BarSystem> {
    (0.05..=5.0_f64, gap())
        .prop_map(|(k, g)| robin_bar_with_obstacle(k, g).expect("admissible spring and gap"))
}

/// Two bars clamped at their left ends whose right ends face each other across a random gap:
/// bar 1 is the unit bar, bar 2 has `l in [0.5, 2]`, `c in [0.5, 2]`, `EA in [0.5, 2]` (the
/// paper's two-bar system with random triplets).
///
/// Serves the identities of the assembled system with a two-end contact (force balance row,
/// gap of two ends, rank detection of the linear rows).
pub fn two_bar_system() -> impl Strategy<Value = BarSystem> {
    (0.5..=2.0_f64, 0.5..=2.0_f64, 0.5..=2.0_f64, gap()).prop_map(|(l, c, ea, g)| {
        let second = Bar::new(l, c, ea).expect("ranges are positive and finite");
        two_bars_in_contact(second, g).expect("admissible gap")
    })
}

/// A period `T in [3.001, 3.999]`: the first family of nonsmooth modes of the clamped bar,
/// `Omega in (pi/2, 2 pi/3)` (formulation §9), kept away from its ends where the exact energy
/// blows up (`T -> 3`) or the contact phase vanishes (`T -> 4`).
///
/// Serves identities of [`crate::reference::ClampedFirstMode`] (its harmonics satisfy the
/// condensed linear rows of the clamped bar, its closed forms match quadratures).
pub fn period_in_first_family() -> impl Strategy<Value = f64> {
    3.001..=3.999_f64
}
