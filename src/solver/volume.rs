//! The XPBD tetrahedron volume constraints of a body, one Gauss–Seidel pass in colour order
//! (`crate::kernels::colouring`): the colours in sequence, the blocks of a colour (which share no
//! particle) split over the thread pool, each block's tetrahedra in their order, four blocks
//! in lock-step, one a lane (`volume_tet_corrections4`). The blocks share no particle, so the
//! result is that of projecting them one after the other, and it does not depend on the
//! thread count. The dual-cell constraints (one per particle) run the same way, colour by
//! colour, their cells in place of the blocks.

use crate::kernels::constraints::volume::{volume_tet_correction, volume_tet_corrections4};
use crate::kernels::lanes::{F4, LANES, V4};
use crate::kernels::math::Real;
use crate::kernels::parallel::{Barrier, Pool, SharedSlice};
use crate::scene::body::Body;
use crate::solver::StepScratch;
use std::ops::Range;

/// Below this many tetrahedra a body's pass stays on one thread: the synchronisation (one
/// barrier per colour) costs about as much as projecting a few hundred tetrahedra per colour.
const MIN_PARALLEL_TETS: usize = 4096;

/// Blocks of one colour projected together, one a lane (see `project_volumes`).
const INTERLEAVED_BLOCKS: usize = LANES;

/// One Gauss–Seidel pass over a body's tetrahedron volume constraints for a substep `h` (s),
/// on its predicted positions in `scratch`. Each constraint's XPBD compliance is the body's
/// compliance per unit volume (1/Pa) times the tetrahedron's rest volume (m³), divided by h².
pub(crate) fn project_volumes(body: &Body, scratch: &mut StepScratch, h: Real, pool: &Pool) {
    if !body.derived.volume_compliance.is_finite() {
        return;
    }
    let compliance_per_h2 = body.derived.volume_compliance / (h * h);
    let model = &body.model;
    let colouring = &model.tet_colouring;
    let p = SharedSlice::new(&mut scratch.p);
    let lambda = SharedSlice::new(&mut scratch.tet_lambda);
    // SAFETY (both closures): within a colour no two blocks share a particle, and each
    // tetrahedron's multiplier is its own; a share projects only its blocks of the colour, and
    // the shares meet at the barrier before the next colour.
    let project_tet = |t: usize| {
        let k = colouring.tets()[t].map(|k| k as usize);
        let v0 = colouring.rest_volume()[t];
        let x = k.map(|k| *unsafe { p.element(k) });
        let w = k.map(|k| body.inv_mass[k]);
        let lambda = unsafe { lambda.element(t) };
        let alpha = compliance_per_h2 * v0;
        if let Some(dp) = volume_tet_correction(x, w, v0, alpha, lambda) {
            for (k, d) in k.into_iter().zip(dp) {
                *unsafe { p.element(k) } += d;
            }
        }
    };
    // The lanes read their corners without a check per index: every index of the colouring
    // is below its particle count (its invariant), which is that of both arrays.
    let particles = colouring.particle_count();
    assert!(p.len() == particles && body.inv_mass.len() == particles);
    // Four blocks of one colour in lock-step, the s-th tetrahedron of each a lane, while all
    // four have one; the rest interleaved tetrahedron by tetrahedron, so that consecutive
    // projections touch different particles and overlap in the processor. The blocks share no
    // particle, so the result is that of projecting them one after the other.
    let project = |firsts: &[u32]| {
        let mut blocks: [std::ops::Range<usize>; INTERLEAVED_BLOCKS] = Default::default();
        for (b, &first) in blocks.iter_mut().zip(firsts) {
            *b = colouring.block(first);
        }
        let together = match firsts.len() {
            LANES => blocks.iter().map(|b| b.len()).min().unwrap_or(0),
            _ => 0,
        };
        // Per lane, the first `together` tetrahedra of its block, their rest volumes and their
        // multipliers.
        let lane_tets = each_lane(|l| &colouring.tets()[blocks[l].start..][..together]);
        let lane_v0 = each_lane(|l| &colouring.rest_volume()[blocks[l].start..][..together]);
        // SAFETY: the four blocks are disjoint ranges of tetrahedra, each projected by this
        // share alone.
        let lane_lambda =
            each_lane(|l| unsafe { lambda.range(blocks[l].start..blocks[l].start + together) });
        for s in 0..together {
            let k = each_lane(|l| lane_tets[l][s].map(|k| k as usize));
            // SAFETY: sixteen distinct particles (four of a tetrahedron, and the blocks share
            // none), each held once; every index is below the particle count (checked above).
            let x = each_lane(|l| each_lane(|c| unsafe { p.element_unchecked(k[l][c]) }));
            let corner = |c: usize| V4::from_refs(each_lane(|l| &*x[l][c]));
            // SAFETY: as for `x`.
            let mass = |c: usize| {
                F4::new(each_lane(|l| unsafe {
                    *body.inv_mass.get_unchecked(k[l][c])
                }))
            };
            let v0 = F4::new(each_lane(|l| lane_v0[l][s]));
            let corners = each_lane(corner);
            let corrections = volume_tet_corrections4(
                corners,
                each_lane(mass),
                v0,
                F4::splat(compliance_per_h2) * v0,
                F4::new(each_lane(|l| lane_lambda[l][s])),
            );
            let dl = corrections.dl.to_array();
            for l in 0..LANES {
                if !corrections.stays.lane(l) {
                    lane_lambda[l][s] += dl[l];
                }
            }
            // Each corner moved lane-wise (the scalar `x += dp`), written back through the
            // references.
            let [x0, x1, x2, x3] = x;
            for c in 0..4 {
                let moved = corners[c] + corrections.dp[c];
                let kept = V4::select(corrections.stays, &corners[c], &moved);
                kept.store_refs([&mut *x0[c], &mut *x1[c], &mut *x2[c], &mut *x3[c]]);
            }
        }
        let steps = blocks.iter().map(|b| b.len()).max().unwrap_or(0);
        for s in together..steps {
            for b in &blocks {
                if s < b.len() {
                    project_tet(b.start + s);
                }
            }
        }
    };
    if pool.threads() == 1 || model.tets.len() < MIN_PARALLEL_TETS {
        colouring
            .colours()
            .for_each(|colour| colour.chunks(INTERLEAVED_BLOCKS).for_each(project));
        return;
    }
    let barrier = Barrier::new(pool.threads());
    pool.run(&|share| {
        let _guard = barrier.guard();
        for colour in colouring.colours() {
            let mine = pool.share(share, colour.len());
            colour[mine].chunks(INTERLEAVED_BLOCKS).for_each(project);
            barrier.wait();
        }
    });
}

