//! A phase condition for bases with sines: the harmonic-balance system bordered by an
//! unfolding unknown and a phase equation.
//!
//! With sines in the basis, every time shift of a periodic motion is one too: at a fixed
//! frequency the solutions form a circle, not a point, and the Jacobian is (nearly) singular
//! along the shift `D x` (`D` differentiates each signal in `theta`). The usual cure
//! (Doedel's integral phase condition, AUTO and COCO) fixes the phase by an equation and
//! frees one unknown to keep the system square:
//!
//! ```text
//! F(x; Omega) + mu w = 0        harmonic balance, unfolded by mu
//! u . x             = 0        the phase: u = D x_ref / |D x_ref|
//! ```
//!
//! `u` is orthogonal to every state that is a shift of the reference to first order; the
//! unfolding column `w` is the `theta`-derivative of the reference's gaps in the law rows
//! (`a_c dg/dtheta`, normalised), a direction the shift-invariant equations cannot produce
//! on their own. On a solution of `F = 0` that satisfies the phase, `mu = 0`; a converged
//! point reports `mu` ([`PhaseLocked::unfolding`]), and `|mu|` of the order of the residual
//! tolerance says the point solves `F = 0` itself. The sampled law is shift-invariant only
//! for shifts by whole grid steps, so the Jacobian is nonsingular on the grid and singular
//! only in the limit: the bordered system is regular in both cases.
//!
//! An even reference (a [`CosineBasis`](crate::fourier::CosineBasis) solution padded with
//! zero sines) puts the phase at a turning point, `t = 0` as in the cosine basis; an even
//! solution then solves the bordered system with `mu = 0` exactly, since the sine
//! projections of an even residual vanish on the grid.

use crate::continuation::{fill_bordered, ContinuationProblem};
use crate::error::{Error, SettingsError};
use crate::fourier::{Basis, SineCosineBasis};
use crate::linalg::DenseMatrix;
use crate::solve::{norm, Problem, Structured};
use crate::system::rows::dot;
use crate::system::NonsmoothSystem;

/// A [`NonsmoothSystem`] with a phase condition: unknowns `y = (x, mu)`, equations
/// `F(x) + mu w = 0` and `u . x = 0` (module docs). A [`ContinuationProblem`] in the
/// frequency `Omega`, as the system it wraps.
#[derive(Debug, Clone)]
pub struct PhaseLocked {
    inner: NonsmoothSystem<SineCosineBasis>,
    /// The phase row `u`, unit length.
    phase: Vec<f64>,
    /// The unfolding column `w`, unit length.
    unfolding: Vec<f64>,
    jacobian: DenseMatrix,
}

/// `D x` for a full-basis vector of `m` harmonics with `per` values per coefficient
/// (coefficient-major, cosine `n` at `n`, sine `n` at `m + n`): each of its signals
/// differentiated in `theta`, `(c_n, s_n) -> (n s_n, -n c_n)`.
pub(crate) fn shift_of(x: &[f64], m: usize, per: usize) -> Vec<f64> {
    let mut out = vec![0.0; x.len()];
    for n in 1..=m {
        let (cosine, sine) = (n * per, (m + n) * per);
        for k in 0..per {
            out[cosine + k] = n as f64 * x[sine + k];
            out[sine + k] = -(n as f64) * x[cosine + k];
        }
    }
    out
}

/// `v / |v|`, or `None` when `v` is zero or not finite.
fn unit(mut v: Vec<f64>) -> Option<Vec<f64>> {
    let norm = norm(&v);
    if !(norm.is_finite() && norm > 0.0) {
        return None;
    }
    v.iter_mut().for_each(|a| *a /= norm);
    Some(v)
}

impl PhaseLocked {
    /// `inner` with the phase of `reference`, a state of `inner` at frequency `omega` (the
    /// start of a branch, or its last point); the problem is left at `omega`.
    ///
    /// # Errors
    /// [`SettingsError::Length`] for a reference of the wrong length;
    /// [`SettingsError::NotPositive`] for a frequency that is not positive and finite;
    /// [`SettingsError::NotFinite`] for a reference with a value that is not;
    /// [`SettingsError::StillReference`] for a reference whose signals do not move (a
    /// state of rest fixes no phase) or whose gaps do not.
    pub fn new(
        inner: NonsmoothSystem<SineCosineBasis>,
        reference: &[f64],
        omega: f64,
    ) -> Result<Self, Error> {
        let mut locked = Self {
            inner,
            phase: Vec::new(),
            unfolding: Vec::new(),
            jacobian: DenseMatrix::zeros(0, 0),
        };
        locked.set_reference(reference, omega)?;
        Ok(locked)
    }

