//! A bounding-volume hierarchy over a body's boundary triangles, the broad phase of the surface
//! self-contact: which boundary vertices can touch which boundary triangles of the same body.
//!
//! The tree's shape is made once from the rest positions ([`SurfaceTree::new`]: the triangles
//! split at the median of their rest centroids along the longest side of their box, down to
//! leaves of at most [`LEAF_TRIANGLES`]) and kept until the boundary changes (a cut). Every
//! boundary vertex belongs to one leaf, the first (in the tree's order) with a triangle at it,
//! so that a subtree holds a run of the triangles and a run of the vertices. The tree also
//! lists the triangles around each vertex, so that a vertex's normal can be gathered on any
//! thread.
//!
//! A build of the pairs refits it ([`TreeFit::refit`], subtrees on several threads): per node
//! the box of its triangles' corners at the start of the substep and at the predicted positions,
//! grown by the reach (the contact skin and a margin), the box
//! of its vertices at both, and the cones of its triangles' unit normals and of its vertices'
//! unit normals (an axis and a half-angle). A vertex and a triangle can only be in contact when
//! the vertex's box meets the triangle's grown box (it is within the skin of the triangle, or
//! crossed it, somewhere between the two positions) and their normals face each other (more
//! than 90° apart). So a pair of subtrees is skipped when the boxes miss each other, or when
//! the angle between the cones' axes plus both half-angles is under 90° (no vertex normal of one
//! faces any triangle normal of the other); a subtree is skipped against itself by the same
//! cone test (a patch of surface that turns by less than 45° everywhere cannot touch itself).
//! Where the surface is far from itself and smooth, that leaves a refit and a few node tests.
//!
//! [`TreeFit::for_each_candidate`] visits the pairs the tests leave below a node pair, leaf by
//! leaf, in an order fixed by the tree and the positions; [`TreeFit::seeds`] splits the whole
//! traversal into node pairs whose traversals together visit each pair once, for several
//! threads.

use crate::kernels::collision::aabb::{grow, inflated, merge, motion, overlap, Aabb, EMPTY_BOX};
use crate::kernels::incidence::corners_around;
use crate::kernels::math::{Real, Vec3};
use crate::kernels::parallel::{Pool, SharedSlice};

/// Most triangles in a leaf (dimensionless). Smaller leaves hold tighter cones (fewer pairs
/// tested exactly) but make more nodes to refit and visit: on the haptic liver_4k, leaves of
/// 8 make the self-contact pass 7–10% cheaper than leaves of 4 (16: the same as 8), with the
/// same pairs (docs/PERFORMANCE.md, "Surface self-contact").
pub(crate) const LEAF_TRIANGLES: usize = 8;

/// Most node pairs [`TreeFit::seeds`] returns (dimensionless).
pub(crate) const MAX_SEEDS: usize = 64;

/// Least cosine (dimensionless) of the widest angle between a vertex normal and a triangle
/// normal for a pair of nodes to be skipped: far above rounding, so that every skipped pair has
/// a positive dot product of normals, as the exact test computes it.
const FACING_MARGIN: Real = 1.0e-9;

/// A node: a run `tris` of the tree's triangle order and a run `verts` of its vertex order; an
/// inner node's left child is the next node.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Node {
    tris: (u32, u32),
    verts: (u32, u32),
    /// The right child (an index of the node array), or [`Node::LEAF`].
    right: u32,
}

impl Node {
    const LEAF: u32 = u32::MAX;

    fn is_leaf(&self) -> bool {
        self.right == Node::LEAF
    }

    fn size(&self) -> u32 {
        self.tris.1 - self.tris.0
    }
}

/// A cone of unit vectors: those within the half-angle `θ` (`cos θ`, `sin θ`) of `axis`.
/// [`Cone::EMPTY`] holds none, a cosine of −1 all.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Cone {
    axis: Vec3,
    cos: Real,
    sin: Real,
}

impl Cone {
    const EMPTY: Cone = Cone {
        axis: Vec3::new(0.0, 0.0, 0.0),
        cos: Real::INFINITY,
        sin: 0.0,
    };
    const FULL: Cone = Cone {
        axis: Vec3::new(0.0, 0.0, 1.0),
        cos: -1.0,
        sin: 0.0,
    };

