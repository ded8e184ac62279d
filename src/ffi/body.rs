//! Bodies: adding them (mesh file, arrays, the default organ), fixing particles, and reading
//! their state into caller buffers.

use crate::ffi::args::{
    all_finite, element_count, input_slice, non_null, read_vec3, world_mut, world_ref, write,
};
use crate::ffi::error::{fail, FfiResult};
use crate::ffi::guard::guard;
use crate::ffi::status::ts_status;
use crate::ffi::world::ts_world;
use crate::kernels::math::Vec3;
use crate::mesh::{self, TetMesh};
use crate::model::body_model::{BodyModel, BodyOptions, Material};
use crate::scene::body::Body;
use crate::scene::BodyId;
use std::ffi::{c_char, CStr};
use std::mem::MaybeUninit;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// An isotropic linear-elastic material (SI units). ts_material_default gives liver-like tissue.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ts_material {
    /// Young's modulus E (Pa), > 0.
    pub youngs_modulus: f64,
    /// Poisson ratio nu (dimensionless), in [0, 0.499]: negative values are auxetic (not
    /// tissue) and unstable here; the volumetric stiffness diverges as nu approaches 0.5.
    pub poisson_ratio: f64,
    /// Mass density rho (kg/m^3), > 0.
    pub density: f64,
}

/// Options for building a body. ts_body_options_default gives automatic radii.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ts_body_options {
    /// Support radius of every particle (m); 0 chooses one per particle automatically.
    /// Otherwise in [0.5, 3] x the mesh's mean edge length (and at most 384 neighbours).
    pub support_radius: f64,
    /// Contact radius of the particles (m) for organ-organ contact and the sampled-points tool
    /// contact (the exact-shape tool contact's skin is a tenth of it); 0 derives it from the
    /// particle spacing (half the mean edge length). Otherwise in [0.05, 2] x the mesh's mean
    /// edge length.
    pub particle_radius: f64,
    /// Target number of neighbours when the support radius is automatic (1..=96).
    pub target_neighbours: u32,
}

impl From<&Material> for ts_material {
    fn from(m: &Material) -> Self {
        ts_material {
            youngs_modulus: m.youngs_modulus,
            poisson_ratio: m.poisson_ratio,
            density: m.density,
        }
    }
}

impl From<&BodyOptions> for ts_body_options {
    fn from(o: &BodyOptions) -> Self {
        ts_body_options {
            support_radius: o.support_radius.unwrap_or(0.0),
            particle_radius: o.particle_radius.unwrap_or(0.0),
            target_neighbours: o.target_neighbours,
        }
    }
}

/// The Rust body options from the C material and (optional) options, checked by
/// [`BodyOptions::validate`] (the one validation of materials and body options).
///
/// # Safety
///
/// `material` is NULL or readable; `options` is NULL or readable.
unsafe fn body_options(
    material: *const ts_material,
    options: *const ts_body_options,
) -> FfiResult<BodyOptions> {
    non_null(material, "material")?;
    // SAFETY: checked non-NULL, readable by contract; any bit pattern is a valid value.
    let m = unsafe { *material };
    let mut o = BodyOptions {
        material: Material {
            youngs_modulus: m.youngs_modulus,
            poisson_ratio: m.poisson_ratio,
            density: m.density,
        },
        ..BodyOptions::default()
    };
    if !options.is_null() {
        // SAFETY: non-NULL, readable by contract.
        let c = unsafe { *options };
        // 0 means automatic; any other value is given to the core, which validates it.
        let radius = |v: f64| (v != 0.0).then_some(v);
        o.support_radius = radius(c.support_radius);
        o.particle_radius = radius(c.particle_radius);
        o.target_neighbours = c.target_neighbours;
    }
    o.validate()?;
    Ok(o)
}

