//! Forces and the symplectic prediction of a body for one substep.

use crate::body::{Body, ROTATION_ITERATIONS};
use crate::elastic::{accumulate_forces, ForceInputs};
use crate::math::{Real, Vec3};
use crate::parallel::Pool;

/// Forces, then the symplectic prediction of one body for a substep `h` (s).
pub(crate) fn predict(body: &mut Body, gravity: Vec3, h: Real, damping_factor: Real, pool: &Pool) {
    for i in 0..body.x.len() {
        body.force[i] = gravity * body.mass[i];
    }
    let input = ForceInputs {
        nbr: &body.nbr,
        volume: &body.particle_volume,
        x: &body.x,
        v: &body.v,
    };
    accumulate_forces(
        &body.model,
        &input,
        &mut body.rotation,
        ROTATION_ITERATIONS,
        &mut body.pair_force,
        &mut body.own_force,
        &mut body.force,
        pool,
    );
    for i in 0..body.x.len() {
        let w = body.inv_mass[i];
        if body.fixed[i] {
            body.v[i] = Vec3::zeros();
            body.p[i] = body.x[i];
        } else {
            body.v[i] = body.v[i] * damping_factor + body.force[i] * (h * w);
            body.p[i] = body.x[i] + body.v[i] * h;
        }
    }
    body.tet_lambda.iter_mut().for_each(|l| *l = 0.0);
}
