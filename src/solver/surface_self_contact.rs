//! Surface self-contact ([`Settings::self_contact`](crate::Settings::self_contact)): a body's boundary vertices kept in front of its own boundary triangles, so that a
//! fold, a dent closing on itself or the two faces of a cut do not pass through each other.
//!
//! For a boundary vertex `i` (predicted position `p`) and a boundary triangle `abc` of the same
//! body (unit outward normal `n` at the start of the pass, height `h = (p − a)·n`), with a skin
//! `s` of [`SELF_CONTACT_SKIN`] particle radii (3 mm on the default organ, a quarter of its
//! particle spacing), the pair is in contact when all of these hold:
//! 1. `i` is not a corner of the triangle (the triangles around a vertex are its own surface);
//! 2. the surfaces face each other: the vertex's normal (the sum of its triangles' area
//!    normals) points against `n`. A vertex whose surface faces the way the triangle does has
//!    its own tissue between itself and the triangle: the surface of that tissue which faces
//!    the triangle touches it first;
//! 3. `h < s`, and the foot of `p` on the triangle's plane lies in the triangle, or the
//!    triangle comes nearer than `s` to `p` (a vertex passing a rim of the surface, where the
//!    feet fall outside the triangles on either side of it); the contact acts at the foot, or
//!    at the triangle's point closest to `p`;
//! 4. `i` came from the front: at the start of the substep (positions `x`) it was on the
//!    outward side of the triangle's plane (`h ≥ 0`), and the triangle has not turned over
//!    since (its normals then and now within 90°); a vertex now behind the plane crossed it
//!    through the triangle (condition 3 at the instant of crossing, positions interpolated
//!    linearly over the substep). A vertex behind a triangle at the start is inside the body
//!    (the far side of a thin part), never pushed through it, nor is one that went round the
//!    triangle's rim;
//! 5. the pair is not close at rest: the rest distance from the vertex to the triangle (rest
//!    positions) is at least `s`. Such pairs (a vertex in a crevice of the rest shape) belong to
//!    the shape of the tissue; the faces a cut opens are boundary triangles like the others,
//!    a removed layer of tetrahedra apart at rest (about a particle spacing, `4 s`), so they
//!    touch unless a stretch of them was closer than `s`.
//!
//! A pair in contact is projected to the height `min(s, h₀ + v Δt)` (`h₀` the height at the
//! substep's start, `v` [`Settings::max_depenetration_speed`](crate::Settings::max_depenetration_speed),
//! `Δt` the substep): a crossing is stopped whole, and a vertex that was already within the
//! skin is lifted out of it no faster than the tool contact lifts the surface out of a tool
//! (without the cap, vertices crumpled around a tool that jumped into the tissue were thrown
//! out at metres per second, and each throw let the next substep's boxes grow). The
//! constraint `C = (p_i − Σ b_k p_k)·n − min(s, h₀ + v Δt) ≥ 0` (`b` the barycentric weights
//! of the foot), corrected by inverse mass — the vertex moves by
//! `w_i/W`, corner `k` by `−b_k w_k/W` (at most [`MAX_CORNER_SHARE`]) times `−C n`, with
//! `W = w_i + Σ b_k² w_k` — then positional Coulomb friction (the body's own pair friction,
//! [`World::set_body_pair_friction`](crate::World::set_body_pair_friction) with both ids the
//! body's; frictionless unless set) on the vertex's motion relative to the foot, spread the
//! same way.
//!
//! Broad phase: the body's [`SurfaceTree`](crate::kernels::collision::surface_tree), a
//! bounding-volume hierarchy of its boundary triangles made at rest, with the boxes of the
//! positions at the substep's start and the predicted ones (the triangles' grown by `s`, so that
//! a vertex that crossed a triangle within the substep meets its box) and the cones of the unit
//! normals (condition 2). Its pairs are kept from pass to pass while the surface moves and turns
//! little ([`SurfacePairs`](crate::kernels::collision::surface_pairs::SurfacePairs), one per body
//! in its step scratch) and filtered every pass by the boxes and normals; the pass then costs the
//! normals, a scan of the boundary's motion and the exact tests, and a build of the pairs when
//! the surface moved too far. The normals, the scan and a build's refit and traversal run on
//! the pool's threads (the pairs found sorted); the projections on the calling thread, the
//! pairs in (vertex, triangle) order: the same bits for any thread count and whenever the pairs
//! were built.

