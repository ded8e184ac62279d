//! The scene's dynamic state as one value, [`WorldState`]: what a step advances, what a
//! diverged step's rollback puts back, and what [`World::save_state`] and
//! [`World::restore_state`] write and read (through the byte format of [`crate::state`]).
//!
//! One mechanism serves the three: [`Scene::state_into`] copies the scene's state into a value
//! (reusing its memory, so the step's rollback copy allocates nothing), [`Scene::set_state`]
//! checks a value against the scene and applies it, and the step puts its rollback copy back
//! with the same code, unchecked ([`Scene::apply_state`]). [`World::state_into`] and
//! [`World::set_state`] are these, on the world's scene.
//!
//! [`World::save_state`]: crate::World::save_state
//! [`World::restore_state`]: crate::World::restore_state
//! [`World::state_into`]: crate::World::state_into
//! [`World::set_state`]: crate::World::set_state

use crate::error::Error;
use crate::kernels::math::{is_finite_vec, Real, Vec3};
use crate::kernels::parallel::Pool;
use crate::scene::body::{Body, ParticleState};
use crate::scene::cut::CutSets;
use crate::scene::grasp_state::Grasp;
use crate::scene::needle_state::ShaftHold;
use crate::scene::substep_hold::{SubstepHold, SUBSTEP_HOLD_STEPS};
use crate::scene::tool::{Pose, Wrench};
use crate::scene::Scene;
use std::sync::Arc;

/// The dynamic state of a world: the time and the substep count held after a raise; per body
/// its particles' positions, velocities and rotations, its fixed flags and what has been cut;
/// per tool its pose, target pose, velocity, last wrench, grasp and needle insertion.
///
/// The scene (meshes, materials, tool shapes, settings) is not part of it: a state applies to
/// the world it was taken from or to one built the same way
/// ([`World::set_state`](crate::World::set_state) checks).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct WorldState {
    /// Simulated time (s).
    pub(crate) time: Real,
    /// The substep count held after a raise ([`crate::scene::substep_hold`]).
    pub(crate) substep_hold: SubstepHold,
    /// One per body, in id order.
    pub(crate) bodies: Vec<BodyState>,
    /// One per tool in the world (removed tools left out), in id order.
    pub(crate) tools: Vec<ToolState>,
}

/// The state of one body.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct BodyState {
    /// Positions (m), velocities (m/s), rotations.
    pub(crate) particles: ParticleState,
    /// Fixed flags, one per particle.
    pub(crate) fixed: Vec<bool>,
    /// Cut pairs and removed tetrahedra (load-time indices, increasing); `None`: nothing cut.
    pub(crate) cuts: Option<Arc<CutSets>>,
}

/// The state of one tool.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct ToolState {
    /// Pose at the end of the last step.
    pub(crate) pose: Pose,
    /// Pose to reach at the end of the next step.
    pub(crate) target: Pose,
    /// Linear velocity of the origin over the last step (m/s).
    pub(crate) linear_velocity: Vec3,
    /// Wrench of the last step.
    pub(crate) wrench: Wrench,
    /// Attachments and slip limit (no attachments: not grasping).
    pub(crate) grasp: Grasp,
    /// The needle's insertion (nothing punctured for a tool that is not a needle).
    pub(crate) needle: NeedleInsertion,
}

/// Where a needle is in the tissue.
#[derive(Debug, Clone, PartialEq, Default)]
pub(crate) struct NeedleInsertion {
    /// The punctured body, if any.
    pub(crate) body: Option<u32>,
    /// Where the tip entered the tissue (m, world frame).
    pub(crate) entry: Vec3,
    /// Particles held on the shaft.
    pub(crate) holds: Vec<ShaftHold>,
}

impl WorldState {
    /// Simulated time (s) of the state.
    pub fn time(&self) -> Real {
        self.time
    }
    /// Number of bodies the state is for.
    pub fn body_count(&self) -> usize {
        self.bodies.len()
    }
    /// Number of tools the state is for (the tools in the world, removed ones left out).
    pub fn tool_count(&self) -> usize {
        self.tools.len()
    }
}

impl BodyState {
    fn of(body: &Body) -> BodyState {
        BodyState {
            particles: body.state.clone(),
            fixed: body.fixed.clone(),
            cuts: crate::scene::cut::cut_sets(body),
        }
    }
}

