//! The FMI 2.0 functions, every common and co-simulation function, generic over the [`Model`]
//! they serve, and the [`export_fmi2!`](crate::export_fmi2) macro that exports them as the
//! `#[no_mangle] extern "C" fn fmi2*` symbols of one model.
//!
//! Each function converts its C arguments (NULL checks, slices, strings), runs behind
//! `catch_unwind` (a panic becomes `fmi2Error`, a log message and the error state), and
//! delegates to [`Instance`]. A library exports exactly one model:
//!
//! ```ignore
//! export_fmi2!(crate::model::MyModel);
//! ```
//!
//! # Safety contract
//!
//! Every function here is `unsafe` for the same reason: it dereferences pointers the FMI master
//! passes, trusting the FMI 2.0 standard's calling contract, which these functions cannot
//! check:
//!
//! * `c` (`fmi2Component`) is NULL or a pointer returned by [`instantiate`] for the same model
//!   `M` and not yet passed to [`free_instance`]; the master does not call two functions of one
//!   instance at the same time (FMI 2.0 §2.1.5), so the instance is borrowed uniquely for the
//!   duration of a call;
//! * an array argument with a count `n > 0` is NULL (refused) or points to `n` valid,
//!   initialised elements (writable ones for outputs) that do not overlap any other argument;
//! * a string argument is NULL or points to a NUL-terminated string alive during the call;
//! * an `fmi2FMUstate` is NULL or a state created by [`get_fmu_state`] or
//!   [`de_serialize_fmu_state`] of this library and not yet freed;
//! * `fmi2CallbackFunctions` points to a valid struct whose logger, when not NULL, is a valid
//!   `fmi2CallbackLogger` for the instance's lifetime.

use super::instance::{check_state_bytes, guid, mask, Instance, Model};
use super::logger::Logger;
use super::types::*;
use super::uri::resource_dir_from_uri;
use super::variables::{BaseType, Value};
use std::ffi::CStr;
use std::os::raw::{c_char, c_int};
use std::panic::{catch_unwind, AssertUnwindSafe};

/// Tag of the memory behind an `fmi2FMUstate` ("FMI2STAT"), to refuse foreign pointers.
const FMU_STATE_TAG: u64 = u64::from_be_bytes(*b"FMI2STAT");

/// The memory behind an `fmi2FMUstate`: a tag (to catch foreign pointers) and the serialised
/// instance state (see [`Instance::save_fmu_state`]).
struct FmuState {
    tag: u64,
    bytes: Vec<u8>,
}

fn panic_message(p: &(dyn std::any::Any + Send)) -> String {
    if let Some(s) = p.downcast_ref::<&str>() {
        (*s).to_string()
    } else if let Some(s) = p.downcast_ref::<String>() {
        s.clone()
    } else {
        "unknown panic".to_string()
    }
}

/// Run `f` on the instance behind `c`, converting a panic into `fmi2Error` + error state.
///
/// # Safety
///
/// `c` is NULL or a live instance of model `M` not borrowed elsewhere (module contract).
unsafe fn guarded<M: Model>(
    c: Fmi2Component,
    func: &'static str,
    f: impl FnOnce(&mut Instance<M>) -> Fmi2Status,
) -> Fmi2Status {
    if c.is_null() {
        return Fmi2Status::Error;
    }
    let ptr = c as *mut Instance<M>;
    // SAFETY: `c` is a non-NULL pointer from `instantiate::<M>` (a leaked
    // `Box<Instance<M>>`), not freed, and no other reference to it exists during this call
    // (the caller's contract); the borrow ends with `f`.
    match catch_unwind(AssertUnwindSafe(|| f(unsafe { &mut *ptr }))) {
        Ok(s) => s,
        Err(p) => {
            let msg = panic_message(&*p);
            let _ = catch_unwind(AssertUnwindSafe(|| {
                // SAFETY: as above; the borrow taken by `f` ended when it unwound.
                let inst = unsafe { &mut *ptr };
                inst.set_error_state();
                inst.log.error(&format!("{func}: internal error: {msg}"));
            }));
            Fmi2Status::Error
        }
    }
}

fn status_of(r: Result<(), Fmi2Status>) -> Fmi2Status {
    match r {
        Ok(()) => Fmi2Status::Ok,
        Err(s) => s,
    }
}

/// A slice from a C array; `None` when the pointer is NULL and `n > 0`.
///
/// # Safety
///
/// A non-NULL `p` with `n > 0` points to `n` initialised `T`s, not written through another
/// pointer while the slice lives.
unsafe fn slice<'a, T>(p: *const T, n: usize) -> Option<&'a [T]> {
    if n == 0 {
        Some(&[])
    } else if p.is_null() {
        None
    } else {
        // SAFETY: non-NULL, `n` initialised elements, not mutated meanwhile (caller).
        Some(unsafe { std::slice::from_raw_parts(p, n) })
    }
}

/// A mutable slice from a C array; `None` when the pointer is NULL and `n > 0`.
///
/// # Safety
///
/// A non-NULL `p` with `n > 0` points to `n` writable `T`s (any bit pattern is overwritten, so
/// `T` must be a plain C type), reached through no other pointer while the slice lives.
unsafe fn slice_mut<'a, T>(p: *mut T, n: usize) -> Option<&'a mut [T]> {
    if n == 0 {
        Some(&mut [])
    } else if p.is_null() {
        None
    } else {
        // SAFETY: non-NULL, `n` writable elements, no other access meanwhile (caller).
        Some(unsafe { std::slice::from_raw_parts_mut(p, n) })
    }
}

/// A UTF-8 string from a C string; `None` when NULL or not UTF-8.
///
/// # Safety
///
/// A non-NULL `p` points to a NUL-terminated string that outlives `'a` unchanged.
unsafe fn string<'a>(p: *const c_char) -> Option<&'a str> {
    if p.is_null() {
        None
    } else {
        // SAFETY: non-NULL and NUL-terminated, alive and unchanged for `'a` (caller).
        unsafe { CStr::from_ptr(p) }.to_str().ok()
    }
}

/// The state behind an `fmi2FMUstate`, if it is one of ours.
///
/// # Safety
///
/// `p` is NULL or a pointer made by [`new_fmu_state`] and not yet freed, reached through no
/// other reference while the result lives.
unsafe fn fmu_state<'a>(p: Fmi2FmuState) -> Option<&'a mut FmuState> {
    // SAFETY: NULL gives None; otherwise a live `Box<FmuState>` from `new_fmu_state` (caller).
    let s = unsafe { (p as *mut FmuState).as_mut() }?;
    (s.tag == FMU_STATE_TAG).then_some(s)
}

fn new_fmu_state(bytes: Vec<u8>) -> Fmi2FmuState {
    Box::into_raw(Box::new(FmuState {
        tag: FMU_STATE_TAG,
        bytes,
    })) as Fmi2FmuState
}

// ---------------------------------------------------------------------------------------------
// Inquire version numbers, logging

/// `fmi2GetTypesPlatform`: "default".
pub fn get_types_platform() -> *const c_char {
    c"default".as_ptr()
}

/// `fmi2GetVersion`: "2.0".
pub fn get_version() -> *const c_char {
    c"2.0".as_ptr()
}

