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

use crate::math::{Real, Vec3};

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
}

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

    /// Rebuild over `triangles` (corner indices into `positions`, m), each box grown by
    /// `margin` (m) on every side. Needs [`TriangleGrid::reserve`] for as many triangles.
    pub(crate) fn build(&mut self, positions: &[Vec3], triangles: &[[u32; 3]], margin: Real) {
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
        self.start = start;
        self.entries = entries;
    }

    /// Call `visit` with every triangle whose grown box contains `p` (m), in triangle order,
    /// each once.
    #[inline]
    pub(crate) fn for_each_containing(&self, p: &Vec3, mut visit: impl FnMut(usize)) {
        let h = self.bucket(self.cell_of(p));
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

    /// Every triangle whose grown box contains a point is visited once, and no other: random
    /// triangles of mixed sizes against random points, checked by brute force.
    #[test]
    fn visits_exactly_the_boxes_that_contain_the_point() {
        let mut seed = 3u64;
        let mut random = move || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as Real / (1u64 << 53) as Real - 0.5
        };
        let mut positions = Vec::new();
        let mut triangles = Vec::new();
        for t in 0..500u32 {
            let centre = Vec3::new(random(), random(), random());
            let size = if t % 10 == 0 { 0.2 } else { 0.03 };
            for _ in 0..3 {
                positions.push(centre + Vec3::new(random(), random(), random()) * size);
            }
            triangles.push([3 * t, 3 * t + 1, 3 * t + 2]);
        }
        let margin = 0.01;
        let mut grid = TriangleGrid::default();
        grid.reserve(triangles.len());
        grid.build(&positions, &triangles, margin);
        let (mut found, mut points) = (0, 0);
        while points < 2_000 {
            // Half the points next to a triangle's corner, half anywhere.
            let near = positions[(points * 7) % positions.len()];
            let offset = Vec3::new(random(), random(), random());
            let p = if points % 2 == 0 {
                near + offset * 0.04
            } else {
                offset
            };
            let mut visited = Vec::new();
            grid.for_each_containing(&p, |t| visited.push(t));
            let brute: Vec<usize> = (0..triangles.len())
                .filter(|&t| {
                    let [a, b, c] = triangles[t].map(|k| positions[k as usize]);
                    let lo = a.inf(&b).inf(&c).add_scalar(-margin);
                    let hi = a.sup(&b).sup(&c).add_scalar(margin);
                    (0..3).all(|k| lo[k] <= p[k] && p[k] <= hi[k])
                })
                .collect();
            assert_eq!(visited, brute);
            found += brute.len();
            points += 1;
        }
        assert!(found > 400, "{found} boxes hit: the cases test little");
    }
}
