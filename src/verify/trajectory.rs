//! A march of a given duration and the histories it records.

use super::grid::MAX_MARCH_WORK;
use super::{Grid, Integrator, MarchOptions, Snapshot, State, VerifyError};
use crate::bar::{End, EndRef};
use crate::fourier::check_memory;

/// History of one bar end along a march (the harmonic-balance side is
/// [`modal::diagnostics::EndHistory`](crate::modal::diagnostics::EndHistory)).
#[derive(Debug, Clone, PartialEq)]
pub struct MarchedEnd {
    /// The end.
    pub end: EndRef,
    /// Displacement at each instant of [`Trajectory::times`].
    pub displacement: Vec<f64>,
    /// Mean strain `u_x` over each step (one fewer entry than `times`).
    pub strain: Vec<f64>,
}

/// History of one unilateral condition.
#[derive(Debug, Clone, PartialEq)]
pub struct ContactHistory {
    /// Index of the condition in the model.
    pub condition: usize,
    /// Gap at each instant of [`Trajectory::times`].
    pub gap: Vec<f64>,
    /// Mean contact force over each step (one fewer entry than `times`): the impulse of the
    /// step divided by its length.
    pub force: Vec<f64>,
}

/// Result of [`march`].
#[derive(Debug, Clone, PartialEq)]
pub struct Trajectory {
    /// Instants: 0, then the end of every step.
    pub times: Vec<f64>,
    /// Energy at each instant ([`State::energy`] of the discrete state, from running
    /// integrals that equal it to rounding).
    pub energy: Vec<f64>,
    /// Every bar end, `[bar 0 left, bar 0 right, bar 1 left, ...]`.
    pub ends: Vec<MarchedEnd>,
    /// Every unilateral condition, in model order.
    pub contacts: Vec<ContactHistory>,
    /// Snapshots every [`MarchOptions::snapshot_every`] steps (and at `t = 0`).
    pub snapshots: Vec<Snapshot>,
    /// Largest penetration over the march (including the initial state).
    pub max_penetration: f64,
    /// Smallest contact force over the march (0 if some contact opened; `+inf` without
    /// unilateral conditions).
    pub min_contact_force: f64,
    /// `max_t |E(t) - E(0)| / E(0)` (absolute if `E(0) = 0`).
    pub energy_drift: f64,
    /// Energy removed over the march by merging short pieces ([`State::projected_energy`]),
    /// absolute: with lossless conditions `E(t) + (removed by t) = E(0)` to rounding, so
    /// `energy_drift E(0)` is at most this much plus rounding.
    pub projected_energy: f64,
    /// The state at the end.
    pub final_state: State,
}

/// Checks that the histories of a march of `steps` steps from `initial`, with a snapshot
/// every `snapshot_every` steps, fit in the memory budget: per step the time and the energy,
/// the displacement and strain of every bar end and the gap and force of every unilateral
/// condition; per snapshot the three fields of every cell.
fn check_history(initial: &State, steps: f64, snapshot_every: usize) -> Result<(), VerifyError> {
    let model = initial.model();
    let bars = model.bars().len() as f64;
    let contacts = model
        .conditions()
        .iter()
        .filter(|c| c.is_unilateral())
        .count() as f64;
    let per_step = 2.0 + 4.0 * bars + 2.0 * contacts;
    let snapshots = if snapshot_every > 0 {
        steps / snapshot_every as f64 + 1.0
    } else {
        0.0
    };
    let grid = initial.grid();
    let cells = (0..grid.bars()).map(|b| grid.cells(b) as f64).sum::<f64>();
    let per_snapshot = 3.0 * cells + bars + 1.0;
    let doubles = steps * per_step + snapshots * per_snapshot;
    Ok(check_memory(
        "the histories of a march (duration / dt steps)",
        doubles,
    )?)
}

/// Checks that a march of `steps` steps on `grid` stays within [`MAX_MARCH_WORK`].
fn check_work(grid: &Grid, steps: f64) -> Result<(), VerifyError> {
    let (per_step, work) = grid.march_work(steps);
    if work > MAX_MARCH_WORK as f64 {
        return Err(VerifyError::TooCostly {
            steps,
            per_step,
            work,
            limit: MAX_MARCH_WORK as f64,
        });
    }
    Ok(())
}

/// The steps of a march: `full` whole steps, then a partial one when the duration is not a
/// whole number of steps, checked against the history and work limits.
struct Plan {
    full: usize,
    partial: Option<f64>,
    planned: f64,
}

impl Plan {
    fn new(initial: &State, duration: f64, snapshot_every: usize) -> Result<Self, VerifyError> {
        let total = duration / initial.grid().dt();
        if !(duration.is_finite() && duration >= 0.0) {
            return Err(VerifyError::InvalidParameter {
                what: "march duration",
                value: duration,
            });
        }
        let full = (total + 1e-9).floor();
        let rest = total - full;
        let partial = (rest > 1e-9).then_some(rest);
        check_history(initial, full + 1.0, snapshot_every)?;
        let planned = full + partial.map_or(0.0, |_| 1.0);
        check_work(initial.grid(), planned)?;
        Ok(Self {
            full: full as usize,
            partial,
            planned,
        })
    }

    fn steps(&self) -> usize {
        self.full + usize::from(self.partial.is_some())
    }

    fn fractions(&self) -> impl Iterator<Item = f64> {
        std::iter::repeat_n(1.0, self.full).chain(self.partial)
    }

