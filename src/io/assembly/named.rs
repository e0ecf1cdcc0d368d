//! A validated system with the names its file gives the bars.

use super::describe::describe;
use super::error::AssemblyFileError;
use super::format::FileFormat;
use super::schema::AssemblyFile;
use crate::bar::BarId;
use crate::system::BarSystem;
use std::path::Path;

/// A validated system with the names its file gives the bars.
#[derive(Debug, Clone)]
pub struct Assembly {
    pub(super) system: BarSystem,
    pub(super) names: Vec<String>,
}

impl Assembly {
    /// Parses and builds `text` in `format` ([`AssemblyFile::parse`], then
    /// [`AssemblyFile::build`]).
    ///
    /// # Errors
    /// Those of [`AssemblyFile::parse`] and [`AssemblyFile::build`].
    pub fn parse(text: &str, format: FileFormat) -> Result<Self, AssemblyFileError> {
        AssemblyFile::parse(text, format)?.build()
    }

    /// Reads, parses and builds the file at `path`, its format told by the extension
    /// ([`FileFormat::from_path`]).
    ///
    /// # Errors
    /// [`AssemblyFileError::UnknownExtension`], [`AssemblyFileError::Read`], then those of
    /// [`Assembly::parse`].
    pub fn from_path(path: impl AsRef<Path>) -> Result<Self, AssemblyFileError> {
        let path = path.as_ref();
        let shown = || path.display().to_string();
        let format = FileFormat::from_path(path)
            .ok_or_else(|| AssemblyFileError::UnknownExtension { path: shown() })?;
        let text = std::fs::read_to_string(path).map_err(|e| AssemblyFileError::Read {
            path: shown(),
            message: e.to_string(),
        })?;
        Self::parse(&text, format)
    }

    /// The system.
    pub fn system(&self) -> &BarSystem {
        &self.system
    }

    /// The system, without the names.
    pub fn into_system(self) -> BarSystem {
        self.system
    }

    /// The bar names, by bar index.
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// The id of the bar named `name`.
    pub fn bar_id(&self, name: &str) -> Option<BarId> {
        let index = self.names.iter().position(|n| n == name)?;
        self.system.bar_id(index)
    }

    /// The name of the bar `id`, if it is a bar of this system.
    pub fn bar_name(&self, id: BarId) -> Option<&str> {
        self.names.get(id.index()).map(String::as_str)
    }

    /// The file describing this assembly, with its bar names (see
    /// [`AssemblyFile::from_system`]).
    ///
    /// # Errors
    /// [`AssemblyFileError::Unrepresentable`] as [`AssemblyFile::from_system`].
    pub fn to_file(&self) -> Result<AssemblyFile, AssemblyFileError> {
        describe(&self.system, &self.names)
    }
}
