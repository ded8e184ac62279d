//! Logging through the master's `fmi2CallbackLogger`, by category.
//!
//! The logger is a printf-style variadic function: every message is passed as the format string
//! with `%` escaped as `%%` (and no further argument), so masters that format it (fmpy, most C
//! masters) print it intact.
//!
//! Categories (declared in `modelDescription.xml`): the status categories (`logStatusWarning`,
//! `logStatusDiscard`, `logStatusError`, `logStatusFatal`: why a call did not return fmi2OK) are
//! on from the start, whatever `loggingOn` says, and can be switched off only by naming them in
//! `fmi2SetDebugLogging`. The debug categories (`logCalls`, `logModel`) follow `loggingOn` of
//! `fmi2Instantiate` and `fmi2SetDebugLogging` (with no category named: all debug categories).

use super::types::{Fmi2CallbackLogger, Fmi2ComponentEnvironment, Fmi2Status};
use std::ffi::CString;

/// A log category.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Category {
    /// Calls that returned fmi2Warning.
    StatusWarning,
    /// Calls that returned fmi2Discard.
    StatusDiscard,
    /// Calls that returned fmi2Error.
    StatusError,
    /// Calls that returned fmi2Fatal.
    StatusFatal,
    /// Every FMI call with its arguments.
    Calls,
    /// What the model and its solver do (world built, substeps, ...).
    Model,
}

impl Category {
    /// All categories, in declaration order.
    pub const ALL: [Category; 6] = [
        Category::StatusWarning,
        Category::StatusDiscard,
        Category::StatusError,
        Category::StatusFatal,
        Category::Calls,
        Category::Model,
    ];
    /// The category's name in `modelDescription.xml`.
    pub fn name(self) -> &'static str {
        match self {
            Category::StatusWarning => "logStatusWarning",
            Category::StatusDiscard => "logStatusDiscard",
            Category::StatusError => "logStatusError",
            Category::StatusFatal => "logStatusFatal",
            Category::Calls => "logCalls",
            Category::Model => "logModel",
        }
    }
    /// What it holds.
    pub fn description(self) -> &'static str {
        match self {
            Category::StatusWarning => "Warnings (on unless switched off by name)",
            Category::StatusDiscard => {
                "Why fmi2DoStep returned fmi2Discard (on unless switched off by name)"
            }
            Category::StatusError => {
                "Why a call returned fmi2Error (on unless switched off by name)"
            }
            Category::StatusFatal => {
                "Why a call returned fmi2Fatal (on unless switched off by name)"
            }
            Category::Calls => "Debug: every FMI call with its arguments",
            Category::Model => "Debug: what the model does",
        }
    }
    /// True for the debug categories (`logCalls`, `logModel`), false for the status ones.
    pub fn is_debug(self) -> bool {
        matches!(self, Category::Calls | Category::Model)
    }
    /// The category by name.
    pub fn from_name(name: &str) -> Option<Category> {
        Category::ALL.into_iter().find(|c| c.name() == name)
    }
    /// The category of a message with this status.
    pub fn for_status(status: Fmi2Status) -> Category {
        match status {
            Fmi2Status::Warning => Category::StatusWarning,
            Fmi2Status::Discard => Category::StatusDiscard,
            Fmi2Status::Error => Category::StatusError,
            Fmi2Status::Fatal => Category::StatusFatal,
            Fmi2Status::Ok | Fmi2Status::Pending => Category::Model,
        }
    }
}

/// Escape a message for a printf-style format string: `%` → `%%`; NUL bytes (which would cut
/// the C string) become U+FFFD.
pub fn escape_percent(message: &str) -> String {
    message.replace('%', "%%").replace('\0', "\u{fffd}")
}

/// The logger of one instance: the master's callback and the enabled categories.
#[derive(Debug)]
pub struct Logger {
    callback: Option<Fmi2CallbackLogger>,
    environment: Fmi2ComponentEnvironment,
    instance_name: CString,
    enabled: [bool; Category::ALL.len()],
}

impl Logger {
    /// A logger calling `callback` (may be `None`); debug logging `logging_on`.
    pub fn new(
        callback: Option<Fmi2CallbackLogger>,
        environment: Fmi2ComponentEnvironment,
        instance_name: &str,
        logging_on: bool,
    ) -> Self {
        let mut logger = Logger {
            callback,
            environment,
            instance_name: CString::new(escape_nul(instance_name)).unwrap_or_default(),
            enabled: Category::ALL.map(|c| !c.is_debug()),
        };
        logger.set_all(logging_on);
        logger
    }

    fn set_all(&mut self, on: bool) {
        for c in Category::ALL {
            if c.is_debug() {
                self.enabled[c as usize] = on;
            }
        }
    }

    /// `fmi2SetDebugLogging`: with no category, every debug category on/off (the status
    /// categories are not debug logging and stay as they are); otherwise on/off for the named
    /// ones. An unknown name is an error (nothing changed).
    pub fn set_debug_logging(&mut self, on: bool, categories: &[String]) -> Result<(), String> {
        if categories.is_empty() {
            self.set_all(on);
            return Ok(());
        }
        let mut parsed = Vec::with_capacity(categories.len());
        for name in categories {
            parsed.push(Category::from_name(name).ok_or_else(|| {
                format!(
                    "unknown log category \"{name}\" (known: {})",
                    Category::ALL.map(Category::name).join(", ")
                )
            })?);
        }
        for c in parsed {
            self.enabled[c as usize] = on;
        }
        Ok(())
    }

