//! Meshes: `TetMesh`, `MeshReport`, `SurfaceMesh` and the `tissuesim.mesh` functions (readers,
//! writers, the default organ, lattice boxes). Node positions in m.

use crate::arrays::{from_indices, from_vec3s, indices, vec3, vec3s};
use crate::errors::{io_error, Check, ARRAYS};
use numpy::{PyArray1, PyArray2, PyArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;
use tissuesim::mesh as core;
use tissuesim::{Real, Vec3};

/// A tetrahedral mesh: nodes (n, 3) in m, tetrahedra (m, 4) node indices, positively oriented.
#[pyclass(module = "tissuesim.mesh", from_py_object)]
#[derive(Clone)]
pub struct TetMesh {
    pub(crate) inner: core::TetMesh,
}

#[pymethods]
impl TetMesh {
    /// A mesh from arrays as given (no cleaning: `World.add_body` checks them; use
    /// `TetMesh.from_raw` to re-orient and clean).
    #[new]
    fn new(nodes: &Bound<'_, PyAny>, tets: &Bound<'_, PyAny>) -> PyResult<Self> {
        Ok(TetMesh {
            inner: core::TetMesh {
                nodes: vec3s(nodes, "nodes")?,
                tets: indices::<4>(tets, "tets")?,
            },
        })
    }
    /// Validate and clean raw arrays: inverted tetrahedra re-oriented, degenerate ones and
    /// unreferenced nodes removed. Returns `(mesh, report)`; bad indices raise `ValueError`.
    #[staticmethod]
    fn from_raw(
        nodes: &Bound<'_, PyAny>,
        tets: &Bound<'_, PyAny>,
    ) -> PyResult<(TetMesh, MeshReport)> {
        let nodes = vec3s(nodes, "nodes")?;
        let tets = indices::<4>(tets, "tets")?;
        let (inner, report) = core::TetMesh::from_raw(nodes, tets, ARRAYS.as_ref()).py()?;
        Ok((TetMesh { inner }, MeshReport::from_core(report)))
    }
    /// Node positions (n, 3), m.
    #[getter]
    fn nodes<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        from_vec3s(py, self.inner.nodes.iter().copied())
    }
    /// Tetrahedra (m, 4), node indices.
    #[getter]
    fn tets<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<u32>> {
        from_indices(py, self.inner.tets.iter().copied())
    }
    /// Number of nodes.
    fn node_count(&self) -> usize {
        self.inner.nodes.len()
    }
    /// Number of tetrahedra.
    fn tet_count(&self) -> usize {
        self.inner.tets.len()
    }
    /// Boundary triangles (k, 3), node indices, outward oriented.
    fn boundary_triangles<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<u32>> {
        from_indices(py, self.inner.boundary_triangles().into_iter())
    }
    /// Sum of the tetrahedron volumes (m³).
    fn volume(&self) -> Real {
        self.inner.volume()
    }
    /// Axis-aligned bounding box `(min, max)` of the nodes, each (3,), m.
    fn bounding_box<'py>(
        &self,
        py: Python<'py>,
    ) -> (Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>) {
        let (lo, hi) = self.inner.bounding_box();
        (
            crate::arrays::from_vec3(py, lo),
            crate::arrays::from_vec3(py, hi),
        )
    }
    /// Mean length of the tetrahedron edges (m).
    fn mean_edge_length(&self) -> Real {
        self.inner.mean_edge_length()
    }
    /// A copy with every node moved by `offset` (m).
    fn translated(&self, offset: &Bound<'_, PyAny>) -> PyResult<TetMesh> {
        let d = vec3(offset, "offset")?;
        let mut inner = self.inner.clone();
        inner.nodes.iter_mut().for_each(|p| *p += d);
        Ok(TetMesh { inner })
    }
    fn __repr__(&self) -> String {
        format!(
            "TetMesh({} nodes, {} tetrahedra)",
            self.inner.nodes.len(),
            self.inner.tets.len()
        )
    }
}

/// What cleaning a raw mesh changed.
#[pyclass(module = "tissuesim.mesh", frozen)]
pub struct MeshReport {
    #[pyo3(get)]
    pub reoriented_tets: usize,
    #[pyo3(get)]
    pub degenerate_tets_removed: usize,
    #[pyo3(get)]
    pub unreferenced_nodes_removed: usize,
    #[pyo3(get)]
    pub skipped_elements: usize,
    original: Vec<u32>,
}

impl MeshReport {
    fn from_core(r: core::MeshReport) -> Self {
        MeshReport {
            reoriented_tets: r.reoriented_tets,
            degenerate_tets_removed: r.degenerate_tets_removed,
            unreferenced_nodes_removed: r.unreferenced_nodes_removed,
            skipped_elements: r.skipped_elements,
            original: r.original_node_index,
        }
    }
}

