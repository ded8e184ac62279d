//! The step: [`Pipeline::step`] runs Algorithm 1 of the paper on a [`Scene`] as a sequence of
//! passes, one file each. The pipeline owns only what a step uses and throws away (the
//! [`Workspace`], the rollback copy included) and the thread pool; everything the step advances
//! is the scene's (rapier's `PhysicsPipeline`, MuJoCo's model/data split).
//!
//! One step of `dt` is split into `n` substeps of `h = dt / n` (`n` from the explicit stability
//! limit of the stiffest body, at least `Settings::min_substeps`: `Scene::substeps_needed`).
//! Data flow of one step:
//!
//! 1. copy the scene's state (one [`WorldState`](crate::WorldState) value: particles, fixed
//!    flags, cuts, tools, grasps, needle holds, time) into the workspace's rollback copy
//!    (`Scene::state_into`); clear the tools' wrench accumulators;
//! 2. per substep: [`predict`] (gravity and point-based elastic forces into `force`, then
//!    `v ← v/(1 + α h) + h f/m`, `p = x + h v`); `Settings::iterations` Gauss–Seidel passes of
//!    [`volume`] (XPBD tetrahedra), [`organ_contact`] (particle pairs through the hash grid),
//!    [`tool_contact`] (each tool against each body, friction, wrench; on the tetrahedra, the
//!    crush guard and the contact again while the contact crushes a tetrahedron), then the grasps
//!    (`crate::grasp`) and needle holds (`crate::needle`); finally `v = (p − x)/h`, `x = p`;
//! 3. the divergence check ([`divergence_check`]): a failure puts the rollback copy back
//!    (`Scene::apply_state`, the code `Scene::set_state` uses after its checks);
//! 4. grasp slip, blade cuts (`crate::cut`), the tools' wrenches (mean over the substeps) and
//!    poses, needle puncture or withdrawal, time.
//!
//! Tools move from their previous pose to the pose set by
//! [`World::set_tool_pose`](crate::World::set_tool_pose) across the substeps (linear position,
//! slerp orientation); a tool faster than
//! [`World::tool_jump_speed`](crate::World::tool_jump_speed) is placed at its new pose at once
//! (a jump; blades excepted). The passes read the scene's bodies (model and state) and write the
//! [`Workspace`] (per body a `StepScratch`: predicted positions `p`, forces, multipliers; the
//! hash grid; the surface-contact scratch; the rollback copy); only the prediction (velocities,
//! rotations) and the final update (`v = (p − x)/h`, `x = p`) write the bodies' state.

mod divergence_check;
mod organ_contact;
mod predict;
pub(crate) mod profile;
pub mod statics;
mod surface_self_contact;
mod tool_contact;
mod volume;
mod workspace;

pub(crate) use crate::interaction::surface_contact::SurfaceScratch;
pub(crate) use surface_self_contact::SelfContactScratch;
pub(crate) use workspace::{StepScratch, Workspace};

use crate::error::Error;
use crate::kernels::math::{Real, Vec3};
use crate::kernels::parallel::{Pool, SharedSlice};
use crate::model::body_model::BodyModel;
use crate::scene::body::{volume_on, Body};
use crate::scene::cut::{Blade, CutReport};
use crate::scene::particles::{ParticleView, ParticleViews};
use crate::scene::settings::{ElasticScheme, VolumeScheme, MAX_THREADS};
use crate::scene::tool::{Pose, ToolShape, Wrench};
use crate::scene::{Scene, StepReport};
use crate::solver::divergence_check::ParticleScan;
use crate::solver::profile::{Profiler, Stage};
use parry3d_f64::math::Point;
use std::time::Instant;

/// The bodies' particle views over their step scratch, by body index.
struct Views<'a> {
    bodies: &'a [Body],
    scratch: &'a mut [StepScratch],
}

impl ParticleViews for Views<'_> {
    fn view(&mut self, b: usize) -> ParticleView<'_> {
        self.scratch[b].view(&self.bodies[b])
    }
}

/// The step's machinery: the scratch memory of a step and the threads, no scene. Sized for the
/// bodies of the scene it steps as they are added (and after a cut), so that
/// [`Pipeline::step`] allocates nothing.
pub(crate) struct Pipeline {
    /// All the memory a step uses and throws away, the rollback copy included.
    pub(crate) workspace: Workspace,
    /// The threads of the force, volume, prediction and update passes.
    pool: Pool,
    /// The stages' wall times, when profiling is on.
    pub(crate) profiler: Profiler,
}