/// The path named by a C string.
///
/// # Safety
///
/// `path` is NULL or a NUL-terminated string.
pub(crate) unsafe fn c_path(path: *const c_char, name: &str) -> FfiResult<PathBuf> {
    non_null(path, name)?;
    // SAFETY: non-NULL and NUL-terminated by contract.
    let bytes = unsafe { CStr::from_ptr(path) }.to_bytes();
    if bytes.is_empty() {
        return Err(fail(ts_status::InvalidArgument, format!("{name} is empty")));
    }
    #[cfg(unix)]
    {
        use std::os::unix::ffi::OsStrExt;
        Ok(Path::new(std::ffi::OsStr::from_bytes(bytes)).to_path_buf())
    }
    #[cfg(not(unix))]
    {
        match std::str::from_utf8(bytes) {
            Ok(s) => Ok(PathBuf::from(s)),
            Err(_) => Err(fail(
                ts_status::InvalidArgument,
                format!("{name} is not valid UTF-8"),
            )),
        }
    }
}

impl ts_world {
    /// Add a body and remember where its particles came from.
    fn add_mesh(
        &mut self,
        mesh: &TetMesh,
        source: Vec<u32>,
        options: &BodyOptions,
    ) -> FfiResult<u32> {
        let model = BodyModel::new(mesh, options)?;
        self.add_model(model, source)
    }

    /// Add a body on `model` and remember where its particles came from.
    fn add_model(&mut self, model: Arc<BodyModel>, source: Vec<u32>) -> FfiResult<u32> {
        let id = self.mutate(|w| Ok(w.add_body_model(model)))?.0;
        let slot = id as usize;
        if self.source_indices.len() <= slot {
            self.source_indices.resize(slot + 1, Vec::new());
        }
        self.source_indices[slot] = source;
        Ok(id)
    }

    /// The body with id `body`.
    fn body(&self, body: u32) -> FfiResult<&Body> {
        Ok(self.world.body(BodyId(body))?)
    }
}

/// Write the default material (liver-like: E = 5 kPa, nu = 0.45, rho = 1060 kg/m^3) into *out.
///
/// # Safety
///
/// `out` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn ts_material_default(out: *mut ts_material) -> ts_status {
    guard(|| {
        non_null(out, "out")?;
        // SAFETY: checked non-NULL.
        unsafe { write(out, ts_material::from(&Material::default())) };
        Ok(())
    })
}

/// Write the default body options (automatic support and contact radii, 20 neighbours) into
/// *out.
///
/// # Safety
///
/// `out` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn ts_body_options_default(out: *mut ts_body_options) -> ts_status {
    guard(|| {
        non_null(out, "out")?;
        // SAFETY: checked non-NULL.
        unsafe { write(out, ts_body_options::from(&BodyOptions::default())) };
        Ok(())
    })
}

/// Add a deformable body from a tetrahedral mesh file: Gmsh .msh (v1, 2.2, 4.1 ASCII), TetGen
/// .node/.ele (either file name) or legacy VTK .vtk. Node positions are multiplied by `scale`
/// (> 0, mesh units to m). `options` is optional (NULL: defaults). A missing or malformed file
/// gives TS_STATUS_MESH_ERROR with a message naming the file (and line). The new body's id goes
/// to *out_body. Particles follow the file's node order, minus unreferenced nodes: see
/// ts_body_source_indices.
///
/// # Safety
///
/// `world` is NULL or a live handle; `path` is NULL or NUL-terminated; `material` and `options`
/// are NULL or readable; `out_body` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn ts_world_add_body_from_file(
    world: *mut ts_world,
    path: *const c_char,
    scale: f64,
    material: *const ts_material,
    options: *const ts_body_options,
    out_body: *mut u32,
) -> ts_status {
    guard(|| {
        non_null(out_body, "out_body")?;
        // SAFETY: contract of this function.
        let path = unsafe { c_path(path, "path")? };
        // SAFETY: contract of this function.
        let o = unsafe { body_options(material, options)? };
        // SAFETY: contract of this function.
        let h = unsafe { world_mut(world)? };
        mesh::validate_scale(scale)?;
        let (mesh, report) = mesh::load(&path, scale)?;
        let id = h.add_mesh(&mesh, report.original_node_index, &o)?;
        // SAFETY: checked non-NULL.
        unsafe { write(out_body, id) };
        Ok(())
    })
}

