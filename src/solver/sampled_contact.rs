//! Tool–tissue contact in the paper's sampled-points mode
//! ([`ContactMode::SampledPoints`](crate::ContactMode::SampledPoints)): the tool's surface
//! samples, each a sphere, against the body's particles, with friction, accumulating the tool's
//! wrench.

use crate::body::Body;
use crate::collision::tool::{Pose, Tool};
use crate::constraints::contact::{project_point_sphere, ContactProjection};
use crate::constraints::friction::friction_correction;
use crate::math::{Real, Vec3};
use crate::solver::StepScratch;
use parry3d_f64::math::Point;

/// Project the contacts between the surface samples of `tool` (moving from `motion.0` to
/// `motion.1` over this substep) and the particles of `body`, with friction, each normal
/// correction at most `max_correction` (m), and accumulate the tool's impulse and moment.
pub(crate) fn project_sampled_contacts(
    tool: &mut Tool,
    body: &Body,
    scratch: &mut StepScratch,
    (prev, cur): (&Pose, &Pose),
    max_correction: Real,
    count: bool,
) {
    let iso = cur.isometry();
    // Maps a point attached to the tool at `cur` to where it was at `prev`.
    let back = prev.isometry() * iso.inverse();
    let centre = cur.position;
    let r = body.model.particle_radius;
    let reach = tool.bounding_radius + r;
    let (mu_s, mu_k) = (tool.options.friction_static, tool.options.friction_kinetic);
    for i in 0..body.state.x.len() {
        if body.inv_mass[i] == 0.0 {
            continue;
        }
        let before = scratch.p[i];
        if (before - centre).norm_squared() > reach * reach {
            continue;
        }
        let mut p = before;
        // The last contact point on the tool surface, where the impulse acts on the tool.
        let mut touched: Option<Vec3> = None;
        let mut apply = |p: &mut Vec3, c: ContactProjection, contact: Vec3, tool: &mut Tool| {
            let tool_motion = contact - back.transform_point(&Point::from(contact)).coords;
            let rel = (*p - body.state.x[i]) - tool_motion;
            *p += friction_correction(&rel, &c.normal, c.correction, mu_s, mu_k);
            tool.acc_penetration = tool.acc_penetration.max(c.depth);
            touched = Some(contact);
        };
        let rs = tool.sample_radius;
        for s in 0..tool.samples.len() {
            let sw = iso.transform_point(&Point::from(tool.samples[s])).coords;
            if let Some(c) = project_point_sphere(&mut p, &sw, r + rs, max_correction) {
                let contact = sw + c.normal * rs;
                apply(&mut p, c, contact, tool);
            }
        }
        if let Some(contact) = touched {
            let impulse = (p - before) * body.inertial_mass[i];
            tool.acc_impulse += impulse;
            tool.acc_moment += (contact - centre).cross(&impulse);
            if count {
                tool.acc_contacts += 1;
            }
            scratch.p[i] = p;
        }
    }
}
