//! The dual cell of each particle: a quarter of every tetrahedron around it. Its volume
//! `V_i(x) = ¼ Σ_{t∋i} vol_t(x)` is what one volume constraint per particle keeps
//! ([`VolumeScheme::DualCells`](crate::VolumeScheme::DualCells)): about one constraint per three
//! unknowns, against six per three for one constraint per tetrahedron, so the discretisation
//! does not lock as ν → 0.5 (the average nodal pressure tetrahedron of Bonet & Burton 1998,
//! solved as XPBD constraints).

use crate::kernels::math::{Real, Vec3};

/// For the tetrahedron corner at position `c` (0..4) of its four, the other three corners in an
/// order that, put after it, is an even permutation of the four: the tetrahedron's volume is
/// then `r_b · (r_c × r_d) / 6` with `r_k` corner k's position relative to corner `c`.
const OTHERS: [[usize; 3]; 4] = [[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]];

/// For every particle, the tetrahedra around it and the particles they hold (its "star", the
/// particle itself first), in compressed rows, each tetrahedron as the star slots of its
/// three other corners, and the cell's rest volume (m³); and the colouring of the cells that
/// the projection runs in (see [`DualCells::colours`]).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct DualCells {
    /// Where each particle's tetrahedra start in `opposite`, then `opposite.len()`.
    offsets: Vec<u32>,
    /// For each tetrahedron around particle `i`, the slots in `i`'s star of its other three
    /// corners, in the order of [`OTHERS`]: the quarter tetrahedron's volume (m³) is
    /// `r_b · (r_c × r_d) / 24`, `r_k` the position of slot k relative to `i` (m).
    opposite: Vec<[u16; 3]>,
    star_offsets: Vec<u32>,
    star: Vec<u32>,
    rest_volume: Vec<Real>,
    /// The most particles in one star (the size of a projection's scratch).
    max_star: usize,
    /// The cells in at least one tetrahedron, colour by colour, increasing within a colour.
    order: Vec<u32>,
    /// Where each colour starts in `order`, then `order.len()`.
    colour_starts: Vec<u32>,
}

impl DualCells {
    /// The cells of `n` particles from the tetrahedra `tets` and their rest volumes (m³).
    /// Panics if a star holds more than 65,535 particles (no tetrahedral mesh comes near).
    pub(crate) fn new(tets: &[[u32; 4]], tet_rest_volume: &[Real], n: usize) -> Self {
        // Each particle's tetrahedra, and its corner among their four (slot 4 t + c).
        let (offsets, around) = crate::kernels::incidence::corners_around(tets, n);
        let rest_volume = (0..n)
            .map(|i| {
                let mine = &around[offsets[i] as usize..offsets[i + 1] as usize];
                mine.iter()
                    .fold(0.0, |v, &s| v + 0.25 * tet_rest_volume[s as usize / 4])
            })
            .collect();
        let mut opposite = vec![[0u16; 3]; around.len()];
        let mut star_offsets = Vec::with_capacity(n + 1);
        let mut star = Vec::new();
        star_offsets.push(0);
        for i in 0..n {
            let first = star.len();
            star.push(i as u32);
            for e in offsets[i] as usize..offsets[i + 1] as usize {
                let (t, c) = (around[e] / 4, around[e] as usize % 4);
                for (o, &k) in opposite[e].iter_mut().zip(&OTHERS[c]) {
                    let k = tets[t as usize][k];
                    let slot = match star[first..].iter().position(|&j| j == k) {
                        Some(s) => s,
                        None => {
                            star.push(k);
                            star.len() - 1 - first
                        }
                    };
                    *o = u16::try_from(slot).expect("a star of < 65,536");
                }
            }
            star_offsets.push(star.len() as u32);
        }
        let max_star = (0..n)
            .map(|i| (star_offsets[i + 1] - star_offsets[i]) as usize)
            .max()
            .unwrap_or(0);
        let mut cells = DualCells {
            offsets,
            opposite,
            star_offsets,
            star,
            rest_volume,
            max_star,
            order: Vec::new(),
            colour_starts: vec![0],
        };
        cells.colour();
        cells
    }
    /// The particles particle `i`'s cell volume depends on.
    pub(crate) fn star(&self, i: usize) -> &[u32] {
        &self.star[self.star_offsets[i] as usize..self.star_offsets[i + 1] as usize]
    }

    /// Rest volume (m³) of particle `i`'s cell; 0 for a particle in no tetrahedron (after a cut).
    pub(crate) fn rest_volume(&self, i: usize) -> Real {
        self.rest_volume[i]
    }

    /// Particles.
    pub(crate) fn len(&self) -> usize {
        self.rest_volume.len()
    }

