//! Tool–tissue contact in [`ContactMode::ExactShape`](crate::ContactMode::ExactShape): the
//! tool's exact shape against the body's deformed boundary triangles, so that the tool keeps out
//! of the surface even where it is thinner than the particle spacing.
//!
//! For each boundary triangle near the tool (positions `p` of the current iteration, outward
//! normal `n`), GJK (parry) between the tool and the triangle, with a skin `r` of
//! [`SURFACE_SKIN`] particle radii, gives the closest points and the separation `d` (EPA the
//! penetration depth when they overlap). A sphere's are exact and in closed form, from the
//! triangle's point closest to the centre: GJK and EPA, iterative on a curved shape, were 60%
//! of this pass's narrow phase in the haptic scene, and stop up to 1e-4 radii short of the
//! exact separation. A triangle-mesh tool is taken as its vertices' convex hull for GJK.
//! When `d < r` the triangle is pushed away from the tool by `r − d` (at most `max_correction`
//! per projection beyond the contact point's predicted motion towards the tool in the
//! substep), the correction spread over its three particles by barycentric weights so that
//! the contact point moves by exactly that much (the point–triangle constraint of PBD), with
//! Coulomb friction on the contact point's motion relative to the tool. The triangles of a
//! dent share particles and undo part of each other's corrections, so the pass repeats over
//! the triangles near the tool until the largest correction is below a hundredth of the skin
//! (at most [`MAX_SURFACE_PASSES`]): with a single pass a 1 mm sphere pressed 2 cm into the
//! default organ slipped through the steep walls of the funnel it made (two passes: 20 steps
//! inside out of 640; three or more: none).
//!
//! The contact is one-sided, so that no depth or speed lets the tool through:
//! - a tool that came from in front of the triangle (the middle of its extent along `n` was in
//!   front of the plane at the start of the substep, against the triangle as it was then) is
//!   kept in front: when its middle is now behind the plane and the separation found would pull
//!   the triangle out past the tool, or when
//!   the tool crossed the whole triangle within the substep (the sweep: the tool is tested at
//!   the instant its middle crossed the plane), the triangle moves along `−n` until the tool's
//!   far side, on the line along `n` through the foot of the tool's middle, is `r` in front of it;
//! - otherwise (a tool inside the body, e.g. after a teleport) the minimal separation.

use crate::interaction::tool_motion_at;
use crate::kernels::constraints::friction::friction_correction;
use crate::kernels::math::{Real, Vec3};
use crate::kernels::parallel::{Pool, SharedSlice};
use crate::scene::particles::{ParticleView, SURFACE_SKIN};
use crate::scene::tool::{Pose, Tool, ToolLoad, ToolShape};
use parry3d_f64::math::{Isometry, Point};
use parry3d_f64::query::epa::EPA;
use parry3d_f64::query::gjk::{self, CSOPoint, GJKResult, VoronoiSimplex};
use parry3d_f64::query::{PointQuery, Ray};
use parry3d_f64::shape::{Ball, Capsule, Cuboid, SupportMap, Triangle};

/// Most Gauss–Seidel passes over the triangles near a tool per projection.
pub(crate) const MAX_SURFACE_PASSES: usize = 8;

/// Rounds of the contact projection per call: each a broad phase on the positions as the last
/// round left them, then the passes. The first round's first pass leaves what the depenetration
/// cap holds back, and its later passes do not retry it; where a small probe's funnel wraps
/// triangles several times its size round it, that left the surface sunk into the probe (0.82 mm
/// into a 1 mm sphere pressed 3 cm into the hanging default organ along −x; 2.7 mm into the side
/// of a 5 mm rod). The second round retries it under the same cap (which counts the substep's
/// whole motion of the contact point) and under the same budget for each corner, its motion
/// along the contact direction divided by its share: without that per-corner bound a box driven
/// at 2 m/s across the fixed top flung a free corner of a triangle with fixed ones and the step
/// diverged; with the per-corner bound in the first round too, the rod got into the organ.
/// Measured (`tests/contact_deep_press.rs`): every sphere of 1–10 mm, the rod and the cube,
/// pressed 3 cm from four sides, keep the surface at the contact skin (never inside the probe:
/// at least 0.18 mm outside, the 5 mm sphere along −z). Cost: about 1–3% of the haptic step.
pub(crate) const SURFACE_ROUNDS: usize = 2;

/// Most a corner moves per contact correction, in units of that correction. The point–triangle
/// constraint moves corner `k` by `b_k w_k / Σ b_j² w_j` times the correction (`b` barycentric
/// weights, `w` inverse masses): at most ~1.4 for equal masses, but without bound when the
/// contact point sits next to a fixed corner (the free corner, at a tiny `b`, would be flung by
/// `1/b`; the soak run saw particles at 1e13 m/s). A capped corner's excess goes to the other
/// corners ([`corner_shares`]); what no corner can take stays as residual penetration, like the
/// depenetration cap's.
pub(crate) const MAX_CORNER_SHARE: Real = 2.0;

