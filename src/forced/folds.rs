//! Folds of a response curve: where the frequency along the curve turns back.
//!
//! A corrector at its smallest step can land on either side of a kink of the contact laws or
//! of a frequency where the harmonic selection changes, and the points' frequencies then
//! zigzag by far less than a step. A turn counts as a fold only once the curve has come back
//! from its extreme by more than a resolution in frequency (hysteresis), so those zigzags are
//! not reported, and a turn the run ended before confirming is not either.

/// The indices of the folds of the curve through `omegas`, in order: the extremes in
/// frequency from which the curve comes back by more than `resolution`.
pub(super) fn folds(omegas: &[f64], resolution: f64) -> Vec<usize> {
    let mut found = Vec::new();
    let Some(&first) = omegas.first() else {
        return found;
    };
    // The direction of travel (0 before the curve has moved by `resolution`) and the index of
    // the extreme reached in it.
    let (mut direction, mut extreme) = (0.0, 0);
    for (i, &omega) in omegas.iter().enumerate().skip(1) {
        if direction == 0.0 {
            if (omega - first).abs() > resolution {
                direction = (omega - first).signum();
                extreme = i;
            }
        } else if (omega - omegas[extreme]) * direction > 0.0 {
            extreme = i;
        } else if (omegas[extreme] - omega) * direction > resolution {
            found.push(extreme);
            direction = -direction;
            extreme = i;
        }
    }
    found
}

#[cfg(test)]
mod tests {
    use super::folds;

    #[test]
    fn turns_back_by_more_than_the_resolution_are_folds() {
        // Up to 2, back down to 1, up to 3: two folds, at the extremes.
        let curve = [0.0, 1.0, 2.0, 1.5, 1.0, 2.0, 3.0];
        assert_eq!(folds(&curve, 0.1), vec![2, 4]);
    }

    #[test]
    fn zigzags_below_the_resolution_and_unconfirmed_turns_are_not() {
        let zigzag = [0.0, 1.0, 0.99, 1.0, 0.995, 2.0, 1.95];
        assert!(folds(&zigzag, 0.1).is_empty());
        assert!(folds(&[], 0.1).is_empty());
        assert!(folds(&[1.0, 1.0, 1.0], 0.1).is_empty());
    }
}
