//! Render surfaces: a visual OBJ (or a body's boundary) bound to a body, its triangles and
//! texture coordinates, and its deformed positions and normals copied into caller buffers.

use crate::ffi::args::{element_count, non_null, world_mut, world_ref, write};
use crate::ffi::body::c_path;
use crate::ffi::error::{fail, FfiResult};
use crate::ffi::guard::guard;
use crate::ffi::status::ts_status;
use crate::ffi::world::ts_world;
use crate::kernels::math::Vec3;
use crate::render::{read_obj, RenderMesh, RenderSurface};
use crate::scene::BodyId;
use crate::world::RenderSurfaceId;
use std::ffi::c_char;
use std::mem::MaybeUninit;

impl ts_world {
    /// The render surface with id `surface`.
    fn render_surface(&self, surface: u32) -> FfiResult<&RenderSurface> {
        Ok(self.world.render_surface(RenderSurfaceId(surface))?)
    }
}

/// `TS_STATUS_BUFFER_TOO_SMALL` when `len < needed`.
fn check_len(len: usize, needed: usize, what: &str, unit: &str) -> FfiResult {
    if len < needed {
        Err(fail(
            ts_status::BufferTooSmall,
            format!("{what}: buffer holds {len} {unit}, {needed} needed"),
        ))
    } else {
        Ok(())
    }
}

/// The first `n` elements of the caller buffer `out` as uninitialised slots.
///
/// # Safety
///
/// `out` is non-NULL and holds at least `n` writable elements.
unsafe fn slots<'a, T>(out: *mut T, n: usize) -> &'a mut [MaybeUninit<T>] {
    // SAFETY: guaranteed by the caller.
    unsafe { std::slice::from_raw_parts_mut(out.cast::<MaybeUninit<T>>(), n) }
}

/// Write `values` as x, y, z doubles into `dst` (3 per vector).
fn put_vectors(dst: &mut [MaybeUninit<f64>], values: &[Vec3]) {
    for (d, v) in dst.chunks_exact_mut(3).zip(values) {
        d[0].write(v.x);
        d[1].write(v.y);
        d[2].write(v.z);
    }
}

/// Add a render surface from a Wavefront OBJ file (`v`, `vt`, `vn`, faces `a`, `a/b`, `a//c`,
/// `a/b/c`, polygons fan-triangulated) bound to body `body`: one render vertex per distinct
/// v/vt/vn triple of the faces. Positions are multiplied by `scale` (> 0, file units to m; use
/// the scale the body's mesh was loaded with: the OBJ must be in the body's rest frame). Every
/// vertex is bound once to its enclosing rest tetrahedron, or to the nearest one (extrapolated)
/// if it lies outside the body. A missing or malformed file gives TS_STATUS_MESH_ERROR naming
/// the file and line. The new surface's id (0, 1, ... per world) goes to *out_surface.
///
/// # Safety
///
/// `world` is NULL or a live handle; `path` is NULL or NUL-terminated; `out_surface` is NULL
/// or writable.
#[no_mangle]
pub unsafe extern "C" fn ts_world_add_render_surface_from_file(
    world: *mut ts_world,
    body: u32,
    path: *const c_char,
    scale: f64,
    out_surface: *mut u32,
) -> ts_status {
    guard(|| {
        non_null(out_surface, "out_surface")?;
        // SAFETY: contract of this function.
        let path = unsafe { c_path(path, "path")? };
        // SAFETY: contract of this function.
        let h = unsafe { world_mut(world)? };
        crate::mesh::validate_scale(scale)?;
        h.world.body(BodyId(body))?;
        let mesh = read_obj(&path, scale)?;
        let id = h.mutate(|w| w.add_render_surface(BodyId(body), mesh))?;
        // SAFETY: checked non-NULL.
        unsafe { write(out_surface, id.0) };
        Ok(())
    })
}

/// Add a render surface made of body `body`'s own boundary triangles (one vertex per boundary
/// particle, no texture coordinates), for bodies without a visual mesh such as the default
/// organ. The new surface's id goes to *out_surface.
///
/// # Safety
///
/// `world` is NULL or a live handle; `out_surface` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn ts_world_add_render_surface_from_boundary(
    world: *mut ts_world,
    body: u32,
    out_surface: *mut u32,
) -> ts_status {
    guard(|| {
        non_null(out_surface, "out_surface")?;
        // SAFETY: contract of this function.
        let h = unsafe { world_mut(world)? };
        let b = h.world.body(BodyId(body))?;
        let mesh = RenderMesh::from_boundary(b.rest_positions(), b.boundary_triangles());
        let id = h.mutate(|w| w.add_render_surface(BodyId(body), mesh))?;
        // SAFETY: checked non-NULL.
        unsafe { write(out_surface, id.0) };
        Ok(())
    })
}

