//! The dual cell of each particle: a quarter of every tetrahedron around it. Its volume
//! `V_i(x) = ¼ Σ_{t∋i} vol_t(x)` is what one volume constraint per particle keeps
//! ([`VolumeScheme::DualCells`](crate::VolumeScheme::DualCells)): about one constraint per three
//! unknowns, against six per three for one constraint per tetrahedron, so the discretisation
//! does not lock as ν → 0.5 (the average nodal pressure tetrahedron of Bonet & Burton 1998,
//! solved as XPBD constraints).

use crate::kernels::lanes::F4;
use crate::kernels::math::{Real, Vec3};

/// For the tetrahedron corner at position `c` (0..4) of its four, the other three corners in an
/// order that, put after it, is an even permutation of the four: the tetrahedron's volume is
/// then `r_b · (r_c × r_d) / 6` with `r_k` corner k's position relative to corner `c`.
const OTHERS: [[usize; 3]; 4] = [[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]];

/// One face of the cell's tetrahedra through its particle `i`, as star slots `[c, d, plus,
/// minus]` (`c < d`): with `r_k` slot k's position relative to `i` (m), the face's
/// `r_c × r_d` (m²) is 6 times the gradient of the volume of the tetrahedron on it with apex
/// `plus`, with respect to `plus`, and −6 times that of the one with apex `minus`. A face with
/// a tetrahedron on one side only has slot 0 (the particle itself) for the other apex: the
/// particle's own gradient is not accumulated face by face but is the negated sum of the
/// others', so what goes to slot 0 is never read.
type Face = [u16; 4];

/// The cells (one per particle in tetrahedra of positive rest volume) in projection order,
/// colour by colour (see [`DualCells::colours`]), with what each cell's constraint reads
/// stored in that order, so that a colour's pass streams through memory: the cell's rest
/// volume (m³), its "star" (the particles its tetrahedra hold, its own particle first) and the
/// faces of its tetrahedra through its particle, as star slots ([`Face`]).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct DualCells {
    /// Where each colour starts in the projection order, then the number of cells.
    colour_starts: Vec<u32>,
    /// Rest volume of each cell (m³).
    rest_volume: Vec<Real>,
    /// Where each cell's star starts in `star`, then `star.len()`.
    star_offsets: Vec<u32>,
    star: Vec<u32>,
    /// Where each cell's faces start in `faces`, then `faces.len()`.
    face_offsets: Vec<u32>,
    faces: Vec<Face>,
    /// The most particles in one star (the size of a projection's scratch).
    max_star: usize,
}

/// One star slot of a cell's volume and gradient ([`DualCells::volume_and_gradient`]): the
/// slot's position relative to the cell's particle (m) in the lanes x, y, z, with the slot
/// particle's inverse mass (1/kg) in the fourth; the same position rotated to y, z, x and to
/// z, x, y (so that a cross product is two products of lanes); and 24 times the gradient of
/// the cell's volume with respect to it (m²) in the lanes x, y, z. The other fourth lanes are
/// 0. (Four lanes a field, 128 bytes a slot: a slot's address is its index shifted.)
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(crate) struct CellSlot {
    xyz_w: F4,
    yzx: F4,
    zxy: F4,
    gradient_24: F4,
}

impl CellSlot {
    /// 24 times the cell volume's gradient with respect to this slot's particle (m²).
    #[inline(always)]
    pub(crate) fn gradient_24(&self) -> Vec3 {
        let [x, y, z, _] = self.gradient_24.to_array();
        Vec3::new(x, y, z)
    }

    /// The slot particle's inverse mass (1/kg).
    #[inline(always)]
    pub(crate) fn inverse_mass(&self) -> Real {
        self.xyz_w.to_array()[3]
    }
}

/// A cell's volume and its constraint's weight in a projection.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct CellVolume {
    /// The cell's volume (m³).
    pub(crate) volume: Real,
    /// `Σ_k w_k |∇_k V|²` over the star (m⁶/kg), `w_k` the inverse masses.
    pub(crate) weight: Real,
}

