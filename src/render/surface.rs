//! [`RenderSurface`]: a render mesh bound to a body, with its deformed positions and
//! recomputed normals.

use super::bind::{bind, BindReport, Binding};
use super::mesh::RenderMesh;
use crate::error::Error;
use crate::kernels::math::{Real, Vec3};
use crate::scene::body::Body;
use crate::scene::BodyId;
use std::path::Path;

/// A render mesh bound once to the rest tetrahedra of a body.
/// [`World::update_render_surface`](crate::World::update_render_surface) recomputes the deformed vertex positions (m) and the
/// per-vertex normals (area-weighted face normals, renormalised) from the body's particles,
/// without allocating; the getters return the last update.
#[derive(Debug, Clone)]
pub struct RenderSurface {
    body: BodyId,
    mesh: RenderMesh,
    bindings: Vec<Binding>,
    report: BindReport,
    /// Normal group of each vertex (see [`RenderMesh::sources`]).
    group: Vec<u32>,
    /// Scratch: the summed face normals of each group.
    group_normal: Vec<Vec3>,
    positions: Vec<Vec3>,
    normals: Vec<Vec3>,
}

impl RenderSurface {
    /// Bind `mesh` (validated; positions in the body's rest frame, m) to the rest tetrahedra of
    /// `body` (whose id is `id`), and update it from the body's current positions.
    pub(crate) fn new(id: BodyId, body: &Body, mesh: RenderMesh) -> Result<Self, Error> {
        mesh.validate()?;
        let (bindings, report) = bind(body.rest_positions(), body.tets(), &mesh.positions);
        let (group, groups) = mesh.normal_groups();
        let n = mesh.vertex_count();
        let mut s = RenderSurface {
            body: id,
            mesh,
            bindings,
            report,
            group,
            group_normal: vec![Vec3::zeros(); groups],
            positions: vec![Vec3::zeros(); n],
            normals: vec![Vec3::zeros(); n],
        };
        s.update(body.positions());
        Ok(s)
    }

    /// Recompute positions and normals from the body's particle positions `x` (m). Allocates
    /// nothing. A vertex whose incident triangles all have zero area gets a zero normal.
    pub(crate) fn update(&mut self, x: &[Vec3]) {
        for (p, b) in self.positions.iter_mut().zip(&self.bindings) {
            *p = b.apply(x);
        }
        self.group_normal.fill(Vec3::zeros());
        for t in &self.mesh.triangles {
            let [a, b, c] = t.map(|i| self.positions[i as usize]);
            // |(b - a) × (c - a)| is twice the area: summing it weights faces by area.
            let n = (b - a).cross(&(c - a));
            for i in t {
                self.group_normal[self.group[*i as usize] as usize] += n;
            }
        }
        for (n, g) in self.normals.iter_mut().zip(&self.group) {
            let sum = self.group_normal[*g as usize];
            *n = sum.try_normalize(0.0).unwrap_or_else(Vec3::zeros);
        }
    }

    /// The body the surface is bound to.
    pub fn body(&self) -> BodyId {
        self.body
    }
    /// Number of render vertices.
    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }
    /// Triangles, three vertex indices each.
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.mesh.triangles
    }
    /// Texture coordinates (u, v) per vertex; (0, 0) where the file gave none.
    pub fn texcoords(&self) -> &[[Real; 2]] {
        &self.mesh.texcoords
    }
    /// Deformed vertex positions (m, world frame) at the last update.
    pub fn positions(&self) -> &[Vec3] {
        &self.positions
    }
    /// Unit vertex normals at the last update (area-weighted, in the triangles' winding).
    pub fn normals(&self) -> &[Vec3] {
        &self.normals
    }
    /// The render mesh as loaded (rest positions, file normals, sources).
    pub fn mesh(&self) -> &RenderMesh {
        &self.mesh
    }
    /// Where each vertex is bound.
    pub fn bindings(&self) -> &[Binding] {
        &self.bindings
    }
    /// How many vertices were inside the body and how far outside the others were.
    pub fn bind_report(&self) -> &BindReport {
        &self.report
    }
    /// Write the surface at the last update as OBJ (`v`, `vt` when the mesh has texture
    /// coordinates, `vn`, `f a/b/c`), positions in m.
    pub fn write_obj(&self, path: &Path) -> std::io::Result<()> {
        let tex = self
            .mesh
            .has_texcoords
            .then_some(self.mesh.texcoords.as_slice());
        super::obj::write_obj(
            path,
            &self.positions,
            &self.normals,
            tex,
            &self.mesh.triangles,
        )
    }
    /// Write the surface at the last update as VTU (triangles, cell type 5) with the point
    /// data `Normals` (unit) and `TextureCoordinates` (u, v, 0).
    pub fn write_vtu(&self, path: &Path) -> std::io::Result<()> {
        let tex: Vec<Vec3> = self
            .mesh
            .texcoords
            .iter()
            .map(|[u, v]| Vec3::new(*u, *v, 0.0))
            .collect();
        crate::mesh::write_vtu_surface(
            path,
            &self.positions,
            &self.mesh.triangles,
            &[],
            &[("Normals", &self.normals), ("TextureCoordinates", &tex)],
        )
    }
}
