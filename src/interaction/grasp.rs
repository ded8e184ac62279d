//! Grasping: a tool holds the tissue within its jaws through compliant attachment constraints.
//!
//! [`World::grasp`](crate::World::grasp) attaches every free particle within
//! [`GraspOptions::reach`] of the tool's surface to the point of the tool frame where it is at
//! that moment. Each substep, every attachment is projected towards its point on the moving tool
//! as an XPBD constraint `C = p − T·a` (vector, `a` the anchor in the tool frame, `T` the tool's
//! pose interpolated over the substep) with compliance `α` (m/N):
//! `Δλ = −(C + α̃ λ) / (w + α̃)`, `α̃ = α / h²`, `Δp = w Δλ`. The particle's correction
//! (times its mass) goes into the tool's wrench like a contact's, so the tool's force is the
//! tissue's pull in N. When the attachments together pull on the tool with more than
//! [`GraspOptions::max_force`] the tissue slips out of the jaws: every attachment is released.
//! While a tool holds particles of a body, contact between that tool and that body is off (the
//! jaws enclose the tissue, and contact would fight the attachments);
//! [`World::release`](crate::World::release) lets go and contact acts again.

use crate::error::Error;
use crate::kernels::math::{Real, Vec3};
use crate::scene::body::Body;
// The grasp's data (its options, the attachments) is in the scene layer, whose tool slots and
// `WorldState` hold it; this file is what a grasp does with it.
use crate::scene::grasp_state::{Attachment, Grasp};
use crate::scene::particles::ParticleViews;
use crate::scene::tool::{Pose, Tool, ToolLoad};
use parry3d_f64::math::Point;

pub use crate::scene::grasp_state::GraspOptions;

impl Grasp {
    /// Whether any particle of body `b` is held: contact between the tool and that body is then
    /// off (the jaws enclose the tissue; contact would fight the attachments).
    pub(crate) fn holds(&self, b: usize) -> bool {
        self.attachments.iter().any(|a| a.body as usize == b)
    }

    /// The free particles of `bodies` within the options' reach of `tool` (at its current pose),
    /// anchored where they are. Empty when nothing is within reach.
    pub(crate) fn new(
        tool: &Tool,
        bodies: &[Body],
        options: &GraspOptions,
    ) -> Result<Grasp, Error> {
        options.validate()?;
        let iso = tool.pose.isometry();
        let mut attachments = Vec::new();
        for (b, body) in bodies.iter().enumerate() {
            let reach = options.reach.unwrap_or(1.5 * body.model.particle_radius);
            let compliance = options.compliance.unwrap_or(
                1.0 / (body.model.options.material.youngs_modulus * body.model.particle_radius),
            );
            let limit = tool.bounding_radius + reach;
            for (i, x) in body.state.x.iter().enumerate() {
                if body.inv_mass[i] == 0.0 || (x - tool.pose.position).norm() > limit {
                    continue;
                }
                let d = tool.shape.distance_to_point(&iso, &Point::from(*x), true);
                if d <= reach {
                    attachments.push(Attachment {
                        body: b as u32,
                        particle: i as u32,
                        anchor: iso.inverse_transform_point(&Point::from(*x)).coords,
                        compliance,
                        lambda: Vec3::zeros(),
                    });
                }
            }
        }
        Ok(Grasp {
            attachments,
            max_force: options.max_force,
            acc_impulse: Vec3::zeros(),
        })
    }

    /// Start a substep: the XPBD multipliers restart from zero.
    pub(crate) fn begin_substep(&mut self) {
        self.attachments
            .iter_mut()
            .for_each(|a| a.lambda = Vec3::zeros());
    }

    /// One projection pass of every attachment towards the tool at pose `cur` for a substep `h`
    /// (s), on the particles of `views`; the particles' corrections (times their masses) go
    /// into the tool's `load` and this grasp's own accumulator.
    pub(crate) fn project(
        &mut self,
        views: &mut impl ParticleViews,
        cur: &Pose,
        load: &mut ToolLoad,
        h: Real,
    ) {
        let iso = cur.isometry();
        for a in &mut self.attachments {
            let view = views.view(a.body as usize);
            let i = a.particle as usize;
            let w = view.inv_mass[i];
            if w == 0.0 {
                continue;
            }
            let target = iso.transform_point(&Point::from(a.anchor)).coords;
            let c = view.p[i] - target;
            let alpha = a.compliance / (h * h);
            let dl = -(c + a.lambda * alpha) / (w + alpha);
            a.lambda += dl;
            let dp = dl * w;
            view.p[i] += dp;
            let impulse = dp * view.mass[i];
            load.impulse += impulse;
            load.moment += (target - cur.position).cross(&impulse);
            self.acc_impulse += impulse;
        }
    }

    /// End a step of `n` substeps of length `h` (s): release everything when the attachments'
    /// mean force over the step exceeded the slip limit. Returns true if the tissue slipped.
    pub(crate) fn end_step(&mut self, h: Real, n: u32) -> bool {
        let force = self.acc_impulse.norm() / (h * h * n as Real);
        self.acc_impulse = Vec3::zeros();
        if force > self.max_force {
            self.attachments.clear();
            return true;
        }
        false
    }
}
