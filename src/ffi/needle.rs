//! Needle insertion from C: a capsule or cylinder tool that punctures the tissue and holds it on
//! its shaft with friction (see the Rust `World::make_needle`).

use crate::ffi::args::{non_null, world_mut, world_ref, write};
use crate::ffi::guard::guard;
use crate::ffi::status::ts_status;
use crate::ffi::world::ts_world;
use crate::interaction::needle::NeedleOptions;
use crate::scene::ToolId;

/// How a needle punctures and holds the tissue. ts_needle_options_default gives 1 N, 20 N/m and
/// automatic reach.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ts_needle_options {
    /// Axial force (N, > 0) the tissue must exert on the tip for the needle to puncture it.
    pub puncture_force: f64,
    /// Axial friction per inserted length (N/m, >= 0) once punctured.
    pub friction_per_length: f64,
    /// Particles within this distance (m) of the inserted shaft's axis are held on it; 0 means
    /// automatic (the needle's radius plus 1.5 particle radii).
    pub reach: f64,
}

impl From<&NeedleOptions> for ts_needle_options {
    fn from(o: &NeedleOptions) -> Self {
        ts_needle_options {
            puncture_force: o.puncture_force,
            friction_per_length: o.friction_per_length,
            reach: o.reach.unwrap_or(0.0),
        }
    }
}

impl ts_needle_options {
    /// The Rust options (reach 0 means automatic); checked by `NeedleOptions::validate` when
    /// used.
    pub fn to_options(&self) -> NeedleOptions {
        NeedleOptions {
            puncture_force: self.puncture_force,
            friction_per_length: self.friction_per_length,
            reach: (self.reach != 0.0).then_some(self.reach),
        }
    }
}

/// Where a needle is: ts_tool_needle_state.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ts_needle_state {
    /// 1 when the needle is in the tissue, else 0.
    pub punctured: u8,
    /// How far the tip is past the entry point along the shaft (m; 0 when not punctured).
    pub inserted_length: f64,
    /// Number of particles held on the shaft.
    pub held: u32,
}

/// Write the default needle options into *out.
///
/// # Safety
///
/// `out` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn ts_needle_options_default(out: *mut ts_needle_options) -> ts_status {
    guard(|| {
        non_null(out, "out")?;
        // SAFETY: checked non-NULL.
        unsafe { write(out, ts_needle_options::from(&NeedleOptions::default())) };
        Ok(())
    })
}

/// Make `tool` (a capsule or a cylinder: shaft along its local y axis, tip at local +y) a needle:
/// it punctures the tissue when the tissue pushes back on its tip with `puncture_force`, then
/// holds the tissue on its shaft with axial friction. `options` may be NULL (defaults). Another
/// shape or a bad option gives TS_STATUS_INVALID_ARGUMENT (NaN: TS_STATUS_NON_FINITE); nothing
/// changes on error.
///
/// # Safety
///
/// `world` is NULL or a live handle; `options` is NULL or readable.
#[no_mangle]
pub unsafe extern "C" fn ts_tool_make_needle(
    world: *mut ts_world,
    tool: u32,
    options: *const ts_needle_options,
) -> ts_status {
    guard(|| {
        let options = if options.is_null() {
            NeedleOptions::default()
        } else {
            // SAFETY: non-NULL, readable by contract; any bit pattern is a valid value.
            unsafe { *options }.to_options()
        };
        // SAFETY: contract of this function.
        let h = unsafe { world_mut(world)? };
        h.mutate(|w| w.make_needle(ToolId(tool), &options))
    })
}

/// The insertion state of needle `tool` into *out_state (TS_STATUS_INVALID_ARGUMENT if the tool
/// is not a needle).
///
/// # Safety
///
/// `world` is NULL or a live handle; `out_state` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn ts_tool_needle_state(
    world: *const ts_world,
    tool: u32,
    out_state: *mut ts_needle_state,
) -> ts_status {
    guard(|| {
        non_null(out_state, "out_state")?;
        // SAFETY: contract of this function.
        let h = unsafe { world_ref(world)? };
        let s = h.world.needle_state(ToolId(tool))?;
        let state = ts_needle_state {
            punctured: s.punctured as u8,
            inserted_length: s.inserted_length,
            held: s.held as u32,
        };
        // SAFETY: checked non-NULL.
        unsafe { write(out_state, state) };
        Ok(())
    })
}
