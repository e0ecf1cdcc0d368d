//! Periodicity defect of a computed periodic orbit.

use super::{march, Grid, MarchOptions, Model, SpringUpdate, State, VerifyError};
use crate::fourier::{period_of_frequency, Basis};
use crate::system::BarSystem;

/// Options of [`periodicity_check`] and [`periodicity_of_state`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PeriodicityOptions {
    /// Time step `dt` (default `1/400`: 400 cells per unit length at `c = 1`). Any step up to
    /// the shortest travel time `l_b / c_b` of the bars ([`Grid::new`]).
    pub dt: f64,
    /// `false` (default): march with `dt` itself. `true`: prefer the nearest step between
    /// `dt / 2` and `2 dt` that gives every bar an integer number of cells
    /// ([`Grid::nearest`]; on such a commensurate grid the waves never need merging for want
    /// of a common lattice), and fall back to `dt` if there is none. The step used is
    /// [`PeriodicityReport::dt`].
    pub adjust_grid: bool,
    /// Update of ground springs (default [`SpringUpdate::Exact`]).
    pub spring: SpringUpdate,
    /// Number of periods to march (default 1).
    pub periods: usize,
}

impl Default for PeriodicityOptions {
    fn default() -> Self {
        Self {
            dt: 1.0 / 400.0,
            adjust_grid: false,
            spring: SpringUpdate::Exact,
            periods: 1,
        }
    }
}

/// Outcome of a periodicity check.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct PeriodicityReport {
    /// Period `T` of the orbit.
    pub period: f64,
    /// Time step used.
    pub dt: f64,
    /// `|X(kT) - X(0)| / |X(0)|` in the state norm of [`State::norm`]
    /// (`k` = [`PeriodicityOptions::periods`]).
    pub defect: f64,
    /// `|X(0)|`.
    pub initial_norm: f64,
    /// `max_x |u(x, kT) - u(x, 0)| / max_x |u(x, 0)|` over the nodes of every bar: the
    /// displacement-only measure (the paper's "maximum difference between the initial and
    /// final states"). It converges faster with the number of harmonics than
    /// [`PeriodicityReport::defect`], which sees the Gibbs error of the strain jumps.
    pub displacement_defect: f64,
    /// Energy at `t = 0` ([`State::energy`]).
    pub initial_energy: f64,
    /// `max_t |E(t) - E(0)| / E(0)` over the march.
    pub energy_drift: f64,
    /// Penetration of the initial state (the harmonic-balance solution's own, not the
    /// integrator's).
    pub initial_penetration: f64,
    /// Largest penetration over the march, initial state included.
    pub max_penetration: f64,
    /// Smallest contact force over the march (0 once a contact opens; never negative; `+inf`
    /// for a system without unilateral condition).
    pub min_contact_force: f64,
    /// Energy removed by merging short wave pieces over the march, relative to the initial
    /// energy ([`Trajectory::projected_energy`](super::Trajectory::projected_energy)
    /// divided by `E(0)`, absolute if `E(0) = 0`): 0 while no wave reaches its piece limit
    /// ([`Grid::max_pieces`]), which is the rule on a commensurate grid without many impacts.
    /// With lossless conditions, [`PeriodicityReport::energy_drift`] is at most this plus
    /// rounding.
    pub projected_energy: f64,
    /// Estimate of the error the merges add to [`PeriodicityReport::defect`]:
    /// `sqrt(2 removed energy) / |X(0)|`, the norm of everything they removed, as if the
    /// removed parts were mutually orthogonal (each is orthogonal to what its merge keeps;
    /// they are sub-cell fluctuations from different places and instants). 0 when nothing
    /// was merged. The defect says something about the checked orbit only where it is well
    /// above this.
    pub projection_error: f64,
}

/// Marches `initial` over `periods * period` and compares the final state with it.
///
/// # Errors
/// [`VerifyError::InvalidParameter`] for a period that is not positive and finite, zero
/// periods, a march shorter than one time step or an infinite march (`periods * period`
/// overflows); [`VerifyError::TooLarge`]
/// if the histories of the march do not fit in the memory budget (see [`march`]);
/// [`VerifyError::TooCostly`] if its work bound exceeds [`MAX_MARCH_WORK`](super::MAX_MARCH_WORK);
/// [`VerifyError::NonFiniteResult`] if a number of the report overflows.
pub fn periodicity_of_state(
    initial: &State,
    period: f64,
    options: &PeriodicityOptions,
) -> Result<PeriodicityReport, VerifyError> {
    if !(period.is_finite() && period > 0.0) {
        return Err(VerifyError::InvalidParameter {
            what: "period",
            value: period,
        });
    }
    if options.periods == 0 {
        return Err(VerifyError::InvalidParameter {
            what: "number of periods",
            value: 0.0,
        });
    }
    // A march shorter than one step compares the state with itself and samples no contact
    // force (the smallest force would stay `+inf`).
    let dt = initial.grid().dt();
    if period * (options.periods as f64) < dt {
        return Err(VerifyError::InvalidParameter {
            what: "period (shorter than the time step)",
            value: period,
        });
    }
    let trajectory = march(
        initial,
        period * options.periods as f64,
        &MarchOptions {
            spring: options.spring,
            snapshot_every: 0,
        },
    )?;
    let initial_norm = initial.norm();
    let difference = trajectory.final_state.distance(initial)?;
    let (before, after) = (initial.snapshot(), trajectory.final_state.snapshot());
    let mut largest: f64 = 0.0;
    let mut change: f64 = 0.0;
    for (b0, b1) in before.bars.iter().zip(&after.bars) {
        for (u0, u1) in b0.displacement.iter().zip(&b1.displacement) {
            largest = largest.max(u0.abs());
            change = change.max((u1 - u0).abs());
        }
    }
    let energy_scale = if trajectory.energy[0] > 0.0 {
        trajectory.energy[0]
    } else {
        1.0
    };
    let report = PeriodicityReport {
        period,
        dt: initial.grid().dt(),
        defect: if initial_norm > 0.0 {
            difference / initial_norm
        } else {
            difference
        },
        initial_norm,
        displacement_defect: if largest > 0.0 {
            change / largest
        } else {
            change
        },
        initial_energy: trajectory.energy[0],
        energy_drift: trajectory.energy_drift,
        initial_penetration: initial.penetration(),
        max_penetration: trajectory.max_penetration,
        min_contact_force: trajectory.min_contact_force,
        projected_energy: trajectory.projected_energy / energy_scale,
        projection_error: if initial_norm > 0.0 {
            (2.0 * trajectory.projected_energy).sqrt() / initial_norm
        } else {
            (2.0 * trajectory.projected_energy).sqrt()
        },
    };
    check_report(&report)?;
    Ok(report)
}

