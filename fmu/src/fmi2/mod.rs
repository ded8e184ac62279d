//! A generic FMI 2.0 co-simulation layer, after the Modelica Reference-FMUs: the C types, the
//! exported `fmi2*` functions, the state machine and argument checks, logging, the resource
//! URI, the FMU-state byte format and the `modelDescription.xml` generator. It knows nothing
//! about soft tissue: a model plugs in through the [`Model`] trait and its variable table.

pub mod bytes;
pub mod exports;
pub mod instance;
pub mod logger;
pub mod types;
pub mod uri;
pub mod variables;
pub mod xml;

pub use instance::{guid, DefaultExperiment, Instance, Model, ModelError, State};
pub use logger::{Category, Logger};
pub use types::Fmi2Status;
pub use variables::{
    BaseType, Causality, EnumItem, EnumType, Kind, Phase, Store, UnitDefinition, Value,
    Variability, Variable,
};
