//! Tools: `ToolShape` (every shape of the Rust enum), `Pose`, `ToolOptions`, `Wrench`, and the
//! `Tool` view of a tool in a world.

use crate::arrays::{from_indices, from_vec3, from_vec3s, indices, vec3, vec3s};
use crate::errors::Check;
use crate::world::{ToolId, World};
use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;
use tissuesim::{Real, Vec3};

/// The shape of a tool in its own frame (m): `ToolShape.Sphere(radius)`, `Capsule`,
/// `Cylinder` (along local y), `Cuboid`, `ConvexHull`, `TriMesh`, or `from_obj`.
#[pyclass(module = "tissuesim", frozen, from_py_object)]
#[derive(Clone)]
pub struct ToolShape {
    pub(crate) inner: tissuesim::ToolShape,
}

impl ToolShape {
    fn checked(inner: tissuesim::ToolShape) -> PyResult<Self> {
        inner.validate().py()?;
        Ok(ToolShape { inner })
    }
}

#[pymethods]
impl ToolShape {
    /// A sphere of `radius` (m) centred on the tool origin.
    #[staticmethod]
    #[allow(non_snake_case)]
    #[pyo3(signature = (radius))]
    fn Sphere(radius: Real) -> PyResult<Self> {
        Self::checked(tissuesim::ToolShape::Sphere { radius })
    }
    /// A capsule along local y: segment half-length `half_height` (m), `radius` (m).
    #[staticmethod]
    #[allow(non_snake_case)]
    #[pyo3(signature = (half_height, radius))]
    fn Capsule(half_height: Real, radius: Real) -> PyResult<Self> {
        Self::checked(tissuesim::ToolShape::Capsule {
            half_height,
            radius,
        })
    }
    /// A cylinder along local y: half-length `half_height` (m), `radius` (m).
    #[staticmethod]
    #[allow(non_snake_case)]
    #[pyo3(signature = (half_height, radius))]
    fn Cylinder(half_height: Real, radius: Real) -> PyResult<Self> {
        Self::checked(tissuesim::ToolShape::Cylinder {
            half_height,
            radius,
        })
    }
    /// A box with `half_extents` (3,) along local x, y, z (m).
    #[staticmethod]
    #[allow(non_snake_case)]
    #[pyo3(signature = (half_extents))]
    fn Cuboid(half_extents: &Bound<'_, PyAny>) -> PyResult<Self> {
        Self::checked(tissuesim::ToolShape::Cuboid {
            half_extents: vec3(half_extents, "half_extents")?,
        })
    }
    /// The convex hull of `points` (n, 3), m, local frame (at least 4, not coplanar).
    #[staticmethod]
    #[allow(non_snake_case)]
    #[pyo3(signature = (points))]
    fn ConvexHull(points: &Bound<'_, PyAny>) -> PyResult<Self> {
        Self::checked(tissuesim::ToolShape::ConvexHull {
            points: vec3s(points, "points")?,
        })
    }
    /// A triangle mesh: `vertices` (n, 3) m, `triangles` (k, 3) vertex indices.
    #[staticmethod]
    #[allow(non_snake_case)]
    #[pyo3(signature = (vertices, triangles))]
    fn TriMesh(vertices: &Bound<'_, PyAny>, triangles: &Bound<'_, PyAny>) -> PyResult<Self> {
        Self::checked(tissuesim::ToolShape::TriMesh {
            vertices: vec3s(vertices, "vertices")?,
            triangles: indices::<3>(triangles, "triangles")?,
        })
    }
    /// A triangle mesh read from an OBJ file, positions times `scale` (to m).
    #[staticmethod]
    #[pyo3(signature = (path, scale = 1.0))]
    fn from_obj(path: PathBuf, scale: Real) -> PyResult<Self> {
        let s = tissuesim::mesh::read_obj(&path, scale).py()?;
        Self::checked(tissuesim::ToolShape::TriMesh {
            vertices: s.vertices,
            triangles: s.triangles,
        })
    }
    /// The variant's name: "Sphere", "Capsule", "Cylinder", "Cuboid", "ConvexHull" or "TriMesh".
    #[getter]
    fn kind(&self) -> &'static str {
        match self.inner {
            tissuesim::ToolShape::Sphere { .. } => "Sphere",
            tissuesim::ToolShape::Capsule { .. } => "Capsule",
            tissuesim::ToolShape::Cylinder { .. } => "Cylinder",
            tissuesim::ToolShape::Cuboid { .. } => "Cuboid",
            tissuesim::ToolShape::ConvexHull { .. } => "ConvexHull",
            tissuesim::ToolShape::TriMesh { .. } => "TriMesh",
        }
    }
    /// The variant's fields as a dict (lengths in m; arrays as numpy arrays).
    fn parameters<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        match &self.inner {
            tissuesim::ToolShape::Sphere { radius } => d.set_item("radius", radius)?,
            tissuesim::ToolShape::Capsule {
                half_height,
                radius,
            }
            | tissuesim::ToolShape::Cylinder {
                half_height,
                radius,
            } => {
                d.set_item("half_height", half_height)?;
                d.set_item("radius", radius)?;
            }
            tissuesim::ToolShape::Cuboid { half_extents } => {
                d.set_item("half_extents", from_vec3(py, *half_extents))?
            }
            tissuesim::ToolShape::ConvexHull { points } => {
                d.set_item("points", from_vec3s(py, points.iter().copied()))?
            }
            tissuesim::ToolShape::TriMesh {
                vertices,
                triangles,
            } => {
                d.set_item("vertices", from_vec3s(py, vertices.iter().copied()))?;
                d.set_item("triangles", from_indices(py, triangles.iter().copied()))?;
            }
        }
        Ok(d)
    }
    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        let p = self.parameters(py)?;
        let mut parts = Vec::new();
        for (k, v) in p.iter() {
            let shown = match v.getattr("shape") {
                Ok(shape) => format!("array{}", shape.repr()?),
                Err(_) => v.repr()?.to_string(),
            };
            parts.push(format!("{}={}", k, shown));
        }
        Ok(format!("ToolShape.{}({})", self.kind(), parts.join(", ")))
    }
}

