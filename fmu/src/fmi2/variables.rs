//! The variable table a model declares (names, value references, causality, variability, units,
//! start values, ranges, descriptions) and the store of current values indexed by value
//! reference. Both `modelDescription.xml` ([`super::xml`]) and the compiled getters/setters
//! ([`super::instance`]) read the same table, so they cannot disagree.
//!
//! A model declares its variables once with [`fmi2_variables!`](crate::fmi2_variables), which
//! numbers the rows (value reference = row) and generates the table and one value-reference
//! constant per row; the XML, the docs table ([`super::docs`]) and the model's code all follow
//! from it.

use std::fmt;

/// FMI 2.0 causality of a variable.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Causality {
    /// Set by the master before initialisation (or while stepping, when tunable).
    Parameter,
    /// Set by the master at every communication point.
    Input,
    /// Computed by the FMU.
    Output,
}

impl Causality {
    /// The XML attribute value.
    pub fn as_str(self) -> &'static str {
        match self {
            Causality::Parameter => "parameter",
            Causality::Input => "input",
            Causality::Output => "output",
        }
    }
}

/// FMI 2.0 variability of a variable.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Variability {
    /// Settable only before the end of initialisation.
    Fixed,
    /// Settable between communication steps as well.
    Tunable,
    /// Changes only at communication points (Integer, Boolean, String).
    Discrete,
    /// A Real that changes continuously in time.
    Continuous,
}

impl Variability {
    /// The XML attribute value.
    pub fn as_str(self) -> &'static str {
        match self {
            Variability::Fixed => "fixed",
            Variability::Tunable => "tunable",
            Variability::Discrete => "discrete",
            Variability::Continuous => "continuous",
        }
    }
}

/// One item of an enumeration type.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EnumItem {
    /// Item name.
    pub name: &'static str,
    /// Its integer value.
    pub value: i32,
    /// What it means.
    pub description: &'static str,
}

/// An enumeration type (`TypeDefinitions/SimpleType/Enumeration`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EnumType {
    /// Type name, referenced by `declaredType`.
    pub name: &'static str,
    /// What it is.
    pub description: &'static str,
    /// Its items.
    pub items: &'static [EnumItem],
}

/// The type of a variable with its start value and range.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Kind {
    /// A Real with a unit (a name from the model's unit table, `""` for dimensionless),
    /// start value (`None` for calculated outputs) and optional range.
    Real {
        /// Unit name, `""` when dimensionless.
        unit: &'static str,
        /// Start value (`None` for calculated outputs).
        start: Option<f64>,
        /// Smallest allowed value.
        min: Option<f64>,
        /// Largest allowed value.
        max: Option<f64>,
    },
    /// An Integer.
    Integer {
        /// Start value (`None` for calculated outputs).
        start: Option<i32>,
        /// Smallest allowed value.
        min: Option<i32>,
        /// Largest allowed value.
        max: Option<i32>,
    },
    /// An Enumeration (set and read through the Integer functions).
    Enumeration {
        /// The declared type.
        ty: &'static EnumType,
        /// Start value.
        start: i32,
    },
    /// A Boolean.
    Boolean {
        /// Start value.
        start: bool,
    },
    /// A String.
    String {
        /// Start value.
        start: &'static str,
    },
}

/// The base type a getter/setter function deals with.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BaseType {
    /// `fmi2GetReal` / `fmi2SetReal`.
    Real,
    /// `fmi2GetInteger` / `fmi2SetInteger` (Integer and Enumeration variables).
    Integer,
    /// `fmi2GetBoolean` / `fmi2SetBoolean`.
    Boolean,
    /// `fmi2GetString` / `fmi2SetString`.
    String,
}

impl fmt::Display for BaseType {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            BaseType::Real => "Real",
            BaseType::Integer => "Integer",
            BaseType::Boolean => "Boolean",
            BaseType::String => "String",
        })
    }
}

impl Kind {
    /// The getter/setter family of this kind.
    pub fn base_type(&self) -> BaseType {
        match self {
            Kind::Real { .. } => BaseType::Real,
            Kind::Integer { .. } | Kind::Enumeration { .. } => BaseType::Integer,
            Kind::Boolean { .. } => BaseType::Boolean,
            Kind::String { .. } => BaseType::String,
        }
    }
}

