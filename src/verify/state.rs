//! The state of the integrator: the two characteristic waves of every bar and its end
//! displacements.

use super::wave::{distance_squared, Resolution, Wave};
use super::{Condition, Grid, Model, VerifyError};
use crate::bar::{End, EndRef};
use crate::check::check_frequency;
use crate::fourier::Basis;
use crate::modal::FieldEvaluator;
use crate::system::BarSystem;
use std::cell::RefCell;

/// Three-point Gauss–Legendre rule on `[0, 1]`: nodes and weights.
const GAUSS3: [(f64, f64); 3] = [
    (0.112_701_665_379_258_31, 5.0 / 18.0),
    (0.5, 8.0 / 18.0),
    (0.887_298_334_620_741_7, 5.0 / 18.0),
];

/// Initial data of one bar on its grid of `N` cells of length `dx = l / N` (`c dt` on a
/// commensurate grid).
#[derive(Debug, Clone, PartialEq)]
pub struct BarCells {
    /// Displacement `u(0)` of the left end.
    pub left_displacement: f64,
    /// Mean strain `u_x` of each cell, `N` values from `x = 0` to `x = l`.
    pub strain: Vec<f64>,
    /// Mean velocity `u_t` of each cell, `N` values.
    pub velocity: Vec<f64>,
}

/// Fields of one bar at one instant, on its grid.
#[derive(Debug, Clone, PartialEq)]
pub struct BarSnapshot {
    /// Displacement at the `N + 1` nodes `x_i = i dx` (`dx = l / N`).
    pub displacement: Vec<f64>,
    /// Mean strain of each of the `N` cells.
    pub strain: Vec<f64>,
    /// Mean velocity of each of the `N` cells.
    pub velocity: Vec<f64>,
}

/// Fields of every bar at time `time`.
#[derive(Debug, Clone, PartialEq)]
pub struct Snapshot {
    /// Time since the start of the march.
    pub time: f64,
    /// One entry per bar.
    pub bars: Vec<BarSnapshot>,
}

/// The waves of one bar: `right` travels to `x = l`, `left` to `x = 0`; both are functions
/// of their arrival clock, defined on `[clock, clock + nu)` (`nu = l / (c dt)`).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct BarWaves {
    pub right: Wave,
    pub left: Wave,
    /// Displacements `[u(0), u(l)]`.
    pub ends: [f64; 2],
}

/// State of the integrator at one instant.
///
/// Each bar holds its right-going wave `R = u_t - c u_x` and left-going wave
/// `L = u_t + c u_x` as piecewise-constant functions of the clock `s = t / dt` at which each
/// part reaches the end it travels to. A wave crosses the bar in `nu = l / (c dt)` steps
/// ([`Grid::travel_steps`]) and a cell in `h = nu / N` steps ([`Grid::cell_steps`], 1 on a
/// commensurate grid): at clock `S` the cell `i` (`x in [i dx, (i+1) dx]`, `dx = l / N`)
/// holds `R` arriving in `[S + nu - (i + 1) h, S + nu - i h)` and `L` arriving in
/// `[S + i h, S + (i + 1) h)`. A step is then only bookkeeping at the ends; the pieces
/// themselves never change, except where short pieces are merged to keep their number
/// bounded ([`State::projected_energy`]). Pieces start as cells and gain breakpoints inside
/// cells at impact instants and, on a grid that is not commensurate, wherever the waves of
/// bars of different travel times meet. The end displacements are carried along (the field
/// only knows `u_x` and `u_t`).
#[derive(Debug, Clone, PartialEq)]
pub struct State {
    pub(crate) model: Model,
    pub(crate) grid: Grid,
    pub(crate) clock: f64,
    pub(crate) bars: Vec<BarWaves>,
}

fn finite(what: &'static str, bar: usize, index: usize, value: f64) -> Result<f64, VerifyError> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(VerifyError::NonFinite {
            what,
            bar,
            index,
            value,
        })
    }
}

/// [`VerifyError::InvalidParameter`] unless `omega` is a fundamental frequency the harmonic
/// balance accepts (finite, positive, not so small that its period overflows).
pub(crate) fn check_fundamental_frequency(omega: f64) -> Result<(), VerifyError> {
    check_frequency(omega)
        .map(|_| ())
        .map_err(|_| VerifyError::InvalidParameter {
            what: "fundamental frequency omega",
            value: omega,
        })
}

