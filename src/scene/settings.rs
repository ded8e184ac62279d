//! The world's settings: one plain struct, every field in SI units, with a [`Default`] suited to
//! an organ of ~0.2 m stepped at 1 kHz.

use crate::kernels::math::{Real, Vec3};

/// The most threads a world's step runs on ([`Settings::threads`]).
pub(crate) const MAX_THREADS: usize = 64;

/// How tool–tissue contact is detected.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ContactMode {
    /// The tool's exact shape against the body's deformed boundary triangles (GJK), the
    /// correction spread over each triangle's particles by barycentric weights, one-sided and
    /// swept so that a tool thinner than the particle spacing neither slips between particles
    /// nor tunnels. Contact starts a skin of a tenth of the particle radius out from the
    /// surface. The default.
    ExactShape,
    /// The paper's mode: the tool surface sampled into points, each a sphere of radius equal to
    /// the sample spacing; particles (spheres of the particle radius) are pushed out of those
    /// spheres. Tools thinner than the particle spacing can slip between particles.
    SampledPoints,
}

/// What carries the elasticity (with the volume constraints on and split, its shear part).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ElasticScheme {
    /// The paper's point-based elasticity: a moving-least-squares deformation gradient per
    /// particle, nodal integration with hourglass control (`crate::kernels::point_elasticity`).
    /// Selectable; too soft by 14–24% on coarse meshes at ν 0.3 (docs/VALIDATION.md).
    PointBased,
    /// Corotated linear tetrahedra: one deformation gradient and rotation per tetrahedron of
    /// the mesh, the same corotated stress (`crate::kernels::tet_elasticity`); no zero-energy
    /// modes, so no hourglass control. The particles stay the unknowns; contact, volume
    /// constraints and everything else are unchanged. With the volume constraints on, a crush
    /// guard keeps every tetrahedron above a tenth of its rest volume (a hard one-sided
    /// constraint, inactive above it), so that inverted tetrahedra come back. The default:
    /// with [`VolumeScheme::DualCells`] the tetrahedra keep the volumetric stiffness up to
    /// λ = 1.5 μ (ν 0.3's, where they do not lock) and the dual cells take the rest.
    Tetrahedra,
}

/// What one volume constraint keeps (with [`Settings::volume_constraints`] on).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum VolumeScheme {
    /// One constraint per tetrahedron (eq. 13 of the paper): about six constraints per
    /// particle's three unknowns, so nearly incompressible tissue locks as linear tetrahedra do
    /// (docs/VALIDATION.md). Selectable (the paper's method, with `ElasticScheme::PointBased`).
    Tetrahedra,
    /// One constraint per particle, on its dual cell (a quarter of each tetrahedron around
    /// it): does not lock as ν → 0.5 (at ν 0.49 a quarter to a half of linear tetrahedra's
    /// static error on the measured meshes, against nearly all of it per tetrahedron).
    /// Projected colour by colour on the thread pool (no two cells of a colour share a
    /// particle: 31 colours on liver_4k, 26 on the default organ), the same bits on any thread
    /// count. The default, with `ElasticScheme::Tetrahedra`: below linear tetrahedra's static
    /// error from ν 0.45 up on every measured mesh (with the particles' shear it is too soft at
    /// ν ≤ 0.45).
    DualCells,
}

