//! One FMU instance: the FMI 2.0 co-simulation state machine (after the Modelica
//! Reference-FMUs), the argument checks on value references and values, the variable store, the
//! versioned FMU-state format, and the [`Model`] it drives.
//!
//! States and the calls each allows (others return `fmi2Error` with the log message
//! "illegal call sequence" and change nothing):
//!
//! | state | reached by | allows |
//! |---|---|---|
//! | instantiated | `fmi2Instantiate`, `fmi2Reset` | SetupExperiment, EnterInitializationMode, Set*, Get/SetFMUstate |
//! | initializationMode | `fmi2EnterInitializationMode` | ExitInitializationMode, Get*, Set*, FMU states |
//! | stepComplete | `fmi2ExitInitializationMode`, `fmi2DoStep` | DoStep, Get*, Set* (inputs, tunable parameters), Terminate, status queries, FMU states |
//! | terminated | `fmi2Terminate` | Get*, status queries, FMU states |
//! | error | a panic inside the model | Get*, SetFMUstate, Reset, FreeInstance |
//!
//! `fmi2Reset`, `fmi2FreeInstance` and `fmi2SetDebugLogging` are allowed in every state.
//! Invalid arguments (unknown value reference, NaN, value out of range, a fixed parameter set
//! after initialisation) return `fmi2Error` and leave the instance exactly as it was, so a
//! master may correct the call and continue.

use super::bytes::{PutBytes, Reader};
use super::logger::{Category, Logger};
use super::types::Fmi2Status;
use super::variables::{
    BaseType, Causality, EnumType, Phase, Store, UnitDefinition, Value, Variable,
};
use std::ffi::CString;
use std::path::PathBuf;

/// Why a model operation failed: the status to return (`Discard` or `Error`) and the message.
#[derive(Debug, Clone, PartialEq)]
pub struct ModelError {
    /// `Fmi2Status::Discard` (step not taken, instance unchanged, retry possible) or
    /// `Fmi2Status::Error`.
    pub status: Fmi2Status,
    /// What went wrong (logged).
    pub message: String,
}

impl ModelError {
    /// An error.
    pub fn error(message: impl Into<String>) -> Self {
        ModelError {
            status: Fmi2Status::Error,
            message: message.into(),
        }
    }
    /// A discarded step.
    pub fn discard(message: impl Into<String>) -> Self {
        ModelError {
            status: Fmi2Status::Discard,
            message: message.into(),
        }
    }
}

/// The `DefaultExperiment` of the model description.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DefaultExperiment {
    /// Start time (s).
    pub start_time: f64,
    /// Stop time (s).
    pub stop_time: f64,
    /// Communication step size (s).
    pub step_size: f64,
}

/// What a model supplies to the generic FMI layer: its static description and the mapping of
/// the variable store to its solver.
pub trait Model: Sized {
    /// `modelName` and `modelIdentifier` (the shared library's file name without extension).
    const MODEL_IDENTIFIER: &'static str;
    /// `description` of the model.
    const DESCRIPTION: &'static str;
    /// The variables; value reference = index.
    const VARIABLES: &'static [Variable];
    /// The units used by the variables.
    const UNITS: &'static [UnitDefinition];
    /// The enumeration types used by the variables.
    const ENUMERATIONS: &'static [&'static EnumType];
    /// The default experiment.
    const DEFAULT_EXPERIMENT: DefaultExperiment;
    /// The first 8 bytes of this model's serialised FMU states (tells its states from other
    /// data; the GUID inside then tells them from states of other versions of the model).
    const STATE_MAGIC: [u8; 8];

    /// A fresh model; `resources` is the FMU's `resources/` directory when known.
    fn new(resources: Option<PathBuf>) -> Self;
    /// Build the simulation from the parameters and inputs in `store` and write the initial
    /// outputs into it. Called at `fmi2ExitInitializationMode`, and earlier when outputs are
    /// read in initialisation mode. On error nothing is changed.
    fn initialize(&mut self, store: &mut Store, log: &Logger) -> Result<(), ModelError>;
    /// Advance from `t` to `t + h` (`h > 0`) with the inputs and tunable parameters of
    /// `store`, writing the outputs. On error the model and the store are unchanged.
    fn do_step(
        &mut self,
        store: &mut Store,
        t: f64,
        h: f64,
        log: &Logger,
    ) -> Result<(), ModelError>;
    /// Forget the simulation (back to the state after [`Model::new`]).
    fn reset(&mut self);
    /// Append the model's dynamic state (not the store, saved by the layer) to `out`.
    fn save_state(&self, out: &mut Vec<u8>);
    /// Restore a state written by [`Model::save_state`]; `store` already holds the restored
    /// variable values. On error nothing is changed.
    fn restore_state(
        &mut self,
        store: &Store,
        bytes: &[u8],
        log: &Logger,
    ) -> Result<(), ModelError>;
}

