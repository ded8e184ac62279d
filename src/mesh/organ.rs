//! The embedded default organ: a liver-like lobed solid defined by an implicit function (a
//! smooth union of ellipsoids), tetrahedralised by a Kuhn-split lattice of cubes whose boundary
//! nodes are then pulled onto the implicit surface.
//!
//! Everything here is deterministic: fixed constants, fixed iteration orders, no hashing.

use super::lattice::KUHN_TETS;
use super::TetMesh;
use crate::kernels::math::{tet_volume, Real, Vec3};
use std::path::Path;

/// Edge length of the lattice cells of the default organ (m).
pub(crate) const DEFAULT_CELL: Real = 0.0095;
/// Lower corner of the lattice (m); it covers the whole implicit solid.
const GRID_MIN: [Real; 3] = [-0.125, -0.085, -0.095];
/// Extent of the lattice along x, y, z (m): 27, 18 and 20 cells of the default size.
const GRID_EXTENT: [Real; 3] = [0.2565, 0.171, 0.19];

/// Number of lattice cells along x, y, z for cells of edge `cell` (m): enough to cover
/// [`GRID_EXTENT`] (27 × 18 × 20 at the default size).
fn grid_cells(cell: Real) -> [usize; 3] {
    GRID_EXTENT.map(|e| ((e / cell) - 1e-6).ceil().max(1.0) as usize)
}
/// Passes of boundary-node snapping.
const SNAP_PASSES: usize = 8;
/// A snapping move is rejected if a tetrahedron would fall below this fraction of its lattice
/// volume.
const MIN_VOLUME_FRACTION: Real = 0.15;

/// An ellipsoid lobe: centre (m) and semi-axes (m).
struct Lobe {
    centre: [Real; 3],
    radii: [Real; 3],
}

/// The lobes of the organ, in the frame x (left–right), y (up), z (front–back).
const LOBES: [Lobe; 4] = [
    // Right lobe: the bulk of the organ.
    Lobe {
        centre: [0.035, 0.0, 0.0],
        radii: [0.068, 0.058, 0.068],
    },
    // Left lobe: thinner, tapering to the left.
    Lobe {
        centre: [-0.05, 0.012, 0.008],
        radii: [0.058, 0.03, 0.048],
    },
    // Caudate lobe: a bump at the back of the underside.
    Lobe {
        centre: [0.0, -0.022, -0.035],
        radii: [0.03, 0.026, 0.026],
    },
    // Quadrate lobe: a bump at the front of the underside.
    Lobe {
        centre: [0.0, -0.018, 0.038],
        radii: [0.028, 0.022, 0.024],
    },
];

/// Blending width of the smooth union (m).
const BLEND: Real = 0.02;

/// Approximate signed distance (m) of an ellipsoid: negative inside.
fn lobe_distance(l: &Lobe, p: &Vec3) -> Real {
    let q = Vec3::new(
        (p.x - l.centre[0]) / l.radii[0],
        (p.y - l.centre[1]) / l.radii[1],
        (p.z - l.centre[2]) / l.radii[2],
    );
    let rmin = l.radii[0].min(l.radii[1]).min(l.radii[2]);
    (q.norm() - 1.0) * rmin
}

/// Polynomial smooth minimum of width `k`.
fn smooth_min(a: Real, b: Real, k: Real) -> Real {
    let h = (k - (a - b).abs()).max(0.0) / k;
    a.min(b) - h * h * k * 0.25
}

/// The implicit function of the organ (m, approximately a signed distance): negative inside.
pub(crate) fn organ_field(p: &Vec3) -> Real {
    let mut f = lobe_distance(&LOBES[0], p);
    for l in &LOBES[1..] {
        f = smooth_min(f, lobe_distance(l, p), BLEND);
    }
    // A notch between the lobes on the front edge (the falciform ligament's groove).
    let notch = (Vec3::new(p.x + 0.008, (p.y - 0.02) * 0.8, p.z - 0.075)).norm() - 0.018;
    // Flatten the underside a little: the visceral surface.
    let floor = -0.045 - p.y + 0.15 * p.x.max(0.0);
    f.max(-notch).max(floor)
}

