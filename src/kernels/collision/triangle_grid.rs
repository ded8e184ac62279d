//! A uniform grid of triangle boxes for the surface self-contact's broad phase: each triangle
//! is listed in every cell its box (grown by a margin) overlaps, and a point looks in its own
//! cell only, which holds every triangle whose grown box contains the point.
//!
//! The cell side is the mean side of the grown boxes (their largest side each), but at least a
//! [`MAX_SPAN`]th of the largest, so that a box overlaps at most `(MAX_SPAN + 1)³` cells; when
//! the boxes would take more than [`ENTRIES_PER_BOX`] entries each on average the side is
//! doubled until they fit. Cells are hashed into buckets (a power of two, at least twice the
//! triangles) and sorted by counting sort into flat arrays sized by [`TriangleGrid::reserve`]:
//! no allocation when it is built again. Built and read on one thread in triangle order: the
//! same lists for any thread count.
//!
//! Each bucket also keeps the cone of its triangles' unit normals (an axis and the cosine of
//! the half-angle about it): a point whose surface normal lies within 90° of every normal in
//! its cell's cone faces none of those triangles, and the look-up ends there. On a smooth
//! stretch of surface that is most points, so that only folds, rims and surfaces near each
//! other cost more than a hash.

use crate::kernels::math::{Real, Vec3};

/// Most cells a grown box spans along an axis, less one (dimensionless).
const MAX_SPAN: i64 = 3;

/// Entries the grid holds per triangle (dimensionless): the mean number of cells per box it
/// allows.
const ENTRIES_PER_BOX: usize = 8;

/// The grid (see the module documentation).
#[derive(Debug, Clone, Default)]
pub(crate) struct TriangleGrid {
    /// Cell side (m).
    cell: Real,
    /// Buckets less one (a power of two less one: a mask).
    mask: usize,
    /// `start[h]..start[h + 1]` indexes `entries` for bucket `h` (length: buckets + 1).
    start: Vec<u32>,
    /// Triangle indices sorted by bucket, in triangle order within a bucket; a triangle is
    /// listed once per cell it overlaps (so twice in a row when two of its cells share a
    /// bucket).
    entries: Vec<u32>,
    /// Per triangle, its box grown by the margin (m): lower and upper corners.
    boxes: Vec<(Vec3, Vec3)>,
    /// Per bucket, the unit axis and the cosine (dimensionless) of the half-angle of the cone
    /// holding the unit normals of its triangles; a cosine of −1 when there is none to trust.
    cones: Vec<(Vec3, Real)>,
}

/// Least cosine (dimensionless) of the widest angle between a point's normal and a cell's cone
/// for the cell to be skipped: far above rounding, so that every skipped triangle's normal has
/// a positive dot product with the point's, as computed.
const FACING_MARGIN: Real = 1.0e-9;

impl TriangleGrid {
    /// Make room for `triangles` triangles (allocates only when it holds fewer).
    pub(crate) fn reserve(&mut self, triangles: usize) {
        if triangles <= self.boxes.len() && !self.start.is_empty() {
            return;
        }
        let buckets = (2 * triangles).next_power_of_two().max(64);
        self.mask = buckets - 1;
        self.start = vec![0; buckets + 1];
        self.entries = vec![0; ENTRIES_PER_BOX * triangles];
        self.boxes = vec![(Vec3::zeros(), Vec3::zeros()); triangles];
        self.cones = vec![(Vec3::zeros(), -1.0); buckets];
    }

    /// Call `visit` with the bucket of every cell the box `lo`–`hi` (m) overlaps, at most
    /// `MAX_SPAN + 1` along an axis (fewer only for a box too large for a finite cell side,
    /// see `build`).
    #[inline]
    fn for_each_bucket(&self, (lo, hi): &(Vec3, Vec3), mut visit: impl FnMut(usize)) {
        let (c0, c1) = (self.cell_of(lo), self.cell_of(hi));
        for z in c0[2]..=c1[2].min(c0[2].saturating_add(MAX_SPAN)) {
            for y in c0[1]..=c1[1].min(c0[1].saturating_add(MAX_SPAN)) {
                for x in c0[0]..=c1[0].min(c0[0].saturating_add(MAX_SPAN)) {
                    visit(self.bucket([x, y, z]));
                }
            }
        }
    }

