//! The surface self-contact's candidate pairs, kept from pass to pass while the surface moves
//! little: where the surface is far from itself and still, the broad phase then costs a scan
//! of how far it moved.
//!
//! A pass needs the pairs of a boundary vertex `i` and a boundary triangle `t` of one body
//! whose boxes meet and whose normals face each other (the *live* pairs):
//! - the box of `i`'s motion over the substep (start `x`, predicted `p`) meets the box of
//!   `t`'s corners at both, grown by the skin `s`;
//! - the unit normals face each other: `n_i · n_t < 0`.
//!
//! A *build* finds, with the [`SurfaceTree`], every pair (`i` not a corner of `t`) that meets
//! looser conditions: the triangle's box grown by a further margin `m`, and `n_i · n_t < sin 2θ`
//! (normals more than 90° − 2θ apart). It remembers the positions and normals it saw (the
//! *anchors*). While the displacements since then of every boundary vertex's `x` and `p`
//! spread by at most `m` in each coordinate (take away their midpoint, a translation that
//! moves no box against another: each box then grows by at most `m/2` a side) and no unit
//! normal turned by more than `θ` (an angle between two normals then shrank by at most `2θ`),
//! every live pair is among the built ones. So a pass checks that (a scan of the boundary),
//! builds again when it does not hold, and filters the built pairs by the live conditions, in
//! the order of their (vertex, triangle) indices. On several threads a build splits the tree's
//! traversal into node pairs dealt round the threads ([`TreeFit::seeds`]); sorted, its pairs do
//! not depend on the split.
//!
//! The live pairs and their order do not depend on when the last build was: the same bits as
//! building every pass, whatever happened since (a restored state, a pose set, a thread count).
//! Only a change of the boundary's triangles (a cut) must [`SurfacePairs::forget`] them.

use crate::kernels::collision::aabb::{grow, inflated, merge, overlap, Aabb, EMPTY_BOX};
use crate::kernels::collision::surface_tree::{SurfaceTree, TreeFit};
use crate::kernels::math::{Real, Vec3};
use crate::kernels::parallel::{Pool, SharedSlice};

/// The margin `m` of a build, in contact skins (dimensionless): how far apart the surface's
/// displacements may spread before the next build. A larger margin keeps more pairs and makes
/// each build dearer, a smaller one builds more often (docs/PERFORMANCE.md: a cost setting; the
/// results do not depend on it).
const REUSE_MARGIN: Real = 1.0;

/// The angle `θ` each unit normal may turn before the next build (radians, 5°); a cost
/// setting as [`REUSE_MARGIN`] is.
const REUSE_TURN: Real = std::f64::consts::PI / 36.0;

/// Seeds of the traversal a build deals to each thread on several (dimensionless): enough to
/// even out the shares' work.
const SEEDS_PER_THREAD: usize = 8;

/// Kept pairs a build reserves room for, per boundary vertex (dimensionless): more are taken
/// when a fold needs them (an allocation in that step, kept for the next).
const RESERVED_PER_VERTEX: usize = 8;

/// What a build is: see the module documentation.
#[derive(Debug, Clone, Default, PartialEq)]
pub(crate) struct SurfacePairs {
    /// The built pairs (vertex: a particle index, triangle: an index of the boundary), sorted.
    built: Vec<(u32, u32)>,
    /// The live pairs of the last pass, in the same order.
    live: Vec<(u32, u32)>,
    /// Per thread of a build on several, the pairs its share of the traversal found.
    shares: Vec<Vec<(u32, u32)>>,
    /// Per thread, what its share of a pass's scan found: the box of the displacements since
    /// the build (m), and whether a normal turned too far.
    scans: Vec<(Aabb, bool)>,
    /// Per particle, its positions at the substep's start and predicted at the build (m), and
    /// its unit normal then (written for boundary vertices only).
    anchor_x: Vec<Vec3>,
    anchor_p: Vec<Vec3>,
    anchor_vertex_normal: Vec<Vec3>,
    /// Per boundary triangle, its unit normal at the build.
    anchor_normal: Vec<Vec3>,
    /// Whether `built` belongs to the current boundary.
    valid: bool,
    /// Builds so far (dimensionless; the tests' count).
    builds: u64,
}