/// Add a deformable body from arrays: `nodes` holds node_count x 3 doubles (x, y, z per node,
/// m), `tets` holds tet_count x 4 node indices (0-based). Inverted tetrahedra are re-oriented,
/// degenerate ones and unreferenced nodes removed (see ts_body_source_indices); indices out of
/// range give TS_STATUS_MESH_ERROR, NaN/Inf coordinates TS_STATUS_NON_FINITE. `options` is
/// optional (NULL: defaults). The new body's id goes to *out_body.
///
/// # Safety
///
/// `nodes` is NULL or holds 3 * node_count readable doubles; `tets` is NULL or holds
/// 4 * tet_count readable uint32_t; the other pointers as in ts_world_add_body_from_file.
#[no_mangle]
pub unsafe extern "C" fn ts_world_add_body_from_arrays(
    world: *mut ts_world,
    nodes: *const f64,
    node_count: usize,
    tets: *const u32,
    tet_count: usize,
    material: *const ts_material,
    options: *const ts_body_options,
    out_body: *mut u32,
) -> ts_status {
    guard(|| {
        non_null(out_body, "out_body")?;
        let n_doubles = element_count::<f64>(node_count, 3, "node_count")?;
        let n_indices = element_count::<u32>(tet_count, 4, "tet_count")?;
        // SAFETY: contract of this function.
        let xyz = unsafe { input_slice(nodes, n_doubles, "nodes")? };
        // SAFETY: contract of this function.
        let idx = unsafe { input_slice(tets, n_indices, "tets")? };
        // SAFETY: contract of this function.
        let o = unsafe { body_options(material, options)? };
        // SAFETY: contract of this function.
        let h = unsafe { world_mut(world)? };
        all_finite(xyz, "nodes")?;
        let nodes: Vec<Vec3> = xyz
            .chunks_exact(3)
            .map(|c| Vec3::new(c[0], c[1], c[2]))
            .collect();
        let tets: Vec<[u32; 4]> = idx
            .chunks_exact(4)
            .map(|c| [c[0], c[1], c[2], c[3]])
            .collect();
        let (mesh, report) = TetMesh::from_raw(nodes, tets, Path::new("<arrays>"))?;
        let id = h.add_mesh(&mesh, report.original_node_index, &o)?;
        // SAFETY: checked non-NULL.
        unsafe { write(out_body, id) };
        Ok(())
    })
}

/// Add the embedded default organ (a liver-like solid about 0.2 m across, generated by
/// tissuesim, no file needed) as a body. `options` is optional (NULL: defaults). The new body's
/// id goes to *out_body.
///
/// # Safety
///
/// As ts_world_add_body_from_file.
#[no_mangle]
pub unsafe extern "C" fn ts_world_add_default_organ(
    world: *mut ts_world,
    material: *const ts_material,
    options: *const ts_body_options,
    out_body: *mut u32,
) -> ts_status {
    guard(|| {
        non_null(out_body, "out_body")?;
        // SAFETY: contract of this function.
        let o = unsafe { body_options(material, options)? };
        // SAFETY: contract of this function.
        let h = unsafe { world_mut(world)? };
        let mesh = mesh::default_organ();
        let source = (0..mesh.nodes.len() as u32).collect();
        let id = h.add_mesh(&mesh, source, &o)?;
        // SAFETY: checked non-NULL.
        unsafe { write(out_body, id) };
        Ok(())
    })
}

