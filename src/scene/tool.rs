//! Kinematic rigid instruments: their shape (a parry shape), pose, friction and contact wrench.

use crate::error::{check_finite, Error};
use crate::kernels::math::{is_finite_vec, Quat, Real, Vec3};
use parry3d_f64::math::{Isometry, Point, Translation};
use parry3d_f64::shape::{SharedShape, TriMeshFlags};

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

/// Points closer than this fraction of the point cloud's extent to a common plane are coplanar
/// for [`ToolShape::ConvexHull`] (dimensionless).
pub const CONVEX_HULL_FLATNESS: Real = 1e-9;

impl ToolShape {
    /// The width (m) of the shape's narrowest part that presses into tissue: a sphere's,
    /// capsule's or cylinder's diameter, a box's smallest edge; `None` for a convex hull or a
    /// triangle mesh, whose narrowest width is not at hand (they count as wide).
    pub(crate) fn width(&self) -> Option<Real> {
        match self {
            ToolShape::Sphere { radius }
            | ToolShape::Capsule { radius, .. }
            | ToolShape::Cylinder { radius, .. } => Some(2.0 * radius),
            ToolShape::Cuboid { half_extents } => Some(2.0 * half_extents.min()),
            ToolShape::ConvexHull { .. } | ToolShape::TriMesh { .. } => None,
        }
    }

    /// Check the shape: NaN or ±Inf give [`Error::NonFinite`]; otherwise radii, cylinder
    /// half-heights and box half-extents must be > 0 m, a capsule's half-height ≥ 0 m (0 is a
    /// sphere), a convex hull needs at least 4 points not all in one plane (within
    /// [`CONVEX_HULL_FLATNESS`](crate::CONVEX_HULL_FLATNESS) of their extent), a triangle mesh at least one triangle and
    /// indices within its vertices; else [`Error::InvalidArgument`]. The one validation of tool
    /// shapes, used by [`World::add_tool`](crate::World::add_tool) and the C API.
    pub fn validate(&self) -> Result<(), Error> {
        match self {
            ToolShape::Sphere { radius } => check_tool_size("tool radius", *radius),
            ToolShape::Capsule {
                half_height,
                radius,
            } => {
                if *half_height != 0.0 {
                    check_tool_size("tool half_height", *half_height)?;
                }
                check_tool_size("tool radius", *radius)
            }
            ToolShape::Cylinder {
                half_height,
                radius,
            } => {
                check_tool_size("tool half_height", *half_height)?;
                check_tool_size("tool radius", *radius)
            }
            ToolShape::Cuboid { half_extents } => (0..3).try_for_each(|k| {
                check_tool_size(&format!("tool half_extents[{k}]"), half_extents[k])
            }),
            ToolShape::ConvexHull { points } => check_hull_points(points),
            ToolShape::TriMesh {
                vertices,
                triangles,
            } => {
                check_finite_points("tool vertices", vertices)?;
                if triangles.is_empty() {
                    return Err(Error::InvalidArgument(
                        "tool triangle mesh has no triangle".into(),
                    ));
                }
                if let Some(t) = triangles
                    .iter()
                    .position(|t| t.iter().any(|&k| k as usize >= vertices.len()))
                {
                    return Err(Error::InvalidArgument(format!(
                        "tool triangle {t} references a vertex out of range ({} vertices)",
                        vertices.len()
                    )));
                }
                check_tool_mesh(vertices, triangles)
            }
        }
    }
}

/// `value` is finite ([`Error::NonFinite`] otherwise) and in [`TOOL_SIZE_RANGE`] m
/// ([`Error::InvalidArgument`] otherwise); `what` names it in the message.
fn check_tool_size(what: &str, value: Real) -> Result<(), Error> {
    check_finite(what, value)?;
    let (lo, hi) = TOOL_SIZE_RANGE;
    if (lo..=hi).contains(&value) {
        Ok(())
    } else {
        Err(Error::InvalidArgument(format!(
            "{what} must be in [{lo:e}, {hi:e}] m, got {value:e}"
        )))
    }
}

/// Every point finite ([`Error::NonFinite`] naming `what` and the index otherwise).
fn check_finite_points(what: &str, points: &[Vec3]) -> Result<(), Error> {
    match points.iter().position(|p| !is_finite_vec(p)) {
        Some(i) => Err(Error::NonFinite(format!("{what}[{i}]"))),
        None => Ok(()),
    }
}

