//! The bottom layer: arithmetic and stateless kernels over plain arrays and load-time data,
//! importing nothing above them (only `crate::error` and, in tests, `crate::mesh`).
//!
//! - numbers: [`math`] (`Real`, the nalgebra aliases), [`lanes`] (four `f64` lanes),
//!   [`vec3_array`] (3-vectors stored by component), [`rotation`] (the rotation of a
//!   deformation gradient);
//! - threads: [`parallel`] (the fork–join pool and barrier), [`pair_sums`] (pair forces summed in
//!   the one-thread order on any number of threads), [`colouring`] (the volume pass's order);
//! - the point-based method: [`neighbours`] (neighbour search and CSR neighbourhoods),
//!   [`point_elasticity`] (the force pass), [`stability`] (the explicit stability limit);
//! - [`tet_elasticity`]: corotated linear tetrahedra, the other force kernel, and [`incidence`]
//!   (the tetrahedra around each node, for it and the dual cells);
//! - [`tet_dashpots`]: stiffness-proportional damping on the mesh edges, implicit;
//! - [`constraints`]: the XPBD/PBD projections (volume, contact, friction);
//! - [`collision`]: broad phases and geometric queries.

pub(crate) mod collision;
pub(crate) mod colouring;
pub(crate) mod constraints;
pub(crate) mod incidence;
pub(crate) mod lanes;
pub(crate) mod math;
pub(crate) mod neighbours;
pub(crate) mod pair_sums;
pub(crate) mod parallel;
pub(crate) mod point_elasticity;
pub(crate) mod rotation;
pub(crate) mod stability;
pub(crate) mod tet_dashpots;
pub(crate) mod tet_elasticity;
pub(crate) mod vec3_array;
