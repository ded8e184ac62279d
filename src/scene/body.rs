//! A deformable body in a world: its shared load-time model ([`BodyModel`]: rest data,
//! neighbourhoods, masses), what it derives from the world's settings ([`Derived`]: elastic
//! constants, volume compliance, inertial masses, stability estimate), the fixed particles and
//! the particle state.
//!
//! A body stores its particles in particle order, the mesh's nodes sorted for memory locality
//! ([`ParticleOrder`]); its Rust API speaks that order, the C ABI and the FMU the mesh's.

use crate::kernels::lanes::{F4, LANES, V4};
use crate::kernels::math::{is_finite_vec, Mat3, Quat, Real, Vec3};
use crate::kernels::neighbours::Neighbourhoods;
use crate::kernels::parallel::{Pool, SharedSlice};
use crate::kernels::point_elasticity::{self, ElasticModel};
use crate::model::body_model::{BodyModel, Material};
use crate::model::particle_order::ParticleOrder;
use crate::scene::derived::{Derived, DerivedFrom};
use std::sync::Arc;

/// Largest distance (in body sizes: the diagonal of the rest bounding box) of a particle from
/// the centre of its body's rest bounding box that [`World::set_body_state`] and
/// [`World::restore_state`] accept. Beyond it a state is not a deformed organ but garbage (a
/// crafted buffer, a unit error), and stepping it would only overflow.
///
/// [`World::set_body_state`]: crate::World::set_body_state
/// [`World::restore_state`]: crate::World::restore_state
pub const STATE_POSITION_LIMIT: Real = 100.0;

/// Largest particle speed (in body sizes per second) that [`World::set_body_state`] and
/// [`World::restore_state`] accept (200 m/s for a 0.2 m organ).
///
/// [`World::set_body_state`]: crate::World::set_body_state
/// [`World::restore_state`]: crate::World::restore_state
pub const STATE_SPEED_LIMIT: Real = 1000.0;

/// The dynamic state of a body's particles: what a step advances; part of the
/// [`WorldState`](crate::WorldState).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct ParticleState {
    /// Positions (m).
    pub(crate) x: Vec<Vec3>,
    /// Velocities (m/s).
    pub(crate) v: Vec<Vec3>,
    /// Per-particle rotation of the corotated model, warm start of the next extraction.
    pub(crate) rotation: Vec<Quat>,
}

impl ParticleState {
    /// Particles at `positions` (m), at rest and unrotated.
    fn at_rest(positions: &[Vec3]) -> Self {
        let n = positions.len();
        ParticleState {
            x: positions.to_vec(),
            v: vec![Vec3::zeros(); n],
            rotation: vec![Quat::identity(); n],
        }
    }

    /// Overwrite with `other`, reusing this value's memory (no allocation when the particle
    /// count is the same).
    pub(crate) fn assign(&mut self, other: &ParticleState) {
        self.x.clone_from(&other.x);
        self.v.clone_from(&other.v);
        self.rotation.clone_from(&other.rotation);
    }

    /// [`ParticleState::assign`], each thread of `pool` copying a range of particles when the
    /// particle counts are the same (the copy of a large body is bound by one core's memory
    /// bandwidth).
    pub(crate) fn assign_on(&mut self, other: &ParticleState, pool: &Pool) {
        let n = other.x.len();
        if pool.threads() == 1 || self.x.len() != n {
            return self.assign(other);
        }
        let x = SharedSlice::new(&mut self.x);
        let v = SharedSlice::new(&mut self.v);
        let rotation = SharedSlice::new(&mut self.rotation);
        pool.for_each_range(n, &|range| {
            // SAFETY: the ranges of the shares are disjoint.
            unsafe {
                x.range(range.clone())
                    .copy_from_slice(&other.x[range.clone()]);
                v.range(range.clone())
                    .copy_from_slice(&other.v[range.clone()]);
                rotation
                    .range(range.clone())
                    .copy_from_slice(&other.rotation[range]);
            }
        });
    }
}

