//! Static equilibrium of a body: the stiffness of its discrete energy at rest, assembled as a
//! sparse matrix and factorised once (sparse Cholesky, faer), used for
//!
//! - the linear (small-strain) static response `K u = f` that the validation compares with FEM;
//! - [`World::settle`](crate::World::settle): the nonlinear equilibrium under gravity, so a
//!   scene can start at rest instead of swinging into place. Newton–Krylov: each direction
//!   solves the tangent system (Hessian products by central differences of the exact forces)
//!   by conjugate gradients preconditioned with the factorised corotated (warped) stiffness;
//!   a backtracking line search on the energy (Armijo) or the residual; and load continuation
//!   (gravity in adaptive fractions) when the full load is out of the Newton basin. Solved to
//!   a relative residual of [`SETTLE_TOLERANCE`] in 7–23 iterations and 3–7 s on the default
//!   organ and liver_4k at ν 0.45 and 0.49.
//!
//! The energy is the one the step integrates: the point-based corotated elasticity
//! `Σ_i v_i Ψ(F_i)`, the hourglass term, and — when the volume constraints carry the
//! volumetric stiffness — each constraint's `(V − V₀)² / (2 α V₀)` (a tetrahedron's or a
//! particle's dual cell's volume) with `α` the constraints' compliance per unit volume (1/Pa). Tools and organ–organ contacts are not part of it.
//!
//! The schemes and the volume-constraint flag are those the body's elastic constants were
//! derived under (`Derived::from`, the world's settings): the public functions here are given
//! only a body, and the stiffness must be that of the constants it holds.

use crate::error::Error;
use crate::kernels::math::{tet_volume, tet_volume_gradient, Mat3, Real, Vec3};
use crate::kernels::point_elasticity::ElasticModel;
use crate::model::dual_cells::CellSlot;
use crate::scene::body::Body;
use crate::scene::settings::{ElasticScheme, VolumeScheme};
use faer::linalg::solvers::Solve;
use faer::sparse::{SparseColMat, Triplet};
use faer::{Mat, Side};

/// A symmetric 3×3-block sparse matrix in block-row (CSR) form, one block row per particle.
pub(crate) struct BlockMatrix {
    offsets: Vec<usize>,
    columns: Vec<u32>,
    blocks: Vec<Mat3>,
}

impl BlockMatrix {
    /// The pattern holding every block `(k, l)` with `k` and `l` in a common stencil.
    fn from_stencils<'a>(n: usize, stencils: impl Iterator<Item = &'a [u32]> + Clone) -> Self {
        let mut rows: Vec<Vec<u32>> = vec![Vec::new(); n];
        for s in stencils {
            for &k in s {
                rows[k as usize].extend_from_slice(s);
            }
        }
        let mut offsets = Vec::with_capacity(n + 1);
        let mut columns = Vec::new();
        offsets.push(0);
        for mut r in rows {
            r.sort_unstable();
            r.dedup();
            columns.extend_from_slice(&r);
            offsets.push(columns.len());
        }
        let blocks = vec![Mat3::zeros(); columns.len()];
        BlockMatrix {
            offsets,
            columns,
            blocks,
        }
    }

    fn add(&mut self, row: u32, column: u32, block: &Mat3) {
        let r = row as usize;
        let cols = &self.columns[self.offsets[r]..self.offsets[r + 1]];
        let k = cols
            .binary_search(&column)
            .expect("block inside the assembled pattern");
        self.blocks[self.offsets[r] + k] += block;
    }

    /// `y = K x` (N for x in m).
    pub(crate) fn mul(&self, x: &[Vec3], y: &mut [Vec3]) {
        for (r, yr) in y.iter_mut().enumerate() {
            let mut s = Vec3::zeros();
            for e in self.offsets[r]..self.offsets[r + 1] {
                s += self.blocks[e] * x[self.columns[e] as usize];
            }
            *yr = s;
        }
    }
}

