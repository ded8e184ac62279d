//! `Body` (a view of a body in a world) and `BodyModel` (a body's shared load-time data).
//!
//! Every per-particle array is in the mesh's node order: row k is the mesh's node k, as in the
//! C API. Index arrays (tetrahedra, boundary triangles) hold node indices.

use crate::arrays::{from_indices, from_vec3s, vec3, vec3s};
use crate::errors::Check;
use crate::material::{BodyOptions, Material};
use crate::mesh::TetMesh;
use crate::world::{BodyId, World};
use numpy::{PyArray1, PyArray2};
use pyo3::exceptions::PyIndexError;
use pyo3::prelude::*;
use std::sync::Arc;
use tissuesim::{ParticleOrder, Real, Vec3};

/// Per-particle vectors in node order.
pub(crate) fn node_order_vec3s<'py>(
    py: Python<'py>,
    order: &ParticleOrder,
    v: &[Vec3],
) -> Bound<'py, PyArray2<f64>> {
    from_vec3s(py, (0..v.len()).map(|k| v[order.particle(k)]))
}

/// Index arrays (particle indices) as node indices.
fn node_indices<'py, const K: usize>(
    py: Python<'py>,
    order: &ParticleOrder,
    t: &[[u32; K]],
) -> Bound<'py, PyArray2<u32>> {
    from_indices(
        py,
        t.iter()
            .map(|t| t.map(|i| order.mesh_index(i as usize) as u32)),
    )
}

/// Node-order positions (one per particle, finite) in particle order.
fn particle_positions(b: &tissuesim::Body, x: Vec<Vec3>) -> PyResult<Vec<Vec3>> {
    let n = b.particle_count();
    if x.len() != n {
        return Err(tissuesim::Error::InvalidArgument(format!(
            "positions: {n} nodes, got {}",
            x.len()
        )))
        .py();
    }
    if !x.iter().flatten().all(|c| c.is_finite()) {
        return Err(tissuesim::Error::NonFinite("positions".into())).py();
    }
    Ok(b.particle_order().to_particle_order(&x))
}

/// A body of a world (a view: every call reads the world's current state).
#[pyclass(module = "tissuesim", frozen)]
pub struct Body {
    pub(crate) world: Py<World>,
    pub(crate) id: BodyId,
}

impl Body {
    fn with<T>(&self, py: Python<'_>, f: impl FnOnce(&tissuesim::Body) -> T) -> PyResult<T> {
        let w = self.world.bind(py).try_borrow()?;
        Ok(f(w.inner.body(self.id.into()).py()?))
    }
    fn vectors<'py>(
        &self,
        py: Python<'py>,
        get: impl FnOnce(&tissuesim::Body) -> &[Vec3],
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let w = self.world.bind(py).try_borrow()?;
        let b = w.inner.body(self.id.into()).py()?;
        Ok(node_order_vec3s(py, b.particle_order(), get(b)))
    }
}