impl Scene {
    /// Copy the scene's dynamic state into `out`, reusing its memory (the particles copied on
    /// `pool`'s threads): once `out` has held a state of this scene, this allocates nothing.
    pub(crate) fn state_into(&self, out: &mut WorldState, pool: &Pool) {
        out.time = self.time;
        out.substep_hold = self.substep_hold;
        out.bodies.truncate(self.bodies.len());
        for (k, body) in self.bodies.iter().enumerate() {
            match out.bodies.get_mut(k) {
                Some(s) => {
                    s.particles.assign_on(&body.state, pool);
                    s.fixed.clone_from(&body.fixed);
                    s.cuts = crate::scene::cut::cut_sets(body);
                }
                None => out.bodies.push(BodyState::of(body)),
            }
        }
        let mut k = 0;
        for slot in self.tools.iter().flatten() {
            let (tool, grasp, needle) = (&slot.tool, &slot.grasp, &slot.needle);
            let (pose, target, linear_velocity, wrench) =
                (tool.pose, tool.target, tool.linear_velocity, tool.wrench);
            if k == out.tools.len() {
                out.tools.push(ToolState {
                    pose,
                    target,
                    linear_velocity,
                    wrench,
                    grasp: Grasp::default(),
                    needle: NeedleInsertion::default(),
                });
            }
            let s = &mut out.tools[k];
            (s.pose, s.target, s.linear_velocity, s.wrench) =
                (pose, target, linear_velocity, wrench);
            // The constraints' multipliers are a substep's scratch: not part of the state.
            s.grasp.attachments.clone_from(&grasp.attachments);
            s.grasp
                .attachments
                .iter_mut()
                .for_each(|a| a.lambda = Vec3::zeros());
            s.grasp.max_force = grasp.max_force;
            match needle {
                Some(n) => {
                    (s.needle.body, s.needle.entry) = (n.body, n.entry);
                    s.needle.holds.clone_from(&n.holds);
                    s.needle
                        .holds
                        .iter_mut()
                        .for_each(|h| h.lambda = Vec3::zeros());
                }
                None => {
                    (s.needle.body, s.needle.entry) = (None, Vec3::zeros());
                    s.needle.holds.clear();
                }
            }
            k += 1;
        }
        out.tools.truncate(k);
    }

    /// Put the scene in `state`, taken from this scene or from one built the same way; on any
    /// mismatch the scene is left unchanged and [`Error::BadState`] says why (see
    /// [`World::set_state`](crate::World::set_state)). A restored cut changes a boundary: the
    /// pipeline's scratch is then refitted (`Pipeline::fit_boundaries`).
    pub(crate) fn set_state(&mut self, state: &WorldState) -> Result<(), Error> {
        self.check_state(state).map_err(Error::BadState)?;
        self.apply_state(state);
        Ok(())
    }