    /// True when messages of `category` are delivered.
    pub fn enabled(&self, category: Category) -> bool {
        self.enabled[category as usize] && self.callback.is_some()
    }

    /// Deliver `message` with `status` in `category` (if enabled).
    pub fn log(&self, status: Fmi2Status, category: Category, message: &str) {
        if !self.enabled(category) {
            return;
        }
        let Some(callback) = self.callback else {
            return;
        };
        let Ok(text) = CString::new(escape_percent(message)) else {
            return;
        };
        let Ok(cat) = CString::new(category.name()) else {
            return;
        };
        // SAFETY: the master guaranteed the callback valid for the instance's lifetime; every
        // string is NUL-terminated and outlives the call; the format string has no
        // conversion left, so no variadic argument is read.
        unsafe {
            callback(
                self.environment,
                self.instance_name.as_ptr(),
                status,
                cat.as_ptr(),
                text.as_ptr(),
            )
        };
    }

    /// Log a message whose category follows from its status.
    pub fn status(&self, status: Fmi2Status, message: &str) {
        self.log(status, Category::for_status(status), message);
    }
    /// Log an error.
    pub fn error(&self, message: &str) {
        self.status(Fmi2Status::Error, message);
    }
    /// Log a warning.
    pub fn warning(&self, message: &str) {
        self.status(Fmi2Status::Warning, message);
    }
    /// Log model information (category `logModel`, status OK).
    pub fn info(&self, message: &str) {
        self.log(Fmi2Status::Ok, Category::Model, message);
    }
}

fn escape_nul(s: &str) -> String {
    s.replace('\0', "\u{fffd}")
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::ffi::CStr;
    use std::os::raw::c_char;
    use std::sync::Mutex;

    static SEEN: Mutex<Vec<(i32, String, String)>> = Mutex::new(Vec::new());

    /// # Safety
    ///
    /// `category` and `message` are NUL-terminated strings alive during the call (as
    /// [`Logger::log`] passes them).
    unsafe extern "C" fn record(
        _env: Fmi2ComponentEnvironment,
        _name: *const c_char,
        status: Fmi2Status,
        category: *const c_char,
        message: *const c_char,
    ) {
        // SAFETY: both are NUL-terminated `CString`s of `Logger::log`, alive during the call.
        let (c, m) = unsafe { (CStr::from_ptr(category), CStr::from_ptr(message)) };
        let (c, m) = (
            c.to_string_lossy().into_owned(),
            m.to_string_lossy().into_owned(),
        );
        SEEN.lock().unwrap().push((status as i32, c, m));
    }

    /// Rust cannot define a C-variadic function on stable; the non-variadic recorder is called
    /// through the variadic pointer type, which the x86-64 and AArch64 C ABIs allow for a
    /// callee that reads no variadic argument.
    fn recorder() -> Fmi2CallbackLogger {
        type Fixed = unsafe extern "C" fn(
            Fmi2ComponentEnvironment,
            *const c_char,
            Fmi2Status,
            *const c_char,
            *const c_char,
        );
        // SAFETY: `Fixed` and the logger type have the same leading parameters; the C ABI of
        // x86-64 and AArch64 passes them identically to a variadic callee, and `record` reads
        // no variadic argument (see above).
        unsafe { std::mem::transmute::<Fixed, Fmi2CallbackLogger>(record as Fixed) }
    }

    #[test]
    fn percent_is_escaped() {
        assert_eq!(escape_percent("100% of 5%d"), "100%% of 5%%d");
        assert_eq!(escape_percent("no percent"), "no percent");
        assert_eq!(escape_percent("%%"), "%%%%");
        assert_eq!(escape_percent("a\0b"), "a\u{fffd}b");
    }

    #[test]
    fn categories_filter_messages() {
        SEEN.lock().unwrap().clear();
        let mut log = Logger::new(Some(recorder()), std::ptr::null_mut(), "i", false);
        log.info("hidden");
        log.error("shown 50%");
        log.warning("warning on");
        assert!(log
            .set_debug_logging(true, &["logModel".to_string()])
            .is_ok());
        log.info("model on");
        log.log(Fmi2Status::Ok, Category::Calls, "calls still off");
        log.set_debug_logging(false, &["logStatusWarning".to_string()])
            .unwrap();
        log.warning("warning off by name");
        assert!(log.set_debug_logging(true, &["nope".to_string()]).is_err());
        log.set_debug_logging(false, &["logStatusError".to_string()])
            .unwrap();
        log.error("error off by name");
        let seen = SEEN.lock().unwrap().clone();
        assert_eq!(
            seen,
            vec![
                (3, "logStatusError".into(), "shown 50%%".into()),
                (1, "logStatusWarning".into(), "warning on".into()),
                (0, "logModel".into(), "model on".into()),
            ]
        );
    }
}