use crate::interaction::surface_contact::MAX_CORNER_SHARE;
use crate::kernels::collision::surface_pairs::SurfaceMotion;
use crate::kernels::collision::surface_tree::TreeFit;
use crate::kernels::constraints::friction::friction_correction;
use crate::kernels::math::{Real, Vec3};
use crate::kernels::parallel::{Pool, SharedSlice};
use crate::model::body_model::BodyModel;
use crate::scene::body::Body;
use crate::solver::StepScratch;
use parry3d_f64::math::Point;
use parry3d_f64::query::PointQuery;
use parry3d_f64::shape::Triangle;

/// Thickness `s` of the self-contact skin, in particle radii (dimensionless): a vertex is kept
/// this far in front of the body's other boundary triangles, and pairs closer than this at
/// rest are not in contact.
pub(crate) const SELF_CONTACT_SKIN: Real = 0.5;

/// Scratch memory of this pass, kept by the pipeline between steps, sized for the largest body.
#[derive(Debug, Clone, Default)]
pub(crate) struct SelfContactScratch {
    fit: TreeFit,
    /// Per boundary triangle, the cross product of two of its edges at the start of the pass
    /// (m²: its outward normal times twice its area), and that normal's unit vector.
    area_normal: Vec<Vec3>,
    normal: Vec<Vec3>,
    /// Per particle, the unit normal of the boundary around it: the sum of the area normals of
    /// the boundary triangles around it, normalised (zero where that sum is; written for
    /// boundary vertices only).
    vertex_normal: Vec<Vec3>,
}

impl SelfContactScratch {
    /// Make room for a body on `model` (allocates only when the scratch is smaller).
    pub(crate) fn reserve(&mut self, model: &BodyModel) {
        let (triangles, particles) = (model.boundary.len(), model.particle_count());
        self.fit.reserve(&model.boundary_tree, particles);
        for per_triangle in [&mut self.area_normal, &mut self.normal] {
            if per_triangle.len() < triangles {
                per_triangle.resize(triangles, Vec3::zeros());
            }
        }
        if self.vertex_normal.len() < particles {
            self.vertex_normal.resize(particles, Vec3::zeros());
        }
    }
}

/// The boundary's normals at the positions `p` (m) into `scratch` (see
/// [`SelfContactScratch`]), on the threads of `pool`: the triangles' in ranges, then each
/// vertex's sum of its triangles' area normals in the order of the triangles (on one thread,
/// each triangle's added to its corners' sums in that order: the same bits, and cheaper
/// there).
fn boundary_normals(scratch: &mut SelfContactScratch, model: &BodyModel, p: &[Vec3], pool: &Pool) {
    let (boundary, tree) = (&model.boundary, &model.boundary_tree);
    let triangles = boundary.len();
    if pool.threads() == 1 {
        let SelfContactScratch {
            normal,
            vertex_normal,
            ..
        } = scratch;
        for &i in tree.vertices() {
            vertex_normal[i as usize] = Vec3::zeros();
        }
        for (t, corners) in boundary.iter().enumerate() {
            let [a, b, c] = corners.map(|k| p[k as usize]);
            let area_normal = (b - a).cross(&(c - a));
            for &k in corners {
                vertex_normal[k as usize] += area_normal;
            }
            normal[t] = area_normal.try_normalize(0.0).unwrap_or_else(Vec3::zeros);
        }
        for &i in tree.vertices() {
            let n = &mut vertex_normal[i as usize];
            *n = n.try_normalize(0.0).unwrap_or_else(Vec3::zeros);
        }
        return;
    }
    let area = SharedSlice::new(&mut scratch.area_normal[..triangles]);
    let unit = SharedSlice::new(&mut scratch.normal[..triangles]);
    pool.for_each_range(triangles, &|range| {
        // SAFETY: the shares' ranges are disjoint.
        let (area, unit) = unsafe { (area.range(range.clone()), unit.range(range.clone())) };
        for ((t, area), unit) in range.zip(area).zip(unit) {
            let [a, b, c] = boundary[t].map(|k| p[k as usize]);
            *area = (b - a).cross(&(c - a));
            *unit = area.try_normalize(0.0).unwrap_or_else(Vec3::zeros);
        }
    });
    let area = &scratch.area_normal;
    let vertex_normal = SharedSlice::new(&mut scratch.vertex_normal);
    pool.for_each_range(tree.vertices().len(), &|range| {
        for j in range {
            let sum = (tree.triangles_around(j).iter())
                .fold(Vec3::zeros(), |sum, &t| sum + area[t as usize]);
            // SAFETY: every boundary vertex is once in the tree's vertices. A zero normal
            // faces no triangle (condition 2).
            *unsafe { vertex_normal.element(tree.vertices()[j] as usize) } =
                sum.try_normalize(0.0).unwrap_or_else(Vec3::zeros);
        }
    });
}