/// The stiffness (N/m) of `body`'s discrete energy at its rest positions (`at = None`), or
/// its corotated approximation at positions `at` (m): each particle's elastic and hourglass
/// blocks rotated by the particle's rotation `R_i` (`R_i K_i R_iᵀ`, stiffness warping) and
/// the volume terms taken with the current tetrahedron gradients (Gauss–Newton).
pub(crate) fn stiffness(body: &Body, at: Option<&[Vec3]>) -> BlockMatrix {
    let nbr = &body.model.nbr;
    let n = body.particle_count();
    let tetrahedra = body.derived.from.elastic.elastic_scheme == ElasticScheme::Tetrahedra;
    // Stencil of particle i: itself, then its neighbours; or of a tetrahedron, its corners.
    let stencils: Vec<Vec<u32>> = if tetrahedra {
        body.model.tets.iter().map(|t| t.to_vec()).collect()
    } else {
        (0..n)
            .map(|i| {
                let mut s = vec![i as u32];
                s.extend_from_slice(&nbr.index[nbr.range(i)]);
                s
            })
            .collect()
    };
    let volume_stiffness = volume_stiffness_per_unit_volume(body);
    // Each volume term's particles, and the term's gradients at `at` (Gauss–Newton).
    let mut volume_terms: Vec<(Real, Vec<(u32, Vec3)>)> = Vec::new();
    if volume_stiffness > 0.0 {
        for_each_volume_term(body, at.unwrap_or(&body.model.rest), |v0, _, g| {
            volume_terms.push((v0, g.to_vec()))
        });
    }
    let volume_stencils: Vec<Vec<u32>> = volume_terms
        .iter()
        .map(|(_, g)| g.iter().map(|(k, _)| *k).collect())
        .collect();
    let mut k = BlockMatrix::from_stencils(
        n,
        stencils
            .iter()
            .map(Vec::as_slice)
            .chain(volume_stencils.iter().map(Vec::as_slice)),
    );
    let ElasticModel {
        lambda,
        mu,
        hourglass,
        ..
    } = body.derived.elastic;
    // The rotation of an element (a particle or a tetrahedron) at `at`, from its deformation
    // gradient there.
    let polar = |f: Mat3| {
        crate::kernels::rotation::rotation_from_svd(&f)
            .to_rotation_matrix()
            .into_inner()
    };
    // Linear elasticity of an element of volume `v` whose displacement gradient is
    // `Σ_k u_k c_kᵀ` over its stencil, warped by its rotation `r`:
    // K_kl = v r [μ (c_k·c_l) I + μ c_l c_kᵀ + λ c_k c_lᵀ] rᵀ.
    let add_element = |k: &mut BlockMatrix, stencil: &[u32], c: &[Vec3], r: Mat3, v: Real| {
        let rt = r.transpose();
        for (p, ck) in c.iter().enumerate() {
            for (q, cl) in c.iter().enumerate() {
                let block = Mat3::identity() * (mu * ck.dot(cl))
                    + cl * ck.transpose() * mu
                    + ck * cl.transpose() * lambda;
                k.add(stencil[p], stencil[q], &(r * block * rt * v));
            }
        }
    };
    if tetrahedra {
        let elements = &body.model.tet_elements;
        for (t, tet) in body.model.tets.iter().enumerate() {
            let r = at.map_or(Mat3::identity(), |x| {
                polar(elements.deformation_gradient(t, x))
            });
            let v = body.model.tet_rest_volume[t];
            add_element(&mut k, tet, &elements.gradients(t), r, v);
        }
    }
    let (mut c, mut a) = (Vec::new(), Vec::new());
    let particles = if tetrahedra { &[][..] } else { &stencils[..] };
    for (i, stencil) in particles.iter().enumerate() {
        let vi = body.model.particle_volume[i];
        let r = at.map_or(Mat3::identity(), |x| {
            polar(crate::kernels::point_elasticity::deformation_gradient(
                nbr, x, i,
            ))
        });
        let range = nbr.range(i);
        // ∇u_i = Σ_k u_k c_kᵀ over the stencil: c_i = −Σ_j g_ij, c_j = g_ij.
        c.clear();
        c.push(-nbr.gradient.iter_range(range.clone()).sum::<Vec3>());
        c.extend(nbr.gradient.iter_range(range.clone()));
        add_element(&mut k, stencil, &c, r, vi);
        // Hourglass: ½ c_ij |ε_ij|², ε_ij = Σ_k a_k x_k with a_k = c_k·u_ij − δ_kj + δ_ki.
        if hourglass != 0.0 {
            for (slot, e) in range.enumerate() {
                let u = nbr.rest_offset.get(e);
                let cij = hourglass * vi * nbr.hourglass_weight[e];
                a.clear();
                a.extend(c.iter().map(|ck| ck.dot(&u)));
                a[0] += 1.0;
                a[slot + 1] -= 1.0;
                for (p, ap) in a.iter().enumerate() {
                    for (q, aq) in a.iter().enumerate() {
                        k.add(
                            stencil[p],
                            stencil[q],
                            &(Mat3::identity() * (cij * ap * aq)),
                        );
                    }
                }
            }
        }
    }
    for (v0, g) in &volume_terms {
        let kt = volume_stiffness / v0;
        for (p, gp) in g {
            for (q, gq) in g {
                k.add(*p, *q, &(gp * gq.transpose() * kt));
            }
        }
    }
    k
}