/// The passes stop when the largest correction of a pass is below this fraction of the skin.
pub(crate) const SURFACE_PASS_TOLERANCE: Real = 0.01;

/// Scratch memory of this pass, kept by the pipeline between steps: parry's EPA (penetration
/// depth), its buffers reused from one query to the next, and the triangles near the tool.
pub(crate) struct SurfaceScratch {
    epa: EPA,
    /// Per boundary triangle: whether the broad phase keeps it (written on the pool).
    near_flags: Vec<bool>,
    near: Vec<u32>,
    /// Penetration of each of `near` left by the depenetration cap (m): kept through the passes.
    residual: Vec<Real>,
}

impl Default for SurfaceScratch {
    /// Warmed up: the buffers are grown by deep queries of a sphere, a capsule and a box against
    /// a sphere and a triangle (EPA runs up to 100 iterations on smooth shapes), so that the
    /// contacts of a step do not allocate.
    fn default() -> Self {
        let mut epa = EPA::new();
        let triangle = Triangle::new(
            Point::new(-1.0, 0.0, -1.0),
            Point::new(1.0, 0.0, -1.0),
            Point::new(0.0, 0.0, 1.0),
        );
        let (ball, capsule, cuboid) = (
            Ball::new(1.0),
            Capsule::new_y(0.5, 0.5),
            Cuboid::new(Vec3::repeat(0.5)),
        );
        let tools: [&dyn SupportMap; 3] = [&ball, &capsule, &cuboid];
        let others: [&dyn SupportMap; 2] = [&ball, &triangle];
        for tool in tools {
            for other in others {
                for offset in [1.0e-3, 0.3, 0.7] {
                    let pos12 = Isometry::translation(offset, 0.2 * offset, 0.1);
                    let mut simplex = VoronoiSimplex::new();
                    simplex.reset(CSOPoint::from_shapes(&pos12, tool, other, &Vec3::x()));
                    if gjk::closest_points(&pos12, tool, other, 0.0, true, &mut simplex)
                        == GJKResult::Intersection
                    {
                        let _ = epa.closest_points(&pos12, tool, other, &simplex);
                    }
                }
            }
        }
        SurfaceScratch {
            epa,
            near_flags: Vec::new(),
            near: Vec::new(),
            residual: Vec::new(),
        }
    }
}

impl Clone for SurfaceScratch {
    fn clone(&self) -> Self {
        SurfaceScratch::default()
    }
}

impl std::fmt::Debug for SurfaceScratch {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("SurfaceScratch")
    }
}