/// The sizes the self-contact's pairs are made for on `model` (`SurfacePairs::reserve`): its
/// particles, boundary vertices and boundary triangles.
pub(crate) fn self_contact_sizes(model: &BodyModel) -> (usize, usize, usize) {
    let vertices = model.boundary_vertices.len();
    (model.particle_count(), vertices, model.boundary.len())
}

/// One Gauss–Seidel pass of `body`'s surface self-contacts (see the module documentation) on
/// the predicted positions in `step`, with static and kinetic friction coefficients
/// `(mu_s, mu_k)` (dimensionless), a vertex already within the skin at the substep's start
/// lifted by at most `max_correction` (m); a build of the pairs on the threads of `pool`.
pub(crate) fn project_self_contacts(
    scratch: &mut SelfContactScratch,
    body: &Body,
    step: &mut StepScratch,
    (mu_s, mu_k): (Real, Real),
    max_correction: Real,
    pool: &Pool,
) {
    let model = &*body.model;
    let boundary = &model.boundary;
    if boundary.is_empty() {
        return;
    }
    scratch.reserve(model);
    (step.self_contact_pairs).reserve(self_contact_sizes(model), pool.threads());
    let skin = SELF_CONTACT_SKIN * model.particle_radius;
    let (x, w, rest) = (&body.state.x, &body.inv_mass, &model.rest);
    let p = &step.p;
    boundary_normals(scratch, model, p, pool);
    let SelfContactScratch {
        fit,
        normal,
        vertex_normal,
        ..
    } = scratch;
    let motion = SurfaceMotion {
        x,
        p,
        vertex_normal,
        normal,
    };
    let pairs = step.self_contact_pairs.live(
        (&model.boundary_tree, fit, pool),
        (boundary, &model.boundary_vertices),
        &motion,
        skin,
    );
    let p = &mut step.p;
    for &(i, t) in pairs {
        let (i, t) = (i as usize, t as usize);
        let n = normal[t];
        let corners = boundary[t].map(|k| k as usize);
        let [a, b, c] = corners.map(|k| p[k]);
        let height = (p[i] - a).dot(&n);
        if height >= skin {
            continue;
        }
        let [a0, b0, c0] = corners.map(|k| x[k]);
        let n0 = (b0 - a0).cross(&(c0 - a0)).try_normalize(0.0).unwrap_or(n);
        let start = (x[i] - a0).dot(&n0);
        if start < 0.0 || n0.dot(&n) <= 0.0 {
            continue;
        }
        let Some(weights) = contact_weights(&p[i], [a, b, c], skin) else {
            continue;
        };
        if height < 0.0 {
            // Crossed the plane in this substep: only through the triangle (or within the
            // skin of it), at the fraction of the substep where the height went through 0.
            let at = start / (start - height);
            let then = |k: usize| x[k] + (p[k] - x[k]) * at;
            if contact_weights(&then(i), corners.map(then), skin).is_none() {
                continue;
            }
        }
        // Stop a crossing whole; lift a vertex that was within the skin at the start by at
        // most `max_correction`.
        let depth = skin.min(start + max_correction) - height;
        if depth <= 0.0 {
            continue;
        }
        let [ra, rb, rc] = corners.map(|k| Point::from(rest[k]));
        let at_rest = Triangle::new(ra, rb, rc).distance_to_local_point(&rest[i].into(), true);
        if at_rest < skin {
            continue;
        }
        let wk = corners.map(|k| w[k]);
        let total = w[i]
            + (0..3)
                .map(|k| weights[k] * weights[k] * wk[k])
                .sum::<Real>();
        if total <= 0.0 {
            continue;
        }
        let own = w[i] / total;
        let shares = [0, 1, 2].map(|k| (weights[k] * wk[k] / total).min(MAX_CORNER_SHARE));
        let spread = |p: &mut [Vec3], shift: Vec3| {
            p[i] += shift * own;
            for k in 0..3 {
                p[corners[k]] -= shift * shares[k];
            }
        };
        spread(p, n * depth);
        let foot_motion: Vec3 = (0..3)
            .map(|k| (p[corners[k]] - x[corners[k]]) * weights[k])
            .sum();
        let relative = (p[i] - x[i]) - foot_motion;
        spread(p, friction_correction(&relative, &n, depth, mu_s, mu_k));
    }
}

