//! The point-based elasticity of the paper (eq. 1–4): MLS deformation gradient, invertible
//! corotated stress, pairwise forces; plus the two pair terms that keep an explicit particle
//! solid well behaved: hourglass control. (Stiffness-proportional damping filters the velocities
//! after the kick, implicitly, on the mesh edges: [`crate::kernels::tet_dashpots`].)
//!
//! Per particle `i` with volume `v_i` (m³):
//! 1. `F_i = I + Σ_j (x_ij - u_ij) d_ijᵀ` (= `Σ_j x_ij d_ijᵀ`, eq. 1–2, written in displacements
//!    for round-off), see [`crate::kernels::neighbours`];
//! 2. `R_i` = the rotation that maximises `tr(Rᵀ F_i)` over proper rotations, found four
//!    particles at a time by warm-started Newton steps, see [`crate::kernels::rotation`]. This is
//!    `U diag(1, 1, det(UVᵀ)) Vᵀ` of the SVD `F = U Σ Vᵀ`: Irving et al.'s inversion handling
//!    (one singular value negated when `F` is inverted);
//! 3. first Piola–Kirchhoff stress of the corotated model (eq. 3, `P = U P̂ Vᵀ` with
//!    `P̂ = λ tr(F̂ - I) I + 2μ (F̂ - I)`), which equals `P = 2μ (F - R) + λ tr(RᵀF - I) R`;
//! 4. force on `i` from pair `ij`: `g_ij = v_i P_i d_ij` (eq. 4), with `f_i += g_ij`,
//!    `f_j -= g_ij`: equal and opposite, so linear momentum is conserved pair by pair, and
//!    `P Fᵀ` symmetric makes the total torque vanish.
//!
//! Hourglass control (in the spirit of Ganzenmüller 2015): the part of a pair's current offset
//! that `F_i` does not explain, `ε_ij = F_i u_ij - x_ij`, is penalised by the energy
//! `Σ_i Σ_j c_ij |ε_ij|² / 2` with `c_ij = c_hg μ v_i ŵ_ij / |u_ij|²` (N/m), `ŵ` the normalised
//! kernel weight. `ε` is linear in the positions (through `F_i`), zero under any affine motion
//! and rotation invariant in norm, so its exact gradient is a conservative force that conserves
//! linear and angular momentum and never pumps energy into the zero-energy modes it removes.

use crate::kernels::lanes::{F4, LANES, M4, V4};
use crate::kernels::math::{Mat3, Quat, Real, Vec3};
use crate::kernels::neighbours::{Neighbourhoods, MAX_FIXED_NEIGHBOURS};
use crate::kernels::pair_sums::{self, Kept, ShareForces};
use crate::kernels::parallel::{Barrier, Pool, SharedSlice};
use crate::kernels::rotation::{extract_rotations, rotation_from_svd};
use std::ops::Range;

/// The constants of the elastic model of one body.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ElasticModel {
    /// First Lamé parameter λ (Pa).
    pub lambda: Real,
    /// Shear modulus μ (Pa).
    pub mu: Real,
    /// Hourglass stiffness `c_hg · μ` (Pa).
    pub hourglass: Real,
    /// Stiffness-proportional damping time β (s), for the edge dashpots of
    /// [`crate::kernels::tet_dashpots`].
    pub damping_stiffness: Real,
}

impl ElasticModel {
    /// The model for Young's modulus `e` (Pa), Poisson ratio `nu`, hourglass coefficient
    /// `c_hg` (dimensionless) and damping time `beta` (s).
    pub fn new(e: Real, nu: Real, c_hg: Real, beta: Real) -> Self {
        ElasticModel {
            lambda: e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)),
            mu: e / (2.0 * (1.0 + nu)),
            hourglass: c_hg * e / (2.0 * (1.0 + nu)),
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
        let du = x[j] - xi - nbr.rest_offset.get(e);
        f += du * nbr.gradient.get(e).transpose();
    }
    f
}

/// First Piola–Kirchhoff stress (Pa) of the corotated model for deformation gradients `f` and
/// their rotations `r`, lane-wise (eq. 3): `2μ (F - R) + λ tr(RᵀF - I) R`.
#[inline(always)]
pub(crate) fn corotated_stress(f: &M4, r: &M4, lambda: Real, mu: Real) -> M4 {
    let tr = r.inner(f) - F4::splat(3.0);
    f.sub(r)
        .scale(F4::splat(2.0 * mu))
        .add(&r.scale(F4::splat(lambda) * tr))
}

