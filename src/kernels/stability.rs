//! The explicit stability limit of a body: the largest angular frequency `ω_max` of its
//! linearised elastic vibrations at rest, by power iteration on `M^{-1/2} K M^{-1/2}`.
//!
//! Symplectic Euler is stable for a substep `h < 2/ω_max`; the world chooses its number of
//! substeps from this (and reports when `Settings::max_substeps` is not enough).

use crate::kernels::math::{Real, Vec3};

/// Power iterations used for the estimate.
const ITERATIONS: usize = 60;

/// Safety factor on the power-iteration estimate (it approaches `ω_max` from below).
const SAFETY: Real = 1.05;

/// Estimate `ω_max` (rad/s) of a body with every particle free: `rest` its rest positions (m),
/// `masses` its inertial masses (kg), `elastic_forces_at` its elastic forces (N) at given
/// positions. (The body passes these in, so this module does not depend on the body type.)
pub(crate) fn max_angular_frequency(
    rest: &[Vec3],
    masses: &[Real],
    elastic_forces_at: impl Fn(&[Vec3]) -> Vec<Vec3>,
) -> Real {
    let n = rest.len();
    let inv_sqrt_m: Vec<Real> = masses.iter().map(|m| 1.0 / m.sqrt()).collect();
    // Deterministic start vector with energy in every particle and direction.
    let mut y: Vec<Vec3> = (0..n)
        .map(|i| {
            let s = (i as Real * 0.618_033_988_75).fract() - 0.5;
            Vec3::new(1.0 + s, -0.7 + s * s, 0.3 - s)
        })
        .collect();
    normalise(&mut y);
    let scale = rest
        .iter()
        .fold(0.0 as Real, |m, p| m.max(p.amax()))
        .max(1e-12);
    let eps = 1e-7 * scale;
    let mut lambda = 0.0;
    let mut x = rest.to_vec();
    for _ in 0..ITERATIONS {
        for i in 0..n {
            x[i] = rest[i] + y[i] * (inv_sqrt_m[i] * eps);
        }
        let f = elastic_forces_at(&x);
        // K z = -f / eps with z = M^{-1/2} y; then A y = M^{-1/2} K z.
        let mut ay: Vec<Vec3> = (0..n).map(|i| -f[i] * (inv_sqrt_m[i] / eps)).collect();
        lambda = ay.iter().zip(&y).map(|(a, b)| a.dot(b)).sum::<Real>();
        normalise(&mut ay);
        y = ay;
    }
    (lambda.max(0.0)).sqrt() * SAFETY
}

fn normalise(y: &mut [Vec3]) {
    let norm = y.iter().map(|v| v.norm_squared()).sum::<Real>().sqrt();
    if norm > 0.0 {
        for v in y.iter_mut() {
            *v /= norm;
        }
    }
}
