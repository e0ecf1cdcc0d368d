//! Assembly builder and validated bar system.

use crate::bar::{Bar, BarId, EndRef};
use crate::bc::{BoundaryCondition, Contact, Dirichlet, Neumann, Robin, Signorini, UnilateralLaw};
use crate::error::ModelError;
use std::collections::BTreeMap;
use std::sync::Arc;

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
    /// its rows and law do not give one equation per end. The builder is then unchanged.
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
    /// builder and are distinct, and that it gives one equation per end.
    fn check(&self, condition: &dyn BoundaryCondition) -> Result<(), ModelError> {
        condition.validate()?;
        let ends = condition.ends();
        for (i, end) in ends.iter().enumerate() {
            if end.bar.0 >= self.bars.len() {
                return Err(ModelError::UnknownBar {
                    condition: condition.name(),
                    bar: end.bar.0,
                    bars: self.bars.len(),
                });
            }
            if ends[..i].contains(end) {
                return Err(ModelError::RepeatedEnd {
                    condition: condition.name(),
                    end: *end,
                });
            }
        }
        let mut rows = crate::bc::LinearRows::new();
        condition.linear_rows(1.0, &|e| self.bars[e.bar.0].stiffness(), &mut rows);
        let laws = usize::from(condition.unilateral().is_some());
        if rows.len() + laws != ends.len() {
            return Err(ModelError::EquationCount {
                condition: condition.name(),
                ends: ends.len(),
                rows: rows.len(),
                laws,
            });
        }
        Ok(())
    }

    /// Validates and builds: every end of every bar has exactly one condition, and every
    /// condition passes the checks of [`AssemblyBuilder::add_condition`] again.
    ///
    /// # Errors
    /// The first [`ModelError`] found, naming the offending end or condition:
    /// [`ModelError::NoBars`], [`ModelError::OverconstrainedEnd`],
    /// [`ModelError::UnconstrainedEnd`].
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
        })
    }
}

/// A validated assembly of bars and boundary conditions. Cheap to clone (conditions are
/// shared).
#[derive(Debug, Clone)]
pub struct BarSystem {
    bars: Vec<Bar>,
    conditions: Vec<Arc<dyn BoundaryCondition>>,
}

impl BarSystem {
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
