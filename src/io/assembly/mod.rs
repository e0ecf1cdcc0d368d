//! Assemblies read from and written to files (feature `serde`): any bar system described in
//! TOML, or in JSON with the same structure, without writing Rust.
//!
//! # Schema
//!
//! Exactly these keys; any other key is an error ([`AssemblyFileError::UnknownKey`]), so that
//! a misspelt key is not silently ignored.
//!
//! ```toml
//! [[bar]]                  # one table per bar, in the order of their `BarId`s
//! name = "a"               # unique; ends are written "a.start" (x = 0) and "a.end" (x = l)
//! length = 1.0
//! wave_speed = 1.0
//! stiffness = 1.0          # EA
//!
//! [[condition]]
//! type = "dirichlet"       # dirichlet | neumann | robin | signorini | contact
//! end = "a.start"
//!
//! [[condition]]
//! type = "robin"           # ground spring
//! end = "a.end"
//! stiffness = 0.5
//!
//! [[condition]]
//! type = "signorini"       # rigid obstacle at `gap` from the end
//! end = "b.end"
//! gap = 1e-3
//!
//! [[condition]]
//! type = "contact"         # two ends facing each other across `gap`
//! ends = ["a.end", "b.end"]
//! gap = 1e-3
//! ```
//!
//! (The four conditions above are the four shapes a condition takes, not one valid assembly:
//! every end needs exactly one condition.) The JSON form is
//! `{"bar": [{"name": "a", ...}], "condition": [{"type": "dirichlet", "end": "a.start"}]}`.
//!
//! The system is built through [`AssemblyBuilder`](crate::system::AssemblyBuilder), so a file
//! meets every check a Rust caller meets (positive finite values, every end with exactly one
//! condition...); its errors come back wrapped with the position of the bar or condition in
//! the file ([`AssemblyFileError`]). No content of a file makes the loader panic.
//!
//! # Example
//!
//! ```
//! use nonsmooth_modes::io::assembly::{Assembly, FileFormat};
//! use nonsmooth_modes::reference::clamped_bar_with_obstacle;
//!
//! let text = r#"
//! [[bar]]
//! name = "rod"
//! length = 1.0
//! wave_speed = 1.0
//! stiffness = 1.0
//!
//! [[condition]]
//! type = "dirichlet"
//! end = "rod.start"
//!
//! [[condition]]
//! type = "signorini"
//! end = "rod.end"
//! gap = 1e-3
//! "#;
//! let assembly = Assembly::parse(text, FileFormat::Toml)?;
//! let rod = assembly.bar_id("rod").unwrap();
//! assert_eq!(assembly.system().bar(rod).length(), 1.0);
//! assert_eq!(assembly.system().contact_count(), 1);
//!
//! // The reverse: a system built in Rust written in the same schema (bars named 1, 2, ...).
//! let file = nonsmooth_modes::io::assembly::AssemblyFile::from_system(
//!     &clamped_bar_with_obstacle(1e-3)?,
//! )?;
//! assert_eq!(file.bar[0].name, "1");
//! let json = file.to_json()?;
//! assert_eq!(Assembly::parse(&json, FileFormat::Json)?.names(), ["1"]);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod build;
mod describe;
mod error;
mod format;
mod named;
mod schema;

pub use error::AssemblyFileError;
pub use format::FileFormat;
pub use named::Assembly;
pub use schema::{AssemblyFile, BarEntry, ConditionEntry};

use crate::system::BarSystem;

impl AssemblyFile {
    /// Parses `text` in `format` (structure only: names and values are checked by
    /// [`AssemblyFile::build`]).
    ///
    /// # Errors
    /// [`AssemblyFileError::Syntax`], [`AssemblyFileError::UnknownKey`],
    /// [`AssemblyFileError::MissingKey`] or [`AssemblyFileError::UnknownConditionType`], with
    /// the line the parser pointed at.
    pub fn parse(text: &str, format: FileFormat) -> Result<Self, AssemblyFileError> {
        match format {
            FileFormat::Toml => toml::from_str(text).map_err(|e| error::from_toml(&e, text)),
            FileFormat::Json => serde_json::from_str(text).map_err(|e| error::from_json(&e, text)),
        }
    }

    /// Builds the system the file describes, keeping the bar names.
    ///
    /// # Errors
    /// [`AssemblyFileError::NoBars`], [`AssemblyFileError::DuplicateBarName`],
    /// [`AssemblyFileError::MalformedEnd`], [`AssemblyFileError::UnknownBarName`], and the
    /// builder's errors wrapped with their place in the file: [`AssemblyFileError::Bar`],
    /// [`AssemblyFileError::Condition`], [`AssemblyFileError::End`].
    pub fn build(&self) -> Result<Assembly, AssemblyFileError> {
        build::build(self)
    }

    /// The file describing `system`, its bars named `1`, `2`, ... in order (the names the
    /// `backbone` example gives the bars of its `--system` shorthands).
    ///
    /// # Errors
    /// [`AssemblyFileError::Unrepresentable`] for a condition that does not give the same
    /// equations as one of the five built-in conditions.
    pub fn from_system(system: &BarSystem) -> Result<Self, AssemblyFileError> {
        let names: Vec<String> = (1..=system.bars().len()).map(|i| i.to_string()).collect();
        describe::describe(system, &names)
    }

    /// The file as TOML.
    ///
    /// # Errors
    /// [`AssemblyFileError::Write`] (not produced for a file of finite values).
    pub fn to_toml(&self) -> Result<String, AssemblyFileError> {
        toml::to_string(self).map_err(|e| AssemblyFileError::Write {
            format: FileFormat::Toml,
            message: e.to_string(),
        })
    }

    /// The file as pretty JSON.
    ///
    /// # Errors
    /// [`AssemblyFileError::Write`] (not produced by this schema).
    pub fn to_json(&self) -> Result<String, AssemblyFileError> {
        serde_json::to_string_pretty(self).map_err(|e| AssemblyFileError::Write {
            format: FileFormat::Json,
            message: e.to_string(),
        })
    }
}