/// Calls `f(v0, v, gradient)` for each volume constraint of `body` at positions `x` (m): its
/// rest volume (m³), its volume (m³), and the volume's gradient (m²) with respect to each
/// particle it depends on. One term per tetrahedron or per particle's dual cell
/// (`Settings::volume_scheme`); a dual cell emptied by a cut has none.
fn for_each_volume_term(body: &Body, x: &[Vec3], mut f: impl FnMut(Real, Real, &[(u32, Vec3)])) {
    let model = &body.model;
    let mut gradient = Vec::new();
    match body.derived.from.elastic.volume_scheme {
        VolumeScheme::Tetrahedra => {
            for (t, tet) in model.tets.iter().enumerate() {
                gradient.clear();
                let [a, b, c, d] = tet.map(|k| x[k as usize]);
                gradient.extend(tet.iter().copied().zip(tet_volume_gradient(&a, &b, &c, &d)));
                let v = tet_volume(&a, &b, &c, &d);
                f(model.tet_rest_volume[t], v, &gradient);
            }
        }
        VolumeScheme::DualCells => {
            let cells = &model.dual_cells;
            let mut slots = vec![CellSlot::default(); cells.max_star()];
            for c in 0..cells.len() {
                let v = cells
                    .volume_and_gradient(c, |k| (x[k], 0.0), &mut slots)
                    .volume;
                gradient.clear();
                let star = cells.star(c).iter().zip(&slots);
                gradient.extend(star.map(|(&k, s)| (k, s.gradient_24() / 24.0)));
                f(cells.rest_volume(c), v, &gradient);
            }
        }
    }
}

/// Stiffness per unit volume (Pa) of the volume constraints, `1/α`; 0 when they are off or
/// infinitely compliant.
fn volume_stiffness_per_unit_volume(body: &Body) -> Real {
    let alpha = body.derived.volume_compliance;
    if body.derived.from.elastic.volume_constraints && alpha.is_finite() && alpha > 0.0 {
        1.0 / alpha
    } else {
        0.0
    }
}

/// The energy (J) whose negative gradient is [`residual`]: elastic and hourglass, the volume
/// terms, and the weight's potential `−Σ m g·x`, at positions `x` (m).
fn energy(body: &Body, x: &[Vec3], g: Vec3) -> Real {
    let model = &body.model;
    let mut e = match body.derived.from.elastic.elastic_scheme {
        ElasticScheme::PointBased => crate::kernels::point_elasticity::energy(
            &body.derived.elastic,
            &model.nbr,
            &model.particle_volume,
            x,
        ),
        ElasticScheme::Tetrahedra => {
            crate::kernels::tet_elasticity::energy(&body.derived.elastic, &model.tet_elements, x)
        }
    };
    let stiffness = volume_stiffness_per_unit_volume(body);
    if stiffness > 0.0 {
        for_each_volume_term(body, x, |v0, v, _| {
            e += 0.5 * stiffness * (v - v0) * (v - v0) / v0
        });
    }
    for ((x, m), fixed) in x.iter().zip(&model.mass).zip(&body.fixed) {
        if !fixed {
            e -= m * g.dot(x);
        }
    }
    e
}

