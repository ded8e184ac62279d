//! Argument conversions shared by the exports: NULL pointers, finiteness of raw input arrays,
//! slices from `(pointer, length)` pairs, and access to a world handle. Value ranges are not
//! checked here: the core's validators (`Settings::validate`, `BodyOptions::validate`,
//! `ToolShape::validate`, `ToolOptions::validate`, `Pose::from_components`, ...) are the one
//! validation path, and their errors become statuses and last-error messages.

use crate::ffi::error::{fail, FfiResult};
use crate::ffi::status::ts_status;
use crate::ffi::world::ts_world;
use crate::kernels::math::Vec3;

/// `TS_STATUS_NULL_PARAMETER` when `p` is NULL.
pub fn non_null<T>(p: *const T, name: &str) -> FfiResult {
    if p.is_null() {
        Err(fail(
            ts_status::NullParameter,
            format!("{name} must not be NULL"),
        ))
    } else {
        Ok(())
    }
}

/// `TS_STATUS_NON_FINITE` when any of `v` is NaN or ±Inf.
pub fn all_finite(v: &[f64], name: &str) -> FfiResult {
    match v.iter().position(|x| !x.is_finite()) {
        None => Ok(()),
        Some(i) => Err(fail(
            ts_status::NonFinite,
            format!("{name}[{i}] is not finite ({})", v[i]),
        )),
    }
}

/// `count * per` without overflow, and small enough to address as `T` elements.
pub fn element_count<T>(count: usize, per: usize, name: &str) -> FfiResult<usize> {
    count
        .checked_mul(per)
        .filter(|n| {
            n.checked_mul(std::mem::size_of::<T>().max(1))
                .is_some_and(|b| b <= isize::MAX as usize)
        })
        .ok_or_else(|| {
            fail(
                ts_status::InvalidArgument,
                format!("{name}: count {count} is too large"),
            )
        })
}

/// The slice of `len` elements at `p` (`TS_STATUS_NULL_PARAMETER` when `p` is NULL).
///
/// # Safety
///
/// `p` is NULL or points to `len` readable, initialised elements that outlive the call.
pub unsafe fn input_slice<'a, T>(p: *const T, len: usize, name: &str) -> FfiResult<&'a [T]> {
    non_null(p, name)?;
    element_count::<T>(len, 1, name)?;
    // SAFETY: non-NULL and, by the caller's contract, valid for `len` elements.
    Ok(unsafe { std::slice::from_raw_parts(p, len) })
}

/// The three doubles at `p` as a vector.
///
/// # Safety
///
/// `p` is non-NULL and points to 3 readable doubles.
pub unsafe fn read_vec3(p: *const f64) -> Vec3 {
    // SAFETY: guaranteed by the caller.
    unsafe { Vec3::new(*p, *p.add(1), *p.add(2)) }
}

/// Write `v` through `p` (checked non-NULL beforehand by the caller).
///
/// # Safety
///
/// `p` is non-NULL, aligned and writable.
pub unsafe fn write<T>(p: *mut T, v: T) {
    // SAFETY: guaranteed by the caller.
    unsafe { p.write(v) }
}

/// The world behind `w`, for reading (`TS_STATUS_NULL_PARAMETER`, `TS_STATUS_POISONED`).
///
/// # Safety
///
/// `w` is NULL or a live handle from `ts_world_new` not used by another thread.
pub unsafe fn world_ref<'a>(w: *const ts_world) -> FfiResult<&'a ts_world> {
    non_null(w, "world")?;
    // SAFETY: non-NULL and live by the caller's contract.
    let h = unsafe { &*w };
    h.check_poisoned()?;
    Ok(h)
}

/// The world behind `w`, for changing (`TS_STATUS_NULL_PARAMETER`, `TS_STATUS_POISONED`).
///
/// # Safety
///
/// `w` is NULL or a live handle from `ts_world_new` not used by another thread.
pub unsafe fn world_mut<'a>(w: *mut ts_world) -> FfiResult<&'a mut ts_world> {
    non_null(w, "world")?;
    // SAFETY: non-NULL, live and exclusively ours by the caller's contract.
    let h = unsafe { &mut *w };
    h.check_poisoned()?;
    Ok(h)
}