/// Project the contacts between `tool` (moving from `motion.0` to `motion.1` over this substep)
/// and the `boundary` triangles of a body (moving its particles' predicted positions in `view`), each
/// correction leaving the contact point's motion along the contact direction in this substep at
/// most the tool's own motion along it plus `max_correction` (m), in [`SURFACE_ROUNDS`] rounds of
/// up to [`MAX_SURFACE_PASSES`] passes (until the largest correction of a pass is below
/// [`SURFACE_PASS_TOLERANCE`] skins), and accumulate the tool's impulse and moment; `count` adds
/// the triangles in contact in the first pass of the first round to the tool's contact count;
/// `retry` (a call after the crush guard, `crate::solver::tool_contact`) keeps a triangle with a
/// fixed corner within the per-corner budget from the first round on, as the second round
/// does (without it, a box driven at 2 m/s across the fixed top flung free corners and the step
/// diverged). The broad phase runs on `pool`, each thread flagging its range of triangles; the
/// rest on the calling thread.
#[allow(clippy::too_many_arguments)]
pub(crate) fn project_tool_surface(
    surface: &mut SurfaceScratch,
    tool: &Tool,
    load: &mut ToolLoad,
    view: ParticleView<'_>,
    boundary: &[[u32; 3]],
    (prev, cur): (&Pose, &Pose),
    max_correction: Real,
    (count, retry): (bool, bool),
    pool: &Pool,
) {
    let iso = cur.isometry();
    let iso_prev = prev.isometry();
    // Maps a point attached to the tool at `cur` to where it was at `prev`.
    let back = iso_prev * iso.inverse();
    let skin = SURFACE_SKIN * view.radius;
    let reach = tool.bounding_radius + skin;
    let (mu_s, mu_k) = (tool.options.friction_static, tool.options.friction_kinetic);
    let hull = match &tool.description {
        ToolShape::TriMesh { vertices, .. } => VertexHull(vertices),
        _ => VertexHull(&[]),
    };
    let shape = tool.shape.clone();
    let map: &dyn SupportMap = shape.as_support_map().unwrap_or(&hull);
    for round in 0..SURFACE_ROUNDS {
        let SurfaceScratch {
            epa,
            near_flags,
            near,
            residual,
        } = surface;
        near.clear();
        residual.clear();
        if near.capacity() < boundary.len() {
            near.reserve(boundary.len());
            residual.reserve(boundary.len());
        }
        near_flags.resize(boundary.len(), false);
        // Broad phase, once: the triangles with a free corner near the tool's path, flagged on the
        // pool, then listed in order (the same list for any thread count).
        let path = PathBox::new(&prev.position, &cur.position, reach);
        let p = &*view.p;
        let inv_mass = view.inv_mass;
        let near_path = |t: usize| {
            let corners = boundary[t].map(|k| k as usize);
            let [a, b, c] = corners.map(|k| p[k]);
            if !path.may_reach([&a, &b, &c]) || corners.iter().all(|&k| inv_mass[k] == 0.0) {
                return false;
            }
            let centroid = (a + b + c) / 3.0;
            let extent = [a, b, c]
                .iter()
                .map(|q| (q - centroid).norm())
                .fold(0.0, Real::max);
            distance_to_segment(&centroid, &prev.position, &cur.position) <= reach + extent
        };
        let flags = SharedSlice::new(near_flags);
        pool.for_each_range(boundary.len(), &|range| {
            // SAFETY: the shares' ranges are disjoint.
            let mine = unsafe { flags.range(range.clone()) };
            for (flag, t) in mine.iter_mut().zip(range) {
                *flag = near_path(t);
            }
        });
        for (t, _) in near_flags.iter().enumerate().filter(|(_, &f)| f) {
            near.push(t as u32);
            residual.push(0.0);
        }
        // Gauss–Seidel passes over them until they agree: the triangles of a dent share particles
        // and undo part of each other's corrections.
        for pass in 0..MAX_SURFACE_PASSES {
            let mut largest: Real = 0.0;
            for (&t, left) in near.iter().zip(residual.iter_mut()) {
                let corners = boundary[t as usize].map(|k| k as usize);
                let w = corners.map(|k| view.inv_mass[k]);
                let [a, b, c] = corners.map(|k| view.p[k]);
                let Some(n) = (b - a).cross(&(c - a)).try_normalize(0.0) else {
                    continue;
                };
                // Which side the tool came from: its middle at the substep's start against the
                // triangle at the substep's start (before the iterations moved or turned it).
                let [a0, b0, c0] = corners.map(|k| view.x[k]);
                let n0 = (b0 - a0).cross(&(c0 - a0)).try_normalize(0.0).unwrap_or(n);
                let middle_prev = middle(map, &iso_prev, &n0);
                let from_front = (middle_prev - a0).dot(&n0) >= 0.0;
                let motion = (&iso_prev, prev, cur);
                let start = from_front.then_some(([a0, b0, c0], n0));
                let Some(contact) =
                    triangle_contact(tool, map, epa, &iso, motion, [a, b, c], &n, start, skin)
                else {
                    continue;
                };
                let weights = barycentric(&contact.point, &a, &b, &c);
                let denominator: Real = (0..3).map(|k| weights[k] * weights[k] * w[k]).sum();
                if denominator <= 0.0 {
                    continue;
                }
                let moved: Vec3 = (0..3)
                    .map(|k| (view.p[corners[k]] - view.x[corners[k]]) * weights[k])
                    .sum();
                // The depenetration cap: after the correction the contact point moves along the
                // contact direction by at most the tool's motion along it plus `max_correction` in
                // this substep. Tissue moving into the tool is stopped whole, the tool pushes the
                // tissue at its own speed, and penetration older than this substep is removed at
                // `max_depenetration_speed` (never faster, however many substeps and triangles
                // push). What the cap leaves in the first pass the later passes do not retry
                // (they remove what the neighbouring triangles' corrections pushed in beyond it,
                // each under the same cap); the second round does (`SURFACE_ROUNDS`).
                let depth = contact.depth;
                let tool_motion = tool_motion_at(&back, &contact.point);
                let pushed = tool_motion.dot(&contact.direction).max(0.0);
                let budget = max_correction + pushed;
                let mut cap = (budget - moved.dot(&contact.direction)).max(0.0);
                let shares = corner_shares(&weights, &w);
                if round > 0 || (retry && w.contains(&0.0)) {
                    // A retry keeps every corner within the budget too.
                    for k in 0..3 {
                        if shares[k] > 0.0 {
                            let own = view.p[corners[k]] - view.x[corners[k]];
                            let left = budget - own.dot(&contact.direction);
                            cap = cap.min((left / shares[k]).max(0.0));
                        }
                    }
                }
                let applied = if pass == 0 {
                    let applied = depth.min(cap);
                    *left = depth - applied;
                    applied
                } else {
                    *left = left.min(depth);
                    (depth - *left).min(cap)
                };
                largest = largest.max(applied);
                let normal_shift = contact.direction * applied;
                let relative = moved + normal_shift - tool_motion;
                let shift = normal_shift
                    + friction_correction(&relative, &contact.direction, applied, mu_s, mu_k);
                // What the cap on the shares keeps the contact point from achieving stays as
                // residual penetration, like the depenetration cap's: not retried in the later passes.
                let achieved: Real = (0..3).map(|k| weights[k] * shares[k]).sum();
                *left += applied * (1.0 - achieved).max(0.0);
                let mut impulse = Vec3::zeros();
                for k in 0..3 {
                    let dp = shift * shares[k];
                    view.p[corners[k]] += dp;
                    impulse += dp * view.mass[corners[k]];
                }
                load.impulse += impulse;
                load.moment += (contact.point - cur.position).cross(&impulse);
                load.penetration = load.penetration.max(depth);
                if count && round == 0 && pass == 0 {
                    load.contacts += 1;
                }
            }
            if largest <= SURFACE_PASS_TOLERANCE * skin {
                break;
            }
        }
    }
}

