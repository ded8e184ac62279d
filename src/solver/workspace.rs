//! The step's workspace: all the memory a step uses and throws away, owned by the
//! [`Pipeline`](super::Pipeline) apart from the scene (bodies' model and state, tools), sized
//! when bodies are added and reused, so that a step allocates nothing.

use crate::kernels::collision::hash_grid::HashGrid;
use crate::kernels::collision::surface_pairs::SurfacePairs;
use crate::kernels::math::{Real, Vec3};
use crate::kernels::tet_elasticity::TetShares;
use crate::model::body_model::BodyModel;
use crate::model::dual_cells::CellSlot;
use crate::scene::body::Body;
use crate::scene::particles::ParticleView;
use crate::scene::WorldState;
use crate::solver::divergence_check::ParticleScan;
use crate::solver::surface_self_contact::self_contact_sizes;
use crate::solver::{SelfContactScratch, SurfaceScratch};

/// A body's working memory of a step; nothing in it outlives a substep but the self-contact's
/// built pairs, which never change a result (`kernels::collision::surface_pairs`).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct StepScratch {
    /// Predicted positions of the current substep (m).
    pub(crate) p: Vec<Vec3>,
    /// Forces of the current substep (N).
    pub(crate) force: Vec<Vec3>,
    /// Pair forces of the force pass (N) kept for the particles summed after its barrier
    /// (`crate::kernels::pair_sums`), one entry per pair slot; empty on one thread, where nothing
    /// is kept.
    pub(crate) pair_force: Vec<Vec3>,
    /// The particles' sums of their pair forces (N), kept as `pair_force` is (one entry per
    /// particle; empty on one thread).
    pub(crate) own_force: Vec<Vec3>,
    /// XPBD multipliers of the volume constraints within a substep: one per load-time
    /// tetrahedron, in the colouring's projection order (a cut body uses the first ones), or
    /// one per dual cell, in the cells' projection order (`DualCells::colours`; the
    /// array holds the larger count).
    pub(crate) tet_lambda: Vec<Real>,
    /// Where the tetrahedron force pass puts its corner forces on several threads, and those it
    /// keeps for the sums after its barrier (`ElasticScheme::Tetrahedra`; made for the body's
    /// current tetrahedra and the thread count).
    pub(crate) tet_shares: TetShares,
    /// The tetrahedra the force pass found below half their rest volume at the substep's start
    /// (`kernels::tet_elasticity::COMPRESSED_RATIO`), one bit a tetrahedron, one entry per
    /// chunk of four (`ElasticScheme::Tetrahedra`; sized for the load-time tetrahedra, a cut
    /// body uses the first ones): the ones the crush guard checks.
    pub(crate) compressed: Vec<u8>,
    /// The dual-cell projection's scratch, per thread a run of the model's largest star: for
    /// each particle of a cell's star its position relative to the cell's particle (m), its
    /// inverse mass (1/kg) and the cell volume's gradient with respect to it (m²).
    pub(crate) cell_scratch: Vec<CellSlot>,
    /// Each particle's load on the damping filter, `2 h β D_i / m_i` (dimensionless), and the
    /// edges' impulses on their particles (N·s), in the load-time mesh's slots (a cut body uses
    /// the first ones) (`kernels::tet_dashpots`).
    pub(crate) dashpot_load: Vec<Real>,
    pub(crate) dashpot_impulse: Vec<Vec3>,
    /// The particles the damping filter leaves alone in a substep: the corners of the
    /// tetrahedra the force pass found crushed.
    pub(crate) dashpot_undamped: Vec<bool>,
    /// The particle half of the divergence check, made in the step's last update pass.
    pub(crate) scan: ParticleScan,
    /// The surface self-contact's candidate pairs, kept while the surface moves little (sized
    /// by the first pass with self-contact on).
    pub(crate) self_contact_pairs: SurfacePairs,
}