    /// The cone of the one unit vector `u`, or [`Cone::EMPTY`] for a zero vector.
    fn unit(u: Vec3) -> Cone {
        if u == Vec3::zeros() {
            return Cone::EMPTY;
        }
        Cone {
            axis: u,
            cos: 1.0,
            sin: 0.0,
        }
    }

    fn is_empty(&self) -> bool {
        self.cos == Real::INFINITY
    }

    /// The cone of the unit vectors `units` (zero vectors left out).
    fn of(units: impl Iterator<Item = Vec3> + Clone) -> Cone {
        let nonzero = units.filter(|u| *u != Vec3::zeros());
        let Some(axis) = nonzero.clone().sum::<Vec3>().try_normalize(0.0) else {
            return match nonzero.clone().next() {
                Some(_) => Cone::FULL,
                None => Cone::EMPTY,
            };
        };
        let cos = nonzero.map(|u| axis.dot(&u)).fold(1.0, Real::min).max(-1.0);
        Cone {
            axis,
            cos,
            sin: (1.0 - cos * cos).max(0.0).sqrt(),
        }
    }

    /// The half-angle (as cosine and sine) about `axis` of a cone holding `self`, or `None` when
    /// it is 180° or more.
    fn about(&self, axis: &Vec3) -> Option<(Real, Real)> {
        let c = axis.dot(&self.axis).clamp(-1.0, 1.0);
        let s = (1.0 - c * c).max(0.0).sqrt();
        let sin = s * self.cos + c * self.sin;
        (sin >= 0.0 && self.cos > -1.0).then_some((c * self.cos - s * self.sin, sin))
    }

    /// This cone with its half-angle grown by the angle whose cosine and sine are `turn`
    /// (at most 90°): it holds every unit vector within that angle of one of its own.
    fn widened(&self, (cos, sin): (Real, Real)) -> Cone {
        if self.is_empty() || sin == 0.0 {
            return *self;
        }
        let grown = Cone {
            axis: self.axis,
            cos: self.cos * cos - self.sin * sin,
            sin: self.sin * cos + self.cos * sin,
        };
        // Past 180° the cone holds every vector.
        if grown.sin < 0.0 {
            Cone::FULL
        } else {
            grown
        }
    }

    /// A cone holding both.
    fn union(&self, other: &Cone) -> Cone {
        if self.is_empty() {
            return *other;
        }
        if other.is_empty() {
            return *self;
        }
        let Some(axis) = (self.axis + other.axis).try_normalize(0.0) else {
            return Cone::FULL;
        };
        match (self.about(&axis), other.about(&axis)) {
            (Some(a), Some(b)) => {
                let (cos, sin) = if a.0 <= b.0 { a } else { b };
                Cone { axis, cos, sin }
            }
            _ => Cone::FULL,
        }
    }

    /// Whether every vector of `self` is less than 90° (with [`FACING_MARGIN`]) from every
    /// vector of `other`: none faces another. True when either holds none.
    fn never_faces(&self, other: &Cone) -> bool {
        if self.is_empty() || other.is_empty() {
            return true;
        }
        // γ (the angle between the axes) + θ₁ + θ₂ under 90°: each half-angle and their sum
        // under 90°, and cos γ above cos(90° − θ₁ − θ₂) = sin(θ₁ + θ₂).
        let (c1, s1, c2, s2) = (self.cos, self.sin, other.cos, other.sin);
        c1 > 0.0
            && c2 > 0.0
            && c1 * c2 - s1 * s2 > 0.0
            && self.axis.dot(&other.axis) > s1 * c2 + c1 * s2 + FACING_MARGIN
    }
}

