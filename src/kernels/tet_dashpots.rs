//! Stiffness-proportional damping on the mesh edges, solved implicitly (both elastic schemes).
//!
//! Each mesh edge `ij` carries a dashpot along its current direction `e` with coefficient
//! `β k_ij` (N·s/m), `k_ij` (N/m) the edge's share of the linear stiffness of the tetrahedra
//! around it, `-e₀ᵀ K_ij e₀` with `K_ij = Σ_t V_t [μ (∇N_i·∇N_j) I + μ ∇N_j ∇N_iᵀ + λ ∇N_i ∇N_jᵀ]`
//! (`e₀` the edge's rest direction, μ and λ the constants the tetrahedra carry), its shear and
//! volumetric parts each kept only where positive (a sliver's edge can have either part
//! negative: its dashpot would push energy in). Six edge-length rates determine a
//! tetrahedron's strain rate, so the dashpots damp every deformation mode and leave rigid
//! motion alone; their impulses are central and opposite, so they conserve linear and angular
//! momentum.
//!
//! Explicit, such a dashpot lowers the stability limit (symplectic Euler needs
//! `h ω² (h + 2β) ≤ 4`): the tetrahedra would need substeps for any useful β. Here the substep's
//! velocities after the elastic kick are filtered instead, with one Jacobi step of the implicit
//! system `(M + h β K_d) Δv = -h β K_d v`: the impulse of edge `ij` is
//! `J = h β k_ij (e·(v_i - v_j)) / (1 + 2 h β max(D_i/m_i, D_j/m_j))` (N·s), `D_i = Σ_j k_ij`
//! (N/m) and `m_i` the inertial mass (kg). The denominator bounds the filter by the edge
//! network's Gershgorin limit, so it never reverses a mode's velocity: it only removes kinetic
//! energy, at any β and any substep. A mode of angular frequency ω with `h β ω² ≪ 1` loses
//! `h β ω² / (1 + 2 h β D/m)` of its velocity a substep, against `h β ω²` for the explicit
//! dashpot: where the stiffest particles sit at the stability limit (mass scaling puts them
//! there) the slow modes get less than the nominal β (docs/VALIDATION.md has the rest times).
//!
//! The corners of a tetrahedron the force pass found crushed (below half its rest volume, the
//! crush guard's list) get no damping: inverted, such a tetrahedron untangles by a snap
//! through its neither-side state that the crush guard starts, and dashpots on its edges took
//! the momentum out of that snap (a mirrored liver stayed tangled, its tetrahedra flapping).
//!
//! The filter is three parallel passes with the same result on any thread count: each
//! particle's load `2 h β D_i / m_i` (fused into the kick), each edge's impulse once, and each
//! particle's sum of its edges' impulses in a fixed order (fused into the drift).

use crate::kernels::lanes::{Mask4, F4, LANES, V4};
use crate::kernels::math::{Real, Vec3};
use crate::kernels::parallel::{Pool, SharedSlice};

/// The edges of a tetrahedral mesh with the geometric parts of their stiffness, and each
/// particle's edges.
#[derive(Debug, Clone, PartialEq, Default)]
pub(crate) struct TetDashpots {
    /// The edges `(i, j)`, `i < j`, ascending, then inert ones (`(0, 0)`, no stiffness) to a
    /// whole number of chunks of [`LANES`].
    edges: Vec<[u32; 2]>,
    /// `max(0, -Σ_t V_t [(∇N_i·∇N_j) + (e₀·∇N_i)(e₀·∇N_j)])` (m) of each edge: its shear
    /// stiffness over μ.
    shear: Vec<Real>,
    /// `max(0, -Σ_t V_t (e₀·∇N_i)(e₀·∇N_j))` (m): its volumetric stiffness over λ.
    volumetric: Vec<Real>,
    /// Per particle the sums of `shear` and `volumetric` over its edges (m): `D_i = μ A_i + λ B_i`.
    shear_sum: Vec<Real>,
    volumetric_sum: Vec<Real>,
    /// `offsets[i]..offsets[i + 1]`: the impulse slots of particle `i`'s edges, ascending by
    /// edge; then one slot the inert edges write to.
    offsets: Vec<u32>,
    /// The impulse slots of each edge's first and second particle.
    slots: Vec<[u32; 2]>,
}

