//! The XPBD tetrahedron volume constraints of a body, one Gauss–Seidel pass.

use crate::body::Body;
use crate::constraints::volume::project_volume_tet;
use crate::math::Real;

/// One Gauss–Seidel pass over a body's tetrahedron volume constraints for a substep `h` (s).
/// Each constraint's XPBD compliance is the body's compliance per unit volume (1/Pa) times the
/// tetrahedron's rest volume (m³), divided by h².
pub(crate) fn project_volumes(body: &mut Body, h: Real) {
    if !body.volume_compliance.is_finite() {
        return;
    }
    let compliance_per_h2 = body.volume_compliance / (h * h);
    for t in 0..body.model.tets.len() {
        let v0 = body.model.tet_rest_volume[t];
        project_volume_tet(
            &mut body.scratch.p,
            &body.inv_mass,
            body.model.tets[t],
            v0,
            compliance_per_h2 * v0,
            &mut body.scratch.tet_lambda[t],
        );
    }
}
