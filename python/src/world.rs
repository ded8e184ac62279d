//! `World`: the scene and its API, mirrored name for name from `tissuesim::World`; ids
//! (`BodyId`, `ToolId`, `RenderSurfaceId`); `StepReport` and `SettleReport`.
//!
//! Per-particle arrays in and out are in the mesh's node order. The GIL is released during
//! `step`, `settle`, `add_body` and the other calls that take long, so other Python threads
//! run meanwhile; a second thread calling into the same world during that time gets a
//! `RuntimeError` (already borrowed), never a data race.

use crate::arrays::{index_list, vec3, vec3s};
use crate::body::{Body, BodyModel};
use crate::errors::Check;
use crate::interaction::{Blade, CutReport, GraspOptions, NeedleOptions, NeedleState};
use crate::material::BodyOptions;
use crate::mesh::TetMesh;
use crate::render::{RenderMesh, RenderSurface};
use crate::settings::Settings;
use crate::state::WorldState;
use crate::tool::{Pose, Tool, ToolOptions, ToolShape};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict};
use std::sync::Arc;
use tissuesim::Real;

macro_rules! id_class {
    ($name:ident, $core:ident, $doc:literal) => {
        #[doc = $doc]
        #[pyclass(module = "tissuesim", frozen, eq, hash, from_py_object)]
        #[derive(Clone, Copy, PartialEq, Eq, Hash, Debug)]
        pub struct $name(pub u32);

        #[pymethods]
        impl $name {
            #[new]
            fn new(index: u32) -> Self {
                $name(index)
            }
            /// The index (insertion order in the world, never reused).
            #[getter]
            fn index(&self) -> u32 {
                self.0
            }
            fn __int__(&self) -> u32 {
                self.0
            }
            fn __index__(&self) -> u32 {
                self.0
            }
            fn __repr__(&self) -> String {
                format!("{}({})", stringify!($name), self.0)
            }
        }

        impl From<$name> for tissuesim::$core {
            fn from(id: $name) -> Self {
                tissuesim::$core(id.0)
            }
        }

        impl From<tissuesim::$core> for $name {
            fn from(id: tissuesim::$core) -> Self {
                $name(id.0)
            }
        }

        impl $name {
            /// An id from an id object or a plain int.
            pub(crate) fn of(obj: &Bound<'_, PyAny>) -> PyResult<tissuesim::$core> {
                if let Ok(id) = obj.cast::<$name>() {
                    return Ok(id.get().clone().into());
                }
                obj.extract::<u32>().map(tissuesim::$core).map_err(|_| {
                    PyTypeError::new_err(format!(
                        "expected a {} or a non-negative int, got {}",
                        stringify!($name),
                        obj.get_type().name().map_or("?".into(), |n| n.to_string())
                    ))
                })
            }
        }
    };
}

id_class!(BodyId, BodyId, "Identifies a body in its world.");
id_class!(ToolId, ToolId, "Identifies a tool in its world.");
id_class!(
    RenderSurfaceId,
    RenderSurfaceId,
    "Identifies a render surface in its world."
);

/// What one step did.
#[pyclass(module = "tissuesim", get_all, frozen)]
pub struct StepReport {
    pub substeps: u32,
    pub substeps_clamped: bool,
    pub cut: Py<CutReport>,
}

#[pymethods]
impl StepReport {
    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        Ok(format!(
            "StepReport(substeps={}, substeps_clamped={}, cut={})",
            self.substeps,
            if self.substeps_clamped {
                "True"
            } else {
                "False"
            },
            self.cut.bind(py).repr()?
        ))
    }
}

/// What `settle` did.
#[pyclass(module = "tissuesim", get_all, frozen)]
pub struct SettleReport {
    pub newton_iterations: u32,
    pub relative_residual: Real,
    pub relaxation_steps: u32,
    pub max_speed: Real,
    pub converged: bool,
}

