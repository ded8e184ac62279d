//! Save and restore a world's dynamic state in an explicit, versioned byte format.
//!
//! Layout (all little-endian):
//!
//! | field | type |
//! |---|---|
//! | magic `TSIMSTAT` | 8 bytes |
//! | format version ([`STATE_VERSION`]) | u32 |
//! | body count, tool count | u32, u32 |
//! | time (s) | f64 |
//! | per body: particle count, then positions (m), velocities (m/s) as xyz, rotations as wxyz | u32, f64… |
//! | per tool in the world (removed tools left out), in id order: pose, target pose (xyz, wxyz), linear velocity (m/s), force (N), torque (N·m), contact count, max penetration (m) | f64…, u32, f64 |
//! | then its grasp: slip force (N), attachment count, and per attachment body, particle, anchor in the tool frame (m), compliance (m/N) | f64, u32, (u32, u32, f64 × 4)… |
//! | then its needle: punctured body (`u32::MAX`: none, or not a needle), entry point (m), hold count, and per hold particle, anchor in the tool frame (m) | u32, f64 × 3, u32, (u32, f64 × 3)… |
//! | per body: cut pairs (count, load-time pair indices, increasing), removed tetrahedra (count, load-time indices, increasing) | u32, u32…, u32, u32… |
//! | FNV-1a 64 checksum of everything before it | u64 |
//!
//! The scene itself (meshes, materials, fixed particles, settings) is not part of the state: a
//! state restores into a world built the same way. Its size depends on the grasps and needle holds in force
//! ([`World::state_size`] at the time of saving). Restoring then stepping reproduces the
//! original run bit for bit.

use crate::collision::tool::{Pose, Wrench};
use crate::error::Error;
use crate::grasp::{Attachment, Grasp};
use crate::math::{is_finite_vec, Quat, Real, Vec3};
use crate::needle::{Needle, ShaftHold};
use crate::world::World;

/// Version of the byte format written by [`World::save_state`].
pub const STATE_VERSION: u32 = 2;

const MAGIC: &[u8; 8] = b"TSIMSTAT";
const HEADER: usize = 8 + 4 + 4 + 4 + 8;
const TOOL_REALS: usize = 7 + 7 + 3 + 3 + 3 + 1;
/// Bytes of a tool's pose, velocity and wrench: the reals and the contact count.
const TOOL_MOTION_BYTES: usize = TOOL_REALS * 8 + 4;
/// Bytes of a tool's fixed part: motion, then the grasp's slip force and attachment count, then
/// the needle's punctured body, entry point and hold count.
const TOOL_BYTES: usize = TOOL_MOTION_BYTES + 8 + 4 + 4 + 3 * 8 + 4;
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
}

struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl Reader<'_> {
    fn u32(&mut self) -> u32 {
        let v = u32::from_le_bytes(
            self.bytes[self.at..self.at + 4]
                .try_into()
                .unwrap_or([0; 4]),
        );
        self.at += 4;
        v
    }
    fn f64(&mut self) -> Real {
        let v = f64::from_le_bytes(
            self.bytes[self.at..self.at + 8]
                .try_into()
                .unwrap_or([0; 8]),
        );
        self.at += 8;
        v
    }
    fn vec3(&mut self) -> Vec3 {
        Vec3::new(self.f64(), self.f64(), self.f64())
    }
    fn quat(&mut self) -> Quat {
        let (w, i, j, k) = (self.f64(), self.f64(), self.f64(), self.f64());
        Quat::new_unchecked(nalgebra::Quaternion::new(w, i, j, k))
    }
    fn pose(&mut self) -> Pose {
        Pose {
            position: self.vec3(),
            orientation: self.quat(),
        }
    }
}

impl World {
    /// Size in bytes of the state [`World::save_state`] writes.
    pub fn state_size(&self) -> usize {
        let particles: usize = self.bodies.iter().map(|b| b.particle_count()).sum();
        HEADER
            + self.bodies.len() * 4
            + particles * 10 * 8
            + self.tool_count() * TOOL_BYTES
            + self.tool_extras(|g, n| {
                g.attachments.len() * ATTACHMENT_BYTES + n.map_or(0, |n| n.holds.len() * HOLD_BYTES)
            })
            + self
                .bodies
                .iter()
                .map(|b| {
                    let (pairs, tets) = crate::cut::cut_sets(b);
                    8 + 4 * (pairs.len() + tets.len())
                })
                .sum::<usize>()
            + 8
    }

