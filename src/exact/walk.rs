//! The walk along the grid: seed, predictor, corrector, events, reseeds, and each point's
//! verdict.

use super::corrector::{correct, Limits, Outcome};
use super::options::ExactOptions;
use super::types::{ExactEnd, ExactPoint, LossReason, Skipped};
use crate::continuation::Event;
use crate::modal::Label;
use crate::solve::norm;
use crate::stability::coordinates::Coordinates;
use crate::stability::monodromy::PeriodMap;
use crate::stability::shooting::{Corrected, PseudoInverse};
use crate::stability::{
    correction_failure_on, open_section, Floquet, StabilityError, UnresolvedReason, Verdict,
    RESOLVED_DEFECT,
};
use crate::verify::State;

/// The smallest trust radius of a continued point's corrector, relative to the state.
const TRUST: f64 = 1e-2;

/// The trust radius of a seed's corrector, relative to the harmonic-balance state: its
/// strain's Gibbs oscillation puts it up to about a fifth of its norm from the orbit (the
/// free–free bar between walls at `m = 20`), and longer steps along the small singular
/// values of `M - I` lead to other orbits.
const SEED_TRUST: f64 = 0.25;

/// A harmonic-balance point's state at `t = 0` on the branch's grid, and its label.
pub(crate) struct Seed {
    pub state: State,
    pub label: Option<Label>,
}

/// An exact orbit: its section state, period, energy, label and factored monodromy.
#[derive(Clone)]
pub(super) struct Orbit {
    /// Its index in the grid (`None` for an orbit half-way between two).
    pub index: Option<usize>,
    pub x: Vec<f64>,
    pub period: f64,
    pub energy: f64,
    pub label: Option<Label>,
    pub jacobian: PseudoInverse,
}

/// What a walk needs: the coordinates and grid, the periods (the map's and the requested
/// ones), the harmonic-balance energies and seeds by grid index.
pub(crate) struct Walker<'a> {
    pub coordinates: &'a Coordinates,
    pub template: &'a State,
    pub periods: &'a [f64],
    pub requested: &'a [f64],
    pub harmonic_balance: &'a [Option<f64>],
    pub seeds: &'a dyn Fn(usize) -> Option<Result<Seed, StabilityError>>,
    pub options: &'a ExactOptions,
    pub grazing_energy: f64,
}