impl Pipeline {
    /// A pipeline with no body, stepping on `threads` threads.
    pub(crate) fn new(threads: u32) -> Pipeline {
        Pipeline {
            workspace: Workspace::default(),
            pool: Pool::new(threads as usize),
            profiler: Profiler::default(),
        }
    }

    /// The pipeline's threads.
    pub(crate) fn pool(&self) -> &Pool {
        &self.pool
    }

    /// Make room for one more body of the scene, on `model`.
    pub(crate) fn add_body(&mut self, model: &BodyModel) {
        self.workspace.add_body(model, self.pool.threads());
    }

    /// Step on `threads` threads from now on, the scratch of the scene's `bodies` resized.
    pub(crate) fn set_threads(&mut self, threads: u32, bodies: &[Body]) {
        self.pool = Pool::new(threads as usize);
        let models = bodies.iter().map(|b| &*b.model);
        self.workspace.set_threads(models, self.pool.threads());
    }

    /// Size the scratch for the scene's `bodies` after a change of topology (a cut, or a
    /// restored state with other cuts), so that the next step allocates nothing.
    pub(crate) fn fit_boundaries(&mut self, bodies: &[Body]) {
        self.workspace
            .fit_boundaries(bodies.iter().map(|b| &*b.model));
    }

    /// Advance `scene` by `settings.dt` (see the module documentation). When a body becomes
    /// non-finite or leaves the physical bounds of
    /// [`Settings::divergence`](crate::Settings::divergence) the scene is rolled back to the
    /// start of the step and [`Error::Diverged`] says which body and why.
    pub(crate) fn step(&mut self, scene: &mut Scene) -> Result<StepReport, Error> {
        let step_start = self.profiler.start();
        let mut rollback = std::mem::take(&mut self.workspace.rollback);
        scene.state_into(&mut rollback, &self.pool);
        let (n, clamped) = scene.take_substeps();
        let mut clock = self.profiler.charge(Stage::StateCopy, step_start);
        // A jump is not swept: the tool is placed at its target for the whole step and the
        // tissue it lands in leaves it at `max_depenetration_speed`. A blade does not push; it
        // cuts along its whole path, however fast.
        let jump = scene.tool_jump_distance();
        for slot in scene.tools.iter_mut().flatten().filter(|s| !s.blade) {
            let t = &mut slot.tool;
            if t.travel() > jump {
                t.pose = t.target;
            }
        }
        let h = scene.settings.dt / n as Real;
        for slot in scene.tools.iter_mut().flatten() {
            slot.load.impulse = Vec3::zeros();
            slot.load.moment = Vec3::zeros();
            slot.load.penetration = 0.0;
        }
        for k in 1..=n {
            clock = self.substep(scene, h, k, n, clock);
        }
        let limits = scene.settings.divergence;
        let failure = (scene.bodies.iter().zip(&rollback.bodies))
            .zip(&self.workspace.bodies)
            .enumerate()
            .find_map(|(b, ((body, before), scratch))| {
                let volume = volume_on(&self.pool, &body.state.x, &body.model.boundary);
                let ratio = volume / body.rest_volume();
                crate::solver::divergence_check::diverged(
                    body,
                    &scratch.scan,
                    ratio,
                    &before.particles.x,
                    &limits,
                )
                .map(|why| (b, why))
            });
        if let Some((b, why)) = failure {
            // The whole state at the start of the step back: particles, grasps, needle holds.
            scene.apply_state(&rollback);
            self.fit_boundaries(&scene.bodies);
            self.workspace.rollback = rollback;
            self.profiler.charge(Stage::EndOfStep, clock);
            self.profiler.finish(step_start);
            return Err(Error::Diverged(format!(
                "body {b} at t = {} s: {why}; the step was rolled back (move the tool away, \
                 restore a state, or reduce dt or the stiffness)",
                scene.time
            )));
        }
        for slot in scene.tools.iter_mut().flatten() {
            slot.grasp.end_step(h, n);
        }
        let mut cut = CutReport::default();
        for slot in scene.tools.iter().flatten().filter(|s| s.blade) {
            let t = &slot.tool;
            let half = match t.description {
                ToolShape::Capsule { half_height, .. }
                | ToolShape::Cylinder { half_height, .. } => half_height,
                _ => continue,
            };
            let edge = |p: &Pose| {
                let iso = p.isometry();
                [-half, half].map(|y| iso.transform_point(&Point::new(0.0, y, 0.0)).coords)
            };
            let blade = Blade {
                from: edge(&t.pose),
                to: edge(&t.target),
            };
            for body in &mut scene.bodies {
                let r = crate::scene::cut::cut(body, &blade);
                cut.pairs += r.pairs;
                cut.tets += r.tets;
                cut.isolated += r.isolated;
            }
        }
        if cut.tets > 0 {
            self.fit_boundaries(&scene.bodies);
        }
        let dt = scene.settings.dt;
        for slot in scene.tools.iter_mut().flatten() {
            let (t, load) = (&mut slot.tool, &slot.load);
            let scale = -1.0 / (h * h * n as Real);
            t.wrench = Wrench {
                force: load.impulse * scale,
                torque: load.moment * scale,
                contact_count: load.contacts,
                max_penetration: load.penetration,
            };
            t.linear_velocity = (t.target.position - t.pose.position) / dt;
            t.pose = t.target;
        }
        for slot in scene.tools.iter_mut().flatten() {
            if let Some(needle) = &mut slot.needle {
                needle.end_step(&slot.tool, &scene.bodies);
            }
        }
        scene.time += dt;
        self.workspace.rollback = rollback;
        self.profiler.charge(Stage::EndOfStep, clock);
        self.profiler.finish(step_start);
        Ok(StepReport {
            substeps: n,
            substeps_clamped: clamped,
            cut,
        })
    }