/// `fmi2SetDebugLogging`.
///
/// # Safety
///
/// The FMI calling contract of the [module](self).
pub unsafe fn set_debug_logging<M: Model>(
    c: Fmi2Component,
    logging_on: Fmi2Boolean,
    n_categories: usize,
    categories: *const Fmi2String,
) -> Fmi2Status {
    const F: &str = "fmi2SetDebugLogging";
    let f = |inst: &mut Instance<M>| {
        // SAFETY: `categories` holds `n_categories` strings (module contract).
        let Some(cats) = (unsafe { slice(categories, n_categories) }) else {
            return inst.fail(F, "categories is NULL");
        };
        let mut names = Vec::with_capacity(cats.len());
        for &p in cats {
            // SAFETY: each category is NULL or a NUL-terminated string (module contract).
            match unsafe { string(p) } {
                Some(s) => names.push(s.to_string()),
                None => return inst.fail(F, "a category is NULL or not UTF-8"),
            }
        }
        inst.set_debug_logging(logging_on != FMI2_FALSE, &names)
    };
    // SAFETY: `c` is NULL or a live instance of `M` (module contract).
    unsafe { guarded::<M>(c, F, f) }
}

// ---------------------------------------------------------------------------------------------
// Creation and destruction

/// `fmi2Instantiate`: NULL on failure (reason logged when a logger was given).
///
/// # Safety
///
/// The FMI calling contract of the [module](self): the strings are NULL or NUL-terminated,
/// `functions` is NULL or points to valid callbacks.
pub unsafe fn instantiate<M: Model>(
    instance_name: Fmi2String,
    fmu_type: c_int,
    fmu_guid: Fmi2String,
    fmu_resource_location: Fmi2String,
    functions: *const Fmi2CallbackFunctions,
    _visible: Fmi2Boolean,
    logging_on: Fmi2Boolean,
) -> Fmi2Component {
    let r = catch_unwind(AssertUnwindSafe(|| {
        // SAFETY: NULL or a valid, readable `fmi2CallbackFunctions` (module contract); it is
        // `Copy` and copied out, so the master's struct need not outlive the call.
        let Some(&cb) = (unsafe { functions.as_ref() }) else {
            return std::ptr::null_mut();
        };
        // SAFETY: the strings are NULL or NUL-terminated and alive during the call (module
        // contract); each is copied before returning.
        let (name, fmu_guid, location) = unsafe {
            (
                string(instance_name).unwrap_or(""),
                string(fmu_guid),
                string(fmu_resource_location),
            )
        };
        let log = Logger::new(
            cb.logger,
            cb.component_environment,
            name,
            logging_on != FMI2_FALSE,
        );
        let f = "fmi2Instantiate";
        if name.is_empty() {
            log.error(&format!("{f}: instanceName is NULL, empty or not UTF-8"));
            return std::ptr::null_mut();
        }
        // fmuType is taken as a plain int so that a bad value is not UB.
        let kind = fmu_type;
        if kind != Fmi2Type::CoSimulation as i32 {
            log.error(&format!(
                "{f}: fmuType = {kind}: this FMU supports co-simulation (1) only"
            ));
            return std::ptr::null_mut();
        }
        let expected = guid::<M>();
        match fmu_guid {
            Some(g) if g == expected => {}
            other => {
                log.error(&format!(
                    "{f}: fmuGUID {other:?} does not match the GUID of this binary {expected}"
                ));
                return std::ptr::null_mut();
            }
        }
        let resources = match location {
            None => {
                log.warning(&format!(
                    "{f}: no fmuResourceLocation: relative resource file names cannot be resolved"
                ));
                None
            }
            Some(uri) => match resource_dir_from_uri(uri) {
                Ok(dir) => Some(dir),
                Err(e) => {
                    log.warning(&format!(
                        "{f}: {e}; relative resource file names cannot be resolved"
                    ));
                    None
                }
            },
        };
        let inst = Box::new(Instance::<M>::new(log, resources));
        inst.log_call(|| {
            format!(
                "{f}(instanceName=\"{name}\", resources={:?}, loggingOn={logging_on})",
                inst.resources()
            )
        });
        Box::into_raw(inst) as Fmi2Component
    }));
    r.unwrap_or(std::ptr::null_mut())
}

/// `fmi2FreeInstance`: NULL is a no-op.
///
/// # Safety
///
/// The FMI calling contract of the [module](self); `c` is not used again.
pub unsafe fn free_instance<M: Model>(c: Fmi2Component) {
    if c.is_null() {
        return;
    }
    let _ = catch_unwind(AssertUnwindSafe(|| {
        // SAFETY: `c` is a non-NULL `Box<Instance<M>>` leaked by `instantiate::<M>`, not yet
        // freed and not used again by the master (module contract): ownership comes back.
        let inst = unsafe { Box::from_raw(c as *mut Instance<M>) };
        inst.log_call(|| "fmi2FreeInstance()".into());
        drop(inst);
    }));
}

// ---------------------------------------------------------------------------------------------
// Initialisation, termination, reset

/// `fmi2SetupExperiment`.
///
/// # Safety
///
/// The FMI calling contract of the [module](self).
pub unsafe fn setup_experiment<M: Model>(
    c: Fmi2Component,
    _tolerance_defined: Fmi2Boolean,
    _tolerance: Fmi2Real,
    start_time: Fmi2Real,
    stop_time_defined: Fmi2Boolean,
    stop_time: Fmi2Real,
) -> Fmi2Status {
    let f = |inst: &mut Instance<M>| {
        inst.log_call(|| {
            format!("fmi2SetupExperiment(startTime={start_time}, stopTimeDefined={stop_time_defined}, stopTime={stop_time})")
        });
        let stop = (stop_time_defined != FMI2_FALSE).then_some(stop_time);
        status_of(inst.setup_experiment(start_time, stop))
    };
    // SAFETY: `c` is NULL or a live instance of `M` (module contract).
    unsafe { guarded::<M>(c, "fmi2SetupExperiment", f) }
}

/// `fmi2EnterInitializationMode`.
///
/// # Safety
///
/// The FMI calling contract of the [module](self).
pub unsafe fn enter_initialization_mode<M: Model>(c: Fmi2Component) -> Fmi2Status {
    let f = |inst: &mut Instance<M>| {
        inst.log_call(|| "fmi2EnterInitializationMode()".into());
        status_of(inst.enter_initialization_mode())
    };
    // SAFETY: `c` is NULL or a live instance of `M` (module contract).
    unsafe { guarded::<M>(c, "fmi2EnterInitializationMode", f) }
}

/// `fmi2ExitInitializationMode`: the model builds its simulation from the parameters.
///
/// # Safety
///
/// The FMI calling contract of the [module](self).
pub unsafe fn exit_initialization_mode<M: Model>(c: Fmi2Component) -> Fmi2Status {
    let f = |inst: &mut Instance<M>| {
        inst.log_call(|| "fmi2ExitInitializationMode()".into());
        status_of(inst.exit_initialization_mode())
    };
    // SAFETY: `c` is NULL or a live instance of `M` (module contract).
    unsafe { guarded::<M>(c, "fmi2ExitInitializationMode", f) }
}

/// `fmi2Terminate`.
///
/// # Safety
///
/// The FMI calling contract of the [module](self).
pub unsafe fn terminate<M: Model>(c: Fmi2Component) -> Fmi2Status {
    let f = |inst: &mut Instance<M>| {
        inst.log_call(|| "fmi2Terminate()".into());
        status_of(inst.terminate())
    };
    // SAFETY: `c` is NULL or a live instance of `M` (module contract).
    unsafe { guarded::<M>(c, "fmi2Terminate", f) }
}

