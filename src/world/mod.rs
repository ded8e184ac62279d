//! The public API of a simulation: [`World`], a scene (bodies, tools, settings, time) and the
//! pipeline that steps it, with the render surfaces bound to its bodies. It builds and queries
//! the scene, and steps it ([`World::step`]: `solver::Pipeline::step`, Algorithm 1 of the paper,
//! one pass a file in the `solver` module). Its dynamic state as a value is in [`state`], as
//! bytes in [`saved_state`] (`World::save_state`, `restore_state`) over the byte format of
//! [`state_bytes`] (public as `tissuesim::state`).

mod saved_state;
mod state;
pub mod state_bytes;

use crate::error::Error;
use crate::kernels::math::{is_finite_vec, Real, Vec3};
use crate::mesh::TetMesh;
use crate::model::body_model::{BodyModel, BodyOptions};
use crate::render::{RenderMesh, RenderSurface};
use crate::scene::body::Body;
use crate::scene::cut::{Blade, CutReport};
use crate::scene::derived::DerivedFrom;
use crate::scene::grasp_state::{Grasp, GraspOptions};
use crate::scene::needle_state::{Needle, NeedleOptions, NeedleState};
use crate::scene::settings::Settings;
use crate::scene::tool::{check_friction, Pose, Tool, ToolOptions, ToolShape};
use crate::scene::{BodyId, PairFriction, Scene, StepReport, ToolId, ToolSlot};
use crate::solver::profile::StepProfile;
use crate::solver::Pipeline;
use std::sync::Arc;

/// Identifies a render surface inside its world (index in insertion order, never reused).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct RenderSurfaceId(pub u32);

/// A simulated scene: the scene's bodies, tools and settings, the pipeline that steps them and
/// the render surfaces bound to the bodies.
pub struct World {
    /// What a step advances: settings, bodies, tools, body-pair friction, time.
    pub(crate) scene: Scene,
    /// The step's scratch memory (the rollback copy included) and threads.
    pub(crate) pipeline: Pipeline,
    pub(crate) render_surfaces: Vec<RenderSurface>,
    /// Steps that diverged and were rolled back.
    pub(crate) diverged_steps: u64,
}