/// A deformable body (see the module documentation).
///
/// Data are laid out as flat arrays (one entry per particle, per pair in CSR, per tetrahedron)
/// so that the step streams through memory and allocates nothing.
#[derive(Debug, Clone)]
pub struct Body {
    /// The load-time data, shared with every other body built from the same model.
    pub(crate) model: Arc<BodyModel>,
    /// What the world's settings and the model determine: elastic constants, volume
    /// compliance, inertial masses, stability estimate, with the settings they were derived
    /// under. Re-derived by `World::set_settings` when those change, kept stable by a cut.
    pub(crate) derived: Derived,
    /// Positions, velocities and rotations of the particles: what a step advances.
    pub(crate) state: ParticleState,
    /// Inverse inertial masses (1/kg), 0 for fixed particles.
    pub(crate) inv_mass: Vec<Real>,
    /// Fixed flags.
    pub(crate) fixed: Vec<bool>,
    /// `active_before[i]`: how many of the particles before `i` are not inert (length:
    /// particles + 1). An inert particle is fixed, and so is every one of its neighbours: its
    /// elastic terms act only on fixed particles, whose forces a step does not use, so the
    /// step's force pass skips it (`point_elasticity::ForceInputs::active_before`). Follows the
    /// fixed flags ([`Body::fixed_flags_changed`]).
    pub(crate) active_before: Vec<u32>,
    /// What has been cut, with the load-time data to rebuild from (`None`: never cut).
    pub(crate) cuts: Option<Box<crate::scene::cut::CutState>>,
}

/// Newton iterations of the rotation extraction per particle per substep before the exact SVD
/// fallback (warm-started, they converge in 1–3).
pub(crate) const ROTATION_ITERATIONS: u32 = 6;

impl Body {
    /// A body at rest, nothing fixed, on `model` (shared, not copied), its data derived under
    /// `from`.
    pub(crate) fn from_model(model: Arc<BodyModel>, from: DerivedFrom) -> Body {
        let n = model.particle_count();
        let mut body = Body {
            derived: Derived::new(&model, from),
            state: ParticleState::at_rest(&model.rest),
            inv_mass: vec![0.0; n],
            fixed: vec![false; n],
            active_before: (0..=n as u32).collect(),
            cuts: None,
            model,
        };
        body.update_inverse_masses();
        body
    }

    /// Re-derive the body's data under `from` ([`Derived::rederive`]): nothing when they were
    /// derived under it already.
    pub(crate) fn rederive(&mut self, from: DerivedFrom) {
        if self.derived.rederive(&self.model, from) {
            self.update_inverse_masses();
        }
    }

    /// Check a particle state against [`STATE_POSITION_LIMIT`] and [`STATE_SPEED_LIMIT`]
    /// (and finiteness): the first offending particle, as a message, on failure.
    pub(crate) fn check_state(&self, i: usize, x: &Vec3, v: &Vec3) -> Result<(), String> {
        if !is_finite_vec(x) {
            return Err(format!("particle {i}: non-finite position"));
        }
        if !is_finite_vec(v) {
            return Err(format!("particle {i}: non-finite velocity"));
        }
        let (d, far) = (
            (x - self.model.rest_centre).norm(),
            STATE_POSITION_LIMIT * self.model.size,
        );
        if d > far {
            return Err(format!(
                "particle {i}: position {d:.3e} m from the body's rest centre, beyond the limit \
                 of {far:.3e} m ({STATE_POSITION_LIMIT} body sizes)"
            ));
        }
        let (speed, fast) = (v.norm(), STATE_SPEED_LIMIT * self.model.size);
        if speed > fast {
            return Err(format!(
                "particle {i}: velocity {speed:.3e} m/s above the limit of {fast:.3e} m/s \
                 ({STATE_SPEED_LIMIT} body sizes per second)"
            ));
        }
        Ok(())
    }

