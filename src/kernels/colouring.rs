//! Colouring of the tetrahedra for the volume pass, by blocks. The tetrahedra are put in a
//! projection order: sorted by their smallest particle index. Particles are numbered along a
//! Morton curve (`crate::model::particle_order`), so tetrahedra that are neighbours in this
//! order are neighbours in space. The order is cut into blocks of [`BLOCK`] consecutive
//! tetrahedra, each working on a compact region of nearby particles, in cache; within a block,
//! consecutive tetrahedra are made to share no particle where possible (so that one projection
//! does not wait for the stores of the one before). The blocks are coloured so that blocks of
//! one colour share no particle. The pass runs the colours in sequence and the
//! blocks of a colour in any order, on any number of threads, each block's tetrahedra in
//! their order: the result does not depend on the thread count.
//!
//! The mesh's own tetrahedron order is left as it is: it scatters neighbouring tetrahedra over
//! the whole mesh (TetGen's livers), so that nearly every block of it touched every other and
//! each colour held a single block (129 colours for 130 blocks on liver_4k): a sequential pass
//! with a barrier per block. The colouring keeps its own copy of the tetrahedra and their rest
//! volumes in projection order (24 bytes a tetrahedron), so the pass reads them in sequence.
//!
//! Greedy first fit in block order: each block takes the first colour none of whose blocks
//! touches its particles.

use crate::kernels::math::Real;

/// Tetrahedra per block.
pub(crate) const BLOCK: usize = 128;

/// The blocks of tetrahedra grouped by colour.
///
/// Invariant (checked by [`TetColouring::new`], kept by the private fields): every particle
/// index of `tets` is below `particles`, so the volume pass reads its corners without a check
/// per index.
#[derive(Debug, Clone, PartialEq, Default)]
pub(crate) struct TetColouring {
    /// The body's tetrahedra (four particle indices each) in projection order.
    tets: Vec<[u32; 4]>,
    /// Their rest volumes (m³), in the same order.
    rest_volume: Vec<Real>,
    /// The blocks, colour by colour, increasing within a colour: the position in `tets` of
    /// each block's first tetrahedron (a block holds `BLOCK` tetrahedra, fewer for the last).
    blocks: Vec<u32>,
    /// Where each colour starts in `blocks`, then `blocks.len()`.
    starts: Vec<u32>,
    /// The number of particles of the body: every index of `tets` is below it.
    particles: usize,
}

/// How far ahead in a block [`alternate`] looks for a tetrahedron that shares no particle with
/// the one before.
const ALTERNATE_WINDOW: usize = 32;

/// Reorder `block` (tetrahedron indices into `tets`) so that consecutive tetrahedra share no
/// particle where possible: each next one is the first of the following [`ALTERNATE_WINDOW`]
/// that shares none with the one before, or the first if none does.
///
/// The projection of a tetrahedron reads the corners the one before it wrote: when they share
/// one, it waits for those stores. A projection of four lanes is ~450 instructions, more than
/// the processor's reorder window (320 on the machine of docs/PERFORMANCE.md), so only the
/// tetrahedron just before can hold it up: one step apart is enough.
fn alternate(block: &mut [u32], tets: &[[u32; 4]]) {
    let mut left: Vec<u32> = block.to_vec();
    for k in 0..block.len() {
        let before = k.checked_sub(1).map(|p| tets[block[p] as usize]);
        let shares =
            |t: &u32| before.is_some_and(|b| tets[*t as usize].iter().any(|p| b.contains(p)));
        let window = left.len().min(ALTERNATE_WINDOW);
        let pick = left[..window].iter().position(|t| !shares(t)).unwrap_or(0);
        block[k] = left.remove(pick);
    }
}