impl StepScratch {
    /// Scratch sized for a body on `model` stepped on `threads` threads.
    pub(crate) fn for_model(model: &BodyModel, threads: usize) -> StepScratch {
        let n = model.particle_count();
        let mut scratch = StepScratch {
            p: model.rest.clone(),
            force: vec![Vec3::zeros(); n],
            pair_force: Vec::new(),
            own_force: Vec::new(),
            tet_lambda: vec![0.0; model.tets.len().max(n)],
            tet_shares: TetShares::default(),
            compressed: vec![0; model.tet_elements.chunk_count()],
            cell_scratch: Vec::new(),
            dashpot_load: vec![0.0; n],
            dashpot_undamped: vec![false; n],
            dashpot_impulse: vec![Vec3::zeros(); model.tet_dashpots.slot_count()],
            scan: ParticleScan::EMPTY,
            self_contact_pairs: SurfacePairs::default(),
        };
        scratch.size_kept(model, threads);
        scratch
    }

    /// The particle view of `body` (the body this scratch is for) that the interactions act
    /// on: these predicted positions, the body's positions and masses.
    pub(crate) fn view<'a>(&'a mut self, body: &'a Body) -> ParticleView<'a> {
        ParticleView {
            p: &mut self.p,
            x: &body.state.x,
            inv_mass: &body.inv_mass,
            mass: &body.derived.inertial_mass,
            radius: body.model.particle_radius,
            youngs_modulus: body.model.options.material.youngs_modulus,
        }
    }

    /// Size the particles' force pass's kept forces for `threads` threads (a body's worth on
    /// several, none on one: the memory is freed), make the tetrahedra's shares for them, and
    /// size the dual-cell scratch (a run per thread; a cut only removes tetrahedra, so no star
    /// outgrows it).
    fn size_kept(&mut self, model: &BodyModel, threads: usize) {
        let (slots, particles) = match threads {
            1 => (0, 0),
            _ => (model.nbr.slot_count(), model.particle_count()),
        };
        self.tet_shares.fit(&model.tet_elements, threads);
        for (kept, len) in [
            (&mut self.pair_force, slots),
            (&mut self.own_force, particles),
        ] {
            kept.resize(len, Vec3::zeros());
            kept.shrink_to_fit();
        }
        let cell_scratch = threads * model.dual_cells.max_star();
        self.cell_scratch.resize(cell_scratch, CellSlot::default());
        self.cell_scratch.shrink_to_fit();
    }
}

/// Everything a step writes that is not the scene's state.
#[derive(Debug, Default)]
pub(crate) struct Workspace {
    /// One per body, in body order.
    pub(crate) bodies: Vec<StepScratch>,
    /// The organ–organ broad phase, rebuilt every substep on the predicted positions.
    pub(crate) grid: HashGrid,
    /// Scratch memory of the tool–surface contact pass.
    pub(crate) surface: SurfaceScratch,
    /// Scratch memory of the surface self-contact pass, sized for the largest body.
    pub(crate) self_contact: SelfContactScratch,
    /// The state at the start of the step in progress, put back if the step diverges.
    pub(crate) rollback: WorldState,
}

impl Workspace {
    /// Make room for one more body, on `model`, stepped on `threads` threads.
    pub(crate) fn add_body(&mut self, model: &BodyModel, threads: usize) {
        self.bodies.push(StepScratch::for_model(model, threads));
        let particles = self.bodies.iter().map(|s| s.p.len()).sum();
        self.grid.reserve(particles);
        self.self_contact.reserve(model);
    }

    /// Size the surface self-contact scratch and refit the tetrahedron force pass's shares for
    /// the bodies on `models` (in body order) after a change of topology (a cut or a restored
    /// cut state changes a boundary and the tetrahedra): the step after it then allocates
    /// nothing.
    pub(crate) fn fit_boundaries<'a>(&mut self, models: impl Iterator<Item = &'a BodyModel>) {
        for (scratch, model) in self.bodies.iter_mut().zip(models) {
            self.self_contact.reserve(model);
            (scratch.self_contact_pairs).forget(self_contact_sizes(model));
            scratch.tet_shares.refit(&model.tet_elements);
        }
    }

    /// Size every body's scratch (the bodies on `models`, in order) for `threads` threads.
    pub(crate) fn set_threads<'a>(
        &mut self,
        models: impl Iterator<Item = &'a BodyModel>,
        threads: usize,
    ) {
        for (scratch, model) in self.bodies.iter_mut().zip(models) {
            scratch.size_kept(model, threads);
        }
    }
}
