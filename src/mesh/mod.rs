//! Tetrahedral meshes: the in-memory [`TetMesh`], one reader per file format, OBJ surfaces for
//! tools, the VTU writer, and the embedded default organ.
//!
//! Readers return node positions multiplied by the caller's `scale` (mesh units → metres).
//! Every mesh goes through [`TetMesh::from_raw`], which re-orients inverted tetrahedra, removes
//! degenerate ones and unreferenced nodes, and reports what it did in a [`MeshReport`].

use crate::kernels::math::{tet_volume, Real, Vec3};
use std::path::Path;

mod boundary;
pub(crate) use boundary::boundary_vertices;
mod clean;
mod gmsh;
mod lattice;
pub(crate) mod obj;
mod organ;
pub(crate) mod parse;
mod tetgen;
mod vtk;
mod vtu;

pub use crate::error::MeshError;
pub use clean::DEGENERATE_RELATIVE_VOLUME;
pub use lattice::lattice_box;

/// A tetrahedral mesh: node positions (m) and tetrahedra as 4 node indices each, every
/// tetrahedron positively oriented (`((b-a)×(c-a))·(d-a) > 0`).
#[derive(Debug, Clone, PartialEq)]
pub struct TetMesh {
    /// Node positions (m), one per node.
    pub nodes: Vec<Vec3>,
    /// Tetrahedra, four indices into `nodes` each, positively oriented.
    pub tets: Vec<[u32; 4]>,
}

/// What cleaning a raw mesh changed.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct MeshReport {
    /// Tetrahedra whose orientation was negative and that were re-oriented (two nodes swapped).
    pub reoriented_tets: usize,
    /// Tetrahedra of (near) zero volume that were removed.
    pub degenerate_tets_removed: usize,
    /// Nodes that no tetrahedron references and that were removed (indices renumbered).
    pub unreferenced_nodes_removed: usize,
    /// Elements of other types (points, lines, triangles, ...) skipped by the reader.
    pub skipped_elements: usize,
    /// For each node kept, its 0-based position in the file's node list (file order).
    pub original_node_index: Vec<u32>,
}

/// A triangulated surface (an OBJ tool shape): vertices (m) and triangles.
#[derive(Debug, Clone, PartialEq)]
pub struct SurfaceMesh {
    /// Vertex positions (m).
    pub vertices: Vec<Vec3>,
    /// Triangles, three vertex indices each.
    pub triangles: Vec<[u32; 3]>,
}

/// Check a load scale factor (mesh units → m): finite, else [`Error::NonFinite`](crate::Error),
/// and positive, else [`Error::InvalidArgument`](crate::Error). The readers apply this rule
/// (reporting a [`MeshError`] naming the file); the C API checks it before opening a file.
pub fn validate_scale(scale: Real) -> Result<(), crate::Error> {
    crate::error::check_positive("scale", scale, "")
}

/// Load a tetrahedral mesh, choosing the reader from the file name: `.msh` (Gmsh v1, 2.2 or
/// 4.1 ASCII), `.node` / `.ele` (TetGen, 0- or 1-based), `.vtk` (legacy VTK ASCII
/// `UNSTRUCTURED_GRID`). Node positions are multiplied by `scale` (mesh units → m).
///
/// A path without one of these extensions is read as a TetGen base name when `<path>.node`
/// exists. `scale` must be finite and > 0.
pub fn load(path: &Path, scale: Real) -> Result<(TetMesh, MeshReport), MeshError> {
    parse::check_scale(path, scale)?;
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase());
    match ext.as_deref() {
        Some("node") | Some("ele") => tetgen::read_tetgen(path, scale),
        Some("msh") => gmsh::read_gmsh(path, scale),
        Some("vtk") => vtk::read_vtk(path, scale),
        _ if tetgen::tetgen_paths(path).0.is_file() => tetgen::read_tetgen(path, scale),
        Some(e) => Err(MeshError::file(
            path,
            format!("unknown mesh file extension `.{e}` (expected .msh, .node, .ele or .vtk)"),
        )),
        None => Err(MeshError::file(
            path,
            "no file extension and no TetGen `.node` file of that base name \
             (expected .msh, .node, .ele or .vtk)",
        )),
    }
}

/// Read a Wavefront OBJ surface (`v` and `f` records; polygons fan-triangulated), positions
/// multiplied by `scale`.
pub fn read_obj(path: &Path, scale: Real) -> Result<SurfaceMesh, MeshError> {
    obj::read_obj(path, scale)
}

/// Write `mesh` as legacy VTK ASCII `UNSTRUCTURED_GRID` (cell type 10), readable by [`load`].
pub fn write_vtk(path: &Path, mesh: &TetMesh) -> std::io::Result<()> {
    vtk::write_vtk(path, mesh)
}