/// A rigid pose: `position` (3,) m and `orientation` (w, x, y, z) unit quaternion, local to
/// world.
#[pyclass(module = "tissuesim", frozen, from_py_object)]
#[derive(Clone, Copy)]
pub struct Pose {
    pub(crate) inner: tissuesim::Pose,
}

#[pymethods]
impl Pose {
    /// A pose from `position` (m) and `orientation` (w, x, y, z), normalised here; NaN/Inf or a
    /// zero quaternion raise `ValueError`.
    #[new]
    #[pyo3(signature = (position, orientation = [1.0, 0.0, 0.0, 0.0]))]
    fn new(position: &Bound<'_, PyAny>, orientation: [Real; 4]) -> PyResult<Self> {
        let p = vec3(position, "position")?;
        Ok(Pose {
            inner: tissuesim::Pose::from_components([p.x, p.y, p.z], orientation).py()?,
        })
    }
    /// A pose at `position` (m) with the identity orientation.
    #[staticmethod]
    fn at(position: &Bound<'_, PyAny>) -> PyResult<Self> {
        let p = vec3(position, "position")?;
        Self::new_checked(tissuesim::Pose::at(p))
    }
    /// Linear in position, slerp in orientation: `a` at s = 0, `b` at s = 1.
    #[staticmethod]
    fn interpolate(a: &Pose, b: &Pose, s: Real) -> Pose {
        Pose {
            inner: tissuesim::Pose::interpolate(&a.inner, &b.inner, s),
        }
    }
    /// Position of the tool origin (3,), m, world frame.
    #[getter]
    fn position<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        from_vec3(py, self.inner.position)
    }
    /// Orientation quaternion (4,): (w, x, y, z).
    #[getter]
    fn orientation<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.quaternion().to_vec())
    }
    /// True when finite with a unit quaternion.
    fn is_valid(&self) -> bool {
        self.inner.is_valid()
    }
    /// Where `point` (3,), given in the tool's frame (m), is in the world frame.
    fn transform_point<'py>(
        &self,
        py: Python<'py>,
        point: &Bound<'_, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let p = vec3(point, "point")?;
        Ok(from_vec3(
            py,
            self.inner.orientation * p + self.inner.position,
        ))
    }
    fn __eq__(&self, other: &Pose) -> bool {
        self.inner == other.inner
    }
    fn __repr__(&self) -> String {
        let p = self.inner.position;
        let q = self.quaternion();
        format!(
            "Pose(position=({}, {}, {}), orientation=({}, {}, {}, {}))",
            p.x, p.y, p.z, q[0], q[1], q[2], q[3]
        )
    }
}

