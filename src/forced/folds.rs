//! Folds of a response curve: where the frequency along the curve turns back.
//!
//! A corrector at its smallest step can land on either side of a kink of the contact laws or
//! of a frequency where the harmonic selection changes, and the points' frequencies then
//! zigzag by far less than a step. A turn counts as a fold only once the curve has come back
//! from its extreme by more than a resolution in frequency (hysteresis), so those zigzags are
//! not reported, and a turn the run ended before confirming is not either. Nor is a run that
//! turns back on the curve it came along (a corrector reversed at a kink): where it has come
//! back by the resolution its energy is the one it had there on the way out, while the two
//! branches of a fold differ there by about twice what either moved from the tip.

/// The indices of the folds of the curve through `(omegas, energies)`, in order: the
/// extremes in frequency from which the curve comes back by more than `resolution` along
/// another branch.
pub(super) fn folds(omegas: &[f64], energies: &[f64], resolution: f64) -> Vec<usize> {
    let mut found = Vec::new();
    let Some(&first) = omegas.first() else {
        return found;
    };
    // The direction of travel (0 before the curve has moved by `resolution`), the index of
    // the extreme reached in it, and where the run in that direction began.
    let (mut direction, mut extreme, mut began) = (0.0, 0, 0);
    for (i, &omega) in omegas.iter().enumerate().skip(1) {
        if direction == 0.0 {
            if (omega - first).abs() > resolution {
                direction = (omega - first).signum();
                extreme = i;
            }
        } else if (omega - omegas[extreme]) * direction > 0.0 {
            extreme = i;
        } else if (omegas[extreme] - omega) * direction > resolution {
            if !retraced((omegas, energies), (began, extreme), i) {
                found.push(extreme);
            }
            direction = -direction;
            (began, extreme) = (extreme, i);
        }
    }
    found
}

/// Whether point `j`, back from the extreme `tip` of the run `began..=tip`, lies on that run:
/// its energy is that of the run at its frequency (interpolated) to a tenth of how far it
/// moved from the tip's.
fn retraced((omegas, energies): (&[f64], &[f64]), (began, tip): (usize, usize), j: usize) -> bool {
    let at = omegas[j];
    let bracket = (began..tip)
        .rev()
        .find(|&k| (omegas[k] - at) * (omegas[k + 1] - at) <= 0.0);
    let Some(k) = bracket else {
        return false;
    };
    let span = omegas[k + 1] - omegas[k];
    let t = if span == 0.0 {
        0.0
    } else {
        (at - omegas[k]) / span
    };
    let there = energies[k] + t * (energies[k + 1] - energies[k]);
    (energies[j] - there).abs() < 0.1 * (energies[j] - energies[tip]).abs()
}

#[cfg(test)]
mod tests {
    use super::folds;

    #[test]
    fn turns_back_by_more_than_the_resolution_are_folds() {
        // Up to 2, back down to 1 on a branch of higher energy, up to 3: two folds.
        let omegas = [0.0, 1.0, 2.0, 1.5, 1.0, 2.0, 3.0];
        let energies = [0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0];
        assert_eq!(folds(&omegas, &energies, 0.1), vec![2, 4]);
    }

    #[test]
    fn zigzags_below_the_resolution_and_unconfirmed_turns_are_not() {
        let zigzag = [0.0, 1.0, 0.99, 1.0, 0.995, 2.0, 1.95];
        let energies = [0.0, 1.0, 1.1, 1.2, 1.3, 2.0, 2.1];
        assert!(folds(&zigzag, &energies, 0.1).is_empty());
        assert!(folds(&[], &[], 0.1).is_empty());
        assert!(folds(&[1.0, 1.0, 1.0], &[1.0, 2.0, 3.0], 0.1).is_empty());
    }

    #[test]
    fn a_run_back_along_the_curve_is_not_a_fold() {
        // Up to 2 and back down the same energies (E = omega).
        let omegas = [0.0, 1.0, 2.0, 1.5, 1.0];
        assert!(folds(&omegas, &omegas, 0.1).is_empty());
    }
}
