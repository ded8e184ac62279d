//! The immutable part of a body: what a mesh and its [`BodyOptions`] (the [`Material`] and the
//! neighbourhood and contact radii, defined here beside the model they build) determine once,
//! at load time — rest positions, tetrahedra and their rest volumes, boundary triangles, particle
//! volumes and masses, and the neighbourhoods with their (variationally consistent) gradient
//! coefficients, the costly part of loading.
//!
//! A [`BodyModel`] is shared behind an [`Arc`]: every world (or FMU instance) built from the
//! same mesh and options may hold the same one ([`World::add_body_model`](crate::World::add_body_model)).
//! What the world's settings and the scene change — the data derived under the settings
//! (elastic constants, mass scaling: `src/scene/derived.rs`), the fixed particles, the particle
//! state — lives in [`Body`](crate::Body).
//! A cut is the one operation that changes a model; it makes the cut body's own copy first
//! (copy-on-write, [`Arc::make_mut`]), so the other holders keep the uncut model.

use crate::error::{check_finite, check_positive, Error};
use crate::kernels::collision::surface_tree::SurfaceTree;
use crate::kernels::colouring::TetColouring;
use crate::kernels::math::{is_finite_vec, tet_volume, Real, Vec3};
use crate::kernels::neighbours::{self, Neighbourhoods, SupportRadius};
use crate::kernels::tet_dashpots::TetDashpots;
use crate::kernels::tet_elasticity::TetElements;
use crate::mesh::TetMesh;
use crate::model::consistency;
use crate::model::dual_cells::DualCells;
use crate::model::particle_order::ParticleOrder;
use std::sync::Arc;

/// An isotropic linear-elastic material (SI units).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Material {
    /// Young's modulus E (Pa).
    pub youngs_modulus: Real,
    /// Poisson ratio ν (dimensionless, in [0, 0.499]: see [`MAX_POISSON_RATIO`]).
    pub poisson_ratio: Real,
    /// Mass density ρ (kg/m³).
    pub density: Real,
}

/// The range of Poisson ratios a body accepts: `[MIN_POISSON_RATIO, MAX_POISSON_RATIO]`.
///
/// Below 0 a material is auxetic (it widens when stretched): no soft tissue is, and the
/// corotated stress with volume constraints was seen to explode there (ν = −0.5 and
/// ν → −1 turned organs inside out under a probe). Towards 0.5 the volumetric stiffness
/// λ = Eν/((1+ν)(1−2ν)) diverges (λ/μ = 2ν/(1−2ν) is 98 at 0.49, 499 at 0.499, ∞ at 0.5).
/// Soft tissue lies at 0.45–0.499; up to 0.499 the volume constraints carry λ implicitly
/// (XPBD), so the step does not stiffen: liver_4k sagging 7 cm keeps its volume within 0.25%
/// at 0.499 (0.5% at 0.49). With the volume constraints off the particles carry λ
/// explicitly, and the mass scaling that keeps such a step stable grows with λ (slow,
/// heavy dynamics near 0.5).
pub const MIN_POISSON_RATIO: Real = 0.0;
/// See [`MIN_POISSON_RATIO`].
pub const MAX_POISSON_RATIO: Real = 0.499;

/// Accepted Young's moduli (Pa): from 10⁻⁶ Pa (far softer than any tissue, and well above the
/// denormal numbers, whose arithmetic is slow and loses precision) to 10¹² Pa (stiffer than
/// diamond; beyond it stresses overflow long before the explicit step could resolve them).
pub const YOUNGS_MODULUS_RANGE: (Real, Real) = (1e-6, 1e12);

/// Accepted densities (kg/m³): from 10⁻⁶ (models in mesh units use ρ = 1) to 10⁵ (four times
/// osmium, the densest element).
pub const DENSITY_RANGE: (Real, Real) = (1e-6, 1e5);

