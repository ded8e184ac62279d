//! XPBD tetrahedral volume constraint (eq. 13 of the paper): `C = V(p1..p4) - V0 = 0`.

use crate::math::{Real, Vec3};

/// The projection of one tetrahedron's volume constraint.
///
/// * `p` — predicted positions (m) of its four particles;
/// * `w` — their inverse masses (1/kg; 0 for fixed particles);
/// * `rest_volume` — `V0` (m³);
/// * `alpha_tilde` — compliance divided by the squared substep, `α / h²` (m³/Pa / s² · …);
///   0 makes the constraint hard;
/// * `lambda` — the constraint's accumulated multiplier within this substep, updated.
///
/// Returns the four position corrections (m; `None` when no particle can move).
#[inline]
pub fn volume_tet_correction(
    [pa, pb, pc, pd]: [Vec3; 4],
    [wa, wb, wc, wd]: [Real; 4],
    rest_volume: Real,
    alpha_tilde: Real,
    lambda: &mut Real,
) -> Option<[Vec3; 4]> {
    let (e1, e2, e3) = (pb - pa, pc - pa, pd - pa);
    // ∂V/∂p_b etc.; V = e1 · (e2 × e3) / 6 = e1 · g1.
    let g1 = e2.cross(&e3) * (1.0 / 6.0);
    let g2 = e3.cross(&e1) * (1.0 / 6.0);
    let g3 = e1.cross(&e2) * (1.0 / 6.0);
    let g0 = -(g1 + g2 + g3);
    let denom = wa * g0.norm_squared()
        + wb * g1.norm_squared()
        + wc * g2.norm_squared()
        + wd * g3.norm_squared()
        + alpha_tilde;
    let c_value = e1.dot(&g1) - rest_volume;
    if denom <= Real::MIN_POSITIVE {
        return None;
    }
    let dl = (-c_value - alpha_tilde * *lambda) / denom;
    *lambda += dl;
    let dp = [
        g0 * (wa * dl),
        g1 * (wb * dl),
        g2 * (wc * dl),
        g3 * (wd * dl),
    ];
    Some(dp)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::tet_volume;

    #[test]
    fn hard_constraint_restores_volume_of_a_single_tet() {
        let mut p = [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(0.0, 0.0, 0.5),
        ];
        let w = [1.0; 4];
        let v0 = 1.0 / 6.0;
        let mut lambda = 0.0;
        for _ in 0..20 {
            if let Some(dp) = volume_tet_correction(p, w, v0, 0.0, &mut lambda) {
                p.iter_mut().zip(dp).for_each(|(x, d)| *x += d);
            }
        }
        let v = tet_volume(&p[0], &p[1], &p[2], &p[3]);
        assert!((v - v0).abs() < 1e-12 * v0, "{v} vs {v0}");
        // Equal masses and gradients summing to zero: the centroid does not move.
        let c: Vec3 = p.iter().sum::<Vec3>() / 4.0;
        let c0 = Vec3::new(1.0, 1.0, 0.5) / 4.0;
        assert!((c - c0).norm() < 1e-14);
    }
}
