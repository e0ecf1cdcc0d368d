//! The bordered corrector system of the pseudo-arclength driver, its bordering solve, and the
//! diagonal metric of the scaled norm on `y = (x, lambda)`.

use crate::continuation::augmented;
use crate::continuation::bordering::{fill_bordered, solve_bordered};
use crate::continuation::ContinuationProblem;
use crate::linalg::DenseMatrix;
use crate::solve::{residual_scale, Problem, SingularStep, Structured};

/// The bordered corrector system `[F(x, lambda); s <t, y - y_p>_W]` as a [`Problem`] in
/// `y = (x, lambda)` (the [`augmented`] layout), with `s` the residual scale of the problem.
///
/// Its structured solve is the bordering algorithm ([`solve_bordered`]) on the problem's own
/// structured solve, with the border row `(c, d)`; where `J` alone is singular (a fold) or
/// has no structure, it falls back to the dense bordered Jacobian.
pub(super) struct Bordered<'a, P: ?Sized> {
    problem: &'a mut P,
    tangent: &'a [f64],
    predicted: &'a [f64],
    metric: &'a Metric,
    scratch: &'a mut BorderScratch,
    /// The residual scale of the problem at the last parameter evaluated.
    scale: f64,
}

/// Storage of the bordered Jacobian's blocks, kept by the driver across corrector iterations
/// and steps.
#[derive(Debug, Default)]
pub(super) struct BorderScratch {
    /// `dF/dx`.
    inner: DenseMatrix,
    /// `dF/dlambda`.
    df: Vec<f64>,
    /// Right-hand sides of the bordering algorithm.
    columns: Vec<f64>,
}

impl<'a, P: ContinuationProblem + ?Sized> Bordered<'a, P> {
    pub(super) fn new(
        problem: &'a mut P,
        (tangent, predicted): (&'a [f64], &'a [f64]),
        metric: &'a Metric,
        scratch: &'a mut BorderScratch,
    ) -> Self {
        let scale = residual_scale(problem);
        Self {
            problem,
            tangent,
            predicted,
            metric,
            scratch,
            scale,
        }
    }

    /// Moves the problem to the parameter of `y` and returns the unknowns of `y`
    /// ([`augmented`] layout).
    fn at<'y>(&mut self, y: &'y [f64]) -> &'y [f64] {
        let (x, lambda) = augmented::split_or_nan(y);
        self.problem.set_parameter(lambda);
        self.scale = residual_scale(self.problem);
        x
    }
}

impl<P: ContinuationProblem + ?Sized> Problem for Bordered<'_, P> {
    fn dimension(&self) -> usize {
        self.problem.dimension() + 1
    }
    fn residual(&mut self, y: &[f64], f: &mut [f64]) {
        let n = self.problem.dimension();
        let x = self.at(y);
        self.problem.residual(x, &mut f[..n]);
        f[n] = self.scale * self.metric.dot_diff(self.tangent, y, self.predicted);
    }
    /// `[dF/dx, dF/dlambda; s t^T W]`.
    fn jacobian(&mut self, y: &[f64], jac: &mut DenseMatrix) {
        let n = self.problem.dimension();
        let x = self.at(y);
        let BorderScratch { inner, df, .. } = &mut *self.scratch;
        df.resize(n, 0.0);
        self.problem.jacobian(x, inner);
        self.problem.parameter_derivative(x, df);
        fill_bordered(
            jac,
            inner,
            df,
            border_row(self.scale, self.tangent, self.metric),
        );
    }
    fn structure(&mut self) -> Option<&mut dyn Structured> {
        Some(self)
    }
}

impl<P: ContinuationProblem + ?Sized> Structured for Bordered<'_, P> {
    fn residual_scale(&self) -> f64 {
        self.scale
    }

    fn solve_jacobian(
        &mut self,
        y: &[f64],
        rhs: &mut [f64],
        columns: usize,
    ) -> Option<Result<(), SingularStep>> {
        let x = self.at(y);
        let mut buffer = std::mem::take(&mut self.scratch.columns);
        let border = border_row(self.scale, self.tangent, self.metric);
        let result = solve_bordered(self.problem, x, (rhs, columns), border, &mut buffer);
        self.scratch.columns = buffer;
        result
    }

    fn set_smoothing(&mut self, smoothing: f64) -> bool {
        self.problem
            .structure()
            .is_some_and(|s| s.set_smoothing(smoothing))
    }
}

/// The border row `(c, d)`: `c_i = s t_i w_i`, `d = s t_lambda w_lambda`, for the residual
/// scale `s`, the tangent `t` and the metric `w`.
fn border_row<'b>(
    scale: f64,
    tangent: &'b [f64],
    metric: &'b Metric,
) -> impl Fn(usize) -> f64 + 'b {
    move |i| scale * tangent[i] * metric.weight(i)
}

/// Diagonal metric `W` of the scaled norm on `y = (x, lambda)`: `x[i]` weighs `x_w[i]`,
/// `lambda` weighs `lambda_w`.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Metric {
    pub(super) x_w: Vec<f64>,
    pub(super) lambda_w: f64,
}

impl Metric {
    pub(super) fn weight(&self, i: usize) -> f64 {
        self.x_w.get(i).copied().unwrap_or(self.lambda_w)
    }

    /// `<a, b>_W`.
    pub(super) fn dot(&self, a: &[f64], b: &[f64]) -> f64 {
        (0..a.len()).map(|i| a[i] * b[i] * self.weight(i)).sum()
    }

    /// `<a, b - c>_W`.
    pub(super) fn dot_diff(&self, a: &[f64], b: &[f64], c: &[f64]) -> f64 {
        (0..a.len())
            .map(|i| a[i] * (b[i] - c[i]) * self.weight(i))
            .sum()
    }

    /// `|v|_W` for `v = (x, lambda)` or `v = x` alone.
    pub(super) fn norm(&self, v: &[f64]) -> f64 {
        (0..v.len())
            .map(|i| v[i] * v[i] * self.weight(i))
            .sum::<f64>()
            .sqrt()
    }
}
