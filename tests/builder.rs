//! The assembly builder: every condition method returns `Result<&mut Self, ModelError>`, so
//! chains go through `?`; what a condition determines alone is rejected at the call, what
//! only the whole set determines at `build`.

use nonsmooth_modes::bar::{Bar, BarId, EndRef};
use nonsmooth_modes::bc::{BoundaryCondition, LinearRows, Quantity, Term};
use nonsmooth_modes::system::{AssemblyBuilder, BarSystem};
use nonsmooth_modes::{Error, ModelError};

/// Values that are not positive, and values that are not finite.
const NOT_POSITIVE: [f64; 3] = [0.0, -0.0, -1.0];
const NOT_FINITE: [f64; 3] = [f64::NAN, f64::INFINITY, f64::NEG_INFINITY];

/// A clamped end written outside the crate: the row `u = 0`.
#[derive(Debug)]
struct Pinned(EndRef);

impl BoundaryCondition for Pinned {
    fn name(&self) -> String {
        format!("pinned at {}", self.0)
    }
    fn ends(&self) -> Vec<EndRef> {
        vec![self.0]
    }
    fn linear_rows(&self, _: f64, _: &dyn Fn(EndRef) -> f64, rows: &mut LinearRows) {
        rows.push(&[Term::new(self.0, Quantity::Displacement, 1.0)]);
    }
}

/// A bar of a builder with three bars: index 2, beyond a one-bar builder.
fn foreign_bar() -> BarId {
    let mut other = AssemblyBuilder::new();
    other.add_bar(Bar::unit());
    other.add_bar(Bar::unit());
    other.add_bar(Bar::unit())
}

/// A one-bar builder and its bar.
fn one_bar() -> (AssemblyBuilder, BarId) {
    let mut b = AssemblyBuilder::new();
    let bar = b.add_bar(Bar::unit());
    (b, bar)
}

fn spring_on_obstacle() -> Result<BarSystem, ModelError> {
    let (mut b, bar) = one_bar();
    b.robin(bar.left(), 0.5)?.signorini(bar.right(), 1e-3)?;
    b.build()
}

#[test]
fn chains_go_through_the_question_mark() -> Result<(), ModelError> {
    let (mut b, bar) = one_bar();
    b.dirichlet(bar.left())?.robin(bar.right(), 0.5)?;
    let system = b.build()?;
    assert_eq!(system.conditions().count(), 2);
    assert_eq!(system.contact_count(), 0);

    let system = spring_on_obstacle()?;
    assert_eq!(system.contact_count(), 1);

    // Every method chains with every other, built-in or downstream.
    let mut b = AssemblyBuilder::new();
    let one = b.add_bar(Bar::unit());
    let two = b.add_bar(Bar::new(0.7, 1.3, 2.0)?);
    let three = b.add_bar(Bar::unit());
    b.dirichlet(one.left())?
        .contact(one.right(), two.left(), 1e-3)?
        .neumann(two.right())?
        .add_condition(Pinned(three.left()))?
        .signorini(three.right(), 2e-3)?;
    let system = b.build()?;
    assert_eq!(system.conditions().count(), 5);
    assert_eq!(system.contact_count(), 2);
    Ok(())
}

#[test]
fn chains_convert_into_the_crate_error() -> Result<(), Error> {
    let (mut b, bar) = one_bar();
    b.neumann(bar.left())?.signorini(bar.right(), 0.1)?;
    assert_eq!(b.build()?.contact_count(), 1);
    Ok(())
}

/// Asserts that `result` is `UnknownBar` for bar 2 of a one-bar builder, from the condition
/// whose name starts with `name`.
fn assert_unknown_bar(result: Result<&mut AssemblyBuilder, ModelError>, name: &str) {
    match result {
        Err(ModelError::UnknownBar {
            condition,
            bar,
            bars,
        }) => {
            assert_eq!((bar, bars), (2, 1), "{name}");
            assert!(condition.starts_with(name), "{condition}");
        }
        Err(other) => panic!("{name}: expected UnknownBar, got {other:?}"),
        Ok(_) => panic!("{name}: a foreign end was accepted"),
    }
}

