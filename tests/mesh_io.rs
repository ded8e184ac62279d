//! Mesh readers, cleaning, boundary extraction, writers and the default organ.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use tissuesim::mesh::{self, lattice_box, MeshError, TetMesh};
use tissuesim::tet_volume;
use tissuesim::Vec3;

mod common;

/// A file of the test mesh set (data/meshes or `$TISSUESIM_MESHES`; panics when missing).
fn shared(name: &str) -> PathBuf {
    common::mesh_path(name)
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

/// A small two-tet mesh (a triangular bipyramid) in mesh units.
const BIPYRAMID_NODES: [[f64; 3]; 5] = [
    [0.0, 0.0, 0.0],
    [1.0, 0.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.0, 0.0, 1.0],
    [0.0, 0.0, -1.0],
];

#[test]
fn gmsh_41_file_loads() {
    let dir = scratch("gmsh41");
    let path = dir.join("small41.msh");
    // Non-contiguous node tags, a surface block of triangles and a volume block of tets;
    // the second tet is stored inverted.
    let text = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n\
$PhysicalNames\n1\n3 1 \"liver\"\n$EndPhysicalNames\n\
$Entities\n0 0 1 1\n1 0 0 0 1 1 1 0 0\n1 0 0 -1 1 1 1 0 0\n$EndEntities\n\
$Nodes\n2 5 10 50\n\
2 1 0 2\n10\n20\n0 0 0\n1 0 0\n\
3 1 0 3\n30\n40\n50\n0 1 0\n0 0 1\n0 0 -1\n\
$EndNodes\n\
$Elements\n2 3 1 3\n\
2 1 2 1\n1 10 20 30\n\
3 1 4 2\n2 10 20 30 40\n3 10 20 30 50\n\
$EndElements\n";
    std::fs::write(&path, text).unwrap();
    let (m, r) = mesh::load(&path, 2.0).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(m.nodes.len(), 5);
    assert_eq!(m.tets.len(), 2);
    assert_eq!(r.skipped_elements, 1);
    assert_eq!(r.reoriented_tets, 1);
    for (p, q) in m.nodes.iter().zip(BIPYRAMID_NODES) {
        assert_eq!(*p, Vec3::from(q) * 2.0, "scaled, in file order");
    }
    assert!((m.volume() - 2.0 * 8.0 / 6.0).abs() < 1e-12);
    assert!(signed_volumes(&m).iter().all(|&v| v > 0.0));
}

#[test]
fn gmsh_22_with_mixed_elements_and_sparse_ids_loads() {
    let dir = scratch("gmsh22");
    let path = dir.join("small22.msh");
    let text = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n6\n\
7 0 0 0\n3 1 0 0\n100 0 1 0\n5 0 0 1\n9 0 0 -1\n11 5 5 5\n$EndNodes\n\
$Elements\n4\n1 15 2 0 1 7\n2 2 2 0 1 7 3 100\n3 4 2 0 1 7 3 100 5\n4 4 3 0 1 2 7 3 9 100\n\
$EndElements\n$NodeData\n1\n\"x\"\n$EndNodeData\n";
    std::fs::write(&path, text).unwrap();
    let (m, r) = mesh::load(&path, 1.0).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!((m.nodes.len(), m.tets.len()), (5, 2));
    assert_eq!(r.skipped_elements, 2);
    assert_eq!(r.unreferenced_nodes_removed, 1);
    assert_eq!(r.original_node_index, vec![0, 1, 2, 3, 4]);
    assert_eq!(r.reoriented_tets, 0);
}

/// TetGen text of the bipyramid, numbered from `base`.
fn bipyramid_tetgen(dir: &Path, name: &str, base: usize) -> PathBuf {
    let mut node = String::from("# bipyramid\n5 3 0 0\n");
    for (k, p) in BIPYRAMID_NODES.iter().enumerate() {
        node += &format!("{} {} {} {}\n", k + base, p[0], p[1], p[2]);
    }
    let ele = format!(
        "2 4 0\n{b0} {a} {b} {c} {d}  # first\n{b1} {a} {b} {e} {c}\n",
        b0 = base,
        b1 = base + 1,
        a = base,
        b = base + 1,
        c = base + 2,
        d = base + 3,
        e = base + 4
    );
    std::fs::write(dir.join(format!("{name}.node")), node).unwrap();
    std::fs::write(dir.join(format!("{name}.ele")), ele).unwrap();
    dir.join(format!("{name}.node"))
}

#[test]
fn one_based_tetgen_loads_like_zero_based() {
    let dir = scratch("tetgen1");
    let zero = mesh::load(&bipyramid_tetgen(&dir, "zero", 0), 1.0).unwrap();
    let one_path = bipyramid_tetgen(&dir, "one", 1);
    let one = mesh::load(&one_path, 1.0).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(zero, one);
    assert_eq!(one.0.tets.len(), 2);
    // The .ele path and the base name work too.
    assert_eq!(mesh::load(&dir.join("one.ele"), 1.0).unwrap(), one);
    assert_eq!(mesh::load(&dir.join("one"), 1.0).unwrap(), one);
    // Second tet (a, b, e, c) is positive: no re-orientation needed.
    assert_eq!(one.1.reoriented_tets, 0);
}

/// Write `text` to `dir/name`, load it and return the error (the load must fail).
fn load_err(dir: &Path, name: &str, text: &str) -> MeshError {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    match mesh::load(&path, 1.0) {
        Ok(_) => panic!("{name} should not load"),
        Err(e) => e,
    }
}

/// The error names the file (in its Display) and the expected 1-based line.
fn assert_error_at(e: &MeshError, file: &str, line: Option<usize>) {
    let shown = e.to_string();
    assert!(shown.contains(file), "`{shown}` should name {file}");
    assert_eq!(e.line, line, "wrong line in `{shown}`");
    if let Some(l) = line {
        assert!(
            shown.contains(&format!(":{l}:")),
            "`{shown}` should show line {l}"
        );
    }
}

#[test]
fn malformed_tetgen_files_give_located_errors() {
    let dir = scratch("bad_tetgen");
    let ele = "1 4 0\n0 0 1 2 3\n";
    std::fs::write(dir.join("trunc.ele"), ele).unwrap();
    // Truncated: 4 points declared, 3 given; the error is at the last line.
    let e = load_err(&dir, "trunc.node", "4 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 1 0\n");
    assert_error_at(&e, "trunc.node", Some(4));
    assert!(e.message.contains("end of file"), "{e}");
    // Non-numeric coordinate on line 3 (after a comment line).
    std::fs::write(dir.join("nan.ele"), ele).unwrap();
    let e = load_err(
        &dir,
        "nan.node",
        "# c\n4 3 0 0\n0 0 0 0\n1 1 zero 0\n2 0 1 0\n3 0 0 1\n",
    );
    assert_error_at(&e, "nan.node", Some(4));
    // Element referencing an undefined point: error in the .ele file, at its line.
    let node = "4 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 1 0\n3 0 0 1\n";
    std::fs::write(dir.join("undef.node"), node).unwrap();
    let e = load_err(&dir, "undef.ele", "2 4 0\n0 0 1 2 3\n\n1 0 1 2 7\n");
    assert_error_at(&e, "undef.ele", Some(4));
    assert!(e.message.contains('7'), "{e}");
    // Wrong count: more tets than declared.
    std::fs::write(dir.join("extra.node"), node).unwrap();
    let e = load_err(&dir, "extra.ele", "1 4 0\n0 0 1 2 3\n1 0 1 3 2\n");
    assert_error_at(&e, "extra.ele", Some(3));
    // Missing .ele file.
    std::fs::write(dir.join("lonely.node"), node).unwrap();
    let e = mesh::load(&dir.join("lonely.node"), 1.0).unwrap_err();
    assert_error_at(&e, "lonely.ele", None);
    // Empty mesh: no tetrahedra.
    std::fs::write(dir.join("empty.node"), node).unwrap();
    let e = load_err(&dir, "empty.ele", "0 4 0\n");
    assert_error_at(&e, "empty.ele", None);
    // Only degenerate tetrahedra.
    std::fs::write(
        dir.join("flat.node"),
        "4 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 1 0\n3 1 1 0\n",
    )
    .unwrap();
    let e = load_err(&dir, "flat.ele", "1 4 0\n0 0 1 2 3\n");
    assert_error_at(&e, "flat.ele", None);
}

#[test]
fn malformed_gmsh_files_give_located_errors() {
    let dir = scratch("bad_gmsh");
    let head = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n";
    let nodes = "$Nodes\n4\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n$EndNodes\n";
    // Undefined node id in an element (line 13).
    let e = load_err(
        &dir,
        "undef.msh",
        &format!("{head}{nodes}$Elements\n1\n1 4 2 0 1 1 2 3 9\n$EndElements\n"),
    );
    assert_error_at(&e, "undef.msh", Some(13));
    // Missing $Elements section.
    let e = load_err(&dir, "noelem.msh", &format!("{head}{nodes}"));
    assert_error_at(&e, "noelem.msh", None);
    assert!(e.message.contains("$Elements"), "{e}");
    // Wrong node count: 3 declared, 4 given; the 4th node line (9) is not $EndNodes.
    let e = load_err(
        &dir,
        "count.msh",
        &format!("{head}$Nodes\n3\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n$EndNodes\n"),
    );
    assert_error_at(&e, "count.msh", Some(9));
    // Non-numeric coordinate (line 7).
    let e = load_err(
        &dir,
        "nan.msh",
        &format!("{head}$Nodes\n4\n1 0 0 0\n2 1 0 x\n3 0 1 0\n4 0 0 1\n$EndNodes\n"),
    );
    assert_error_at(&e, "nan.msh", Some(7));
    // Truncated inside the elements.
    let e = load_err(
        &dir,
        "trunc.msh",
        &format!("{head}{nodes}$Elements\n2\n1 4 2 0 1 1 2 3 4\n"),
    );
    assert_error_at(&e, "trunc.msh", Some(13));
    // Legacy v1: the element declares 4 nodes but lists 3 (line 9).
    let e = load_err(
        &dir,
        "v1.msh",
        "$NOD\n4\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n$ENDNOD\n$ELM\n1\n1 4 1 1 4 1 2 3\n$ENDELM\n",
    );
    assert_error_at(&e, "v1.msh", Some(10));
    // Unsupported version and binary files.
    let e = load_err(&dir, "v3.msh", "$MeshFormat\n3.0 0 8\n$EndMeshFormat\n");
    assert_error_at(&e, "v3.msh", Some(2));
    let e = load_err(&dir, "bin.msh", "$MeshFormat\n2.2 1 8\n$EndMeshFormat\n");
    assert_error_at(&e, "bin.msh", Some(2));
    // Not a Gmsh file at all.
    let e = load_err(&dir, "junk.msh", "\nhello\n");
    assert_error_at(&e, "junk.msh", Some(2));
    // 4.1 with a node block shorter than announced.
    let e = load_err(
        &dir,
        "short41.msh",
        "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 4 1 4\n3 1 0 4\n1\n2\n3\n4\n0 0 0\n1 0 0\n$EndNodes\n",
    );
    assert_error_at(&e, "short41.msh", Some(13));
}

#[test]
fn malformed_vtk_files_give_located_errors() {
    let dir = scratch("bad_vtk");
    let head = "# vtk DataFile Version 2.0\ntitle\nASCII\nDATASET UNSTRUCTURED_GRID\n";
    let points = "POINTS 4 double\n0 0 0 1 0 0\n0 1 0 0 0 1\n";
    // Cell type table with the wrong count (line 10).
    let e = load_err(
        &dir,
        "types.vtk",
        &format!("{head}{points}CELLS 1 5\n4 0 1 2 3\nCELL_TYPES 2\n10\n10\n"),
    );
    assert_error_at(&e, "types.vtk", Some(10));
    // Tetra cell type on a 3-node cell: error at its type line (13).
    let e = load_err(
        &dir,
        "tri.vtk",
        &format!("{head}{points}CELLS 2 9\n4 0 1 2 3\n3 0 1 2\nCELL_TYPES 2\n10\n10\n"),
    );
    assert_error_at(&e, "tri.vtk", Some(13));
    // Point index out of range (line 9).
    let e = load_err(
        &dir,
        "range.vtk",
        &format!("{head}{points}CELLS 1 5\n4 0 1 2 4\nCELL_TYPES 1\n10\n"),
    );
    assert_error_at(&e, "range.vtk", Some(9));
    // Truncated points (declared 5).
    let e = load_err(
        &dir,
        "trunc.vtk",
        &format!("{head}POINTS 5 float\n0 0 0\n1 0 0\n"),
    );
    assert_error_at(&e, "trunc.vtk", Some(7));
    // Non-numeric coordinate on line 6.
    let e = load_err(&dir, "nan.vtk", &format!("{head}POINTS 1 float\n0 a 0\n"));
    assert_error_at(&e, "nan.vtk", Some(6));
    // Missing CELL_TYPES.
    let e = load_err(
        &dir,
        "nocells.vtk",
        &format!("{head}{points}CELLS 1 5\n4 0 1 2 3\n"),
    );
    assert_error_at(&e, "nocells.vtk", None);
    // CELLS size that does not match the records.
    let e = load_err(
        &dir,
        "size.vtk",
        &format!("{head}{points}CELLS 1 6\n4 0 1 2 3\nCELL_TYPES 1\n10\n"),
    );
    assert!(e.to_string().contains("size.vtk"), "{e}");
    // Other datasets are rejected at line 4.
    let e = load_err(
        &dir,
        "poly.vtk",
        "# vtk DataFile Version 2.0\nt\nASCII\nDATASET POLYDATA\n",
    );
    assert_error_at(&e, "poly.vtk", Some(4));
    // Mixed cells: the triangle is skipped and counted.
    let path = dir.join("mixed.vtk");
    std::fs::write(
        &path,
        format!("{head}{points}CELLS 2 9\n3 0 1 2\n4 0 1 2 3\nCELL_TYPES 2\n5\n10\n"),
    )
    .unwrap();
    let (m, r) = mesh::load(&path, 1.0).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!((m.tets.len(), r.skipped_elements), (1, 1));
}

#[test]
fn bad_paths_extensions_and_scales_are_errors() {
    let dir = scratch("bad_paths");
    let e = mesh::load(&dir.join("nothere.msh"), 1.0).unwrap_err();
    assert_error_at(&e, "nothere.msh", None);
    std::fs::write(dir.join("mesh.stl"), "solid x\n").unwrap();
    let e = mesh::load(&dir.join("mesh.stl"), 1.0).unwrap_err();
    assert_error_at(&e, "mesh.stl", None);
    let e = mesh::load(&dir.join("noext"), 1.0).unwrap_err();
    assert_error_at(&e, "noext", None);
    for scale in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        let e = mesh::load(&shared("liver.msh"), scale).unwrap_err();
        assert_error_at(&e, "liver.msh", None);
        assert!(mesh::read_obj(&shared("liver-smooth.obj"), scale).is_err());
    }
    // Absurd counts in headers are errors, not allocation failures.
    let e = load_err(&dir, "huge.msh", "$NOD\n18446744073709551615\n1 0 0 0\n");
    assert_error_at(&e, "huge.msh", Some(3));
    let e = load_err(
        &dir,
        "huge.vtk",
        "# vtk DataFile Version 2.0\nt\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 9000000000000000000 double\n0 0 0\n",
    );
    assert_error_at(&e, "huge.vtk", Some(6));
    let e = load_err(&dir, "empty.vtk", "");
    assert!(e.to_string().contains("empty.vtk"));
    let e = load_err(&dir, "empty.msh", "");
    assert!(e.to_string().contains("empty.msh"));
}

