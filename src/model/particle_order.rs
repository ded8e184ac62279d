//! The order in which a body stores its particles: the mesh's nodes sorted along a Morton
//! (Z-order) curve, so that particles close in space sit close in memory.
//!
//! A particle's neighbours are the particles nearest to it, and its tetrahedra join it to
//! nearby nodes. Mesh generators number nodes with little regard for that (TetGen's liver_4k:
//! the two nodes of a tetrahedron edge are on average 857 places apart), so the force pass,
//! gathering each particle's ~20 neighbours, and the volume pass, each tetrahedron's 4 nodes,
//! read memory almost at random. Sorted along a space-filling curve, nearby particles share
//! cache lines (the same mesh: 95 places apart on average). See docs/PERFORMANCE.md for what it
//! measures.
//!
//! The order is internal: the C ABI and the FMU read and write every per-particle array and
//! index in the mesh's order, and so do [`World::add_body`](crate::World::add_body) error
//! messages. The Rust API of [`Body`](crate::Body) and [`BodyModel`](crate::BodyModel) works in
//! particle order (so its slices are views, not copies), and [`ParticleOrder`] converts.

use crate::kernels::math::Vec3;
use crate::mesh::TetMesh;

/// A permutation between a mesh's node indices and a body's particle indices.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ParticleOrder {
    /// For each particle, the index of its node in the mesh.
    mesh_index: Vec<u32>,
    /// For each mesh node, the index of its particle.
    particle_index: Vec<u32>,
}

/// Bits per axis of the Morton code (3 × 21 = 63 bits of a `u64`).
const MORTON_BITS: u32 = 21;

impl ParticleOrder {
    /// The nodes sorted by the Morton code of their position in the bounding box, quantised to
    /// 2²¹ cells per axis; ties (nodes in one cell) keep the mesh's order. Non-finite positions
    /// quantise to cell 0 (the caller rejects them).
    pub(crate) fn morton(nodes: &[Vec3]) -> ParticleOrder {
        let (lo, hi) = nodes.iter().fold(
            (Vec3::repeat(f64::MAX), Vec3::repeat(f64::MIN)),
            |(lo, hi), p| (lo.inf(p), hi.sup(p)),
        );
        let cells = ((1u64 << MORTON_BITS) - 1) as f64;
        let extent = (hi - lo).max();
        let scale = if extent > 0.0 { cells / extent } else { 0.0 };
        let code = |p: &Vec3| {
            (0..3).fold(0u64, |code, axis| {
                let q = ((p[axis] - lo[axis]) * scale).clamp(0.0, cells) as u64;
                code | (spread_bits(q) << axis)
            })
        };
        let mut keyed: Vec<(u64, u32)> = nodes
            .iter()
            .enumerate()
            .map(|(k, p)| (code(p), k as u32))
            .collect();
        keyed.sort_unstable();
        ParticleOrder::from_mesh_indices(keyed.into_iter().map(|(_, k)| k).collect())
    }

    /// The order given by `mesh_index` (a permutation of `0..n`): particle `i` is mesh node
    /// `mesh_index[i]`.
    fn from_mesh_indices(mesh_index: Vec<u32>) -> ParticleOrder {
        let mut particle_index = vec![0; mesh_index.len()];
        for (i, &k) in mesh_index.iter().enumerate() {
            particle_index[k as usize] = i as u32;
        }
        ParticleOrder {
            mesh_index,
            particle_index,
        }
    }

    /// Number of particles (= mesh nodes).
    pub fn len(&self) -> usize {
        self.mesh_index.len()
    }
    /// True for an empty order.
    pub fn is_empty(&self) -> bool {
        self.mesh_index.is_empty()
    }
    /// Mesh node index of particle `i` (panics when `i` is out of range).
    pub fn mesh_index(&self, i: usize) -> usize {
        self.mesh_index[i] as usize
    }
    /// Particle index of mesh node `k` (panics when `k` is out of range).
    pub fn particle(&self, k: usize) -> usize {
        self.particle_index[k] as usize
    }
    /// For each particle, its mesh node index.
    pub fn mesh_indices(&self) -> &[u32] {
        &self.mesh_index
    }
    /// A per-particle array rearranged into mesh order: entry `k` is mesh node `k`'s value.
    /// Panics when the lengths differ.
    pub fn to_mesh_order<T: Copy>(&self, per_particle: &[T]) -> Vec<T> {
        assert_eq!(per_particle.len(), self.len(), "one value per particle");
        gather(per_particle, &self.particle_index)
    }
    /// A per-node array (mesh order) rearranged into particle order. Panics when the lengths
    /// differ.
    pub fn to_particle_order<T: Copy>(&self, per_node: &[T]) -> Vec<T> {
        assert_eq!(per_node.len(), self.len(), "one value per mesh node");
        gather(per_node, &self.mesh_index)
    }
    /// Particle indices of a list of mesh node indices (`None` if one is out of range).
    pub fn particles_of(&self, nodes: &[u32]) -> Option<Vec<u32>> {
        nodes
            .iter()
            .map(|&k| self.particle_index.get(k as usize).copied())
            .collect()
    }