/// The inputs of [`accumulate_forces`].
pub struct ForceInputs<'a> {
    /// Neighbourhoods of the body.
    pub nbr: &'a Neighbourhoods,
    /// Particle volumes `v_i` (m³).
    pub volume: &'a [Real],
    /// Current positions (m).
    pub x: &'a [Vec3],
    /// Which particles' terms are computed, or empty: all of them. Otherwise `active_before[i]`
    /// counts the computed particles before `i` (length: particles + 1), and a particle that
    /// is not counted must be one whose terms act on nothing that is used: a fixed particle
    /// whose neighbours are all fixed (`Body::active_before`). The pass skips a block of four
    /// such particles, which leaves the forces on fixed particles incomplete and their
    /// rotations as they were, and splits the particles among the threads by the computed ones.
    pub active_before: &'a [u32],
}

/// Add the elastic and hourglass forces (N) of every particle to `force`.
///
/// `rotation` holds each particle's rotation, warm-started and updated in place; `pair_force`
/// (one entry per pair slot) and `own_force` (one per particle) are scratch, used on several
/// threads only (they may be empty on one): no allocation inside.
///
/// Every particle `i` computes its deformation gradient, rotation and stress and the force
/// `g_ij` of each of its pairs (+`g_ij` on `i`, −`g_ij` on `j`). The particles are split into
/// one contiguous share per thread; each share runs its particles in order and scatters each
/// term to a particle all of whose terms come from the share, and keeps the others for a sum
/// after a barrier, in the same order ([`crate::kernels::pair_sums`]). Every force is so summed
/// in the one-thread order: the result is bit-identical for any number of threads. Particles that
/// [`ForceInputs::active_before`] leaves out are skipped, four at a time.
#[allow(clippy::too_many_arguments)]
pub fn accumulate_forces(
    model: &ElasticModel,
    input: &ForceInputs<'_>,
    rotation: &mut [Quat],
    rotation_iterations: u32,
    pair_force: &mut [Vec3],
    own_force: &mut [Vec3],
    force: &mut [Vec3],
    pool: &Pool,
) {
    let pass = ParticlePass {
        model,
        input,
        rotation_iterations,
    };
    accumulate_forces_in(
        Kernel::detect(),
        &pass,
        rotation,
        pair_force,
        own_force,
        force,
        pool,
    );
}

/// [`accumulate_forces`] with the particle loops of `kernel`.
fn accumulate_forces_in(
    kernel: Kernel,
    pass: &ParticlePass<'_, '_>,
    rotation: &mut [Quat],
    pair_force: &mut [Vec3],
    own_force: &mut [Vec3],
    force: &mut [Vec3],
    pool: &Pool,
) {
    let nbr = pass.input.nbr;
    let n = nbr.particle_count();
    assert!(rotation.len() == n && force.len() == n);
    let active_before = pass.input.active_before;
    assert!(active_before.is_empty() || active_before.len() == n + 1);
    let several = pool.threads() > 1;
    assert!(
        !several || (pair_force.len() == nbr.slot_count() && own_force.len() == n),
        "the kept forces are sized for several threads"
    );
    let rotation = SharedSlice::new(rotation);
    let pairs = SharedSlice::new(pair_force);
    let own = SharedSlice::new(own_force);
    let forces = SharedSlice::new(force);
    let barrier = Barrier::new(pool.threads());
    pool.run(&|share| {
        let _guard = barrier.guard();
        let particles = balanced_share(pool, share, active_before, n);
        {
            // One share keeps nothing (its kept forces may be empty).
            let (slots, kept) = if several {
                let first_slot = nbr.offsets[particles.start] as usize;
                (
                    first_slot..nbr.offsets[particles.end] as usize,
                    particles.clone(),
                )
            } else {
                (0..0, 0..0)
            };
            // SAFETY: shares own disjoint particle ranges, hence disjoint pair ranges (CSR).
            let mut out = unsafe {
                ShareForces {
                    nbr,
                    share: particles.clone(),
                    force: forces.range(particles.clone()),
                    pair_force: pairs.range(slots),
                    own: own.range(kept),
                }
            };
            // SAFETY: as above.
            let rotation = unsafe { rotation.range(particles.clone()) };
            kernel.share_pass(pass, rotation, &mut out);
        }
        if !several {
            return; // one share: no particle crosses shares
        }
        barrier.wait();
        // SAFETY: every share's first pass has finished: what it kept is only read from here
        // on; each share writes only its own particles' forces.
        let kept = unsafe {
            Kept {
                pairs: pairs.read(0..nbr.slot_count()),
                own: own.read(0..n),
            }
        };
        // SAFETY: shares own disjoint particle ranges.
        let f = unsafe { forces.range(particles.clone()) };
        pair_sums::sum_after_barrier(nbr, particles, f, kept);
    });
}

