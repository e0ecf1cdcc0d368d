//! Two bar ends facing each other.

use super::{
    complementarity_samples, smoothed_complementarity, BoundaryCondition, LawSamples, LawValue,
    LinearRows, Observable, Quantity, Term, TimeDomainForm, UnilateralLaw,
};
use crate::bar::EndRef;
use crate::check::positive;
use crate::error::ModelError;

/// Unilateral contact between two ends that face each other across a gap `g0`:
/// `g = g0 - v_A - v_B`, the forces balance (`lambda_A = lambda_B`, one linear row per harmonic,
/// i.e. `EA_A u_x,A = EA_B u_x,B`), and Signorini holds between `g` and `lambda = lambda_A`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Contact {
    /// First end.
    pub first: EndRef,
    /// Second end.
    pub second: EndRef,
    gap: f64,
}

impl Contact {
    /// Contact between `first` and `second` with gap `g0 > 0` at rest.
    ///
    /// # Errors
    /// [`ModelError::NotPositive`] if `g0` is not positive and finite.
    pub fn new(first: EndRef, second: EndRef, gap: f64) -> Result<Self, ModelError> {
        Ok(Self {
            first,
            second,
            gap: positive("contact gap", gap)?,
        })
    }

    /// The gap at rest `g0`.
    pub fn initial_gap(&self) -> f64 {
        self.gap
    }
}

impl BoundaryCondition for Contact {
    fn name(&self) -> String {
        format!(
            "contact (gap {}) between {} and {}",
            self.gap, self.first, self.second
        )
    }
    fn ends(&self) -> Vec<EndRef> {
        vec![self.first, self.second]
    }
    fn validate(&self) -> Result<(), ModelError> {
        positive("contact gap", self.gap).map(|_| ())
    }
    fn linear_rows(&self, _: f64, _: &dyn Fn(EndRef) -> f64, rows: &mut LinearRows) {
        rows.push(&[
            Term::new(self.first, Quantity::ContactForce, 1.0),
            Term::new(self.second, Quantity::ContactForce, -1.0),
        ]);
    }
    fn unilateral(&self) -> Option<&dyn UnilateralLaw> {
        Some(self)
    }
    fn time_domain_form(&self) -> Option<TimeDomainForm> {
        Some(TimeDomainForm::Contact {
            first: self.first,
            second: self.second,
            gap: self.gap,
        })
    }
}

impl UnilateralLaw for Contact {
    fn gap(&self) -> Observable {
        Observable {
            offset: self.gap,
            terms: vec![
                Term::new(self.first, Quantity::OutwardDisplacement, -1.0),
                Term::new(self.second, Quantity::OutwardDisplacement, -1.0),
            ],
        }
    }
    fn force(&self) -> Observable {
        Observable {
            offset: 0.0,
            terms: vec![Term::new(self.first, Quantity::ContactForce, 1.0)],
        }
    }
    fn smoothed_residual(&self, gap: f64, force: f64, a_c: f64, smoothing: f64) -> LawValue {
        smoothed_complementarity(gap, force, a_c, smoothing)
    }

    fn sample(&self, gaps: &[f64], forces: &[f64], a_c: f64, smoothing: f64, out: LawSamples<'_>) {
        complementarity_samples(gaps, forces, a_c, smoothing, out);
    }
}
