//! Regular lattices of cubes split into tetrahedra (Kuhn/Freudenthal split: six tetrahedra
//! per cell around the cell's main diagonal, the same split in every cell so that the faces of
//! neighbouring cells match).

use super::TetMesh;
use crate::kernels::math::{tet_volume, Vec3};

/// The six Kuhn tetrahedra of a unit cell, as corner indices `i + 2j + 4k` for the corner at
/// `(i, j, k) ∈ {0,1}³`. Each walks from corner 0 to corner 7 along the three axes in one of the
/// six orders; all are positively oriented.
pub(crate) const KUHN_TETS: [[usize; 4]; 6] = kuhn_tets();

const fn kuhn_tets() -> [[usize; 4]; 6] {
    // Axis bits: x = 1, y = 2, z = 4. Each permutation of the axes gives a path 0 → 7.
    let perms: [[usize; 3]; 6] = [
        [1, 2, 4],
        [1, 4, 2],
        [2, 1, 4],
        [2, 4, 1],
        [4, 1, 2],
        [4, 2, 1],
    ];
    // Even permutations of (x, y, z) give positive orientation with the order 0, a, a+b, 7;
    // odd ones need two nodes swapped.
    let even = [true, false, false, true, true, false];
    let mut out = [[0usize; 4]; 6];
    let mut k = 0;
    while k < 6 {
        let p = perms[k];
        let a = p[0];
        let b = p[0] + p[1];
        out[k] = if even[k] { [0, a, b, 7] } else { [0, b, a, 7] };
        k += 1;
    }
    out
}

/// A box `[min, max]` (m) filled with a regular lattice of `cells[0] × cells[1] × cells[2]`
/// cells, each split into six positively oriented tetrahedra (Kuhn split, conforming across
/// cells). Node `(i, j, k)`, `0 ≤ i ≤ cells[0]` etc., has index `i + (cells[0]+1)(j +
/// (cells[1]+1) k)`. A cell count of 0 is treated as 1; `min` must be below `max` on every axis
/// for the tetrahedra to have positive volume.
pub fn lattice_box(min: Vec3, max: Vec3, cells: [usize; 3]) -> TetMesh {
    let [nx, ny, nz] = cells.map(|c| c.max(1));
    let step = Vec3::new(
        (max.x - min.x) / nx as f64,
        (max.y - min.y) / ny as f64,
        (max.z - min.z) / nz as f64,
    );
    let (px, py) = (nx + 1, ny + 1);
    let index = |i: usize, j: usize, k: usize| (i + px * (j + py * k)) as u32;
    let mut nodes = Vec::with_capacity(px * py * (nz + 1));
    for k in 0..=nz {
        for j in 0..=ny {
            for i in 0..=nx {
                // Exact end values so that the box is not shrunk by rounding.
                let coord = |c: usize, n: usize, lo: f64, hi: f64, s: f64| {
                    if c == n {
                        hi
                    } else {
                        lo + c as f64 * s
                    }
                };
                nodes.push(Vec3::new(
                    coord(i, nx, min.x, max.x, step.x),
                    coord(j, ny, min.y, max.y, step.y),
                    coord(k, nz, min.z, max.z, step.z),
                ));
            }
        }
    }
    let mut tets = Vec::with_capacity(6 * nx * ny * nz);
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                let corner = |c: usize| index(i + (c & 1), j + ((c >> 1) & 1), k + ((c >> 2) & 1));
                for t in KUHN_TETS {
                    tets.push(t.map(corner));
                }
            }
        }
    }
    // A box given with max < min on an odd number of axes mirrors the lattice: keep every
    // tetrahedron positively oriented anyway.
    for t in &mut tets {
        let p = |c: usize| &nodes[t[c] as usize];
        if tet_volume(p(0), p(1), p(2), p(3)) < 0.0 {
            t.swap(2, 3);
        }
    }
    TetMesh { nodes, tets }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kuhn_tets_are_positive_and_fill_the_cell() {
        let corner =
            |c: usize| Vec3::new((c & 1) as f64, ((c >> 1) & 1) as f64, ((c >> 2) & 1) as f64);
        let mut total = 0.0;
        for t in KUHN_TETS {
            let v = tet_volume(&corner(t[0]), &corner(t[1]), &corner(t[2]), &corner(t[3]));
            assert!((v - 1.0 / 6.0).abs() < 1e-12, "{t:?} {v}");
            total += v;
        }
        assert!((total - 1.0).abs() < 1e-12);
    }

    #[test]
    fn box_counts() {
        let m = lattice_box(Vec3::zeros(), Vec3::new(2.0, 1.0, 1.0), [4, 2, 3]);
        assert_eq!(m.nodes.len(), 5 * 3 * 4);
        assert_eq!(m.tets.len(), 6 * 4 * 2 * 3);
    }
}
