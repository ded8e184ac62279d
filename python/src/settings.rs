//! `Settings`, `DivergenceLimits`, `ContactMode`, `VolumeScheme` and `ElasticScheme`: the world's parameters, every field as in
//! the Rust `tissuesim::Settings` (SI units; see the `.pyi` stub for each field's unit).

use pyo3::prelude::*;
use pyo3::types::PyDict;
use tissuesim::{Real, Vec3};

/// How tool–tissue contact is detected.
#[pyclass(module = "tissuesim", eq, eq_int, from_py_object)]
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub enum ContactMode {
    /// The tool's exact shape against the body's deformed boundary triangles (the default).
    ExactShape,
    /// The paper's mode: the tool surface sampled into points pushing particles out.
    SampledPoints,
}

impl From<ContactMode> for tissuesim::ContactMode {
    fn from(m: ContactMode) -> Self {
        match m {
            ContactMode::ExactShape => tissuesim::ContactMode::ExactShape,
            ContactMode::SampledPoints => tissuesim::ContactMode::SampledPoints,
        }
    }
}

impl From<tissuesim::ContactMode> for ContactMode {
    fn from(m: tissuesim::ContactMode) -> Self {
        match m {
            tissuesim::ContactMode::ExactShape => ContactMode::ExactShape,
            tissuesim::ContactMode::SampledPoints => ContactMode::SampledPoints,
        }
    }
}

/// What one volume constraint keeps.
#[pyclass(module = "tissuesim", eq, eq_int, from_py_object)]
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub enum VolumeScheme {
    /// One constraint per tetrahedron (the paper's): locks like linear tetrahedra as nu -> 0.5.
    Tetrahedra,
    /// One constraint per particle on its dual cell (the default): does not lock as nu -> 0.5.
    DualCells,
}

impl From<VolumeScheme> for tissuesim::VolumeScheme {
    fn from(m: VolumeScheme) -> Self {
        match m {
            VolumeScheme::Tetrahedra => tissuesim::VolumeScheme::Tetrahedra,
            VolumeScheme::DualCells => tissuesim::VolumeScheme::DualCells,
        }
    }
}

impl From<tissuesim::VolumeScheme> for VolumeScheme {
    fn from(m: tissuesim::VolumeScheme) -> Self {
        match m {
            tissuesim::VolumeScheme::Tetrahedra => VolumeScheme::Tetrahedra,
            tissuesim::VolumeScheme::DualCells => VolumeScheme::DualCells,
        }
    }
}

/// What carries the elasticity.
#[pyclass(module = "tissuesim", eq, eq_int, from_py_object)]
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub enum ElasticScheme {
    /// The paper's point-based particles (MLS deformation gradient).
    PointBased,
    /// Corotated linear tetrahedra of the mesh (the default).
    Tetrahedra,
}

impl From<ElasticScheme> for tissuesim::ElasticScheme {
    fn from(m: ElasticScheme) -> Self {
        match m {
            ElasticScheme::PointBased => tissuesim::ElasticScheme::PointBased,
            ElasticScheme::Tetrahedra => tissuesim::ElasticScheme::Tetrahedra,
        }
    }
}

impl From<tissuesim::ElasticScheme> for ElasticScheme {
    fn from(m: tissuesim::ElasticScheme) -> Self {
        match m {
            tissuesim::ElasticScheme::PointBased => ElasticScheme::PointBased,
            tissuesim::ElasticScheme::Tetrahedra => ElasticScheme::Tetrahedra,
        }
    }
}

/// Bounds beyond which a step counts as diverged and is rolled back (relative to the body's
/// rest size; infinity switches a check off).
#[pyclass(module = "tissuesim", get_all, set_all, eq, from_py_object)]
#[derive(Clone, PartialEq, Debug)]
pub struct DivergenceLimits {
    /// Largest particle speed, in body sizes per second (1/s).
    pub max_speed: Real,
    /// Largest deformed extent over the rest size (dimensionless).
    pub max_extent_ratio: Real,
    /// Accepted range of volume / rest volume (dimensionless).
    pub volume_ratio: (Real, Real),
}