impl Material {
    /// Check the material: NaN or ±Inf give [`Error::NonFinite`]; E outside
    /// [`YOUNGS_MODULUS_RANGE`], ν outside [[`MIN_POISSON_RATIO`], [`MAX_POISSON_RATIO`]] or ρ
    /// outside [`DENSITY_RANGE`] give [`Error::InvalidArgument`], the message naming the field,
    /// the range and why. The one validation of materials, used when a body is built, by the C
    /// API and by the FMU.
    pub fn validate(&self) -> Result<(), Error> {
        check_finite("material.youngs_modulus", self.youngs_modulus)?;
        check_finite("material.poisson_ratio", self.poisson_ratio)?;
        check_finite("material.density", self.density)?;
        let bad = |s: String| Err(Error::InvalidArgument(s));
        let (e_lo, e_hi) = YOUNGS_MODULUS_RANGE;
        if !(e_lo..=e_hi).contains(&self.youngs_modulus) {
            return bad(format!(
                "material.youngs_modulus must be in [{e_lo:e}, {e_hi:e}] Pa, got {:e}",
                self.youngs_modulus
            ));
        }
        let nu = self.poisson_ratio;
        if !(MIN_POISSON_RATIO..=MAX_POISSON_RATIO).contains(&nu) {
            return bad(format!(
                "material.poisson_ratio must be in [{MIN_POISSON_RATIO}, {MAX_POISSON_RATIO}], got {nu}: \
                 negative values are auxetic (not tissue) and unstable here, and the volumetric \
                 stiffness lambda = E nu / ((1 + nu)(1 - 2 nu)) diverges as nu -> 0.5"
            ));
        }
        let (d_lo, d_hi) = DENSITY_RANGE;
        if !(d_lo..=d_hi).contains(&self.density) {
            return bad(format!(
                "material.density must be in [{d_lo:e}, {d_hi:e}] kg/m3, got {:e}",
                self.density
            ));
        }
        Ok(())
    }
    /// First Lamé parameter λ = Eν / ((1 + ν)(1 - 2ν)) (Pa): under the volumetric split the
    /// volume constraints get compliance `1/λ`.
    pub fn lame_lambda(&self) -> Real {
        let (e, nu) = (self.youngs_modulus, self.poisson_ratio);
        e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu))
    }
    /// Shear modulus μ = E / (2(1 + ν)) (Pa).
    pub fn shear_modulus(&self) -> Real {
        self.youngs_modulus / (2.0 * (1.0 + self.poisson_ratio))
    }
}

impl Default for Material {
    /// Liver-like soft tissue: E = 5 kPa, ν = 0.45, ρ = 1060 kg/m³.
    fn default() -> Self {
        Material {
            youngs_modulus: 5.0e3,
            poisson_ratio: 0.45,
            density: 1060.0,
        }
    }
}

/// Options for building a body.
#[derive(Debug, Clone, PartialEq)]
pub struct BodyOptions {
    /// The material.
    pub material: Material,
    /// Support radius of every particle (m); `None` chooses one per particle so that its moment
    /// matrix is well conditioned.
    pub support_radius: Option<Real>,
    /// Target number of neighbours when the support radius is chosen automatically.
    pub target_neighbours: u32,
    /// Contact radius of the particles (m) for organ–organ contact and the sampled-points tool
    /// contact (tools in the exact-shape mode touch the boundary triangles, with a skin of a
    /// tenth of this radius); `None` takes half the mean tetrahedron edge.
    pub particle_radius: Option<Real>,
    /// Correct the MLS gradients at load time so that nodal integration satisfies the discrete
    /// divergence theorem (variationally consistent integration, Chen, Hillman & Rüter 2013): a
    /// uniform stress then leaves interior particles in equilibrium on any point set, and the
    /// response does not depend on how irregular the mesh is. `false` keeps the plain MLS
    /// gradients of the paper (for comparison only).
    pub consistent_gradients: bool,
}

/// Accepted range of [`BodyOptions::particle_radius`], in mean tetrahedron edge lengths: a
/// radius far below the spacing lets particles pass between each other and makes every swept
/// tool motion need countless substeps; far above it, neighbouring particles of one body
/// overlap and tool contact pushes whole regions at once.
pub const PARTICLE_RADIUS_RANGE: (Real, Real) = (0.05, 2.0);

/// Accepted range of [`BodyOptions::support_radius`], in mean tetrahedron edge lengths: below,
/// a particle has too few neighbours for a well-conditioned moment matrix; above, the neighbour
/// count (and the memory and time of every step) grows with the cube of the radius.
pub const SUPPORT_RADIUS_RANGE: (Real, Real) = (0.5, 3.0);