    /// Why `state` does not fit this scene, if it does not.
    fn check_state(&self, state: &WorldState) -> Result<(), String> {
        if !state.time.is_finite() {
            return Err("non-finite time".into());
        }
        let hold = state.substep_hold;
        if hold.steps_left > SUBSTEP_HOLD_STEPS || (hold.steps_left > 0 && hold.count == 0) {
            return Err(format!(
                "substep hold of {} substeps for {} steps (at most {SUBSTEP_HOLD_STEPS}, of at \
                 least one substep)",
                hold.count, hold.steps_left
            ));
        }
        if state.bodies.len() != self.bodies.len() || state.tools.len() != self.tool_count() {
            return Err(format!(
                "state of {} bodies and {} tools, this world has {} and {}",
                state.bodies.len(),
                state.tools.len(),
                self.bodies.len(),
                self.tool_count()
            ));
        }
        for (k, (s, body)) in state.bodies.iter().zip(&self.bodies).enumerate() {
            check_body(s, body).map_err(|m| format!("body {k}: {m}"))?;
        }
        let particle_of = |body: u32, particle: u32| {
            self.bodies
                .get(body as usize)
                .is_some_and(|b| (particle as usize) < b.particle_count())
        };
        let slots = self.tools.iter().flatten();
        for (k, (s, slot)) in state.tools.iter().zip(slots).enumerate() {
            let needle = &slot.needle;
            let finite = [s.pose, s.target].iter().all(|p| {
                is_finite_vec(&p.position) && p.orientation.coords.iter().all(|c| c.is_finite())
            }) && [s.linear_velocity, s.wrench.force, s.wrench.torque]
                .iter()
                .all(is_finite_vec)
                && s.wrench.max_penetration.is_finite();
            if !finite {
                return Err(format!("tool {k}: non-finite tool state"));
            }
            let g = &s.grasp;
            if g.max_force.is_nan() || g.max_force <= 0.0 {
                return Err(format!("tool {k}: grasp slip force {}", g.max_force));
            }
            for a in &g.attachments {
                let ok = a.compliance >= 0.0 && a.compliance.is_finite();
                if !(particle_of(a.body, a.particle) && is_finite_vec(&a.anchor) && ok) {
                    return Err(format!(
                        "tool {k}: grasped particle {} of body {}: unknown or non-finite",
                        a.particle, a.body
                    ));
                }
            }
            let n = &s.needle;
            let inserted = n.body.is_some() || !n.holds.is_empty();
            if (needle.is_none() && inserted)
                || n.body.is_some_and(|b| b as usize >= self.bodies.len())
                || !is_finite_vec(&n.entry)
            {
                return Err(format!("tool {k}: needle state does not fit this tool"));
            }
            for h in &n.holds {
                if !(n.body.is_some_and(|b| particle_of(b, h.particle)) && is_finite_vec(&h.anchor))
                {
                    return Err(format!(
                        "tool {k}: needle hold of particle {}: unknown or non-finite",
                        h.particle
                    ));
                }
            }
        }
        Ok(())
    }

    /// Put the scene in `state`, which fits it (checked by [`Scene::set_state`], or taken from
    /// it by [`Scene::state_into`]). Allocates nothing when only the particles, the tools and
    /// the fixed flags differ. A restored cut changes a boundary: the caller refits the
    /// pipeline's scratch (`Pipeline::fit_boundaries`) before the next step.
    pub(crate) fn apply_state(&mut self, state: &WorldState) {
        self.time = state.time;
        self.substep_hold = state.substep_hold;
        for (body, s) in self.bodies.iter_mut().zip(&state.bodies) {
            crate::scene::cut::restore(body, &s.cuts);
            if body.fixed != s.fixed {
                body.fixed.copy_from_slice(&s.fixed);
                body.fixed_flags_changed();
            }
            body.state.assign(&s.particles);
        }
        for (slot, s) in self.tools.iter_mut().flatten().zip(&state.tools) {
            let (tool, grasp, needle) = (&mut slot.tool, &mut slot.grasp, &mut slot.needle);
            (tool.pose, tool.target, tool.linear_velocity, tool.wrench) =
                (s.pose, s.target, s.linear_velocity, s.wrench);
            grasp.attachments.clone_from(&s.grasp.attachments);
            grasp.max_force = s.grasp.max_force;
            grasp.acc_impulse = Vec3::zeros();
            if let Some(n) = needle {
                (n.body, n.entry) = (s.needle.body, s.needle.entry);
                n.holds.clone_from(&s.needle.holds);
            }
        }
    }
}

/// Why `s` does not fit `body`, if it does not.
fn check_body(s: &BodyState, body: &Body) -> Result<(), String> {
    let n = body.particle_count();
    let p = &s.particles;
    if [p.x.len(), p.v.len(), p.rotation.len(), s.fixed.len()] != [n; 4] {
        return Err(format!(
            "{} particles in the state, {n} in this world",
            p.x.len()
        ));
    }
    for (i, (x, v)) in p.x.iter().zip(&p.v).enumerate() {
        body.check_state(i, x, v)?;
    }
    if !p
        .rotation
        .iter()
        .all(|q| q.coords.iter().all(|c| c.is_finite()))
    {
        return Err("non-finite particle rotation".into());
    }
    if let Some(sets) = &s.cuts {
        let (pairs, tets) = crate::scene::cut::load_time_counts(body);
        for (list, limit) in [(&sets.0, pairs), (&sets.1, tets)] {
            let increasing = list.windows(2).all(|w| w[0] < w[1]);
            if !increasing || list.last().is_some_and(|&v| v as usize >= limit) {
                return Err("cut entries out of range or out of order".into());
            }
        }
    }
    Ok(())
}
