//! Corotated linear tetrahedra: the elasticity of the mesh's own elements, the alternative to
//! the paper's point-based particles ([`crate::ElasticScheme`]).
//!
//! Per tetrahedron with corners `x_0..x_3` (m), rest volume `V` (m³) and the gradients
//! `b_0..b_3` (1/m) of its linear shape functions at rest (`b_1, b_2, b_3` the rows of
//! `D_m⁻¹`, `D_m = [X_1 - X_0, X_2 - X_0, X_3 - X_0]`, and `b_0 = -(b_1 + b_2 + b_3)`):
//! 1. `F = Σ_k x_k b_kᵀ = D_s D_m⁻¹` (dimensionless), constant over the tetrahedron;
//! 2. `R`, the proper rotation maximising `tr(RᵀF)`. It needs no state: Newton's iteration for
//!    the polar factor, `X₀ = F`, `X_{k+1} = (X_k + X_k⁻ᵀ)/2`, converges quadratically from `F`
//!    itself (two or three iterations for strains of a few percent), each a cofactor matrix and a
//!    determinant. An inverted or nearly flat `F`, where that iteration keeps the wrong sign or
//!    crawls, goes to the inversion-aware extraction of the particles
//!    ([`crate::kernels::rotation`], started from the Gram–Schmidt rotation of `F`'s first two
//!    columns; the chunk takes that path only for the lanes that need it);
//! 3. `P = 2μ (F - R) + λ tr(RᵀF - I) R` (Pa), the same corotated stress as the particles'
//!    (`λ = 0` when the volume constraints carry the volumetric stiffness);
//! 4. the force on corner `k` is `-V P b_k` (N): the exact negative gradient of the energy
//!    `V [μ |F - R|² + λ/2 tr(RᵀF - I)²]`, whose four corner forces sum to zero and whose
//!    torque vanishes (`P Fᵀ` is symmetric).
//!
//! Stiffness-proportional damping is not a force here: it filters the velocities after the
//! kick, implicitly ([`crate::kernels::tet_dashpots`]).
//!
//! Unlike the particles' nodal integration, a tetrahedron has no zero-energy mode: no
//! hourglass control is needed (the hourglass setting does not apply).
//!
//! The pass takes the tetrahedra four at a time, one a lane. On one thread each chunk's corner
//! forces go straight to the particles; on several each share of the chunks adds them straight
//! to the particles whose tetrahedra are all in its share and keeps those of the few particles
//! whose tetrahedra span shares, which are summed after a barrier ([`TetShares`]). Every
//! particle's force is so summed in the elements' order: the same bits on any number of threads.

use crate::kernels::lanes::{F4, LANES, M4, V4};
use crate::kernels::math::{tet_volume, Mat3, Quat, Real, Vec3};
use crate::kernels::parallel::{share_of, Barrier, Pool, SharedSlice};
use crate::kernels::point_elasticity::{corotated_stress, ElasticModel};
use crate::kernels::rotation::{extract_rotations, rotation_from_svd};

/// The force pass reports the tetrahedra whose volume is below this fraction of their rest
/// volume (dimensionless; their `det F`): the list the crush guard of the solver's volume pass
/// checks, five times its floor, so that a tetrahedron it lifted to the floor stays on it.
pub(crate) const COMPRESSED_RATIO: Real = 0.5;

/// Most iterations of the polar Newton iteration (dimensionless). Each squares the distance of
/// the singular values from 1 (halves it far from 1): a strain of 1% takes three, principal
/// stretches of 0.3 or 3 five, 0.01 nine.
const POLAR_ITERATIONS: u32 = 10;

/// Newton iterations of [`rotation_by_quaternion_newton`] before the exact SVD fallback.
const ROTATION_ITERATIONS: u32 = 8;

/// A polar Newton step shorter than this (dimensionless, Frobenius) ends the iteration: the
/// convergence is quadratic, so the error left is about half its square (5e-11), below the
/// particles' [`crate::kernels::rotation::ROTATION_TOLERANCE`] of 1e-10.
const POLAR_STEP_TOLERANCE: Real = 1.0e-5;

/// `det F` at or below this fraction of `|F|³` (Frobenius; dimensionless) is inverted or nearly
/// flat: the polar iteration, which keeps the sign of the determinant and needs many steps for
/// tiny singular values, hands such a tetrahedron to the inversion-aware extraction (`|F|³` is
/// `3√3` at rest).
const POLAR_MIN_DETERMINANT: Real = 1.0e-3;

