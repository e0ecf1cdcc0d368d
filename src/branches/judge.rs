//! The time-domain check of points: of one point, as a request asks it, and of a sample of a
//! run's points, which is how [`Method::Auto`](crate::branches::Method::Auto) judges its
//! candidate runs.
//!
//! # Why a sample, and why always
//! `Auto` compares runs (two equation sets, two starts, a run lifted from fewer harmonics)
//! by how many of their points are motions of the bars. Counting converged points alone
//! trusts the truncation; checking every point costs more than the runs themselves. So the
//! judge marches [`JUDGE_SAMPLES`] points spread evenly over each run's converged points, on
//! a grid of [`JUDGE_CELLS_PER_TRAVEL`] cells per shortest travel time (a sixteenth of the
//! work of the default check's 400: the displacement defect that decides is set by the
//! low harmonics, which this grid resolves to well under the 5 % tolerance), and scales the
//! run's count of converged points by the share of the sample that passed. The judge is the
//! same whether the request asks for the check or not, so asking for it annotates the answer
//! without changing it; the check the request asks runs only on the points of the run kept.
//!
//! # What it tells, and what it does not
//! The sample tells a run of motions from a run of points that are not: on chains with
//! floating bars a start can lead to a branch whose points miss periodicity by 10 to 80 %
//! while another start's pass. It does not grade accuracy: on the clamped bar at `m = 20`,
//! the paper's equations give points 20 to 40 % off the exact family's energy whose defects
//! (median 2.8 %) pass, while the selected equations' points, within a few per cent of it,
//! sit at the tolerance's edge (defects 1.7 to 9 %). So the sample decides between runs that
//! differ in whether they found the branch (the start, the tethered start, the arclength
//! fallback, the lift), and the choice between the two equation sets, which find the same
//! branch, is made by the branch's coverage ([`crate::branches::selected`]).

use crate::bar::shortest_travel_time;
use crate::branches::point::{BackbonePoint, CheckOutcome};
use crate::branches::request::TimeDomainCheck;
use crate::fourier::{Basis, CosineBasis};
use crate::system::{BarSystem, NonsmoothSystem};
use crate::verify::{periodicity_check, PeriodicityOptions, PeriodicityReport, VerifyError};

/// Points of a candidate run that [`Method::Auto`](crate::branches::Method::Auto) marches in
/// time to judge it (all of them where the run has fewer), spread evenly over its converged
/// points: the run's converged points count in the proportion of the sample that passes.
/// The judge is the same whether the request asks for the time-domain check or not, so
/// asking for it only annotates the points returned. It tells runs of motions from runs whose
/// points miss periodicity (10 to 80 % on chains with floating bars); it does not grade their
/// accuracy, and the choice between the paper's equations and harmonic selection does not
/// use it.
pub const JUDGE_SAMPLES: usize = 8;

/// Cells per shortest travel time of the judge's march ([`JUDGE_SAMPLES`]): a sixteenth of
/// the work of the default check's 400, with the displacement defect that decides resolved
/// well under its 5 % tolerance.
pub const JUDGE_CELLS_PER_TRAVEL: f64 = 100.0;

/// The outcome of `check` on the converged `point` of `system` in `basis`, and the march's
/// report where it ran.
pub(crate) fn check_point<B: Basis>(
    check: &TimeDomainCheck,
    (system, basis): (&BarSystem, &B),
    point: &BackbonePoint,
) -> (CheckOutcome, Option<PeriodicityReport>) {
    let options = &check.options;
    let steps = point.period / options.dt * options.periods as f64;
    if steps > check.max_steps {
        let max_steps = check.max_steps;
        return (CheckOutcome::OverBudget { steps, max_steps }, None);
    }
    match periodicity_check(system, basis, &point.x, point.omega, options) {
        Ok(r) if r.displacement_defect <= check.max_displacement_defect => {
            (CheckOutcome::Passed, Some(r))
        }
        Ok(r) => (CheckOutcome::Failed, Some(r)),
        Err(VerifyError::NoTimeDomainForm { condition }) => {
            (CheckOutcome::Unchecked { condition }, None)
        }
        Err(e) => (CheckOutcome::NotRun(e), None),
    }
}

/// The judge's check of `system`: [`TimeDomainCheck::for_system`] on a grid of
/// [`JUDGE_CELLS_PER_TRAVEL`] cells per shortest travel time.
pub(crate) fn judge_check(system: &BarSystem) -> TimeDomainCheck {
    let check = TimeDomainCheck::for_system(system);
    TimeDomainCheck {
        options: PeriodicityOptions {
            dt: shortest_travel_time(system.bars()) / JUDGE_CELLS_PER_TRAVEL,
            ..check.options
        },
        ..check
    }
}

/// The sample of a run the judge marched: how many of its points passed and failed (points
/// it could not march, or whose conditions have no time-domain form, are neither).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub(crate) struct Sampled {
    pub passed: usize,
    pub failed: usize,
}

impl Sampled {
    /// `count` scaled by the share of the sample that passed (`count` itself where nothing
    /// could be marched), rounded to the nearest integer.
    pub(crate) fn scale(&self, count: usize) -> usize {
        let marched = self.passed + self.failed;
        if marched == 0 {
            return count;
        }
        ((count * self.passed) as f64 / marched as f64).round() as usize
    }
}

