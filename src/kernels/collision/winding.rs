//! Inside or outside a closed triangulated surface, by its winding number.

use crate::kernels::math::Vec3;

/// Whether `point` is inside the closed surface of `triangles` (outward oriented) at positions
/// `x`: its winding number (the sum of the triangles' solid angles, Van Oosterom & Strackee,
/// over 4π) is above one half.
pub(crate) fn inside_surface(point: &Vec3, x: &[Vec3], triangles: &[[u32; 3]]) -> bool {
    let mut solid_angle = 0.0;
    for t in triangles {
        let [a, b, c] = t.map(|k| x[k as usize] - point);
        let (la, lb, lc) = (a.norm(), b.norm(), c.norm());
        let numerator = a.dot(&b.cross(&c));
        let denominator = la * lb * lc + a.dot(&b) * lc + b.dot(&c) * la + c.dot(&a) * lb;
        solid_angle += 2.0 * numerator.atan2(denominator);
    }
    solid_angle.abs() > 2.0 * std::f64::consts::PI
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn winding_number_tells_inside_from_outside_of_a_tetrahedron() {
        let x = [Vec3::zeros(), Vec3::x(), Vec3::y(), Vec3::z()];
        // Outward faces of the tetrahedron (0, 1, 2, 3).
        let faces = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
        assert!(inside_surface(&Vec3::repeat(0.1), &x, &faces));
        assert!(!inside_surface(&Vec3::repeat(0.5), &x, &faces));
        assert!(!inside_surface(&Vec3::new(-0.1, 0.1, 0.1), &x, &faces));
    }
}