/// The rest data of a body's tetrahedra as elements, built from the model's tetrahedra (and
/// rebuilt with them by a cut). Laid out four tetrahedra a chunk, one a lane, as the force
/// pass reads them; the last chunk repeats its last tetrahedron in its unused lanes.
///
/// The elements are stored in the order of their lowest corner (the particles are in Morton
/// order, so this is a spatial order), not in the mesh's: consecutive chunks touch nearby
/// particles (cache locality), and the contiguous shares of the chunks on several threads
/// meet at few particles (on liver_10k 5% of the particles have tetrahedra in both of two
/// shares, against 90% in TetGen's order; see [`TetShares`]). An element's position in this
/// order is its *slot*; the accessors taking a tetrahedron index `t` (the model's) map it.
#[derive(Debug, Clone, PartialEq, Default)]
pub(crate) struct TetElements {
    /// The number of tetrahedra.
    count: usize,
    chunks: Vec<TetChunk>,
    /// `tet_at[e]`: the model's tetrahedron in slot `e`; `slot_of[t]` its inverse.
    tet_at: Vec<u32>,
    slot_of: Vec<u32>,
    /// `corners[corner_offsets[i]..corner_offsets[i + 1]]`: the corner slots `4 e + c` of the
    /// elements around particle `i` (corner `c` of the element in slot `e` is `i`), in slot
    /// order.
    corner_offsets: Vec<u32>,
    corners: Vec<u32>,
}

/// Four tetrahedra, one a lane.
#[derive(Debug, Clone, PartialEq)]
struct TetChunk {
    /// Corner particles, `tets[l][c]` corner `c` of lane `l`.
    tets: [[u32; 4]; LANES],
    /// `D_m⁻¹` (1/m): its rows are `b_1, b_2, b_3`.
    rest_inverse: M4,
    /// Rest volumes (m³).
    volume: F4,
}

impl TetElements {
    /// The elements of the positively oriented tetrahedra `tets` over `n` particles at rest
    /// positions `rest` (m), with rest volumes `volume` (m³).
    pub(crate) fn new(rest: &[Vec3], tets: &[[u32; 4]], volume: &[Real], n: usize) -> TetElements {
        assert!(volume.len() == tets.len());
        let mut tet_at: Vec<u32> = (0..tets.len() as u32).collect();
        tet_at.sort_by_key(|&t| (tets[t as usize].iter().min().copied(), t));
        let mut slot_of = vec![0u32; tets.len()];
        for (e, &t) in tet_at.iter().enumerate() {
            slot_of[t as usize] = e as u32;
        }
        let sorted: Vec<[u32; 4]> = tet_at.iter().map(|&t| tets[t as usize]).collect();
        let chunks = (0..sorted.len().div_ceil(LANES))
            .map(|c| {
                let e: [usize; LANES] =
                    std::array::from_fn(|l| (LANES * c + l).min(sorted.len() - 1));
                let t = e.map(|e| tet_at[e] as usize);
                TetChunk {
                    tets: t.map(|t| tets[t]),
                    rest_inverse: M4::from_matrices(&t.map(|t| rest_inverse(rest, &tets[t]))),
                    volume: F4::new(t.map(|t| volume[t])),
                }
            })
            .collect();
        let (corner_offsets, corners) = crate::kernels::incidence::corners_around(&sorted, n);
        TetElements {
            count: tets.len(),
            chunks,
            tet_at,
            slot_of,
            corner_offsets,
            corners,
        }
    }

    /// The number of tetrahedra.
    pub(crate) fn len(&self) -> usize {
        self.count
    }

    /// The model's tetrahedron in slot `e` (the order of the chunks).
    pub(crate) fn tet_at(&self, e: usize) -> usize {
        self.tet_at[e] as usize
    }

    /// Tetrahedron `t`'s corners and `D_m⁻¹` (1/m).
    fn element(&self, t: usize) -> ([u32; 4], Mat3) {
        let e = self.slot_of[t] as usize;
        let chunk = &self.chunks[e / LANES];
        (chunk.tets[e % LANES], chunk.rest_inverse.lane(e % LANES))
    }

    /// The corners (particle indices) of tetrahedron `t`.
    pub(crate) fn corners(&self, t: usize) -> [u32; 4] {
        self.element(t).0
    }

    /// The rest volume (m³) of tetrahedron `t`.
    pub(crate) fn volume(&self, t: usize) -> Real {
        let e = self.slot_of[t] as usize;
        self.chunks[e / LANES].volume.to_array()[e % LANES]
    }

    /// The shape-function gradients `b_0..b_3` (1/m) of tetrahedron `t`.
    pub(crate) fn gradients(&self, t: usize) -> [Vec3; 4] {
        let d = self.element(t).1;
        let [b1, b2, b3] = [0, 1, 2].map(|r| d.row(r).transpose());
        [-(b1 + b2 + b3), b1, b2, b3]
    }

    /// The number of chunks of four tetrahedra (the last one padded).
    pub(crate) fn chunk_count(&self) -> usize {
        self.chunks.len()
    }

