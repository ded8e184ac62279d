//! Python bindings of tissuesim: a thin layer over the public Rust API, no physics here.
//!
//! The extension module `tissuesim._tissuesim` holds the classes; the Python package
//! `tissuesim` re-exports them under the Rust names (`tissuesim.World`, `tissuesim.mesh.load`,
//! ...). Per-particle arrays cross the boundary as numpy arrays of shape (n, 3), float64, in
//! the mesh's node order (as the C API); the Rust API's particle order stays inside.

use pyo3::prelude::*;

#[macro_use]
mod fields;
mod arrays;
mod bench;
mod body;
mod errors;
mod interaction;
mod material;
mod mesh;
mod render;
mod settings;
mod state;
mod statics;
mod tool;
mod world;

/// The compiled part of the `tissuesim` package.
#[pymodule]
fn _tissuesim(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    errors::register(m)?;
    settings::register(m)?;
    material::register(m)?;
    mesh::register(m)?;
    tool::register(m)?;
    interaction::register(m)?;
    body::register(m)?;
    render::register(m)?;
    state::register(m)?;
    statics::register(m)?;
    world::register(m)?;
    bench::register(m)?;
    Ok(())
}