#[test]
fn truncated_files_never_panic() {
    // Every prefix of a small file (cut at each line) either loads or gives an error naming
    // the file; only the complete file (or one missing just its trailing sections) loads.
    let dir = scratch("truncate");
    for source in ["liver.msh", "liver2.msh"] {
        let text = std::fs::read_to_string(shared(source)).unwrap();
        let cuts: Vec<usize> = text.match_indices('\n').map(|(i, _)| i).collect();
        let path = dir.join(source);
        for (k, &cut) in cuts.iter().enumerate().step_by(7) {
            std::fs::write(&path, &text[..cut]).unwrap();
            match mesh::load(&path, 1.0) {
                Ok(_) => assert!(k + 2 >= cuts.len(), "{source} cut at line {k} loaded"),
                Err(e) => assert!(e.to_string().contains(source), "{e}"),
            }
        }
    }
    let text = std::fs::read_to_string(shared("liver_4k.vtk")).unwrap();
    let path = dir.join("cut.vtk");
    for k in 1..40 {
        let mut cut = text.len() * k / 40;
        while !text.is_char_boundary(cut) {
            cut -= 1;
        }
        std::fs::write(&path, &text[..cut]).unwrap();
        let e = mesh::load(&path, 1.0).unwrap_err();
        assert!(e.to_string().contains("cut.vtk"), "{e}");
    }
}

