//! The substeps of a step that starts with the tissue at a tool compressed, from C (the Rust
//! `Settings::crushed_substeps`). Not a field of ts_settings, whose layout is fixed: a world
//! starts with 1 (none added by the setting), ts_world_set_crushed_substeps changes it, and
//! ts_world_set_settings keeps it.

use crate::ffi::args::world_mut;
use crate::ffi::guard::guard;
use crate::ffi::status::ts_status;
use crate::ffi::world::{ts_world, world_value};
use crate::Settings;

/// From the next step on, take at least `substeps` substeps (1..=max_substeps of the world's
/// settings) in a step that starts with the tissue at a tool compressed: a tetrahedron with a
/// corner within a particle radius of a tool's bounding box below half its rest volume, now or
/// two steps ahead (the elasticity on tetrahedra, the volume constraints on). 1, the default,
/// adds none (where the tool is narrower than a compressed tetrahedron's longest rest edge the
/// step takes twice its substeps whatever this setting); 2 keeps wide probes pressed deep out
/// of the tissue too, at twice the cost of the steps that compress it (docs/SETTINGS.md,
/// "Deep presses"). 0 or more than max_substeps returns TS_STATUS_INVALID_ARGUMENT and changes
/// nothing.
///
/// # Safety
///
/// `world` is NULL or a live handle.
#[no_mangle]
pub unsafe extern "C" fn ts_world_set_crushed_substeps(
    world: *mut ts_world,
    substeps: u32,
) -> ts_status {
    guard(|| {
        // SAFETY: contract of this function.
        let h = unsafe { world_mut(world)? };
        h.mutate(|w| {
            w.set_settings(Settings {
                crushed_substeps: substeps,
                ..w.settings().clone()
            })
        })
    })
}

/// Write the world's crushed-step substeps into *out_substeps (1 until
/// ts_world_set_crushed_substeps).
///
/// # Safety
///
/// `world` is NULL or a live handle; `out_substeps` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn ts_world_crushed_substeps(
    world: *const ts_world,
    out_substeps: *mut u32,
) -> ts_status {
    // SAFETY: contract of this function.
    unsafe {
        world_value(world, out_substeps, "out_substeps", |w| {
            w.settings().crushed_substeps
        })
    }
}
