//! Tools: kinematic rigid instruments (sphere, capsule, cylinder, box, convex hull, triangle
//! mesh from arrays or OBJ), adding and removing them, their poses, friction
//! and the contact wrench the tissue exerts on them.

use crate::ffi::args::{element_count, input_slice, non_null, world_mut, world_ref, write};
use crate::ffi::body::c_path;
use crate::ffi::error::FfiResult;
use crate::ffi::guard::guard;
use crate::ffi::status::ts_status;
use crate::ffi::world::ts_world;
use crate::kernels::math::Vec3;
use crate::mesh;
use crate::scene::tool::{Pose, ToolOptions, ToolShape};
use crate::scene::ToolId;
use std::ffi::c_char;

/// A rigid pose in the world frame: the position of the tool origin and its orientation.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ts_pose {
    /// Position of the tool origin (m, world frame), [x, y, z].
    pub position: [f64; 3],
    /// Orientation as a quaternion [w, x, y, z] (local to world); normalised on use, so it
    /// need not be unit length, but its norm must be at least 1e-12 (else
    /// TS_STATUS_INVALID_ARGUMENT). Identity: {1, 0, 0, 0}.
    pub orientation: [f64; 4],
}

impl ts_pose {
    /// The Rust pose by [`Pose::from_components`] (the one quaternion check and normalisation):
    /// NaN/Inf give TS_STATUS_NON_FINITE, a (near) zero quaternion TS_STATUS_INVALID_ARGUMENT.
    pub fn to_pose(&self) -> FfiResult<Pose> {
        Ok(Pose::from_components(self.position, self.orientation)?)
    }
}

impl From<&Pose> for ts_pose {
    fn from(p: &Pose) -> Self {
        let q = p.orientation.quaternion();
        ts_pose {
            position: [p.position.x, p.position.y, p.position.z],
            orientation: [q.w, q.i, q.j, q.k],
        }
    }
}

/// Options of a tool. ts_tool_options_default gives frictionless contact.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ts_tool_options {
    /// Static friction coefficient mu_s between tool and tissue (dimensionless, >= 0).
    pub friction_static: f64,
    /// Kinetic friction coefficient mu_k (dimensionless, 0 <= mu_k <= mu_s).
    pub friction_kinetic: f64,
    /// Spacing of the surface samples in TS_CONTACT_MODE_SAMPLED_POINTS (m); 0 uses the
    /// particle radius of the first body.
    pub sample_spacing: f64,
}

impl From<&ToolOptions> for ts_tool_options {
    fn from(o: &ToolOptions) -> Self {
        ts_tool_options {
            friction_static: o.friction_static,
            friction_kinetic: o.friction_kinetic,
            sample_spacing: o.sample_spacing.unwrap_or(0.0),
        }
    }
}

impl ts_tool_options {
    /// The Rust options (sample_spacing 0 means automatic), checked by
    /// [`ToolOptions::validate`].
    pub fn to_options(&self) -> FfiResult<ToolOptions> {
        let o = ToolOptions {
            friction_static: self.friction_static,
            friction_kinetic: self.friction_kinetic,
            sample_spacing: (self.sample_spacing != 0.0).then_some(self.sample_spacing),
        };
        o.validate()?;
        Ok(o)
    }
}

/// The wrench the tissue exerts on a tool, averaged over the substeps of the last step.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ts_wrench {
    /// Force on the tool (N, world frame), [x, y, z]; feed it to a haptic device as is.
    pub force: [f64; 3],
    /// Torque on the tool about its origin (N m, world frame), [x, y, z].
    pub torque: [f64; 3],
    /// Largest contact violation before projection, last step (m): how far the surface was
    /// inside the tool's contact skin.
    pub max_penetration: f64,
    /// Number of contacts at the last substep: boundary triangles touching the tool in the
    /// exact-shape contact mode, particles in the sampled-points mode.
    pub contact_count: u32,
}

