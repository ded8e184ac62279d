//! `WorldState`: the dynamic state of a world as one value (`World.state` / `set_state`), and
//! its checksummed bytes (`to_bytes` / `from_bytes`, the format of `save_state`).

use crate::errors::Check;
use pyo3::prelude::*;
use pyo3::types::PyBytes;
use tissuesim::Real;

/// The dynamic state of a world: time, particles, fixed flags, cuts, tool poses, grasps and
/// needles (not the scene itself).
#[pyclass(module = "tissuesim", frozen)]
pub struct WorldState {
    pub(crate) inner: tissuesim::WorldState,
}

#[pymethods]
impl WorldState {
    /// Simulated time (s).
    fn time(&self) -> Real {
        self.inner.time()
    }
    /// Number of bodies.
    fn body_count(&self) -> usize {
        self.inner.body_count()
    }
    /// Number of tools.
    fn tool_count(&self) -> usize {
        self.inner.tool_count()
    }
    /// The state as checksummed bytes (the format of `World.save_state`).
    fn to_bytes<'py>(&self, py: Python<'py>) -> Bound<'py, PyBytes> {
        let mut out = Vec::with_capacity(self.inner.byte_size());
        self.inner.to_bytes(&mut out);
        PyBytes::new(py, &out)
    }
    /// Size of `to_bytes()` (bytes).
    fn byte_size(&self) -> usize {
        self.inner.byte_size()
    }
    /// A state from bytes (`ValueError` for a bad version, size or checksum).
    #[staticmethod]
    fn from_bytes(data: &[u8]) -> PyResult<Self> {
        Ok(WorldState {
            inner: tissuesim::WorldState::from_bytes(data).py()?,
        })
    }
    fn __eq__(&self, other: &WorldState) -> bool {
        self.inner == other.inner
    }
    fn __repr__(&self) -> String {
        format!(
            "WorldState(time={}, bodies={}, tools={})",
            self.inner.time(),
            self.inner.body_count(),
            self.inner.tool_count()
        )
    }
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<WorldState>()?;
    Ok(())
}
