//! Scalar and linear-algebra aliases, the 3×3 rotation extraction used by the corotated stress,
//! and conversions at the parry boundary.

use nalgebra::{Matrix3, UnitQuaternion, Vector3};

/// The scalar type of the solver: every length (m), mass (kg), time (s) and force (N) is an `f64`.
pub type Real = f64;
/// A 3-vector of [`Real`] (a position in m, a velocity in m/s, a force in N, ...).
pub type Vec3 = Vector3<Real>;
/// A 3×3 matrix of [`Real`] (deformation gradient, stress in Pa, rotation).
pub type Mat3 = Matrix3<Real>;
/// A unit quaternion (orientation of a tool).
pub type Quat = UnitQuaternion<Real>;

/// True when every component of `v` is finite (neither NaN nor ±Inf).
pub fn is_finite_vec(v: &Vec3) -> bool {
    v.x.is_finite() && v.y.is_finite() && v.z.is_finite()
}

/// Signed volume (m³) of the tetrahedron `a, b, c, d`: positive when `((b-a)×(c-a))·(d-a) > 0`.
pub fn tet_volume(a: &Vec3, b: &Vec3, c: &Vec3, d: &Vec3) -> Real {
    (b - a).cross(&(c - a)).dot(&(d - a)) / 6.0
}

/// Gradients (m²) of [`tet_volume`] with respect to the corners `a`, `b`, `c`, `d` (m).
pub(crate) fn tet_volume_gradient(a: &Vec3, b: &Vec3, c: &Vec3, d: &Vec3) -> [Vec3; 4] {
    let gb = (c - a).cross(&(d - a)) / 6.0;
    let gc = (d - a).cross(&(b - a)) / 6.0;
    let gd = (b - a).cross(&(c - a)) / 6.0;
    [-(gb + gc + gd), gb, gc, gd]
}

/// Numbers uniform in [−0.5, 0.5) (dimensionless) from a linear congruential generator started
/// at `seed`: the unit tests' reproducible randomness.
#[cfg(test)]
pub(crate) fn uniform(mut seed: u64) -> impl FnMut() -> Real {
    move || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (seed >> 11) as Real / (1u64 << 53) as Real - 0.5
    }
}
