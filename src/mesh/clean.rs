//! Cleaning of raw tetrahedral meshes ([`TetMesh::from_raw`](super::TetMesh::from_raw)):
//! index validation, re-orientation of inverted tetrahedra, removal of degenerate tetrahedra
//! and of unreferenced nodes.

use super::{MeshError, MeshReport, TetMesh};
use crate::kernels::math::{is_finite_vec, tet_volume, Real, Vec3};
use std::path::Path;

/// A tetrahedron whose |volume| is at most this fraction of the mean |volume| is degenerate.
pub const DEGENERATE_RELATIVE_VOLUME: Real = 1e-10;

/// Validate and clean raw arrays (see [`TetMesh::from_raw`](super::TetMesh::from_raw)).
pub(crate) fn clean(
    nodes: Vec<Vec3>,
    tets: Vec<[u32; 4]>,
    path: &Path,
) -> Result<(TetMesh, MeshReport), MeshError> {
    if let Some(i) = nodes.iter().position(|p| !is_finite_vec(p)) {
        return Err(MeshError::file(
            path,
            format!("node {i} has a non-finite coordinate"),
        ));
    }
    let n = nodes.len();
    for (t, tet) in tets.iter().enumerate() {
        if let Some(&bad) = tet.iter().find(|&&i| i as usize >= n) {
            return Err(MeshError::file(
                path,
                format!("tetrahedron {t} references node {bad} but the mesh has {n} nodes"),
            ));
        }
    }
    if tets.is_empty() {
        return Err(MeshError::file(path, "the mesh has no tetrahedra"));
    }

    let volumes: Vec<Real> = tets
        .iter()
        .map(|t| {
            tet_volume(
                &nodes[t[0] as usize],
                &nodes[t[1] as usize],
                &nodes[t[2] as usize],
                &nodes[t[3] as usize],
            )
        })
        .collect();
    let mean_abs = volumes.iter().map(|v| v.abs()).sum::<Real>() / volumes.len() as Real;
    let threshold = DEGENERATE_RELATIVE_VOLUME * mean_abs;

    let mut report = MeshReport::default();
    let mut kept: Vec<[u32; 4]> = Vec::with_capacity(tets.len());
    for (tet, &v) in tets.iter().zip(&volumes) {
        let distinct = (0..4).all(|a| (a + 1..4).all(|b| tet[a] != tet[b]));
        // `v.abs() > 0.0` is false for zero and NaN volumes alike.
        let nonzero = v.abs() > 0.0;
        if !distinct || !nonzero || v.abs() <= threshold {
            report.degenerate_tets_removed += 1;
        } else if v < 0.0 {
            report.reoriented_tets += 1;
            kept.push([tet[0], tet[1], tet[3], tet[2]]);
        } else {
            kept.push(*tet);
        }
    }
    if kept.is_empty() {
        return Err(MeshError::file(
            path,
            format!(
                "no tetrahedron left: all {} tetrahedra are degenerate",
                tets.len()
            ),
        ));
    }

    // Renumber the referenced nodes in file order.
    let mut new_index = vec![u32::MAX; n];
    for tet in &kept {
        for &i in tet {
            new_index[i as usize] = 0;
        }
    }
    let mut out_nodes = Vec::with_capacity(n);
    for (old, slot) in new_index.iter_mut().enumerate() {
        if *slot == 0 {
            *slot = out_nodes.len() as u32;
            out_nodes.push(nodes[old]);
            report.original_node_index.push(old as u32);
        }
    }
    report.unreferenced_nodes_removed = n - out_nodes.len();
    for tet in &mut kept {
        for i in tet.iter_mut() {
            *i = new_index[*i as usize];
        }
    }
    Ok((
        TetMesh {
            nodes: out_nodes,
            tets: kept,
        },
        report,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit_nodes() -> Vec<Vec3> {
        vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(0.0, 0.0, 1.0),
        ]
    }

    #[test]
    fn keeps_a_positive_tet() {
        let (m, r) = clean(unit_nodes(), vec![[0, 1, 2, 3]], Path::new("t")).unwrap();
        assert_eq!(m.tets, vec![[0, 1, 2, 3]]);
        assert_eq!(r.original_node_index, vec![0, 1, 2, 3]);
        assert_eq!(
            r,
            MeshReport {
                original_node_index: vec![0, 1, 2, 3],
                ..Default::default()
            }
        );
    }

    #[test]
    fn reorients_and_renumbers() {
        let mut nodes = unit_nodes();
        nodes.insert(0, Vec3::new(5.0, 5.0, 5.0));
        let (m, r) = clean(nodes, vec![[1, 3, 2, 4]], Path::new("t")).unwrap();
        assert_eq!(r.reoriented_tets, 1);
        assert_eq!(r.unreferenced_nodes_removed, 1);
        assert_eq!(r.original_node_index, vec![1, 2, 3, 4]);
        let t = m.tets[0];
        let v = tet_volume(
            &m.nodes[t[0] as usize],
            &m.nodes[t[1] as usize],
            &m.nodes[t[2] as usize],
            &m.nodes[t[3] as usize],
        );
        assert!(v > 0.0);
    }

    #[test]
    fn errors() {
        assert!(clean(unit_nodes(), vec![[0, 1, 2, 4]], Path::new("t")).is_err());
        assert!(clean(unit_nodes(), vec![], Path::new("t")).is_err());
        assert!(clean(unit_nodes(), vec![[0, 1, 2, 2]], Path::new("t")).is_err());
        let mut bad = unit_nodes();
        bad[0].x = Real::NAN;
        assert!(clean(bad, vec![[0, 1, 2, 3]], Path::new("t")).is_err());
    }
}