/// The state of an instance (bit flags, so that a set of states is a mask).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u32)]
pub enum State {
    /// After `fmi2Instantiate` / `fmi2Reset`.
    Instantiated = 1 << 0,
    /// Between `fmi2EnterInitializationMode` and `fmi2ExitInitializationMode`.
    InitializationMode = 1 << 1,
    /// Between steps.
    StepComplete = 1 << 2,
    /// After `fmi2Terminate`.
    Terminated = 1 << 3,
    /// After an internal error (a panic): only Get*, SetFMUstate, Reset, FreeInstance.
    Error = 1 << 4,
}

impl State {
    /// The FMI name of the state.
    pub fn name(self) -> &'static str {
        match self {
            State::Instantiated => "instantiated",
            State::InitializationMode => "initializationMode",
            State::StepComplete => "stepComplete",
            State::Terminated => "terminated",
            State::Error => "error",
        }
    }
    fn code(self) -> u8 {
        match self {
            State::Instantiated => 1,
            State::InitializationMode => 2,
            State::StepComplete => 3,
            State::Terminated => 4,
            State::Error => 5,
        }
    }
    fn from_code(c: u8) -> Option<State> {
        Some(match c {
            1 => State::Instantiated,
            2 => State::InitializationMode,
            3 => State::StepComplete,
            4 => State::Terminated,
            _ => return None,
        })
    }
}

/// Masks of the states in which each function may be called.
pub mod mask {
    use super::State::*;
    const fn m(states: &[super::State]) -> u32 {
        let mut bits = 0;
        let mut i = 0;
        while i < states.len() {
            bits |= states[i] as u32;
            i += 1;
        }
        bits
    }
    /// Every state.
    pub const ANY: u32 = m(&[
        Instantiated,
        InitializationMode,
        StepComplete,
        Terminated,
        Error,
    ]);
    /// `fmi2SetupExperiment`, `fmi2EnterInitializationMode`.
    pub const INSTANTIATED: u32 = m(&[Instantiated]);
    /// `fmi2ExitInitializationMode`.
    pub const INIT: u32 = m(&[InitializationMode]);
    /// `fmi2DoStep`, `fmi2Terminate`, `fmi2CancelStep`.
    pub const STEP: u32 = m(&[StepComplete]);
    /// `fmi2Get{Real,Integer,Boolean,String}`.
    pub const GET: u32 = m(&[InitializationMode, StepComplete, Terminated, Error]);
    /// `fmi2Set{Real,Integer,Boolean,String}`.
    pub const SET: u32 = m(&[Instantiated, InitializationMode, StepComplete]);
    /// `fmi2GetFMUstate`.
    pub const GET_STATE: u32 = m(&[Instantiated, InitializationMode, StepComplete, Terminated]);
    /// `fmi2SetFMUstate`, `fmi2FreeFMUstate`, serialisation.
    pub const SET_STATE: u32 = ANY;
    /// `fmi2Get*Status`.
    pub const STATUS: u32 = m(&[StepComplete, Terminated]);
    /// `fmi2GetDirectionalDerivative`.
    pub const DIRECTIONAL: u32 = m(&[InitializationMode, StepComplete, Terminated, Error]);
    /// `fmi2SetRealInputDerivatives`.
    pub const INPUT_DERIVATIVES: u32 = m(&[Instantiated, InitializationMode, StepComplete]);
    /// `fmi2GetRealOutputDerivatives`.
    pub const OUTPUT_DERIVATIVES: u32 = m(&[StepComplete, Terminated, Error]);
}

/// Version of the FMU-state byte format: 2 added the trailing checksum over every byte.
pub const STATE_VERSION: u32 = 2;

/// One instance of a model behind the FMI 2.0 co-simulation interface.
pub struct Instance<M: Model> {
    /// The logger (callback, categories).
    pub log: Logger,
    state: State,
    store: Store,
    model: M,
    resources: Option<PathBuf>,
    start_time: f64,
    stop_time: Option<f64>,
    time: f64,
    init_dirty: bool,
    strings_out: Vec<CString>,
}

impl<M: Model> Instance<M> {
    /// A new instance in state instantiated.
    pub fn new(log: Logger, resources: Option<PathBuf>) -> Self {
        Instance {
            log,
            state: State::Instantiated,
            store: Store::new(M::VARIABLES),
            model: M::new(resources.clone()),
            resources,
            start_time: 0.0,
            stop_time: None,
            time: 0.0,
            init_dirty: true,
            strings_out: Vec::new(),
        }
    }

