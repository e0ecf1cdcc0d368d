//! What can be wrong with an assembly file, and the translation of the parsers' errors into
//! it.
//!
//! The parsers report a misspelt key, a missing key and an unknown condition `type` as plain
//! messages (serde's `unknown field`, `missing field`, `unknown variant`); they are read back
//! into typed variants so that a program (a GUI, a test) can tell them apart without parsing
//! text itself, and every variant keeps the line the parser pointed at.

use super::format::FileFormat;
use crate::error::ModelError;
use std::fmt;
use thiserror::Error;

/// Errors of reading, building or writing an assembly file ([`crate::io::assembly`]).
///
/// Indices are 0-based positions in the file (`index` 0 is the first `[[bar]]` or
/// `[[condition]]`); the messages count from 1, as a reader does.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum AssemblyFileError {
    /// The file could not be read.
    #[error("cannot read `{path}`: {message}")]
    Read {
        /// The path.
        path: String,
        /// The operating system's message.
        message: String,
    },
    /// The path's extension names no known format.
    #[error("`{path}`: cannot tell the format from the extension (expected .toml or .json)")]
    UnknownExtension {
        /// The path.
        path: String,
    },
    /// The text is not valid TOML or JSON, or a value has the wrong type.
    #[error("{format} error{}: {message}", Location(.line, .column))]
    Syntax {
        /// The format parsed.
        format: FileFormat,
        /// 1-based line the parser pointed at, if it did.
        line: Option<usize>,
        /// 1-based column, if known.
        column: Option<usize>,
        /// The parser's message.
        message: String,
    },
    /// A key that the schema does not have (at the top level, in a `[[bar]]` or in a
    /// `[[condition]]` of that type).
    #[error("unknown key `{key}`{}", Location(.line, &None))]
    UnknownKey {
        /// The key.
        key: String,
        /// 1-based line, if known.
        line: Option<usize>,
    },
    /// A key that the table needs is missing.
    #[error("missing key `{key}`{}", Location(.line, &None))]
    MissingKey {
        /// The key.
        key: String,
        /// 1-based line, if known.
        line: Option<usize>,
    },
    /// A condition's `type` is none of `dirichlet`, `neumann`, `robin`, `signorini`,
    /// `contact`.
    #[error(
        "unknown condition type `{type_name}`{} (expected dirichlet, neumann, robin, signorini or contact)",
        Location(.line, &None)
    )]
    UnknownConditionType {
        /// The value of `type`.
        type_name: String,
        /// 1-based line, if known.
        line: Option<usize>,
    },
    /// The file lists no bar.
    #[error("the assembly has no [[bar]]")]
    NoBars,
    /// Two bars have the same name.
    #[error("bars {} and {} are both named `{name}`", one_based(.first), one_based(.second))]
    DuplicateBarName {
        /// The name.
        name: String,
        /// Index of the first bar with it.
        first: usize,
        /// Index of the second.
        second: usize,
    },
    /// An end is not written `NAME.start` or `NAME.end`.
    #[error("[[condition]] {}: end `{end}` is not of the form NAME.start or NAME.end", one_based(.condition))]
    MalformedEnd {
        /// Index of the condition.
        condition: usize,
        /// The end as written.
        end: String,
    },
    /// An end names a bar that the file does not have.
    #[error("[[condition]] {}: end `{end}` names bar `{bar}`, which is not in the file", one_based(.condition))]
    UnknownBarName {
        /// Index of the condition.
        condition: usize,
        /// The end as written.
        end: String,
        /// The bar name in it.
        bar: String,
    },
    /// A bar's values are rejected ([`Bar::new`](crate::bar::Bar::new)).
    #[error("[[bar]] {} (`{name}`): {source}", one_based(.index))]
    Bar {
        /// Index of the bar.
        index: usize,
        /// Its name.
        name: String,
        /// The model's error.
        source: ModelError,
    },
    /// A contact lists the same end twice.
    #[error("[[condition]] {}: end `{end}` is listed twice", .condition + 1)]
    RepeatedEnd {
        /// Index of the condition.
        condition: usize,
        /// The end as written.
        end: String,
    },
    /// A condition is rejected by the assembly builder (a gap or stiffness not positive and
    /// finite).
    #[error("[[condition]] {} ({type_name}): {source}", one_based(.index))]
    Condition {
        /// Index of the condition.
        index: usize,
        /// Its `type`.
        type_name: &'static str,
        /// The builder's error.
        source: ModelError,
    },
    /// An end has no condition, or two (found by
    /// [`AssemblyBuilder::build`](crate::system::AssemblyBuilder::build)).
    #[error("end `{end}` {}", EndProblem(.conditions, .source))]
    End {
        /// The end, as the file writes it.
        end: String,
        /// Indices of the conditions that name it (none, or two).
        conditions: Vec<usize>,
        /// The builder's error.
        source: ModelError,
    },
    /// A condition of the system is not one of the five built-in conditions, so the schema
    /// cannot describe it.
    #[error("condition {} (`{condition}`) is not a built-in condition: the file schema cannot describe it", one_based(.index))]
    Unrepresentable {
        /// Its index in the system.
        index: usize,
        /// Its name.
        condition: String,
    },
    /// The serialiser failed (not produced for files built by this module).
    #[error("cannot write {format}: {message}")]
    Write {
        /// The format written.
        format: FileFormat,
        /// The serialiser's message.
        message: String,
    },
}