/// `fmi2Reset`.
///
/// # Safety
///
/// The FMI calling contract of the [module](self).
pub unsafe fn reset<M: Model>(c: Fmi2Component) -> Fmi2Status {
    let f = |inst: &mut Instance<M>| {
        inst.log_call(|| "fmi2Reset()".into());
        status_of(inst.reset())
    };
    // SAFETY: `c` is NULL or a live instance of `M` (module contract).
    unsafe { guarded::<M>(c, "fmi2Reset", f) }
}

// ---------------------------------------------------------------------------------------------
// Getting and setting variable values

/// `fmi2Get{Real,Integer,Boolean}`: the values of `vr[..nvr]` into `value[..nvr]`.
///
/// # Safety
///
/// The FMI calling contract of the [module](self); `T` is a plain C type.
pub unsafe fn get_values<M: Model, T>(
    c: Fmi2Component,
    func: &'static str,
    ty: BaseType,
    vr: *const Fmi2ValueReference,
    nvr: usize,
    value: *mut T,
    convert: impl Fn(&Value) -> T,
) -> Fmi2Status {
    let f = |inst: &mut Instance<M>| {
        // SAFETY: `vr` holds `nvr` references and `value` room for `nvr` values, not
        // overlapping (module contract).
        let (Some(vrs), Some(out)) = (unsafe { slice(vr, nvr) }, unsafe { slice_mut(value, nvr) })
        else {
            return inst.fail(func, "vr or value is NULL");
        };
        if let Err(s) = inst.prepare_get(func, ty, vrs) {
            return s;
        }
        for (o, &r) in out.iter_mut().zip(vrs) {
            *o = convert(inst.store().get(r));
        }
        Fmi2Status::Ok
    };
    // SAFETY: `c` is NULL or a live instance of `M` (module contract).
    unsafe { guarded::<M>(c, func, f) }
}

/// `fmi2Set{Real,Integer,Boolean,String}`: `value[..nvr]` into `vr[..nvr]`, all or nothing.
///
/// # Safety
///
/// The FMI calling contract of the [module](self); `convert` only reads what `T` points to
/// within that contract.
pub unsafe fn set_values<M: Model, T: Copy>(
    c: Fmi2Component,
    func: &'static str,
    ty: BaseType,
    vr: *const Fmi2ValueReference,
    nvr: usize,
    value: *const T,
    convert: impl Fn(T) -> Option<Value>,
) -> Fmi2Status {
    let f = |inst: &mut Instance<M>| {
        // SAFETY: `vr` and `value` each hold `nvr` elements (module contract).
        let (Some(vrs), Some(vals)) = (unsafe { slice(vr, nvr) }, unsafe { slice(value, nvr) })
        else {
            return inst.fail(func, "vr or value is NULL");
        };
        let mut values = Vec::with_capacity(nvr);
        for &v in vals {
            match convert(v) {
                Some(v) => values.push(v),
                None => return inst.fail(func, "a value is NULL or not UTF-8"),
            }
        }
        inst.set(func, ty, vrs, values)
    };
    // SAFETY: `c` is NULL or a live instance of `M` (module contract).
    unsafe { guarded::<M>(c, func, f) }
}

/// `fmi2GetReal`.
///
/// # Safety
///
/// The FMI calling contract of the [module](self).
pub unsafe fn get_real<M: Model>(
    c: Fmi2Component,
    vr: *const Fmi2ValueReference,
    nvr: usize,
    value: *mut Fmi2Real,
) -> Fmi2Status {
    // SAFETY: forwarded under the same contract; `f64` is a plain C type.
    unsafe {
        get_values::<M, _>(
            c,
            "fmi2GetReal",
            BaseType::Real,
            vr,
            nvr,
            value,
            |v| match v {
                Value::Real(x) => *x,
                _ => f64::NAN,
            },
        )
    }
}

/// `fmi2GetInteger` (Integer and Enumeration variables).
///
/// # Safety
///
/// The FMI calling contract of the [module](self).
pub unsafe fn get_integer<M: Model>(
    c: Fmi2Component,
    vr: *const Fmi2ValueReference,
    nvr: usize,
    value: *mut Fmi2Integer,
) -> Fmi2Status {
    // SAFETY: forwarded under the same contract; `c_int` is a plain C type.
    unsafe {
        get_values::<M, _>(
            c,
            "fmi2GetInteger",
            BaseType::Integer,
            vr,
            nvr,
            value,
            |v| match v {
                Value::Integer(x) => *x,
                _ => 0,
            },
        )
    }
}

/// `fmi2GetBoolean`.
///
/// # Safety
///
/// The FMI calling contract of the [module](self).
pub unsafe fn get_boolean<M: Model>(
    c: Fmi2Component,
    vr: *const Fmi2ValueReference,
    nvr: usize,
    value: *mut Fmi2Boolean,
) -> Fmi2Status {
    // SAFETY: forwarded under the same contract; `c_int` is a plain C type.
    unsafe {
        get_values::<M, _>(
            c,
            "fmi2GetBoolean",
            BaseType::Boolean,
            vr,
            nvr,
            value,
            |v| match v {
                Value::Boolean(true) => FMI2_TRUE,
                _ => FMI2_FALSE,
            },
        )
    }
}

/// `fmi2GetString`: the returned pointers stay valid until the next `fmi2GetString` call on
/// this instance (or its release).
///
/// # Safety
///
/// The FMI calling contract of the [module](self).
pub unsafe fn get_string<M: Model>(
    c: Fmi2Component,
    vr: *const Fmi2ValueReference,
    nvr: usize,
    value: *mut Fmi2String,
) -> Fmi2Status {
    const F: &str = "fmi2GetString";
    let f = |inst: &mut Instance<M>| {
        // SAFETY: `vr` holds `nvr` references and `value` room for `nvr` pointers, not
        // overlapping (module contract).
        let (Some(vrs), Some(out)) = (unsafe { slice(vr, nvr) }, unsafe { slice_mut(value, nvr) })
        else {
            return inst.fail(F, "vr or value is NULL");
        };
        match inst.get_strings(vrs) {
            Ok(strings) => {
                for (o, s) in out.iter_mut().zip(strings) {
                    *o = s.as_ptr();
                }
                Fmi2Status::Ok
            }
            Err(s) => s,
        }
    };
    // SAFETY: `c` is NULL or a live instance of `M` (module contract).
    unsafe { guarded::<M>(c, F, f) }
}

/// `fmi2SetReal`: NaN/Inf and out-of-range values are refused (nothing set).
///
/// # Safety
///
/// The FMI calling contract of the [module](self).
pub unsafe fn set_real<M: Model>(
    c: Fmi2Component,
    vr: *const Fmi2ValueReference,
    nvr: usize,
    value: *const Fmi2Real,
) -> Fmi2Status {
    // SAFETY: forwarded under the same contract.
    unsafe {
        set_values::<M, _>(c, "fmi2SetReal", BaseType::Real, vr, nvr, value, |v| {
            Some(Value::Real(v))
        })
    }
}