/// Parameters of the time integration and of the constraint projection.
///
/// Modelled after rapier's `IntegrationParameters`: plain data, `Default`, units on every field.
#[derive(Debug, Clone, PartialEq)]
pub struct Settings {
    /// Time step of one call to [`World::step`](crate::World::step) (s).
    pub dt: Real,
    /// Gravity acceleration (m/s²).
    pub gravity: Vec3,
    /// Smallest number of substeps per step (≥ 1). The world adds substeps when the explicit
    /// elastic step would be unstable (see [`Settings::stability_margin`]).
    pub min_substeps: u32,
    /// Smallest number of substeps (≥ 1) of a step that starts with the tissue at a tool
    /// compressed: a tetrahedron with a corner within a particle radius of a tool's bounding box
    /// below half its rest volume, now or two steps ahead at its corners' velocities. Applies
    /// with the elasticity on tetrahedra and the volume constraints on (where the crush guard
    /// runs).
    /// 1 (the default) adds none; where the tool is narrower than a compressed tetrahedron's
    /// longest rest edge the step takes twice its substeps whatever this setting (the
    /// narrower tool presses on a corner or an edge: small probes pressed deep stay out of the
    /// tissue). 2 keeps wide probes pressed deep out too (a 1 cm probe 20 cm into the default
    /// organ) at twice the cost of the steps that compress the tissue, which in a deep press
    /// is most of them (docs/SETTINGS.md, "Deep presses"). The check costs a distance per
    /// particle each step while a sphere, capsule, cylinder or box tool is in the world (any
    /// tool when the setting is above 1).
    pub crushed_substeps: u32,
    /// Largest number of substeps per step; a step that needs more is reported
    /// (`StepReport::substeps_clamped`) and runs with this many.
    pub max_substeps: u32,
    /// Fraction (0, 1] of the explicit stability limit `2/ω_max` that a substep may use.
    pub stability_margin: Real,
    /// Selective mass scaling: particles whose own stable time step is shorter than
    /// `dt / min_substeps` (tiny boundary particles of graded meshes) get extra inertial mass so
    /// that the step needs no extra substeps. Gravity still acts on the physical mass, so static
    /// equilibria and contact forces at rest are unchanged; the added mass is reported by
    /// [`Body::added_mass`](crate::Body::added_mass). It adds at most 10% of a body's mass: a
    /// body that would need more (a stiff material, E ≳ 100 kPa at dt = 1 ms) gets substeps
    /// instead, as many as keep the scaling within that.
    pub mass_scaling: bool,
    /// Mass-proportional (ambient) damping rate α (1/s): each substep of length `h` (s) scales
    /// particle velocities by `1/(1 + α·h)`. Models the viscous surroundings of an organ; damps rigid motion too.
    pub damping_mass: Real,
    /// Stiffness-proportional damping time β (s; default 0.3 ms, 0 for none; docs/SETTINGS.md,
    /// docs/VALIDATION.md for how soon a struck organ comes to rest): a dashpot along each mesh
    /// edge with coefficient β·k_ij (k_ij the edge's share of the tetrahedra's stiffness, N/m),
    /// for both elastic schemes. Central and zero under rigid motion, so momentum is conserved.
    /// Solved implicitly (one Jacobi step on each substep's kicked velocities,
    /// `crate::kernels::tet_dashpots`): any β is stable and adds no substeps.
    pub damping_stiffness: Real,
    /// Hourglass-control stiffness (dimensionless, multiplies the shear modulus μ): penalises
    /// the part of each pair's deformation that the particle's deformation gradient does not
    /// explain (in the spirit of Ganzenmüller 2015; the form in
    /// `crate::kernels::point_elasticity`), which suppresses the zero-energy modes of nodal
    /// integration. Zero for every affine motion, so it never affects the patch test. The
    /// default 0.25 comes from the static study of docs/VALIDATION.md: with the volume
    /// constraints on, the worst error against FEM over two livers and a beam is flat for
    /// 0.13–0.5 and grows outside it; with the particles carrying λ, 1.0 minimises it.
    pub hourglass_stiffness: Real,
    /// Enable the XPBD volume constraints (eq. 13 of the paper; what each keeps is
    /// [`Settings::volume_scheme`]). With them (the default) the volumetric stiffness λ is
    /// handled implicitly by XPBD, robust under contact and for nearly incompressible tissue.
    /// Without them the elasticity carries all of λ explicitly: the paper's particles then do
    /// not lock (docs/VALIDATION.md) but need more added mass and settle slowly after a tool
    /// jump; on the tetrahedra it is linear tetrahedra's locking response, and their stiff
    /// explicit bulk term grew unstable under large deformation at the default
    /// `stability_margin` in our runs (0.5 held). For static studies, not interactive scenes.
    pub volume_constraints: bool,
    /// With volume constraints on: the volumetric (λ) term leaves the particle stress and the
    /// tetrahedron volume constraints carry it, with compliance `1/λ` per unit volume (plus
    /// [`Settings::volume_compliance`]). The particles keep the shear part `2μ (F - R)`. The
    /// linear response is the material's own; the stiff volumetric response of nearly
    /// incompressible tissue (ν → 0.5) is handled implicitly by XPBD instead of limiting the
    /// explicit step; constraints and stress never fight each other. `false` gives the paper's
    /// literal arrangement: the full corotated stress on the particles plus volume constraints
    /// of compliance `volume_compliance` on top (0 = hard, which over-constrains a tetrahedral
    /// mesh: more tetrahedra than degrees of freedom).
    pub volumetric_split: bool,
    /// What each volume constraint keeps: a particle's dual cell (the default: about one
    /// constraint per particle, which does not lock as ν → 0.5) or a tetrahedron's volume (the
    /// paper's: about six constraints per particle, locking like linear tetrahedra).
    pub volume_scheme: VolumeScheme,
    /// What carries the elasticity: corotated linear tetrahedra (the default: with dual cells,
    /// at most linear tetrahedra's static error at every ν and half of it or less from
    /// ν 0.49 up, docs/VALIDATION.md) or the paper's point-based particles (MLS deformation
    /// gradients, 1.5–5× linear tetrahedra's error at ν 0.3 on the measured organs).
    pub elastic_scheme: ElasticScheme,
    /// Compliance (1/Pa, per unit volume) the volume constraints get in addition to `1/λ`
    /// under the split, or in total without it (0 = hard constraints).
    pub volume_compliance: Real,
    /// Gauss–Seidel iterations over all constraints per substep.
    pub iterations: u32,
    /// How tool–tissue contact is detected.
    pub contact_mode: ContactMode,
    /// Largest speed (m/s) at which a tool contact removes a penetration that was already
    /// there at the start of a substep: after a contact correction, a particle (or a surface
    /// triangle's contact point) moves along the contact normal in that substep by at most the
    /// tool's own motion along it plus `max_depenetration_speed · h`. A tool that jumps into
    /// the tissue (a haptic glitch, see [`World::tool_jump_speed`](crate::World::tool_jump_speed))
    /// is left by the particles gently over the following steps instead of flinging them out
    /// (PhysX's `maxDepenetrationVelocity`), while the tool pushes the tissue at its own speed
    /// and tissue that moves into a tool is stopped whole.
    pub max_depenetration_speed: Real,
    /// Surface self-contact (off by default, see docs/SETTINGS.md): each body's boundary
    /// vertices are kept a skin of half a particle radius in front of the body's other boundary
    /// triangles (one-sided, with the body's own pair friction, see
    /// [`World::set_body_pair_friction`](crate::World::set_body_pair_friction)), so that folds,
    /// a dent closing on itself and the faces of a cut do not pass through each other. The
    /// triangles around a vertex and pairs closer than the skin at rest are not in contact.
    /// Off, a body passes through itself.
    pub self_contact: bool,
    /// Threads a step runs on (≥ 1): the calling thread plus `threads - 1` workers owned by
    /// the world, sharing the force, volume, prediction and update passes (tool contacts stay
    /// on the calling thread). Results are bit-identical for any count.
    /// Default 1: a haptic loop usually owns one core; set 2 on a machine with a free core.
    pub threads: u32,
    /// Physical bounds checked after every step: a step that leaves them is rolled back and
    /// reported as [`Error::Diverged`](crate::Error::Diverged), like a non-finite one.
    pub divergence: DivergenceLimits,
}