/// The 1-based number of the item at index `i`, as a reader counts (no overflow at
/// `usize::MAX`: the fields of the error are public).
fn one_based(i: &usize) -> u128 {
    *i as u128 + 1
}

/// ` at line L, column C`, or nothing when the parser gave no position.
struct Location<'a>(&'a Option<usize>, &'a Option<usize>);

impl fmt::Display for Location<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match (*self.0, *self.1) {
            (Some(line), Some(column)) => write!(f, " at line {line}, column {column}"),
            (Some(line), None) => write!(f, " at line {line}"),
            _ => Ok(()),
        }
    }
}

/// What is wrong with an end, in the file's terms: `has no boundary condition`, or `has two
/// boundary conditions: [[condition]] 2 and 3` (1-based). The builder's own message would
/// name the end and its conditions the way Rust code writes them.
struct EndProblem<'a>(&'a [usize], &'a ModelError);

impl fmt::Display for EndProblem<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let numbers: Vec<String> = self.0.iter().map(|i| one_based(i).to_string()).collect();
        let list = match numbers.as_slice() {
            [] => String::new(),
            [one] => one.clone(),
            [init @ .., last] => format!("{} and {last}", init.join(", ")),
        };
        match self.1 {
            ModelError::UnconstrainedEnd { .. } => write!(f, "has no boundary condition"),
            ModelError::OverconstrainedEnd { .. } => {
                write!(f, "has two boundary conditions: [[condition]] {list}")
            }
            other if numbers.is_empty() => write!(f, "(no condition): {other}"),
            other => write!(f, "([[condition]] {list}): {other}"),
        }
    }
}

/// The parser's message `message` at `line`/`column`, as a typed variant when it is one of
/// serde's messages about keys and variants.
pub(super) fn classify(
    format: FileFormat,
    message: &str,
    line: Option<usize>,
    column: Option<usize>,
) -> AssemblyFileError {
    if let Some(key) = quoted_after(message, "unknown field `") {
        AssemblyFileError::UnknownKey { key, line }
    } else if let Some(key) = quoted_after(message, "missing field `") {
        AssemblyFileError::MissingKey { key, line }
    } else if let Some(type_name) = quoted_after(message, "unknown variant `") {
        AssemblyFileError::UnknownConditionType { type_name, line }
    } else {
        AssemblyFileError::Syntax {
            format,
            line,
            column,
            message: message.trim_end().to_string(),
        }
    }
}