#[test]
fn write_vtk_round_trips() {
    let dir = scratch("vtk_roundtrip");
    for (name, m) in [
        (
            "box.vtk",
            lattice_box(
                Vec3::new(0.0, -0.1, 0.0),
                Vec3::new(0.1, 0.0, 0.3),
                [3, 4, 5],
            ),
        ),
        ("organ.vtk", mesh::default_organ()),
        (
            "liver.vtk",
            mesh::load(&shared("liver.msh"), 0.0317).unwrap().0,
        ),
    ] {
        let path = dir.join(name);
        mesh::write_vtk(&path, &m).unwrap();
        let (back, r) = mesh::load(&path, 1.0).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(back, m, "{name}: bit-exact round trip");
        assert_eq!(r.reoriented_tets + r.degenerate_tets_removed, 0);
        assert_eq!(r.unreferenced_nodes_removed + r.skipped_elements, 0);
    }
}

/// A minimal XML well-formedness check: balanced, properly nested tags, one root, quoted
/// attributes; returns the attributes of every element start (name, attribute text).
fn xml_elements(text: &str) -> Vec<(String, String)> {
    let mut stack: Vec<String> = Vec::new();
    let mut out = Vec::new();
    let mut roots = 0;
    let mut rest = text;
    while let Some(open) = rest.find('<') {
        assert!(!rest[..open].contains('>'), "stray `>` in character data");
        let close = rest[open..].find('>').expect("unclosed tag") + open;
        let tag = &rest[open + 1..close];
        rest = &rest[close + 1..];
        if tag.starts_with('?') {
            assert!(tag.ends_with('?'));
            continue;
        }
        if let Some(name) = tag.strip_prefix('/') {
            assert_eq!(
                stack.pop().as_deref(),
                Some(name.trim()),
                "misnested </{name}>"
            );
            continue;
        }
        let self_closing = tag.ends_with('/');
        let body = tag.trim_end_matches('/');
        let name = body
            .split_whitespace()
            .next()
            .expect("empty tag")
            .to_string();
        let attrs = body[name.len()..].to_string();
        assert_eq!(
            attrs.matches('"').count() % 2,
            0,
            "unbalanced quotes in <{name}>"
        );
        if stack.is_empty() {
            roots += 1;
        }
        out.push((name.clone(), attrs));
        if !self_closing {
            stack.push(name);
        }
    }
    assert!(stack.is_empty(), "unclosed elements {stack:?}");
    assert_eq!(roots, 1, "one root element");
    out
}