    /// The current state.
    pub fn state(&self) -> State {
        self.state
    }
    /// The current time (s).
    pub fn time(&self) -> f64 {
        self.time
    }
    /// The variable store.
    pub fn store(&self) -> &Store {
        &self.store
    }
    /// The model.
    pub fn model(&self) -> &M {
        &self.model
    }
    /// The resources directory, when known.
    pub fn resources(&self) -> Option<&PathBuf> {
        self.resources.as_ref()
    }

    /// Enter the error state (after a panic).
    pub fn set_error_state(&mut self) {
        self.state = State::Error;
    }

    /// Log an error for `func` and return `fmi2Error`.
    pub fn fail(&self, func: &str, message: &str) -> Fmi2Status {
        self.log.error(&format!("{func}: {message}"));
        Fmi2Status::Error
    }

    /// Log a call (category `logCalls`).
    pub fn log_call(&self, text: impl FnOnce() -> String) {
        if self.log.enabled(Category::Calls) {
            self.log.log(Fmi2Status::Ok, Category::Calls, &text());
        }
    }

    /// Check that `func` may be called in the current state; logs and returns `fmi2Error`
    /// otherwise.
    pub fn check_state(&self, func: &str, allowed: u32) -> Result<(), Fmi2Status> {
        if self.state as u32 & allowed != 0 {
            Ok(())
        } else {
            Err(self.fail(
                func,
                &format!(
                    "illegal call sequence: not allowed in state {}",
                    self.state.name()
                ),
            ))
        }
    }

    /// `fmi2SetDebugLogging`.
    pub fn set_debug_logging(&mut self, on: bool, categories: &[String]) -> Fmi2Status {
        match self.log.set_debug_logging(on, categories) {
            Ok(()) => Fmi2Status::Ok,
            Err(e) => self.fail("fmi2SetDebugLogging", &e),
        }
    }

    /// `fmi2SetupExperiment`.
    pub fn setup_experiment(
        &mut self,
        start_time: f64,
        stop_time: Option<f64>,
    ) -> Result<(), Fmi2Status> {
        const F: &str = "fmi2SetupExperiment";
        self.check_state(F, mask::INSTANTIATED)?;
        if !start_time.is_finite() {
            return Err(self.fail(F, &format!("startTime = {start_time} is not finite")));
        }
        if let Some(stop) = stop_time {
            if !(stop.is_finite() && stop >= start_time) {
                return Err(self.fail(F, &format!("stopTime = {stop} is not >= startTime")));
            }
        }
        self.start_time = start_time;
        self.stop_time = stop_time;
        self.time = start_time;
        Ok(())
    }

    /// `fmi2EnterInitializationMode`.
    pub fn enter_initialization_mode(&mut self) -> Result<(), Fmi2Status> {
        self.check_state("fmi2EnterInitializationMode", mask::INSTANTIATED)?;
        self.state = State::InitializationMode;
        self.init_dirty = true;
        self.time = self.start_time;
        Ok(())
    }

    fn initialize_if_dirty(&mut self, func: &str) -> Result<(), Fmi2Status> {
        if self.init_dirty {
            if let Err(e) = self.model.initialize(&mut self.store, &self.log) {
                self.log.status(e.status, &format!("{func}: {}", e.message));
                return Err(Fmi2Status::Error);
            }
            self.init_dirty = false;
        }
        Ok(())
    }

    /// `fmi2ExitInitializationMode`: builds the simulation. On failure the instance stays in
    /// initialisation mode (parameters may be corrected and the call repeated).
    pub fn exit_initialization_mode(&mut self) -> Result<(), Fmi2Status> {
        const F: &str = "fmi2ExitInitializationMode";
        self.check_state(F, mask::INIT)?;
        self.initialize_if_dirty(F)?;
        self.state = State::StepComplete;
        Ok(())
    }

    /// `fmi2Terminate`.
    pub fn terminate(&mut self) -> Result<(), Fmi2Status> {
        self.check_state("fmi2Terminate", mask::STEP)?;
        self.state = State::Terminated;
        Ok(())
    }

    /// `fmi2Reset`: back to instantiated with the start values (log settings kept).
    pub fn reset(&mut self) -> Result<(), Fmi2Status> {
        self.check_state("fmi2Reset", mask::ANY)?;
        self.model.reset();
        self.store = Store::new(M::VARIABLES);
        self.state = State::Instantiated;
        self.start_time = 0.0;
        self.stop_time = None;
        self.time = 0.0;
        self.init_dirty = true;
        self.strings_out.clear();
        Ok(())
    }

    fn phase(&self) -> Phase {
        match self.state {
            State::Instantiated => Phase::Instantiated,
            State::InitializationMode => Phase::Initialization,
            _ => Phase::Stepping,
        }
    }