/// Number of render surfaces in the world into *out_count.
///
/// # Safety
///
/// `world` is NULL or a live handle; `out_count` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn ts_world_render_surface_count(
    world: *const ts_world,
    out_count: *mut usize,
) -> ts_status {
    guard(|| {
        non_null(out_count, "out_count")?;
        // SAFETY: contract of this function.
        let h = unsafe { world_ref(world)? };
        // SAFETY: checked non-NULL.
        unsafe { write(out_count, h.world.render_surface_count()) };
        Ok(())
    })
}

/// Read one value of a render surface into `out`.
///
/// # Safety
///
/// `world` is NULL or a live handle; `out` is NULL or writable.
unsafe fn surface_value<T>(
    world: *const ts_world,
    surface: u32,
    out: *mut T,
    get: impl FnOnce(&RenderSurface) -> T,
) -> ts_status {
    guard(|| {
        non_null(out, "out")?;
        // SAFETY: contract of the caller.
        let h = unsafe { world_ref(world)? };
        let v = get(h.render_surface(surface)?);
        // SAFETY: checked non-NULL.
        unsafe { write(out, v) };
        Ok(())
    })
}

/// Number of vertices of a render surface into *out_count (the length, in vertices, of the
/// arrays of ts_render_surface_texcoords and ts_render_surface_update).
///
/// # Safety
///
/// `world` is NULL or a live handle; `out_count` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn ts_render_surface_vertex_count(
    world: *const ts_world,
    surface: u32,
    out_count: *mut usize,
) -> ts_status {
    // SAFETY: contract of this function.
    unsafe { surface_value(world, surface, out_count, |s| s.vertex_count()) }
}

/// Number of triangles of a render surface into *out_count.
///
/// # Safety
///
/// `world` is NULL or a live handle; `out_count` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn ts_render_surface_triangle_count(
    world: *const ts_world,
    surface: u32,
    out_count: *mut usize,
) -> ts_status {
    // SAFETY: contract of this function.
    unsafe { surface_value(world, surface, out_count, |s| s.triangles().len()) }
}

/// The triangles of a render surface into `out`: triangle_count x 3 vertex indices (0-based,
/// in the file's winding). `len` is the buffer length in uint32_t; below 3 * triangle_count
/// gives TS_STATUS_BUFFER_TOO_SMALL and writes nothing. Does not allocate.
///
/// # Safety
///
/// `world` is NULL or a live handle; `out` is NULL or holds `len` writable uint32_t.
#[no_mangle]
pub unsafe extern "C" fn ts_render_surface_triangles(
    world: *const ts_world,
    surface: u32,
    out: *mut u32,
    len: usize,
) -> ts_status {
    guard(|| {
        non_null(out, "out")?;
        // SAFETY: contract of this function.
        let h = unsafe { world_ref(world)? };
        let tris = h.render_surface(surface)?.triangles();
        let needed = element_count::<u32>(tris.len(), 3, "triangles")?;
        check_len(len, needed, "triangles", "uint32_t")?;
        // SAFETY: `out` holds `len >= needed` writable elements by contract.
        let dst = unsafe { slots(out, needed) };
        for (d, i) in dst.iter_mut().zip(tris.iter().flatten()) {
            d.write(*i);
        }
        Ok(())
    })
}

/// The texture coordinates of a render surface into `out`: vertex_count x 2 doubles (u, v per
/// vertex; 0, 0 for vertices the file gave none). `len` is the buffer length in doubles; below
/// 2 * vertex_count gives TS_STATUS_BUFFER_TOO_SMALL and writes nothing. Does not allocate.
///
/// # Safety
///
/// `world` is NULL or a live handle; `out` is NULL or holds `len` writable doubles.
#[no_mangle]
pub unsafe extern "C" fn ts_render_surface_texcoords(
    world: *const ts_world,
    surface: u32,
    out: *mut f64,
    len: usize,
) -> ts_status {
    guard(|| {
        non_null(out, "out")?;
        // SAFETY: contract of this function.
        let h = unsafe { world_ref(world)? };
        let tex = h.render_surface(surface)?.texcoords();
        let needed = element_count::<f64>(tex.len(), 2, "texcoords")?;
        check_len(len, needed, "texcoords", "doubles")?;
        // SAFETY: `out` holds `len >= needed` writable elements by contract.
        let dst = unsafe { slots(out, needed) };
        for (d, v) in dst.iter_mut().zip(tex.iter().flatten()) {
            d.write(*v);
        }
        Ok(())
    })
}

