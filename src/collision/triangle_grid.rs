//! A uniform grid of triangle boxes for the surface self-contact's broad phase: each triangle
//! is listed in every cell its box (grown by a margin) overlaps, and a point looks in its own
//! cell only, which holds every triangle whose grown box contains the point.
//!
//! The cell side is the largest side of any grown box, so a box overlaps at most 2 × 2 × 2
//! cells. Cells are hashed into buckets (a power of two, at least twice the triangles) and
//! sorted by counting sort into flat arrays sized by [`TriangleGrid::reserve`]: no allocation
//! when it is built again. Built and read on one thread in triangle order: the same lists for
//! any thread count.

use crate::math::{Real, Vec3};

/// Most cells one grown triangle box overlaps.
const CELLS_PER_BOX: usize = 8;

/// The grid (see the module documentation).
#[derive(Debug, Clone, Default)]
pub(crate) struct TriangleGrid {
    /// Cell side (m).
    cell: Real,
    /// `start[h]..start[h + 1]` indexes `entries` for bucket `h` (length: buckets + 1).
    start: Vec<u32>,
    /// Triangle indices sorted by bucket; a triangle is listed once per bucket it reaches.
    entries: Vec<u32>,
    /// Per triangle, its box grown by the margin (m): lower and upper corners.
    boxes: Vec<(Vec3, Vec3)>,
    /// Per triangle, the buckets of its cells (`u32::MAX` past the last): counting sort scratch.
    buckets_of: Vec<[u32; CELLS_PER_BOX]>,
}

impl TriangleGrid {
    /// Make room for `triangles` triangles (allocates only when it holds fewer).
    pub(crate) fn reserve(&mut self, triangles: usize) {
        if triangles <= self.boxes.len() && !self.start.is_empty() {
            return;
        }
        let buckets = (2 * triangles).next_power_of_two().max(64);
        self.start = vec![0; buckets + 1];
        self.entries = vec![0; CELLS_PER_BOX * triangles];
        self.boxes = vec![(Vec3::zeros(), Vec3::zeros()); triangles];
        self.buckets_of = vec![[u32::MAX; CELLS_PER_BOX]; triangles];
    }

    #[inline]
    fn bucket(&self, c: [i64; 3]) -> u32 {
        let h = (c[0].wrapping_mul(73_856_093))
            ^ (c[1].wrapping_mul(19_349_663))
            ^ (c[2].wrapping_mul(83_492_791));
        ((h as u64 as usize) & (self.start.len() - 2)) as u32
    }

    #[inline]
    fn cell_of(&self, p: &Vec3) -> [i64; 3] {
        [0, 1, 2].map(|a| (p[a] / self.cell).floor() as i64)
    }

    /// Rebuild over `triangles` (corner indices into `positions`, m), each box grown by
    /// `margin` (m) on every side. Needs [`TriangleGrid::reserve`] for as many triangles.
    pub(crate) fn build(&mut self, positions: &[Vec3], triangles: &[[u32; 3]], margin: Real) {
        let n = triangles.len();
        let mut side: Real = 0.0;
        for (t, corners) in triangles.iter().enumerate() {
            let [a, b, c] = corners.map(|k| positions[k as usize]);
            let lo = a.inf(&b).inf(&c).add_scalar(-margin);
            let hi = a.sup(&b).sup(&c).add_scalar(margin);
            side = side.max((hi - lo).max());
            self.boxes[t] = (lo, hi);
        }
        // A hair above the largest side, so that rounding never lets a box span three cells;
        // a NaN position makes every comparison false: the cell stays finite and positive.
        self.cell = if side > 0.0 && side.is_finite() {
            side * (1.0 + 1.0e-6)
        } else {
            1.0
        };
        self.start.iter_mut().for_each(|s| *s = 0);
        for t in 0..n {
            let (lo, hi) = self.boxes[t];
            let (c0, c1) = (self.cell_of(&lo), self.cell_of(&hi));
            let mut mine = [u32::MAX; CELLS_PER_BOX];
            let mut count = 0;
            for z in c0[2]..=c1[2].min(c0[2] + 1) {
                for y in c0[1]..=c1[1].min(c0[1] + 1) {
                    for x in c0[0]..=c1[0].min(c0[0] + 1) {
                        let h = self.bucket([x, y, z]);
                        // Two cells of one box hashed to one bucket: listed once.
                        if !mine[..count].contains(&h) {
                            mine[count] = h;
                            count += 1;
                            self.start[h as usize + 1] += 1;
                        }
                    }
                }
            }
            self.buckets_of[t] = mine;
        }
        for h in 0..self.start.len() - 1 {
            self.start[h + 1] += self.start[h];
        }
        // `start[h]` as a moving cursor, shifted back below; each bucket keeps triangle order.
        for t in 0..n {
            for &h in self.buckets_of[t].iter().take_while(|&&h| h != u32::MAX) {
                self.entries[self.start[h as usize] as usize] = t as u32;
                self.start[h as usize] += 1;
            }
        }
        for h in (1..self.start.len()).rev() {
            self.start[h] = self.start[h - 1];
        }
        self.start[0] = 0;
    }

    /// Call `visit` with every triangle whose grown box contains `p` (m), in triangle order,
    /// each once.
    #[inline]
    pub(crate) fn for_each_containing(&self, p: &Vec3, mut visit: impl FnMut(usize)) {
        let h = self.bucket(self.cell_of(p)) as usize;
        for &t in &self.entries[self.start[h] as usize..self.start[h + 1] as usize] {
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