/// How far each corner of a triangle moves, in units of a correction of its contact point at
/// barycentric `weights`, for corner inverse masses `w`: the mass-weighted least-norm shares
/// `s_k = λ b_k w_k` with `Σ b_k s_k = 1` (the contact point moves by exactly the correction,
/// `λ = 1 / Σ b_j² w_j`), each at most [`MAX_CORNER_SHARE`]. A corner that would move more is
/// held at the cap and the rest of the correction goes to the others in the same proportion
/// (a larger common `λ`), so that a light corner beside heavier ones does not leave the contact
/// point short; but `λ` grows to at most [`MAX_CORNER_SHARE`] times its uncapped value. Without
/// that bound the excess of a corner next to the contact point went whole to a corner at a
/// tiny barycentric weight (the contact point on the edge between a free and a fixed corner):
/// its share `≈ target / b_k` hit the cap, and the far corner moved twice the correction, pass
/// after pass, while the contact point barely moved (the soak run's diverged steps: a corner
/// 28 mm from the contact point of a capsule flung out of the organ). When the remaining
/// corners cannot take the excess within these bounds, `Σ b_k s_k < 1`, and what is left stays
/// as residual penetration.
fn corner_shares(weights: &[Real; 3], w: &[Real; 3]) -> [Real; 3] {
    let mut shares = [0.0; 3];
    let mut capped = [false; 3];
    // What the corners not at the cap must still achieve of the correction.
    let mut target = 1.0;
    let uncapped_denominator: Real = (0..3).map(|k| weights[k] * weights[k] * w[k]).sum();
    if uncapped_denominator <= 0.0 {
        return shares;
    }
    // The largest common multiplier λ the redistribution may reach.
    let max_lambda = MAX_CORNER_SHARE / uncapped_denominator;
    // Each round caps at least one more corner, or ends.
    for _ in 0..3 {
        let denominator: Real = (0..3)
            .filter(|&k| !capped[k])
            .map(|k| weights[k] * weights[k] * w[k])
            .sum();
        if denominator <= 0.0 {
            break;
        }
        let lambda = (target / denominator).min(max_lambda);
        let mut newly_capped = false;
        for k in 0..3 {
            if capped[k] {
                continue;
            }
            shares[k] = weights[k] * w[k] * lambda;
            if shares[k] > MAX_CORNER_SHARE {
                shares[k] = MAX_CORNER_SHARE;
                capped[k] = true;
                newly_capped = true;
            }
        }
        if !newly_capped {
            break;
        }
        // A capped corner has b_k < 1/MAX_CORNER_SHARE (its share is at most 1/b_k before the
        // cap), so what is left to achieve stays positive.
        target = 1.0
            - (0..3)
                .filter(|&k| capped[k])
                .map(|k| weights[k] * MAX_CORNER_SHARE)
                .sum::<Real>();
    }
    shares
}

/// A contact of a tool with one boundary triangle.
struct TriangleContact {
    /// Where it acts on the triangle (m, world frame).
    point: Vec3,
    /// The direction the triangle must move (unit).
    direction: Vec3,
    /// How far it must move (m, > 0).
    depth: Real,
}