/// The positions and normals of a pass: per particle its positions `x` at the substep's start
/// and `p` predicted (m) and its unit normal (zero where it faces nothing), per boundary
/// triangle its unit normal (zero for a degenerate one).
pub(crate) struct SurfaceMotion<'a> {
    pub(crate) x: &'a [Vec3],
    pub(crate) p: &'a [Vec3],
    pub(crate) vertex_normal: &'a [Vec3],
    pub(crate) normal: &'a [Vec3],
}

impl SurfacePairs {
    /// Make room for a body of `particles` particles, `vertices` boundary vertices and
    /// `triangles` boundary triangles, built on `threads` threads (allocates only when it holds
    /// fewer).
    pub(crate) fn reserve(
        &mut self,
        (particles, vertices, triangles): (usize, usize, usize),
        threads: usize,
    ) {
        for anchor in [
            &mut self.anchor_x,
            &mut self.anchor_p,
            &mut self.anchor_vertex_normal,
        ] {
            if anchor.len() < particles {
                anchor.resize(particles, Vec3::zeros());
            }
        }
        if self.anchor_normal.len() < triangles {
            self.anchor_normal.resize(triangles, Vec3::zeros());
        }
        let pairs = RESERVED_PER_VERTEX * vertices;
        if threads > 1 && self.shares.len() < threads {
            self.shares.resize(threads, Vec::new());
        }
        if self.scans.len() < threads {
            self.scans.resize(threads, (EMPTY_BOX, false));
        }
        // A share's list: twice an even share of the pairs.
        let share = match threads {
            1 => 0,
            _ => 2 * pairs / threads,
        };
        let lists = [&mut self.built, &mut self.live].into_iter();
        for (list, room) in lists
            .map(|l| (l, pairs))
            .chain(self.shares.iter_mut().map(|l| (l, share)))
        {
            list.reserve(room.saturating_sub(list.len()));
        }
    }

    /// Drop the built pairs: the boundary's triangles changed, to the `sizes` of
    /// [`SurfacePairs::reserve`]. When the pairs were in use, make room for those (so that the
    /// next pass allocates nothing).
    pub(crate) fn forget(&mut self, sizes: (usize, usize, usize)) {
        self.valid = false;
        if !self.anchor_x.is_empty() {
            self.reserve(sizes, self.shares.len().max(1));
        }
    }

    /// Builds so far.
    #[cfg(test)]
    fn builds(&self) -> u64 {
        self.builds
    }

    /// The live pairs of a pass over the boundary triangles `boundary` (corner particle
    /// indices) and the boundary vertices `vertices` of the body of `tree`, at `motion`, with
    /// the contact skin `skin` (m) (see the module documentation). Builds with `fit` when the
    /// surface moved or turned too far since the last build, on the threads of `pool`. Needs
    /// [`SurfacePairs::reserve`] for the body and the pool and [`TreeFit::reserve`] for `tree`.
    pub(crate) fn live(
        &mut self,
        (tree, fit, pool): (&SurfaceTree, &mut TreeFit, &Pool),
        (boundary, vertices): (&[[u32; 3]], &[u32]),
        motion: &SurfaceMotion,
        skin: Real,
    ) -> &[(u32, u32)] {
        let margin = REUSE_MARGIN * skin;
        if !self.valid || self.moved((boundary, vertices), motion, margin, pool) {
            let reach = skin + margin;
            self.build((tree, fit, pool), (boundary, vertices), motion, reach);
        }
        self.live.clear();
        for &(i, t) in &self.built {
            let (k, u) = (i as usize, t as usize);
            if motion.vertex_normal[k].dot(&motion.normal[u]) < 0.0
                && overlap(
                    &motion_box(motion, k),
                    &triangle_box(motion, boundary[u], skin),
                )
            {
                self.live.push((i, t));
            }
        }
        &self.live
    }