impl Walker<'_> {
    pub(super) fn map(&self, period: f64) -> PeriodMap<'_> {
        PeriodMap {
            coordinates: self.coordinates,
            template: self.template,
            period,
            spring: self.options.stability.spring,
        }
    }

    pub(super) fn energy(&self, x: &[f64]) -> Result<f64, StabilityError> {
        Ok(self.coordinates.energy(self.template, x)?)
    }

    /// Segments until the grid is covered: a seed at the first period from `next` whose
    /// harmonic-balance point corrects, the walk back from it to `next`, then forward until
    /// the branch is lost for good; the next segment starts after the period where it was.
    pub(crate) fn walk(&self) -> (Vec<ExactPoint>, Vec<Skipped>, ExactEnd) {
        let n = self.periods.len();
        let (mut points, mut skipped) = (Vec::new(), Vec::new());
        let (mut next, mut branch) = (0, 0);
        let mut end = ExactEnd::Completed;
        while next < n {
            let (found, attempts, last) = self.find_seed(next);
            let Some((s, orbit, mut point)) = found else {
                end = match points.is_empty() {
                    true => ExactEnd::NoSeed { attempts, last },
                    false => ExactEnd::Lost {
                        period: self.periods[next],
                        attempts,
                        last,
                    },
                };
                break;
            };
            point.point.branch = branch;
            points.push(point);
            let back = (next..s).rev();
            let lost = self.walk_from(orbit.clone(), back, &mut branch, &mut points, &mut skipped);
            if let Some((j, _)) = lost {
                // The periods the walk back did not reach are said, not dropped.
                skipped.extend((next..j).map(|i| Skipped {
                    period: self.periods[i],
                    reason: LossReason::Unreached,
                }));
            }
            match self.walk_from(orbit, s + 1..n, &mut branch, &mut points, &mut skipped) {
                None => {
                    end = ExactEnd::Completed;
                    break;
                }
                Some((j, last)) => {
                    (next, branch) = (j + 1, branch + 1);
                    let attempts = self.options.max_lost;
                    let period = self.periods[j];
                    end = ExactEnd::Lost {
                        period,
                        attempts,
                        last,
                    };
                }
            }
        }
        points.sort_by_key(|p| p.point.step);
        skipped.sort_by(|a, b| a.period.total_cmp(&b.period));
        stability_events(&mut points);
        (points, skipped, end)
    }

    /// The first period from `from` whose harmonic-balance point corrects to a seed, within
    /// [`ExactOptions::seed_attempts`] failures: its index, orbit and point, with the failures
    /// counted and the last one's reason.
    #[allow(clippy::type_complexity)]
    fn find_seed(&self, from: usize) -> (Option<(usize, Orbit, ExactPoint)>, usize, LossReason) {
        let mut attempts = 0;
        let mut last = LossReason::NoHarmonicBalancePoint;
        for j in from..self.periods.len() {
            match self.seed(j) {
                Ok((orbit, point)) => return (Some((j, orbit, point)), attempts, last),
                Err(LossReason::NoHarmonicBalancePoint) => {}
                Err(reason) => {
                    attempts += 1;
                    last = reason;
                    if attempts >= self.options.seed_attempts {
                        break;
                    }
                }
            }
        }
        (None, attempts, last)
    }

    /// Continues from `orbit` over `indices`, reseeding where the branch is lost; the index
    /// and reason where it was lost [`ExactOptions::max_lost`] times in a row.
    fn walk_from(
        &self,
        orbit: Orbit,
        indices: impl Iterator<Item = usize>,
        branch: &mut usize,
        points: &mut Vec<ExactPoint>,
        skipped: &mut Vec<Skipped>,
    ) -> Option<(usize, LossReason)> {
        let (mut last, mut before): (Orbit, Option<Orbit>) = (orbit, None);
        let mut lost = 0;
        for j in indices {
            let period = self.periods[j];
            let reason = match self.continue_to(j, &last, before.as_ref()) {
                Ok((next, point)) => {
                    points.push(point);
                    before = Some(std::mem::replace(&mut last, next));
                    lost = 0;
                    continue;
                }
                Err(reason) => reason,
            };
            before = None;
            match self.seed(j) {
                Ok((next, mut point)) => {
                    *branch += 1;
                    point.point.branch = *branch;
                    let ratio = ((next.energy - last.energy) / last.energy).abs();
                    point.point.events.push(Event::Jump { ratio });
                    points.push(point);
                    last = next;
                    lost = 0;
                }
                Err(seed_failure) => {
                    skipped.push(Skipped { period, reason });
                    lost += 1;
                    if lost >= self.options.max_lost {
                        return Some((j, seed_failure));
                    }
                }
            }
        }
        None
    }

    /// The orbit of grid period `j` corrected from the harmonic-balance point there.
    fn seed(&self, j: usize) -> Result<(Orbit, ExactPoint), LossReason> {
        let seed = (self.seeds)(j).ok_or(LossReason::NoHarmonicBalancePoint)?;
        let seed = seed.map_err(LossReason::Error)?;
        let period = self.periods[j];
        let stability = &self.options.stability;
        let section =
            open_section(&seed.state, period, stability.spring).map_err(LossReason::Error)?;
        let mut base = Vec::new();
        self.coordinates.of_snapshot(&section.snapshot(), &mut base);
        // Chord steps as along the branch, fresh matrices only where they stall.
        let limits = Limits {
            iterations: stability.corrections + self.options.iterations,
            refreshes: stability.corrections,
            relative_step: stability.relative_step,
            tolerance: crate::stability::PERIODIC_DEFECT,
            max_step: SEED_TRUST * norm(&base),
        };
        let map = self.map(period);
        let outcome = correct(&map, &base, &mut None, &limits).map_err(LossReason::Error)?;
        let energy = self.energy(&base).map_err(LossReason::Error)?;
        let corrected = self
            .corrected(&outcome, &base, energy)
            .map_err(LossReason::Error)?;
        let failure = correction_failure_on(&map, &corrected, stability);
        if let Some(reason) = failure.map_err(LossReason::Error)? {
            return Err(LossReason::Correction(reason));
        }
        self.finish(j, outcome, (&base, energy), (seed.label, None, true))
            .map_err(LossReason::Error)
    }

    /// The orbit of grid period `j` continued from `last` (and `before`, for the secant).
    /// Where the correction fails over more than one step of the grid, the step is halved:
    /// an orbit at the whole number of steps half-way, not reported, then on from it.
    fn continue_to(
        &self,
        j: usize,
        last: &Orbit,
        before: Option<&Orbit>,
    ) -> Result<(Orbit, ExactPoint), LossReason> {
        let period = self.periods[j];
        let ratio = match (last.index, self.harmonic_balance[j]) {
            (Some(i), Some(e)) => self.harmonic_balance[i].map(|e_last| e / e_last),
            _ => None,
        };
        let (outcome, prediction, predicted) = match self.correct_to(period, ratio, last, before) {
            Ok(found) => found,
            Err(reason) => {
                let dt = self.template.grid().dt();
                let steps = ((period - last.period) / dt).round();
                if steps.abs() < 2.0 {
                    return Err(reason);
                }
                let mid = last.period + (steps / 2.0).trunc() * dt;
                let half = ratio.map(f64::sqrt);
                let (outcome, _, _) = self
                    .correct_to(mid, half, last, before)
                    .map_err(|_| reason)?;
                let halfway = self.orbit(mid, outcome, last).map_err(LossReason::Error)?;
                return self.continue_to(j, &halfway, Some(last));
            }
        };
        let context = (last.label.clone(), Some(last.period), false);
        self.finish(j, outcome, (&prediction, predicted), context)
            .map_err(LossReason::Error)
    }

    /// The unreported orbit `outcome` at `period` half-way from `last`, with its monodromy.
    fn orbit(&self, period: f64, outcome: Outcome, last: &Orbit) -> Result<Orbit, StabilityError> {
        let step = self.options.stability.relative_step;
        let monodromy = self.map(period).monodromy(&outcome.x, step)?;
        Ok(Orbit {
            index: None,
            energy: self.energy(&outcome.x)?,
            x: outcome.x,
            period,
            label: last.label.clone(),
            jacobian: PseudoInverse::of_monodromy(&monodromy)?,
        })
    }

    /// The periodic orbit at `period` from `last` (and `before`, for the secant), with the
    /// prediction and its energy; `ratio`, harmonic balance's ratio of energies, predicts the
    /// energy without a secant.
    #[allow(clippy::type_complexity)]
    fn correct_to(
        &self,
        period: f64,
        ratio: Option<f64>,
        last: &Orbit,
        before: Option<&Orbit>,
    ) -> Result<(Outcome, Vec<f64>, f64), LossReason> {
        // The secant's step without the directions `M - I` annihilates at the last orbit:
        // along them nothing fixes the step, and a step carried on from one point to the next
        // drifts the branch off its family onto the orbits around it, the waves that return
        // onto themselves over the period (`docs/validation.md`). The plain secant is the
        // fallback.
        let (prediction, secant, predicted_energy) = match before {
            Some(b) => {
                let s = (period - last.period) / (last.period - b.period);
                let step: Vec<f64> = last.x.iter().zip(&b.x).map(|(a, b)| s * (a - b)).collect();
                let kept = last.jacobian.without_null_directions(&step);
                let along =
                    |d: &[f64]| -> Vec<f64> { last.x.iter().zip(d).map(|(a, d)| a + d).collect() };
                let energy = last.energy + s * (last.energy - b.energy);
                (along(&kept), Some(along(&step)), energy)
            }
            None => (last.x.clone(), None, last.energy * ratio.unwrap_or(1.0)),
        };
        let predicted_change = (predicted_energy - last.energy).abs() / last.energy;
        let allowed = match (before, predicted_change > 0.0) {
            (None, false) => self.options.first_step_jump,
            _ => predicted_change + self.options.max_energy_jump,
        };
        // The trust radius: twice the predictor's step, and at least a hundredth of the state.
        let moved: Vec<f64> = prediction.iter().zip(&last.x).map(|(a, b)| a - b).collect();
        let limits = Limits {
            iterations: self.options.iterations,
            refreshes: self.options.refreshes,
            relative_step: self.options.stability.relative_step,
            tolerance: crate::stability::PERIODIC_DEFECT,
            max_step: (2.0 * norm(&moved)).max(TRUST * norm(&last.x)),
        };
        let map = self.map(period);
        let attempt = |start: &[f64], mut jacobian: Option<PseudoInverse>| {
            let outcome = correct(&map, start, &mut jacobian, &limits)?;
            let energy = self.energy(&outcome.x)?;
            Ok::<_, StabilityError>((outcome, energy))
        };
        let judge_attempt = |(outcome, energy): (Outcome, f64)| {
            if outcome.defect > RESOLVED_DEFECT {
                let corrected = self
                    .corrected(&outcome, &prediction, predicted_energy)
                    .map_err(LossReason::Error)?;
                let reason = correction_failure_on(&map, &corrected, &self.options.stability)
                    .map_err(LossReason::Error)?;
                return Err(LossReason::Correction(reason.unwrap_or(
                    UnresolvedReason::NotPeriodic {
                        defect: outcome.defect,
                        bound: RESOLVED_DEFECT,
                        iterations: outcome.iterations,
                        corrections: limits.iterations,
                    },
                )));
            }
            let change = (energy - predicted_energy).abs() / last.energy;
            if change > allowed {
                return Err(LossReason::Jump { change, allowed });
            }
            Ok(outcome)
        };
        // The prediction, then the plain secant, with the last orbit's matrix; then once more
        // from the last orbit, with a matrix of the new period. A march that fails on the
        // way is one more failed attempt.
        let starts = [
            Some((&prediction, true)),
            secant.as_ref().map(|x| (x, true)),
            Some((&last.x, false)),
        ];
        let mut found = Err(LossReason::Unreached);
        for (start, chord) in starts.into_iter().flatten() {
            let jacobian = chord.then(|| last.jacobian.clone());
            found = (attempt(start, jacobian).map_err(LossReason::Error)).and_then(judge_attempt);
            if found.is_ok() {
                break;
            }
        }
        Ok((found?, prediction, predicted_energy))
    }

    /// The correction `outcome` from `start` (of energy `energy`), as [`Corrected`].
    pub(super) fn corrected(
        &self,
        outcome: &Outcome,
        start: &[f64],
        energy: f64,
    ) -> Result<Corrected, StabilityError> {
        Corrected::measured(
            (self.coordinates, self.template),
            (outcome.x.clone(), start, energy),
            (outcome.initial_defect, outcome.defect, outcome.iterations),
        )
    }
}

/// Adds [`Event::StabilityLost`] and [`Event::StabilityGained`] where the verdict changes
/// between resolved points of the same branch.
fn stability_events(points: &mut [ExactPoint]) {
    let verdict = |p: &ExactPoint| match &p.point.stability {
        Some(Ok(Floquet { verdict, .. })) if *verdict != Verdict::Unresolved => Some(*verdict),
        _ => None,
    };
    let mut last: Option<(usize, Verdict)> = None;
    for p in points.iter_mut() {
        let Some(now) = verdict(p) else { continue };
        if let Some((branch, before)) = last {
            let event = Event::of_verdicts(before, now);
            if let Some(event) = event.filter(|_| branch == p.point.branch) {
                p.point.events.push(event);
            }
        }
        last = Some((p.point.branch, now));
    }
}