/// Numerical gradient of [`organ_field`].
fn organ_gradient(p: &Vec3) -> Vec3 {
    let e = 1e-5;
    let d = |v: Vec3| (organ_field(&(p + v)) - organ_field(&(p - v))) / (2.0 * e);
    Vec3::new(
        d(Vec3::new(e, 0.0, 0.0)),
        d(Vec3::new(0.0, e, 0.0)),
        d(Vec3::new(0.0, 0.0, e)),
    )
}

/// Which lattice cells belong to the organ: centre inside the implicit solid, then small
/// clean-ups so that the cell set is one face-connected piece without edge-only contacts.
fn organ_cells(cell: Real) -> Vec<bool> {
    let [nx, ny, nz] = grid_cells(cell);
    let idx = |i: usize, j: usize, k: usize| i + nx * (j + ny * k);
    let centre = |i: usize, j: usize, k: usize| {
        Vec3::new(
            GRID_MIN[0] + (i as Real + 0.5) * cell,
            GRID_MIN[1] + (j as Real + 0.5) * cell,
            GRID_MIN[2] + (k as Real + 0.5) * cell,
        )
    };
    let mut full = vec![false; nx * ny * nz];
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                full[idx(i, j, k)] = organ_field(&centre(i, j, k)) < 0.0;
            }
        }
    }
    let neighbours = |i: usize, j: usize, k: usize| {
        let mut out = Vec::with_capacity(6);
        if i > 0 {
            out.push(idx(i - 1, j, k));
        }
        if i + 1 < nx {
            out.push(idx(i + 1, j, k));
        }
        if j > 0 {
            out.push(idx(i, j - 1, k));
        }
        if j + 1 < ny {
            out.push(idx(i, j + 1, k));
        }
        if k > 0 {
            out.push(idx(i, j, k - 1));
        }
        if k + 1 < nz {
            out.push(idx(i, j, k + 1));
        }
        out
    };
    for _ in 0..4 {
        let mut changed = false;
        // Remove spikes (cells held by at most one face), fill dents (at least 5 full faces).
        for k in 0..nz {
            for j in 0..ny {
                for i in 0..nx {
                    let n = neighbours(i, j, k).iter().filter(|&&c| full[c]).count();
                    let c = idx(i, j, k);
                    if full[c] && n <= 1 {
                        full[c] = false;
                        changed = true;
                    } else if !full[c] && n >= 5 {
                        full[c] = true;
                        changed = true;
                    }
                }
            }
        }
        // Edge-only contacts: two full cells sharing an edge whose two common face
        // neighbours are empty. Fill the bridging cell nearer to the surface.
        for k in 0..nz {
            for j in 0..ny {
                for i in 0..nx {
                    let c = [i, j, k];
                    for (a, b) in [(0usize, 1usize), (0, 2), (1, 2)] {
                        for sa in [-1i64, 1] {
                            for sb in [-1i64, 1] {
                                let mut d = [c[0] as i64, c[1] as i64, c[2] as i64];
                                d[a] += sa;
                                d[b] += sb;
                                let dims = [nx as i64, ny as i64, nz as i64];
                                if (0..3).any(|t| d[t] < 0 || d[t] >= dims[t]) {
                                    continue;
                                }
                                let du = d.map(|v| v as usize);
                                let mut b1 = c;
                                b1[a] = du[a];
                                let mut b2 = c;
                                b2[b] = du[b];
                                let (ci, di) = (idx(c[0], c[1], c[2]), idx(du[0], du[1], du[2]));
                                let (i1, i2) = (idx(b1[0], b1[1], b1[2]), idx(b2[0], b2[1], b2[2]));
                                if full[ci] && full[di] && !full[i1] && !full[i2] {
                                    let f1 = organ_field(&centre(b1[0], b1[1], b1[2]));
                                    let f2 = organ_field(&centre(b2[0], b2[1], b2[2]));
                                    full[if f1 <= f2 { i1 } else { i2 }] = true;
                                    changed = true;
                                }
                            }
                        }
                    }
                }
            }
        }
        if !changed {
            break;
        }
    }
    // Keep the largest face-connected component (first found wins ties).
    let mut label = vec![usize::MAX; full.len()];
    let mut best = (0usize, usize::MAX);
    let mut next_label = 0;
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                let start = idx(i, j, k);
                if !full[start] || label[start] != usize::MAX {
                    continue;
                }
                let mut stack = vec![(i, j, k)];
                label[start] = next_label;
                let mut size = 0;
                while let Some((a, b, c)) = stack.pop() {
                    size += 1;
                    let coords = [
                        (a.wrapping_sub(1), b, c),
                        (a + 1, b, c),
                        (a, b.wrapping_sub(1), c),
                        (a, b + 1, c),
                        (a, b, c.wrapping_sub(1)),
                        (a, b, c + 1),
                    ];
                    for (x, y, z) in coords {
                        if x < nx && y < ny && z < nz {
                            let n = idx(x, y, z);
                            if full[n] && label[n] == usize::MAX {
                                label[n] = next_label;
                                stack.push((x, y, z));
                            }
                        }
                    }
                }
                if size > best.0 {
                    best = (size, next_label);
                }
                next_label += 1;
            }
        }
    }
    label.iter().map(|&l| l == best.1).collect()
}