    /// The model's tetrahedra that the force pass's `compressed` bits (one byte a chunk, the
    /// first [`TetElements::chunk_count`] read) list, in the order of the chunks.
    pub(crate) fn compressed<'a>(
        &'a self,
        compressed: &'a [u8],
    ) -> impl Iterator<Item = usize> + 'a {
        let chunks = compressed[..self.chunk_count()].iter().enumerate();
        chunks.flat_map(move |(c, &bits)| {
            let lanes = (0..LANES).filter(move |l| bits & 1 << l != 0);
            lanes.map(move |l| self.tet_at(LANES * c + l))
        })
    }

    /// The longest rest edge (m) of the tetrahedra with corner `i` that are below `ratio`
    /// (dimensionless) of their rest volume at positions `x` (m), or will be after `time` (s) at
    /// velocities `v` (m/s); `None` when none is. `rest` holds the rest positions (m).
    pub(crate) fn compressed_around(
        &self,
        i: usize,
        (x, v): (&[Vec3], &[Vec3]),
        time: Real,
        ratio: Real,
        rest: &[Vec3],
    ) -> Option<Real> {
        let (start, end) = (self.corner_offsets[i], self.corner_offsets[i + 1]);
        let compressed = self.corners[start as usize..end as usize]
            .iter()
            .filter_map(|&slot| {
                let e = slot as usize / 4;
                let chunk = &self.chunks[e / LANES];
                let corners = chunk.tets[e % LANES].map(|k| k as usize);
                let floor = ratio * chunk.volume.to_array()[e % LANES];
                let below = |[a, b, c, d]: [Vec3; 4]| tet_volume(&a, &b, &c, &d) < floor;
                (below(corners.map(|k| x[k])) || below(corners.map(|k| x[k] + v[k] * time)))
                    .then_some(corners)
            });
        compressed
            .map(|corners| {
                let edge = |(a, b): (usize, usize)| (rest[corners[a]] - rest[corners[b]]).norm();
                [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)]
                    .map(edge)
                    .into_iter()
                    .fold(0.0, Real::max)
            })
            .reduce(Real::max)
    }

    /// The deformation gradient (dimensionless) of tetrahedron `t` at positions `x` (m).
    pub(crate) fn deformation_gradient(&self, t: usize, x: &[Vec3]) -> Mat3 {
        let (tet, dinv) = self.element(t);
        let [x0, x1, x2, x3] = tet.map(|k| x[k as usize]);
        Mat3::from_columns(&[x1 - x0, x2 - x0, x3 - x0]) * dinv
    }

    /// Heap memory (bytes).
    pub(crate) fn heap_bytes(&self) -> usize {
        size_of_val(self.chunks.as_slice())
            + size_of_val(self.tet_at.as_slice())
            + size_of_val(self.slot_of.as_slice())
            + size_of_val(self.corner_offsets.as_slice())
            + size_of_val(self.corners.as_slice())
    }
}

/// `D_m⁻¹` (1/m) of tetrahedron `tet` at rest positions `rest` (m); zero if it is degenerate
/// (a model's tetrahedra are not).
fn rest_inverse(rest: &[Vec3], tet: &[u32; 4]) -> Mat3 {
    let [x0, x1, x2, x3] = tet.map(|k| rest[k as usize]);
    let dm = Mat3::from_columns(&[x1 - x0, x2 - x0, x3 - x0]);
    dm.try_inverse().unwrap_or_else(Mat3::zeros)
}

/// What the tetrahedron force pass reads.
pub(crate) struct TetForceInputs<'a> {
    pub(crate) elements: &'a TetElements,
    /// Current positions (m).
    pub(crate) x: &'a [Vec3],
    /// The fixed flags, or empty. A chunk of tetrahedra all of whose corners are fixed acts
    /// only on fixed particles, whose forces a step does not use: the pass skips it, which
    /// leaves the forces on fixed particles incomplete.
    pub(crate) fixed: &'a [bool],
}

/// Where the corner forces of the force pass go on several threads, for one body's tetrahedra and
/// one thread count: the shares take the chunks of tetrahedra in [`Pool::share`]'s contiguous
/// ranges. A particle all of whose tetrahedra fall in one share's range gets its corner forces
/// added straight away by that share, in slot order; a particle whose tetrahedra span shares
/// (those near a range's end) gets them kept, in slot order, and summed after the barrier.
/// Either way a particle's force is summed in slot order, as on one thread.
#[derive(Debug, Clone, PartialEq, Default)]
pub(crate) struct TetShares {
    /// The thread count and the number of tetrahedra it was made for (0 threads: not made).
    threads: usize,
    count: usize,
    /// Per corner slot `4 e + c` (corner `c` of the element in slot `e`): [`TetShares::DIRECT`], or the
    /// index of its kept force.
    target: Vec<u32>,
    /// The particles whose tetrahedra span shares, in increasing order, and the ranges
    /// `kept_offsets[b]..kept_offsets[b + 1]` of their kept forces (in slot order).
    spanning: Vec<u32>,
    kept_offsets: Vec<u32>,
    /// The kept corner forces (N).
    kept: Vec<Vec3>,
}