/// At least 4 finite points, not all in one plane.
fn check_hull_points(points: &[Vec3]) -> Result<(), Error> {
    check_finite_points("convex hull points", points)?;
    if points.len() < 4 {
        return Err(Error::InvalidArgument(format!(
            "a convex hull needs at least 4 points, got {}",
            points.len()
        )));
    }
    let a = points[0];
    let farthest = |f: &dyn Fn(&Vec3) -> Real| points.iter().map(f).fold(0.0, Real::max);
    let extent = farthest(&|p| (p - a).norm());
    let b = *points
        .iter()
        .max_by(|p, q| (*p - a).norm().total_cmp(&(*q - a).norm()))
        .unwrap_or(&a);
    let c = *points
        .iter()
        .max_by(|p, q| {
            let d = |x: &Vec3| (b - a).cross(&(x - a)).norm();
            d(p).total_cmp(&d(q))
        })
        .unwrap_or(&a);
    let normal = (b - a).cross(&(c - a)).try_normalize(0.0);
    let height = normal.map_or(0.0, |n| farthest(&|p| n.dot(&(p - a)).abs()));
    if !(extent > 0.0 && height > CONVEX_HULL_FLATNESS * extent) {
        return Err(Error::InvalidArgument(
            "convex hull points are all in one plane (or on one line or point)".into(),
        ));
    }
    Ok(())
}

/// Quaternions of a smaller norm are rejected as zero by [`Pose::from_components`].
pub const MIN_QUATERNION_NORM: Real = 1e-12;

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

    /// A pose from a position (m) and a quaternion `(w, x, y, z)`, normalised here. NaN/Inf give
    /// [`Error::NonFinite`], a quaternion of norm below [`MIN_QUATERNION_NORM`](crate::MIN_QUATERNION_NORM)
    /// [`Error::InvalidArgument`]. The one conversion of raw poses (the C API uses it too).
    pub fn from_components(position: [Real; 3], quaternion: [Real; 4]) -> Result<Self, Error> {
        let p = Vec3::from(position);
        if !is_finite_vec(&p) || quaternion.iter().any(|c| !c.is_finite()) {
            return Err(Error::NonFinite("tool pose".into()));
        }
        let [w, x, y, z] = quaternion;
        let q = nalgebra::Quaternion::new(w, x, y, z);
        let norm = q.norm();
        if norm < MIN_QUATERNION_NORM {
            return Err(Error::InvalidArgument(
                "tool orientation: zero quaternion".into(),
            ));
        }
        Ok(Pose {
            position: p,
            orientation: Quat::new_unchecked(q / norm),
        })
    }

    /// Interpolate between `a` (s = 0) and `b` (s = 1): linear in position, slerp in
    /// orientation.
    pub fn interpolate(a: &Pose, b: &Pose, s: Real) -> Pose {
        Pose {
            position: a.position.lerp(&b.position, s),
            orientation: a
                .orientation
                .try_slerp(&b.orientation, s, 1e-12)
                .unwrap_or(b.orientation),
        }
    }

    /// The pose as a parry isometry.
    pub(crate) fn isometry(&self) -> Isometry<Real> {
        Isometry::from_parts(Translation::from(self.position), self.orientation)
    }

    /// True when both parts are finite and the quaternion has unit norm (within 1e-6).
    pub fn is_valid(&self) -> bool {
        is_finite_vec(&self.position)
            && self.orientation.coords.iter().all(|c| c.is_finite())
            && (self.orientation.coords.norm() - 1.0).abs() < 1e-6
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

impl ToolOptions {
    /// Check the options: friction coefficients finite with 0 ≤ μ_k ≤ μ_s, a given sample
    /// spacing finite and > 0 m. NaN or ±Inf give [`Error::NonFinite`], other bad values
    /// [`Error::InvalidArgument`].
    pub fn validate(&self) -> Result<(), Error> {
        check_friction(self.friction_static, self.friction_kinetic)?;
        if let Some(s) = self.sample_spacing {
            check_tool_size("options.sample_spacing", s)?;
        }
        Ok(())
    }
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
    /// Number of contacts at the last substep: boundary triangles touching the tool in the
    /// exact-shape contact mode, particles in the sampled-points mode.
    pub contact_count: u32,
    /// Largest contact violation (m) before projection in the last step: how far a surface
    /// triangle was inside the tool's skin (a particle inside its contact radius in the
    /// sampled-points mode).
    pub max_penetration: Real,
}

/// A kinematic tool inside a world.
#[derive(Clone)]
pub struct Tool {
    pub(crate) description: ToolShape,
    pub(crate) shape: SharedShape,
    pub(crate) options: ToolOptions,
    /// Pose at the end of the last step.
    pub(crate) pose: Pose,
    /// Pose to reach at the end of the next step.
    pub(crate) target: Pose,
    /// Radius (m) of a sphere about the tool origin that contains the shape.
    pub(crate) bounding_radius: Real,
    /// Surface samples in the local frame (m), moved inwards by `sample_radius`.
    pub(crate) samples: Vec<Vec3>,
    /// Radius of each surface sample sphere (m).
    pub(crate) sample_radius: Real,
    /// Linear velocity of the origin over the last step (m/s).
    pub(crate) linear_velocity: Vec3,
    pub(crate) wrench: Wrench,
}

/// What the interactions (contact, grasp, needle) put on a tool during a step, accumulated
/// over its substeps and turned into the tool's [`Wrench`] at its end.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(crate) struct ToolLoad {
    /// Σ m Δx of the corrections (kg·m).
    pub(crate) impulse: Vec3,
    /// Σ (q − o) × m Δx, q where the correction acts on the tool, o its origin (kg·m²).
    pub(crate) moment: Vec3,
    /// Contacts of the substep in progress (counted in its first iteration).
    pub(crate) contacts: u32,
    /// Deepest penetration seen in the step (m).
    pub(crate) penetration: Real,
}

