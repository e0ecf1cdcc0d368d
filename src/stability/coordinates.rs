//! The state of the integrator as a vector of numbers of one unit, and back.

use crate::bar::{BarId, End};
use crate::verify::{BarCells, Condition, Grid, Model, Snapshot, State, VerifyError};

/// How one bar's cells map to coordinates: every coordinate is a velocity (`u_t`, `c u_x`,
/// `c u(0) / l`), so that one perturbation step suits all of them.
#[derive(Debug, Clone, Copy, PartialEq)]
struct BarLayout {
    /// Number of cells `N`.
    cells: usize,
    /// Whether `u(0)` is a coordinate (not when the left end is clamped: it stays 0).
    left_displacement: bool,
    /// Wave speed `c`.
    speed: f64,
    /// `c / l`: the scale of `u(0)`.
    displacement_scale: f64,
    /// `l`.
    length: f64,
}

/// The coordinates of a grid: per bar `[c u(0) / l]` (unless clamped), `c u_x` and `u_t` of
/// each cell.
///
/// A clamped **right** end is not removed: its displacement `u(0) + dx sum u_x` is conserved
/// exactly by the march (the end does not move), so it adds one multiplier exactly 1 with
/// the physical ones unchanged (the states where it is 0 form an invariant subspace of the
/// linearised map). [`Coordinates::spurious_unit_multipliers`] counts them.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Coordinates {
    bars: Vec<BarLayout>,
    spurious: usize,
}

fn clamped(model: &Model, bar: usize, side: End) -> bool {
    model.conditions().iter().any(
        |c| matches!(c, Condition::Clamped { end } if end.bar == BarId(bar) && end.end == side),
    )
}

impl Coordinates {
    pub(crate) fn new(model: &Model, grid: &Grid) -> Self {
        let bars = model
            .bars()
            .iter()
            .enumerate()
            .map(|(b, bar)| BarLayout {
                cells: grid.cells(b),
                left_displacement: !clamped(model, b, End::Left),
                speed: bar.wave_speed(),
                displacement_scale: bar.wave_speed() / bar.length(),
                length: bar.length(),
            })
            .collect();
        let spurious = (0..model.bars().len())
            .filter(|&b| clamped(model, b, End::Right))
            .count();
        Self { bars, spurious }
    }

    /// Number of coordinates.
    pub(crate) fn len(&self) -> usize {
        self.bars
            .iter()
            .map(|b| 2 * b.cells + usize::from(b.left_displacement))
            .sum()
    }

    /// Exact multipliers 1 that the coordinates add to the physical ones (one per clamped
    /// right end).
    pub(crate) fn spurious_unit_multipliers(&self) -> usize {
        self.spurious
    }

    /// The coordinates of a snapshot.
    pub(crate) fn of_snapshot(&self, snapshot: &Snapshot, out: &mut Vec<f64>) {
        out.clear();
        for (layout, bar) in self.bars.iter().zip(&snapshot.bars) {
            if layout.left_displacement {
                out.push(layout.displacement_scale * bar.displacement[0]);
            }
            out.extend(bar.strain.iter().map(|e| layout.speed * e));
            out.extend_from_slice(&bar.velocity);
        }
    }

    /// `max |u - u0| / max |u0|` over the nodes of every bar: how far the displacement of the
    /// coordinates `v` is from that of `v0`.
    pub(crate) fn displacement_distance(&self, v: &[f64], v0: &[f64]) -> f64 {
        let (mut largest, mut change) = (0.0f64, 0.0f64);
        let mut at = 0;
        for layout in &self.bars {
            let (mut u, mut u0) = (0.0, 0.0);
            if layout.left_displacement {
                u = v[at] / layout.displacement_scale;
                u0 = v0[at] / layout.displacement_scale;
                at += 1;
            }
            let dx = layout.length / layout.cells as f64;
            for i in 0..=layout.cells {
                largest = largest.max(u0.abs());
                change = change.max((u - u0).abs());
                if i < layout.cells {
                    u += dx * v[at + i] / layout.speed;
                    u0 += dx * v0[at + i] / layout.speed;
                }
            }
            at += 2 * layout.cells;
        }
        if largest > 0.0 {
            change / largest
        } else {
            change
        }
    }

    /// The energy of the state `v` (on `template`'s model and grid).
    pub(crate) fn energy(&self, template: &State, v: &[f64]) -> Result<f64, VerifyError> {
        Ok(self
            .to_state(template.model(), template.grid(), v)?
            .energy())
    }

    /// The state of the coordinates `v`.
    pub(crate) fn to_state(
        &self,
        model: &Model,
        grid: &Grid,
        v: &[f64],
    ) -> Result<State, VerifyError> {
        let mut at = 0;
        let cells: Vec<BarCells> = self
            .bars
            .iter()
            .map(|layout| {
                let left_displacement = if layout.left_displacement {
                    at += 1;
                    v[at - 1] / layout.displacement_scale
                } else {
                    0.0
                };
                let n = layout.cells;
                let strain = v[at..at + n].iter().map(|e| e / layout.speed).collect();
                let velocity = v[at + n..at + 2 * n].to_vec();
                at += 2 * n;
                BarCells {
                    left_displacement,
                    strain,
                    velocity,
                }
            })
            .collect();
        State::from_cells(model, grid, &cells)
    }
}
