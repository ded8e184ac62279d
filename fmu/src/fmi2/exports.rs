//! The exported FMI 2.0 functions (`#[no_mangle] extern "C"`), every FMI 2.0 common and
//! co-simulation function. Each converts its C arguments (NULL checks, slices, strings), runs
//! behind `catch_unwind` (a panic becomes `fmi2Error`, a log message and the error state), and
//! delegates to [`Instance`]. The only model-specific line is the [`Inst`] alias.

#![allow(clippy::missing_safety_doc)]

use super::instance::{check_state_header, guid, mask, Instance};
use super::logger::Logger;
use super::types::*;
use super::uri::resource_dir_from_uri;
use super::variables::{BaseType, Value};
use std::ffi::CStr;
use std::os::raw::c_char;
use std::panic::{catch_unwind, AssertUnwindSafe};

/// The model this library exports.
pub type Inst = Instance<crate::model::TissueSim>;

const FMU_STATE_MAGIC: u64 = 0x5453_464d_5553_5441; // "TSFMUSTA"

/// The memory behind an `fmi2FMUstate`: a tag (to catch foreign pointers) and the serialised
/// instance state (see [`Instance::save_fmu_state`]).
struct FmuState {
    magic: u64,
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
unsafe fn guarded(
    c: Fmi2Component,
    func: &'static str,
    f: impl FnOnce(&mut Inst) -> Fmi2Status,
) -> Fmi2Status {
    if c.is_null() {
        return Fmi2Status::Error;
    }
    let ptr = c as *mut Inst;
    match catch_unwind(AssertUnwindSafe(|| f(&mut *ptr))) {
        Ok(s) => s,
        Err(p) => {
            let msg = panic_message(&*p);
            let _ = catch_unwind(AssertUnwindSafe(|| {
                let inst = &mut *ptr;
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
unsafe fn slice<'a, T>(p: *const T, n: usize) -> Option<&'a [T]> {
    if n == 0 {
        Some(&[])
    } else if p.is_null() {
        None
    } else {
        Some(std::slice::from_raw_parts(p, n))
    }
}

unsafe fn slice_mut<'a, T>(p: *mut T, n: usize) -> Option<&'a mut [T]> {
    if n == 0 {
        Some(&mut [])
    } else if p.is_null() {
        None
    } else {
        Some(std::slice::from_raw_parts_mut(p, n))
    }
}

unsafe fn string<'a>(p: *const c_char) -> Option<&'a str> {
    if p.is_null() {
        None
    } else {
        CStr::from_ptr(p).to_str().ok()
    }
}

// ---------------------------------------------------------------------------------------------
// Inquire version numbers, logging

/// `fmi2GetTypesPlatform`: "default".
#[no_mangle]
pub extern "C" fn fmi2GetTypesPlatform() -> *const c_char {
    c"default".as_ptr()
}

/// `fmi2GetVersion`: "2.0".
#[no_mangle]
pub extern "C" fn fmi2GetVersion() -> *const c_char {
    c"2.0".as_ptr()
}

/// `fmi2SetDebugLogging`.
#[no_mangle]
pub unsafe extern "C" fn fmi2SetDebugLogging(
    c: Fmi2Component,
    logging_on: Fmi2Boolean,
    n_categories: usize,
    categories: *const Fmi2String,
) -> Fmi2Status {
    guarded(c, "fmi2SetDebugLogging", |inst| {
        let Some(cats) = slice(categories, n_categories) else {
            return inst.fail("fmi2SetDebugLogging", "categories is NULL");
        };
        let mut names = Vec::with_capacity(cats.len());
        for &p in cats {
            match string(p) {
                Some(s) => names.push(s.to_string()),
                None => return inst.fail("fmi2SetDebugLogging", "a category is NULL or not UTF-8"),
            }
        }
        inst.set_debug_logging(logging_on != FMI2_FALSE, &names)
    })
}

// ---------------------------------------------------------------------------------------------
// Creation and destruction

/// `fmi2Instantiate`: NULL on failure (reason logged when a logger was given).
#[no_mangle]
pub unsafe extern "C" fn fmi2Instantiate(
    instance_name: Fmi2String,
    fmu_type: std::os::raw::c_int,
    fmu_guid: Fmi2String,
    fmu_resource_location: Fmi2String,
    functions: *const Fmi2CallbackFunctions,
    _visible: Fmi2Boolean,
    logging_on: Fmi2Boolean,
) -> Fmi2Component {
    let r = catch_unwind(AssertUnwindSafe(|| {
        if functions.is_null() {
            return std::ptr::null_mut();
        }
        let cb = *functions;
        let name = string(instance_name).unwrap_or("");
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
        let expected = guid::<crate::model::TissueSim>();
        match string(fmu_guid) {
            Some(g) if g == expected => {}
            other => {
                log.error(&format!(
                    "{f}: fmuGUID {other:?} does not match the GUID of this binary {expected}"
                ));
                return std::ptr::null_mut();
            }
        }
        let resources = match string(fmu_resource_location) {
            None => {
                log.warning(&format!(
                    "{f}: no fmuResourceLocation: relative mesh file names cannot be resolved"
                ));
                None
            }
            Some(uri) => match resource_dir_from_uri(uri) {
                Ok(dir) => Some(dir),
                Err(e) => {
                    log.warning(&format!(
                        "{f}: {e}; relative mesh file names cannot be resolved"
                    ));
                    None
                }
            },
        };
        let inst = Box::new(Inst::new(log, resources));
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
#[no_mangle]
pub unsafe extern "C" fn fmi2FreeInstance(c: Fmi2Component) {
    if c.is_null() {
        return;
    }
    let _ = catch_unwind(AssertUnwindSafe(|| {
        let inst = Box::from_raw(c as *mut Inst);
        inst.log_call(|| "fmi2FreeInstance()".into());
        drop(inst);
    }));
}

// ---------------------------------------------------------------------------------------------
// Initialisation, termination, reset

/// `fmi2SetupExperiment`.
#[no_mangle]
pub unsafe extern "C" fn fmi2SetupExperiment(
    c: Fmi2Component,
    _tolerance_defined: Fmi2Boolean,
    _tolerance: Fmi2Real,
    start_time: Fmi2Real,
    stop_time_defined: Fmi2Boolean,
    stop_time: Fmi2Real,
) -> Fmi2Status {
    guarded(c, "fmi2SetupExperiment", |inst| {
        inst.log_call(|| {
            format!("fmi2SetupExperiment(startTime={start_time}, stopTimeDefined={stop_time_defined}, stopTime={stop_time})")
        });
        let stop = (stop_time_defined != FMI2_FALSE).then_some(stop_time);
        status_of(inst.setup_experiment(start_time, stop))
    })
}

/// `fmi2EnterInitializationMode`.
#[no_mangle]
pub unsafe extern "C" fn fmi2EnterInitializationMode(c: Fmi2Component) -> Fmi2Status {
    guarded(c, "fmi2EnterInitializationMode", |inst| {
        inst.log_call(|| "fmi2EnterInitializationMode()".into());
        status_of(inst.enter_initialization_mode())
    })
}

/// `fmi2ExitInitializationMode`: builds the world from the parameters.
#[no_mangle]
pub unsafe extern "C" fn fmi2ExitInitializationMode(c: Fmi2Component) -> Fmi2Status {
    guarded(c, "fmi2ExitInitializationMode", |inst| {
        inst.log_call(|| "fmi2ExitInitializationMode()".into());
        status_of(inst.exit_initialization_mode())
    })
}

/// `fmi2Terminate`.
#[no_mangle]
pub unsafe extern "C" fn fmi2Terminate(c: Fmi2Component) -> Fmi2Status {
    guarded(c, "fmi2Terminate", |inst| {
        inst.log_call(|| "fmi2Terminate()".into());
        status_of(inst.terminate())
    })
}

/// `fmi2Reset`.
#[no_mangle]
pub unsafe extern "C" fn fmi2Reset(c: Fmi2Component) -> Fmi2Status {
    guarded(c, "fmi2Reset", |inst| {
        inst.log_call(|| "fmi2Reset()".into());
        status_of(inst.reset())
    })
}

// ---------------------------------------------------------------------------------------------
// Getting and setting variable values

unsafe fn get_values<T>(
    c: Fmi2Component,
    func: &'static str,
    ty: BaseType,
    vr: *const Fmi2ValueReference,
    nvr: usize,
    value: *mut T,
    convert: impl Fn(&Value) -> T,
) -> Fmi2Status {
    guarded(c, func, |inst| {
        let (Some(vrs), Some(out)) = (slice(vr, nvr), slice_mut(value, nvr)) else {
            return inst.fail(func, "vr or value is NULL");
        };
        if let Err(s) = inst.prepare_get(func, ty, vrs) {
            return s;
        }
        for (o, &r) in out.iter_mut().zip(vrs) {
            *o = convert(inst.store().get(r));
        }
        Fmi2Status::Ok
    })
}

unsafe fn set_values<T: Copy>(
    c: Fmi2Component,
    func: &'static str,
    ty: BaseType,
    vr: *const Fmi2ValueReference,
    nvr: usize,
    value: *const T,
    convert: impl Fn(T) -> Option<Value>,
) -> Fmi2Status {
    guarded(c, func, |inst| {
        let (Some(vrs), Some(vals)) = (slice(vr, nvr), slice(value, nvr)) else {
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
    })
}

/// `fmi2GetReal`.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetReal(
    c: Fmi2Component,
    vr: *const Fmi2ValueReference,
    nvr: usize,
    value: *mut Fmi2Real,
) -> Fmi2Status {
    get_values(
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

/// `fmi2GetInteger` (Integer and Enumeration variables).
#[no_mangle]
pub unsafe extern "C" fn fmi2GetInteger(
    c: Fmi2Component,
    vr: *const Fmi2ValueReference,
    nvr: usize,
    value: *mut Fmi2Integer,
) -> Fmi2Status {
    get_values(
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

/// `fmi2GetBoolean`.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetBoolean(
    c: Fmi2Component,
    vr: *const Fmi2ValueReference,
    nvr: usize,
    value: *mut Fmi2Boolean,
) -> Fmi2Status {
    get_values(
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

/// `fmi2GetString`: the returned pointers stay valid until the next `fmi2GetString` call on
/// this instance (or its release).
#[no_mangle]
pub unsafe extern "C" fn fmi2GetString(
    c: Fmi2Component,
    vr: *const Fmi2ValueReference,
    nvr: usize,
    value: *mut Fmi2String,
) -> Fmi2Status {
    const F: &str = "fmi2GetString";
    guarded(c, F, |inst| {
        let (Some(vrs), Some(out)) = (slice(vr, nvr), slice_mut(value, nvr)) else {
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
    })
}

/// `fmi2SetReal`: NaN/Inf and out-of-range values are refused (nothing set).
#[no_mangle]
pub unsafe extern "C" fn fmi2SetReal(
    c: Fmi2Component,
    vr: *const Fmi2ValueReference,
    nvr: usize,
    value: *const Fmi2Real,
) -> Fmi2Status {
    set_values(c, "fmi2SetReal", BaseType::Real, vr, nvr, value, |v| {
        Some(Value::Real(v))
    })
}

/// `fmi2SetInteger`.
#[no_mangle]
pub unsafe extern "C" fn fmi2SetInteger(
    c: Fmi2Component,
    vr: *const Fmi2ValueReference,
    nvr: usize,
    value: *const Fmi2Integer,
) -> Fmi2Status {
    set_values(
        c,
        "fmi2SetInteger",
        BaseType::Integer,
        vr,
        nvr,
        value,
        |v| Some(Value::Integer(v)),
    )
}

/// `fmi2SetBoolean`.
#[no_mangle]
pub unsafe extern "C" fn fmi2SetBoolean(
    c: Fmi2Component,
    vr: *const Fmi2ValueReference,
    nvr: usize,
    value: *const Fmi2Boolean,
) -> Fmi2Status {
    set_values(
        c,
        "fmi2SetBoolean",
        BaseType::Boolean,
        vr,
        nvr,
        value,
        |v| Some(Value::Boolean(v != FMI2_FALSE)),
    )
}

/// `fmi2SetString`.
#[no_mangle]
pub unsafe extern "C" fn fmi2SetString(
    c: Fmi2Component,
    vr: *const Fmi2ValueReference,
    nvr: usize,
    value: *const Fmi2String,
) -> Fmi2Status {
    set_values(c, "fmi2SetString", BaseType::String, vr, nvr, value, |v| {
        string(v).map(|s| Value::String(s.to_string()))
    })
}

// ---------------------------------------------------------------------------------------------
// FMU states

unsafe fn fmu_state<'a>(p: Fmi2FmuState) -> Option<&'a mut FmuState> {
    let s = (p as *mut FmuState).as_mut()?;
    (s.magic == FMU_STATE_MAGIC).then_some(s)
}

/// `fmi2GetFMUstate`: allocates a state when `*state` is NULL, overwrites it otherwise.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetFMUstate(c: Fmi2Component, state: *mut Fmi2FmuState) -> Fmi2Status {
    const F: &str = "fmi2GetFMUstate";
    guarded(c, F, |inst| {
        let Some(slot) = state.as_mut() else {
            return inst.fail(F, "FMUstate is NULL");
        };
        let mut bytes = Vec::new();
        if let Err(s) = inst.save_fmu_state(&mut bytes) {
            return s;
        }
        if slot.is_null() {
            *slot = Box::into_raw(Box::new(FmuState {
                magic: FMU_STATE_MAGIC,
                bytes,
            })) as Fmi2FmuState;
        } else {
            match fmu_state(*slot) {
                Some(s) => s.bytes = bytes,
                None => return inst.fail(F, "*FMUstate is not a state of this FMU"),
            }
        }
        inst.log_call(|| format!("{F}() -> {:?}", *slot));
        Fmi2Status::Ok
    })
}

/// `fmi2SetFMUstate`.
#[no_mangle]
pub unsafe extern "C" fn fmi2SetFMUstate(c: Fmi2Component, state: Fmi2FmuState) -> Fmi2Status {
    const F: &str = "fmi2SetFMUstate";
    guarded(c, F, |inst| {
        inst.log_call(|| format!("{F}({state:?})"));
        match fmu_state(state) {
            Some(s) => status_of(inst.restore_fmu_state(&s.bytes)),
            None => inst.fail(F, "FMUstate is NULL or not a state of this FMU"),
        }
    })
}

/// `fmi2FreeFMUstate`: frees `*state` and sets it to NULL; a NULL `*state` is a no-op.
#[no_mangle]
pub unsafe extern "C" fn fmi2FreeFMUstate(
    c: Fmi2Component,
    state: *mut Fmi2FmuState,
) -> Fmi2Status {
    const F: &str = "fmi2FreeFMUstate";
    guarded(c, F, |inst| {
        let Some(slot) = state.as_mut() else {
            return inst.fail(F, "FMUstate is NULL");
        };
        if slot.is_null() {
            return Fmi2Status::Ok;
        }
        if fmu_state(*slot).is_none() {
            return inst.fail(F, "*FMUstate is not a state of this FMU");
        }
        let mut s = Box::from_raw(*slot as *mut FmuState);
        s.magic = 0;
        drop(s);
        *slot = std::ptr::null_mut();
        Fmi2Status::Ok
    })
}

/// `fmi2SerializedFMUstateSize`.
#[no_mangle]
pub unsafe extern "C" fn fmi2SerializedFMUstateSize(
    c: Fmi2Component,
    state: Fmi2FmuState,
    size: *mut usize,
) -> Fmi2Status {
    const F: &str = "fmi2SerializedFMUstateSize";
    guarded(c, F, |inst| {
        if let Err(s) = inst.check_state(F, mask::SET_STATE) {
            return s;
        }
        match (fmu_state(state), size.as_mut()) {
            (Some(s), Some(out)) => {
                *out = s.bytes.len();
                Fmi2Status::Ok
            }
            _ => inst.fail(F, "FMUstate or size is NULL (or not a state of this FMU)"),
        }
    })
}

/// `fmi2SerializeFMUstate`: copies the versioned state bytes into the caller's buffer.
#[no_mangle]
pub unsafe extern "C" fn fmi2SerializeFMUstate(
    c: Fmi2Component,
    state: Fmi2FmuState,
    serialized_state: *mut Fmi2Byte,
    size: usize,
) -> Fmi2Status {
    const F: &str = "fmi2SerializeFMUstate";
    guarded(c, F, |inst| {
        if let Err(s) = inst.check_state(F, mask::SET_STATE) {
            return s;
        }
        let Some(s) = fmu_state(state) else {
            return inst.fail(F, "FMUstate is NULL or not a state of this FMU");
        };
        if size < s.bytes.len() {
            return inst.fail(
                F,
                &format!("buffer of {size} bytes too small, {} needed", s.bytes.len()),
            );
        }
        let Some(out) = slice_mut(serialized_state as *mut u8, s.bytes.len()) else {
            return inst.fail(F, "serializedState is NULL");
        };
        out.copy_from_slice(&s.bytes);
        Fmi2Status::Ok
    })
}

/// `fmi2DeSerializeFMUstate`: checks the header (magic, version, GUID) and creates a state
/// (or overwrites `*state` when it is not NULL).
#[no_mangle]
pub unsafe extern "C" fn fmi2DeSerializeFMUstate(
    c: Fmi2Component,
    serialized_state: *const Fmi2Byte,
    size: usize,
    state: *mut Fmi2FmuState,
) -> Fmi2Status {
    const F: &str = "fmi2DeSerializeFMUstate";
    guarded(c, F, |inst| {
        if let Err(s) = inst.check_state(F, mask::SET_STATE) {
            return s;
        }
        let (Some(bytes), Some(slot)) =
            (slice(serialized_state as *const u8, size), state.as_mut())
        else {
            return inst.fail(F, "serializedState or FMUstate is NULL");
        };
        if let Err(e) = check_state_header::<crate::model::TissueSim>(bytes) {
            return inst.fail(F, &e);
        }
        if slot.is_null() {
            *slot = Box::into_raw(Box::new(FmuState {
                magic: FMU_STATE_MAGIC,
                bytes: bytes.to_vec(),
            })) as Fmi2FmuState;
        } else {
            match fmu_state(*slot) {
                Some(s) => s.bytes = bytes.to_vec(),
                None => return inst.fail(F, "*FMUstate is not a state of this FMU"),
            }
        }
        Fmi2Status::Ok
    })
}

// ---------------------------------------------------------------------------------------------
// Derivatives (not supported)

/// `fmi2GetDirectionalDerivative`: not supported (`providesDirectionalDerivative="false"`).
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
    const F: &str = "fmi2GetDirectionalDerivative";
    guarded(c, F, |inst| {
        if let Err(s) = inst.check_state(F, mask::DIRECTIONAL) {
            return s;
        }
        inst.fail(F, "directional derivatives are not supported")
    })
}

/// `fmi2SetRealInputDerivatives`: not supported (`canInterpolateInputs="false"`; the FMU
/// interpolates the tool pose linearly between communication points by itself).
#[no_mangle]
pub unsafe extern "C" fn fmi2SetRealInputDerivatives(
    c: Fmi2Component,
    _vr: *const Fmi2ValueReference,
    _nvr: usize,
    _order: *const Fmi2Integer,
    _value: *const Fmi2Real,
) -> Fmi2Status {
    const F: &str = "fmi2SetRealInputDerivatives";
    guarded(c, F, |inst| {
        if let Err(s) = inst.check_state(F, mask::INPUT_DERIVATIVES) {
            return s;
        }
        inst.fail(
            F,
            "input derivatives are not supported (canInterpolateInputs=false)",
        )
    })
}

/// `fmi2GetRealOutputDerivatives`: not supported (`maxOutputDerivativeOrder="0"`).
#[no_mangle]
pub unsafe extern "C" fn fmi2GetRealOutputDerivatives(
    c: Fmi2Component,
    _vr: *const Fmi2ValueReference,
    _nvr: usize,
    _order: *const Fmi2Integer,
    _value: *mut Fmi2Real,
) -> Fmi2Status {
    const F: &str = "fmi2GetRealOutputDerivatives";
    guarded(c, F, |inst| {
        if let Err(s) = inst.check_state(F, mask::OUTPUT_DERIVATIVES) {
            return s;
        }
        inst.fail(
            F,
            "output derivatives are not supported (maxOutputDerivativeOrder=0)",
        )
    })
}

// ---------------------------------------------------------------------------------------------
// Stepping and status

/// `fmi2DoStep`: synchronous; sub-steps at `internal_step` and interpolates the tool pose.
/// Returns `fmi2Discard` (nothing changed, time not advanced) when the solver diverged.
#[no_mangle]
pub unsafe extern "C" fn fmi2DoStep(
    c: Fmi2Component,
    current_communication_point: Fmi2Real,
    communication_step_size: Fmi2Real,
    _no_set_fmu_state_prior_to_current_point: Fmi2Boolean,
) -> Fmi2Status {
    guarded(c, "fmi2DoStep", |inst| {
        inst.do_step(current_communication_point, communication_step_size)
    })
}

/// `fmi2CancelStep`: steps are synchronous, so there is never a step to cancel (fmi2Error).
#[no_mangle]
pub unsafe extern "C" fn fmi2CancelStep(c: Fmi2Component) -> Fmi2Status {
    const F: &str = "fmi2CancelStep";
    guarded(c, F, |inst| {
        if let Err(s) = inst.check_state(F, mask::STEP) {
            return s;
        }
        inst.fail(
            F,
            "no asynchronous step is pending (fmi2DoStep never returns fmi2Pending)",
        )
    })
}

unsafe fn status_query<T>(
    c: Fmi2Component,
    func: &'static str,
    value: *mut T,
    answer: impl FnOnce(&Inst) -> Option<T>,
) -> Fmi2Status {
    guarded(c, func, |inst| {
        if let Err(s) = inst.check_state(func, mask::STATUS) {
            return s;
        }
        let Some(out) = value.as_mut() else {
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
    })
}

/// `fmi2GetStatus`: no status kind applies to a synchronous FMU (fmi2Discard).
#[no_mangle]
pub unsafe extern "C" fn fmi2GetStatus(
    c: Fmi2Component,
    _s: Fmi2StatusKind,
    value: *mut Fmi2Status,
) -> Fmi2Status {
    status_query(c, "fmi2GetStatus", value, |_| None)
}

/// `fmi2GetRealStatus`: `fmi2LastSuccessfulTime` gives the time reached by the last step.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetRealStatus(
    c: Fmi2Component,
    s: Fmi2StatusKind,
    value: *mut Fmi2Real,
) -> Fmi2Status {
    status_query(c, "fmi2GetRealStatus", value, |inst| {
        (s == FMI2_LAST_SUCCESSFUL_TIME).then(|| inst.last_successful_time())
    })
}

/// `fmi2GetIntegerStatus`: no integer status kind exists (fmi2Discard).
#[no_mangle]
pub unsafe extern "C" fn fmi2GetIntegerStatus(
    c: Fmi2Component,
    _s: Fmi2StatusKind,
    value: *mut Fmi2Integer,
) -> Fmi2Status {
    status_query(c, "fmi2GetIntegerStatus", value, |_| None)
}

/// `fmi2GetBooleanStatus`: `fmi2Terminated` is always false (the FMU never asks to stop).
#[no_mangle]
pub unsafe extern "C" fn fmi2GetBooleanStatus(
    c: Fmi2Component,
    s: Fmi2StatusKind,
    value: *mut Fmi2Boolean,
) -> Fmi2Status {
    status_query(c, "fmi2GetBooleanStatus", value, |_| {
        (s == FMI2_TERMINATED).then_some(FMI2_FALSE)
    })
}

/// `fmi2GetStringStatus`: `fmi2PendingStatus` is never available (fmi2Discard).
#[no_mangle]
pub unsafe extern "C" fn fmi2GetStringStatus(
    c: Fmi2Component,
    _s: Fmi2StatusKind,
    value: *mut Fmi2String,
) -> Fmi2Status {
    status_query(c, "fmi2GetStringStatus", value, |_| None)
}
