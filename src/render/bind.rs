//! Binding points to a tetrahedral mesh: for each point, the rest tetrahedron that encloses it
//! (or, outside the mesh, the nearest one) and its barycentric coordinates there.
//!
//! A uniform grid over the tetrahedra's bounding boxes (cell edge ≈ the cube root of the mean
//! volume per tetrahedron of the mesh's box) lists the tetrahedra overlapping each cell. A point
//! inside the mesh tests only the tetrahedra of its cell; a point outside searches rings of
//! cells around it until no unvisited cell can hold a closer tetrahedron. Building the grid is
//! linear in the number of tetrahedra and each query touches a bounded number of cells for
//! points near the mesh: binding n points is near-linear, never O(n · tets).

use crate::kernels::math::{Real, Vec3};
use parry3d_f64::math::Point;
use parry3d_f64::query::PointQuery;
use parry3d_f64::shape::Tetrahedron;

/// A point counts as inside a tetrahedron when its smallest barycentric coordinate is at
/// least `-INSIDE_TOLERANCE` (dimensionless; absorbs rounding on shared faces).
pub const INSIDE_TOLERANCE: Real = 1e-10;

/// Where one point is bound: a tetrahedron and the barycentric coordinates of the point with
/// respect to its four rest nodes. They sum to 1 and reproduce the rest point
/// (`Σ w_k X_k = p`); for a point outside the mesh they are the extrapolated coordinates (some
/// negative), so the point follows the affine map of the tetrahedron exactly.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Binding {
    /// Index of the tetrahedron in the body's tetrahedra.
    pub tet: u32,
    /// The tetrahedron's four node (particle) indices.
    pub nodes: [u32; 4],
    /// Barycentric coordinates (dimensionless), one per node.
    pub weights: [Real; 4],
}

impl Binding {
    /// The bound point for node positions `x` (m): `Σ w_k x_{nodes[k]}`.
    #[inline]
    pub fn apply(&self, x: &[Vec3]) -> Vec3 {
        let [a, b, c, d] = self.nodes.map(|i| x[i as usize]);
        let [wa, wb, wc, wd] = self.weights;
        a * wa + b * wb + c * wc + d * wd
    }
}

/// What binding found.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct BindReport {
    /// Points inside a tetrahedron (all barycentric coordinates ≥ `-INSIDE_TOLERANCE`).
    pub inside: usize,
    /// Points outside every tetrahedron, bound to the nearest one.
    pub outside: usize,
    /// Largest distance (m) from an outside point to its tetrahedron (0 when none is outside).
    pub max_outside_distance: Real,
}

/// Barycentric coordinates of `p` in the tetrahedron `(a, b, c, d)`, or `None` when it is
/// degenerate.
fn barycentric(p: &Vec3, [a, b, c, d]: [Vec3; 4]) -> Option<[Real; 4]> {
    let m = crate::kernels::math::Mat3::from_columns(&[b - a, c - a, d - a]);
    let l = m.try_inverse()? * (p - a);
    Some([1.0 - l.x - l.y - l.z, l.x, l.y, l.z])
}

/// The uniform grid of tetrahedron bounding boxes, in CSR form.
struct TetGrid {
    origin: Vec3,
    /// Cell edge (m).
    cell: Real,
    dims: [i64; 3],
    /// `start[c]..start[c + 1]` indexes `tets` for cell `c`.
    start: Vec<u32>,
    tets: Vec<u32>,
}

