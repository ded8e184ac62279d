//! A deformable body: particles at the mesh nodes, their neighbourhoods with the rest-state
//! quantities precomputed, the tetrahedra for volume conservation, and the material.

use crate::math::{Real, Vec3};

/// An isotropic linear-elastic material (SI units).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Material {
    /// Young's modulus E (Pa).
    pub youngs_modulus: Real,
    /// Poisson ratio ν (dimensionless, in (-1, 0.5)).
    pub poisson_ratio: Real,
    /// Mass density ρ (kg/m³).
    pub density: Real,
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
    /// Contact radius of the particles (m); `None` derives it from the particle spacing.
    pub particle_radius: Option<Real>,
}

impl Default for BodyOptions {
    fn default() -> Self {
        BodyOptions {
            material: Material::default(),
            support_radius: None,
            target_neighbours: 20,
            particle_radius: None,
        }
    }
}

/// A deformable body (see the module documentation).
#[derive(Debug, Clone)]
pub struct Body {
    pub(crate) x: Vec<Vec3>,
}

impl Body {
    /// Number of particles (= mesh nodes).
    pub fn particle_count(&self) -> usize {
        self.x.len()
    }
    /// Current particle positions (m), one per particle.
    pub fn positions(&self) -> &[Vec3] {
        &self.x
    }
    /// Current particle velocities (m/s), one per particle.
    pub fn velocities(&self) -> &[Vec3] {
        todo!()
    }
    /// Rest positions (m), one per particle.
    pub fn rest_positions(&self) -> &[Vec3] {
        todo!()
    }
    /// Tetrahedra (4 particle indices each).
    pub fn tets(&self) -> &[[u32; 4]] {
        todo!()
    }
    /// Boundary triangles of the tetrahedral mesh (3 particle indices each, outward normals).
    pub fn boundary_triangles(&self) -> &[[u32; 3]] {
        todo!()
    }
    /// Current volume (m³): the sum of the signed tetrahedron volumes.
    pub fn volume(&self) -> Real {
        todo!()
    }
    /// Rest volume (m³).
    pub fn rest_volume(&self) -> Real {
        todo!()
    }
    /// `volume() / rest_volume()` (dimensionless).
    pub fn volume_ratio(&self) -> Real {
        self.volume() / self.rest_volume()
    }
    /// Largest distance of a particle from its rest position (m).
    pub fn max_displacement(&self) -> Real {
        todo!()
    }
    /// True when particle `i` is fixed.
    pub fn is_fixed(&self, i: usize) -> bool {
        let _ = i;
        todo!()
    }
    /// Contact radius of the particles (m).
    pub fn particle_radius(&self) -> Real {
        todo!()
    }
    /// Total mass (kg).
    pub fn mass(&self) -> Real {
        todo!()
    }
    /// The material.
    pub fn material(&self) -> &Material {
        todo!()
    }
}