/// Where the contact of the point `q` with the triangle `a b c` (m) acts on the triangle, as
/// barycentric weights: the foot of `q` on the triangle's plane when it lies in the closed
/// triangle, else the triangle's point closest to `q` when that is nearer than `skin` (m: a
/// point passing a rim of the surface); `None` otherwise or for a degenerate triangle.
fn contact_weights(q: &Vec3, [a, b, c]: [Vec3; 3], skin: Real) -> Option<[Real; 3]> {
    let weights = |q: &Vec3| {
        let (e1, e2, d) = (b - a, c - a, q - a);
        let (d11, d12, d22) = (e1.dot(&e1), e1.dot(&e2), e2.dot(&e2));
        let (d1, d2) = (d.dot(&e1), d.dot(&e2));
        let det = d11 * d22 - d12 * d12;
        let v = (d22 * d1 - d12 * d2) / det;
        let w = (d11 * d2 - d12 * d1) / det;
        (det > 0.0).then_some([1.0 - v - w, v, w])
    };
    let foot = weights(q)?;
    if foot.iter().all(|&b| b >= 0.0) {
        return Some(foot);
    }
    let triangle = Triangle::new(a.into(), b.into(), c.into());
    let closest = triangle
        .project_local_point(&(*q).into(), true)
        .point
        .coords;
    if (q - closest).norm() >= skin {
        return None;
    }
    // On the triangle: weights in [0, 1] up to rounding.
    weights(&closest).map(|w| w.map(|b| b.clamp(0.0, 1.0)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn contact_weights_take_the_foot_or_the_closest_point_within_the_skin() {
        let corners = [Vec3::zeros(), Vec3::x(), Vec3::y()];
        let at = |[u, v, w]: [Real; 3]| corners[0] * u + corners[1] * v + corners[2] * w;
        let skin = 0.1;
        let foot = contact_weights(&Vec3::new(0.2, 0.3, 0.7), corners, skin).unwrap();
        assert!((at(foot) - Vec3::new(0.2, 0.3, 0.0)).norm() < 1e-15);
        let rim = contact_weights(&Vec3::new(0.3, -0.05, 0.05), corners, skin).unwrap();
        assert!((at(rim) - Vec3::new(0.3, 0.0, 0.0)).norm() < 1e-15);
        assert!(contact_weights(&Vec3::new(0.6, 0.6, -0.1), corners, skin).is_none());
        assert!(contact_weights(&Vec3::new(0.3, -0.05, 0.1), corners, skin).is_none());
    }
}
