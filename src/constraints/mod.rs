//! Stateless PBD/XPBD projection kernels. Constraint storage and the solver loop live in
//! [`crate::world`]; each kernel takes positions and inverse masses and moves them.

pub mod contact;
pub mod friction;
pub mod volume;