    /// Moves the phase condition to the reference `reference` at frequency `omega` (drivers
    /// move it to the last accepted point of a long branch). Errors as [`Self::new`].
    ///
    /// # Errors
    /// As [`Self::new`]; on error the problem keeps its previous reference.
    pub fn set_reference(&mut self, reference: &[f64], omega: f64) -> Result<(), Error> {
        let n = self.inner.dimension();
        if reference.len() != n {
            return Err(SettingsError::Length {
                what: "phase reference",
                got: reference.len(),
                expected: n,
            }
            .into());
        }
        if !(omega.is_finite() && omega > 0.0) {
            return Err(SettingsError::NotPositive {
                what: "frequency of the phase reference",
                value: omega,
            }
            .into());
        }
        if let Some(v) = reference.iter().find(|v| !v.is_finite()) {
            return Err(SettingsError::NotFinite {
                what: "phase reference",
                value: *v,
            }
            .into());
        }
        self.inner.set_parameter(omega);
        let phase = unit(self.shift(reference)).ok_or(SettingsError::StillReference {
            what: "its signals",
        })?;
        let unfolding = unit(self.gap_shift(reference))
            .ok_or(SettingsError::StillReference { what: "its gaps" })?;
        self.phase = phase;
        self.unfolding = unfolding;
        Ok(())
    }

    /// `D x`: every signal of `x` (each bar's two Helmholtz components) differentiated in
    /// `theta`.
    fn shift(&self, x: &[f64]) -> Vec<f64> {
        let basis = self.inner.basis();
        shift_of(x, basis.harmonics(), x.len() / basis.len())
    }

    /// The residual-space column `a_c D g` in the law rows: the `theta`-derivative of each
    /// law's gap coefficients `g_i = gap_row . x_i` at the current frequency.
    fn gap_shift(&mut self, x: &[f64]) -> Vec<f64> {
        let omega = self.inner.parameter();
        let a_c = self.inner.complementarity();
        let basis = self.inner.basis().clone();
        let (len, m, n) = (basis.len(), basis.harmonics(), self.inner.dimension());
        let rows = self.inner.rows_at(omega);
        let (unknowns, linear) = (rows[0].unknowns(), rows[0].linear_count());
        let laws = unknowns - linear;
        let mut out = vec![0.0; n];
        for l in 0..laws {
            let gaps: Vec<f64> = (0..len)
                .map(|i| {
                    let xi = &x[i * unknowns..(i + 1) * unknowns];
                    dot(rows[basis.harmonic(i)].gap_row(l), xi)
                })
                .collect();
            let base = len * linear + l * len;
            for (o, d) in out[base..base + len].iter_mut().zip(shift_of(&gaps, m, 1)) {
                *o = a_c * d;
            }
        }
        out
    }

    /// The harmonic-balance system (at the frequency of the last evaluation).
    pub fn inner(&self) -> &NonsmoothSystem<SineCosineBasis> {
        &self.inner
    }

    /// The harmonic-balance system, mutably.
    pub fn inner_mut(&mut self) -> &mut NonsmoothSystem<SineCosineBasis> {
        &mut self.inner
    }

    /// The unfolding unknown `mu` of `y = (x, mu)`: 0 on a solution of `F(x) = 0`.
    pub fn unfolding(y: &[f64]) -> f64 {
        y.last().copied().unwrap_or(f64::NAN)
    }

    /// `y = (x, 0)`: a state of the inner system as an unknown of this one.
    pub fn lift(x: &[f64]) -> Vec<f64> {
        let mut y = x.to_vec();
        y.push(0.0);
        y
    }

    /// The phase `u . x` of a state of the inner system (0 on the locked phase).
    pub fn phase_of(&self, x: &[f64]) -> f64 {
        dot(&self.phase, x)
    }
}

impl Problem for PhaseLocked {
    fn dimension(&self) -> usize {
        self.inner.dimension() + 1
    }

    fn residual(&mut self, y: &[f64], f: &mut [f64]) {
        let n = self.inner.dimension();
        let (x, mu) = (&y[..n], y[n]);
        self.inner.residual(x, &mut f[..n]);
        for (fi, w) in f[..n].iter_mut().zip(&self.unfolding) {
            *fi += mu * w;
        }
        f[n] = self.phase_of(x);
    }

    /// `[dF/dx, w; u^T, 0]`.
    fn jacobian(&mut self, y: &[f64], jac: &mut DenseMatrix) {
        let n = self.inner.dimension();
        self.inner.jacobian(&y[..n], &mut self.jacobian);
        let phase = &self.phase;
        fill_bordered(jac, &self.jacobian, &self.unfolding, |i| {
            phase.get(i).copied().unwrap_or(0.0)
        });
    }

    fn structure(&mut self) -> Option<&mut dyn Structured> {
        Some(self)
    }
}

