//! Assembly builder and validated bar system.

use crate::bar::{Bar, BarId, EndRef};
use crate::bc::{
    BoundaryCondition, Contact, Dirichlet, Neumann, Robin, Signorini, Term, UnilateralLaw,
};
use crate::error::ModelError;
use crate::system::spectra::Spectra;
use std::cell::Cell;
use std::collections::BTreeMap;
use std::sync::{Arc, Weak};

/// Collects bars and boundary conditions; [`AssemblyBuilder::build`] validates them.
///
/// Every condition method checks, when it is called, what the condition alone determines:
/// its parameters (positive and finite values), that each end it lists belongs to a bar
/// already added to this builder and is listed once, and that it gives one equation per end.
/// A rejected condition is not added, and the error comes back at the call, so a chain stops
/// at the first bad link with `?`. [`AssemblyBuilder::build`] checks what only the whole set
/// determines: every end of every bar has exactly one condition.
///
/// ```
/// use nonsmooth_modes::bar::Bar;
/// use nonsmooth_modes::system::AssemblyBuilder;
///
/// let mut b = AssemblyBuilder::new();
/// let bar = b.add_bar(Bar::unit());
/// b.dirichlet(bar.left())?.signorini(bar.right(), 1e-3)?;
/// let system = b.build()?;
/// assert_eq!(system.contact_count(), 1);
/// # Ok::<(), nonsmooth_modes::ModelError>(())
/// ```
#[derive(Debug, Default, Clone)]
pub struct AssemblyBuilder {
    bars: Vec<Bar>,
    conditions: Vec<Arc<dyn BoundaryCondition>>,
}

impl AssemblyBuilder {
    /// An empty assembly.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds a bar and returns its id.
    pub fn add_bar(&mut self, bar: Bar) -> BarId {
        self.bars.push(bar);
        BarId(self.bars.len() - 1)
    }

    /// Adds any boundary condition, built-in or downstream, after checking it on its own
    /// (see the type's documentation).
    ///
    /// # Errors
    /// The error of the condition's [`BoundaryCondition::validate`];
    /// [`ModelError::UnknownBar`] if it lists an end of a bar this builder has not added,
    /// [`ModelError::RepeatedEnd`] if it lists an end twice, [`ModelError::EquationCount`] if
    /// its rows and law do not give one equation per end (at `omega = 0` or `1`);
    /// [`ModelError::UnknownBar`] too if a row, an observable, a stiffness it reads or its
    /// stored energy names an end of another bar, and [`ModelError::NonFiniteCoefficient`] if
    /// one of these numbers is not finite. The builder is then unchanged.
    pub fn add_condition(
        &mut self,
        condition: impl BoundaryCondition + 'static,
    ) -> Result<&mut Self, ModelError> {
        self.check(&condition)?;
        self.conditions.push(Arc::new(condition));
        Ok(self)
    }

    /// Clamps `end` ([`Dirichlet`]).
    ///
    /// # Errors
    /// [`ModelError::UnknownBar`] if `end` is not an end of a bar added to this builder.
    pub fn dirichlet(&mut self, end: EndRef) -> Result<&mut Self, ModelError> {
        self.add_condition(Dirichlet::new(end))
    }

    /// Frees `end` ([`Neumann`]).
    ///
    /// # Errors
    /// [`ModelError::UnknownBar`] if `end` is not an end of a bar added to this builder.
    pub fn neumann(&mut self, end: EndRef) -> Result<&mut Self, ModelError> {
        self.add_condition(Neumann::new(end))
    }

    /// Ground spring at `end` ([`Robin`]).
    ///
    /// # Errors
    /// [`ModelError::NotPositive`] if the stiffness is not positive and finite,
    /// [`ModelError::UnknownBar`] if `end` is not an end of a bar added to this builder.
    pub fn robin(&mut self, end: EndRef, stiffness: f64) -> Result<&mut Self, ModelError> {
        self.add_condition(Robin::new(end, stiffness)?)
    }

    /// Rigid obstacle at `gap` from `end` ([`Signorini`]).
    ///
    /// # Errors
    /// [`ModelError::NotPositive`] if the gap is not positive and finite,
    /// [`ModelError::UnknownBar`] if `end` is not an end of a bar added to this builder.
    pub fn signorini(&mut self, end: EndRef, gap: f64) -> Result<&mut Self, ModelError> {
        self.add_condition(Signorini::new(end, gap)?)
    }

    /// Unilateral contact between two ends ([`Contact`]).
    ///
    /// # Errors
    /// [`ModelError::NotPositive`] if the gap is not positive and finite,
    /// [`ModelError::UnknownBar`] if an end is not an end of a bar added to this builder,
    /// [`ModelError::RepeatedEnd`] if `first == second`.
    pub fn contact(
        &mut self,
        first: EndRef,
        second: EndRef,
        gap: f64,
    ) -> Result<&mut Self, ModelError> {
        self.add_condition(Contact::new(first, second, gap)?)
    }

