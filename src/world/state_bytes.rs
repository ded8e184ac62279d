//! A [`WorldState`] as bytes: an explicit, versioned, checksummed format for saving a world to
//! disk or into an FMU state and restoring it.
//!
//! Layout (all little-endian):
//!
//! | field | type |
//! |---|---|
//! | magic `TSIMSTAT` | 8 bytes |
//! | format version ([`STATE_VERSION`]) | u32 |
//! | body count, tool count | u32, u32 |
//! | time (s) | f64 |
//! | held substep count, steps (dimensionless) it is still held for (`scene::substep_hold`) | u32, u32 |
//! | per body: particle count, then positions (m), velocities (m/s) as xyz, rotations as wxyz | u32, f64… |
//! | then its fixed flags, one byte per particle (0 or 1) | u8… |
//! | then its cut pairs (count, load-time pair slot indices, increasing) and removed tetrahedra (count, load-time indices, increasing) | u32, u32…, u32, u32… |
//! | per tool in the world (removed tools left out), in id order: pose, target pose (xyz, wxyz), linear velocity (m/s), force (N), torque (N·m), contact count, max penetration (m) | f64…, u32, f64 |
//! | then its grasp: slip force (N), attachment count, and per attachment body, particle, anchor in the tool frame (m), compliance (m/N) | f64, u32, (u32, u32, f64 × 4)… |
//! | then its needle: punctured body (`u32::MAX`: none, or not a needle), entry point (m), hold count, and per hold particle, anchor in the tool frame (m) | u32, f64 × 3, u32, (u32, f64 × 3)… |
//! | FNV-1a 64 checksum of everything before it | u64 |
//!
//! Particles are in each body's particle order (the mesh's nodes sorted for locality, a function
//! of the mesh alone; version 4 introduced it, so older states are refused rather than
//! restored onto the wrong particles). Cut pairs are indices into the neighbourhoods' pair
//! slots, padded per particle (version 5). Version 6 added the substep hold. The scene itself
//! (meshes, materials, settings) is not part of the state: a state restores into a world built
//! the same way. Its size depends on the cuts, grasps and needle holds in force
//! ([`World::state_size`] at the time of saving). Restoring then stepping reproduces the
//! original run bit for bit.
//!
//! Reading ([`WorldState::from_bytes`]) needs no world: it checks the magic, the version, the
//! checksum and that every count fits in the bytes before it allocates;
//! [`World::set_state`] then checks the values against the world.
//!
//! [`World::state_size`]: crate::World::state_size
//! [`World::set_state`]: crate::World::set_state

use crate::error::Error;
use crate::kernels::math::{Quat, Real, Vec3};
use crate::scene::body::ParticleState;
use crate::scene::grasp_state::{Attachment, Grasp};
use crate::scene::needle_state::ShaftHold;
use crate::scene::state::{BodyState, NeedleInsertion, ToolState, WorldState};
use crate::scene::substep_hold::SubstepHold;
use crate::scene::tool::{Pose, Wrench};
use std::sync::Arc;

/// Version of the byte format written by [`World::save_state`](crate::World::save_state).
pub const STATE_VERSION: u32 = 6;

const MAGIC: &[u8; 8] = b"TSIMSTAT";
const HEADER: usize = 8 + 4 + 4 + 4 + 8 + 4 + 4;
/// Bytes of one particle: position, velocity, rotation, fixed flag.
const PARTICLE_BYTES: usize = 10 * 8 + 1;
/// Bytes of a tool's fixed part: poses, velocity, wrench, then the grasp's slip force and
/// attachment count, then the needle's punctured body, entry point and hold count.
const TOOL_BYTES: usize = (7 + 7 + 3 + 3 + 3 + 1) * 8 + 4 + 8 + 4 + 4 + 3 * 8 + 4;
/// Bytes of one grasp attachment: body, particle, anchor, compliance.
const ATTACHMENT_BYTES: usize = 4 + 4 + 4 * 8;
/// Bytes of one needle hold: particle, anchor.
const HOLD_BYTES: usize = 4 + 3 * 8;
/// The punctured-body field of a needle that is out of the tissue (or of a tool that is not a
/// needle).
const NO_BODY: u32 = u32::MAX;

fn fnv1a(bytes: &[u8]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for &b in bytes {
        h ^= b as u64;
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}

struct Writer<'a>(&'a mut Vec<u8>);

impl Writer<'_> {
    fn u32(&mut self, v: u32) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    fn f64(&mut self, v: Real) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    fn vec3(&mut self, v: &Vec3) {
        v.iter().for_each(|c| self.f64(*c));
    }
    fn quat(&mut self, q: &Quat) {
        [q.w, q.i, q.j, q.k].iter().for_each(|c| self.f64(*c));
    }
    fn pose(&mut self, p: &Pose) {
        self.vec3(&p.position);
        self.quat(&p.orientation);
    }
    fn list(&mut self, list: &[u32]) {
        self.u32(list.len() as u32);
        list.iter().for_each(|&k| self.u32(k));
    }
}

