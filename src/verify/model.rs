//! The assembly as the integrator sees it: bars and one exact end rule per condition, the
//! time-domain form each condition declares.

use super::VerifyError;
use crate::bar::{Bar, BarId, End};
use crate::bc::{BoundaryCondition, TimeDomainForm};
use crate::error::ModelError;
use crate::system::BarSystem;

/// An end rule the integrator advances (see the [module docs](super)): the time-domain form a
/// condition declares ([`TimeDomainForm`]), gaps of any sign allowed.
pub type Condition = TimeDomainForm;

/// Bars and exact end rules: the input of the integrator.
///
/// Build it from a validated [`BarSystem`] with [`Model::from_system`], or directly with
/// [`Model::new`] (which, unlike the harmonic-balance conditions, accepts gaps `g0 <= 0`).
#[derive(Debug, Clone, PartialEq)]
pub struct Model {
    bars: Vec<Bar>,
    conditions: Vec<Condition>,
}

impl Model {
    /// Bars and conditions given directly. Bar ids are minted by
    /// [`AssemblyBuilder::add_bar`](crate::system::AssemblyBuilder::add_bar) (bar `i` is the
    /// `i`-th bar added); the simplest route is often [`Model::from_system`] followed by
    /// [`Model::with_gap`].
    ///
    /// # Errors
    /// [`ModelError::NoBars`], [`ModelError::UnknownBar`], [`ModelError::RepeatedEnd`],
    /// [`ModelError::OverconstrainedEnd`], [`ModelError::UnconstrainedEnd`] (wrapped in
    /// [`VerifyError::Model`]) for a malformed assembly; [`VerifyError::InvalidParameter`] for a
    /// non-finite gap or a spring stiffness that is not positive and finite.
    pub fn new(bars: Vec<Bar>, conditions: Vec<Condition>) -> Result<Self, VerifyError> {
        if bars.is_empty() {
            return Err(ModelError::NoBars.into());
        }
        let mut owner: Vec<[Option<usize>; 2]> = vec![[None, None]; bars.len()];
        for (index, c) in conditions.iter().enumerate() {
            match *c {
                Condition::Spring { stiffness, .. }
                | Condition::CompliantObstacle { stiffness, .. }
                    if !(stiffness.is_finite() && stiffness > 0.0) =>
                {
                    return Err(VerifyError::InvalidParameter {
                        what: "spring stiffness",
                        value: stiffness,
                    })
                }
                Condition::Obstacle { gap, .. }
                | Condition::CompliantObstacle { gap, .. }
                | Condition::Contact { gap, .. }
                    if !gap.is_finite() =>
                {
                    return Err(VerifyError::InvalidParameter {
                        what: "contact gap",
                        value: gap,
                    })
                }
                _ => {}
            }
            let ends = c.ends();
            for (i, end) in ends.iter().enumerate() {
                let b = end.bar.index();
                if b >= bars.len() {
                    return Err(ModelError::UnknownBar {
                        condition: c.name(),
                        bar: b,
                        bars: bars.len(),
                    }
                    .into());
                }
                if ends[..i].contains(end) {
                    return Err(ModelError::RepeatedEnd {
                        condition: c.name(),
                        end: *end,
                    }
                    .into());
                }
                let slot = &mut owner[b][usize::from(end.end == End::Right)];
                if let Some(first) = *slot {
                    return Err(ModelError::OverconstrainedEnd {
                        end: *end,
                        first: conditions[first].name(),
                        second: c.name(),
                    }
                    .into());
                }
                *slot = Some(index);
            }
        }
        for (b, o) in owner.iter().enumerate() {
            let id = BarId(b);
            for (slot, end) in o.iter().zip([id.left(), id.right()]) {
                if slot.is_none() {
                    return Err(ModelError::UnconstrainedEnd { end }.into());
                }
            }
        }
        Ok(Self { bars, conditions })
    }