/// Bounds beyond which a step counts as diverged (a finite explosion: the solver gained
/// energy, the tissue turned inside out or flew apart), checked on every body after every
/// step in O(particles + boundary triangles). Each is relative to the body's rest size (the diagonal
/// of its rest bounding box), so one setting fits a 2 cm lobe and a 30 cm liver; set a field
/// to infinity (or the volume range to (0, ∞)) to switch that check off. The extent and volume
/// bounds fail a step only when it moves the body farther out of them, so that a body set into
/// an inverted or flattened state recovers.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DivergenceLimits {
    /// Largest particle speed, in body sizes per second (1/s). Default 250: 50 m/s for a
    /// 0.2 m organ, 25× the fastest instrument motion of a trainer (2 m/s) and far above what
    /// tissue pushed by it reaches; an explosion passes it within a step or two.
    pub max_speed: Real,
    /// Largest extent of a body (the diagonal of its deformed bounding box) over its rest
    /// size (dimensionless). Default 10: a body stretched to ten times its size has flown
    /// apart; rigid motion and free fall leave the extent unchanged.
    pub max_extent_ratio: Real,
    /// Accepted range of a body's volume over its rest volume (dimensionless, signed volume of
    /// its tetrahedra). Default [0.1, 10]: tissue under a press keeps its volume within a few
    /// per cent (ν ≥ 0.3), so leaving this range means inverted or exploded tetrahedra.
    pub volume_ratio: (Real, Real),
}