/// Reads the bytes before the checksum; every read is bounds-checked.
struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl<'a> Reader<'a> {
    fn take<const N: usize>(&mut self) -> Result<[u8; N], Error> {
        let end = self.at + N;
        let b = self.bytes.get(self.at..end).ok_or_else(too_short)?;
        self.at = end;
        Ok(b.try_into().unwrap_or([0; N]))
    }
    fn u32(&mut self) -> Result<u32, Error> {
        self.take::<4>().map(u32::from_le_bytes)
    }
    fn f64(&mut self) -> Result<Real, Error> {
        self.take::<8>().map(f64::from_le_bytes)
    }
    fn vec3(&mut self) -> Result<Vec3, Error> {
        Ok(Vec3::new(self.f64()?, self.f64()?, self.f64()?))
    }
    fn quat(&mut self) -> Result<Quat, Error> {
        let (w, i, j, k) = (self.f64()?, self.f64()?, self.f64()?, self.f64()?);
        Ok(Quat::new_unchecked(nalgebra::Quaternion::new(w, i, j, k)))
    }
    fn pose(&mut self) -> Result<Pose, Error> {
        Ok(Pose {
            position: self.vec3()?,
            orientation: self.quat()?,
        })
    }
    /// A count of items of `size` bytes each that must fit in the bytes left.
    fn count(&mut self, size: usize, what: &str) -> Result<usize, Error> {
        let n = self.u32()? as usize;
        if n.saturating_mul(size) > self.bytes.len() - self.at {
            return Err(Error::BadState(format!(
                "the state declares {n} {what} beyond its end"
            )));
        }
        Ok(n)
    }
    fn list(&mut self, what: &str) -> Result<Vec<u32>, Error> {
        let n = self.count(4, what)?;
        (0..n).map(|_| self.u32()).collect()
    }
}

/// Bytes of a state of `bodies` (particle count, cut entries of each) and `tools` (grasp
/// attachments, needle holds of each).
pub(crate) fn layout_size(
    bodies: impl Iterator<Item = (usize, usize)>,
    tools: impl Iterator<Item = (usize, usize)>,
) -> usize {
    let bodies: usize = bodies
        .map(|(particles, cuts)| 4 + particles * PARTICLE_BYTES + 8 + 4 * cuts)
        .sum();
    let tools: usize = tools
        .map(|(attachments, holds)| {
            TOOL_BYTES + attachments * ATTACHMENT_BYTES + holds * HOLD_BYTES
        })
        .sum();
    HEADER + bodies + tools + 8
}

fn too_short() -> Error {
    Error::BadState("the state is too short for what it declares".into())
}

impl WorldState {
    /// Append the state to `out` in the byte format of [`crate::state`].
    pub fn to_bytes(&self, out: &mut Vec<u8>) {
        let start = out.len();
        let mut w = Writer(out);
        w.0.extend_from_slice(MAGIC);
        w.u32(STATE_VERSION);
        w.u32(self.bodies.len() as u32);
        w.u32(self.tools.len() as u32);
        w.f64(self.time);
        w.u32(self.substep_hold.count);
        w.u32(self.substep_hold.steps_left);
        for b in &self.bodies {
            let p = &b.particles;
            w.u32(p.x.len() as u32);
            p.x.iter().for_each(|x| w.vec3(x));
            p.v.iter().for_each(|v| w.vec3(v));
            p.rotation.iter().for_each(|q| w.quat(q));
            w.0.extend(b.fixed.iter().map(|&f| f as u8));
            let none = Vec::new();
            let (pairs, tets) = b.cuts.as_deref().map_or((&none, &none), |(p, t)| (p, t));
            w.list(pairs);
            w.list(tets);
        }
        for t in &self.tools {
            w.pose(&t.pose);
            w.pose(&t.target);
            w.vec3(&t.linear_velocity);
            w.vec3(&t.wrench.force);
            w.vec3(&t.wrench.torque);
            w.u32(t.wrench.contact_count);
            w.f64(t.wrench.max_penetration);
            w.f64(t.grasp.max_force);
            w.u32(t.grasp.attachments.len() as u32);
            for a in &t.grasp.attachments {
                w.u32(a.body);
                w.u32(a.particle);
                w.vec3(&a.anchor);
                w.f64(a.compliance);
            }
            w.u32(t.needle.body.unwrap_or(NO_BODY));
            w.vec3(&t.needle.entry);
            w.u32(t.needle.holds.len() as u32);
            for h in &t.needle.holds {
                w.u32(h.particle);
                w.vec3(&h.anchor);
            }
        }
        let sum = fnv1a(&out[start..]);
        out.extend_from_slice(&sum.to_le_bytes());
    }

