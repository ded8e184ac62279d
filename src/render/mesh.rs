//! [`RenderMesh`]: the visual surface as a renderer wants it, one vertex per distinct
//! combination of position, texture coordinate and normal.

use crate::error::Error;
use crate::kernels::math::{is_finite_vec, Real, Vec3};
use std::collections::HashMap;

/// Where a render vertex came from: 0-based indices of its OBJ `v`, `vt` and `vn` records.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct ObjVertex {
    /// Index of the position (`v` record; for a body boundary, the particle index).
    pub position: u32,
    /// Index of the texture coordinate (`vt` record), if the face gave one.
    pub texcoord: Option<u32>,
    /// Index of the normal (`vn` record), if the face gave one.
    pub normal: Option<u32>,
}

/// A triangulated visual surface. Vertex `i` has position `positions[i]` (m),
/// texture coordinates `texcoords[i]`, file normal `normals[i]` and source `sources[i]`; all
/// four arrays have one entry per render vertex.
#[derive(Debug, Clone, PartialEq)]
pub struct RenderMesh {
    /// Rest positions of the render vertices (m).
    pub positions: Vec<Vec3>,
    /// Texture coordinates (u, v) (dimensionless); (0, 0) for vertices given without one.
    pub texcoords: Vec<[Real; 2]>,
    /// Normals read from the file (unit); zero for vertices given without one. The render
    /// surface recomputes its normals from the deformed triangles; these are for reference.
    pub normals: Vec<Vec3>,
    /// The OBJ triple of each render vertex. Vertices with the same position index move
    /// together; vertices with the same position and normal index share a recomputed normal
    /// (so texture seams stay smooth and the file's hard edges stay hard).
    pub sources: Vec<ObjVertex>,
    /// Triangles, three render-vertex indices each, in the file's winding.
    pub triangles: Vec<[u32; 3]>,
    /// True when at least one vertex had a texture coordinate.
    pub has_texcoords: bool,
}

impl RenderMesh {
    /// A body's boundary as a render mesh: one vertex per node used by `boundary` (triangles
    /// indexing `nodes`, m; `sources[i].position` is the node index), the same triangles
    /// renumbered, no texture coordinates and no file normals. For bodies that have no visual
    /// surface of their own: `from_boundary(body.rest_positions(), body.boundary_triangles())`.
    /// Indices of `boundary` must be in range.
    pub fn from_boundary(nodes: &[Vec3], boundary: &[[u32; 3]]) -> RenderMesh {
        let mut vertex_of = vec![u32::MAX; nodes.len()];
        let mut sources = Vec::new();
        let triangles = boundary
            .iter()
            .map(|t| {
                t.map(|node| {
                    let v = &mut vertex_of[node as usize];
                    if *v == u32::MAX {
                        *v = sources.len() as u32;
                        sources.push(ObjVertex {
                            position: node,
                            texcoord: None,
                            normal: None,
                        });
                    }
                    *v
                })
            })
            .collect();
        let n = sources.len();
        RenderMesh {
            positions: sources.iter().map(|s| nodes[s.position as usize]).collect(),
            texcoords: vec![[0.0; 2]; n],
            normals: vec![Vec3::zeros(); n],
            sources,
            triangles,
            has_texcoords: false,
        }
    }

    /// Number of render vertices.
    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }

    /// Check that the arrays agree in length, indices are in range and positions are finite.
    pub fn validate(&self) -> Result<(), Error> {
        let n = self.positions.len();
        let bad = |m: String| Err(Error::InvalidArgument(format!("render mesh: {m}")));
        if n == 0 || self.triangles.is_empty() {
            return bad("no vertices or no triangles".into());
        }
        if self.texcoords.len() != n || self.normals.len() != n || self.sources.len() != n {
            return bad(format!(
                "{n} positions but {} texcoords, {} normals, {} sources",
                self.texcoords.len(),
                self.normals.len(),
                self.sources.len()
            ));
        }
        if let Some(t) = self
            .triangles
            .iter()
            .find(|t| t.iter().any(|&i| i as usize >= n))
        {
            return bad(format!("triangle {t:?} out of range ({n} vertices)"));
        }
        if let Some(i) = self.positions.iter().position(|p| !is_finite_vec(p)) {
            return Err(Error::NonFinite(format!("render mesh vertex {i}")));
        }
        Ok(())
    }

    /// For each render vertex, the index of its normal group: vertices with the same position
    /// and normal index (see [`sources`](Self::sources)) share one group.
    pub(crate) fn normal_groups(&self) -> (Vec<u32>, usize) {
        let mut ids: HashMap<(u32, Option<u32>), u32> = HashMap::new();
        let groups = self
            .sources
            .iter()
            .map(|s| {
                let next = ids.len() as u32;
                *ids.entry((s.position, s.normal)).or_insert(next)
            })
            .collect();
        (groups, ids.len())
    }
}