#[test]
fn write_vtu_gives_well_formed_xml_with_the_right_sizes() {
    let dir = scratch("vtu");
    let m = lattice_box(Vec3::zeros(), Vec3::new(0.2, 0.1, 0.1), [4, 2, 2]);
    let n = m.nodes.len();
    let temperature: Vec<f64> = (0..n).map(|i| i as f64 * 0.5).collect();
    let displacement: Vec<Vec3> = m.nodes.iter().map(|p| p * 0.01).collect();
    let path = dir.join("state.vtu");
    mesh::write_vtu(
        &path,
        &m.nodes,
        &m.tets,
        &[("temperature <K>", &temperature)],
        &[("displacement", &displacement)],
    )
    .unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    let elements = xml_elements(&text);
    let piece = elements
        .iter()
        .find(|(name, _)| name == "Piece")
        .expect("a Piece element");
    assert!(
        piece.1.contains(&format!("NumberOfPoints=\"{n}\"")),
        "{}",
        piece.1
    );
    assert!(
        piece
            .1
            .contains(&format!("NumberOfCells=\"{}\"", m.tets.len())),
        "{}",
        piece.1
    );
    assert_eq!(elements[0].0, "VTKFile");
    assert!(elements[0].1.contains("UnstructuredGrid"));
    let arrays = elements
        .iter()
        .filter(|(name, _)| name == "DataArray")
        .count();
    assert_eq!(arrays, 2 + 1 + 3, "2 point arrays, points, 3 cell arrays");
    assert!(text.contains("Name=\"temperature &lt;K&gt;\""));
    // The connectivity holds 4 indices per tet.
    let conn = text
        .split("Name=\"connectivity\" format=\"ascii\">")
        .nth(1)
        .and_then(|s| s.split("</DataArray>").next())
        .unwrap();
    assert_eq!(conn.split_whitespace().count(), 4 * m.tets.len());
    // Wrong array lengths are refused.
    let short = vec![0.0; n - 1];
    assert!(mesh::write_vtu(
        &dir.join("bad.vtu"),
        &m.nodes,
        &m.tets,
        &[("s", &short)],
        &[]
    )
    .is_err());
}

