//! The common time step and the cells of each bar (`dx_b = c_b dt`).

use super::{Model, VerifyError};
use crate::bar::Bar;
use crate::fourier::check_memory;

/// Relative tolerance under which `l / (c dt)` counts as an integer.
const INTEGER_TOLERANCE: f64 = 1e-9;

/// Doubles held per cell of the grid by a periodicity check: the initial strain, velocity and
/// nodal displacement, the two waves (a start and a value per piece) and the snapshots of
/// the initial and final states (displacement, strain and velocity each), rounded up.
pub(super) const DOUBLES_PER_CELL: f64 = 16.0;

/// What a grid with too many cells is called in its error.
const GRID_CELLS: &str = "the cells of a time-domain grid (l / (c dt) per bar)";

/// Checks that `cells` cells in all fit in the memory budget.
fn check_cells(cells: f64) -> Result<(), VerifyError> {
    Ok(check_memory(GRID_CELLS, cells * DOUBLES_PER_CELL)?)
}

/// A common time step `dt` such that every bar `b` holds an integer number of cells
/// `N_b = l_b / (c_b dt)` of length `dx_b = c_b dt`: then a wave crosses exactly one cell per
/// step in every bar, and a wave leaving one end reaches the other end after exactly `N_b`
/// steps, so the waves of all bars stay on one lattice of instants (formulation §10).
#[derive(Debug, Clone, PartialEq)]
pub struct Grid {
    dt: f64,
    cells: Vec<usize>,
}

fn check_dt(dt: f64) -> Result<f64, VerifyError> {
    if dt.is_finite() && dt > 0.0 {
        Ok(dt)
    } else {
        Err(VerifyError::InvalidTimeStep { dt })
    }
}

/// The travel time `l / c` of a wave across `bar`.
fn travel_time(bar: &Bar) -> f64 {
    bar.length() / bar.wave_speed()
}

/// `l / (c dt)` rounded, if it is an integer within tolerance.
fn cells_of(travel_time: f64, dt: f64) -> Result<usize, f64> {
    let ratio = travel_time / dt;
    let n = ratio.round();
    if n >= 1.0 && (ratio - n).abs() <= INTEGER_TOLERANCE * ratio.max(1.0) && n < 1e12 {
        Ok(n as usize)
    } else {
        Err(ratio)
    }
}

impl Grid {
    /// The grid of step `dt`.
    ///
    /// # Errors
    /// [`VerifyError::InvalidTimeStep`] if `dt` is not positive and finite;
    /// [`VerifyError::NonMatchingGrid`] naming the first bar whose `l / (c dt)` is not an
    /// integer (within a relative `1e-9`) or is below 1; [`VerifyError::TooLarge`] if the
    /// cells of all bars do not fit in the memory budget
    /// ([`MEMORY_BUDGET_BYTES`](crate::fourier::MEMORY_BUDGET_BYTES), at 16 doubles per
    /// cell: the initial state, its waves and two snapshots).
    pub fn new(model: &Model, dt: f64) -> Result<Self, VerifyError> {
        let dt = check_dt(dt)?;
        let cells: Vec<usize> = model
            .bars()
            .iter()
            .enumerate()
            .map(|(b, bar)| {
                let travel_time = travel_time(bar);
                cells_of(travel_time, dt).map_err(|cells| VerifyError::NonMatchingGrid {
                    bar: b,
                    travel_time,
                    dt,
                    cells,
                })
            })
            .collect::<Result<_, _>>()?;
        check_cells(cells.iter().map(|&n| n as f64).sum())?;
        Ok(Self { dt, cells })
    }

