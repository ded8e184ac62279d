//! The scene: what a step advances. The settings, the bodies, one slot per tool, the body-pair
//! friction and the simulated time, with the lookups by id and what the step needs to know of
//! them before it starts (how many substeps, when a tool jumps).
//!
//! A [`Scene`] holds no scratch memory and no threads: `solver::Pipeline` owns those and steps
//! the scene it is handed; [`World`](crate::World) is the public API over the two. The scene's
//! dynamic state as one value, [`WorldState`], is in [`state`].
//!
//! Beside it, what the scene is made of: [`body`] (a body in a world: its model, derived data,
//! fixed particles and particle state), [`derived`] (what a body derives from the settings and
//! its model), [`settings`] (`Settings`), [`tool`] (the tools: shapes, poses, wrench),
//! [`grasp_state`] and [`needle_state`] (the data of a tool's grasp and needle; what they do is
//! in [`crate::interaction`]), [`particles`] (the narrow view of a body that the interactions
//! act on) and [`cut`] (a body's topology changed by a blade, and restored from a saved state's
//! cut sets).

pub(crate) mod body;
pub mod cut;
pub(crate) mod derived;
pub(crate) mod grasp_state;
pub(crate) mod needle_state;
pub(crate) mod particles;
pub(crate) mod settings;
pub(crate) mod state;
pub(crate) mod substep_hold;
pub(crate) mod tool;

pub use state::WorldState;

use crate::error::Error;
use crate::kernels::math::Real;
use crate::kernels::tet_elasticity::COMPRESSED_RATIO;
use crate::scene::body::Body;
use crate::scene::cut::CutReport;
use crate::scene::grasp_state::Grasp;
use crate::scene::needle_state::Needle;
use crate::scene::settings::{ElasticScheme, Settings};
use crate::scene::substep_hold::SubstepHold;
use crate::scene::tool::{Tool, ToolLoad};
use parry3d_f64::bounding_volume::BoundingVolume;

/// How many steps ahead (dimensionless) [`Settings::crushed_substeps`] looks for tetrahedra at
/// a tool going below half their volume, at their corners' velocities. Switching on the
/// volumes at the start of the step alone toggled one and two substeps while a 1 cm probe
/// wobbled in the haptic scene of liver_4k, and a corner under it gained speed with each
/// switch until the step diverged (72 m/s at 1.2 s); two steps ahead keep the two substeps
/// through the wobble (3,000 steps).
const CRUSH_LOOKAHEAD_STEPS: Real = 2.0;

/// What [`Scene::crushed_at_tools`] finds at the tools.
#[derive(Debug, Clone, Copy, Default)]
struct CrushedAtTools {
    /// A tetrahedron at a tool is compressed.
    any: bool,
    /// One of them is longer than the tool is wide.
    by_a_thinner_tool: bool,
}

/// Fraction of the divergence speed bound above which a tool's motion is a jump (placed, not
/// swept). Tissue pushed by a swept tool moves faster than the tool: friction drags it along
/// and compressed tissue springs back (measured in `tests/api_robustness.rs`, friction 1,
/// random sweeps at up to 12 m/s inside the default organ: tissue at up to 42 m/s, 3.5×), so
/// the tool must stay well below the bound for the tissue to stay within it.
pub const TOOL_JUMP_FRACTION: Real = 0.25;

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
    /// What the blades cut at the end of this step (all bodies together).
    pub cut: CutReport,
}

/// Friction between two bodies.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct PairFriction {
    pub(crate) bodies: (u32, u32),
    pub(crate) mu_s: Real,
    pub(crate) mu_k: Real,
}

/// One tool of a scene: its shape and pose, what the interactions put on it during a step, and
/// the roles it plays (a tool may grasp, be a needle and be a blade at once).
#[derive(Debug)]
pub(crate) struct ToolSlot {
    /// Shape, pose, target pose, options, last wrench.
    pub(crate) tool: Tool,
    /// What contact, grasp and needle put on the tool in the step in progress.
    pub(crate) load: ToolLoad,
    /// The tool's grasp (no attachments: not grasping).
    pub(crate) grasp: Grasp,
    /// The tool's needle (`None`: not a needle).
    pub(crate) needle: Option<Needle>,
    /// Whether the tool is a blade.
    pub(crate) blade: bool,
}

impl ToolSlot {
    /// A tool that is neither grasping, a needle nor a blade.
    pub(crate) fn new(tool: Tool) -> ToolSlot {
        ToolSlot {
            tool,
            load: ToolLoad::default(),
            grasp: Grasp::default(),
            needle: None,
            blade: false,
        }
    }
}

