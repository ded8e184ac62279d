//! What a mesh and its options determine once, at load time: [`body_model`] (`BodyModel`,
//! immutable and `Arc`-shared, with the `BodyOptions` and `Material` it is built from),
//! [`particle_order`] (the Morton order of the particles), [`consistency`] (the variationally
//! consistent gradients) and [`dual_cells`] (each particle's dual cell, for the per-particle
//! volume constraints). Imports the kernels and the mesh types, nothing above.

pub(crate) mod body_model;
pub(crate) mod consistency;
pub(crate) mod dual_cells;
pub(crate) mod particle_order;
