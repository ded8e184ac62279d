//! Cutting: a blade swept through a body removes the neighbour pairs and tetrahedra it crosses.
//!
//! The blade is a segment (its edge); over a step it sweeps the quadrilateral between its edge at
//! the start and at the end of the step, split into two triangles. At the end of the step, in
//! the deformed configuration:
//!
//! - every neighbour pair `(i, j)` whose segment `x_i x_j` crosses the swept surface is cut (the
//!   visibility criterion of meshfree cutting: a particle no longer sees a neighbour through the
//!   cut). Particles that lost a neighbour get their MLS gradients recomputed from the
//!   neighbours they still see (first-order consistent; the load-time variationally consistent
//!   correction is not re-imposed there); a particle left with fewer than four neighbours, or an
//!   ill-conditioned moment matrix, loses its elasticity (it stays in the volume constraints);
//! - every tetrahedron with an edge crossing the swept surface is removed from the volume
//!   constraints and from the volume, and the boundary surface is rebuilt from the remaining
//!   tetrahedra (so the cut faces become boundary);
//! - with mass scaling, the particles whose stiffness grew get their inertial mass scaled by the
//!   same factor (their local frequency does not rise: the step stays stable without a new
//!   global estimate); without it, the stability limit is estimated anew.
//!
//! No buffer grows: cut pairs keep their slots with zero coefficients, and the tetrahedra are
//! removed in place. The set of cut pairs and tetrahedra is part of the saved state; restoring
//! a state rebuilds the body's topology from the load-time data it keeps after the first cut.

use crate::kernels::collision::surface_tree::SurfaceTree;
use crate::kernels::colouring::TetColouring;
use crate::kernels::math::{Mat3, Real, Vec3};
use crate::kernels::neighbours::Neighbourhoods;
use crate::kernels::tet_dashpots::TetDashpots;
use crate::kernels::tet_elasticity::TetElements;
use crate::mesh::TetMesh;
use crate::model::body_model::BodyModel;
use crate::model::dual_cells::DualCells;
use crate::scene::body::Body;
use crate::scene::derived::StabilityBase;
use std::sync::Arc;

/// A blade's edge at the start and at the end of its motion over one step (m, world frame).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Blade {
    /// The edge's two ends at the start of the motion.
    pub from: [Vec3; 2],
    /// The edge's two ends at the end of the motion.
    pub to: [Vec3; 2],
}

/// What a cut removed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct CutReport {
    /// Neighbour pairs cut by this call.
    pub pairs: usize,
    /// Tetrahedra removed by this call.
    pub tets: usize,
    /// Particles left without elasticity by this call (too few neighbours).
    pub isolated: usize,
}

/// The cut pairs and removed tetrahedra of a body (load-time indices, increasing).
pub(crate) type CutSets = (Vec<u32>, Vec<u32>);

/// Load-time data of a body, kept from its first cut on, and what has been cut.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct CutState {
    /// The model as loaded (shared with the other holders of it: the cut body works on its own
    /// copy from the first cut on).
    original: Arc<BodyModel>,
    /// The inertial masses and diagonal stiffnesses of the particles before the first cut.
    base: StabilityBase,
    /// Per pair (load-time order): cut.
    pub(crate) pair_cut: Vec<bool>,
    /// Per load-time tetrahedron: removed.
    pub(crate) tet_cut: Vec<bool>,
    /// The same as lists, shared with the world states that hold them (rebuilt at each cut).
    sets: Arc<CutSets>,
}

impl CutState {
    fn new(body: &Body) -> CutState {
        CutState {
            original: Arc::clone(&body.model),
            base: body.derived.stability_base(&body.model),
            pair_cut: vec![false; body.model.nbr.slot_count()],
            tet_cut: vec![false; body.model.tets.len()],
            sets: Arc::default(),
        }
    }
}

/// Smallest number of remaining neighbours for a particle to keep its elasticity.
const MIN_NEIGHBOURS: usize = 4;
/// Largest condition number of a recomputed moment matrix.
const MAX_CONDITION: Real = 1e8;

/// Whether segment `p q` crosses triangle `a b c` (Möller–Trumbore, the segment's interior
/// against the closed triangle).
fn segment_crosses(p: &Vec3, q: &Vec3, [a, b, c]: &[Vec3; 3]) -> bool {
    let d = q - p;
    let (e1, e2) = (b - a, c - a);
    let h = d.cross(&e2);
    let det = e1.dot(&h);
    if det.abs() < 1e-300 {
        return false;
    }
    let inv = 1.0 / det;
    let s = p - a;
    let u = s.dot(&h) * inv;
    if !(0.0..=1.0).contains(&u) {
        return false;
    }
    let qv = s.cross(&e1);
    let v = d.dot(&qv) * inv;
    if v < 0.0 || u + v > 1.0 {
        return false;
    }
    let t = e2.dot(&qv) * inv;
    (0.0..=1.0).contains(&t)
}

