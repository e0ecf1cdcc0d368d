//! The file's structure as serde types: exactly the keys of the schema, nothing else; and
//! how an end is written (`NAME.start`, `NAME.end`).
//!
//! `deny_unknown_fields` makes a misspelt key an error instead of a silently ignored line
//! (a `stifness = 0.5` that leaves a Robin spring at its default would be a wrong model, not a
//! typo); the `type` tag picks the condition and, with it, which keys that condition takes.

use crate::bar::End;
use crate::bar::EndRef;
use serde::{Deserialize, Serialize};

/// Suffix of the end at `x = 0` in an end string.
pub(super) const START: &str = "start";
/// Suffix of the end at `x = l`.
pub(super) const END: &str = "end";

/// A whole assembly file: its `[[bar]]` and `[[condition]]` tables, in file order.
///
/// Both lists may be left out (an empty file has no bar, which
/// [`AssemblyFile::build`](crate::io::assembly::AssemblyFile::build) reports as
/// [`NoBars`](crate::io::assembly::AssemblyFileError::NoBars)).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AssemblyFile {
    /// The bars, in the order they get their [`BarId`](crate::bar::BarId)s.
    #[serde(default)]
    pub bar: Vec<BarEntry>,
    /// The boundary conditions, in the order they are added to the assembly.
    #[serde(default)]
    pub condition: Vec<ConditionEntry>,
}

/// One `[[bar]]` table.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BarEntry {
    /// The name its ends are written with (`"NAME.start"`, `"NAME.end"`); unique in the file.
    pub name: String,
    /// Length `l`.
    pub length: f64,
    /// Wave speed `c`.
    pub wave_speed: f64,
    /// Axial stiffness `EA`.
    pub stiffness: f64,
}

/// One `[[condition]]` table; its `type` key selects the variant (lower case).
///
/// Ends are written `"NAME.start"` (the end at `x = 0`) or `"NAME.end"` (at `x = l`), `NAME`
/// being a bar's `name` (the text before the last `.`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "lowercase", deny_unknown_fields)]
pub enum ConditionEntry {
    /// Clamped end ([`Dirichlet`](crate::bc::Dirichlet)).
    Dirichlet {
        /// The end.
        end: String,
    },
    /// Free end ([`Neumann`](crate::bc::Neumann)).
    Neumann {
        /// The end.
        end: String,
    },
    /// Ground spring ([`Robin`](crate::bc::Robin)).
    Robin {
        /// The end.
        end: String,
        /// Spring stiffness `k_s`.
        stiffness: f64,
    },
    /// Rigid obstacle ([`Signorini`](crate::bc::Signorini)).
    Signorini {
        /// The end.
        end: String,
        /// Gap at rest `g0`.
        gap: f64,
    },
    /// Two ends facing each other ([`Contact`](crate::bc::Contact)).
    Contact {
        /// The two ends.
        ends: [String; 2],
        /// Gap at rest `g0`.
        gap: f64,
    },
}

impl ConditionEntry {
    /// The value of the `type` key.
    pub fn type_name(&self) -> &'static str {
        match self {
            ConditionEntry::Dirichlet { .. } => "dirichlet",
            ConditionEntry::Neumann { .. } => "neumann",
            ConditionEntry::Robin { .. } => "robin",
            ConditionEntry::Signorini { .. } => "signorini",
            ConditionEntry::Contact { .. } => "contact",
        }
    }

    /// The ends it names, as written.
    pub fn ends(&self) -> Vec<&str> {
        match self {
            ConditionEntry::Dirichlet { end }
            | ConditionEntry::Neumann { end }
            | ConditionEntry::Robin { end, .. }
            | ConditionEntry::Signorini { end, .. } => vec![end],
            ConditionEntry::Contact { ends, .. } => ends.iter().map(String::as_str).collect(),
        }
    }
}

/// `NAME.start` or `NAME.end` for `end`, with the bar names `names` (by bar index).
pub(super) fn end_name(names: &[String], end: EndRef) -> String {
    let side = match end.end {
        End::Left => START,
        End::Right => END,
    };
    let bar = names.get(end.bar.index()).map_or("?", String::as_str);
    format!("{bar}.{side}")
}