impl TetGrid {
    /// The grid over the bounding boxes `(min, max)` of the tetrahedra (at least one).
    fn new(boxes: &[(Vec3, Vec3)]) -> TetGrid {
        let (lo, hi) = boxes.iter().fold(
            (Vec3::repeat(Real::MAX), Vec3::repeat(Real::MIN)),
            |(lo, hi), (a, b)| (lo.inf(a), hi.sup(b)),
        );
        let extent = hi - lo;
        let diag = extent.norm().max(Real::MIN_POSITIVE);
        let side = |a: usize| extent[a].max(1e-9 * diag);
        // About one cell per tetrahedron, at most 128 cells along an axis.
        let cell = (side(0) * side(1) * side(2) / boxes.len() as Real)
            .cbrt()
            .max(extent.max() / 128.0)
            .max(1e-12 * diag);
        let dims = [0, 1, 2].map(|a| ((extent[a] / cell).floor() as i64 + 1).max(1));
        let mut grid = TetGrid {
            origin: lo,
            cell,
            dims,
            start: vec![0; (dims[0] * dims[1] * dims[2]) as usize + 1],
            tets: Vec::new(),
        };
        let mut counts = vec![0u32; grid.start.len()];
        for (a, b) in boxes {
            grid.for_cells_of_box(a, b, |c| counts[c + 1] += 1);
        }
        grid.start = counts;
        for c in 1..grid.start.len() {
            grid.start[c] += grid.start[c - 1];
        }
        let mut fill = grid.start.clone();
        let mut tets = vec![0; *grid.start.last().unwrap_or(&0) as usize];
        for (t, (a, b)) in boxes.iter().enumerate() {
            grid.for_cells_of_box(a, b, |c| {
                tets[fill[c] as usize] = t as u32;
                fill[c] += 1;
            });
        }
        grid.tets = tets;
        grid
    }

    /// Integer cell coordinates of `p`, not clamped to the grid.
    fn cell_of(&self, p: &Vec3) -> [i64; 3] {
        [0, 1, 2].map(|a| ((p[a] - self.origin[a]) / self.cell).floor() as i64)
    }

    /// Linear index of the cell `c` (inside the grid).
    fn index(&self, c: [i64; 3]) -> usize {
        (c[0] + self.dims[0] * (c[1] + self.dims[1] * c[2])) as usize
    }

    /// Call `f` with the linear index of every cell overlapped by the box `[a, b]`, clamped to
    /// the grid.
    fn for_cells_of_box(&self, a: &Vec3, b: &Vec3, mut f: impl FnMut(usize)) {
        let (lo, hi, d) = (self.cell_of(a), self.cell_of(b), self.dims);
        let r = |k: usize| lo[k].clamp(0, d[k] - 1)..=hi[k].clamp(0, d[k] - 1);
        for z in r(2) {
            for y in r(1) {
                for x in r(0) {
                    f(self.index([x, y, z]));
                }
            }
        }
    }

    /// The tetrahedra listed in cell `c` (empty outside the grid).
    fn tets_in(&self, c: [i64; 3]) -> &[u32] {
        if (0..3).any(|a| c[a] < 0 || c[a] >= self.dims[a]) {
            return &[];
        }
        let i = self.index(c);
        &self.tets[self.start[i] as usize..self.start[i + 1] as usize]
    }

    /// Call `f` with every in-grid cell at Chebyshev distance exactly `r` from `c`.
    fn for_shell(&self, c: [i64; 3], r: i64, mut f: impl FnMut([i64; 3])) {
        let range = |a: usize| (c[a] - r).max(0)..=(c[a] + r).min(self.dims[a] - 1);
        for x in range(0) {
            for y in range(1) {
                if (x - c[0]).abs() == r || (y - c[1]).abs() == r {
                    for z in range(2) {
                        f([x, y, z]);
                    }
                } else {
                    for z in [c[2] - r, c[2] + r] {
                        if (0..self.dims[2]).contains(&z) {
                            f([x, y, z]);
                        }
                    }
                }
            }
        }
    }
}