/// Build the organ on a lattice of cells of edge `cell` (m) (see
/// [`organ_with_cell`](super::organ_with_cell)).
pub(crate) fn build_organ(cell: Real) -> TetMesh {
    let [nx, ny, nz] = grid_cells(cell);
    let cells = organ_cells(cell);
    let (px, py) = (nx + 1, ny + 1);
    let node_index = |i: usize, j: usize, k: usize| (i + px * (j + py * k)) as u32;
    let mut nodes = Vec::with_capacity(px * py * (nz + 1));
    for k in 0..=nz {
        for j in 0..=ny {
            for i in 0..=nx {
                nodes.push(Vec3::new(
                    GRID_MIN[0] + i as Real * cell,
                    GRID_MIN[1] + j as Real * cell,
                    GRID_MIN[2] + k as Real * cell,
                ));
            }
        }
    }
    let mut tets = Vec::new();
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                if !cells[i + nx * (j + ny * k)] {
                    continue;
                }
                let corner =
                    |c: usize| node_index(i + (c & 1), j + ((c >> 1) & 1), k + ((c >> 2) & 1));
                for t in KUHN_TETS {
                    tets.push(t.map(corner));
                }
            }
        }
    }
    // Drop the lattice nodes outside the organ; the lattice is valid by construction.
    let (mut mesh, _) = TetMesh::from_raw(nodes, tets, Path::new("<default organ>"))
        .expect("the default organ lattice is a valid mesh");
    snap_boundary(&mut mesh, cell);
    mesh
}