    /// Σ `f(grasp, needle)` over the tools in the world.
    fn tool_extras(&self, f: impl Fn(&Grasp, Option<&Needle>) -> usize) -> usize {
        self.tools
            .iter()
            .zip(self.grasps.iter().zip(&self.needles))
            .filter(|(t, _)| t.is_some())
            .map(|(_, (g, n))| f(g, n.as_ref()))
            .sum()
    }

    /// Append the dynamic state (time, particle positions, velocities and rotations, tool poses,
    /// velocities, wrenches and grasps) to `out`, in the format of [`crate::state`].
    pub fn save_state(&self, out: &mut Vec<u8>) {
        let start = out.len();
        out.reserve(self.state_size());
        let mut w = Writer(out);
        w.0.extend_from_slice(MAGIC);
        w.u32(STATE_VERSION);
        w.u32(self.bodies.len() as u32);
        w.u32(self.tool_count() as u32);
        w.f64(self.time);
        for b in &self.bodies {
            w.u32(b.particle_count() as u32);
            b.state.x.iter().for_each(|p| w.vec3(p));
            b.state.v.iter().for_each(|v| w.vec3(v));
            b.state.rotation.iter().for_each(|q| w.quat(q));
        }
        for (t, (g, needle)) in self.tools.iter().zip(self.grasps.iter().zip(&self.needles)) {
            let Some(t) = t else { continue };
            w.pose(&t.pose);
            w.pose(&t.target);
            w.vec3(&t.linear_velocity);
            w.vec3(&t.wrench.force);
            w.vec3(&t.wrench.torque);
            w.u32(t.wrench.contact_count);
            w.f64(t.wrench.max_penetration);
            w.f64(g.max_force);
            w.u32(g.attachments.len() as u32);
            for a in &g.attachments {
                w.u32(a.body);
                w.u32(a.particle);
                w.vec3(&a.anchor);
                w.f64(a.compliance);
            }
            match needle {
                Some(n) => {
                    w.u32(n.body.unwrap_or(NO_BODY));
                    w.vec3(&n.entry);
                    w.u32(n.holds.len() as u32);
                    for h in &n.holds {
                        w.u32(h.particle);
                        w.vec3(&h.anchor);
                    }
                }
                None => {
                    w.u32(NO_BODY);
                    w.vec3(&Vec3::zeros());
                    w.u32(0);
                }
            }
        }
        for b in &self.bodies {
            let (pairs, tets) = crate::cut::cut_sets(b);
            for list in [pairs, tets] {
                w.u32(list.len() as u32);
                list.iter().for_each(|&k| w.u32(k));
            }
        }
        let sum = fnv1a(&out[start..]);
        out.extend_from_slice(&sum.to_le_bytes());
    }