/// Add to `world` a body on the load-time model of body `body` of `source` (another world or
/// the same one), at rest, nothing fixed: the same mesh, options and material without redoing
/// the load-time work (neighbour search, consistent gradients) and without copying its arrays,
/// which the two bodies share read-only (a body that is cut later takes its own copy). For a
/// body already cut, the new body is the uncut original. Source indices are the source
/// body's. The new body's id goes to *out_body.
///
/// # Safety
///
/// `world` is NULL or a live handle not used by another thread; `source` is NULL or a live
/// handle that no other thread changes during the call (it may be `world`); `out_body` is
/// NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn ts_world_add_body_shared(
    world: *mut ts_world,
    source: *const ts_world,
    body: u32,
    out_body: *mut u32,
) -> ts_status {
    guard(|| {
        non_null(out_body, "out_body")?;
        let (model, indices) = {
            // SAFETY: contract of this function; the reference ends before `world` is borrowed
            // mutably (the two may be the same handle).
            let src = unsafe { world_ref(source)? };
            let b = src.body(body)?;
            let indices = src.source_indices.get(body as usize).cloned();
            (Arc::clone(b.load_time_model()), indices.unwrap_or_default())
        };
        // SAFETY: contract of this function.
        let id = unsafe { world_mut(world)? }.add_model(model, indices)?;
        // SAFETY: checked non-NULL.
        unsafe { write(out_body, id) };
        Ok(())
    })
}

/// Fix the particles whose indices (count of them, 0-based particle indices) are given: they
/// keep their current positions. An index >= the particle count gives
/// TS_STATUS_INVALID_ARGUMENT and fixes nothing.
///
/// # Safety
///
/// `world` is NULL or a live handle; `indices` is NULL or holds `count` readable uint32_t.
#[no_mangle]
pub unsafe extern "C" fn ts_body_fix_particles(
    world: *mut ts_world,
    body: u32,
    indices: *const u32,
    count: usize,
) -> ts_status {
    guard(|| {
        // SAFETY: contract of this function.
        let idx = unsafe { input_slice(indices, count, "indices")? };
        // SAFETY: contract of this function.
        let h = unsafe { world_mut(world)? };
        // Node k is particle order.particle(k); an index out of range stays as it is, for
        // World::fix_particles to refuse.
        let order = h.body(body)?.particle_order();
        let particles: Vec<u32> = idx
            .iter()
            .map(|&k| {
                if (k as usize) < order.len() {
                    order.particle(k as usize) as u32
                } else {
                    k
                }
            })
            .collect();
        h.mutate(|w| w.fix_particles(BodyId(body), &particles))
    })
}

/// Fix every particle whose current position lies in the axis-aligned box [min, max] (`min`
/// and `max` are 3 doubles each, m, world frame, min <= max per axis). The number of particles
/// fixed goes to *out_fixed, which is optional (may be NULL).
///
/// # Safety
///
/// `world` is NULL or a live handle; `min` and `max` are NULL or hold 3 readable doubles;
/// `out_fixed` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn ts_body_fix_box(
    world: *mut ts_world,
    body: u32,
    min: *const f64,
    max: *const f64,
    out_fixed: *mut usize,
) -> ts_status {
    guard(|| {
        non_null(min, "min")?;
        non_null(max, "max")?;
        // SAFETY: contract of this function.
        let h = unsafe { world_mut(world)? };
        // SAFETY: checked non-NULL; 3 doubles each by contract.
        let (lo, hi) = unsafe { (read_vec3(min), read_vec3(max)) };
        let n = h.mutate(|w| w.fix_box(BodyId(body), lo, hi))?;
        if !out_fixed.is_null() {
            // SAFETY: non-NULL, writable by contract.
            unsafe { write(out_fixed, n) };
        }
        Ok(())
    })
}

/// Read one value of a body into `out`.
///
/// # Safety
///
/// `world` is NULL or a live handle; `out` is NULL or writable.
unsafe fn body_value<T>(
    world: *const ts_world,
    body: u32,
    out: *mut T,
    get: impl FnOnce(&Body) -> T,
) -> ts_status {
    guard(|| {
        non_null(out, "out")?;
        // SAFETY: contract of the caller.
        let h = unsafe { world_ref(world)? };
        let v = get(h.body(body)?);
        // SAFETY: checked non-NULL.
        unsafe { write(out, v) };
        Ok(())
    })
}

/// Write `values` into the start of `dst`.
fn put<T>(dst: &mut [MaybeUninit<T>], values: impl Iterator<Item = T>) {
    for (d, v) in dst.iter_mut().zip(values) {
        d.write(v);
    }
}