/// Which particles a step's force pass computes, given the `fixed` flags: into
/// `active_before[i]` (length: particles + 1), how many of the particles before `i` are not
/// inert, an inert particle being fixed with every neighbour fixed ([`ForceInputs::active_before`]).
pub(crate) fn count_active(nbr: &Neighbourhoods, fixed: &[bool], active_before: &mut [u32]) {
    assert!(fixed.len() == nbr.particle_count() && active_before.len() == fixed.len() + 1);
    let mut active = 0;
    for (i, &fixed_i) in fixed.iter().enumerate() {
        active_before[i] = active;
        let inert = fixed_i && nbr.index[nbr.range(i)].iter().all(|&j| fixed[j as usize]);
        active += u32::from(!inert);
    }
    active_before[fixed.len()] = active;
}

/// The particles of share `share` of the `n` in a force pass: contiguous ranges in order that
/// hold as many computed particles each as [`Pool::share`] would give them (see
/// [`ForceInputs::active_before`]).
fn balanced_share(pool: &Pool, share: usize, active_before: &[u32], n: usize) -> Range<usize> {
    if active_before.is_empty() {
        return pool.share(share, n);
    }
    let computed = active_before[n] as usize;
    let boundary = |k: usize| match k {
        0 => 0,
        k if k == pool.threads() => n,
        k => {
            let work = pool.share(k, computed).start;
            active_before[..n].partition_point(|&a| (a as usize) < work)
        }
    };
    boundary(share)..boundary(share + 1)
}

/// What every particle of a force pass needs besides its own arrays.
struct ParticlePass<'a, 'b> {
    model: &'a ElasticModel,
    input: &'a ForceInputs<'b>,
    rotation_iterations: u32,
}

/// The first pass of one share's particles (`out.share`, their rotations in `rotation`), a
/// block of four at a time, each particle's results handed on in order
/// ([`ShareForces::distribute`]).
#[inline(always)]
fn share_pass(pass: &ParticlePass<'_, '_>, rotation: &mut [Quat], out: &mut ShareForces<'_>) {
    let nbr = pass.input.nbr;
    let active = pass.input.active_before;
    let share = out.share.clone();
    let mut buffer = BlockBuffer::new();
    let mut own = [Vec3::zeros(); LANES];
    for (block, q) in rotation.chunks_mut(LANES).enumerate() {
        let first = share.start + block * LANES;
        let particles = first..first + q.len();
        if !active.is_empty() && active[particles.start] == active[particles.end] {
            continue; // a block of inert particles
        }
        let base = nbr.offsets[first] as usize;
        let own = &mut own[..q.len()];
        block_pair_forces(pass, first, q, &mut buffer, own);
        for (i, &fi) in particles.zip(own.iter()) {
            let s = nbr.slots(i);
            let chunks = (s.start - base) / LANES..(s.end - base) / LANES;
            out.distribute(i, buffer.pair_force[chunks].as_flattened(), fi);
        }
    }
}

/// How the particle loops of the force pass are compiled, chosen at run time.
///
/// The pair passes keep a 3×3 matrix of four-lane accumulators, a splatted matrix and the
/// chunk's operands live at once: more than AVX2's 16 vector registers, so some spill to the
/// stack every chunk. Processors with AVX-512 (VL) have 32 registers for the same 256-bit
/// instructions; on them the loops run in a copy compiled with those features. The arithmetic
/// is the same lane-wise IEEE operations (fused multiply–adds where the build has FMA, in both
/// copies: `wide` decides at the build's target, not the copy's), so both give the same bits.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kernel {
    /// Compiled for the build's target (x86-64-v3 in this repository, `.cargo/config.toml`).
    Build,
    /// Compiled with AVX-512 F and VL enabled (x86-64 only).
    #[cfg_attr(not(target_arch = "x86_64"), allow(dead_code))]
    Avx512,
}

impl Kernel {
    /// The best kernel this processor runs.
    fn detect() -> Kernel {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx512f")
            && std::arch::is_x86_feature_detected!("avx512vl")
        {
            return Kernel::Avx512;
        }
        Kernel::Build
    }

    /// [`share_pass`] in this kernel's copy.
    fn share_pass(
        self,
        pass: &ParticlePass<'_, '_>,
        rotation: &mut [Quat],
        out: &mut ShareForces<'_>,
    ) {
        match self {
            #[cfg(target_arch = "x86_64")]
            // SAFETY: `detect` returns `Avx512` only on a processor with AVX-512 F and VL.
            Kernel::Avx512 => unsafe { avx512::share_pass(pass, rotation, out) },
            _ => share_pass(pass, rotation, out),
        }
    }
}

