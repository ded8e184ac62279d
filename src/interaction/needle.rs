//! Needle insertion: a capsule or cylinder tool that punctures the tissue when the force at its
//! tip exceeds a threshold, then holds the tissue on its shaft with axial friction.
//!
//! A tool becomes a needle with [`World::make_needle`](crate::World::make_needle); its shaft is
//! the tool's local y axis and its tip the end at local +y. Before puncture it is an ordinary
//! tool: contact pushes the tissue. At the end of a step, when the tissue pushes back against the
//! tip along the shaft with at least [`NeedleOptions::puncture_force`] (N), the needle punctures
//! the body nearest its tip: from then on contact between the needle and that body is off, and
//! every free particle of the body that comes within [`NeedleOptions::reach`] of the inserted
//! part of the shaft (from the entry point, where the tip was at puncture, to the tip) is held
//! on the shaft:
//!
//! - laterally, at its offset from the axis in the needle's frame (an XPBD constraint of
//!   compliance `1/(E r)` as for grasping), so the tissue moves with the shaft sideways;
//! - axially with friction: the particle sticks to its axial position on the shaft while the
//!   force that takes is below its share of `friction_per_length × inserted length`, and slips
//!   along the shaft with that force otherwise (position-level Coulomb friction, like the
//!   contact friction of PBD).
//!
//! The axial force on the needle therefore shows the classic profile: a rise while the tip
//! indents the surface, a drop at puncture, and a growth with the inserted length. Particles that
//! the tip withdraws past are let go; once the tip is back behind the entry point the needle is
//! out and contact acts again.

use crate::error::Error;
use crate::kernels::math::{Real, Vec3};
use crate::scene::body::Body;
// The needle's data (options, shaft, insertion, holds) is in the scene layer, whose tool slots
// and `WorldState` hold it; this file is what a needle does with it.
use crate::scene::needle_state::{Needle, ShaftHold};
use crate::scene::particles::ParticleViews;
use crate::scene::tool::{Pose, Tool, ToolLoad, ToolShape};
use parry3d_f64::math::Point;

pub use crate::scene::needle_state::{NeedleOptions, NeedleState};

impl Needle {
    /// A needle made of `tool`, which must be a capsule or a cylinder.
    pub(crate) fn new(tool: &Tool, options: NeedleOptions) -> Result<Needle, Error> {
        options.validate()?;
        let (tip, radius) = match tool.description {
            ToolShape::Capsule {
                half_height,
                radius,
            } => (half_height + radius, radius),
            ToolShape::Cylinder {
                half_height,
                radius,
            } => (half_height, radius),
            _ => {
                return Err(Error::InvalidArgument(
                    "a needle is a capsule or a cylinder tool (shaft along local y)".into(),
                ))
            }
        };
        Ok(Needle {
            options,
            tip,
            radius,
            body: None,
            entry: Vec3::zeros(),
            holds: Vec::new(),
        })
    }

    /// Unit shaft direction (world frame) at `pose`.
    fn axis(pose: &Pose) -> Vec3 {
        pose.orientation * Vec3::y()
    }

    /// The tip (m, world frame) at `pose`.
    fn tip_at(&self, pose: &Pose) -> Vec3 {
        pose.position + Self::axis(pose) * self.tip
    }

    /// Inserted length (m) at `pose`: how far the tip is past the entry point along the shaft.
    pub(crate) fn inserted_length(&self, pose: &Pose) -> Real {
        match self.body {
            Some(_) => (self.tip_at(pose) - self.entry).dot(&Self::axis(pose)),
            None => 0.0,
        }
    }

    /// Whether contact between this needle and body `b` is off (punctured).
    pub(crate) fn passes_through(&self, b: usize) -> bool {
        self.body == Some(b as u32)
    }

