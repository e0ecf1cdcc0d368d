//! Linear end conditions: one row per harmonic.

use super::{BoundaryCondition, LinearRows, Quantity, Term, TimeDomainForm};
use crate::bar::EndRef;
use crate::check::positive;
use crate::error::ModelError;

/// Clamped end: `u = 0`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dirichlet {
    /// The end.
    pub end: EndRef,
}

impl Dirichlet {
    /// Clamps `end`.
    pub fn new(end: EndRef) -> Self {
        Self { end }
    }
}

impl BoundaryCondition for Dirichlet {
    fn name(&self) -> String {
        format!("Dirichlet at {}", self.end)
    }
    fn ends(&self) -> Vec<EndRef> {
        vec![self.end]
    }
    fn linear_rows(&self, _: f64, _: &dyn Fn(EndRef) -> f64, rows: &mut LinearRows) {
        rows.push(&[Term::new(self.end, Quantity::Displacement, 1.0)]);
    }
    fn time_domain_form(&self) -> Option<TimeDomainForm> {
        Some(TimeDomainForm::Clamped { end: self.end })
    }
}

/// Free end: `u_x = 0`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Neumann {
    /// The end.
    pub end: EndRef,
}

impl Neumann {
    /// Frees `end`.
    pub fn new(end: EndRef) -> Self {
        Self { end }
    }
}

impl BoundaryCondition for Neumann {
    fn name(&self) -> String {
        format!("Neumann at {}", self.end)
    }
    fn ends(&self) -> Vec<EndRef> {
        vec![self.end]
    }
    fn linear_rows(&self, _: f64, _: &dyn Fn(EndRef) -> f64, rows: &mut LinearRows) {
        rows.push(&[Term::new(self.end, Quantity::OutwardStrain, 1.0)]);
    }
    fn time_domain_form(&self) -> Option<TimeDomainForm> {
        Some(TimeDomainForm::Free { end: self.end })
    }
}

/// End on a ground spring of stiffness `k_s`: `EA p + k_s u = 0` (the paper's
/// `-u_x(0) + k u(0) = 0` for a left end with `EA = 1`). The spring stores `k_s u^2 / 2`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Robin {
    /// The end.
    pub end: EndRef,
    stiffness: f64,
}

impl Robin {
    /// A spring of stiffness `k_s` between `end` and the ground.
    ///
    /// # Errors
    /// [`ModelError::NotPositive`] if `k_s` is not positive and finite (use [`Neumann`] for
    /// `k_s = 0`).
    pub fn new(end: EndRef, spring_stiffness: f64) -> Result<Self, ModelError> {
        Ok(Self {
            end,
            stiffness: positive("Robin spring stiffness", spring_stiffness)?,
        })
    }

    /// The spring stiffness `k_s`.
    pub fn spring_stiffness(&self) -> f64 {
        self.stiffness
    }
}

impl BoundaryCondition for Robin {
    fn name(&self) -> String {
        format!("Robin (k = {}) at {}", self.stiffness, self.end)
    }
    fn ends(&self) -> Vec<EndRef> {
        vec![self.end]
    }
    fn validate(&self) -> Result<(), ModelError> {
        positive("Robin spring stiffness", self.stiffness).map(|_| ())
    }
    fn linear_rows(&self, _: f64, stiffness: &dyn Fn(EndRef) -> f64, rows: &mut LinearRows) {
        rows.push(&[
            Term::new(self.end, Quantity::OutwardStrain, stiffness(self.end)),
            Term::new(self.end, Quantity::Displacement, self.stiffness),
        ]);
    }
    fn stored_energy(&self, value: &dyn Fn(EndRef, Quantity) -> f64) -> f64 {
        let u = value(self.end, Quantity::Displacement);
        0.5 * self.stiffness * u * u
    }
    fn time_domain_form(&self) -> Option<TimeDomainForm> {
        Some(TimeDomainForm::Spring {
            end: self.end,
            stiffness: self.stiffness,
        })
    }
}