/// Copy a body's array into a caller buffer of `len` elements (nothing written when short),
/// without allocating: `get` returns the number of elements and a function filling them.
///
/// # Safety
///
/// `world` is NULL or a live handle; `out` is NULL or holds `len` writable elements.
#[allow(clippy::too_many_arguments)]
unsafe fn body_array<T: Copy>(
    world: *const ts_world,
    body: u32,
    out: *mut T,
    len: usize,
    what: &str,
    unit: &str,
    needed: impl FnOnce(&ts_world, &Body) -> usize,
    fill: impl FnOnce(&ts_world, &Body, &mut [MaybeUninit<T>]),
) -> ts_status {
    guard(|| {
        non_null(out, "out")?;
        // SAFETY: contract of the caller.
        let h = unsafe { world_ref(world)? };
        let b = h.body(body)?;
        let n = needed(h, b);
        if len < n {
            return Err(fail(
                ts_status::BufferTooSmall,
                format!("{what}: buffer holds {len} {unit}, {n} needed for body {body}"),
            ));
        }
        // SAFETY: `out` holds at least `len >= n` writable (possibly uninitialised) elements by
        // contract.
        let dst = unsafe { std::slice::from_raw_parts_mut(out.cast::<MaybeUninit<T>>(), n) };
        fill(h, b, dst);
        Ok(())
    })
}

/// Copy a body's per-particle vectors into a caller buffer of `len` doubles in the mesh's node
/// order, without allocating.
///
/// # Safety
///
/// As [`body_array`].
unsafe fn body_vectors(
    world: *const ts_world,
    body: u32,
    out: *mut f64,
    len: usize,
    what: &str,
    get: impl FnOnce(&Body) -> &[Vec3],
) -> ts_status {
    guard(|| {
        non_null(out, "out")?;
        // SAFETY: contract of the caller.
        let h = unsafe { world_ref(world)? };
        let b = h.body(body)?;
        let v = get(b);
        let needed = 3 * v.len();
        if len < needed {
            return Err(fail(
                ts_status::BufferTooSmall,
                format!("{what}: buffer holds {len} doubles, {needed} needed for body {body}"),
            ));
        }
        // SAFETY: `out` holds at least `len >= needed` writable (possibly uninitialised)
        // doubles by contract.
        let dst = unsafe { std::slice::from_raw_parts_mut(out.cast::<MaybeUninit<f64>>(), needed) };
        let order = b.particle_order();
        put(
            dst,
            (0..v.len()).flat_map(|k| {
                let p = v[order.particle(k)];
                [p.x, p.y, p.z]
            }),
        );
        Ok(())
    })
}

/// Number of particles of a body (= nodes of its mesh) into *out_count.
///
/// # Safety
///
/// `world` is NULL or a live handle; `out_count` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn ts_body_particle_count(
    world: *const ts_world,
    body: u32,
    out_count: *mut usize,
) -> ts_status {
    // SAFETY: contract of this function.
    unsafe { body_value(world, body, out_count, |b| b.particle_count()) }
}

/// Current particle positions into `out`: particle_count x 3 doubles (x, y, z per particle, m,
/// world frame). `len` is the buffer length in doubles; below 3 * particle_count gives
/// TS_STATUS_BUFFER_TOO_SMALL and writes nothing. Does not allocate.
///
/// # Safety
///
/// `world` is NULL or a live handle; `out` is NULL or holds `len` writable doubles.
#[no_mangle]
pub unsafe extern "C" fn ts_body_positions(
    world: *const ts_world,
    body: u32,
    out: *mut f64,
    len: usize,
) -> ts_status {
    // SAFETY: contract of this function.
    unsafe { body_vectors(world, body, out, len, "positions", |b| b.positions()) }
}