impl BodyOptions {
    /// Check the options: the material ([`Material::validate`]), radii finite and > 0 m when
    /// given, `target_neighbours` ≥ 1. NaN or ±Inf give [`Error::NonFinite`], other bad values
    /// [`Error::InvalidArgument`]. Used when a body is built and by the C API.
    pub fn validate(&self) -> Result<(), Error> {
        self.material.validate()?;
        if let Some(r) = self.support_radius {
            check_positive("options.support_radius", r, "m")?;
        }
        if let Some(r) = self.particle_radius {
            check_positive("options.particle_radius", r, "m")?;
        }
        if self.target_neighbours == 0 {
            return Err(Error::InvalidArgument(
                "options.target_neighbours must be >= 1".into(),
            ));
        }
        Ok(())
    }

    /// Check the material and the radii against a mesh of mean edge length `mean_edge` (m):
    /// explicit radii must lie in [`PARTICLE_RADIUS_RANGE`] and [`SUPPORT_RADIUS_RANGE`] (in
    /// mean edge lengths), `target_neighbours` in 1..=[`MAX_NEIGHBOURS`](crate::MAX_NEIGHBOURS).
    pub fn check_radii(&self, mean_edge: Real) -> Result<(), Error> {
        self.validate()?;
        for (name, value, (lo, hi)) in [
            (
                "particle_radius",
                self.particle_radius,
                PARTICLE_RADIUS_RANGE,
            ),
            ("support_radius", self.support_radius, SUPPORT_RADIUS_RANGE),
        ] {
            let Some(r) = value else { continue };
            let (min, max) = (lo * mean_edge, hi * mean_edge);
            if !(r.is_finite() && r >= min && r <= max) {
                return Err(Error::InvalidArgument(format!(
                    "{name} {r:e} m is outside [{min:.3e}, {max:.3e}] m, i.e. [{lo}, {hi}] x the \
                     mesh's mean edge length {mean_edge:.3e} m"
                )));
            }
        }
        let k = self.target_neighbours as usize;
        if !(1..=neighbours::MAX_NEIGHBOURS).contains(&k) {
            return Err(Error::InvalidArgument(format!(
                "target_neighbours must be in 1..={}, got {k}",
                neighbours::MAX_NEIGHBOURS
            )));
        }
        Ok(())
    }
}

impl Default for BodyOptions {
    fn default() -> Self {
        BodyOptions {
            material: Material::default(),
            support_radius: None,
            target_neighbours: 20,
            particle_radius: None,
            consistent_gradients: true,
        }
    }
}

/// The load-time data of a body (see the module documentation).
#[derive(Debug, Clone, PartialEq)]
pub struct BodyModel {
    /// The options it was built with (material, neighbourhood and contact settings).
    pub(crate) options: BodyOptions,
    /// Rest positions (m).
    pub(crate) rest: Vec<Vec3>,
    /// Physical particle masses `ρ v_i` (kg): gravity acts on these.
    pub(crate) mass: Vec<Real>,
    /// Particle volumes (m³): a quarter of each tetrahedron around the particle.
    pub(crate) particle_volume: Vec<Real>,
    pub(crate) nbr: Neighbourhoods,
    pub(crate) tets: Vec<[u32; 4]>,
    /// Tetrahedron rest volumes (m³).
    pub(crate) tet_rest_volume: Vec<Real>,
    /// Boundary triangles, outward normals.
    pub(crate) boundary: Vec<[u32; 3]>,
    /// The particles at the boundary triangles' corners, each once, increasing.
    pub(crate) boundary_vertices: Vec<u32>,
    /// The bounding-volume hierarchy of the boundary triangles at rest, the self-contact's
    /// broad phase.
    pub(crate) boundary_tree: SurfaceTree,
    /// Contact radius of the particles (m).
    pub(crate) particle_radius: Real,
    /// Centre of the rest bounding box (m).
    pub(crate) rest_centre: Vec3,
    /// Diagonal of the rest bounding box (m): the body's size.
    pub(crate) size: Real,
    /// Rest volume (m³).
    pub(crate) rest_volume: Real,
    /// The tetrahedra grouped into colours that share no particle, for the volume pass.
    pub(crate) tet_colouring: TetColouring,
    /// The particles' dual cells, for volume constraints per particle.
    pub(crate) dual_cells: DualCells,
    /// The tetrahedra as corotated elements (`ElasticScheme::Tetrahedra`).
    pub(crate) tet_elements: TetElements,
    /// The tetrahedra's edges as dashpots (`Settings::damping_stiffness`, both elastic schemes).
    pub(crate) tet_dashpots: TetDashpots,
    /// Which mesh node each particle is: every array above is in particle order.
    pub(crate) order: ParticleOrder,
}

