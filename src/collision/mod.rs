//! Collision: kinematic tools (parry shapes with a pose), their surface sampling for the
//! paper's point mode, and the spatial hash grid used for organ–organ contact.

pub mod hash_grid;
pub mod sampling;
pub mod tool;
pub(crate) mod winding;
