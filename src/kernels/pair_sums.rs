//! How the pair forces of the force pass reach the particles' sums, bit-identically for any
//! number of threads.
//!
//! The force on particle `j` is what else acts on it, minus `g_ij` of every pair `(i, j)` and
//! plus its own `Σ_k g_jk`, added in the order of the one-thread scatter: pairs from particles
//! before `j`, its own sum, pairs from particles after `j`. Each thread's share of the
//! particles runs the first pass in particle order, so a particle all of whose sources
//! ([`Neighbourhoods::sources`]) lie in the share gets its terms in exactly that order when the
//! share scatters them as they are computed ([`ShareForces::distribute`]). Only a particle with
//! a source in another share needs its terms kept: they are written to the pair slots and
//! summed, in the same order, after a barrier that every share's first pass reaches
//! ([`sum_after_barrier`]). On one thread nothing is kept.
//!
//! Keeping every pair force (24 bytes a pair slot) and summing every particle from them, as an
//! earlier version did, streamed the pair forces through memory on the large livers: on
//! liver_31k ~15 MB written and read back a step, next to the ~37 MB of rest data.

use crate::kernels::math::Vec3;
use crate::kernels::neighbours::Neighbourhoods;
use std::ops::Range;

/// Whether particle `j` has a source outside the particles `share`: its sum is then taken from
/// the kept pair forces after the barrier, not scattered by the share.
#[inline(always)]
fn crosses(nbr: &Neighbourhoods, j: usize, share: &Range<usize>) -> bool {
    let [first, last] = nbr.sources[j].map(|k| k as usize);
    first < share.start || last >= share.end
}

/// The results of one share's first pass.
pub(crate) struct ShareForces<'a> {
    /// The neighbourhoods of the whole body.
    pub(crate) nbr: &'a Neighbourhoods,
    /// The share's particles.
    pub(crate) share: Range<usize>,
    /// Forces on the share's particles (N), particle `j` at `j - share.start`: on entry what
    /// else acts on them.
    pub(crate) force: &'a mut [Vec3],
    /// The share's pair slots (from its first particle's), pair `e` at
    /// `e - offsets[share.start]`: the forces `g_ij` (N) of the pairs whose neighbour `j`
    /// crosses shares.
    pub(crate) pair_force: &'a mut [Vec3],
    /// The own sums `Σ_k g_ik` (N) of the share's particles that cross shares, particle `i` at
    /// `i - share.start`.
    pub(crate) own: &'a mut [Vec3],
}

impl ShareForces<'_> {
    /// Hand on the first pass's results for particle `i` of the share, whose particles before
    /// `i` have had theirs: `pairs`, the forces `g_ij` (N) of its pair slots, padding included,
    /// and `own`, their sum. Each term goes to the force of a particle that crosses no share,
    /// or is kept for [`sum_after_barrier`].
    #[inline(always)]
    pub(crate) fn distribute(&mut self, i: usize, pairs: &[Vec3], own: Vec3) {
        let nbr = self.nbr;
        let start = self.share.start;
        let range = nbr.range(i);
        let [first, last] = nbr.reach[i].map(|k| k as usize);
        if first >= start && last < self.share.end {
            // Nothing of i's crosses shares (always so on one thread).
            for (&j, g) in nbr.index[range].iter().zip(pairs) {
                self.force[j as usize - start] -= g;
            }
            self.force[i - start] += own;
            return;
        }
        let first_pair = nbr.offsets[start] as usize;
        for ((e, &j), g) in range.clone().zip(&nbr.index[range]).zip(pairs) {
            let j = j as usize;
            if crosses(nbr, j, &self.share) {
                self.pair_force[e - first_pair] = *g;
            } else {
                self.force[j - start] -= g;
            }
        }
        if crosses(nbr, i, &self.share) {
            self.own[i - start] = own;
        } else {
            self.force[i - start] += own;
        }
    }
}

/// The kept results of every share's first pass, read after the barrier: pair `e`'s force
/// `pairs[e]` and particle `i`'s own sum `own[i]` (N), written where the pair's neighbour or the
/// particle crosses shares.
#[derive(Clone, Copy)]
pub(crate) struct Kept<'a> {
    pub(crate) pairs: &'a [Vec3],
    pub(crate) own: &'a [Vec3],
}

/// After the barrier: the sums of the particles of `share` that cross shares, added to
/// `force` (theirs, N), from every share's kept results.
pub(crate) fn sum_after_barrier(
    nbr: &Neighbourhoods,
    share: Range<usize>,
    force: &mut [Vec3],
    kept: Kept<'_>,
) {
    let mut held = None;
    for j in share.clone().filter(|&j| crosses(nbr, j, &share)) {
        match held.take() {
            None => held = Some(j),
            Some(i) => sum_two(nbr, [i, j], kept, force, share.start),
        }
    }
    if let Some(i) = held {
        sum_two(nbr, [i, i], kept, force, share.start);
    }
}