/// One scalar variable of the model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Variable {
    /// Flat name.
    pub name: &'static str,
    /// Value reference (unique over the whole table; equal to the variable's index).
    pub vr: u32,
    /// Causality.
    pub causality: Causality,
    /// Variability.
    pub variability: Variability,
    /// Type, start value, unit and range.
    pub kind: Kind,
    /// What it means, with its unit.
    pub description: &'static str,
}

impl Variable {
    /// A Real variable (value reference 0 until placed by [`fmi2_variables!`]).
    ///
    /// [`fmi2_variables!`]: crate::fmi2_variables
    #[allow(clippy::too_many_arguments)]
    pub const fn real(
        name: &'static str,
        causality: Causality,
        variability: Variability,
        unit: &'static str,
        start: Option<f64>,
        min: Option<f64>,
        max: Option<f64>,
        description: &'static str,
    ) -> Variable {
        Variable {
            name,
            vr: 0,
            causality,
            variability,
            kind: Kind::Real {
                unit,
                start,
                min,
                max,
            },
            description,
        }
    }
    /// An Integer variable.
    pub const fn integer(
        name: &'static str,
        causality: Causality,
        variability: Variability,
        start: Option<i32>,
        min: Option<i32>,
        max: Option<i32>,
        description: &'static str,
    ) -> Variable {
        Variable {
            name,
            vr: 0,
            causality,
            variability,
            kind: Kind::Integer { start, min, max },
            description,
        }
    }
    /// An Enumeration variable of type `ty`.
    pub const fn enumeration(
        name: &'static str,
        causality: Causality,
        variability: Variability,
        ty: &'static EnumType,
        start: i32,
        description: &'static str,
    ) -> Variable {
        Variable {
            name,
            vr: 0,
            causality,
            variability,
            kind: Kind::Enumeration { ty, start },
            description,
        }
    }
    /// A Boolean variable.
    pub const fn boolean(
        name: &'static str,
        causality: Causality,
        variability: Variability,
        start: bool,
        description: &'static str,
    ) -> Variable {
        Variable {
            name,
            vr: 0,
            causality,
            variability,
            kind: Kind::Boolean { start },
            description,
        }
    }
    /// A String variable.
    pub const fn string(
        name: &'static str,
        causality: Causality,
        variability: Variability,
        start: &'static str,
        description: &'static str,
    ) -> Variable {
        Variable {
            name,
            vr: 0,
            causality,
            variability,
            kind: Kind::String { start },
            description,
        }
    }
    /// This variable with value reference `vr`.
    pub const fn at(self, vr: u32) -> Variable {
        Variable { vr, ..self }
    }

    /// True when the master may set this variable in the given phase.
    pub fn settable(&self, phase: Phase) -> bool {
        match self.causality {
            Causality::Output => false,
            Causality::Input => true,
            Causality::Parameter => match phase {
                Phase::Instantiated | Phase::Initialization => true,
                Phase::Stepping => self.variability == Variability::Tunable,
            },
        }
    }

    /// The start value as a store value (calculated outputs start at zero / false / "").
    pub fn start_value(&self) -> Value {
        match self.kind {
            Kind::Real { start, .. } => Value::Real(start.unwrap_or(0.0)),
            Kind::Integer { start, .. } => Value::Integer(start.unwrap_or(0)),
            Kind::Enumeration { start, .. } => Value::Integer(start),
            Kind::Boolean { start } => Value::Boolean(start),
            Kind::String { start } => Value::String(start.to_string()),
        }
    }

    /// Check that `value` is allowed for this variable (finite, in range, an item of the
    /// enumeration); the message names the variable.
    pub fn check(&self, value: &Value) -> Result<(), String> {
        match (&self.kind, value) {
            (Kind::Real { min, max, .. }, Value::Real(v)) => {
                if !v.is_finite() {
                    return Err(format!("{} = {v} is not finite", self.name));
                }
                if min.is_some_and(|m| *v < m) || max.is_some_and(|m| *v > m) {
                    return Err(format!(
                        "{} = {v} is outside [{}, {}]",
                        self.name,
                        min.map_or("-inf".into(), |m| m.to_string()),
                        max.map_or("inf".into(), |m| m.to_string())
                    ));
                }
                Ok(())
            }
            (Kind::Integer { min, max, .. }, Value::Integer(v)) => {
                if min.is_some_and(|m| *v < m) || max.is_some_and(|m| *v > m) {
                    return Err(format!("{} = {v} is out of range", self.name));
                }
                Ok(())
            }
            (Kind::Enumeration { ty, .. }, Value::Integer(v)) => {
                if ty.items.iter().any(|i| i.value == *v) {
                    Ok(())
                } else {
                    Err(format!("{} = {v} is not an item of {}", self.name, ty.name))
                }
            }
            (Kind::Boolean { .. }, Value::Boolean(_)) | (Kind::String { .. }, Value::String(_)) => {
                Ok(())
            }
            _ => Err(format!(
                "{} is of type {}, not {}",
                self.name,
                self.kind.base_type(),
                value.base_type()
            )),
        }
    }
}