    /// Checks one condition on its own: its parameters, that its ends belong to bars of this
    /// builder and are distinct, and what it gives at the constant term and at one harmonic
    /// (`omega = 0` and `1`): one equation per end, finite coefficients on ends of this
    /// builder's bars (its rows, its law's observables and its stored energy are read through
    /// guards, so a condition written downstream that names a foreign end gets a typed error
    /// here instead of a panic later).
    fn check(&self, condition: &dyn BoundaryCondition) -> Result<(), ModelError> {
        condition.validate()?;
        let ends = condition.ends();
        for (i, end) in ends.iter().enumerate() {
            self.known(condition, *end)?;
            if ends[..i].contains(end) {
                return Err(ModelError::RepeatedEnd {
                    condition: condition.name(),
                    end: *end,
                });
            }
        }
        let law = condition.unilateral();
        let laws = usize::from(law.is_some());
        let mut rows = crate::bc::LinearRows::new();
        for omega in [0.0, 1.0] {
            let read = Cell::new(None);
            let stiffness = |e: EndRef| self.guarded(e, &read, |bar| bar.stiffness());
            rows.clear();
            condition.linear_rows(omega, &stiffness, &mut rows);
            self.read_known(condition, &read)?;
            if rows.len() + laws != ends.len() {
                return Err(ModelError::EquationCount {
                    condition: condition.name(),
                    ends: ends.len(),
                    rows: rows.len(),
                    laws,
                });
            }
            for r in 0..rows.len() {
                self.check_terms(condition, "linear-row coefficient", rows.row(r))?;
            }
        }
        if let Some(law) = law {
            for (what, observable) in [
                ("gap observable", law.gap()),
                ("contact-force observable", law.force()),
            ] {
                finite(condition, what, observable.offset)?;
                self.check_terms(condition, what, &observable.terms)?;
            }
        }
        let read = Cell::new(None);
        let energy = condition.stored_energy(&|e, _| self.guarded(e, &read, |_| 1.0));
        self.read_known(condition, &read)?;
        finite(condition, "stored energy", energy)
    }

    /// [`ModelError::UnknownBar`] unless `end` is an end of a bar of this builder.
    fn known(&self, condition: &dyn BoundaryCondition, end: EndRef) -> Result<(), ModelError> {
        if end.bar.0 < self.bars.len() {
            Ok(())
        } else {
            Err(ModelError::UnknownBar {
                condition: condition.name(),
                bar: end.bar.0,
                bars: self.bars.len(),
            })
        }
    }

    /// `value(bar of end)`, or `1.0` with `end` remembered in `read` when its bar is unknown
    /// (for the closures handed to a condition, which cannot return an error).
    fn guarded(
        &self,
        end: EndRef,
        read: &Cell<Option<EndRef>>,
        value: impl Fn(&Bar) -> f64,
    ) -> f64 {
        match self.bars.get(end.bar.0) {
            Some(bar) => value(bar),
            None => {
                read.set(Some(end));
                1.0
            }
        }
    }

    /// The error of [`AssemblyBuilder::known`] for an end remembered by
    /// [`AssemblyBuilder::guarded`].
    fn read_known(
        &self,
        condition: &dyn BoundaryCondition,
        read: &Cell<Option<EndRef>>,
    ) -> Result<(), ModelError> {
        read.get().map_or(Ok(()), |end| self.known(condition, end))
    }

    /// Every term is on an end of this builder's bars, with a finite coefficient and
    /// derivative.
    fn check_terms(
        &self,
        condition: &dyn BoundaryCondition,
        what: &'static str,
        terms: &[Term],
    ) -> Result<(), ModelError> {
        for t in terms {
            self.known(condition, t.end)?;
            finite(condition, what, t.coefficient)?;
            finite(condition, what, t.d_coefficient)?;
        }
        Ok(())
    }

    /// Validates and builds: every end of every bar has exactly one condition, and every
    /// condition passes the checks of [`AssemblyBuilder::add_condition`] again.
    ///
    /// # Errors
    /// The first [`ModelError`] found, naming the offending end or condition:
    /// [`ModelError::NoBars`], [`ModelError::OverconstrainedEnd`],
    /// [`ModelError::UnconstrainedEnd`], and the errors of
    /// [`AssemblyBuilder::add_condition`].
    pub fn build(&self) -> Result<BarSystem, ModelError> {
        if self.bars.is_empty() {
            return Err(ModelError::NoBars);
        }
        let mut owner: BTreeMap<EndRef, usize> = BTreeMap::new();
        for (index, condition) in self.conditions.iter().enumerate() {
            self.check(condition.as_ref())?;
            for end in condition.ends() {
                if let Some(&first) = owner.get(&end) {
                    return Err(ModelError::OverconstrainedEnd {
                        end,
                        first: self.conditions[first].name(),
                        second: condition.name(),
                    });
                }
                owner.insert(end, index);
            }
        }
        for b in 0..self.bars.len() {
            let id = BarId(b);
            for end in [id.left(), id.right()] {
                if !owner.contains_key(&end) {
                    return Err(ModelError::UnconstrainedEnd { end });
                }
            }
        }
        Ok(BarSystem {
            bars: self.bars.clone(),
            conditions: self.conditions.clone(),
            spectra: Arc::default(),
        })
    }
}

