//! Particle neighbourhoods in CSR form with the rest-state quantities of the moving-least-squares
//! deformation gradient precomputed (eq. 1–2 of the paper).
//!
//! For particle `i` with support radius `h_i`, the neighbours are the particles `j ≠ i` with
//! `|X_j - X_i| < h_i` in the rest state (Lagrangian: fixed for the body's life). With
//! `u_ij = X_j - X_i`, the poly6 kernel `w_ij = (1 - |u_ij|²/h_i²)³` and the moment matrix
//! `A_i = Σ_j w_ij u_ij u_ijᵀ`, the deformation gradient is `F_i = Σ_j x_ij d_ijᵀ` with
//! `d_ij = w_ij A_i⁻¹ u_ij`, stored per pair.

use crate::math::{Mat3, Real, Vec3};
use crate::vec3_array::Vec3Array;

/// Largest accepted condition number of a particle's moment matrix `A_i`; a particle above it
/// gets a larger support radius (more neighbours) at load time.
pub const MAX_MOMENT_CONDITION: Real = 200.0;

/// Largest number of neighbours the automatic support radius may reach for one particle.
pub const MAX_NEIGHBOURS: usize = 96;

/// Largest number of neighbours a fixed support radius may give one particle (the step's time
/// and memory grow with it).
pub const MAX_FIXED_NEIGHBOURS: usize = 4 * MAX_NEIGHBOURS;

/// Neighbour lists of every particle of a body (CSR) and their rest-state quantities.
#[derive(Debug, Clone, PartialEq)]
pub struct Neighbourhoods {
    /// `offsets[i]..offsets[i+1]` is the range of particle `i`'s pairs in the arrays below
    /// (length: particles + 1).
    pub offsets: Vec<u32>,
    /// Neighbour index `j` of each pair.
    pub index: Vec<u32>,
    /// Rest offset `u_ij = X_j - X_i` of each pair (m), by component.
    pub rest_offset: Vec3Array,
    /// MLS gradient vector `d_ij = w_ij A_i⁻¹ u_ij` of each pair (1/m), by component.
    pub gradient: Vec3Array,
    /// Kernel weight of each pair normalised over the particle's neighbourhood (which sums to
    /// 1), divided by the squared rest distance: `ŵ_ij / |u_ij|²` (1/m²), the geometric factor
    /// of the hourglass-control stiffness.
    pub hourglass_weight: Vec<Real>,
    /// Support radius `h_i` of each particle (m).
    pub support_radius: Vec<Real>,
    /// The transpose: `incoming_offsets[j]..incoming_offsets[j+1]` indexes `incoming`, the pairs
    /// `e` whose neighbour is `j`, in increasing `e` (length: particles + 1).
    pub incoming_offsets: Vec<u32>,
    /// Pair indices grouped by neighbour (see `incoming_offsets`).
    pub incoming: Vec<u32>,
}

impl Neighbourhoods {
    /// Number of particles.
    pub fn particle_count(&self) -> usize {
        self.offsets.len() - 1
    }
    /// The pair range of particle `i`.
    #[inline]
    pub fn range(&self, i: usize) -> std::ops::Range<usize> {
        self.offsets[i] as usize..self.offsets[i + 1] as usize
    }
    /// Total number of (directed) pairs.
    pub fn pair_count(&self) -> usize {
        self.index.len()
    }
    /// The pairs whose neighbour is particle `j`, in increasing pair order.
    #[inline]
    pub fn incoming(&self, j: usize) -> &[u32] {
        &self.incoming[self.incoming_offsets[j] as usize..self.incoming_offsets[j + 1] as usize]
    }
}

/// How the support radius is chosen.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SupportRadius {
    /// Per particle: the smallest radius that holds `target` neighbours, grown until the moment
    /// matrix is well conditioned.
    Automatic {
        /// Neighbours wanted per particle.
        target: usize,
    },
    /// The same radius (m) for every particle; an ill-conditioned particle is an error.
    Fixed(Real),
}

/// Why [`build`] failed: at which particle (none for a set too small), and the reason.
#[derive(Debug, Clone, PartialEq)]
pub struct NeighbourhoodError {
    /// The particle whose neighbourhood failed (an index into `rest`).
    pub particle: Option<usize>,
    /// What failed, and what to change.
    pub reason: String,
}