/// The swept surface of `blade` as two triangles, and its bounding box.
fn swept(blade: &Blade) -> ([[Vec3; 3]; 2], Vec3, Vec3) {
    let ([a0, b0], [a1, b1]) = (blade.from, blade.to);
    let tris = [[a0, b0, b1], [a0, b1, a1]];
    let (mut lo, mut hi) = (a0, a0);
    for p in [b0, a1, b1] {
        lo = lo.inf(&p);
        hi = hi.sup(&p);
    }
    (tris, lo, hi)
}

fn crosses(p: &Vec3, q: &Vec3, tris: &[[Vec3; 3]; 2], lo: &Vec3, hi: &Vec3) -> bool {
    let (plo, phi) = (p.inf(q), p.sup(q));
    if (0..3).any(|k| phi[k] < lo[k] || plo[k] > hi[k]) {
        return false;
    }
    tris.iter().any(|t| segment_crosses(p, q, t))
}

/// Cut `body` with `blade` (see the module documentation). A blade that crosses nothing
/// changes nothing.
pub(crate) fn cut(body: &mut Body, blade: &Blade) -> CutReport {
    let (tris, lo, hi) = swept(blade);
    let x = &body.state.x;
    let nbr = &body.model.nbr;
    let already = |e: usize| body.cuts.as_ref().is_some_and(|c| c.pair_cut[e]);
    let mut new_pairs = Vec::new();
    for i in 0..x.len() {
        for e in nbr.range(i) {
            let j = nbr.index[e] as usize;
            if !already(e) && crosses(&x[i], &x[j], &tris, &lo, &hi) {
                new_pairs.push(e);
            }
        }
    }
    let mut new_tets = Vec::new();
    let original_tets = body
        .cuts
        .as_ref()
        .map_or(&body.model.tets, |c| &c.original.tets);
    for (t, tet) in original_tets.iter().enumerate() {
        if body.cuts.as_ref().is_some_and(|c| c.tet_cut[t]) {
            continue;
        }
        let p = tet.map(|k| x[k as usize]);
        let edges = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)];
        if edges
            .iter()
            .any(|&(a, b)| crosses(&p[a], &p[b], &tris, &lo, &hi))
        {
            new_tets.push(t);
        }
    }
    if new_pairs.is_empty() && new_tets.is_empty() {
        return CutReport::default();
    }
    let mut state = body
        .cuts
        .take()
        .unwrap_or_else(|| Box::new(CutState::new(body)));
    new_pairs.iter().for_each(|&e| state.pair_cut[e] = true);
    new_tets.iter().for_each(|&t| state.tet_cut[t] = true);
    let isolated = apply(body, state, Some(&new_pairs));
    CutReport {
        pairs: new_pairs.len(),
        tets: new_tets.len(),
        isolated,
    }
}

/// Rebuild `body`'s topology for the cut sets of `state`: gradients of the particles with cut
/// pairs (all particles with a cut pair when `changed` is `None`, else the centres of the pairs
/// in `changed`), the tetrahedra, the rest volume, the boundary and the stability data. Returns
/// the number of particles left without elasticity among those recomputed.
fn apply(body: &mut Body, mut state: Box<CutState>, changed: Option<&[usize]>) -> usize {
    let n = body.state.x.len();
    let list = |v: &[bool]| {
        v.iter()
            .enumerate()
            .filter(|(_, &b)| b)
            .map(|(k, _)| k as u32)
            .collect()
    };
    state.sets = Arc::new((list(&state.pair_cut), list(&state.tet_cut)));
    let original = &state.original;
    // Copy-on-write: the first change of a shared model gives this body its own copy.
    let model = Arc::make_mut(&mut body.model);
    let mut rows = vec![false; n];
    match changed {
        Some(pairs) => {
            for &e in pairs {
                rows[centre_of(&model.nbr, e)] = true;
            }
        }
        None => {
            model.nbr.gradient.copy_from(&original.nbr.gradient);
            model
                .nbr
                .hourglass_weight
                .copy_from_slice(&original.nbr.hourglass_weight);
            for (e, &cut) in state.pair_cut.iter().enumerate() {
                if cut {
                    rows[centre_of(&model.nbr, e)] = true;
                }
            }
        }
    }
    let mut isolated = 0;
    for (i, &row) in rows.iter().enumerate() {
        if row && !recompute_row(&mut model.nbr, &state.pair_cut, i) {
            isolated += 1;
        }
    }
    model.tets.clear();
    model.tet_rest_volume.clear();
    for (t, tet) in original.tets.iter().enumerate() {
        if !state.tet_cut[t] {
            model.tets.push(*tet);
            model.tet_rest_volume.push(original.tet_rest_volume[t]);
        }
    }
    model.rest_volume = model.tet_rest_volume.iter().sum();
    model.tet_colouring = TetColouring::new(&model.tets, &model.tet_rest_volume, n);
    model.dual_cells = DualCells::new(&model.tets, &model.tet_rest_volume, n);
    model.tet_elements = TetElements::new(&model.rest, &model.tets, &model.tet_rest_volume, n);
    model.tet_dashpots = TetDashpots::new(&model.rest, &model.tets, &model.tet_rest_volume, n);
    let mesh = TetMesh {
        nodes: model.rest.clone(),
        tets: model.tets.clone(),
    };
    model.boundary = mesh.boundary_triangles();
    model.boundary_vertices = crate::mesh::boundary_vertices(&model.boundary);
    model.boundary_tree = SurfaceTree::new(&model.rest, &model.boundary);
    // Keep the step stable on the new topology.
    body.derived.restabilise(&body.model, &state.base);
    body.update_inverse_masses();
    body.cuts = Some(state);
    isolated
}

