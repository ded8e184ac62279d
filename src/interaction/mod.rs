//! What tools do to the tissue during a substep, each over the narrow particle view of a body
//! ([`ParticleView`](crate::scene::particles::ParticleView): predicted positions, positions at
//! the substep's start, masses) and a tool's pose, never the solver's scratch:
//!
//! - [`surface_contact`]: a tool's exact shape against the boundary triangles (the default
//!   contact mode), with friction;
//! - [`sampled_contact`]: the paper's sampled tool surface against the particles, with friction;
//! - [`grasp`]: compliant attachments between a grasping tool and the tissue it holds;
//! - [`needle`]: puncture, and tissue held on a needle's shaft with axial friction.
//!
//! The contacts between bodies and of a body with itself need the solver's broad phases and
//! stay in [`crate::solver`]. Grasps and needles keep their data in the scene's tool slots, as
//! the types of [`crate::scene::grasp_state`] and [`crate::scene::needle_state`] (the public
//! ones re-exported by [`grasp`] and [`needle`]); the files here hold what they do.

pub mod grasp;
pub mod needle;
pub(crate) mod sampled_contact;
pub(crate) mod surface_contact;

use crate::kernels::math::{Real, Vec3};
use parry3d_f64::math::{Isometry, Point};

/// How far (m) the point of a tool now at `point` moved in this substep: `back` maps a point
/// attached to the tool at the substep's end to where it was at its start.
pub(crate) fn tool_motion_at(back: &Isometry<Real>, point: &Vec3) -> Vec3 {
    point - back.transform_point(&Point::from(*point)).coords
}