impl From<&DivergenceLimits> for tissuesim::DivergenceLimits {
    fn from(d: &DivergenceLimits) -> Self {
        tissuesim::DivergenceLimits {
            max_speed: d.max_speed,
            max_extent_ratio: d.max_extent_ratio,
            volume_ratio: d.volume_ratio,
        }
    }
}

impl From<&tissuesim::DivergenceLimits> for DivergenceLimits {
    fn from(d: &tissuesim::DivergenceLimits) -> Self {
        DivergenceLimits {
            max_speed: d.max_speed,
            max_extent_ratio: d.max_extent_ratio,
            volume_ratio: d.volume_ratio,
        }
    }
}

#[pymethods]
impl DivergenceLimits {
    /// The defaults (250 body sizes/s, extent ratio 10, volume ratio in [0.1, 10]), with any
    /// field given by keyword.
    #[new]
    #[pyo3(signature = (**kwargs))]
    fn new(kwargs: Option<&Bound<'_, PyDict>>) -> PyResult<Self> {
        let mut s = DivergenceLimits::from(&tissuesim::DivergenceLimits::default());
        apply_kwargs!(s, kwargs, [max_speed, max_extent_ratio, volume_ratio]);
        Ok(s)
    }
    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        let s = self;
        repr_fields!(
            py,
            "DivergenceLimits",
            s,
            [max_speed, max_extent_ratio, volume_ratio]
        )
    }
}

/// Parameters of the time integration and the constraint projection (see the stub for units).
#[pyclass(module = "tissuesim", get_all, set_all, eq, from_py_object)]
#[derive(Clone, PartialEq, Debug)]
pub struct Settings {
    /// Time step of one `World.step` (s). Default 0.001.
    pub dt: Real,
    /// Gravity acceleration (m/s²), [x, y, z]. Default [0, -9.81, 0].
    pub gravity: [Real; 3],
    /// Smallest number of substeps per step (>= 1). Default 1.
    pub min_substeps: u32,
    /// Smallest number of substeps of a step that starts with the tissue at a tool compressed
    /// (a tetrahedron touching it below half its rest volume). Default 1 (none added by the
    /// setting; a tool narrower than the compressed tetrahedron doubles the step's substeps
    /// anyway); 2 for deep presses with wide probes.
    pub crushed_substeps: u32,
    /// Largest number of substeps per step; a step needing more is clamped. Default 64.
    pub max_substeps: u32,
    /// Fraction (0, 1] of the explicit stability limit 2/omega_max a substep may use. Default 0.9.
    pub stability_margin: Real,
    /// Selective mass scaling of particles whose own stable step is too short. Default True.
    pub mass_scaling: bool,
    /// Mass-proportional damping rate alpha (1/s). Default 2.
    pub damping_mass: Real,
    /// Stiffness-proportional damping time beta (s): dashpots on the mesh edges, implicit.
    /// Default 0.0003 (0: none).
    pub damping_stiffness: Real,
    /// Hourglass-control stiffness (dimensionless, times the shear modulus). Default 0.25.
    pub hourglass_stiffness: Real,
    /// XPBD per-tetrahedron volume constraints. Default True.
    pub volume_constraints: bool,
    /// With volume constraints: lambda carried by them (compliance 1/lambda). Default True.
    pub volumetric_split: bool,
    /// What each volume constraint keeps. Default VolumeScheme.DualCells.
    pub volume_scheme: VolumeScheme,
    /// What carries the elasticity. Default ElasticScheme.Tetrahedra.
    pub elastic_scheme: ElasticScheme,
    /// Extra compliance of the volume constraints (1/Pa, per unit volume). Default 0.
    pub volume_compliance: Real,
    /// Gauss-Seidel iterations over all constraints per substep. Default 1.
    pub iterations: u32,
    /// How tool-tissue contact is detected. Default ContactMode.ExactShape.
    pub contact_mode: ContactMode,
    /// Largest speed (m/s) at which contact removes a penetration already there. Default 1.
    pub max_depenetration_speed: Real,
    /// Surface self-contact: a body's boundary kept off its own boundary triangles. Default False.
    pub self_contact: bool,
    /// Threads a step runs on (1..=64); the same bits for any count. Default 1.
    pub threads: u32,
    /// Physical bounds checked after every step (a copy on read: assign it whole).
    pub divergence: DivergenceLimits,
}