impl Pose {
    fn new_checked(inner: tissuesim::Pose) -> PyResult<Self> {
        if !inner.is_valid() {
            return Err(tissuesim::Error::NonFinite("tool pose".into())).py();
        }
        Ok(Pose { inner })
    }
    /// (w, x, y, z).
    fn quaternion(&self) -> [Real; 4] {
        let q = self.inner.orientation.quaternion();
        [q.w, q.i, q.j, q.k]
    }
}

/// Friction of a tool (μ_s ≥ μ_k ≥ 0) and the sample spacing of the sampled contact mode (m).
#[pyclass(module = "tissuesim", get_all, set_all, eq, from_py_object)]
#[derive(Clone, PartialEq, Debug)]
pub struct ToolOptions {
    /// Static friction coefficient mu_s (dimensionless). Default 0.
    pub friction_static: Real,
    /// Kinetic friction coefficient mu_k <= mu_s (dimensionless). Default 0.
    pub friction_kinetic: Real,
    /// Surface sample spacing (m) of the sampled contact mode; None: particle radius.
    pub sample_spacing: Option<Real>,
}

impl ToolOptions {
    pub(crate) fn to_core(&self) -> tissuesim::ToolOptions {
        tissuesim::ToolOptions {
            friction_static: self.friction_static,
            friction_kinetic: self.friction_kinetic,
            sample_spacing: self.sample_spacing,
        }
    }
    pub(crate) fn from_core(o: &tissuesim::ToolOptions) -> Self {
        ToolOptions {
            friction_static: o.friction_static,
            friction_kinetic: o.friction_kinetic,
            sample_spacing: o.sample_spacing,
        }
    }
}

#[pymethods]
impl ToolOptions {
    /// Frictionless, automatic sample spacing; any field by keyword.
    #[new]
    #[pyo3(signature = (**kwargs))]
    fn new(kwargs: Option<&Bound<'_, PyDict>>) -> PyResult<Self> {
        let mut s = ToolOptions::from_core(&tissuesim::ToolOptions::default());
        apply_kwargs!(
            s,
            kwargs,
            [friction_static, friction_kinetic, sample_spacing]
        );
        Ok(s)
    }
    /// Check the options (`ValueError`).
    fn validate(&self) -> PyResult<()> {
        self.to_core().validate().py()
    }
    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        let s = self;
        repr_fields!(
            py,
            "ToolOptions",
            s,
            [friction_static, friction_kinetic, sample_spacing]
        )
    }
}

/// The wrench the tissue exerts on a tool, averaged over the substeps of the last step.
#[pyclass(module = "tissuesim", frozen)]
pub struct Wrench {
    pub(crate) inner: tissuesim::Wrench,
}