/// Write a body's state for ParaView as VTU (XML `UnstructuredGrid`, ASCII): points (m),
/// tetrahedra, and per-point data arrays (scalars and 3-vectors, named).
pub fn write_vtu(
    path: &Path,
    positions: &[Vec3],
    tets: &[[u32; 4]],
    point_scalars: &[(&str, &[Real])],
    point_vectors: &[(&str, &[Vec3])],
) -> std::io::Result<()> {
    vtu::write_vtu(
        path,
        positions,
        tets,
        vtu::VTK_TETRA,
        point_scalars,
        point_vectors,
    )
}

/// Write a triangulated surface for ParaView as VTU (XML `UnstructuredGrid`, ASCII, cell type
/// 5): points (m), triangles, and per-point data arrays (scalars and 3-vectors, named), e.g.
/// the deformed render surface with its `Normals`.
pub fn write_vtu_surface(
    path: &Path,
    positions: &[Vec3],
    triangles: &[[u32; 3]],
    point_scalars: &[(&str, &[Real])],
    point_vectors: &[(&str, &[Vec3])],
) -> std::io::Result<()> {
    vtu::write_vtu(
        path,
        positions,
        triangles,
        vtu::VTK_TRIANGLE,
        point_scalars,
        point_vectors,
    )
}

/// The embedded default organ: a liver-like lobed solid about 0.2 m across, tetrahedralised
/// by the project's own code. Needs no file.
///
/// It has 2,243 nodes and 9,918 tetrahedra (mean edge 0.012 m), a volume of about
/// 1.4 × 10⁻³ m³ (1.4 L) and a bounding box of about [-0.108, 0.103] × [-0.045, 0.058] ×
/// [-0.068, 0.068] m (x left–right, y up, z front–back). Every call returns the same bits.
pub fn default_organ() -> TetMesh {
    organ::build_organ(organ::DEFAULT_CELL)
}

/// The default organ's shape tetrahedralised on a lattice of cubes of edge `cell` (m), for
/// convergence studies: `organ_with_cell(0.0095)` is [`default_organ`]; halving `cell`
/// gives about eight times the nodes. `cell` is clamped to [0.003, 0.05] m.
pub fn organ_with_cell(cell: Real) -> TetMesh {
    organ::build_organ(cell.clamp(0.003, 0.05))
}

impl TetMesh {
    /// Validate and clean raw arrays: indices in range, inverted tetrahedra re-oriented,
    /// degenerate ones and unreferenced nodes removed. `path` names the source in errors.
    pub fn from_raw(
        nodes: Vec<Vec3>,
        tets: Vec<[u32; 4]>,
        path: &Path,
    ) -> Result<(TetMesh, MeshReport), MeshError> {
        clean::clean(nodes, tets, path)
    }
    /// Boundary triangles (faces belonging to one tetrahedron only), outward oriented, in a
    /// deterministic order.
    pub fn boundary_triangles(&self) -> Vec<[u32; 3]> {
        boundary::boundary_triangles(self)
    }
    /// Sum of the tetrahedron volumes (m³).
    pub fn volume(&self) -> Real {
        let n = self.nodes.len();
        self.tets
            .iter()
            .filter(|t| t.iter().all(|&i| (i as usize) < n))
            .map(|t| {
                let p = |k: usize| &self.nodes[t[k] as usize];
                tet_volume(p(0), p(1), p(2), p(3))
            })
            .sum()
    }
    /// Axis-aligned bounding box `(min, max)` of the nodes (m).
    ///
    /// An empty mesh gives `(0, 0)`.
    pub fn bounding_box(&self) -> (Vec3, Vec3) {
        let Some(first) = self.nodes.first() else {
            return (Vec3::zeros(), Vec3::zeros());
        };
        self.nodes
            .iter()
            .fold((*first, *first), |(lo, hi), p| (lo.inf(p), hi.sup(p)))
    }
    /// Mean length of the tetrahedron edges (m).
    ///
    /// Every edge shared by several tetrahedra counts once; an empty mesh gives 0.
    pub fn mean_edge_length(&self) -> Real {
        let n = self.nodes.len();
        let mut edges: Vec<(u32, u32)> = Vec::with_capacity(self.tets.len() * 6);
        for t in self
            .tets
            .iter()
            .filter(|t| t.iter().all(|&i| (i as usize) < n))
        {
            for a in 0..4 {
                for b in a + 1..4 {
                    if t[a] != t[b] {
                        edges.push((t[a].min(t[b]), t[a].max(t[b])));
                    }
                }
            }
        }
        edges.sort_unstable();
        edges.dedup();
        if edges.is_empty() {
            return 0.0;
        }
        let total: Real = edges
            .iter()
            .map(|&(a, b)| (self.nodes[a as usize] - self.nodes[b as usize]).norm())
            .sum();
        total / edges.len() as Real
    }
}
