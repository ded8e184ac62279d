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

// The source tree by layer, bottom to top, each importing only the layers below it:
// `kernels` (arithmetic, threads, stateless kernels) → `model` (what a mesh determines once) →
// `scene` (what a step advances) → `interaction` (tools on a body's particle view) → `solver`
// (the step) → `world` (the public API). Beside them: `mesh` (readers and writers), `render`
// (render surfaces) and `ffi` (the C ABI); `error` is shared by all. docs/ARCHITECTURE.md has
// the table. Public paths are the re-exports below, not the tree.
pub(crate) mod error;
pub mod ffi;
pub(crate) mod interaction;
pub(crate) mod kernels;
pub mod mesh;
pub(crate) mod model;
pub mod render;
pub(crate) mod scene;
pub(crate) mod solver;
pub(crate) mod world;

pub use interaction::{grasp, needle};
pub use scene::cut;
pub use solver::statics;
// The saved-state byte format, public under its historical name (the state as a value is
// `WorldState`, in `scene::state`).
pub use world::state_bytes as state;

#[doc(no_inline)]
pub use cut::{Blade, CutReport};
pub use error::Error;
#[doc(no_inline)]
pub use grasp::GraspOptions;
pub use kernels::math::{tet_volume, Mat3, Quat, Real, Vec3};
pub use kernels::neighbours::MAX_NEIGHBOURS;
pub use model::body_model::{
    BodyModel, BodyOptions, Material, DENSITY_RANGE, MAX_POISSON_RATIO, MIN_POISSON_RATIO,
    PARTICLE_RADIUS_RANGE, SUPPORT_RADIUS_RANGE, YOUNGS_MODULUS_RANGE,
};
pub use model::particle_order::ParticleOrder;
#[doc(no_inline)]
pub use needle::{NeedleOptions, NeedleState};
pub use scene::body::{Body, STATE_POSITION_LIMIT, STATE_SPEED_LIMIT};
pub use scene::settings::{ContactMode, DivergenceLimits, ElasticScheme, Settings, VolumeScheme};
pub use scene::substep_hold::SUBSTEP_HOLD_STEPS;
pub use scene::tool::{
    Pose, Tool, ToolOptions, ToolShape, Wrench, CONVEX_HULL_FLATNESS, MIN_QUATERNION_NORM,
    TOOL_SIZE_RANGE,
};
pub use scene::{BodyId, StepReport, ToolId, WorldState, TOOL_JUMP_FRACTION};
pub use solver::profile::StepProfile;
pub use world::{RenderSurfaceId, World};