/// Current particle velocities into `out`: particle_count x 3 doubles (m/s, world frame).
/// `len` in doubles, as ts_body_positions.
///
/// # Safety
///
/// As ts_body_positions.
#[no_mangle]
pub unsafe extern "C" fn ts_body_velocities(
    world: *const ts_world,
    body: u32,
    out: *mut f64,
    len: usize,
) -> ts_status {
    // SAFETY: contract of this function.
    unsafe { body_vectors(world, body, out, len, "velocities", |b| b.velocities()) }
}

/// Rest positions into `out`: particle_count x 3 doubles (m, world frame). `len` in doubles,
/// as ts_body_positions.
///
/// # Safety
///
/// As ts_body_positions.
#[no_mangle]
pub unsafe extern "C" fn ts_body_rest_positions(
    world: *const ts_world,
    body: u32,
    out: *mut f64,
    len: usize,
) -> ts_status {
    // SAFETY: contract of this function.
    unsafe {
        body_vectors(world, body, out, len, "rest positions", |b| {
            b.rest_positions()
        })
    }
}

/// For each particle, its 0-based index in the source the body was built from (the node order
/// of the mesh file, or of the nodes array), into `out`: particle_count uint32_t. Use it to
/// address file nodes (for example SOFA's fixed nodes) after unreferenced nodes were removed.
/// `len` in uint32_t; short buffers give TS_STATUS_BUFFER_TOO_SMALL.
///
/// # Safety
///
/// `world` is NULL or a live handle; `out` is NULL or holds `len` writable uint32_t.
#[no_mangle]
pub unsafe extern "C" fn ts_body_source_indices(
    world: *const ts_world,
    body: u32,
    out: *mut u32,
    len: usize,
) -> ts_status {
    // SAFETY: contract of this function.
    unsafe {
        body_array(
            world,
            body,
            out,
            len,
            "source indices",
            "uint32_t",
            |_, b| b.particle_count(),
            |h, b, dst| match h.source_indices.get(body as usize) {
                Some(s) if s.len() == b.particle_count() => put(dst, s.iter().copied()),
                _ => put(dst, 0u32..),
            },
        )
    }
}

/// Number of boundary triangles of a body's tetrahedral mesh into *out_count.
///
/// # Safety
///
/// `world` is NULL or a live handle; `out_count` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn ts_body_boundary_triangle_count(
    world: *const ts_world,
    body: u32,
    out_count: *mut usize,
) -> ts_status {
    // SAFETY: contract of this function.
    unsafe { body_value(world, body, out_count, |b| b.boundary_triangles().len()) }
}

/// Boundary triangles into `out`: triangle_count x 3 particle indices (0-based, counter-
/// clockwise seen from outside, so normals point out). `len` in uint32_t; below
/// 3 * triangle_count gives TS_STATUS_BUFFER_TOO_SMALL and writes nothing. Use with
/// ts_body_positions to render the deformed surface.
///
/// # Safety
///
/// `world` is NULL or a live handle; `out` is NULL or holds `len` writable uint32_t.
#[no_mangle]
pub unsafe extern "C" fn ts_body_boundary_triangles(
    world: *const ts_world,
    body: u32,
    out: *mut u32,
    len: usize,
) -> ts_status {
    // SAFETY: contract of this function.
    unsafe {
        body_array(
            world,
            body,
            out,
            len,
            "boundary triangles",
            "uint32_t",
            |_, b| 3 * b.boundary_triangles().len(),
            |_, b, dst| {
                let order = b.particle_order();
                let mesh_order = |t: &[u32; 3]| order.mesh_indices_of_array(t);
                put(dst, b.boundary_triangles().iter().flat_map(mesh_order))
            },
        )
    }
}

/// Number of tetrahedra of a body into *out_count.
///
/// # Safety
///
/// `world` is NULL or a live handle; `out_count` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn ts_body_tet_count(
    world: *const ts_world,
    body: u32,
    out_count: *mut usize,
) -> ts_status {
    // SAFETY: contract of this function.
    unsafe { body_value(world, body, out_count, |b| b.tets().len()) }
}

