//! Render (visual) surfaces: `RenderMesh` (a visual mesh as loaded) and `RenderSurface` (a
//! view of one bound to a body in a world, with deformed positions and normals).

use crate::arrays::{from_indices, from_vec3s, indices, vec3s};
use crate::errors::{io_error, Check};
use crate::world::{BodyId, RenderSurfaceId, World};
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use std::path::PathBuf;
use tissuesim::render as core;
use tissuesim::Real;

/// Texture coordinates as an (n, 2) array.
fn uv_array<'py>(py: Python<'py>, t: &[[Real; 2]]) -> Bound<'py, PyArray2<f64>> {
    let data: Vec<f64> = t.iter().flatten().copied().collect();
    Array2::from_shape_vec((t.len(), 2), data)
        .expect("2 per vertex")
        .into_pyarray(py)
}

/// A triangulated visual surface: one vertex per distinct OBJ v/vt/vn triple, rest positions
/// in m.
#[pyclass(module = "tissuesim.render", frozen, from_py_object)]
#[derive(Clone)]
pub struct RenderMesh {
    pub(crate) inner: core::RenderMesh,
}

#[pymethods]
impl RenderMesh {
    /// A body's boundary as a render mesh: `nodes` (n, 3) m and `boundary` (k, 3) node
    /// indices, e.g. `from_boundary(body.rest_positions(), body.boundary_triangles())`.
    #[staticmethod]
    fn from_boundary(nodes: &Bound<'_, PyAny>, boundary: &Bound<'_, PyAny>) -> PyResult<Self> {
        let x = vec3s(nodes, "nodes")?;
        let t = indices::<3>(boundary, "boundary")?;
        if let Some(bad) = t.iter().flatten().find(|&&k| k as usize >= x.len()) {
            return Err(PyValueError::new_err(format!(
                "boundary: node {bad} out of range ({} nodes)",
                x.len()
            )));
        }
        Ok(RenderMesh {
            inner: core::RenderMesh::from_boundary(&x, &t),
        })
    }
    /// Number of render vertices.
    fn vertex_count(&self) -> usize {
        self.inner.vertex_count()
    }
    /// Rest positions (n, 3), m.
    #[getter]
    fn positions<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        from_vec3s(py, self.inner.positions.iter().copied())
    }
    /// Texture coordinates (n, 2).
    #[getter]
    fn texcoords<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        uv_array(py, &self.inner.texcoords)
    }
    /// File normals (n, 3) (zero where none).
    #[getter]
    fn normals<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        from_vec3s(py, self.inner.normals.iter().copied())
    }
    /// Triangles (k, 3), vertex indices.
    #[getter]
    fn triangles<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<u32>> {
        from_indices(py, self.inner.triangles.iter().copied())
    }
    /// Whether the file gave texture coordinates.
    #[getter]
    fn has_texcoords(&self) -> bool {
        self.inner.has_texcoords
    }
    fn __repr__(&self) -> String {
        format!(
            "RenderMesh({} vertices, {} triangles)",
            self.inner.vertex_count(),
            self.inner.triangles.len()
        )
    }
}

/// Read an OBJ render surface (v/vt/vn/f), positions times `scale` (to m).
#[pyfunction]
#[pyo3(signature = (path, scale = 1.0))]
fn render_read_obj(path: PathBuf, scale: Real) -> PyResult<RenderMesh> {
    Ok(RenderMesh {
        inner: core::read_obj(&path, scale).py()?,
    })
}

/// How a render surface was bound: vertices `inside` the rest tetrahedra, `outside`, and the
/// largest outside distance (m).
#[pyclass(module = "tissuesim.render", get_all, frozen)]
pub struct BindReport {
    pub inside: usize,
    pub outside: usize,
    pub max_outside_distance: Real,
}

#[pymethods]
impl BindReport {
    fn __repr__(&self) -> String {
        format!(
            "BindReport(inside={}, outside={}, max_outside_distance={})",
            self.inside, self.outside, self.max_outside_distance
        )
    }
}

/// A render surface of a world (a view: every call reads its last update;
/// `World.update_render_surface` recomputes it).
#[pyclass(module = "tissuesim", frozen)]
pub struct RenderSurface {
    pub(crate) world: Py<World>,
    pub(crate) id: RenderSurfaceId,
}

impl RenderSurface {
    fn with<T>(&self, py: Python<'_>, f: impl FnOnce(&core::RenderSurface) -> T) -> PyResult<T> {
        let w = self.world.bind(py).try_borrow()?;
        Ok(f(w.inner.render_surface(self.id.into()).py()?))
    }
}

#[pymethods]
impl RenderSurface {
    /// The surface's id.
    #[getter]
    fn id(&self) -> RenderSurfaceId {
        self.id
    }
    /// The body it is bound to.
    fn body(&self, py: Python<'_>) -> PyResult<BodyId> {
        self.with(py, |s| s.body().into())
    }
    /// Number of render vertices.
    fn vertex_count(&self, py: Python<'_>) -> PyResult<usize> {
        self.with(py, |s| s.vertex_count())
    }
    /// Triangles (k, 3), vertex indices.
    fn triangles<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<u32>>> {
        let w = self.world.bind(py).try_borrow()?;
        let s = w.inner.render_surface(self.id.into()).py()?;
        Ok(from_indices(py, s.triangles().iter().copied()))
    }
    /// Texture coordinates (n, 2).
    fn texcoords<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let w = self.world.bind(py).try_borrow()?;
        let s = w.inner.render_surface(self.id.into()).py()?;
        Ok(uv_array(py, s.texcoords()))
    }
    /// Deformed vertex positions (n, 3), m, at the last update.
    fn positions<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let w = self.world.bind(py).try_borrow()?;
        let s = w.inner.render_surface(self.id.into()).py()?;
        Ok(from_vec3s(py, s.positions().iter().copied()))
    }
    /// Unit vertex normals (n, 3) at the last update.
    fn normals<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let w = self.world.bind(py).try_borrow()?;
        let s = w.inner.render_surface(self.id.into()).py()?;
        Ok(from_vec3s(py, s.normals().iter().copied()))
    }
    /// The render mesh as loaded (a copy).
    fn mesh(&self, py: Python<'_>) -> PyResult<RenderMesh> {
        self.with(py, |s| RenderMesh {
            inner: s.mesh().clone(),
        })
    }
    /// How the vertices were bound.
    fn bind_report(&self, py: Python<'_>) -> PyResult<BindReport> {
        self.with(py, |s| {
            let r = s.bind_report();
            BindReport {
                inside: r.inside,
                outside: r.outside,
                max_outside_distance: r.max_outside_distance,
            }
        })
    }
    /// Write the surface at its last update as OBJ (m).
    fn write_obj(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        self.with(py, |s| s.write_obj(&path))?
            .map_err(|e| io_error(&path, e))
    }
    /// Write the surface at its last update as VTU with `Normals` and `TextureCoordinates`.
    fn write_vtu(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        self.with(py, |s| s.write_vtu(&path))?
            .map_err(|e| io_error(&path, e))
    }
    fn __repr__(&self) -> String {
        format!("RenderSurface(id={})", self.id.0)
    }
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<RenderMesh>()?;
    m.add_class::<BindReport>()?;
    m.add_class::<RenderSurface>()?;
    m.add_function(wrap_pyfunction!(render_read_obj, m)?)?;
    Ok(())
}
