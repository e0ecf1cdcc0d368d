//! The common time step, the travel time of each bar in steps and its cells.

use super::wave::Resolution;
use super::{Model, VerifyError};
use crate::fourier::check_memory;

/// Relative tolerance under which `l / (c dt)` counts as an integer.
const INTEGER_TOLERANCE: f64 = 1e-9;

/// Pieces per cell a wave may hold before its short pieces are merged
/// ([`Grid::max_pieces`]): a wave of `N` cells merges pieces shorter than a quarter of a cell
/// once it holds `4 N` pieces, and so never holds more than `8 N + 2`.
pub const PIECES_PER_CELL: usize = 4;

/// Piece operations a [`march`](super::march) may spend before it merges pieces below the
/// default resolution of [`PIECES_PER_CELL`] pieces per cell: a march is exact (no merge)
/// unless its waves would otherwise cost more, and in all it does at most about
/// `2 MARCH_WORK + 32 bars steps` piece operations (a fraction of a second for `MARCH_WORK`,
/// then a constant time per step). The waves then hold at most `MARCH_WORK` pieces beyond the
/// default resolution, 256 MiB at 16 bytes a piece.
pub const MARCH_WORK: usize = 1 << 24;

/// The most wave-piece operations a [`march`](super::march) may take by its bound
/// ([`Grid::march_work`]): longer marches are refused with
/// [`VerifyError::TooCostly`](super::VerifyError::TooCostly). That is about 5.6e6 steps of one
/// bar or 2.8e6 of two (seconds, `docs/reliability.md`); the memory budget of the histories
/// alone would allow ten times more.
pub const MAX_MARCH_WORK: usize = 1 << 27;

/// Doubles held per cell of the grid by a periodicity check: the initial strain, velocity and
/// nodal displacement, the snapshots of the initial and final states (displacement, strain
/// and velocity each), and the two waves (a start and a value per piece) at their largest,
/// `2 PIECES_PER_CELL` pieces per cell each.
pub(super) const DOUBLES_PER_CELL: f64 = 9.0 + 8.0 * PIECES_PER_CELL as f64;

/// What a grid with too many cells is called in its error.
const GRID_CELLS: &str = "the cells of a time-domain grid (l / (c dt) per bar)";

/// Checks that `cells` cells in all fit in the memory budget.
fn check_cells(cells: f64) -> Result<(), VerifyError> {
    Ok(check_memory(GRID_CELLS, cells * DOUBLES_PER_CELL)?)
}

/// A common time step `dt`, and for each bar `b` its travel time in steps
/// `nu_b = l_b / (c_b dt) >= 1` and its `N_b = ceil(nu_b)` cells of length `l_b / N_b`
/// (formulation §10, and the [module docs](super) for any travel times).
///
/// The grid is **commensurate** when every `nu_b` is an integer (within a relative `1e-9`;
/// it is then taken as exactly that integer): a cell is then crossed in exactly one step and
/// the waves of all bars stay on one lattice of instants. Otherwise a wave still crosses bar
/// `b` in exactly `nu_b` steps, but its breakpoints drift off the lattice, and the march keeps
/// the number of pieces bounded by merging short ones (an `L2` projection whose error is
/// reported).
#[derive(Debug, Clone, PartialEq)]
pub struct Grid {
    dt: f64,
    cells: Vec<usize>,
    steps: Vec<f64>,
}

fn check_dt(dt: f64) -> Result<f64, VerifyError> {
    if dt.is_finite() && dt > 0.0 {
        Ok(dt)
    } else {
        Err(VerifyError::InvalidTimeStep { dt })
    }
}

/// `l / (c dt)`, snapped to the nearest integer when within tolerance of it.
fn steps_of(travel_time: f64, dt: f64) -> f64 {
    let ratio = travel_time / dt;
    let n = ratio.round();
    if (ratio - n).abs() <= INTEGER_TOLERANCE * ratio.max(1.0) {
        n
    } else {
        ratio
    }
}

impl Grid {
    /// The grid of step `dt`: any step up to the shortest travel time `l_b / c_b`.
    ///
    /// # Errors
    /// [`VerifyError::InvalidTimeStep`] if `dt` is not positive and finite;
    /// [`VerifyError::NonMatchingGrid`] naming the first bar whose travel time is shorter than
    /// one step (`l / (c dt) < 1`: a wave would cross it within a step, before the other end
    /// has answered); [`VerifyError::TooLarge`] if the cells of all bars do not fit in the
    /// memory budget ([`MEMORY_BUDGET_BYTES`](crate::fourier::MEMORY_BUDGET_BYTES), at
    /// `9 + 8 PIECES_PER_CELL` doubles per cell: the initial state, two snapshots and the
    /// waves at their largest).
    pub fn new(model: &Model, dt: f64) -> Result<Self, VerifyError> {
        let dt = check_dt(dt)?;
        let mut steps = Vec::with_capacity(model.bars().len());
        for (b, bar) in model.bars().iter().enumerate() {
            let travel_time = bar.travel_time();
            let nu = steps_of(travel_time, dt);
            if nu < 1.0 {
                return Err(VerifyError::NonMatchingGrid {
                    bar: b,
                    travel_time,
                    dt,
                    cells: travel_time / dt,
                });
            }
            steps.push(nu);
        }
        check_cells(steps.iter().map(|nu| nu.ceil()).sum())?;
        let cells = steps.iter().map(|nu| nu.ceil() as usize).collect();
        Ok(Self { dt, cells, steps })
    }