    /// Whether the boundary's positions moved apart by more than (nearly) `margin` in a
    /// coordinate since the build (the spread of the displacements of every boundary vertex's
    /// `x` and `p`: a common translation moves no box against another), or a unit normal
    /// turned by more than [`REUSE_TURN`]: a normal that was zero and is not counts as turned,
    /// one that is zero now faces nothing. Scanned in ranges on the threads of `pool`.
    fn moved(
        &mut self,
        (boundary, vertices): (&[[u32; 3]], &[u32]),
        motion: &SurfaceMotion,
        margin: Real,
        pool: &Pool,
    ) -> bool {
        let least_cos = REUSE_TURN.cos();
        let turned = |now: &Vec3, then: &Vec3| *now != Vec3::zeros() && now.dot(then) < least_cos;
        let threads = pool.threads();
        let scans = SharedSlice::new(&mut self.scans[..threads]);
        let this = &*self;
        pool.run(&|share| {
            // SAFETY: each share writes its own entry.
            let scan = unsafe { scans.element(share) };
            *scan = (EMPTY_BOX, true);
            let mut spread = EMPTY_BOX;
            for &k in &vertices[pool.share(share, vertices.len())] {
                let k = k as usize;
                grow(&mut spread, &(motion.x[k] - this.anchor_x[k]));
                grow(&mut spread, &(motion.p[k] - this.anchor_p[k]));
                if turned(&motion.vertex_normal[k], &this.anchor_vertex_normal[k]) {
                    return;
                }
            }
            let triangles = pool.share(share, boundary.len());
            let normals = motion.normal[triangles.clone()].iter();
            if !normals
                .zip(&this.anchor_normal[triangles])
                .any(|(now, then)| turned(now, then))
            {
                *scan = (spread, false);
            }
        });
        let (spread, any_turned) = (self.scans[..threads].iter())
            .fold((EMPTY_BOX, false), |(b, t), (share, turned)| {
                (merge(&b, share), t || *turned)
            });
        // Under the margin by far more than rounding.
        any_turned || (spread.1 - spread.0).amax() > 0.998 * margin
    }

    /// Build the pairs within `reach` (m: the skin and the margin) whose normals are more than
    /// `90° − 2θ` apart, sorted, and anchor them at `motion`.
    fn build(
        &mut self,
        (tree, fit, pool): (&SurfaceTree, &mut TreeFit, &Pool),
        (boundary, vertices): (&[[u32; 3]], &[u32]),
        motion: &SurfaceMotion,
        reach: Real,
    ) {
        let turn = 2.0 * REUSE_TURN;
        let (x, p) = (motion.x, motion.p);
        let normals = (motion.normal, motion.vertex_normal);
        fit.refit(
            tree,
            boundary,
            (x, p),
            normals,
            reach,
            (turn.cos(), turn.sin()),
            pool,
        );
        // Above sin 2θ by far more than rounding.
        let facing = turn.sin() + 1.0e-9;
        let kept = |i: usize, t: usize| {
            let corners = boundary[t];
            !corners.contains(&(i as u32))
                && motion.vertex_normal[i].dot(&motion.normal[t]) < facing
                && overlap(
                    &motion_box(motion, i),
                    &triangle_box(motion, corners, reach),
                )
        };
        let built = &mut self.built;
        built.clear();
        let threads = pool.threads();
        let fit = &*fit;
        if threads == 1 {
            fit.for_each_candidate(tree, (0, 0), motion.vertex_normal, |i, t| {
                if kept(i, t) {
                    built.push((i as u32, t as u32));
                }
            });
        } else {
            // The traversal split into seeds dealt round the threads, each into its own list;
            // sorted below, the pairs do not depend on the split.
            let (seeds, count) = fit.seeds(tree, SEEDS_PER_THREAD * threads);
            let lists = SharedSlice::new(&mut self.shares[..threads]);
            pool.run(&|share| {
                // SAFETY: each share writes its own list.
                let list = unsafe { lists.element(share) };
                list.clear();
                for &seed in seeds[..count].iter().skip(share).step_by(threads) {
                    fit.for_each_candidate(tree, seed, motion.vertex_normal, |i, t| {
                        if kept(i, t) {
                            list.push((i as u32, t as u32));
                        }
                    });
                }
            });
            for list in &self.shares[..threads] {
                built.extend_from_slice(list);
            }
        }
        built.sort_unstable();
        for &k in vertices {
            let k = k as usize;
            self.anchor_x[k] = x[k];
            self.anchor_p[k] = p[k];
            self.anchor_vertex_normal[k] = motion.vertex_normal[k];
        }
        let triangles = boundary.len();
        self.anchor_normal[..triangles].copy_from_slice(&motion.normal[..triangles]);
        self.valid = true;
        self.builds += 1;
    }
}