impl TetColouring {
    /// Order and colour `tets` (4 particle indices each, all below `particles`: panics
    /// otherwise) with their rest volumes `rest_volume` (m³).
    pub(crate) fn new(tets: &[[u32; 4]], rest_volume: &[Real], particles: usize) -> TetColouring {
        assert!(
            tets.iter().flatten().all(|&k| (k as usize) < particles),
            "a tetrahedron's particle index is out of range"
        );
        assert_eq!(tets.len(), rest_volume.len());
        let mut order: Vec<u32> = (0..tets.len() as u32).collect();
        order.sort_by_key(|&t| (tets[t as usize].iter().min().copied(), t));
        for block in order.chunks_mut(BLOCK) {
            alternate(block, tets);
        }
        // Per colour, whether each particle is taken by one of its blocks.
        let mut taken: Vec<Vec<bool>> = Vec::new();
        let mut colour_of = Vec::new();
        for block in order.chunks(BLOCK) {
            let particles_of = || {
                block
                    .iter()
                    .flat_map(|&t| tets[t as usize])
                    .map(|k| k as usize)
            };
            let free = |t: &Vec<bool>| particles_of().all(|k| !t[k]);
            let c = match taken.iter().position(free) {
                Some(c) => c,
                None => {
                    taken.push(vec![false; particles]);
                    taken.len() - 1
                }
            };
            particles_of().for_each(|k| taken[c][k] = true);
            colour_of.push(c);
        }
        let mut starts = vec![0u32; taken.len() + 1];
        colour_of.iter().for_each(|&c| starts[c + 1] += 1);
        for c in 0..taken.len() {
            starts[c + 1] += starts[c];
        }
        let mut next: Vec<u32> = starts[..taken.len()].to_vec();
        let mut blocks = vec![0; colour_of.len()];
        for (b, &c) in colour_of.iter().enumerate() {
            blocks[next[c] as usize] = (b * BLOCK) as u32;
            next[c] += 1;
        }
        TetColouring {
            tets: order.iter().map(|&t| tets[t as usize]).collect(),
            rest_volume: order.iter().map(|&t| rest_volume[t as usize]).collect(),
            blocks,
            starts,
            particles,
        }
    }

    /// The tetrahedra (four particle indices each, every one below
    /// [`particle_count`](Self::particle_count)) in projection order.
    pub(crate) fn tets(&self) -> &[[u32; 4]] {
        &self.tets
    }

    /// The rest volumes (m³) of [`tets`](Self::tets), in the same order.
    pub(crate) fn rest_volume(&self) -> &[Real] {
        &self.rest_volume
    }

    /// The number of particles of the body the tetrahedra index.
    pub(crate) fn particle_count(&self) -> usize {
        self.particles
    }

    /// The heap memory held (bytes).
    pub(crate) fn heap_bytes(&self) -> usize {
        size_of_val(self.tets.as_slice())
            + size_of_val(self.rest_volume.as_slice())
            + size_of_val(self.blocks.as_slice())
            + size_of_val(self.starts.as_slice())
    }

    /// The blocks of each colour (first tetrahedron of each), in colour order.
    pub(crate) fn colours(&self) -> impl Iterator<Item = &[u32]> {
        self.starts
            .windows(2)
            .map(|w| &self.blocks[w[0] as usize..w[1] as usize])
    }

