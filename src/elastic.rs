//! The point-based elasticity of the paper (eq. 1–4): MLS deformation gradient, invertible
//! corotated stress, pairwise forces; plus the two pair terms that keep an explicit particle
//! solid well behaved: hourglass control and stiffness-proportional damping.
//!
//! Per particle `i` with volume `v_i` (m³):
//! 1. `F_i = I + Σ_j (x_ij - u_ij) d_ijᵀ` (= `Σ_j x_ij d_ijᵀ`, eq. 1–2, written in displacements
//!    for round-off), see [`crate::neighbours`];
//! 2. `R_i` = the rotation that maximises `tr(Rᵀ F_i)` over proper rotations, found by the
//!    iterative method of Müller et al. (2016) warm-started from the previous step. This is
//!    `U diag(1, 1, det(UVᵀ)) Vᵀ` of the SVD `F = U Σ Vᵀ`: Irving et al.'s inversion handling
//!    (one singular value negated when `F` is inverted);
//! 3. first Piola–Kirchhoff stress of the corotated model (eq. 3, `P = U P̂ Vᵀ` with
//!    `P̂ = λ tr(F̂ - I) I + 2μ (F̂ - I)`), which equals `P = 2μ (F - R) + λ tr(RᵀF - I) R`;
//! 4. force on `i` from pair `ij`: `g_ij = v_i P_i d_ij` (eq. 4), with `f_i += g_ij`,
//!    `f_j -= g_ij`: equal and opposite, so linear momentum is conserved pair by pair, and
//!    `P Fᵀ` symmetric makes the total torque vanish.
//!
//! Hourglass control (after Ganzenmüller 2015): the part of a pair's current offset that `F_i`
//! does not explain, `δ_ij = (F_i u_ij - x_ij)·x̂_ij`, drives a central force of stiffness
//! `c_ij = c_hg E v_i ŵ_ij / |u_ij|²` (N/m), `ŵ` the normalised kernel weight. It vanishes under any affine motion.
//!
//! Damping: a dashpot along each pair, `β k_ij (v_ij·x̂_ij)`, with `k_ij = (λ + 2μ) v_i |d_ij|²`
//! the pair's elastic stiffness (N/m): stiffness-proportional (Rayleigh β) damping that is
//! central (momentum conserving) and zero under rigid motion.

use crate::math::{Mat3, Quat, Real, Vec3};
use crate::neighbours::Neighbourhoods;
use nalgebra::Quaternion;

/// The constants of the elastic model of one body.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ElasticModel {
    /// First Lamé parameter λ (Pa).
    pub lambda: Real,
    /// Shear modulus μ (Pa).
    pub mu: Real,
    /// Hourglass stiffness `c_hg · E` (Pa).
    pub hourglass: Real,
    /// Stiffness-proportional damping time β (s).
    pub damping_stiffness: Real,
}

impl ElasticModel {
    /// The model for Young's modulus `e` (Pa), Poisson ratio `nu`, hourglass coefficient
    /// `c_hg` (dimensionless) and damping time `beta` (s).
    pub fn new(e: Real, nu: Real, c_hg: Real, beta: Real) -> Self {
        ElasticModel {
            lambda: e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)),
            mu: e / (2.0 * (1.0 + nu)),
            hourglass: c_hg * e,
            damping_stiffness: beta,
        }
    }
    /// P-wave modulus λ + 2μ (Pa).
    pub fn p_wave_modulus(&self) -> Real {
        self.lambda + 2.0 * self.mu
    }
}

/// Deformation gradient `F_i` (dimensionless) of particle `i` at positions `x` (m), eq. 1–2.
#[inline]
pub fn deformation_gradient(nbr: &Neighbourhoods, x: &[Vec3], i: usize) -> Mat3 {
    let xi = x[i];
    let mut f = Mat3::identity();
    for e in nbr.range(i) {
        let j = nbr.index[e] as usize;
        let du = x[j] - xi - nbr.rest_offset[e];
        f += du * nbr.gradient[e].transpose();
    }
    f
}

