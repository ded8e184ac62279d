//! Where a step's time goes: the wall time of each stage of a step, measured only while
//! profiling is on ([`World::set_profiling`](crate::World::set_profiling)), read after the step
//! with [`World::step_profile`](crate::World::step_profile). Off, a step reads no clock.
//!
//! Each stage is the time the calling thread spends in it, the pool's threads included while it
//! waits for them: on several threads a stage's share of the one-thread time shows how much of it
//! the threads share (Amdahl's serial share per stage, docs/PERFORMANCE.md).

use std::time::{Duration, Instant};

/// The wall time of each stage of the last step, summed over its substeps and iterations.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct StepProfile {
    /// The copy of the state a diverged step is rolled back to.
    pub state_copy: Duration,
    /// Gravity and elastic forces, velocities and predicted positions (on the pool).
    pub prediction: Duration,
    /// The volume constraints (per-tetrahedron or dual cells, on the pool; the crush guard of the
    /// tetrahedra on the calling thread).
    pub volume: Duration,
    /// Organ–organ contact: the hash grid and the particle pairs (calling thread).
    pub organ_contact: Duration,
    /// Surface self-contact (calling thread).
    pub self_contact: Duration,
    /// Tool–tissue contact (the broad phase on the pool, the projections on the calling thread).
    pub tool_contact: Duration,
    /// Grasps and needle holds (calling thread).
    pub grasp_and_needle: Duration,
    /// The update of positions and velocities from the predicted positions (on the pool).
    pub update: Duration,
    /// The divergence check, grasp slip, cuts, the tools' wrenches and poses, needle puncture.
    pub end_of_step: Duration,
    /// The whole step.
    pub total: Duration,
}

impl StepProfile {
    /// The stages by their field names, in the order of a step, then `("total", total)`.
    pub fn stages(&self) -> [(&'static str, Duration); 10] {
        [
            ("state_copy", self.state_copy),
            ("prediction", self.prediction),
            ("volume", self.volume),
            ("organ_contact", self.organ_contact),
            ("self_contact", self.self_contact),
            ("tool_contact", self.tool_contact),
            ("grasp_and_needle", self.grasp_and_needle),
            ("update", self.update),
            ("end_of_step", self.end_of_step),
            ("total", self.total),
        ]
    }
}

/// A stage of [`StepProfile`].
#[derive(Debug, Clone, Copy)]
pub(crate) enum Stage {
    StateCopy,
    Prediction,
    Volume,
    OrganContact,
    SelfContact,
    ToolContact,
    GraspAndNeedle,
    Update,
    EndOfStep,
}

/// The pipeline's stopwatch: on or off, the step being measured and the last one measured.
#[derive(Debug, Clone, Default)]
pub(crate) struct Profiler {
    on: bool,
    current: StepProfile,
    last: Option<StepProfile>,
}

impl Profiler {
    /// Measure the steps from now on (`true`), or stop and forget the last measurement.
    pub(crate) fn set(&mut self, on: bool) {
        self.on = on;
        if !on {
            self.last = None;
        }
    }

    /// The last measured step, if profiling is on and a step has run since.
    pub(crate) fn last(&self) -> Option<StepProfile> {
        self.last
    }

    /// The time now if profiling is on: the start of a stage.
    pub(crate) fn start(&self) -> Option<Instant> {
        self.on.then(Instant::now)
    }

    /// Add the time since `since` (a [`Profiler::start`] or the last `charge`) to `stage`;
    /// the time now, the start of the next stage.
    pub(crate) fn charge(&mut self, stage: Stage, since: Option<Instant>) -> Option<Instant> {
        let since = since?;
        let now = Instant::now();
        let p = &mut self.current;
        let slot = match stage {
            Stage::StateCopy => &mut p.state_copy,
            Stage::Prediction => &mut p.prediction,
            Stage::Volume => &mut p.volume,
            Stage::OrganContact => &mut p.organ_contact,
            Stage::SelfContact => &mut p.self_contact,
            Stage::ToolContact => &mut p.tool_contact,
            Stage::GraspAndNeedle => &mut p.grasp_and_needle,
            Stage::Update => &mut p.update,
            Stage::EndOfStep => &mut p.end_of_step,
        };
        *slot += now - since;
        Some(now)
    }

    /// End the step that started at `start`: its profile becomes the last one.
    pub(crate) fn finish(&mut self, start: Option<Instant>) {
        if let Some(start) = start {
            self.current.total = start.elapsed();
            self.last = Some(std::mem::take(&mut self.current));
        }
    }
}