    /// The commensurate grid whose step is nearest to `dt`: candidates are `l_1 / (c_1 n)`
    /// for integers `n` with a step between `dt / 2` and `2 dt`; the nearest one that gives
    /// every bar an integer number of cells is kept. [`Grid::dt`] tells which step was chosen.
    /// (Any step gives a valid grid, [`Grid::new`]; a commensurate one transports the waves
    /// without ever merging pieces for want of a lattice.)
    ///
    /// # Errors
    /// [`VerifyError::InvalidTimeStep`] for a bad `dt`; [`VerifyError::TooLarge`] if the
    /// cells at step `dt` do not fit in the memory budget (as for [`Grid::new`]);
    /// [`VerifyError::NoAdmissibleGrid`] if the bars' travel times are not commensurate
    /// enough for any candidate.
    pub fn nearest(model: &Model, dt: f64) -> Result<Self, VerifyError> {
        let dt = check_dt(dt)?;
        // The cells at `dt` bound the candidates' counts (a tiny `dt` overflows them).
        check_cells(model.bars().iter().map(|bar| bar.travel_time() / dt).sum())?;
        let tau = model.bars()[0].travel_time();
        let low = (tau / (2.0 * dt)).floor().max(1.0) as usize;
        let high = ((2.0 * tau / dt).ceil() as usize).max(low);
        let mut best: Option<Grid> = None;
        for n in low..=high.min(low.saturating_add(1_000_000)) {
            let candidate = tau / n as f64;
            if let Ok(grid) = Self::new(model, candidate) {
                let better = best
                    .as_ref()
                    .is_none_or(|b| (grid.dt - dt).abs() < (b.dt - dt).abs());
                if grid.is_commensurate() && better {
                    best = Some(grid);
                }
            }
        }
        best.ok_or(VerifyError::NoAdmissibleGrid {
            low: tau / high as f64,
            high: tau / low as f64,
        })
    }

    /// [`Grid::nearest`] where some step near `dt` is commensurate, [`Grid::new`] at `dt`
    /// itself where none is.
    ///
    /// # Errors
    /// Those of [`Grid::new`].
    pub fn nearest_or_new(model: &Model, dt: f64) -> Result<Self, VerifyError> {
        match Self::nearest(model, dt) {
            Err(VerifyError::NoAdmissibleGrid { .. }) => Self::new(model, dt),
            other => other,
        }
    }

    /// The time step `dt`.
    pub fn dt(&self) -> f64 {
        self.dt
    }

    /// Number of cells `N_b = ceil(nu_b)` of bar `bar` (`nu_b` itself on a commensurate
    /// grid).
    ///
    /// # Panics
    /// If `bar` is out of range.
    pub fn cells(&self, bar: usize) -> usize {
        self.cells[bar]
    }

    /// Travel time of bar `bar` in steps, `nu_b = l_b / (c_b dt) >= 1` (exactly
    /// [`Grid::cells`] on a commensurate grid).
    ///
    /// # Panics
    /// If `bar` is out of range.
    pub fn travel_steps(&self, bar: usize) -> f64 {
        self.steps[bar]
    }

    /// Duration of one cell of bar `bar` in steps, `nu_b / N_b` (1 on a commensurate grid,
    /// between 1/2 and 1 otherwise): the time a wave takes to cross it.
    ///
    /// # Panics
    /// If `bar` is out of range.
    pub fn cell_steps(&self, bar: usize) -> f64 {
        self.steps[bar] / self.cells[bar] as f64
    }

    /// Whether every bar holds an integer number of steps (see [`Grid`]).
    pub fn is_commensurate(&self) -> bool {
        self.steps
            .iter()
            .zip(&self.cells)
            .all(|(&nu, &n)| nu == n as f64)
    }

    /// The most pieces a wave of bar `bar` ever holds, `2 PIECES_PER_CELL N_b + 2` (see
    /// [`PIECES_PER_CELL`]): each step of a march costs a bounded amount of work because of
    /// this bound, whatever the travel times and however many impacts.
    ///
    /// # Panics
    /// If `bar` is out of range.
    pub fn max_pieces(&self, bar: usize) -> usize {
        (2 * PIECES_PER_CELL)
            .saturating_mul(self.cells[bar])
            .saturating_add(2)
    }