/// The dense bordered matrix is factorised: the inner structured solves assume a regular
/// `dF/dx`, which the shift makes nearly singular.
impl Structured for PhaseLocked {
    fn residual_scale(&self) -> f64 {
        self.inner.description().residual_scale()
    }

    fn set_smoothing(&mut self, smoothing: f64) -> bool {
        self.inner.set_smoothing(smoothing)
    }

    fn active_set(&mut self, y: &[f64]) -> Option<Vec<usize>> {
        let n = self.inner.dimension();
        self.inner.active_set(&y[..n])
    }
}

impl ContinuationProblem for PhaseLocked {
    /// The fundamental frequency `Omega`.
    fn parameter(&self) -> f64 {
        self.inner.parameter()
    }

    fn set_parameter(&mut self, omega: f64) {
        self.inner.set_parameter(omega);
    }

    /// `dF/dOmega` of the inner system; the phase row and `w` do not depend on `Omega`.
    fn parameter_derivative(&mut self, y: &[f64], df: &mut [f64]) {
        let n = self.inner.dimension();
        self.inner.parameter_derivative(&y[..n], &mut df[..n]);
        df[n] = 0.0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::modal::branch_seed;
    use crate::reference::clamped_bar_with_obstacle;
    use crate::system::HarmonicBalanceSettings;

    /// A clamped bar's cosine seed at `T = 3.9`, padded with sines, and the full system.
    fn seeded() -> (NonsmoothSystem<SineCosineBasis>, Vec<f64>, f64) {
        let system = clamped_bar_with_obstacle(1e-3).unwrap();
        let m = 8;
        let settings = HarmonicBalanceSettings {
            harmonics: m,
            ..Default::default()
        };
        let mut even = NonsmoothSystem::new(&system, settings).unwrap();
        let omega = 2.0 * std::f64::consts::PI / 3.9;
        let seed = branch_seed(&mut even, 1, 1, omega).unwrap();
        let basis = SineCosineBasis::new(m, settings.samples_per_harmonic).unwrap();
        let full = NonsmoothSystem::with_basis(&system, basis, settings.complementarity).unwrap();
        let x = pad(&seed, &full, m);
        (full, x, omega)
    }

    /// A cosine state padded with zero sines (coefficient-major layout).
    fn pad(x: &[f64], full: &NonsmoothSystem<SineCosineBasis>, m: usize) -> Vec<f64> {
        let per = x.len() / (m + 1);
        let mut y = x.to_vec();
        y.resize(full.dimension(), 0.0);
        assert_eq!(per * full.basis().len(), full.dimension());
        y
    }

    #[test]
    fn the_jacobian_matches_finite_differences() {
        let (full, x, omega) = seeded();
        let mut locked = PhaseLocked::new(full, &x, omega).unwrap();
        let n = locked.dimension();
        // A point off the even states: some sines and some mu.
        let mut y = PhaseLocked::lift(&x);
        for (i, v) in y.iter_mut().enumerate() {
            *v += 3e-5 * (((i * 7) % 11) as f64 - 5.0) / 5.0;
        }
        locked.set_smoothing(1e-4);
        let mut jac = DenseMatrix::zeros(0, 0);
        locked.jacobian(&y, &mut jac);
        let (mut plus, mut minus) = (vec![0.0; n], vec![0.0; n]);
        let h = 1e-7;
        let mut worst: f64 = 0.0;
        for j in 0..n {
            let mut yp = y.clone();
            yp[j] += h;
            locked.residual(&yp, &mut plus);
            yp[j] -= 2.0 * h;
            locked.residual(&yp, &mut minus);
            for i in 0..n {
                let fd = (plus[i] - minus[i]) / (2.0 * h);
                worst = worst.max((fd - jac[(i, j)]).abs() / (1.0 + jac[(i, j)].abs()));
            }
        }
        assert!(worst < 1e-5, "worst relative difference {worst:e}");
    }

    #[test]
    fn a_still_reference_or_a_wrong_length_is_a_typed_error() {
        let (full, x, omega) = seeded();
        let rest = vec![0.0; x.len()];
        assert!(matches!(
            PhaseLocked::new(full.clone(), &rest, omega),
            Err(Error::Settings(SettingsError::StillReference { .. }))
        ));
        assert!(matches!(
            PhaseLocked::new(full.clone(), &x[1..], omega),
            Err(Error::Settings(SettingsError::Length { .. }))
        ));
        assert!(matches!(
            PhaseLocked::new(full.clone(), &x, f64::NAN),
            Err(Error::Settings(SettingsError::NotPositive { .. }))
        ));
        let mut bad = x.clone();
        bad[3] = f64::NAN;
        assert!(matches!(
            PhaseLocked::new(full, &bad, omega),
            Err(Error::Settings(SettingsError::NotFinite { .. }))
        ));
    }
}