    /// Restore a state written by [`World::save_state`] of a world built the same way. On any
    /// mismatch (magic, version, counts, size, checksum, non-finite values, a particle
    /// farther than [`STATE_POSITION_LIMIT`](crate::STATE_POSITION_LIMIT) body sizes from
    /// its body's rest centre or faster than
    /// [`STATE_SPEED_LIMIT`](crate::STATE_SPEED_LIMIT) body sizes per second) the world
    /// is left unchanged and [`Error::BadState`] says why.
    pub fn restore_state(&mut self, bytes: &[u8]) -> Result<(), Error> {
        let bad = |m: &str| Err(Error::BadState(m.to_string()));
        if bytes.len() < HEADER + 8 || &bytes[..8] != MAGIC {
            return bad("not a tissuesim state (magic bytes missing)");
        }
        let mut r = Reader { bytes, at: 8 };
        let version = r.u32();
        if version != STATE_VERSION {
            return Err(Error::BadState(format!(
                "state format version {version}, this library reads {STATE_VERSION}"
            )));
        }
        if r.u32() as usize != self.bodies.len() || r.u32() as usize != self.tool_count() {
            return bad("body or tool count differs from this world");
        }
        let body_len = bytes.len() - 8;
        let sum = u64::from_le_bytes(bytes[body_len..].try_into().unwrap_or([0; 8]));
        if fnv1a(&bytes[..body_len]) != sum {
            return bad("checksum mismatch (corrupted state)");
        }
        let (extras, cuts_at) = self.read_tool_extras(bytes)?;
        let cuts = self.read_cuts(bytes, cuts_at)?;
        // Check particle counts and finiteness before changing anything.
        let mut check = Reader { bytes, at: HEADER };
        for b in &self.bodies {
            if check.u32() as usize != b.particle_count() {
                return bad("particle count differs from this world");
            }
            check.at += b.particle_count() * 10 * 8;
        }
        let mut scan = Reader {
            bytes,
            at: HEADER - 8,
        };
        if !scan.f64().is_finite() {
            return bad("non-finite time");
        }
        for (k, b) in self.bodies.iter().enumerate() {
            scan.at += 4;
            let n = b.particle_count();
            let velocities = scan.at + n * 24;
            for i in 0..n {
                let x = scan.vec3();
                let mut at_v = Reader {
                    bytes,
                    at: velocities + i * 24,
                };
                let v = at_v.vec3();
                if let Err(m) = b.check_state(i, &x, &v) {
                    return Err(Error::BadState(format!("body {k} {m}")));
                }
            }
            scan.at = velocities + n * 24;
            if (0..n * 4).any(|_| !scan.f64().is_finite()) {
                return bad("non-finite particle rotation");
            }
        }
        for extra in &extras {
            let head_finite = (0..TOOL_REALS - 1).all(|_| scan.f64().is_finite());
            scan.at += 4;
            if !head_finite || !scan.f64().is_finite() {
                return bad("non-finite tool state");
            }
            scan.at += extra.bytes;
        }
        // Everything checked: apply.
        for (b, (pairs, tets)) in self.bodies.iter_mut().zip(&cuts) {
            crate::cut::restore(b, pairs, tets);
        }
        r.at = HEADER - 8;
        self.time = r.f64();
        for b in &mut self.bodies {
            r.u32();
            b.state.x.iter_mut().for_each(|p| *p = r.vec3());
            b.state.v.iter_mut().for_each(|v| *v = r.vec3());
            b.state.rotation.iter_mut().for_each(|q| *q = r.quat());
        }
        let mut extras = extras.into_iter();
        let slots = self.grasps.iter_mut().zip(&mut self.needles);
        for (t, (g, needle)) in self.tools.iter_mut().zip(slots) {
            let Some(t) = t else { continue };
            t.pose = r.pose();
            t.target = r.pose();
            t.linear_velocity = r.vec3();
            let force = r.vec3();
            let torque = r.vec3();
            let contact_count = r.u32();
            let max_penetration = r.f64();
            t.wrench = Wrench {
                force,
                torque,
                contact_count,
                max_penetration,
            };
            let Some(extra) = extras.next() else { break };
            r.at += extra.bytes;
            *g = extra.grasp;
            if let Some(n) = needle {
                (n.body, n.entry, n.holds) = extra.needle;
            }
        }
        Ok(())
    }