impl TetShares {
    /// A corner force added straight to its particle.
    const DIRECT: u32 = u32::MAX;

    /// Make the layout for `elements` on `threads` threads (nothing on one thread). Reuses its
    /// memory: allocates only when `elements` has more corners or spanning particles than any
    /// layout before.
    pub(crate) fn fit(&mut self, elements: &TetElements, threads: usize) {
        self.threads = if threads > 1 { threads } else { 0 };
        self.count = elements.count;
        self.target.clear();
        self.spanning.clear();
        self.kept_offsets.clear();
        if threads == 1 {
            return;
        }
        let chunks = elements.chunks.len();
        let share_of = |slot: u32| {
            let chunk = slot as usize / 4 / LANES;
            (0..threads)
                .find(|&s| share_of(threads, s, chunks).contains(&chunk))
                .unwrap_or(0)
        };
        self.target.resize(4 * elements.count, TetShares::DIRECT);
        self.kept_offsets.push(0);
        let mut kept = 0u32;
        for (i, range) in elements.corner_offsets.windows(2).enumerate() {
            let slots = &elements.corners[range[0] as usize..range[1] as usize];
            let Some(&first) = slots.first() else {
                continue;
            };
            let share = share_of(first);
            if slots.iter().all(|&slot| share_of(slot) == share) {
                continue;
            }
            self.spanning.push(i as u32);
            for &slot in slots {
                self.target[slot as usize] = kept;
                kept += 1;
            }
            self.kept_offsets.push(kept);
        }
        self.kept.resize(kept as usize, Vec3::zeros());
    }

    /// [`TetShares::fit`] for `elements` (after a cut) on the thread count it was made for.
    pub(crate) fn refit(&mut self, elements: &TetElements) {
        self.fit(elements, self.threads.max(1));
    }
}

/// Add every tetrahedron's elastic forces (N) to `force`, one per particle.
/// `shares` says where each corner force goes on several threads ([`TetShares::fit`] for these
/// elements and this pool; unused on one thread): nothing is allocated. Unless `compressed` is empty (one entry per
/// chunk of four tetrahedra, [`TetElements::chunk_count`]), bit `l` of chunk `c`'s entry is set
/// where the element in slot `4 c + l` ([`TetElements::tet_at`]) is below [`COMPRESSED_RATIO`]
/// of its rest volume at `x`, from
/// the pass's own `det F` (a chunk whose corners are all fixed reads 0).
///
/// On one thread each chunk's corner forces go straight to the particles, chunk after chunk;
/// on several, each share of the chunks adds its particles' forces straight away where the
/// particle's tetrahedra are all its own, and keeps the others' (see [`TetShares`]), summed
/// after a barrier in slot order. A particle's force is so summed in slot order either way: the
/// same bits on any number of threads.
pub(crate) fn accumulate_forces(
    model: &ElasticModel,
    input: &TetForceInputs<'_>,
    shares: &mut TetShares,
    compressed: &mut [u8],
    force: &mut [Vec3],
    pool: &Pool,
) {
    let elements = input.elements;
    let (m, n) = (elements.count, force.len());
    assert!(elements.corner_offsets.len() == n + 1 && input.x.len() == n);
    assert!(input.fixed.is_empty() || input.fixed.len() == n);
    let report = !compressed.is_empty();
    assert!(!report || compressed.len() >= elements.chunks.len());
    // The chunk's bits of the tetrahedra (not its padding) below the floor.
    let compressed_bits = |c: usize, ratio: F4| {
        let below = ratio.lt(F4::splat(COMPRESSED_RATIO));
        (0..LANES.min(m - LANES * c))
            .filter(|&l| below.lane(l))
            .fold(0u8, |bits, l| bits | 1 << l)
    };
    let chunks = &elements.chunks;
    let inert = |chunk: &TetChunk| {
        !input.fixed.is_empty()
            && chunk
                .tets
                .iter()
                .flatten()
                .all(|&k| input.fixed[k as usize])
    };
    if pool.threads() == 1 {
        for (c, chunk) in chunks.iter().enumerate() {
            if inert(chunk) {
                if report {
                    compressed[c] = 0;
                }
                continue;
            }
            let (corners, ratio) = chunk_forces(model, input, chunk);
            if report {
                compressed[c] = compressed_bits(c, ratio);
            }
            for (l, tet) in chunk.tets.iter().enumerate().take(m - LANES * c) {
                for (corner, &k) in corners.iter().zip(tet) {
                    force[k as usize] += corner[l];
                }
            }
        }
        return;
    }
    assert!(
        shares.threads == pool.threads() && shares.count == m,
        "the shares are made for this thread count and these tetrahedra (TetShares::fit)"
    );
    let TetShares {
        target,
        spanning,
        kept_offsets,
        kept,
        ..
    } = shares;
    let kept = SharedSlice::new(kept);
    let compressed = SharedSlice::new(compressed);
    let forces = SharedSlice::new(force);
    let barrier = Barrier::new(pool.threads());
    pool.run(&|share| {
        let _guard = barrier.guard();
        let mine = pool.share(share, chunks.len());
        // SAFETY: the shares' chunks, hence their entries of `compressed`, are disjoint.
        let flags = unsafe { compressed.range(if report { mine.clone() } else { 0..0 }) };
        for (c, chunk) in mine.clone().zip(&chunks[mine.clone()]) {
            if inert(chunk) {
                if report {
                    flags[c - mine.start] = 0;
                }
                continue;
            }
            let (corners, ratio) = chunk_forces(model, input, chunk);
            if report {
                flags[c - mine.start] = compressed_bits(c, ratio);
            }
            for (l, tet) in chunk.tets.iter().enumerate().take(m - LANES * c) {
                let t = LANES * c + l;
                for (k, (corner, &i)) in corners.iter().zip(tet).enumerate() {
                    // SAFETY: a particle with a direct corner has all its tetrahedra in this
                    // share, so no other share writes its force; a kept slot is its corner's
                    // own, written by the share of its tetrahedron only.
                    match target[4 * t + k] {
                        TetShares::DIRECT => *unsafe { forces.element(i as usize) } += corner[l],
                        slot => *unsafe { kept.element(slot as usize) } = corner[l],
                    }
                }
            }
        }
        barrier.wait();
        // SAFETY: every share has written its kept slots (the barrier); from here they are
        // only read, and each share adds to its own spanning particles only.
        let all = unsafe { kept.read(0..kept.len()) };
        for b in pool.share(share, spanning.len()) {
            let f = unsafe { forces.element(spanning[b] as usize) };
            for k in &all[kept_offsets[b] as usize..kept_offsets[b + 1] as usize] {
                *f += *k;
            }
        }
    });
}