impl DualCells {
    /// The cells of `n` particles from the tetrahedra `tets` and their rest volumes (m³).
    /// Panics if a star holds more than 65,535 particles (no tetrahedral mesh comes near).
    pub(crate) fn new(tets: &[[u32; 4]], tet_rest_volume: &[Real], n: usize) -> Self {
        // Each particle's tetrahedra, and its corner among their four (slot 4 t + c).
        let (offsets, around) = crate::kernels::incidence::corners_around(tets, n);
        let rest_volume: Vec<Real> = (0..n)
            .map(|i| {
                let mine = &around[offsets[i] as usize..offsets[i + 1] as usize];
                mine.iter()
                    .fold(0.0, |v, &s| v + 0.25 * tet_rest_volume[s as usize / 4])
            })
            .collect();
        // By particle: its star, and each tetrahedron around it as the star slots of its other
        // three corners, in the order of `OTHERS` (the tetrahedron's volume is
        // `r_b · (r_c × r_d) / 6`).
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
        let star_of = |i: usize| &star[star_offsets[i] as usize..star_offsets[i + 1] as usize];
        let max_star = (0..n).map(|i| star_of(i).len()).max().unwrap_or(0);
        let (order, colour_starts) = colour(n, &rest_volume, star_of);
        // The cells' data in projection order.
        let mut cells = DualCells {
            colour_starts,
            rest_volume: order.iter().map(|&i| rest_volume[i as usize]).collect(),
            star_offsets: vec![0],
            star: Vec::with_capacity(star.len()),
            face_offsets: vec![0],
            faces: Vec::new(),
            max_star,
        };
        let mut sides = Vec::new();
        for i in order.into_iter().map(|i| i as usize) {
            cells.star.extend_from_slice(star_of(i));
            cells.star_offsets.push(cells.star.len() as u32);
            // Per tetrahedron (volume `r_b · (r_c × r_d) / 6`), its three faces through `i`
            // and the apex opposite each: b gets r_c × r_d, c gets r_d × r_b, d r_b × r_c.
            sides.clear();
            for &[b, c, d] in &opposite[offsets[i] as usize..offsets[i + 1] as usize] {
                for (apex, c, d) in [(b, c, d), (c, d, b), (d, b, c)] {
                    sides.push((c.min(d), c.max(d), c > d, apex));
                }
            }
            faces_of(&mut sides, &mut cells.faces);
            cells.face_offsets.push(cells.faces.len() as u32);
        }
        cells
    }

    /// Cells: the particles in tetrahedra of positive rest volume.
    pub(crate) fn len(&self) -> usize {
        self.rest_volume.len()
    }

    /// Cell `c`'s particle.
    #[cfg(test)]
    pub(crate) fn particle(&self, c: usize) -> usize {
        self.star(c)[0] as usize
    }

    /// The particles cell `c`'s volume depends on, its own first.
    pub(crate) fn star(&self, c: usize) -> &[u32] {
        &self.star[self.star_offsets[c] as usize..self.star_offsets[c + 1] as usize]
    }

    /// Rest volume of cell `c` (m³).
    pub(crate) fn rest_volume(&self, c: usize) -> Real {
        self.rest_volume[c]
    }

    /// The most particles one cell's volume depends on.
    pub(crate) fn max_star(&self) -> usize {
        self.max_star
    }

    /// Heap bytes held.
    pub(crate) fn heap_bytes(&self) -> usize {
        use std::mem::size_of_val;
        size_of_val(self.colour_starts.as_slice())
            + size_of_val(self.rest_volume.as_slice())
            + size_of_val(self.star_offsets.as_slice())
            + size_of_val(self.star.as_slice())
            + size_of_val(self.face_offsets.as_slice())
            + size_of_val(self.faces.as_slice())
    }

