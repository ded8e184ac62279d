//! `tissuesim.statics`: the linear static solutions of the Rust `tissuesim::statics` module
//! (small-strain displacements from rest, node order), and the library's constants.

use crate::arrays::{vec3, vec3s};
use crate::body::{node_order_vec3s, Body};
use crate::errors::Check;
use numpy::PyArray2;
use pyo3::prelude::*;
use tissuesim::statics;

/// The linear static displacement (n, 3), m, of `body` from rest under gravity `g` (m/s²),
/// fixed nodes held: K u = m g. The GIL is released during the factorisation.
#[pyfunction]
fn statics_linear_gravity_sag<'py>(
    py: Python<'py>,
    body: &Body,
    g: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let g = vec3(g, "g")?;
    let w = body.world.bind(py).try_borrow()?;
    let b = w.inner.body(body.id.into()).py()?;
    let u = py.detach(|| statics::linear_gravity_sag(b, g)).py()?;
    Ok(node_order_vec3s(py, b.particle_order(), &u))
}

/// The linear static displacement (n, 3), m, of `body` from rest: K u = `load` (n, 3), N, on
/// the free nodes, u = `prescribed` (n, 3), m, on the fixed ones (node order).
#[pyfunction]
fn statics_linear_response<'py>(
    py: Python<'py>,
    body: &Body,
    load: &Bound<'py, PyAny>,
    prescribed: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let (f, p) = (vec3s(load, "load")?, vec3s(prescribed, "prescribed")?);
    let w = body.world.bind(py).try_borrow()?;
    let b = w.inner.body(body.id.into()).py()?;
    let order = b.particle_order();
    let reorder = |a: Vec<tissuesim::Vec3>| {
        if a.len() == order.len() {
            order.to_particle_order(&a)
        } else {
            a
        }
    };
    let (f, p) = (reorder(f), reorder(p));
    let u = py.detach(|| statics::linear_response(b, &f, &p)).py()?;
    Ok(node_order_vec3s(py, order, &u))
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(statics_linear_gravity_sag, m)?)?;
    m.add_function(wrap_pyfunction!(statics_linear_response, m)?)?;
    m.add("SETTLE_TOLERANCE", statics::SETTLE_TOLERANCE)?;
    m.add("SETTLE_MAX_ITERATIONS", statics::SETTLE_MAX_ITERATIONS)?;
    m.add("SETTLE_SPEED", statics::SETTLE_SPEED)?;
    m.add("SETTLE_MAX_STEPS", statics::SETTLE_MAX_STEPS)?;
    // The library's limits (tissuesim::*), each documented in the stub.
    m.add("MIN_POISSON_RATIO", tissuesim::MIN_POISSON_RATIO)?;
    m.add("MAX_POISSON_RATIO", tissuesim::MAX_POISSON_RATIO)?;
    m.add("YOUNGS_MODULUS_RANGE", tissuesim::YOUNGS_MODULUS_RANGE)?;
    m.add("DENSITY_RANGE", tissuesim::DENSITY_RANGE)?;
    m.add("PARTICLE_RADIUS_RANGE", tissuesim::PARTICLE_RADIUS_RANGE)?;
    m.add("SUPPORT_RADIUS_RANGE", tissuesim::SUPPORT_RADIUS_RANGE)?;
    m.add("STATE_POSITION_LIMIT", tissuesim::STATE_POSITION_LIMIT)?;
    m.add("STATE_SPEED_LIMIT", tissuesim::STATE_SPEED_LIMIT)?;
    m.add("TOOL_SIZE_RANGE", tissuesim::TOOL_SIZE_RANGE)?;
    m.add("MIN_QUATERNION_NORM", tissuesim::MIN_QUATERNION_NORM)?;
    m.add("CONVEX_HULL_FLATNESS", tissuesim::CONVEX_HULL_FLATNESS)?;
    m.add("MAX_NEIGHBOURS", tissuesim::MAX_NEIGHBOURS)?;
    m.add("TOOL_JUMP_FRACTION", tissuesim::TOOL_JUMP_FRACTION)?;
    m.add("SUBSTEP_HOLD_STEPS", tissuesim::SUBSTEP_HOLD_STEPS)?;
    Ok(())
}