    /// At the end of a step: puncture when the tissue pushes back on the tip along the shaft
    /// with at least the puncture force (the body nearest the tip is punctured), or when the
    /// tip is inside a body's deformed boundary surface (a needle thinner than the particle
    /// spacing can pass between particles: it is then in the tissue, and is held as such);
    /// pull out when the tip is back behind the entry point.
    pub(crate) fn end_step(&mut self, tool: &Tool, bodies: &[Body]) {
        let pose = tool.pose;
        match self.body {
            None => {
                let tip = self.tip_at(&pose);
                if let Some(b) = bodies.iter().position(|body| body.contains(&tip)) {
                    self.body = Some(b as u32);
                    self.entry = tip;
                    return;
                }
                let resisting = -tool.wrench.force.dot(&Self::axis(&pose));
                if tool.wrench.contact_count == 0 || resisting < self.options.puncture_force {
                    return;
                }
                let nearest = bodies
                    .iter()
                    .enumerate()
                    .filter_map(|(b, body)| {
                        body.state
                            .x
                            .iter()
                            .map(|x| (x - tip).norm())
                            .min_by(Real::total_cmp)
                            .map(|d| (d, b))
                    })
                    .min_by(|a, b| a.0.total_cmp(&b.0));
                if let Some((_, b)) = nearest {
                    self.body = Some(b as u32);
                    self.entry = tip;
                }
            }
            Some(_) => {
                if self.inserted_length(&pose) <= 0.0 {
                    self.body = None;
                    self.holds.clear();
                }
            }
        }
    }

    /// Start a substep at needle pose `cur`: hold the particles (of `views`) newly within
    /// reach of the inserted shaft, let go of those the tip withdrew past, restart the
    /// multipliers.
    pub(crate) fn begin_substep(&mut self, views: &mut impl ParticleViews, cur: &Pose) {
        let Some(b) = self.body else { return };
        let view = views.view(b as usize);
        let iso = cur.isometry();
        let length = self.inserted_length(cur);
        let (top, bottom) = (self.tip, self.tip - length.max(0.0));
        let reach = self
            .options
            .reach
            .unwrap_or(self.radius + 1.5 * view.radius);
        self.holds.retain(|h| h.anchor.y <= top);
        for h in &mut self.holds {
            h.lambda = Vec3::zeros();
        }
        for (i, x) in view.x.iter().enumerate() {
            if view.inv_mass[i] == 0.0 {
                continue;
            }
            let local = iso.inverse_transform_point(&Point::from(*x)).coords;
            let lateral = (local.x * local.x + local.z * local.z).sqrt();
            if lateral > reach || local.y > top || local.y < bottom {
                continue;
            }
            if self.holds.iter().any(|h| h.particle == i as u32) {
                continue;
            }
            self.holds.push(ShaftHold {
                particle: i as u32,
                anchor: local,
                lambda: Vec3::zeros(),
            });
        }
    }

    /// One projection pass of the held particles (of `views`) towards the shaft at pose `cur`
    /// for a substep `h` (s): lateral XPBD constraints and axial stick-or-slip friction; the
    /// corrections (times the particles' masses) go into the tool's `load`.
    pub(crate) fn project(
        &mut self,
        views: &mut impl ParticleViews,
        cur: &Pose,
        load: &mut ToolLoad,
        h: Real,
    ) {
        let Some(b) = self.body else { return };
        if self.holds.is_empty() {
            return;
        }
        let view = views.view(b as usize);
        let iso = cur.isometry();
        let axis = Self::axis(cur);
        let compliance = 1.0 / (view.youngs_modulus * view.radius);
        let alpha = compliance / (h * h);
        // Each held particle's share of the friction force (N).
        let length = self.inserted_length(cur).max(0.0);
        let share = self.options.friction_per_length * length / self.holds.len() as Real;
        for hold in &mut self.holds {
            let i = hold.particle as usize;
            let w = view.inv_mass[i];
            if w == 0.0 {
                continue;
            }
            let before = view.p[i];
            let local = iso.inverse_transform_point(&Point::from(before)).coords;
            // Lateral: towards the anchor's offset from the axis (local x, z).
            let c = Vec3::new(local.x - hold.anchor.x, 0.0, local.z - hold.anchor.z);
            let dl = -(c + hold.lambda * alpha) / (w + alpha);
            hold.lambda += dl;
            let lateral_world = cur.orientation * (dl * w);
            // Axial: stick if the force that takes is within the share, else slip with it.
            let m = view.mass[i];
            let stick = hold.anchor.y - local.y;
            let limit = share * h * h / m;
            let axial = stick.clamp(-limit, limit);
            if axial != stick {
                hold.anchor.y = local.y + axial;
            }
            let dp = lateral_world + axis * axial;
            view.p[i] += dp;
            let impulse = dp * m;
            load.impulse += impulse;
            let at = iso.transform_point(&Point::from(hold.anchor)).coords;
            load.moment += (at - cur.position).cross(&impulse);
        }
    }
}
