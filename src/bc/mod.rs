//! Boundary conditions: one trait, five built-in conditions, and the shared complementarity law.
//!
//! A condition constrains one or more bar ends and gives, per end, one equation: either a
//! **linear row** per harmonic (Dirichlet, Neumann, Robin, the force balance of a contact) or a
//! **unilateral law** enforced in time (Signorini, contact). Rows and laws are written with
//! [`Term`]s on end [`Quantity`]s, so a condition never sees the harmonic-balance unknowns and a
//! downstream crate can add its own condition by implementing [`BoundaryCondition`] (and
//! [`UnilateralLaw`] for a nonsmooth one).
//!
//! A condition also declares how it acts in time ([`TimeDomainForm`], through
//! [`BoundaryCondition::time_domain_form`]): the end rule the exact time-domain check
//! ([`crate::verify`]) marches for it. Every built-in condition declares its own; a
//! condition written downstream declares none unless it says so, and the check then reports
//! the system unchecked instead of marching another law than the one that was solved.

mod contact;
mod form;
mod law;
mod linear;
mod signorini;

pub use contact::Contact;
pub use form::TimeDomainForm;
pub use law::{
    complementarity, complementarity_samples, smoothed_complementarity, LawSamples, LawValue,
    Observable, UnilateralLaw,
};
pub use linear::{Dirichlet, Neumann, Robin};
pub use signorini::Signorini;

use crate::bar::EndRef;
use crate::error::ModelError;
use std::fmt::Debug;

/// A physical quantity at a bar end, at one harmonic or at one instant.
///
/// With outward normal `n` (`-1` at `x = 0`, `+1` at `x = l`):
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Quantity {
    /// Displacement `u`.
    Displacement,
    /// Outward displacement `v = n u` (towards an obstacle facing the end).
    OutwardDisplacement,
    /// Strain `u_x`.
    Strain,
    /// Outward strain `p = n u_x` (the BEM flux; the paper's `p`).
    OutwardStrain,
    /// Compressive force `lambda = -EA u_x` that the end exerts on what it touches
    /// (positive in compression, at either end).
    ContactForce,
}

/// One term `coefficient * quantity(end)` of a linear row or an observable.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Term {
    /// The end.
    pub end: EndRef,
    /// The quantity at that end.
    pub quantity: Quantity,
    /// Its coefficient.
    pub coefficient: f64,
    /// Derivative of the coefficient with respect to the harmonic's angular frequency
    /// (zero for every built-in condition; an end mass would give `-m 2 omega`).
    pub d_coefficient: f64,
}

impl Term {
    /// A frequency-independent term.
    pub fn new(end: EndRef, quantity: Quantity, coefficient: f64) -> Self {
        Self {
            end,
            quantity,
            coefficient,
            d_coefficient: 0.0,
        }
    }
}

/// Rows collected from conditions: a flat list of terms with row boundaries.
#[derive(Debug, Clone, Default)]
pub struct LinearRows {
    terms: Vec<Term>,
    starts: Vec<usize>,
}

impl LinearRows {
    /// An empty collection.
    pub fn new() -> Self {
        Self::default()
    }

    /// Appends the row `sum(terms) = 0`.
    pub fn push(&mut self, terms: &[Term]) {
        self.starts.push(self.terms.len());
        self.terms.extend_from_slice(terms);
    }

    /// Number of rows.
    pub fn len(&self) -> usize {
        self.starts.len()
    }

    /// Whether there is no row.
    pub fn is_empty(&self) -> bool {
        self.starts.is_empty()
    }

    /// The terms of row `i`.
    ///
    /// # Panics
    /// If `i >= self.len()`.
    pub fn row(&self, i: usize) -> &[Term] {
        let end = self.starts.get(i + 1).copied().unwrap_or(self.terms.len());
        &self.terms[self.starts[i]..end]
    }

    /// Removes every row.
    pub fn clear(&mut self) {
        self.terms.clear();
        self.starts.clear();
    }
}

/// A boundary condition on one or more bar ends.
///
/// Every end it lists needs one equation: `linear_rows` must push as many rows as
/// `ends().len()` minus one if it has a unilateral law, minus zero otherwise, at every
/// `omega`. Its rows, observables, stiffness reads and stored energy may name only ends of the
/// assembly's bars, with finite coefficients. The assembly checks all this at `omega = 0` and
/// `omega = 1` ([`crate::system::AssemblyBuilder::add_condition`]); a condition that changes
/// its ends or its row count with `omega` breaks the contract and may panic later.
///
/// # Example: a condition written outside the crate
///
/// ```
/// use nonsmooth_modes::bar::EndRef;
/// use nonsmooth_modes::bc::{BoundaryCondition, LinearRows, Quantity, Term};
///
/// /// End held by a massless dashpot-free spring to a moving-with-the-end reference:
/// /// here simply `u = 2 p` (an arbitrary linear law).
/// #[derive(Debug)]
/// struct MyCondition(EndRef);
///
/// impl BoundaryCondition for MyCondition {
///     fn name(&self) -> String { format!("my condition at {}", self.0) }
///     fn ends(&self) -> Vec<EndRef> { vec![self.0] }
///     fn linear_rows(&self, _omega: f64, _stiffness: &dyn Fn(EndRef) -> f64, rows: &mut LinearRows) {
///         rows.push(&[
///             Term::new(self.0, Quantity::Displacement, 1.0),
///             Term::new(self.0, Quantity::OutwardStrain, -2.0),
///         ]);
///     }
/// }
/// ```
pub trait BoundaryCondition: Debug + Send + Sync {
    /// A short description used in error messages.
    fn name(&self) -> String;

