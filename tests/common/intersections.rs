//! Surface self-intersections measured on the geometry, independently of the library: the
//! pairs of triangles of a surface that cross each other, pairs sharing a vertex skipped.
//! Included by path (`#[path = ...] mod intersections;`) by the self-contact tests and by
//! `examples/soak.rs`.

use tissuesim::{Real, Vec3};

/// Six times the signed volume of the tetrahedron `a b c d` (m³): positive when `d` is on the
/// side of `a b c` its normal `(b − a) × (c − a)` points to.
fn orient(a: &Vec3, b: &Vec3, c: &Vec3, d: &Vec3) -> Real {
    (b - a).cross(&(c - a)).dot(&(d - a))
}

/// Whether the segment `p q` passes through the interior of the triangle `t`: its ends strictly
/// on either side of the triangle's plane, and the line through them strictly inside the three
/// edges (the orientation predicates; touching does not count).
fn segment_crosses_triangle(p: &Vec3, q: &Vec3, t: &[Vec3; 3]) -> bool {
    let [a, b, c] = t;
    if orient(a, b, c, p) * orient(a, b, c, q) >= 0.0 {
        return false;
    }
    let s = [orient(p, q, a, b), orient(p, q, b, c), orient(p, q, c, a)];
    s.iter().all(|&v| v > 0.0) || s.iter().all(|&v| v < 0.0)
}

/// Whether two triangles (corners in m) cross: two triangles that are not coplanar intersect
/// exactly when an edge of one passes through the other.
pub fn triangles_cross(t: &[Vec3; 3], u: &[Vec3; 3]) -> bool {
    let edges = |v: &[Vec3; 3]| [(v[0], v[1]), (v[1], v[2]), (v[2], v[0])];
    edges(t)
        .iter()
        .any(|(p, q)| segment_crosses_triangle(p, q, u))
        || edges(u)
            .iter()
            .any(|(p, q)| segment_crosses_triangle(p, q, t))
}

/// The pairs of `triangles` (corner indices into `x`, m) that cross each other, pairs sharing
/// a corner skipped, each pair once `(t, u)` with `t < u`. Sweep and prune along x over the
/// triangles' bounding boxes, then [`triangles_cross`].
pub fn crossing_pairs(x: &[Vec3], triangles: &[[u32; 3]]) -> Vec<(usize, usize)> {
    let corners = |t: usize| triangles[t].map(|k| x[k as usize]);
    let boxes: Vec<(Vec3, Vec3)> = (0..triangles.len())
        .map(|t| {
            let [a, b, c] = corners(t);
            (a.inf(&b).inf(&c), a.sup(&b).sup(&c))
        })
        .collect();
    let mut order: Vec<usize> = (0..triangles.len()).collect();
    order.sort_by(|&s, &t| boxes[s].0.x.total_cmp(&boxes[t].0.x));
    let mut pairs = Vec::new();
    for (k, &t) in order.iter().enumerate() {
        let (lo, hi) = boxes[t];
        for &u in &order[k + 1..] {
            let (ulo, uhi) = boxes[u];
            if ulo.x > hi.x {
                break;
            }
            let overlap = (1..3).all(|a| ulo[a] <= hi[a] && lo[a] <= uhi[a]);
            let shared = triangles[t].iter().any(|v| triangles[u].contains(v));
            if overlap && !shared && triangles_cross(&corners(t), &corners(u)) {
                pairs.push((t.min(u), t.max(u)));
            }
        }
    }
    pairs.sort_unstable();
    pairs
}
