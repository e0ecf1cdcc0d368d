//! A converged orbit made a point: its section, its monodromy and verdict, its periodicity
//! report and contacts.

use super::corrector::Outcome;
use super::types::ExactPoint;
use super::walk::{Orbit, Walker};
use crate::branches::{BackbonePoint, CheckOutcome, PointStatus};
use crate::fourier::frequency_of_period;
use crate::modal::Label;
use crate::stability::shooting::PseudoInverse;
use crate::stability::{judge, law_gap, open_section, Floquet, StabilityError, UnresolvedReason};
use crate::verify::{
    march, periodicity_of_state, MarchOptions, PeriodicityOptions, PeriodicityReport, SpringUpdate,
    State,
};

/// A state whose smallest gap, relative to its law's, is below this is moved to the
/// widest-open instant of its orbit.
const MIN_OPEN_GAP: f64 = 0.25;

/// An orbit with its monodromy and verdict.
struct Judged {
    outcome: Outcome,
    state: State,
    /// The truncated pseudo-inverse of `M - I`: the next point's chord matrix.
    inverse: PseudoInverse,
    floquet: Floquet,
    /// The orbit's march over one period (its removed energy decides `Merged`).
    report: PeriodicityReport,
}

impl Walker<'_> {
    /// The monodromy and verdict of the periodic orbit `outcome` at `period`, corrected from
    /// `start`. Where the trivial pair is missed, no other differences' steps are tried (as
    /// [`floquet_of_state`](crate::stability::floquet_of_state) does): each costs a
    /// monodromy, and on the clamped bar's branch none found a pair the first step missed.
    fn judged(
        &self,
        period: f64,
        outcome: Outcome,
        start: (&[f64], f64),
    ) -> Result<Judged, StabilityError> {
        let stability = &self.options.stability;
        let (model, grid) = (self.template.model(), self.template.grid());
        let state = self.coordinates.to_state(model, grid, &outcome.x)?;
        let map = self.map(period);
        let monodromy = map.monodromy(&outcome.x, stability.relative_step)?;
        let report = periodicity_of_state(&state, period, &self.periodicity())?;
        let removed = report.projected_energy;
        let failure =
            (removed > self.options.max_removed_energy).then_some(UnresolvedReason::Merged {
                removed,
                bound: self.options.max_removed_energy,
            });
        let corrected = self.corrected(&outcome, start.0, start.1)?;
        // The eigenvalues and the singular value decomposition of one matrix are independent.
        let (floquet, inverse) = both(
            || judge(&map, &corrected, &monodromy, failure, stability, &[]),
            || PseudoInverse::of_monodromy(&monodromy),
        );
        Ok(Judged {
            outcome,
            state,
            inverse: inverse?,
            floquet: floquet?,
            report,
        })
    }

    fn periodicity(&self) -> PeriodicityOptions {
        PeriodicityOptions {
            dt: self.template.grid().dt(),
            adjust_grid: false,
            spring: self.options.stability.spring,
            periods: 1,
        }
    }

    /// The point of the periodic orbit `outcome` at grid period `j`, corrected from `start`:
    /// its section moved to an open instant where needed, its monodromy and verdict,
    /// periodicity report and contacts. `context`: its label, the previous period, whether it
    /// is a seed.
    pub(super) fn finish(
        &self,
        j: usize,
        mut outcome: Outcome,
        start: (&[f64], f64),
        context: (Option<Label>, Option<f64>, bool),
    ) -> Result<(Orbit, ExactPoint), StabilityError> {
        let period = self.periods[j];
        let stability = &self.options.stability;
        let (model, grid) = (self.template.model(), self.template.grid());
        let state = self.coordinates.to_state(model, grid, &outcome.x)?;
        if open_gap(&state) < MIN_OPEN_GAP {
            let section = open_section(&state, period, stability.spring)?;
            self.coordinates
                .of_snapshot(&section.snapshot(), &mut outcome.x);
        }
        let Judged {
            outcome,
            state,
            inverse,
            floquet,
            report,
        } = self.judged(period, outcome, start)?;
        let energy = self.energy(&outcome.x)?;
        let (label, previous, seeded) = context;
        let normalized = energy / self.grazing_energy;
        let status = PointStatus::Converged.with_energy(energy, normalized);
        let point = BackbonePoint {
            step: j,
            period,
            omega: frequency_of_period(period),
            energy,
            energy_normalized: normalized,
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
            removed_energy: report.projected_energy,
            contacts: contacts(&state, period, stability.spring)?,
            seeded,
        };
        let orbit = Orbit {
            index: Some(j),
            x: outcome.x,
            period,
            energy,
            label,
            jacobian: inverse,
        };
        Ok((orbit, exact))
    }
}

/// `(a(), b())`, on rayon's pool with the `parallel` feature.
fn both<A: Send, B: Send>(a: impl FnOnce() -> A + Send, b: impl FnOnce() -> B + Send) -> (A, B) {
    #[cfg(feature = "parallel")]
    return rayon::join(a, b);
    #[cfg(not(feature = "parallel"))]
    (a(), b())
}

/// The smallest gap of `state`'s unilateral conditions relative to their laws' gaps (`inf`
/// without any).
fn open_gap(state: &State) -> f64 {
    (0..state.model().conditions().len())
        .filter_map(|i| {
            let law = law_gap(state.model(), i).abs();
            state.gap(i).map(|g| g / law.max(f64::MIN_POSITIVE))
        })
        .fold(f64::INFINITY, f64::min)
}

/// Contact intervals per period of each unilateral condition: the runs of steps with a
/// positive contact force, counted around the period (1 for a contact that never opens).
fn contacts(
    state: &State,
    period: f64,
    spring: SpringUpdate,
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
            let n = pressed.len();
            let starts = (0..n)
                .filter(|&k| pressed[k] && !pressed[(k + n - 1) % n])
                .count();
            if starts == 0 && n > 0 && pressed[0] {
                1
            } else {
                starts
            }
        })
        .collect())
}
