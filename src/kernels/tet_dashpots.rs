//! Stiffness-proportional damping of the tetrahedra, solved implicitly on the mesh edges.
//!
//! Each mesh edge `ij` carries a dashpot along its current direction `e` with coefficient
//! `β k_ij` (N·s/m), `k_ij = max(0, -e₀ᵀ K_ij e₀)` (N/m) the edge's share of the linear stiffness
//! of the tetrahedra around it (`K_ij = Σ_t V_t [μ (∇N_i·∇N_j) I + μ ∇N_j ∇N_iᵀ + λ ∇N_i ∇N_jᵀ]`,
//! `e₀` the edge's rest direction, μ and λ the constants the tetrahedra carry). Six edge-length
//! rates determine a tetrahedron's strain rate, so the dashpots damp every deformation mode
//! and leave rigid motion alone; their impulses are central and opposite, so they conserve
//! linear and angular momentum.
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
//! dashpot: on meshes whose stiffest particles sit at the stability limit the low modes get
//! about a third to a half of the nominal damping (docs/SETTINGS.md).
//!
//! Each particle gathers the impulses of its own edges (both ends compute the same impulse
//! bit for bit), so the filter is one parallel pass with the same result on any thread count.

use crate::kernels::math::{Real, Vec3};
use crate::kernels::parallel::{Pool, SharedSlice};

/// The edges of a tetrahedral mesh as a per-particle adjacency, with the geometric parts of
/// each edge's stiffness.
#[derive(Debug, Clone, PartialEq, Default)]
pub(crate) struct TetDashpots {
    /// `neighbour[offsets[i]..offsets[i + 1]]`: the particles sharing an edge with `i`,
    /// ascending.
    offsets: Vec<u32>,
    neighbour: Vec<u32>,
    /// `Σ_t V_t [(∇N_i·∇N_j) + (e₀·∇N_i)(e₀·∇N_j)]` (m) of each entry: its shear stiffness over μ.
    shear: Vec<Real>,
    /// `Σ_t V_t (e₀·∇N_i)(e₀·∇N_j)` (m): its volumetric stiffness over λ.
    volumetric: Vec<Real>,
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

impl TetDashpots {
    /// The edges of the tetrahedra `tets` (rest volumes `volume`, m³) over `n` particles at rest
    /// positions `rest` (m).
    pub(crate) fn new(rest: &[Vec3], tets: &[[u32; 4]], volume: &[Real], n: usize) -> TetDashpots {
        let mut entries: Vec<(u32, u32, Real, Real)> = Vec::with_capacity(12 * tets.len());
        for (tet, &v) in tets.iter().zip(volume) {
            let [a, b, c, d] = tet.map(|k| rest[k as usize]);
            let six_v = 6.0 * v;
            // ∇N of the corners (1/m): each the inward normal of its opposite face over 3V.
            let gb = (c - a).cross(&(d - a)) / six_v;
            let gc = (d - a).cross(&(b - a)) / six_v;
            let gd = (b - a).cross(&(c - a)) / six_v;
            let grad = [-(gb + gc + gd), gb, gc, gd];
            for p in 0..4 {
                for q in 0..4 {
                    if p == q {
                        continue;
                    }
                    let (i, j) = (tet[p], tet[q]);
                    let e = (rest[j as usize] - rest[i as usize]).normalize();
                    let along = e.dot(&grad[p]) * e.dot(&grad[q]);
                    let shear = v * (grad[p].dot(&grad[q]) + along);
                    entries.push((i, j, shear, v * along));
                }
            }
        }
        entries.sort_unstable_by_key(|&(i, j, _, _)| (i, j));
        let mut dashpots = TetDashpots {
            offsets: vec![0; n + 1],
            ..TetDashpots::default()
        };
        let mut previous = None;
        for (i, j, shear, volumetric) in entries {
            if previous == Some((i, j)) {
                let last = dashpots.neighbour.len() - 1;
                dashpots.shear[last] += shear;
                dashpots.volumetric[last] += volumetric;
            } else {
                dashpots.neighbour.push(j);
                dashpots.shear.push(shear);
                dashpots.volumetric.push(volumetric);
            }
            previous = Some((i, j));
            dashpots.offsets[i as usize + 1] = dashpots.neighbour.len() as u32;
        }
        for i in 0..n {
            dashpots.offsets[i + 1] = dashpots.offsets[i + 1].max(dashpots.offsets[i]);
        }
        dashpots
    }

