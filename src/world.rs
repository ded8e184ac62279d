//! The scene: bodies, tools and settings; [`World::step`] runs Algorithm 1 of the paper.

use crate::body::{Body, BodyOptions};
use crate::collision::tool::{Pose, Tool, ToolOptions, ToolShape};
use crate::error::Error;
use crate::math::{Real, Vec3};
use crate::mesh::TetMesh;
use crate::settings::Settings;

/// Identifies a body inside its world (index in insertion order, never reused).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct BodyId(pub u32);

/// Identifies a tool inside its world (index in insertion order, never reused).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct ToolId(pub u32);

/// What one step did.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct StepReport {
    /// Substeps taken.
    pub substeps: u32,
    /// True when stability asked for more than `Settings::max_substeps` substeps.
    pub substeps_clamped: bool,
}

/// A simulated scene.
pub struct World {
    settings: Settings,
    bodies: Vec<Body>,
    tools: Vec<Tool>,
    time: Real,
    diverged_steps: u64,
}

impl World {
    /// An empty world; the settings are validated first.
    pub fn new(settings: Settings) -> Result<Self, Error> {
        settings.validate()?;
        Ok(World {
            settings,
            bodies: Vec::new(),
            tools: Vec::new(),
            time: 0.0,
            diverged_steps: 0,
        })
    }
    /// The settings in force.
    pub fn settings(&self) -> &Settings {
        &self.settings
    }
    /// Replace the settings (validated; the world is unchanged on error).
    pub fn set_settings(&mut self, settings: Settings) -> Result<(), Error> {
        let _ = settings;
        todo!()
    }
    /// Simulated time (s) since the world was created.
    pub fn time(&self) -> Real {
        self.time
    }
    /// Number of steps that produced NaN/Inf and were rolled back.
    pub fn diverged_steps(&self) -> u64 {
        self.diverged_steps
    }
    /// Add a deformable body built from `mesh` (node positions in m).
    pub fn add_body(&mut self, mesh: &TetMesh, options: &BodyOptions) -> Result<BodyId, Error> {
        let _ = (mesh, options, &mut self.bodies);
        todo!()
    }
    /// Number of bodies.
    pub fn body_count(&self) -> usize {
        self.bodies.len()
    }
    /// A body by id.
    pub fn body(&self, id: BodyId) -> Result<&Body, Error> {
        self.bodies
            .get(id.0 as usize)
            .ok_or(Error::UnknownBody(id.0))
    }
    /// Fix the particles with the given indices (they keep their current position).
    pub fn fix_particles(&mut self, id: BodyId, indices: &[u32]) -> Result<(), Error> {
        let _ = (id, indices);
        todo!()
    }
    /// Fix every particle whose current position lies in the box `[min, max]` (m); returns how many.
    pub fn fix_box(&mut self, id: BodyId, min: Vec3, max: Vec3) -> Result<usize, Error> {
        let _ = (id, min, max);
        todo!()
    }
    /// Add a kinematic tool.
    pub fn add_tool(
        &mut self,
        shape: ToolShape,
        pose: Pose,
        options: &ToolOptions,
    ) -> Result<ToolId, Error> {
        let _ = (shape, pose, options, &mut self.tools);
        todo!()
    }
    /// Number of tools.
    pub fn tool_count(&self) -> usize {
        self.tools.len()
    }
    /// A tool by id.
    pub fn tool(&self, id: ToolId) -> Result<&Tool, Error> {
        self.tools.get(id.0 as usize).ok_or(Error::UnknownTool(id.0))
    }
    /// Set the pose a tool reaches at the end of the next step (interpolated across substeps).
    pub fn set_tool_pose(&mut self, id: ToolId, pose: Pose) -> Result<(), Error> {
        let _ = (id, pose);
        todo!()
    }
    /// Friction coefficients (μ_s, μ_k) between two bodies (organ–organ contact).
    pub fn set_body_pair_friction(
        &mut self,
        a: BodyId,
        b: BodyId,
        friction_static: Real,
        friction_kinetic: Real,
    ) -> Result<(), Error> {
        let _ = (a, b, friction_static, friction_kinetic);
        todo!()
    }
    /// Advance the world by `settings.dt`.
    pub fn step(&mut self) -> Result<StepReport, Error> {
        todo!()
    }
    /// Size in bytes of the state [`World::save_state`] writes.
    pub fn state_size(&self) -> usize {
        todo!()
    }
    /// Append the dynamic state (time, positions, velocities, tool poses, ...) to `out`,
    /// in the versioned format of [`crate::state`].
    pub fn save_state(&self, out: &mut Vec<u8>) {
        let _ = out;
        todo!()
    }
    /// Restore a state written by [`World::save_state`] of a world with the same scene.
    pub fn restore_state(&mut self, bytes: &[u8]) -> Result<(), Error> {
        let _ = bytes;
        todo!()
    }
}