impl BodyModel {
    /// Build the model of a cleaned mesh (positions in m) with `options`: validates both,
    /// computes the particle volumes, the neighbourhoods and their gradient coefficients.
    ///
    /// Errors: [`Error::InvalidArgument`] for invalid options, a mesh with fewer than one
    /// tetrahedron or 5 nodes, an index out of range, a tetrahedron not positively oriented,
    /// a node in no tetrahedron, or no well-conditioned neighbourhood; [`Error::NonFinite`]
    /// for a non-finite node.
    pub fn new(mesh: &TetMesh, options: &BodyOptions) -> Result<Arc<BodyModel>, Error> {
        options.validate()?;
        let bad = |s: String| Err(Error::InvalidArgument(s));
        let n = mesh.nodes.len();
        if mesh.tets.is_empty() || n < 5 {
            return bad("a body needs at least one tetrahedron and 5 nodes".into());
        }
        if let Some(k) = mesh.nodes.iter().position(|p| !is_finite_vec(p)) {
            return Err(Error::NonFinite(format!("mesh node {k}")));
        }
        if let Some(t) = mesh
            .tets
            .iter()
            .position(|tet| tet.iter().any(|&k| k as usize >= n))
        {
            return bad(format!("tetrahedron {t} references a node out of range"));
        }
        // Everything below works in particle order; messages name mesh nodes.
        let order = ParticleOrder::morton(&mesh.nodes);
        let boundary: Vec<[u32; 3]> = mesh
            .boundary_triangles()
            .iter()
            .map(|t| order.particles_of_array(t))
            .collect();
        let mesh = &order.renumber(mesh);
        let mut particle_volume = vec![0.0; n];
        let mut tet_rest_volume = Vec::with_capacity(mesh.tets.len());
        for (t, tet) in mesh.tets.iter().enumerate() {
            let [a, b, c, d] = tet.map(|k| mesh.nodes[k as usize]);
            let vol = tet_volume(&a, &b, &c, &d);
            if vol <= 0.0 {
                return bad(format!("tetrahedron {t} is not positively oriented"));
            }
            tet_rest_volume.push(vol);
            for &k in tet {
                particle_volume[k as usize] += 0.25 * vol;
            }
        }
        if let Some(i) = particle_volume.iter().position(|&v| v <= 0.0) {
            let k = order.mesh_index(i);
            return bad(format!("node {k} belongs to no tetrahedron"));
        }
        options.check_radii(mesh.mean_edge_length())?;
        let support = match options.support_radius {
            Some(h) => SupportRadius::Fixed(h),
            None => SupportRadius::Automatic {
                target: options.target_neighbours as usize,
            },
        };
        let mut nbr = neighbours::build(&mesh.nodes, support).map_err(|e| {
            Error::InvalidArgument(match e.particle {
                Some(i) => format!("mesh node {}: {}", order.mesh_index(i), e.reason),
                None => e.reason,
            })
        })?;
        if options.consistent_gradients {
            consistency::correct_gradients(&mut nbr, &mesh.nodes, &particle_volume, &boundary);
        }
        let density = options.material.density;
        let (lo, hi) = mesh.bounding_box();
        let tet_colouring = TetColouring::new(&mesh.tets, &tet_rest_volume, n);
        let dual_cells = DualCells::new(&mesh.tets, &tet_rest_volume, n);
        let tet_elements = TetElements::new(&mesh.nodes, &mesh.tets, &tet_rest_volume, n);
        let tet_dashpots = TetDashpots::new(&mesh.nodes, &mesh.tets, &tet_rest_volume, n);
        Ok(Arc::new(BodyModel {
            options: options.clone(),
            rest: mesh.nodes.clone(),
            mass: particle_volume.iter().map(|v| v * density).collect(),
            particle_volume,
            nbr,
            rest_volume: tet_rest_volume.iter().sum(),
            tet_rest_volume,
            tets: mesh.tets.clone(),
            boundary_vertices: crate::mesh::boundary_vertices(&boundary),
            boundary_tree: SurfaceTree::new(&mesh.nodes, &boundary),
            boundary,
            particle_radius: options
                .particle_radius
                .unwrap_or_else(|| 0.5 * mesh.mean_edge_length()),
            rest_centre: (lo + hi) * 0.5,
            size: (hi - lo).norm(),
            tet_colouring,
            dual_cells,
            tet_elements,
            tet_dashpots,
            order,
        }))
    }

