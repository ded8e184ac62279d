//! Contact kernels (eq. 9 of the paper): `C = d - r >= 0`, projected on predicted positions.

use crate::math::{Real, Vec3};

/// A contact that was violated and projected.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactProjection {
    /// Unit normal of the contact, pointing from the obstacle towards the particle.
    pub normal: Vec3,
    /// Depth of the violation before the projection, `-C` (m, > 0).
    pub depth: Real,
    /// Length of the correction applied along the normal (m): the depth, or less when
    /// limited by `max_correction`.
    pub correction: Real,
}

/// Push a particle at `p` out of a sphere of radius `radius` (m) centred at `centre` (m), by at
/// most `max_correction` (m): the paper's point–point contact with a tool sample.
#[inline]
pub fn project_point_sphere(
    p: &mut Vec3,
    centre: &Vec3,
    radius: Real,
    max_correction: Real,
) -> Option<ContactProjection> {
    let offset = *p - centre;
    let d2 = offset.norm_squared();
    if d2 >= radius * radius {
        return None;
    }
    let d = d2.sqrt();
    let normal = if d > 1e-12 { offset / d } else { Vec3::y() };
    let depth = radius - d;
    let correction = depth.min(max_correction);
    *p += normal * correction;
    Some(ContactProjection {
        normal,
        depth,
        correction,
    })
}

/// Separate two particles (inverse masses `wa`, `wb` in 1/kg) to at least `distance` (m)
/// apart. Returns the projection (normal from `b` to `a`) when they were too close.
#[inline]
pub fn project_particle_particle(
    pa: &mut Vec3,
    pb: &mut Vec3,
    wa: Real,
    wb: Real,
    distance: Real,
) -> Option<ContactProjection> {
    let offset = *pa - *pb;
    let d2 = offset.norm_squared();
    let wsum = wa + wb;
    if d2 >= distance * distance || wsum <= 0.0 {
        return None;
    }
    let d = d2.sqrt();
    let normal = if d > 1e-12 { offset / d } else { Vec3::y() };
    let depth = distance - d;
    *pa += normal * (depth * wa / wsum);
    *pb -= normal * (depth * wb / wsum);
    Some(ContactProjection {
        normal,
        depth,
        correction: depth,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn particle_pair_separation_conserves_momentum_and_reaches_distance() {
        let (mut a, mut b) = (Vec3::new(0.0, 0.0, 0.0), Vec3::new(0.5, 0.0, 0.0));
        let (ma, mb) = (2.0, 3.0);
        let before = a * ma + b * mb;
        let c = project_particle_particle(&mut a, &mut b, 1.0 / ma, 1.0 / mb, 1.0).unwrap();
        assert!(((a - b).norm() - 1.0).abs() < 1e-12);
        assert!((a * ma + b * mb - before).norm() < 1e-12);
        assert!((c.depth - 0.5).abs() < 1e-12);
    }
}