impl State {
    /// The state with the given cell means of strain and velocity (the most general input:
    /// the march is exact for it).
    ///
    /// # Errors
    /// [`VerifyError::BarCount`], [`VerifyError::Length`] for inputs of the wrong shape,
    /// [`VerifyError::NonFinite`] for NaN or infinite values, [`VerifyError::MismatchedStates`]
    /// if `grid` was not built for `model`.
    pub fn from_cells(model: &Model, grid: &Grid, cells: &[BarCells]) -> Result<Self, VerifyError> {
        if Grid::new(model, grid.dt())? != *grid {
            return Err(VerifyError::MismatchedStates);
        }
        if cells.len() != model.bars().len() {
            return Err(VerifyError::BarCount {
                got: cells.len(),
                expected: model.bars().len(),
            });
        }
        let mut bars = Vec::with_capacity(cells.len());
        for (b, (data, bar)) in cells.iter().zip(model.bars()).enumerate() {
            let n = grid.cells(b);
            for (what, v) in [("strain", &data.strain), ("velocity", &data.velocity)] {
                if v.len() != n {
                    return Err(VerifyError::Length {
                        what,
                        bar: b,
                        got: v.len(),
                        expected: n,
                    });
                }
            }
            let u0 = finite("left displacement", b, 0, data.left_displacement)?;
            let c = bar.wave_speed();
            let (nu, h) = (grid.travel_steps(b), grid.cell_steps(b));
            let dx = c * grid.dt() * h;
            let resolution = grid.resolution(b);
            let mut right = Wave::with_resolution(0.0, resolution);
            for i in (0..n).rev() {
                let e = finite("strain", b, i, data.strain[i])?;
                let v = finite("velocity", b, i, data.velocity[i])?;
                // The last cell ends exactly at `nu`.
                let until = if i == 0 { nu } else { nu - i as f64 * h };
                right.push_until(until, v - c * e);
            }
            let mut left = Wave::with_resolution(0.0, resolution);
            for i in 0..n {
                let until = if i + 1 == n { nu } else { (i + 1) as f64 * h };
                left.push_until(until, data.velocity[i] + c * data.strain[i]);
            }
            let ul = u0 + dx * data.strain.iter().sum::<f64>();
            bars.push(BarWaves {
                right,
                left,
                ends: [u0, ul],
            });
        }
        Ok(Self {
            model: model.clone(),
            grid: grid.clone(),
            clock: 0.0,
            bars,
        })
    }

    /// The state of the fields `field(bar, x) = (u, u_t)`: strain means from the nodal
    /// displacements (exact), velocity means by 3-point Gauss quadrature in each of the `N`
    /// cells of length `l / N`.
    ///
    /// # Errors
    /// As [`State::from_cells`].
    pub fn from_fields(
        model: &Model,
        grid: &Grid,
        field: impl Fn(usize, f64) -> (f64, f64),
    ) -> Result<Self, VerifyError> {
        if Grid::new(model, grid.dt())? != *grid {
            return Err(VerifyError::MismatchedStates);
        }
        let cells: Vec<BarCells> = model
            .bars()
            .iter()
            .enumerate()
            .map(|(b, bar)| {
                let n = grid.cells(b);
                let dx = bar.length() / n as f64;
                let nodes: Vec<f64> = (0..=n).map(|i| field(b, i as f64 * dx).0).collect();
                BarCells {
                    left_displacement: nodes[0],
                    strain: nodes.windows(2).map(|w| (w[1] - w[0]) / dx).collect(),
                    velocity: (0..n)
                        .map(|i| {
                            GAUSS3
                                .iter()
                                .map(|(x, w)| w * field(b, (i as f64 + x) * dx).1)
                                .sum()
                        })
                        .collect(),
                }
            })
            .collect();
        Self::from_cells(model, grid, &cells)
    }

