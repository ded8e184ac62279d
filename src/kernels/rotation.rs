//! The rotation of a deformation gradient: the proper rotation `R` that maximises `tr(Rᵀ F)`,
//! the `R` of the corotated stress (paper eq. 3).
//!
//! That is `U diag(1, 1, det(UVᵀ)) Vᵀ` of the SVD `F = U Σ Vᵀ`: Irving et al.'s inversion
//! handling (the smallest singular value negated when `F` is inverted). The force pass finds it
//! for four particles at once ([`extract_rotations`]), by warm-started Newton iterations on the
//! objective of Müller, Bender, Chentanez and Macklin (2016), with the SVD ([`rotation_from_svd`])
//! where those do not converge.

use crate::kernels::lanes::{Mask4, F4, LANES, M4, V4};
use crate::kernels::math::{Mat3, Quat, Real};

/// Convergence tolerance of the rotation extraction: the gradient `|g|` relative to `|F|`
/// (a rotation error of about this many radians).
pub const ROTATION_TOLERANCE: Real = 1.0e-10;

/// A Newton step of the rotation extraction shorter than this (rad) ends it without another
/// evaluation of the gradient. Newton's method converges quadratically here: the error left
/// after a step of `|δ|` is about `C |δ|²`, with `C` of order one for a deformation gradient
/// that is not nearly flat (the ratio of `|F|` to the Hessian's smallest eigenvalue), so below
/// `ROTATION_TOLERANCE` with a margin of 100 in `C`. The evaluation it saves (rotation matrix
/// and gradient) is a fifth of the extraction's cost, and the next step's first evaluation,
/// warm-started from this rotation, checks it anyway.
const CONVERGED_NEWTON_STEP: Real = 1.0e-6;

/// Four unit quaternions `w + x i + y j + z k` (dimensionless), one lane each.
#[derive(Debug, Clone, Copy)]
struct Q4 {
    w: F4,
    v: V4,
}

impl Q4 {
    #[inline(always)]
    fn load(q: &[Quat; LANES]) -> Q4 {
        Q4 {
            w: F4::new(q.map(|q| q.w)),
            v: V4 {
                x: F4::new(q.map(|q| q.i)),
                y: F4::new(q.map(|q| q.j)),
                z: F4::new(q.map(|q| q.k)),
            },
        }
    }

    /// Quaternion `l`, taken as unit (it is one to rounding).
    #[inline(always)]
    fn lane(&self, l: usize) -> Quat {
        let c = |f: F4| f.to_array()[l];
        Quat::new_unchecked(nalgebra::Quaternion::new(
            c(self.w),
            c(self.v.x),
            c(self.v.y),
            c(self.v.z),
        ))
    }

    /// The rotation matrices, from the products of a unit quaternion's components.
    #[inline(always)]
    fn rotation_matrix(&self) -> M4 {
        let (w, V4 { x, y, z }) = (self.w, self.v);
        let two = F4::splat(2.0);
        let (ww, xx, yy, zz) = (w * w, x * x, y * y, z * z);
        let (xy, xz, yz) = (x * y, x * z, y * z);
        let (wx, wy, wz) = (w * x, w * y, w * z);
        M4 {
            rows: [
                V4 {
                    x: ww + xx - yy - zz,
                    y: two * (xy - wz),
                    z: two * (xz + wy),
                },
                V4 {
                    x: two * (xy + wz),
                    y: ww - xx + yy - zz,
                    z: two * (yz - wx),
                },
                V4 {
                    x: two * (xz - wy),
                    y: two * (yz + wx),
                    z: ww - xx - yy + zz,
                },
            ],
        }
    }

    /// `(1, a) self`, normalised: `self` turned by about `2|a|` about `a` (no trigonometry).
    #[inline(always)]
    fn turned(&self, a: &V4) -> Q4 {
        let w = self.w - a.dot(&self.v);
        let v = self.v + a.scale(self.w) + a.cross(&self.v);
        let inverse_norm = F4::splat(1.0) / (w * w + v.dot(&v)).sqrt();
        Q4 {
            w: w * inverse_norm,
            v: v.scale(inverse_norm),
        }
    }

    #[inline(always)]
    fn select(mask: Mask4, t: &Q4, f: &Q4) -> Q4 {
        Q4 {
            w: mask.select(t.w, f.w),
            v: V4::select(mask, &t.v, &f.v),
        }
    }
}

