//! The XPBD tetrahedron volume constraints of a body, one Gauss–Seidel pass.

use crate::body::Body;
use crate::constraints::volume::project_volume_tet;
use crate::math::Real;
use crate::solver::StepScratch;

/// One Gauss–Seidel pass over a body's tetrahedron volume constraints for a substep `h` (s),
/// on its predicted positions in `scratch`.
/// Each constraint's XPBD compliance is the body's compliance per unit volume (1/Pa) times the
/// tetrahedron's rest volume (m³), divided by h².
pub(crate) fn project_volumes(body: &Body, scratch: &mut StepScratch, h: Real) {
    if !body.volume_compliance.is_finite() {
        return;
    }
    let compliance_per_h2 = body.volume_compliance / (h * h);
    for t in 0..body.model.tets.len() {
        let v0 = body.model.tet_rest_volume[t];
        project_volume_tet(
            &mut scratch.p,
            &body.inv_mass,
            body.model.tets[t],
            v0,
            compliance_per_h2 * v0,
            &mut scratch.tet_lambda[t],
        );
    }
}
