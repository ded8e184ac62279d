//! Forces and the symplectic prediction of a body for one substep.

use crate::kernels::math::{Real, Vec3};
use crate::kernels::parallel::{Pool, SharedSlice};
use crate::kernels::point_elasticity::{accumulate_forces, ForceInputs};
use crate::kernels::tet_dashpots::DashpotFilter;
use crate::kernels::tet_elasticity::{self, TetForceInputs};
use crate::scene::body::{Body, ROTATION_ITERATIONS};
use crate::scene::settings::ElasticScheme;
use crate::solver::StepScratch;

/// Forces, then the symplectic prediction of one body for a substep `h` (s): velocities into
/// the body's state, forces and predicted positions into its `scratch`; the elastic forces of
/// the world's `scheme`.
pub(crate) fn predict(
    body: &mut Body,
    scheme: ElasticScheme,
    scratch: &mut StepScratch,
    gravity: Vec3,
    h: Real,
    damping_factor: Real,
    pool: &Pool,
) {
    // Gravity into the forces, and the volume constraints' multipliers of the substep reset,
    // each share its range.
    let mass = &body.model.mass;
    let (forces, multipliers) = (
        SharedSlice::new(&mut scratch.force),
        SharedSlice::new(&mut scratch.tet_lambda),
    );
    pool.run(&|share| {
        let particles = pool.share(share, mass.len());
        // SAFETY: the shares' ranges are disjoint.
        let (f, lambda) = unsafe {
            (
                forces.range(particles.clone()),
                multipliers.range(pool.share(share, multipliers.len())),
            )
        };
        for (f, &m) in f.iter_mut().zip(&mass[particles]) {
            *f = gravity * m;
        }
        lambda.fill(0.0);
    });
    match scheme {
        ElasticScheme::PointBased => {
            let input = ForceInputs {
                nbr: &body.model.nbr,
                volume: &body.model.particle_volume,
                x: &body.state.x,
                active_before: &body.active_before,
            };
            accumulate_forces(
                &body.derived.elastic,
                &input,
                &mut body.state.rotation,
                ROTATION_ITERATIONS,
                &mut scratch.pair_force,
                &mut scratch.own_force,
                &mut scratch.force,
                pool,
            );
        }
        ElasticScheme::Tetrahedra => tet_elasticity::accumulate_forces(
            &body.derived.elastic,
            &TetForceInputs {
                elements: &body.model.tet_elements,
                x: &body.state.x,
                fixed: &body.fixed,
            },
            &mut scratch.tet_shares,
            &mut scratch.compressed,
            &mut scratch.force,
            pool,
        ),
    }
    // The stiffness-proportional damping filters the kicked velocities before the drift
    // (`kernels::tet_dashpots`): the particles' loads with the kick, the edges' impulses, then
    // each particle's sum of them with the drift.
    let elastic = &body.derived.elastic;
    let dashpots = &body.model.tet_dashpots;
    let filter = (elastic.damping_stiffness > 0.0).then_some(DashpotFilter {
        mu: elastic.mu,
        lambda: elastic.lambda,
        beta: elastic.damping_stiffness,
        h,
    });
    let n = body.state.x.len();
    let state = &mut body.state;
    let (x, force, inv_mass, fixed) = (&state.x, &scratch.force, &body.inv_mass, &body.fixed);
    let (velocity, predicted, loads) = (
        SharedSlice::new(&mut state.v),
        SharedSlice::new(&mut scratch.p),
        SharedSlice::new(&mut scratch.dashpot_load),
    );
    pool.for_each_range(n, &|range| {
        // SAFETY: the shares' ranges are disjoint.
        let (v, p, load) = unsafe {
            (
                velocity.range(range.clone()),
                predicted.range(range.clone()),
                loads.range(range.clone()),
            )
        };
        for (((i, v), p), load) in range.zip(v).zip(p).zip(load) {
            if fixed[i] {
                *v = Vec3::zeros();
                *p = x[i];
                *load = 0.0;
            } else {
                *v = *v * damping_factor + force[i] * (h * inv_mass[i]);
                match &filter {
                    // The drift waits for the filtered velocity.
                    Some(filter) => *load = filter.load(dashpots, i, inv_mass[i]),
                    None => *p = x[i] + *v * h,
                }
            }
        }
    });
    let Some(filter) = filter else {
        return;
    };
    // The corners of the tetrahedra the force pass found crushed get no damping.
    let undamped = &mut scratch.dashpot_undamped;
    undamped.fill(false);
    if scheme == ElasticScheme::Tetrahedra {
        let elements = &body.model.tet_elements;
        for t in elements.compressed(&scratch.compressed) {
            for k in elements.corners(t) {
                undamped[k as usize] = true;
            }
        }
    }
    let impulse = &mut scratch.dashpot_impulse[..dashpots.slot_count()];
    let (load, undamped) = (&scratch.dashpot_load, &scratch.dashpot_undamped);
    dashpots.edge_impulses(&filter, x, &state.v, load, undamped, impulse, pool);
    let impulse = &*impulse;
    let (velocity, predicted) = (
        SharedSlice::new(&mut state.v),
        SharedSlice::new(&mut scratch.p),
    );
    pool.for_each_range(n, &|range| {
        // SAFETY: the shares' ranges are disjoint.
        let (v, p) = unsafe {
            (
                velocity.range(range.clone()),
                predicted.range(range.clone()),
            )
        };
        for ((i, v), p) in range.zip(v).zip(p) {
            if !fixed[i] {
                *v += dashpots.impulse_on(i, impulse) * inv_mass[i];
                *p = x[i] + *v * h;
            }
        }
    });
}