/// `error` with its line moved to the first line, at or after the one the parser gave, that
/// writes its key: inside a `[[condition]]` the parsers point at the whole list (serde reads
/// a tagged table as a whole before it looks at its keys), not at the key.
fn refine_line(mut error: AssemblyFileError, text: &str, format: FileFormat) -> AssemblyFileError {
    if let AssemblyFileError::UnknownKey { key, line } = &mut error {
        let writes_key = |l: &str| {
            let l = l.trim_start();
            let rest = match format {
                FileFormat::Toml => l.strip_prefix(key.as_str()),
                FileFormat::Json => l
                    .find(&format!("\"{key}\""))
                    .map(|at| &l[at + key.len() + 2..]),
            };
            rest.is_some_and(|r| r.trim_start().starts_with(['=', ':']))
        };
        let from = line.unwrap_or(1).saturating_sub(1);
        if let Some(found) = text.lines().skip(from).position(writes_key) {
            *line = Some(from + found + 1);
        }
    }
    error
}

/// The text between `prefix` (ending with a backtick) and the next backtick, if `message`
/// contains `prefix`.
fn quoted_after(message: &str, prefix: &str) -> Option<String> {
    let start = message.find(prefix)? + prefix.len();
    let rest = &message[start..];
    rest.find('`').map(|end| rest[..end].to_string())
}

/// A TOML parser error as an [`AssemblyFileError`], with the 1-based line and column of the
/// start of the span it points at.
pub(super) fn from_toml(error: &toml::de::Error, text: &str) -> AssemblyFileError {
    let (line, column) = match error.span() {
        Some(span) => {
            let before = text.get(..span.start).unwrap_or(text);
            let line = before.matches('\n').count() + 1;
            let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
            (Some(line), Some(column))
        }
        None => (None, None),
    };
    let error = classify(FileFormat::Toml, error.message(), line, column);
    refine_line(error, text, FileFormat::Toml)
}

/// A JSON parser error as an [`AssemblyFileError`] (serde_json appends the position to its
/// message; it is taken off and kept in the fields).
pub(super) fn from_json(error: &serde_json::Error, text: &str) -> AssemblyFileError {
    let shown = error.to_string();
    let (line, column) = (error.line(), error.column());
    let suffix = format!(" at line {line} column {column}");
    let message = shown.strip_suffix(&suffix).unwrap_or(&shown);
    let known = |v: usize| (v > 0).then_some(v);
    let error = classify(FileFormat::Json, message, known(line), known(column));
    refine_line(error, text, FileFormat::Json)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn serde_messages_become_typed_variants() {
        let unknown = classify(
            FileFormat::Toml,
            "unknown field `stifness`, expected `end` or `stiffness`",
            Some(3),
            None,
        );
        assert_eq!(
            unknown,
            AssemblyFileError::UnknownKey {
                key: "stifness".into(),
                line: Some(3)
            }
        );
        assert!(matches!(
            classify(FileFormat::Json, "unknown variant `spring`, expected one of", None, None),
            AssemblyFileError::UnknownConditionType { type_name, .. } if type_name == "spring"
        ));
        // An unterminated quote is not mistaken for a key.
        assert!(matches!(
            classify(FileFormat::Json, "missing field `gap", None, None),
            AssemblyFileError::Syntax { .. }
        ));
        let end = |conditions: Vec<usize>, source| {
            AssemblyFileError::End {
                end: "a.end".into(),
                conditions,
                source,
            }
            .to_string()
        };
        let right = crate::system::AssemblyBuilder::new()
            .add_bar(crate::bar::Bar::unit())
            .right();
        assert_eq!(
            end(vec![], ModelError::UnconstrainedEnd { end: right }),
            "end `a.end` has no boundary condition"
        );
        let two = ModelError::OverconstrainedEnd {
            end: right,
            first: "x".into(),
            second: "y".into(),
        };
        assert_eq!(
            end(vec![1, 2], two),
            "end `a.end` has two boundary conditions: [[condition]] 2 and 3"
        );
        assert_eq!(
            end(vec![0, 1, 4], ModelError::NoBars),
            "end `a.end` ([[condition]] 1, 2 and 5): the assembly has no bar"
        );
    }
}
