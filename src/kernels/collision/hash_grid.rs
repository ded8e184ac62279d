//! A spatial hash grid over the particles of every body (the paper's Fig. 1), rebuilt each
//! substep from predicted positions, for organ–organ (and optional self-) contact.
//!
//! Built by counting sort into flat arrays sized when bodies are added: no allocation per step.

use crate::kernels::math::{Real, Vec3};

/// A particle reference: body index and particle index.
pub type ParticleRef = [u32; 2];

/// The grid (see the module documentation).
#[derive(Debug, Clone, Default)]
pub struct HashGrid {
    cell: Real,
    /// `start[h]..start[h+1]` indexes `entries` for bucket `h` (length: buckets + 1).
    start: Vec<u32>,
    /// Particles sorted by bucket.
    entries: Vec<ParticleRef>,
    /// Bucket of each particle in insertion order; scratch of the counting sort.
    bucket_of: Vec<u32>,
}

impl HashGrid {
    /// Size the grid for `particles` particles in all (allocates; called when bodies change).
    pub fn reserve(&mut self, particles: usize) {
        let buckets = (2 * particles).next_power_of_two().max(64);
        self.start = vec![0; buckets + 1];
        self.entries = vec![[0, 0]; particles];
        self.bucket_of = vec![0; particles];
    }

    #[inline]
    fn bucket(&self, c: [i64; 3]) -> usize {
        let h = (c[0].wrapping_mul(73_856_093))
            ^ (c[1].wrapping_mul(19_349_663))
            ^ (c[2].wrapping_mul(83_492_791));
        (h as u64 as usize) & (self.start.len() - 2)
    }

    #[inline]
    fn cell_coords(&self, p: &Vec3) -> [i64; 3] {
        [0, 1, 2].map(|a| (p[a] / self.cell).floor() as i64)
    }

    /// Rebuild from the positions of each body (`positions` yields one slice per body, m) with
    /// cell size `cell` (m, at least the largest contact distance). Needs
    /// [`HashGrid::reserve`] for the total particle count.
    pub fn build<'a, I>(&mut self, positions: I, cell: Real)
    where
        I: Iterator<Item = &'a [Vec3]> + Clone,
    {
        self.cell = cell;
        self.start.iter_mut().for_each(|s| *s = 0);
        let mut k = 0;
        for pos in positions.clone() {
            for p in pos.iter() {
                let b = self.bucket(self.cell_coords(p));
                self.bucket_of[k] = b as u32;
                self.start[b + 1] += 1;
                k += 1;
            }
        }
        for h in 0..self.start.len() - 1 {
            self.start[h + 1] += self.start[h];
        }
        // Each bucket keeps insertion order (deterministic).
        // Use start[h] as a moving cursor, then shift back below.
        let mut k = 0;
        for (b, pos) in positions.enumerate() {
            for i in 0..pos.len() {
                let h = self.bucket_of[k] as usize;
                self.entries[self.start[h] as usize] = [b as u32, i as u32];
                self.start[h] += 1;
                k += 1;
            }
        }
        // The cursors now sit at each bucket's end: shift back to the starts.
        for h in (1..self.start.len()).rev() {
            self.start[h] = self.start[h - 1];
        }
        self.start[0] = 0;
    }

    /// Call `visit` for every particle whose bucket is one of the 27 cells around `p`. A bucket
    /// reached twice through hash collisions is visited once.
    #[inline]
    pub fn for_each_near(&self, p: &Vec3, mut visit: impl FnMut(ParticleRef)) {
        let c = self.cell_coords(p);
        let mut seen = [usize::MAX; 27];
        let mut n = 0;
        for dz in -1..=1 {
            for dy in -1..=1 {
                for dx in -1..=1 {
                    let h = self.bucket([c[0] + dx, c[1] + dy, c[2] + dz]);
                    if seen[..n].contains(&h) {
                        continue;
                    }
                    seen[n] = h;
                    n += 1;
                    for e in &self.entries[self.start[h] as usize..self.start[h + 1] as usize] {
                        visit(*e);
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_every_close_pair_that_brute_force_finds() {
        let a: Vec<Vec3> = (0..200)
            .map(|i| {
                let t = i as Real;
                Vec3::new((t * 0.37).sin(), (t * 0.73).cos(), (t * 0.11).sin() * 0.5)
            })
            .collect();
        let b: Vec<Vec3> = a
            .iter()
            .map(|p| p * 0.9 + Vec3::new(0.05, 0.0, 0.0))
            .collect();
        let mut grid = HashGrid::default();
        grid.reserve(a.len() + b.len());
        let r = 0.1;
        grid.build([a.as_slice(), b.as_slice()].into_iter(), r);
        let mut found = 0;
        let mut brute = 0;
        for p in &a {
            grid.for_each_near(p, |[body, j]| {
                if body == 1 && (b[j as usize] - p).norm() < r {
                    found += 1;
                }
            });
            brute += b.iter().filter(|q| (*q - p).norm() < r).count();
        }
        assert_eq!(found, brute);
        assert!(brute > 0);
    }
}
