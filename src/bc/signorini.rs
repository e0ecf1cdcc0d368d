//! An end facing a rigid obstacle.

use super::{
    complementarity_samples, smoothed_complementarity, BoundaryCondition, LawSamples, LawValue,
    Observable, Quantity, Term, TimeDomainForm, UnilateralLaw,
};
use crate::bar::EndRef;
use crate::check::positive;
use crate::error::ModelError;

/// Rigid obstacle at distance `g0` from an end: gap `g = g0 - v` (`v` the outward
/// displacement), force `lambda = -EA u_x`, and `g >= 0, lambda >= 0, g lambda = 0`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Signorini {
    /// The end.
    pub end: EndRef,
    gap: f64,
}

impl Signorini {
    /// An obstacle at gap `g0 > 0` from `end`.
    ///
    /// # Errors
    /// [`ModelError::NotPositive`] if `g0` is not positive and finite.
    pub fn new(end: EndRef, gap: f64) -> Result<Self, ModelError> {
        Ok(Self {
            end,
            gap: positive("Signorini gap", gap)?,
        })
    }

    /// The gap at rest `g0`.
    pub fn initial_gap(&self) -> f64 {
        self.gap
    }
}

impl BoundaryCondition for Signorini {
    fn name(&self) -> String {
        format!("Signorini (gap {}) at {}", self.gap, self.end)
    }
    fn ends(&self) -> Vec<EndRef> {
        vec![self.end]
    }
    fn validate(&self) -> Result<(), ModelError> {
        positive("Signorini gap", self.gap).map(|_| ())
    }
    fn unilateral(&self) -> Option<&dyn UnilateralLaw> {
        Some(self)
    }
    fn time_domain_form(&self) -> Option<TimeDomainForm> {
        Some(TimeDomainForm::Obstacle {
            end: self.end,
            gap: self.gap,
        })
    }
}

impl UnilateralLaw for Signorini {
    fn gap(&self) -> Observable {
        Observable {
            offset: self.gap,
            terms: vec![Term::new(self.end, Quantity::OutwardDisplacement, -1.0)],
        }
    }
    fn force(&self) -> Observable {
        Observable {
            offset: 0.0,
            terms: vec![Term::new(self.end, Quantity::ContactForce, 1.0)],
        }
    }
    fn smoothed_residual(&self, gap: f64, force: f64, a_c: f64, smoothing: f64) -> LawValue {
        smoothed_complementarity(gap, force, a_c, smoothing)
    }

    fn sample(&self, gaps: &[f64], forces: &[f64], a_c: f64, smoothing: f64, out: LawSamples<'_>) {
        complementarity_samples(gaps, forces, a_c, smoothing, out);
    }
}