#[test]
fn a_foreign_end_is_rejected_at_the_call() {
    let foreign = foreign_bar();
    let (mut b, bar) = one_bar();
    assert_unknown_bar(b.dirichlet(foreign.left()), "Dirichlet");
    assert_unknown_bar(b.neumann(foreign.right()), "Neumann");
    assert_unknown_bar(b.robin(foreign.left(), 0.5), "Robin");
    assert_unknown_bar(b.signorini(foreign.right(), 0.1), "Signorini");
    assert_unknown_bar(b.contact(foreign.right(), bar.right(), 0.1), "contact");
    assert_unknown_bar(b.contact(bar.right(), foreign.left(), 0.1), "contact");
    assert_unknown_bar(b.add_condition(Pinned(foreign.left())), "pinned");

    // None of them was added: the builder still has only its own bar's ends to constrain.
    assert_eq!(
        b.build().unwrap_err(),
        ModelError::UnconstrainedEnd { end: bar.left() }
    );
    b.dirichlet(bar.left())
        .unwrap()
        .neumann(bar.right())
        .unwrap();
    assert_eq!(b.build().unwrap().conditions().count(), 2);
}

/// Asserts that `result` is `NotPositive` for `what`, carrying `value` (NaN for NaN).
fn assert_not_positive(result: Result<&mut AssemblyBuilder, ModelError>, what: &str, value: f64) {
    match result {
        Err(ModelError::NotPositive { what: w, value: v }) => {
            assert_eq!(w, what);
            let same = v == value && v.is_sign_negative() == value.is_sign_negative()
                || v.is_nan() && value.is_nan();
            assert!(same, "{what}: reported {v}, given {value}");
        }
        Err(other) => panic!("{what} = {value}: expected NotPositive, got {other:?}"),
        Ok(_) => panic!("{what} = {value} was accepted"),
    }
}

#[test]
fn a_non_positive_or_non_finite_value_is_rejected_at_the_call() {
    let (mut b, bar) = one_bar();
    let two = b.add_bar(Bar::unit());
    for v in NOT_POSITIVE.into_iter().chain(NOT_FINITE) {
        assert_not_positive(b.robin(bar.left(), v), "Robin spring stiffness", v);
        assert_not_positive(b.signorini(bar.right(), v), "Signorini gap", v);
        assert_not_positive(b.contact(bar.right(), two.right(), v), "contact gap", v);
    }
    // A bad value is reported before a foreign end.
    let foreign = foreign_bar();
    assert_not_positive(
        b.signorini(foreign.right(), f64::NAN),
        "Signorini gap",
        f64::NAN,
    );
    // Nothing was added.
    assert_eq!(
        b.build().unwrap_err(),
        ModelError::UnconstrainedEnd { end: bar.left() }
    );
}

#[test]
fn a_chain_stops_at_its_first_bad_link() {
    fn chain(b: &mut AssemblyBuilder, bar: BarId) -> Result<(), ModelError> {
        b.dirichlet(bar.left())?
            .signorini(bar.right(), -1.0)?
            .neumann(bar.right())?;
        Ok(())
    }
    let (mut b, bar) = one_bar();
    assert!(matches!(
        chain(&mut b, bar),
        Err(ModelError::NotPositive {
            what: "Signorini gap",
            ..
        })
    ));
    // The link before the bad one was added, the ones after it were not.
    assert_eq!(
        b.build().unwrap_err(),
        ModelError::UnconstrainedEnd { end: bar.right() }
    );
}

#[test]
fn two_conditions_on_one_end_are_rejected_at_build() -> Result<(), ModelError> {
    // Each condition is valid alone, so the builder takes both.
    let (mut b, bar) = one_bar();
    b.dirichlet(bar.left())?
        .neumann(bar.right())?
        .signorini(bar.right(), 0.1)?;
    assert!(matches!(
        b.build(),
        Err(ModelError::OverconstrainedEnd { end, .. }) if end == bar.right()
    ));
    Ok(())
}

#[test]
fn a_contact_of_an_end_with_itself_is_rejected_at_the_call() {
    let (mut b, bar) = one_bar();
    assert!(matches!(
        b.contact(bar.right(), bar.right(), 0.1),
        Err(ModelError::RepeatedEnd { end, .. }) if end == bar.right()
    ));
}

