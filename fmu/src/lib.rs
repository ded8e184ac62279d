//! # tissuesim-fmu
//!
//! The FMI 2.0 co-simulation FMU of tissuesim: a kinematic tool (inputs: its pose) pressing an
//! organ (outputs: the contact force and torque on the tool, the organ's volume).
//!
//! * [`fmi2`]: a generic FMI 2.0 layer (C types, the exported `fmi2*` functions, the state
//!   machine, argument checks, logging, resource URIs, FMU-state bytes, XML generation),
//!   after the Modelica Reference-FMUs; it knows nothing about tissue.
//! * [`model`]: the variable table and its mapping to a [`tissuesim::World`].
//!
//! Build the `.fmu` with `cargo run --release -p tissuesim-fmu --bin build-fmu` (see
//! `docs/FMU.md`).
#![warn(missing_docs)]
// The library name `TissueSim` is the FMU's model identifier, fixed by the FMI standard.
#![allow(non_snake_case)]

pub mod fmi2;
pub mod model;

pub use model::TissueSim;

/// The `generationTool` written into `modelDescription.xml`.
pub fn generation_tool() -> String {
    format!("tissuesim-fmu {}", env!("CARGO_PKG_VERSION"))
}

/// The complete `modelDescription.xml` of the FMU.
pub fn model_description() -> String {
    fmi2::xml::model_description::<TissueSim>(&generation_tool())
}
