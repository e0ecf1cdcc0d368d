//! The derivative of the exact one-period map, by central differences.

use super::coordinates::Coordinates;
use crate::error::StabilityError;
use crate::verify::{advance, MarchOptions, SpringUpdate, State};
use faer::Mat;

/// The monodromy matrix `M = dP/dX` of the one-period map `P` at a state, in the coordinates
/// of [`Coordinates`].
pub(crate) type Monodromy = Mat<f64>;

/// The one-period map `P` of the exact integrator, in coordinates.
pub(crate) struct PeriodMap<'a> {
    pub coordinates: &'a Coordinates,
    /// Gives the model and grid.
    pub template: &'a State,
    pub period: f64,
    pub spring: SpringUpdate,
}

impl PeriodMap<'_> {
    /// `out = P(v)`.
    pub(crate) fn apply(&self, v: &[f64], out: &mut Vec<f64>) -> Result<(), StabilityError> {
        self.flow(v, self.period, out)
    }

    /// `out`: the coordinates of the motion from `v` after `duration`.
    pub(crate) fn flow(
        &self,
        v: &[f64],
        duration: f64,
        out: &mut Vec<f64>,
    ) -> Result<(), StabilityError> {
        let (_, end) = self.march(v, duration)?;
        self.coordinates.of_snapshot(&end.snapshot(), out);
        Ok(())
    }

    /// The state of the coordinates `v` and the state of its motion after `duration`, its
    /// waves exact (before the cell means the coordinates take).
    fn march(&self, v: &[f64], duration: f64) -> Result<(State, State), StabilityError> {
        let state = self
            .coordinates
            .to_state(self.template.model(), self.template.grid(), v)?;
        let options = MarchOptions {
            spring: self.spring,
            snapshot_every: 0,
        };
        let end = advance(&state, duration, &options)?;
        Ok((state, end))
    }

    /// The share of the energy of `v` that the cell means of its state after one period
    /// remove: zero where every breakpoint of the waves then lies on the cells' edges (the
    /// march conserves the energy of its pieces exactly, up to the merges it reports).
    pub(crate) fn projected_share(&self, v: &[f64]) -> Result<f64, StabilityError> {
        let (state, end) = self.march(v, self.period)?;
        let start = state.energy();
        let mut out = Vec::new();
        self.coordinates.of_snapshot(&end.snapshot(), &mut out);
        let means = self.coordinates.energy(self.template, &out)?;
        Ok(if start > 0.0 {
            ((end.energy() - means) / start).max(0.0)
        } else {
            0.0
        })
    }

    /// Column `j` of `dP/dX` at `base` by central differences of `step`, into `scratch[1]`.
    fn column(
        &self,
        base: &[f64],
        j: usize,
        step: f64,
        scratch: &mut [Vec<f64>; 3],
    ) -> Result<(), StabilityError> {
        let [v, plus, minus] = scratch;
        v.clear();
        v.extend_from_slice(base);
        v[j] = base[j] + step;
        self.apply(v, plus)?;
        v[j] = base[j] - step;
        self.apply(v, minus)?;
        for (p, m) in plus.iter_mut().zip(minus.iter()) {
            *p = (*p - m) / (2.0 * step);
        }
        Ok(())
    }

    /// The monodromy matrix at `base`, with the step `relative_step |X|_inf` for every
    /// coordinate (`2 n` marches of one period).
    ///
    /// The step is relative to the state, so that the matrix is the same for a state and gap
    /// scaled together (the map is positively homogeneous of degree 1 in both).
    pub(crate) fn monodromy(
        &self,
        base: &[f64],
        relative_step: f64,
    ) -> Result<Monodromy, StabilityError> {
        let scale = base.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        if scale == 0.0 {
            return Err(StabilityError::AtRest);
        }
        let step = relative_step * scale;
        let n = base.len();
        let column = |scratch: &mut [Vec<f64>; 3], j: usize| -> Result<Vec<f64>, StabilityError> {
            self.column(base, j, step, scratch)?;
            match scratch[1].iter().find(|v| !v.is_finite()) {
                Some(value) => Err(StabilityError::NonFinite {
                    column: j,
                    value: *value,
                }),
                None => Ok(scratch[1].clone()),
            }
        };
        // The columns are independent marches: with the `parallel` feature they run on
        // rayon's pool (the matrix is the same, bit for bit).
        #[cfg(feature = "parallel")]
        let columns: Vec<Result<Vec<f64>, StabilityError>> = {
            use rayon::prelude::*;
            (0..n)
                .into_par_iter()
                .map_init(|| [Vec::new(), Vec::new(), Vec::new()], column)
                .collect()
        };
        #[cfg(not(feature = "parallel"))]
        let columns: Vec<Result<Vec<f64>, StabilityError>> = {
            let mut scratch = [Vec::new(), Vec::new(), Vec::new()];
            (0..n).map(|j| column(&mut scratch, j)).collect()
        };
        let mut matrix = Mat::<f64>::zeros(n, n);
        for (j, values) in columns.into_iter().enumerate() {
            for (i, value) in values?.into_iter().enumerate() {
                matrix[(i, j)] = value;
            }
        }
        Ok(matrix)
    }
}