/// The corner forces (N) of the four tetrahedra of `chunk`, `[corner][lane]`, and their volume
/// ratios `det F` (dimensionless).
#[inline(always)]
fn chunk_forces(
    model: &ElasticModel,
    input: &TetForceInputs<'_>,
    chunk: &TetChunk,
) -> ([[Vec3; LANES]; 4], F4) {
    let (x, tets, dinv) = (input.x, &chunk.tets, &chunk.rest_inverse);
    // F = Σ_k e_k b_kᵀ over the three edges e_k = x_k - x_0 (k = 1..3).
    let origin = corner_lanes(x, tets, 0);
    let mut f = M4::default();
    for (c, b) in dinv.rows.iter().enumerate() {
        f.add_outer(&(corner_lanes(x, tets, c + 1) - origin), b);
    }
    let (c0, c1, c2) = (f.column(0), f.column(1), f.column(2));
    let det = c0.dot(&c1.cross(&c2));
    let r = rotation(&f, det);
    let p = corotated_stress(&f, &r, model.lambda, model.mu);
    // g_k = V P b_k: the force on corner k is -g_k, on corner 0 the sum.
    let g_of = |k: usize| p.mul(&dinv.rows[k]).scale(chunk.volume);
    let g = [g_of(0), g_of(1), g_of(2)];
    let mut out = [[Vec3::zeros(); LANES]; 4];
    (g[0] + g[1] + g[2]).store(&mut out[0]);
    for (k, g) in g.iter().enumerate() {
        (-*g).store(&mut out[k + 1]);
    }
    (out, det)
}

/// Corner `c` of the four tetrahedra `tets` in `field` (m), one a lane. Written out rather than
/// with `array::map`, which the compiler did not inline here: those calls held 16% of the
/// haptic liver_4k step's profile.
#[inline(always)]
fn corner_lanes(field: &[Vec3], tets: &[[u32; 4]; LANES], c: usize) -> V4 {
    let [t0, t1, t2, t3] = tets;
    let at = |tet: &[u32; 4]| &field[tet[c] as usize];
    V4::from_refs([at(t0), at(t1), at(t2), at(t3)])
}