/// The particle whose neighbourhood holds pair `e`.
fn centre_of(nbr: &Neighbourhoods, e: usize) -> usize {
    nbr.offsets.partition_point(|&o| o as usize <= e) - 1
}

/// Recompute particle `i`'s MLS gradients (poly6 kernel, its support radius) and hourglass
/// weights from its uncut pairs; cut pairs get zeros. False (and all zeros) when fewer than
/// [`MIN_NEIGHBOURS`] remain or the moment matrix is ill-conditioned.
fn recompute_row(nbr: &mut Neighbourhoods, pair_cut: &[bool], i: usize) -> bool {
    let range = nbr.range(i);
    let h2 = nbr.support_radius[i] * nbr.support_radius[i];
    let weight = |u: &Vec3| {
        let s = 1.0 - u.norm_squared() / h2;
        if s > 0.0 {
            s * s * s
        } else {
            0.0
        }
    };
    let mut a = Mat3::zeros();
    let (mut wsum, mut alive) = (0.0, 0);
    for e in range.clone() {
        if !pair_cut[e] {
            let u = nbr.rest_offset.get(e);
            let w = weight(&u);
            a += u * u.transpose() * w;
            wsum += w;
            alive += 1;
        }
    }
    let eig = a.symmetric_eigenvalues();
    let inverse = (alive >= MIN_NEIGHBOURS && eig.min() > eig.max() / MAX_CONDITION && wsum > 0.0)
        .then(|| a.try_inverse())
        .flatten();
    for e in range {
        let u = nbr.rest_offset.get(e);
        match inverse {
            Some(inv) if !pair_cut[e] => {
                let w = weight(&u);
                nbr.gradient.set(e, inv * u * w);
                nbr.hourglass_weight[e] = w / wsum / u.norm_squared();
            }
            _ => {
                nbr.gradient.set(e, Vec3::zeros());
                nbr.hourglass_weight[e] = 0.0;
            }
        }
    }
    inverse.is_some()
}

/// The cut pairs and removed tetrahedra of `body` (load-time indices, increasing), for the
/// world state: `None` when nothing is cut. Shares the body's lists (no copy).
pub(crate) fn cut_sets(body: &Body) -> Option<Arc<CutSets>> {
    let sets = &body.cuts.as_ref()?.sets;
    let cut = !(sets.0.is_empty() && sets.1.is_empty());
    cut.then(|| Arc::clone(sets))
}

/// Give `body` exactly the cut sets `sets` (load-time indices, checked by the caller to be in
/// range; `None`: uncut). Nothing is rebuilt when they are the body's already.
pub(crate) fn restore(body: &mut Body, sets: &Option<Arc<CutSets>>) {
    let now = cut_sets(body);
    let same = match (&now, sets) {
        (Some(a), Some(b)) => Arc::ptr_eq(a, b) || a == b,
        (a, b) => a.is_none() && b.is_none(),
    };
    if same {
        return;
    }
    let mut state = body
        .cuts
        .take()
        .unwrap_or_else(|| Box::new(CutState::new(body)));
    state.pair_cut.iter_mut().for_each(|c| *c = false);
    state.tet_cut.iter_mut().for_each(|c| *c = false);
    if let Some(sets) = sets {
        sets.0
            .iter()
            .for_each(|&e| state.pair_cut[e as usize] = true);
        sets.1
            .iter()
            .for_each(|&t| state.tet_cut[t as usize] = true);
    }
    apply(body, state, None);
}

/// Number of load-time pair slots and tetrahedra of `body` (the ranges of the saved cut sets).
pub(crate) fn load_time_counts(body: &Body) -> (usize, usize) {
    let tets = body
        .cuts
        .as_ref()
        .map_or(body.model.tets.len(), |c| c.original.tets.len());
    (body.model.nbr.slot_count(), tets)
}

impl Body {
    /// The model this body was built on (for a cut body, the uncut original it keeps to rebuild
    /// from): pass it to [`World::add_body_model`](crate::World::add_body_model) to build the
    /// same body elsewhere without redoing the load-time work.
    pub fn load_time_model(&self) -> &Arc<BodyModel> {
        self.cuts.as_ref().map_or(&self.model, |c| &c.original)
    }
    /// Neighbour pairs cut and tetrahedra removed so far (0, 0 for a body never cut).
    pub fn cut_counts(&self) -> (usize, usize) {
        cut_sets(self).map_or((0, 0), |s| (s.0.len(), s.1.len()))
    }
}
