//! The step's workspace: all the memory a step uses and throws away, owned by the world apart
//! from the bodies (model and state), sized when bodies are added and reused, so that a step
//! allocates nothing.

use crate::body_model::BodyModel;
use crate::collision::hash_grid::HashGrid;
use crate::divergence::ParticleScan;
use crate::math::{Real, Vec3};
use crate::solver::SurfaceScratch;
use crate::world_state::WorldState;

/// A body's working memory of a step; nothing in it outlives a substep.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct StepScratch {
    /// Predicted positions of the current substep (m).
    pub(crate) p: Vec<Vec3>,
    /// Forces of the current substep (N).
    pub(crate) force: Vec<Vec3>,
    /// Pair forces of the force pass (N), one entry per pair slot: on several threads, those
    /// kept for the particles summed after its barrier (`crate::pair_sums`).
    pub(crate) pair_force: Vec<Vec3>,
    /// The particles' sums of their pair forces (N), kept as `pair_force` is.
    pub(crate) own_force: Vec<Vec3>,
    /// XPBD multipliers of the volume constraints within a substep, one per load-time
    /// tetrahedron, in the colouring's projection order (a cut body uses the first ones).
    pub(crate) tet_lambda: Vec<Real>,
    /// The particle half of the divergence check, made in the step's last update pass.
    pub(crate) scan: ParticleScan,
}

impl StepScratch {
    /// Scratch sized for a body on `model`.
    pub(crate) fn for_model(model: &BodyModel) -> StepScratch {
        let n = model.particle_count();
        StepScratch {
            p: model.rest.clone(),
            force: vec![Vec3::zeros(); n],
            pair_force: vec![Vec3::zeros(); model.nbr.slot_count()],
            own_force: vec![Vec3::zeros(); n],
            tet_lambda: vec![0.0; model.tets.len()],
            scan: ParticleScan::EMPTY,
        }
    }
}

/// Everything a step writes that is not the world's state.
#[derive(Debug, Default)]
pub(crate) struct Workspace {
    /// One per body, in body order.
    pub(crate) bodies: Vec<StepScratch>,
    /// The organ–organ broad phase, rebuilt every substep on the predicted positions.
    pub(crate) grid: HashGrid,
    /// Scratch memory of the tool–surface contact pass.
    pub(crate) surface: SurfaceScratch,
    /// The state at the start of the step in progress, put back if the step diverges.
    pub(crate) rollback: WorldState,
}

impl Workspace {
    /// Make room for one more body, on `model`.
    pub(crate) fn add_body(&mut self, model: &BodyModel) {
        self.bodies.push(StepScratch::for_model(model));
        let particles = self.bodies.iter().map(|s| s.p.len()).sum();
        self.grid.reserve(particles);
    }
}
