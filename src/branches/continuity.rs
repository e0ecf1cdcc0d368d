//! Whether a point continues the branch its run has followed so far, measured on the points
//! themselves, so that every driver's run is judged alike.
//!
//! # Why
//! A point's harmonic content says which mode it resembles, not which solution it is: after
//! a jump of the corrector to a neighbouring solution of the truncated equations (a spike
//! of an internal resonance, or a branch of its own that a change of the harmonic
//! selection's set lands on), harmonic 1 still dominates. Such points used to be labelled
//! skeleton next to the family they were 20 to 50 % away from.
//!
//! # The test
//! The last two points of the branch, `(T_a, x_a)` and `(T_b, x_b)`, predict by their
//! secant in the period
//!
//! ```text
//!   x^ = x_b + f (x_b - x_a),    f = (T - T_b) / (T_b - T_a)
//! ```
//!
//! and a point `(T, x)` continues the branch when its distance to the prediction is at most
//! [`JUMP_RATIO`] times the predicted step, `|x - x^|_W <= JUMP_RATIO |x^ - x_b|_W`, in the
//! energy weights `W` of the arclength norm
//! ([`Structured::state_weights`](crate::solve::Structured::state_weights)). The ratio is
//! free of units and of the grid: on a smooth branch it is of the order of the step (the
//! secant's error is quadratic), so it falls as the grid is refined; at a kink of the branch
//! (a contact that appears, a harmonic the selection drops) it stays of order one; a jump to
//! another solution keeps a distance of order one over a step that shrinks, so its ratio grows
//! without bound. The harmonics the harmonic selection holds at zero at any of the three
//! points are left out of both norms: where the selection's set changes, the equations
//! change, and the coefficient it drops or restores steps by its whole content, which says
//! nothing of whether the rest of the motion stayed on its branch.
//!
//! Where the secant cannot predict (fewer than two points, a period that turns
//! back at a fold or does not move), the point is taken as it comes. A point that fails the
//! test is not added to the branch: the next points are measured against the last two that
//! passed, so that a run that comes back from an excursion is recognised.

/// The largest ratio of a point's distance to the branch's secant prediction over the
/// predicted step that still continues the branch (module docs).
///
/// Measured with the default request on the two exact families (the clamped bar and the
/// free–free bar between walls, `tests/convergence_in_m.rs`): at `m = 20`, `40` and `80` no
/// point more than 20 % off its family is labelled skeleton but one (the clamped bar at
/// `m = 80`, `T = 3.835`, where harmonic 24 sits 0.13 % from a natural frequency, just
/// outside the selection's band, with a ratio of 3.1), and at least 97 % of the points within
/// 2 % are. A ratio of 3 labels that spike too, but also 8 to 14 % of the points within 2 %
/// (the kinks of a coarse grid near the clamped family's singularity at `T = 3`).
pub const JUMP_RATIO: f64 = 6.0;

/// A point as the test sees it: its period, unknowns and the basis coefficients the
/// harmonic selection holds at zero there.
#[derive(Debug, Clone, Default)]
pub(crate) struct Sample {
    pub(crate) period: f64,
    pub(crate) x: Vec<f64>,
    pub(crate) held: Vec<usize>,
}

/// The last two points of a branch, to measure the next against ([module docs](self)).
#[derive(Debug, Clone, Default)]
pub(crate) struct BranchTail {
    /// The last two points, the older first.
    points: Vec<Sample>,
}

impl BranchTail {
    /// The ratio of the distance from `p` to the branch's secant prediction over the
    /// predicted step, in the weights `weights` of unknowns grouped `per` a basis
    /// coefficient; `None` where the secant cannot predict (module docs).
    pub(crate) fn ratio(&self, p: &Sample, weights: &[f64], per: usize) -> Option<f64> {
        let [a, b] = self.points.as_slice() else {
            return None;
        };
        let f = (p.period - b.period) / (b.period - a.period);
        let n = p.x.len();
        if !(f.is_finite() && f > 0.0) || a.x.len() != n || weights.len() != n || per == 0 {
            return None;
        }
        let held = |i: usize| {
            [&a.held, &b.held, &p.held]
                .iter()
                .any(|h| h.contains(&(i / per)))
        };
        let (mut off, mut step) = (0.0, 0.0);
        for i in (0..n).filter(|&i| !held(i)) {
            let predicted = b.x[i] + f * (b.x[i] - a.x[i]);
            off += weights[i] * (p.x[i] - predicted).powi(2);
            step += weights[i] * (predicted - b.x[i]).powi(2);
        }
        let ratio = (off / step).sqrt();
        (step > 0.0 && ratio.is_finite()).then_some(ratio)
    }

