//! Colouring of the tetrahedra for the volume pass, by blocks: the tetrahedra are cut into
//! blocks of [`BLOCK`] consecutive ones (neighbours in the mesh's order, so a block works on a
//! few hundred nearby particles, in cache), and the blocks are coloured so that blocks of one
//! colour share no particle. The pass runs the colours in sequence and the blocks of a colour
//! in any order, on any number of threads, each block's tetrahedra in their order: the result
//! does not depend on the thread count.
//!
//! Greedy first fit in block order: each block takes the first colour none of whose blocks
//! touches its particles.

/// Tetrahedra per block.
pub(crate) const BLOCK: usize = 128;

/// The blocks of tetrahedra grouped by colour.
#[derive(Debug, Clone, PartialEq, Default)]
pub(crate) struct TetColouring {
    /// The blocks, colour by colour, increasing within a colour: the index of each block's
    /// first tetrahedron (a block holds `BLOCK` tetrahedra, fewer for the last one).
    pub(crate) blocks: Vec<u32>,
    /// Where each colour starts in `blocks`, then `blocks.len()`.
    pub(crate) starts: Vec<u32>,
    /// Number of tetrahedra.
    pub(crate) tets: u32,
}

impl TetColouring {
    /// Colour the blocks of `tets` (4 particle indices each, all below `particles`).
    pub(crate) fn new(tets: &[[u32; 4]], particles: usize) -> TetColouring {
        // Per colour, whether each particle is taken by one of its blocks.
        let mut taken: Vec<Vec<bool>> = Vec::new();
        let mut colour_of = Vec::new();
        for block in tets.chunks(BLOCK) {
            let particles_of = || block.iter().flatten().map(|&k| k as usize);
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
            blocks,
            starts,
            tets: tets.len() as u32,
        }
    }

    /// The blocks of each colour (first tetrahedron of each), in colour order.
    pub(crate) fn colours(&self) -> impl Iterator<Item = &[u32]> {
        self.starts
            .windows(2)
            .map(|w| &self.blocks[w[0] as usize..w[1] as usize])
    }

    /// The tetrahedra of the block starting at `first`.
    pub(crate) fn block(&self, first: u32) -> std::ops::Range<usize> {
        first as usize..(first as usize + BLOCK).min(self.tets as usize)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Vec3;
    use crate::mesh::lattice_box;

    #[test]
    fn every_tet_once_and_no_shared_particle_within_a_colour() {
        let mesh = lattice_box(Vec3::zeros(), Vec3::repeat(1.0), [12, 10, 11]);
        let c = TetColouring::new(&mesh.tets, mesh.nodes.len());
        let mut seen = vec![0; mesh.tets.len()];
        for colour in c.colours() {
            let mut used = vec![false; mesh.nodes.len()];
            for &first in colour {
                let mut mine = vec![false; mesh.nodes.len()];
                for t in c.block(first) {
                    seen[t] += 1;
                    for &k in &mesh.tets[t] {
                        assert!(!used[k as usize], "particle {k} in two blocks of a colour");
                        mine[k as usize] = true;
                    }
                }
                used.iter_mut().zip(&mine).for_each(|(u, m)| *u |= m);
            }
            assert!(colour.windows(2).all(|w| w[0] < w[1]));
        }
        assert!(seen.iter().all(|&n| n == 1));
        let blocks = mesh.tets.len().div_ceil(BLOCK);
        let colours = c.starts.len() - 1;
        assert!(
            colours >= 2 && colours < blocks,
            "{colours} colours for {blocks} blocks"
        );
    }
}