/// Add a tool of `shape` (built after the pose and options are converted and checked, so that
/// a bad pose fails before a file is read); every value is checked by the core.
///
/// # Safety
///
/// Pointers as in the exported add functions.
unsafe fn add_tool(
    world: *mut ts_world,
    shape: impl FnOnce() -> FfiResult<ToolShape>,
    pose: *const ts_pose,
    options: *const ts_tool_options,
    out_tool: *mut u32,
) -> ts_status {
    guard(|| {
        non_null(pose, "pose")?;
        non_null(out_tool, "out_tool")?;
        // SAFETY: contract of the caller.
        let h = unsafe { world_mut(world)? };
        // SAFETY: checked non-NULL, readable by contract; every bit pattern is a valid value.
        let pose = unsafe { *pose }.to_pose()?;
        let options = if options.is_null() {
            ToolOptions::default()
        } else {
            // SAFETY: non-NULL, readable by contract.
            unsafe { *options }.to_options()?
        };
        let shape = shape()?;
        let id = h.mutate(|w| w.add_tool(shape, pose, &options))?;
        // SAFETY: checked non-NULL.
        unsafe { write(out_tool, id.0) };
        Ok(())
    })
}

/// Write the default tool options (no friction, automatic sample spacing) into *out.
///
/// # Safety
///
/// `out` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn ts_tool_options_default(out: *mut ts_tool_options) -> ts_status {
    guard(|| {
        non_null(out, "out")?;
        // SAFETY: checked non-NULL.
        unsafe { write(out, ts_tool_options::from(&ToolOptions::default())) };
        Ok(())
    })
}

/// Add a spherical tool of `radius` (m, > 0) centred on its origin, at `pose`. `options` is
/// optional (NULL: defaults). The new tool's id goes to *out_tool.
///
/// # Safety
///
/// `world` is NULL or a live handle; `pose`, `options` are NULL or readable; `out_tool` is
/// NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn ts_world_add_tool_sphere(
    world: *mut ts_world,
    radius: f64,
    pose: *const ts_pose,
    options: *const ts_tool_options,
    out_tool: *mut u32,
) -> ts_status {
    let shape = || Ok(ToolShape::Sphere { radius });
    // SAFETY: contract of this function.
    unsafe { add_tool(world, shape, pose, options, out_tool) }
}

/// Add a capsule tool along its local y axis: `half_height` (m, >= 0; 0 gives a sphere) is half
/// the distance between the hemisphere centres, `radius` (m, > 0). Otherwise as
/// ts_world_add_tool_sphere.
///
/// # Safety
///
/// As ts_world_add_tool_sphere.
#[no_mangle]
pub unsafe extern "C" fn ts_world_add_tool_capsule(
    world: *mut ts_world,
    half_height: f64,
    radius: f64,
    pose: *const ts_pose,
    options: *const ts_tool_options,
    out_tool: *mut u32,
) -> ts_status {
    let shape = || {
        Ok(ToolShape::Capsule {
            half_height,
            radius,
        })
    };
    // SAFETY: contract of this function.
    unsafe { add_tool(world, shape, pose, options, out_tool) }
}

/// Add a cylinder tool along its local y axis: `half_height` (m, > 0) is half its length,
/// `radius` (m, > 0). Otherwise as ts_world_add_tool_sphere.
///
/// # Safety
///
/// As ts_world_add_tool_sphere.
#[no_mangle]
pub unsafe extern "C" fn ts_world_add_tool_cylinder(
    world: *mut ts_world,
    half_height: f64,
    radius: f64,
    pose: *const ts_pose,
    options: *const ts_tool_options,
    out_tool: *mut u32,
) -> ts_status {
    let shape = || {
        Ok(ToolShape::Cylinder {
            half_height,
            radius,
        })
    };
    // SAFETY: contract of this function.
    unsafe { add_tool(world, shape, pose, options, out_tool) }
}

