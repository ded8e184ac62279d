//! Stateless PBD/XPBD projection kernels. The solver loop lives in [`crate::solver`], the
//! multipliers in its workspace (volume) and in the scene's tool slots (grasp, needle); each
//! kernel takes positions and inverse masses and moves them.

pub mod contact;
pub mod friction;
pub mod volume;
