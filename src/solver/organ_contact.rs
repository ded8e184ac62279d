//! Organ–organ contact: particle spheres of different bodies (or of one body far apart at rest)
//! pushed apart, with body-pair friction.

use crate::body::Body;
use crate::collision::hash_grid::HashGrid;
use crate::constraints::contact::project_particle_particle;
use crate::constraints::friction::friction_correction;
use crate::solver::StepScratch;
use crate::world::PairFriction;

/// One Gauss–Seidel pass over the particle–particle contacts between bodies (and within a body
/// when `self_contact`), found through `grid` (built on the predicted positions, in `scratch`), with the
/// body-pair friction of `pair_friction`.
pub(crate) fn project_organ_contacts(
    grid: &HashGrid,
    bodies: &[Body],
    scratch: &mut [StepScratch],
    pair_friction: &[PairFriction],
    self_contact: bool,
) {
    let nb = bodies.len();
    for a in 0..nb {
        for i in 0..bodies[a].particle_count() {
            let pi = scratch[a].p[i];
            let friction = pair_friction;
            grid.for_each_near(&pi, |[b, j]| {
                let (b, j) = (b as usize, j as usize);
                if (b, j) <= (a, i) || (a == b && !self_contact) {
                    return;
                }
                let ra = bodies[a].model.particle_radius;
                let rb = bodies[b].model.particle_radius;
                if a == b {
                    // Particles close at rest belong to the same piece of tissue.
                    let rest_d = (bodies[a].model.rest[i] - bodies[a].model.rest[j]).norm();
                    if rest_d < 2.0 * (ra + rb) {
                        return;
                    }
                }
                let (wa, wb) = (bodies[a].inv_mass[i], bodies[b].inv_mass[j]);
                let (mut pa, mut pb) = (scratch[a].p[i], scratch[b].p[j]);
                let Some(c) = project_particle_particle(&mut pa, &mut pb, wa, wb, ra + rb) else {
                    return;
                };
                let key = (a.min(b) as u32, a.max(b) as u32);
                if let Some(f) = friction.iter().find(|f| f.bodies == key) {
                    let rel = (pa - bodies[a].state.x[i]) - (pb - bodies[b].state.x[j]);
                    let dfr = friction_correction(&rel, &c.normal, c.depth, f.mu_s, f.mu_k);
                    let wsum = wa + wb;
                    pa += dfr * (wa / wsum);
                    pb -= dfr * (wb / wsum);
                }
                scratch[a].p[i] = pa;
                scratch[b].p[j] = pb;
            });
        }
    }
}
