//! The per-step divergence check: a body whose particles became non-finite, or left the
//! physical bounds of [`DivergenceLimits`] (a finite explosion), makes the step fail and be
//! rolled back. O(particles + tetrahedra) per body.
//!
//! The extent and volume bounds fail a step only when it moves the body farther out of them
//! than it was at the start of the step (`before`, its positions then): a body set into an inverted or
//! flattened state on purpose recovers through states outside the volume range, and each of
//! those steps brings it closer.

use crate::body::{volume_of, Body};
use crate::math::{is_finite_vec, Real, Vec3};
use crate::settings::DivergenceLimits;

/// Why `body` has diverged, or `None` when it is within `limits`; `before` holds its positions
/// (m) at the start of the step.
pub(crate) fn diverged(body: &Body, before: &[Vec3], limits: &DivergenceLimits) -> Option<String> {
    let size = body.model.size;
    let max_speed = limits.max_speed * size;
    let (mut lo, mut hi) = (Vec3::repeat(Real::INFINITY), Vec3::repeat(-Real::INFINITY));
    for (i, (x, v)) in body.state.x.iter().zip(&body.state.v).enumerate() {
        if !is_finite_vec(x) || !is_finite_vec(v) {
            return Some(format!("particle {i} became non-finite"));
        }
        let speed = v.norm();
        if speed > max_speed {
            return Some(format!(
                "particle {i} moves at {speed:.3e} m/s, above the limit of {max_speed:.3e} m/s \
                 ({} body sizes per second)",
                limits.max_speed
            ));
        }
        lo = lo.inf(x);
        hi = hi.sup(x);
    }
    let extent = (hi - lo).norm() / size;
    if extent > limits.max_extent_ratio && extent > extent_of(before) / size {
        return Some(format!(
            "the body spans {extent:.3e} times its rest size (limit {})",
            limits.max_extent_ratio
        ));
    }
    let (min_ratio, max_ratio) = limits.volume_ratio;
    let ratio = body.volume_ratio();
    let ratio_before = || volume_of(before, &body.model.boundary) / body.model.rest_volume;
    if (ratio < min_ratio && ratio < ratio_before())
        || (ratio > max_ratio && ratio > ratio_before())
    {
        return Some(format!(
            "its volume is {ratio:.3e} times the rest volume (accepted [{min_ratio}, {max_ratio}])"
        ));
    }
    None
}

/// Diagonal of the bounding box of `x` (m).
fn extent_of(x: &[Vec3]) -> Real {
    let (lo, hi) = x.iter().fold(
        (Vec3::repeat(Real::INFINITY), Vec3::repeat(-Real::INFINITY)),
        |(lo, hi), p| (lo.inf(p), hi.sup(p)),
    );
    (hi - lo).norm()
}