#[test]
fn obj_surfaces_load() {
    let s = mesh::read_obj(&shared("liver-smooth.obj"), 0.03).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!((s.vertices.len(), s.triangles.len()), (2194, 4384));
    assert!(s
        .triangles
        .iter()
        .flatten()
        .all(|&i| (i as usize) < s.vertices.len()));

    let dir = scratch("obj");
    let path = dir.join("quad.obj");
    std::fs::write(
        &path,
        "# a unit square and a triangle\no q\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\n\
         f 1/1/1 2/1/1 3//1 4\nv 2 2 2\nf -3 -2 -1\n",
    )
    .unwrap();
    let s = mesh::read_obj(&path, 2.0).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(s.vertices.len(), 5);
    assert_eq!(s.vertices[2], Vec3::new(2.0, 2.0, 0.0));
    assert_eq!(s.triangles, vec![[0, 1, 2], [0, 2, 3], [2, 3, 4]]);

    let bad = dir.join("bad.obj");
    std::fs::write(&bad, "v 0 0 0\nv 1 0 0\nv 0 1 0\n\nf 1 2 9\n").unwrap();
    let e = mesh::read_obj(&bad, 1.0).unwrap_err();
    assert_error_at(&e, "bad.obj", Some(5));
    std::fs::write(&bad, "v 0 0 0\nv 1 0 0\nf 1 2 -3\n").unwrap();
    assert_error_at(&mesh::read_obj(&bad, 1.0).unwrap_err(), "bad.obj", Some(3));
    std::fs::write(&bad, "v 0 0 0\nv 1 x 0\n").unwrap();
    assert_error_at(&mesh::read_obj(&bad, 1.0).unwrap_err(), "bad.obj", Some(2));
    std::fs::write(&bad, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n").unwrap();
    assert_error_at(&mesh::read_obj(&bad, 1.0).unwrap_err(), "bad.obj", Some(4));
    std::fs::write(&bad, "v 0 0 0\n").unwrap();
    assert_error_at(&mesh::read_obj(&bad, 1.0).unwrap_err(), "bad.obj", None);
}

/// Number of connected components of the tets (two tets are connected when they share a node).
fn components(m: &TetMesh) -> usize {
    let mut parent: Vec<usize> = (0..m.nodes.len()).collect();
    fn find(p: &mut [usize], mut i: usize) -> usize {
        while p[i] != i {
            p[i] = p[p[i]];
            i = p[i];
        }
        i
    }
    for t in &m.tets {
        for k in 1..4 {
            let (a, b) = (
                find(&mut parent, t[0] as usize),
                find(&mut parent, t[k] as usize),
            );
            parent[a] = b;
        }
    }
    (0..m.nodes.len())
        .filter(|&i| find(&mut parent, i) == i)
        .count()
}

#[test]
fn default_organ_is_a_valid_deterministic_liver_sized_solid() {
    let m = mesh::default_organ();
    assert_eq!(m, mesh::default_organ(), "deterministic");
    let n = m.nodes.len();
    assert!((1500..=3000).contains(&n), "{n} nodes");
    assert!(m.tets.len() >= 3 * n, "{} tets", m.tets.len());
    // Positive, non-degenerate tets: the smallest is a sizeable fraction of the mean.
    let vols = signed_volumes(&m);
    let mean = vols.iter().sum::<f64>() / vols.len() as f64;
    let min = vols.iter().cloned().fold(f64::INFINITY, f64::min);
    assert!(min > 0.05 * mean, "min tet volume {min} vs mean {mean}");
    // Cleaning changes nothing.
    let (again, r) =
        TetMesh::from_raw(m.nodes.clone(), m.tets.clone(), Path::new("organ")).unwrap();
    assert_eq!(again, m);
    assert_eq!(
        r.reoriented_tets + r.degenerate_tets_removed + r.unreferenced_nodes_removed,
        0
    );
    // About 0.2 m across, a liver-like volume (an adult liver is ~1.5 L).
    let (lo, hi) = m.bounding_box();
    let size = hi - lo;
    assert!(size.max() > 0.18 && size.max() < 0.22, "size {size:?}");
    assert!(size.min() > 0.05, "not flat: {size:?}");
    let v = m.volume();
    assert!(v > 0.8e-3 && v < 2.0e-3, "volume {v} m^3");
    // One piece, closed outward boundary.
    assert_eq!(components(&m), 1);
    let tris = m.boundary_triangles();
    assert_closed_and_consistent(&tris);
    let sv = surface_volume(&m, &tris);
    assert!((sv - v).abs() < 1e-9 * v);
    let e = m.mean_edge_length();
    assert!(e > 0.005 && e < 0.02, "mean edge {e} m");
}
