//! Pass B of the force pass on several threads: each particle `j` sums the forces of the pairs
//! that concern it, `−g_ij` of every pair `(i, j)` and its own `Σ_k g_jk`, in exactly the order
//! of the one-thread scatter (pairs from particles before `j`, its own sum, pairs from
//! particles after `j`), so that the result is bit-identical for any number of threads.
//!
//! The sums trail pass A within each share. Read back after the whole of pass A, the pair
//! forces (24 bytes each, ~20 a particle, scattered over the arrays) came from the last-level
//! cache or from memory: on liver_31k that took 2.0 ms of a 7.7 ms step, 5× liver_4k's cost
//! per particle. Now a share sums particle `j` as soon as its own pass A has done every
//! particle `j` reads ([`Neighbourhoods::sources`]), while their forces are still in the
//! core's cache. A particle that reads a particle of another share, or one more than
//! [`TRAIL_WINDOW`] ahead of it, is summed after a barrier that every share's pass A reaches:
//! waiting for it would hold back the particles behind it.

use crate::math::Vec3;
use crate::neighbours::Neighbourhoods;
use std::ops::Range;

/// How far ahead of a particle (in particle order) its last source may be for the particle to
/// be summed while pass A goes on. The particles behind it wait that long while pass A moves
/// ~1.7 kB a particle (rest data read, pair forces written): 2048 particles are ~3.5 MB, a
/// ninth of the reference machine's 32 MB last-level cache, so what the waiting particles
/// read is still there. (A core's 1 MB L2 cannot hold the window in any case: a particle's
/// first source is often hundreds of particles behind it along the Morton curve.)
pub(crate) const TRAIL_WINDOW: usize = 2048;

/// Whether particle `j` of the share of particles `share` is summed after the barrier: it
/// reads a particle of another share, or one more than `window` ahead (in production
/// [`TRAIL_WINDOW`]).
#[inline]
fn after_barrier(nbr: &Neighbourhoods, j: usize, share: &Range<usize>, window: usize) -> bool {
    let [first, last] = nbr.sources[j].map(|k| k as usize);
    first < share.start || last >= share.end || last >= j + window
}

/// The pair forces and own sums (N) of pass A that a sum reads: pair `e`'s force is
/// `pairs[e - pair_base]`, particle `i`'s own sum `own[i - own_base]`.
#[derive(Clone, Copy)]
pub(crate) struct PassA<'a> {
    pub(crate) pairs: &'a [Vec3],
    pub(crate) pair_base: usize,
    pub(crate) own: &'a [Vec3],
    pub(crate) own_base: usize,
}

/// The sums of one share's particles that trail its pass A.
pub(crate) struct TrailingSums<'a> {
    nbr: &'a Neighbourhoods,
    share: Range<usize>,
    window: usize,
    /// The next particle to look at.
    next: usize,
    /// A ready particle held back to be summed beside the next one.
    held: Option<usize>,
    /// The share's forces (N), particle `j` at `j - share.start`: on entry what else acts on
    /// the particles.
    force: &'a mut [Vec3],
}

impl<'a> TrailingSums<'a> {
    /// The trailing sums of the particles `share`, added to `force` (theirs, N), leaving to
    /// the barrier the particles whose last source is `window` or more ahead.
    pub(crate) fn new(
        nbr: &'a Neighbourhoods,
        share: Range<usize>,
        window: usize,
        force: &'a mut [Vec3],
    ) -> Self {
        assert_eq!(force.len(), share.len());
        TrailingSums {
            nbr,
            next: share.start,
            share,
            window,
            held: None,
            force,
        }
    }

    /// Sum every particle not yet summed, not left for the barrier, whose sources are all
    /// before `done`, now that the share's pass A has done the particles before `done`, in
    /// `pass_a` (the share's pair slots and own sums). At `done` = the share's end, every
    /// particle not left for the barrier is summed.
    #[inline]
    pub(crate) fn advance(&mut self, done: usize, pass_a: PassA<'_>) {
        let nbr = self.nbr;
        while self.next < self.share.end {
            let j = self.next;
            if !after_barrier(nbr, j, &self.share, self.window) {
                if nbr.sources[j][1] as usize >= done {
                    break;
                }
                match self.held.take() {
                    None => self.held = Some(j),
                    Some(i) => sum_two(nbr, [i, j], pass_a, self.force, self.share.start),
                }
            }
            self.next += 1;
        }
        if done >= self.share.end {
            if let Some(i) = self.held.take() {
                sum_two(nbr, [i, i], pass_a, self.force, self.share.start);
            }
        }
    }
}

