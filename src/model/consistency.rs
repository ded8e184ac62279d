//! Variationally consistent gradients (Chen, Hillman & Rüter 2013): a load-time correction of
//! the MLS gradient coefficients so that nodal integration satisfies the discrete divergence
//! theorem, and a uniform stress leaves every interior particle in equilibrium.
//!
//! Notation: particle `i` with volume `v_i` (m³) and neighbours `j ∈ N(i)`; the rest offsets
//! `u_ij` are the rows of `U_i` (`k_i × 3`) and the gradient coefficients `g_ij` (1/m) the rows
//! of `G_i`, so that `∇ψ_j(X_i) = g_ij` and `∇ψ_i(X_i) = −Σ_j g_ij` (the deformation gradient
//! `F_i = I + Σ_j (x_ij − u_ij) g_ijᵀ` of [`crate::kernels::point_elasticity`]).
//!
//! - Linear consistency (kept): `G_iᵀ U_i = I`, so an affine motion gives exactly its `F`.
//! - Integration constraint (imposed): for every particle `l`,
//!   `Σ_i v_i ∇ψ_l(X_i) = b_l` with `b_l = ∮ ψ_l n dA = Σ_{boundary triangles ∋ l} (area/3) n`
//!   (outward unit normal, `ψ_l` linear on the boundary triangles). Then a uniform stress `P`
//!   gives particle `l` the force `−P b_l`: zero inside, the traction's share on the boundary.
//!
//! The smallest change `Σ_i ‖ΔG_i‖²` that meets both is `ΔG_i = v_i Π_i A_i Λ`, with
//! `Π_i = I − U_i (U_iᵀ U_i)⁻¹ U_iᵀ` (`k_i × k_i`, it keeps `ΔG_iᵀ U_i = 0`),
//! `(A_i Λ)_j = Λ_j − Λ_i`, and the multipliers `Λ` (`n × 3`) solving
//! `S Λ = −R`, `S = Σ_i v_i² A_iᵀ Π_i A_i`, `R_l = Σ_i v_i ∇ψ_l(X_i) − b_l` (the residual of
//! the uncorrected gradients). `S` is symmetric positive semi-definite; its null space (constant
//! and linear `Λ`) is orthogonal to `R` because the MLS gradients reproduce linear fields and
//! `Σ_i v_i` is the mesh volume. It is solved matrix-free by Jacobi-preconditioned conjugate
//! gradients, once at load time; the step's cost does not change.

use crate::kernels::math::{Mat3, Real, Vec3};
use crate::kernels::neighbours::Neighbourhoods;

/// Largest number of conjugate-gradient iterations of the correction.
const MAX_ITERATIONS: usize = 20_000;

/// The CG stops when the residual of `S Λ = −R` falls below this fraction of `|R|`.
const RELATIVE_TOLERANCE: Real = 1.0e-13;

/// What the correction achieved, for reports and tests.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CorrectionReport {
    /// `|R|` before the correction, relative to `Σ_l |b_l|` (dimensionless).
    pub residual_before: Real,
    /// `|R|` after it, relative to `Σ_l |b_l|` (dimensionless).
    pub residual_after: Real,
    /// Conjugate-gradient iterations used.
    pub iterations: usize,
}

/// The boundary integrals `b_l = Σ_{triangles ∋ l} (area / 3) n` (m²) of every particle:
/// a third of each boundary triangle's vector area goes to each of its corners.
pub fn boundary_integrals(rest: &[Vec3], boundary: &[[u32; 3]]) -> Vec<Vec3> {
    let mut b = vec![Vec3::zeros(); rest.len()];
    for t in boundary {
        let [p, q, r] = t.map(|k| rest[k as usize]);
        let third_area_normal = (q - p).cross(&(r - p)) / 6.0;
        for &k in t {
            b[k as usize] += third_area_normal;
        }
    }
    b
}

/// The integration-constraint residual `R_l = Σ_i v_i ∇ψ_l(X_i) − b_l` (m²) of every particle
/// for the gradients in `nbr`, particle volumes `volume` (m³) and boundary integrals `b` (m²).
pub fn integration_residual(nbr: &Neighbourhoods, volume: &[Real], b: &[Vec3]) -> Vec<Vec3> {
    let mut r: Vec<Vec3> = b.iter().map(|v| -v).collect();
    for (i, vi) in volume.iter().enumerate() {
        for e in nbr.range(i) {
            let g = nbr.gradient.get(e) * *vi;
            r[nbr.index[e] as usize] += g;
            r[i] -= g;
        }
    }
    r
}

/// Correct the gradients of `nbr` in place (see the module documentation) for particles at
/// `rest` (m) with volumes `volume` (m³) and the body's outward boundary triangles.
pub fn correct_gradients(
    nbr: &mut Neighbourhoods,
    rest: &[Vec3],
    volume: &[Real],
    boundary: &[[u32; 3]],
) -> CorrectionReport {
    let n = rest.len();
    let b = boundary_integrals(rest, boundary);
    let scale = b
        .iter()
        .map(|v| v.norm())
        .sum::<Real>()
        .max(Real::MIN_POSITIVE);
    let residual = integration_residual(nbr, volume, &b);
    let before = norm(&residual) / scale;
    let op = Operator::new(nbr, volume);
    // Solve S Λ = −R (three independent columns handled together).
    let rhs: Vec<Vec3> = residual.iter().map(|r| -r).collect();
    let mut lambda = vec![Vec3::zeros(); n];
    let iterations = op.solve(&rhs, &mut lambda);
    // ΔG_i = v_i Π_i A_i Λ, kept apart until every particle's is computed from the old
    // gradients.
    let mut delta = vec![Vec3::zeros(); nbr.slot_count()];
    let mut y = Vec::new();
    for (i, vi) in volume.iter().enumerate() {
        op.projected_differences(i, &lambda, &mut y);
        for (e, yj) in nbr.range(i).zip(&y) {
            delta[e] = yj * *vi;
        }
    }
    for i in 0..n {
        for e in nbr.range(i) {
            nbr.gradient.set(e, nbr.gradient.get(e) + delta[e]);
        }
    }
    let after = norm(&integration_residual(nbr, volume, &b)) / scale;
    CorrectionReport {
        residual_before: before,
        residual_after: after,
        iterations,
    }
}