impl Settings {
    /// The Rust settings.
    pub(crate) fn to_core(&self) -> tissuesim::Settings {
        let g = self.gravity;
        tissuesim::Settings {
            dt: self.dt,
            gravity: Vec3::new(g[0], g[1], g[2]),
            min_substeps: self.min_substeps,
            crushed_substeps: self.crushed_substeps,
            max_substeps: self.max_substeps,
            stability_margin: self.stability_margin,
            mass_scaling: self.mass_scaling,
            damping_mass: self.damping_mass,
            damping_stiffness: self.damping_stiffness,
            hourglass_stiffness: self.hourglass_stiffness,
            volume_constraints: self.volume_constraints,
            volumetric_split: self.volumetric_split,
            volume_scheme: self.volume_scheme.into(),
            elastic_scheme: self.elastic_scheme.into(),
            volume_compliance: self.volume_compliance,
            iterations: self.iterations,
            contact_mode: self.contact_mode.into(),
            max_depenetration_speed: self.max_depenetration_speed,
            self_contact: self.self_contact,
            threads: self.threads,
            divergence: (&self.divergence).into(),
        }
    }
    /// The Python settings of Rust settings.
    pub(crate) fn from_core(s: &tissuesim::Settings) -> Self {
        Settings {
            dt: s.dt,
            gravity: [s.gravity.x, s.gravity.y, s.gravity.z],
            min_substeps: s.min_substeps,
            crushed_substeps: s.crushed_substeps,
            max_substeps: s.max_substeps,
            stability_margin: s.stability_margin,
            mass_scaling: s.mass_scaling,
            damping_mass: s.damping_mass,
            damping_stiffness: s.damping_stiffness,
            hourglass_stiffness: s.hourglass_stiffness,
            volume_constraints: s.volume_constraints,
            volumetric_split: s.volumetric_split,
            volume_scheme: s.volume_scheme.into(),
            elastic_scheme: s.elastic_scheme.into(),
            volume_compliance: s.volume_compliance,
            iterations: s.iterations,
            contact_mode: s.contact_mode.into(),
            max_depenetration_speed: s.max_depenetration_speed,
            self_contact: s.self_contact,
            threads: s.threads,
            divergence: (&s.divergence).into(),
        }
    }
}

#[pymethods]
impl Settings {
    /// The defaults (`tissuesim::Settings::default()`: dt 1 ms, gravity -9.81 m/s² along y,
    /// ...), with any field given by keyword.
    #[new]
    #[pyo3(signature = (**kwargs))]
    fn new(kwargs: Option<&Bound<'_, PyDict>>) -> PyResult<Self> {
        let mut s = Settings::from_core(&tissuesim::Settings::default());
        apply_kwargs!(
            s,
            kwargs,
            [
                dt,
                gravity,
                min_substeps,
                crushed_substeps,
                max_substeps,
                stability_margin,
                mass_scaling,
                damping_mass,
                damping_stiffness,
                hourglass_stiffness,
                volume_constraints,
                volumetric_split,
                volume_scheme,
                elastic_scheme,
                volume_compliance,
                iterations,
                contact_mode,
                max_depenetration_speed,
                self_contact,
                threads,
                divergence,
            ]
        );
        Ok(s)
    }
    /// Check every field (`ValueError` naming the first bad one).
    fn validate(&self) -> PyResult<()> {
        crate::errors::Check::py(self.to_core().validate())
    }
    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        let s = self;
        repr_fields!(
            py,
            "Settings",
            s,
            [
                dt,
                gravity,
                min_substeps,
                crushed_substeps,
                max_substeps,
                stability_margin,
                mass_scaling,
                damping_mass,
                damping_stiffness,
                hourglass_stiffness,
                volume_constraints,
                volumetric_split,
                volume_scheme,
                elastic_scheme,
                volume_compliance,
                iterations,
                contact_mode,
                max_depenetration_speed,
                self_contact,
                threads,
                divergence,
            ]
        )
    }
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<ContactMode>()?;
    m.add_class::<VolumeScheme>()?;
    m.add_class::<ElasticScheme>()?;
    m.add_class::<DivergenceLimits>()?;
    m.add_class::<Settings>()?;
    Ok(())
}
