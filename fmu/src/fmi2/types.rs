//! The C types of the FMI 2.0 standard (`fmi2TypesPlatform.h`, `fmi2FunctionTypes.h`), platform
//! "default".

use std::os::raw::{c_char, c_double, c_int, c_uint, c_void};

/// `fmi2Component`: the opaque pointer to one FMU instance.
pub type Fmi2Component = *mut c_void;
/// `fmi2ComponentEnvironment`: the master's opaque pointer handed back to the callbacks.
pub type Fmi2ComponentEnvironment = *mut c_void;
/// `fmi2FMUstate`: the opaque pointer to a saved FMU state.
pub type Fmi2FmuState = *mut c_void;
/// `fmi2ValueReference`.
pub type Fmi2ValueReference = c_uint;
/// `fmi2Real`.
pub type Fmi2Real = c_double;
/// `fmi2Integer`.
pub type Fmi2Integer = c_int;
/// `fmi2Boolean` (`fmi2True` = 1, `fmi2False` = 0).
pub type Fmi2Boolean = c_int;
/// `fmi2Char`.
pub type Fmi2Char = c_char;
/// `fmi2String`: a NUL-terminated UTF-8 string.
pub type Fmi2String = *const c_char;
/// `fmi2Byte`.
pub type Fmi2Byte = c_char;

/// `fmi2True`.
pub const FMI2_TRUE: Fmi2Boolean = 1;
/// `fmi2False`.
pub const FMI2_FALSE: Fmi2Boolean = 0;

/// `fmi2Status`: the result of every FMI function.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Fmi2Status {
    /// All well.
    Ok = 0,
    /// Things are not quite right, but the computation can continue.
    Warning = 1,
    /// The step could not be completed (co-simulation: `fmi2DoStep` did not advance).
    Discard = 2,
    /// The call failed; see the log message.
    Error = 3,
    /// The computations are irreparably corrupted for all instances.
    Fatal = 4,
    /// An asynchronous step is still running (never returned by this FMU).
    Pending = 5,
}

/// `fmi2Type`: model exchange or co-simulation.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Fmi2Type {
    /// Model exchange.
    ModelExchange = 0,
    /// Co-simulation.
    CoSimulation = 1,
}

/// `fmi2StatusKind`: which status `fmi2Get*Status` asks for.
pub type Fmi2StatusKind = c_int;
/// `fmi2DoStepStatus`.
pub const FMI2_DO_STEP_STATUS: Fmi2StatusKind = 0;
/// `fmi2PendingStatus`.
pub const FMI2_PENDING_STATUS: Fmi2StatusKind = 1;
/// `fmi2LastSuccessfulTime`.
pub const FMI2_LAST_SUCCESSFUL_TIME: Fmi2StatusKind = 2;
/// `fmi2Terminated`.
pub const FMI2_TERMINATED: Fmi2StatusKind = 3;

/// `fmi2CallbackLogger`: variadic, `message` is a printf format (hence `%` escaped as `%%`).
///
/// # Safety
///
/// A foreign function of the master: callers pass the master's `componentEnvironment`, and
/// NUL-terminated strings alive during the call, with a format string that reads no variadic
/// argument (see `logger::Logger::log`).
pub type Fmi2CallbackLogger = unsafe extern "C" fn(
    Fmi2ComponentEnvironment,
    Fmi2String,
    Fmi2Status,
    Fmi2String,
    Fmi2String,
    ...
);
/// `fmi2CallbackAllocateMemory`.
///
/// # Safety
///
/// A foreign function of the master; never called (`canNotUseMemoryManagementFunctions`).
pub type Fmi2CallbackAllocateMemory = unsafe extern "C" fn(usize, usize) -> *mut c_void;
/// `fmi2CallbackFreeMemory`.
///
/// # Safety
///
/// A foreign function of the master; never called (`canNotUseMemoryManagementFunctions`).
pub type Fmi2CallbackFreeMemory = unsafe extern "C" fn(*mut c_void);
/// `fmi2StepFinished`.
///
/// # Safety
///
/// A foreign function of the master; never called (steps are synchronous).
pub type Fmi2StepFinished = unsafe extern "C" fn(Fmi2ComponentEnvironment, Fmi2Status);

/// `fmi2CallbackFunctions`, as passed to `fmi2Instantiate` (copied by the instance).
#[repr(C)]
#[derive(Debug, Clone, Copy)]
pub struct Fmi2CallbackFunctions {
    /// The logger (may be NULL: then nothing is logged).
    pub logger: Option<Fmi2CallbackLogger>,
    /// Memory allocation (unused: `canNotUseMemoryManagementFunctions="true"`).
    pub allocate_memory: Option<Fmi2CallbackAllocateMemory>,
    /// Memory release (unused).
    pub free_memory: Option<Fmi2CallbackFreeMemory>,
    /// Asynchronous step completion (unused: steps are synchronous).
    pub step_finished: Option<Fmi2StepFinished>,
    /// The master's pointer handed back to the logger.
    pub component_environment: Fmi2ComponentEnvironment,
}