/// Set `q[l]` to the rotation that maximises `tr(Rᵀ F_l)` over proper rotations, `F_l` lane `l`
/// of `f`, for the lanes `l < q.len()` (at most [`LANES`]); returns the rotations as matrices
/// (the identity in the other lanes).
///
/// Up to `newton_iterations` iterations, each lane warm-started from its `q`: gradient
/// `g = Σ_c r_c × f_c`, Newton step `δ = H⁻¹ g`, `H = tr(G) I - sym(G)`, `G = F Rᵀ` (quadratic
/// convergence: 1–3 iterations from the previous step's rotation). A lane stops when
/// `|g| < ROTATION_TOLERANCE · |F|` or after a step shorter than `CONVERGED_NEWTON_STEP`; the
/// lanes that stopped are carried unchanged while the others go on, so every lane gives the
/// bits it would give alone. Where that does not converge (near a saddle of a strongly inverted
/// `F`, where `H` is indefinite) the lane's rotation comes from [`rotation_from_svd`].
#[inline(always)]
pub(crate) fn extract_rotations(f: &M4, q: &mut [Quat], newton_iterations: u32) -> M4 {
    let count = q.len();
    assert!(count <= LANES, "{count} rotations in {LANES} lanes");
    let mut start = [Quat::identity(); LANES];
    start[..count].copy_from_slice(q);
    let mut quat = Q4::load(&start);
    let tolerance2 =
        F4::splat(ROTATION_TOLERANCE * ROTATION_TOLERANCE) * f.inner(f).max(F4::splat(1.0e-30));
    // Lanes still iterating, lanes whose last step was short, lanes left to the SVD.
    let mut pending = Mask4::new(std::array::from_fn(|l| l < count));
    let mut short = Mask4::new([false; LANES]);
    let mut failed = Mask4::new([false; LANES]);
    let mut rotation = M4::splat(&Mat3::identity());
    for iteration in 0..=newton_iterations {
        let r = quat.rotation_matrix();
        rotation = M4::select(short, &r, &rotation);
        if iteration == newton_iterations || !pending.any() {
            break;
        }
        let g = r.column(0).cross(&f.column(0))
            + r.column(1).cross(&f.column(1))
            + r.column(2).cross(&f.column(2));
        let converged = pending & g.dot(&g).lt(tolerance2);
        rotation = M4::select(converged, &r, &rotation);
        pending = pending & !converged;
        if !pending.any() {
            break;
        }
        // H = tr(G) I - sym(G), G = F Rᵀ (G_ab = F row a · R row b); its adjugate and
        // determinant. Positive definite by Sylvester's criterion, or the lane fails.
        let [f0, f1, f2] = &f.rows;
        let [r0, r1, r2] = &r.rows;
        let (g00, g11, g22) = (f0.dot(r0), f1.dot(r1), f2.dot(r2));
        let t = g00 + g11 + g22;
        let half = F4::splat(-0.5);
        let (a, d, z) = (t - g00, t - g11, t - g22);
        let b = half * (f0.dot(r1) + f1.dot(r0));
        let c = half * (f0.dot(r2) + f2.dot(r0));
        let e = half * (f1.dot(r2) + f2.dot(r1));
        let (m00, m01, m02) = (
            d.mul_sub(z, e * e),
            c.mul_sub(e, b * z),
            b.mul_sub(e, c * d),
        );
        let (m11, m12, m22) = (
            a.mul_sub(z, c * c),
            b.mul_sub(c, a * e),
            a.mul_sub(d, b * b),
        );
        let adjugate = M4 {
            rows: [
                V4 {
                    x: m00,
                    y: m01,
                    z: m02,
                },
                V4 {
                    x: m01,
                    y: m11,
                    z: m12,
                },
                V4 {
                    x: m02,
                    y: m12,
                    z: m22,
                },
            ],
        };
        let det = adjugate.rows[0].dot(&V4 { x: a, y: b, z: c });
        let zero = F4::splat(0.0);
        let indefinite = pending & (a.le(zero) | m22.le(zero) | det.le(zero));
        failed = failed | indefinite;
        pending = pending & !indefinite;
        let delta = adjugate.mul(&g).scale(F4::splat(1.0) / det);
        quat = Q4::select(pending, &quat.turned(&delta.scale(F4::splat(0.5))), &quat);
        short = pending
            & delta
                .dot(&delta)
                .lt(F4::splat(CONVERGED_NEWTON_STEP * CONVERGED_NEWTON_STEP));
        pending = pending & !short;
    }
    failed = failed | pending;
    for (l, q) in q.iter_mut().enumerate() {
        *q = if failed.lane(l) {
            rotation_from_svd(&f.lane(l))
        } else {
            quat.lane(l)
        };
    }
    if failed.any() {
        start[..count].copy_from_slice(q);
        let exact = Q4::load(&start).rotation_matrix();
        rotation = M4::select(failed, &exact, &rotation);
    }
    rotation
}