    /// The grasps and needle states of a state whose header, counts and checksum were checked,
    /// one per tool in the world, after checking the state's length against the counts it
    /// declares and every attachment and hold against this world (body, particle, finite
    /// anchor, compliance ≥ 0, needle state only for needles).
    fn read_tool_extras(&self, bytes: &[u8]) -> Result<(Vec<ToolExtras>, usize), Error> {
        let bad = |m: String| Err(Error::BadState(m));
        let mut at = HEADER;
        for b in &self.bodies {
            at += 4 + b.particle_count() * 10 * 8;
        }
        let particle_of = |body: u32, particle: u32| {
            self.bodies
                .get(body as usize)
                .is_some_and(|b| (particle as usize) < b.particle_count())
        };
        let mut out = Vec::with_capacity(self.tool_count());
        for (_, needle) in self
            .tools
            .iter()
            .zip(&self.needles)
            .filter(|(t, _)| t.is_some())
        {
            let start = at + TOOL_MOTION_BYTES;
            let fits = |end: Option<usize>| end.is_some_and(|end| end + 8 <= bytes.len());
            if !fits(Some(at + TOOL_BYTES)) {
                return bad(format!(
                    "state is {} bytes: too short for this world",
                    bytes.len()
                ));
            }
            let mut r = Reader { bytes, at: start };
            let max_force = r.f64();
            let count = r.u32() as usize;
            let grasp_end = count.checked_mul(ATTACHMENT_BYTES).map(|n| n + r.at);
            if !fits(grasp_end.map(|e| e + TOOL_BYTES - TOOL_MOTION_BYTES - 12)) {
                return bad(format!(
                    "state declares {count} grasped particles beyond its end"
                ));
            }
            if max_force.is_nan() || max_force <= 0.0 {
                return bad(format!("grasp slip force {max_force}"));
            }
            let mut attachments = Vec::with_capacity(count);
            for _ in 0..count {
                let (body, particle) = (r.u32(), r.u32());
                let (anchor, compliance) = (r.vec3(), r.f64());
                let ok = compliance >= 0.0 && compliance.is_finite();
                if !(particle_of(body, particle) && is_finite_vec(&anchor) && ok) {
                    return bad(format!(
                        "grasped particle {particle} of body {body}: unknown or non-finite"
                    ));
                }
                attachments.push(Attachment {
                    body,
                    particle,
                    anchor,
                    compliance,
                    lambda: Vec3::zeros(),
                });
            }
            let (body, entry, holds) = (r.u32(), r.vec3(), r.u32() as usize);
            if !fits(holds.checked_mul(HOLD_BYTES).map(|n| n + r.at)) {
                return bad(format!(
                    "state declares {holds} needle holds beyond its end"
                ));
            }
            let punctured = (body != NO_BODY).then_some(body);
            if (needle.is_none() && (punctured.is_some() || holds > 0))
                || punctured.is_some_and(|b| b as usize >= self.bodies.len())
                || !is_finite_vec(&entry)
            {
                return bad(format!("needle state (body {body}) does not fit this tool"));
            }
            let mut held = Vec::with_capacity(holds);
            for _ in 0..holds {
                let (particle, anchor) = (r.u32(), r.vec3());
                if !(punctured.is_some_and(|b| particle_of(b, particle)) && is_finite_vec(&anchor))
                {
                    return bad(format!(
                        "needle hold of particle {particle}: unknown or non-finite"
                    ));
                }
                held.push(ShaftHold {
                    particle,
                    anchor,
                    lambda: Vec3::zeros(),
                });
            }
            out.push(ToolExtras {
                bytes: r.at - start,
                grasp: Grasp {
                    attachments,
                    max_force,
                    acc_impulse: Vec3::zeros(),
                },
                needle: (punctured, entry, held),
            });
            at = r.at;
        }
        Ok((out, at))
    }

    /// The cut sets of every body (cut pairs, removed tetrahedra; load-time indices) from the
    /// section starting at `at`, after checking them against this world's bodies (in range,
    /// strictly increasing) and the state's length.
    fn read_cuts(&self, bytes: &[u8], mut at: usize) -> Result<Vec<crate::cut::CutSets>, Error> {
        let mut out = Vec::with_capacity(self.bodies.len());
        for (k, b) in self.bodies.iter().enumerate() {
            let (pair_count, tet_count) = crate::cut::load_time_counts(b);
            let mut lists = [Vec::new(), Vec::new()];
            for (list, limit) in lists.iter_mut().zip([pair_count, tet_count]) {
                if at + 4 + 8 > bytes.len() {
                    return Err(Error::BadState("state too short for its cut sets".into()));
                }
                let mut r = Reader { bytes, at };
                let count = r.u32() as usize;
                let end = count.checked_mul(4).map(|n| n + r.at);
                if !end.is_some_and(|end| end + 8 <= bytes.len()) {
                    return Err(Error::BadState(format!(
                        "body {k}: {count} cut entries beyond the state's end"
                    )));
                }
                for _ in 0..count {
                    let v = r.u32();
                    if v as usize >= limit || list.last().is_some_and(|&last| last >= v) {
                        return Err(Error::BadState(format!(
                            "body {k}: cut entry {v} out of range or out of order"
                        )));
                    }
                    list.push(v);
                }
                at = r.at;
            }
            let [pairs, tets] = lists;
            out.push((pairs, tets));
        }
        if at + 8 != bytes.len() {
            return Err(Error::BadState(format!(
                "state is {} bytes, this world's layout gives {}",
                bytes.len(),
                at + 8
            )));
        }
        Ok(out)
    }
}

/// What a state holds of a tool beyond its motion and wrench.
struct ToolExtras {
    /// Length of this part in the state (bytes).
    bytes: usize,
    grasp: Grasp,
    /// Punctured body, entry point (m), held particles.
    needle: (Option<u32>, Vec3, Vec<ShaftHold>),
}
