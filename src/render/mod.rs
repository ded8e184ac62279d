//! Render surfaces: a visual mesh (an OBJ with normals and texture coordinates, or a body's
//! own boundary) bound once to a body's rest tetrahedra and carried along by its particles.
//!
//! - [`RenderMesh`] (`mesh.rs`): render vertices (one per distinct OBJ `v/vt/vn` triple),
//!   texture coordinates, triangles;
//! - [`read_obj`] / [`write_obj`] (`obj.rs`): the OBJ reader and writer;
//! - [`bind`] (`bind.rs`): barycentric coordinates of every vertex in its enclosing rest
//!   tetrahedron (the nearest one, extrapolated, for vertices outside), through a uniform grid
//!   over the tetrahedra's bounding boxes;
//! - [`RenderSurface`] (`surface.rs`): a bound render mesh, its deformed positions and
//!   recomputed normals, updated without allocating; OBJ and VTU export.
//!
//! A bound vertex is an affine function of the four nodes of its tetrahedron, so any affine
//! motion of the particles moves it by exactly that motion. `World::add_render_surface` binds,
//! `World::update_render_surface` updates.

mod bind;
mod mesh;
mod obj;
mod surface;

pub use bind::{bind, BindReport, Binding, INSIDE_TOLERANCE};
pub use mesh::{ObjVertex, RenderMesh};
pub use obj::{read_obj, write_obj};
pub use surface::RenderSurface;