/// The particle loops compiled with AVX-512 F and VL (see [`Kernel`]).
#[cfg(target_arch = "x86_64")]
mod avx512 {
    use super::*;

    #[target_feature(enable = "avx512f,avx512vl")]
    pub(super) fn share_pass(
        pass: &ParticlePass<'_, '_>,
        rotation: &mut [Quat],
        out: &mut ShareForces<'_>,
    ) {
        super::share_pass(pass, rotation, out)
    }
}

/// Pair data of [`block_pair_forces`], four pair slots a chunk: held between its passes, the
/// current offsets `x_ij` (m) of a block's particles and the hourglass residuals `ε_ij` (m) of
/// one particle; its result, the pair forces of the block's particles.
struct BlockBuffer {
    offset: [V4; LANES * MAX_CHUNKS],
    residual: [V4; MAX_CHUNKS],
    /// The forces `g_ij` (N) of the block's pair slots, four a chunk, zero for the padding.
    pair_force: [[Vec3; LANES]; LANES * MAX_CHUNKS],
}

/// Chunks of four pair slots a particle may have: the largest neighbourhood that
/// [`crate::kernels::neighbours::build`] accepts, padded.
const MAX_CHUNKS: usize = MAX_FIXED_NEIGHBOURS.div_ceil(LANES);

impl BlockBuffer {
    fn new() -> Self {
        BlockBuffer {
            offset: [V4::default(); LANES * MAX_CHUNKS],
            residual: [V4::default(); MAX_CHUNKS],
            pair_force: [[Vec3::zeros(); LANES]; LANES * MAX_CHUNKS],
        }
    }
}

/// The rest data of four consecutive pair slots (their neighbours are gathered through
/// [`PairChunks::gather`]): rest offsets `u_ij` (m), MLS gradients `d_ij` (1/m) and hourglass
/// weights `ŵ_ij / |u_ij|²` (1/m²).
struct PairChunk {
    u: V4,
    d: V4,
    w: F4,
}

/// The rest data of a particle's pair slots (a whole number of chunks, see
/// [`crate::kernels::neighbours::PAIR_SLOT_ALIGNMENT`]), four slots a chunk.
struct PairChunks<'a> {
    /// Above every neighbour index of `j` (of the slots these were split from, for a
    /// [`PairChunks::sub`]): a field at least this long can be gathered from without a check
    /// per index ([`PairChunks::gather`]).
    bound: usize,
    j: &'a [[u32; LANES]],
    u: [&'a [[Real; LANES]]; 3],
    d: [&'a [[Real; LANES]]; 3],
    w: &'a [[Real; LANES]],
}

impl<'a> PairChunks<'a> {
    #[inline(always)]
    fn new(nbr: &'a Neighbourhoods, slots: Range<usize>) -> Self {
        fn whole<T>(s: &[T]) -> &[[T; LANES]] {
            let (chunks, rest) = s.as_chunks();
            assert!(rest.is_empty(), "pair slots come in whole chunks");
            chunks
        }
        let (u, d) = (&nbr.rest_offset, &nbr.gradient);
        let s = slots;
        let j = whole(&nbr.index[s.clone()]);
        let out = PairChunks {
            bound: j.as_flattened().iter().fold(0, |m, &j| m.max(j)) as usize + 1,
            j,
            u: [&u.x, &u.y, &u.z].map(|c| whole(&c[s.clone()])),
            d: [&d.x, &d.y, &d.z].map(|c| whole(&c[s.clone()])),
            w: whole(&nbr.hourglass_weight[s]),
        };
        let n = out.len();
        assert!(out.u.iter().chain(&out.d).all(|c| c.len() == n) && out.w.len() == n);
        out
    }
    /// The chunks `chunks` of these.
    #[inline(always)]
    fn sub(&self, chunks: Range<usize>) -> PairChunks<'a> {
        PairChunks {
            bound: self.bound,
            j: &self.j[chunks.clone()],
            u: self.u.map(|a| &a[chunks.clone()]),
            d: self.d.map(|a| &a[chunks.clone()]),
            w: &self.w[chunks],
        }
    }
    #[inline(always)]
    fn len(&self) -> usize {
        self.j.len()
    }
    /// Whether every neighbour index is below `len` (one comparison for all the chunks).
    #[inline(always)]
    fn indexes_below(&self, len: usize) -> bool {
        self.bound <= len
    }
    /// `field[j]` for the four neighbours `j` of chunk `k`, where [`PairChunks::indexes_below`]
    /// the field's length (checked by the caller, once for all its chunks).
    ///
    /// # Safety
    /// `self.indexes_below(field.len())`.
    #[inline(always)]
    unsafe fn gather(&self, field: &[Vec3], k: usize) -> V4 {
        // SAFETY: every index of `j` is below `bound` (computed from them, or from a superset
        // for a sub-view), hence below the field's length (the caller's contract).
        unsafe { V4::gather_unchecked(field, &self.j[k]) }
    }
    #[inline(always)]
    fn get(&self, k: usize) -> PairChunk {
        let v = |c: &[&[[Real; LANES]]; 3]| V4 {
            x: F4::new(c[0][k]),
            y: F4::new(c[1][k]),
            z: F4::new(c[2][k]),
        };
        PairChunk {
            u: v(&self.u),
            d: v(&self.d),
            w: F4::new(self.w[k]),
        }
    }
}

