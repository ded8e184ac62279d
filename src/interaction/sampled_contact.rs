//! Tool–tissue contact in the paper's sampled-points mode
//! ([`ContactMode::SampledPoints`](crate::ContactMode::SampledPoints)): the tool's surface
//! samples, each a sphere, against the body's particles, with friction, accumulating the tool's
//! wrench.
//!
//! A particle inside the tool's solid shape (after a jump, or a sweep faster than the contacts
//! can push) is first pushed along the normal of the nearest point of the tool's surface, and
//! meets the samples only once it is out: the samples alone would push it out of each sample
//! separately, in directions that fight, and a particle deep inside meets none of them.

use crate::interaction::tool_motion_at;
use crate::kernels::constraints::contact::{
    project_point_sphere, push_out_of_solid, ContactProjection,
};
use crate::kernels::constraints::friction::friction_correction;
use crate::kernels::math::{Real, Vec3};
use crate::scene::particles::ParticleView;
use crate::scene::tool::{Pose, Tool, ToolLoad};
use parry3d_f64::math::Point;

/// Project the contacts between the surface samples of `tool` (moving from `motion.0` to
/// `motion.1` over this substep) and the particles of a body (`view`), with friction, each normal
/// correction leaving the particle's motion along the normal in this substep at most the
/// tool's motion along it plus `max_correction` (m), and accumulate the tool's impulse and
/// moment.
pub(crate) fn project_sampled_contacts(
    tool: &Tool,
    load: &mut ToolLoad,
    view: ParticleView<'_>,
    (prev, cur): (&Pose, &Pose),
    max_correction: Real,
    count: bool,
) {
    let iso = cur.isometry();
    // Maps a point attached to the tool at `cur` to where it was at `prev`.
    let back = prev.isometry() * iso.inverse();
    let centre = cur.position;
    let r = view.radius;
    let reach = tool.bounding_radius + r;
    let (mu_s, mu_k) = (tool.options.friction_static, tool.options.friction_kinetic);
    for i in 0..view.x.len() {
        if view.inv_mass[i] == 0.0 {
            continue;
        }
        let before = view.p[i];
        if (before - centre).norm_squared() > reach * reach {
            continue;
        }
        let mut p = before;
        // The last contact point on the tool surface, where the impulse acts on the tool.
        let mut touched: Option<Vec3> = None;
        let mut apply = |p: &mut Vec3, c: ContactProjection, contact: Vec3| {
            let tool_motion = tool_motion_at(&back, &contact);
            let rel = (*p - view.x[i]) - tool_motion;
            *p += friction_correction(&rel, &c.normal, c.correction, mu_s, mu_k);
            load.penetration = load.penetration.max(c.depth);
            touched = Some(contact);
        };
        // The depenetration cap, as in the exact-shape mode: after a contact the particle moves
        // along its normal by at most the tool's motion along it plus `max_correction` in this
        // substep. Tissue moving into the tool is stopped whole, the tool pushes the tissue at
        // its own speed, and older penetration (a jump into the tissue) is removed at
        // `max_depenetration_speed`, however many samples overlap the particle.
        let start = view.x[i];
        let cap = |p: &Vec3, normal: &Vec3, contact: &Vec3| {
            let tool_motion = tool_motion_at(&back, contact);
            let pushed = tool_motion.dot(normal).max(0.0);
            (max_correction + pushed - (p - start).dot(normal)).max(0.0)
        };
        let surface = tool.shape.project_point(&iso, &Point::from(p), false);
        if surface.is_inside {
            let on_tool = surface.point.coords;
            let away = (p - centre).try_normalize(1e-12).unwrap_or(Vec3::y());
            let q = p;
            let c = push_out_of_solid(&mut p, &on_tool, &away, r, &|n| cap(&q, n, &on_tool));
            apply(&mut p, c, on_tool);
        }
        if !surface.is_inside || !tool.shape.contains_point(&iso, &Point::from(p)) {
            let rs = tool.sample_radius;
            for s in 0..tool.samples.len() {
                let sw = iso.transform_point(&Point::from(tool.samples[s])).coords;
                let q = p;
                let limit = |n: &Vec3| cap(&q, n, &(sw + n * rs));
                if let Some(c) = project_point_sphere(&mut p, &sw, r + rs, limit) {
                    let contact = sw + c.normal * rs;
                    apply(&mut p, c, contact);
                }
            }
        }
        if let Some(contact) = touched {
            let impulse = (p - before) * view.mass[i];
            load.impulse += impulse;
            load.moment += (contact - centre).cross(&impulse);
            if count {
                load.contacts += 1;
            }
            view.p[i] = p;
        }
    }
}
