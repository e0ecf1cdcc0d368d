//! Initial state of the exact first nonsmooth mode of the clamped bar (formulation §9), for
//! either sign of the gap.

use super::{BarCells, Grid, Model, State, VerifyError};

/// The state at `t = 0` (middle of the contact phase) of the exact first mode of the unit bar
/// clamped at `x = 0` with an obstacle at gap `g0` at `x = 1`, on the grid of step `dt`,
/// together with its model ([`Model::clamped_bar_with_obstacle`], which allows `g0 < 0`).
///
/// With `a = g0 / (2 (T - 3))` and `t_c = 4 - T`, the end moves as
/// `v(t) = g0 - 2a max(0, |t| - t_c/2)` and the contact force is `g0/(T-3)` during contact.
/// Writing `u(x, t) = f(t + x) - f(t - x)` (clamped at 0) with `u(1, t) = v(t)` and
/// `u_x(1, t) = -lambda(t)` gives `f'(s) = -(v'(s + 1) + lambda(s + 1)) / 2`, hence at `t = 0`
/// `u_t(x, 0) = f'(x) - f'(-x) = 0` (the motion is even) and
/// `u_x(x, 0) = 2 f'(x) = 2a` for `x < T/2 - 1`, `-2a` beyond, so `u(1, 0) = 2a (T - 3) = g0`.
/// The same field holds for `g0 > 0, T in (3, 4)` (the family of the paper) and for
/// `g0 < 0, T in (2, 3)`: a bar pressed into the obstacle by `|g0|`, compressed by
/// `2a = g0/(T-3) > 0` at rest in the middle of contact, which leaves the obstacle for a free
/// flight of `2T - 4` and comes back. The strain jump at `x = T/2 - 1` is averaged exactly
/// over its cell.
///
/// # Errors
/// [`VerifyError::InvalidParameter`] unless `g0 > 0` and `3 < T < 4`, or `g0 < 0` and
/// `2 < T < 3`; the errors of [`Grid::new`].
pub fn clamped_first_mode(gap: f64, period: f64, dt: f64) -> Result<State, VerifyError> {
    let admissible =
        (gap > 0.0 && period > 3.0 && period < 4.0) || (gap < 0.0 && period > 2.0 && period < 3.0);
    if !gap.is_finite() || gap == 0.0 {
        return Err(VerifyError::InvalidParameter {
            what: "gap of the exact clamped mode",
            value: gap,
        });
    }
    if !admissible {
        return Err(VerifyError::InvalidParameter {
            what: "period of the exact clamped mode (3 < T < 4 for g0 > 0, 2 < T < 3 for g0 < 0)",
            value: period,
        });
    }
    let model = Model::clamped_bar_with_obstacle(gap)?;
    let grid = Grid::new(&model, dt)?;
    let n = grid.cells(0);
    let dx = 1.0 / n as f64;
    let a = gap / (2.0 * (period - 3.0));
    let jump = 0.5 * period - 1.0;
    let strain = (0..n)
        .map(|i| {
            let (x0, x1) = (i as f64 * dx, (i + 1) as f64 * dx);
            let before = (jump.min(x1) - x0).clamp(0.0, dx);
            2.0 * a * (2.0 * before - dx) / dx
        })
        .collect();
    State::from_cells(
        &model,
        &grid,
        &[BarCells {
            left_displacement: 0.0,
            strain,
            velocity: vec![0.0; n],
        }],
    )
}