/// The tree's shape (see the module documentation), made from the rest positions.
#[derive(Debug, Clone, Default, PartialEq)]
pub(crate) struct SurfaceTree {
    /// Nodes in depth-first order (a node's left child is the next one), the root first.
    nodes: Vec<Node>,
    /// Boundary triangles (indices into the body's boundary) in the tree's order.
    triangles: Vec<u32>,
    /// Boundary vertices (particle indices) in the tree's order.
    vertices: Vec<u32>,
    /// The triangles around each of `vertices` (indices into the boundary, increasing):
    /// `around[around_offsets[j]..around_offsets[j + 1]]` for the `j`-th.
    around_offsets: Vec<u32>,
    around: Vec<u32>,
}

/// The boxes and cones of a [`SurfaceTree`]'s nodes at the last refit, one entry per node.
#[derive(Debug, Clone, Default)]
pub(crate) struct TreeFit {
    nodes: Vec<NodeFit>,
    /// Per particle, the box of its position at the substep's start and its predicted one (m;
    /// written for boundary vertices only).
    hull: Vec<Aabb>,
    /// The cosine and sine of the angle the vertices' cones are widened by at the last refit.
    turn: (Real, Real),
}

/// A node's boxes and cones at the last refit.
#[derive(Debug, Clone, Copy, PartialEq)]
struct NodeFit {
    /// Its triangles' corners' box grown by the reach, and its vertices' box (m).
    triangle_box: Aabb,
    vertex_box: Aabb,
    /// The cones of its triangles' and of its vertices' unit normals.
    triangle_cone: Cone,
    vertex_cone: Cone,
}

impl NodeFit {
    const EMPTY: NodeFit = NodeFit {
        triangle_box: EMPTY_BOX,
        vertex_box: EMPTY_BOX,
        triangle_cone: Cone::EMPTY,
        vertex_cone: Cone::EMPTY,
    };
}

/// Subtrees per thread a refit on several threads deals round them (dimensionless): enough to
/// even out the shares' work.
const SUBTREES_PER_THREAD: usize = 4;

/// Most subtrees a refit splits the tree into, and most nodes above them (dimensionless):
/// [`SurfaceTree::subtrees`] keeps their count under twice what it is asked for, plus one.
const MAX_SUBTREES: usize = 2 * MAX_SEEDS;

impl SurfaceTree {
    /// The tree over `boundary` (corner particle indices) at the rest positions `rest` (m).
    pub(crate) fn new(rest: &[Vec3], boundary: &[[u32; 3]]) -> SurfaceTree {
        let mut tree = SurfaceTree {
            triangles: (0..boundary.len() as u32).collect(),
            ..SurfaceTree::default()
        };
        if boundary.is_empty() {
            return tree;
        }
        let centroid = |t: u32| {
            let [a, b, c] = boundary[t as usize].map(|k| rest[k as usize]);
            (a + b + c) / 3.0
        };
        tree.split(0, boundary.len(), &centroid);
        // Vertices to the first leaf with a triangle at them, leaf by leaf in order.
        let mut taken = vec![false; rest.len()];
        for n in 0..tree.nodes.len() {
            let node = tree.nodes[n];
            if !node.is_leaf() {
                continue;
            }
            let start = tree.vertices.len() as u32;
            for &t in &tree.triangles[node.tris.0 as usize..node.tris.1 as usize] {
                for k in boundary[t as usize] {
                    if !std::mem::replace(&mut taken[k as usize], true) {
                        tree.vertices.push(k);
                    }
                }
            }
            tree.nodes[n].verts = (start, tree.vertices.len() as u32);
        }
        for n in (0..tree.nodes.len()).rev() {
            let node = tree.nodes[n];
            if !node.is_leaf() {
                let (left, right) = (tree.nodes[n + 1], tree.nodes[node.right as usize]);
                tree.nodes[n].verts = (left.verts.0, right.verts.1);
            }
        }
        let (offsets, slots) = corners_around(boundary, rest.len());
        tree.around_offsets.push(0);
        for &k in &tree.vertices {
            let mine = &slots[offsets[k as usize] as usize..offsets[k as usize + 1] as usize];
            tree.around.extend(mine.iter().map(|slot| slot / 3));
            tree.around_offsets.push(tree.around.len() as u32);
        }
        tree
    }

    /// The boundary vertices (particle indices) in the tree's order.
    pub(crate) fn vertices(&self) -> &[u32] {
        &self.vertices
    }

