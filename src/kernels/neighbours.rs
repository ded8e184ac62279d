//! Particle neighbourhoods in CSR form with the rest-state quantities of the moving-least-squares
//! deformation gradient precomputed (eq. 1–2 of the paper).
//!
//! For particle `i` with support radius `h_i`, the neighbours are the particles `j ≠ i` with
//! `|X_j - X_i| < h_i` in the rest state (Lagrangian: fixed for the body's life). With
//! `u_ij = X_j - X_i`, the poly6 kernel `w_ij = (1 - |u_ij|²/h_i²)³` and the moment matrix
//! `A_i = Σ_j w_ij u_ij u_ijᵀ`, the deformation gradient is `F_i = Σ_j x_ij d_ijᵀ` with
//! `d_ij = w_ij A_i⁻¹ u_ij`, stored per pair.
//!
//! Each particle's pairs start at a multiple of [`PAIR_SLOT_ALIGNMENT`] in the per-pair arrays
//! and are followed by inert padding slots up to the next multiple (neighbour `i` itself, zero
//! offset, gradient and weight), so the force pass reads whole chunks of four pairs with no
//! partial last chunk. [`Neighbourhoods::range`] gives a particle's real pairs and
//! [`Neighbourhoods::slots`] its padded run.

use crate::kernels::lanes::LANES;
use crate::kernels::math::{Mat3, Real, Vec3};
use crate::kernels::vec3_array::Vec3Array;

/// Largest accepted condition number of a particle's moment matrix `A_i`; a particle above it
/// gets a larger support radius (more neighbours) at load time.
pub const MAX_MOMENT_CONDITION: Real = 200.0;

/// Largest number of neighbours the automatic support radius may reach for one particle.
pub const MAX_NEIGHBOURS: usize = 96;

/// Largest number of neighbours a fixed support radius may give one particle (the step's time
/// and memory grow with it).
pub const MAX_FIXED_NEIGHBOURS: usize = 4 * MAX_NEIGHBOURS;

/// Every particle's run of pair slots starts at a multiple of this and is this many slots
/// long, or a multiple of it (the force pass's lane count).
pub const PAIR_SLOT_ALIGNMENT: usize = LANES;

/// Neighbour lists of every particle of a body (CSR) and their rest-state quantities.
///
/// The per-pair arrays (`index`, `rest_offset`, `gradient`, `hourglass_weight`) hold, for each
/// particle in turn, its pairs then padding slots up to a multiple of [`PAIR_SLOT_ALIGNMENT`];
/// a padding slot of particle `i` has neighbour `i`, zero offset, zero gradient and zero weight,
/// and adds nothing to any sum. A pair index `e` is an index into these arrays.
#[derive(Debug, Clone, PartialEq)]
pub struct Neighbourhoods {
    /// `offsets[i]..offsets[i+1]` is particle `i`'s run of pair slots in the arrays below, its
    /// pairs first (length: particles + 1; every entry a multiple of [`PAIR_SLOT_ALIGNMENT`]).
    pub offsets: Vec<u32>,
    /// `offsets[i]..ends[i]` is the range of particle `i`'s pairs (length: particles).
    pub ends: Vec<u32>,
    /// Neighbour index `j` of each pair slot.
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
    /// `sources[j]`: the first and the last of the particles whose pairs particle `j`'s force
    /// sum reads, the particles that have `j` as a neighbour and `j` itself (length:
    /// particles). A thread whose share of the particles holds them scatters `j`'s terms itself
    /// ([`crate::kernels::pair_sums`]).
    pub sources: Vec<[u32; 2]>,
    /// `reach[i]`: the first and the last of the sources of particle `i` and of its neighbours
    /// (length: particles). A share that holds them scatters every term of `i` itself, with no
    /// check per pair.
    pub reach: Vec<[u32; 2]>,
}