    /// Resolve the value references of a getter: every one known and of type `ty`. In
    /// initialisation mode, outputs are computed first.
    pub fn prepare_get(&mut self, func: &str, ty: BaseType, vrs: &[u32]) -> Result<(), Fmi2Status> {
        self.check_state(func, mask::GET)?;
        let mut needs_outputs = false;
        for &vr in vrs {
            match self.store.lookup(vr, ty) {
                Some(v) => needs_outputs |= v.causality == Causality::Output,
                None => return Err(self.fail(func, &format!("unknown {ty} value reference {vr}"))),
            }
        }
        if needs_outputs && self.state == State::InitializationMode {
            self.initialize_if_dirty(func)?;
        }
        Ok(())
    }

    /// `fmi2GetString`: the values as C strings, valid until the next `fmi2GetString` call.
    pub fn get_strings(&mut self, vrs: &[u32]) -> Result<&[CString], Fmi2Status> {
        self.prepare_get("fmi2GetString", BaseType::String, vrs)?;
        self.strings_out.clear();
        for &vr in vrs {
            let s = self.store.string(vr).replace('\0', "\u{fffd}");
            self.strings_out.push(CString::new(s).unwrap_or_default());
        }
        Ok(&self.strings_out)
    }

    /// Set `values` (one per value reference, of type `ty`) atomically: every reference,
    /// permission and value is checked before any is written.
    pub fn set(&mut self, func: &str, ty: BaseType, vrs: &[u32], values: Vec<Value>) -> Fmi2Status {
        if let Err(s) = self.check_state(func, mask::SET) {
            return s;
        }
        let phase = self.phase();
        for (&vr, value) in vrs.iter().zip(&values) {
            let Some(var) = self.store.lookup(vr, ty) else {
                return self.fail(func, &format!("unknown {ty} value reference {vr}"));
            };
            if !var.settable(phase) {
                let why = match var.causality {
                    Causality::Output => "it is an output".to_string(),
                    _ => format!(
                        "it is a fixed parameter and the instance is in state {}",
                        self.state.name()
                    ),
                };
                return self.fail(func, &format!("cannot set {}: {why}", var.name));
            }
            if let Err(e) = var.check(value) {
                return self.fail(func, &e);
            }
        }
        self.log_call(|| {
            let items: Vec<String> = vrs
                .iter()
                .zip(&values)
                .map(|(vr, v)| format!("{}={v:?}", M::VARIABLES[*vr as usize].name))
                .collect();
            format!("{func}({})", items.join(", "))
        });
        for (&vr, value) in vrs.iter().zip(values) {
            self.store.set(vr, value);
        }
        if self.state == State::InitializationMode {
            self.init_dirty = true;
        }
        Fmi2Status::Ok
    }

    /// `fmi2DoStep`.
    pub fn do_step(&mut self, t: f64, h: f64) -> Fmi2Status {
        const F: &str = "fmi2DoStep";
        if let Err(s) = self.check_state(F, mask::STEP) {
            return s;
        }
        self.log_call(|| format!("{F}(currentCommunicationPoint={t}, communicationStepSize={h})"));
        if !(h.is_finite() && h > 0.0) {
            return self.fail(
                F,
                &format!("communicationStepSize = {h} must be finite and > 0"),
            );
        }
        let tol = 1e-9 * self.time.abs().max(1.0);
        if !t.is_finite() || (t - self.time).abs() > tol {
            return self.fail(
                F,
                &format!(
                    "currentCommunicationPoint = {t} but the FMU is at time {}",
                    self.time
                ),
            );
        }
        if let Some(stop) = self.stop_time {
            if t + h > stop + (1e-9 * stop.abs().max(1.0)).max(1e-6 * h) {
                return self.fail(F, &format!("t + h = {} is beyond stopTime = {stop}", t + h));
            }
        }
        match self.model.do_step(&mut self.store, t, h, &self.log) {
            Ok(()) => {
                self.time = t + h;
                Fmi2Status::Ok
            }
            Err(e) => {
                self.log.status(e.status, &format!("{F}: {}", e.message));
                e.status
            }
        }
    }

    /// `fmi2GetRealStatus(fmi2LastSuccessfulTime)`: the time reached by the last step.
    pub fn last_successful_time(&self) -> f64 {
        self.time
    }