    /// The positions in `tets` of the block starting at position `first`.
    pub(crate) fn block(&self, first: u32) -> std::ops::Range<usize> {
        first as usize..(first as usize + BLOCK).min(self.tets.len())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kernels::math::tet_volume;
    use crate::kernels::math::Vec3;
    use crate::mesh::{lattice_box, TetMesh};

    fn volumes(mesh: &TetMesh) -> Vec<Real> {
        let x = |k: u32| mesh.nodes[k as usize];
        mesh.tets
            .iter()
            .map(|&[a, b, c, d]| tet_volume(&x(a), &x(b), &x(c), &x(d)))
            .collect()
    }

    /// Order and colour `mesh`'s tetrahedra, checking what the volume pass relies on: the
    /// projection order holds every tetrahedron once, with its own rest volume; the blocks
    /// cover every position once, increasing within a colour; and no two blocks of a colour
    /// share a particle.
    fn coloured(mesh: &TetMesh) -> TetColouring {
        let rest_volume = volumes(mesh);
        let c = TetColouring::new(&mesh.tets, &rest_volume, mesh.nodes.len());
        let key = |(&t, v): (&[u32; 4], &Real)| (t, v.to_bits());
        let mut ours: Vec<_> = c.tets.iter().zip(&c.rest_volume).map(key).collect();
        let mut theirs: Vec<_> = mesh.tets.iter().zip(&rest_volume).map(key).collect();
        ours.sort();
        theirs.sort();
        assert_eq!(ours, theirs);
        let mut seen = vec![0; c.tets.len()];
        for colour in c.colours() {
            assert!(colour.windows(2).all(|w| w[0] < w[1]));
            let mut used = vec![false; mesh.nodes.len()];
            for &first in colour {
                let mut mine = vec![false; mesh.nodes.len()];
                for t in c.block(first) {
                    seen[t] += 1;
                    for &k in &c.tets[t] {
                        assert!(!used[k as usize], "particle {k} in two blocks of a colour");
                        mine[k as usize] = true;
                    }
                }
                used.iter_mut().zip(&mine).for_each(|(u, m)| *u |= m);
            }
        }
        assert!(seen.iter().all(|&n| n == 1));
        c
    }

    /// Within a block, consecutive tetrahedra rarely share a particle (they nearly all do in
    /// the sorted order), and each block holds the tetrahedra of the sorted order's block.
    #[test]
    fn consecutive_tetrahedra_of_a_block_rarely_share_a_particle() {
        let mesh = lattice_box(Vec3::zeros(), Vec3::repeat(1.0), [12, 10, 11]);
        let c = coloured(&mesh);
        let share = |a: &[u32; 4], b: &[u32; 4]| a.iter().any(|k| b.contains(k));
        let fraction = |tets: &[[u32; 4]]| {
            let (mut pairs, mut shared) = (0, 0);
            for block in tets.chunks(BLOCK) {
                for w in block.windows(2) {
                    pairs += 1;
                    shared += usize::from(share(&w[0], &w[1]));
                }
            }
            shared as Real / pairs as Real
        };
        let mut sorted = mesh.tets.clone();
        sorted.sort_by_key(|t| *t.iter().min().unwrap());
        assert!(fraction(&sorted) > 0.5, "sorted: {}", fraction(&sorted));
        assert!(fraction(&c.tets) < 0.02, "reordered: {}", fraction(&c.tets));
        for (ours, theirs) in c.tets.chunks(BLOCK).zip(sorted.chunks(BLOCK)) {
            let (mut a, mut b) = (ours.to_vec(), theirs.to_vec());
            a.sort();
            b.sort();
            assert_eq!(a, b);
        }
    }

    /// The volume pass reads corners without a check per index: a tetrahedron naming a
    /// particle past the count is refused when the colouring is built.
    #[test]
    #[should_panic(expected = "out of range")]
    fn an_index_past_the_particle_count_is_refused() {
        let mesh = lattice_box(Vec3::zeros(), Vec3::repeat(1.0), [2, 2, 2]);
        let rest_volume = volumes(&mesh);
        TetColouring::new(&mesh.tets, &rest_volume, mesh.nodes.len() - 1);
    }

    #[test]
    fn every_tet_once_and_no_shared_particle_within_a_colour() {
        let mesh = lattice_box(Vec3::zeros(), Vec3::repeat(1.0), [12, 10, 11]);
        let c = coloured(&mesh);
        let blocks = mesh.tets.len().div_ceil(BLOCK);
        let colours = c.starts.len() - 1;
        assert!(
            colours >= 2 && colours < blocks,
            "{colours} colours for {blocks} blocks"
        );
    }

    /// With the tetrahedra listed in a scrambled order (as TetGen lists a liver's), the
    /// projection order still makes compact blocks: a colour holds several blocks, so the
    /// pass has work to split and few barriers.
    #[test]
    fn scrambled_tetrahedra_still_give_few_colours() {
        let mut mesh = lattice_box(Vec3::zeros(), Vec3::repeat(1.0), [16, 14, 15]);
        let n = mesh.tets.len();
        // A fixed permutation: t -> t * 7919 mod n (7919 is prime and does not divide n).
        assert_ne!(n % 7919, 0);
        let scrambled: Vec<[u32; 4]> = (0..n).map(|t| mesh.tets[t * 7919 % n]).collect();
        mesh.tets = scrambled;
        let c = coloured(&mesh);
        let blocks = c.blocks.len();
        let colours = c.starts.len() - 1;
        assert!(blocks >= 100, "{blocks} blocks");
        assert!(
            colours * 4 <= blocks,
            "{colours} colours for {blocks} blocks"
        );
    }
}