/// [`ModelError::NonFiniteCoefficient`] unless `value` is finite.
fn finite(
    condition: &dyn BoundaryCondition,
    what: &'static str,
    value: f64,
) -> Result<(), ModelError> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(ModelError::NonFiniteCoefficient {
            condition: condition.name(),
            what,
            value,
        })
    }
}

/// A validated assembly of bars and boundary conditions. Cheap to clone (conditions are
/// shared).
#[derive(Debug, Clone)]
pub struct BarSystem {
    bars: Vec<Bar>,
    conditions: Vec<Arc<dyn BoundaryCondition>>,
    /// Natural-frequency scans of this system, shared by its clones (built fresh with new
    /// conditions).
    spectra: Arc<Spectra>,
}

impl BarSystem {
    /// The same bars with each condition replaced by `f` of it (a condition that keeps the
    /// ends and the equation count of the one it replaces, as the crate's own auxiliary
    /// systems do).
    pub(crate) fn map_conditions(
        &self,
        f: impl FnMut(&Arc<dyn BoundaryCondition>) -> Arc<dyn BoundaryCondition>,
    ) -> BarSystem {
        BarSystem {
            bars: self.bars.clone(),
            conditions: self.conditions.iter().map(f).collect(),
            spectra: Arc::default(),
        }
    }

    /// The natural-frequency scans of this system ([`Spectra`]).
    pub(crate) fn spectra(&self) -> &Spectra {
        &self.spectra
    }

    /// What identifies the bars and conditions of this system among those built: the same
    /// handle ([`Weak::ptr_eq`]) for its clones, another for any other system, even one built
    /// after this one is dropped while the handle lives.
    pub(crate) fn identity(&self) -> Weak<Spectra> {
        Arc::downgrade(&self.spectra)
    }

    /// The bars, in the order they were added.
    pub fn bars(&self) -> &[Bar] {
        &self.bars
    }

    /// The ids of the bars, in the order they were added (bar `i` has index `i`).
    pub fn bar_ids(&self) -> impl Iterator<Item = BarId> {
        (0..self.bars.len()).map(BarId)
    }

    /// The id of bar number `index`, if the system has that many bars (for systems built
    /// elsewhere, such as the [`crate::reference`] systems).
    pub fn bar_id(&self, index: usize) -> Option<BarId> {
        (index < self.bars.len()).then_some(BarId(index))
    }

    /// The bar with id `id`.
    ///
    /// # Panics
    /// If `id` was minted by another assembly with more bars.
    pub fn bar(&self, id: BarId) -> &Bar {
        &self.bars[id.0]
    }

    /// Every boundary condition.
    pub fn conditions(&self) -> impl Iterator<Item = &dyn BoundaryCondition> {
        self.conditions.iter().map(|c| c.as_ref())
    }

    /// The unilateral laws, in condition order.
    pub fn laws(&self) -> impl Iterator<Item = &dyn UnilateralLaw> {
        self.conditions.iter().filter_map(|c| c.unilateral())
    }

    /// Number of unilateral conditions (contacts and obstacles).
    pub fn contact_count(&self) -> usize {
        self.laws().count()
    }

    /// Axial stiffness of the bar owning `end`.
    ///
    /// # Panics
    /// If `end` belongs to a bar this system does not have (an id minted by another builder
    /// with more bars). The ends that the system's own conditions name are all checked by
    /// [`AssemblyBuilder::build`].
    pub fn stiffness_at(&self, end: EndRef) -> f64 {
        self.bars[end.bar.0].stiffness()
    }

    /// Number of Helmholtz unknowns per harmonic: `(A, B)` for each bar.
    pub fn unknowns_per_harmonic(&self) -> usize {
        2 * self.bars.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ids_of_a_built_system() {
        let system = crate::reference::two_bars_in_contact(Bar::unit(), 1e-3).unwrap();
        let ids: Vec<BarId> = system.bar_ids().collect();
        assert_eq!(ids.len(), 2);
        assert_eq!(system.bar_id(1), Some(ids[1]));
        assert_eq!(system.bar_id(2), None);
        assert_eq!(system.bar(ids[0]).length(), 1.0);
    }

    #[test]
    fn names_the_offending_end() {
        let mut b = AssemblyBuilder::new();
        let bar = b.add_bar(Bar::unit());
        b.dirichlet(bar.left()).unwrap();
        assert_eq!(
            b.build().unwrap_err(),
            ModelError::UnconstrainedEnd { end: bar.right() }
        );
        b.neumann(bar.right())
            .unwrap()
            .neumann(bar.right())
            .unwrap();
        assert!(matches!(
            b.build(),
            Err(ModelError::OverconstrainedEnd { end, .. }) if end == bar.right()
        ));
    }
}
