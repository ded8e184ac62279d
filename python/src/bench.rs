//! The Rust side of the overhead benchmark (python/bench/overhead.py): the haptic loop
//! (set_tool_pose + step + wrench) run in Rust on a Python world, each step timed.

use crate::arrays::vec3s;
use crate::errors::Check;
use crate::world::{ToolId, World};
use numpy::PyArray1;
use pyo3::prelude::*;
use std::time::Instant;

/// Run `len(positions)` steps of `world`, before each one setting `tool`'s pose to the next
/// row of `positions` (k, 3), m, and after it reading the wrench, all in Rust with the GIL
/// released; returns each step's time (s), measured as the Python loop measures its own.
#[pyfunction]
fn _bench_rust_loop<'py>(
    py: Python<'py>,
    world: &Bound<'py, World>,
    tool: &Bound<'py, PyAny>,
    positions: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let id = ToolId::of(tool)?;
    let path = vec3s(positions, "positions")?;
    let mut w = world.try_borrow_mut()?;
    let w = &mut w.inner;
    let times = py.detach(|| -> Result<Vec<f64>, tissuesim::Error> {
        let mut times = Vec::with_capacity(path.len());
        let mut sink = 0.0;
        for p in &path {
            let t0 = Instant::now();
            w.set_tool_pose(id, tissuesim::Pose::at(*p))?;
            w.step()?;
            sink += w.tool(id)?.wrench().force.z;
            times.push(t0.elapsed().as_secs_f64());
        }
        std::hint::black_box(sink);
        Ok(times)
    });
    Ok(PyArray1::from_vec(py, times.py()?))
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(_bench_rust_loop, m)?)?;
    Ok(())
}