    /// Number of particles (= mesh nodes).
    pub fn particle_count(&self) -> usize {
        self.state.x.len()
    }
    /// Which mesh node each particle is. The per-particle slices and indices of this API
    /// (positions, velocities, masses, tetrahedra, fixed flags, [`World::fix_particles`])
    /// are in particle order: the mesh's nodes sorted for memory locality at load time.
    /// [`ParticleOrder::to_mesh_order`] gives any of them in the mesh's order.
    ///
    /// [`World::fix_particles`]: crate::World::fix_particles
    pub fn particle_order(&self) -> &ParticleOrder {
        &self.model.order
    }
    /// Current particle positions (m), one per particle.
    pub fn positions(&self) -> &[Vec3] {
        &self.state.x
    }
    /// Current particle velocities (m/s), one per particle.
    pub fn velocities(&self) -> &[Vec3] {
        &self.state.v
    }
    /// Rest positions (m), one per particle.
    pub fn rest_positions(&self) -> &[Vec3] {
        &self.model.rest
    }
    /// Physical particle masses `ρ v_i` (kg), one per particle: gravity acts on these.
    pub fn masses(&self) -> &[Real] {
        &self.model.mass
    }
    /// Inertial particle masses (kg), one per particle: the physical mass plus the mass added
    /// by [`Settings::mass_scaling`](crate::Settings::mass_scaling). Momentum is
    /// `Σ inertial_mass · v`.
    pub fn inertial_masses(&self) -> &[Real] {
        &self.derived.inertial_mass
    }
    /// Total inertial mass added by mass scaling (kg).
    pub fn added_mass(&self) -> Real {
        self.derived.inertial_mass.iter().sum::<Real>() - self.mass()
    }
    /// Tetrahedra (4 particle indices each).
    pub fn tets(&self) -> &[[u32; 4]] {
        &self.model.tets
    }
    /// Boundary triangles of the tetrahedral mesh (3 particle indices each, outward normals).
    pub fn boundary_triangles(&self) -> &[[u32; 3]] {
        &self.model.boundary
    }
    /// The model this body runs on now: the load-time model, shared with its other holders,
    /// until a cut gives the body its own cut copy. To build the same body elsewhere use
    /// [`Body::load_time_model`].
    pub fn model(&self) -> &Arc<BodyModel> {
        &self.model
    }
    /// The neighbourhoods and their rest-state quantities.
    pub fn neighbourhoods(&self) -> &Neighbourhoods {
        &self.model.nbr
    }
    /// Whether `point` (m, world frame) is inside the body's deformed boundary surface (its
    /// winding number about the point is above one half). Cost: one pass over the boundary
    /// triangles.
    pub fn contains(&self, point: &Vec3) -> bool {
        crate::kernels::collision::winding::inside_surface(
            point,
            &self.state.x,
            &self.model.boundary,
        )
    }
    /// Current volume (m³): the sum of the signed tetrahedron volumes, computed as the volume
    /// the boundary surface encloses (the same sum: the inner faces cancel), a pass over the
    /// boundary triangles instead of the tetrahedra.
    pub fn volume(&self) -> Real {
        volume_of(&self.state.x, &self.model.boundary)
    }
    /// Rest volume (m³).
    pub fn rest_volume(&self) -> Real {
        self.model.rest_volume
    }
    /// `volume() / rest_volume()` (dimensionless).
    pub fn volume_ratio(&self) -> Real {
        self.volume() / self.rest_volume()
    }
    /// Largest distance of a particle from its rest position (m).
    pub fn max_displacement(&self) -> Real {
        self.state
            .x
            .iter()
            .zip(&self.model.rest)
            .map(|(x, r)| (x - r).norm())
            .fold(0.0, Real::max)
    }
    /// True when particle `i` is fixed (false for an index out of range).
    pub fn is_fixed(&self, i: usize) -> bool {
        self.fixed.get(i).copied().unwrap_or(false)
    }
    /// Contact radius of the particles (m).
    pub fn particle_radius(&self) -> Real {
        self.model.particle_radius
    }
    /// Thickness of the contact skin over the boundary surface (m): tools in the exact-shape
    /// contact mode touch the surface this far out of it (a tenth of the particle radius).
    pub fn contact_skin(&self) -> Real {
        crate::scene::particles::SURFACE_SKIN * self.model.particle_radius
    }
    /// Total mass (kg).
    pub fn mass(&self) -> Real {
        self.model.mass.iter().sum()
    }
    /// The elastic model in force: Lamé parameters of the particle stress (λ is 0 when the
    /// volumetric split moves it into the volume constraints), hourglass and damping terms.
    pub fn elastic_model(&self) -> &ElasticModel {
        &self.derived.elastic
    }
    /// The material.
    pub fn material(&self) -> &Material {
        &self.model.options.material
    }
    /// Largest angular frequency (rad/s) of the body's linearised elastic vibrations at rest,
    /// the quantity that sets the explicit stability limit `2/ω_max` of a substep.
    pub fn max_angular_frequency(&self) -> Real {
        self.derived.omega_max
    }

    /// Deformation gradient of particle `i` if the particles were at `positions` (m).
    pub fn deformation_gradient_at(&self, positions: &[Vec3], i: usize) -> Mat3 {
        point_elasticity::deformation_gradient(&self.model.nbr, positions, i)
    }

    /// Elastic (and hourglass) forces (N) on every particle if the particles were at
    /// `positions` (m) with zero velocity, from the elasticity of the world's
    /// `Settings::elastic_scheme`; an analysis helper that allocates.
    pub fn elastic_forces_at(&self, positions: &[Vec3]) -> Vec<Vec3> {
        self.derived.elastic_forces_at(&self.model, positions)
    }

    /// The inverse inertial masses from the inertial masses and the fixed flags.
    pub(crate) fn update_inverse_masses(&mut self) {
        for i in 0..self.state.x.len() {
            self.inv_mass[i] = if self.fixed[i] {
                0.0
            } else {
                1.0 / self.derived.inertial_mass[i]
            };
        }
    }