#[pymethods]
impl Body {
    /// The body's id.
    #[getter]
    fn id(&self) -> BodyId {
        self.id
    }
    /// Number of particles (= mesh nodes).
    fn particle_count(&self, py: Python<'_>) -> PyResult<usize> {
        self.with(py, |b| b.particle_count())
    }
    /// Positions (n, 3), m, node order.
    fn positions<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        self.vectors(py, |b| b.positions())
    }
    /// Velocities (n, 3), m/s, node order.
    fn velocities<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        self.vectors(py, |b| b.velocities())
    }
    /// Rest positions (n, 3), m, node order.
    fn rest_positions<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        self.vectors(py, |b| b.rest_positions())
    }
    /// Physical masses (n,), kg, node order.
    fn masses<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let v = self.with(py, |b| b.particle_order().to_mesh_order(b.masses()))?;
        Ok(PyArray1::from_vec(py, v))
    }
    /// Inertial masses (n,), kg, node order (physical plus mass scaling).
    fn inertial_masses<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let v = self.with(py, |b| {
            b.particle_order().to_mesh_order(b.inertial_masses())
        })?;
        Ok(PyArray1::from_vec(py, v))
    }
    /// Inertial mass added by selective mass scaling (kg).
    fn added_mass(&self, py: Python<'_>) -> PyResult<Real> {
        self.with(py, |b| b.added_mass())
    }
    /// Total physical mass (kg).
    fn mass(&self, py: Python<'_>) -> PyResult<Real> {
        self.with(py, |b| b.mass())
    }
    /// Tetrahedra (m, 4), node indices (removed ones left out after a cut).
    fn tets<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<u32>>> {
        let w = self.world.bind(py).try_borrow()?;
        let b = w.inner.body(self.id.into()).py()?;
        Ok(node_indices(py, b.particle_order(), b.tets()))
    }
    /// Boundary triangles (k, 3), node indices, outward (rebuilt after a cut).
    fn boundary_triangles<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<u32>>> {
        let w = self.world.bind(py).try_borrow()?;
        let b = w.inner.body(self.id.into()).py()?;
        Ok(node_indices(py, b.particle_order(), b.boundary_triangles()))
    }
    /// Current volume (m³): sum of the signed tetrahedron volumes.
    fn volume(&self, py: Python<'_>) -> PyResult<Real> {
        self.with(py, |b| b.volume())
    }
    /// Rest volume (m³).
    fn rest_volume(&self, py: Python<'_>) -> PyResult<Real> {
        self.with(py, |b| b.rest_volume())
    }
    /// volume / rest volume.
    fn volume_ratio(&self, py: Python<'_>) -> PyResult<Real> {
        self.with(py, |b| b.volume_ratio())
    }
    /// Largest distance of a particle from its rest position (m).
    fn max_displacement(&self, py: Python<'_>) -> PyResult<Real> {
        self.with(py, |b| b.max_displacement())
    }
    /// Whether mesh node `k` is fixed (`IndexError` when out of range).
    fn is_fixed(&self, py: Python<'_>, k: usize) -> PyResult<bool> {
        self.with(py, |b| {
            (k < b.particle_count()).then(|| b.is_fixed(b.particle_order().particle(k)))
        })?
        .ok_or_else(|| PyIndexError::new_err(format!("node {k} out of range")))
    }
    /// Fixed flags (n,), bool, node order.
    fn fixed_flags<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<bool>>> {
        let v = self.with(py, |b| {
            let o = b.particle_order();
            (0..b.particle_count())
                .map(|k| b.is_fixed(o.particle(k)))
                .collect::<Vec<bool>>()
        })?;
        Ok(PyArray1::from_vec(py, v))
    }
    /// Contact radius of the particles (m).
    fn particle_radius(&self, py: Python<'_>) -> PyResult<Real> {
        self.with(py, |b| b.particle_radius())
    }
    /// Contact skin of the exact-shape mode (m): a tenth of the particle radius.
    fn contact_skin(&self, py: Python<'_>) -> PyResult<Real> {
        self.with(py, |b| b.contact_skin())
    }
    /// The material (a copy).
    fn material(&self, py: Python<'_>) -> PyResult<Material> {
        self.with(py, |b| Material::from_core(b.material()))
    }
    /// Largest angular frequency of the linearised elastic system at rest (rad/s).
    fn max_angular_frequency(&self, py: Python<'_>) -> PyResult<Real> {
        self.with(py, |b| b.max_angular_frequency())
    }
    /// Whether `point` (3,), m, is inside the deformed body.
    fn contains(&self, py: Python<'_>, point: &Bound<'_, PyAny>) -> PyResult<bool> {
        let p = vec3(point, "point")?;
        if !p.iter().all(|c| c.is_finite()) {
            return Err(tissuesim::Error::NonFinite("contains: point".into())).py();
        }
        self.with(py, |b| b.contains(&p))
    }
    /// Deformation gradient F (3, 3) of mesh node `k` if the nodes were at `positions` (n, 3),
    /// m, node order (an analysis helper; the body is not changed).
    fn deformation_gradient_at<'py>(
        &self,
        py: Python<'py>,
        positions: &Bound<'py, PyAny>,
        k: usize,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let x = vec3s(positions, "positions")?;
        let f = self.with(py, |b| -> PyResult<tissuesim::Mat3> {
            let x = particle_positions(b, x)?;
            if k >= b.particle_count() {
                return Err(PyIndexError::new_err(format!("node {k} out of range")));
            }
            Ok(b.deformation_gradient_at(&x, b.particle_order().particle(k)))
        })??;
        let rows: Vec<Vec<f64>> = (0..3)
            .map(|r| (0..3).map(|c| f[(r, c)]).collect())
            .collect();
        Ok(PyArray2::from_vec2(py, &rows).expect("3 x 3"))
    }
    /// Elastic (and hourglass) forces (n, 3), N, on every node if the nodes were at
    /// `positions` (n, 3), m, node order, at rest (an analysis helper that allocates).
    fn elastic_forces_at<'py>(
        &self,
        py: Python<'py>,
        positions: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let x = vec3s(positions, "positions")?;
        let w = self.world.bind(py).try_borrow()?;
        let b = w.inner.body(self.id.into()).py()?;
        let x = particle_positions(b, x)?;
        let f = py.detach(|| b.elastic_forces_at(&x));
        Ok(node_order_vec3s(py, b.particle_order(), &f))
    }
    /// Neighbour pairs cut and tetrahedra removed so far.
    fn cut_counts(&self, py: Python<'_>) -> PyResult<(usize, usize)> {
        self.with(py, |b| b.cut_counts())
    }
    /// The body's model (for a cut body, its own cut copy).
    fn model(&self, py: Python<'_>) -> PyResult<BodyModel> {
        self.with(py, |b| BodyModel {
            inner: Arc::clone(b.model()),
        })
    }
    /// The uncut model the body was built on: `World.add_body_model` builds it again.
    fn load_time_model(&self, py: Python<'_>) -> PyResult<BodyModel> {
        self.with(py, |b| BodyModel {
            inner: Arc::clone(b.load_time_model()),
        })
    }
    /// For each particle (internal storage order), its mesh node index (n,).
    fn particle_order<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<u32>>> {
        let v = self.with(py, |b| b.particle_order().mesh_indices().to_vec())?;
        Ok(PyArray1::from_vec(py, v))
    }
    fn __repr__(&self) -> String {
        format!("Body(id={})", self.id.0)
    }
}