/// The judge of one run: its sample of up to [`JUDGE_SAMPLES`] converged points, the `k`-th
/// of `s` at `(2k + 1) n / 2s` among the `n` converged, marched one at a time as far as a
/// question needs.
///
/// # Why lazily
/// Most questions `Auto` asks of a run are whether it falls short of half its grid's steps.
/// Once the points marched decide that whatever the others give (the run's count scaled by
/// the share that passed, with every remaining point failing, still reaches half the steps;
/// or with every one passing, still does not), the rest of the sample is not marched: on the
/// clamped bar four passing points of eight settle it. A question that needs the count
/// itself marches the whole sample, so every answer is the one the whole sample gives.
#[derive(Debug, Clone)]
pub(crate) struct Judge {
    system: BarSystem,
    basis: CosineBasis,
    /// The check each sampled point is marched with ([`judge_check`]).
    check: TimeDomainCheck,
    /// Indices of the sample among the run's points, in marching order.
    sample: Vec<usize>,
    /// How many of the sample were marched, and with what outcome.
    marched: usize,
    sampled: Sampled,
    /// The run's good points before scaling.
    count: usize,
}

impl Judge {
    /// The judge of the run of `points` on `problem`, nothing marched yet.
    pub(crate) fn new(points: &[BackbonePoint], problem: &NonsmoothSystem) -> Self {
        let converged: Vec<usize> = (0..points.len())
            .filter(|&i| points[i].converged())
            .collect();
        let (n, s) = (converged.len(), converged.len().min(JUDGE_SAMPLES));
        Self {
            system: problem.system().clone(),
            basis: problem.basis().clone(),
            check: judge_check(problem.system()),
            sample: (0..s)
                .map(|k| converged[(2 * k + 1) * n / (2 * s)])
                .collect(),
            marched: 0,
            sampled: Sampled::default(),
            count: points.iter().filter(|p| p.is_good()).count(),
        }
    }

    /// Marches the next point of the sample; `false` when none is left.
    fn march_next(&mut self, points: &[BackbonePoint]) -> bool {
        let Some(&i) = self.sample.get(self.marched) else {
            return false;
        };
        self.marched += 1;
        let Some(point) = points.get(i) else {
            return true;
        };
        match check_point(&self.check, (&self.system, &self.basis), point).0 {
            CheckOutcome::Passed => self.sampled.passed += 1,
            CheckOutcome::Failed => self.sampled.failed += 1,
            _ => {}
        }
        true
    }

    /// The run's good points, scaled by the share of the whole sample that passed.
    pub(crate) fn good(&mut self, points: &[BackbonePoint]) -> usize {
        while self.march_next(points) {}
        self.sampled.scale(self.count)
    }

    /// Whether the run's good points ([`Judge::good`]) are fewer than half of `steps`,
    /// marching only as much of the sample as decides it.
    pub(crate) fn falls_short(&mut self, points: &[BackbonePoint], steps: usize) -> bool {
        loop {
            let left = self.sample.len() - self.marched;
            let Sampled { passed, failed } = self.sampled;
            let least = Sampled {
                passed,
                failed: failed + left,
            };
            let most = Sampled {
                passed: passed + left,
                failed,
            };
            if 2 * least.scale(self.count) >= steps {
                return false;
            }
            if 2 * most.scale(self.count) < steps {
                return true;
            }
            if !self.march_next(points) {
                return 2 * self.sampled.scale(self.count) < steps;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_scale_by_the_share_that_passed() {
        let none = Sampled::default();
        assert_eq!(none.scale(181), 181);
        let half = Sampled {
            passed: 4,
            failed: 4,
        };
        assert_eq!(half.scale(181), 91);
        let all_failed = Sampled {
            passed: 0,
            failed: 3,
        };
        assert_eq!(all_failed.scale(181), 0);
    }

    /// The lazy judge answers whether a run falls short as the whole sample does, marching
    /// only what decides it: on the clamped bar's run, whose sampled points pass or fail
    /// whatever the order, the answer and the count match those of the full sample.
    #[test]
    fn falling_short_is_decided_as_the_whole_sample_decides_it() {
        use crate::branches::backbone::BackboneOptions;
        use crate::branches::compute::compute;
        use crate::branches::request::{Method, Request};
        use crate::reference::clamped_bar_with_obstacle;
        let system = clamped_bar_with_obstacle(1e-3).unwrap();
        let grid = BackboneOptions::for_mode(&system, 1, 1).unwrap();
        let request = Request::new(1)
            .harmonics(10)
            .method(Method::PeriodGrid(grid));
        let run = compute(&system, &request).unwrap();
        let points = run.points.clone();
        let mut whole = Judge::new(&points, run.problem());
        let good = whole.good(&points);
        for steps in [0, 1, good, 2 * good, 2 * good + 1, 2 * good + 2, 400] {
            let mut lazy = Judge::new(&points, run.problem());
            assert_eq!(
                lazy.falls_short(&points, steps),
                2 * good < steps,
                "{steps}"
            );
            assert!(lazy.marched <= JUDGE_SAMPLES);
            assert_eq!(lazy.good(&points), good);
        }
        // Half the steps reached with every sampled point passing: decided before the end.
        if whole.sampled.failed == 0 && whole.sampled.passed == JUDGE_SAMPLES {
            let mut lazy = Judge::new(&points, run.problem());
            assert!(!lazy.falls_short(&points, good));
            assert!(lazy.marched < JUDGE_SAMPLES);
        }
    }
}
