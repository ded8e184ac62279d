//! # tissuesim
//!
//! A real-time soft-tissue solver for surgical simulation, after Shan, Si, Li, Wang et al.,
//! *Interactive Point based Method for Soft Tissue Deformation in Surgical Simulation* (2015).
//!
//! Organs are sets of points (the nodes of a tetrahedral mesh) whose elasticity comes from the
//! point-based method of Müller et al. (2004): a moving-least-squares deformation gradient per
//! particle and an inversion-robust corotated stress (Irving et al. 2004). Position-based dynamics
//! (XPBD) handles what must never fail interactively: instrument–tissue and organ–organ contact,
//! friction, and per-tetrahedron volume conservation.
//!
//! All quantities are SI: metres, kilograms, seconds, newtons, pascals.
//!
//! ```no_run
//! use tissuesim::{mesh, BodyOptions, Settings, World};
//! let organ = mesh::default_organ();
//! let mut world = World::new(Settings::default()).unwrap();
//! let body = world.add_body(&organ, &BodyOptions::default()).unwrap();
//! world.fix_box(body, [-1.0, 0.05, -1.0].into(), [1.0, 1.0, 1.0].into()).unwrap();
//! for _ in 0..100 {
//!     world.step().unwrap();
//! }
//! println!("volume ratio {}", world.body(body).unwrap().volume_ratio());
//! ```
#![warn(missing_docs)]

pub mod body;
pub mod collision;
pub mod consistency;
pub mod constraints;
pub(crate) mod divergence;
pub mod elastic;
pub mod error;
pub mod ffi;
pub mod math;
pub mod mesh;
pub mod neighbours;
pub mod parallel;
pub mod render;
pub mod settings;
pub mod stability;
pub mod state;
pub mod statics;
pub mod world;

pub use body::{Body, BodyOptions, Material};
pub use collision::tool::{Pose, Tool, ToolOptions, ToolShape, Wrench};
pub use error::Error;
pub use math::{Mat3, Quat, Real, Vec3};
pub use settings::{ContactMode, DivergenceLimits, Settings};
pub use world::{BodyId, RenderSurfaceId, StepReport, ToolId, World};