    /// `fmi2GetFMUstate`: the whole instance state as versioned bytes.
    pub fn save_fmu_state(&self, out: &mut Vec<u8>) -> Result<(), Fmi2Status> {
        self.check_state("fmi2GetFMUstate", mask::GET_STATE)?;
        out.clear();
        out.extend_from_slice(&M::STATE_MAGIC);
        out.put_u32(STATE_VERSION);
        out.put_blob(guid::<M>().as_bytes());
        out.put_u8(self.state.code());
        out.put_f64(self.time);
        out.put_f64(self.start_time);
        out.put_u8(self.stop_time.is_some() as u8);
        out.put_f64(self.stop_time.unwrap_or(0.0));
        out.put_u8(self.init_dirty as u8);
        out.put_u32(self.store.values().len() as u32);
        for v in self.store.values() {
            match v {
                Value::Real(x) => {
                    out.put_u8(0);
                    out.put_f64(*x)
                }
                Value::Integer(x) => {
                    out.put_u8(1);
                    out.put_i32(*x)
                }
                Value::Boolean(x) => {
                    out.put_u8(2);
                    out.put_u8(*x as u8)
                }
                Value::String(x) => {
                    out.put_u8(3);
                    out.put_blob(x.as_bytes())
                }
            }
        }
        let mut model = Vec::new();
        self.model.save_state(&mut model);
        out.put_blob(&model);
        let checksum = fnv1a_64(out);
        out.put_u64(checksum);
        Ok(())
    }

    /// `fmi2SetFMUstate`: restore bytes written by [`Instance::save_fmu_state`] (possibly by
    /// another instance of the same FMU). On error nothing changes.
    pub fn restore_fmu_state(&mut self, bytes: &[u8]) -> Result<(), Fmi2Status> {
        const F: &str = "fmi2SetFMUstate";
        self.check_state(F, mask::SET_STATE)?;
        let parsed = parse_state::<M>(bytes).map_err(|e| self.fail(F, &e))?;
        let mut store = Store::new(M::VARIABLES);
        store.replace_all(parsed.values);
        if let Err(e) = self.model.restore_state(&store, parsed.model, &self.log) {
            return Err(self.fail(F, &e.message));
        }
        self.store = store;
        self.state = parsed.state;
        self.time = parsed.time;
        self.start_time = parsed.start_time;
        self.stop_time = parsed.stop_time;
        self.init_dirty = parsed.init_dirty;
        Ok(())
    }
}

struct ParsedState<'a> {
    state: State,
    time: f64,
    start_time: f64,
    stop_time: Option<f64>,
    init_dirty: bool,
    values: Vec<Value>,
    model: &'a [u8],
}

/// Check that `bytes` are an intact FMU state of model `M`: magic, format version, the
/// checksum over every byte (so any corruption, in the header, the variable values or the
/// model's own state, is caught here), GUID and the variable section. The model's section is
/// parsed only by [`Instance::restore_fmu_state`].
pub fn check_state_bytes<M: Model>(bytes: &[u8]) -> Result<(), String> {
    parse_state::<M>(bytes).map(|_| ())
}

/// Bytes of the trailing checksum.
const CHECKSUM_BYTES: usize = 8;

fn parse_state<M: Model>(bytes: &[u8]) -> Result<ParsedState<'_>, String> {
    let mut r = Reader::new(bytes);
    if r.take(8).ok() != Some(&M::STATE_MAGIC[..]) {
        return Err(format!(
            "not an FMU state of {} (bad magic)",
            M::MODEL_IDENTIFIER
        ));
    }
    let version = r.u32()?;
    if version != STATE_VERSION {
        return Err(format!(
            "FMU state format version {version} is not supported (expected {STATE_VERSION})"
        ));
    }
    let Some(body_len) = bytes.len().checked_sub(CHECKSUM_BYTES).filter(|&n| n >= 12) else {
        return Err(format!("FMU state truncated ({} bytes)", bytes.len()));
    };
    let (body, tail) = bytes.split_at(body_len);
    let stored = u64::from_le_bytes(tail.try_into().expect("8 bytes"));
    let computed = fnv1a_64(body);
    if stored != computed {
        return Err(format!(
            "FMU state is corrupt: checksum {stored:016x} does not match its {body_len} bytes \
             ({computed:016x})"
        ));
    }
    let mut r = Reader::new(body);
    r.take(12)?;
    let g = r.blob()?;
    if g != guid::<M>().as_bytes() {
        return Err(format!(
            "FMU state was saved by another FMU (GUID {})",
            String::from_utf8_lossy(g)
        ));
    }
    let state = State::from_code(r.u8()?).ok_or("bad state code")?;
    let time = r.f64()?;
    let start_time = r.f64()?;
    let stop_defined = r.u8()? != 0;
    let stop = r.f64()?;
    let init_dirty = r.u8()? != 0;
    let n = r.u32()? as usize;
    if n != M::VARIABLES.len() {
        return Err(format!(
            "FMU state holds {n} variables, the model has {}",
            M::VARIABLES.len()
        ));
    }
    let mut values = Vec::with_capacity(n);
    for var in M::VARIABLES {
        let v = match r.u8()? {
            0 => Value::Real(r.f64()?),
            1 => Value::Integer(r.i32()?),
            2 => Value::Boolean(r.u8()? != 0),
            3 => Value::String(
                String::from_utf8(r.blob()?.to_vec()).map_err(|_| "string not UTF-8")?,
            ),
            t => return Err(format!("bad value tag {t}")),
        };
        if v.base_type() != var.kind.base_type() {
            return Err(format!(
                "variable {} has the wrong type in the state",
                var.name
            ));
        }
        values.push(v);
    }
    let model = r.blob()?;
    r.finish()?;
    Ok(ParsedState {
        state,
        time,
        start_time,
        stop_time: stop_defined.then_some(stop),
        init_dirty,
        values,
        model,
    })
}

