//! The one grid of a branch, on which every requested period is a whole number of steps.

use crate::bar::shortest_travel_time;
use crate::stability::coordinates::Coordinates;
use crate::stability::{StabilityError, MAX_DIMENSION, MAX_MARCH_STEPS};
use crate::verify::{Grid, Model};

/// A period more than this relative amount off a whole number of steps is rounded.
const WHOLE: f64 = 1e-9;

/// The grid of a branch and its periods, each a whole number of its steps.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct BranchGrid {
    pub grid: Grid,
    /// The requested periods rounded to whole steps.
    pub periods: Vec<f64>,
}

/// The grid of `k` cells per shortest travel time (commensurate where one is near) and the
/// steps of `periods` on it: whether they are distinct and their largest relative rounding.
fn candidate(
    model: &Model,
    periods: &[f64],
    k: usize,
) -> Result<(Grid, Vec<f64>, bool, f64), StabilityError> {
    let grid = Grid::nearest_or_new(model, shortest_travel_time(model.bars()) / k as f64)?;
    let steps: Vec<f64> = periods
        .iter()
        .map(|t| (t / grid.dt()).round().max(1.0))
        .collect();
    let distinct = steps.windows(2).all(|w| w[0] != w[1]);
    let miss = periods
        .iter()
        .zip(&steps)
        .map(|(t, n)| (t - n * grid.dt()).abs() / t)
        .fold(0.0, f64::max);
    let rounded = steps.iter().map(|n| n * grid.dt()).collect();
    Ok((grid, rounded, distinct, miss))
}

/// The rows of the monodromy on `grid` and the time steps of marching one point's matrices
/// over `longest` with `passes` monodromies: what the limits of
/// [`stability`](crate::stability) bound.
pub(crate) fn cost(model: &Model, grid: &Grid, longest: f64, passes: usize) -> (usize, f64) {
    let n = Coordinates::new(model, grid).len();
    let steps = 2.0 * n as f64 * (longest / grid.dt()).ceil() * (2.0 + passes as f64);
    (n, steps)
}

/// Whether a cost is within [`MAX_DIMENSION`] and [`MAX_MARCH_STEPS`].
pub(crate) fn affordable((n, steps): (usize, f64)) -> bool {
    n <= MAX_DIMENSION && steps <= MAX_MARCH_STEPS
}

/// The grid of a branch over `periods`, with at least `cells` cells per shortest travel time.
/// Only grids within `fits` are tried beyond the first (a grid of more cells that makes the
/// periods whole is no use if its matrices are over the limits).
///
/// One grid for the whole branch keeps the coordinates, so that the monodromy of one point
/// is the corrector's matrix at the next; and a period of a whole number of steps keeps the
/// map sharp (a final fractional step projects the waves onto the cells and blurs the
/// multipliers). The cell count is the smallest in `[cells, 2 cells]` that makes every period
/// whole and distinct; otherwise the one in `[cells, 1.25 cells]` with distinct periods and
/// the smallest rounding; otherwise the smallest up to `2 cells` with distinct periods;
/// otherwise the one in `[cells, 1.25 cells]` with the smallest rounding.
pub(crate) fn branch_grid(
    model: &Model,
    periods: &[f64],
    cells: f64,
    fits: &dyn Fn(&Grid) -> bool,
) -> Result<BranchGrid, StabilityError> {
    let first = cells.ceil().max(1.0) as usize;
    let near = (1.25 * first as f64).ceil() as usize;
    let mut near_best: Option<(Grid, Vec<f64>, bool, f64)> = None;
    let mut far_distinct = None;
    for k in first..=2 * first {
        let c = candidate(model, periods, k)?;
        if k > first && !fits(&c.0) {
            continue;
        }
        if c.2 && c.3 <= WHOLE {
            near_best = Some(c);
            break;
        }
        if k <= near {
            let better = near_best
                .as_ref()
                .is_none_or(|b| (c.2 && !b.2) || (c.2 == b.2 && c.3 < b.3));
            if better {
                near_best = Some(c);
            }
        } else if c.2 && far_distinct.is_none() {
            far_distinct = Some(c);
        }
    }
    let chosen = match near_best {
        Some(b) if b.2 => b,
        other => match far_distinct.or(other) {
            Some(c) => c,
            None => candidate(model, periods, first)?,
        },
    };
    Ok(BranchGrid {
        grid: chosen.0,
        periods: chosen.1,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The clamped bar's grid `3.95 -> 3.05` in 181 periods is whole at 200 cells; a grid of
    /// half that step needs 400.
    #[test]
    fn whole_periods_are_found() {
        let model = Model::clamped_bar_with_obstacle(1e-3).unwrap();
        let periods: Vec<f64> = (0..181).map(|j| 3.95 - 0.005 * j as f64).collect();
        let b = branch_grid(&model, &periods, 200.0, &|_| true).unwrap();
        assert_eq!(b.grid.cells(0), 200);
        assert!(b
            .periods
            .iter()
            .zip(&periods)
            .all(|(a, t)| (a - t).abs() < 1e-12));
        let half: Vec<f64> = (0..181).map(|j| 1.975 - 0.0025 * j as f64).collect();
        let b = branch_grid(&model, &half, 200.0, &|_| true).unwrap();
        assert_eq!(b.grid.cells(0), 400);
    }
}