/// The forces (N) of the volume energy at positions `x` (m), added to `force`.
fn add_volume_forces(body: &Body, x: &[Vec3], force: &mut [Vec3]) {
    let stiffness = volume_stiffness_per_unit_volume(body);
    if stiffness == 0.0 {
        return;
    }
    for_each_volume_term(body, x, |v0, v, gradient| {
        let scale = -stiffness * (v - v0) / v0;
        for (k, g) in gradient {
            force[*k as usize] += g * scale;
        }
    });
}

/// The rest stiffness restricted to the free particles, factorised.
pub(crate) struct FactorisedStiffness {
    /// Free particle → dof block (`u32::MAX` for fixed particles).
    dof: Vec<u32>,
    free: usize,
    llt: faer::sparse::linalg::solvers::Llt<usize, Real>,
    /// The unrestricted matrix, for residual checks.
    pub(crate) matrix: BlockMatrix,
}

impl FactorisedStiffness {
    /// Assemble and factorise `body`'s rest stiffness with its fixed particles removed.
    pub(crate) fn new(body: &Body, at: Option<&[Vec3]>) -> Result<Self, Error> {
        let matrix = stiffness(body, at);
        let n = body.particle_count();
        let mut dof = vec![u32::MAX; n];
        let mut free = 0;
        for (d, fixed) in dof.iter_mut().zip(&body.fixed) {
            if !fixed {
                *d = free as u32;
                free += 1;
            }
        }
        if free == 0 {
            return Err(Error::InvalidArgument(
                "every particle is fixed: nothing to solve".into(),
            ));
        }
        let mut triplets = Vec::new();
        for r in 0..n {
            let dr = dof[r];
            if dr == u32::MAX {
                continue;
            }
            for e in matrix.offsets[r]..matrix.offsets[r + 1] {
                let dc = dof[matrix.columns[e] as usize];
                if dc == u32::MAX || dc > dr {
                    continue;
                }
                let block = &matrix.blocks[e];
                for a in 0..3 {
                    for b in 0..3 {
                        let (row, col) = (3 * dr as usize + a, 3 * dc as usize + b);
                        if col <= row {
                            triplets.push(Triplet::new(row, col, block[(a, b)]));
                        }
                    }
                }
            }
        }
        let m = 3 * free;
        let sparse = SparseColMat::<usize, Real>::try_new_from_triplets(m, m, &triplets)
            .map_err(|e| Error::InvalidArgument(format!("stiffness assembly: {e:?}")))?;
        let llt = sparse.sp_cholesky(Side::Lower).map_err(|_| {
            Error::InvalidArgument(
                "the body's stiffness is singular: fix enough particles to hold it \
                 (a free body has no static equilibrium under gravity)"
                    .into(),
            )
        })?;
        Ok(FactorisedStiffness {
            dof,
            free,
            llt,
            matrix,
        })
    }

    /// Solve `K Δx = r` on the free particles (`r` in N, `Δx` in m; fixed particles get 0).
    pub(crate) fn solve(&self, r: &[Vec3], dx: &mut [Vec3]) {
        let mut rhs = Mat::<Real>::zeros(3 * self.free, 1);
        for (i, d) in self.dof.iter().enumerate() {
            if *d != u32::MAX {
                for a in 0..3 {
                    rhs[(3 * *d as usize + a, 0)] = r[i][a];
                }
            }
        }
        self.llt.solve_in_place(rhs.as_mut());
        for (i, d) in self.dof.iter().enumerate() {
            dx[i] = if *d == u32::MAX {
                Vec3::zeros()
            } else {
                let k = 3 * *d as usize;
                Vec3::new(rhs[(k, 0)], rhs[(k + 1, 0)], rhs[(k + 2, 0)])
            };
        }
    }
}