/// The first pass of the particles `first..first + rotation.len()` (a block of at most
/// [`LANES`]): their deformation gradients, rotations (warm-started in `rotation`) and stresses,
/// the force `g_ij` on `i` of each of their pair slots written to `buffer.pair_force` (the
/// block's slots, from the first particle's; zero for the padding), and each particle's sum in
/// `own`.
///
/// Per particle, three passes over its slots, four at a time (see [`crate::kernels::lanes`]); the
/// rotations and stresses of the block's particles in lanes, one a lane. A padding slot
/// (neighbour `i`, zero rest data) adds nothing anywhere. Always inlined, so that [`Kernel`]
/// compiles it into its copies.
#[inline(always)]
fn block_pair_forces(
    pass: &ParticlePass<'_, '_>,
    first: usize,
    rotation: &mut [Quat],
    buffer: &mut BlockBuffer,
    own: &mut [Vec3],
) {
    let (model, input) = (pass.model, pass.input);
    let nbr = input.nbr;
    let particles = first..first + rotation.len();
    let base = nbr.offsets[first] as usize;
    let chunks = |i: usize| {
        let s = nbr.slots(i);
        (s.start - base) / LANES..(s.end - base) / LANES
    };
    // The rest data of the block's slots, split once into chunks.
    let rest = PairChunks::new(nbr, base..nbr.offsets[particles.end] as usize);
    let mut f = [Mat3::identity(); LANES];
    let mut volume = [0.0; LANES];
    for (l, i) in particles.clone().enumerate() {
        let c = chunks(i);
        f[l] = gradient_pass(input, i, &rest.sub(c.clone()), &mut buffer.offset[c]);
        volume[l] = input.volume[i];
    }
    let f4 = M4::from_matrices(&f);
    let r4 = extract_rotations(&f4, rotation, pass.rotation_iterations);
    let stress = corotated_stress(&f4, &r4, model.lambda, model.mu).scale(F4::new(volume));
    for (l, i) in particles.enumerate() {
        let c = chunks(i);
        own[l] = pair_pass(
            pass,
            i,
            &rest.sub(c.clone()),
            (&f[l], &stress.lane(l)),
            &buffer.offset[c.clone()],
            &mut buffer.residual,
            &mut buffer.pair_force[c],
        );
    }
}

/// Pass 1 of particle `i`, `rest` the rest data of its slots: `F = I + Σ (x_ij - u_ij) d_ijᵀ`
/// (dimensionless), keeping the offsets `x_ij` (m) of its slots in `offset` (one entry per
/// chunk of four).
#[inline(always)]
fn gradient_pass(
    input: &ForceInputs<'_>,
    i: usize,
    rest: &PairChunks<'_>,
    offset: &mut [V4],
) -> Mat3 {
    let offset = &mut offset[..rest.len()];
    let xi = V4::splat(&input.x[i]);
    let mut fsum = M4::default();
    assert!(rest.indexes_below(input.x.len()));
    for (k, o) in offset.iter_mut().enumerate() {
        let c = rest.get(k);
        // SAFETY: checked before the loop.
        *o = unsafe { rest.gather(input.x, k) } - xi;
        fsum.add_outer(&(*o - c.u), &c.d);
    }
    fsum.sum() + Mat3::identity()
}