/// The phase of an instance, as far as setting variables is concerned.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Phase {
    /// After `fmi2Instantiate`, before `fmi2EnterInitializationMode`.
    Instantiated,
    /// Between `fmi2EnterInitializationMode` and `fmi2ExitInitializationMode`.
    Initialization,
    /// After initialisation (step complete).
    Stepping,
}

/// A variable's current value.
#[derive(Debug, Clone, PartialEq)]
pub enum Value {
    /// Real.
    Real(f64),
    /// Integer or Enumeration.
    Integer(i32),
    /// Boolean.
    Boolean(bool),
    /// String.
    String(String),
}

impl Value {
    /// The getter/setter family of this value.
    pub fn base_type(&self) -> BaseType {
        match self {
            Value::Real(_) => BaseType::Real,
            Value::Integer(_) => BaseType::Integer,
            Value::Boolean(_) => BaseType::Boolean,
            Value::String(_) => BaseType::String,
        }
    }
    /// Bit-exact equality (NaN-safe, distinguishes -0.0 from 0.0).
    pub fn same_bits(&self, other: &Value) -> bool {
        match (self, other) {
            (Value::Real(a), Value::Real(b)) => a.to_bits() == b.to_bits(),
            _ => self == other,
        }
    }
}

/// The current values of every variable, indexed by value reference.
#[derive(Debug, Clone, PartialEq)]
pub struct Store {
    table: &'static [Variable],
    values: Vec<Value>,
}

impl Store {
    /// A store holding the start values of `table`.
    pub fn new(table: &'static [Variable]) -> Self {
        Store {
            table,
            values: table.iter().map(Variable::start_value).collect(),
        }
    }
    /// The variable table.
    pub fn table(&self) -> &'static [Variable] {
        self.table
    }
    /// All values, in table order.
    pub fn values(&self) -> &[Value] {
        &self.values
    }
    /// Replace every value (same count and types as the table; checked by the caller).
    pub fn replace_all(&mut self, values: Vec<Value>) {
        debug_assert_eq!(values.len(), self.values.len());
        self.values = values;
    }
    /// The variable with value reference `vr` if its base type is `ty`.
    pub fn lookup(&self, vr: u32, ty: BaseType) -> Option<&'static Variable> {
        self.table
            .get(vr as usize)
            .filter(|v| v.vr == vr && v.kind.base_type() == ty)
    }
    /// The value of `vr`.
    pub fn get(&self, vr: u32) -> &Value {
        &self.values[vr as usize]
    }
    /// Set the value of `vr` (no checks: the caller checked it).
    pub fn set(&mut self, vr: u32, value: Value) {
        self.values[vr as usize] = value;
    }
    /// The Real value of `vr` (panics if `vr` is not a Real: a bug in the model).
    pub fn real(&self, vr: u32) -> f64 {
        match &self.values[vr as usize] {
            Value::Real(v) => *v,
            v => panic!("variable {vr} is not a Real: {v:?}"),
        }
    }
    /// The Integer value of `vr`.
    pub fn integer(&self, vr: u32) -> i32 {
        match &self.values[vr as usize] {
            Value::Integer(v) => *v,
            v => panic!("variable {vr} is not an Integer: {v:?}"),
        }
    }
    /// The Boolean value of `vr`.
    pub fn boolean(&self, vr: u32) -> bool {
        match &self.values[vr as usize] {
            Value::Boolean(v) => *v,
            v => panic!("variable {vr} is not a Boolean: {v:?}"),
        }
    }
    /// The String value of `vr`.
    pub fn string(&self, vr: u32) -> &str {
        match &self.values[vr as usize] {
            Value::String(v) => v,
            v => panic!("variable {vr} is not a String: {v:?}"),
        }
    }
    /// Set a Real.
    pub fn set_real(&mut self, vr: u32, v: f64) {
        self.set(vr, Value::Real(v));
    }
    /// Set an Integer.
    pub fn set_integer(&mut self, vr: u32, v: i32) {
        self.set(vr, Value::Integer(v));
    }
}