/// The linear (small-strain) static displacement (m) of `body` from its rest state: the
/// solution of `K u = load` on the free particles, with `u = prescribed` on the fixed ones
/// (`load` in N and `prescribed` in m, one entry per particle; `prescribed` is read only at
/// fixed particles). `K` is the stiffness of the body's discrete energy at rest.
pub fn linear_response(
    body: &Body,
    load: &[Vec3],
    prescribed: &[Vec3],
) -> Result<Vec<Vec3>, Error> {
    let n = body.particle_count();
    if load.len() != n || prescribed.len() != n {
        return Err(Error::InvalidArgument(format!(
            "linear_response: {n} particles, got {} loads and {} prescribed displacements",
            load.len(),
            prescribed.len()
        )));
    }
    let k = FactorisedStiffness::new(body, None)?;
    // Move the prescribed displacements to the right-hand side: f − K u_b.
    let boundary: Vec<Vec3> = (0..n)
        .map(|i| {
            if body.fixed[i] {
                prescribed[i]
            } else {
                Vec3::zeros()
            }
        })
        .collect();
    let mut ku = vec![Vec3::zeros(); n];
    k.matrix.mul(&boundary, &mut ku);
    let rhs: Vec<Vec3> = load.iter().zip(&ku).map(|(f, k)| f - k).collect();
    let mut u = vec![Vec3::zeros(); n];
    k.solve(&rhs, &mut u);
    for i in 0..n {
        if body.fixed[i] {
            u[i] = prescribed[i];
        }
    }
    Ok(u)
}

/// The linear (small-strain) static displacement (m) of `body` under gravity `g` (m/s²), its
/// fixed particles held at rest: `K u = m g`.
pub fn linear_gravity_sag(body: &Body, g: Vec3) -> Result<Vec<Vec3>, Error> {
    let load: Vec<Vec3> = body.model.mass.iter().map(|m| g * *m).collect();
    linear_response(body, &load, &vec![Vec3::zeros(); body.particle_count()])
}

/// Outcome of [`World::settle`](crate::World::settle).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SettleReport {
    /// Newton iterations of the static solve, over all bodies.
    pub newton_iterations: u32,
    /// Largest force residual the static solve left on a body, L2 over its free particles
    /// relative to the L2 of its particle weights (dimensionless).
    pub relative_residual: Real,
    /// Steps of the dynamic relaxation that followed (each `Settings::dt` long; simulated time
    /// is not advanced by `settle`).
    pub relaxation_steps: u32,
    /// Largest particle speed at the end (m/s).
    pub max_speed: Real,
    /// True when the largest particle speed fell below [`SETTLE_SPEED`].
    pub converged: bool,
}

/// Relative force residual at which the static solve stops.
pub const SETTLE_TOLERANCE: Real = 1.0e-7;
/// Largest number of Newton iterations of the static solve, per body.
pub const SETTLE_MAX_ITERATIONS: u32 = 40;
/// Relative residual to which the intermediate loads of the continuation are solved.
const CONTINUATION_TOLERANCE: Real = 1.0e-3;
/// Smallest load increment (fraction of gravity) the continuation tries.
const MIN_LOAD_INCREMENT: Real = 1.0 / 64.0;
/// Particle speed (m/s) below which a settled world counts as at rest.
pub const SETTLE_SPEED: Real = 1.0e-5;
/// Largest number of dynamic-relaxation steps of `settle`.
pub const SETTLE_MAX_STEPS: u32 = 20_000;

/// What the static solve of one body reached.
pub(crate) struct StaticSolve {
    pub(crate) iterations: u32,
    pub(crate) relative_residual: Real,
}

/// The force residual (N) of `body` at positions `x` (m) under gravity `g`: elastic, hourglass
/// and volume forces plus the weight; zero on fixed particles.
fn residual(body: &Body, x: &[Vec3], g: Vec3) -> Vec<Vec3> {
    let mut r = body.elastic_forces_at(x);
    add_volume_forces(body, x, &mut r);
    for (i, ri) in r.iter_mut().enumerate() {
        if body.fixed[i] {
            *ri = Vec3::zeros();
        } else {
            *ri += g * body.model.mass[i];
        }
    }
    r
}

/// L2 norm of `v`.
fn l2(v: &[Vec3]) -> Real {
    v.iter().map(|x| x.norm_squared()).sum::<Real>().sqrt()
}

/// L2 norm (N) of the particles' weights under gravity `g`, the scale of the residual.
fn weight_of(body: &Body, g: Vec3) -> Real {
    body.model
        .mass
        .iter()
        .map(|m| (g * *m).norm_squared())
        .sum::<Real>()
        .sqrt()
        .max(Real::MIN_POSITIVE)
}