/// Bind every point of `points` to the tetrahedral mesh (`nodes`, m; `tets`, positively
/// oriented): the enclosing tetrahedron when there is one (the one where the point lies
/// deepest, if several share it), else the nearest tetrahedron (ties to the lowest index)
/// with the extrapolated barycentric coordinates. Deterministic. `tets` must not be empty and
/// its indices must be in range (a [`crate::Body`]'s are).
pub fn bind(nodes: &[Vec3], tets: &[[u32; 4]], points: &[Vec3]) -> (Vec<Binding>, BindReport) {
    let corners = |t: usize| tets[t].map(|i| nodes[i as usize]);
    let boxes: Vec<(Vec3, Vec3)> = (0..tets.len())
        .map(|t| {
            let c = corners(t);
            c.iter()
                .fold((c[0], c[0]), |(lo, hi), p| (lo.inf(p), hi.sup(p)))
        })
        .collect();
    let grid = TetGrid::new(&boxes);
    let mut report = BindReport::default();
    let bindings = points
        .iter()
        .map(|p| {
            let cell = grid.cell_of(p);
            // Inside: the tetrahedron of this cell where p lies deepest.
            let mut best: Option<(Real, u32, [Real; 4])> = None;
            for &t in grid.tets_in(cell) {
                if let Some(w) = barycentric(p, corners(t as usize)) {
                    let depth = w.iter().copied().fold(Real::MAX, Real::min);
                    if depth >= -INSIDE_TOLERANCE && best.is_none_or(|(d, _, _)| depth > d) {
                        best = Some((depth, t, w));
                    }
                }
            }
            if let Some((_, t, w)) = best {
                report.inside += 1;
                return Binding {
                    tet: t,
                    nodes: tets[t as usize],
                    weights: w,
                };
            }
            let (distance, t) = nearest(&grid, p, cell, &corners);
            report.outside += 1;
            report.max_outside_distance = report.max_outside_distance.max(distance);
            let c = corners(t as usize);
            // A positively oriented tetrahedron of a body is never degenerate; the centroid
            // weights keep a (never expected) degenerate one finite.
            let w = barycentric(p, c).unwrap_or([0.25; 4]);
            Binding {
                tet: t,
                nodes: tets[t as usize],
                weights: w,
            }
        })
        .collect();
    (bindings, report)
}

/// The nearest tetrahedron to `p` (whose grid cell is `cell`): `(distance (m), index)`.
fn nearest(
    grid: &TetGrid,
    p: &Vec3,
    cell: [i64; 3],
    corners: &impl Fn(usize) -> [Vec3; 4],
) -> (Real, u32) {
    let mut best = (Real::MAX, u32::MAX);
    // First ring that can touch the grid, and the ring after which every cell was seen.
    let gap = |a: usize| (-cell[a]).max(cell[a] - (grid.dims[a] - 1)).max(0);
    let far = |a: usize| (cell[a]).max(grid.dims[a] - 1 - cell[a]).max(0);
    let first = gap(0).max(gap(1)).max(gap(2));
    let last = far(0).max(far(1)).max(far(2));
    let pt = Point::from(*p);
    for r in first..=last {
        grid.for_shell(cell, r, |visited| {
            for &t in grid.tets_in(visited) {
                let [a, b, c, d] = corners(t as usize).map(Point::from);
                let dist = Tetrahedron::new(a, b, c, d).distance_to_local_point(&pt, true);
                if (dist, t) < best {
                    best = (dist, t);
                }
            }
        });
        // Every cell beyond ring r is at least r cells away from p's cell.
        if best.1 != u32::MAX && best.0 <= r as Real * grid.cell {
            break;
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn barycentric_reproduces_the_point() {
        let c = [Vec3::zeros(), Vec3::x(), Vec3::y(), Vec3::z()];
        let p = Vec3::new(0.1, 0.2, 0.3);
        let w = barycentric(&p, c).unwrap();
        let q = c[0] * w[0] + c[1] * w[1] + c[2] * w[2] + c[3] * w[3];
        assert!((q - p).norm() < 1e-15);
        assert!((w.iter().sum::<Real>() - 1.0).abs() < 1e-15);
    }
}
