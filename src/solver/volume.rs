//! The XPBD tetrahedron volume constraints of a body, one Gauss–Seidel pass in colour order
//! (`crate::colouring`): the colours in sequence, the blocks of a colour (which share no
//! particle) split over the thread pool, each block's tetrahedra in their order. The result
//! does not depend on the thread count.

use crate::body::Body;
use crate::constraints::volume::volume_tet_correction;
use crate::math::Real;
use crate::parallel::{Barrier, Pool, SharedSlice};
use crate::solver::StepScratch;

/// Below this many tetrahedra a body's pass stays on one thread: the synchronisation (one
/// barrier per colour) costs about as much as projecting a few hundred tetrahedra per colour.
const MIN_PARALLEL_TETS: usize = 4096;

/// One Gauss–Seidel pass over a body's tetrahedron volume constraints for a substep `h` (s),
/// on its predicted positions in `scratch`. Each constraint's XPBD compliance is the body's
/// compliance per unit volume (1/Pa) times the tetrahedron's rest volume (m³), divided by h².
pub(crate) fn project_volumes(body: &Body, scratch: &mut StepScratch, h: Real, pool: &Pool) {
    if !body.volume_compliance.is_finite() {
        return;
    }
    let compliance_per_h2 = body.volume_compliance / (h * h);
    let model = &body.model;
    let colouring = &model.tet_colouring;
    let p = SharedSlice::new(&mut scratch.p);
    let lambda = SharedSlice::new(&mut scratch.tet_lambda);
    // SAFETY (both closures): within a colour no two blocks share a particle, and each
    // tetrahedron's multiplier is its own; a share projects only its blocks of the colour, and
    // the shares meet at the barrier before the next colour.
    let project = |first: u32| {
        for t in colouring.block(first) {
            let k = model.tets[t].map(|k| k as usize);
            let v0 = model.tet_rest_volume[t];
            let x = k.map(|k| *unsafe { p.element(k) });
            let w = k.map(|k| body.inv_mass[k]);
            let lambda = unsafe { lambda.element(t) };
            let alpha = compliance_per_h2 * v0;
            if let Some(dp) = volume_tet_correction(x, w, v0, alpha, lambda) {
                for (k, d) in k.into_iter().zip(dp) {
                    *unsafe { p.element(k) } += d;
                }
            }
        }
    };
    if pool.threads() == 1 || model.tets.len() < MIN_PARALLEL_TETS {
        colouring.blocks.iter().for_each(|&b| project(b));
        return;
    }
    let barrier = Barrier::new(pool.threads());
    pool.run(&|share| {
        let _guard = barrier.guard();
        for colour in colouring.colours() {
            let mine = pool.share(share, colour.len());
            colour[mine].iter().for_each(|&t| project(t));
            barrier.wait();
        }
    });
}