    /// The triangles (indices into the boundary) around the `j`-th of
    /// [`SurfaceTree::vertices`], in increasing order.
    pub(crate) fn triangles_around(&self, j: usize) -> &[u32] {
        &self.around[self.around_offsets[j] as usize..self.around_offsets[j + 1] as usize]
    }

    /// Make the subtree of the triangles `start..end` of the tree's order; returns its node.
    fn split(&mut self, start: usize, end: usize, centroid: &impl Fn(u32) -> Vec3) -> u32 {
        let n = self.nodes.len();
        self.nodes.push(Node {
            tris: (start as u32, end as u32),
            verts: (0, 0),
            right: Node::LEAF,
        });
        if end - start <= LEAF_TRIANGLES {
            return n as u32;
        }
        let mut bounds = EMPTY_BOX;
        for &t in &self.triangles[start..end] {
            grow(&mut bounds, &centroid(t));
        }
        let side = bounds.1 - bounds.0;
        let axis = (0..3).fold(0, |a, k| if side[k] > side[a] { k } else { a });
        let mid = (start + end) / 2;
        self.triangles[start..end].select_nth_unstable_by(mid - start, |&a, &b| {
            let (ca, cb) = (centroid(a)[axis], centroid(b)[axis]);
            ca.total_cmp(&cb).then(a.cmp(&b))
        });
        self.split(start, mid, centroid);
        let right = self.split(mid, end, centroid);
        self.nodes[n].right = right;
        n as u32
    }

    /// Bytes held on the heap.
    pub(crate) fn heap_bytes(&self) -> usize {
        use std::mem::size_of;
        self.nodes.capacity() * size_of::<Node>()
            + 4 * (self.triangles.capacity() + self.vertices.capacity())
            + 4 * (self.around_offsets.capacity() + self.around.capacity())
    }

    /// The node after the last of the subtree at `node` (depth-first order keeps a subtree's
    /// nodes together): past its rightmost leaf.
    fn subtree_end(&self, mut node: usize) -> usize {
        while !self.nodes[node].is_leaf() {
            node = self.nodes[node].right as usize;
        }
        node + 1
    }

    /// The tree cut for a refit on several threads: the largest subtrees that hold at most a
    /// `want`-th of the triangles (leaves where those are larger), at most [`MAX_SUBTREES`] for
    /// `want` up to half that, and the nodes above them, each list in the tree's order.
    fn subtrees(&self, want: usize) -> [([u32; MAX_SUBTREES], usize); 2] {
        let target = self
            .triangles
            .len()
            .div_ceil(want.clamp(1, MAX_SUBTREES / 2));
        let (mut roots, mut above) = (([0; MAX_SUBTREES], 0), ([0; MAX_SUBTREES], 0));
        // A subtree is split only when it holds more than `target`, into halves (median
        // splits) of more than half of it: so under `2 want` subtrees and fewer nodes above.
        // Pending nodes: one per level and the last split's two, under 32 + 2.
        let mut pending = [0u32; 34];
        let mut top = usize::from(!self.nodes.is_empty());
        while top > 0 {
            top -= 1;
            let n = pending[top];
            let node = self.nodes[n as usize];
            let list = if node.is_leaf() || node.size() as usize <= target {
                &mut roots
            } else {
                pending[top] = node.right;
                pending[top + 1] = n + 1;
                top += 2;
                &mut above
            };
            list.0[list.1] = n;
            list.1 += 1;
        }
        [roots, above]
    }
}

impl TreeFit {
    /// Make room for `tree`'s nodes and `particles` particles (allocates only when it holds
    /// fewer).
    pub(crate) fn reserve(&mut self, tree: &SurfaceTree, particles: usize) {
        if self.hull.len() < particles {
            self.hull.resize(particles, EMPTY_BOX);
        }
        if self.nodes.len() < tree.nodes.len() {
            self.nodes.resize(tree.nodes.len(), NodeFit::EMPTY);
        }
    }