/// What a step advances: settings, bodies (model and state), tools, body-pair friction, time.
pub(crate) struct Scene {
    /// The settings in force (validated).
    pub(crate) settings: Settings,
    /// The bodies, by id ([`BodyId`] is the index).
    pub(crate) bodies: Vec<Body>,
    /// The tools, one slot each, by id ([`ToolId`] is the index); `None` for a removed tool
    /// (ids are never reused).
    pub(crate) tools: Vec<Option<ToolSlot>>,
    /// Friction between pairs of bodies (frictionless for a pair without an entry).
    pub(crate) pair_friction: Vec<PairFriction>,
    /// Simulated time (s).
    pub(crate) time: Real,
    /// The substep count held after the rules raised it ([`substep_hold`]).
    pub(crate) substep_hold: SubstepHold,
}

impl Scene {
    /// An empty scene at time 0 under `settings` (validated by the caller).
    pub(crate) fn new(settings: Settings) -> Scene {
        Scene {
            settings,
            bodies: Vec::new(),
            tools: Vec::new(),
            pair_friction: Vec::new(),
            time: 0.0,
            substep_hold: SubstepHold::default(),
        }
    }

    /// A body by id.
    pub(crate) fn body(&self, id: BodyId) -> Result<&Body, Error> {
        self.bodies
            .get(id.0 as usize)
            .ok_or(Error::UnknownBody(id.0))
    }

    /// A body by id, to change.
    pub(crate) fn body_mut(&mut self, id: BodyId) -> Result<&mut Body, Error> {
        self.bodies
            .get_mut(id.0 as usize)
            .ok_or(Error::UnknownBody(id.0))
    }

    /// A tool's slot by id ([`Error::UnknownTool`] for an id never issued or removed).
    pub(crate) fn slot(&self, id: ToolId) -> Result<&ToolSlot, Error> {
        self.tools
            .get(id.0 as usize)
            .and_then(Option::as_ref)
            .ok_or(Error::UnknownTool(id.0))
    }

    /// A tool's slot by id, to change ([`Error::UnknownTool`] for an id never issued or
    /// removed).
    pub(crate) fn slot_mut(&mut self, id: ToolId) -> Result<&mut ToolSlot, Error> {
        self.tools
            .get_mut(id.0 as usize)
            .and_then(Option::as_mut)
            .ok_or(Error::UnknownTool(id.0))
    }

    /// Number of tools (removed tools not counted).
    pub(crate) fn tool_count(&self) -> usize {
        self.tools.iter().flatten().count()
    }

    /// The fastest (m/s) a tool may move and still be swept across the substeps:
    /// [`TOOL_JUMP_FRACTION`] of the divergence bound on particle speed
    /// (`divergence.max_speed` body sizes per second, the smallest over the bodies); infinite
    /// when the speed bound is off or the scene has no body. See
    /// [`World::tool_jump_speed`](crate::World::tool_jump_speed).
    pub(crate) fn tool_jump_speed(&self) -> Real {
        let bound = self.settings.divergence.max_speed;
        let slowest = (self.bodies.iter())
            .map(|b| bound * b.model.size)
            .fold(Real::INFINITY, Real::min);
        TOOL_JUMP_FRACTION * slowest
    }

    /// The distance (m) beyond which a tool's pose change in one step is a jump:
    /// [`Scene::tool_jump_speed`] times `dt`.
    pub(crate) fn tool_jump_distance(&self) -> Real {
        self.tool_jump_speed() * self.settings.dt
    }

    /// Whether the crush guard runs: the elasticity on tetrahedra, the volume constraints on,
    /// and a tool that pushes (not a blade) in the world.
    pub(crate) fn crush_guard_on(&self) -> bool {
        let s = &self.settings;
        s.volume_constraints
            && s.elastic_scheme == ElasticScheme::Tetrahedra
            && self.tools.iter().flatten().any(|slot| !slot.blade)
    }