/// The box of particle `k`'s motion over the substep (m).
fn motion_box(motion: &SurfaceMotion, k: usize) -> Aabb {
    crate::kernels::collision::aabb::motion(&motion.x[k], &motion.p[k])
}

/// The box of the triangle `corners`' motion over the substep, grown by `by` (m).
fn triangle_box(m: &SurfaceMotion, corners: [u32; 3], by: Real) -> Aabb {
    let moved = (corners.iter()).fold(EMPTY_BOX, |b, &k| merge(&b, &motion_box(m, k as usize)));
    inflated(&moved, by)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kernels::collision::surface_tree::tests::{sphere, unit_normals};
    use crate::kernels::math::uniform;

    /// Skin of the tests' surfaces (m).
    const SKIN: Real = 0.02;

    /// Follow the surface `boundary` through the positions `frames` (one a pass; a pass's
    /// start is the frame before), asserting that the pairs kept from build to build (on one
    /// thread) are those of a build every pass (on two), in the same order. Returns per pass whether it built and how many
    /// pairs were live.
    fn follow(boundary: &[[u32; 3]], frames: &[Vec<Vec3>]) -> Vec<(bool, usize)> {
        let n = frames[0].len();
        let vertices: Vec<u32> = (0..n as u32).collect();
        let tree = SurfaceTree::new(&frames[0], boundary);
        let mut fits = [TreeFit::default(), TreeFit::default()];
        fits.iter_mut().for_each(|f| f.reserve(&tree, n));
        let mut kept = SurfacePairs::default();
        kept.reserve((n, n, boundary.len()), 1);
        // Built every pass on two threads, kept on one.
        let (one, two) = (Pool::new(1), Pool::new(2));
        let mut passes = Vec::new();
        for (pass, pair) in frames.windows(2).enumerate() {
            let (x, p) = (&pair[0], &pair[1]);
            let (normal, vertex_normal) = unit_normals(p, boundary);
            let motion = SurfaceMotion {
                x,
                p,
                vertex_normal: &vertex_normal,
                normal: &normal,
            };
            let [a, b] = &mut fits;
            let builds = kept.builds();
            let reused = kept.live((&tree, a, &one), (boundary, &vertices), &motion, SKIN);
            let reused = reused.to_vec();
            let mut fresh = SurfacePairs::default();
            fresh.reserve((n, n, boundary.len()), 2);
            let built = fresh.live((&tree, b, &two), (boundary, &vertices), &motion, SKIN);
            assert!(reused == *built, "pass {pass}: the kept pairs differ");
            passes.push((kept.builds() > builds, reused.len()));
        }
        passes
    }

    /// A sphere squashed until its caps face each other within the skin, held there with a
    /// jitter, moved whole and turned over: a held surface is not built again.
    #[test]
    fn a_squashed_sphere_keeps_its_pairs_while_held() {
        let (rest, boundary) = sphere(24, 40);
        let mut random = uniform(3);
        let frames: Vec<Vec<Vec3>> = (0..500)
            .map(|pass| {
                // Squashed from 1 to 0.005 over 300 passes, held 100, moved by 1 m, turned 90°.
                let squash = 1.0 - 0.995 * (pass.min(300) as Real / 300.0);
                let shift = if pass >= 400 {
                    Vec3::x()
                } else {
                    Vec3::zeros()
                };
                let mut jitter = || Vec3::new(random(), random(), random()) * 1.0e-5;
                (rest.iter())
                    .map(|r| {
                        let q = Vec3::new(r.x, r.y, r.z * squash) + jitter() + shift;
                        match pass >= 450 {
                            true => Vec3::new(q.x, -q.z, q.y),
                            false => q,
                        }
                    })
                    .collect()
            })
            .collect();
        let passes = follow(&boundary, &frames);
        let held = &passes[301..399];
        let builds = held.iter().filter(|(built, _)| *built).count();
        assert!(builds == 0, "{builds} builds of a held surface");
        let live: usize = held.iter().map(|(_, live)| live).sum();
        assert!(live > 10_000, "{live} live pairs held: no teeth");
    }

    /// A square plate of side `side` (m) centred on `centre`, turned by `tilt` (radians) about
    /// the x axis from facing +z, in a grid of `cells` × `cells` squares: its positions and its
    /// triangles (corner indices from `first`).
    fn plate(
        side: Real,
        cells: usize,
        centre: Vec3,
        tilt: Real,
        first: u32,
    ) -> (Vec<Vec3>, Vec<[u32; 3]>) {
        let (sin, cos) = tilt.sin_cos();
        let at = |i: usize, j: usize| first + (i * (cells + 1) + j) as u32;
        let mut points = Vec::new();
        for i in 0..=cells {
            for j in 0..=cells {
                let (u, v) = (
                    side * (i as Real / cells as Real - 0.5),
                    side * (j as Real / cells as Real - 0.5),
                );
                points.push(centre + Vec3::new(u, v * cos, v * sin));
            }
        }
        let mut triangles = Vec::new();
        for i in 0..cells {
            for j in 0..cells {
                triangles.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
                triangles.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
            }
        }
        (points, triangles)
    }

    /// A small plate over a large one, moved a step a pass: the pairs that come within the skin
    /// (or turn to face each other) after a build are found, the build's margins kept.
    #[test]
    fn plates_coming_together_or_turning_to_face_are_found() {
        // Facing each other (the small plate turned over), from 3 skins apart down to 0.3.
        let floor = plate(1.0, 4, Vec3::new(0.5, 0.5, 0.0), 0.0, 0);
        let first = floor.0.len() as u32;
        let boundary = [floor.1.clone(), plate(0.05, 1, Vec3::zeros(), 0.0, first).1].concat();
        let at = |height: Real, tilt: Real| {
            let top = plate(0.05, 1, Vec3::new(0.5, 0.5, height), tilt, first).0;
            [floor.0.clone(), top].concat()
        };
        let pi = std::f64::consts::PI;
        let descent: Vec<_> = (0..=90)
            .map(|k| at(SKIN * (3.0 - 0.03 * k as Real), pi))
            .collect();
        let passes = follow(&boundary, &descent);
        assert!(
            passes.iter().any(|(_, live)| *live > 0),
            "no pair came within the skin"
        );
        // Half a skin apart, turned from 75° to 105° from facing +z, a degree a pass.
        let turning: Vec<_> = (0..=30)
            .map(|k| at(0.5 * SKIN, (75.0 + k as Real).to_radians()))
            .collect();
        let passes = follow(&boundary, &turning);
        assert!(
            passes.iter().any(|(_, live)| *live > 0),
            "no pair turned to face"
        );
    }
}