/// A unit with its SI base-unit exponents (`UnitDefinitions/Unit/BaseUnit`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UnitDefinition {
    /// Unit name as used in the `unit` attribute.
    pub name: &'static str,
    /// Exponent of kg.
    pub kg: i32,
    /// Exponent of m.
    pub m: i32,
    /// Exponent of s.
    pub s: i32,
}

/// Check a variable table: value references equal to indices, unique names, every unit
/// defined, start values valid. Returns the first problem.
pub fn check_table(table: &[Variable], units: &[UnitDefinition]) -> Result<(), String> {
    for (i, v) in table.iter().enumerate() {
        if v.vr as usize != i {
            return Err(format!("{}: value reference {} != index {i}", v.name, v.vr));
        }
        if table[..i].iter().any(|w| w.name == v.name) {
            return Err(format!("{}: duplicate name", v.name));
        }
        if let Kind::Real { unit, .. } = v.kind {
            if !unit.is_empty() && !units.iter().any(|u| u.name == unit) {
                return Err(format!("{}: unit {unit} not defined", v.name));
            }
        }
        let calculated = v.causality == Causality::Output;
        match v.kind {
            Kind::Real { start, .. } if start.is_some() == calculated => {
                return Err(format!(
                    "{}: start value must be given unless output",
                    v.name
                ))
            }
            Kind::Integer { start, .. } if start.is_some() == calculated => {
                return Err(format!(
                    "{}: start value must be given unless output",
                    v.name
                ))
            }
            _ => {}
        }
        if !calculated {
            v.check(&v.start_value())
                .map_err(|e| format!("start value: {e}"))?;
        }
        let ok = matches!(
            (v.causality, v.variability, v.kind.base_type()),
            (
                Causality::Parameter,
                Variability::Fixed | Variability::Tunable,
                _
            ) | (
                Causality::Input | Causality::Output,
                Variability::Continuous,
                BaseType::Real
            ) | (
                Causality::Input | Causality::Output,
                Variability::Discrete,
                _
            )
        );
        if !ok {
            return Err(format!("{}: illegal causality/variability", v.name));
        }
    }
    Ok(())
}

/// Declare a model's variables once: the table (value reference = row, in order) and a module
/// of value-reference constants, one per row, named by the row's identifier.
///
/// ```ignore
/// fmi2_variables! {
///     /// Value references.
///     pub mod vr;
///     /// The variable table.
///     pub static VARIABLES = [
///         U = Variable::real("u", Input, Continuous, "m", Some(0.0), None, None, "input"),
///         Y = Variable::real("y", Output, Continuous, "m", None, None, None, "output"),
///     ];
/// }
/// // vr::U == 0, vr::Y == 1, VARIABLES[1].vr == vr::Y,
/// // vr::IDENTIFIERS == ["U", "Y"] (to check them against the variable names).
/// ```
#[macro_export]
macro_rules! fmi2_variables {
    (
        $(#[$vr_meta:meta])* $vr_vis:vis mod $vr_mod:ident;
        $(#[$t_meta:meta])* $t_vis:vis static $table:ident = [
            $( $name:ident = $def:expr ),* $(,)?
        ];
    ) => {
        $(#[$vr_meta])*
        $vr_vis mod $vr_mod {
            #[allow(non_camel_case_types, clippy::upper_case_acronyms, dead_code)]
            #[repr(u32)]
            enum Row {
                $($name),*
            }
            $(
                #[doc = concat!("Value reference of row `", stringify!($name), "`.")]
                pub const $name: u32 = Row::$name as u32;
            )*
            /// The row identifiers, in table order.
            pub const IDENTIFIERS: &[&str] = &[$(stringify!($name)),*];
        }
        $(#[$t_meta])*
        $t_vis static $table: &[$crate::fmi2::Variable] = &[
            $( $crate::fmi2::Variable::at($def, $vr_mod::$name) ),*
        ];
    };
}