/// The contact of the tool (`map` at `iso`; `motion`: at `iso_prev`, the poses at the substep's
/// start and end) with the triangle `corners` (outward unit normal `n`) within `skin` (m),
/// one-sided as the module describes; `start`: when the tool came from in front of it, the
/// triangle's corners and unit normal at the substep's start.
#[allow(clippy::too_many_arguments)]
fn triangle_contact(
    tool: &Tool,
    map: &dyn SupportMap,
    epa: &mut EPA,
    iso: &Isometry<Real>,
    (iso_prev, prev, cur): (&Isometry<Real>, &Pose, &Pose),
    corners: [Vec3; 3],
    n: &Vec3,
    start: Option<([Vec3; 3], Vec3)>,
    skin: Real,
) -> Option<TriangleContact> {
    let [a, b, c] = corners;
    let triangle = Triangle::new(Point::from(a), Point::from(b), Point::from(c));
    let height = |q: &Vec3| (q - a).dot(n);
    if height(&map.support_point(iso, &-n).coords) >= skin {
        return None;
    }
    // Kept in front: the triangle moves along −n until the tool's far side, on the line along n
    // through the foot of the tool's middle, is `skin` in front of it.
    let in_front = || {
        let foot = triangle
            .project_local_point(&Point::from(middle(map, iso, n)), true)
            .point
            .coords;
        let depth = skin + depth_below(tool, iso, &foot, n)?;
        (depth > 0.0).then_some(TriangleContact {
            point: foot,
            direction: -n,
            depth,
        })
    };
    match separation(tool, map, epa, iso, &triangle, n, skin) {
        Separation::Near {
            on_tool,
            on_triangle,
            axis,
        } => {
            if start.is_some() && axis.dot(n) > 0.0 && height(&middle(map, iso, n)) < 0.0 {
                // The tool came from in front and its middle is now behind the plane: separating
                // this way would put the triangle in front of it; the tool went through it.
                return in_front();
            }
            Some(TriangleContact {
                point: on_triangle,
                direction: axis,
                depth: skin - (on_triangle - on_tool).dot(&axis),
            })
        }
        Separation::Apart => {
            // Swept: the tool's middle crossed the triangle's plane within the substep relative
            // to the triangle (the tool moved, or the passes before this one moved the
            // triangle past it), and the tool touched the triangle at that instant. Heights and
            // corners are taken as linear in the substep's fraction between start and end.
            let ([a0, b0, c0], n0) = start?;
            let (h0, h1) = (
                (middle(map, iso_prev, &n0) - a0).dot(&n0),
                height(&middle(map, iso, n)),
            );
            if h1 >= 0.0 || h0 < 0.0 {
                return None;
            }
            let s = h0 / (h0 - h1);
            let [sa, sb, sc] = [(a0, a), (b0, b), (c0, c)].map(|(q0, q)| q0 + (q - q0) * s);
            let n_s = (sb - sa).cross(&(sc - sa)).try_normalize(0.0)?;
            let triangle_s = Triangle::new(Point::from(sa), Point::from(sb), Point::from(sc));
            let crossing = Pose::interpolate(prev, cur, s).isometry();
            match separation(tool, map, epa, &crossing, &triangle_s, &n_s, skin) {
                Separation::Apart => None,
                _ => in_front(),
            }
        }
        Separation::Unknown => None,
    }
}

/// How the tool and a boundary triangle lie within the contact skin.
enum Separation {
    /// Within the skin of each other, or overlapping: the closest points, or the deepest ones
    /// (m, world frame), and the unit axis along which the triangle leaves the tool.
    Near {
        on_tool: Vec3,
        on_triangle: Vec3,
        axis: Vec3,
    },
    /// Farther apart than the skin.
    Apart,
    /// Overlapping, but EPA found no penetration depth.
    Unknown,
}

/// The separation of the tool (`map` at `iso`) and `triangle` (world frame, m; outward unit
/// normal `n`) within `skin` (m): in closed form for a sphere (a capsule of half-height 0
/// included), otherwise GJK (parry), and EPA when they overlap.
#[allow(clippy::too_many_arguments)]
fn separation(
    tool: &Tool,
    map: &dyn SupportMap,
    epa: &mut EPA,
    iso: &Isometry<Real>,
    triangle: &Triangle,
    n: &Vec3,
    skin: Real,
) -> Separation {
    match tool.description {
        ToolShape::Sphere { radius }
        | ToolShape::Capsule {
            half_height: 0.0,
            radius,
        } => sphere_separation(&iso.translation.vector, radius, triangle, n, skin),
        _ => gjk_separation(map, epa, iso, triangle, skin),
    }
}

/// [`separation`] by GJK, and EPA when they overlap.
fn gjk_separation(
    map: &dyn SupportMap,
    epa: &mut EPA,
    iso: &Isometry<Real>,
    triangle: &Triangle,
    skin: Real,
) -> Separation {
    // GJK and EPA work in the tool's frame.
    let near = |on_tool: Point<Real>, on_triangle: Point<Real>, axis: Vec3| Separation::Near {
        on_tool: iso.transform_point(&on_tool).coords,
        on_triangle: iso.transform_point(&on_triangle).coords,
        axis: iso.transform_vector(&axis),
    };
    let mut simplex = VoronoiSimplex::new();
    match gjk_at(iso, map, triangle, skin, &mut simplex) {
        GJKResult::ClosestPoints(on_tool, on_triangle, axis) => {
            near(on_tool, on_triangle, axis.into_inner())
        }
        GJKResult::Intersection => {
            match epa.closest_points(&iso.inverse(), map, triangle, &simplex) {
                Some((on_tool, on_triangle, axis)) => near(on_tool, on_triangle, axis.into_inner()),
                None => Separation::Unknown,
            }
        }
        _ => Separation::Apart,
    }
}