#[pymethods]
impl MeshReport {
    /// For each node kept, its 0-based position in the file's (or array's) node list (n,).
    #[getter]
    fn original_node_index<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<u32>> {
        PyArray1::from_slice(py, &self.original)
    }
    fn __repr__(&self) -> String {
        format!(
            "MeshReport(reoriented_tets={}, degenerate_tets_removed={}, \
             unreferenced_nodes_removed={}, skipped_elements={})",
            self.reoriented_tets,
            self.degenerate_tets_removed,
            self.unreferenced_nodes_removed,
            self.skipped_elements
        )
    }
}

/// A triangulated surface (an OBJ tool shape): vertices (n, 3) m, triangles (k, 3).
#[pyclass(module = "tissuesim.mesh", frozen)]
pub struct SurfaceMesh {
    pub(crate) inner: core::SurfaceMesh,
}

#[pymethods]
impl SurfaceMesh {
    /// Vertex positions (n, 3), m.
    #[getter]
    fn vertices<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        from_vec3s(py, self.inner.vertices.iter().copied())
    }
    /// Triangles (k, 3), vertex indices.
    #[getter]
    fn triangles<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<u32>> {
        from_indices(py, self.inner.triangles.iter().copied())
    }
    fn __repr__(&self) -> String {
        format!(
            "SurfaceMesh({} vertices, {} triangles)",
            self.inner.vertices.len(),
            self.inner.triangles.len()
        )
    }
}

/// Load a tetrahedral mesh (.msh Gmsh, .node/.ele TetGen, .vtk legacy VTK), positions times
/// `scale` (mesh units to m). Returns `(mesh, report)`; raises `MeshError` (an `OSError`).
#[pyfunction]
#[pyo3(signature = (path, scale = 1.0))]
fn mesh_load(py: Python<'_>, path: PathBuf, scale: Real) -> PyResult<(TetMesh, MeshReport)> {
    let (inner, report) = py.detach(|| core::load(&path, scale)).py()?;
    Ok((TetMesh { inner }, MeshReport::from_core(report)))
}

/// The embedded default organ (2,243 nodes, ~0.2 m, generated: no file needed).
#[pyfunction]
fn mesh_default_organ(py: Python<'_>) -> TetMesh {
    TetMesh {
        inner: py.detach(core::default_organ),
    }
}

/// The default organ's shape on a lattice of cubes of edge `cell` (m, clamped to [0.003, 0.05]).
#[pyfunction]
fn mesh_organ_with_cell(py: Python<'_>, cell: Real) -> PyResult<TetMesh> {
    if !cell.is_finite() {
        return Err(PyValueError::new_err(format!(
            "cell must be finite, got {cell}"
        )));
    }
    Ok(TetMesh {
        inner: py.detach(|| core::organ_with_cell(cell)),
    })
}

/// A box `[min, max]` (m) filled with a lattice of `cells` = (nx, ny, nz) cells, each split
/// into six tetrahedra; node (i, j, k) has index i + (nx+1)(j + (ny+1)k).
#[pyfunction]
fn mesh_lattice_box(
    min: &Bound<'_, PyAny>,
    max: &Bound<'_, PyAny>,
    cells: [usize; 3],
) -> PyResult<TetMesh> {
    let (lo, hi) = (vec3(min, "min")?, vec3(max, "max")?);
    if !(lo.iter().chain(hi.iter()).all(|v| v.is_finite()) && (0..3).all(|k| lo[k] < hi[k])) {
        return Err(PyValueError::new_err(
            "lattice_box: min and max must be finite with min < max on every axis",
        ));
    }
    if cells.iter().any(|&c| c == 0 || c > 1000) || cells.iter().product::<usize>() > 1_000_000 {
        return Err(PyValueError::new_err(format!(
            "lattice_box: cells must be in 1..=1000 per axis and at most 10^6 in all, got {cells:?}"
        )));
    }
    Ok(TetMesh {
        inner: core::lattice_box(lo, hi, cells),
    })
}

/// Read a Wavefront OBJ surface (`v` and `f` records), positions times `scale`.
#[pyfunction]
#[pyo3(signature = (path, scale = 1.0))]
fn mesh_read_obj(path: PathBuf, scale: Real) -> PyResult<SurfaceMesh> {
    Ok(SurfaceMesh {
        inner: core::read_obj(&path, scale).py()?,
    })
}

/// Write `mesh` as legacy VTK ASCII (readable by `load`).
#[pyfunction]
fn mesh_write_vtk(path: PathBuf, mesh: &TetMesh) -> PyResult<()> {
    core::write_vtk(&path, &mesh.inner).map_err(|e| io_error(&path, e))
}

