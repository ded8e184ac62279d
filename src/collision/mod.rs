//! Collision: kinematic tools (parry shapes with a pose), their surface sampling for the
//! paper's point mode, the spatial hash grid used for organ–organ contact, and the grid of
//! triangle boxes of the surface self-contact.

pub mod hash_grid;
pub mod sampling;
pub mod tool;
pub(crate) mod triangle_grid;
pub(crate) mod winding;