    /// The cells of each colour, in colour order, as ranges of the projection order (cell
    /// indices): no two cells of a colour have a particle in common in their stars, so a
    /// colour's constraints can be projected in any order, or at once. Within a colour the
    /// cells' particles increase. Every particle in tetrahedra of positive rest volume has one
    /// cell; the others (after a cut) have none.
    pub(crate) fn colours(&self) -> impl Iterator<Item = std::ops::Range<usize>> + '_ {
        self.colour_starts
            .windows(2)
            .map(|w| w[0] as usize..w[1] as usize)
    }

    /// Cell `c`'s volume (m³) and the weight of its constraint, at the positions and inverse
    /// masses `particle(k)` (m, 1/kg) of its star's particles. The cell volume's gradient
    /// (m²) with respect to each particle of [`DualCells::star`], and its inverse mass, go to
    /// the first `star(c).len()` entries of `slots`, in the star's order (`slots` must hold
    /// the star: [`DualCells::max_star`] entries always do).
    ///
    /// Each face through the cell's particle is one cross product of lanes, added to the
    /// gradient of the apex on one side and subtracted from the other's (the faces' products
    /// are a tetrahedron's gradients, each shared by the two tetrahedra on the face). The
    /// particle's own gradient is the negated sum of the others' (the volume does not change
    /// when the whole star moves), and the volume is `Σ_k r_k · ∇_k V / 3` over the star
    /// (Euler's theorem: `V` is a cubic form of the relative positions `r_k`).
    #[inline]
    pub(crate) fn volume_and_gradient(
        &self,
        c: usize,
        particle: impl Fn(usize) -> (Vec3, Real),
        slots: &mut [CellSlot],
    ) -> CellVolume {
        let star = self.star(c);
        let slots = &mut slots[..star.len()];
        let lanes = |(x, w): (Vec3, Real)| F4::new([x.x, x.y, x.z, w]);
        let centre = lanes((particle(star[0] as usize).0, 0.0));
        for (slot, &k) in slots.iter_mut().zip(star) {
            let xyz_w = lanes(particle(k as usize)) - centre;
            // The relative position alone, the fourth lane 0 (the inverse mass is finite).
            let r = xyz_w * F4::new([1.0, 1.0, 1.0, 0.0]);
            *slot = CellSlot {
                xyz_w,
                yzx: r.rotate_yzx(),
                zxy: r.rotate_zxy(),
                gradient_24: F4::splat(0.0),
            };
        }
        let faces = &self.faces[self.face_offsets[c] as usize..self.face_offsets[c + 1] as usize];
        // SAFETY (the face loop's accesses): every slot of a cell's faces is below its star's
        // length (as `new` makes them), which is that of `slots` (checked when it was cut to
        // it above); no reference into `slots` is held across them.
        let slot = slots.as_mut_ptr();
        for &[c, d, plus, minus] in faces {
            let [c, d, plus, minus] =
                [c, d, plus, minus].map(|k| unsafe { slot.add(usize::from(k)) });
            // r_c × r_d, lane-wise: (y z, z x, x y) − (z y, x z, y x).
            let face = unsafe { (*c).yzx.mul_sub((*d).zxy, (*c).zxy * (*d).yzx) };
            unsafe {
                (*plus).gradient_24 += face;
                (*minus).gradient_24 = (*minus).gradient_24 - face;
            }
        }
        let (own, others) = slots.split_first_mut().expect("a star holds its particle");
        // Two of each sum, the even slots' and the odd ones', which do not wait on each other.
        let zero = F4::splat(0.0);
        let (mut sum, mut volume_72, mut weight_576) = ([zero; 2], [zero; 2], [zero; 2]);
        for pair in others.chunks(2) {
            for (h, slot) in pair.iter().enumerate() {
                let g = slot.gradient_24;
                sum[h] += g;
                // The fourth lanes: the inverse mass times 0.
                volume_72[h] = slot.xyz_w.mul_add(g, volume_72[h]);
                weight_576[h] = (g * g).mul_add(F4::splat(slot.inverse_mass()), weight_576[h]);
            }
        }
        let sum = sum[0] + sum[1];
        own.gradient_24 = -sum;
        let weight_576 =
            (sum * sum).mul_add(F4::splat(own.inverse_mass()), weight_576[0] + weight_576[1]);
        CellVolume {
            volume: (volume_72[0] + volume_72[1]).sum() * (1.0 / 72.0),
            weight: weight_576.sum() * (1.0 / 576.0),
        }
    }
}

