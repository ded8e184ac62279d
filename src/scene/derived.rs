//! Everything a body derives from the world's settings and its model, in one place: the
//! elastic constants under the settings (hourglass and damping terms, λ split between the
//! elastic model and the volume constraints), the effective compliance of the volume
//! constraints, the explicit stability estimate and the inertial masses of the selective mass
//! scaling.
//!
//! [`DerivedFrom`] is exactly the part of the [`Settings`] these depend on, taken by one
//! function ([`DerivedFrom::settings`]). The derivation is handed only that value, so it cannot
//! read a setting outside it: the compiler keeps the list of "settings that affect bodies"
//! honest. `World::set_settings` re-derives a body iff the value changed, in two levels:
//!
//! - [`ElasticSettings`]: the elastic model and the compliance. The stability estimate with the
//!   physical masses depends on the model, the elastic model and the elastic scheme alone; it is
//!   kept while they stay the same (a new volume compliance does not redo it).
//! - [`MassScalingSettings`]: the inertial masses for substeps of `dt / min_substeps`, from the
//!   kept estimate. A new time step (an FMU master varying its step) redoes only this, and no
//!   power iteration unless the body needs mass scaling at the new step.
//!
//! A cut changes the model under the derived data; [`Derived::restabilise`] keeps the step
//! stable on the new topology with the same stiffness and estimate functions.
//!
//! The solver and the settle read the schemes and flags from the scene's settings; a reader
//! that has only a body (its public helpers, the linear statics) reads [`Derived::from`], the
//! settings the body was derived under, which are the world's.

use crate::kernels::math::{Quat, Real, Vec3};
use crate::kernels::parallel::Pool;
use crate::kernels::point_elasticity::{self as elastic, ElasticModel, ForceInputs};
use crate::kernels::stability;
use crate::kernels::tet_elasticity::{self, TetForceInputs};
use crate::model::body_model::BodyModel;
use crate::scene::settings::{ElasticScheme, Settings, VolumeScheme};

/// The settings a body's elastic constants and volume compliance derive from (the fields of
/// [`Settings`] of the same names).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct ElasticSettings {
    /// Hourglass-control stiffness (dimensionless, times μ).
    pub(crate) hourglass_stiffness: Real,
    /// Stiffness-proportional damping time β (s).
    pub(crate) damping_stiffness: Real,
    /// Whether the volume constraints are projected.
    pub(crate) volume_constraints: bool,
    /// Whether λ moves from the elastic model into the volume constraints.
    pub(crate) volumetric_split: bool,
    /// Compliance of the volume constraints per unit volume (1/Pa), before the split's `1/λ`.
    pub(crate) volume_compliance: Real,
    /// What each volume constraint keeps.
    pub(crate) volume_scheme: VolumeScheme,
    /// What carries the elasticity.
    pub(crate) elastic_scheme: ElasticScheme,
}

/// The settings the mass scaling derives from (the fields of [`Settings`] of the same names).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct MassScalingSettings {
    /// Whether particles get extra inertial mass until the body is stable at `dt / min_substeps`.
    pub(crate) mass_scaling: bool,
    /// Time step (s).
    pub(crate) dt: Real,
    /// Smallest number of substeps per step.
    pub(crate) min_substeps: u32,
    /// Largest number of substeps per step: the most the budget may ask for.
    pub(crate) max_substeps: u32,
    /// Fraction of the stability limit `2/ω_max` a substep may use (dimensionless).
    pub(crate) stability_margin: Real,
}

/// Exactly the settings a body's derived data depend on (see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct DerivedFrom {
    /// What the elastic constants, the volume compliance and the physical estimate depend on.
    pub(crate) elastic: ElasticSettings,
    /// What the inertial masses depend on, besides the elastic level.
    pub(crate) mass_scaling: MassScalingSettings,
}