/// Named per-point arrays of a dict: scalars (n,) or vectors (n, 3).
fn point_data<T>(
    data: Option<&Bound<'_, PyDict>>,
    n: usize,
    read: impl Fn(&Bound<'_, PyAny>, &str) -> PyResult<Vec<T>>,
) -> PyResult<Vec<(String, Vec<T>)>> {
    let mut out = Vec::new();
    if let Some(d) = data {
        for (k, v) in d.iter() {
            let name: String = k.extract()?;
            let values = read(&v, &name)?;
            if values.len() != n {
                return Err(PyValueError::new_err(format!(
                    "point data `{name}` has {} values, {n} points",
                    values.len()
                )));
            }
            out.push((name, values));
        }
    }
    Ok(out)
}

/// Scalars (n,) as floats.
fn scalars(v: &Bound<'_, PyAny>, name: &str) -> PyResult<Vec<Real>> {
    let np = v.py().import("numpy")?;
    let a = np.call_method1("ascontiguousarray", (v, "float64"))?;
    let a = a.cast_into::<PyArray1<f64>>().map_err(|_| {
        PyValueError::new_err(format!("point scalars `{name}` must have shape (n,)"))
    })?;
    Ok(a.readonly().as_slice()?.to_vec())
}

/// Write a volume mesh state for ParaView as VTU: `positions` (n, 3) m, `tets` (m, 4), and
/// optional per-point data `{name: (n,)}` and `{name: (n, 3)}`.
#[pyfunction]
#[pyo3(signature = (path, positions, tets, point_scalars = None, point_vectors = None))]
fn mesh_write_vtu(
    path: PathBuf,
    positions: &Bound<'_, PyAny>,
    tets: &Bound<'_, PyAny>,
    point_scalars: Option<&Bound<'_, PyDict>>,
    point_vectors: Option<&Bound<'_, PyDict>>,
) -> PyResult<()> {
    let x = vec3s(positions, "positions")?;
    let t = indices::<4>(tets, "tets")?;
    if let Some(bad) = t.iter().flatten().find(|&&k| k as usize >= x.len()) {
        return Err(PyValueError::new_err(format!(
            "tets: index {bad} out of range ({} points)",
            x.len()
        )));
    }
    let s = point_data(point_scalars, x.len(), scalars)?;
    let v = point_data(point_vectors, x.len(), vec3s)?;
    let s: Vec<(&str, &[Real])> = s.iter().map(|(k, v)| (k.as_str(), v.as_slice())).collect();
    let v: Vec<(&str, &[Vec3])> = v.iter().map(|(k, v)| (k.as_str(), v.as_slice())).collect();
    core::write_vtu(&path, &x, &t, &s, &v).map_err(|e| io_error(&path, e))
}

/// Write a triangulated surface for ParaView as VTU: `positions` (n, 3) m, `triangles` (k, 3),
/// and optional per-point data `{name: (n,)}` and `{name: (n, 3)}`.
#[pyfunction]
#[pyo3(signature = (path, positions, triangles, point_scalars = None, point_vectors = None))]
fn mesh_write_vtu_surface(
    path: PathBuf,
    positions: &Bound<'_, PyAny>,
    triangles: &Bound<'_, PyAny>,
    point_scalars: Option<&Bound<'_, PyDict>>,
    point_vectors: Option<&Bound<'_, PyDict>>,
) -> PyResult<()> {
    let x = vec3s(positions, "positions")?;
    let t = indices::<3>(triangles, "triangles")?;
    if let Some(bad) = t.iter().flatten().find(|&&k| k as usize >= x.len()) {
        return Err(PyValueError::new_err(format!(
            "triangles: index {bad} out of range ({} points)",
            x.len()
        )));
    }
    let s = point_data(point_scalars, x.len(), scalars)?;
    let v = point_data(point_vectors, x.len(), vec3s)?;
    let s: Vec<(&str, &[Real])> = s.iter().map(|(k, v)| (k.as_str(), v.as_slice())).collect();
    let v: Vec<(&str, &[Vec3])> = v.iter().map(|(k, v)| (k.as_str(), v.as_slice())).collect();
    core::write_vtu_surface(&path, &x, &t, &s, &v).map_err(|e| io_error(&path, e))
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<TetMesh>()?;
    m.add_class::<MeshReport>()?;
    m.add_class::<SurfaceMesh>()?;
    m.add_function(wrap_pyfunction!(mesh_load, m)?)?;
    m.add_function(wrap_pyfunction!(mesh_default_organ, m)?)?;
    m.add_function(wrap_pyfunction!(mesh_organ_with_cell, m)?)?;
    m.add_function(wrap_pyfunction!(mesh_lattice_box, m)?)?;
    m.add_function(wrap_pyfunction!(mesh_read_obj, m)?)?;
    m.add_function(wrap_pyfunction!(mesh_write_vtk, m)?)?;
    m.add_function(wrap_pyfunction!(mesh_write_vtu, m)?)?;
    m.add_function(wrap_pyfunction!(mesh_write_vtu_surface, m)?)?;
    Ok(())
}