/// The GUID of model `M`: a 128-bit FNV-1a hash of its identifier, variable table, units and
/// enumerations, formatted as `{8-4-4-4-12}`. Both the generated `modelDescription.xml` and the
/// check in `fmi2Instantiate` use it, so they agree by construction.
pub fn guid<M: Model>() -> String {
    let text = format!(
        "{}|{:?}|{:?}|{:?}",
        M::MODEL_IDENTIFIER,
        M::VARIABLES,
        M::UNITS,
        M::ENUMERATIONS
    );
    let h = fnv1a_128(text.as_bytes());
    let x = format!("{h:032x}");
    format!(
        "{{{}-{}-{}-{}-{}}}",
        &x[0..8],
        &x[8..12],
        &x[12..16],
        &x[16..20],
        &x[20..32]
    )
}

/// FNV-1a, 64 bits: the checksum of FMU states. Every step is a bijection of the running hash,
/// so any change confined to one byte (every single-bit flip) changes the result.
pub fn fnv1a_64(bytes: &[u8]) -> u64 {
    const OFFSET: u64 = 0xcbf2_9ce4_8422_2325;
    const PRIME: u64 = 0x0000_0100_0000_01b3;
    bytes
        .iter()
        .fold(OFFSET, |h, &b| (h ^ b as u64).wrapping_mul(PRIME))
}