/// The faces through a cell's particle of its tetrahedra, from the tetrahedra's `sides`: each
/// `(c, d, negated, apex)` (star slots, `c < d`) says that `r_c × r_d`, negated if `negated`,
/// is 6 times the gradient of a tetrahedron's volume with respect to its apex. Appended to
/// `faces` by increasing slot pair, the sides on one face paired as they come, one of each
/// orientation a [`Face`] (two in a consistently oriented mesh, one on its boundary); `sides`
/// is sorted.
fn faces_of(sides: &mut [(u16, u16, bool, u16)], faces: &mut Vec<Face>) {
    sides.sort_unstable();
    let mut rest = &sides[..];
    while let Some(&(c, d, _, _)) = rest.first() {
        let on_face = rest.iter().take_while(|s| (s.0, s.1) == (c, d)).count();
        let (face, tail) = rest.split_at(on_face);
        rest = tail;
        let (plus, minus) = face.split_at(face.iter().filter(|s| !s.2).count());
        for k in 0..plus.len().max(minus.len()) {
            let apex = |of: &[(u16, u16, bool, u16)]| of.get(k).map_or(0, |s| s.3);
            faces.push([c, d, apex(plus), apex(minus)]);
        }
    }
}

/// The cells in projection order and where each colour starts in it, then its length: the
/// particles in a tetrahedron of positive rest volume (`rest_volume`, m³) coloured greedily,
/// deterministically. The cells are taken by decreasing star size (ties by index), each given
/// the first colour that no cell already coloured with a particle in common with its star has,
/// a new one if there is none. (Largest first needs the fewest colours of the orders tried: 31
/// on liver_4k, against 38 in index order and 37 choosing the least used colour instead of
/// the first; the colours of the pass are split evenly over the threads whatever their sizes.)
/// Two cells have a particle in common when one is within two edges of the other: the
/// conflicts of `i` are the stars of the particles of `i`'s star (`star_of(i)`; stars are
/// symmetric: `k` is in `j`'s star if and only if `j` is in `k`'s).
fn colour<'a>(
    n: usize,
    rest_volume: &[Real],
    star_of: impl Fn(usize) -> &'a [u32],
) -> (Vec<u32>, Vec<u32>) {
    let mut cells: Vec<u32> = (0..n as u32)
        .filter(|&i| rest_volume[i as usize] > 0.0)
        .collect();
    cells.sort_by_key(|&i| (std::cmp::Reverse(star_of(i as usize).len()), i));
    const NONE: u32 = u32::MAX;
    let mut colour_of = vec![NONE; n];
    // Per colour, its number of cells and the last cell (plus one) it was forbidden to.
    let mut size: Vec<u32> = Vec::new();
    let mut forbidden: Vec<u32> = Vec::new();
    for &i in &cells {
        for &k in star_of(i as usize) {
            for &j in star_of(k as usize) {
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
    (order, starts)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kernels::math::{tet_volume, tet_volume_gradient};
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
        assert_eq!(cells.len(), 5);
        let total: Real = (0..5).map(|c| cells.rest_volume(c)).sum();
        assert!((total - vols.iter().sum::<Real>()).abs() < 1e-15);
        assert_eq!(cells.max_star(), 5);
        let mut slots = [CellSlot::default(); 5];
        for c in 0..5 {
            let v = cells
                .volume_and_gradient(c, |k| (x[k], 1.0), &mut slots)
                .volume;
            assert!((v - cells.rest_volume(c)).abs() < 1e-15);
            let star = cells.star(c);
            assert_eq!(star[0] as usize, cells.particle(c));
            for (&k, slot) in star.iter().zip(slots) {
                for axis in 0..3 {
                    let eps = 1e-6;
                    let mut xp = x.clone();
                    xp[k as usize][axis] += eps;
                    let mut xm = x.clone();
                    xm[k as usize][axis] -= eps;
                    let mut s = [CellSlot::default(); 5];
                    let fd = (cells
                        .volume_and_gradient(c, |k| (xp[k], 1.0), &mut s)
                        .volume
                        - cells
                            .volume_and_gradient(c, |k| (xm[k], 1.0), &mut s)
                            .volume)
                        / (2.0 * eps);
                    let g = slot.gradient_24() / 24.0;
                    assert!((fd - g[axis]).abs() < 1e-9, "cell {c} node {k} axis {axis}");
                }
            }
        }
    }

    /// A lattice box, its nodes moved off the lattice and one tetrahedron left out (a hole
    /// with faces on one side only inside the mesh): every cell's volume and gradient are a
    /// quarter of the sums of its tetrahedra's.
    #[test]
    fn cells_are_quarters_of_their_tetrahedra() {
        let mesh = lattice_box(Vec3::zeros(), Vec3::repeat(1.0), [4, 3, 5]);
        let tets: Vec<[u32; 4]> = mesh.tets[1..].to_vec();
        let x: Vec<Vec3> = mesh
            .nodes
            .iter()
            .enumerate()
            .map(|(i, p)| {
                let s = i as Real;
                p + 0.03 * Vec3::new((1.3 * s).sin(), (2.1 * s).cos(), (0.7 * s).sin())
            })
            .collect();
        let corners = |t: &[u32; 4]| t.map(|k| x[k as usize]);
        let cells = DualCells::new(&tets, &vec![1.0; tets.len()], x.len());
        let mut slots = vec![CellSlot::default(); cells.max_star()];
        for c in 0..cells.len() {
            let i = cells.particle(c);
            let (mut volume, mut gradient) = (0.0, vec![Vec3::zeros(); x.len()]);
            for t in tets.iter().filter(|t| t.contains(&(i as u32))) {
                let [a, b, cc, d] = corners(t);
                volume += tet_volume(&a, &b, &cc, &d) / 4.0;
                for (&k, g) in t.iter().zip(tet_volume_gradient(&a, &b, &cc, &d)) {
                    gradient[k as usize] += g / 4.0;
                }
            }
            let v = cells
                .volume_and_gradient(c, |k| (x[k], 1.0), &mut slots)
                .volume;
            assert!((v - volume).abs() < 1e-14, "cell {c}: {v} against {volume}");
            let star = cells.star(c);
            for (&k, slot) in star.iter().zip(&slots) {
                let error = (slot.gradient_24() / 24.0 - gradient[k as usize]).norm();
                assert!(error < 1e-14, "cell {c} node {k}: {error}");
            }
            let in_star = |k: usize| star.contains(&(k as u32));
            assert!((0..x.len()).all(|k| in_star(k) || gradient[k] == Vec3::zeros()));
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
        let n = mesh.nodes.len();
        let cells = DualCells::new(&tets, &vec![1.0; tets.len()], n);
        let mut seen = vec![0; n];
        for colour in cells.colours() {
            let particles: Vec<usize> = colour.clone().map(|c| cells.particle(c)).collect();
            assert!(particles.windows(2).all(|w| w[0] < w[1]));
            let mut taken = vec![false; n];
            for c in colour {
                seen[cells.particle(c)] += 1;
                for &k in cells.star(c) {
                    assert!(!taken[k as usize], "particle {k} in two stars of a colour");
                    taken[k as usize] = true;
                }
            }
        }
        for (i, &count) in seen.iter().enumerate() {
            let in_a_tet = tets.iter().any(|t| t.contains(&(i as u32)));
            assert_eq!(count, usize::from(in_a_tet), "particle {i}");
        }
        assert_eq!(seen[lone as usize], 0);
        let colours = cells.colours().count();
        assert!((10..=40).contains(&colours), "{colours} colours");
    }
}