/// Passes 2 and 3 of particle `i` (`rest`: the rest data of its slots), given its deformation
/// gradient and its stress times its volume `v_i P_i` (N·m) in `(f, stress)` and its offsets
/// `x_ij` from pass 1: the force `g_ij` (N) of each pair slot written to `pair_force`, their
/// sum returned.
#[inline(always)]
fn pair_pass(
    pass: &ParticlePass<'_, '_>,
    i: usize,
    rest: &PairChunks<'_>,
    (f, stress): (&Mat3, &Mat3),
    offset: &[V4],
    residual: &mut [V4],
    pair_force: &mut [[Vec3; LANES]],
) -> Vec3 {
    let (model, input) = (pass.model, pass.input);
    let chunks = rest.len();
    let (offset, residual) = (&offset[..chunks], &mut residual[..chunks]);
    let pair_force = &mut pair_force[..chunks];
    let vi = input.volume[i];
    // Pass 2: hourglass residuals ε = F u - x_ij and Q = Σ c ε uᵀ; skipped without hourglass
    // control (ε then multiplies c = 0 below).
    let c_scale = F4::splat(model.hourglass * vi);
    let mut qsum = M4::default();
    if model.hourglass != 0.0 {
        let fl = M4::splat(f);
        for (k, (o, eps)) in offset.iter().zip(residual.iter_mut()).enumerate() {
            let c = rest.get(k);
            *eps = fl.mul_sub(&c.u, o);
            qsum.add_outer(eps, &c.u.scale(c.w * c_scale));
        }
    } else {
        residual.fill(V4::default());
    }
    // Pass 3: force on neighbour j is -(v_i P + Q) d + c ε, on i the opposite: g_ij.
    let m = M4::splat(&(stress + qsum.sum()));
    let data = PairForceData {
        rest,
        m: &m,
        c_scale,
        residual,
    };
    let fi = pair_forces(&data, pair_force);
    fi.sum()
}

/// What pass 3 of one particle reads (see [`pair_pass`]): the rest data of its slots, `v_i P +
/// Q` (N·m) splatted, the hourglass scale `c v_i` (N/m · m²) and the residuals `ε_ij` (m) of
/// pass 2.
struct PairForceData<'a, 'r> {
    rest: &'a PairChunks<'r>,
    m: &'a M4,
    c_scale: F4,
    residual: &'a [V4],
}

/// Pass 3 of one particle: the force `g_ij` (N) of each pair slot written to `pair_force`,
/// their sum returned.
#[inline(always)]
fn pair_forces(data: &PairForceData<'_, '_>, pair_force: &mut [[Vec3; LANES]]) -> V4 {
    let rest = data.rest;
    let mut fi = V4::default();
    for (k, (eps, out)) in data.residual.iter().zip(pair_force).enumerate() {
        let c = rest.get(k);
        let g = eps.scale_sub_from(c.w * data.c_scale, &data.m.mul(&c.d));
        g.store(out);
        fi += g;
    }
    fi
}