/// Add a box tool centred on its origin: `half_extents` is 3 doubles (m, > 0 each) along its
/// local x, y, z. Otherwise as ts_world_add_tool_sphere.
///
/// # Safety
///
/// As ts_world_add_tool_sphere; `half_extents` is NULL or holds 3 readable doubles.
#[no_mangle]
pub unsafe extern "C" fn ts_world_add_tool_box(
    world: *mut ts_world,
    half_extents: *const f64,
    pose: *const ts_pose,
    options: *const ts_tool_options,
    out_tool: *mut u32,
) -> ts_status {
    if half_extents.is_null() {
        return guard(|| non_null(half_extents, "half_extents"));
    }
    let shape = || {
        // SAFETY: non-NULL, 3 readable doubles by contract.
        let e = unsafe { crate::ffi::args::read_vec3(half_extents) };
        Ok(ToolShape::Cuboid { half_extents: e })
    };
    // SAFETY: contract of this function.
    unsafe { add_tool(world, shape, pose, options, out_tool) }
}

/// Add a triangle-mesh tool read from a Wavefront OBJ file (`v` and `f` records), vertex
/// positions multiplied by `scale` (> 0, file units to m), in the tool's local frame. A missing
/// or malformed file gives TS_STATUS_MESH_ERROR naming the file. Otherwise as
/// ts_world_add_tool_sphere.
///
/// # Safety
///
/// As ts_world_add_tool_sphere; `path` is NULL or NUL-terminated.
#[no_mangle]
pub unsafe extern "C" fn ts_world_add_tool_mesh_file(
    world: *mut ts_world,
    path: *const c_char,
    scale: f64,
    pose: *const ts_pose,
    options: *const ts_tool_options,
    out_tool: *mut u32,
) -> ts_status {
    if path.is_null() {
        return guard(|| non_null(path, "path"));
    }
    let shape = || {
        // SAFETY: non-NULL and NUL-terminated by contract.
        let path = unsafe { c_path(path, "path")? };
        mesh::validate_scale(scale)?;
        let surface = mesh::read_obj(&path, scale)?;
        Ok(ToolShape::TriMesh {
            vertices: surface.vertices,
            triangles: surface.triangles,
        })
    };
    // SAFETY: contract of this function.
    unsafe { add_tool(world, shape, pose, options, out_tool) }
}

/// Set the pose the tool reaches at the end of the next ts_world_step (the tool moves there
/// across the substeps of that step). NaN/Inf give TS_STATUS_NON_FINITE, a zero quaternion
/// TS_STATUS_INVALID_ARGUMENT; the tool is unchanged on error.
///
/// # Safety
///
/// `world` is NULL or a live handle; `pose` is NULL or readable.
#[no_mangle]
pub unsafe extern "C" fn ts_tool_set_pose(
    world: *mut ts_world,
    tool: u32,
    pose: *const ts_pose,
) -> ts_status {
    guard(|| {
        non_null(pose, "pose")?;
        // SAFETY: contract of this function.
        let h = unsafe { world_mut(world)? };
        // SAFETY: checked non-NULL, readable by contract.
        let pose = unsafe { *pose }.to_pose()?;
        h.world.tool(ToolId(tool))?;
        h.mutate(|w| w.set_tool_pose(ToolId(tool), pose))
    })
}

/// The pose the tool reached at the end of the last step into *out_pose (unit quaternion).
///
/// # Safety
///
/// `world` is NULL or a live handle; `out_pose` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn ts_tool_get_pose(
    world: *const ts_world,
    tool: u32,
    out_pose: *mut ts_pose,
) -> ts_status {
    guard(|| {
        non_null(out_pose, "out_pose")?;
        // SAFETY: contract of this function.
        let h = unsafe { world_ref(world)? };
        let p = ts_pose::from(&h.world.tool(ToolId(tool))?.pose());
        // SAFETY: checked non-NULL.
        unsafe { write(out_pose, p) };
        Ok(())
    })
}