impl DerivedFrom {
    /// The part of `settings` a body's derived data depend on.
    pub(crate) fn settings(settings: &Settings) -> DerivedFrom {
        DerivedFrom {
            elastic: ElasticSettings {
                hourglass_stiffness: settings.hourglass_stiffness,
                damping_stiffness: settings.damping_stiffness,
                volume_constraints: settings.volume_constraints,
                volumetric_split: settings.volumetric_split,
                volume_compliance: settings.volume_compliance,
                volume_scheme: settings.volume_scheme,
                elastic_scheme: settings.elastic_scheme,
            },
            mass_scaling: MassScalingSettings {
                mass_scaling: settings.mass_scaling,
                dt: settings.dt,
                min_substeps: settings.min_substeps,
                max_substeps: settings.max_substeps,
                stability_margin: settings.stability_margin,
            },
        }
    }
}

/// The most volumetric stiffness λ/μ (dimensionless) that corotated tetrahedra keep in their
/// stress when the dual cells carry the volume (`ElasticScheme::Tetrahedra` with
/// `VolumeScheme::DualCells`): 1.5, a material of ν = 0.3 (λ/μ = 2ν/(1 - 2ν)). Up to it linear
/// tetrahedra do not lock (their static error at ν 0.3 is that of the mesh); the dual cells
/// alone are too soft there (their nodal volumes have spurious modes the tetrahedra
/// suppress). Above it the dual cells carry the rest, so nearly incompressible tissue does not
/// lock. Measured on eight organ meshes against FEM references in docs/VALIDATION.md.
pub(crate) const TETRAHEDRON_LAMBDA_OVER_MU: Real = 1.5;

/// Most mass (a fraction of the body's, dimensionless) the selective mass scaling may add to a
/// body. Mass scaling exists for the few tiny particles of graded meshes (liver_4k at E 5 kPa:
/// 5.6% of its mass, the default organ none); a stiff body whose stability needs more (a 100 kPa
/// block on corotated tetrahedra needed four times its mass) takes substeps instead, so that no
/// body moves as if it were more than 10% heavier than it is (a block on a slope slides at the
/// kinetic-friction acceleration: `tests/contact_tools_and_organs.rs`). A body that even
/// `max_substeps` would not keep within it (the slivers of a poor mesh) gets the scaling it needs
/// at `min_substeps`, as without the budget.
pub(crate) const MASS_SCALING_BUDGET: Real = 0.1;

/// Most substep counts whose full mass scaling (power iterations) is tried against the budget.
const MASS_SCALING_TRIES: usize = 3;

/// A body's data derived from its model and [`DerivedFrom`] (and, after a cut, from its cut
/// record: [`Derived::restabilise`]).
#[derive(Debug, Clone)]
pub(crate) struct Derived {
    /// The settings it was derived under: the world's.
    pub(crate) from: DerivedFrom,
    /// The elastic constants: Lamé parameters of the elastic stress (λ reduced or 0 under the
    /// volumetric split), hourglass and damping terms.
    pub(crate) elastic: ElasticModel,
    /// Compliance of the volume constraints per unit rest volume (1/Pa), the split's `1/λ`
    /// included; ∞ (ν = 0 under the split) disables them.
    pub(crate) volume_compliance: Real,
    /// Inertial masses (kg): the physical masses plus any mass scaling.
    pub(crate) inertial_mass: Vec<Real>,
    /// Largest angular frequency of the linearised elastic system at rest with the inertial
    /// masses (rad/s).
    pub(crate) omega_max: Real,
    /// The same with the physical masses, once estimated: it depends on the model, the elastic
    /// constants and the elastic scheme alone, so a new time step does not estimate it again.
    /// A cut forgets it.
    omega_physical: Option<Real>,
}