/// Update a render surface from its body's current particle positions and copy the deformed
/// vertex positions (m, world frame) into `positions_out` and the vertex normals (unit,
/// area-weighted face normals, renormalised) into `normals_out`: vertex_count x 3 doubles each
/// (x, y, z per vertex). `len` is the length in doubles of each buffer; below
/// 3 * vertex_count gives TS_STATUS_BUFFER_TOO_SMALL and writes nothing. Does not allocate:
/// call it after ts_world_step whenever a frame is drawn.
///
/// # Safety
///
/// `world` is NULL or a live handle; `positions_out` and `normals_out` are NULL or hold `len`
/// writable doubles each.
#[no_mangle]
pub unsafe extern "C" fn ts_render_surface_update(
    world: *mut ts_world,
    surface: u32,
    positions_out: *mut f64,
    normals_out: *mut f64,
    len: usize,
) -> ts_status {
    guard(|| {
        non_null(positions_out, "positions_out")?;
        non_null(normals_out, "normals_out")?;
        // SAFETY: contract of this function.
        let h = unsafe { world_mut(world)? };
        let n = h.render_surface(surface)?.vertex_count();
        let needed = element_count::<f64>(n, 3, "vertices")?;
        check_len(len, needed, "render surface update", "doubles")?;
        let id = RenderSurfaceId(surface);
        h.mutate(|w| w.update_render_surface(id).map(|_| ()))?;
        let s = h.render_surface(surface)?;
        // SAFETY: both buffers hold `len >= needed` writable doubles by contract.
        let (p, m) = unsafe { (slots(positions_out, needed), slots(normals_out, needed)) };
        put_vectors(p, s.positions());
        put_vectors(m, s.normals());
        Ok(())
    })
}

/// Write a file of a render surface at its last update (ts_render_surface_update).
///
/// # Safety
///
/// `world` is NULL or a live handle; `path` is NULL or NUL-terminated.
unsafe fn write_surface(
    world: *const ts_world,
    surface: u32,
    path: *const c_char,
    writer: impl FnOnce(&RenderSurface, &std::path::Path) -> std::io::Result<()>,
) -> ts_status {
    guard(|| {
        // SAFETY: contract of the caller.
        let path = unsafe { c_path(path, "path")? };
        // SAFETY: contract of the caller.
        let h = unsafe { world_ref(world)? };
        writer(h.render_surface(surface)?, &path).map_err(|e| {
            fail(
                ts_status::IoError,
                format!("{}: cannot write: {e}", path.display()),
            )
        })
    })
}

/// Write a render surface as it was at its last ts_render_surface_update (or when it was
/// added) to a Wavefront OBJ file: v (m), vt (when the source had texture coordinates), vn and
/// f a/b/c records. A file that cannot be written gives TS_STATUS_IO_ERROR. Allocates (not for
/// the haptic loop).
///
/// # Safety
///
/// `world` is NULL or a live handle; `path` is NULL or NUL-terminated.
#[no_mangle]
pub unsafe extern "C" fn ts_render_surface_write_obj(
    world: *const ts_world,
    surface: u32,
    path: *const c_char,
) -> ts_status {
    // SAFETY: contract of this function.
    unsafe { write_surface(world, surface, path, RenderSurface::write_obj) }
}

/// Write a render surface as it was at its last ts_render_surface_update (or when it was
/// added) to a VTU file for ParaView: triangles, with point data Normals and
/// TextureCoordinates. A file that cannot be written gives TS_STATUS_IO_ERROR.
///
/// # Safety
///
/// `world` is NULL or a live handle; `path` is NULL or NUL-terminated.
#[no_mangle]
pub unsafe extern "C" fn ts_render_surface_write_vtu(
    world: *const ts_world,
    surface: u32,
    path: *const c_char,
) -> ts_status {
    // SAFETY: contract of this function.
    unsafe { write_surface(world, surface, path, RenderSurface::write_vtu) }
}
