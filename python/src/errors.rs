//! `tissuesim::Error` as Python exceptions, with the core's message.
//!
//! - `Error::Mesh` from a file: `tissuesim.MeshError` (a subclass of `OSError`); from arrays
//!   (`<arrays>`): `ValueError`;
//! - `InvalidArgument`, `NonFinite`, unknown ids, `BadState`: `ValueError`;
//! - `Diverged`: `tissuesim.DivergedError` (a subclass of `RuntimeError`); the world was rolled
//!   back;
//! - any later variant: `RuntimeError`.

use pyo3::exceptions::{PyOSError, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use tissuesim::mesh::MeshError as CoreMeshError;
use tissuesim::Error;

pyo3::create_exception!(
    tissuesim,
    MeshError,
    PyOSError,
    "A mesh file could not be read or is malformed (the message names the file and line)."
);
pyo3::create_exception!(
    tissuesim,
    DivergedError,
    PyRuntimeError,
    "A step diverged and the world was rolled back to its state before the step."
);

/// The path meshes built from arrays report in their errors.
pub(crate) const ARRAYS: &str = "<arrays>";

/// The Python exception for a core error.
pub(crate) fn to_py(e: Error) -> PyErr {
    let message = e.to_string();
    match e {
        Error::Mesh(m) if m.path.as_os_str() == ARRAYS => PyValueError::new_err(message),
        Error::Mesh(_) => MeshError::new_err(message),
        Error::Diverged(_) => DivergedError::new_err(message),
        Error::InvalidArgument(_)
        | Error::NonFinite(_)
        | Error::UnknownBody(_)
        | Error::UnknownTool(_)
        | Error::UnknownRenderSurface(_)
        | Error::BadState(_) => PyValueError::new_err(message),
        _ => PyRuntimeError::new_err(message),
    }
}

/// `?`-friendly conversion of core results into Python results.
pub(crate) trait Check<T> {
    /// The value, or the Python exception for the error.
    fn py(self) -> PyResult<T>;
}

impl<T> Check<T> for Result<T, Error> {
    fn py(self) -> PyResult<T> {
        self.map_err(to_py)
    }
}

impl<T> Check<T> for Result<T, CoreMeshError> {
    fn py(self) -> PyResult<T> {
        self.map_err(|e| to_py(Error::Mesh(e)))
    }
}

/// An I/O error writing `path` as `OSError` naming the file.
pub(crate) fn io_error(path: &std::path::Path, e: std::io::Error) -> PyErr {
    PyOSError::new_err(format!("{}: {e}", path.display()))
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("MeshError", m.py().get_type::<MeshError>())?;
    m.add("DivergedError", m.py().get_type::<DivergedError>())?;
    Ok(())
}
