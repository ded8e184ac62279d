//! XPBD tetrahedral volume constraint (eq. 13 of the paper): `C = V(p1..p4) - V0 = 0`.

use crate::kernels::lanes::{cross, dot, Mask4, F4, V4};
use crate::kernels::math::{Real, Vec3};

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
    // ∂V/∂p_b etc.; V = e1 · (e2 × e3) / 6 = e1 · g1. One lane of the four-lane formula below,
    // with its fused products (`lanes::cross`, `lanes::dot`).
    let g1 = cross(&e2, &e3) * (1.0 / 6.0);
    let g2 = cross(&e3, &e1) * (1.0 / 6.0);
    let g3 = cross(&e1, &e2) * (1.0 / 6.0);
    let g0 = -(g1 + g2 + g3);
    let denom = wa * dot(&g0, &g0)
        + wb * dot(&g1, &g1)
        + wc * dot(&g2, &g2)
        + wd * dot(&g3, &g3)
        + alpha_tilde;
    let c_value = dot(&e1, &g1) - rest_volume;
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

/// [`volume_tet_correction`] for four tetrahedra at once, one a lane, with the same
/// arguments by lane (`p`, `w`, `rest_volume`, `alpha_tilde`, `lambda`; `lambda` is not
/// updated: the result holds its change).
///
/// Lane-wise IEEE operations in the order of the scalar formula, the same products fused (see
/// [`crate::kernels::lanes`]), so each lane gives the bits of [`volume_tet_correction`] for its
/// tetrahedron.
#[inline(always)]
pub(crate) fn volume_tet_corrections4(
    [pa, pb, pc, pd]: [V4; 4],
    [wa, wb, wc, wd]: [F4; 4],
    rest_volume: F4,
    alpha_tilde: F4,
    lambda: F4,
) -> TetCorrections4 {
    let (e1, e2, e3) = (pb - pa, pc - pa, pd - pa);
    let sixth = F4::splat(1.0 / 6.0);
    let g1 = e2.cross(&e3).scale(sixth);
    let g2 = e3.cross(&e1).scale(sixth);
    let g3 = e1.cross(&e2).scale(sixth);
    let g0 = -(g1 + g2 + g3);
    let denom =
        wa * g0.dot(&g0) + wb * g1.dot(&g1) + wc * g2.dot(&g2) + wd * g3.dot(&g3) + alpha_tilde;
    let c_value = e1.dot(&g1) - rest_volume;
    let dl = (-c_value - alpha_tilde * lambda) / denom;
    TetCorrections4 {
        // A NaN denominator moves, as in the scalar formula (and the step reports the
        // divergence).
        stays: denom.le(F4::splat(Real::MIN_POSITIVE)),
        dl,
        dp: [
            g0.scale(wa * dl),
            g1.scale(wb * dl),
            g2.scale(wc * dl),
            g3.scale(wd * dl),
        ],
    }
}

/// The result of [`volume_tet_corrections4`], by lane.
pub(crate) struct TetCorrections4 {
    /// The lanes whose tetrahedron does not move: no particle can move (the scalar
    /// projection's `None`).
    pub(crate) stays: Mask4,
    /// The change of each lane's multiplier `Δλ`.
    pub(crate) dl: F4,
    /// `dp[c]`: the correction (m) of corner `c` of each lane's tetrahedron.
    pub(crate) dp: [V4; 4],
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kernels::lanes::LANES;
    use crate::kernels::math::tet_volume;

    /// Every lane of the four-lane projection gives the scalar projection's bits, whatever the
    /// other lanes hold: soft and hard constraints, a partly and a fully fixed tetrahedron, an
    /// inverted one, a non-zero multiplier.
    #[test]
    fn each_lane_gives_the_scalar_projection_bits() {
        let p = [
            Vec3::new(0.1, -0.2, 0.05),
            Vec3::new(1.3, 0.1, -0.2),
            Vec3::new(-0.1, 0.9, 0.3),
            Vec3::new(0.2, 0.3, 0.7),
        ];
        let inverted = [p[1], p[0], p[2], p[3]];
        let cases = [
            (p, [1.0, 2.0, 0.5, 1.5], 0.2, 1e-3, 0.0),
            (p, [0.0, 2.0, 0.0, 1.5], 0.2, 0.0, 0.01),
            (p, [0.0; 4], 0.2, 0.0, 0.0),
            (inverted, [1.0; 4], 0.15, 1e-4, -0.02),
        ];
        for (case, &(p, w, v0, alpha, lambda)) in cases.iter().enumerate() {
            let mut updated = lambda;
            let expected = volume_tet_correction(p, w, v0, alpha, &mut updated);
            for lane in 0..LANES {
                // The other lanes hold the other cases.
                let index = |l: usize| (case + l + LANES - lane) % cases.len();
                let at = |l: usize| cases[index(l)];
                let corner =
                    |c: usize| V4::from_refs(std::array::from_fn(|l| &cases[index(l)].0[c]));
                let lanes = |f: &dyn Fn(usize) -> Real| F4::new(std::array::from_fn(f));
                let got = volume_tet_corrections4(
                    [0, 1, 2, 3].map(corner),
                    [0, 1, 2, 3].map(|c| lanes(&|l| at(l).1[c])),
                    lanes(&|l| at(l).2),
                    lanes(&|l| at(l).3),
                    lanes(&|l| at(l).4),
                );
                let dp = got.dp.map(|d| {
                    let mut lanes = [Vec3::zeros(); LANES];
                    d.store(&mut lanes);
                    lanes[lane]
                });
                let got = (!got.stays.lane(lane)).then(|| (got.dl.to_array()[lane], dp));
                match (got, expected) {
                    (Some((dl, dp)), Some(expected_dp)) => {
                        assert_eq!(lambda + dl, updated, "case {case}, lane {lane}");
                        assert_eq!(dp, expected_dp, "case {case}, lane {lane}");
                    }
                    (None, None) => {}
                    _ => panic!("case {case}, lane {lane}: {got:?} against {expected:?}"),
                }
            }
        }
    }

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