/// The rotations of the four deformation gradients `f` of determinants `det`, without a warm
/// start (see the module documentation): Newton's iteration for the polar factor, `X₀ = F`,
/// `X_{k+1} = (X_k + X_k⁻ᵀ)/2`, each lane until its step `|X_{k+1} − X_k|` (Frobenius) is below
/// [`POLAR_STEP_TOLERANCE`], then frozen. A lane whose `F` is inverted or nearly flat
/// (`det F ≤` [`POLAR_MIN_DETERMINANT`] `|F|³`), or that has not converged after
/// [`POLAR_ITERATIONS`], takes [`rotation_by_quaternion_newton`]'s rotation instead.
#[inline(always)]
fn rotation(f: &M4, det: F4) -> M4 {
    let columns = |x: &M4| (x.column(0), x.column(1), x.column(2));
    let norm2 = f.inner(f);
    let valid = (F4::splat(POLAR_MIN_DETERMINANT) * norm2 * norm2.sqrt()).lt(det);
    let tolerance2 = F4::splat(POLAR_STEP_TOLERANCE * POLAR_STEP_TOLERANCE);
    let mut x = *f;
    let mut pending = valid;
    for _ in 0..POLAR_ITERATIONS {
        if !pending.any() {
            break;
        }
        let (c0, c1, c2) = columns(&x);
        let (k0, k1, k2) = (c1.cross(&c2), c2.cross(&c0), c0.cross(&c1));
        // X⁻ᵀ = [c1×c2, c2×c0, c0×c1] / det X, by columns.
        let half_inverse = F4::splat(0.5) / c0.dot(&k0);
        let next = x
            .scale(F4::splat(0.5))
            .add(&M4::from_columns(&k0, &k1, &k2).scale(half_inverse));
        let change = next.add(&x.scale(F4::splat(-1.0)));
        x = M4::select(pending, &next, &x);
        pending = pending & !change.inner(&change).lt(tolerance2);
    }
    let inverted = !valid | pending;
    if inverted.any() {
        x = M4::select(inverted, &rotation_by_quaternion_newton(f), &x);
    }
    x
}

/// The rotations of the four deformation gradients `f` by the inversion-aware extraction of
/// [`crate::kernels::rotation`]: Newton from the identity on `QᵀF`, `Q` the Gram–Schmidt
/// rotation of `F`'s first two columns (the identity where they are degenerate), the exact SVD
/// where that does not converge. For an inverted tetrahedron `Q` keeps the orientation of the
/// face of corners 0, 1, 2 and finds the fourth corner on the wrong side of it: a mirrored
/// tetrahedron, whose singular values are all 1 and leave the SVD's choice arbitrary, is pushed
/// back through that face.
#[cold]
#[inline(never)]
fn rotation_by_quaternion_newton(f: &M4) -> M4 {
    let (c0, c1) = (f.column(0), f.column(1));
    let tiny = F4::splat(1.0e-24) * f.inner(f);
    let n0 = c0.dot(&c0);
    let q0 = c0.scale(F4::splat(1.0) / n0.max(F4::splat(1.0e-300)).sqrt());
    let u1 = q0.scale_sub_from(q0.dot(&c1), &c1);
    let n1 = u1.dot(&u1);
    let q1 = u1.scale(F4::splat(1.0) / n1.max(F4::splat(1.0e-300)).sqrt());
    let q = M4::from_columns(&q0, &q1, &q0.cross(&q1));
    let degenerate = n0.le(tiny) | n1.le(tiny);
    let q = M4::select(degenerate, &M4::splat(&Mat3::identity()), &q);
    let mut start = [Quat::identity(); LANES];
    let r_t = extract_rotations(&q.transpose().mul_mat(f), &mut start, ROTATION_ITERATIONS);
    q.mul_mat(&r_t)
}

/// The elastic energy (J) of the tetrahedra at positions `x` (m), whose negative gradient
/// [`accumulate_forces`] computes (without damping):
/// `Σ_t V_t [μ |F_t - R_t|² + λ/2 tr(R_tᵀF_t - I)²]`.
pub(crate) fn energy(model: &ElasticModel, elements: &TetElements, x: &[Vec3]) -> Real {
    (0..elements.len())
        .map(|t| {
            let f = elements.deformation_gradient(t, x);
            let r = rotation_from_svd(&f).to_rotation_matrix().into_inner();
            let tr = (r.transpose() * f).trace() - 3.0;
            elements.volume(t) * (model.mu * (f - r).norm_squared() + 0.5 * model.lambda * tr * tr)
        })
        .sum()
}

