//! `Material` and `BodyOptions`: how a body is built (SI units).

use crate::errors::Check;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use tissuesim::Real;

/// An isotropic linear-elastic material: E (Pa), ν (-), ρ (kg/m³).
#[pyclass(module = "tissuesim", get_all, set_all, eq, from_py_object)]
#[derive(Clone, PartialEq, Debug)]
pub struct Material {
    /// Young's modulus E (Pa), in [1e-6, 1e12]. Default 5000.
    pub youngs_modulus: Real,
    /// Poisson ratio nu (dimensionless), in [0, 0.499]. Default 0.45.
    pub poisson_ratio: Real,
    /// Mass density rho (kg/m³), in [1e-6, 1e5]. Default 1060.
    pub density: Real,
}

impl Material {
    pub(crate) fn to_core(&self) -> tissuesim::Material {
        tissuesim::Material {
            youngs_modulus: self.youngs_modulus,
            poisson_ratio: self.poisson_ratio,
            density: self.density,
        }
    }
    pub(crate) fn from_core(m: &tissuesim::Material) -> Self {
        Material {
            youngs_modulus: m.youngs_modulus,
            poisson_ratio: m.poisson_ratio,
            density: m.density,
        }
    }
}

#[pymethods]
impl Material {
    /// Liver-like tissue (E 5 kPa, ν 0.45, ρ 1060 kg/m³), with any field given by keyword.
    #[new]
    #[pyo3(signature = (**kwargs))]
    fn new(kwargs: Option<&Bound<'_, PyDict>>) -> PyResult<Self> {
        let mut s = Material::from_core(&tissuesim::Material::default());
        apply_kwargs!(s, kwargs, [youngs_modulus, poisson_ratio, density]);
        Ok(s)
    }
    /// Check the ranges (`ValueError` naming the field).
    fn validate(&self) -> PyResult<()> {
        self.to_core().validate().py()
    }
    /// First Lamé parameter λ (Pa).
    fn lame_lambda(&self) -> Real {
        self.to_core().lame_lambda()
    }
    /// Shear modulus μ (Pa).
    fn shear_modulus(&self) -> Real {
        self.to_core().shear_modulus()
    }
    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        let s = self;
        repr_fields!(py, "Material", s, [youngs_modulus, poisson_ratio, density])
    }
}

/// Options for building a body (radii in m; None: automatic).
#[pyclass(module = "tissuesim", get_all, set_all, eq, from_py_object)]
#[derive(Clone, PartialEq, Debug)]
pub struct BodyOptions {
    /// The material (a copy on read: assign it whole). Default Material().
    pub material: Material,
    /// Support radius of every particle (m); None chooses one per particle.
    pub support_radius: Option<Real>,
    /// Target neighbours when the support radius is automatic. Default 20.
    pub target_neighbours: u32,
    /// Contact radius of the particles (m); None: half the mean edge length.
    pub particle_radius: Option<Real>,
    /// Variationally consistent MLS gradients. Default True.
    pub consistent_gradients: bool,
}

impl BodyOptions {
    pub(crate) fn to_core(&self) -> tissuesim::BodyOptions {
        tissuesim::BodyOptions {
            material: self.material.to_core(),
            support_radius: self.support_radius,
            target_neighbours: self.target_neighbours,
            particle_radius: self.particle_radius,
            consistent_gradients: self.consistent_gradients,
        }
    }
    pub(crate) fn from_core(o: &tissuesim::BodyOptions) -> Self {
        BodyOptions {
            material: Material::from_core(&o.material),
            support_radius: o.support_radius,
            target_neighbours: o.target_neighbours,
            particle_radius: o.particle_radius,
            consistent_gradients: o.consistent_gradients,
        }
    }
    /// `options` or the defaults.
    pub(crate) fn or_default(options: Option<&BodyOptions>) -> tissuesim::BodyOptions {
        options.map_or_else(tissuesim::BodyOptions::default, BodyOptions::to_core)
    }
}

#[pymethods]
impl BodyOptions {
    /// The defaults (liver-like material, automatic radii, 20 neighbours, consistent
    /// gradients), with any field given by keyword.
    #[new]
    #[pyo3(signature = (**kwargs))]
    fn new(kwargs: Option<&Bound<'_, PyDict>>) -> PyResult<Self> {
        let mut s = BodyOptions::from_core(&tissuesim::BodyOptions::default());
        apply_kwargs!(
            s,
            kwargs,
            [
                material,
                support_radius,
                target_neighbours,
                particle_radius,
                consistent_gradients
            ]
        );
        Ok(s)
    }
    /// Check the options (`ValueError` naming the field).
    fn validate(&self) -> PyResult<()> {
        self.to_core().validate().py()
    }
    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        let s = self;
        repr_fields!(
            py,
            "BodyOptions",
            s,
            [
                material,
                support_radius,
                target_neighbours,
                particle_radius,
                consistent_gradients
            ]
        )
    }
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Material>()?;
    m.add_class::<BodyOptions>()?;
    Ok(())
}