/// Tetrahedra into `out`: tet_count x 4 particle indices (0-based, positively oriented). `len`
/// in uint32_t; below 4 * tet_count gives TS_STATUS_BUFFER_TOO_SMALL and writes nothing.
///
/// # Safety
///
/// `world` is NULL or a live handle; `out` is NULL or holds `len` writable uint32_t.
#[no_mangle]
pub unsafe extern "C" fn ts_body_tets(
    world: *const ts_world,
    body: u32,
    out: *mut u32,
    len: usize,
) -> ts_status {
    // SAFETY: contract of this function.
    unsafe {
        body_array(
            world,
            body,
            out,
            len,
            "tets",
            "uint32_t",
            |_, b| 4 * b.tets().len(),
            |_, b, dst| {
                let order = b.particle_order();
                let mesh_order = |t: &[u32; 4]| order.mesh_indices_of_array(t);
                put(dst, b.tets().iter().flat_map(mesh_order))
            },
        )
    }
}

/// Current volume of a body (m^3, the sum of its signed tetrahedron volumes) into *out_volume.
///
/// # Safety
///
/// `world` is NULL or a live handle; `out_volume` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn ts_body_volume(
    world: *const ts_world,
    body: u32,
    out_volume: *mut f64,
) -> ts_status {
    // SAFETY: contract of this function.
    unsafe { body_value(world, body, out_volume, |b| b.volume()) }
}

/// Rest volume of a body (m^3) into *out_volume.
///
/// # Safety
///
/// `world` is NULL or a live handle; `out_volume` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn ts_body_rest_volume(
    world: *const ts_world,
    body: u32,
    out_volume: *mut f64,
) -> ts_status {
    // SAFETY: contract of this function.
    unsafe { body_value(world, body, out_volume, |b| b.rest_volume()) }
}

/// Largest distance of a particle of the body from its rest position (m) into *out.
///
/// # Safety
///
/// `world` is NULL or a live handle; `out` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn ts_body_max_displacement(
    world: *const ts_world,
    body: u32,
    out: *mut f64,
) -> ts_status {
    // SAFETY: contract of this function.
    unsafe { body_value(world, body, out, |b| b.max_displacement()) }
}

/// Inertial mass added to the body by selective mass scaling (kg; 0 when ts_settings.mass_scaling
/// is off or no particle needed it) into *out_mass.
///
/// # Safety
///
/// `world` is NULL or a live handle; `out_mass` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn ts_body_added_mass(
    world: *const ts_world,
    body: u32,
    out_mass: *mut f64,
) -> ts_status {
    // SAFETY: contract of this function.
    unsafe { body_value(world, body, out_mass, |b| b.added_mass()) }
}

/// Total mass of a body (kg) into *out_mass.
///
/// # Safety
///
/// `world` is NULL or a live handle; `out_mass` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn ts_body_mass(
    world: *const ts_world,
    body: u32,
    out_mass: *mut f64,
) -> ts_status {
    // SAFETY: contract of this function.
    unsafe { body_value(world, body, out_mass, |b| b.mass()) }
}

/// Set the positions and velocities of every particle of a body, e.g. an initial condition or
/// a reset: `positions` holds particle_count x 3 doubles (m, world frame), `velocities`
/// particle_count x 3 doubles (m/s); `positions_len` and `velocities_len` are their lengths in
/// doubles and must both be 3 * particle_count (else TS_STATUS_INVALID_ARGUMENT). NaN/Inf give
/// TS_STATUS_NON_FINITE. Fixed particles take the given position and zero velocity (and stay
/// fixed there). Nothing changes on error. Allocates (not for every haptic frame).
///
/// # Safety
///
/// `world` is NULL or a live handle; `positions` is NULL or holds `positions_len` readable
/// doubles; `velocities` is NULL or holds `velocities_len` readable doubles.
#[no_mangle]
pub unsafe extern "C" fn ts_body_set_state(
    world: *mut ts_world,
    body: u32,
    positions: *const f64,
    positions_len: usize,
    velocities: *const f64,
    velocities_len: usize,
) -> ts_status {
    guard(|| {
        // SAFETY: contract of this function.
        let x = unsafe { input_slice(positions, positions_len, "positions")? };
        // SAFETY: contract of this function.
        let v = unsafe { input_slice(velocities, velocities_len, "velocities")? };
        // SAFETY: contract of this function.
        let h = unsafe { world_mut(world)? };
        let vectors = |xyz: &[f64], name: &str| -> FfiResult<Vec<Vec3>> {
            if !xyz.len().is_multiple_of(3) {
                return Err(fail(
                    ts_status::InvalidArgument,
                    format!("{name}_len {} is not a multiple of 3", xyz.len()),
                ));
            }
            Ok(xyz
                .chunks_exact(3)
                .map(|c| Vec3::new(c[0], c[1], c[2]))
                .collect())
        };
        let (x, v) = (vectors(x, "positions")?, vectors(v, "velocities")?);
        // Into particle order; arrays of the wrong length stay as they are, for
        // World::set_body_state to refuse.
        let order = h.body(body)?.particle_order();
        let reorder = |a: Vec<Vec3>| {
            if a.len() == order.len() {
                order.to_particle_order(&a)
            } else {
                a
            }
        };
        let (x, v) = (reorder(x), reorder(v));
        h.mutate(|w| w.set_body_state(BodyId(body), &x, &v))
    })
}

