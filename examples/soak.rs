//! Soak run (docs/VALIDATION.md "Soak"; not part of CI): the hanging default organ probed for a
//! long time along random paths at up to 2 m/s with an occasional teleport, cycling through
//! every tool shape and both contact modes. Counts steps, diverged (rolled-back) steps and any
//! non-finite value that escaped, and samples the resident memory, which must stay flat.
//!
//! ```text
//! cargo run --release --example soak -- [STEPS]     # default 1000000
//! ```
//!
//! Prints one line per phase (tool shape × contact mode) and a summary; exits non-zero if a
//! non-finite position escaped or the resident memory grew by more than 1 MB within a phase
//! (measured from its 1000th step to its end).

use tissuesim::{BodyOptions, ContactMode, Error, Pose, Real, Settings, ToolOptions, ToolShape};
use tissuesim::{Quat, Vec3, World};

/// Resident set size (bytes) from /proc/self/statm (0 where there is none).
fn resident_bytes() -> u64 {
    let statm = std::fs::read_to_string("/proc/self/statm").unwrap_or_default();
    let pages: u64 = statm
        .split_whitespace()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(0);
    pages * 4096
}

/// xorshift64: a seeded random number in [-1, 1).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> Real {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as Real / (1u64 << 53) as Real * 2.0 - 1.0
    }
    fn point(&mut self) -> Vec3 {
        Vec3::new(0.1 * self.next(), 0.06 * self.next(), 0.08 * self.next())
    }
}

fn shapes() -> Vec<(&'static str, ToolShape)> {
    vec![
        ("sphere 5 mm", ToolShape::Sphere { radius: 0.005 }),
        (
            "capsule",
            ToolShape::Capsule {
                half_height: 0.02,
                radius: 0.003,
            },
        ),
        (
            "cylinder",
            ToolShape::Cylinder {
                half_height: 0.02,
                radius: 0.004,
            },
        ),
        (
            "box",
            ToolShape::Cuboid {
                half_extents: Vec3::new(0.01, 0.004, 0.015),
            },
        ),
    ]
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let total: u64 = match std::env::args().nth(1) {
        Some(s) => s.parse()?,
        None => 1_000_000,
    };
    let phases: Vec<(ContactMode, (&str, ToolShape))> =
        [ContactMode::ExactShape, ContactMode::SampledPoints]
            .into_iter()
            .flat_map(|m| shapes().into_iter().map(move |s| (m, s)))
            .collect();
    let per_phase = (total / phases.len() as u64).max(1);
    let mut rng = Rng(0x50a4_2026);
    let (mut all_steps, mut all_diverged, mut escaped) = (0u64, 0u64, 0u64);
    let mut worst_growth = 0i64;
    let start = std::time::Instant::now();
    for (mode, (name, shape)) in phases {
        let settings = Settings {
            contact_mode: mode,
            ..Settings::default()
        };
        let dt = settings.dt;
        let mut w = World::new(settings)?;
        let b = w.add_body(&tissuesim::mesh::default_organ(), &BodyOptions::default())?;
        w.fix_box(b, Vec3::new(-1.0, 0.04, -1.0), Vec3::repeat(1.0))?;
        let options = ToolOptions {
            friction_static: 0.4,
            friction_kinetic: 0.3,
            ..ToolOptions::default()
        };
        let mut pose = Pose::at(Vec3::new(0.0, 0.0, 0.2));
        let t = w.add_tool(shape, pose, &options)?;
        let mut saved = Vec::new();
        w.save_state(&mut saved);
        let (mut target, mut speed) = (rng.point(), 0.0);
        let (mut diverged, mut restores) = (0u64, 0u64);
        let mut memory_at_start = resident_bytes();
        for step in 0..per_phase {
            // A new random target every ~0.2 s at up to 2 m/s; a teleport one step in 5000.
            if step % 200 == 0 {
                target = rng.point();
                speed = 2.0 * (0.5 + 0.5 * rng.next());
            }
            let to_target = target - pose.position;
            let reach = speed * dt;
            pose.position += if step % 5000 == 4999 {
                to_target
            } else {
                to_target * (reach / to_target.norm().max(reach))
            };
            let tilt = Vec3::new(rng.next(), rng.next(), rng.next()) * 0.01;
            pose.orientation = Quat::from_scaled_axis(tilt) * pose.orientation;
            w.set_tool_pose(t, pose)?;
            match w.step() {
                Ok(_) => {}
                Err(Error::Diverged(reason)) => {
                    if diverged < 3 {
                        eprintln!("  step {step}: {reason}");
                    }
                    diverged += 1;
                    // The documented remedy: restore the last good state.
                    if diverged % 10 == 0 {
                        w.restore_state(&saved)?;
                        pose = w.tool(t)?.pose();
                        restores += 1;
                    }
                }
                Err(e) => return Err(e.into()),
            }
            if step == 999 {
                memory_at_start = resident_bytes();
            }
            if step % 10_000 == 9_999 {
                let body = w.body(b)?;
                if body
                    .positions()
                    .iter()
                    .any(|x| !x.iter().all(|c| c.is_finite()))
                {
                    escaped += 1;
                }
                saved.clear();
                w.save_state(&mut saved);
            }
        }
        let rss = resident_bytes();
        worst_growth = worst_growth.max(rss as i64 - memory_at_start as i64);
        println!(
            "{mode:?} {name}: {per_phase} steps, {diverged} diverged (rolled back), {restores} \
             restores, volume ratio {:.4}, resident {:.1} MB",
            w.body(b)?.volume_ratio(),
            rss as f64 / 1e6
        );
        all_steps += per_phase;
        all_diverged += diverged;
    }
    println!(
        "soak: {all_steps} steps in {:.0} s, {all_diverged} diverged and rolled back, {escaped} \
         non-finite escaped, largest resident memory growth within a phase {:.2} MB",
        start.elapsed().as_secs_f64(),
        worst_growth as f64 / 1e6
    );
    if escaped > 0 || worst_growth > 1_000_000 {
        return Err("soak failed".into());
    }
    Ok(())
}