/// The contact wrench of the last step (force in N and torque in N m exerted by the tissue on
/// the tool, world frame, averaged over the substeps; contact count) into *out_wrench.
///
/// # Safety
///
/// `world` is NULL or a live handle; `out_wrench` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn ts_tool_wrench(
    world: *const ts_world,
    tool: u32,
    out_wrench: *mut ts_wrench,
) -> ts_status {
    guard(|| {
        non_null(out_wrench, "out_wrench")?;
        // SAFETY: contract of this function.
        let h = unsafe { world_ref(world)? };
        let w = h.world.tool(ToolId(tool))?.wrench();
        let out = ts_wrench {
            force: [w.force.x, w.force.y, w.force.z],
            torque: [w.torque.x, w.torque.y, w.torque.z],
            max_penetration: w.max_penetration,
            contact_count: w.contact_count,
        };
        // SAFETY: checked non-NULL.
        unsafe { write(out_wrench, out) };
        Ok(())
    })
}

/// Number of contacts of the tool at the last substep (boundary triangles in the exact-shape
/// contact mode, particles in the sampled-points mode) into *out_count.
///
/// # Safety
///
/// `world` is NULL or a live handle; `out_count` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn ts_tool_contact_count(
    world: *const ts_world,
    tool: u32,
    out_count: *mut u32,
) -> ts_status {
    guard(|| {
        non_null(out_count, "out_count")?;
        // SAFETY: contract of this function.
        let h = unsafe { world_ref(world)? };
        let n = h.world.tool(ToolId(tool))?.wrench().contact_count;
        // SAFETY: checked non-NULL.
        unsafe { write(out_count, n) };
        Ok(())
    })
}

/// `count` points given as `count x 3` doubles at `xyz` (the length check of a C array; the
/// values are checked by the core).
///
/// # Safety
///
/// `xyz` is NULL or holds `3 * count` readable doubles.
unsafe fn points(xyz: *const f64, count: usize, name: &str) -> FfiResult<Vec<Vec3>> {
    let n = element_count::<f64>(count, 3, name)?;
    // SAFETY: contract of the caller.
    let xyz = unsafe { input_slice(xyz, n, name)? };
    Ok(xyz
        .chunks_exact(3)
        .map(|c| Vec3::new(c[0], c[1], c[2]))
        .collect())
}

/// Add a convex tool: the convex hull of `point_count` points (`points` holds point_count x 3
/// doubles, x, y, z per point, m, tool frame). At least 4 points not all in one plane (else
/// TS_STATUS_INVALID_ARGUMENT); NaN/Inf give TS_STATUS_NON_FINITE. Points inside the hull are
/// ignored. Otherwise as ts_world_add_tool_sphere. Allocates.
///
/// # Safety
///
/// As ts_world_add_tool_sphere; `points` is NULL or holds 3 * point_count readable doubles.
#[no_mangle]
pub unsafe extern "C" fn ts_world_add_tool_convex_hull(
    world: *mut ts_world,
    points: *const f64,
    point_count: usize,
    pose: *const ts_pose,
    options: *const ts_tool_options,
    out_tool: *mut u32,
) -> ts_status {
    if points.is_null() {
        return guard(|| non_null(points, "points"));
    }
    let shape = || {
        // SAFETY: non-NULL, 3 * point_count readable doubles by contract.
        let points = unsafe { self::points(points, point_count, "points")? };
        Ok(ToolShape::ConvexHull { points })
    };
    // SAFETY: contract of this function.
    unsafe { add_tool(world, shape, pose, options, out_tool) }
}

