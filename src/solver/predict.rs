//! Forces and the symplectic prediction of a body for one substep.

use crate::body::{Body, ROTATION_ITERATIONS};
use crate::elastic::{accumulate_forces, ForceInputs};
use crate::math::{Real, Vec3};
use crate::parallel::Pool;

/// Forces, then the symplectic prediction of one body for a substep `h` (s).
pub(crate) fn predict(body: &mut Body, gravity: Vec3, h: Real, damping_factor: Real, pool: &Pool) {
    for i in 0..body.state.x.len() {
        body.scratch.force[i] = gravity * body.model.mass[i];
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
        &mut body.scratch.pair_force,
        &mut body.scratch.own_force,
        &mut body.scratch.force,
        pool,
    );
    for i in 0..body.state.x.len() {
        let w = body.inv_mass[i];
        if body.fixed[i] {
            body.state.v[i] = Vec3::zeros();
            body.scratch.p[i] = body.state.x[i];
        } else {
            body.state.v[i] = body.state.v[i] * damping_factor + body.scratch.force[i] * (h * w);
            body.scratch.p[i] = body.state.x[i] + body.state.v[i] * h;
        }
    }
    body.scratch.tet_lambda.iter_mut().for_each(|l| *l = 0.0);
}
