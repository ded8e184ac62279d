//! The tool-contact stage of an iteration: every tool against every body
//! ([`surface_contact`] against the boundary triangles, or [`sampled_contact`], the paper's tool
//! samples against the particles; off between a needle and the body it punctured and between a
//! grasping tool and the body it holds), then, on the tetrahedra, the crush guard and the
//! contact again while the contact has crushed a tetrahedron.
//!
//! Why the rounds: a small probe pressed deep moves surface corners through the opposite face
//! of the tetrahedra under it. The crush guard, projected before the contact, cannot hold them,
//! and an inverted tetrahedron, stretched in its mirror image, drives an oscillation that lets
//! the probe through the surface (a 1 mm sphere pressed 3 cm into the gmsh kidney: tetrahedra
//! inverted from 1.9 cm on, the tissue beside the probe at 1 m/s, the probe's centre inside the
//! organ on 1,159–1,370 of 1,780 steps from every side; two rounds hold it from three). The
//! guard alone after the contact pushes the surface into the probe; alternated with the
//! contact, the two converge to moving the crushed tetrahedron's inner corner away. A round
//! runs only while the guard finds a tetrahedron below its floor, so a scene that crushes none
//! pays nothing.

use crate::interaction::{sampled_contact, surface_contact};
use crate::kernels::math::Real;
use crate::kernels::parallel::Pool;
use crate::scene::body::Body;
use crate::scene::settings::ContactMode;
use crate::scene::tool::Pose;
use crate::scene::{Scene, ToolSlot};
use crate::solver::volume;
use crate::solver::{StepScratch, SurfaceScratch};

/// Most rounds of crush guard and contact after an iteration's contact (each only while the
/// guard finds a tetrahedron below its floor). More rounds hold deeper presses but cost the
/// random probing of the soak robustness (docs/VALIDATION.md §5), measured with 0 / 2 / 4 / 8
/// (before the default stiffness-proportional damping):
/// the 24 presses of 1–10 mm probes 3 cm into the gmsh kidney meeting the contact goal 11 / 23 /
/// – / 24; a 1 cm probe driven 20 cm into the default organ inside on 1,819 / 469 / 204 / 0
/// steps (four sides); 80,000 soak steps with 0 / 5 / 10 / 12 rolled back, crossing surface
/// triangles at 156 / 145 / 191 / 282 checks, in 74 / 83 / 97 / 139 s.
pub(crate) const CRUSH_CONTACT_ROUNDS: usize = 2;

/// Project every tool's contacts with every body, the tools moving from their pose at substep
/// fraction `s_prev` to `s_cur` (dimensionless) over a substep of `h` (s); `count` adds the
/// contacts to the tools' contact counts (the first iteration's). Then, with the elasticity
/// on tetrahedra and the volume constraints on, up to [`CRUSH_CONTACT_ROUNDS`] rounds of the
/// crush guard and the contact again (without counting), while the guard finds a tetrahedron
/// below its floor.
#[allow(clippy::too_many_arguments)]
pub(crate) fn project_tool_contacts(
    surface: &mut SurfaceScratch,
    scene: &mut Scene,
    scratch: &mut [StepScratch],
    (s_prev, s_cur): (Real, Real),
    h: Real,
    count: bool,
    pool: &Pool,
) {
    let contact = |surface: &mut SurfaceScratch,
                   scene: &mut Scene,
                   scratch: &mut [StepScratch],
                   count: bool,
                   retry: bool| {
        let mode = scene.settings.contact_mode;
        let max_correction = scene.settings.max_depenetration_speed * h;
        for slot in scene.tools.iter_mut().flatten().filter(|s| !s.blade) {
            let ToolSlot {
                tool,
                load,
                grasp,
                needle,
                ..
            } = slot;
            let prev = Pose::interpolate(&tool.pose, &tool.target, s_prev);
            let cur = Pose::interpolate(&tool.pose, &tool.target, s_cur);
            for (b, (body, scratch)) in scene.bodies.iter().zip(scratch.iter_mut()).enumerate() {
                if needle.as_ref().is_some_and(|n| n.passes_through(b)) || grasp.holds(b) {
                    continue;
                }
                let motion = (&prev, &cur);
                match mode {
                    ContactMode::ExactShape => surface_contact::project_tool_surface(
                        surface,
                        tool,
                        load,
                        scratch.view(body),
                        &body.model.boundary,
                        motion,
                        max_correction,
                        (count, retry),
                        pool,
                    ),
                    ContactMode::SampledPoints => sampled_contact::project_sampled_contacts(
                        tool,
                        load,
                        scratch.view(body),
                        motion,
                        max_correction,
                        count,
                    ),
                }
            }
        }
    };
    contact(surface, scene, scratch, count, false);
    if !scene.crush_guard_on() {
        return;
    }
    for _ in 0..CRUSH_CONTACT_ROUNDS {
        if !lift_crushed(&scene.bodies, scratch) {
            break;
        }
        contact(surface, scene, scratch, false, true);
    }
}

/// The crush guard on every body; whether it lifted any tetrahedron.
fn lift_crushed(bodies: &[Body], scratch: &mut [StepScratch]) -> bool {
    let mut lifted = false;
    for (body, scratch) in bodies.iter().zip(scratch.iter_mut()) {
        lifted |= volume::project_crushed_tets(body, scratch);
    }
    lifted
}
