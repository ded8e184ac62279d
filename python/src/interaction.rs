//! Grasping, needles and cutting: `GraspOptions`, `NeedleOptions`, `NeedleState`, `Blade`,
//! `CutReport`.

use crate::arrays::{from_vec3s, vec3};
use crate::errors::Check;
use numpy::PyArray2;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use tissuesim::Real;

/// How a tool grasps: `reach` (m, None: 1.5 particle radii), `compliance` (m/N, None: that of
/// the tissue), `max_force` (N, infinity: never slips).
#[pyclass(module = "tissuesim", get_all, set_all, eq, from_py_object)]
#[derive(Clone, PartialEq, Debug)]
pub struct GraspOptions {
    /// Particles within this distance (m) of the tool are held; None: 1.5 particle radii.
    pub reach: Option<Real>,
    /// Compliance of each attachment (m/N); None: that of the tissue around it.
    pub compliance: Option<Real>,
    /// Largest total pull (N) before the tissue slips; infinity never slips.
    pub max_force: Real,
}

impl GraspOptions {
    pub(crate) fn to_core(&self) -> tissuesim::GraspOptions {
        tissuesim::GraspOptions {
            reach: self.reach,
            compliance: self.compliance,
            max_force: self.max_force,
        }
    }
    fn from_core(o: &tissuesim::GraspOptions) -> Self {
        GraspOptions {
            reach: o.reach,
            compliance: o.compliance,
            max_force: o.max_force,
        }
    }
}

#[pymethods]
impl GraspOptions {
    /// The defaults; any field by keyword.
    #[new]
    #[pyo3(signature = (**kwargs))]
    fn new(kwargs: Option<&Bound<'_, PyDict>>) -> PyResult<Self> {
        let mut s = GraspOptions::from_core(&tissuesim::GraspOptions::default());
        apply_kwargs!(s, kwargs, [reach, compliance, max_force]);
        Ok(s)
    }
    /// Check the options (`ValueError`).
    fn validate(&self) -> PyResult<()> {
        self.to_core().validate().py()
    }
    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        let s = self;
        repr_fields!(py, "GraspOptions", s, [reach, compliance, max_force])
    }
}

/// How a needle punctures (`puncture_force`, N) and holds (`friction_per_length`, N/m;
/// `reach`, m, None: radius + 1.5 particle radii).
#[pyclass(module = "tissuesim", get_all, set_all, eq, from_py_object)]
#[derive(Clone, PartialEq, Debug)]
pub struct NeedleOptions {
    /// Axial force (N) on the tip that punctures the tissue. Default 1.
    pub puncture_force: Real,
    /// Axial friction per inserted length (N/m). Default 20.
    pub friction_per_length: Real,
    /// Hold radius around the shaft (m); None: the needle's radius + 1.5 particle radii.
    pub reach: Option<Real>,
}

impl NeedleOptions {
    pub(crate) fn to_core(&self) -> tissuesim::NeedleOptions {
        tissuesim::NeedleOptions {
            puncture_force: self.puncture_force,
            friction_per_length: self.friction_per_length,
            reach: self.reach,
        }
    }
    fn from_core(o: &tissuesim::NeedleOptions) -> Self {
        NeedleOptions {
            puncture_force: o.puncture_force,
            friction_per_length: o.friction_per_length,
            reach: o.reach,
        }
    }
}

#[pymethods]
impl NeedleOptions {
    /// The defaults (1 N, 20 N/m, automatic reach); any field by keyword.
    #[new]
    #[pyo3(signature = (**kwargs))]
    fn new(kwargs: Option<&Bound<'_, PyDict>>) -> PyResult<Self> {
        let mut s = NeedleOptions::from_core(&tissuesim::NeedleOptions::default());
        apply_kwargs!(s, kwargs, [puncture_force, friction_per_length, reach]);
        Ok(s)
    }
    /// Check the options (`ValueError`).
    fn validate(&self) -> PyResult<()> {
        self.to_core().validate().py()
    }
    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        let s = self;
        repr_fields!(
            py,
            "NeedleOptions",
            s,
            [puncture_force, friction_per_length, reach]
        )
    }
}

/// Where a needle is: `punctured`, `inserted_length` (m), `held` (particles on the shaft).
#[pyclass(module = "tissuesim", get_all, frozen)]
pub struct NeedleState {
    pub punctured: bool,
    pub inserted_length: Real,
    pub held: usize,
}

impl From<tissuesim::NeedleState> for NeedleState {
    fn from(s: tissuesim::NeedleState) -> Self {
        NeedleState {
            punctured: s.punctured,
            inserted_length: s.inserted_length,
            held: s.held,
        }
    }
}

#[pymethods]
impl NeedleState {
    fn __repr__(&self) -> String {
        format!(
            "NeedleState(punctured={}, inserted_length={}, held={})",
            if self.punctured { "True" } else { "False" },
            self.inserted_length,
            self.held
        )
    }
}

/// A blade's edge at the start (`from_`) and at the end (`to`) of its motion, m, world frame:
/// `Blade(from_=[a0, a1], to=[b0, b1])`, each end a point (3,).
#[pyclass(module = "tissuesim", frozen)]
pub struct Blade {
    pub(crate) inner: tissuesim::Blade,
}

#[pymethods]
impl Blade {
    #[new]
    #[pyo3(signature = (from_, to))]
    fn new(
        from_: (Bound<'_, PyAny>, Bound<'_, PyAny>),
        to: (Bound<'_, PyAny>, Bound<'_, PyAny>),
    ) -> PyResult<Self> {
        Ok(Blade {
            inner: tissuesim::Blade {
                from: [vec3(&from_.0, "from_[0]")?, vec3(&from_.1, "from_[1]")?],
                to: [vec3(&to.0, "to[0]")?, vec3(&to.1, "to[1]")?],
            },
        })
    }
    /// The edge's two ends at the start (2, 3), m.
    #[getter]
    fn from_<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        from_vec3s(py, self.inner.from.iter().copied())
    }
    /// The edge's two ends at the end (2, 3), m.
    #[getter]
    fn to<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        from_vec3s(py, self.inner.to.iter().copied())
    }
    fn __repr__(&self) -> String {
        format!(
            "Blade(from_={:?}, to={:?})",
            self.inner.from.map(|p| [p.x, p.y, p.z]),
            self.inner.to.map(|p| [p.x, p.y, p.z])
        )
    }
}

/// What a cut removed: neighbour `pairs`, `tets`, `isolated` particles (left without
/// elasticity).
#[pyclass(module = "tissuesim", get_all, frozen, eq)]
#[derive(PartialEq)]
pub struct CutReport {
    pub pairs: usize,
    pub tets: usize,
    pub isolated: usize,
}

impl From<tissuesim::CutReport> for CutReport {
    fn from(r: tissuesim::CutReport) -> Self {
        CutReport {
            pairs: r.pairs,
            tets: r.tets,
            isolated: r.isolated,
        }
    }
}

#[pymethods]
impl CutReport {
    fn __repr__(&self) -> String {
        format!(
            "CutReport(pairs={}, tets={}, isolated={})",
            self.pairs, self.tets, self.isolated
        )
    }
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<GraspOptions>()?;
    m.add_class::<NeedleOptions>()?;
    m.add_class::<NeedleState>()?;
    m.add_class::<Blade>()?;
    m.add_class::<CutReport>()?;
    Ok(())
}