/// The material constants and the substep the filter runs with.
#[derive(Debug, Clone, Copy)]
pub(crate) struct DashpotFilter {
    /// Shear modulus μ and the volumetric constant λ the tetrahedra carry (Pa).
    pub(crate) mu: Real,
    pub(crate) lambda: Real,
    /// Damping time β (s).
    pub(crate) beta: Real,
    /// Substep (s).
    pub(crate) h: Real,
}

impl DashpotFilter {
    /// The load `2 h β D_i / m_i` (dimensionless) of particle `i` of `dashpots`, `inv_mass` its
    /// inverse inertial mass (1/kg; 0 when fixed).
    #[inline]
    pub(crate) fn load(&self, dashpots: &TetDashpots, i: usize, inv_mass: Real) -> Real {
        let d = self.mu * dashpots.shear_sum[i] + self.lambda * dashpots.volumetric_sum[i];
        2.0 * self.h * self.beta * d * inv_mass
    }
}

impl TetDashpots {
    /// The edges of the tetrahedra `tets` (rest volumes `volume`, m³) over `n` particles at rest
    /// positions `rest` (m).
    pub(crate) fn new(rest: &[Vec3], tets: &[[u32; 4]], volume: &[Real], n: usize) -> TetDashpots {
        let mut entries: Vec<([u32; 2], Real, Real)> = Vec::with_capacity(6 * tets.len());
        for (tet, &v) in tets.iter().zip(volume) {
            let [a, b, c, d] = tet.map(|k| rest[k as usize]);
            let six_v = 6.0 * v;
            // ∇N of the corners (1/m): each the inward normal of its opposite face over 3V.
            let gb = (c - a).cross(&(d - a)) / six_v;
            let gc = (d - a).cross(&(b - a)) / six_v;
            let gd = (b - a).cross(&(c - a)) / six_v;
            let grad = [-(gb + gc + gd), gb, gc, gd];
            for p in 0..4 {
                for q in p + 1..4 {
                    let (i, j) = (tet[p], tet[q]);
                    let e = (rest[j as usize] - rest[i as usize]).normalize();
                    let along = e.dot(&grad[p]) * e.dot(&grad[q]);
                    let shear = v * (grad[p].dot(&grad[q]) + along);
                    entries.push(([i.min(j), i.max(j)], shear, v * along));
                }
            }
        }
        entries.sort_unstable_by_key(|&(edge, _, _)| edge);
        let mut dashpots = TetDashpots::default();
        for (edge, shear, volumetric) in entries {
            if dashpots.edges.last() == Some(&edge) {
                *dashpots.shear.last_mut().unwrap() += shear;
                *dashpots.volumetric.last_mut().unwrap() += volumetric;
            } else {
                dashpots.edges.push(edge);
                dashpots.shear.push(shear);
                dashpots.volumetric.push(volumetric);
            }
        }
        for k in dashpots.shear.iter_mut().chain(&mut dashpots.volumetric) {
            *k = (-*k).max(0.0);
        }
        let edge_count = dashpots.edges.len();
        let mut count = vec![0u32; n + 1];
        for [i, j] in &dashpots.edges {
            count[*i as usize + 1] += 1;
            count[*j as usize + 1] += 1;
        }
        for i in 0..n {
            count[i + 1] += count[i];
        }
        let mut next = count.clone();
        let mut slots = Vec::with_capacity(edge_count.next_multiple_of(LANES));
        let (mut shear_sum, mut volumetric_sum) = (vec![0.0; n], vec![0.0; n]);
        for (e, edge) in dashpots.edges.iter().enumerate() {
            slots.push(edge.map(|end| {
                let end = end as usize;
                shear_sum[end] += dashpots.shear[e];
                volumetric_sum[end] += dashpots.volumetric[e];
                next[end] += 1;
                next[end] - 1
            }));
        }
        let padded = edge_count.next_multiple_of(LANES);
        dashpots.edges.resize(padded, [0, 0]);
        dashpots.shear.resize(padded, 0.0);
        dashpots.volumetric.resize(padded, 0.0);
        slots.resize(padded, [count[n]; 2]);
        TetDashpots {
            shear_sum,
            volumetric_sum,
            offsets: count,
            slots,
            ..dashpots
        }
    }

