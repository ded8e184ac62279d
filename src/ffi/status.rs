//! `ts_status`: the result code of every fallible call, and its text.

use std::ffi::c_char;
use std::os::raw::c_int;

/// The result of every fallible call of the C API. `TS_STATUS_OK` (0) is success; every other
/// value is a failure and the thread's last error message (ts_last_error_message) says why.
/// The numbers are part of the ABI: they are never changed or reused.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ts_status {
    /// Success; the outputs were written.
    Ok = 0,
    /// A required pointer argument was NULL.
    NullParameter = 1,
    /// An argument is out of its valid range (negative radius, zero quaternion, bad enum value).
    InvalidArgument = 2,
    /// An input holds NaN or +/-Inf; nothing was changed.
    NonFinite = 3,
    /// No body with this id exists in the world.
    UnknownBody = 4,
    /// No tool with this id exists in the world.
    UnknownTool = 5,
    /// A caller buffer is too small; nothing was written (the message gives the size needed).
    BufferTooSmall = 6,
    /// A mesh file could not be read or a mesh is malformed (the message names the file).
    MeshError = 7,
    /// A saved state cannot be restored (truncated, corrupt, wrong version or other scene).
    BadState = 8,
    /// The step produced NaN/Inf or left the divergence limits of ts_settings (particle speed,
    /// body extent, volume ratio); the world was rolled back to its state before the step and
    /// the message names the body and the reason.
    Diverged = 9,
    /// An I/O error other than reading a mesh.
    IoError = 10,
    /// A Rust panic was caught at the API boundary (a bug in tissuesim; please report it).
    Panic = 11,
    /// The world is unusable because an earlier call panicked while changing it; free it.
    Poisoned = 12,
    /// No render surface with this id exists in the world.
    UnknownRenderSurface = 13,
}

impl ts_status {
    /// Every status, in numeric order.
    pub(crate) const ALL: [ts_status; 14] = [
        ts_status::Ok,
        ts_status::NullParameter,
        ts_status::InvalidArgument,
        ts_status::NonFinite,
        ts_status::UnknownBody,
        ts_status::UnknownTool,
        ts_status::BufferTooSmall,
        ts_status::MeshError,
        ts_status::BadState,
        ts_status::Diverged,
        ts_status::IoError,
        ts_status::Panic,
        ts_status::Poisoned,
        ts_status::UnknownRenderSurface,
    ];

    /// The status with numeric value `code`, if there is one.
    pub(crate) fn from_code(code: c_int) -> Option<ts_status> {
        ts_status::ALL.iter().copied().find(|s| *s as c_int == code)
    }

    /// The static, NUL-terminated description of this status.
    pub(crate) fn text(self) -> &'static str {
        match self {
            ts_status::Ok => "TS_STATUS_OK: success\0",
            ts_status::NullParameter => {
                "TS_STATUS_NULL_PARAMETER: a required pointer argument was NULL\0"
            }
            ts_status::InvalidArgument => {
                "TS_STATUS_INVALID_ARGUMENT: an argument is out of its valid range\0"
            }
            ts_status::NonFinite => "TS_STATUS_NON_FINITE: an input holds NaN or Inf\0",
            ts_status::UnknownBody => "TS_STATUS_UNKNOWN_BODY: no body with this id\0",
            ts_status::UnknownTool => "TS_STATUS_UNKNOWN_TOOL: no tool with this id\0",
            ts_status::BufferTooSmall => {
                "TS_STATUS_BUFFER_TOO_SMALL: the caller buffer is too small\0"
            }
            ts_status::MeshError => {
                "TS_STATUS_MESH_ERROR: a mesh could not be read or is malformed\0"
            }
            ts_status::BadState => "TS_STATUS_BAD_STATE: the saved state cannot be restored\0",
            ts_status::Diverged => {
                "TS_STATUS_DIVERGED: the step produced NaN/Inf or left the divergence limits and was rolled back\0"
            }
            ts_status::IoError => "TS_STATUS_IO_ERROR: input/output error\0",
            ts_status::Panic => "TS_STATUS_PANIC: internal error (a Rust panic was caught)\0",
            ts_status::Poisoned => {
                "TS_STATUS_POISONED: the world is unusable after an internal error\0"
            }
            ts_status::UnknownRenderSurface => {
                "TS_STATUS_UNKNOWN_RENDER_SURFACE: no render surface with this id\0"
            }
        }
    }
}

const UNKNOWN_STATUS: &str = "unknown ts_status value\0";

/// A static, NUL-terminated English description of a status, starting with its enumerator name
/// (for example "TS_STATUS_NULL_PARAMETER: ..."). Never NULL; values that are not a ts_status
/// give "unknown ts_status value". The parameter is an int so that any value is safe to pass.
#[no_mangle]
pub extern "C" fn ts_status_string(status: c_int) -> *const c_char {
    let text = crate::ffi::guard::guard_value(UNKNOWN_STATUS, || {
        ts_status::from_code(status).map_or(UNKNOWN_STATUS, ts_status::text)
    });
    text.as_ptr().cast()
}