    /// Mark the `particles` fixed: zero velocity, and what follows from the fixed flags.
    pub(crate) fn fix(&mut self, particles: impl IntoIterator<Item = usize>) {
        for i in particles {
            self.fixed[i] = true;
            self.state.v[i] = Vec3::zeros();
        }
        self.fixed_flags_changed();
    }

    /// Recompute what follows from the fixed flags: the inverse masses and the inert particles.
    /// A cut leaves the neighbour lists as they were (it zeroes a cut pair's data), so the
    /// inert particles depend on the fixed flags alone.
    pub(crate) fn fixed_flags_changed(&mut self) {
        self.update_inverse_masses();
        point_elasticity::count_active(&self.model.nbr, &self.fixed, &mut self.active_before);
    }
}

/// Volume (m³) enclosed by the closed `boundary` (outward triangles) at positions `x`: the sum
/// of the signed volumes of the tetrahedra it bounds. The triangles are summed in
/// [`VOLUME_RUNS`] runs of near-equal length, each in order, then the runs' sums in order: the
/// order [`volume_on`] keeps on any number of threads.
pub(crate) fn volume_of(x: &[Vec3], boundary: &[[u32; 3]]) -> Real {
    (0..VOLUME_RUNS).map(|k| volume_run(x, boundary, k)).sum()
}

/// [`volume_of`] with its runs shared among the threads of `pool`: the same bits.
pub(crate) fn volume_on(pool: &Pool, x: &[Vec3], boundary: &[[u32; 3]]) -> Real {
    let mut runs = [0.0; VOLUME_RUNS];
    let shared = SharedSlice::new(&mut runs);
    pool.run(&|share| {
        let mine = pool.share(share, VOLUME_RUNS);
        // SAFETY: the shares' ranges of runs are disjoint.
        let out = unsafe { shared.range(mine.clone()) };
        for (sum, k) in out.iter_mut().zip(mine) {
            *sum = volume_run(x, boundary, k);
        }
    });
    runs.iter().sum()
}

/// Runs of boundary triangles in a volume sum: enough for any thread count a world takes.
const VOLUME_RUNS: usize = crate::scene::settings::MAX_THREADS;

/// Run `k` of the volume sum of [`volume_of`] (m³): the signed volumes of the tetrahedra its
/// triangles span with a point of the surface, four triangles a lane (the last ones of the run
/// scalar), the lanes then the scalar ones summed in order, divided by six once.
fn volume_run(x: &[Vec3], boundary: &[[u32; 3]], k: usize) -> Real {
    let Some(&[o, ..]) = boundary.first() else {
        return 0.0;
    };
    // The divergence theorem about a point of the surface (small terms, little cancellation).
    let o = x[o as usize];
    let n = boundary.len();
    let run = &boundary[k * n / VOLUME_RUNS..(k + 1) * n / VOLUME_RUNS];
    let (quads, tail) = run.as_chunks::<LANES>();
    let mut lanes = F4::splat(0.0);
    let o4 = V4::splat(&o);
    for [t0, t1, t2, t3] in quads {
        // The corners `c` of the four triangles, relative to o.
        let corner = |c: usize| {
            let at = |t: &[u32; 3]| &x[t[c] as usize];
            V4::from_refs([at(t0), at(t1), at(t2), at(t3)]) - o4
        };
        lanes += corner(0).cross(&corner(1)).dot(&corner(2));
    }
    let tail: Real = tail
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|k| x[k as usize] - o);
            a.cross(&b).dot(&c)
        })
        .sum();
    (lanes.sum() + tail) / 6.0
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The volume sum on the pool gives the bits of the one on the calling thread, for
    /// boundaries shorter and longer than the number of runs.
    #[test]
    fn the_volume_on_the_pool_has_the_bits_of_the_serial_one() {
        let x: Vec<Vec3> = (0..50)
            .map(|i| {
                let t = i as Real * 0.7;
                Vec3::new(t.sin(), (1.3 * t).cos(), 0.01 * t * t)
            })
            .collect();
        for triangles in [0, 1, 17, 64, 65, 1000] {
            let boundary: Vec<[u32; 3]> = (0..triangles)
                .map(|t| [t % 50, (7 * t + 3) % 50, (13 * t + 11) % 50])
                .collect();
            let serial = volume_of(&x, &boundary);
            assert!(triangles < 2 || serial != 0.0);
            for threads in [1, 2, 3] {
                let pooled = volume_on(&Pool::new(threads), &x, &boundary);
                assert_eq!(pooled.to_bits(), serial.to_bits(), "{triangles} triangles");
            }
        }
    }
}
