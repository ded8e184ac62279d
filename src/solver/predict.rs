//! Forces and the symplectic prediction of a body for one substep.

use crate::body::{Body, ROTATION_ITERATIONS};
use crate::elastic::{accumulate_forces, ForceInputs};
use crate::math::{Real, Vec3};
use crate::parallel::Pool;
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
    for i in 0..body.state.x.len() {
        let w = body.inv_mass[i];
        if body.fixed[i] {
            body.state.v[i] = Vec3::zeros();
            scratch.p[i] = body.state.x[i];
        } else {
            body.state.v[i] = body.state.v[i] * damping_factor + scratch.force[i] * (h * w);
            scratch.p[i] = body.state.x[i] + body.state.v[i] * h;
        }
    }
    scratch.tet_lambda.iter_mut().for_each(|l| *l = 0.0);
}