fn fnv1a_128(bytes: &[u8]) -> u128 {
    const OFFSET: u128 = 0x6c62272e07bb014262b821756295c58d;
    const PRIME: u128 = 0x0000000001000000000000000000013B;
    bytes
        .iter()
        .fold(OFFSET, |h, &b| (h ^ b as u128).wrapping_mul(PRIME))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fmi2::variables::{
        Causality::{Input, Output, Parameter},
        Kind,
        Variability::{Continuous, Fixed, Tunable},
    };

    /// A toy model: `y += k * u * h` per step; `k` fixed, `g` tunable; fails on `u > 100`.
    struct Toy {
        y: f64,
        built: bool,
    }

    const fn r(
        vr: u32,
        name: &'static str,
        c: Causality,
        v: crate::fmi2::Variability,
        start: Option<f64>,
    ) -> Variable {
        Variable {
            name,
            vr,
            causality: c,
            variability: v,
            kind: Kind::Real {
                unit: "",
                start,
                min: None,
                max: None,
            },
            description: "",
        }
    }

    static TOY_VARS: &[Variable] = &[
        r(0, "u", Input, Continuous, Some(1.0)),
        r(1, "y", Output, Continuous, None),
        r(2, "k", Parameter, Fixed, Some(2.0)),
        r(3, "g", Parameter, Tunable, Some(0.0)),
        Variable {
            name: "s",
            vr: 4,
            causality: Parameter,
            variability: Fixed,
            kind: Kind::String { start: "abc" },
            description: "",
        },
    ];

    impl Model for Toy {
        const MODEL_IDENTIFIER: &'static str = "Toy";
        const DESCRIPTION: &'static str = "toy";
        const VARIABLES: &'static [Variable] = TOY_VARS;
        const UNITS: &'static [UnitDefinition] = &[];
        const ENUMERATIONS: &'static [&'static EnumType] = &[];
        const DEFAULT_EXPERIMENT: DefaultExperiment = DefaultExperiment {
            start_time: 0.0,
            stop_time: 1.0,
            step_size: 0.1,
        };
        const STATE_MAGIC: [u8; 8] = *b"TOYSTATE";
        fn new(_: Option<PathBuf>) -> Self {
            Toy {
                y: 0.0,
                built: false,
            }
        }
        fn initialize(&mut self, store: &mut Store, _: &Logger) -> Result<(), ModelError> {
            self.built = true;
            self.y = store.real(2);
            store.set_real(1, self.y);
            Ok(())
        }
        fn do_step(
            &mut self,
            store: &mut Store,
            _t: f64,
            h: f64,
            _: &Logger,
        ) -> Result<(), ModelError> {
            let u = store.real(0);
            if u > 100.0 {
                return Err(ModelError::discard("u too large"));
            }
            self.y += store.real(2) * u * h + store.real(3);
            store.set_real(1, self.y);
            Ok(())
        }
        fn reset(&mut self) {
            *self = Toy::new(None);
        }
        fn save_state(&self, out: &mut Vec<u8>) {
            out.put_u8(self.built as u8);
            out.put_f64(self.y);
        }
        fn restore_state(&mut self, _: &Store, b: &[u8], _: &Logger) -> Result<(), ModelError> {
            let mut r = Reader::new(b);
            let built = r.u8().map_err(ModelError::error)? != 0;
            let y = r.f64().map_err(ModelError::error)?;
            r.finish().map_err(ModelError::error)?;
            self.built = built;
            self.y = y;
            Ok(())
        }
    }

    fn toy() -> Instance<Toy> {
        Instance::new(Logger::new(None, std::ptr::null_mut(), "toy", false), None)
    }

    fn get(i: &mut Instance<Toy>, vr: u32) -> f64 {
        i.prepare_get("get", BaseType::Real, &[vr]).unwrap();
        i.store().real(vr)
    }

    fn set(i: &mut Instance<Toy>, vr: u32, v: f64) -> Fmi2Status {
        i.set("set", BaseType::Real, &[vr], vec![Value::Real(v)])
    }

    fn initialised() -> Instance<Toy> {
        let mut i = toy();
        i.setup_experiment(0.0, Some(10.0)).unwrap();
        i.enter_initialization_mode().unwrap();
        i.exit_initialization_mode().unwrap();
        i
    }

    #[test]
    fn normal_sequence() {
        let mut i = toy();
        assert_eq!(i.state(), State::Instantiated);
        assert_eq!(set(&mut i, 2, 3.0), Fmi2Status::Ok);
        i.setup_experiment(1.0, None).unwrap();
        i.enter_initialization_mode().unwrap();
        // Outputs are computed when read in initialisation mode.
        assert_eq!(get(&mut i, 1), 3.0);
        assert_eq!(set(&mut i, 2, 4.0), Fmi2Status::Ok);
        assert_eq!(get(&mut i, 1), 4.0);
        i.exit_initialization_mode().unwrap();
        assert_eq!(i.state(), State::StepComplete);
        assert_eq!(i.do_step(1.0, 0.5), Fmi2Status::Ok);
        assert_eq!(get(&mut i, 1), 4.0 + 4.0 * 0.5);
        assert_eq!(i.time(), 1.5);
        i.terminate().unwrap();
        assert_eq!(i.state(), State::Terminated);
        assert_eq!(get(&mut i, 1), 6.0);
        i.reset().unwrap();
        assert_eq!(i.state(), State::Instantiated);
        assert_eq!(i.store().real(2), 2.0);
    }

    #[test]
    fn illegal_call_sequences_change_nothing() {
        let mut i = toy();
        assert_eq!(i.do_step(0.0, 0.1), Fmi2Status::Error);
        assert!(i.exit_initialization_mode().is_err());
        assert!(i.terminate().is_err());
        assert!(i.prepare_get("fmi2GetReal", BaseType::Real, &[1]).is_err());
        assert_eq!(i.state(), State::Instantiated);
        let mut i = initialised();
        assert!(i.setup_experiment(0.0, None).is_err());
        assert!(i.enter_initialization_mode().is_err());
        assert!(i.exit_initialization_mode().is_err());
        assert_eq!(i.state(), State::StepComplete);
        i.terminate().unwrap();
        assert_eq!(i.do_step(0.0, 0.1), Fmi2Status::Error);
        assert_eq!(set(&mut i, 0, 1.0), Fmi2Status::Error);
        assert_eq!(i.state(), State::Terminated);
    }

    #[test]
    fn set_checks_are_atomic() {
        let mut i = initialised();
        // Fixed parameter after initialisation, output, unknown reference, wrong type, NaN.
        assert_eq!(set(&mut i, 2, 5.0), Fmi2Status::Error);
        assert_eq!(set(&mut i, 1, 5.0), Fmi2Status::Error);
        assert_eq!(set(&mut i, 99, 5.0), Fmi2Status::Error);
        assert_eq!(set(&mut i, 4, 5.0), Fmi2Status::Error);
        assert_eq!(set(&mut i, 0, f64::NAN), Fmi2Status::Error);
        assert_eq!(set(&mut i, 0, f64::INFINITY), Fmi2Status::Error);
        let s = i.set(
            "fmi2SetReal",
            BaseType::Real,
            &[0, 0],
            vec![Value::Real(7.0), Value::Real(f64::NAN)],
        );
        assert_eq!(s, Fmi2Status::Error);
        assert_eq!(i.store().real(0), 1.0, "nothing set by a refused call");
        // Tunable parameters and inputs are settable while stepping.
        assert_eq!(set(&mut i, 3, 0.5), Fmi2Status::Ok);
        assert_eq!(set(&mut i, 0, 2.0), Fmi2Status::Ok);
        assert!(i.prepare_get("g", BaseType::Real, &[77]).is_err());
        assert!(i.prepare_get("g", BaseType::Integer, &[0]).is_err());
        assert_eq!(i.state(), State::StepComplete);
    }

    #[test]
    fn step_arguments_are_checked() {
        let mut i = initialised();
        assert_eq!(i.do_step(0.0, 0.0), Fmi2Status::Error);
        assert_eq!(i.do_step(0.0, -1.0), Fmi2Status::Error);
        assert_eq!(i.do_step(0.0, f64::NAN), Fmi2Status::Error);
        assert_eq!(i.do_step(0.5, 0.1), Fmi2Status::Error, "wrong time");
        assert_eq!(i.do_step(0.0, 11.0), Fmi2Status::Error, "beyond stop time");
        assert_eq!(set(&mut i, 0, 1000.0), Fmi2Status::Ok);
        assert_eq!(i.do_step(0.0, 0.1), Fmi2Status::Discard);
        assert_eq!(i.time(), 0.0);
        assert_eq!(set(&mut i, 0, 1.0), Fmi2Status::Ok);
        assert_eq!(i.do_step(0.0, 0.1), Fmi2Status::Ok);
        assert_eq!(i.state(), State::StepComplete);
    }

    #[test]
    fn fmu_state_round_trip() {
        let mut a = initialised();
        assert_eq!(a.do_step(0.0, 0.25), Fmi2Status::Ok);
        let mut bytes = Vec::new();
        a.save_fmu_state(&mut bytes).unwrap();
        assert_eq!(a.do_step(0.25, 0.25), Fmi2Status::Ok);
        let y1 = get(&mut a, 1);
        a.restore_fmu_state(&bytes).unwrap();
        assert_eq!(a.time(), 0.25);
        assert_eq!(a.do_step(0.25, 0.25), Fmi2Status::Ok);
        assert_eq!(get(&mut a, 1).to_bits(), y1.to_bits());
        // Into a fresh instance still in state instantiated.
        let mut b = toy();
        b.restore_fmu_state(&bytes).unwrap();
        assert_eq!(b.state(), State::StepComplete);
        assert_eq!(b.do_step(0.25, 0.25), Fmi2Status::Ok);
        assert_eq!(get(&mut b, 1).to_bits(), y1.to_bits());
        // Corrupted states are refused and change nothing.
        let mut bad = bytes.clone();
        bad[0] ^= 1;
        assert!(b.restore_fmu_state(&bad).is_err());
        assert!(b.restore_fmu_state(&bytes[..bytes.len() - 1]).is_err());
        let mut longer = bytes.clone();
        longer.push(0);
        assert!(b.restore_fmu_state(&longer).is_err());
        let mut version = bytes.clone();
        version[8] = 99;
        assert!(b.restore_fmu_state(&version).is_err());
        assert_eq!(b.time(), 0.5);
    }

    /// Every single-bit flip anywhere in a state (header, variables, model section, checksum)
    /// is refused, by the byte check of deserialisation and by restoring, and changes nothing.
    #[test]
    fn every_bit_flip_is_refused() {
        let mut a = initialised();
        assert_eq!(a.do_step(0.0, 0.25), Fmi2Status::Ok);
        let mut bytes = Vec::new();
        a.save_fmu_state(&mut bytes).unwrap();
        check_state_bytes::<Toy>(&bytes).unwrap();
        assert_eq!(a.do_step(0.25, 0.25), Fmi2Status::Ok);
        let y = get(&mut a, 1);
        for bit in 0..bytes.len() * 8 {
            let mut bad = bytes.clone();
            bad[bit / 8] ^= 1 << (bit % 8);
            assert!(
                check_state_bytes::<Toy>(&bad).is_err(),
                "bit {bit} accepted"
            );
            assert!(a.restore_fmu_state(&bad).is_err(), "bit {bit} restored");
        }
        assert_eq!(a.time(), 0.5);
        assert_eq!(get(&mut a, 1).to_bits(), y.to_bits());
        a.restore_fmu_state(&bytes).unwrap();
        assert_eq!(a.time(), 0.25);
        assert_eq!(fnv1a_64(b""), 0xcbf2_9ce4_8422_2325);
        assert_eq!(fnv1a_64(b"a"), 0xaf63_dc4c_8601_ec8c);
    }

    #[test]
    fn guid_is_stable_and_well_formed() {
        let g = guid::<Toy>();
        assert_eq!(g, guid::<Toy>());
        assert_eq!(g.len(), 38);
        assert!(g.starts_with('{') && g.ends_with('}'));
        assert_eq!(g.matches('-').count(), 4);
    }
}