/// The proper rotation maximising `tr(Rᵀ f)`, from the SVD of `f` (singular values sorted in
/// decreasing order; the smallest one's direction flipped when `det(UVᵀ) < 0`).
/// A non-finite `f` (which the step reports as divergence) gives the identity.
pub fn rotation_from_svd(f: &Mat3) -> Quat {
    if !f.iter().all(|c| c.is_finite()) {
        return Quat::identity();
    }
    let Some(svd) = f.try_svd(true, true, Real::EPSILON, 200) else {
        return Quat::identity();
    };
    let (Some(mut u), Some(v_t)) = (svd.u, svd.v_t) else {
        return Quat::identity();
    };
    if (u * v_t).determinant() < 0.0 {
        // nalgebra sorts singular values decreasingly: the last is the smallest.
        let mut k = 0;
        for c in 1..3 {
            if svd.singular_values[c] < svd.singular_values[k] {
                k = c;
            }
        }
        u.column_mut(k).neg_mut();
    }
    let r = u * v_t;
    if !r.iter().all(|c| c.is_finite()) {
        return Quat::identity();
    }
    // `from_matrix` iterates without bound (a matrix that overflowed inside the SVD never
    // converges: a hang); 100 iterations are plenty for the orthogonal `U Vᵀ`.
    let rot = nalgebra::Rotation3::from_matrix_eps(
        &r,
        Real::EPSILON,
        100,
        nalgebra::Rotation3::identity(),
    );
    Quat::from_rotation_matrix(&rot)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kernels::math::Vec3;

    /// Deformation gradients that are turned and stretched, sheared, strongly compressed and
    /// inverted (the last one needs the SVD).
    fn gradients() -> [Mat3; 5] {
        let turn = Quat::from_scaled_axis(Vec3::new(0.4, -0.3, 0.8))
            .to_rotation_matrix()
            .into_inner();
        [
            turn,
            turn * Mat3::from_diagonal(&Vec3::new(1.3, 0.9, 0.8)),
            turn * Mat3::new(1.0, 0.4, 0.0, 0.0, 1.0, 0.2, 0.1, 0.0, 1.0),
            turn * Mat3::from_diagonal(&Vec3::new(0.2, 1.1, 0.9)),
            turn * Mat3::from_diagonal(&Vec3::new(-0.9, -1.0, 1.1)),
        ]
    }

    /// The rotations of one to four gradients in lanes, from the starts `q`.
    fn extract(f: &[Mat3], q: &mut [Quat]) -> Vec<Mat3> {
        let mut lanes = [Mat3::identity(); LANES];
        lanes[..f.len()].copy_from_slice(f);
        let r = extract_rotations(&M4::from_matrices(&lanes), q, 6);
        (0..f.len()).map(|l| r.lane(l)).collect()
    }

    /// The Newton iterations end on the rotation of the SVD (to the tolerance), whether they
    /// stop on the gradient or on a short step, from a cold start (identity) and from a start
    /// one degree off; the quaternion left in `q` is the matrix returned.
    #[test]
    fn extracted_rotations_match_the_svd() {
        let f = gradients();
        let expected = f.map(|f| rotation_from_svd(&f));
        let near = expected.map(|q| Quat::from_scaled_axis(Vec3::new(0.0, 0.0175, 0.0)) * q);
        for (start, name) in [([Quat::identity(); 5], "cold"), (near, "warm")] {
            for block in [0..4, 4..5, 1..5] {
                let mut q = start[block.clone()].to_vec();
                let r = extract(&f[block.clone()], &mut q);
                for ((k, r), q) in block.zip(&r).zip(&q) {
                    let error = (r - expected[k].to_rotation_matrix().into_inner()).norm();
                    assert!(error < 1e-9, "gradient {k}, {name} start: error {error:e}");
                    assert!((q.to_rotation_matrix().into_inner() - r).norm() < 1e-15);
                }
            }
        }
    }

    /// A lane gives the same bits whatever the other lanes hold and however long they iterate:
    /// which particles share a block depends on the thread count, the results must not.
    #[test]
    fn every_lane_gives_the_bits_it_gives_alone() {
        let f = gradients();
        let start =
            [0.3, -0.2, 0.1, 0.0, 0.05].map(|a| Quat::from_scaled_axis(Vec3::new(a, a, -a)));
        let mut alone = Vec::new();
        for k in 0..f.len() {
            let mut q = [start[k]];
            alone.push((extract(&f[k..k + 1], &mut q)[0], q[0]));
        }
        for block in [0..4, 1..5, 2..5] {
            let mut q = start[block.clone()].to_vec();
            let r = extract(&f[block.clone()], &mut q);
            for ((k, r), q) in block.zip(r).zip(q) {
                assert_eq!((r, q), alone[k], "gradient {k}");
            }
        }
    }

    /// The rotation of an overflowing or underflowing deformation gradient returns, finite
    /// (the SVD fallback is bounded), and a non-finite gradient gives the identity in its lane
    /// without touching the others.
    #[test]
    fn rotation_of_an_overflowing_deformation_gradient_returns_finite() {
        for f in [
            Mat3::from_element(1e300),
            Mat3::new(1e300, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, -1e300),
            Mat3::from_element(Real::MIN_POSITIVE),
        ] {
            let q = rotation_from_svd(&f);
            assert!(q.coords.iter().all(|c| c.is_finite()), "{f}");
        }
        let f = [gradients()[1], Mat3::from_element(Real::NAN)];
        let mut q = [Quat::identity(); 2];
        let r = extract(&f, &mut q);
        assert_eq!(r[1], Mat3::identity());
        let mut alone = [Quat::identity()];
        assert_eq!(r[0], extract(&f[..1], &mut alone)[0]);
    }
}
