//! Unit tests of the multipliers, the trivial pair and the verdict.

use super::*;
use faer::Mat;

/// A block-diagonal monodromy: the 2 x 2 block `pair` at the top, then rotations by the
/// angles `phases` (multipliers `e^{+-i phi}` on the circle, away from 1).
fn monodromy(pair: [[f64; 2]; 2], phases: &[f64]) -> Monodromy {
    let n = 2 + 2 * phases.len();
    Mat::from_fn(n, n, |i, j| match (i / 2, j / 2) {
        (0, 0) => pair[i][j],
        (b, c) if b == c => {
            let (cos, sin) = (phases[b - 1].cos(), phases[b - 1].sin());
            [[cos, -sin], [sin, cos]][i % 2][j % 2]
        }
        _ => 0.0,
    })
}

fn pair_of(m: &Monodromy, tolerance: f64) -> TrivialPair {
    let multipliers = eigenvalues(m).unwrap();
    trivial_pair(m, &multipliers, 0, tolerance, true).unwrap()
}

/// A Jordan block at 1 with coupling `c`, perturbed by `e` below the diagonal, has its
/// multipliers at `1 +- sqrt(c e)`: the distance is the square root, the perturbation
/// found `2 e / (1 + e / c)` (Wilkinson's estimate, within a factor 2), whatever the
/// coupling.
#[test]
fn a_perturbed_jordan_block_gives_back_its_perturbation() {
    for c in [0.3, 1.0, 7.0] {
        for e in [1e-8, 1e-6, 1e-4] {
            let m = monodromy([[1.0, c], [e, 1.0]], &[0.7, 2.0]);
            let pair = pair_of(&m, 0.0);
            assert!(
                ((pair.distance - (c * e).sqrt()) / (c * e).sqrt()).abs() < 1e-6,
                "c {c}, e {e}: {pair:?}"
            );
            let found = pair.perturbation.unwrap();
            let expected = 2.0 * e / (1.0 + e / c);
            assert!(
                (found - expected).abs() <= 1e-6 * e,
                "c {c}, e {e}: {pair:?}"
            );
            // Found at a tolerance between 2 e and sqrt(c e), not below e.
            assert!(pair.found(2.0 * e) && !pair.found(e), "c {c}, e {e}");
        }
    }
}

/// Two simple multipliers `1 +- s` with orthogonal eigenvectors are `s` from a double
/// multiplier 1: a split that is the perturbation itself, not its square root.
#[test]
fn a_split_with_orthogonal_eigenvectors_is_its_own_perturbation() {
    for s in [1e-5, 1e-3, 2e-2] {
        let pair = pair_of(&monodromy([[1.0 + s, 0.0], [0.0, 1.0 - s]], &[1.1]), 0.0);
        assert!(
            (pair.perturbation.unwrap() - s).abs() <= 1e-9,
            "{s}: {pair:?}"
        );
    }
}

/// A pair pulled inward together, `(1 - p) J`: the mean's distance counts in full.
#[test]
fn a_pair_moved_together_counts_the_move() {
    for p in [1e-4, 1e-2] {
        let pair = pair_of(&monodromy([[1.0 - p, 0.5], [0.0, 1.0 - p]], &[0.4]), 0.0);
        let found = pair.perturbation.unwrap();
        assert!((found - p).abs() <= 1e-6 * p, "{p}: {pair:?}");
    }
}

/// Within the tolerance, the eigenvectors are not needed: no perturbation is computed.
#[test]
fn a_pair_within_the_tolerance_is_found_without_eigenvectors() {
    let pair = pair_of(&monodromy([[1.0, 1.0], [1e-8, 1.0]], &[0.9]), 1e-3);
    assert!(pair.perturbation.is_none() && pair.found(1e-3), "{pair:?}");
}

fn corrected() -> Corrected {
    Corrected {
        x: vec![1.0; 4],
        initial_defect: 1e-2,
        defect: 1e-12,
        energy_change: 1e-3,
        shift: 1e-2,
        displacement_shift: 1e-3,
        iterations: 2,
    }
}

const SHAPE: MapShape = MapShape {
    dimension: 4,
    dt: 0.01,
    period: 3.5,
};