    /// The ends it constrains.
    fn ends(&self) -> Vec<EndRef>;

    /// Checks the condition's own parameters (called by the assembly builder).
    fn validate(&self) -> Result<(), ModelError> {
        Ok(())
    }

    /// Pushes the linear rows that hold for every harmonic of angular frequency `omega`
    /// (`omega = 0` for the constant term). `stiffness(end)` gives the axial stiffness of the
    /// bar that owns `end`.
    fn linear_rows(&self, omega: f64, stiffness: &dyn Fn(EndRef) -> f64, rows: &mut LinearRows) {
        let _ = (omega, stiffness, rows);
    }

    /// The unilateral law it enforces in time, if any.
    fn unilateral(&self) -> Option<&dyn UnilateralLaw> {
        None
    }

    /// Potential energy stored in the condition itself (a spring) at one instant of a motion,
    /// whose end quantities are `value(end, quantity)` (displacement, strain, contact force,
    /// ...); zero by default.
    ///
    /// A linear condition's energy should be a quadratic form of the displacements: the
    /// grazing energy `E_g` ([`crate::modal::grazing_energy`]) evaluates it on unit-sized
    /// linear mode shapes and scales quadratically. A unilateral condition is left out of
    /// `E_g` (its contact is open in the linear modes); its spring, if it has one, should
    /// write its energy from the force it carries, `lambda^2 / (2 k)` for a compliant obstacle
    /// of stiffness `k`: that energy tends to zero as `k` grows, as the rigid obstacle's,
    /// whereas `k p^2 / 2` of the harmonic-balance penetration `p` (an approximation error)
    /// does not.
    fn stored_energy(&self, value: &dyn Fn(EndRef, Quantity) -> f64) -> f64 {
        let _ = value;
        0.0
    }

    /// The law the condition enforces in time, as one of the end rules of the exact
    /// integrator ([`TimeDomainForm`]); `None` (the default) if it has none of those forms.
    ///
    /// The time-domain check ([`crate::verify::periodicity_check`], the `check` of a
    /// [`Request`](crate::branches::Request)) marches exactly the declared forms: a system
    /// with a condition that declares none is not marched (the check says it is unchecked,
    /// naming the condition), because its rows and residual do not determine the law in time
    /// (a penalty residual and Signorini's share their observables). The form must be the
    /// same law as the rows and the residual, with the same parameters, and act on
    /// [`BoundaryCondition::ends`]: the check verifies a motion of the declared law, so a
    /// form that differs from the law solved makes it judge another system.
    ///
    /// ```
    /// use nonsmooth_modes::bar::{Bar, EndRef};
    /// use nonsmooth_modes::bc::{BoundaryCondition, LinearRows, Quantity, Term, TimeDomainForm};
    /// use nonsmooth_modes::system::AssemblyBuilder;
    /// use nonsmooth_modes::verify::{Condition, Model};
    ///
    /// /// A clamped end written downstream: the row `u = 0`, and in time the clamped rule.
    /// #[derive(Debug)]
    /// struct Pinned(EndRef);
    ///
    /// impl BoundaryCondition for Pinned {
    ///     fn name(&self) -> String { format!("pinned at {}", self.0) }
    ///     fn ends(&self) -> Vec<EndRef> { vec![self.0] }
    ///     fn linear_rows(&self, _: f64, _: &dyn Fn(EndRef) -> f64, rows: &mut LinearRows) {
    ///         rows.push(&[Term::new(self.0, Quantity::Displacement, 1.0)]);
    ///     }
    ///     fn time_domain_form(&self) -> Option<TimeDomainForm> {
    ///         Some(TimeDomainForm::Clamped { end: self.0 })
    ///     }
    /// }
    ///
    /// let mut b = AssemblyBuilder::new();
    /// let bar = b.add_bar(Bar::unit());
    /// b.add_condition(Pinned(bar.left()))?.signorini(bar.right(), 1e-3)?;
    /// let model = Model::from_system(&b.build()?)?;
    /// assert_eq!(model.conditions()[0], Condition::Clamped { end: bar.left() });
    /// # Ok::<(), nonsmooth_modes::Error>(())
    /// ```
    fn time_domain_form(&self) -> Option<TimeDomainForm> {
        None
    }
}