    /// How the waves of bar `bar` are kept bounded by default (an [`Integrator`] stepping on
    /// its own): once a wave holds `PIECES_PER_CELL N_b` pieces, parts shorter than
    /// `1 / PIECES_PER_CELL` of a cell are merged.
    ///
    /// [`Integrator`]: super::Integrator
    pub(super) fn resolution(&self, bar: usize) -> Resolution {
        Resolution {
            cap: PIECES_PER_CELL.saturating_mul(self.cells[bar]),
            min_piece: self.cell_steps(bar) / PIECES_PER_CELL as f64,
        }
    }

    /// The resolution of bar `bar` for a march of `steps` steps: the default one, with the
    /// cap raised to this bar's share of [`MARCH_WORK`], `MARCH_WORK / (2 bars)
    /// min(1, nu_b / steps)` pieces per wave, when that is more. A wave of `cap` pieces is
    /// consumed once every `nu_b` steps, so the merges start only where the march would
    /// otherwise do more than about `MARCH_WORK` piece operations in all.
    pub(super) fn march_resolution(&self, bar: usize, steps: f64) -> Resolution {
        let base = self.resolution(bar);
        let waves = 2.0 * self.bars() as f64;
        let share = MARCH_WORK as f64 / waves * (self.steps[bar] / steps.max(1.0)).min(1.0);
        Resolution {
            cap: base.cap.max(share as usize),
            ..base
        }
    }

    /// The bound on the work of a [`march`](super::march) of `steps` steps, in pieces taken
    /// at the ends: `(per step, in all)` with
    /// `per step = sum_waves ((2 PIECES_PER_CELL N_b + 2) / nu_b + 1)` and
    /// `in all = 2 MARCH_WORK + sum_waves ((steps / nu_b + 1) (2 PIECES_PER_CELL N_b + 2) + steps)`.
    ///
    /// A wave holds exactly the pieces that reach its end within the next `nu_b` steps, at
    /// most `cap + 2 PIECES_PER_CELL N_b + 2` ([`Grid::max_pieces`] plus the share of
    /// [`MARCH_WORK`] its cap may add), so every `nu_b` steps it gives up at most that many,
    /// plus one piece split per step; the caps of a march add at most `2 MARCH_WORK` in all.
    pub fn march_work(&self, steps: f64) -> (f64, f64) {
        let mut per_step = 0.0;
        let mut work = 2.0 * MARCH_WORK as f64;
        for b in 0..self.bars() {
            let (pieces, nu) = (self.max_pieces(b) as f64, self.steps[b]);
            per_step += 2.0 * (pieces / nu + 1.0);
            work += 2.0 * ((steps / nu + 1.0) * pieces + steps);
        }
        (per_step, work)
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
    fn any_step_up_to_the_shortest_travel_time() {
        let two = Model::from_system(
            &two_bars_in_contact(Bar::new(0.95, 1.0, 1.0).unwrap(), 0.1).unwrap(),
        )
        .unwrap();
        let g = Grid::new(&two, 0.01).unwrap();
        assert_eq!((g.cells(0), g.cells(1)), (100, 95));
        assert_eq!((g.travel_steps(0), g.travel_steps(1)), (100.0, 95.0));
        assert_eq!((g.cell_steps(0), g.cell_steps(1)), (1.0, 1.0));
        assert!(g.is_commensurate());
        // 0.95 / 0.03 = 31.67 steps: 32 cells of 0.99 steps each.
        let g = Grid::new(&two, 0.03).unwrap();
        assert!(!g.is_commensurate());
        assert_eq!((g.cells(0), g.cells(1)), (34, 32));
        assert!((g.travel_steps(1) - 0.95 / 0.03).abs() < 1e-12);
        assert!((g.cell_steps(1) * 32.0 - g.travel_steps(1)).abs() < 1e-12);
        assert_eq!(g.max_pieces(1), 8 * 32 + 2);
        // One step per crossing of the shorter bar is the longest step.
        assert!(Grid::new(&two, 0.95).unwrap().cell_steps(1) == 1.0);
        assert!(matches!(
            Grid::new(&two, 0.96),
            Err(VerifyError::NonMatchingGrid { bar: 1, .. })
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
        assert!(near.is_commensurate());
        let irrational = Model::from_system(
            &two_bars_in_contact(Bar::new(std::f64::consts::SQRT_2, 1.0, 1.0).unwrap(), 0.1)
                .unwrap(),
        )
        .unwrap();
        assert!(matches!(
            Grid::nearest(&irrational, 0.01),
            Err(VerifyError::NoAdmissibleGrid { .. })
        ));
        let g = Grid::new(&irrational, 0.01).unwrap();
        assert_eq!((g.cells(0), g.cells(1)), (100, 142));
        assert!(!g.is_commensurate());
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