/// A pair missed only inward is the grid's damping up to the bound: stable, with the
/// damping said; a multiplier outside the circle, a damping over the bound or a time shift
/// that is not found leave the point unresolved.
#[test]
fn a_pair_damped_by_the_grid_is_said_and_bounded() {
    let judged = |pair: [[f64; 2]; 2], phases: &[f64], scale: f64, max_damping: f64| {
        let mut m = monodromy(pair, phases);
        for i in 2..m.nrows() {
            for j in 2..m.ncols() {
                m[(i, j)] *= scale;
            }
        }
        let multipliers = eigenvalues(&m).unwrap();
        let pair = pair_of(&m, 1e-3);
        verdict(
            multipliers,
            (1e-3, max_damping),
            pair,
            None,
            &corrected(),
            SHAPE,
        )
    };
    let damped = [[1.0, 0.0], [0.0, 0.97]];
    let f = judged(damped, &[0.5, 1.5], 0.98, 0.1);
    assert_eq!((f.verdict, f.unresolved), (Verdict::Stable, None), "{f:?}");
    assert!((f.damping.unwrap() - 0.03).abs() < 1e-9, "{f:?}");
    for (pair, scale, bound) in [
        (damped, 1.01, 0.1),
        (damped, 0.98, 0.01),
        ([[1.0 + 2e-3, 0.0], [0.0, 0.97]], 0.98, 0.1),
    ] {
        let f = judged(pair, &[0.5], scale, bound);
        assert_eq!(f.verdict, Verdict::Unresolved, "{pair:?} {scale} {bound}");
        assert!(f.damping.is_none());
    }
}

/// A failed correction is the reason, whatever the pair; a found pair is set to 1 and the
/// verdict follows from the others; a missing pair is the reason, with its numbers.
#[test]
fn the_verdict_names_its_reason() {
    let m = monodromy([[1.0, 1.0], [1e-4, 1.0]], &[0.5]);
    let multipliers = eigenvalues(&m).unwrap();
    let pair = pair_of(&m, 1e-3);
    let failure = UnresolvedReason::EnergyMoved {
        change: 0.2,
        bound: 0.05,
    };
    let f = verdict(
        multipliers.clone(),
        (1e-3, 0.1),
        pair,
        Some(failure),
        &corrected(),
        SHAPE,
    );
    assert_eq!(
        (f.verdict, f.unresolved),
        (Verdict::Unresolved, Some(failure))
    );

    let f = verdict(
        multipliers.clone(),
        (1e-3, 0.1),
        pair,
        None,
        &corrected(),
        SHAPE,
    );
    assert_eq!((f.verdict, f.unresolved), (Verdict::Stable, None), "{f:?}");
    assert_eq!(f.max_multiplier, 1.0);
    assert_eq!(f.multipliers.iter().filter(|mu| mu.re == 1.0).count(), 2);

    let pair = pair_of(&m, 1e-5);
    let f = verdict(multipliers, (1e-5, 0.1), pair, None, &corrected(), SHAPE);
    let Some(UnresolvedReason::TrivialPairMissing {
        distance,
        perturbation,
        tolerance,
    }) = f.unresolved
    else {
        panic!("{f:?}");
    };
    assert_eq!(f.verdict, Verdict::Unresolved);
    assert!((distance - 1e-2).abs() < 1e-8 && (perturbation - 2e-4).abs() < 1e-7);
    assert_eq!(tolerance, 1e-5);
}

/// Every reason's sentence carries its numbers and no comma (a CSV cell).
#[test]
fn reasons_read_as_one_sentence_with_their_numbers() {
    let cases = [
        (
            UnresolvedReason::NotPeriodic {
                defect: 0.23,
                bound: 1e-8,
                iterations: 3,
                corrections: 8,
            },
            &["2.3e-1", "3 of 8", "stalled", "1e-8"][..],
        ),
        (
            UnresolvedReason::NotPeriodic {
                defect: 4e-3,
                bound: 1e-8,
                iterations: 8,
                corrections: 8,
            },
            &["4.0e-3", "all 8"][..],
        ),
        (
            UnresolvedReason::OffGrid {
                defect: 2.5e-5,
                projected: 5e-8,
                bound: 1e-8,
            },
            &["2.5e-5", "5.0e-8", "1e-8", "finer than a cell"][..],
        ),
        (
            UnresolvedReason::EnergyMoved {
                change: -0.12,
                bound: 0.05,
            },
            &["12.0 % less energy", "5.0 %"][..],
        ),
        (
            UnresolvedReason::DisplacementMoved {
                change: 0.071,
                bound: 0.05,
            },
            &["7.1 %", "5.0 %"][..],
        ),
        (
            UnresolvedReason::TrivialPairMissing {
                distance: 1.4e-2,
                perturbation: 1.1e-2,
                tolerance: 1e-3,
            },
            &["1.4e-2", "1.1e-2", "1.0e-3"][..],
        ),
        (
            UnresolvedReason::Merged {
                removed: 3e-5,
                bound: 1e-6,
            },
            &["3.0e-5", "1.0e-6"][..],
        ),
    ];
    for (reason, numbers) in cases {
        let text = reason.to_string();
        assert!(!text.contains(',') && !text.contains('\n'), "{text}");
        for n in numbers {
            assert!(text.contains(n), "{text} lacks {n}");
        }
    }
}