/// After the barrier: the sums of the particles of `share` left for it (`window` as in
/// [`TrailingSums::new`]), added to `force` (theirs, N), reading every share's pass A in
/// `pass_a`.
pub(crate) fn sum_after_barrier(
    nbr: &Neighbourhoods,
    share: Range<usize>,
    window: usize,
    force: &mut [Vec3],
    pass_a: PassA<'_>,
) {
    let mut held = None;
    for j in share
        .clone()
        .filter(|&j| after_barrier(nbr, j, &share, window))
    {
        match held.take() {
            None => held = Some(j),
            Some(i) => sum_two(nbr, [i, j], pass_a, force, share.start),
        }
    }
    if let Some(i) = held {
        sum_two(nbr, [i, i], pass_a, force, share.start);
    }
}

/// The sums of particles `j` (two; the same twice for one), added to `force[j - first]` (N).
/// Each sum is a chain of dependent additions; two side by side keep the adder busy, each in
/// its own order.
#[inline(always)]
fn sum_two(
    nbr: &Neighbourhoods,
    j: [usize; 2],
    pass_a: PassA<'_>,
    force: &mut [Vec3],
    first: usize,
) {
    let split = |j: usize| {
        // Pairs of particles before j have indices below offsets[j].
        let incoming = nbr.incoming(j);
        incoming.split_at(incoming.partition_point(|&e| e < nbr.offsets[j]))
    };
    let [(before0, after0), (before1, after1)] = j.map(split);
    let mut sums = j.map(|j| force[j - first]);
    subtract_pairs(&mut sums, [before0, before1], pass_a);
    sums[0] += pass_a.own[j[0] - pass_a.own_base];
    sums[1] += pass_a.own[j[1] - pass_a.own_base];
    subtract_pairs(&mut sums, [after0, after1], pass_a);
    force[j[0] - first] = sums[0];
    force[j[1] - first] = sums[1];
}

/// `sums[s] -= g_e` for the pairs `e` of `lists[s]` in order, the two lists side by side.
#[inline(always)]
fn subtract_pairs(sums: &mut [Vec3; 2], lists: [&[u32]; 2], pass_a: PassA<'_>) {
    let pair = |e: u32| &pass_a.pairs[e as usize - pass_a.pair_base];
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
    use crate::math::Real;
    use crate::neighbours::{build, SupportRadius};

    /// Three shares of a lattice body, pass A's results revealed four particles at a time: the
    /// trailing sums and those after the barrier give exactly the bits of the one-thread
    /// scatter, and never read a result before pass A has written it (unwritten ones are NaN).
    #[test]
    fn trailing_and_barrier_sums_give_the_scatter_bits() {
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
        // Row-major lattice order: a particle's neighbours lie up to a layer (64) and a row
        // (8) on either side, so this window leaves some particles to the barrier.
        let window = 64;
        let shares = [0..170, 170..341, 341..n];
        let mut force = external.clone();
        let (mut trailing, mut by_window) = (0, 0);
        for share in shares.clone() {
            let slots = nbr.offsets[share.start] as usize..nbr.offsets[share.end] as usize;
            let mut written_pairs = vec![Vec3::repeat(Real::NAN); slots.len()];
            let mut written_own = vec![Vec3::repeat(Real::NAN); share.len()];
            let mut sums =
                TrailingSums::new(&nbr, share.clone(), window, &mut force[share.clone()]);
            for first in share.clone().step_by(4) {
                let done = (first + 4).min(share.end);
                for i in first..done {
                    written_own[i - share.start] = own[i];
                    for e in nbr.slots(i) {
                        written_pairs[e - slots.start] = pairs[e];
                    }
                }
                let pass_a = PassA {
                    pairs: &written_pairs,
                    pair_base: slots.start,
                    own: &written_own,
                    own_base: share.start,
                };
                sums.advance(done, pass_a);
            }
            for j in share.clone() {
                let [first, last] = nbr.sources[j].map(|k| k as usize);
                let inside = first >= share.start && last < share.end;
                trailing += usize::from(!after_barrier(&nbr, j, &share, window));
                by_window += usize::from(inside && last >= j + window);
            }
        }
        let pass_a = PassA {
            pairs: &pairs,
            pair_base: 0,
            own: &own,
            own_base: 0,
        };
        for share in shares {
            let mine = &mut force[share.clone()];
            sum_after_barrier(&nbr, share, window, mine, pass_a);
        }
        assert!(
            trailing > 20 && by_window > 20,
            "{trailing} trailing, {by_window} by the window"
        );
        assert!(trailing + by_window < n, "no particle of another share's");
        for j in 0..n {
            assert_eq!(force[j], expected[j], "particle {j}");
        }
    }
}