    /// Number of particles (= mesh nodes).
    pub fn particle_count(&self) -> usize {
        self.rest.len()
    }
    /// The options the model was built with.
    pub fn options(&self) -> &BodyOptions {
        &self.options
    }
    /// Rest positions (m), one per particle, in particle order.
    pub fn rest_positions(&self) -> &[Vec3] {
        &self.rest
    }
    /// Which mesh node each particle is (the model stores its particles in an order of its
    /// own, see [`ParticleOrder`]).
    pub fn particle_order(&self) -> &ParticleOrder {
        &self.order
    }
    /// Whether this model was built from `mesh` (in the mesh's node order) and `options`.
    pub fn is_built_from(&self, mesh: &TetMesh, options: &BodyOptions) -> bool {
        self.options == *options
            && self.rest.len() == mesh.nodes.len()
            && self.tets.len() == mesh.tets.len()
            && mesh
                .nodes
                .iter()
                .enumerate()
                .all(|(k, p)| self.rest[self.order.particle(k)] == *p)
            && self
                .tets
                .iter()
                .zip(&mesh.tets)
                .all(|(t, m)| self.order.mesh_indices_of_array(t) == *m)
    }
    /// Tetrahedra (4 particle indices each).
    pub fn tets(&self) -> &[[u32; 4]] {
        &self.tets
    }
    /// The neighbourhoods and their rest-state quantities.
    pub fn neighbourhoods(&self) -> &Neighbourhoods {
        &self.nbr
    }
    /// Bytes of heap memory the model's arrays hold (their lengths): what each additional
    /// holder of a shared model does not allocate.
    pub fn heap_bytes(&self) -> usize {
        use std::mem::size_of_val;
        let n = &self.nbr;
        size_of_val(self.rest.as_slice())
            + size_of_val(self.mass.as_slice())
            + size_of_val(self.particle_volume.as_slice())
            + size_of_val(self.tets.as_slice())
            + size_of_val(self.tet_rest_volume.as_slice())
            + size_of_val(self.boundary.as_slice())
            + size_of_val(self.boundary_vertices.as_slice())
            + size_of_val(n.offsets.as_slice())
            + size_of_val(n.ends.as_slice())
            + size_of_val(n.index.as_slice())
            + n.rest_offset.heap_bytes()
            + n.gradient.heap_bytes()
            + size_of_val(n.hourglass_weight.as_slice())
            + size_of_val(n.support_radius.as_slice())
            + size_of_val(n.incoming_offsets.as_slice())
            + size_of_val(n.incoming.as_slice())
            + size_of_val(n.sources.as_slice())
            + self.tet_colouring.heap_bytes()
            + self.dual_cells.heap_bytes()
            + self.tet_elements.heap_bytes()
            + self.tet_dashpots.heap_bytes()
            + self.boundary_tree.heap_bytes()
            + 2 * size_of_val(self.order.mesh_indices())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::lattice_box;

    /// The model keeps its particles in its own order, but every array agrees with the mesh
    /// through that order, and an error names the mesh's node, not the particle.
    #[test]
    fn the_model_is_the_mesh_in_particle_order_and_errors_name_mesh_nodes() {
        let mesh = lattice_box(Vec3::zeros(), Vec3::new(0.04, 0.03, 0.02), [4, 3, 2]);
        let model = BodyModel::new(&mesh, &BodyOptions::default()).unwrap();
        let order = model.particle_order();
        assert!((0..order.len()).any(|i| order.mesh_index(i) != i));
        assert!(model.is_built_from(&mesh, &BodyOptions::default()));
        assert_eq!(order.to_mesh_order(model.rest_positions()), mesh.nodes);
        for (t, m) in model.tets().iter().zip(&mesh.tets) {
            assert_eq!(order.mesh_indices_of_array(t), *m);
        }
        for (b, m) in model.boundary.iter().zip(mesh.boundary_triangles()) {
            assert_eq!(order.mesh_indices_of_array(b), m);
        }
        // A node in no tetrahedron, appended last but sorted into the middle.
        let mut stray = mesh.clone();
        stray.nodes.push(Vec3::new(0.021, 0.016, 0.011));
        let k = stray.nodes.len() - 1;
        let i = ParticleOrder::morton(&stray.nodes).particle(k);
        assert_ne!(i, k);
        let e = BodyModel::new(&stray, &BodyOptions::default()).unwrap_err();
        assert_eq!(
            e.to_string(),
            Error::InvalidArgument(format!("node {k} belongs to no tetrahedron")).to_string()
        );
    }
}
