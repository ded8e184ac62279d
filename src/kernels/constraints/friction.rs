//! Position-based Coulomb friction (eq. 10–12 of the paper, in the form of Macklin et al. 2014).

use crate::kernels::math::{Real, Vec3};

/// The friction correction (m) to add to a particle after a contact projection.
///
/// * `relative` — displacement of the particle relative to the obstacle over the substep (m);
/// * `normal` — the contact normal (unit);
/// * `depth` — the normal correction of the contact (m, > 0);
/// * `mu_s`, `mu_k` — static and kinetic coefficients.
///
/// When the tangential relative displacement is within the static cone (`|Δx_t| < μ_s d`) it is
/// removed entirely (sticking); otherwise it is reduced by at most `μ_k d` (sliding).
#[inline]
pub fn friction_correction(
    relative: &Vec3,
    normal: &Vec3,
    depth: Real,
    mu_s: Real,
    mu_k: Real,
) -> Vec3 {
    let tangential = relative - normal * relative.dot(normal);
    let t = tangential.norm();
    if t <= 0.0 {
        return Vec3::zeros();
    }
    if t < mu_s * depth {
        -tangential
    } else {
        -tangential * (mu_k * depth / t).min(1.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sticks_inside_the_static_cone_and_slides_outside() {
        let n = Vec3::y();
        let rel = Vec3::new(0.3, -0.2, 0.0);
        let stick = friction_correction(&rel, &n, 1.0, 0.5, 0.4);
        assert!((stick - Vec3::new(-0.3, 0.0, 0.0)).norm() < 1e-15);
        let slide = friction_correction(&rel, &n, 0.5, 0.5, 0.4);
        assert!((slide - Vec3::new(-0.2, 0.0, 0.0)).norm() < 1e-15);
        assert_eq!(friction_correction(&rel, &n, 1.0, 0.0, 0.0), Vec3::zeros());
    }
}