    /// The admissible grid whose step is nearest to `dt`: candidates are `l_1 / (c_1 n)` for
    /// integers `n` with a step between `dt / 2` and `2 dt`; the nearest one that gives every
    /// bar an integer number of cells is kept. [`Grid::dt`] tells which step was chosen.
    ///
    /// # Errors
    /// [`VerifyError::InvalidTimeStep`] for a bad `dt`; [`VerifyError::TooLarge`] if the
    /// cells at step `dt` do not fit in the memory budget (as for [`Grid::new`]);
    /// [`VerifyError::NoAdmissibleGrid`] if the bars' travel times are not commensurate
    /// enough for any candidate.
    pub fn nearest(model: &Model, dt: f64) -> Result<Self, VerifyError> {
        let dt = check_dt(dt)?;
        // The cells at `dt` bound the candidates' counts (a tiny `dt` overflows them).
        check_cells(model.bars().iter().map(|bar| travel_time(bar) / dt).sum())?;
        let tau = travel_time(&model.bars()[0]);
        let low = (tau / (2.0 * dt)).floor().max(1.0) as usize;
        let high = ((2.0 * tau / dt).ceil() as usize).max(low);
        let mut best: Option<Grid> = None;
        for n in low..=high.min(low.saturating_add(1_000_000)) {
            let candidate = tau / n as f64;
            if let Ok(grid) = Self::new(model, candidate) {
                let better = best
                    .as_ref()
                    .is_none_or(|b| (grid.dt - dt).abs() < (b.dt - dt).abs());
                if better {
                    best = Some(grid);
                }
            }
        }
        best.ok_or(VerifyError::NoAdmissibleGrid {
            low: tau / high as f64,
            high: tau / low as f64,
        })
    }

    /// The time step `dt`.
    pub fn dt(&self) -> f64 {
        self.dt
    }

    /// Number of cells `N_b` of bar `bar`.
    ///
    /// # Panics
    /// If `bar` is out of range.
    pub fn cells(&self, bar: usize) -> usize {
        self.cells[bar]
    }

    /// Number of bars.
    pub fn bars(&self) -> usize {
        self.cells.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bar::Bar;
    use crate::reference::two_bars_in_contact;

    #[test]
    fn integer_cells_or_a_typed_error() {
        let two = Model::from_system(
            &two_bars_in_contact(Bar::new(0.95, 1.0, 1.0).unwrap(), 0.1).unwrap(),
        )
        .unwrap();
        let g = Grid::new(&two, 0.01).unwrap();
        assert_eq!((g.cells(0), g.cells(1)), (100, 95));
        assert!(matches!(
            Grid::new(&two, 0.03),
            Err(VerifyError::NonMatchingGrid { bar: 0, .. })
        ));
        assert!(matches!(
            Grid::new(&two, 0.0),
            Err(VerifyError::InvalidTimeStep { .. })
        ));
        assert!(matches!(
            Grid::new(&two, -1.0),
            Err(VerifyError::InvalidTimeStep { .. })
        ));
        assert!(matches!(
            Grid::new(&two, f64::NAN),
            Err(VerifyError::InvalidTimeStep { .. })
        ));
        let near = Grid::nearest(&two, 0.03).unwrap();
        assert!((near.dt() - 0.025).abs() < 1e-12, "{}", near.dt());
        assert_eq!((near.cells(0), near.cells(1)), (40, 38));
        let irrational = Model::from_system(
            &two_bars_in_contact(Bar::new(std::f64::consts::SQRT_2, 1.0, 1.0).unwrap(), 0.1)
                .unwrap(),
        )
        .unwrap();
        assert!(matches!(
            Grid::nearest(&irrational, 0.01),
            Err(VerifyError::NoAdmissibleGrid { .. })
        ));
    }

    #[test]
    fn grids_beyond_the_memory_budget_are_typed_errors() {
        let one = Model::from_system(&crate::reference::clamped_bar_with_obstacle(1e-3).unwrap())
            .unwrap();
        // 1e11 cells: an integer count, but 12.8 TB of state.
        for dt in [1e-11, 1e-300, 5e-324] {
            assert!(
                matches!(Grid::nearest(&one, dt), Err(VerifyError::TooLarge(_))),
                "nearest, dt = {dt}"
            );
        }
        match Grid::new(&one, 1e-11) {
            Err(VerifyError::TooLarge(e)) => {
                assert_eq!(e.requested_bytes, 1e11 * DOUBLES_PER_CELL * 8.0);
            }
            other => panic!("expected TooLarge, got {other:?}"),
        }
        // A million cells is fine.
        assert_eq!(Grid::new(&one, 1e-6).unwrap().cells(0), 1_000_000);
    }
}