/// Build the neighbourhoods of particles at rest positions `rest` (m).
///
/// Fails when a particle cannot get a well-conditioned moment matrix, i.e. the points around it
/// are (nearly) coplanar even with [`MAX_NEIGHBOURS`] neighbours, or when a fixed support
/// radius holds too many or too few of them.
pub fn build(rest: &[Vec3], support: SupportRadius) -> Result<Neighbourhoods, NeighbourhoodError> {
    let n = rest.len();
    let fail = |particle, reason| Err(NeighbourhoodError { particle, reason });
    if n < 5 {
        return fail(None, format!("a body needs at least 5 particles, got {n}"));
    }
    let grid = PointGrid::new(rest);
    let mut out = Neighbourhoods {
        offsets: Vec::with_capacity(n + 1),
        index: Vec::new(),
        rest_offset: Vec3Array::default(),
        gradient: Vec3Array::default(),
        hourglass_weight: Vec::new(),
        support_radius: Vec::with_capacity(n),
        incoming_offsets: Vec::new(),
        incoming: Vec::new(),
    };
    out.offsets.push(0);
    let mut candidates: Vec<(Real, u32)> = Vec::new();
    for i in 0..n {
        let (h, count) = match support {
            SupportRadius::Fixed(h) => {
                grid.within(rest, i, h, &mut candidates);
                let c = candidates.len();
                if c > MAX_FIXED_NEIGHBOURS {
                    return fail(
                        Some(i),
                        format!(
                            "support_radius {h} m holds {c} neighbours, more than \
                             {MAX_FIXED_NEIGHBOURS}; use a smaller radius"
                        ),
                    );
                }
                if moment_condition(rest, i, &candidates[..c], h) > MAX_MOMENT_CONDITION {
                    return fail(
                        Some(i),
                        format!(
                            "support radius {h} m gives an ill-conditioned moment matrix ({c} \
                             neighbours); use a larger radius"
                        ),
                    );
                }
                (h, c)
            }
            SupportRadius::Automatic { target } => {
                let mut k = target.clamp(6, MAX_NEIGHBOURS).min(n - 1);
                loop {
                    grid.nearest(rest, i, k + 1, &mut candidates);
                    // h between the k-th and (k+1)-th nearest: exactly k neighbours inside.
                    let h = if candidates.len() > k {
                        0.5 * (candidates[k - 1].0 + candidates[k].0)
                    } else {
                        candidates[k - 1].0 * 1.05
                    };
                    let inside = candidates.iter().filter(|c| c.0 < h).count();
                    let cond = moment_condition(rest, i, &candidates[..inside], h);
                    if cond <= MAX_MOMENT_CONDITION {
                        break (h, inside);
                    }
                    if k >= MAX_NEIGHBOURS.min(n - 1) {
                        return fail(
                            Some(i),
                            format!(
                                "no well-conditioned neighbourhood with up to {k} neighbours \
                                 (condition {cond:.3e}); the points around it are nearly \
                                 coplanar"
                            ),
                        );
                    }
                    k = (k + k / 4 + 1).min(MAX_NEIGHBOURS).min(n - 1);
                }
            }
        };
        let pairs = &candidates[..count];
        let a = moment_matrix(rest, i, pairs, h);
        let a_inv = a.try_inverse().ok_or_else(|| NeighbourhoodError {
            particle: Some(i),
            reason: "singular moment matrix".into(),
        })?;
        let wsum: Real = pairs
            .iter()
            .map(|&(r, _)| kernel(r * r, h * h))
            .sum::<Real>();
        for &(r, j) in pairs {
            let u = rest[j as usize] - rest[i];
            let w = kernel(r * r, h * h);
            out.index.push(j);
            out.rest_offset.push(u);
            out.gradient.push(a_inv * u * w);
            out.hourglass_weight.push(w / wsum / u.norm_squared());
        }
        out.support_radius.push(h);
        out.offsets.push(out.index.len() as u32);
    }
    // The transposed pair lists, by counting sort (pairs stay in increasing order).
    out.incoming_offsets = vec![0; n + 1];
    for &j in &out.index {
        out.incoming_offsets[j as usize + 1] += 1;
    }
    for j in 0..n {
        out.incoming_offsets[j + 1] += out.incoming_offsets[j];
    }
    let mut fill = out.incoming_offsets.clone();
    out.incoming = vec![0; out.index.len()];
    for (e, &j) in out.index.iter().enumerate() {
        out.incoming[fill[j as usize] as usize] = e as u32;
        fill[j as usize] += 1;
    }
    Ok(out)
}

/// Poly6 kernel without its normalisation constant (it cancels in `A⁻¹`): `(1 - r²/h²)³`.
#[inline]
fn kernel(r2: Real, h2: Real) -> Real {
    let q = 1.0 - r2 / h2;
    if q > 0.0 {
        q * q * q
    } else {
        0.0
    }
}