impl World {
    /// An empty world; the settings are validated first.
    pub fn new(settings: Settings) -> Result<Self, Error> {
        settings.validate()?;
        Ok(World {
            pipeline: Pipeline::new(settings.threads),
            scene: Scene::new(settings),
            render_surfaces: Vec::new(),
            diverged_steps: 0,
        })
    }
    /// The settings in force.
    pub fn settings(&self) -> &Settings {
        &self.scene.settings
    }
    /// Replace the settings (validated; the world is unchanged on error).
    pub fn set_settings(&mut self, settings: Settings) -> Result<(), Error> {
        settings.validate()?;
        // Each body re-derives what depends on the settings iff that part of them changed.
        let from = DerivedFrom::settings(&settings);
        for b in &mut self.scene.bodies {
            b.rederive(from);
        }
        let s = &self.scene.settings;
        if settings.threads != s.threads {
            self.pipeline
                .set_threads(settings.threads, &self.scene.bodies);
        }
        self.scene.settings = settings;
        Ok(())
    }
    /// Simulated time (s) since the world was created.
    pub fn time(&self) -> Real {
        self.scene.time
    }
    /// Number of steps that produced NaN/Inf and were rolled back.
    pub fn diverged_steps(&self) -> u64 {
        self.diverged_steps
    }
    /// Add a deformable body built from `mesh` (node positions in m): [`BodyModel::new`]
    /// then [`World::add_body_model`].
    pub fn add_body(&mut self, mesh: &TetMesh, options: &BodyOptions) -> Result<BodyId, Error> {
        Ok(self.add_body_model(BodyModel::new(mesh, options)?))
    }
    /// Add a deformable body at rest on `model`, shared with its other holders (other worlds,
    /// other bodies): the load-time work (neighbourhoods, consistent gradients) is not redone
    /// and its arrays are not copied. Cutting the body gives it its own copy of the model
    /// first; the other holders keep theirs.
    pub fn add_body_model(&mut self, model: Arc<BodyModel>) -> BodyId {
        self.pipeline.add_body(&model);
        let scene = &mut self.scene;
        let from = DerivedFrom::settings(&scene.settings);
        scene.bodies.push(Body::from_model(model, from));
        BodyId(scene.bodies.len() as u32 - 1)
    }
    /// Number of bodies.
    pub fn body_count(&self) -> usize {
        self.scene.bodies.len()
    }
    /// A body by id.
    pub fn body(&self, id: BodyId) -> Result<&Body, Error> {
        self.scene.body(id)
    }
    /// Set the positions (m) and velocities (m/s) of every particle of a body, e.g. an initial
    /// condition. Both slices must have one entry per particle, in particle order
    /// ([`Body::particle_order`](crate::Body::particle_order)), and be finite, within
    /// [`STATE_POSITION_LIMIT`](crate::STATE_POSITION_LIMIT) body sizes of the body's
    /// rest centre and below [`STATE_SPEED_LIMIT`](crate::STATE_SPEED_LIMIT) body sizes
    /// per second; fixed particles take the given position and zero velocity. Nothing changes
    /// on error.
    pub fn set_body_state(
        &mut self,
        id: BodyId,
        positions: &[Vec3],
        velocities: &[Vec3],
    ) -> Result<(), Error> {
        let body = self.scene.body_mut(id)?;
        let n = body.particle_count();
        if positions.len() != n || velocities.len() != n {
            return Err(Error::InvalidArgument(format!(
                "set_body_state needs {n} positions and {n} velocities, got {} and {}",
                positions.len(),
                velocities.len()
            )));
        }
        if positions
            .iter()
            .chain(velocities)
            .any(|v| !is_finite_vec(v))
        {
            return Err(Error::NonFinite("particle state".into()));
        }
        for (i, (x, v)) in positions.iter().zip(velocities).enumerate() {
            body.check_state(i, x, v).map_err(Error::InvalidArgument)?;
        }
        body.state.x.copy_from_slice(positions);
        for ((v, given), fixed) in body.state.v.iter_mut().zip(velocities).zip(&body.fixed) {
            *v = if *fixed { Vec3::zeros() } else { *given };
        }
        Ok(())
    }
    /// Bind a render (visual) surface to a body: every vertex gets barycentric coordinates in
    /// the body's enclosing rest tetrahedron, or in the nearest one (extrapolated) when it lies
    /// outside. `mesh` positions are in the body's rest frame (m), e.g. from
    /// [`crate::render::read_obj`] with the scale of the body's mesh, or
    /// [`RenderMesh::from_boundary`]. The surface is updated from the body's current positions
    /// once here, then on request ([`World::update_render_surface`]); `step()` never touches it.
    pub fn add_render_surface(
        &mut self,
        body: BodyId,
        mesh: RenderMesh,
    ) -> Result<RenderSurfaceId, Error> {
        let surface = RenderSurface::new(body, self.body(body)?, mesh)?;
        self.render_surfaces.push(surface);
        Ok(RenderSurfaceId(self.render_surfaces.len() as u32 - 1))
    }
    /// Number of render surfaces.
    pub fn render_surface_count(&self) -> usize {
        self.render_surfaces.len()
    }
    /// A render surface by id, as of its last update.
    pub fn render_surface(&self, id: RenderSurfaceId) -> Result<&RenderSurface, Error> {
        self.render_surfaces
            .get(id.0 as usize)
            .ok_or(Error::UnknownRenderSurface(id.0))
    }
    /// Recompute a render surface's deformed positions (m) and normals from its body's current
    /// particle positions, and return it. Allocates nothing; O(vertices + triangles).
    pub fn update_render_surface(&mut self, id: RenderSurfaceId) -> Result<&RenderSurface, Error> {
        let surface = self
            .render_surfaces
            .get_mut(id.0 as usize)
            .ok_or(Error::UnknownRenderSurface(id.0))?;
        let body = &self.scene.bodies[surface.body().0 as usize];
        surface.update(body.positions());
        Ok(surface)
    }
    /// Fix the particles with the given indices (particle order:
    /// [`ParticleOrder::particles_of`](crate::ParticleOrder::particles_of) converts mesh node
    /// indices). They keep their current position. Nothing is fixed if any index is out of
    /// range.
    pub fn fix_particles(&mut self, id: BodyId, indices: &[u32]) -> Result<(), Error> {
        let body = self.scene.body_mut(id)?;
        let n = body.particle_count();
        if let Some(&k) = indices.iter().find(|&&k| k as usize >= n) {
            return Err(Error::InvalidArgument(format!(
                "particle index {k} out of range (body has {n} particles)"
            )));
        }
        body.fix(indices.iter().map(|&k| k as usize));
        Ok(())
    }
    /// Fix every particle whose current position lies in the box `[min, max]` (m, world
    /// frame, `min <= max` on every axis); returns how many particles the box holds. Nothing
    /// is fixed on error.
    pub fn fix_box(&mut self, id: BodyId, min: Vec3, max: Vec3) -> Result<usize, Error> {
        if !is_finite_vec(&min) || !is_finite_vec(&max) {
            return Err(Error::NonFinite("fixed box min/max".into()));
        }
        if (0..3).any(|k| min[k] > max[k]) {
            return Err(Error::InvalidArgument(
                "fixed box: min must be <= max on every axis".into(),
            ));
        }
        let body = self.scene.body_mut(id)?;
        let inside: Vec<usize> = (0..body.particle_count())
            .filter(|&i| {
                let p = body.state.x[i];
                (0..3).all(|a| p[a] >= min[a] && p[a] <= max[a])
            })
            .collect();
        body.fix(inside.iter().copied());
        Ok(inside.len())
    }
    /// Add a kinematic tool. Its surface samples (for the sampled contact mode) are spaced by
    /// `options.sample_spacing`, or by the particle radius of the first body (5 mm without one).
    pub fn add_tool(
        &mut self,
        shape: ToolShape,
        pose: Pose,
        options: &ToolOptions,
    ) -> Result<ToolId, Error> {
        let spacing = (self.scene.bodies.first())
            .map(|b| b.particle_radius())
            .unwrap_or(0.005);
        let id = u32::try_from(self.scene.tools.len())
            .map_err(|_| Error::InvalidArgument("no tool id left".into()))?;
        let tool = Tool::new(shape, pose, options, spacing)?;
        self.scene.tools.push(Some(ToolSlot::new(tool)));
        Ok(ToolId(id))
    }
    /// Remove a tool: it no longer touches the tissue from the next step on, and its id stays
    /// unused (later tools get new ids; calls with the removed id give
    /// [`Error::UnknownTool`]). Nothing changes on error.
    pub fn remove_tool(&mut self, id: ToolId) -> Result<(), Error> {
        self.scene.slot(id)?;
        self.scene.tools[id.0 as usize] = None;
        Ok(())
    }
    /// Cut body `id` with `blade` now (see [`crate::cut`]): the neighbour pairs and tetrahedra
    /// crossed by the blade's swept edge are removed. Nothing changes on error.
    pub fn cut(&mut self, id: BodyId, blade: &Blade) -> Result<CutReport, Error> {
        let ends = blade.from.iter().chain(&blade.to);
        if ends.clone().any(|p| !is_finite_vec(p)) {
            return Err(Error::NonFinite("blade edge".into()));
        }
        let report = crate::scene::cut::cut(self.scene.body_mut(id)?, blade);
        self.pipeline.fit_boundaries(&self.scene.bodies);
        Ok(report)
    }
    /// Make tool `id` (a capsule or a cylinder) a blade: its edge is the segment of its local y
    /// axis between ±half_height; at the end of every step it cuts every body along the surface
    /// its edge swept during the step, and it does not push the tissue (a blade slices). Nothing
    /// changes on error.
    pub fn make_blade(&mut self, id: ToolId) -> Result<(), Error> {
        let slot = self.scene.slot_mut(id)?;
        match slot.tool.description {
            ToolShape::Capsule { .. } | ToolShape::Cylinder { .. } => {
                slot.blade = true;
                Ok(())
            }
            _ => Err(Error::InvalidArgument(
                "a blade is a capsule or a cylinder tool (edge along local y)".into(),
            )),
        }
    }
    /// Make tool `id` (a capsule or a cylinder: the shaft along local y, the tip at local +y) a
    /// needle: it punctures the tissue when the tissue pushes back on its tip with the puncture
    /// force, then holds the tissue on its shaft with axial friction (see [`crate::needle`]).
    /// Nothing changes on error.
    pub fn make_needle(&mut self, id: ToolId, options: &NeedleOptions) -> Result<(), Error> {
        let slot = self.scene.slot_mut(id)?;
        slot.needle = Some(Needle::new(&slot.tool, *options)?);
        Ok(())
    }
    /// The insertion state of needle `id` ([`Error::InvalidArgument`] if the tool is not a
    /// needle).
    pub fn needle_state(&self, id: ToolId) -> Result<NeedleState, Error> {
        let slot = self.scene.slot(id)?;
        let needle = (slot.needle.as_ref())
            .ok_or_else(|| Error::InvalidArgument(format!("tool {} is not a needle", id.0)))?;
        Ok(NeedleState {
            punctured: needle.body.is_some(),
            inserted_length: needle.inserted_length(&slot.tool.pose).max(0.0),
            held: needle.holds.len(),
        })
    }
    /// Grasp with tool `id`: every free particle within [`GraspOptions::reach`] of the tool's
    /// surface is attached, where it is now, to the tool (compliant attachment constraints, see
    /// [`crate::grasp`]), and follows the tool until [`World::release`] or until the tissue
    /// slips (pull beyond [`GraspOptions::max_force`]). A grasp replaces the tool's previous
    /// one. Returns the number of grasped particles (0: nothing within reach, not an error).
    /// Nothing changes on error.
    pub fn grasp(&mut self, id: ToolId, options: &GraspOptions) -> Result<usize, Error> {
        let scene = &mut self.scene;
        let grasp = Grasp::new(&scene.slot(id)?.tool, &scene.bodies, options)?;
        let count = grasp.attachments.len();
        scene.slot_mut(id)?.grasp = grasp;
        Ok(count)
    }
    /// Release tool `id`'s grasp: the tissue is free again (contact with the tool still acts).
    pub fn release(&mut self, id: ToolId) -> Result<(), Error> {
        self.scene.slot_mut(id)?.grasp = Grasp::default();
        Ok(())
    }
    /// Number of particles tool `id` holds (0 when not grasping, or after the tissue slipped).
    pub fn grasped_count(&self, id: ToolId) -> Result<usize, Error> {
        Ok(self.scene.slot(id)?.grasp.attachments.len())
    }
    /// Number of tools in the world (removed tools not counted).
    pub fn tool_count(&self) -> usize {
        self.scene.tool_count()
    }
    /// The ids of the tools in the world, in increasing order (removed tools left out).
    pub fn tool_ids(&self) -> impl Iterator<Item = ToolId> + '_ {
        (self.scene.tools.iter().enumerate())
            .filter(|(_, t)| t.is_some())
            .map(|(i, _)| ToolId(i as u32))
    }
    /// A tool by id ([`Error::UnknownTool`] for an id never issued or removed).
    pub fn tool(&self, id: ToolId) -> Result<&Tool, Error> {
        Ok(&self.scene.slot(id)?.tool)
    }
    fn tool_mut(&mut self, id: ToolId) -> Result<&mut Tool, Error> {
        Ok(&mut self.scene.slot_mut(id)?.tool)
    }
    /// Set the pose a tool reaches at the end of the next step (interpolated across substeps).
    /// A NaN/Inf or non-unit pose is rejected and nothing changes.
    pub fn set_tool_pose(&mut self, id: ToolId, pose: Pose) -> Result<(), Error> {
        if !pose.is_valid() {
            return Err(Error::NonFinite(
                "tool pose must be finite with a unit quaternion".into(),
            ));
        }
        self.tool_mut(id)?.target = pose;
        Ok(())
    }
    /// Set the friction coefficients of a tool: static μ_s and kinetic μ_k (dimensionless,
    /// finite, 0 ≤ μ_k ≤ μ_s), from the next step on. Nothing changes on error.
    pub fn set_tool_friction(
        &mut self,
        id: ToolId,
        friction_static: Real,
        friction_kinetic: Real,
    ) -> Result<(), Error> {
        check_friction(friction_static, friction_kinetic)?;
        let tool = self.tool_mut(id)?;
        tool.options.friction_static = friction_static;
        tool.options.friction_kinetic = friction_kinetic;
        Ok(())
    }
    /// Set the friction coefficients between two bodies (organ–organ contact; frictionless
    /// unless set): static μ_s and kinetic μ_k (dimensionless, finite, 0 ≤ μ_k ≤ μ_s). `a`
    /// may equal `b` (self-contact friction). Nothing changes on error.
    pub fn set_body_pair_friction(
        &mut self,
        a: BodyId,
        b: BodyId,
        friction_static: Real,
        friction_kinetic: Real,
    ) -> Result<(), Error> {
        self.body(a)?;
        self.body(b)?;
        check_friction(friction_static, friction_kinetic)?;
        let key = (a.0.min(b.0), a.0.max(b.0));
        let pairs = &mut self.scene.pair_friction;
        pairs.retain(|f| f.bodies != key);
        pairs.push(PairFriction {
            bodies: key,
            mu_s: friction_static,
            mu_k: friction_kinetic,
        });
        Ok(())
    }

    /// The fastest (m/s) a tool may move and still be swept across the substeps, pushing the
    /// tissue along: [`TOOL_JUMP_FRACTION`](crate::TOOL_JUMP_FRACTION) of the divergence bound
    /// on particle speed (`divergence.max_speed` body sizes per second, the smallest over the
    /// bodies). A faster pose change is a jump (a tracking glitch): the tissue it would push
    /// along could move faster than the bound and fail the step, so [`World::step`] places the
    /// tool at its new pose at once, and the tissue it lands in leaves it at
    /// [`Settings::max_depenetration_speed`]. Infinite when the speed bound is off or the world
    /// has no body.
    pub fn tool_jump_speed(&self) -> Real {
        self.scene.tool_jump_speed()
    }

    /// Substeps the next step needs, and whether `max_substeps` clamped that number: enough
    /// for the explicit stability limit of the stiffest body, and enough that no tool moves
    /// (translation plus rotation at its bounding radius) more than one particle radius per
    /// substep, so that a fast tool is swept rather than teleported; a jump (faster than
    /// [`World::tool_jump_speed`]) is not swept. A count raised by these rules (or by the
    /// crushed-tissue rules of [`Settings::crushed_substeps`]) is kept for
    /// [`SUBSTEP_HOLD_STEPS`](crate::SUBSTEP_HOLD_STEPS) steps after they ask for less.
    pub fn substeps_needed(&self) -> (u32, bool) {
        self.scene.substeps_needed()
    }

    /// Advance the world by `settings.dt` (`solver::Pipeline::step` on the world's scene).
    /// When a body becomes non-finite or leaves the physical bounds of
    /// [`Settings::divergence`](crate::Settings::divergence) the world is rolled back to the
    /// start of the step and [`Error::Diverged`] says which body and why.
    pub fn step(&mut self) -> Result<StepReport, Error> {
        let report = self.pipeline.step(&mut self.scene);
        if let Err(Error::Diverged(_)) = report {
            self.diverged_steps += 1;
        }
        report
    }

    /// Measure the wall time of every stage of the steps from now on (`true`), or stop
    /// (`false`, the default): [`World::step_profile`]. Off, a step reads no clock.
    pub fn set_profiling(&mut self, on: bool) {
        self.pipeline.profiler.set(on);
    }

    /// Where the last step's time went, stage by stage ([`StepProfile`]: wall times of the
    /// calling thread, summed over the substeps), while profiling is on
    /// ([`World::set_profiling`]); `None` when it is off or no step has run since.
    pub fn step_profile(&self) -> Option<StepProfile> {
        self.pipeline.profiler.last()
    }

    /// Bring the world to rest in its equilibrium under gravity, fixed particles held: a scene
    /// that starts from `settle()` hangs still instead of swinging into place. Two stages:
    /// a static solve of each body's discrete energy (Newton–Krylov with load continuation,
    /// at most [`SETTLE_MAX_ITERATIONS`] per body, to a relative force residual of
    /// [`SETTLE_TOLERANCE`]: `crate::statics`), then dynamic relaxation with the world's own
    /// step and kinetic damping (every particle stopped, half a substep back, whenever the
    /// kinetic energy passes a peak) until no particle moves faster than [`SETTLE_SPEED`] or
    /// [`SETTLE_MAX_STEPS`] steps. The second stage ends in the equilibrium the step itself
    /// holds, tools included: with the volume constraints on (the default) that is a few per
    /// cent of the sag away from the energy's minimum (2–6% on the default organ and liver_4k
    /// at ν 0.45–0.49: one XPBD pass per substep under-applies the volume stiffness), and a
    /// few hundred steps close it; with them off the static solution is the step's own rest.
    /// When the static solve does not converge, its bodies keep their positions and the
    /// relaxation does all the work (`SettleReport::relative_residual` then says how far from
    /// equilibrium they started). Simulated time is not advanced and velocities end at zero.
    ///
    /// Fails without changing anything for a body with no fixed particle (a free body has no
    /// static equilibrium under gravity), or if a relaxation step diverges.
    ///
    /// [`SETTLE_MAX_ITERATIONS`]: crate::statics::SETTLE_MAX_ITERATIONS
    /// [`SETTLE_TOLERANCE`]: crate::statics::SETTLE_TOLERANCE
    /// [`SETTLE_SPEED`]: crate::statics::SETTLE_SPEED
    /// [`SETTLE_MAX_STEPS`]: crate::statics::SETTLE_MAX_STEPS
    pub fn settle(&mut self) -> Result<crate::solver::statics::SettleReport, Error> {
        use crate::solver::statics::{settle_body, SettleReport, SETTLE_MAX_STEPS, SETTLE_SPEED};
        let g = self.scene.settings.gravity;
        let mut settled = self.scene.bodies.clone();
        let (mut newton_iterations, mut relative_residual) = (0, 0.0 as Real);
        for body in &mut settled {
            let s = settle_body(body, g)?;
            newton_iterations += s.iterations;
            relative_residual = relative_residual.max(s.relative_residual);
        }
        let before = std::mem::replace(&mut self.scene.bodies, settled);
        let time = self.scene.time;
        let (steps, speed) = match self.relax(SETTLE_MAX_STEPS, true) {
            Ok(r) => r,
            Err(e) => {
                self.scene.bodies = before;
                self.scene.time = time;
                return Err(e);
            }
        };
        self.scene.time = time;
        Ok(SettleReport {
            newton_iterations,
            relative_residual,
            relaxation_steps: steps,
            max_speed: speed,
            converged: speed < SETTLE_SPEED,
        })
    }

    /// Dynamic relaxation: steps with kinetic damping until no particle moves faster than
    /// [`SETTLE_SPEED`](crate::statics::SETTLE_SPEED) (m/s) or `max_steps` steps; ends at rest.
    /// Returns the steps taken and the last largest speed (m/s).
    ///
    /// When the kinetic energy passes a peak, every particle goes back half its last substep
    /// (`x ← x − h v / 2`, settle's choice; `back = false` stops it where it is) and stops. The
    /// half step matters: symplectic Euler's velocity belongs half a substep behind its
    /// position, and a mode of frequency ω stopped where it is restarts with up to
    /// `1/√(1 − (ωh)²/4)` of its amplitude (2.3× at the `ωh = 1.8` the default stability margin
    /// allows), so the stiffest modes can grow under repeated stops. Stopped half a substep
    /// back, no mode with `ωh < 2` gains amplitude.
    fn relax(&mut self, max_steps: u32, back: bool) -> Result<(u32, Real), Error> {
        // Stop every particle after moving it back by its velocity times `rewind` (s).
        let at_rest = |w: &mut World, rewind: Real| {
            for b in &mut w.scene.bodies {
                let state = &mut b.state;
                for (x, v) in state.x.iter_mut().zip(state.v.iter_mut()) {
                    *x -= *v * rewind;
                    *v = Vec3::zeros();
                }
            }
        };
        let mut previous = 0.0;
        let mut steps = 0;
        let mut speed = Real::INFINITY;
        // Whether the last step ended with a stop: the step after one starts from rest, and
        // its speed (the residual force's one step of acceleration, slowed by the damping
        // filter) says little about how far the rest is.
        let mut stopped = false;
        while steps < max_steps {
            let report = self.step()?;
            steps += 1;
            speed = (self.scene.bodies.iter().flat_map(|b| b.state.v.iter()))
                .map(|v| v.norm())
                .fold(0.0, Real::max);
            if speed < crate::solver::statics::SETTLE_SPEED && !stopped {
                break;
            }
            stopped = false;
            let kinetic: Real = (self.scene.bodies.iter())
                .flat_map(|b| b.state.v.iter().zip(&b.derived.inertial_mass))
                .map(|(v, m)| m * v.norm_squared())
                .sum();
            if kinetic < previous {
                let half = if back { 0.5 } else { 0.0 };
                at_rest(
                    self,
                    half * self.scene.settings.dt / report.substeps as Real,
                );
                previous = 0.0;
                stopped = true;
            } else {
                previous = kinetic;
            }
        }
        at_rest(self, 0.0);
        Ok((steps, speed))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::lattice_box;

    /// A lattice block, bottom layer fixed, no gravity, its stiffest mode at ωh = 1.97, every
    /// free particle displaced by ±1% of a cell in a checkerboard (mostly the stiffest modes):
    /// the kinetic-damping relaxation brings it to rest. Without stiffness-proportional
    /// damping, which would take those modes out by itself.
    fn relax_checkerboard(back: bool) -> Result<(u32, Real), Error> {
        let settings = |dt| Settings {
            dt,
            gravity: Vec3::zeros(),
            stability_margin: 0.99,
            mass_scaling: false,
            volume_constraints: false,
            damping_stiffness: 0.0,
            ..Settings::default()
        };
        let mut world = World::new(settings(1e-3)).unwrap();
        let cells = [6, 6, 6];
        let id = world
            .add_body(
                &lattice_box(Vec3::zeros(), Vec3::repeat(0.06), cells),
                &crate::BodyOptions::default(),
            )
            .unwrap();
        world
            .fix_box(id, Vec3::repeat(-1.0), Vec3::new(1.0, 1e-6, 1.0))
            .unwrap();
        let omega = world.scene.bodies[0].max_angular_frequency();
        world.set_settings(settings(1.97 / omega)).unwrap();
        assert_eq!(world.substeps_needed().0, 1);
        let body = &world.scene.bodies[0];
        let x: Vec<Vec3> = (body.rest_positions().iter().enumerate())
            .map(|(i, x)| {
                let (a, b, c) = (i % 7, (i / 7) % 7, i / 49);
                let sign = if (a + b + c) % 2 == 0 { 1.0 } else { -1.0 };
                if body.is_fixed(i) {
                    *x
                } else {
                    x + Vec3::new(1.0, 0.7, 0.4) * (1e-4 * sign)
                }
            })
            .collect();
        let v = vec![Vec3::zeros(); x.len()];
        world.set_body_state(id, &x, &v).unwrap();
        world.relax(5000, back)
    }

    #[test]
    fn relaxation_stops_the_stiffest_modes_half_a_substep_back() {
        let (steps, speed) = relax_checkerboard(true).unwrap();
        assert!(
            speed < crate::solver::statics::SETTLE_SPEED,
            "{steps} steps, {speed} m/s"
        );
        // Stopped where they are, the same modes gain amplitude at the stops until the step
        // diverges (measured: at t ≈ 0.11 s, after ~1,600 steps with the half step back).
        let without = relax_checkerboard(false);
        assert!(
            without
                .as_ref()
                .map_or(true, |r| r.1 >= crate::solver::statics::SETTLE_SPEED),
            "{without:?}"
        );
    }

    /// The force pass keeps pair forces only on several threads: a world on one holds none (a
    /// body's worth of memory, ~15 MB on liver_31k); switched to two it sizes them and steps
    /// with the bits of a world built on two; switched back it frees them.
    #[test]
    fn kept_pair_forces_follow_the_thread_count() {
        let world = |threads| {
            let mut w = World::new(Settings {
                threads,
                ..Settings::default()
            })
            .unwrap();
            let mesh = lattice_box(Vec3::zeros(), Vec3::new(0.08, 0.04, 0.04), [8, 4, 4]);
            let id = w.add_body(&mesh, &crate::BodyOptions::default()).unwrap();
            w.fix_box(id, Vec3::repeat(-1.0), Vec3::new(1e-6, 1.0, 1.0))
                .unwrap();
            w
        };
        let kept = |w: &World| {
            let s = &w.pipeline.workspace.bodies[0];
            (s.pair_force.len(), s.own_force.len())
        };
        let sized = {
            let b = &world(1).scene.bodies[0];
            (b.model.nbr.slot_count(), b.state.x.len())
        };
        let mut switched = world(1);
        assert_eq!(kept(&switched), (0, 0));
        switched
            .set_settings(Settings {
                threads: 2,
                ..Settings::default()
            })
            .unwrap();
        assert_eq!(kept(&switched), sized);
        let mut built = world(2);
        assert_eq!(kept(&built), sized);
        for _ in 0..20 {
            switched.step().unwrap();
            built.step().unwrap();
        }
        assert_eq!(
            switched.scene.bodies[0].state.x,
            built.scene.bodies[0].state.x
        );
        assert!(switched.scene.bodies[0]
            .state
            .v
            .iter()
            .any(|v| v.norm() > 0.0));
        switched.set_settings(Settings::default()).unwrap();
        assert_eq!(kept(&switched), (0, 0));
        switched.step().unwrap();
    }
}