    /// Refit the boxes and cones of `tree` (see the module documentation) to the positions `x`
    /// at the substep's start and `p` predicted (m), the triangles' unit normals `normal` (per
    /// boundary triangle, zero for a degenerate one) and the vertices' unit normals
    /// `vertex_normal` (per particle, zero for a vertex that faces nothing), the triangles'
    /// boxes grown by `reach` (m) and the vertices' cones by the angle whose cosine and sine
    /// are `turn` (at most 90°: the pairs kept then include those whose normals could face
    /// each other after each normal turned by half of it), on the threads of `pool`: the
    /// vertices' boxes in ranges, then subtrees dealt round the threads, then the nodes above
    /// them (each node's fit is the same whichever thread computes it). Needs
    /// [`TreeFit::reserve`] for `tree`.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn refit(
        &mut self,
        tree: &SurfaceTree,
        boundary: &[[u32; 3]],
        (x, p): (&[Vec3], &[Vec3]),
        (normal, vertex_normal): (&[Vec3], &[Vec3]),
        reach: Real,
        turn: (Real, Real),
        pool: &Pool,
    ) {
        self.turn = turn;
        let hull = SharedSlice::new(&mut self.hull);
        pool.for_each_range(tree.vertices.len(), &|range| {
            for &k in &tree.vertices[range] {
                let k = k as usize;
                // SAFETY: every boundary vertex is once in the tree's vertices.
                *unsafe { hull.element(k) } = motion(&x[k], &p[k]);
            }
        });
        let hull = &self.hull;
        // Node `n` from its children (at `n − base` in `fits`) or its leaf's triangles.
        let fit = |fits: &mut [NodeFit], base: usize, n: usize| {
            let node = tree.nodes[n];
            fits[n - base] = if node.is_leaf() {
                let tris = &tree.triangles[node.tris.0 as usize..node.tris.1 as usize];
                let verts = &tree.vertices[node.verts.0 as usize..node.verts.1 as usize];
                let corners = (tris.iter().flat_map(|&t| boundary[t as usize]))
                    .fold(EMPTY_BOX, |b, k| merge(&b, &hull[k as usize]));
                NodeFit {
                    triangle_box: inflated(&corners, reach),
                    vertex_box: (verts.iter())
                        .fold(EMPTY_BOX, |b, &k| merge(&b, &hull[k as usize])),
                    triangle_cone: Cone::of(tris.iter().map(|&t| normal[t as usize])),
                    vertex_cone: Cone::of(verts.iter().map(|&k| vertex_normal[k as usize]))
                        .widened(turn),
                }
            } else {
                let (l, r) = (&fits[n + 1 - base], &fits[node.right as usize - base]);
                NodeFit {
                    triangle_box: merge(&l.triangle_box, &r.triangle_box),
                    vertex_box: merge(&l.vertex_box, &r.vertex_box),
                    triangle_cone: l.triangle_cone.union(&r.triangle_cone),
                    vertex_cone: l.vertex_cone.union(&r.vertex_cone),
                }
            };
        };
        let fits = &mut self.nodes[..tree.nodes.len()];
        let threads = pool.threads();
        if threads == 1 {
            (0..fits.len()).rev().for_each(|n| fit(fits, 0, n));
            return;
        }
        let [(roots, count), (above, above_count)] = tree.subtrees(SUBTREES_PER_THREAD * threads);
        let shared = SharedSlice::new(fits);
        pool.run(&|share| {
            for &root in roots[..count].iter().skip(share).step_by(threads) {
                let nodes = root as usize..tree.subtree_end(root as usize);
                // SAFETY: the subtrees hold disjoint runs of nodes.
                let mine = unsafe { shared.range(nodes.clone()) };
                nodes.clone().rev().for_each(|n| fit(mine, nodes.start, n));
            }
        });
        (above[..above_count].iter().rev()).for_each(|&n| fit(fits, 0, n as usize));
    }

    /// Whether the vertices of node `a` can touch the triangles of node `b` (last refit).
    fn may_touch(&self, a: usize, b: usize) -> bool {
        let (a, b) = (&self.nodes[a], &self.nodes[b]);
        overlap(&a.vertex_box, &b.triangle_box) && !a.vertex_cone.never_faces(&b.triangle_cone)
    }

    /// Node pairs to start traversals from ([`TreeFit::for_each_candidate`]) that together
    /// visit what one from the root does, each pair once: the root's pair split breadth-first
    /// into the pairs it descends to (those the last refit keeps apart dropped) until at least
    /// `want` (at most [`MAX_SEEDS`] less 3) are left or only pairs of leaves. Returns them and
    /// their count; with `want` = 1 the root alone.
    pub(crate) fn seeds(
        &self,
        tree: &SurfaceTree,
        want: usize,
    ) -> ([(u32, u32); MAX_SEEDS], usize) {
        let want = want.min(MAX_SEEDS - 3);
        let mut seeds = [(0, 0); MAX_SEEDS];
        let mut leaves = 0;
        // Pending pairs, first in first out; a split adds at most 3, so they fit.
        let mut ring = [(0u32, 0u32); MAX_SEEDS];
        let (mut head, mut pending) = (0, usize::from(!tree.nodes.is_empty()));
        while pending > 0 && leaves + pending < want {
            let (a, b) = ring[head];
            (head, pending) = ((head + 1) % MAX_SEEDS, pending - 1);
            let (a, b) = (a as usize, b as usize);
            if !self.may_touch(a, b) {
                continue;
            }
            let split = descend(tree, (a, b), |x, y| {
                ring[(head + pending) % MAX_SEEDS] = (x as u32, y as u32);
                pending += 1;
            });
            if !split {
                seeds[leaves] = (a as u32, b as u32);
                leaves += 1;
            }
        }
        for k in 0..pending {
            seeds[leaves + k] = ring[(head + k) % MAX_SEEDS];
        }
        (seeds, leaves + pending)
    }

    /// Call `visit(vertex, triangle)` (a particle index, an index of the boundary) for every
    /// pair of a vertex and a triangle in leaves below the node pair `seed` (vertices of the
    /// first node, triangles of the second; `(0, 0)` is the whole tree against itself) that the
    /// last refit's boxes and cones do not keep apart (see the module documentation), leaf pair
    /// by leaf pair. A vertex is visited with the triangles around it too: the caller turns
    /// those away.
    pub(crate) fn for_each_candidate(
        &self,
        tree: &SurfaceTree,
        seed: (u32, u32),
        vertex_normal: &[Vec3],
        mut visit: impl FnMut(usize, usize),
    ) {
        // Depth-first over (vertices of a, triangles of b) node pairs; a pair with a == b is a
        // node against itself. Pending pairs: a node against itself leaves three for each
        // level it descends, a pair of nodes one for each level either descends, so at most
        // five times the depth plus one; median splits keep the depth under 32 for any `u32`
        // count of triangles.
        let mut stack = [seed; 5 * 32 + 1];
        let mut top = usize::from(!tree.nodes.is_empty());
        while top > 0 {
            top -= 1;
            let (a, b) = (stack[top].0 as usize, stack[top].1 as usize);
            if !self.may_touch(a, b) {
                continue;
            }
            let split = descend(tree, (a, b), |x, y| {
                stack[top] = (x as u32, y as u32);
                top += 1;
            });
            if split {
                continue;
            }
            let (na, nb) = (tree.nodes[a], tree.nodes[b]);
            let verts = &tree.vertices[na.verts.0 as usize..na.verts.1 as usize];
            let tris = &tree.triangles[nb.tris.0 as usize..nb.tris.1 as usize];
            let (reach, cone) = (&self.nodes[b].triangle_box, &self.nodes[b].triangle_cone);
            for &i in verts {
                let i = i as usize;
                if !overlap(&self.hull[i], reach)
                    || Cone::unit(vertex_normal[i])
                        .widened(self.turn)
                        .never_faces(cone)
                {
                    continue;
                }
                for &t in tris {
                    visit(i, t as usize);
                }
            }
        }
    }
}

