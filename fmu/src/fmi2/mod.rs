//! A generic FMI 2.0 co-simulation layer, after the Modelica Reference-FMUs: the C types, the
//! `fmi2*` functions, the state machine and argument checks, logging, the resource URI, the
//! checksummed FMU-state byte format, and the `modelDescription.xml` and documentation-table
//! generators. It names no particular model. A model plugs in by
//!
//! 1. declaring its variables once with [`fmi2_variables!`](crate::fmi2_variables) (the table
//!    and its value-reference constants),
//! 2. implementing the [`Model`] trait (identifier, units, start-up, step, reset, state
//!    save/restore), and
//! 3. exporting the C entry points with [`export_fmi2!`](crate::export_fmi2).

pub mod bytes;
pub mod docs;
pub mod exports;
pub mod instance;
pub mod logger;
pub mod types;
pub mod uri;
pub mod variables;
pub mod xml;

pub use instance::{
    check_state_bytes, fnv1a_64, guid, DefaultExperiment, Instance, Model, ModelError, State,
};
pub use logger::{Category, Logger};
pub use types::Fmi2Status;
pub use variables::{
    BaseType, Causality, EnumItem, EnumType, Kind, Phase, Store, UnitDefinition, Value,
    Variability, Variable,
};