#[pymethods]
impl Wrench {
    /// Force on the tool (3,), N, world frame.
    #[getter]
    fn force<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        from_vec3(py, self.inner.force)
    }
    /// Torque on the tool about its origin (3,), N·m, world frame.
    #[getter]
    fn torque<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        from_vec3(py, self.inner.torque)
    }
    /// Contacts at the last substep.
    #[getter]
    fn contact_count(&self) -> u32 {
        self.inner.contact_count
    }
    /// Largest contact violation before projection in the last step (m).
    #[getter]
    fn max_penetration(&self) -> Real {
        self.inner.max_penetration
    }
    fn __repr__(&self) -> String {
        let (f, t) = (self.inner.force, self.inner.torque);
        format!(
            "Wrench(force=({:.6}, {:.6}, {:.6}), torque=({:.6}, {:.6}, {:.6}), \
             contact_count={}, max_penetration={})",
            f.x, f.y, f.z, t.x, t.y, t.z, self.inner.contact_count, self.inner.max_penetration
        )
    }
}

/// A tool of a world (a view: every call reads the world's current state).
#[pyclass(module = "tissuesim", frozen)]
pub struct Tool {
    pub(crate) world: Py<World>,
    pub(crate) id: ToolId,
}

impl Tool {
    fn with<T>(&self, py: Python<'_>, f: impl FnOnce(&tissuesim::Tool) -> T) -> PyResult<T> {
        let w = self.world.bind(py).try_borrow()?;
        Ok(f(w.inner.tool(self.id.into()).py()?))
    }
}

#[pymethods]
impl Tool {
    /// The tool's id.
    #[getter]
    fn id(&self) -> ToolId {
        self.id
    }
    /// Pose at the end of the last step.
    fn pose(&self, py: Python<'_>) -> PyResult<Pose> {
        self.with(py, |t| Pose { inner: t.pose() })
    }
    /// Pose to reach at the end of the next step.
    fn target_pose(&self, py: Python<'_>) -> PyResult<Pose> {
        self.with(py, |t| Pose {
            inner: t.target_pose(),
        })
    }
    /// The tool's shape.
    fn shape(&self, py: Python<'_>) -> PyResult<ToolShape> {
        self.with(py, |t| ToolShape {
            inner: t.shape().clone(),
        })
    }
    /// The tool's options (a copy).
    fn options(&self, py: Python<'_>) -> PyResult<ToolOptions> {
        self.with(py, |t| ToolOptions::from_core(t.options()))
    }
    /// Linear velocity of the origin over the last step (3,), m/s.
    fn linear_velocity<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let v = self.with(py, |t| t.linear_velocity())?;
        Ok(from_vec3(py, v))
    }
    /// The wrench of the last step.
    fn wrench(&self, py: Python<'_>) -> PyResult<Wrench> {
        self.with(py, |t| Wrench { inner: t.wrench() })
    }
    /// Number of surface samples (sampled contact mode).
    fn sample_count(&self, py: Python<'_>) -> PyResult<usize> {
        self.with(py, |t| t.sample_count())
    }
    /// Signed distance (m) from `point` (3,) to the tool's surface at `pose` (< 0 inside).
    fn signed_distance(
        &self,
        py: Python<'_>,
        pose: &Pose,
        point: &Bound<'_, PyAny>,
    ) -> PyResult<Real> {
        let p: Vec3 = vec3(point, "point")?;
        if !p.iter().all(|c| c.is_finite()) || !pose.inner.is_valid() {
            return Err(tissuesim::Error::NonFinite(
                "signed_distance: point or pose".into(),
            ))
            .py();
        }
        self.with(py, |t| t.signed_distance(&pose.inner, &p))
    }
    fn __repr__(&self) -> String {
        format!("Tool(id={})", self.id.0)
    }
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<ToolShape>()?;
    m.add_class::<Pose>()?;
    m.add_class::<ToolOptions>()?;
    m.add_class::<Wrench>()?;
    m.add_class::<Tool>()?;
    Ok(())
}
