//! The thread-local last error message and the mapping from the crate's [`Error`] to
//! [`ts_status`].

use crate::error::Error;
use crate::ffi::status::ts_status;
use std::cell::RefCell;
use std::ffi::c_char;

thread_local! {
    static LAST_ERROR: RefCell<String> = const { RefCell::new(String::new()) };
}

/// A failed call: the status to return and the message to store as the thread's last error.
#[derive(Debug, Clone, PartialEq)]
pub struct Failure {
    /// The status returned to C.
    pub status: ts_status,
    /// The message stored for `ts_last_error_message`.
    pub message: String,
}

/// The result type of the bodies of exported functions.
pub type FfiResult<T = ()> = Result<T, Failure>;

/// A failure with `status` and `message`.
pub fn fail(status: ts_status, message: impl Into<String>) -> Failure {
    Failure {
        status,
        message: message.into(),
    }
}

/// The status that corresponds to a crate error.
pub fn status_of(e: &Error) -> ts_status {
    match e {
        Error::Mesh(_) => ts_status::MeshError,
        Error::InvalidArgument(_) => ts_status::InvalidArgument,
        Error::NonFinite(_) => ts_status::NonFinite,
        Error::UnknownBody(_) => ts_status::UnknownBody,
        Error::UnknownTool(_) => ts_status::UnknownTool,
        Error::UnknownRenderSurface(_) => ts_status::UnknownRenderSurface,
        Error::BadState(_) => ts_status::BadState,
        Error::Diverged(_) => ts_status::Diverged,
    }
}

impl From<Error> for Failure {
    fn from(e: Error) -> Self {
        Failure {
            status: status_of(&e),
            message: e.to_string(),
        }
    }
}

impl From<crate::mesh::MeshError> for Failure {
    fn from(e: crate::mesh::MeshError) -> Self {
        Failure::from(Error::Mesh(e))
    }
}

/// Store `message` as this thread's last error.
pub fn set_last_error(message: &str) {
    LAST_ERROR.with(|m| {
        if let Ok(mut m) = m.try_borrow_mut() {
            m.clear();
            m.push_str(message);
        }
    });
}

/// This thread's last error message (empty when none).
pub fn last_error() -> String {
    LAST_ERROR.with(|m| m.try_borrow().map(|m| m.clone()).unwrap_or_default())
}

/// Copy this thread's last error message into `buf` (`len` bytes): at most `len - 1` bytes of
/// the message followed by a NUL, truncated to fit (UTF-8 may be cut mid-character). Returns
/// the length in bytes of the whole message, without the NUL, whatever `len` is (as snprintf
/// does): a return value >= len means the copy was truncated. Writes nothing when buf is NULL
/// or len is 0 (a size query). The message is empty ("") when no call on this thread has
/// failed since the thread started or since ts_last_error_clear. Successful calls leave it
/// unchanged, so read it right after the failing call.
///
/// # Safety
///
/// `buf` is NULL or points to at least `len` writable bytes.
#[no_mangle]
pub unsafe extern "C" fn ts_last_error_message(buf: *mut c_char, len: usize) -> usize {
    crate::ffi::guard::guard_value(0, || {
        LAST_ERROR.with(|m| {
            let Ok(m) = m.try_borrow() else { return 0 };
            let bytes = m.as_bytes();
            if !buf.is_null() && len > 0 {
                let n = bytes.len().min(len - 1);
                // SAFETY: the caller guarantees `len` writable bytes at `buf`; n + 1 <= len.
                unsafe {
                    std::ptr::copy_nonoverlapping(bytes.as_ptr(), buf.cast::<u8>(), n);
                    *buf.add(n) = 0;
                }
            }
            bytes.len()
        })
    })
}

/// Clear this thread's last error message (it becomes "").
#[no_mangle]
pub extern "C" fn ts_last_error_clear() {
    crate::ffi::guard::guard_value((), || set_last_error(""));
}