/// The sums of particles `j` (two; the same twice for one), added to `force[j - first]` (N).
/// Each sum is a chain of dependent additions; two side by side keep the adder busy, each in
/// its own order.
#[inline(always)]
fn sum_two(nbr: &Neighbourhoods, j: [usize; 2], kept: Kept<'_>, force: &mut [Vec3], first: usize) {
    let split = |j: usize| {
        // Pairs of particles before j have indices below offsets[j].
        let incoming = nbr.incoming(j);
        incoming.split_at(incoming.partition_point(|&e| e < nbr.offsets[j]))
    };
    let [(before0, after0), (before1, after1)] = j.map(split);
    let mut sums = j.map(|j| force[j - first]);
    subtract_pairs(&mut sums, [before0, before1], kept);
    sums[0] += kept.own[j[0]];
    sums[1] += kept.own[j[1]];
    subtract_pairs(&mut sums, [after0, after1], kept);
    force[j[0] - first] = sums[0];
    force[j[1] - first] = sums[1];
}

/// `sums[s] -= g_e` for the pairs `e` of `lists[s]` in order, the two lists side by side.
#[inline(always)]
fn subtract_pairs(sums: &mut [Vec3; 2], lists: [&[u32]; 2], kept: Kept<'_>) {
    let pair = |e: u32| &kept.pairs[e as usize];
    let common = lists[0].len().min(lists[1].len());
    let (head0, tail0) = lists[0].split_at(common);
    let (head1, tail1) = lists[1].split_at(common);
    for (&e0, &e1) in head0.iter().zip(head1) {
        sums[0] -= pair(e0);
        sums[1] -= pair(e1);
    }
    for &e in tail0 {
        sums[0] -= pair(e);
    }
    for &e in tail1 {
        sums[1] -= pair(e);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kernels::math::Real;
    use crate::kernels::neighbours::{build, SupportRadius};

    /// Shares of a lattice body, each handing on its particles' results in order: the forces
    /// after the barrier are exactly the bits of the one-thread scatter, in three shares (with
    /// particles that cross shares and particles that do not in each) and in one (where nothing
    /// is kept: what was not written stays NaN, and a sum that read it would be NaN).
    #[test]
    fn shares_give_the_scatter_bits() {
        let side = 8;
        let mut rest = Vec::new();
        for k in 0..side * side * side {
            let s = k as Real;
            let jitter = Vec3::new((s * 0.7).sin(), (s * 1.3).cos(), (s * 2.1).sin());
            let cell = Vec3::new(
                (k % side) as Real,
                (k / side % side) as Real,
                (k / 64) as Real,
            );
            rest.push(cell + 0.1 * jitter);
        }
        let n = rest.len();
        let nbr = build(&rest, SupportRadius::Automatic { target: 13 }).unwrap();
        // Values over many magnitudes, so that any change of the order of a sum shows.
        let value = |k: usize, salt: Real| {
            let s = k as Real + salt;
            Vec3::new(s.sin(), (1.7 * s).cos(), (0.3 * s).sin()) * (10.0 as Real).powi(k as i32 % 9)
        };
        let pairs: Vec<Vec3> = (0..nbr.slot_count()).map(|e| value(e, 0.5)).collect();
        let own: Vec<Vec3> = (0..n).map(|i| value(i, 0.25)).collect();
        let external: Vec<Vec3> = (0..n).map(|j| value(j, 0.75)).collect();
        let mut expected = external.clone();
        for i in 0..n {
            for e in nbr.range(i) {
                expected[nbr.index[e] as usize] -= pairs[e];
            }
            expected[i] += own[i];
        }
        let nan = Vec3::repeat(Real::NAN);
        let run = |shares: &[Range<usize>]| {
            let mut force = external.clone();
            let mut kept_pairs = vec![nan; nbr.slot_count()];
            let mut kept_own = vec![nan; n];
            // Shares are independent until the barrier: one after the other here.
            for share in shares {
                let slots = nbr.offsets[share.start] as usize..nbr.offsets[share.end] as usize;
                let mut out = ShareForces {
                    nbr: &nbr,
                    share: share.clone(),
                    force: &mut force[share.clone()],
                    pair_force: &mut kept_pairs[slots],
                    own: &mut kept_own[share.clone()],
                };
                for i in share.clone() {
                    out.distribute(i, &pairs[nbr.slots(i)], own[i]);
                }
            }
            let kept = Kept {
                pairs: &kept_pairs,
                own: &kept_own,
            };
            for share in shares {
                sum_after_barrier(&nbr, share.clone(), &mut force[share.clone()], kept);
            }
            for j in 0..n {
                assert_eq!(force[j], expected[j], "particle {j}, shares {shares:?}");
            }
            let crossing = shares
                .iter()
                .map(|share| share.clone().filter(|&j| crosses(&nbr, j, share)).count())
                .collect::<Vec<_>>();
            let untouched = kept_pairs.iter().chain(&kept_own).all(|g| g.x.is_nan());
            (crossing, untouched)
        };
        // Row-major lattice order: a particle's neighbours lie up to a layer (64 particles)
        // and a row (8) on either side, so the particles near a share's ends cross.
        let shares = [0..170, 170..341, 341..n];
        let (crossing, untouched) = run(&shares);
        for (share, &count) in shares.iter().zip(&crossing) {
            assert!(
                count > 10 && count + 10 < share.len(),
                "{crossing:?} of {shares:?} cross"
            );
        }
        assert!(!untouched);
        let whole = 0..n;
        assert_eq!(run(std::slice::from_ref(&whole)), (vec![0], true));
    }
}
