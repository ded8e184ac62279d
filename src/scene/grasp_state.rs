//! A tool's grasp as data: how a tool grasps ([`GraspOptions`]) and what it holds ([`Grasp`]:
//! its [`Attachment`]s and slip limit), as the scene's tool slots and
//! [`WorldState`](crate::WorldState) keep them. The grasping itself — which particles a grasp
//! takes, the attachments' projection, the slip — is in
//! [`interaction::grasp`](crate::interaction::grasp), which re-exports [`GraspOptions`] at its
//! public path `tissuesim::grasp::GraspOptions`.

use crate::error::{check_finite, Error};
use crate::kernels::math::{Real, Vec3};

/// How a tool grasps.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GraspOptions {
    /// Particles whose centre is within this distance (m) of the tool's surface (or inside it)
    /// are grasped. `None`: 1.5 × the body's particle radius (three quarters of the mean edge by
    /// default) — the corners of the surface triangles the tool touches and none of the layer
    /// of particles behind them.
    pub reach: Option<Real>,
    /// Compliance of each attachment (m/N; 0 = rigid). `None`: `1 / (E r)`, the compliance of a
    /// cube of the body's tissue one particle radius `r` across (E its Young's modulus), so the
    /// jaws hold as firmly as the tissue around them.
    pub compliance: Option<Real>,
    /// Largest total force (N) the attachments may exert on the tool; beyond it the tissue slips
    /// and every attachment is released. Infinity (the default) never slips.
    pub max_force: Real,
}

impl Default for GraspOptions {
    fn default() -> Self {
        GraspOptions {
            reach: None,
            compliance: None,
            max_force: Real::INFINITY,
        }
    }
}

impl GraspOptions {
    /// Check the options: `reach` and `compliance` finite and ≥ 0 when given, `max_force` > 0
    /// (infinity allowed). NaN gives [`Error::NonFinite`], other bad values
    /// [`Error::InvalidArgument`].
    pub fn validate(&self) -> Result<(), Error> {
        for (name, v) in [
            ("grasp reach", self.reach),
            ("grasp compliance", self.compliance),
        ] {
            if let Some(v) = v {
                check_finite(name, v)?;
                if v < 0.0 {
                    return Err(Error::InvalidArgument(format!(
                        "{name} must be >= 0, got {v}"
                    )));
                }
            }
        }
        if self.max_force.is_nan() {
            return Err(Error::NonFinite("grasp max_force is NaN".into()));
        }
        if self.max_force <= 0.0 {
            return Err(Error::InvalidArgument(format!(
                "grasp max_force must be > 0 N (infinity: never slips), got {}",
                self.max_force
            )));
        }
        Ok(())
    }
}

/// One grasped particle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Attachment {
    /// The grasped particle's body (index in id order).
    pub(crate) body: u32,
    /// The grasped particle (index in its body's particle order).
    pub(crate) particle: u32,
    /// Where the particle is held, in the tool's frame (m).
    pub(crate) anchor: Vec3,
    /// Compliance (m/N).
    pub(crate) compliance: Real,
    /// XPBD multiplier of the substep in progress (N·s²).
    pub(crate) lambda: Vec3,
}

/// The attachments of one tool and its slip limit.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Grasp {
    /// The grasped particles (none: not grasping).
    pub(crate) attachments: Vec<Attachment>,
    /// Slip limit: the largest mean force (N) of the attachments on the tool over a step.
    pub(crate) max_force: Real,
    /// Σ m Δx of the attachments over the step in progress (kg·m).
    pub(crate) acc_impulse: Vec3,
}

impl Default for Grasp {
    /// Not grasping.
    fn default() -> Self {
        Grasp {
            attachments: Vec::new(),
            max_force: Real::INFINITY,
            acc_impulse: Vec3::zeros(),
        }
    }
}
