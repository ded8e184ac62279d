//! Contact kernels (eq. 9 of the paper): `C = d - r >= 0`, projected on predicted positions.

use crate::kernels::math::{Real, Vec3};

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
/// most `cap(normal)` (m) along the unit `normal` of the push (evaluated only on contact): the
/// paper's point–point contact with a tool sample.
#[inline]
pub fn project_point_sphere(
    p: &mut Vec3,
    centre: &Vec3,
    radius: Real,
    cap: impl Fn(&Vec3) -> Real,
) -> Option<ContactProjection> {
    let offset = *p - centre;
    let d2 = offset.norm_squared();
    if d2 >= radius * radius {
        return None;
    }
    let d = d2.sqrt();
    let normal = if d > 1e-12 { offset / d } else { Vec3::y() };
    let depth = radius - d;
    let correction = depth.min(cap(&normal));
    *p += normal * correction;
    Some(ContactProjection {
        normal,
        depth,
        correction,
    })
}

/// Push a particle at `p` (m), inside a solid whose surface is nearest at `on_surface` (m), out
/// through that point to `radius` (m) beyond it, by at most `cap(normal)` (m) along the unit
/// `normal` of the push; `fallback` (unit) is the normal when `p` lies on the surface itself.
#[inline]
pub fn push_out_of_solid(
    p: &mut Vec3,
    on_surface: &Vec3,
    fallback: &Vec3,
    radius: Real,
    cap: &impl Fn(&Vec3) -> Real,
) -> ContactProjection {
    let outwards = on_surface - *p;
    let d = outwards.norm();
    let normal = if d > 1e-12 { outwards / d } else { *fallback };
    let depth = d + radius;
    let correction = depth.min(cap(&normal));
    *p += normal * correction;
    ContactProjection {
        normal,
        depth,
        correction,
    }
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

    #[test]
    fn a_particle_inside_a_solid_leaves_through_the_nearest_surface_point_up_to_the_cap() {
        // 0.1 m inside a face at x = 1, particle radius 0.05 m: 0.15 m out along +x.
        let surface = Vec3::new(1.0, 0.3, 0.0);
        let mut p = Vec3::new(0.9, 0.3, 0.0);
        let c = push_out_of_solid(&mut p, &surface, &Vec3::y(), 0.05, &|_| 1.0);
        assert!((p - Vec3::new(1.05, 0.3, 0.0)).norm() < 1e-12);
        assert!((c.normal - Vec3::x()).norm() < 1e-12);
        assert!((c.depth - 0.15).abs() < 1e-12 && (c.correction - 0.15).abs() < 1e-12);
        // Capped: only 0.02 m of the 0.15 m this substep, along the same normal.
        let mut q = Vec3::new(0.9, 0.3, 0.0);
        let c = push_out_of_solid(&mut q, &surface, &Vec3::y(), 0.05, &|n| 0.02 * n.x);
        assert!((q - Vec3::new(0.92, 0.3, 0.0)).norm() < 1e-12);
        assert!((c.depth - 0.15).abs() < 1e-12 && (c.correction - 0.02).abs() < 1e-12);
        // On the surface itself: out along the fallback.
        let mut s = surface;
        let c = push_out_of_solid(&mut s, &surface, &Vec3::z(), 0.05, &|_| 1.0);
        assert!((c.normal - Vec3::z()).norm() < 1e-12);
    }
}