impl std::fmt::Debug for Tool {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Tool")
            .field("shape", &self.description)
            .field("pose", &self.pose)
            .field("wrench", &self.wrench)
            .finish()
    }
}

impl Tool {
    /// Build a tool; `default_spacing` (m) is used for surface samples when the options give
    /// none.
    pub(crate) fn new(
        description: ToolShape,
        pose: Pose,
        options: &ToolOptions,
        default_spacing: Real,
    ) -> Result<Tool, Error> {
        if !pose.is_valid() {
            return Err(Error::NonFinite("tool pose".into()));
        }
        options.validate()?;
        description.validate()?;
        let to_points =
            |v: &[Vec3]| -> Vec<Point<Real>> { v.iter().map(|p| Point::from(*p)).collect() };
        let shape = match &description {
            ToolShape::Sphere { radius } => SharedShape::ball(*radius),
            ToolShape::Capsule {
                half_height,
                radius,
            } => SharedShape::capsule_y(*half_height, *radius),
            ToolShape::Cylinder {
                half_height,
                radius,
            } => SharedShape::cylinder(*half_height, *radius),
            ToolShape::Cuboid { half_extents } => {
                SharedShape::cuboid(half_extents.x, half_extents.y, half_extents.z)
            }
            ToolShape::ConvexHull { points } => SharedShape::convex_hull(&to_points(points))
                .ok_or_else(|| {
                    Error::InvalidArgument("convex hull of the tool points is degenerate".into())
                })?,
            ToolShape::TriMesh {
                vertices,
                triangles,
            } => SharedShape::trimesh_with_flags(
                to_points(vertices),
                triangles.clone(),
                TriMeshFlags::ORIENTED
                    | TriMeshFlags::MERGE_DUPLICATE_VERTICES
                    | TriMeshFlags::DELETE_DEGENERATE_TRIANGLES,
            )
            .map_err(|e| Error::InvalidArgument(format!("tool triangle mesh: {e:?}")))?,
        };
        let aabb = shape.compute_local_aabb();
        let bounding_radius = aabb.center().coords.norm() + aabb.half_extents().norm();
        let spacing = options.sample_spacing.unwrap_or(default_spacing);
        let (samples, sample_radius) =
            crate::kernels::collision::sampling::sample_surface(&shape, spacing)
                .map_err(Error::InvalidArgument)?;
        Ok(Tool {
            description,
            shape,
            options: options.clone(),
            pose,
            target: pose,
            bounding_radius,
            samples,
            sample_radius,
            linear_velocity: Vec3::zeros(),
            wrench: Wrench::default(),
        })
    }

    /// How far (m) the tool moves in the coming step: its translation from the pose to the
    /// target plus its rotation (rad) times its bounding radius.
    pub(crate) fn travel(&self) -> Real {
        (self.target.position - self.pose.position).norm()
            + self.pose.orientation.angle_to(&self.target.orientation) * self.bounding_radius
    }

