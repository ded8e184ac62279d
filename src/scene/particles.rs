//! The narrow view of a body's particles that the interactions act on: tool contact (both
//! modes), grasping and needle holds see the predicted positions they correct, the positions
//! at the start of the substep, the inverse and inertial masses, and the few per-body numbers
//! they need, never the body or the solver's scratch. The solver builds the views
//! ([`ParticleViews`]) from what it owns; the constants the interactions share with the scene
//! live here too, below both.

use crate::kernels::math::{Real, Vec3};

/// Thickness of the contact skin over the boundary surface, in particle radii: contact starts
/// this far out (0.6 mm on the default organ), so that a tool resting on the surface stays in
/// contact from one substep to the next instead of touching and leaving it in turn.
pub(crate) const SURFACE_SKIN: Real = 0.1;

/// One body's particles as an interaction sees them during a substep.
pub(crate) struct ParticleView<'a> {
    /// Predicted positions of the substep in progress (m): what the projections correct.
    pub(crate) p: &'a mut [Vec3],
    /// Positions at the start of the substep (m).
    pub(crate) x: &'a [Vec3],
    /// Inverse inertial masses (1/kg; 0 for a fixed particle).
    pub(crate) inv_mass: &'a [Real],
    /// Inertial masses (kg): a correction times its particle's mass goes into the tool's wrench.
    pub(crate) mass: &'a [Real],
    /// The body's particle radius (m).
    pub(crate) radius: Real,
    /// The body's Young's modulus (Pa), for the compliance of holds on the tissue.
    pub(crate) youngs_modulus: Real,
}

/// The particle views of every body, by body index: what an interaction that may touch
/// several bodies (a grasp) is handed.
pub(crate) trait ParticleViews {
    /// The view of body `b`.
    fn view(&mut self, b: usize) -> ParticleView<'_>;
}