    /// `mesh` renumbered into this order: the nodes permuted, the tetrahedra (same order)
    /// referring to particles. Every index of `mesh.tets` must be in range.
    pub(crate) fn renumber(&self, mesh: &TetMesh) -> TetMesh {
        TetMesh {
            nodes: self.to_particle_order(&mesh.nodes),
            tets: mesh
                .tets
                .iter()
                .map(|t| self.particles_of_array(t))
                .collect(),
        }
    }
    /// The particle indices of the mesh node indices of one simplex.
    pub(crate) fn particles_of_array<const N: usize>(&self, nodes: &[u32; N]) -> [u32; N] {
        nodes.map(|k| self.particle_index[k as usize])
    }
    /// The mesh node indices of the particle indices of one simplex.
    pub(crate) fn mesh_indices_of_array<const N: usize>(&self, particles: &[u32; N]) -> [u32; N] {
        particles.map(|i| self.mesh_index[i as usize])
    }
}

/// `values[at[0]], values[at[1]], …`.
fn gather<T: Copy>(values: &[T], at: &[u32]) -> Vec<T> {
    at.iter().map(|&k| values[k as usize]).collect()
}

/// The 21 low bits of `v` spread to every third bit (bit `b` to bit `3b`).
fn spread_bits(v: u64) -> u64 {
    let mut x = v & 0x1f_ffff;
    x = (x | x << 32) & 0x001f_0000_0000_ffff;
    x = (x | x << 16) & 0x001f_0000_ff00_00ff;
    x = (x | x << 8) & 0x100f_00f0_0f00_f00f;
    x = (x | x << 4) & 0x10c3_0c30_c30c_30c3;
    x = (x | x << 2) & 0x1249_2492_4924_9249;
    x
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::lattice_box;

    /// Mean `|i − j|` over the tetrahedron edges: how far apart in memory neighbours sit.
    fn mean_edge_span(tets: &[[u32; 4]]) -> f64 {
        let (mut sum, mut count) = (0.0, 0.0);
        for t in tets {
            for a in 0..4 {
                for b in a + 1..4 {
                    sum += (t[a] as f64 - t[b] as f64).abs();
                    count += 1.0;
                }
            }
        }
        sum / count
    }

    #[test]
    fn spreading_puts_each_bit_three_places_apart() {
        assert_eq!(spread_bits(0b1), 0b1);
        assert_eq!(spread_bits(0b11), 0b1001);
        assert_eq!(spread_bits(0x1f_ffff).count_ones(), 21);
        assert_eq!(spread_bits(1 << 20), 1 << 60);
    }

    #[test]
    fn the_order_is_a_permutation_and_its_maps_are_inverse() {
        let mesh = lattice_box(Vec3::zeros(), Vec3::new(0.05, 0.04, 0.03), [5, 4, 3]);
        let order = ParticleOrder::morton(&mesh.nodes);
        assert_eq!(order.len(), mesh.nodes.len());
        let mut seen = order.mesh_indices().to_vec();
        seen.sort_unstable();
        assert!(seen.iter().enumerate().all(|(k, &m)| k as u32 == m));
        for i in 0..order.len() {
            assert_eq!(order.particle(order.mesh_index(i)), i);
        }
        let there = order.to_particle_order(&mesh.nodes);
        assert_eq!(order.to_mesh_order(&there), mesh.nodes);
        let renumbered = order.renumber(&mesh);
        for (t, r) in mesh.tets.iter().zip(&renumbered.tets) {
            assert_eq!(order.mesh_indices_of_array(r), *t);
            for k in 0..4 {
                assert_eq!(renumbered.nodes[r[k] as usize], mesh.nodes[t[k] as usize]);
            }
        }
        assert_eq!(order.particles_of(&[0, 1_000]), None);
    }

    #[test]
    fn a_shuffled_mesh_gets_its_locality_back() {
        // A lattice numbered at random, as a mesh generator might: neighbours far apart.
        let mesh = lattice_box(Vec3::zeros(), Vec3::new(0.12, 0.1, 0.08), [12, 10, 8]);
        let n = mesh.nodes.len();
        let mut shuffle: Vec<u32> = (0..n as u32).collect();
        let mut state = 0x2545_f491_4f6c_dd1du64;
        for k in (1..n).rev() {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            shuffle.swap(k, (state % (k as u64 + 1)) as usize);
        }
        let shuffled = ParticleOrder::from_mesh_indices(shuffle).renumber(&mesh);
        let sorted = ParticleOrder::morton(&shuffled.nodes).renumber(&shuffled);
        let lexicographic = mean_edge_span(&mesh.tets);
        let (before, after) = (mean_edge_span(&shuffled.tets), mean_edge_span(&sorted.tets));
        // Measured: 432 shuffled, 91 sorted, 87 in the lattice's own (i, j, k) order.
        assert!(
            after < 0.25 * before && after < 1.5 * lexicographic,
            "mean edge span {before:.0} shuffled, {after:.0} sorted, {lexicographic:.0} (i, j, k)"
        );
    }
}