    /// Substep `k` of `n` (1-based) of length `h` (s), its stages' times charged from `clock`
    /// (profiling on); returns the end of its last stage.
    fn substep(
        &mut self,
        scene: &mut Scene,
        h: Real,
        k: u32,
        n: u32,
        mut clock: Option<Instant>,
    ) -> Option<Instant> {
        let s = &scene.settings;
        let gravity = s.gravity;
        let alpha_damp = 1.0 / (1.0 + s.damping_mass * h);
        let scratch = &mut self.workspace.bodies;
        for (body, scratch) in scene.bodies.iter_mut().zip(scratch.iter_mut()) {
            predict::predict(
                body,
                s.elastic_scheme,
                scratch,
                gravity,
                h,
                alpha_damp,
                &self.pool,
            );
        }
        clock = self.profiler.charge(Stage::Prediction, clock);
        let organ_contact = scene.bodies.len() > 1;
        if organ_contact {
            let cell = 2.0
                * scene
                    .bodies
                    .iter()
                    .map(|b| b.model.particle_radius)
                    .fold(0.0, Real::max);
            self.workspace
                .grid
                .build(scratch.iter().map(|s| s.p.as_slice()), cell);
            clock = self.profiler.charge(Stage::OrganContact, clock);
        }
        for slot in scene.tools.iter_mut().flatten() {
            slot.load.contacts = 0;
        }
        for slot in scene.tools.iter_mut().flatten() {
            slot.grasp.begin_substep();
        }
        let s_cur = k as Real / n as Real;
        for slot in scene.tools.iter_mut().flatten() {
            if let Some(needle) = &mut slot.needle {
                let tool = &slot.tool;
                let cur = Pose::interpolate(&tool.pose, &tool.target, s_cur);
                let mut views = Views {
                    bodies: &scene.bodies,
                    scratch,
                };
                needle.begin_substep(&mut views, &cur);
            }
        }
        let s_prev = (k - 1) as Real / n as Real;
        clock = self.profiler.charge(Stage::GraspAndNeedle, clock);
        for it in 0..scene.settings.iterations {
            if scene.settings.volume_constraints {
                for (body, scratch) in scene.bodies.iter().zip(scratch.iter_mut()) {
                    match scene.settings.volume_scheme {
                        VolumeScheme::Tetrahedra => {
                            volume::project_volumes(body, scratch, h, &self.pool)
                        }
                        VolumeScheme::DualCells => {
                            volume::project_dual_cells(body, scratch, h, &self.pool)
                        }
                    }
                    if scene.settings.elastic_scheme == ElasticScheme::Tetrahedra {
                        volume::project_crushed_tets(body, scratch);
                    }
                }
            }
            clock = self.profiler.charge(Stage::Volume, clock);
            if organ_contact {
                organ_contact::project_organ_contacts(
                    &self.workspace.grid,
                    &scene.bodies,
                    scratch,
                    &scene.pair_friction,
                );
                clock = self.profiler.charge(Stage::OrganContact, clock);
            }
            if scene.settings.self_contact {
                for (b, (body, scratch)) in scene.bodies.iter().zip(scratch.iter_mut()).enumerate()
                {
                    let own = (b as u32, b as u32);
                    let friction = (scene.pair_friction.iter().find(|f| f.bodies == own))
                        .map_or((0.0, 0.0), |f| (f.mu_s, f.mu_k));
                    surface_self_contact::project_self_contacts(
                        &mut self.workspace.self_contact,
                        body,
                        scratch,
                        friction,
                        scene.settings.max_depenetration_speed * h,
                        &self.pool,
                    );
                }
                clock = self.profiler.charge(Stage::SelfContact, clock);
            }
            tool_contact::project_tool_contacts(
                &mut self.workspace.surface,
                scene,
                scratch,
                (s_prev, s_cur),
                h,
                it == 0,
                &self.pool,
            );
            clock = self.profiler.charge(Stage::ToolContact, clock);
            for slot in scene.tools.iter_mut().flatten() {
                if !slot.grasp.attachments.is_empty() {
                    let tool = &slot.tool;
                    let cur = Pose::interpolate(&tool.pose, &tool.target, s_cur);
                    let mut views = Views {
                        bodies: &scene.bodies,
                        scratch,
                    };
                    slot.grasp.project(&mut views, &cur, &mut slot.load, h);
                }
            }
            for slot in scene.tools.iter_mut().flatten() {
                if let Some(needle) = &mut slot.needle {
                    let tool = &slot.tool;
                    let cur = Pose::interpolate(&tool.pose, &tool.target, s_cur);
                    let mut views = Views {
                        bodies: &scene.bodies,
                        scratch,
                    };
                    needle.project(&mut views, &cur, &mut slot.load, h);
                }
            }
        }
        clock = self.profiler.charge(Stage::GraspAndNeedle, clock);
        // The update, and on the last substep the particle half of the divergence check,
        // one scan per share merged in share order.
        let inv_h = 1.0 / h;
        let last = k == n;
        for (body, scratch) in scene.bodies.iter_mut().zip(scratch.iter_mut()) {
            let n = body.state.x.len();
            let max_speed =
                crate::solver::divergence_check::max_speed(body, &scene.settings.divergence);
            let predicted = &scratch.p;
            let state = &mut body.state;
            let (position, velocity) = (
                SharedSlice::new(&mut state.x),
                SharedSlice::new(&mut state.v),
            );
            let mut scans = [ParticleScan::EMPTY; MAX_THREADS];
            let shared_scans = SharedSlice::new(&mut scans[..self.pool.threads()]);
            self.pool.run(&|share| {
                let range = self.pool.share(share, n);
                // SAFETY: the shares' ranges are disjoint, and each writes its own scan.
                let (x, v, scan) = unsafe {
                    (
                        position.range(range.clone()),
                        velocity.range(range.clone()),
                        shared_scans.element(share),
                    )
                };
                let updated = predicted[range.clone()].iter().zip(x).zip(v).zip(range);
                let update = |((p, x), v): ((&Vec3, &mut Vec3), &mut Vec3)| {
                    *v = (p - *x) * inv_h;
                    *x = *p;
                };
                if last {
                    let mut mine = ParticleScan::EMPTY;
                    for (((p, x), v), i) in updated {
                        update(((p, &mut *x), &mut *v));
                        mine.visit(i, x, v, max_speed);
                    }
                    *scan = mine;
                } else {
                    updated.for_each(|(pxv, _)| update(pxv));
                }
            });
            if last {
                let shares = &scans[..self.pool.threads()];
                scratch.scan = shares.iter().fold(ParticleScan::EMPTY, |a, b| a.then(b));
            }
        }
        self.profiler.charge(Stage::Update, clock)
    }
}
