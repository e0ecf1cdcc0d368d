//! The two formats of an assembly file.

use std::fmt;
use std::path::Path;

/// The two formats of an assembly file; they share one structure.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum FileFormat {
    /// TOML (extension `.toml`).
    Toml,
    /// JSON (extension `.json`).
    Json,
}

impl FileFormat {
    /// The format named by `path`'s extension (`.toml` or `.json`, in any case).
    pub fn from_path(path: &Path) -> Option<Self> {
        let extension = path.extension()?.to_str()?;
        if extension.eq_ignore_ascii_case("toml") {
            Some(FileFormat::Toml)
        } else if extension.eq_ignore_ascii_case("json") {
            Some(FileFormat::Json)
        } else {
            None
        }
    }
}

impl fmt::Display for FileFormat {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            FileFormat::Toml => "TOML",
            FileFormat::Json => "JSON",
        })
    }
}