fn norm(v: &[Vec3]) -> Real {
    v.iter().map(|x| x.norm_squared()).sum::<Real>().sqrt()
}

fn dot(a: &[Vec3], b: &[Vec3]) -> Real {
    a.iter().zip(b).map(|(x, y)| x.dot(y)).sum()
}

/// The operator `S = Σ_i v_i² A_iᵀ Π_i A_i`, applied matrix-free.
struct Operator<'a> {
    nbr: &'a Neighbourhoods,
    volume: &'a [Real],
    /// `(U_iᵀ U_i)⁻¹` of every particle (1/m²).
    gram_inverse: Vec<Mat3>,
    /// The diagonal of `S`, for the Jacobi preconditioner.
    diagonal: Vec<Real>,
}

impl<'a> Operator<'a> {
    fn new(nbr: &'a Neighbourhoods, volume: &'a [Real]) -> Self {
        let n = volume.len();
        let mut gram_inverse = Vec::with_capacity(n);
        let mut diagonal = vec![0.0; n];
        for (i, vi) in volume.iter().enumerate() {
            let range = nbr.range(i);
            let u = || nbr.rest_offset.iter_range(range.clone());
            let gram: Mat3 = u().map(|u| u * u.transpose()).sum();
            // The neighbourhood builder guarantees a well-conditioned moment matrix, hence
            // three independent offsets and an invertible Gram matrix.
            let ginv = gram.try_inverse().unwrap_or_else(Mat3::zeros);
            let w = vi * vi;
            // Π_jj = 1 − u_jᵀ G⁻¹ u_j; 1ᵀ Π 1 = k − sᵀ G⁻¹ s with s = Σ_j u_j.
            let s: Vec3 = u().sum();
            diagonal[i] += w * (range.len() as Real - s.dot(&(ginv * s)));
            for (e, uj) in range.clone().zip(u()) {
                diagonal[nbr.index[e] as usize] += w * (1.0 - uj.dot(&(ginv * uj)));
            }
            gram_inverse.push(ginv);
        }
        Operator {
            nbr,
            volume,
            gram_inverse,
            diagonal,
        }
    }

    /// `y = Π_i A_i Λ` (one row per pair of `i`).
    fn projected_differences(&self, i: usize, lambda: &[Vec3], y: &mut Vec<Vec3>) {
        let nbr = self.nbr;
        let range = nbr.range(i);
        y.clear();
        let mut ut_y = Mat3::zeros();
        for e in range.clone() {
            let d = lambda[nbr.index[e] as usize] - lambda[i];
            ut_y += nbr.rest_offset.get(e) * d.transpose();
            y.push(d);
        }
        // Π y = y − U (UᵀU)⁻¹ Uᵀ y; row j of U (UᵀU)⁻¹ Uᵀ y is u_jᵀ G⁻¹ (Uᵀ y).
        let c = self.gram_inverse[i] * ut_y;
        for (e, yj) in range.zip(y.iter_mut()) {
            *yj -= c.transpose() * nbr.rest_offset.get(e);
        }
    }

    /// `out = S x`.
    fn apply(&self, x: &[Vec3], out: &mut [Vec3], scratch: &mut Vec<Vec3>) {
        out.iter_mut().for_each(|o| *o = Vec3::zeros());
        for (i, vi) in self.volume.iter().enumerate() {
            self.projected_differences(i, x, scratch);
            let w = vi * vi;
            let mut sum = Vec3::zeros();
            for (e, z) in self.nbr.range(i).zip(scratch.iter()) {
                out[self.nbr.index[e] as usize] += z * w;
                sum += z;
            }
            out[i] -= sum * w;
        }
    }

    /// Jacobi-preconditioned conjugate gradients for `S x = rhs` from `x = 0`; returns the
    /// iterations used.
    fn solve(&self, rhs: &[Vec3], x: &mut [Vec3]) -> usize {
        let n = rhs.len();
        let inv_diag: Vec<Real> = self
            .diagonal
            .iter()
            .map(|d| if *d > 0.0 { 1.0 / d } else { 0.0 })
            .collect();
        let target = RELATIVE_TOLERANCE * norm(rhs);
        let mut r = rhs.to_vec();
        let mut z: Vec<Vec3> = r.iter().zip(&inv_diag).map(|(r, d)| r * *d).collect();
        let mut p = z.clone();
        let mut sp = vec![Vec3::zeros(); n];
        let mut scratch = Vec::new();
        let mut rz = dot(&r, &z);
        for it in 0..MAX_ITERATIONS {
            if norm(&r) <= target {
                return it;
            }
            self.apply(&p, &mut sp, &mut scratch);
            let psp = dot(&p, &sp);
            if psp <= 0.0 {
                return it;
            }
            let alpha = rz / psp;
            for k in 0..n {
                x[k] += p[k] * alpha;
                r[k] -= sp[k] * alpha;
                z[k] = r[k] * inv_diag[k];
            }
            let rz_next = dot(&r, &z);
            let beta = rz_next / rz;
            rz = rz_next;
            for k in 0..n {
                p[k] = z[k] + p[k] * beta;
            }
        }
        MAX_ITERATIONS
    }
}