/// [`separation`] of a sphere (`centre`, m; `radius`, m) and `triangle`, exact: the triangle's
/// point `q` closest to the centre, the axis from the centre to `q`, and the sphere's point
/// along it. The distance from the centre to the triangle less the radius is the separation
/// (negative when they overlap), since the points within `radius` of a triangle are the
/// triangle swept by the sphere. A centre on the triangle takes the axis `−n`.
fn sphere_separation(
    centre: &Vec3,
    radius: Real,
    triangle: &Triangle,
    n: &Vec3,
    skin: Real,
) -> Separation {
    let on_triangle = triangle
        .project_local_point(&Point::from(*centre), true)
        .point
        .coords;
    let offset = on_triangle - centre;
    let distance = offset.norm();
    if distance - radius > skin {
        return Separation::Apart;
    }
    let axis = if distance > 0.0 {
        offset / distance
    } else {
        -n
    };
    Separation::Near {
        on_tool: centre + axis * radius,
        on_triangle,
        axis,
    }
}

/// GJK between the tool (`map` at `iso`) and `triangle` (world frame, m) within `skin` (m),
/// starting from a fresh `simplex`, which is left for EPA.
fn gjk_at(
    iso: &Isometry<Real>,
    map: &dyn SupportMap,
    triangle: &Triangle,
    skin: Real,
    simplex: &mut VoronoiSimplex,
) -> GJKResult {
    let pos12 = iso.inverse();
    simplex.reset(CSOPoint::from_shapes(
        &pos12,
        map,
        triangle,
        &pos12.translation.vector,
    ));
    gjk::closest_points(&pos12, map, triangle, skin, true, simplex)
}

/// How far (m) the tool at `iso` reaches behind `point` along −`n`: the distance from `point`
/// to the tool's far (−`n`) side on the line through `point` along `n` (negative when the tool
/// is wholly in front); `None` when that line misses the tool.
fn depth_below(tool: &Tool, iso: &Isometry<Real>, point: &Vec3, n: &Vec3) -> Option<Real> {
    // From a point beyond the tool's far side, cast towards +n: the first hit is that side.
    let beyond = (point - iso.translation.vector).norm() + tool.bounding_radius + 1.0e-3;
    let ray = Ray::new(Point::from(point - n * beyond), *n);
    let hit = tool.shape.cast_ray(iso, &ray, 2.0 * beyond, true)?;
    Some(beyond - hit)
}

/// The middle of the tool's extent along `direction` (m, world frame), at `iso`.
fn middle(map: &dyn SupportMap, iso: &Isometry<Real>, direction: &Vec3) -> Vec3 {
    0.5 * (map.support_point(iso, direction) + map.support_point(iso, &-direction).coords).coords
}

/// A triangle-mesh tool as the convex hull of its vertices (m, tool frame), for this pass.
struct VertexHull<'a>(&'a [Vec3]);

impl SupportMap for VertexHull<'_> {
    fn local_support_point(&self, direction: &Vec3) -> Point<Real> {
        let farthest = self
            .0
            .iter()
            .max_by(|p, q| p.dot(direction).total_cmp(&q.dot(direction)));
        Point::from(farthest.copied().unwrap_or_else(Vec3::zeros))
    }
}

