//! Forces and the symplectic prediction of a body for one substep.

use crate::body::{Body, ROTATION_ITERATIONS};
use crate::elastic::{accumulate_forces, ForceInputs};
use crate::math::{Real, Vec3};
use crate::parallel::{Pool, SharedSlice};
use crate::solver::StepScratch;

/// Forces, then the symplectic prediction of one body for a substep `h` (s): velocities into
/// the body's state, forces and predicted positions into its `scratch`.
pub(crate) fn predict(
    body: &mut Body,
    scratch: &mut StepScratch,
    gravity: Vec3,
    h: Real,
    damping_factor: Real,
    pool: &Pool,
) {
    for i in 0..body.state.x.len() {
        scratch.force[i] = gravity * body.model.mass[i];
    }
    let input = ForceInputs {
        nbr: &body.model.nbr,
        volume: &body.model.particle_volume,
        x: &body.state.x,
        v: &body.state.v,
    };
    accumulate_forces(
        &body.elastic,
        &input,
        &mut body.state.rotation,
        ROTATION_ITERATIONS,
        &mut scratch.pair_force,
        &mut scratch.own_force,
        &mut scratch.force,
        pool,
    );
    let n = body.state.x.len();
    let state = &mut body.state;
    let (x, force, inv_mass, fixed) = (&state.x, &scratch.force, &body.inv_mass, &body.fixed);
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
            if fixed[i] {
                *v = Vec3::zeros();
                *p = x[i];
            } else {
                *v = *v * damping_factor + force[i] * (h * inv_mass[i]);
                *p = x[i] + *v * h;
            }
        }
    });
    scratch.tet_lambda.iter_mut().for_each(|l| *l = 0.0);
}