/// Call `push` with each node pair the traversal descends to from the pair `(a, b)` (a node
/// against itself: its children against themselves and each other; two nodes: the larger
/// one's children against the other), in the order it takes them last first; false for a pair
/// of leaves, which it does not split.
fn descend(tree: &SurfaceTree, (a, b): (usize, usize), mut push: impl FnMut(usize, usize)) -> bool {
    let (na, nb) = (tree.nodes[a], tree.nodes[b]);
    if a == b && !na.is_leaf() {
        let (l, r) = (a + 1, na.right as usize);
        push(r, l);
        push(l, r);
        push(r, r);
        push(l, l);
    } else if na.is_leaf() && nb.is_leaf() {
        return false;
    } else if !na.is_leaf() && (nb.is_leaf() || na.size() >= nb.size()) {
        push(na.right as usize, b);
        push(a + 1, b);
    } else {
        push(a, nb.right as usize);
        push(a, b + 1);
    }
    true
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::kernels::math::uniform;

    /// A closed sphere of radius 1 (m): `rings` rings of `segments` vertices between two poles,
    /// triangles wound outwards.
    pub(crate) fn sphere(rings: usize, segments: usize) -> (Vec<Vec3>, Vec<[u32; 3]>) {
        let mut v = vec![Vec3::new(0.0, 0.0, 1.0)];
        for r in 1..=rings {
            let polar = std::f64::consts::PI * r as Real / (rings + 1) as Real;
            for s in 0..segments {
                let azimuth = std::f64::consts::TAU * s as Real / segments as Real;
                let (sp, cp) = polar.sin_cos();
                v.push(Vec3::new(sp * azimuth.cos(), sp * azimuth.sin(), cp));
            }
        }
        v.push(Vec3::new(0.0, 0.0, -1.0));
        let at = |r: usize, s: usize| (1 + (r - 1) * segments + s % segments) as u32;
        let south = (v.len() - 1) as u32;
        let mut t = Vec::new();
        for s in 0..segments {
            t.push([0, at(1, s), at(1, s + 1)]);
            t.push([south, at(rings, s + 1), at(rings, s)]);
            for r in 1..rings {
                t.push([at(r, s), at(r + 1, s), at(r + 1, s + 1)]);
                t.push([at(r, s), at(r + 1, s + 1), at(r, s + 1)]);
            }
        }
        (v, t)
    }

    /// The unit normals of the triangles `boundary` and of the vertices at `p` (m).
    pub(crate) fn unit_normals(p: &[Vec3], boundary: &[[u32; 3]]) -> (Vec<Vec3>, Vec<Vec3>) {
        let mut vertex = vec![Vec3::zeros(); p.len()];
        let triangle = (boundary.iter())
            .map(|c| {
                let [a, b, d] = c.map(|k| p[k as usize]);
                let n = (b - a).cross(&(d - a));
                c.iter().for_each(|&k| vertex[k as usize] += n);
                n.try_normalize(0.0).unwrap_or_else(Vec3::zeros)
            })
            .collect();
        let vertex = vertex
            .iter()
            .map(|n| n.try_normalize(0.0).unwrap_or_else(Vec3::zeros));
        (triangle, vertex.collect())
    }

    /// Every pair the exact test could keep is visited, exactly once, from the root as from
    /// seeds for several traversals: a vertex facing a
    /// triangle (normals more than 90° apart, or more than 90° less the cones' widening) that
    /// is not one of its corners, the box of its two positions meeting the triangle's box at
    /// both grown by the reach. On a sphere pressed flat between two planes until its caps
    /// nearly touch, with random jitter, so that the caps face each other within the skin and
    /// its rim is sharp; unwidened and widened by 30°.
    #[test]
    fn visits_every_pair_the_exact_test_could_keep_exactly_once() {
        let (rest, boundary) = sphere(24, 40);
        let tree = SurfaceTree::new(&rest, &boundary);
        let mut random = uniform(11);
        let turns = [0.0, 30.0_f64.to_radians()];
        for (squash, turn) in [1.0, 0.3, 0.05, 0.01]
            .into_iter()
            .flat_map(|s| turns.map(|t| (s, t)))
        {
            let mut jitter = || Vec3::new(random(), random(), random()) * 0.004;
            let x: Vec<Vec3> = (rest.iter())
                .map(|r| Vec3::new(r.x, r.y, r.z * squash) + jitter())
                .collect();
            let p: Vec<Vec3> = x.iter().map(|x| x + jitter()).collect();
            let (normal, vertex_normal) = unit_normals(&p, &boundary);
            let skin = 0.02;
            // Refitted on one thread and on three: the same boxes and cones.
            let [mut fit, mut on_three] = [TreeFit::default(), TreeFit::default()];
            let normals = (normal.as_slice(), vertex_normal.as_slice());
            for (f, threads) in [(&mut fit, 1), (&mut on_three, 3)] {
                f.reserve(&tree, rest.len());
                let pool = Pool::new(threads);
                let turn = (turn.cos(), turn.sin());
                f.refit(&tree, &boundary, (&x, &p), normals, skin, turn, &pool);
            }
            assert!(
                fit.nodes == on_three.nodes,
                "the refit on three threads differs"
            );
            // From the root, and from seeds split for 16 traversals: the same pairs.
            let visits_from = |want: usize| {
                let mut visits = vec![0u8; rest.len() * boundary.len()];
                let (seeds, count) = fit.seeds(&tree, want);
                for &seed in &seeds[..count] {
                    fit.for_each_candidate(&tree, seed, &vertex_normal, |i, t| {
                        visits[i * boundary.len() + t] += 1;
                    });
                }
                (visits, count)
            };
            let (visits, one) = visits_from(1);
            let (split, count) = visits_from(16);
            assert!(one == 1 && count >= 16, "{one} and {count} seeds");
            assert!(visits == split, "the seeds' traversals visit other pairs");
            assert!(visits.iter().all(|&v| v <= 1), "a pair visited twice");
            let mut needed = 0;
            for (t, corners) in boundary.iter().enumerate() {
                let b = corners.iter().fold(EMPTY_BOX, |b, &k| {
                    let k = k as usize;
                    merge(&b, &motion(&x[k], &p[k]))
                });
                let reach = inflated(&b, skin);
                for i in 0..rest.len() {
                    let facing = vertex_normal[i].dot(&normal[t]) < turn.sin();
                    let hull = motion(&x[i], &p[i]);
                    if facing && !corners.contains(&(i as u32)) && overlap(&hull, &reach) {
                        needed += 1;
                        assert_eq!(visits[i * boundary.len() + t], 1, "pair {i}, {t} missed");
                    }
                }
            }
            // The flattened sphere's caps face each other within the skin: the test has
            // teeth only if such pairs exist.
            assert!(
                squash > 0.02 || needed > 1000,
                "{needed} pairs at squash {squash}"
            );
            let visited = visits.iter().filter(|&&v| v > 0).count();
            assert!(
                visited < boundary.len() * rest.len() / 10,
                "the tree culls little: {visited} pairs"
            );
        }
    }

    /// Cones: a union holds both, and two cones said never to face hold no pair of vectors
    /// more than 90° apart (random cones against random members).
    #[test]
    fn cone_unions_hold_both_and_never_faces_is_conservative() {
        let mut random = uniform(5);
        let mut members = |axis: Vec3, spread: Real| -> Vec<Vec3> {
            (0..20)
                .map(|_| (axis + Vec3::new(random(), random(), random()) * spread).normalize())
                .collect()
        };
        let mut skipped = 0;
        for case in 0..400 {
            let spread = [0.05, 0.3, 1.0, 3.0][case % 4];
            let a_axis = Vec3::new(1.0, 0.1 * (case % 7) as Real, 0.0).normalize();
            let b_axis = Vec3::new((case % 5) as Real * 0.2 - 0.3, 1.0, 0.2).normalize();
            let (a, b) = (members(a_axis, spread), members(b_axis, spread));
            let (ca, cb) = (Cone::of(a.iter().copied()), Cone::of(b.iter().copied()));
            let u = ca.union(&cb);
            for v in a.iter().chain(&b) {
                assert!(u.cos == -1.0 || v.dot(&u.axis) >= u.cos - 1e-12);
            }
            if ca.never_faces(&cb) {
                skipped += 1;
                assert!(a.iter().all(|v| b.iter().all(|w| v.dot(w) > 0.0)));
            }
        }
        assert!(skipped > 50, "only {skipped} cases skipped");
    }
}
