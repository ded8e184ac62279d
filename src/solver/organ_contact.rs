//! Organ–organ contact: particle spheres of different bodies pushed apart, with body-pair
//! friction. (Contact of a body with itself is the surface self-contact,
//! `crate::solver::surface_self_contact`.)

use crate::kernels::collision::hash_grid::HashGrid;
use crate::kernels::constraints::contact::project_particle_particle;
use crate::kernels::constraints::friction::friction_correction;
use crate::kernels::math::{Real, Vec3};
use crate::scene::body::Body;
use crate::scene::PairFriction;
use crate::solver::StepScratch;

/// Bodies up to which the organ contact pass skips particles far from every other body (a
/// fixed-size array: the step allocates nothing).
const BOUNDED_BODIES: usize = 16;

/// One Gauss–Seidel pass over the particle–particle contacts between bodies, found through
/// `grid` (built on the predicted positions, in `scratch`), with the body-pair friction of
/// `pair_friction`.
pub(crate) fn project_organ_contacts(
    grid: &HashGrid,
    bodies: &[Body],
    scratch: &mut [StepScratch],
    pair_friction: &[PairFriction],
) {
    let nb = bodies.len();
    // Only particles near another body can touch: each body's bounding
    // box of its predicted positions, grown by every write of the pass (so it always holds
    // them all), lets a particle farther than the contact distance from every other body's box
    // skip the grid query. It skips only pairs that cannot touch: the same projections in the
    // same order, the same bits. Up to `BOUNDED_BODIES` bodies (no allocation in a step); more
    // bodies query every particle.
    let mut bounds = [(
        Vec3::repeat(Real::INFINITY),
        Vec3::repeat(Real::NEG_INFINITY),
    ); BOUNDED_BODIES];
    let bounded = nb <= BOUNDED_BODIES;
    if bounded {
        for (b, s) in scratch.iter().enumerate() {
            bounds[b] =
                s.p.iter()
                    .fold(bounds[b], |(lo, hi), p| (lo.inf(p), hi.sup(p)));
        }
    }
    let reach = bodies
        .iter()
        .map(|b| b.model.particle_radius)
        .fold(0.0, Real::max);
    for a in 0..nb {
        let ra = bodies[a].model.particle_radius;
        for i in 0..bodies[a].particle_count() {
            let pi = scratch[a].p[i];
            if bounded
                && (0..nb).all(|b| {
                    let (lo, hi) = bounds[b];
                    let margin = Vec3::repeat(ra + reach);
                    b == a || (pi - (lo - margin)).min() < 0.0 || ((hi + margin) - pi).min() < 0.0
                })
            {
                continue;
            }
            let friction = pair_friction;
            grid.for_each_near(&pi, |[b, j]| {
                let (b, j) = (b as usize, j as usize);
                if b <= a {
                    return;
                }
                let ra = bodies[a].model.particle_radius;
                let rb = bodies[b].model.particle_radius;
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
                if bounded {
                    for (k, p) in [(a, pa), (b, pb)] {
                        bounds[k] = (bounds[k].0.inf(&p), bounds[k].1.sup(&p));
                    }
                }
            });
        }
    }
}