    /// The most particles one cell's volume depends on.
    pub(crate) fn max_star(&self) -> usize {
        self.max_star
    }

    /// Heap bytes held.
    pub(crate) fn heap_bytes(&self) -> usize {
        use std::mem::size_of_val;
        size_of_val(self.offsets.as_slice())
            + size_of_val(self.opposite.as_slice())
            + size_of_val(self.star_offsets.as_slice())
            + size_of_val(self.star.as_slice())
            + size_of_val(self.rest_volume.as_slice())
            + size_of_val(self.order.as_slice())
            + size_of_val(self.colour_starts.as_slice())
    }

    /// The cells of each colour (particle indices, increasing), in colour order: no two cells
    /// of a colour have a particle in common in their stars, so a colour's constraints can be
    /// projected in any order, or at once. Every cell in at least one tetrahedron is in one
    /// colour; the others (rest volume 0) are in none. The position of a cell in the
    /// concatenation of the colours is its index in [`DualCells::projection_order`].
    pub(crate) fn colours(&self) -> impl Iterator<Item = std::ops::Range<usize>> + '_ {
        self.colour_starts
            .windows(2)
            .map(|w| w[0] as usize..w[1] as usize)
    }

    /// The cells, colour by colour (see [`DualCells::colours`]).
    pub(crate) fn projection_order(&self) -> &[u32] {
        &self.order
    }

    /// Colour the cells greedily, deterministically: the cells taken by decreasing star size
    /// (ties by index), each given the first colour that no cell already coloured with a
    /// particle in common with its star has, a new one if there is none. (Largest first needs
    /// the fewest colours of the orders tried: 31 on liver_4k, against 38 in index order and
    /// 37 choosing the least used colour instead of the first; the colours of the pass are
    /// split evenly over the threads whatever their sizes.) Two cells have a particle in common
    /// when one is within two edges of the other: the conflicts of `i` are the stars of the
    /// particles of `i`'s star (stars are symmetric: `k` is in `j`'s star if and only if `j`
    /// is in `k`'s).
    fn colour(&mut self) {
        let n = self.len();
        let mut cells: Vec<u32> = (0..n as u32)
            .filter(|&i| self.rest_volume[i as usize] > 0.0)
            .collect();
        cells.sort_by_key(|&i| (std::cmp::Reverse(self.star(i as usize).len()), i));
        const NONE: u32 = u32::MAX;
        let mut colour_of = vec![NONE; n];
        // Per colour, its number of cells and the last cell (plus one) it was forbidden to.
        let mut size: Vec<u32> = Vec::new();
        let mut forbidden: Vec<u32> = Vec::new();
        for &i in &cells {
            for &k in self.star(i as usize) {
                for &j in self.star(k as usize) {
                    let c = colour_of[j as usize];
                    if c != NONE {
                        forbidden[c as usize] = i + 1;
                    }
                }
            }
            let c = match (0..size.len()).find(|&c| forbidden[c] != i + 1) {
                Some(c) => c,
                None => {
                    size.push(0);
                    forbidden.push(0);
                    size.len() - 1
                }
            };
            size[c] += 1;
            colour_of[i as usize] = c as u32;
        }
        let mut starts = vec![0u32; size.len() + 1];
        for c in 0..size.len() {
            starts[c + 1] = starts[c] + size[c];
        }
        let mut next = starts.clone();
        let mut order = vec![0u32; cells.len()];
        for (i, &c) in colour_of.iter().enumerate().filter(|(_, &c)| c != NONE) {
            order[next[c as usize] as usize] = i as u32;
            next[c as usize] += 1;
        }
        self.order = order;
        self.colour_starts = starts;
    }

    /// Particle `i`'s cell volume (m³) at the positions `position(k)` (m) of its star's
    /// particles; its gradient (m²) with respect to each particle of [`DualCells::star`], in
    /// the star's order, goes to the first `star(i).len()` entries of `gradient`. `relative` is
    /// scratch for the star's positions relative to particle `i` (m). Both must hold at least
    /// the star ([`DualCells::max_star`] entries are always enough).
    pub(crate) fn volume_and_gradient(
        &self,
        i: usize,
        position: impl Fn(usize) -> Vec3,
        relative: &mut [Vec3],
        gradient: &mut [Vec3],
    ) -> Real {
        let star = self.star(i);
        let (relative, gradient) = (&mut relative[..star.len()], &mut gradient[..star.len()]);
        let centre = position(i);
        for (r, &k) in relative.iter_mut().zip(star) {
            *r = position(k as usize) - centre;
        }
        gradient.fill(Vec3::zeros());
        // Six times the volume of the cell's tetrahedra (24 times the cell's), and 24 times the
        // cell's gradient with respect to each particle but `i` (whose own is slot 0).
        let mut six_volume = 0.0;
        for &[b, c, d] in &self.opposite[self.offsets[i] as usize..self.offsets[i + 1] as usize] {
            let [b, c, d] = [b, c, d].map(usize::from);
            let (rb, rc, rd) = (relative[b], relative[c], relative[d]);
            let gb = rc.cross(&rd);
            six_volume += rb.dot(&gb);
            gradient[b] += gb;
            gradient[c] += rd.cross(&rb);
            gradient[d] += rb.cross(&rc);
        }
        // The volume does not change when the whole star moves: the gradients sum to zero.
        let (own, others) = gradient
            .split_first_mut()
            .expect("a star holds its particle");
        *own = -others.iter().sum::<Vec3>();
        gradient.iter_mut().for_each(|g| *g /= 24.0);
        six_volume / 24.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kernels::math::tet_volume;
    use crate::mesh::lattice_box;

    /// Two tetrahedra sharing a face; the cells' volumes sum to the mesh's, and each gradient
    /// matches central differences of the cell volume.
    #[test]
    fn cell_volumes_and_gradients() {
        let x = vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(0.0, 0.0, 1.0),
            Vec3::new(0.7, 0.8, 0.9),
        ];
        let tets = [[0, 1, 2, 3], [1, 2, 3, 4]];
        let vols: Vec<Real> = tets
            .iter()
            .map(|t| {
                let [a, b, c, d] = t.map(|k| x[k as usize]);
                tet_volume(&a, &b, &c, &d)
            })
            .collect();
        assert!(vols.iter().all(|v| *v > 0.0));
        let cells = DualCells::new(&tets, &vols, x.len());
        let total: Real = (0..5).map(|i| cells.rest_volume(i)).sum();
        assert!((total - vols.iter().sum::<Real>()).abs() < 1e-15);
        assert_eq!(cells.max_star(), 5);
        let (mut relative, mut gradient) = ([Vec3::zeros(); 5], [Vec3::zeros(); 5]);
        for i in 0..5 {
            let v = cells.volume_and_gradient(i, |k| x[k], &mut relative, &mut gradient);
            assert!((v - cells.rest_volume(i)).abs() < 1e-15);
            for (&k, &g) in cells.star(i).iter().zip(gradient.clone().iter()) {
                for axis in 0..3 {
                    let eps = 1e-6;
                    let mut xp = x.clone();
                    xp[k as usize][axis] += eps;
                    let mut xm = x.clone();
                    xm[k as usize][axis] -= eps;
                    let mut s = [Vec3::zeros(); 5];
                    let fd = (cells.volume_and_gradient(i, |k| xp[k], &mut relative, &mut s)
                        - cells.volume_and_gradient(i, |k| xm[k], &mut relative, &mut s))
                        / (2.0 * eps);
                    assert!((fd - g[axis]).abs() < 1e-9, "cell {i} node {k} axis {axis}");
                }
            }
        }
    }

    /// The colouring of a lattice box with one particle left out of every tetrahedron (as a
    /// cut leaves it): every cell of positive rest volume once, none other, increasing within
    /// a colour, no two cells of a colour with a particle in common, and a few tens of colours.
    #[test]
    fn cells_of_one_colour_share_no_particle() {
        let mesh = lattice_box(Vec3::zeros(), Vec3::repeat(1.0), [8, 7, 6]);
        let lone = mesh.tets[0][0];
        let tets: Vec<[u32; 4]> = mesh
            .tets
            .iter()
            .copied()
            .filter(|t| !t.contains(&lone))
            .collect();
        let cells = DualCells::new(&tets, &vec![1.0; tets.len()], mesh.nodes.len());
        let mut seen = vec![0; cells.len()];
        for colour in cells.colours() {
            let members = &cells.projection_order()[colour];
            assert!(members.windows(2).all(|w| w[0] < w[1]));
            let mut taken = vec![false; cells.len()];
            for &i in members {
                seen[i as usize] += 1;
                for &k in cells.star(i as usize) {
                    assert!(!taken[k as usize], "particle {k} in two stars of a colour");
                    taken[k as usize] = true;
                }
            }
        }
        for (i, &n) in seen.iter().enumerate() {
            assert_eq!(n, usize::from(cells.rest_volume(i) > 0.0), "cell {i}");
        }
        assert_eq!(cells.rest_volume(lone as usize), 0.0);
        let colours = cells.colours().count();
        assert!((10..=40).contains(&colours), "{colours} colours");
    }
}