    /// The number of impulse slots: two an edge, and one for the inert edges.
    pub(crate) fn slot_count(&self) -> usize {
        self.offsets.last().map_or(0, |&n| n as usize + 1)
    }

    /// Bytes held on the heap.
    pub(crate) fn heap_bytes(&self) -> usize {
        8 * (self.edges.capacity() + self.slots.capacity())
            + 4 * self.offsets.capacity()
            + std::mem::size_of::<Real>()
                * (self.shear.capacity()
                    + self.volumetric.capacity()
                    + self.shear_sum.capacity()
                    + self.volumetric_sum.capacity())
    }

    /// Each edge's impulses on its two particles (N·s) into their slots of `impulse`, from the
    /// velocities `v` (m/s) at positions `x` (m) and the particles' loads
    /// ([`DashpotFilter::load`]); none on an edge with a particle flagged `undamped` (a corner
    /// of a crushed tetrahedron). Each slot is written by one edge only.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn edge_impulses(
        &self,
        filter: &DashpotFilter,
        x: &[Vec3],
        v: &[Vec3],
        load: &[Real],
        undamped: &[bool],
        impulse: &mut [Vec3],
        pool: &Pool,
    ) {
        // Every edge's particles are below the count it was built for.
        let n = self.offsets.len() - 1;
        assert!(x.len() == n && v.len() == n && load.len() == n && undamped.len() == n);
        assert!(impulse.len() == self.slot_count());
        let hb = F4::splat(-filter.h * filter.beta);
        let (mu, lambda) = (F4::splat(filter.mu), F4::splat(filter.lambda));
        let out = SharedSlice::new(impulse);
        pool.for_each_range(self.edges.len() / LANES, &|chunks| {
            for c in chunks {
                let e = LANES * c..LANES * (c + 1);
                let lanes = |field: &[Real]| F4::new(field[e.clone()].try_into().unwrap());
                let [i, j]: [[u32; LANES]; 2] = std::array::from_fn(|end| {
                    std::array::from_fn(|l| self.edges[e.start + l][end])
                });
                // SAFETY: every index is below `n`, the fields' length (checked above).
                let at =
                    |field: &[Vec3], k: &[u32; LANES]| unsafe { V4::gather_unchecked(field, k) };
                let gather = |k: &[u32; LANES]| F4::new(k.map(|k| load[k as usize]));
                let k = mu.mul_add(lanes(&self.shear), lambda * lanes(&self.volumetric));
                let d = at(x, &j) - at(x, &i);
                let length2 = d.dot(&d);
                // The rate at which the edge shortens times its length (m²/s).
                let closing = d.dot(&(at(v, &i) - at(v, &j)));
                let denominator = length2 * (F4::splat(1.0) + gather(&i).max(gather(&j)));
                let crushed = |k: &[u32; LANES]| Mask4::new(k.map(|k| undamped[k as usize]));
                let live = F4::splat(0.0).lt(k)
                    & F4::splat(0.0).lt(length2)
                    & !(crushed(&i) | crushed(&j));
                let scale = live.select(hb * k * closing / denominator, F4::splat(0.0));
                let mut on_first = [Vec3::zeros(); LANES];
                d.scale(scale).store(&mut on_first);
                for (l, j) in on_first.iter().enumerate() {
                    let [first, second] = self.slots[e.start + l].map(|s| s as usize);
                    // SAFETY: each edge's slots are its own, but for the inert edges' one
                    // slot, which only the last chunk's share writes.
                    unsafe {
                        *out.element(first) = *j;
                        *out.element(second) = -*j;
                    }
                }
            }
        });
    }

    /// The sum (N·s) of the edge impulses on particle `i`, in the order of its edges.
    #[inline]
    pub(crate) fn impulse_on(&self, i: usize, impulse: &[Vec3]) -> Vec3 {
        let slots = self.offsets[i] as usize..self.offsets[i + 1] as usize;
        impulse[slots].iter().sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tet() -> (Vec<Vec3>, Vec<[u32; 4]>, Vec<Real>) {
        let rest = vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(0.0, 0.0, 1.0),
        ];
        (rest, vec![[0, 1, 2, 3]], vec![1.0 / 6.0])
    }

    /// The filtered velocities of one tetrahedron at `x` moving with `v`, masses 0.1 kg.
    fn run(x: &[Vec3], v: &[Vec3], beta: Real) -> Vec<Vec3> {
        let (rest, tets, volume) = tet();
        let dashpots = TetDashpots::new(&rest, &tets, &volume, 4);
        let filter = DashpotFilter {
            mu: 1000.0,
            lambda: 1500.0,
            beta,
            h: 1e-3,
        };
        let inv_mass = 10.0;
        let load: Vec<Real> = (0..4)
            .map(|i| filter.load(&dashpots, i, inv_mass))
            .collect();
        let mut impulse = vec![Vec3::zeros(); dashpots.slot_count()];
        let undamped = [false; 4];
        dashpots.edge_impulses(&filter, x, v, &load, &undamped, &mut impulse, &Pool::new(1));
        (0..4)
            .map(|i| v[i] + dashpots.impulse_on(i, &impulse) * inv_mass)
            .collect()
    }

    #[test]
    fn every_edge_of_a_tetrahedron_gets_a_dashpot() {
        let (rest, tets, volume) = tet();
        let d = TetDashpots::new(&rest, &tets, &volume, 4);
        // Six edges, then two inert ones to a whole chunk.
        assert_eq!((d.edges.len(), d.slot_count()), (8, 13));
        assert_eq!(d.offsets, vec![0, 3, 6, 9, 12]);
        for e in 0..8 {
            let live = d.shear[e] > 0.0 && d.volumetric[e] > 0.0;
            assert_eq!(live, e < 6, "edge {e}");
        }
    }

    #[test]
    fn rigid_motion_passes_unchanged() {
        let (rest, _, _) = tet();
        let w = Vec3::new(0.3, -1.0, 2.0);
        let v: Vec<Vec3> = rest
            .iter()
            .map(|p| Vec3::new(1.0, 2.0, 3.0) + w.cross(p))
            .collect();
        let out = run(&rest, &v, 1.0);
        for (a, b) in out.iter().zip(&v) {
            assert!((a - b).norm() < 1e-12, "{a} != {b}");
        }
    }

    #[test]
    fn a_stretching_tetrahedron_slows_without_reversing_and_keeps_its_momentum() {
        let (rest, _, _) = tet();
        // Each corner moving away from the centroid: a uniform expansion rate.
        let centre = rest.iter().sum::<Vec3>() / 4.0;
        let v: Vec<Vec3> = rest.iter().map(|p| (p - centre) * 2.0).collect();
        for beta in [1e-3, 1.0, 1e6] {
            let out = run(&rest, &v, beta);
            let momentum: Vec3 = out.iter().sum();
            let angular: Vec3 = rest.iter().zip(&out).map(|(p, u)| p.cross(u)).sum();
            assert!(
                momentum.norm() < 1e-12 && angular.norm() < 1e-12,
                "β {beta}"
            );
            for (a, b) in out.iter().zip(&v) {
                // Slower, in the same direction: the filter only removes kinetic energy.
                assert!(
                    a.dot(b) > 0.0 && a.norm() < b.norm(),
                    "β {beta}: {a} from {b}"
                );
            }
        }
    }
}