/// Below this many dual cells a body's pass stays on one thread: a colour is a barrier, and
/// the cells need a few tens of colours.
const MIN_PARALLEL_CELLS: usize = 1024;

/// One Gauss–Seidel pass over a body's dual-cell volume constraints for a substep `h` (s), on
/// its predicted positions in `scratch`, in the cells' colour order (`DualCells::colours`):
/// the colours in sequence, the cells of a colour (whose stars share no particle) split over
/// the thread pool, with a barrier between colours; the same bits for any thread count.
/// Particle `i`'s constraint `C_i = V_i(x) − V_i⁰` (its cell's volume against its rest volume,
/// m³) has the XPBD compliance of the body's compliance per unit volume (1/Pa) times `V_i⁰`,
/// divided by h²; its correction moves every particle of the cell's tetrahedra.
pub(crate) fn project_dual_cells(body: &Body, scratch: &mut StepScratch, h: Real, pool: &Pool) {
    if !body.derived.volume_compliance.is_finite() {
        return;
    }
    let compliance_per_h2 = body.derived.volume_compliance / (h * h);
    let cells = &body.model.dual_cells;
    let star = cells.max_star();
    let p = SharedSlice::new(&mut scratch.p);
    let lambda = SharedSlice::new(&mut scratch.tet_lambda[..cells.len()]);
    let cell_scratch = SharedSlice::new(&mut scratch.cell_scratch);
    // The cells `range` (of the projection order), with share `share`'s scratch.
    // SAFETY (the closure's accesses): within a colour no two cells' stars share a particle,
    // a cell's multiplier is its own (by its position), and each share has its own scratch;
    // a share projects only its cells of the colour, and the shares meet at the barrier before
    // the next colour.
    let project = |share: usize, range: Range<usize>| {
        let slots = unsafe { cell_scratch.range(share * star..(share + 1) * star) };
        let lambda = unsafe { lambda.range(range.clone()) };
        for (c, lambda) in range.zip(lambda) {
            let v0 = cells.rest_volume(c);
            let particle = |k: usize| (*unsafe { p.element(k) }, body.inv_mass[k]);
            let cell = cells.volume_and_gradient(c, particle, slots);
            let alpha = compliance_per_h2 * v0;
            let denominator = cell.weight + alpha;
            if denominator <= 0.0 {
                continue;
            }
            let dl = (-(cell.volume - v0) - alpha * *lambda) / denominator;
            *lambda += dl;
            // Each particle k moves by w_k ∇_k V dl (m).
            let dl_24 = dl * (1.0 / 24.0);
            for (&k, slot) in cells.star(c).iter().zip(slots.iter()) {
                *unsafe { p.element(k as usize) } +=
                    slot.gradient_24() * (slot.inverse_mass() * dl_24);
            }
        }
    };
    if pool.threads() == 1 || cells.len() < MIN_PARALLEL_CELLS {
        cells.colours().for_each(|colour| project(0, colour));
        return;
    }
    let barrier = Barrier::new(pool.threads());
    pool.run(&|share| {
        let _guard = barrier.guard();
        for colour in cells.colours() {
            let mine = pool.share(share, colour.len());
            project(share, colour.start + mine.start..colour.start + mine.end);
            barrier.wait();
        }
    });
}