/// Whether each particle is fixed (1) or free (0) into `out`: particle_count bytes. `len` in
/// bytes; below particle_count gives TS_STATUS_BUFFER_TOO_SMALL and writes nothing. Does not
/// allocate.
///
/// # Safety
///
/// `world` is NULL or a live handle; `out` is NULL or holds `len` writable bytes.
#[no_mangle]
pub unsafe extern "C" fn ts_body_fixed_flags(
    world: *const ts_world,
    body: u32,
    out: *mut u8,
    len: usize,
) -> ts_status {
    // SAFETY: contract of this function.
    unsafe {
        body_array(
            world,
            body,
            out,
            len,
            "fixed flags",
            "bytes",
            |_, b| b.particle_count(),
            |_, b, dst| {
                let order = b.particle_order();
                put(
                    dst,
                    (0..b.particle_count()).map(|k| b.is_fixed(order.particle(k)) as u8),
                )
            },
        )
    }
}

/// Contact radius of the body's particles (m) into *out_radius: particles of different bodies
/// are kept r_a + r_b apart, and in TS_CONTACT_MODE_SAMPLED_POINTS a particle touches a tool
/// when its centre comes closer than this to the tool's samples. In the default
/// TS_CONTACT_MODE_EXACT_SHAPE tools touch the boundary triangles, with a skin of a tenth of
/// this radius.
///
/// # Safety
///
/// `world` is NULL or a live handle; `out_radius` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn ts_body_particle_radius(
    world: *const ts_world,
    body: u32,
    out_radius: *mut f64,
) -> ts_status {
    // SAFETY: contract of this function.
    unsafe { body_value(world, body, out_radius, |b| b.particle_radius()) }
}

/// Set the friction between two bodies where they touch (organ-organ contact; frictionless
/// unless set): static coefficient `friction_static` (mu_s) and kinetic `friction_kinetic`
/// (mu_k), dimensionless, 0 <= mu_k <= mu_s (else TS_STATUS_INVALID_ARGUMENT; NaN/Inf give
/// TS_STATUS_NON_FINITE). The pair is unordered; `body_a` may equal `body_b` (self-contact,
/// see ts_settings.self_contact). Setting a pair again replaces its coefficients. Nothing
/// changes on error.
///
/// # Safety
///
/// `world` is NULL or a live handle.
#[no_mangle]
pub unsafe extern "C" fn ts_world_set_body_pair_friction(
    world: *mut ts_world,
    body_a: u32,
    body_b: u32,
    friction_static: f64,
    friction_kinetic: f64,
) -> ts_status {
    guard(|| {
        // SAFETY: contract of this function.
        let h = unsafe { world_mut(world)? };
        h.mutate(|w| {
            w.set_body_pair_friction(
                BodyId(body_a),
                BodyId(body_b),
                friction_static,
                friction_kinetic,
            )
        })
    })
}