#[pymethods]
impl SettleReport {
    fn __repr__(&self) -> String {
        format!(
            "SettleReport(newton_iterations={}, relative_residual={:e}, relaxation_steps={}, \
             max_speed={:e}, converged={})",
            self.newton_iterations,
            self.relative_residual,
            self.relaxation_steps,
            self.max_speed,
            if self.converged { "True" } else { "False" }
        )
    }
}

/// A simulated scene (SI units). `World(settings=None)`.
#[pyclass(module = "tissuesim")]
pub struct World {
    pub(crate) inner: tissuesim::World,
}

/// A pose from a `Pose` or a position (3,) (identity orientation).
fn pose_of(obj: &Bound<'_, PyAny>) -> PyResult<tissuesim::Pose> {
    if let Ok(p) = obj.cast::<Pose>() {
        return Ok(p.get().inner);
    }
    Ok(tissuesim::Pose::at(vec3(
        obj,
        "pose (a Pose or a position)",
    )?))
}

#[pymethods]
impl World {
    /// An empty world; `settings` (default `Settings()`) are validated first.
    #[new]
    #[pyo3(signature = (settings = None))]
    fn new(settings: Option<&Settings>) -> PyResult<Self> {
        let s = settings.map_or_else(tissuesim::Settings::default, Settings::to_core);
        Ok(World {
            inner: tissuesim::World::new(s).py()?,
        })
    }
    /// The settings in force (a copy).
    fn settings(&self) -> Settings {
        Settings::from_core(self.inner.settings())
    }
    /// Replace the settings (validated; nothing changes on error).
    fn set_settings(&mut self, settings: &Settings) -> PyResult<()> {
        self.inner.set_settings(settings.to_core()).py()
    }
    /// Simulated time (s).
    fn time(&self) -> Real {
        self.inner.time()
    }
    /// Number of steps that diverged and were rolled back.
    fn diverged_steps(&self) -> u64 {
        self.inner.diverged_steps()
    }
    /// Measure the wall time of every stage of the steps from now on (`True`), or stop
    /// (`False`, the default: a step then reads no clock). Profiling changes no result.
    fn set_profiling(&mut self, on: bool) {
        self.inner.set_profiling(on);
    }
    /// Where the last step's time went: a dict of each stage's wall time (s) by name (`state_copy`,
    /// `prediction`, `volume`, `organ_contact`, `self_contact`, `tool_contact`,
    /// `grasp_and_needle`, `update`, `end_of_step`, `total`); `None` while profiling is off or
    /// before a step has run since it was switched on.
    fn step_profile<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        let Some(p) = self.inner.step_profile() else {
            return Ok(None);
        };
        let stages = PyDict::new(py);
        for (name, time) in p.stages() {
            stages.set_item(name, time.as_secs_f64())?;
        }
        Ok(Some(stages))
    }
    /// Add a deformable body built from `mesh` (m) with `options` (default `BodyOptions()`).
    #[pyo3(signature = (mesh, options = None))]
    fn add_body(
        &mut self,
        py: Python<'_>,
        mesh: &TetMesh,
        options: Option<&BodyOptions>,
    ) -> PyResult<BodyId> {
        let o = BodyOptions::or_default(options);
        let (w, m) = (&mut self.inner, &mesh.inner);
        Ok(py.detach(|| w.add_body(m, &o)).py()?.into())
    }
    /// Add a body at rest on a shared `model` (no load-time work redone).
    fn add_body_model(&mut self, model: &BodyModel) -> BodyId {
        self.inner.add_body_model(Arc::clone(&model.inner)).into()
    }
    /// Number of bodies.
    fn body_count(&self) -> usize {
        self.inner.body_count()
    }
    /// The body `id` (a `BodyId` or an int); `ValueError` for an unknown id.
    fn body(slf: &Bound<'_, Self>, id: &Bound<'_, PyAny>) -> PyResult<Body> {
        let id = BodyId::of(id)?;
        slf.try_borrow()?.inner.body(id).py()?;
        Ok(Body {
            world: slf.clone().unbind(),
            id: id.into(),
        })
    }
    /// Set the positions (n, 3) m and velocities (n, 3) m/s of every particle of `body`, in
    /// node order. Nothing changes on error.
    fn set_body_state(
        &mut self,
        body: &Bound<'_, PyAny>,
        positions: &Bound<'_, PyAny>,
        velocities: &Bound<'_, PyAny>,
    ) -> PyResult<()> {
        let id = BodyId::of(body)?;
        let x = vec3s(positions, "positions")?;
        let v = vec3s(velocities, "velocities")?;
        let order = self.inner.body(id).py()?.particle_order();
        let reorder = |a: Vec<tissuesim::Vec3>| {
            if a.len() == order.len() {
                order.to_particle_order(&a)
            } else {
                a
            }
        };
        let (x, v) = (reorder(x), reorder(v));
        self.inner.set_body_state(id, &x, &v).py()
    }
    /// Bind a render mesh (rest frame, m) to `body`; returns its id.
    fn add_render_surface(
        &mut self,
        py: Python<'_>,
        body: &Bound<'_, PyAny>,
        mesh: &RenderMesh,
    ) -> PyResult<RenderSurfaceId> {
        let id = BodyId::of(body)?;
        let (w, m) = (&mut self.inner, mesh.inner.clone());
        Ok(py.detach(|| w.add_render_surface(id, m)).py()?.into())
    }
    /// Number of render surfaces.
    fn render_surface_count(&self) -> usize {
        self.inner.render_surface_count()
    }
    /// The render surface `id`, as of its last update.
    fn render_surface(slf: &Bound<'_, Self>, id: &Bound<'_, PyAny>) -> PyResult<RenderSurface> {
        let id = RenderSurfaceId::of(id)?;
        slf.try_borrow()?.inner.render_surface(id).py()?;
        Ok(RenderSurface {
            world: slf.clone().unbind(),
            id: id.into(),
        })
    }
    /// Recompute a render surface from its body's current positions and return it.
    fn update_render_surface(
        slf: &Bound<'_, Self>,
        id: &Bound<'_, PyAny>,
    ) -> PyResult<RenderSurface> {
        let id = RenderSurfaceId::of(id)?;
        slf.try_borrow_mut()?.inner.update_render_surface(id).py()?;
        Ok(RenderSurface {
            world: slf.clone().unbind(),
            id: id.into(),
        })
    }
    /// Fix the mesh nodes `indices` (1-D ints, node order) of `body`; nothing is fixed if any
    /// is out of range.
    fn fix_particles(
        &mut self,
        body: &Bound<'_, PyAny>,
        indices: &Bound<'_, PyAny>,
    ) -> PyResult<()> {
        let id = BodyId::of(body)?;
        let nodes = index_list(indices, "indices")?;
        let order = self.inner.body(id).py()?.particle_order();
        let n = order.len();
        // An index out of range stays as it is, for the core to refuse with its message.
        let particles: Vec<u32> = nodes
            .iter()
            .map(|&k| {
                if (k as usize) < n {
                    order.particle(k as usize) as u32
                } else {
                    k
                }
            })
            .collect();
        self.inner.fix_particles(id, &particles).py()
    }
    /// Fix every particle of `body` inside the box [min, max] (m); returns how many.
    fn fix_box(
        &mut self,
        body: &Bound<'_, PyAny>,
        min: &Bound<'_, PyAny>,
        max: &Bound<'_, PyAny>,
    ) -> PyResult<usize> {
        let id = BodyId::of(body)?;
        let (lo, hi) = (vec3(min, "min")?, vec3(max, "max")?);
        self.inner.fix_box(id, lo, hi).py()
    }
    /// Add a kinematic tool of `shape` at `pose` (a `Pose` or a position) with `options`.
    #[pyo3(signature = (shape, pose, options = None))]
    fn add_tool(
        &mut self,
        shape: &ToolShape,
        pose: &Bound<'_, PyAny>,
        options: Option<&ToolOptions>,
    ) -> PyResult<ToolId> {
        let o = options.map_or_else(tissuesim::ToolOptions::default, ToolOptions::to_core);
        let p = pose_of(pose)?;
        Ok(self.inner.add_tool(shape.inner.clone(), p, &o).py()?.into())
    }
    /// Remove a tool (its id is never reused).
    fn remove_tool(&mut self, tool: &Bound<'_, PyAny>) -> PyResult<()> {
        self.inner.remove_tool(ToolId::of(tool)?).py()
    }
    /// Cut `body` with `blade` now; returns what was removed.
    fn cut(
        &mut self,
        py: Python<'_>,
        body: &Bound<'_, PyAny>,
        blade: &Blade,
    ) -> PyResult<CutReport> {
        let id = BodyId::of(body)?;
        let (w, b) = (&mut self.inner, blade.inner);
        Ok(py.detach(|| w.cut(id, &b)).py()?.into())
    }
    /// Make a capsule or cylinder tool a blade (its edge: local y between ±half_height).
    fn make_blade(&mut self, tool: &Bound<'_, PyAny>) -> PyResult<()> {
        self.inner.make_blade(ToolId::of(tool)?).py()
    }
    /// Make a capsule or cylinder tool a needle (tip at local +y).
    #[pyo3(signature = (tool, options = None))]
    fn make_needle(
        &mut self,
        tool: &Bound<'_, PyAny>,
        options: Option<&NeedleOptions>,
    ) -> PyResult<()> {
        let o = options.map_or_else(tissuesim::NeedleOptions::default, NeedleOptions::to_core);
        self.inner.make_needle(ToolId::of(tool)?, &o).py()
    }
    /// The insertion state of a needle.
    fn needle_state(&self, tool: &Bound<'_, PyAny>) -> PyResult<NeedleState> {
        Ok(self.inner.needle_state(ToolId::of(tool)?).py()?.into())
    }
    /// Grasp with `tool`: returns the number of particles held (0: nothing within reach).
    #[pyo3(signature = (tool, options = None))]
    fn grasp(
        &mut self,
        tool: &Bound<'_, PyAny>,
        options: Option<&GraspOptions>,
    ) -> PyResult<usize> {
        let o = options.map_or_else(tissuesim::GraspOptions::default, GraspOptions::to_core);
        self.inner.grasp(ToolId::of(tool)?, &o).py()
    }
    /// Release `tool`'s grasp.
    fn release(&mut self, tool: &Bound<'_, PyAny>) -> PyResult<()> {
        self.inner.release(ToolId::of(tool)?).py()
    }
    /// Number of particles `tool` holds.
    fn grasped_count(&self, tool: &Bound<'_, PyAny>) -> PyResult<usize> {
        self.inner.grasped_count(ToolId::of(tool)?).py()
    }
    /// Number of tools (removed ones not counted).
    fn tool_count(&self) -> usize {
        self.inner.tool_count()
    }
    /// The ids of the tools, increasing.
    fn tool_ids(&self) -> Vec<ToolId> {
        self.inner.tool_ids().map(ToolId::from).collect()
    }
    /// The tool `id`; `ValueError` for an unknown or removed id.
    fn tool(slf: &Bound<'_, Self>, id: &Bound<'_, PyAny>) -> PyResult<Tool> {
        let id = ToolId::of(id)?;
        slf.try_borrow()?.inner.tool(id).py()?;
        Ok(Tool {
            world: slf.clone().unbind(),
            id: id.into(),
        })
    }
    /// Set the pose (a `Pose` or a position, m) `tool` reaches at the end of the next step.
    fn set_tool_pose(&mut self, tool: &Bound<'_, PyAny>, pose: &Bound<'_, PyAny>) -> PyResult<()> {
        let id = ToolId::of(tool)?;
        let p = pose_of(pose)?;
        self.inner.set_tool_pose(id, p).py()
    }
    /// Set a tool's friction coefficients (0 ≤ μ_k ≤ μ_s).
    fn set_tool_friction(
        &mut self,
        tool: &Bound<'_, PyAny>,
        friction_static: Real,
        friction_kinetic: Real,
    ) -> PyResult<()> {
        let id = ToolId::of(tool)?;
        self.inner
            .set_tool_friction(id, friction_static, friction_kinetic)
            .py()
    }
    /// Set the friction between two bodies (0 ≤ μ_k ≤ μ_s; a may equal b).
    fn set_body_pair_friction(
        &mut self,
        a: &Bound<'_, PyAny>,
        b: &Bound<'_, PyAny>,
        friction_static: Real,
        friction_kinetic: Real,
    ) -> PyResult<()> {
        let (a, b) = (BodyId::of(a)?, BodyId::of(b)?);
        self.inner
            .set_body_pair_friction(a, b, friction_static, friction_kinetic)
            .py()
    }
    /// The fastest a tool may move (m/s) and still be swept; faster is a jump.
    fn tool_jump_speed(&self) -> Real {
        self.inner.tool_jump_speed()
    }
    /// Substeps the next step needs, and whether `max_substeps` clamped them (a raised count is
    /// kept for `SUBSTEP_HOLD_STEPS` steps).
    fn substeps_needed(&self) -> (u32, bool) {
        self.inner.substeps_needed()
    }
    /// Advance by `settings.dt` (GIL released). Raises `DivergedError` (rolled back) when a
    /// body leaves the divergence bounds.
    fn step(&mut self, py: Python<'_>) -> PyResult<StepReport> {
        let w = &mut self.inner;
        let r = py.detach(|| w.step()).py()?;
        Ok(StepReport {
            substeps: r.substeps,
            substeps_clamped: r.substeps_clamped,
            cut: Py::new(py, CutReport::from(r.cut))?,
        })
    }
    /// Bring the world to rest in its equilibrium under gravity (GIL released; seconds on
    /// large meshes). Nothing changes on error.
    fn settle(&mut self, py: Python<'_>) -> PyResult<SettleReport> {
        let w = &mut self.inner;
        let r = py.detach(|| w.settle()).py()?;
        Ok(SettleReport {
            newton_iterations: r.newton_iterations,
            relative_residual: r.relative_residual,
            relaxation_steps: r.relaxation_steps,
            max_speed: r.max_speed,
            converged: r.converged,
        })
    }
    /// The dynamic state as one value.
    fn state(&self) -> WorldState {
        WorldState {
            inner: self.inner.state(),
        }
    }
    /// Restore a state taken from this world or one built the same way (`ValueError`
    /// otherwise; nothing changes on error).
    fn set_state(&mut self, state: &WorldState) -> PyResult<()> {
        self.inner.set_state(&state.inner).py()
    }
    /// Size of `save_state()` (bytes).
    fn state_size(&self) -> usize {
        self.inner.state_size()
    }
    /// The dynamic state as checksummed bytes.
    fn save_state<'py>(&self, py: Python<'py>) -> Bound<'py, PyBytes> {
        let mut out = Vec::with_capacity(self.inner.state_size());
        self.inner.save_state(&mut out);
        PyBytes::new(py, &out)
    }
    /// Restore bytes from `save_state` (`ValueError` for bad bytes; nothing changes on error).
    fn restore_state(&mut self, data: &[u8]) -> PyResult<()> {
        if data.is_empty() {
            return Err(PyValueError::new_err("cannot restore state: no bytes"));
        }
        self.inner.restore_state(data).py()
    }
    fn __repr__(&self) -> String {
        format!(
            "World(time={}, bodies={}, tools={})",
            self.inner.time(),
            self.inner.body_count(),
            self.inner.tool_count()
        )
    }
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<BodyId>()?;
    m.add_class::<ToolId>()?;
    m.add_class::<RenderSurfaceId>()?;
    m.add_class::<StepReport>()?;
    m.add_class::<SettleReport>()?;
    m.add_class::<World>()?;
    Ok(())
}