    #[inline]
    fn bucket(&self, c: [i64; 3]) -> usize {
        let h = (c[0].wrapping_mul(73_856_093))
            ^ (c[1].wrapping_mul(19_349_663))
            ^ (c[2].wrapping_mul(83_492_791));
        (h as u64 as usize) & self.mask
    }

    #[inline]
    fn cell_of(&self, p: &Vec3) -> [i64; 3] {
        [0, 1, 2].map(|a| (p[a] / self.cell).floor() as i64)
    }

    /// Rebuild over `triangles` (corner indices into `positions`, m; `normals` their unit
    /// normals, or zero for a degenerate one), each box grown by `margin` (m) on every side.
    /// Needs [`TriangleGrid::reserve`] for as many triangles.
    pub(crate) fn build(
        &mut self,
        positions: &[Vec3],
        triangles: &[[u32; 3]],
        normals: &[Vec3],
        margin: Real,
    ) {
        let n = triangles.len();
        let (mut sum, mut largest): (Real, Real) = (0.0, 0.0);
        for (t, corners) in triangles.iter().enumerate() {
            let [a, b, c] = corners.map(|k| positions[k as usize]);
            let lo = a.inf(&b).inf(&c).add_scalar(-margin);
            let hi = a.sup(&b).sup(&c).add_scalar(margin);
            self.boxes[t] = if lo.iter().chain(hi.iter()).all(|v| v.is_finite()) {
                let side = (hi - lo).max();
                sum += side;
                largest = largest.max(side);
                (lo, hi)
            } else {
                // A NaN or infinite corner: an empty box (upper below lower), in no cell.
                (Vec3::repeat(1.0), Vec3::repeat(-1.0))
            };
        }
        // A hair above a MAX_SPAN-th of the largest side, so that rounding never lets a box
        // span more cells; the cell stays finite and positive when the sum overflows.
        let floor = largest / MAX_SPAN as Real * (1.0 + 1.0e-6);
        let mean = sum / n.max(1) as Real;
        self.cell = if floor > 0.0 && mean.is_finite() {
            mean.max(floor)
        } else {
            1.0
        };
        let capacity = ENTRIES_PER_BOX * n;
        let mut start = std::mem::take(&mut self.start);
        loop {
            start.iter_mut().for_each(|s| *s = 0);
            let mut total = 0;
            for b in &self.boxes[..n] {
                self.for_each_bucket(b, |h| {
                    start[h + 1] += 1;
                    total += 1;
                });
            }
            if total <= capacity {
                break;
            }
            // At most twice (from a MAX_SPAN-th of the largest side): above the largest side a
            // box spans at most 2 × 2 × 2 cells.
            self.cell *= 2.0;
        }
        for h in 0..start.len() - 1 {
            start[h + 1] += start[h];
        }
        // `start[h]` as a moving cursor, shifted back below; each bucket keeps triangle order.
        let mut entries = std::mem::take(&mut self.entries);
        for (t, b) in self.boxes[..n].iter().enumerate() {
            self.for_each_bucket(b, |h| {
                entries[start[h] as usize] = t as u32;
                start[h] += 1;
            });
        }
        for h in (1..start.len()).rev() {
            start[h] = start[h - 1];
        }
        start[0] = 0;
        for (h, cone) in self.cones.iter_mut().enumerate() {
            let listed = &entries[start[h] as usize..start[h + 1] as usize];
            let sum: Vec3 = listed.iter().map(|&t| normals[t as usize]).sum();
            *cone = match sum.try_normalize(0.0) {
                Some(axis) => {
                    let nonzero = listed.iter().map(|&t| normals[t as usize]);
                    let nonzero = nonzero.filter(|n| *n != Vec3::zeros());
                    (axis, nonzero.map(|n| axis.dot(&n)).fold(1.0, Real::min))
                }
                None => (Vec3::zeros(), -1.0),
            };
        }
        self.start = start;
        self.entries = entries;
    }