/// Update `q` towards the rotation that maximises `tr(Rᵀ f)` over proper rotations
/// (Müller, Bender, Chentanez, Macklin 2016), at most `max_iterations` iterations.
#[inline]
pub fn extract_rotation(f: &Mat3, q: &mut Quat, max_iterations: u32) {
    for _ in 0..max_iterations {
        let r = q.to_rotation_matrix();
        let r = r.matrix();
        let mut num = Vec3::zeros();
        let mut den = 0.0;
        for c in 0..3 {
            let rc = r.column(c);
            let fc = f.column(c);
            num += rc.cross(&fc);
            den += rc.dot(&fc);
        }
        let omega = num / (den.abs() + 1.0e-9);
        let w2 = omega.norm_squared();
        if w2 < 1.0e-24 {
            break;
        }
        // A rotation by ~|ω| about ω: the normalised quaternion (1, ω/2); no trigonometry.
        let dq = Quaternion::new(1.0, 0.5 * omega.x, 0.5 * omega.y, 0.5 * omega.z);
        *q = Quat::new_normalize(dq * q.into_inner());
    }
}

/// First Piola–Kirchhoff stress (Pa) of the corotated model for deformation gradient `f` and
/// its rotation `r` (eq. 3): `2μ (F - R) + λ tr(RᵀF - I) R`.
#[inline]
pub fn corotated_stress(f: &Mat3, r: &Mat3, lambda: Real, mu: Real) -> Mat3 {
    let tr = (r.transpose() * f).trace() - 3.0;
    (f - r) * (2.0 * mu) + r * (lambda * tr)
}

/// Scratch and output of [`accumulate_forces`] that the caller owns (no allocation inside).
pub struct ForceInputs<'a> {
    /// Neighbourhoods of the body.
    pub nbr: &'a Neighbourhoods,
    /// Particle volumes `v_i` (m³).
    pub volume: &'a [Real],
    /// Current positions (m).
    pub x: &'a [Vec3],
    /// Current velocities (m/s); used only when the model's damping is non-zero.
    pub v: &'a [Vec3],
}

/// Add the elastic, hourglass and damping forces (N) of every particle to `force`.
/// `rotation` holds each particle's rotation, warm-started and updated in place.
pub fn accumulate_forces(
    model: &ElasticModel,
    input: &ForceInputs<'_>,
    rotation: &mut [Quat],
    rotation_iterations: u32,
    force: &mut [Vec3],
) {
    let nbr = input.nbr;
    let x = input.x;
    let damped = model.damping_stiffness > 0.0;
    let pwave = model.p_wave_modulus();
    for i in 0..nbr.particle_count() {
        let f = deformation_gradient(nbr, x, i);
        extract_rotation(&f, &mut rotation[i], rotation_iterations);
        let r = rotation[i].to_rotation_matrix().into_inner();
        let vi = input.volume[i];
        let p = corotated_stress(&f, &r, model.lambda, model.mu) * vi;
        let xi = x[i];
        let mut fi = Vec3::zeros();
        for e in nbr.range(i) {
            let j = nbr.index[e] as usize;
            let d = nbr.gradient[e];
            let u = nbr.rest_offset[e];
            let xij = x[j] - xi;
            let mut g = p * d;
            let len2 = xij.norm_squared();
            if len2 > 1.0e-30 {
                // Central terms along x_ij, written without a square root:
                // -c δ x̂ = -c ((F u - x)·x) x / |x|², and β k (v_ij·x̂) x̂ likewise.
                let c_hg = model.hourglass * vi * nbr.hourglass_weight[e];
                let mut central = -c_hg * (f * u - xij).dot(&xij);
                if damped {
                    let k = pwave * vi * d.norm_squared();
                    central += model.damping_stiffness * k * (input.v[j] - input.v[i]).dot(&xij);
                }
                g += xij * (central / len2);
            }
            fi += g;
            force[j] -= g;
        }
        force[i] += fi;
    }
}
