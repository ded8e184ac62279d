//! Cutting from C: a blade's swept edge removes the neighbour pairs and tetrahedra it crosses
//! (see the Rust `World::cut` and `World::make_blade`).

use crate::ffi::args::{all_finite, input_slice, non_null, world_mut, world_ref, write};
use crate::ffi::guard::guard;
use crate::ffi::status::ts_status;
use crate::ffi::world::ts_world;
use crate::kernels::math::Vec3;
use crate::scene::cut::Blade;
use crate::scene::{BodyId, ToolId};

/// What a cut removed.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ts_cut_report {
    /// Neighbour pairs cut.
    pub pairs: u64,
    /// Tetrahedra removed.
    pub tets: u64,
    /// Particles left without elasticity (too few neighbours).
    pub isolated: u64,
}

/// Cut `body` now with a blade whose edge runs from `from[0..3]` to `from[3..6]` at the start
/// of its motion and from `to[0..3]` to `to[3..6]` at its end (m, world frame): the neighbour
/// pairs and tetrahedra crossed by the swept surface are removed. What was removed goes to
/// *out_report when `out_report` is not NULL. NaN/Inf give TS_STATUS_NON_FINITE; nothing
/// changes on error.
///
/// # Safety
///
/// `world` is NULL or a live handle; `from` and `to` are NULL or point to 6 readable doubles;
/// `out_report` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn ts_world_cut(
    world: *mut ts_world,
    body: u32,
    from: *const f64,
    to: *const f64,
    out_report: *mut ts_cut_report,
) -> ts_status {
    guard(|| {
        // SAFETY: 6 readable doubles each by contract (NULL checked inside).
        let (from, to) = unsafe { (input_slice(from, 6, "from")?, input_slice(to, 6, "to")?) };
        all_finite(from, "from")?;
        all_finite(to, "to")?;
        let edge = |v: &[f64]| [Vec3::new(v[0], v[1], v[2]), Vec3::new(v[3], v[4], v[5])];
        let blade = Blade {
            from: edge(from),
            to: edge(to),
        };
        // SAFETY: contract of this function.
        let h = unsafe { world_mut(world)? };
        let r = h.mutate(|w| w.cut(BodyId(body), &blade))?;
        if !out_report.is_null() {
            let report = ts_cut_report {
                pairs: r.pairs as u64,
                tets: r.tets as u64,
                isolated: r.isolated as u64,
            };
            // SAFETY: non-NULL, writable by contract.
            unsafe { write(out_report, report) };
        }
        Ok(())
    })
}

/// Make `tool` (a capsule or a cylinder) a blade: its edge is the segment of its local y axis
/// between +-half_height; at the end of every step it cuts every body along the surface its
/// edge swept, and it does not push the tissue. Another shape gives TS_STATUS_INVALID_ARGUMENT.
///
/// # Safety
///
/// `world` is NULL or a live handle.
#[no_mangle]
pub unsafe extern "C" fn ts_tool_make_blade(world: *mut ts_world, tool: u32) -> ts_status {
    guard(|| {
        // SAFETY: contract of this function.
        let h = unsafe { world_mut(world)? };
        h.mutate(|w| w.make_blade(ToolId(tool)))
    })
}

/// The neighbour pairs cut and tetrahedra removed from `body` so far into *out_pairs and
/// *out_tets.
///
/// # Safety
///
/// `world` is NULL or a live handle; `out_pairs` and `out_tets` are NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn ts_body_cut_counts(
    world: *const ts_world,
    body: u32,
    out_pairs: *mut u64,
    out_tets: *mut u64,
) -> ts_status {
    guard(|| {
        non_null(out_pairs, "out_pairs")?;
        non_null(out_tets, "out_tets")?;
        // SAFETY: contract of this function.
        let h = unsafe { world_ref(world)? };
        let (pairs, tets) = h.world.body(BodyId(body))?.cut_counts();
        // SAFETY: checked non-NULL.
        unsafe {
            write(out_pairs, pairs as u64);
            write(out_tets, tets as u64);
        }
        Ok(())
    })
}
