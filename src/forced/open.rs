//! The open-contact response of a forced system: where a response curve starts.

use crate::check::check_frequency_named;
use crate::error::{Error, SettingsError, SolveError};
use crate::forced::ForcedSystem;
use crate::fourier::Basis;
use crate::linalg::{DenseMatrix, Lu};
use crate::solve::Problem;
use crate::system::problem::max_frequency;

impl ForcedSystem {
    /// The linear response at the current frequency: the solution with every contact open
    /// (each law's force row held at zero instead of its law), the start of a response
    /// curve far from contact. The excitation drives harmonic 1 alone, and without contact
    /// the harmonics do not couple: every other harmonic is zero, and only harmonic 1's
    /// cosine and sine are solved for (a constant rigid motion, singular here, stays zero).
    ///
    /// # Errors
    /// [`SettingsError::NotFinite`] before a frequency is set
    /// ([`ContinuationProblem::set_parameter`](crate::continuation::ContinuationProblem::set_parameter)); [`SettingsError::NotPositive`],
    /// [`SettingsError::FrequencyTooSmall`] or [`SettingsError::FrequencyTooLarge`] for a
    /// frequency set that is not positive and finite or out of the basis' range;
    /// [`SettingsError::NonFiniteResult`] when amplitudes or damping near the ends of `f64`
    /// overflow the response;
    /// [`SolveError::SingularJacobian`](crate::SolveError::SingularJacobian) when the open
    /// system is singular at harmonic 1 (an undamped natural frequency).
    pub fn open_response(&self) -> Result<Vec<f64>, Error> {
        if self.omega.is_nan() {
            return Err(SettingsError::NotFinite {
                what: "forcing frequency (none set yet: set_parameter gives it)",
                value: self.omega,
            }
            .into());
        }
        self.check_forcing_frequency()?;
        let (u, m) = (self.unknowns, self.basis.harmonics());
        let rows = &self.rows[1];
        // Harmonic 1's equations: the linear rows, then every law's force held at zero, for
        // the cosine (unknowns 0..u of the block) and the sine (u..2u). A complex row `a`
        // gives `[a_r, a_i]` on the cosine's and `[-a_i, a_r]` on the sine's (`real_form`).
        let complex_rows: Vec<_> = (0..self.linear_count)
            .map(|r| rows.linear.row(r).0)
            .chain((0..self.offsets.len()).map(|l| rows.force.row(l).0))
            .collect();
        let mut block = DenseMatrix::zeros(2 * u, 2 * u);
        for (r, a) in complex_rows.iter().enumerate() {
            for (k, a) in a.iter().enumerate() {
                block[(r, k)] = a.re;
                block[(r, u + k)] = a.im;
                block[(u + r, k)] = -a.im;
                block[(u + r, u + k)] = a.re;
            }
        }
        let mut b = vec![0.0; 2 * u];
        for &(r, value, _) in &self.rhs {
            b[r] += value;
        }
        let lu = Lu::factor(&block, 1e-14).map_err(|p| SolveError::SingularJacobian {
            iteration: 0,
            pivot: p.pivot,
            ratio: p.ratio,
        })?;
        lu.solve_in_place(&mut b);
        // Amplitudes or damping near the ends of `f64` (finite, so accepted) can overflow
        // the solve.
        if b.iter().any(|v| !v.is_finite()) {
            return Err(SettingsError::NonFiniteResult {
                what: "open-contact response",
                omega: self.omega,
            }
            .into());
        }
        let mut x = vec![0.0; self.dimension()];
        x[u..2 * u].copy_from_slice(&b[..u]);
        x[(m + 1) * u..(m + 2) * u].copy_from_slice(&b[u..]);
        Ok(x)
    }

    /// Checks the frequency set: positive and finite, not subnormal
    /// ([`MIN_FREQUENCY`](crate::modal::MIN_FREQUENCY)), and not so high that the phase
    /// `k l` of the highest harmonic over a bar passes [`MAX_PHASE`](crate::system::MAX_PHASE), where the rows'
    /// sines and cosines carry no digit (they came out NaN at `1e300`).
    pub(super) fn check_forcing_frequency(&self) -> Result<(), SettingsError> {
        let max = max_frequency(&self.system, self.basis.harmonics());
        check_frequency_named("forcing frequency", self.omega, max).map(|_| ())
    }
}
