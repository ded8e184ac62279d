//! Mesh readers, cleaning, boundary extraction, writers and the default organ.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use tissuesim::math::tet_volume;
use tissuesim::mesh::{self, lattice_box, MeshError, TetMesh};
use tissuesim::Vec3;

/// A file of the shared mesh set.
fn shared(name: &str) -> PathBuf {
    PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../shared/meshes")).join(name)
}

/// A fresh scratch directory for this test.
fn scratch(test: &str) -> PathBuf {
    let dir = std::env::temp_dir()
        .join(format!("tissuesim-mesh-io-{}", std::process::id()))
        .join(test);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn signed_volumes(m: &TetMesh) -> Vec<f64> {
    m.tets
        .iter()
        .map(|t| {
            tet_volume(
                &m.nodes[t[0] as usize],
                &m.nodes[t[1] as usize],
                &m.nodes[t[2] as usize],
                &m.nodes[t[3] as usize],
            )
        })
        .collect()
}

/// Every edge of the boundary in exactly two triangles, used once in each direction.
fn assert_closed_and_consistent(tris: &[[u32; 3]]) {
    let mut directed: HashMap<(u32, u32), usize> = HashMap::new();
    for t in tris {
        for k in 0..3 {
            *directed.entry((t[k], t[(k + 1) % 3])).or_default() += 1;
        }
    }
    for (&(a, b), &n) in &directed {
        assert_eq!(n, 1, "directed edge {a}->{b} used {n} times");
        assert_eq!(
            directed.get(&(b, a)).copied(),
            Some(1),
            "edge {a}-{b} has no opposite half-edge: surface not closed"
        );
    }
}

/// Divergence theorem: sum over triangles of centroid·normal·area / 3 (normal·area = cross/2).
fn surface_volume(m: &TetMesh, tris: &[[u32; 3]]) -> f64 {
    tris.iter()
        .map(|t| {
            let (a, b, c) = (
                m.nodes[t[0] as usize],
                m.nodes[t[1] as usize],
                m.nodes[t[2] as usize],
            );
            let centroid = (a + b + c) / 3.0;
            centroid.dot(&((b - a).cross(&(c - a)) / 2.0)) / 3.0
        })
        .sum()
}

#[test]
fn tetgen_meshes_load_with_readme_counts() {
    for (name, nodes, tets) in [
        ("liver_1k6.node", 1594, 5948),
        ("liver_4k.node", 4152, 16599),
        ("liver_10k.ele", 10087, 42319),
        ("liver_31k", 30764, 136209),
    ] {
        let (m, r) = mesh::load(&shared(name), 1.0).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(m.nodes.len(), nodes, "{name}");
        assert_eq!(m.tets.len(), tets, "{name}");
        assert_eq!(
            r.reoriented_tets, 0,
            "{name}: README says all tets are positive"
        );
        assert_eq!(r.original_node_index.len(), nodes);
        assert!(signed_volumes(&m).iter().all(|&v| v > 0.0));
    }
}

#[test]
fn lattice_box_boundary_is_closed_and_outward() {
    let (lo, hi) = (Vec3::new(-0.1, 0.0, 0.2), Vec3::new(0.3, 0.05, 0.3));
    let m = lattice_box(lo, hi, [8, 2, 3]);
    assert_eq!(m.nodes.len(), 9 * 3 * 4);
    assert_eq!(m.tets.len(), 6 * 8 * 2 * 3);
    let expected = 0.4 * 0.05 * 0.1;
    assert!((m.volume() - expected).abs() < 1e-12 * expected.max(1.0));
    assert!(signed_volumes(&m).iter().all(|&v| v > 0.0));
    let tris = m.boundary_triangles();
    // Each cell face on the box surface is split into 2 triangles.
    assert_eq!(tris.len(), 2 * 2 * (8 * 2 + 2 * 3 + 8 * 3));
    assert_closed_and_consistent(&tris);
    let sv = surface_volume(&m, &tris);
    assert!(
        (sv - m.volume()).abs() < 1e-9 * m.volume(),
        "{sv} vs {}",
        m.volume()
    );
    assert_eq!(tris, m.boundary_triangles(), "deterministic");
    let (bmin, bmax) = m.bounding_box();
    assert_eq!((bmin, bmax), (lo, hi));
    // Edges of a 0.05 × 0.025 × 0.0333 cell: between the shortest axis and the main diagonal.
    let e = m.mean_edge_length();
    assert!(e > 0.025 && e < (0.05f64.powi(2) + 0.025f64.powi(2) + 0.0333f64.powi(2)).sqrt());
}

#[test]
fn tetgen_meshes_have_closed_outward_boundaries() {
    let (m, _) = mesh::load(&shared("liver_1k6.node"), 0.03).unwrap();
    let tris = m.boundary_triangles();
    assert_closed_and_consistent(&tris);
    let sv = surface_volume(&m, &tris);
    assert!((sv - m.volume()).abs() < 1e-9 * m.volume());
    let (lo, hi) = m.bounding_box();
    let size = (hi - lo).max();
    assert!(
        size > 0.15 && size < 0.25,
        "scaled liver is ~0.2 m, got {size}"
    );
}

#[test]
fn unreferenced_inverted_and_degenerate_tets_are_cleaned() {
    let nodes = vec![
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(0.0, 1.0, 0.0),
        Vec3::new(0.0, 0.0, 1.0),
        Vec3::new(7.0, 7.0, 7.0), // unreferenced
        Vec3::new(1.0, 1.0, 0.0), // coplanar with 0,1,2: degenerate tet
        Vec3::new(1.0, 1.0, 1.0),
    ];
    let tets = vec![[0, 1, 2, 3], [1, 2, 6, 3], [0, 1, 2, 5]];
    let (m, r) = TetMesh::from_raw(nodes.clone(), tets, Path::new("arrays")).unwrap();
    assert_eq!(r.reoriented_tets, 1);
    assert_eq!(r.degenerate_tets_removed, 1);
    assert_eq!(
        r.unreferenced_nodes_removed, 2,
        "node 4, and node 5 of the removed tet"
    );
    assert_eq!(r.original_node_index, vec![0, 1, 2, 3, 6]);
    assert_eq!(m.tets.len(), 2);
    for (k, &orig) in r.original_node_index.iter().enumerate() {
        assert_eq!(m.nodes[k], nodes[orig as usize]);
    }
    assert!(signed_volumes(&m).iter().all(|&v| v > 0.0));
    let tris = m.boundary_triangles();
    assert_eq!(tris.len(), 6);
    assert_closed_and_consistent(&tris);

    let e: MeshError =
        TetMesh::from_raw(nodes, vec![[0, 1, 2, 9]], Path::new("arrays")).unwrap_err();
    assert!(e.to_string().contains("arrays"));
}

#[test]
fn gmsh_v1_meshes_load_with_readme_counts() {
    let (m, r) = mesh::load(&shared("liver.msh"), 1.0).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!((m.nodes.len(), m.tets.len()), (181, 596));
    assert_eq!(r.skipped_elements, 0);
    let (m, r) = mesh::load(&shared("liver2.msh"), 1.0).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!((m.nodes.len(), m.tets.len()), (507, 1493));
    assert_eq!(r.skipped_elements, 860 + 71);
    assert!(signed_volumes(&m).iter().all(|&v| v > 0.0));
}

#[test]
fn liver_4k_is_the_same_mesh_in_three_formats() {
    let (a, ra) = mesh::load(&shared("liver_4k.node"), 0.03).unwrap();
    let (b, rb) = mesh::load(&shared("liver_4k.msh"), 0.03).unwrap_or_else(|e| panic!("{e}"));
    let (c, rc) = mesh::load(&shared("liver_4k.vtk"), 0.03).unwrap_or_else(|e| panic!("{e}"));
    for (name, m, r) in [("msh", &b, &rb), ("vtk", &c, &rc)] {
        assert_eq!(m.tets, a.tets, "{name}: same connectivity");
        assert_eq!(m.nodes.len(), a.nodes.len());
        let max_diff = m
            .nodes
            .iter()
            .zip(&a.nodes)
            .map(|(p, q)| (p - q).norm())
            .fold(0.0, f64::max);
        assert!(
            max_diff < 1e-6 * 0.03,
            "{name}: positions differ by {max_diff} m"
        );
        assert_eq!(r.original_node_index, ra.original_node_index);
    }
}
