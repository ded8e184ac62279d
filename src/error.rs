//! The error type of every fallible operation of the library, and [`MeshError`] (public as
//! `tissuesim::mesh::MeshError`), the error of a mesh reader, which [`Error::Mesh`] carries.

use std::fmt;
use std::path::{Path, PathBuf};

/// Why an operation failed. Whatever failed left the world as it was.
///
/// `#[non_exhaustive]`: match with a wildcard arm, new variants may come in minor versions.
/// [`std::error::Error::source`] gives the underlying [`MeshError`] of [`Error::Mesh`].
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum Error {
    /// A mesh file could not be read or is malformed (names the file and, where known, the line).
    Mesh(MeshError),
    /// An argument is out of its valid range (the message says which and why).
    InvalidArgument(String),
    /// An input holds NaN or ±Inf (the message says which).
    NonFinite(String),
    /// No body with this id exists in the world.
    UnknownBody(u32),
    /// No tool with this id exists in the world.
    UnknownTool(u32),
    /// No render surface with this id exists in the world.
    UnknownRenderSurface(u32),
    /// A saved state cannot be restored into this world (version, size or scene mismatch).
    BadState(String),
    /// A step produced NaN or Inf, or left the physical bounds of
    /// [`DivergenceLimits`](crate::DivergenceLimits) (speed, extent, volume ratio); the world was
    /// rolled back to its state before the step, and the message names the body and the reason.
    Diverged(String),
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::Mesh(e) => write!(f, "{e}"),
            Error::InvalidArgument(m) => write!(f, "invalid argument: {m}"),
            Error::NonFinite(m) => write!(f, "non-finite input: {m}"),
            Error::UnknownBody(id) => write!(f, "unknown body id {id}"),
            Error::UnknownTool(id) => write!(f, "unknown tool id {id}"),
            Error::UnknownRenderSurface(id) => write!(f, "unknown render surface id {id}"),
            Error::BadState(m) => write!(f, "cannot restore state: {m}"),
            Error::Diverged(m) => write!(f, "step diverged and was rolled back: {m}"),
        }
    }
}

impl std::error::Error for Error {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Error::Mesh(e) => Some(e),
            _ => None,
        }
    }
}

impl From<MeshError> for Error {
    fn from(e: MeshError) -> Self {
        Error::Mesh(e)
    }
}

/// A mesh that could not be read: the file, the line (1-based) where known, and what is wrong.
#[derive(Debug, Clone, PartialEq)]
pub struct MeshError {
    /// The file that failed (empty for meshes built from arrays).
    pub path: PathBuf,
    /// The 1-based line where the problem was found, when it is tied to one.
    pub line: Option<usize>,
    /// What is wrong.
    pub message: String,
}

impl fmt::Display for MeshError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.line {
            Some(l) => write!(f, "{}:{}: {}", self.path.display(), l, self.message),
            None => write!(f, "{}: {}", self.path.display(), self.message),
        }
    }
}

impl std::error::Error for MeshError {}

impl MeshError {
    /// An error in `path` at 1-based `line`.
    pub fn at(path: &Path, line: usize, message: impl Into<String>) -> Self {
        MeshError {
            path: path.to_path_buf(),
            line: Some(line),
            message: message.into(),
        }
    }
    /// An error in `path` not tied to a line.
    pub fn file(path: &Path, message: impl Into<String>) -> Self {
        MeshError {
            path: path.to_path_buf(),
            line: None,
            message: message.into(),
        }
    }
}

/// `value` is finite: NaN or ±Inf give [`Error::NonFinite`] naming `what`.
pub(crate) fn check_finite(what: &str, value: f64) -> Result<(), Error> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(Error::NonFinite(format!("{what} is {value}")))
    }
}

/// `value` is finite ([`Error::NonFinite`] otherwise) and > 0 ([`Error::InvalidArgument`]
/// otherwise); `what` names it and `unit` is its unit in the message.
pub(crate) fn check_positive(what: &str, value: f64, unit: &str) -> Result<(), Error> {
    check_finite(what, value)?;
    if value > 0.0 {
        Ok(())
    } else {
        Err(Error::InvalidArgument(format!(
            "{what} must be > 0 {unit}, got {value}"
        )))
    }
}

/// `value` is finite ([`Error::NonFinite`] otherwise) and >= 0 ([`Error::InvalidArgument`]
/// otherwise); `what` names it and `unit` is its unit in the message.
pub(crate) fn check_non_negative(what: &str, value: f64, unit: &str) -> Result<(), Error> {
    check_finite(what, value)?;
    if value >= 0.0 {
        Ok(())
    } else {
        Err(Error::InvalidArgument(format!(
            "{what} must be >= 0 {unit}, got {value}"
        )))
    }
}
