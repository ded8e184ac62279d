//! Boundary extraction: the triangles of a tetrahedral mesh that belong to exactly one
//! tetrahedron, oriented with their normal pointing out of the solid.

use super::TetMesh;
use crate::kernels::math::tet_volume;

/// The four faces of a positively oriented tetrahedron `[a, b, c, d]`, as local indices, each
/// ordered so that its normal `(v1-v0)×(v2-v0)` points away from the opposite node.
pub(crate) const OUTWARD_FACES: [[usize; 3]; 4] = [[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]];

/// Boundary triangles of `mesh` (faces used by one tetrahedron only), outward oriented, in
/// the order of their tetrahedron and, within it, of [`OUTWARD_FACES`].
pub(crate) fn boundary_triangles(mesh: &TetMesh) -> Vec<[u32; 3]> {
    let n = mesh.nodes.len();
    // (sorted key, tet index, local face): sorting groups the copies of each face together.
    let mut faces: Vec<([u32; 3], u32, u8)> = Vec::with_capacity(mesh.tets.len() * 4);
    for (t, tet) in mesh.tets.iter().enumerate() {
        if tet.iter().any(|&i| i as usize >= n) {
            continue;
        }
        for (f, local) in OUTWARD_FACES.iter().enumerate() {
            let mut key = [tet[local[0]], tet[local[1]], tet[local[2]]];
            key.sort_unstable();
            faces.push((key, t as u32, f as u8));
        }
    }
    faces.sort_unstable();
    let mut single: Vec<(u32, u8)> = Vec::new();
    let mut i = 0;
    while i < faces.len() {
        let mut j = i + 1;
        while j < faces.len() && faces[j].0 == faces[i].0 {
            j += 1;
        }
        if j - i == 1 {
            single.push((faces[i].1, faces[i].2));
        }
        i = j;
    }
    single.sort_unstable();
    single
        .into_iter()
        .map(|(t, f)| {
            let tet = mesh.tets[t as usize];
            let local = OUTWARD_FACES[f as usize];
            let p = |k: usize| &mesh.nodes[tet[k] as usize];
            let tri = [tet[local[0]], tet[local[1]], tet[local[2]]];
            // A tetrahedron stored with negative orientation has its faces flipped.
            if tet_volume(p(0), p(1), p(2), p(3)) < 0.0 {
                [tri[0], tri[2], tri[1]]
            } else {
                tri
            }
        })
        .collect()
}

/// The particles at the corners of `boundary` triangles, each once, increasing.
pub(crate) fn boundary_vertices(boundary: &[[u32; 3]]) -> Vec<u32> {
    let mut vertices: Vec<u32> = boundary.iter().flatten().copied().collect();
    vertices.sort_unstable();
    vertices.dedup();
    vertices
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kernels::math::Vec3;

    #[test]
    fn outward_faces_point_away_from_opposite_node() {
        let nodes = [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(0.0, 0.0, 1.0),
        ];
        assert!(tet_volume(&nodes[0], &nodes[1], &nodes[2], &nodes[3]) > 0.0);
        for (opposite, f) in OUTWARD_FACES.iter().enumerate() {
            let k = (0..4).find(|k| !f.contains(k)).unwrap();
            assert_eq!(k, opposite);
            let n = (nodes[f[1]] - nodes[f[0]]).cross(&(nodes[f[2]] - nodes[f[0]]));
            assert!(n.dot(&(nodes[k] - nodes[f[0]])) < 0.0);
        }
    }

    #[test]
    fn single_tet_has_four_faces() {
        let mesh = TetMesh {
            nodes: vec![
                Vec3::new(0.0, 0.0, 0.0),
                Vec3::new(1.0, 0.0, 0.0),
                Vec3::new(0.0, 1.0, 0.0),
                Vec3::new(0.0, 0.0, 1.0),
            ],
            tets: vec![[0, 1, 2, 3]],
        };
        assert_eq!(boundary_triangles(&mesh).len(), 4);
    }
}