/// `a · b` over all particles.
fn dot(a: &[Vec3], b: &[Vec3]) -> Real {
    a.iter().zip(b).map(|(a, b)| a.dot(b)).sum()
}

/// The tangent stiffness (N/m) of `body` at `x` applied to `v` (m): `−∂r/∂x · v` by central
/// differences of the residual (the forces are the exact gradient of the energy, so this is
/// its Hessian times `v`, to ~1e-10 relative with the step below).
fn tangent_times(body: &Body, x: &[Vec3], g: Vec3, v: &[Vec3], size: Real) -> Vec<Vec3> {
    let norm = v.iter().map(|v| v.norm()).fold(0.0, Real::max);
    if norm == 0.0 {
        return vec![Vec3::zeros(); v.len()];
    }
    let eps = 1e-7 * size / norm;
    let shifted = |s: Real| -> Vec<Vec3> { x.iter().zip(v).map(|(x, v)| x + v * s).collect() };
    let plus = residual(body, &shifted(eps), g);
    let minus = residual(body, &shifted(-eps), g);
    plus.iter()
        .zip(&minus)
        .map(|(p, m)| (m - p) / (2.0 * eps))
        .collect()
}

/// A Newton direction `d` (m) for the residual `r` (N) at `x`: the tangent system
/// `K_t d = r` solved by conjugate gradients to a relative tolerance `eta`, preconditioned by
/// the factorised corotated stiffness `k` (SPD). Stops at negative curvature (a buckling
/// region), keeping the last iterate or, at the first, the preconditioned residual. Returns
/// the direction and the iterations taken (all of them at negative curvature).
fn newton_direction(
    body: &Body,
    x: &[Vec3],
    g: Vec3,
    r: &[Vec3],
    k: &FactorisedStiffness,
    eta: Real,
    size: Real,
) -> (Vec<Vec3>, usize) {
    let mut used = 0;
    let n = r.len();
    let mut d = vec![Vec3::zeros(); n];
    let mut res = r.to_vec();
    let mut z = vec![Vec3::zeros(); n];
    k.solve(&res, &mut z);
    let mut p = z.clone();
    let mut rz = dot(&res, &z);
    let target = eta * l2(r);
    for it in 0..NEWTON_CG_ITERATIONS {
        used = it + 1;
        let kp = tangent_times(body, x, g, &p, size);
        let curvature = dot(&p, &kp);
        if curvature <= 0.0 {
            if dot(&d, &d) == 0.0 {
                d = p;
            }
            used = NEWTON_CG_ITERATIONS;
            break;
        }
        let alpha = rz / curvature;
        for i in 0..n {
            d[i] += p[i] * alpha;
            res[i] -= kp[i] * alpha;
        }
        if l2(&res) <= target {
            break;
        }
        k.solve(&res, &mut z);
        let rz_next = dot(&res, &z);
        let beta = rz_next / rz;
        rz = rz_next;
        for i in 0..n {
            p[i] = z[i] + p[i] * beta;
        }
    }
    (d, used)
}

/// Conjugate-gradient iterations per Newton direction, at most.
const NEWTON_CG_ITERATIONS: usize = 100;
/// Conjugate-gradient iterations beyond which the next Newton iteration refactorises its
/// preconditioner.
const REFACTORISE_AFTER: usize = 20;

