//! Saving and restoring a world's dynamic state through caller buffers.
//!
//! The bytes are those of [`crate::World::save_state`]: a versioned, explicit format (never a
//! memory image), checked on restore. A state restores into a world with the same scene (same
//! bodies, particle counts and tools), in this process or another.

use crate::ffi::args::{input_slice, non_null, world_mut, world_ref, write};
use crate::ffi::error::fail;
use crate::ffi::guard::guard;
use crate::ffi::status::ts_status;
use crate::ffi::world::ts_world;

/// Size in bytes of the state ts_world_save_state writes for the world as it is now (it
/// changes when bodies or tools are added) into *out_size.
///
/// # Safety
///
/// `world` is NULL or a live handle; `out_size` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn ts_world_state_size(
    world: *const ts_world,
    out_size: *mut usize,
) -> ts_status {
    guard(|| {
        non_null(out_size, "out_size")?;
        // SAFETY: contract of this function.
        let h = unsafe { world_ref(world)? };
        let n = h.world.state_size();
        // SAFETY: checked non-NULL.
        unsafe { write(out_size, n) };
        Ok(())
    })
}

/// Save the world's dynamic state (time, particle positions and velocities, fixed flags, cuts,
/// tool poses, grasps, needle holds)
/// into `buf` of `len` bytes. `len` below ts_world_state_size gives TS_STATUS_BUFFER_TOO_SMALL
/// and writes nothing. The number of bytes written goes to *out_written, which is optional
/// (may be NULL). Restoring it with ts_world_restore_state and stepping again reproduces the
/// original run bit for bit.
///
/// # Safety
///
/// `world` is NULL or a live handle; `buf` is NULL or holds `len` writable bytes;
/// `out_written` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn ts_world_save_state(
    world: *mut ts_world,
    buf: *mut u8,
    len: usize,
    out_written: *mut usize,
) -> ts_status {
    guard(|| {
        non_null(buf, "buf")?;
        // SAFETY: contract of this function.
        let h = unsafe { world_mut(world)? };
        let needed = h.world.state_size();
        if len < needed {
            return Err(fail(
                ts_status::BufferTooSmall,
                format!("state: buffer holds {len} bytes, {needed} needed"),
            ));
        }
        let mut scratch = std::mem::take(&mut h.scratch);
        scratch.clear();
        h.world.save_state(&mut scratch);
        let n = scratch.len();
        let r = if n > len {
            Err(fail(
                ts_status::BufferTooSmall,
                format!("state: buffer holds {len} bytes, {n} needed"),
            ))
        } else {
            // SAFETY: `buf` holds `len >= n` writable bytes by contract.
            unsafe { std::ptr::copy_nonoverlapping(scratch.as_ptr(), buf, n) };
            if !out_written.is_null() {
                // SAFETY: non-NULL, writable by contract.
                unsafe { write(out_written, n) };
            }
            Ok(())
        };
        h.scratch = scratch;
        r
    })
}

/// Restore a state saved by ts_world_save_state (`buf`, `len` bytes) from a world with the same
/// scene. A truncated, corrupt or wrong-version buffer, or one from another scene, gives
/// TS_STATUS_BAD_STATE and leaves the world unchanged.
///
/// # Safety
///
/// `world` is NULL or a live handle; `buf` is NULL or holds `len` readable bytes.
#[no_mangle]
pub unsafe extern "C" fn ts_world_restore_state(
    world: *mut ts_world,
    buf: *const u8,
    len: usize,
) -> ts_status {
    guard(|| {
        // SAFETY: contract of this function.
        let bytes = unsafe { input_slice(buf, len, "buf")? };
        // SAFETY: contract of this function.
        let h = unsafe { world_mut(world)? };
        h.mutate(|w| w.restore_state(bytes))
    })
}
