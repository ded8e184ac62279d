//! The dual cell of each particle: a quarter of every tetrahedron around it. Its volume
//! `V_i(x) = ¼ Σ_{t∋i} vol_t(x)` is what one volume constraint per particle keeps
//! ([`VolumeScheme::DualCells`](crate::VolumeScheme::DualCells)): about one constraint per three
//! unknowns, against six per three for one constraint per tetrahedron, so the discretisation
//! does not lock as ν → 0.5 (the average nodal pressure tetrahedron of Bonet & Burton 1998,
//! solved as XPBD constraints).

use crate::math::{tet_volume, tet_volume_gradient, Real, Vec3};

/// For every particle, the tetrahedra around it and the particles they hold (its "star"),
/// in compressed rows, each tetrahedron corner's slot in the star, and the cell's rest volume
/// (m³).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct DualCells {
    offsets: Vec<u32>,
    tets: Vec<u32>,
    /// For the k-th tetrahedron of particle `i`'s row, `corner_slot[4 (offsets[i] + k) + c]`
    /// is corner `c`'s position in `i`'s star.
    corner_slot: Vec<u16>,
    star_offsets: Vec<u32>,
    star: Vec<u32>,
    rest_volume: Vec<Real>,
    /// The most particles in one star (the size of a projection's scratch).
    max_star: usize,
}

impl DualCells {
    /// The cells of `n` particles from the tetrahedra `tets` and their rest volumes (m³).
    /// Panics if a star holds more than 65,535 particles (no tetrahedral mesh comes near).
    pub(crate) fn new(tets: &[[u32; 4]], tet_rest_volume: &[Real], n: usize) -> Self {
        let mut count = vec![0u32; n + 1];
        for tet in tets {
            tet.iter().for_each(|&k| count[k as usize + 1] += 1);
        }
        for i in 0..n {
            count[i + 1] += count[i];
        }
        let offsets = count.clone();
        let mut next = count;
        let mut around = vec![0u32; offsets[n] as usize];
        let mut rest_volume = vec![0.0; n];
        for (t, tet) in tets.iter().enumerate() {
            for &k in tet {
                around[next[k as usize] as usize] = t as u32;
                next[k as usize] += 1;
                rest_volume[k as usize] += 0.25 * tet_rest_volume[t];
            }
        }
        let mut corner_slot = vec![0u16; 4 * around.len()];
        let mut star_offsets = Vec::with_capacity(n + 1);
        let mut star = Vec::new();
        star_offsets.push(0);
        for i in 0..n {
            let first = star.len();
            for e in offsets[i] as usize..offsets[i + 1] as usize {
                for (c, &k) in tets[around[e] as usize].iter().enumerate() {
                    let slot = match star[first..].iter().position(|&j| j == k) {
                        Some(s) => s,
                        None => {
                            star.push(k);
                            star.len() - 1 - first
                        }
                    };
                    corner_slot[4 * e + c] = u16::try_from(slot).expect("a star of < 65,536");
                }
            }
            star_offsets.push(star.len() as u32);
        }
        let max_star = (0..n)
            .map(|i| (star_offsets[i + 1] - star_offsets[i]) as usize)
            .max()
            .unwrap_or(0);
        DualCells {
            offsets,
            tets: around,
            corner_slot,
            star_offsets,
            star,
            rest_volume,
            max_star,
        }
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
        4 * (self.offsets.capacity()
            + self.tets.capacity()
            + self.star_offsets.capacity()
            + self.star.capacity())
            + 2 * self.corner_slot.capacity()
            + 8 * self.rest_volume.capacity()
    }

    /// Particle `i`'s cell volume (m³) at positions `x` (m); its gradient (m²) with respect to
    /// each particle of [`DualCells::star`] goes to `gradient`, in the star's order (resized
    /// to it: no allocation once its capacity is [`DualCells::max_star`]).
    pub(crate) fn volume_and_gradient(
        &self,
        i: usize,
        tets: &[[u32; 4]],
        x: &[Vec3],
        gradient: &mut Vec<Vec3>,
    ) -> Real {
        gradient.clear();
        gradient.resize(self.star(i).len(), Vec3::zeros());
        let mut volume = 0.0;
        for e in self.offsets[i] as usize..self.offsets[i + 1] as usize {
            let tet = tets[self.tets[e] as usize];
            let [a, b, c, d] = tet.map(|k| x[k as usize]);
            // A quarter of the tetrahedron: its volume and its gradient.
            volume += 0.25 * tet_volume(&a, &b, &c, &d);
            let slots = &self.corner_slot[4 * e..4 * e + 4];
            for (slot, g) in slots.iter().zip(tet_volume_gradient(&a, &b, &c, &d)) {
                gradient[*slot as usize] += g * 0.25;
            }
        }
        volume
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
        let mut gradient = Vec::new();
        for i in 0..5 {
            let v = cells.volume_and_gradient(i, &tets, &x, &mut gradient);
            assert!((v - cells.rest_volume(i)).abs() < 1e-15);
            for (&k, &g) in cells.star(i).iter().zip(gradient.clone().iter()) {
                for axis in 0..3 {
                    let eps = 1e-6;
                    let mut xp = x.clone();
                    xp[k as usize][axis] += eps;
                    let mut xm = x.clone();
                    xm[k as usize][axis] -= eps;
                    let mut s = Vec::new();
                    let fd = (cells.volume_and_gradient(i, &tets, &xp, &mut s)
                        - cells.volume_and_gradient(i, &tets, &xm, &mut s))
                        / (2.0 * eps);
                    assert!((fd - g[axis]).abs() < 1e-9, "cell {i} node {k} axis {axis}");
                }
            }
        }
    }
}
