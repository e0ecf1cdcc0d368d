//! From a [`BarSystem`] back to the file schema, so that systems built in Rust (the
//! [`crate::reference`] systems among them) can be written as files and edited.
//!
//! A [`BarSystem`] keeps its conditions as trait objects, so a condition is recognised by what
//! it does: its ends, whether it has a unilateral law, and the parameter read from its rows
//! or its gap. The built-in condition with those ends and that parameter is then rebuilt and
//! compared with it (name, rows, observables): a condition is written as built-in only if it
//! gives the same equations as the built-in one.

use super::error::AssemblyFileError;
use super::schema::end_name;
use super::schema::{AssemblyFile, BarEntry, ConditionEntry};
use crate::bar::EndRef;
use crate::bc::{
    BoundaryCondition, Contact, Dirichlet, LinearRows, Neumann, Quantity, Robin, Signorini,
};
use crate::system::BarSystem;

/// The file describing `system`, with bar `i` named `names[i]`.
pub(super) fn describe(
    system: &BarSystem,
    names: &[String],
) -> Result<AssemblyFile, AssemblyFileError> {
    let bar = system
        .bars()
        .iter()
        .zip(names)
        .map(|(b, name)| BarEntry {
            name: name.clone(),
            length: b.length(),
            wave_speed: b.wave_speed(),
            stiffness: b.stiffness(),
        })
        .collect();
    let condition = system
        .conditions()
        .enumerate()
        .map(|(index, c)| {
            recognise(system, c, names).ok_or_else(|| AssemblyFileError::Unrepresentable {
                index,
                condition: c.name(),
            })
        })
        .collect::<Result<_, _>>()?;
    Ok(AssemblyFile { bar, condition })
}

/// The entry of the built-in condition that gives the same equations as `c`, if there is one.
fn recognise(
    system: &BarSystem,
    c: &dyn BoundaryCondition,
    names: &[String],
) -> Option<ConditionEntry> {
    let name = |end: EndRef| end_name(names, end);
    let stiffness = |end: EndRef| system.stiffness_at(end);
    let law_gap = c.unilateral().map(|law| law.gap().offset);
    let (entry, built): (ConditionEntry, Box<dyn BoundaryCondition>) =
        match (c.ends().as_slice(), law_gap) {
            (&[end], None) => {
                let mut rows = LinearRows::new();
                c.linear_rows(1.0, &stiffness, &mut rows);
                if rows.len() != 1 {
                    return None;
                }
                match rows.row(0) {
                    [t] if t.quantity == Quantity::Displacement => (
                        ConditionEntry::Dirichlet { end: name(end) },
                        Box::new(Dirichlet::new(end)),
                    ),
                    [t] if t.quantity == Quantity::OutwardStrain => (
                        ConditionEntry::Neumann { end: name(end) },
                        Box::new(Neumann::new(end)),
                    ),
                    [_, spring] if spring.quantity == Quantity::Displacement => (
                        ConditionEntry::Robin {
                            end: name(end),
                            stiffness: spring.coefficient,
                        },
                        Box::new(Robin::new(end, spring.coefficient).ok()?),
                    ),
                    _ => return None,
                }
            }
            (&[end], Some(gap)) => (
                ConditionEntry::Signorini {
                    end: name(end),
                    gap,
                },
                Box::new(Signorini::new(end, gap).ok()?),
            ),
            (&[first, second], Some(gap)) => (
                ConditionEntry::Contact {
                    ends: [name(first), name(second)],
                    gap,
                },
                Box::new(Contact::new(first, second, gap).ok()?),
            ),
            _ => return None,
        };
    same_equations(system, c, built.as_ref()).then_some(entry)
}

/// Whether `a` and `b` have the same name, ends, rows (at a few frequencies) and law
/// observables.
fn same_equations(
    system: &BarSystem,
    a: &dyn BoundaryCondition,
    b: &dyn BoundaryCondition,
) -> bool {
    let stiffness = |end: EndRef| system.stiffness_at(end);
    let rows = |c: &dyn BoundaryCondition, omega: f64| {
        let mut rows = LinearRows::new();
        c.linear_rows(omega, &stiffness, &mut rows);
        (0..rows.len())
            .map(|r| rows.row(r).to_vec())
            .collect::<Vec<_>>()
    };
    let law = |c: &dyn BoundaryCondition| c.unilateral().map(|l| (l.gap(), l.force()));
    a.name() == b.name()
        && a.ends() == b.ends()
        && [0.0, 1.0, 2.5].iter().all(|&w| rows(a, w) == rows(b, w))
        && law(a) == law(b)
}