    /// Bytes held on the heap.
    pub(crate) fn heap_bytes(&self) -> usize {
        4 * (self.offsets.capacity() + self.neighbour.capacity())
            + std::mem::size_of::<Real>() * (self.shear.capacity() + self.volumetric.capacity())
    }

    /// The dashpot stiffness `k_ij` (N/m) of entry `e`.
    fn stiffness(&self, e: usize, mu: Real, lambda: Real) -> Real {
        (-(mu * self.shear[e] + lambda * self.volumetric[e])).max(0.0)
    }

    /// `2 h β D_i / m_i` (dimensionless) of every particle into `load`, `inv_mass` the inverse
    /// inertial masses (1/kg; 0 for a fixed particle).
    fn loads(&self, filter: &DashpotFilter, inv_mass: &[Real], load: &mut [Real], pool: &Pool) {
        let out = SharedSlice::new(load);
        pool.for_each_range(inv_mass.len(), &|range| {
            // SAFETY: the shares' ranges are disjoint.
            let load = unsafe { out.range(range.clone()) };
            for (i, l) in range.zip(load) {
                let entries = self.offsets[i] as usize..self.offsets[i + 1] as usize;
                let d: Real = entries
                    .map(|e| self.stiffness(e, filter.mu, filter.lambda))
                    .sum();
                *l = 2.0 * filter.h * filter.beta * d * inv_mass[i];
            }
        });
    }

    /// Filter the velocities `v` (m/s) of particles at positions `x` (m) into `out`: one
    /// Jacobi step of the implicit dashpots (module doc). `load` is scratch of one entry a
    /// particle.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn filter(
        &self,
        filter: &DashpotFilter,
        x: &[Vec3],
        v: &[Vec3],
        inv_mass: &[Real],
        load: &mut [Real],
        out: &mut [Vec3],
        pool: &Pool,
    ) {
        self.loads(filter, inv_mass, load, pool);
        let load = &*load;
        let hb = filter.h * filter.beta;
        let filtered = SharedSlice::new(out);
        pool.for_each_range(v.len(), &|range| {
            // SAFETY: the shares' ranges are disjoint.
            let out = unsafe { filtered.range(range.clone()) };
            for (i, o) in range.zip(out) {
                let mut impulse = Vec3::zeros();
                for e in self.offsets[i] as usize..self.offsets[i + 1] as usize {
                    let j = self.neighbour[e] as usize;
                    let k = self.stiffness(e, filter.mu, filter.lambda);
                    let d = x[j] - x[i];
                    let length = d.norm();
                    if k == 0.0 || length == 0.0 {
                        continue;
                    }
                    let dir = d / length;
                    // The rate at which the edge shortens (m/s), and its impulse on i (N·s).
                    let closing = dir.dot(&(v[i] - v[j]));
                    let j_e = hb * k * closing / (1.0 + load[i].max(load[j]));
                    impulse -= dir * j_e;
                }
                *o = v[i] + impulse * inv_mass[i];
            }
        });
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

    fn run(x: &[Vec3], v: &[Vec3], beta: Real) -> Vec<Vec3> {
        let (rest, tets, volume) = tet();
        let dashpots = TetDashpots::new(&rest, &tets, &volume, 4);
        let filter = DashpotFilter {
            mu: 1000.0,
            lambda: 1500.0,
            beta,
            h: 1e-3,
        };
        let mut out = vec![Vec3::zeros(); 4];
        let mut load = vec![0.0; 4];
        dashpots.filter(
            &filter,
            x,
            v,
            &[10.0; 4],
            &mut load,
            &mut out,
            &Pool::new(1),
        );
        out
    }

    #[test]
    fn every_edge_of_a_tetrahedron_gets_a_dashpot() {
        let (rest, tets, volume) = tet();
        let d = TetDashpots::new(&rest, &tets, &volume, 4);
        assert_eq!(d.offsets, vec![0, 3, 6, 9, 12]);
        for e in 0..12 {
            assert!(d.stiffness(e, 1000.0, 1500.0) > 0.0, "edge entry {e}");
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