/// Every number of a report is finite (but the smallest contact force, `+inf` for a system
/// without unilateral condition, as in [`march`]), or [`VerifyError::NonFiniteResult`]
/// names the first that is not: the checks of the initial state let through finite values whose squares,
/// sums or ratios overflow (unknowns near `f64::MAX`, a gap of `1e300`).
fn check_report(r: &PeriodicityReport) -> Result<(), VerifyError> {
    let values = [
        ("period", r.period),
        ("time step", r.dt),
        ("defect", r.defect),
        ("initial norm", r.initial_norm),
        ("displacement defect", r.displacement_defect),
        ("initial energy", r.initial_energy),
        ("energy drift", r.energy_drift),
        ("initial penetration", r.initial_penetration),
        ("largest penetration", r.max_penetration),
        ("projected energy", r.projected_energy),
        ("projection error", r.projection_error),
    ];
    match values.into_iter().find(|(_, v)| !v.is_finite()) {
        Some((what, value)) => Err(VerifyError::NonFiniteResult { what, value }),
        None => Ok(()),
    }
}

/// The periodicity check of a harmonic-balance point: builds the fields of the solution `x`
/// (layout of [`NonsmoothSystem`](crate::system::NonsmoothSystem), basis `basis`) at `t = 0`
/// on the grid, marches one period `T = 2 pi / omega` exactly and reports the relative
/// defect, the penetration, the smallest contact force and the energy drift.
///
/// ```
/// use nonsmooth_modes::branches::{compute, BackboneOptions, Method, PeriodGrid, Request};
/// use nonsmooth_modes::reference::clamped_bar_with_obstacle;
/// use nonsmooth_modes::solve::Solver;
/// use nonsmooth_modes::verify::{periodicity_check, PeriodicityOptions};
///
/// let system = clamped_bar_with_obstacle(1e-3)?;
/// let grid = PeriodGrid { start: 3.9, end: 3.8, steps: 3 };
/// let request = Request {
///     solver: Some(Solver::default()),
///     ..Request::new(1).harmonics(10).method(Method::PeriodGrid(BackboneOptions::on_grid(grid, 1, 1)))
/// };
/// let point = compute(&system, &request)?.points.pop().unwrap();
/// let basis = request.settings.cosine_basis()?;
/// let check = PeriodicityOptions { dt: 0.01, ..Default::default() };
/// let report = periodicity_check(&system, &basis, &point.x, point.omega, &check).unwrap();
/// // Ten harmonics: the displacement comes back within a few percent; the energy-norm defect
/// // is larger (it sees the truncated strain jumps, ~ m^(-1/2)).
/// assert!(report.displacement_defect < 0.1);
/// assert!(report.defect < 0.5);
/// assert!(report.min_contact_force >= 0.0);
/// # Ok::<(), nonsmooth_modes::Error>(())
/// ```
///
/// Any travel times: on a grid that is not commensurate the march merges short pieces where
/// needed and reports what that costs in [`PeriodicityReport::projected_energy`] and
/// [`PeriodicityReport::projection_error`].
///
/// # Errors
/// A condition without a time-domain form ([`VerifyError::NoTimeDomainForm`]), a time step
/// longer than a bar's travel time
/// ([`VerifyError::NonMatchingGrid`]), a solution vector of the wrong length or with NaN, an
/// `omega` that is not positive and finite or is below
/// [`MIN_FREQUENCY`](crate::modal::MIN_FREQUENCY) ([`VerifyError`]);
/// [`VerifyError::TooLarge`] if the cells of the grid or the histories of the
/// `periods 2 pi / (omega dt)` steps do not fit in the memory budget
/// ([`MEMORY_BUDGET_BYTES`](crate::fourier::MEMORY_BUDGET_BYTES)); [`VerifyError::TooCostly`]
/// if the march's work bound exceeds [`MAX_MARCH_WORK`](super::MAX_MARCH_WORK).
pub fn periodicity_check<B: Basis>(
    system: &BarSystem,
    basis: &B,
    x: &[f64],
    omega: f64,
    options: &PeriodicityOptions,
) -> Result<PeriodicityReport, VerifyError> {
    let model = Model::from_system(system)?;
    let grid = if options.adjust_grid {
        Grid::nearest_or_new(&model, options.dt)?
    } else {
        Grid::new(&model, options.dt)?
    };
    let initial = State::from_harmonic_balance(system, basis, x, omega, 0.0, grid.dt())?;
    periodicity_of_state(&initial, period_of_frequency(omega), options)
}