/// `fmi2SetInteger`.
///
/// # Safety
///
/// The FMI calling contract of the [module](self).
pub unsafe fn set_integer<M: Model>(
    c: Fmi2Component,
    vr: *const Fmi2ValueReference,
    nvr: usize,
    value: *const Fmi2Integer,
) -> Fmi2Status {
    // SAFETY: forwarded under the same contract.
    unsafe {
        set_values::<M, _>(
            c,
            "fmi2SetInteger",
            BaseType::Integer,
            vr,
            nvr,
            value,
            |v| Some(Value::Integer(v)),
        )
    }
}

/// `fmi2SetBoolean`.
///
/// # Safety
///
/// The FMI calling contract of the [module](self).
pub unsafe fn set_boolean<M: Model>(
    c: Fmi2Component,
    vr: *const Fmi2ValueReference,
    nvr: usize,
    value: *const Fmi2Boolean,
) -> Fmi2Status {
    // SAFETY: forwarded under the same contract.
    unsafe {
        set_values::<M, _>(
            c,
            "fmi2SetBoolean",
            BaseType::Boolean,
            vr,
            nvr,
            value,
            |v| Some(Value::Boolean(v != FMI2_FALSE)),
        )
    }
}

/// `fmi2SetString`.
///
/// # Safety
///
/// The FMI calling contract of the [module](self).
pub unsafe fn set_string<M: Model>(
    c: Fmi2Component,
    vr: *const Fmi2ValueReference,
    nvr: usize,
    value: *const Fmi2String,
) -> Fmi2Status {
    let convert = |v: Fmi2String| {
        // SAFETY: each value is NULL or a NUL-terminated string alive during the call (module
        // contract); it is copied into an owned `String` at once.
        unsafe { string(v) }.map(|s| Value::String(s.to_string()))
    };
    // SAFETY: forwarded under the same contract.
    unsafe {
        set_values::<M, _>(
            c,
            "fmi2SetString",
            BaseType::String,
            vr,
            nvr,
            value,
            convert,
        )
    }
}

// ---------------------------------------------------------------------------------------------
// FMU states

/// `fmi2GetFMUstate`: allocates a state when `*state` is NULL, overwrites it otherwise.
///
/// # Safety
///
/// The FMI calling contract of the [module](self).
pub unsafe fn get_fmu_state<M: Model>(c: Fmi2Component, state: *mut Fmi2FmuState) -> Fmi2Status {
    const F: &str = "fmi2GetFMUstate";
    let f = |inst: &mut Instance<M>| {
        // SAFETY: `state` is NULL or points to a writable `fmi2FMUstate` (module contract).
        let Some(slot) = (unsafe { state.as_mut() }) else {
            return inst.fail(F, "FMUstate is NULL");
        };
        let mut bytes = Vec::new();
        if let Err(s) = inst.save_fmu_state(&mut bytes) {
            return s;
        }
        if slot.is_null() {
            *slot = new_fmu_state(bytes);
        } else {
            // SAFETY: a non-NULL `*state` is a live state of this library (module contract).
            match unsafe { fmu_state(*slot) } {
                Some(s) => s.bytes = bytes,
                None => return inst.fail(F, "*FMUstate is not a state of this FMU"),
            }
        }
        inst.log_call(|| format!("{F}() -> {:?}", *slot));
        Fmi2Status::Ok
    };
    // SAFETY: `c` is NULL or a live instance of `M` (module contract).
    unsafe { guarded::<M>(c, F, f) }
}

/// `fmi2SetFMUstate`: everything is checked (checksum included) before anything changes.
///
/// # Safety
///
/// The FMI calling contract of the [module](self).
pub unsafe fn set_fmu_state<M: Model>(c: Fmi2Component, state: Fmi2FmuState) -> Fmi2Status {
    const F: &str = "fmi2SetFMUstate";
    let f = |inst: &mut Instance<M>| {
        inst.log_call(|| format!("{F}({state:?})"));
        // SAFETY: `state` is NULL or a live state of this library (module contract).
        match unsafe { fmu_state(state) } {
            Some(s) => status_of(inst.restore_fmu_state(&s.bytes)),
            None => inst.fail(F, "FMUstate is NULL or not a state of this FMU"),
        }
    };
    // SAFETY: `c` is NULL or a live instance of `M` (module contract).
    unsafe { guarded::<M>(c, F, f) }
}

/// `fmi2FreeFMUstate`: frees `*state` and sets it to NULL; a NULL `*state` is a no-op.
///
/// # Safety
///
/// The FMI calling contract of the [module](self); `*state` is not used again.
pub unsafe fn free_fmu_state<M: Model>(c: Fmi2Component, state: *mut Fmi2FmuState) -> Fmi2Status {
    const F: &str = "fmi2FreeFMUstate";
    let f = |inst: &mut Instance<M>| {
        // SAFETY: `state` is NULL or points to a writable `fmi2FMUstate` (module contract).
        let Some(slot) = (unsafe { state.as_mut() }) else {
            return inst.fail(F, "FMUstate is NULL");
        };
        if slot.is_null() {
            return Fmi2Status::Ok;
        }
        // SAFETY: a non-NULL `*state` is a live state of this library (module contract).
        if unsafe { fmu_state(*slot) }.is_none() {
            return inst.fail(F, "*FMUstate is not a state of this FMU");
        }
        // SAFETY: `*slot` is a `Box<FmuState>` leaked by `new_fmu_state` (tag checked just
        // above), not yet freed; the master does not use it again, and the slot is cleared.
        let mut s = unsafe { Box::from_raw(*slot as *mut FmuState) };
        s.tag = 0;
        drop(s);
        *slot = std::ptr::null_mut();
        Fmi2Status::Ok
    };
    // SAFETY: `c` is NULL or a live instance of `M` (module contract).
    unsafe { guarded::<M>(c, F, f) }
}

/// `fmi2SerializedFMUstateSize`.
///
/// # Safety
///
/// The FMI calling contract of the [module](self).
pub unsafe fn serialized_fmu_state_size<M: Model>(
    c: Fmi2Component,
    state: Fmi2FmuState,
    size: *mut usize,
) -> Fmi2Status {
    const F: &str = "fmi2SerializedFMUstateSize";
    let f = |inst: &mut Instance<M>| {
        if let Err(s) = inst.check_state(F, mask::SET_STATE) {
            return s;
        }
        // SAFETY: `state` is NULL or a live state of this library, `size` NULL or
        // writable (module contract).
        match unsafe { (fmu_state(state), size.as_mut()) } {
            (Some(s), Some(out)) => {
                *out = s.bytes.len();
                Fmi2Status::Ok
            }
            _ => inst.fail(F, "FMUstate or size is NULL (or not a state of this FMU)"),
        }
    };
    // SAFETY: `c` is NULL or a live instance of `M` (module contract).
    unsafe { guarded::<M>(c, F, f) }
}

