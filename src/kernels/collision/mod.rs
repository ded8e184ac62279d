//! Collision geometry that keeps no scene state (scratch such as the self-contact tree's refit
//! is the caller's): axis-aligned boxes, the paper's sampling of a tool surface into points, the
//! spatial hash grid of the organ–organ broad phase, the bounding-volume hierarchy of the surface
//! self-contact's broad phase and the candidate pairs it keeps from pass to pass, and the inside
//! test of a closed surface (winding number). The tools themselves are scene objects
//! ([`crate::scene::tool`]); the contact passes that use these are in [`crate::interaction`] and
//! [`crate::solver`].

pub(crate) mod aabb;
pub mod hash_grid;
pub mod sampling;
pub(crate) mod surface_pairs;
pub(crate) mod surface_tree;
pub(crate) mod winding;