/// Pull the boundary nodes onto the implicit surface, a fraction of the way per pass,
/// accepting a move only if every tetrahedron around the node keeps a healthy volume.
fn snap_boundary(mesh: &mut TetMesh, cell: Real) {
    let n = mesh.nodes.len();
    let mut on_boundary = vec![false; n];
    for t in mesh.boundary_triangles() {
        for i in t {
            on_boundary[i as usize] = true;
        }
    }
    // Tets around each node (CSR).
    let mut start = vec![0usize; n + 1];
    for t in &mesh.tets {
        for &i in t {
            start[i as usize + 1] += 1;
        }
    }
    for i in 0..n {
        start[i + 1] += start[i];
    }
    let mut fill = start.clone();
    let mut around = vec![0u32; start[n]];
    for (ti, t) in mesh.tets.iter().enumerate() {
        for &i in t {
            around[fill[i as usize]] = ti as u32;
            fill[i as usize] += 1;
        }
    }
    let min_volume = MIN_VOLUME_FRACTION * cell * cell * cell / 6.0;
    let volume_ok = |nodes: &[Vec3], node: usize, tets: &[[u32; 4]]| {
        around[start[node]..start[node + 1]].iter().all(|&ti| {
            let t = tets[ti as usize];
            let p = |c: usize| &nodes[t[c] as usize];
            tet_volume(p(0), p(1), p(2), p(3)) > min_volume
        })
    };
    // Node neighbours through tet edges (CSR), for the smoothing of interior nodes.
    let mut edges: Vec<(u32, u32)> = Vec::with_capacity(mesh.tets.len() * 12);
    for t in &mesh.tets {
        for a in 0..4 {
            for b in 0..4 {
                if a != b {
                    edges.push((t[a], t[b]));
                }
            }
        }
    }
    edges.sort_unstable();
    edges.dedup();
    let mut nstart = vec![0usize; n + 1];
    for &(a, _) in &edges {
        nstart[a as usize + 1] += 1;
    }
    for i in 0..n {
        nstart[i + 1] += nstart[i];
    }
    let boundary: Vec<usize> = (0..n).filter(|&i| on_boundary[i]).collect();
    let interior: Vec<usize> = (0..n).filter(|&i| !on_boundary[i]).collect();
    // Move node `i` by `step`, or by a shorter step, or not at all: whatever keeps its
    // tetrahedra healthy.
    let try_move = |nodes: &mut Vec<Vec3>, i: usize, step: Vec3| {
        let old = nodes[i];
        for shrink in [1.0, 0.5, 0.25] {
            nodes[i] = old + step * shrink;
            if volume_ok(nodes, i, &mesh.tets) {
                return;
            }
        }
        nodes[i] = old;
    };
    for pass in 0..SNAP_PASSES {
        let fraction = if pass + 1 == SNAP_PASSES { 1.0 } else { 0.5 };
        for &i in &boundary {
            let p = mesh.nodes[i];
            let f = organ_field(&p);
            let g = organ_gradient(&p);
            let g2 = g.norm_squared();
            if g2 < 1e-12 {
                continue;
            }
            let mut step = -g * (f / g2) * fraction;
            // Never move more than half a cell in one go.
            let limit = 0.5 * cell;
            if step.norm() > limit {
                step *= limit / step.norm();
            }
            try_move(&mut mesh.nodes, i, step);
        }
        // Relax the interior nodes halfway towards the mean of their neighbours, which makes
        // room for the boundary to follow the surface in the next pass.
        if pass + 1 < SNAP_PASSES {
            for &i in &interior {
                let nb = &edges[nstart[i]..nstart[i + 1]];
                let mean = nb
                    .iter()
                    .fold(Vec3::zeros(), |acc, &(_, j)| acc + mesh.nodes[j as usize])
                    / nb.len() as Real;
                let step = (mean - mesh.nodes[i]) * 0.5;
                try_move(&mut mesh.nodes, i, step);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn field_is_negative_in_the_lobes_and_positive_far_away() {
        for l in &LOBES[..2] {
            let c = Vec3::new(l.centre[0], l.centre[1], l.centre[2]);
            assert!(organ_field(&c) < 0.0);
        }
        assert!(organ_field(&Vec3::new(0.5, 0.0, 0.0)) > 0.0);
    }

    #[test]
    fn default_lattice_is_27_by_18_by_20() {
        assert_eq!(grid_cells(DEFAULT_CELL), [27, 18, 20]);
    }

    #[test]
    fn finer_cells_give_more_nodes() {
        let coarse = build_organ(1.4 * DEFAULT_CELL).nodes.len();
        let fine = build_organ(0.8 * DEFAULT_CELL).nodes.len();
        assert!(fine > coarse * 3, "{coarse} -> {fine}");
    }

    #[test]
    fn lattice_covers_the_solid() {
        // No part of the solid touches the lattice border.
        let [nx, ny, nz] = grid_cells(DEFAULT_CELL);
        let hi = [
            GRID_MIN[0] + nx as Real * DEFAULT_CELL,
            GRID_MIN[1] + ny as Real * DEFAULT_CELL,
            GRID_MIN[2] + nz as Real * DEFAULT_CELL,
        ];
        let steps = 40;
        for a in 0..=steps {
            for b in 0..=steps {
                let (s, t) = (a as Real / steps as Real, b as Real / steps as Real);
                let lerp = |d: usize, u: Real| GRID_MIN[d] + u * (hi[d] - GRID_MIN[d]);
                for p in [
                    Vec3::new(GRID_MIN[0], lerp(1, s), lerp(2, t)),
                    Vec3::new(hi[0], lerp(1, s), lerp(2, t)),
                    Vec3::new(lerp(0, s), GRID_MIN[1], lerp(2, t)),
                    Vec3::new(lerp(0, s), hi[1], lerp(2, t)),
                    Vec3::new(lerp(0, s), lerp(1, t), GRID_MIN[2]),
                    Vec3::new(lerp(0, s), lerp(1, t), hi[2]),
                ] {
                    assert!(organ_field(&p) > 0.0, "{p:?}");
                }
            }
        }
    }
}