fn moment_matrix(rest: &[Vec3], i: usize, pairs: &[(Real, u32)], h: Real) -> Mat3 {
    let mut a = Mat3::zeros();
    for &(r, j) in pairs {
        let u = rest[j as usize] - rest[i];
        a += u * u.transpose() * kernel(r * r, h * h);
    }
    a
}

/// Condition number (largest / smallest eigenvalue) of the moment matrix; ∞ when singular.
fn moment_condition(rest: &[Vec3], i: usize, pairs: &[(Real, u32)], h: Real) -> Real {
    if pairs.len() < 3 {
        return Real::INFINITY;
    }
    let eig = moment_matrix(rest, i, pairs, h).symmetric_eigenvalues();
    let (lo, hi) = (eig.min(), eig.max());
    if lo <= hi * 1e-14 {
        Real::INFINITY
    } else {
        hi / lo
    }
}

/// A uniform grid over rest positions for load-time neighbour queries.
struct PointGrid {
    origin: Vec3,
    cell: Real,
    dims: [usize; 3],
    start: Vec<u32>,
    items: Vec<u32>,
}

impl PointGrid {
    fn new(points: &[Vec3]) -> Self {
        let mut lo = points[0];
        let mut hi = points[0];
        for p in points {
            lo = lo.inf(p);
            hi = hi.sup(p);
        }
        let ext = hi - lo;
        let vol = (ext.x.max(1e-12)) * (ext.y.max(1e-12)) * (ext.z.max(1e-12));
        // About two points per cell.
        let cell = (2.0 * vol / points.len() as Real)
            .cbrt()
            .max(ext.max() * 1e-6);
        let dims = [0, 1, 2].map(|a| ((ext[a] / cell) as usize + 1).min(1 << 10));
        let mut grid = PointGrid {
            origin: lo,
            cell,
            dims,
            start: vec![0; dims[0] * dims[1] * dims[2] + 1],
            items: vec![0; points.len()],
        };
        for p in points {
            let c = grid.cell_of(p);
            grid.start[c + 1] += 1;
        }
        for c in 0..grid.start.len() - 1 {
            grid.start[c + 1] += grid.start[c];
        }
        let mut fill = grid.start.clone();
        for (k, p) in points.iter().enumerate() {
            let c = grid.cell_of(p);
            grid.items[fill[c] as usize] = k as u32;
            fill[c] += 1;
        }
        grid
    }

    fn coord(&self, p: &Vec3) -> [usize; 3] {
        [0, 1, 2].map(|a| (((p[a] - self.origin[a]) / self.cell) as usize).min(self.dims[a] - 1))
    }

    fn cell_of(&self, p: &Vec3) -> usize {
        let c = self.coord(p);
        c[0] + self.dims[0] * (c[1] + self.dims[1] * c[2])
    }

    /// Points within the cube of `ring` cells around `p`'s cell, with their distances.
    fn gather(&self, points: &[Vec3], i: usize, ring: usize, out: &mut Vec<(Real, u32)>) {
        out.clear();
        let c = self.coord(&points[i]);
        let lo = c.map(|v| v.saturating_sub(ring));
        let hi = [0, 1, 2].map(|a| (c[a] + ring).min(self.dims[a] - 1));
        for z in lo[2]..=hi[2] {
            for y in lo[1]..=hi[1] {
                for x in lo[0]..=hi[0] {
                    let cell = x + self.dims[0] * (y + self.dims[1] * z);
                    for &j in &self.items[self.start[cell] as usize..self.start[cell + 1] as usize]
                    {
                        if j as usize != i {
                            out.push(((points[j as usize] - points[i]).norm(), j));
                        }
                    }
                }
            }
        }
        // Sort by distance, ties by index: deterministic.
        out.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    }

    /// The `k` nearest points to point `i` (fewer if the set is smaller), sorted by distance.
    fn nearest(&self, points: &[Vec3], i: usize, k: usize, out: &mut Vec<(Real, u32)>) {
        let max_ring = *self.dims.iter().max().unwrap_or(&1);
        let mut ring = 1;
        loop {
            self.gather(points, i, ring, out);
            // Every point closer than `ring * cell` is guaranteed to be in the gathered cube.
            let complete = ring as Real * self.cell;
            if (out.len() >= k && out[k - 1].0 <= complete) || ring >= max_ring {
                out.truncate(k);
                return;
            }
            ring += 1;
        }
    }

    /// Every point closer than `h` to point `i`, sorted by distance.
    fn within(&self, points: &[Vec3], i: usize, h: Real, out: &mut Vec<(Real, u32)>) {
        let ring = ((h / self.cell).ceil() as usize).max(1);
        self.gather(points, i, ring, out);
        out.retain(|c| c.0 < h);
    }
}