    /// Call `visit` with every triangle whose grown box contains `p` (m), in triangle order,
    /// each once — or with none when `facing` (a unit vector: the surface normal at `p`) has a
    /// dot product above zero with every triangle's normal in `p`'s cell (see the module
    /// documentation).
    #[inline]
    pub(crate) fn for_each_containing(
        &self,
        p: &Vec3,
        facing: &Vec3,
        mut visit: impl FnMut(usize),
    ) {
        let h = self.bucket(self.cell_of(p));
        // cos(α + θ) for α the angle from the cone's axis to `facing`, θ the cone's half-angle.
        let (axis, cos_cone) = self.cones[h];
        let cos_facing = axis.dot(facing).min(1.0);
        let sin = |c: Real| (1.0 - c * c).max(0.0).sqrt();
        if cos_cone > 0.0
            && cos_facing > 0.0
            && cos_facing * cos_cone - sin(cos_facing) * sin(cos_cone) > FACING_MARGIN
        {
            return;
        }
        let mut last = u32::MAX;
        for &t in &self.entries[self.start[h] as usize..self.start[h + 1] as usize] {
            if t == last {
                continue;
            }
            last = t;
            let (lo, hi) = &self.boxes[t as usize];
            if (0..3).all(|k| lo[k] <= p[k] && p[k] <= hi[k]) {
                visit(t as usize);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every triangle whose grown box contains a point is visited once, and no other, unless
    /// the point's normal is within 90° of all of them and none is visited: random flat-ish
    /// triangles of mixed sizes (normals within about 30° of +z) against random points and
    /// normals, checked by brute force.
    #[test]
    fn visits_exactly_the_boxes_that_contain_the_point_unless_none_faces_it() {
        let mut seed = 3u64;
        let mut random = move || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as Real / (1u64 << 53) as Real - 0.5
        };
        let mut positions = Vec::new();
        let mut triangles = Vec::new();
        let mut normals = Vec::new();
        for t in 0..500u32 {
            let centre = Vec3::new(random(), random(), random());
            let size = if t % 10 == 0 { 0.2 } else { 0.03 };
            let corners =
                [(); 3].map(|_| centre + Vec3::new(random(), random(), 0.2 * random()) * size);
            let n = (corners[1] - corners[0]).cross(&(corners[2] - corners[0]));
            let (b, c) = if n.z >= 0.0 { (1, 2) } else { (2, 1) };
            positions.extend([corners[0], corners[b], corners[c]]);
            triangles.push([3 * t, 3 * t + 1, 3 * t + 2]);
            normals.push(n.normalize() * n.z.signum());
        }
        let margin = 0.01;
        let mut grid = TriangleGrid::default();
        grid.reserve(triangles.len());
        grid.build(&positions, &triangles, &normals, margin);
        let (mut found, mut skipped) = (0, 0);
        for points in 0..4_000 {
            // Half the points next to a triangle's corner, half anywhere.
            let near = positions[(points * 7) % positions.len()];
            let offset = Vec3::new(random(), random(), random());
            let p = if points % 2 == 0 {
                near + offset * 0.04
            } else {
                offset
            };
            let facing = Vec3::new(random(), random(), random()).normalize();
            let mut visited = Vec::new();
            grid.for_each_containing(&p, &facing, |t| visited.push(t));
            let brute: Vec<usize> = (0..triangles.len())
                .filter(|&t| {
                    let [a, b, c] = triangles[t].map(|k| positions[k as usize]);
                    let lo = a.inf(&b).inf(&c).add_scalar(-margin);
                    let hi = a.sup(&b).sup(&c).add_scalar(margin);
                    (0..3).all(|k| lo[k] <= p[k] && p[k] <= hi[k])
                })
                .collect();
            if visited.is_empty() && !brute.is_empty() {
                assert!(brute.iter().all(|&t| normals[t].dot(&facing) > 0.0));
                skipped += 1;
            } else {
                assert_eq!(visited, brute);
                found += brute.len();
            }
        }
        assert!(
            found > 400 && skipped > 200,
            "{found} boxes hit, {skipped} points skipped: the cases test little"
        );
    }
}
