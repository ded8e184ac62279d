//! Surface sampling of tool shapes for the paper's sampled-point contact mode.
//!
//! The tool surface is triangulated (parry's `to_trimesh`), each triangle is filled with a
//! barycentric grid of points about `spacing` apart, and each point is moved inwards along the
//! surface normal by the sample radius, so that the union of the sample spheres approximates the
//! tool's own surface rather than a surface inflated by one radius.

use crate::kernels::math::{Real, Vec3};
use parry3d_f64::math::Point;
use parry3d_f64::shape::SharedShape;
use std::f64::consts::PI;

/// Largest number of surface samples (before removing duplicates on shared edges) a tool may
/// get: 2 × 10⁶ points, 48 MB. A shape much larger than the sample spacing (or a spacing much
/// smaller than the shape) is refused with a message instead of exhausting memory.
pub const MAX_TOOL_SAMPLES: usize = 2_000_000;

/// Sample the surface of `shape` (local frame) about `spacing` (m) apart. Returns the sample
/// centres (m, local frame) and the radius of each sample sphere (m), or a message when that
/// would take more than [`MAX_TOOL_SAMPLES`] samples.
pub fn sample_surface(shape: &SharedShape, spacing: Real) -> Result<(Vec<Vec3>, Real), String> {
    let aabb = shape.compute_local_aabb();
    let thinnest = aabb.half_extents().min();
    let radius = spacing.min(0.9 * thinnest);
    let subdivisions = |length: Real| ((length / spacing).ceil() as u32).clamp(3, 256);
    let convex = shape.as_trimesh().is_none();
    let (vertices, triangles): (Vec<Point<Real>>, Vec<[u32; 3]>) =
        if let Some(ball) = shape.as_ball() {
            let n = subdivisions(2.0 * PI * ball.radius);
            ball.to_trimesh(n, n / 2 + 1)
        } else if let Some(c) = shape.as_capsule() {
            let n = subdivisions(2.0 * PI * c.radius);
            c.to_trimesh(n, n / 2 + 1)
        } else if let Some(c) = shape.as_cylinder() {
            c.to_trimesh(subdivisions(2.0 * PI * c.radius))
        } else if let Some(c) = shape.as_cuboid() {
            c.to_trimesh()
        } else if let Some(c) = shape.as_convex_polyhedron() {
            c.to_trimesh()
        } else if let Some(m) = shape.as_trimesh() {
            (m.vertices().to_vec(), m.indices().to_vec())
        } else {
            (Vec::new(), Vec::new())
        };
    let centre = aabb.center().coords;
    // Count first (in floating point: no overflow), so that nothing huge is allocated.
    let mut count: Real = 0.0;
    for t in &triangles {
        let [a, b, c] = t.map(|k| vertices[k as usize].coords);
        let longest = (b - a).norm().max((c - b).norm()).max((a - c).norm());
        let m = (longest / spacing).ceil().max(1.0);
        count += (m + 1.0) * (m + 2.0) / 2.0;
    }
    if count.is_nan() || count > MAX_TOOL_SAMPLES as Real {
        return Err(format!(
            "the tool surface needs about {count:.3e} samples at a sample spacing of {spacing:.3e} \
             m (at most {MAX_TOOL_SAMPLES}): raise sample_spacing or use a smaller tool"
        ));
    }
    let mut samples: Vec<Vec3> = Vec::with_capacity(count as usize);
    for t in &triangles {
        let [a, b, c] = t.map(|k| vertices[k as usize].coords);
        let mut normal = (b - a).cross(&(c - a));
        let area2 = normal.norm();
        if area2 <= 0.0 {
            continue;
        }
        normal /= area2;
        if convex && normal.dot(&((a + b + c) / 3.0 - centre)) < 0.0 {
            normal = -normal;
        }
        let longest = (b - a).norm().max((c - b).norm()).max((a - c).norm());
        let m = ((longest / spacing).ceil() as usize).max(1);
        for i in 0..=m {
            for j in 0..=(m - i) {
                let (s, r) = (i as Real / m as Real, j as Real / m as Real);
                let q = a + (b - a) * s + (c - a) * r;
                let on_surface = shape.project_local_point(&Point::from(q), false).point;
                samples.push(on_surface.coords - normal * radius);
            }
        }
    }
    // Points on shared edges and vertices appear once per triangle: keep one of each.
    let key = |p: &Vec3| p.map(|c| (c / (1e-3 * spacing)).round() as i64);
    samples.sort_by(|p, q| {
        let (kp, kq) = (key(p), key(q));
        (kp.x, kp.y, kp.z).cmp(&(kq.x, kq.y, kq.z))
    });
    samples.dedup_by(|p, q| key(p) == key(q));
    Ok((samples, radius))
}