impl Neighbourhoods {
    /// Number of particles.
    pub fn particle_count(&self) -> usize {
        self.offsets.len() - 1
    }
    /// The pair range of particle `i` (its real pairs, without the padding).
    #[inline]
    pub fn range(&self, i: usize) -> std::ops::Range<usize> {
        self.offsets[i] as usize..self.ends[i] as usize
    }
    /// The run of pair slots of particle `i`: its pairs, then padding up to a multiple of
    /// [`PAIR_SLOT_ALIGNMENT`].
    #[inline]
    pub fn slots(&self, i: usize) -> std::ops::Range<usize> {
        self.offsets[i] as usize..self.offsets[i + 1] as usize
    }
    /// Total number of (directed) pairs, padding excluded.
    pub fn pair_count(&self) -> usize {
        self.incoming.len()
    }
    /// Length of the per-pair arrays: every pair index is below it (padding included).
    pub fn slot_count(&self) -> usize {
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
        ends: Vec::with_capacity(n),
        index: Vec::new(),
        rest_offset: Vec3Array::default(),
        gradient: Vec3Array::default(),
        hourglass_weight: Vec::new(),
        support_radius: Vec::with_capacity(n),
        incoming_offsets: Vec::new(),
        incoming: Vec::new(),
        sources: (0..n as u32).map(|j| [j, j]).collect(),
        reach: Vec::new(),
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
        out.ends.push(out.index.len() as u32);
        while !out.index.len().is_multiple_of(PAIR_SLOT_ALIGNMENT) {
            out.index.push(i as u32);
            out.rest_offset.push(Vec3::zeros());
            out.gradient.push(Vec3::zeros());
            out.hourglass_weight.push(0.0);
        }
        out.support_radius.push(h);
        out.offsets.push(out.index.len() as u32);
    }
    // The transposed pair lists, by counting sort (pairs stay in increasing order).
    out.incoming_offsets = vec![0; n + 1];
    for i in 0..n {
        for &j in &out.index[out.range(i)] {
            out.incoming_offsets[j as usize + 1] += 1;
        }
    }
    for j in 0..n {
        out.incoming_offsets[j + 1] += out.incoming_offsets[j];
    }
    let mut fill = out.incoming_offsets.clone();
    out.incoming = vec![0; out.incoming_offsets[n] as usize];
    for i in 0..n {
        for e in out.range(i) {
            let j = out.index[e] as usize;
            out.incoming[fill[j] as usize] = e as u32;
            fill[j] += 1;
            let [first, last] = &mut out.sources[j];
            *first = (*first).min(i as u32);
            *last = (*last).max(i as u32);
        }
    }
    out.reach = (0..n)
        .map(|i| {
            let neighbours = out.index[out.range(i)].iter().map(|&j| j as usize);
            neighbours.fold(out.sources[i], |[first, last], j| {
                let [a, b] = out.sources[j];
                [first.min(a), last.max(b)]
            })
        })
        .collect();
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A 5×4×4 lattice (m) with a deterministic jitter, so distances are all different.
    fn jittered_lattice() -> Vec<Vec3> {
        let mut points = Vec::new();
        for i in 0..5 {
            for j in 0..4 {
                for k in 0..4 {
                    let s = (i * 16 + j * 4 + k) as Real;
                    let jitter = Vec3::new((s * 0.7).sin(), (s * 1.3).cos(), (s * 2.1).sin());
                    points.push(Vec3::new(i as Real, j as Real, k as Real) + 0.1 * jitter);
                }
            }
        }
        points
    }

    /// Each particle's slots start on a chunk boundary and hold its pairs then at most three
    /// inert padding slots (neighbour itself, zero rest data); the transposed lists, the
    /// sources, their reach and the pair count see only the real pairs.
    #[test]
    fn pair_slots_are_chunk_aligned_and_padding_is_inert() {
        let rest = jittered_lattice();
        let nbr = build(&rest, SupportRadius::Automatic { target: 13 }).unwrap();
        let mut real = 0;
        let mut padded = 0;
        for i in 0..rest.len() {
            let (range, slots) = (nbr.range(i), nbr.slots(i));
            assert_eq!(range.start, slots.start);
            assert_eq!(slots.start % PAIR_SLOT_ALIGNMENT, 0);
            assert_eq!(slots.len() % PAIR_SLOT_ALIGNMENT, 0);
            assert!(range.end <= slots.end && slots.end - range.end < PAIR_SLOT_ALIGNMENT);
            assert!(range.len() >= 13, "particle {i}: {} pairs", range.len());
            for e in range.clone() {
                assert_ne!(nbr.index[e] as usize, i);
                assert!(nbr.hourglass_weight[e] > 0.0);
            }
            for e in range.end..slots.end {
                assert_eq!(nbr.index[e] as usize, i);
                assert_eq!(nbr.rest_offset.get(e), Vec3::zeros());
                assert_eq!(nbr.gradient.get(e), Vec3::zeros());
                assert_eq!(nbr.hourglass_weight[e], 0.0);
                padded += 1;
            }
            real += range.len();
        }
        assert!(padded > 0, "13 neighbours must leave padding");
        assert_eq!(nbr.pair_count(), real);
        assert_eq!(nbr.slot_count(), real + padded);
        for j in 0..rest.len() {
            let mut sources = [j, j];
            for &e in nbr.incoming(j) {
                let e = e as usize;
                let owner = (0..rest.len())
                    .find(|&i| nbr.slots(i).contains(&e))
                    .unwrap();
                assert!(
                    nbr.range(owner).contains(&e),
                    "padding slot {e} listed as incoming"
                );
                assert_eq!(nbr.index[e] as usize, j);
                sources = [sources[0].min(owner), sources[1].max(owner)];
            }
            assert_eq!(nbr.sources[j].map(|k| k as usize), sources, "particle {j}");
        }
        for i in 0..rest.len() {
            let mut reached = vec![i];
            reached.extend(nbr.index[nbr.range(i)].iter().map(|&j| j as usize));
            let first = reached.iter().map(|&j| nbr.sources[j][0]).min();
            let last = reached.iter().map(|&j| nbr.sources[j][1]).max();
            assert_eq!(
                Some(nbr.reach[i]),
                first.zip(last).map(|(a, b)| [a, b]),
                "{i}"
            );
        }
    }
}