/// An estimate (N/m) of each particle's diagonal stiffness at rest, added to `k`: per
/// tetrahedron around it `V (λ + 2μ) |b_k|²`, the largest eigenvalue of its diagonal block.
pub(crate) fn add_diagonal_stiffness(model: &ElasticModel, elements: &TetElements, k: &mut [Real]) {
    for t in 0..elements.len() {
        let v = elements.volume(t);
        for (&i, b) in elements.corners(t).iter().zip(elements.gradients(t)) {
            k[i as usize] += v * model.p_wave_modulus() * b.norm_squared();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 2×2×1-cell lattice box (a few dozen tetrahedra, so several chunks and a short last
    /// one), jittered so that no two tetrahedra are alike.
    fn mesh() -> (Vec<Vec3>, Vec<[u32; 4]>) {
        let m = crate::mesh::lattice_box(Vec3::zeros(), Vec3::new(2.0, 2.0, 1.0), [2, 2, 1]);
        let x = (m.nodes.iter().enumerate())
            .map(|(i, p)| p + 0.05 * Vec3::new((i as Real).sin(), (2.0 * i as Real).cos(), 0.0))
            .collect();
        let mut tets = m.tets;
        tets.pop(); // a short last chunk
        assert!(tets.len() > 2 * LANES && !tets.len().is_multiple_of(LANES));
        (x, tets)
    }

    fn volumes(x: &[Vec3], tets: &[[u32; 4]]) -> Vec<Real> {
        tets.iter()
            .map(|t| {
                let [a, b, c, d] = t.map(|k| x[k as usize]);
                crate::kernels::math::tet_volume(&a, &b, &c, &d)
            })
            .collect()
    }

    fn forces(
        model: &ElasticModel,
        rest: &[Vec3],
        tets: &[[u32; 4]],
        x: &[Vec3],
        threads: usize,
    ) -> Vec<Vec3> {
        let elements = TetElements::new(rest, tets, &volumes(rest, tets), rest.len());
        let input = TetForceInputs {
            elements: &elements,
            x,
            fixed: &[],
        };
        let mut shares = TetShares::default();
        shares.fit(&elements, threads);
        if threads > 1 {
            // Both ways of summing are exercised: particles of one share, and spanning ones.
            let direct = shares.target.contains(&TetShares::DIRECT);
            assert!(direct && !shares.spanning.is_empty());
        }
        let mut force = vec![Vec3::zeros(); x.len()];
        let mut compressed = vec![0xff; elements.chunk_count()];
        let pool = Pool::new(threads);
        accumulate_forces(
            model,
            &input,
            &mut shares,
            &mut compressed,
            &mut force,
            &pool,
        );
        // The reported tetrahedra are exactly those below the floor.
        let current = volumes(x, tets);
        let expected = current
            .iter()
            .zip(elements.chunks.iter().flat_map(|c| c.volume.to_array()))
            .map(|(v, v0)| v / v0 < COMPRESSED_RATIO);
        for (t, below) in expected.enumerate() {
            assert_eq!(
                compressed[t / LANES] & 1 << (t % LANES) != 0,
                below,
                "tetrahedron {t}"
            );
        }
        force
    }

    /// A large rotation and stretch of the mesh.
    fn deformed(rest: &[Vec3]) -> Vec<Vec3> {
        let rot = Quat::from_scaled_axis(Vec3::new(1.1, -0.6, 2.0));
        rest.iter()
            .map(|p| rot * Vec3::new(1.3 * p.x + 0.2 * p.y, 0.8 * p.y + 0.1 * p.z * p.z, p.z))
            .collect()
    }

    /// The polar iteration gives the rotation the SVD gives (the proper rotation maximising
    /// `tr(RᵀF)`) for small strains, large stretches and compressions and nearly flat gradients
    /// (handed over), in mixed chunks; for inverted ones (handed over) a proper rotation with
    /// `RᵀF` symmetric, so that the corner forces have no torque.
    #[test]
    fn the_rotation_is_the_svds_in_every_regime() {
        let turn = |axis: Vec3, angle: Real| {
            nalgebra::Rotation3::from_axis_angle(&nalgebra::Unit::new_normalize(axis), angle)
                .into_inner()
        };
        let stretch = |a: Real, b: Real, c: Real| Mat3::from_diagonal(&Vec3::new(a, b, c));
        let shear = Mat3::new(1.0, 0.3, -0.2, 0.05, 1.0, 0.4, 0.0, -0.1, 1.0);
        let gradients = [
            turn(Vec3::new(1.0, 2.0, 3.0), 0.7) * (Mat3::identity() + 1e-3 * shear),
            turn(Vec3::new(-1.0, 0.5, 0.2), 2.9) * stretch(0.3, 1.0, 3.0),
            turn(Vec3::new(0.0, 1.0, 1.0), 1.2) * shear * stretch(0.02, 1.5, 1.0),
            turn(Vec3::new(0.3, -1.0, 0.4), 0.4) * stretch(1e-4, 1.0, 1.0),
            turn(Vec3::new(2.0, 1.0, 0.0), 1.0) * stretch(-0.2, 1.1, 0.9),
            turn(Vec3::new(1.0, 0.0, 0.0), 3.1) * shear * stretch(1.0, -1.0, 1.0),
            Mat3::identity(),
            shear,
        ];
        for chunk in gradients.chunks(LANES) {
            let f = M4::from_matrices(&std::array::from_fn(|l| chunk[l]));
            let det = F4::new(std::array::from_fn(|l| chunk[l].determinant()));
            let r = rotation(&f, det);
            for (l, f) in chunk.iter().enumerate() {
                let got = r.lane(l);
                if f.determinant() < 0.0 {
                    let asymmetry = got.transpose() * f - f.transpose() * got;
                    assert!((got.transpose() * got - Mat3::identity()).norm() < 1e-12);
                    assert!((got.determinant() - 1.0).abs() < 1e-12 && asymmetry.norm() < 1e-9);
                    continue;
                }
                let expected = rotation_from_svd(f).to_rotation_matrix().into_inner();
                assert!(
                    (got - expected).norm() < 1e-9,
                    "F = {f}: rotation {got}, the SVD's {expected}"
                );
            }
        }
    }

    #[test]
    fn the_forces_are_the_negative_gradient_of_the_energy() {
        let (rest, tets) = mesh();
        let model = ElasticModel::new(3000.0, 0.4, 0.0, 0.0);
        let x = deformed(&rest);
        let f = forces(&model, &rest, &tets, &x, 1);
        let elements = TetElements::new(&rest, &tets, &volumes(&rest, &tets), rest.len());
        let energy_at = |x: &[Vec3]| energy(&model, &elements, x);
        let h = 1e-6;
        for i in 0..x.len() {
            for a in 0..3 {
                let (mut xp, mut xm) = (x.clone(), x.clone());
                xp[i][a] += h;
                xm[i][a] -= h;
                let fd = -(energy_at(&xp) - energy_at(&xm)) / (2.0 * h);
                assert!(
                    (fd - f[i][a]).abs() < 1e-6 * 3000.0,
                    "particle {i} axis {a}: {fd} against {}",
                    f[i][a]
                );
            }
        }
    }

    #[test]
    fn rigid_motion_gives_no_force() {
        let (rest, tets) = mesh();
        let model = ElasticModel::new(3000.0, 0.45, 0.0, 0.0);
        let rot = Quat::from_scaled_axis(Vec3::new(0.4, 2.9, -1.0));
        let x: Vec<Vec3> = rest
            .iter()
            .map(|p| rot * p + Vec3::new(0.3, -2.0, 5.0))
            .collect();
        for threads in [1, 2] {
            let f = forces(&model, &rest, &tets, &x, threads);
            for f in &f {
                assert!(f.norm() < 1e-10, "{f}");
            }
        }
    }

    #[test]
    fn forces_balance_and_do_not_depend_on_the_thread_count() {
        let (rest, tets) = mesh();
        let model = ElasticModel::new(3000.0, 0.3, 0.0, 0.0);
        let x = deformed(&rest);
        let one = forces(&model, &rest, &tets, &x, 1);
        let sum: Vec3 = one.iter().sum();
        let scale: Real = one.iter().map(|f| f.norm()).sum();
        assert!(scale > 1.0 && sum.norm() < 1e-12 * scale, "{sum}");
        let torque_elastic = one
            .iter()
            .zip(&x)
            .fold(Vec3::zeros(), |t, (f, p)| t + p.cross(f));
        assert!(torque_elastic.norm() < 1e-10 * scale, "{torque_elastic}");
        for threads in [2, 3] {
            let many = forces(&model, &rest, &tets, &x, threads);
            assert!(one
                .iter()
                .zip(&many)
                .all(|(a, b)| a.map(Real::to_bits) == b.map(Real::to_bits)));
        }
    }

    #[test]
    fn an_inverted_tetrahedron_pushes_back_towards_its_rest_shape() {
        let (rest, tets) = mesh();
        let tet = [tets[0]];
        let model = ElasticModel::new(3000.0, 0.3, 0.0, 0.0);
        // Corner 3 reflected through the plane of the other three: the tetrahedron inverted.
        let [a, b, c, d] = tet[0].map(|k| rest[k as usize]);
        let n = (b - a).cross(&(c - a)).normalize();
        let mut x = rest.clone();
        let k = tet[0][3] as usize;
        x[k] = d - n * (2.0 * n.dot(&(d - a)));
        let f = forces(&model, &rest, &tet, &x, 1);
        assert!(
            crate::kernels::math::tet_volume(
                &x[tet[0][0] as usize],
                &x[tet[0][1] as usize],
                &x[tet[0][2] as usize],
                &x[k]
            ) < 0.0,
            "inverted, so reported as compressed (checked in `forces`)"
        );
        // Back through the plane, towards the side corner 3 came from.
        assert!(f[k].dot(&n) * n.dot(&(d - a)) > 0.0, "{}", f[k]);
    }
}
