//! The panic boundary: every export runs its body through [`guard`] or [`guard_value`], so that
//! no Rust panic unwinds into C.

use crate::ffi::error::{set_last_error, FfiResult};
use crate::ffi::status::ts_status;
use std::any::Any;
use std::panic::{catch_unwind, AssertUnwindSafe};

/// The text of a panic payload.
fn panic_message(payload: &(dyn Any + Send)) -> String {
    if let Some(s) = payload.downcast_ref::<&str>() {
        (*s).to_string()
    } else if let Some(s) = payload.downcast_ref::<String>() {
        s.clone()
    } else {
        "non-string panic payload".to_string()
    }
}

/// Drop a panic payload without letting a panicking `Drop` escape.
fn drop_payload(payload: Box<dyn Any + Send>) {
    let _ = catch_unwind(AssertUnwindSafe(move || drop(payload)));
}

/// Run `body`: `Ok` gives `TS_STATUS_OK`; an error stores its message as the thread's last
/// error and returns its status; a panic stores "internal panic: `<message>`" and returns
/// `TS_STATUS_PANIC`.
pub fn guard(body: impl FnOnce() -> FfiResult) -> ts_status {
    match catch_unwind(AssertUnwindSafe(body)) {
        Ok(Ok(())) => ts_status::Ok,
        Ok(Err(failure)) => {
            set_last_error(&failure.message);
            failure.status
        }
        Err(payload) => {
            let msg = panic_message(&*payload);
            drop_payload(payload);
            let _ = catch_unwind(|| set_last_error(&format!("internal panic: {msg}")));
            ts_status::Panic
        }
    }
}

/// Run an infallible `body`, returning `fallback` (and storing the panic message as the last
/// error) if it panics. For exports that return a value rather than a status.
pub fn guard_value<T>(fallback: T, body: impl FnOnce() -> T) -> T {
    match catch_unwind(AssertUnwindSafe(body)) {
        Ok(v) => v,
        Err(payload) => {
            let msg = panic_message(&*payload);
            drop_payload(payload);
            let _ = catch_unwind(|| set_last_error(&format!("internal panic: {msg}")));
            fallback
        }
    }
}