/// `fmi2SerializeFMUstate`: copies the versioned, checksummed state bytes into the caller's
/// buffer.
///
/// # Safety
///
/// The FMI calling contract of the [module](self): `serialized_state` holds `size` writable
/// bytes.
pub unsafe fn serialize_fmu_state<M: Model>(
    c: Fmi2Component,
    state: Fmi2FmuState,
    serialized_state: *mut Fmi2Byte,
    size: usize,
) -> Fmi2Status {
    const F: &str = "fmi2SerializeFMUstate";
    let f = |inst: &mut Instance<M>| {
        if let Err(s) = inst.check_state(F, mask::SET_STATE) {
            return s;
        }
        // SAFETY: `state` is NULL or a live state of this library (module contract).
        let Some(s) = (unsafe { fmu_state(state) }) else {
            return inst.fail(F, "FMUstate is NULL or not a state of this FMU");
        };
        if size < s.bytes.len() {
            return inst.fail(
                F,
                &format!("buffer of {size} bytes too small, {} needed", s.bytes.len()),
            );
        }
        // SAFETY: the buffer holds `size >= s.bytes.len()` writable bytes (module
        // contract); `c_char` and `u8` have the same layout.
        let Some(out) = (unsafe { slice_mut(serialized_state as *mut u8, s.bytes.len()) }) else {
            return inst.fail(F, "serializedState is NULL");
        };
        out.copy_from_slice(&s.bytes);
        Fmi2Status::Ok
    };
    // SAFETY: `c` is NULL or a live instance of `M` (module contract).
    unsafe { guarded::<M>(c, F, f) }
}

/// `fmi2DeSerializeFMUstate`: checks the whole byte string (magic, version, checksum over
/// every byte, GUID, variable section) and creates a state (or overwrites `*state` when it is
/// not NULL). Corrupt bytes give `fmi2Error` with a log message; `*state` is then unchanged.
///
/// # Safety
///
/// The FMI calling contract of the [module](self): `serialized_state` holds `size` bytes.
pub unsafe fn de_serialize_fmu_state<M: Model>(
    c: Fmi2Component,
    serialized_state: *const Fmi2Byte,
    size: usize,
    state: *mut Fmi2FmuState,
) -> Fmi2Status {
    const F: &str = "fmi2DeSerializeFMUstate";
    let f = |inst: &mut Instance<M>| {
        if let Err(s) = inst.check_state(F, mask::SET_STATE) {
            return s;
        }
        // SAFETY: the buffer holds `size` readable bytes (`c_char` has the layout of `u8`)
        // and `state` is NULL or a writable `fmi2FMUstate` (module contract).
        let (Some(bytes), Some(slot)) = (
            unsafe { slice(serialized_state as *const u8, size) },
            unsafe { state.as_mut() },
        ) else {
            return inst.fail(F, "serializedState or FMUstate is NULL");
        };
        if let Err(e) = check_state_bytes::<M>(bytes) {
            return inst.fail(F, &e);
        }
        if slot.is_null() {
            *slot = new_fmu_state(bytes.to_vec());
        } else {
            // SAFETY: a non-NULL `*state` is a live state of this library (module contract).
            match unsafe { fmu_state(*slot) } {
                Some(s) => s.bytes = bytes.to_vec(),
                None => return inst.fail(F, "*FMUstate is not a state of this FMU"),
            }
        }
        Fmi2Status::Ok
    };
    // SAFETY: `c` is NULL or a live instance of `M` (module contract).
    unsafe { guarded::<M>(c, F, f) }
}

// ---------------------------------------------------------------------------------------------
// Derivatives (not supported)

/// `fmi2GetDirectionalDerivative`: not supported (`providesDirectionalDerivative="false"`).
///
/// # Safety
///
/// The FMI calling contract of the [module](self) (only `c` is read).
pub unsafe fn get_directional_derivative<M: Model>(c: Fmi2Component) -> Fmi2Status {
    const F: &str = "fmi2GetDirectionalDerivative";
    let f = |inst: &mut Instance<M>| {
        if let Err(s) = inst.check_state(F, mask::DIRECTIONAL) {
            return s;
        }
        inst.fail(F, "directional derivatives are not supported")
    };
    // SAFETY: `c` is NULL or a live instance of `M` (module contract).
    unsafe { guarded::<M>(c, F, f) }
}

/// `fmi2SetRealInputDerivatives`: not supported (`canInterpolateInputs="false"`).
///
/// # Safety
///
/// The FMI calling contract of the [module](self) (only `c` is read).
pub unsafe fn set_real_input_derivatives<M: Model>(c: Fmi2Component) -> Fmi2Status {
    const F: &str = "fmi2SetRealInputDerivatives";
    let f = |inst: &mut Instance<M>| {
        if let Err(s) = inst.check_state(F, mask::INPUT_DERIVATIVES) {
            return s;
        }
        inst.fail(
            F,
            "input derivatives are not supported (canInterpolateInputs=false)",
        )
    };
    // SAFETY: `c` is NULL or a live instance of `M` (module contract).
    unsafe { guarded::<M>(c, F, f) }
}

/// `fmi2GetRealOutputDerivatives`: not supported (`maxOutputDerivativeOrder="0"`).
///
/// # Safety
///
/// The FMI calling contract of the [module](self) (only `c` is read).
pub unsafe fn get_real_output_derivatives<M: Model>(c: Fmi2Component) -> Fmi2Status {
    const F: &str = "fmi2GetRealOutputDerivatives";
    let f = |inst: &mut Instance<M>| {
        if let Err(s) = inst.check_state(F, mask::OUTPUT_DERIVATIVES) {
            return s;
        }
        inst.fail(
            F,
            "output derivatives are not supported (maxOutputDerivativeOrder=0)",
        )
    };
    // SAFETY: `c` is NULL or a live instance of `M` (module contract).
    unsafe { guarded::<M>(c, F, f) }
}

// ---------------------------------------------------------------------------------------------
// Stepping and status

/// `fmi2DoStep`: synchronous; [`Model::do_step`] from the current communication point.
/// Returns `fmi2Discard` (nothing changed, time not advanced) when the model discards the step.
///
/// # Safety
///
/// The FMI calling contract of the [module](self).
pub unsafe fn do_step<M: Model>(
    c: Fmi2Component,
    current_communication_point: Fmi2Real,
    communication_step_size: Fmi2Real,
) -> Fmi2Status {
    let f =
        |inst: &mut Instance<M>| inst.do_step(current_communication_point, communication_step_size);
    // SAFETY: `c` is NULL or a live instance of `M` (module contract).
    unsafe { guarded::<M>(c, "fmi2DoStep", f) }
}

/// `fmi2CancelStep`: steps are synchronous, so there is never a step to cancel (fmi2Error).
///
/// # Safety
///
/// The FMI calling contract of the [module](self).
pub unsafe fn cancel_step<M: Model>(c: Fmi2Component) -> Fmi2Status {
    const F: &str = "fmi2CancelStep";
    let f = |inst: &mut Instance<M>| {
        if let Err(s) = inst.check_state(F, mask::STEP) {
            return s;
        }
        inst.fail(
            F,
            "no asynchronous step is pending (fmi2DoStep never returns fmi2Pending)",
        )
    };
    // SAFETY: `c` is NULL or a live instance of `M` (module contract).
    unsafe { guarded::<M>(c, F, f) }
}

