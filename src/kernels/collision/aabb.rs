//! Axis-aligned boxes as the surface self-contact's broad phase uses them: a pair of corners,
//! the box of a particle's motion over a substep, grown, merged and tested for overlap.

use crate::kernels::math::{Real, Vec3};

/// An axis-aligned box (m): lower and upper corners; [`EMPTY_BOX`] holds nothing.
pub(crate) type Aabb = (Vec3, Vec3);

pub(crate) const EMPTY_BOX: Aabb = (
    Vec3::new(Real::INFINITY, Real::INFINITY, Real::INFINITY),
    Vec3::new(-Real::INFINITY, -Real::INFINITY, -Real::INFINITY),
);

/// The box of the segment from `x` to `p` (m): a particle's motion over a substep.
pub(crate) fn motion(x: &Vec3, p: &Vec3) -> Aabb {
    (x.inf(p), x.sup(p))
}

/// `b` grown to hold the point `p` (m).
pub(crate) fn grow(b: &mut Aabb, p: &Vec3) {
    b.0 = b.0.inf(p);
    b.1 = b.1.sup(p);
}

/// `b` grown by `by` (m) on every side.
pub(crate) fn inflated(b: &Aabb, by: Real) -> Aabb {
    (b.0.add_scalar(-by), b.1.add_scalar(by))
}

/// The smallest box holding both.
pub(crate) fn merge(a: &Aabb, b: &Aabb) -> Aabb {
    (a.0.inf(&b.0), a.1.sup(&b.1))
}

/// Whether the closed boxes share a point.
pub(crate) fn overlap(a: &Aabb, b: &Aabb) -> bool {
    (0..3).all(|k| a.0[k] <= b.1[k] && b.0[k] <= a.1[k])
}
