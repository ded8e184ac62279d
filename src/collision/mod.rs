//! Collision: kinematic tools (parry shapes with a pose) and the spatial hash grid used for
//! organ–organ contact.

pub mod tool;