/// Add a triangle-mesh tool from arrays: `vertices` holds vertex_count x 3 doubles (m, tool
/// frame), `triangles` holds triangle_count x 3 vertex indices (0-based, counter-clockwise seen
/// from outside). An index >= vertex_count or no triangle gives TS_STATUS_INVALID_ARGUMENT,
/// NaN/Inf TS_STATUS_NON_FINITE. Otherwise as ts_world_add_tool_sphere. Allocates.
///
/// # Safety
///
/// As ts_world_add_tool_sphere; `vertices` is NULL or holds 3 * vertex_count readable doubles;
/// `triangles` is NULL or holds 3 * triangle_count readable uint32_t.
#[no_mangle]
pub unsafe extern "C" fn ts_world_add_tool_mesh(
    world: *mut ts_world,
    vertices: *const f64,
    vertex_count: usize,
    triangles: *const u32,
    triangle_count: usize,
    pose: *const ts_pose,
    options: *const ts_tool_options,
    out_tool: *mut u32,
) -> ts_status {
    if vertices.is_null() || triangles.is_null() {
        return guard(|| {
            non_null(vertices, "vertices")?;
            non_null(triangles, "triangles")
        });
    }
    let shape = || {
        // SAFETY: non-NULL, 3 * vertex_count readable doubles by contract.
        let vertices = unsafe { points(vertices, vertex_count, "vertices")? };
        let n = element_count::<u32>(triangle_count, 3, "triangle_count")?;
        // SAFETY: non-NULL, 3 * triangle_count readable uint32_t by contract.
        let idx = unsafe { input_slice(triangles, n, "triangles")? };
        Ok(ToolShape::TriMesh {
            vertices,
            triangles: idx.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(),
        })
    };
    // SAFETY: contract of this function.
    unsafe { add_tool(world, shape, pose, options, out_tool) }
}

/// Remove a tool: from the next ts_world_step on it no longer touches the tissue. Its id is
/// not reused: every later call with it gives TS_STATUS_UNKNOWN_TOOL, and tools added later get
/// new ids. A state saved before the removal no longer restores (TS_STATUS_BAD_STATE).
///
/// # Safety
///
/// `world` is NULL or a live handle.
#[no_mangle]
pub unsafe extern "C" fn ts_world_remove_tool(world: *mut ts_world, tool: u32) -> ts_status {
    guard(|| {
        // SAFETY: contract of this function.
        let h = unsafe { world_mut(world)? };
        h.mutate(|w| w.remove_tool(ToolId(tool)))
    })
}

/// Set a tool's friction with the tissue, from the next step on: static coefficient
/// `friction_static` (mu_s) and kinetic `friction_kinetic` (mu_k), dimensionless, with
/// 0 <= mu_k <= mu_s (else TS_STATUS_INVALID_ARGUMENT; NaN/Inf give TS_STATUS_NON_FINITE). The
/// tool is unchanged on error.
///
/// # Safety
///
/// `world` is NULL or a live handle.
#[no_mangle]
pub unsafe extern "C" fn ts_tool_set_friction(
    world: *mut ts_world,
    tool: u32,
    friction_static: f64,
    friction_kinetic: f64,
) -> ts_status {
    guard(|| {
        // SAFETY: contract of this function.
        let h = unsafe { world_mut(world)? };
        h.mutate(|w| w.set_tool_friction(ToolId(tool), friction_static, friction_kinetic))
    })
}

/// The options a tool has now (friction coefficients, dimensionless; sample spacing in m, 0 when
/// automatic) into *out_options.
///
/// # Safety
///
/// `world` is NULL or a live handle; `out_options` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn ts_tool_get_options(
    world: *const ts_world,
    tool: u32,
    out_options: *mut ts_tool_options,
) -> ts_status {
    guard(|| {
        non_null(out_options, "out_options")?;
        // SAFETY: contract of this function.
        let h = unsafe { world_ref(world)? };
        let o = ts_tool_options::from(h.world.tool(ToolId(tool))?.options());
        // SAFETY: checked non-NULL.
        unsafe { write(out_options, o) };
        Ok(())
    })
}
