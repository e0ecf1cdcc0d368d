//! The walk along the grid: seed, predictor, corrector, events, reseeds, and each point's
//! verdict.

use super::corrector::{correct, Limits, Outcome};
use super::{ExactEnd, ExactOptions, ExactPoint, LossReason, Skipped};
use crate::branches::{BackbonePoint, CheckOutcome, PointStatus};
use crate::continuation::Event;
use crate::fourier::frequency_of_period;
use crate::modal::Label;
use crate::solve::norm;
use crate::stability::coordinates::Coordinates;
use crate::stability::monodromy::PeriodMap;
use crate::stability::shooting::{Corrected, PseudoInverse};
use crate::stability::{
    correction_failure, judge, open_section, Floquet, StabilityError, UnresolvedReason, Verdict,
    RESOLVED_DEFECT,
};
use crate::verify::{march, periodicity_of_state, MarchOptions, PeriodicityOptions, State};

/// A state whose smallest gap, relative to its law's, is below this is moved to the
/// widest-open instant of its orbit.
const MIN_OPEN_GAP: f64 = 0.25;

/// A harmonic-balance point's state at `t = 0` on the branch's grid, and its label.
pub(crate) struct Seed {
    pub state: State,
    pub label: Option<Label>,
}

/// An exact orbit: its section state, period, energy, label and factored monodromy.
#[derive(Clone)]
struct Orbit {
    x: Vec<f64>,
    period: f64,
    energy: f64,
    label: Option<Label>,
    jacobian: PseudoInverse,
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
    fn map(&self, period: f64) -> PeriodMap<'_> {
        PeriodMap {
            coordinates: self.coordinates,
            template: self.template,
            period,
            spring: self.options.stability.spring,
        }
    }

    fn energy(&self, x: &[f64]) -> Result<f64, StabilityError> {
        Ok(self.coordinates.energy(self.template, x)?)
    }

    /// The seed, the walk forward from it, then back to the grid's first period.
    pub(crate) fn walk(&self) -> (Vec<ExactPoint>, Vec<Skipped>, ExactEnd) {
        let n = self.periods.len();
        let mut attempts = 0;
        let mut last = LossReason::NoHarmonicBalancePoint;
        let mut seeded = None;
        for j in 0..n {
            match self.seed(j) {
                Ok(found) => {
                    seeded = Some((j, found));
                    break;
                }
                Err(LossReason::NoHarmonicBalancePoint) => continue,
                Err(reason) => {
                    attempts += 1;
                    last = reason;
                    if attempts >= self.options.seed_attempts {
                        break;
                    }
                }
            }
        }
        let Some((s, (orbit, point))) = seeded else {
            let end = ExactEnd::NoSeed { attempts, last };
            return (Vec::new(), Vec::new(), end);
        };
        let mut points = vec![point];
        let mut skipped = Vec::new();
        let mut branch = 0;
        let forward = self.walk_from(
            orbit.clone(),
            s + 1..n,
            &mut branch,
            &mut points,
            &mut skipped,
        );
        let backward = self.walk_from(orbit, (0..s).rev(), &mut branch, &mut points, &mut skipped);
        points.sort_by_key(|p| p.point.step);
        stability_events(&mut points);
        let end = forward.or(backward).unwrap_or(ExactEnd::Completed);
        (points, skipped, end)
    }

    /// Continues from `orbit` over `indices`; `Some` end where the branch was lost for good.
    fn walk_from(
        &self,
        orbit: Orbit,
        indices: impl Iterator<Item = usize>,
        branch: &mut usize,
        points: &mut Vec<ExactPoint>,
        skipped: &mut Vec<Skipped>,
    ) -> Option<ExactEnd> {
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
                        return Some(ExactEnd::Lost {
                            period,
                            attempts: lost,
                            last: seed_failure,
                        });
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
        let limits = Limits {
            iterations: stability.corrections,
            refreshes: stability.corrections,
            relative_step: stability.relative_step,
            tolerance: crate::stability::PERIODIC_DEFECT,
        };
        let map = self.map(period);
        let outcome = correct(&map, &base, &mut None, &limits).map_err(LossReason::Error)?;
        let energy = self.energy(&base).map_err(LossReason::Error)?;
        let corrected = self
            .corrected(&outcome, &base, energy)
            .map_err(LossReason::Error)?;
        if let Some(reason) = correction_failure(&corrected, stability) {
            return Err(LossReason::Correction(reason));
        }
        self.finish(j, outcome, (&base, energy), (seed.label, None, true))
            .map_err(LossReason::Error)
    }

    /// The orbit of grid period `j` continued from `last` (and `before`, for the secant).
    fn continue_to(
        &self,
        j: usize,
        last: &Orbit,
        before: Option<&Orbit>,
    ) -> Result<(Orbit, ExactPoint), LossReason> {
        let period = self.periods[j];
        let (prediction, predicted_energy) = match before {
            Some(b) => {
                let s = (period - last.period) / (last.period - b.period);
                let x: Vec<f64> = last
                    .x
                    .iter()
                    .zip(&b.x)
                    .map(|(a, b)| a + s * (a - b))
                    .collect();
                (x, last.energy + s * (last.energy - b.energy))
            }
            None => (last.x.clone(), last.energy),
        };
        let allowed = match before {
            Some(_) => {
                (predicted_energy - last.energy).abs() / last.energy + self.options.max_energy_jump
            }
            None => self.options.first_step_jump,
        };
        let limits = Limits {
            iterations: self.options.iterations,
            refreshes: self.options.refreshes,
            relative_step: self.options.stability.relative_step,
            tolerance: crate::stability::PERIODIC_DEFECT,
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
                let reason = correction_failure(&corrected, &self.options.stability);
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
        let first = attempt(&prediction, Some(last.jacobian.clone())).map_err(LossReason::Error)?;
        let outcome = match judge_attempt(first) {
            Ok(outcome) => outcome,
            // Once more from the previous orbit, with a matrix of the new period.
            Err(_) => judge_attempt(attempt(&last.x, None).map_err(LossReason::Error)?)?,
        };
        let context = (last.label.clone(), Some(last.period), false);
        self.finish(j, outcome, (&prediction, predicted_energy), context)
            .map_err(LossReason::Error)
    }

    /// The correction `outcome` from `start` (of energy `energy`), as [`Corrected`].
    fn corrected(
        &self,
        outcome: &Outcome,
        start: &[f64],
        energy: f64,
    ) -> Result<Corrected, StabilityError> {
        let change: Vec<f64> = outcome.x.iter().zip(start).map(|(a, b)| a - b).collect();
        let reached = self.energy(&outcome.x)?;
        Ok(Corrected {
            x: outcome.x.clone(),
            initial_defect: outcome.initial_defect,
            defect: outcome.defect,
            energy_change: (reached - energy) / energy,
            shift: norm(&change) / norm(start),
            displacement_shift: self.coordinates.displacement_distance(&outcome.x, start),
            iterations: outcome.iterations,
        })
    }

    /// The point of the periodic orbit `outcome` at grid period `j`, corrected from `start`:
    /// its section moved to an open instant where needed, its monodromy, verdict, periodicity
    /// report and contacts. `context`: its label, the previous period, whether it is a seed.
    fn finish(
        &self,
        j: usize,
        mut outcome: Outcome,
        start: (&[f64], f64),
        context: (Option<Label>, Option<f64>, bool),
    ) -> Result<(Orbit, ExactPoint), StabilityError> {
        let period = self.periods[j];
        let stability = &self.options.stability;
        let (model, grid) = (self.template.model(), self.template.grid());
        let mut state = self.coordinates.to_state(model, grid, &outcome.x)?;
        if open_gap(&state) < MIN_OPEN_GAP {
            state = open_section(&state, period, stability.spring)?;
            self.coordinates
                .of_snapshot(&state.snapshot(), &mut outcome.x);
        }
        let map = self.map(period);
        let monodromy = map.monodromy(&outcome.x, stability.relative_step)?;
        let options = PeriodicityOptions {
            dt: grid.dt(),
            adjust_grid: false,
            spring: stability.spring,
            periods: 1,
        };
        let report = periodicity_of_state(&state, period, &options)?;
        let removed = report.projected_energy;
        let failure =
            (removed > self.options.max_removed_energy).then_some(UnresolvedReason::Merged {
                removed,
                bound: self.options.max_removed_energy,
            });
        let corrected = self.corrected(&outcome, start.0, start.1)?;
        let floquet = judge(&map, &corrected, &monodromy, failure, stability)?;
        let energy = self.energy(&outcome.x)?;
        let (label, previous, seeded) = context;
        let status = PointStatus::Converged.with_energy(energy, energy / self.grazing_energy);
        let point = BackbonePoint {
            step: j,
            period,
            omega: frequency_of_period(period),
            energy,
            energy_normalized: energy / self.grazing_energy,
            converged: status == PointStatus::Converged,
            status,
            residual_norm: outcome.defect,
            iterations: outcome.iterations,
            x: Vec::new(),
            step_size: previous.map_or(0.0, |t| period - t),
            events: Vec::new(),
            branch: 0,
            time_domain: Some(report),
            check: Some(CheckOutcome::Passed),
            character: None,
            label: label.clone(),
            stability: Some(Ok(floquet)),
            hill: None,
        };
        let exact = ExactPoint {
            point,
            requested_period: self.requested[j],
            harmonic_balance_distance: self.harmonic_balance[j].map(|e| (energy - e) / e),
            removed_energy: removed,
            contacts: contacts(&state, period, stability.spring)?,
            seeded,
        };
        let orbit = Orbit {
            x: outcome.x,
            period,
            energy,
            label,
            jacobian: PseudoInverse::of_monodromy(&monodromy)?,
        };
        Ok((orbit, exact))
    }
}

