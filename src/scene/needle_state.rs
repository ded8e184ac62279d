//! A tool's needle role as data: how it punctures and holds the tissue ([`NeedleOptions`]),
//! its shaft and insertion ([`Needle`], with the particles held on the shaft, [`ShaftHold`]),
//! and what the API reports of it ([`NeedleState`]), as the scene's tool slots and
//! [`WorldState`](crate::WorldState) keep them. The needle itself — puncture, withdrawal, the
//! holds' projection with axial friction — is in
//! [`interaction::needle`](crate::interaction::needle), which re-exports [`NeedleOptions`] and
//! [`NeedleState`] at their public paths `tissuesim::needle::…`.

use crate::error::{check_finite, Error};
use crate::kernels::math::{Real, Vec3};

/// How a needle punctures and holds the tissue.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NeedleOptions {
    /// Axial force (N) the tissue must exert on the tip for the needle to puncture it (a
    /// property of the tissue and the needle; liver and a 1 mm needle: ~0.5–1.5 N).
    pub puncture_force: Real,
    /// Axial friction force per inserted length (N/m) once punctured.
    pub friction_per_length: Real,
    /// Particles whose centre comes within this distance (m) of the inserted shaft's axis are
    /// held. `None`: the needle's radius plus 1.5 particle radii (the particles contact had
    /// placed around it).
    pub reach: Option<Real>,
}

impl Default for NeedleOptions {
    fn default() -> Self {
        NeedleOptions {
            puncture_force: 1.0,
            friction_per_length: 20.0,
            reach: None,
        }
    }
}

impl NeedleOptions {
    /// Check the options: `puncture_force` > 0, `friction_per_length` ≥ 0, `reach` > 0 when
    /// given; all finite ([`Error::NonFinite`] otherwise).
    pub fn validate(&self) -> Result<(), Error> {
        check_finite("needle puncture_force", self.puncture_force)?;
        check_finite("needle friction_per_length", self.friction_per_length)?;
        let bad = |m: String| Err(Error::InvalidArgument(m));
        if self.puncture_force <= 0.0 {
            return bad(format!(
                "needle puncture_force must be > 0 N, got {}",
                self.puncture_force
            ));
        }
        if self.friction_per_length < 0.0 {
            return bad(format!(
                "needle friction_per_length must be >= 0 N/m, got {}",
                self.friction_per_length
            ));
        }
        if let Some(r) = self.reach {
            check_finite("needle reach", r)?;
            if r <= 0.0 {
                return bad(format!("needle reach must be > 0 m, got {r}"));
            }
        }
        Ok(())
    }
}

/// Where a needle is: [`World::needle_state`](crate::World::needle_state).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NeedleState {
    /// Whether the needle is in the tissue.
    pub punctured: bool,
    /// How far the tip is past the entry point along the shaft (m; 0 when not punctured).
    pub inserted_length: Real,
    /// Number of particles held on the shaft.
    pub held: usize,
}

/// One particle held on the shaft.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct ShaftHold {
    /// The held particle (index in the punctured body's particle order).
    pub(crate) particle: u32,
    /// Where the particle is held, in the needle's frame (m): x and z lateral, y axial.
    pub(crate) anchor: Vec3,
    /// XPBD multiplier of the lateral constraint, this substep (N·s²).
    pub(crate) lambda: Vec3,
}

/// The needle state of a tool.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Needle {
    /// How it punctures and holds the tissue (validated).
    pub(crate) options: NeedleOptions,
    /// Distance (m) from the tool origin to the tip along local +y.
    pub(crate) tip: Real,
    /// Radius of the shaft (m).
    pub(crate) radius: Real,
    /// The punctured body (index in id order), if any.
    pub(crate) body: Option<u32>,
    /// Where the tip entered the tissue (m, world frame).
    pub(crate) entry: Vec3,
    /// The particles of the punctured body held on the shaft.
    pub(crate) holds: Vec<ShaftHold>,
}