    /// The pose reached at the end of the last step.
    pub fn pose(&self) -> Pose {
        self.pose
    }
    /// The pose the tool will reach at the end of the next step.
    pub fn target_pose(&self) -> Pose {
        self.target
    }
    /// The shape as given.
    pub fn shape(&self) -> &ToolShape {
        &self.description
    }
    /// The options (friction, sampling).
    pub fn options(&self) -> &ToolOptions {
        &self.options
    }
    /// Linear velocity of the tool origin over the last step (m/s).
    pub fn linear_velocity(&self) -> Vec3 {
        self.linear_velocity
    }
    /// The contact wrench of the last step (see [`Wrench`]).
    pub fn wrench(&self) -> Wrench {
        self.wrench
    }
    /// Number of surface samples used in [`ContactMode::SampledPoints`](crate::ContactMode).
    pub fn sample_count(&self) -> usize {
        self.samples.len()
    }
    /// Signed distance (m) from `point` to the tool surface at `pose`: negative inside.
    pub fn signed_distance(&self, pose: &Pose, point: &Vec3) -> Real {
        let proj = self
            .shape
            .project_point(&pose.isometry(), &Point::from(*point), false);
        let d = (proj.point.coords - point).norm();
        if proj.is_inside {
            -d
        } else {
            d
        }
    }
}

/// Accepted range (m) of a tool's radii, half heights, half extents and sample spacing: from a
/// micrometre (finer than any instrument, and far above denormal numbers) to a kilometre
/// (beyond it the contact arithmetic loses every digit of a millimetre).
pub const TOOL_SIZE_RANGE: (Real, Real) = (1e-6, 1e3);

/// Smallest accepted triangle area of a tool mesh, relative to the square of its bounding-box
/// diagonal.
pub const MIN_TOOL_TRIANGLE_AREA: Real = 1e-12;

/// Smallest accepted thickness of a tool mesh (its thinnest bounding-box extent), relative to
/// its bounding-box diagonal: a flat mesh encloses no volume and has no inside.
pub const MIN_TOOL_THICKNESS: Real = 1e-6;

/// Check a tool's triangle mesh (vertices finite and indices in range already checked): at
/// least one triangle, no triangle of (near) zero area (repeated or collinear vertices), not
/// flat. A degenerate mesh has no well-defined inside and poisons the contact query.
pub fn check_tool_mesh(vertices: &[Vec3], triangles: &[[u32; 3]]) -> Result<(), Error> {
    let bad = |m: String| Err(Error::InvalidArgument(format!("tool mesh: {m}")));
    if triangles.is_empty() || vertices.is_empty() {
        return bad("no triangles".into());
    }
    let (mut lo, mut hi) = (vertices[0], vertices[0]);
    for t in triangles {
        for &k in t {
            lo = lo.inf(&vertices[k as usize]);
            hi = hi.sup(&vertices[k as usize]);
        }
    }
    let diag = (hi - lo).norm();
    if !(diag > 0.0 && diag.is_finite()) {
        return bad(format!(
            "all triangle vertices coincide (bounding-box diagonal {diag} m)"
        ));
    }
    let min_area = MIN_TOOL_TRIANGLE_AREA * diag * diag;
    for (i, t) in triangles.iter().enumerate() {
        let [a, b, c] = t.map(|k| vertices[k as usize]);
        let area = 0.5 * (b - a).cross(&(c - a)).norm();
        if area.is_nan() || area <= min_area {
            return bad(format!(
                "triangle {i} (vertices {}, {}, {}) has zero area ({area:.3e} m2; at least \
                 {MIN_TOOL_TRIANGLE_AREA:e} x the squared bounding-box diagonal is needed): \
                 repeated or collinear vertices",
                t[0], t[1], t[2]
            ));
        }
    }
    let thinnest = (hi - lo).min();
    if thinnest < MIN_TOOL_THICKNESS * diag {
        return bad(format!(
            "the mesh is flat (thinnest extent {thinnest:.3e} m of a {diag:.3e} m bounding box): \
             a tool needs a volume"
        ));
    }
    Ok(())
}

/// Check a pair of friction coefficients: finite ([`Error::NonFinite`]), ≥ 0 and μ_k ≤ μ_s
/// ([`Error::InvalidArgument`]).
pub(crate) fn check_friction(mu_s: Real, mu_k: Real) -> Result<(), Error> {
    check_finite("friction_static", mu_s)?;
    check_finite("friction_kinetic", mu_k)?;
    if !(mu_s >= 0.0 && mu_k >= 0.0 && mu_k <= mu_s) {
        return Err(Error::InvalidArgument(format!(
            "friction needs 0 <= friction_kinetic <= friction_static, got static {mu_s}, \
             kinetic {mu_k}"
        )));
    }
    Ok(())
}