/// The smallest gap of `state`'s unilateral conditions relative to their laws' gaps (`inf`
/// without any).
fn open_gap(state: &State) -> f64 {
    (0..state.model().conditions().len())
        .filter_map(|i| {
            let law = crate::stability::law_gap(state.model(), i).abs();
            state.gap(i).map(|g| g / law.max(f64::MIN_POSITIVE))
        })
        .fold(f64::INFINITY, f64::min)
}

/// Contact intervals per period of each unilateral condition: the runs of steps with a
/// positive contact force, counted around the period.
fn contacts(
    state: &State,
    period: f64,
    spring: crate::verify::SpringUpdate,
) -> Result<Vec<usize>, StabilityError> {
    let options = MarchOptions {
        spring,
        snapshot_every: 0,
    };
    let trajectory = march(state, period, &options)?;
    Ok(trajectory
        .contacts
        .iter()
        .map(|h| {
            let pressed: Vec<bool> = h.force.iter().map(|f| *f > 0.0).collect();
            let starts = (0..pressed.len())
                .filter(|&k| pressed[k] && !pressed[(k + pressed.len() - 1) % pressed.len()])
                .count();
            if starts == 0 && pressed.iter().all(|p| *p) && !pressed.is_empty() {
                1
            } else {
                starts
            }
        })
        .collect())
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
            if branch == p.point.branch {
                match (before, now) {
                    (Verdict::Stable, Verdict::Unstable(crossing)) => {
                        p.point.events.push(Event::StabilityLost { crossing })
                    }
                    (Verdict::Unstable(crossing), Verdict::Stable) => {
                        p.point.events.push(Event::StabilityGained { crossing })
                    }
                    _ => {}
                }
            }
        }
        last = Some((p.point.branch, now));
    }
}