/// The elastic energy (J) at positions `x` (m) whose negative gradient the force pass
/// computes (with the exact polar rotations):
/// `Σ_i v_i [μ |F_i - R_i|² + λ/2 tr(R_iᵀF_i - I)²] + Σ_i Σ_j c_ij |ε_ij|² / 2`.
pub(crate) fn energy(
    model: &ElasticModel,
    nbr: &Neighbourhoods,
    volume: &[Real],
    x: &[Vec3],
) -> Real {
    let mut total = 0.0;
    for (i, vi) in volume.iter().enumerate() {
        let f = deformation_gradient(nbr, x, i);
        let r = rotation_from_svd(&f).to_rotation_matrix().into_inner();
        let tr = (r.transpose() * f).trace() - 3.0;
        total += vi * (model.mu * (f - r).norm_squared() + 0.5 * model.lambda * tr * tr);
        for e in nbr.range(i) {
            let j = nbr.index[e] as usize;
            let eps = f * nbr.rest_offset.get(e) - (x[j] - x[i]);
            total += 0.5 * model.hourglass * vi * nbr.hourglass_weight[e] * eps.norm_squared();
        }
    }
    total
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kernels::neighbours::{build, SupportRadius};

    /// A jittered 5×4×4 block of points (m), with a deterministic pseudo-random jitter.
    fn jittered_block() -> Vec<Vec3> {
        let mut random = crate::kernels::math::uniform(12345);
        let mut jitter = move || random() * 0.3;
        let mut points = Vec::new();
        for i in 0..5 {
            for j in 0..4 {
                for k in 0..4 {
                    let p = Vec3::new(i as Real, j as Real, k as Real);
                    points.push(p + Vec3::new(jitter(), jitter(), jitter()));
                }
            }
        }
        points
    }

    /// A smooth large deformation with some rotation of the block.
    fn deformed(rest: &[Vec3]) -> Vec<Vec3> {
        let rot = Quat::from_scaled_axis(Vec3::new(0.3, -0.2, 0.5));
        rest.iter()
            .map(|p| rot * Vec3::new(1.2 * p.x + 0.1 * p.y * p.y, 0.9 * p.y, p.z + 0.2 * p.x))
            .collect()
    }

    fn forces(model: &ElasticModel, input: &ForceInputs<'_>, threads: usize) -> Vec<Vec3> {
        let n = input.x.len();
        let mut rotation = vec![Quat::identity(); n];
        let mut pair_force = vec![Vec3::zeros(); input.nbr.slot_count()];
        let mut own_force = vec![Vec3::zeros(); n];
        let mut force = vec![Vec3::zeros(); n];
        accumulate_forces(
            model,
            input,
            &mut rotation,
            50,
            &mut pair_force,
            &mut own_force,
            &mut force,
            &Pool::new(threads),
        );
        force
    }

    /// The four-lane force pass is the exact negative gradient of the energy (central finite
    /// differences), on neighbourhoods whose sizes are not all multiples of four (the padded
    /// lanes must add nothing), and the same bits on one, two and three threads.
    #[test]
    fn forces_are_the_negative_energy_gradient_on_any_neighbourhood_size() {
        let rest = jittered_block();
        let nbr = build(&rest, SupportRadius::Automatic { target: 13 }).unwrap();
        let sizes: Vec<usize> = (0..rest.len()).map(|i| nbr.range(i).len()).collect();
        assert!(sizes.iter().any(|k| k % LANES != 0), "{sizes:?}");
        let volume: Vec<Real> = (0..rest.len()).map(|i| 1.0 + 0.01 * i as Real).collect();
        let model = ElasticModel::new(1000.0, 0.3, 0.5, 0.0);
        let x = deformed(&rest);
        let input = ForceInputs {
            nbr: &nbr,
            volume: &volume,
            x: &x,
            active_before: &[],
        };
        let f = forces(&model, &input, 1);
        // Three threads: shares of odd length (pass B takes particles two at a time).
        assert_eq!(f, forces(&model, &input, 2));
        assert_eq!(f, forces(&model, &input, 3));
        let scale = f.iter().map(|g| g.norm()).fold(0.0, Real::max);
        let h = 1e-6;
        for i in [0, 7, 33, 79] {
            for c in 0..3 {
                let (mut plus, mut minus) = (x.clone(), x.clone());
                plus[i][c] += h;
                minus[i][c] -= h;
                let de =
                    energy(&model, &nbr, &volume, &plus) - energy(&model, &nbr, &volume, &minus);
                let expected = -de / (2.0 * h);
                assert!(
                    (f[i][c] - expected).abs() < 1e-6 * scale,
                    "particle {i} component {c}: force {} against -dE/dx {expected}",
                    f[i][c]
                );
            }
        }
    }

    /// The pass skips the blocks of inert particles (fixed, with every neighbour fixed) and
    /// changes no force on a particle that is not fixed, on one thread or several (whose
    /// shares it balances by the particles computed). Marking a fixed particle with a free
    /// neighbour inert does change them: the skip is real.
    #[test]
    fn inert_particles_change_no_free_force() {
        let rest = jittered_block();
        let nbr = build(&rest, SupportRadius::Automatic { target: 13 }).unwrap();
        let n = rest.len();
        let volume = vec![1.0; n];
        let model = ElasticModel::new(1000.0, 0.3, 0.5, 0.0);
        let x = deformed(&rest);
        // The block's first three layers (x ≤ 2 before the jitter) fixed.
        let fixed: Vec<bool> = rest.iter().map(|p| p.x < 2.5).collect();
        let mut active_before = vec![0; n + 1];
        count_active(&nbr, &fixed, &mut active_before);
        let inert = |i: usize| active_before[i] == active_before[i + 1];
        let inert_blocks = (0..n / LANES)
            .filter(|b| (b * LANES..(b + 1) * LANES).all(inert))
            .count();
        assert!(inert_blocks >= 2, "{inert_blocks} inert blocks");
        assert!((0..n).all(|i| !inert(i) || fixed[i]));
        let input = |active_before| ForceInputs {
            nbr: &nbr,
            volume: &volume,
            x: &x,
            active_before,
        };
        let free_forces = |f: Vec<Vec3>| -> Vec<Vec3> {
            f.into_iter()
                .zip(&fixed)
                .filter(|(_, &fixed)| !fixed)
                .map(|(f, _)| f)
                .collect()
        };
        let all = free_forces(forces(&model, &input(&[]), 1));
        for threads in 1..=3 {
            let pool = Pool::new(threads);
            let shares: Vec<_> = (0..threads)
                .map(|k| balanced_share(&pool, k, &active_before, n))
                .collect();
            assert_eq!((shares[0].start, shares[threads - 1].end), (0, n));
            for (k, pair) in shares.windows(2).enumerate() {
                assert_eq!(pair[0].end, pair[1].start, "share {k}");
            }
            for (k, share) in shares.iter().enumerate() {
                let computed = active_before[share.end] - active_before[share.start];
                let even = pool.share(k, active_before[n] as usize).len() as u32;
                assert_eq!(computed, even, "share {k}");
            }
            let skipped = forces(&model, &input(&active_before), threads);
            assert_eq!(all, free_forces(skipped), "{threads} threads");
        }
        // A fixed particle next to a free one, wrongly marked inert with its block.
        let edge = (0..n)
            .find(|&i| fixed[i] && nbr.index[nbr.range(i)].iter().any(|&j| !fixed[j as usize]))
            .unwrap();
        let block = edge / LANES * LANES;
        let mut wrong = active_before.clone();
        for (i, w) in wrong.iter_mut().enumerate().skip(block + 1) {
            *w = active_before[i] - (active_before[i.min(block + LANES)] - active_before[block]);
        }
        assert_ne!(all, free_forces(forces(&model, &input(&wrong), 1)));
    }

    /// The gathers of the pair loops read without a check per index, after one check per
    /// particle: positions that stop before a neighbour of the block (though not before its
    /// own particles) are refused with a panic, never read past.
    #[test]
    fn fields_shorter_than_the_neighbourhoods_are_refused() {
        let rest = jittered_block();
        let nbr = build(&rest, SupportRadius::Automatic { target: 13 }).unwrap();
        let n = rest.len();
        let volume = vec![1.0; n];
        let model = ElasticModel::new(1000.0, 0.3, 0.5, 0.0);
        // The first block's farthest neighbour: positions that stop just before it.
        let block = 0..LANES;
        let far = nbr.index[nbr.offsets[0] as usize..nbr.offsets[LANES] as usize]
            .iter()
            .fold(0, |m, &j| m.max(j as usize));
        assert!(far >= LANES, "a neighbour past the block's particles");
        let input = ForceInputs {
            nbr: &nbr,
            volume: &volume,
            x: &rest[..far],
            active_before: &[],
        };
        let pass = ParticlePass {
            model: &model,
            input: &input,
            rotation_iterations: 50,
        };
        let run = std::panic::catch_unwind(|| {
            let mut rotation = [Quat::identity(); LANES];
            let mut own = [Vec3::zeros(); LANES];
            let mut buffer = BlockBuffer::new();
            block_pair_forces(&pass, block.start, &mut rotation, &mut buffer, &mut own);
        });
        assert!(run.is_err(), "{far} positions");
    }

    /// The AVX-512 copy of the particle loops gives the same bits as the build's own, on one
    /// thread and on three (where pair forces are kept and summed after the barrier), with
    /// hourglass control on. On a processor without AVX-512 there is only one
    /// copy: nothing to compare.
    #[test]
    fn every_kernel_gives_the_same_bits() {
        if Kernel::detect() == Kernel::Build {
            eprintln!("no AVX-512 on this processor: one kernel only");
            return;
        }
        let rest = jittered_block();
        let nbr = build(&rest, SupportRadius::Automatic { target: 13 }).unwrap();
        let n = rest.len();
        let volume: Vec<Real> = (0..n).map(|i| 1.0 + 0.01 * i as Real).collect();
        let model = ElasticModel::new(1000.0, 0.3, 0.5, 0.0);
        let x = deformed(&rest);
        let input = ForceInputs {
            nbr: &nbr,
            volume: &volume,
            x: &x,
            active_before: &[],
        };
        let pass = ParticlePass {
            model: &model,
            input: &input,
            rotation_iterations: 50,
        };
        let run = |kernel: Kernel, threads: usize| {
            let mut rotation = vec![Quat::identity(); n];
            let mut pair_force = vec![Vec3::zeros(); nbr.slot_count()];
            let mut own = vec![Vec3::zeros(); n];
            let mut force = vec![Vec3::zeros(); n];
            let pool = Pool::new(threads);
            accumulate_forces_in(
                kernel,
                &pass,
                &mut rotation,
                &mut pair_force,
                &mut own,
                &mut force,
                &pool,
            );
            (force, rotation)
        };
        let (force, rotation) = run(Kernel::Build, 1);
        assert!(force.iter().any(|f| f.norm() > 0.0));
        for threads in [1, 3] {
            assert_eq!(
                run(Kernel::Avx512, threads),
                (force.clone(), rotation.clone())
            );
        }
    }
}