/// A body's immutable load-time data (rest positions, tetrahedra, neighbourhoods, masses),
/// shared by every body built on it.
#[pyclass(module = "tissuesim", frozen)]
pub struct BodyModel {
    pub(crate) inner: Arc<tissuesim::BodyModel>,
}

#[pymethods]
impl BodyModel {
    /// Build the model of `mesh` (m) with `options` (default: `BodyOptions()`); the GIL is
    /// released during the neighbour search.
    #[new]
    #[pyo3(signature = (mesh, options = None))]
    fn new(py: Python<'_>, mesh: &TetMesh, options: Option<&BodyOptions>) -> PyResult<Self> {
        let o = BodyOptions::or_default(options);
        let m = &mesh.inner;
        let inner = py.detach(|| tissuesim::BodyModel::new(m, &o)).py()?;
        Ok(BodyModel { inner })
    }
    /// Number of particles.
    fn particle_count(&self) -> usize {
        self.inner.particle_count()
    }
    /// Rest positions (n, 3), m, node order.
    fn rest_positions<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        node_order_vec3s(py, self.inner.particle_order(), self.inner.rest_positions())
    }
    /// Tetrahedra (m, 4), node indices.
    fn tets<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<u32>> {
        node_indices(py, self.inner.particle_order(), self.inner.tets())
    }
    /// The options it was built with (a copy).
    fn options(&self) -> BodyOptions {
        BodyOptions::from_core(self.inner.options())
    }
    /// Whether it was built from `mesh` with `options`.
    #[pyo3(signature = (mesh, options = None))]
    fn is_built_from(&self, mesh: &TetMesh, options: Option<&BodyOptions>) -> bool {
        self.inner
            .is_built_from(&mesh.inner, &BodyOptions::or_default(options))
    }
    /// Heap memory held (bytes).
    fn heap_bytes(&self) -> usize {
        self.inner.heap_bytes()
    }
    fn __repr__(&self) -> String {
        format!("BodyModel({} particles)", self.inner.particle_count())
    }
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Body>()?;
    m.add_class::<BodyModel>()?;
    Ok(())
}
