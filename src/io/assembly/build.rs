//! From a parsed file to a validated [`BarSystem`], through [`AssemblyBuilder`] so that the
//! file meets exactly the checks a Rust caller meets; the file only adds what the builder
//! cannot know: names.

use super::error::AssemblyFileError;
use super::named::Assembly;
use super::schema::end_name;
use super::schema::END;
use super::schema::START;
use super::schema::{AssemblyFile, ConditionEntry};
use crate::bar::{Bar, BarId, EndRef};
use crate::error::ModelError;
use crate::system::AssemblyBuilder;
use std::collections::BTreeMap;

/// Builds the assembly `file` describes.
pub(super) fn build(file: &AssemblyFile) -> Result<Assembly, AssemblyFileError> {
    if file.bar.is_empty() {
        return Err(AssemblyFileError::NoBars);
    }
    let mut builder = AssemblyBuilder::new();
    let mut ids: BTreeMap<&str, (usize, BarId)> = BTreeMap::new();
    for (index, entry) in file.bar.iter().enumerate() {
        if let Some(&(first, _)) = ids.get(entry.name.as_str()) {
            return Err(AssemblyFileError::DuplicateBarName {
                name: entry.name.clone(),
                first,
                second: index,
            });
        }
        let bar = Bar::new(entry.length, entry.wave_speed, entry.stiffness).map_err(|source| {
            AssemblyFileError::Bar {
                index,
                name: entry.name.clone(),
                source,
            }
        })?;
        ids.insert(&entry.name, (index, builder.add_bar(bar)));
    }
    let resolve = |condition: usize, end: &str| -> Result<EndRef, AssemblyFileError> {
        let malformed = || AssemblyFileError::MalformedEnd {
            condition,
            end: end.to_string(),
        };
        let (bar, side) = end.rsplit_once('.').ok_or_else(malformed)?;
        let left = match side {
            START => true,
            END => false,
            _ => return Err(malformed()),
        };
        let &(_, id) = ids
            .get(bar)
            .ok_or_else(|| AssemblyFileError::UnknownBarName {
                condition,
                end: end.to_string(),
                bar: bar.to_string(),
            })?;
        Ok(if left { id.left() } else { id.right() })
    };
    let names: Vec<String> = file.bar.iter().map(|b| b.name.clone()).collect();
    // The ends of each condition, kept to name the conditions of an end the builder rejects.
    let mut owners: Vec<Vec<EndRef>> = Vec::with_capacity(file.condition.len());
    for (index, entry) in file.condition.iter().enumerate() {
        let resolve = |end: &str| resolve(index, end);
        add(&mut builder, entry, &resolve).map_err(|e| match e {
            Rejected::File(e) => e,
            Rejected::Model(ModelError::RepeatedEnd { end, .. }) => {
                AssemblyFileError::RepeatedEnd {
                    condition: index,
                    end: end_name(&names, end),
                }
            }
            Rejected::Model(source) => AssemblyFileError::Condition {
                index,
                type_name: entry.type_name(),
                source,
            },
        })?;
        owners.push(
            entry
                .ends()
                .into_iter()
                .filter_map(|e| resolve(e).ok())
                .collect(),
        );
    }
    let system = builder.build().map_err(|source| {
        let end = match &source {
            ModelError::UnconstrainedEnd { end } | ModelError::OverconstrainedEnd { end, .. } => {
                *end
            }
            // Every other error of `build` is raised by a condition's own check, which
            // `add` ran already; kept typed should the builder learn a new one.
            _ => {
                return AssemblyFileError::Condition {
                    index: file.condition.len().saturating_sub(1),
                    type_name: file.condition.last().map_or("", ConditionEntry::type_name),
                    source,
                }
            }
        };
        AssemblyFileError::End {
            end: end_name(&names, end),
            conditions: (0..owners.len())
                .filter(|&i| owners[i].contains(&end))
                .collect(),
            source,
        }
    })?;
    Ok(Assembly { system, names })
}

/// Why [`add`] refused a condition: an end it cannot resolve, or the builder's check.
enum Rejected {
    File(AssemblyFileError),
    Model(ModelError),
}

/// Adds the condition `entry`, its ends resolved by `resolve`.
fn add(
    builder: &mut AssemblyBuilder,
    entry: &ConditionEntry,
    resolve: &dyn Fn(&str) -> Result<EndRef, AssemblyFileError>,
) -> Result<(), Rejected> {
    let end = |text: &str| resolve(text).map_err(Rejected::File);
    match entry {
        ConditionEntry::Dirichlet { end: e } => builder.dirichlet(end(e)?),
        ConditionEntry::Neumann { end: e } => builder.neumann(end(e)?),
        ConditionEntry::Robin { end: e, stiffness } => builder.robin(end(e)?, *stiffness),
        ConditionEntry::Signorini { end: e, gap } => builder.signorini(end(e)?, *gap),
        ConditionEntry::Contact {
            ends: [first, second],
            gap,
        } => builder.contact(end(first)?, end(second)?, *gap),
    }
    .map(|_| ())
    .map_err(Rejected::Model)
}