    /// The state of a harmonic-balance solution `x` (layout of
    /// [`NonsmoothSystem`](crate::system::NonsmoothSystem)) at fundamental frequency `omega`
    /// and phase `theta = omega t`, on the grid of step `grid.dt()`.
    ///
    /// # Errors
    /// [`VerifyError::Length`] if `x` does not match the basis and system,
    /// [`VerifyError::InvalidParameter`] for a bad `theta` or an `omega` that is not positive
    /// and finite or is below [`MIN_FREQUENCY`](crate::modal::MIN_FREQUENCY)
    /// (subnormal, or with an infinite period), and the errors of
    /// [`Model::from_system`] and [`State::from_cells`].
    pub fn from_harmonic_balance<B: Basis>(
        system: &BarSystem,
        basis: &B,
        x: &[f64],
        omega: f64,
        theta: f64,
        dt: f64,
    ) -> Result<Self, VerifyError> {
        let expected = basis.len() * system.unknowns_per_harmonic();
        if x.len() != expected {
            return Err(VerifyError::Length {
                what: "harmonic-balance unknowns",
                bar: 0,
                got: x.len(),
                expected,
            });
        }
        check_fundamental_frequency(omega)?;
        if !theta.is_finite() {
            return Err(VerifyError::InvalidParameter {
                what: "phase theta",
                value: theta,
            });
        }
        if let Some((i, v)) = x.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            return Err(VerifyError::NonFinite {
                what: "harmonic-balance unknown",
                bar: 0,
                index: i,
                value: *v,
            });
        }
        let model = Model::from_system(system)?;
        let grid = Grid::new(&model, dt)?;
        let evaluator = FieldEvaluator::new(system, basis, x, omega);
        let mut phi = vec![0.0; basis.len()];
        let mut dphi = vec![0.0; basis.len()];
        basis.functions_at(theta, &mut phi);
        basis.derivatives_at(theta, &mut dphi);
        let (ks, table) = (evaluator.wavenumbers(), RefCell::new(Vec::new()));
        Self::from_fields(&model, &grid, |b, p| {
            let table = &mut table.borrow_mut();
            evaluator.displacement_and_velocity((b, p), (&phi, &dphi), (&ks, table))
        })
    }

    /// The model.
    pub fn model(&self) -> &Model {
        &self.model
    }

    /// The grid.
    pub fn grid(&self) -> &Grid {
        &self.grid
    }

    /// Time since the initial state, `clock * dt`.
    pub fn time(&self) -> f64 {
        self.clock * self.grid.dt()
    }

    /// Displacement of an end.
    ///
    /// # Panics
    /// If the end's bar is not in the model.
    pub fn end_displacement(&self, end: EndRef) -> f64 {
        self.bars[end.bar.index()].ends[usize::from(end.end == End::Right)]
    }

    /// Gap of condition `index` (`None` if it is not an obstacle or a contact): for a
    /// compliant obstacle, the distance `g0 - v` from the end to the spring's free end,
    /// negative by the spring's compression while the end presses it.
    pub fn gap(&self, index: usize) -> Option<f64> {
        match *self.model.conditions().get(index)? {
            Condition::Obstacle { end, gap } | Condition::CompliantObstacle { end, gap, .. } => {
                Some(gap - end.end.normal() * self.end_displacement(end))
            }
            Condition::Contact { first, second, gap } => Some(
                gap - first.end.normal() * self.end_displacement(first)
                    - second.end.normal() * self.end_displacement(second),
            ),
            _ => None,
        }
    }

    /// Largest penetration `max(0, -g)` over the rigid obstacles and contacts (a compliant
    /// obstacle's compression is its law, not a violation of it).
    pub fn penetration(&self) -> f64 {
        let conditions = self.model.conditions().iter().enumerate();
        conditions
            .filter(|(_, c)| !matches!(c, Condition::CompliantObstacle { .. }))
            .filter_map(|(i, _)| self.gap(i))
            .fold(0.0, |m, g| m.max(-g))
    }

    /// Energy `sum_b EA_b / (4 c_b^2) int (R^2 + L^2) dx + sum k_s u^2 / 2 + sum k p^2 / 2`,
    /// exact for the piecewise-constant waves (it equals
    /// `sum_b EA_b/2 int (u_t^2/c_b^2 + u_x^2) dx` plus the ground springs and the compliant
    /// obstacles, each compressed by `p = max(0, v - g0)`).
    pub fn energy(&self) -> f64 {
        self.energy_with(|b| {
            let (w, nu) = (&self.bars[b], self.grid.travel_steps(b));
            let (_, r2) = w.right.moments(self.clock, self.clock + nu);
            let (_, l2) = w.left.moments(self.clock, self.clock + nu);
            r2 + l2
        })
    }

    /// [`State::energy`] from the running integrals the waves keep (equal to rounding, in
    /// `O(bars)` rather than `O(pieces)`): the energy history of a march.
    pub(crate) fn tracked_energy(&self) -> f64 {
        self.energy_with(|b| self.bars[b].right.square() + self.bars[b].left.square())
    }

    /// The energy with `int (R^2 + L^2) ds` of bar `b` given by `squares(b)`.
    fn energy_with(&self, squares: impl Fn(usize) -> f64) -> f64 {
        let mut e = 0.0;
        for (b, bar) in self.model.bars().iter().enumerate() {
            let c = bar.wave_speed();
            e += bar.stiffness() / (4.0 * c * c) * c * self.grid.dt() * squares(b);
        }
        for c in self.model.conditions() {
            let (stretch, stiffness) = match *c {
                Condition::Spring { end, stiffness } => (self.end_displacement(end), stiffness),
                Condition::CompliantObstacle {
                    end,
                    gap,
                    stiffness,
                } => {
                    let v = end.end.normal() * self.end_displacement(end);
                    ((v - gap).max(0.0), stiffness)
                }
                _ => continue,
            };
            e += 0.5 * stiffness * stretch * stretch;
        }
        e
    }

    /// Energy removed so far (since the state was built from fields or cells) by the merges
    /// of short pieces that keep the number of pieces bounded: each merge replaces two pieces
    /// `(h_1, v_1)`, `(h_2, v_2)` by their mean, which keeps the integral of the wave (hence
    /// every displacement) and removes exactly `Z dt / 4 h_1 h_2 / (h_1 + h_2) (v_1 - v_2)^2`
    /// (`Z = EA / c`, `h` in steps) of energy. Zero while no wave reaches its piece limit (to
    /// rounding: pieces equal to rounding and slivers of `1e-10` steps are always merged);
    /// never negative. The lossless conditions (all but a spring under
    /// [`SpringUpdate::Exact`](super::SpringUpdate::Exact)) conserve
    /// `energy() + projected_energy()` to rounding.
    ///
    /// The part a merge removes is orthogonal to what it keeps, and its norm in the state norm
    /// of [`State::norm`] is `sqrt(2 removed energy)`.
    pub fn projected_energy(&self) -> f64 {
        self.model
            .bars()
            .iter()
            .zip(&self.bars)
            .map(|(bar, w)| {
                let z = bar.stiffness() / bar.wave_speed();
                0.25 * z * self.grid.dt() * (w.right.removed() + w.left.removed())
            })
            .sum()
    }

    /// The state norm
    /// `|X|^2 = sum_b [EA_b int (u_t^2/c_b^2 + u_x^2) dx + EA_b/l_b (u_b(0)^2 + u_b(l)^2)]`.
    pub fn norm(&self) -> f64 {
        self.norm_squared_with(|b, clock, nu| {
            let w = &self.bars[b];
            (
                w.right.moments(clock, clock + nu).1,
                w.left.moments(clock, clock + nu).1,
                w.ends,
            )
        })
        .sqrt()
    }

    /// `|X - Y|` in the norm of [`State::norm`], with the fields of both states compared at
    /// the same positions (exactly: the pieces are merged).
    ///
    /// # Errors
    /// [`VerifyError::MismatchedStates`] if the states have different models or grids.
    pub fn distance(&self, other: &State) -> Result<f64, VerifyError> {
        if self.model != other.model || self.grid != other.grid {
            return Err(VerifyError::MismatchedStates);
        }
        Ok(self
            .norm_squared_with(|b, clock, nu| {
                let (w, v) = (&self.bars[b], &other.bars[b]);
                (
                    distance_squared(&w.right, clock, &v.right, other.clock, nu),
                    distance_squared(&w.left, clock, &v.left, other.clock, nu),
                    [w.ends[0] - v.ends[0], w.ends[1] - v.ends[1]],
                )
            })
            .sqrt())
    }

    /// `sum_b EA_b dt/(2 c_b) (int R^2 + int L^2) ds + EA_b/l_b (u0^2 + ul^2)`, the squared
    /// integrals `(R, L)` and end values given per bar by `parts(bar, clock, nu)`.
    fn norm_squared_with(&self, parts: impl Fn(usize, f64, f64) -> (f64, f64, [f64; 2])) -> f64 {
        self.model
            .bars()
            .iter()
            .enumerate()
            .map(|(b, bar)| {
                let (r2, l2, ends) = parts(b, self.clock, self.grid.travel_steps(b));
                let c = bar.wave_speed();
                bar.stiffness() * self.grid.dt() / (2.0 * c) * (r2 + l2)
                    + bar.stiffness() / bar.length() * (ends[0] * ends[0] + ends[1] * ends[1])
            })
            .sum()
    }

    /// Cell means of strain and velocity and nodal displacements of every bar, on its `N`
    /// cells of length `l / N`.
    pub fn snapshot(&self) -> Snapshot {
        let bars = self
            .bars
            .iter()
            .zip(self.model.bars())
            .enumerate()
            .map(|(b, (w, bar))| {
                let n = self.grid.cells(b);
                let c = bar.wave_speed();
                let (nu, h) = (self.grid.travel_steps(b), self.grid.cell_steps(b));
                let dx = c * self.grid.dt() * h;
                let s = self.clock;
                let mut strain = Vec::with_capacity(n);
                let mut velocity = Vec::with_capacity(n);
                let mut displacement = Vec::with_capacity(n + 1);
                displacement.push(w.ends[0]);
                for i in 0..n {
                    // Cell means: integrals over one cell duration `h` (1 when commensurate).
                    let top = s + (nu - i as f64 * h);
                    let (r, _) = w.right.moments(top - h, top);
                    let bottom = s + i as f64 * h;
                    let (l, _) = w.left.moments(bottom, bottom + h);
                    let (r, l) = (r / h, l / h);
                    strain.push((l - r) / (2.0 * c));
                    velocity.push(0.5 * (r + l));
                    displacement.push(displacement[i] + dx * strain[i]);
                }
                BarSnapshot {
                    displacement,
                    strain,
                    velocity,
                }
            })
            .collect();
        Snapshot {
            time: self.time(),
            bars,
        }
    }

    /// Sets the resolution of every wave: `resolution(bar)`.
    pub(crate) fn set_resolution(&mut self, resolution: impl Fn(usize) -> Resolution) {
        for (b, w) in self.bars.iter_mut().enumerate() {
            w.right.set_resolution(resolution(b));
            w.left.set_resolution(resolution(b));
        }
    }

    /// Total number of wave pieces (a measure of the cost of a step), at most
    /// `sum_b 2 Grid::max_pieces(b)` ([`Grid::max_pieces`]).
    pub fn pieces(&self) -> usize {
        self.bars.iter().map(|w| w.right.len() + w.left.len()).sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn energy_and_norm_of_a_uniform_strain() {
        let model = Model::clamped_bar_with_obstacle(0.1).unwrap();
        let grid = Grid::new(&model, 0.01).unwrap();
        let state = State::from_fields(&model, &grid, |_, x| (0.3 * x, 0.0)).unwrap();
        // E = 1/2 int u_x^2 = 0.045; |X|^2 = 2E + u(1)^2.
        assert!((state.energy() - 0.045).abs() < 1e-14);
        assert!((state.norm() - (0.09f64 + 0.09).sqrt()).abs() < 1e-14);
        assert!((state.gap(1).unwrap() + 0.2).abs() < 1e-14);
        assert!((state.penetration() - 0.2).abs() < 1e-15);
        let snap = state.snapshot();
        assert!((snap.bars[0].displacement[100] - 0.3).abs() < 1e-14);
        assert!(snap.bars[0].strain.iter().all(|e| (e - 0.3).abs() < 1e-14));
        assert_eq!(state.distance(&state).unwrap(), 0.0);
        let bad = State::from_fields(&model, &grid, |_, x| (x, f64::NAN));
        assert!(matches!(
            bad,
            Err(VerifyError::NonFinite {
                what: "velocity",
                ..
            })
        ));
    }
}