/// How a downstream condition on one end misbehaves.
#[derive(Debug, Clone, Copy)]
enum Fault {
    /// Reads the stiffness of an end of a bar the assembly lacks.
    ReadsForeignStiffness,
    /// Puts a term of its row on such an end.
    RowOnForeignEnd,
    /// Only at the harmonic `omega = 1`, not at the constant term.
    RowOnForeignEndAtHarmonic,
    /// Gives its row a coefficient of this value.
    Coefficient(f64),
    /// Gives the derivative of its row's coefficient this value.
    Derivative(f64),
    /// Reads the displacement of a foreign end in its stored energy.
    EnergyOfForeignEnd,
    /// Stores this energy.
    Energy(f64),
}

/// A spring to the ground (the row `u + p = 0`) that misbehaves in one way.
#[derive(Debug)]
struct Faulty {
    end: EndRef,
    foreign: EndRef,
    fault: Fault,
}

impl BoundaryCondition for Faulty {
    fn name(&self) -> String {
        format!("faulty ({:?}) at {}", self.fault, self.end)
    }
    fn ends(&self) -> Vec<EndRef> {
        vec![self.end]
    }
    fn linear_rows(&self, omega: f64, stiffness: &dyn Fn(EndRef) -> f64, rows: &mut LinearRows) {
        let mut spring = Term::new(self.end, Quantity::OutwardStrain, stiffness(self.end));
        let mut u = Term::new(self.end, Quantity::Displacement, 1.0);
        match self.fault {
            Fault::ReadsForeignStiffness => spring.coefficient = stiffness(self.foreign),
            Fault::RowOnForeignEnd => u.end = self.foreign,
            Fault::RowOnForeignEndAtHarmonic if omega > 0.0 => u.end = self.foreign,
            Fault::Coefficient(c) => u.coefficient = c,
            Fault::Derivative(d) => u.d_coefficient = d,
            _ => {}
        }
        rows.push(&[u, spring]);
    }
    fn stored_energy(&self, value: &dyn Fn(EndRef, Quantity) -> f64) -> f64 {
        match self.fault {
            Fault::EnergyOfForeignEnd => value(self.foreign, Quantity::Displacement).powi(2),
            Fault::Energy(e) => e,
            _ => 0.5 * value(self.end, Quantity::Displacement).powi(2),
        }
    }
}

/// A downstream condition that names an end of a bar the assembly lacks, in a row, a
/// stiffness it reads or its stored energy, or that gives a non-finite number, is a typed
/// error at the call (not a panic then or later), and is not added.
#[test]
fn a_downstream_condition_is_checked_in_what_it_reads_and_gives() {
    let foreign = foreign_bar().right();
    let (mut b, bar) = one_bar();
    let faulty = |fault| Faulty {
        end: bar.right(),
        foreign,
        fault,
    };
    for fault in [
        Fault::ReadsForeignStiffness,
        Fault::RowOnForeignEnd,
        Fault::RowOnForeignEndAtHarmonic,
        Fault::EnergyOfForeignEnd,
    ] {
        assert_unknown_bar(b.add_condition(faulty(fault)), "faulty");
    }
    for fault in NOT_FINITE.iter().flat_map(|&v| {
        [
            Fault::Coefficient(v),
            Fault::Derivative(v),
            Fault::Energy(v),
        ]
    }) {
        match b.add_condition(faulty(fault)) {
            Err(ModelError::NonFiniteCoefficient {
                condition, value, ..
            }) => {
                assert!(condition.starts_with("faulty"), "{condition}");
                assert!(!value.is_finite(), "{fault:?}: {value}");
            }
            other => panic!("{fault:?}: expected NonFiniteCoefficient, got {other:?}"),
        }
    }
    // Nothing was added, and the well-behaved condition builds.
    b.dirichlet(bar.left()).unwrap();
    assert_eq!(
        b.build().unwrap_err(),
        ModelError::UnconstrainedEnd { end: bar.right() }
    );
    b.add_condition(faulty(Fault::Coefficient(2.0))).unwrap();
    assert_eq!(b.build().unwrap().conditions().count(), 2);
}