    /// Whether the tissue at a tool is compressed: a tetrahedron with a corner within a
    /// particle radius of a tool's bounding box (not a blade's; at the tool's pose) is below
    /// [`COMPRESSED_RATIO`] of its rest volume at the start of the step, or will be
    /// [`CRUSH_LOOKAHEAD_STEPS`] steps later at its corners' velocities; and whether such a
    /// tetrahedron is longer (its longest rest edge) than the tool is wide. Reads the state only (positions, velocities,
    /// tool poses). Only `thin_only`: the tools without a width ([`ToolShape::width`]) are not
    /// looked at (they can only set `any`). Cost: a distance per particle and tool, a point in
    /// a box for those within the tool's bounding sphere, and the tetrahedra around those in
    /// the box.
    ///
    /// [`ToolShape::width`]: crate::ToolShape
    fn crushed_at_tools(&self, thin_only: bool) -> CrushedAtTools {
        let mut found = CrushedAtTools::default();
        let tools = self.tools.iter().flatten().filter(|slot| !slot.blade);
        let ahead = CRUSH_LOOKAHEAD_STEPS * self.settings.dt;
        for tool in tools.map(|slot| &slot.tool) {
            let width = tool.description.width();
            if thin_only && width.is_none() {
                continue;
            }
            let (iso, local_box) = (tool.pose.isometry(), tool.shape.compute_local_aabb());
            for body in &self.bodies {
                let reach = body.model.particle_radius;
                let (near, within) = (tool.bounding_radius + reach, local_box.loosened(reach));
                let (x, v) = (&body.state.x, &body.state.v);
                let elements = &body.model.tet_elements;
                for (i, p) in x.iter().enumerate() {
                    let at_tool = (p - tool.pose.position).norm_squared() < near * near
                        && within.contains_local_point(&iso.inverse_transform_point(&(*p).into()));
                    let longest = at_tool
                        .then(|| {
                            let rest = &body.model.rest;
                            elements.compressed_around(i, (x, v), ahead, COMPRESSED_RATIO, rest)
                        })
                        .flatten();
                    if let Some(longest) = longest {
                        found.any = true;
                        if width.is_some_and(|w| longest > w) {
                            found.by_a_thinner_tool = true;
                            return found;
                        }
                    }
                }
            }
        }
        found
    }

    /// Substeps the next step needs, and whether `max_substeps` clamped that number: enough
    /// for the explicit stability limit of the stiffest body, and enough that no tool moves
    /// (translation plus rotation at its bounding radius) more than one particle radius per
    /// substep, so that a fast tool is swept rather than teleported; a jump (faster than
    /// [`Scene::tool_jump_speed`]) is not swept. At least `min_substeps`, and at least
    /// `crushed_substeps` when the crush guard runs and the tissue at a tool is compressed; and
    /// twice that (before `crushed_substeps`) when a compressed tetrahedron there is longer than
    /// the tool is wide ([`Scene::crushed_at_tools`]: a function of the state, so a restored
    /// state steps the same). A tool narrower than the tetrahedra it crushes presses on a corner
    /// or an edge of the mesh: in one substep the contact and the crush guard fought over those
    /// corners until the tetrahedra inverted and the tool slipped into the tissue
    /// (docs/VALIDATION.md §5); half the substep holds it. A count these rules raised is held
    /// for [`substep_hold::SUBSTEP_HOLD_STEPS`] steps after they ask for less ([`substep_hold`]).
    pub(crate) fn substeps_needed(&self) -> (u32, bool) {
        self.held_substeps(self.substeps_asked())
    }

    /// Start a step: the substeps it takes ([`Scene::substeps_needed`]), and the hold on the
    /// count moved on (part of the state, so a rolled-back step puts it back).
    pub(crate) fn take_substeps(&mut self) -> (u32, bool) {
        let asked = self.substeps_asked();
        let (n, clamped) = self.held_substeps(asked);
        self.substep_hold.advance(asked.0, n);
        (n, clamped)
    }

    /// The count of `asked` (from [`Scene::substeps_asked`]) with the hold.
    fn held_substeps(&self, (asked, clamped): (u32, bool)) -> (u32, bool) {
        let n = self
            .substep_hold
            .count_for(asked)
            .min(self.settings.max_substeps);
        (n, clamped && n == asked)
    }

    /// What the rules of [`Scene::substeps_needed`] ask for, before the hold.
    fn substeps_asked(&self) -> (u32, bool) {
        let s = &self.settings;
        let mut h_max = Real::INFINITY;
        let mut radius = Real::INFINITY;
        for b in &self.bodies {
            let w = b.derived.omega_max;
            if w > 0.0 {
                h_max = h_max.min(2.0 / w);
            }
            radius = radius.min(b.model.particle_radius);
        }
        let stable = (s.dt / (s.stability_margin * h_max)).ceil();
        let mut needed = if stable.is_finite() { stable as u32 } else { 1 };
        let jump = self.tool_jump_distance();
        let tools = self.tools.iter().flatten().map(|s| &s.tool);
        for t in tools.filter(|t| t.travel() <= jump) {
            let sweep = (t.travel() / radius).ceil();
            if sweep.is_finite() {
                needed = needed.max(sweep.min(u32::MAX as Real) as u32);
            }
        }
        let mut n = needed.max(s.min_substeps);
        if self.crush_guard_on() {
            // Where `crushed_substeps` cannot add a substep only a narrower tool matters.
            let crushed = self.crushed_at_tools(n >= s.crushed_substeps);
            if crushed.by_a_thinner_tool {
                n *= 2;
            }
            if crushed.any {
                n = n.max(s.crushed_substeps);
            }
        }
        if n > s.max_substeps {
            (s.max_substeps, true)
        } else {
            (n, false)
        }
    }
}