/// `fmi2Get*Status`: `answer` gives the value, or `None` for fmi2Discard.
///
/// # Safety
///
/// The FMI calling contract of the [module](self): `value` is NULL or writable.
pub unsafe fn status_query<M: Model, T>(
    c: Fmi2Component,
    func: &'static str,
    value: *mut T,
    answer: impl FnOnce(&Instance<M>) -> Option<T>,
) -> Fmi2Status {
    let f = |inst: &mut Instance<M>| {
        if let Err(s) = inst.check_state(func, mask::STATUS) {
            return s;
        }
        // SAFETY: `value` is NULL or points to a writable `T` (module contract).
        let Some(out) = (unsafe { value.as_mut() }) else {
            return inst.fail(func, "value is NULL");
        };
        match answer(inst) {
            Some(v) => {
                *out = v;
                Fmi2Status::Ok
            }
            None => {
                inst.log.status(
                    Fmi2Status::Discard,
                    &format!("{func}: this status kind is not available (steps are synchronous)"),
                );
                Fmi2Status::Discard
            }
        }
    };
    // SAFETY: `c` is NULL or a live instance of `M` (module contract).
    unsafe { guarded::<M>(c, func, f) }
}

/// Export the FMI 2.0 co-simulation functions (`#[no_mangle] extern "C" fn fmi2*`) for one
/// model type implementing [`Model`]. Invoke it once, in the crate that builds the `cdylib`:
///
/// ```ignore
/// export_fmi2!(crate::model::MyModel);
/// ```
///
/// Every function forwards to the generic one of [`crate::fmi2::exports`] with the same name in
/// snake case; they share that module's safety contract, which the FMI master upholds.
#[macro_export]
macro_rules! export_fmi2 {
    ($model:ty) => {
        #[doc(hidden)]
        type __Fmi2ExportedModel = $model;

        /// The exported FMI 2.0 functions of the model (see `fmi2::exports`).
        #[allow(non_snake_case)]
        pub mod fmi2_exports {
            use std::os::raw::{c_char, c_int};
            use $crate::fmi2::exports as x;
            use $crate::fmi2::types::*;
            type M = super::__Fmi2ExportedModel;

            /// `fmi2GetTypesPlatform`: "default".
            #[no_mangle]
            pub extern "C" fn fmi2GetTypesPlatform() -> *const c_char {
                x::get_types_platform()
            }

            /// `fmi2GetVersion`: "2.0".
            #[no_mangle]
            pub extern "C" fn fmi2GetVersion() -> *const c_char {
                x::get_version()
            }

            /// `fmi2SetDebugLogging`.
            ///
            /// # Safety
            ///
            /// The FMI 2.0 calling contract of `fmi2::exports`: the master passes live instances,
            /// valid arrays and strings, and states of this FMU.
            #[no_mangle]
            pub unsafe extern "C" fn fmi2SetDebugLogging(
                c: Fmi2Component,
                logging_on: Fmi2Boolean,
                n: usize,
                categories: *const Fmi2String,
            ) -> Fmi2Status {
                // SAFETY: the master upholds the FMI calling contract of `exports`.
                unsafe { x::set_debug_logging::<M>(c, logging_on, n, categories) }
            }

            /// `fmi2Instantiate`.
            ///
            /// # Safety
            ///
            /// The FMI 2.0 calling contract of `fmi2::exports`: the master passes live instances,
            /// valid arrays and strings, and states of this FMU.
            #[no_mangle]
            pub unsafe extern "C" fn fmi2Instantiate(
                instance_name: Fmi2String,
                fmu_type: c_int,
                fmu_guid: Fmi2String,
                fmu_resource_location: Fmi2String,
                functions: *const Fmi2CallbackFunctions,
                visible: Fmi2Boolean,
                logging_on: Fmi2Boolean,
            ) -> Fmi2Component {
                // SAFETY: the master upholds the FMI calling contract of `exports`.
                unsafe {
                    x::instantiate::<M>(
                        instance_name,
                        fmu_type,
                        fmu_guid,
                        fmu_resource_location,
                        functions,
                        visible,
                        logging_on,
                    )
                }
            }

            /// `fmi2FreeInstance`.
            ///
            /// # Safety
            ///
            /// The FMI 2.0 calling contract of `fmi2::exports`: the master passes live instances,
            /// valid arrays and strings, and states of this FMU.
            #[no_mangle]
            pub unsafe extern "C" fn fmi2FreeInstance(c: Fmi2Component) {
                // SAFETY: the master upholds the FMI calling contract of `exports`.
                unsafe { x::free_instance::<M>(c) }
            }

            /// `fmi2SetupExperiment`.
            ///
            /// # Safety
            ///
            /// The FMI 2.0 calling contract of `fmi2::exports`: the master passes live instances,
            /// valid arrays and strings, and states of this FMU.
            #[no_mangle]
            pub unsafe extern "C" fn fmi2SetupExperiment(
                c: Fmi2Component,
                tolerance_defined: Fmi2Boolean,
                tolerance: Fmi2Real,
                start_time: Fmi2Real,
                stop_time_defined: Fmi2Boolean,
                stop_time: Fmi2Real,
            ) -> Fmi2Status {
                // SAFETY: the master upholds the FMI calling contract of `exports`.
                unsafe {
                    x::setup_experiment::<M>(
                        c,
                        tolerance_defined,
                        tolerance,
                        start_time,
                        stop_time_defined,
                        stop_time,
                    )
                }
            }

            /// `fmi2EnterInitializationMode`.
            ///
            /// # Safety
            ///
            /// The FMI 2.0 calling contract of `fmi2::exports`: the master passes live instances,
            /// valid arrays and strings, and states of this FMU.
            #[no_mangle]
            pub unsafe extern "C" fn fmi2EnterInitializationMode(c: Fmi2Component) -> Fmi2Status {
                // SAFETY: the master upholds the FMI calling contract of `exports`.
                unsafe { x::enter_initialization_mode::<M>(c) }
            }

            /// `fmi2ExitInitializationMode`.
            ///
            /// # Safety
            ///
            /// The FMI 2.0 calling contract of `fmi2::exports`: the master passes live instances,
            /// valid arrays and strings, and states of this FMU.
            #[no_mangle]
            pub unsafe extern "C" fn fmi2ExitInitializationMode(c: Fmi2Component) -> Fmi2Status {
                // SAFETY: the master upholds the FMI calling contract of `exports`.
                unsafe { x::exit_initialization_mode::<M>(c) }
            }

            /// `fmi2Terminate`.
            ///
            /// # Safety
            ///
            /// The FMI 2.0 calling contract of `fmi2::exports`: the master passes live instances,
            /// valid arrays and strings, and states of this FMU.
            #[no_mangle]
            pub unsafe extern "C" fn fmi2Terminate(c: Fmi2Component) -> Fmi2Status {
                // SAFETY: the master upholds the FMI calling contract of `exports`.
                unsafe { x::terminate::<M>(c) }
            }

            /// `fmi2Reset`.
            ///
            /// # Safety
            ///
            /// The FMI 2.0 calling contract of `fmi2::exports`: the master passes live instances,
            /// valid arrays and strings, and states of this FMU.
            #[no_mangle]
            pub unsafe extern "C" fn fmi2Reset(c: Fmi2Component) -> Fmi2Status {
                // SAFETY: the master upholds the FMI calling contract of `exports`.
                unsafe { x::reset::<M>(c) }
            }

            /// `fmi2GetReal`.
            ///
            /// # Safety
            ///
            /// The FMI 2.0 calling contract of `fmi2::exports`: the master passes live instances,
            /// valid arrays and strings, and states of this FMU.
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetReal(
                c: Fmi2Component,
                vr: *const Fmi2ValueReference,
                nvr: usize,
                value: *mut Fmi2Real,
            ) -> Fmi2Status {
                // SAFETY: the master upholds the FMI calling contract of `exports`.
                unsafe { x::get_real::<M>(c, vr, nvr, value) }
            }

            /// `fmi2GetInteger`.
            ///
            /// # Safety
            ///
            /// The FMI 2.0 calling contract of `fmi2::exports`: the master passes live instances,
            /// valid arrays and strings, and states of this FMU.
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetInteger(
                c: Fmi2Component,
                vr: *const Fmi2ValueReference,
                nvr: usize,
                value: *mut Fmi2Integer,
            ) -> Fmi2Status {
                // SAFETY: the master upholds the FMI calling contract of `exports`.
                unsafe { x::get_integer::<M>(c, vr, nvr, value) }
            }

            /// `fmi2GetBoolean`.
            ///
            /// # Safety
            ///
            /// The FMI 2.0 calling contract of `fmi2::exports`: the master passes live instances,
            /// valid arrays and strings, and states of this FMU.
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetBoolean(
                c: Fmi2Component,
                vr: *const Fmi2ValueReference,
                nvr: usize,
                value: *mut Fmi2Boolean,
            ) -> Fmi2Status {
                // SAFETY: the master upholds the FMI calling contract of `exports`.
                unsafe { x::get_boolean::<M>(c, vr, nvr, value) }
            }

            /// `fmi2GetString`.
            ///
            /// # Safety
            ///
            /// The FMI 2.0 calling contract of `fmi2::exports`: the master passes live instances,
            /// valid arrays and strings, and states of this FMU.
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetString(
                c: Fmi2Component,
                vr: *const Fmi2ValueReference,
                nvr: usize,
                value: *mut Fmi2String,
            ) -> Fmi2Status {
                // SAFETY: the master upholds the FMI calling contract of `exports`.
                unsafe { x::get_string::<M>(c, vr, nvr, value) }
            }

            /// `fmi2SetReal`.
            ///
            /// # Safety
            ///
            /// The FMI 2.0 calling contract of `fmi2::exports`: the master passes live instances,
            /// valid arrays and strings, and states of this FMU.
            #[no_mangle]
            pub unsafe extern "C" fn fmi2SetReal(
                c: Fmi2Component,
                vr: *const Fmi2ValueReference,
                nvr: usize,
                value: *const Fmi2Real,
            ) -> Fmi2Status {
                // SAFETY: the master upholds the FMI calling contract of `exports`.
                unsafe { x::set_real::<M>(c, vr, nvr, value) }
            }

            /// `fmi2SetInteger`.
            ///
            /// # Safety
            ///
            /// The FMI 2.0 calling contract of `fmi2::exports`: the master passes live instances,
            /// valid arrays and strings, and states of this FMU.
            #[no_mangle]
            pub unsafe extern "C" fn fmi2SetInteger(
                c: Fmi2Component,
                vr: *const Fmi2ValueReference,
                nvr: usize,
                value: *const Fmi2Integer,
            ) -> Fmi2Status {
                // SAFETY: the master upholds the FMI calling contract of `exports`.
                unsafe { x::set_integer::<M>(c, vr, nvr, value) }
            }

            /// `fmi2SetBoolean`.
            ///
            /// # Safety
            ///
            /// The FMI 2.0 calling contract of `fmi2::exports`: the master passes live instances,
            /// valid arrays and strings, and states of this FMU.
            #[no_mangle]
            pub unsafe extern "C" fn fmi2SetBoolean(
                c: Fmi2Component,
                vr: *const Fmi2ValueReference,
                nvr: usize,
                value: *const Fmi2Boolean,
            ) -> Fmi2Status {
                // SAFETY: the master upholds the FMI calling contract of `exports`.
                unsafe { x::set_boolean::<M>(c, vr, nvr, value) }
            }

            /// `fmi2SetString`.
            ///
            /// # Safety
            ///
            /// The FMI 2.0 calling contract of `fmi2::exports`: the master passes live instances,
            /// valid arrays and strings, and states of this FMU.
            #[no_mangle]
            pub unsafe extern "C" fn fmi2SetString(
                c: Fmi2Component,
                vr: *const Fmi2ValueReference,
                nvr: usize,
                value: *const Fmi2String,
            ) -> Fmi2Status {
                // SAFETY: the master upholds the FMI calling contract of `exports`.
                unsafe { x::set_string::<M>(c, vr, nvr, value) }
            }

            /// `fmi2GetFMUstate`.
            ///
            /// # Safety
            ///
            /// The FMI 2.0 calling contract of `fmi2::exports`: the master passes live instances,
            /// valid arrays and strings, and states of this FMU.
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetFMUstate(
                c: Fmi2Component,
                state: *mut Fmi2FmuState,
            ) -> Fmi2Status {
                // SAFETY: the master upholds the FMI calling contract of `exports`.
                unsafe { x::get_fmu_state::<M>(c, state) }
            }

            /// `fmi2SetFMUstate`.
            ///
            /// # Safety
            ///
            /// The FMI 2.0 calling contract of `fmi2::exports`: the master passes live instances,
            /// valid arrays and strings, and states of this FMU.
            #[no_mangle]
            pub unsafe extern "C" fn fmi2SetFMUstate(
                c: Fmi2Component,
                state: Fmi2FmuState,
            ) -> Fmi2Status {
                // SAFETY: the master upholds the FMI calling contract of `exports`.
                unsafe { x::set_fmu_state::<M>(c, state) }
            }

            /// `fmi2FreeFMUstate`.
            ///
            /// # Safety
            ///
            /// The FMI 2.0 calling contract of `fmi2::exports`: the master passes live instances,
            /// valid arrays and strings, and states of this FMU.
            #[no_mangle]
            pub unsafe extern "C" fn fmi2FreeFMUstate(
                c: Fmi2Component,
                state: *mut Fmi2FmuState,
            ) -> Fmi2Status {
                // SAFETY: the master upholds the FMI calling contract of `exports`.
                unsafe { x::free_fmu_state::<M>(c, state) }
            }

            /// `fmi2SerializedFMUstateSize`.
            ///
            /// # Safety
            ///
            /// The FMI 2.0 calling contract of `fmi2::exports`: the master passes live instances,
            /// valid arrays and strings, and states of this FMU.
            #[no_mangle]
            pub unsafe extern "C" fn fmi2SerializedFMUstateSize(
                c: Fmi2Component,
                state: Fmi2FmuState,
                size: *mut usize,
            ) -> Fmi2Status {
                // SAFETY: the master upholds the FMI calling contract of `exports`.
                unsafe { x::serialized_fmu_state_size::<M>(c, state, size) }
            }

            /// `fmi2SerializeFMUstate`.
            ///
            /// # Safety
            ///
            /// The FMI 2.0 calling contract of `fmi2::exports`: the master passes live instances,
            /// valid arrays and strings, and states of this FMU.
            #[no_mangle]
            pub unsafe extern "C" fn fmi2SerializeFMUstate(
                c: Fmi2Component,
                state: Fmi2FmuState,
                serialized_state: *mut Fmi2Byte,
                size: usize,
            ) -> Fmi2Status {
                // SAFETY: the master upholds the FMI calling contract of `exports`.
                unsafe { x::serialize_fmu_state::<M>(c, state, serialized_state, size) }
            }

            /// `fmi2DeSerializeFMUstate`.
            ///
            /// # Safety
            ///
            /// The FMI 2.0 calling contract of `fmi2::exports`: the master passes live instances,
            /// valid arrays and strings, and states of this FMU.
            #[no_mangle]
            pub unsafe extern "C" fn fmi2DeSerializeFMUstate(
                c: Fmi2Component,
                serialized_state: *const Fmi2Byte,
                size: usize,
                state: *mut Fmi2FmuState,
            ) -> Fmi2Status {
                // SAFETY: the master upholds the FMI calling contract of `exports`.
                unsafe { x::de_serialize_fmu_state::<M>(c, serialized_state, size, state) }
            }

            /// `fmi2GetDirectionalDerivative`: not supported.
            ///
            /// # Safety
            ///
            /// The FMI 2.0 calling contract of `fmi2::exports`: the master passes live instances,
            /// valid arrays and strings, and states of this FMU.
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetDirectionalDerivative(
                c: Fmi2Component,
                _v_unknown_ref: *const Fmi2ValueReference,
                _n_unknown: usize,
                _v_known_ref: *const Fmi2ValueReference,
                _n_known: usize,
                _dv_known: *const Fmi2Real,
                _dv_unknown: *mut Fmi2Real,
            ) -> Fmi2Status {
                // SAFETY: the master upholds the FMI calling contract of `exports`.
                unsafe { x::get_directional_derivative::<M>(c) }
            }

            /// `fmi2SetRealInputDerivatives`: not supported.
            ///
            /// # Safety
            ///
            /// The FMI 2.0 calling contract of `fmi2::exports`: the master passes live instances,
            /// valid arrays and strings, and states of this FMU.
            #[no_mangle]
            pub unsafe extern "C" fn fmi2SetRealInputDerivatives(
                c: Fmi2Component,
                _vr: *const Fmi2ValueReference,
                _nvr: usize,
                _order: *const Fmi2Integer,
                _value: *const Fmi2Real,
            ) -> Fmi2Status {
                // SAFETY: the master upholds the FMI calling contract of `exports`.
                unsafe { x::set_real_input_derivatives::<M>(c) }
            }

            /// `fmi2GetRealOutputDerivatives`: not supported.
            ///
            /// # Safety
            ///
            /// The FMI 2.0 calling contract of `fmi2::exports`: the master passes live instances,
            /// valid arrays and strings, and states of this FMU.
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetRealOutputDerivatives(
                c: Fmi2Component,
                _vr: *const Fmi2ValueReference,
                _nvr: usize,
                _order: *const Fmi2Integer,
                _value: *mut Fmi2Real,
            ) -> Fmi2Status {
                // SAFETY: the master upholds the FMI calling contract of `exports`.
                unsafe { x::get_real_output_derivatives::<M>(c) }
            }

            /// `fmi2DoStep`.
            ///
            /// # Safety
            ///
            /// The FMI 2.0 calling contract of `fmi2::exports`: the master passes live instances,
            /// valid arrays and strings, and states of this FMU.
            #[no_mangle]
            pub unsafe extern "C" fn fmi2DoStep(
                c: Fmi2Component,
                current_communication_point: Fmi2Real,
                communication_step_size: Fmi2Real,
                _no_set_fmu_state_prior_to_current_point: Fmi2Boolean,
            ) -> Fmi2Status {
                // SAFETY: the master upholds the FMI calling contract of `exports`.
                unsafe { x::do_step::<M>(c, current_communication_point, communication_step_size) }
            }

            /// `fmi2CancelStep`.
            ///
            /// # Safety
            ///
            /// The FMI 2.0 calling contract of `fmi2::exports`: the master passes live instances,
            /// valid arrays and strings, and states of this FMU.
            #[no_mangle]
            pub unsafe extern "C" fn fmi2CancelStep(c: Fmi2Component) -> Fmi2Status {
                // SAFETY: the master upholds the FMI calling contract of `exports`.
                unsafe { x::cancel_step::<M>(c) }
            }

            /// `fmi2GetStatus`: no status kind applies to a synchronous FMU (fmi2Discard).
            ///
            /// # Safety
            ///
            /// The FMI 2.0 calling contract of `fmi2::exports`: the master passes live instances,
            /// valid arrays and strings, and states of this FMU.
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetStatus(
                c: Fmi2Component,
                _s: Fmi2StatusKind,
                value: *mut Fmi2Status,
            ) -> Fmi2Status {
                // SAFETY: the master upholds the FMI calling contract of `exports`.
                unsafe { x::status_query::<M, _>(c, "fmi2GetStatus", value, |_| None) }
            }

            /// `fmi2GetRealStatus`: `fmi2LastSuccessfulTime` gives the time of the last step.
            ///
            /// # Safety
            ///
            /// The FMI 2.0 calling contract of `fmi2::exports`: the master passes live instances,
            /// valid arrays and strings, and states of this FMU.
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetRealStatus(
                c: Fmi2Component,
                s: Fmi2StatusKind,
                value: *mut Fmi2Real,
            ) -> Fmi2Status {
                // SAFETY: the master upholds the FMI calling contract of `exports`.
                unsafe {
                    x::status_query::<M, _>(c, "fmi2GetRealStatus", value, |inst| {
                        (s == FMI2_LAST_SUCCESSFUL_TIME).then(|| inst.last_successful_time())
                    })
                }
            }

            /// `fmi2GetIntegerStatus`: no integer status kind exists (fmi2Discard).
            ///
            /// # Safety
            ///
            /// The FMI 2.0 calling contract of `fmi2::exports`: the master passes live instances,
            /// valid arrays and strings, and states of this FMU.
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetIntegerStatus(
                c: Fmi2Component,
                _s: Fmi2StatusKind,
                value: *mut Fmi2Integer,
            ) -> Fmi2Status {
                // SAFETY: the master upholds the FMI calling contract of `exports`.
                unsafe { x::status_query::<M, _>(c, "fmi2GetIntegerStatus", value, |_| None) }
            }

            /// `fmi2GetBooleanStatus`: `fmi2Terminated` is always false.
            ///
            /// # Safety
            ///
            /// The FMI 2.0 calling contract of `fmi2::exports`: the master passes live instances,
            /// valid arrays and strings, and states of this FMU.
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetBooleanStatus(
                c: Fmi2Component,
                s: Fmi2StatusKind,
                value: *mut Fmi2Boolean,
            ) -> Fmi2Status {
                // SAFETY: the master upholds the FMI calling contract of `exports`.
                unsafe {
                    x::status_query::<M, _>(c, "fmi2GetBooleanStatus", value, |_| {
                        (s == FMI2_TERMINATED).then_some(FMI2_FALSE)
                    })
                }
            }

            /// `fmi2GetStringStatus`: `fmi2PendingStatus` is never available (fmi2Discard).
            ///
            /// # Safety
            ///
            /// The FMI 2.0 calling contract of `fmi2::exports`: the master passes live instances,
            /// valid arrays and strings, and states of this FMU.
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetStringStatus(
                c: Fmi2Component,
                _s: Fmi2StatusKind,
                value: *mut Fmi2String,
            ) -> Fmi2Status {
                // SAFETY: the master upholds the FMI calling contract of `exports`.
                unsafe { x::status_query::<M, _>(c, "fmi2GetStringStatus", value, |_| None) }
            }
        }
    };
}