/// `[f(0), f(1), f(2), f(3)]`, always inlined (`array::map` and `from_fn` are not always, in a
/// loop this hot).
#[inline(always)]
fn each_lane<T>(mut f: impl FnMut(usize) -> T) -> [T; LANES] {
    [f(0), f(1), f(2), f(3)]
}

/// Least volume (in rest volumes, dimensionless) the crush guard keeps a tetrahedron at.
pub(crate) const CRUSH_FLOOR_RATIO: Real = 0.1;

/// The crush guard of `ElasticScheme::Tetrahedra`: every tetrahedron that the substep's force
/// pass found below [`CRUSH_FLOOR_RATIO`] of its rest volume (at the positions the substep
/// started from, `StepScratch::crushed`) and that is still below it on the predicted positions
/// is projected back to that, as a hard one-sided constraint. The corotated elements push an
/// inverted tetrahedron back only weakly (where two singular values of `F` sum to zero its
/// rotation, hence its force, jumps), and with the volumetric stiffness on the dual cells
/// nothing else does: after a mirroring, inverted tetrahedra flapped for seconds. The guard is
/// inactive in any deformation that keeps every tetrahedron above a tenth of its volume, so it
/// adds no stiffness there (no locking). Its list costs nothing (the force pass forms every
/// `det F`); a tetrahedron that goes from above half its volume to below a tenth within one
/// substep is lifted at the end of the next one, and one lifted to the floor stays listed.
/// The listed tetrahedra are projected one by one, on the calling thread in the order of the
/// force pass's elements. Returns whether it moved any.
pub(crate) fn project_crushed_tets(body: &Body, scratch: &mut StepScratch) -> bool {
    let mut lifted = false;
    let elements = &body.model.tet_elements;
    let p = &mut scratch.p;
    for t in elements.compressed(&scratch.compressed) {
        let corners = elements.corners(t).map(|k| k as usize);
        let x = corners.map(|k| p[k]);
        let w = corners.map(|k| body.inv_mass[k]);
        let floor = CRUSH_FLOOR_RATIO * elements.volume(t);
        let mut lambda = 0.0;
        // The hard constraint `V = floor`, applied only below it.
        if crate::kernels::math::tet_volume(&x[0], &x[1], &x[2], &x[3]) >= floor {
            continue;
        }
        if let Some(dp) = volume_tet_correction(x, w, floor, 0.0, &mut lambda) {
            for (k, d) in corners.iter().zip(dp) {
                p[*k] += d;
            }
            lifted = true;
        }
    }
    lifted
}
