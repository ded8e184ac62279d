//! Grasping from C: a tool attaches the tissue within its jaws (see the Rust `World::grasp`).

use crate::ffi::args::{non_null, world_mut, world_ref, write};
use crate::ffi::guard::guard;
use crate::ffi::status::ts_status;
use crate::ffi::world::ts_world;
use crate::interaction::grasp::GraspOptions;
use crate::scene::ToolId;

/// How a tool grasps. ts_grasp_options_default gives automatic reach and compliance and a grasp
/// that never slips.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ts_grasp_options {
    /// Particles within this distance (m) of the tool's surface are grasped; 0 means automatic
    /// (1.5 x the body's particle radius).
    pub reach: f64,
    /// Compliance of each attachment (m/N; 0 = rigid); negative means automatic (1 / (E r),
    /// E the body's Young's modulus, r its particle radius).
    pub compliance: f64,
    /// Largest total pull (N) the grasp holds before the tissue slips out; 0 or INFINITY means
    /// it never slips.
    pub max_force: f64,
}

impl From<&GraspOptions> for ts_grasp_options {
    fn from(o: &GraspOptions) -> Self {
        ts_grasp_options {
            reach: o.reach.unwrap_or(0.0),
            compliance: o.compliance.unwrap_or(-1.0),
            max_force: o.max_force,
        }
    }
}

impl ts_grasp_options {
    /// The Rust options (the automatic values mapped to `None`, 0 N to infinity); checked by
    /// `GraspOptions::validate` when used.
    pub fn to_options(&self) -> GraspOptions {
        GraspOptions {
            reach: (self.reach != 0.0).then_some(self.reach),
            compliance: (self.compliance >= 0.0 || self.compliance.is_nan())
                .then_some(self.compliance),
            max_force: if self.max_force == 0.0 {
                f64::INFINITY
            } else {
                self.max_force
            },
        }
    }
}

/// Write the default grasp options into *out.
///
/// # Safety
///
/// `out` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn ts_grasp_options_default(out: *mut ts_grasp_options) -> ts_status {
    guard(|| {
        non_null(out, "out")?;
        // SAFETY: checked non-NULL.
        unsafe { write(out, ts_grasp_options::from(&GraspOptions::default())) };
        Ok(())
    })
}

/// Grasp with `tool`: every free particle within reach of its surface is attached to the tool
/// where it is now, and follows the tool (compliant constraints) until ts_tool_release or until
/// the pull exceeds `max_force` (the tissue slips). `options` may be NULL (defaults). The number
/// of grasped particles goes to *out_count when `out_count` is not NULL (0: nothing within
/// reach, not an error). A grasp replaces the tool's previous one. NaN gives
/// TS_STATUS_NON_FINITE, a negative reach or max_force TS_STATUS_INVALID_ARGUMENT; nothing
/// changes on error.
///
/// # Safety
///
/// `world` is NULL or a live handle; `options` is NULL or readable; `out_count` is NULL or
/// writable.
#[no_mangle]
pub unsafe extern "C" fn ts_tool_grasp(
    world: *mut ts_world,
    tool: u32,
    options: *const ts_grasp_options,
    out_count: *mut u32,
) -> ts_status {
    guard(|| {
        let options = if options.is_null() {
            GraspOptions::default()
        } else {
            // SAFETY: non-NULL, readable by contract; any bit pattern is a valid value.
            unsafe { *options }.to_options()
        };
        // SAFETY: contract of this function.
        let h = unsafe { world_mut(world)? };
        let count = h.mutate(|w| w.grasp(ToolId(tool), &options))?;
        if !out_count.is_null() {
            // SAFETY: non-NULL, writable by contract.
            unsafe { write(out_count, count as u32) };
        }
        Ok(())
    })
}

/// Release `tool`'s grasp: the tissue is free again (contact with the tool still acts).
///
/// # Safety
///
/// `world` is NULL or a live handle.
#[no_mangle]
pub unsafe extern "C" fn ts_tool_release(world: *mut ts_world, tool: u32) -> ts_status {
    guard(|| {
        // SAFETY: contract of this function.
        let h = unsafe { world_mut(world)? };
        h.mutate(|w| w.release(ToolId(tool)))
    })
}

/// The number of particles `tool` holds into *out_count (0 when not grasping or after the
/// tissue slipped).
///
/// # Safety
///
/// `world` is NULL or a live handle; `out_count` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn ts_tool_grasped_count(
    world: *const ts_world,
    tool: u32,
    out_count: *mut u32,
) -> ts_status {
    guard(|| {
        non_null(out_count, "out_count")?;
        // SAFETY: contract of this function.
        let h = unsafe { world_ref(world)? };
        let n = h.world.grasped_count(ToolId(tool))?;
        // SAFETY: checked non-NULL.
        unsafe { write(out_count, n as u32) };
        Ok(())
    })
}