/// Newton–Krylov iterations toward the equilibrium under gravity `g` from `x`, at most
/// `max_iterations`; returns the relative residual reached (`|r| / |m g|`, L2). Each
/// direction solves the tangent system (central-difference Hessian products) by conjugate
/// gradients preconditioned with the corotated stiffness, factorised at the iterate; a
/// backtracking line search on the residual keeps every accepted iterate better than the last.
fn newton(
    body: &Body,
    x: &mut Vec<Vec3>,
    g: Vec3,
    tolerance: Real,
    max_iterations: u32,
    iterations: &mut u32,
) -> Result<Real, Error> {
    let weight = weight_of(body, g);
    let size = {
        let rest = &body.model.rest;
        let (lo, hi) = rest.iter().fold(
            (
                Vec3::repeat(Real::INFINITY),
                Vec3::repeat(Real::NEG_INFINITY),
            ),
            |(lo, hi), p| (lo.inf(p), hi.sup(p)),
        );
        (hi - lo).norm()
    };
    let mut r = residual(body, x, g);
    let mut res = l2(&r) / weight;
    // The preconditioner, factorised at the first iterate that needs one and again whenever
    // the last solve needed many iterations (factorising costs ~50 tangent products).
    let mut k: Option<FactorisedStiffness> = None;
    let mut cg_used = 0;
    for _ in 0..max_iterations {
        if res <= tolerance {
            break;
        }
        *iterations += 1;
        if k.is_none() || cg_used > REFACTORISE_AFTER {
            k = Some(FactorisedStiffness::new(body, Some(x))?);
        }
        let preconditioner = k.as_ref().expect("factorised above");
        // Inexact Newton: a loose linear solve far from the solution, tighter near it.
        let eta = res.sqrt().clamp(1e-4, 0.1);
        let (dx, used) = newton_direction(body, x, g, &r, preconditioner, eta, size);
        cg_used = used;
        // Backtrack until the energy falls by a fair share of what the slope promises
        // (Armijo), or the residual falls: near the solution the energy's change drowns in
        // its rounding, and the residual decides.
        let e0 = energy(body, x, g);
        let slope = -dot(&r, &dx);
        let mut step = 1.0;
        loop {
            let x_try: Vec<Vec3> = x.iter().zip(&dx).map(|(x, d)| x + d * step).collect();
            let r_try = residual(body, &x_try, g);
            let res_try = l2(&r_try) / weight;
            let descends = energy(body, &x_try, g) <= e0 + 1e-4 * step * slope;
            if res_try.is_finite() && (res_try < res || (slope < 0.0 && descends)) {
                *x = x_try;
                r = r_try;
                res = res_try;
                break;
            }
            step *= 0.5;
            if step < 1.0 / 64.0 {
                return Ok(res);
            }
        }
    }
    Ok(res)
}

/// Move `body`'s free particles toward their static equilibrium under gravity `g` (m/s²),
/// from their current positions, in at most [`SETTLE_MAX_ITERATIONS`] Newton iterations; the
/// result is kept only if it converged (otherwise the positions are left as they were).
/// Velocities are set to zero. Returns the iterations and the residual reached.
pub(crate) fn settle_body(body: &mut Body, g: Vec3) -> Result<StaticSolve, Error> {
    let mut x = body.state.x.clone();
    let mut iterations = 0;
    // Load continuation: gravity applied in fractions `s` of its full value, the increment
    // doubled after a converged solve and halved after a failed one (from the last converged
    // positions). Intermediate loads are solved loosely, the full load to the tolerance.
    let (mut s, mut ds): (Real, Real) = (0.0, 1.0);
    let mut res = Real::INFINITY;
    while s < 1.0 && iterations < SETTLE_MAX_ITERATIONS && ds >= MIN_LOAD_INCREMENT {
        let target = (s + ds).min(1.0);
        let tolerance = if target == 1.0 {
            SETTLE_TOLERANCE
        } else {
            CONTINUATION_TOLERANCE
        };
        let mut trial = x.clone();
        let reached = newton(
            body,
            &mut trial,
            g * target,
            tolerance,
            SETTLE_MAX_ITERATIONS - iterations,
            &mut iterations,
        )?;
        if reached <= tolerance {
            x = trial;
            s = target;
            res = reached;
            ds *= 2.0;
        } else {
            if target == 1.0 {
                res = reached;
            }
            ds *= 0.5;
        }
    }
    if s < 1.0 || res > SETTLE_TOLERANCE {
        // Not converged: an unconverged iterate can hold strongly distorted particles, so
        // keep the starting positions and leave the work to the relaxation.
        x.copy_from_slice(&body.state.x);
        res = l2(&residual(body, &x, g)) / weight_of(body, g);
    }
    body.state.x.copy_from_slice(&x);
    body.state.v.iter_mut().for_each(|v| *v = Vec3::zeros());
    for i in 0..x.len() {
        let f = crate::kernels::point_elasticity::deformation_gradient(&body.model.nbr, &x, i);
        body.state.rotation[i] = crate::kernels::rotation::rotation_from_svd(&f);
    }
    Ok(StaticSolve {
        iterations,
        relative_residual: res,
    })
}
