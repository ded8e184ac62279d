//! Soak run (docs/VALIDATION.md "Soak"; not part of CI): the hanging default organ probed for a
//! long time along random paths at up to 2 m/s with an occasional teleport, cycling through
//! every tool shape and both contact modes. Counts steps, diverged (rolled-back) steps and any
//! non-finite value that escaped, and samples the resident memory, which must stay flat. Measures
//! the geometry too: every 100 steps the organ's crossing surface-triangle pairs (an exact
//! triangle–triangle test independent of the library, `tests/common/intersections.rs`), and
//! every 10 steps how deep the organ's surface (its boundary vertices and triangle centroids)
//! is inside the tool, counting the checks where it is deeper than a fifth of the tool's
//! radius (DESIGN §7). Both are reported, not failed on: a teleport puts the tool where it
//! lands.
//!
//! ```text
//! cargo run --release --example soak -- [STEPS] [--self-contact] [--crushed-substeps N]
//!     [--damping S] [--seed N]
//! ```
//! `STEPS` defaults to 1000000. `--self-contact` turns on `Settings::self_contact` (off by
//! default); `--crushed-substeps N` sets `Settings::crushed_substeps` (1 by default);
//! `--damping S` the stiffness-proportional damping time β (s, `Settings::damping_stiffness`); `--seed`
//! the random paths' seed (a non-zero integer; the default is the one of the runs reported).
//!
//! Prints one line per phase (tool shape × contact mode) and a summary; exits non-zero if a
//! non-finite position escaped or the resident memory grew by more than 1 MB within a phase
//! (measured from its 1000th step to its end).

#[path = "../tests/common/intersections.rs"]
mod intersections;

use tissuesim::{Body, BodyOptions, ContactMode, Error, Pose, Real, Settings, Tool, ToolOptions};
use tissuesim::{Quat, ToolShape, Vec3, World};

/// Steps between two counts of crossing surface triangles.
const CROSSING_EVERY: u64 = 100;
/// Steps between two measures of the surface's depth inside the tool.
const OVERLAP_EVERY: u64 = 10;
/// Depth of the surface inside the tool counted as an overlap, in tool radii (DESIGN §7).
const OVERLAP_DEPTH: Real = 0.2;

/// Deepest (m) any boundary vertex or triangle centroid of `body` is inside `tool`, whose
/// points all lie within `extent` (m) of its position (0 when none is inside).
fn surface_depth_in_tool(body: &Body, tool: &Tool, extent: Real) -> Real {
    let (x, pose) = (body.positions(), tool.pose());
    body.boundary_triangles()
        .iter()
        .flat_map(|t| {
            let [a, b, c] = t.map(|k| x[k as usize]);
            [a, b, c, (a + b + c) / 3.0]
        })
        .filter(|p| (p - pose.position).norm() <= extent)
        .map(|p| -tool.signed_distance(&pose, &p))
        .fold(0.0, Real::max)
}

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

/// A tool of the soak.
struct Probe {
    name: &'static str,
    shape: ToolShape,
    /// Its radius (m; the box's smallest half extent).
    radius: Real,
    /// The radius (m) of a sphere about its position that holds it.
    extent: Real,
}

fn probes() -> Vec<Probe> {
    let probe = |name, shape, radius, extent| Probe {
        name,
        shape,
        radius,
        extent,
    };
    vec![
        probe(
            "sphere 5 mm",
            ToolShape::Sphere { radius: 0.005 },
            0.005,
            0.005,
        ),
        probe(
            "capsule",
            ToolShape::Capsule {
                half_height: 0.02,
                radius: 0.003,
            },
            0.003,
            0.023,
        ),
        probe(
            "cylinder",
            ToolShape::Cylinder {
                half_height: 0.02,
                radius: 0.004,
            },
            0.004,
            0.0204,
        ),
        probe(
            "box",
            ToolShape::Cuboid {
                half_extents: Vec3::new(0.01, 0.004, 0.015),
            },
            0.004,
            0.0185,
        ),
    ]
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let (mut total, mut self_contact, mut crushed_substeps) = (1_000_000, false, 1);
    let mut damping_stiffness = Settings::default().damping_stiffness;
    let mut seed = 0x50a4_2026;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--self-contact" => self_contact = true,
            "--crushed-substeps" => {
                crushed_substeps = args.next().ok_or("--crushed-substeps N")?.parse()?
            }
            "--damping" => damping_stiffness = args.next().ok_or("--damping S")?.parse()?,
            "--seed" => seed = args.next().ok_or("--seed N")?.parse()?,
            steps => total = steps.parse()?,
        }
    }
    let phases: Vec<(ContactMode, Probe)> = [ContactMode::ExactShape, ContactMode::SampledPoints]
        .into_iter()
        .flat_map(|m| probes().into_iter().map(move |p| (m, p)))
        .collect();
    let per_phase = (total / phases.len() as u64).max(1);
    let mut rng = Rng(seed);
    let (mut all_steps, mut all_diverged, mut escaped) = (0u64, 0u64, 0u64);
    let mut worst_growth = 0i64;
    let start = std::time::Instant::now();
    let (mut all_crossing, mut all_overlaps) = (0u64, 0u64);
    for (mode, probe) in phases {
        let Probe {
            name,
            shape,
            radius,
            extent,
        } = probe;
        let settings = Settings {
            contact_mode: mode,
            self_contact,
            crushed_substeps,
            damping_stiffness,
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
        // Checks with crossing surface triangles, and the most pairs at one check.
        let (mut crossing_checks, mut most_pairs) = (0u64, 0usize);
        // Checks with the surface deeper than OVERLAP_DEPTH radii in the tool, and the deepest.
        let (mut overlaps, mut deepest) = (0u64, 0.0 as Real);
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
            if step % CROSSING_EVERY == CROSSING_EVERY - 1 {
                let body = w.body(b)?;
                let pairs =
                    intersections::crossing_pairs(body.positions(), body.boundary_triangles());
                crossing_checks += u64::from(!pairs.is_empty());
                most_pairs = most_pairs.max(pairs.len());
            }
            if step % OVERLAP_EVERY == OVERLAP_EVERY - 1 {
                let depth = surface_depth_in_tool(w.body(b)?, w.tool(t)?, extent);
                overlaps += u64::from(depth > OVERLAP_DEPTH * radius);
                deepest = deepest.max(depth);
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
             restores, volume ratio {:.4}, resident {:.1} MB; self-intersections at {} of {} \
             checks (at most {most_pairs} crossing pairs); surface more than {OVERLAP_DEPTH} \
             radii in the tool at {overlaps} of {} checks (deepest {:.2} mm)",
            w.body(b)?.volume_ratio(),
            rss as f64 / 1e6,
            crossing_checks,
            per_phase / CROSSING_EVERY,
            per_phase / OVERLAP_EVERY,
            deepest * 1e3
        );
        all_steps += per_phase;
        all_diverged += diverged;
        all_crossing += crossing_checks;
        all_overlaps += overlaps;
    }
    println!(
        "soak: {all_steps} steps in {:.0} s, {all_diverged} diverged and rolled back, {escaped} \
         non-finite escaped, largest resident memory growth within a phase {:.2} MB, \
         self-intersections at {all_crossing} checks, tool overlaps at {all_overlaps} checks",
        start.elapsed().as_secs_f64(),
        worst_growth as f64 / 1e6
    );
    if escaped > 0 || worst_growth > 1_000_000 {
        return Err("soak failed".into());
    }
    Ok(())
}
