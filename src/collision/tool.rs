//! Kinematic rigid instruments: their shape (a parry shape), pose, friction and contact wrench.

use crate::math::{Quat, Real, Vec3};

/// The shape of a tool, in its own frame (m). Built into a parry shape when the tool is added.
#[derive(Debug, Clone, PartialEq)]
pub enum ToolShape {
    /// A sphere centred on the tool origin.
    Sphere {
        /// Radius (m).
        radius: Real,
    },
    /// A capsule along the tool's local y axis, centred on the origin.
    Capsule {
        /// Half the length of the segment between the two hemisphere centres (m).
        half_height: Real,
        /// Radius (m).
        radius: Real,
    },
    /// A cylinder along the tool's local y axis, centred on the origin.
    Cylinder {
        /// Half the length (m).
        half_height: Real,
        /// Radius (m).
        radius: Real,
    },
    /// A box centred on the origin.
    Cuboid {
        /// Half extents along local x, y, z (m).
        half_extents: Vec3,
    },
    /// The convex hull of a point cloud (m, local frame).
    ConvexHull {
        /// Points whose hull is the shape (m).
        points: Vec<Vec3>,
    },
    /// A triangle mesh (m, local frame), e.g. read from OBJ.
    TriMesh {
        /// Vertex positions (m).
        vertices: Vec<Vec3>,
        /// Triangles as three vertex indices.
        triangles: Vec<[u32; 3]>,
    },
}

/// A rigid pose: position (m) of the tool origin and orientation, both in the world frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pose {
    /// Position of the tool origin (m, world frame).
    pub position: Vec3,
    /// Orientation (unit quaternion, local → world).
    pub orientation: Quat,
}

impl Pose {
    /// A pose at `position` (m) with the identity orientation.
    pub fn at(position: Vec3) -> Self {
        Pose {
            position,
            orientation: Quat::identity(),
        }
    }
}

/// Options of a tool.
#[derive(Debug, Clone, PartialEq)]
pub struct ToolOptions {
    /// Static friction coefficient μ_s between the tool and tissue (dimensionless).
    pub friction_static: Real,
    /// Kinetic friction coefficient μ_k between the tool and tissue (dimensionless, ≤ μ_s).
    pub friction_kinetic: Real,
    /// Spacing (m) of the surface samples in [`ContactMode::SampledPoints`](crate::ContactMode);
    /// `None` uses the particle radius of the first body.
    pub sample_spacing: Option<Real>,
}

impl Default for ToolOptions {
    fn default() -> Self {
        ToolOptions {
            friction_static: 0.0,
            friction_kinetic: 0.0,
            sample_spacing: None,
        }
    }
}

/// The wrench the tissue exerts on a tool, averaged over the substeps of the last step.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Wrench {
    /// Force on the tool (N, world frame).
    pub force: Vec3,
    /// Torque on the tool about its origin (N·m, world frame).
    pub torque: Vec3,
    /// Number of particles in contact with the tool at the last substep.
    pub contact_count: u32,
    /// Largest penetration depth of a particle into the tool (m) before projection, last step.
    pub max_penetration: Real,
}

/// A kinematic tool inside a world.
#[derive(Debug, Clone)]
pub struct Tool {
    pub(crate) pose: Pose,
    pub(crate) wrench: Wrench,
}

impl Tool {
    /// The pose reached at the end of the last step.
    pub fn pose(&self) -> Pose {
        self.pose
    }
    /// The contact wrench of the last step (see [`Wrench`]).
    pub fn wrench(&self) -> Wrench {
        self.wrench
    }
}