impl Derived {
    /// The data of `model` under `from`.
    pub(crate) fn new(model: &BodyModel, from: DerivedFrom) -> Derived {
        let (elastic, volume_compliance) = elastic_constants(model, &from.elastic);
        let mut derived = Derived {
            from,
            elastic,
            volume_compliance,
            inertial_mass: model.mass.clone(),
            omega_max: 0.0,
            omega_physical: None,
        };
        derived.scale_masses(model);
        derived
    }

    /// Re-derive under `from`: nothing when it is what the data were derived under; only the
    /// damping time when nothing else changed; the elastic level when that changed (the physical estimate only if the elastic constants or
    /// the scheme changed), then the mass scaling. Returns whether the inertial masses were
    /// recomputed (the caller's inverse masses follow them).
    pub(crate) fn rederive(&mut self, model: &BodyModel, from: DerivedFrom) -> bool {
        if from == self.from {
            return false;
        }
        // The stiffness-proportional damping filters velocities only: neither the stability
        // estimate nor the inertial masses depend on it.
        let mut damped = self.from;
        damped.elastic.damping_stiffness = from.elastic.damping_stiffness;
        if from == damped {
            self.from = from;
            self.elastic.damping_stiffness = from.elastic.damping_stiffness;
            return false;
        }
        if from.elastic != self.from.elastic {
            let (elastic, volume_compliance) = elastic_constants(model, &from.elastic);
            let scheme = from.elastic.elastic_scheme;
            if (elastic, scheme) != (self.elastic, self.from.elastic.elastic_scheme) {
                self.omega_physical = None;
            }
            self.elastic = elastic;
            self.volume_compliance = volume_compliance;
        }
        self.from = from;
        self.scale_masses(model);
        true
    }

    /// The mass level: the physical masses, the estimate with them (kept if known), and with
    /// mass scaling the inertial masses that make the body stable at `dt / min_substeps` with
    /// the stability margin — unless they add more than [`MASS_SCALING_BUDGET`], when the
    /// physical masses stay and the step takes the substeps they need.
    fn scale_masses(&mut self, model: &BodyModel) {
        self.inertial_mass.copy_from_slice(&model.mass);
        let omega = match self.omega_physical {
            Some(omega) => omega,
            None => self.estimate(model),
        };
        self.omega_physical = Some(omega);
        self.omega_max = omega;
        let s = self.from.mass_scaling;
        if !s.mass_scaling {
            return;
        }
        // The target of `n` substeps a step; `n` from `min_substeps` up to `max_substeps` until
        // the scaling stays within the budget (or none is needed).
        let target = |n: u32| 2.0 * s.stability_margin * n as Real / s.dt;
        let mut n = s.min_substeps;
        if omega <= target(n) {
            return;
        }
        let stiffness = self.diagonal_stiffness(model);
        let total: Real = model.mass.iter().sum();
        // The first round's masses (factor 2) are a lower bound of the scaling's: skip the
        // substep counts where even they exceed the budget.
        let first_round = |n: u32| -> Real {
            let t2 = target(n) * target(n);
            let added = stiffness.iter().zip(&model.mass);
            added.map(|(k, m)| (2.0 * k / t2 - m).max(0.0)).sum()
        };
        for _ in 0..MASS_SCALING_TRIES {
            while n < s.max_substeps
                && omega > target(n)
                && first_round(n) > MASS_SCALING_BUDGET * total
            {
                n += 1;
            }
            if omega <= target(n) {
                self.inertial_mass.copy_from_slice(&model.mass);
                self.omega_max = omega;
                return;
            }
            if n == s.max_substeps && first_round(n) > MASS_SCALING_BUDGET * total {
                break;
            }
            self.scale_to(model, &stiffness, target(n));
            if !self.over_budget(model) {
                return;
            }
            if n == s.max_substeps {
                break;
            }
            n += 1;
        }
        // Not within the budget up to `max_substeps` (the slivers of a poor mesh): the scaling
        // the body needs at `min_substeps`, as without the budget.
        self.scale_to(model, &stiffness, target(s.min_substeps));
    }