    /// Size in bytes of what [`WorldState::to_bytes`] writes.
    pub fn byte_size(&self) -> usize {
        let bodies = self.bodies.iter().map(|b| {
            let cuts = b.cuts.as_ref().map_or(0, |c| c.0.len() + c.1.len());
            (b.particles.x.len(), cuts)
        });
        let tools = (self.tools.iter()).map(|t| (t.grasp.attachments.len(), t.needle.holds.len()));
        layout_size(bodies, tools)
    }

    /// Read a state written by [`WorldState::to_bytes`]. Checks the magic bytes, the version,
    /// the checksum and the layout (every count within the bytes, nothing left over); the
    /// values are checked against a world by [`World::set_state`](crate::World::set_state).
    /// [`Error::BadState`] says what is wrong.
    pub fn from_bytes(bytes: &[u8]) -> Result<WorldState, Error> {
        let bad = |m: &str| Err(Error::BadState(m.to_string()));
        if bytes.len() < HEADER + 8 || &bytes[..8] != MAGIC {
            return bad("not a tissuesim state (magic bytes missing)");
        }
        let body_len = bytes.len() - 8;
        let mut r = Reader {
            bytes: &bytes[..body_len],
            at: 8,
        };
        let version = r.u32()?;
        if version != STATE_VERSION {
            return Err(Error::BadState(format!(
                "state format version {version}, this library reads {STATE_VERSION}"
            )));
        }
        let sum = u64::from_le_bytes(bytes[body_len..].try_into().unwrap_or([0; 8]));
        if fnv1a(&bytes[..body_len]) != sum {
            return bad("checksum mismatch (corrupted state)");
        }
        let body_count = r.count(4 + 8, "bodies")?;
        let tool_count = r.count(TOOL_BYTES, "tools")?;
        let time = r.f64()?;
        let substep_hold = SubstepHold {
            count: r.u32()?,
            steps_left: r.u32()?,
        };
        let mut bodies = Vec::with_capacity(body_count);
        for _ in 0..body_count {
            let n = r.count(PARTICLE_BYTES, "particles")?;
            let x = (0..n).map(|_| r.vec3()).collect::<Result<_, _>>()?;
            let v = (0..n).map(|_| r.vec3()).collect::<Result<_, _>>()?;
            let rotation = (0..n).map(|_| r.quat()).collect::<Result<_, _>>()?;
            let fixed = (0..n)
                .map(|_| match r.take::<1>()? {
                    [0] => Ok(false),
                    [1] => Ok(true),
                    _ => Err(Error::BadState("a fixed flag other than 0 or 1".into())),
                })
                .collect::<Result<_, _>>()?;
            let (pairs, tets) = (r.list("cut pairs")?, r.list("removed tetrahedra")?);
            let cut = !(pairs.is_empty() && tets.is_empty());
            bodies.push(BodyState {
                particles: ParticleState { x, v, rotation },
                fixed,
                cuts: cut.then(|| Arc::new((pairs, tets))),
            });
        }
        let mut tools = Vec::with_capacity(tool_count);
        for _ in 0..tool_count {
            let (pose, target, linear_velocity) = (r.pose()?, r.pose()?, r.vec3()?);
            let wrench = Wrench {
                force: r.vec3()?,
                torque: r.vec3()?,
                contact_count: r.u32()?,
                max_penetration: r.f64()?,
            };
            let max_force = r.f64()?;
            let attachments = (0..r.count(ATTACHMENT_BYTES, "grasped particles")?)
                .map(|_| {
                    Ok(Attachment {
                        body: r.u32()?,
                        particle: r.u32()?,
                        anchor: r.vec3()?,
                        compliance: r.f64()?,
                        lambda: Vec3::zeros(),
                    })
                })
                .collect::<Result<_, Error>>()?;
            let (body, entry) = (r.u32()?, r.vec3()?);
            let holds = (0..r.count(HOLD_BYTES, "needle holds")?)
                .map(|_| {
                    Ok(ShaftHold {
                        particle: r.u32()?,
                        anchor: r.vec3()?,
                        lambda: Vec3::zeros(),
                    })
                })
                .collect::<Result<_, Error>>()?;
            tools.push(ToolState {
                pose,
                target,
                linear_velocity,
                wrench,
                grasp: Grasp {
                    attachments,
                    max_force,
                    acc_impulse: Vec3::zeros(),
                },
                needle: NeedleInsertion {
                    body: (body != NO_BODY).then_some(body),
                    entry,
                    holds,
                },
            });
        }
        if r.at != body_len {
            return Err(Error::BadState(format!(
                "{} bytes left over after the state's last tool",
                body_len - r.at
            )));
        }
        Ok(WorldState {
            time,
            substep_hold,
            bodies,
            tools,
        })
    }
}