impl Default for DivergenceLimits {
    fn default() -> Self {
        DivergenceLimits {
            max_speed: 250.0,
            max_extent_ratio: 10.0,
            volume_ratio: (0.1, 10.0),
        }
    }
}

impl Default for Settings {
    fn default() -> Self {
        Settings {
            dt: 1.0e-3,
            gravity: Vec3::new(0.0, -9.81, 0.0),
            min_substeps: 1,
            crushed_substeps: 1,
            max_substeps: 64,
            stability_margin: 0.9,
            mass_scaling: true,
            damping_mass: 2.0,
            damping_stiffness: 3.0e-4,
            hourglass_stiffness: 0.25,
            volume_constraints: true,
            volumetric_split: true,
            volume_scheme: VolumeScheme::DualCells,
            elastic_scheme: ElasticScheme::Tetrahedra,
            volume_compliance: 0.0,
            iterations: 1,
            contact_mode: ContactMode::ExactShape,
            max_depenetration_speed: 1.0,
            self_contact: false,
            threads: 1,
            divergence: DivergenceLimits::default(),
        }
    }
}

impl Settings {
    /// Check every field: NaN or ±Inf give [`Error::NonFinite`](crate::Error::NonFinite),
    /// out-of-range values [`Error::InvalidArgument`](crate::Error::InvalidArgument); the
    /// message names the first bad field (`settings.<field>`). The one validation of settings,
    /// used by [`World::new`](crate::World::new), [`World::set_settings`](crate::World::set_settings)
    /// and the C API.
    pub fn validate(&self) -> Result<(), crate::Error> {
        use crate::error::{check_finite, check_non_negative, check_positive};
        use crate::Error;
        let bad = |m: &str| Err(Error::InvalidArgument(format!("settings.{m}")));
        for (name, v) in [
            ("settings.dt", self.dt),
            ("settings.gravity[0]", self.gravity.x),
            ("settings.gravity[1]", self.gravity.y),
            ("settings.gravity[2]", self.gravity.z),
            ("settings.stability_margin", self.stability_margin),
            ("settings.damping_mass", self.damping_mass),
            ("settings.damping_stiffness", self.damping_stiffness),
            ("settings.hourglass_stiffness", self.hourglass_stiffness),
            ("settings.volume_compliance", self.volume_compliance),
            (
                "settings.max_depenetration_speed",
                self.max_depenetration_speed,
            ),
        ] {
            check_finite(name, v)?;
        }
        check_positive("settings.dt", self.dt, "s")?;
        if self.min_substeps == 0 || self.max_substeps < self.min_substeps {
            return bad("min_substeps/max_substeps: need 1 <= min_substeps <= max_substeps");
        }
        if self.crushed_substeps == 0 || self.max_substeps < self.crushed_substeps {
            return bad("crushed_substeps: need 1 <= crushed_substeps <= max_substeps");
        }
        if !(self.stability_margin > 0.0 && self.stability_margin <= 1.0) {
            return bad("stability_margin must be in (0, 1]");
        }
        check_non_negative("settings.damping_mass", self.damping_mass, "1/s")?;
        check_non_negative("settings.damping_stiffness", self.damping_stiffness, "s")?;
        check_non_negative("settings.hourglass_stiffness", self.hourglass_stiffness, "")?;
        check_non_negative("settings.volume_compliance", self.volume_compliance, "1/Pa")?;
        check_positive(
            "settings.max_depenetration_speed",
            self.max_depenetration_speed,
            "m/s",
        )?;
        if !(1..=MAX_THREADS as u32).contains(&self.threads) {
            return bad("threads must be in 1..=64");
        }
        if self.iterations == 0 {
            return bad("iterations must be >= 1");
        }
        let d = &self.divergence;
        let (lo, hi) = d.volume_ratio;
        if !(d.max_speed > 0.0 && d.max_extent_ratio > 1.0 && (0.0..1.0).contains(&lo) && hi > 1.0)
        {
            return bad(
                "divergence limits: need max_speed > 0 (body sizes/s), max_extent_ratio > 1, \
                 and 0 <= volume_ratio.0 < 1 < volume_ratio.1 (infinity switches a check off)",
            );
        }
        Ok(())
    }
}