    /// Raise the inertial masses until the estimate is at most `omega_target` (rad/s) (a few
    /// rounds at most), from the particles' diagonal `stiffness` (N/m).
    fn scale_to(&mut self, model: &BodyModel, stiffness: &[Real], omega_target: Real) {
        self.inertial_mass.copy_from_slice(&model.mass);
        self.omega_max = self.omega_physical.unwrap_or(Real::INFINITY);
        // Local frequency ω_i² ≈ factor · k_ii / m_i; the factor starts at Gershgorin's 2 and
        // grows until the power iteration confirms the target (a few rounds at most).
        let mut factor = 2.0;
        for _ in 0..4 {
            if self.omega_max <= omega_target {
                break;
            }
            for ((mi, m0), k) in self
                .inertial_mass
                .iter_mut()
                .zip(&model.mass)
                .zip(stiffness)
            {
                *mi = m0.max(factor * k / (omega_target * omega_target));
            }
            self.omega_max = self.estimate(model);
            factor *= (self.omega_max / omega_target).powi(2).max(1.1);
        }
    }

    /// Whether the inertial masses add more than [`MASS_SCALING_BUDGET`] of `model`'s mass.
    fn over_budget(&self, model: &BodyModel) -> bool {
        let physical: Real = model.mass.iter().sum();
        let inertial: Real = self.inertial_mass.iter().sum();
        inertial - physical > MASS_SCALING_BUDGET * physical
    }

    /// The estimate of `ω_max` (rad/s) of `model` under these elastic constants with the
    /// current inertial masses.
    fn estimate(&self, model: &BodyModel) -> Real {
        stability::max_angular_frequency(&model.rest, &self.inertial_mass, |x| {
            self.elastic_forces_at(model, x)
        })
    }

    /// What [`Derived::restabilise`] keeps from before a body's first cut: the inertial
    /// masses (kg) and diagonal stiffnesses (N/m) of its particles.
    pub(crate) fn stability_base(&self, model: &BodyModel) -> StabilityBase {
        StabilityBase {
            inertial_mass: self.inertial_mass.clone(),
            stiffness: self.diagonal_stiffness(model),
        }
    }

    /// Keep the step stable after `model`'s topology changed (a cut, or a restored cut set).
    /// With mass scaling at `base` (inertial masses above the physical ones), a particle whose
    /// diagonal stiffness rose above its `base` value gets its `base` inertial mass scaled by
    /// the same factor, so its local frequency stays where mass scaling put it; a function of
    /// the current topology only, so restoring a state reproduces it. Without, or when that
    /// adds more than [`MASS_SCALING_BUDGET`], the physical masses and `ω_max` estimated anew. Either way the estimate with the physical masses, which the new topology
    /// changes, is forgotten. The caller's inverse masses follow the inertial masses.
    pub(crate) fn restabilise(&mut self, model: &BodyModel, base: &StabilityBase) {
        self.omega_physical = None;
        let scaled = base
            .inertial_mass
            .iter()
            .zip(&model.mass)
            .any(|(mi, m)| mi > m);
        if scaled {
            let now = self.diagonal_stiffness(model);
            let base = base.inertial_mass.iter().zip(&base.stiffness);
            for ((mi, (m0, k0)), k) in self.inertial_mass.iter_mut().zip(base).zip(&now) {
                let ratio = if *k0 > 0.0 { (k / k0).max(1.0) } else { 1.0 };
                *mi = m0 * ratio;
            }
            if !self.over_budget(model) {
                return;
            }
            self.inertial_mass.copy_from_slice(&model.mass);
        }
        self.omega_max = self.estimate(model);
    }