    /// The bars of `system` and the time-domain form each of its conditions declares
    /// ([`BoundaryCondition::time_domain_form`]). Nothing is inferred from a condition's rows
    /// or observables: a residual is opaque, and the same observables serve a rigid obstacle
    /// and a penalty law.
    ///
    /// # Errors
    /// [`VerifyError::NoTimeDomainForm`] naming the first condition that declares no form;
    /// [`VerifyError::Unsupported`] for a form on other ends than its condition's; those of
    /// [`Model::new`] for a form with bad parameters.
    pub fn from_system(system: &BarSystem) -> Result<Self, VerifyError> {
        let conditions = system
            .conditions()
            .map(declared)
            .collect::<Result<Vec<_>, _>>()?;
        Self::new(system.bars().to_vec(), conditions)
    }

    /// A unit bar clamped at `x = 0` facing a rigid obstacle at gap `g0` (any finite value) at
    /// `x = 1`: the system of [`reference::clamped_bar_with_obstacle`](crate::reference::clamped_bar_with_obstacle)
    /// without the restriction `g0 > 0`.
    ///
    /// # Errors
    /// [`VerifyError::InvalidParameter`] if `g0` is not finite.
    pub fn clamped_bar_with_obstacle(gap: f64) -> Result<Self, VerifyError> {
        let bar = BarId(0);
        Self::new(
            vec![Bar::unit()],
            vec![
                Condition::Clamped { end: bar.left() },
                Condition::Obstacle {
                    end: bar.right(),
                    gap,
                },
            ],
        )
    }

    /// The same model with the gap of condition `index` (an obstacle, rigid or compliant, or a
    /// contact) set to
    /// `gap`, which may be zero or negative.
    ///
    /// # Errors
    /// [`VerifyError::InvalidParameter`] if `index` is not a unilateral condition or `gap` is
    /// not finite.
    pub fn with_gap(mut self, index: usize, gap: f64) -> Result<Self, VerifyError> {
        if !gap.is_finite() {
            return Err(VerifyError::InvalidParameter {
                what: "contact gap",
                value: gap,
            });
        }
        match self.conditions.get_mut(index) {
            Some(
                Condition::Obstacle { gap: g, .. }
                | Condition::CompliantObstacle { gap: g, .. }
                | Condition::Contact { gap: g, .. },
            ) => {
                *g = gap;
                Ok(self)
            }
            _ => Err(VerifyError::InvalidParameter {
                what: "index of a unilateral condition",
                value: index as f64,
            }),
        }
    }

    /// The bars.
    pub fn bars(&self) -> &[Bar] {
        &self.bars
    }

    /// The conditions, in the order of the system they came from.
    pub fn conditions(&self) -> &[Condition] {
        &self.conditions
    }
}