    /// An integrator from `initial`, its waves allowed the pieces this many steps need.
    fn integrator(&self, initial: &State, options: &MarchOptions) -> Integrator {
        let mut start = initial.clone();
        let grid = initial.grid().clone();
        start.set_resolution(|b| grid.march_resolution(b, self.planned));
        Integrator::new(start, *options)
    }
}

/// The integrator's state, back at the grid's own resolution.
fn finish(integrator: Integrator) -> State {
    let mut state = integrator.into_state();
    let grid = state.grid().clone();
    state.set_resolution(|b| grid.resolution(b));
    state
}

/// The state `duration` after `initial`: the `final_state` of [`march`] bit for bit, without
/// recording histories. The stability analysis maps states over one period `2 n` times per
/// monodromy matrix and needs only where they end.
///
/// # Errors
/// As [`march`].
pub fn advance(
    initial: &State,
    duration: f64,
    options: &MarchOptions,
) -> Result<State, VerifyError> {
    let plan = Plan::new(initial, duration, 0)?;
    let mut integrator = plan.integrator(initial, options);
    for f in plan.fractions() {
        integrator.advance_quietly(f);
    }
    Ok(finish(integrator))
}

/// Marches `initial` over `duration` (full steps, then one partial step for the remainder)
/// and records end histories, contact histories, energy and snapshots.
///
/// **Cost.** A step takes the pieces of the waves that reach the ends during it. The march
/// caps the pieces of each wave according to its length ([`MARCH_WORK`](super::MARCH_WORK)):
/// it is exact (no merge) as long as the waves would cost less than about `MARCH_WORK` piece
/// operations in all; beyond, it keeps at least
/// [`PIECES_PER_CELL`](super::PIECES_PER_CELL) pieces per cell and merges shorter ones
/// ([`Trajectory::projected_energy`]). Its work is therefore at most
/// `2 MARCH_WORK + sum_waves ((steps / nu_b + 1) (2 PIECES_PER_CELL N_b + 2) + steps)`
/// pieces taken ([`Grid::march_work`]): linear in the number of steps, whatever the travel
/// times and the impacts. Marches whose bound exceeds [`MAX_MARCH_WORK`] are refused.
///
/// # Errors
/// [`VerifyError::InvalidParameter`] if `duration` is negative or not finite;
/// [`VerifyError::TooLarge`] if the histories of its `duration / dt` steps (and its
/// snapshots) do not fit in the memory budget
/// ([`MEMORY_BUDGET_BYTES`](crate::fourier::MEMORY_BUDGET_BYTES));
/// [`VerifyError::TooCostly`] if the bound on its work exceeds [`MAX_MARCH_WORK`].
pub fn march(
    initial: &State,
    duration: f64,
    options: &MarchOptions,
) -> Result<Trajectory, VerifyError> {
    let plan = Plan::new(initial, duration, options.snapshot_every)?;
    let steps = plan.steps();
    let model = initial.model().clone();
    let mut ends: Vec<MarchedEnd> = (0..model.bars().len())
        .flat_map(|b| {
            let id = crate::bar::BarId(b);
            [id.left(), id.right()]
        })
        .map(|end| MarchedEnd {
            end,
            displacement: vec![initial.end_displacement(end)],
            strain: Vec::with_capacity(steps),
        })
        .collect();
    let mut contacts: Vec<ContactHistory> = model
        .conditions()
        .iter()
        .enumerate()
        .filter(|(_, c)| c.is_unilateral())
        .map(|(i, _)| ContactHistory {
            condition: i,
            gap: vec![initial.gap(i).unwrap_or(0.0)],
            force: Vec::with_capacity(steps),
        })
        .collect();
    let e0 = initial.tracked_energy();
    let mut times = vec![0.0];
    let mut energy = vec![e0];
    let mut snapshots = Vec::new();
    if options.snapshot_every > 0 {
        snapshots.push(initial.snapshot());
    }
    let mut max_penetration = initial.penetration();
    let mut min_contact_force = f64::INFINITY;
    let mut integrator = plan.integrator(initial, options);
    for (k, f) in plan.fractions().enumerate() {
        let summary = integrator.advance_unchecked(f);
        let state = integrator.state();
        times.push(summary.time);
        energy.push(state.tracked_energy());
        for h in ends.iter_mut() {
            h.displacement.push(state.end_displacement(h.end));
            h.strain
                .push(summary.end_strain[h.end.bar.index()][usize::from(h.end.end == End::Right)]);
        }
        for h in contacts.iter_mut() {
            h.gap.push(state.gap(h.condition).unwrap_or(0.0));
            h.force.push(summary.contact_force[h.condition]);
        }
        max_penetration = max_penetration.max(summary.max_penetration);
        min_contact_force = min_contact_force.min(summary.min_contact_force);
        if options.snapshot_every > 0 && (k + 1) % options.snapshot_every == 0 {
            snapshots.push(state.snapshot());
        }
    }
    let final_state = finish(integrator);
    let scale = if e0 > 0.0 { e0 } else { 1.0 };
    let energy_drift = energy
        .iter()
        .fold(0.0f64, |m, e| m.max((e - e0).abs() / scale));
    Ok(Trajectory {
        times,
        energy,
        ends,
        contacts,
        snapshots,
        max_penetration,
        min_contact_force,
        energy_drift,
        projected_energy: final_state.projected_energy() - initial.projected_energy(),
        final_state,
    })
}