    /// Elastic (and hourglass) forces (N) on every particle of `model` if its particles were at
    /// `positions` (m) with zero velocity, under these elastic constants and scheme; allocates.
    pub(crate) fn elastic_forces_at(&self, model: &BodyModel, positions: &[Vec3]) -> Vec<Vec3> {
        let n = model.particle_count();
        let mut force = vec![Vec3::zeros(); n];
        if self.from.elastic.elastic_scheme == ElasticScheme::Tetrahedra {
            let input = TetForceInputs {
                elements: &model.tet_elements,
                x: positions,
                fixed: &[],
            };
            // One thread needs no shares.
            tet_elasticity::accumulate_forces(
                &self.elastic,
                &input,
                &mut tet_elasticity::TetShares::default(),
                &mut [],
                &mut force,
                &Pool::new(1),
            );
            return force;
        }
        let mut rotation = vec![Quat::identity(); n];
        // One thread keeps no pair forces.
        let (mut pair_force, mut own_force) = (Vec::new(), Vec::new());
        let input = ForceInputs {
            nbr: &model.nbr,
            volume: &model.particle_volume,
            x: positions,
            active_before: &[],
        };
        elastic::accumulate_forces(
            &self.elastic,
            &input,
            &mut rotation,
            50,
            &mut pair_force,
            &mut own_force,
            &mut force,
            &Pool::new(1),
        );
        force
    }

    /// An estimate (N/m) of each particle's diagonal stiffness at rest: the elastic terms of
    /// the pairs it belongs to (as neighbour and as centre) plus their hourglass terms, or
    /// those of the tetrahedra around it.
    fn diagonal_stiffness(&self, model: &BodyModel) -> Vec<Real> {
        let pwave = self.elastic.p_wave_modulus();
        let mut k = vec![0.0; model.particle_count()];
        if self.from.elastic.elastic_scheme == ElasticScheme::Tetrahedra {
            tet_elasticity::add_diagonal_stiffness(&self.elastic, &model.tet_elements, &mut k);
            return k;
        }
        let nbr = &model.nbr;
        for (i, vi) in model.particle_volume.iter().enumerate() {
            let mut dsum = Vec3::zeros();
            for e in nbr.range(i) {
                let j = nbr.index[e] as usize;
                let d = nbr.gradient.get(e);
                let hg = self.elastic.hourglass * vi * nbr.hourglass_weight[e];
                k[j] += pwave * vi * d.norm_squared() + hg;
                k[i] += hg;
                dsum += d;
            }
            k[i] += pwave * vi * dsum.norm_squared();
        }
        k
    }
}

/// The inertial masses (kg) and diagonal stiffnesses (N/m) of a body's particles before its
/// first cut, which [`Derived::restabilise`] scales from.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct StabilityBase {
    inertial_mass: Vec<Real>,
    stiffness: Vec<Real>,
}

/// The elastic constants of `model`'s material under `s`, and the compliance of the volume
/// constraints per unit volume (1/Pa): under the volumetric split the constraints take λ (or,
/// for tetrahedra under dual cells, what exceeds [`TETRAHEDRON_LAMBDA_OVER_MU`]).
fn elastic_constants(model: &BodyModel, s: &ElasticSettings) -> (ElasticModel, Real) {
    let m = model.options.material;
    let mut elastic = ElasticModel::new(
        m.youngs_modulus,
        m.poisson_ratio,
        s.hourglass_stiffness,
        s.damping_stiffness,
    );
    let mut volume_compliance = s.volume_compliance;
    if s.volume_constraints && s.volumetric_split {
        // Tetrahedra under dual cells keep the volumetric stiffness they carry without
        // locking; the dual cells take the rest (all of it for the other schemes).
        let kept = match (s.elastic_scheme, s.volume_scheme) {
            (ElasticScheme::Tetrahedra, VolumeScheme::DualCells) => {
                elastic.lambda.min(TETRAHEDRON_LAMBDA_OVER_MU * elastic.mu)
            }
            _ => 0.0,
        };
        volume_compliance += 1.0 / (elastic.lambda - kept);
        elastic.lambda = kept;
    }
    (elastic, volume_compliance)
}