/// The form `c` declares, on its own ends.
fn declared(c: &dyn BoundaryCondition) -> Result<Condition, VerifyError> {
    let form = c
        .time_domain_form()
        .ok_or_else(|| VerifyError::NoTimeDomainForm {
            condition: c.name(),
        })?;
    let (mut own, mut named) = (c.ends(), form.ends());
    own.sort_unstable();
    named.sort_unstable();
    if own != named {
        return Err(VerifyError::Unsupported {
            condition: c.name(),
            reason: "its time-domain form acts on other ends than the condition",
        });
    }
    Ok(form)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bar::EndRef;
    use crate::bc::{LinearRows, Quantity, Term};
    use crate::reference::{
        clamped_bar_with_obstacle, robin_bar_with_obstacle, two_bars_in_contact,
    };
    use crate::system::AssemblyBuilder;

    #[test]
    fn reads_the_built_in_conditions() {
        let m = Model::from_system(&clamped_bar_with_obstacle(0.1).unwrap()).unwrap();
        let bar = BarId(0);
        assert_eq!(
            m.conditions(),
            &[
                Condition::Clamped { end: bar.left() },
                Condition::Obstacle {
                    end: bar.right(),
                    gap: 0.1
                }
            ]
        );
        let m = Model::from_system(&robin_bar_with_obstacle(0.5, 0.2).unwrap()).unwrap();
        assert_eq!(
            m.conditions()[0],
            Condition::Spring {
                end: bar.left(),
                stiffness: 0.5
            }
        );
        let second = Bar::new(0.95, 2.0, 3.0).unwrap();
        let m = Model::from_system(&two_bars_in_contact(second, 0.3).unwrap()).unwrap();
        assert!(matches!(m.conditions()[2], Condition::Contact { gap, .. } if gap == 0.3));
        // Robin at a right end on a stiff bar, Neumann at the left.
        let mut b = AssemblyBuilder::new();
        let id = b.add_bar(Bar::new(1.0, 1.0, 4.0).unwrap());
        b.neumann(id.left())
            .unwrap()
            .robin(id.right(), 2.0)
            .unwrap();
        let m = Model::from_system(&b.build().unwrap()).unwrap();
        assert_eq!(m.conditions()[0], Condition::Free { end: id.left() });
        assert_eq!(
            m.conditions()[1],
            Condition::Spring {
                end: id.right(),
                stiffness: 2.0
            }
        );
    }

    #[derive(Debug)]
    struct EndMass(EndRef);
    impl BoundaryCondition for EndMass {
        fn name(&self) -> String {
            "end mass".into()
        }
        fn ends(&self) -> Vec<EndRef> {
            vec![self.0]
        }
        fn linear_rows(&self, omega: f64, _: &dyn Fn(EndRef) -> f64, rows: &mut LinearRows) {
            rows.push(&[
                Term::new(self.0, Quantity::OutwardStrain, 1.0),
                Term::new(self.0, Quantity::Displacement, -omega * omega),
            ]);
        }
    }

    #[test]
    fn rejects_what_it_cannot_advance() {
        let mut b = AssemblyBuilder::new();
        let id = b.add_bar(Bar::unit());
        b.dirichlet(id.left())
            .unwrap()
            .add_condition(EndMass(id.right()))
            .unwrap();
        let err = Model::from_system(&b.build().unwrap()).unwrap_err();
        assert!(
            matches!(err, VerifyError::NoTimeDomainForm { ref condition } if condition == "end mass")
        );
        let bar = BarId(0);
        assert!(matches!(
            Model::new(
                vec![Bar::unit()],
                vec![Condition::Clamped { end: bar.left() }]
            ),
            Err(VerifyError::Model(ModelError::UnconstrainedEnd { .. }))
        ));
        assert!(matches!(
            Model::clamped_bar_with_obstacle(f64::NAN),
            Err(VerifyError::InvalidParameter { .. })
        ));
        assert!(Model::clamped_bar_with_obstacle(-0.5).is_ok());
    }

    /// A clamped end that declares a form on another end than its own.
    #[derive(Debug)]
    struct Misplaced(EndRef, EndRef);
    impl BoundaryCondition for Misplaced {
        fn name(&self) -> String {
            "misplaced".into()
        }
        fn ends(&self) -> Vec<EndRef> {
            vec![self.0]
        }
        fn linear_rows(&self, _: f64, _: &dyn Fn(EndRef) -> f64, rows: &mut LinearRows) {
            rows.push(&[Term::new(self.0, Quantity::Displacement, 1.0)]);
        }
        fn time_domain_form(&self) -> Option<TimeDomainForm> {
            Some(TimeDomainForm::Clamped { end: self.1 })
        }
    }

    #[test]
    fn a_form_acts_on_its_conditions_ends() {
        let mut b = AssemblyBuilder::new();
        let id = b.add_bar(Bar::unit());
        b.add_condition(Misplaced(id.left(), id.right()))
            .unwrap()
            .signorini(id.right(), 0.1)
            .unwrap();
        let err = Model::from_system(&b.build().unwrap()).unwrap_err();
        assert!(
            matches!(err, VerifyError::Unsupported { ref condition, .. } if condition == "misplaced"),
            "{err}"
        );
        // A compliant obstacle needs a positive, finite stiffness.
        for stiffness in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            let c = Condition::CompliantObstacle {
                end: id.right(),
                gap: 0.1,
                stiffness,
            };
            let model = Model::new(
                vec![Bar::unit()],
                vec![Condition::Free { end: id.left() }, c],
            );
            assert!(matches!(model, Err(VerifyError::InvalidParameter { .. })));
        }
    }
}