    /// Whether `p` continues the branch: its ratio is at most [`JUMP_RATIO`] or cannot be
    /// measured (`Err` with the ratio otherwise). A point that continues the branch becomes
    /// its last.
    pub(crate) fn continues(&mut self, p: Sample, weights: &[f64], per: usize) -> Result<(), f64> {
        match self.ratio(&p, weights, per) {
            Some(ratio) if ratio > JUMP_RATIO => Err(ratio),
            _ => {
                if self.points.len() == 2 {
                    self.points.remove(0);
                }
                self.points.push(p);
                Ok(())
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The point at `t` of the curve `x(T) = (T, T^2)`, nothing held.
    fn on_curve(t: f64) -> Sample {
        Sample {
            period: t,
            x: vec![t, t * t],
            ..Sample::default()
        }
    }

    const UNIT: [f64; 2] = [1.0, 1.0];

    #[test]
    fn a_smooth_branch_continues_and_its_ratio_falls_with_the_step() {
        let mut ratios = Vec::new();
        for h in [0.1, 0.05, 0.025] {
            let mut tail = BranchTail::default();
            for k in 0..2 {
                assert!(tail
                    .continues(on_curve(1.0 + k as f64 * h), &UNIT, 1)
                    .is_ok());
            }
            let p = on_curve(1.0 + 2.0 * h);
            ratios.push(tail.ratio(&p, &UNIT, 1).expect("a ratio"));
            assert!(tail.continues(p, &UNIT, 1).is_ok());
        }
        assert!(ratios.windows(2).all(|w| w[1] < 0.6 * w[0]), "{ratios:?}");
    }

    #[test]
    fn a_jump_is_refused_and_the_branch_is_found_again() {
        let mut tail = BranchTail::default();
        for k in 0..3 {
            assert!(tail
                .continues(on_curve(1.0 + 0.01 * k as f64), &UNIT, 1)
                .is_ok());
        }
        // A point 0.5 away from the curve, where a step moves it by about 0.03.
        let mut off = on_curve(1.03);
        off.x[1] += 0.5;
        let ratio = tail.continues(off, &UNIT, 1).expect_err("a jump");
        assert!(ratio > 3.0 * JUMP_RATIO, "{ratio}");
        // The next point of the curve is measured against the two before the jump.
        assert!(tail.continues(on_curve(1.04), &UNIT, 1).is_ok());
    }

    #[test]
    fn a_coefficient_held_at_any_of_the_points_is_left_out() {
        let mut tail = BranchTail::default();
        for k in 0..2 {
            assert!(tail
                .continues(on_curve(1.0 + 0.01 * k as f64), &UNIT, 1)
                .is_ok());
        }
        // The second coefficient steps by its whole content where the selection drops it.
        let mut dropped = on_curve(1.02);
        dropped.x[1] = 0.0;
        dropped.held = vec![1];
        let ratio = tail.ratio(&dropped, &UNIT, 1).expect("a ratio");
        assert!(ratio < 1e-9, "{ratio}");
        assert!(tail.continues(dropped, &UNIT, 1).is_ok());
        // Restored at the next point: still left out, since it was held at one of the three.
        assert!(tail.continues(on_curve(1.03), &UNIT, 1).is_ok());
    }

    #[test]
    fn no_prediction_no_verdict() {
        let mut tail = BranchTail::default();
        assert_eq!(tail.ratio(&on_curve(1.0), &UNIT, 1), None);
        assert!(tail.continues(on_curve(1.0), &UNIT, 1).is_ok());
        assert!(tail.continues(on_curve(1.1), &UNIT, 1).is_ok());
        // The period turns back (a fold): no secant in the period.
        let back = Sample {
            period: 1.05,
            x: vec![0.0, 9.0],
            ..Sample::default()
        };
        assert_eq!(tail.ratio(&back, &UNIT, 1), None);
        // A state of another length (another problem): no verdict either.
        let other = Sample {
            period: 1.2,
            x: vec![1.2],
            ..Sample::default()
        };
        assert_eq!(tail.ratio(&other, &UNIT, 1), None);
    }
}