/// Distance (m) from `point` to the segment from `a` to `b`.
fn distance_to_segment(point: &Vec3, a: &Vec3, b: &Vec3) -> Real {
    let ab = b - a;
    let length2 = ab.norm_squared();
    let s = if length2 > 0.0 {
        ((point - a).dot(&ab) / length2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (point - (a + ab * s)).norm()
}

/// The bounding box of a tool's path in a substep, a segment (m), and the tool's reach (m): a
/// quick first test of the broad phase, which spends no division or square root on the
/// triangles far away.
struct PathBox {
    lo: Vec3,
    hi: Vec3,
    reach: Real,
}

impl PathBox {
    fn new(from: &Vec3, to: &Vec3, reach: Real) -> Self {
        PathBox {
            lo: from.inf(to),
            hi: from.sup(to),
            reach,
        }
    }

    /// False only for a triangle (corners `a b c`) whose centroid is farther than `reach` plus
    /// the triangle's extent from the segment (the broad phase's exact test). The extent
    /// (largest distance of a corner from the centroid) is at most the diagonal of the corners'
    /// box, at most the sum of its sides; a centroid that close to the segment is that close to
    /// the path's box along each axis, and the centroid lies in the corners' box, so that box
    /// overlaps the path's box widened by the margin. (Plain comparisons: a NaN corner, which
    /// the exact test never keeps, may go either way.)
    #[inline]
    fn may_reach(&self, [a, b, c]: [&Vec3; 3]) -> bool {
        let lower = |x: Real, y: Real| if x < y { x } else { y };
        let upper = |x: Real, y: Real| if x > y { x } else { y };
        let lo = [0, 1, 2].map(|k| lower(lower(a[k], b[k]), c[k]));
        let hi = [0, 1, 2].map(|k| upper(upper(a[k], b[k]), c[k]));
        let margin = self.reach + (hi[0] - lo[0]) + (hi[1] - lo[1]) + (hi[2] - lo[2]);
        (0..3).all(|k| hi[k] >= self.lo[k] - margin && lo[k] <= self.hi[k] + margin)
    }
}

/// Barycentric weights of `q` (a point on the triangle `a b c`), clamped to the triangle.
fn barycentric(q: &Vec3, a: &Vec3, b: &Vec3, c: &Vec3) -> [Real; 3] {
    let (e1, e2, d) = (b - a, c - a, q - a);
    let (d11, d12, d22) = (e1.dot(&e1), e1.dot(&e2), e2.dot(&e2));
    let (d1, d2) = (d.dot(&e1), d.dot(&e2));
    let det = d11 * d22 - d12 * d12;
    if det <= 0.0 {
        return [1.0 / 3.0; 3];
    }
    let v = ((d22 * d1 - d12 * d2) / det).max(0.0);
    let w = ((d11 * d2 - d12 * d1) / det).max(0.0);
    let u = (1.0 - v - w).max(0.0);
    let sum = u + v + w;
    [u / sum, v / sum, w / sum]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kernels::math::uniform;

    /// The path box's quick test keeps every triangle the exact test keeps, and still turns
    /// away most of those far from the path: random slivers and segments, near and far.
    #[test]
    fn the_path_box_rejects_only_triangles_out_of_reach() {
        let mut random = uniform(7);
        let mut point = |scale: Real| Vec3::new(random(), random(), random()) * scale;
        let (mut kept, mut rejected) = (0, 0);
        for case in 0..20_000 {
            let (from, to) = (point(1.0), point(1.0));
            let reach = 0.1 * (case % 4) as Real;
            // Half the triangles next to a point of the path, half anywhere around it.
            let along = from + (to - from) * (point(1.0).x + 0.5);
            let centre = along + point(if case % 2 == 0 { 0.5 } else { 3.0 });
            // Every fourth triangle a sliver along one axis, the worst case of the box.
            let thin = if case % 4 == 0 { 1.0e-3 } else { 1.0 };
            let squash = Vec3::new(1.0, thin, thin);
            let [a, b, c] = [0; 3].map(|_| centre + point(0.1).component_mul(&squash));
            let centroid = (a + b + c) / 3.0;
            let extent = [a, b, c]
                .iter()
                .map(|q| (q - centroid).norm())
                .fold(0.0, Real::max);
            let exact = distance_to_segment(&centroid, &from, &to) <= reach + extent;
            let quick = PathBox::new(&from, &to, reach).may_reach([&a, &b, &c]);
            assert!(quick || !exact, "case {case}: a triangle in reach rejected");
            kept += usize::from(exact);
            rejected += usize::from(!quick);
        }
        let far = 20_000 - kept;
        assert!(
            kept > 1_000,
            "{kept} triangles in reach: the cases test little"
        );
        assert!(
            rejected * 2 > far,
            "only {rejected} of {far} far triangles rejected"
        );
    }

    /// The sphere's closed form against parry's GJK and EPA on a ball, for random triangles
    /// and centres apart, within the skin and overlapping: the same verdict, separation and
    /// axis, to GJK's accuracy on a curved shape, and never a larger gap than GJK's.
    #[test]
    fn the_sphere_closed_form_agrees_with_gjk_and_epa() {
        let mut random = uniform(11);
        let (radius, skin) = (0.1, 0.02);
        let ball = Ball::new(radius);
        let mut epa = EPA::new();
        let (mut near, mut overlapping, mut apart) = (0, 0, 0);
        for case in 0..5_000 {
            let mut point = || Vec3::new(random(), random(), random());
            let [a, b, c] = [point() * 0.6, point() * 0.6, point() * 0.6];
            let Some(n) = (b - a).cross(&(c - a)).try_normalize(1.0e-3) else {
                continue;
            };
            let triangle = Triangle::new(Point::from(a), Point::from(b), Point::from(c));
            let centre = (a + b + c) / 3.0 + point() * 0.5;
            let iso = Isometry::translation(centre.x, centre.y, centre.z);
            let exact = sphere_separation(&centre, radius, &triangle, &n, skin);
            let reference = gjk_separation(&ball, &mut epa, &iso, &triangle, skin);
            let gap =
                |on_tool: &Vec3, on_triangle: &Vec3, axis: &Vec3| (on_triangle - on_tool).dot(axis);
            match (exact, reference) {
                (Separation::Apart, Separation::Apart) => apart += 1,
                (
                    Separation::Near {
                        on_tool,
                        on_triangle,
                        axis,
                    },
                    Separation::Near {
                        on_tool: tool_ref,
                        on_triangle: triangle_ref,
                        axis: axis_ref,
                    },
                ) => {
                    let (got, want) = (
                        gap(&on_tool, &on_triangle, &axis),
                        gap(&tool_ref, &triangle_ref, &axis_ref),
                    );
                    // GJK's points lie on the shapes, so apart its gap is never below the
                    // true one; on a curved shape it stops within ~1e-5 of it.
                    assert!(
                        (got - want).abs() < 1e-4,
                        "case {case}: {got} against {want}"
                    );
                    assert!(
                        want <= 0.0 || got <= want + 1e-12,
                        "case {case}: {got} > {want}"
                    );
                    if got + radius > 1e-3 {
                        assert!((axis - axis_ref).norm() < 1e-2, "case {case}: axis");
                    }
                    if got < 0.0 {
                        overlapping += 1;
                    } else {
                        near += 1;
                    }
                }
                (exact, reference) => {
                    // Only at the skin's edge may the verdicts differ.
                    let centre_gap =
                        triangle.distance_to_local_point(&Point::from(centre), true) - radius;
                    assert!(
                        (centre_gap - skin).abs() < 1e-9,
                        "case {case}: {} against {}",
                        matches!(exact, Separation::Apart),
                        matches!(reference, Separation::Apart)
                    );
                }
            }
        }
        assert!(
            near > 100 && overlapping > 100 && apart > 100,
            "{near} {overlapping} {apart}"
        );
    }

    /// The shares of a triangle with a free corner `A` next to the contact point, a fixed corner
    /// and a free corner `B` at a tiny barycentric weight (the contact point on the edge from `A`
    /// to the fixed corner, the case of the soak run): `A` at the cap, and `B`, which can hardly
    /// move the contact point, moves by a tiny fraction of the correction, not by twice it.
    #[test]
    fn a_far_corner_does_not_take_a_capped_corners_excess() {
        // Barycentric weights and inverse masses (1/kg) printed by the soak run's replay.
        let (weights, w) = ([0.28, 1.0e-4, 0.72 - 1.0e-4], [2589.2, 2991.5, 0.0]);
        let shares = corner_shares(&weights, &w);
        assert_eq!(shares[0], MAX_CORNER_SHARE);
        assert_eq!(shares[2], 0.0);
        // Its uncapped least-norm share, grown at most MAX_CORNER_SHARE-fold.
        let uncapped =
            weights[1] * w[1] / (0..3).map(|k| weights[k] * weights[k] * w[k]).sum::<Real>();
        assert!(
            shares[1] <= MAX_CORNER_SHARE * uncapped * (1.0 + 1e-12),
            "{shares:?}"
        );
        assert!(shares[1] < 0.01, "{shares:?}");
    }

    /// A light corner beside two heavier ones at comparable weights: the light one at the cap,
    /// the others take its excess, and the contact point moves by the whole correction.
    #[test]
    fn heavier_corners_take_a_light_corners_excess() {
        let (weights, w) = ([0.3, 0.35, 0.35], [10.0, 1.0, 1.0]);
        let shares = corner_shares(&weights, &w);
        assert_eq!(shares[0], MAX_CORNER_SHARE);
        let achieved: Real = (0..3).map(|k| weights[k] * shares[k]).sum();
        assert!((achieved - 1.0).abs() < 1e-12, "{shares:?}");
    }

    #[test]
    fn barycentric_weights_rebuild_the_point_and_sum_to_one() {
        let (a, b, c) = (Vec3::zeros(), Vec3::x(), Vec3::y());
        let q = Vec3::new(0.2, 0.3, 0.0);
        let w = barycentric(&q, &a, &b, &c);
        assert!((w.iter().sum::<Real>() - 1.0).abs() < 1e-15);
        assert!((a * w[0] + b * w[1] + c * w[2] - q).norm() < 1e-15);
    }

    #[test]
    fn segment_distance_is_to_the_nearest_point_of_the_segment() {
        let (a, b) = (Vec3::zeros(), Vec3::x());
        assert!((distance_to_segment(&Vec3::new(0.5, 2.0, 0.0), &a, &b) - 2.0).abs() < 1e-15);
        assert!((distance_to_segment(&Vec3::new(3.0, 0.0, 0.0), &a, &b) - 2.0).abs() < 1e-15);
    }
}
