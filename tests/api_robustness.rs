//! "Robust under abuse": inputs a hostile host may pass must give a clear error, never an
//! abort, a hang or a poisoned world. Each test reproduces one report of the issue.

use std::sync::mpsc;
use std::time::Duration;
use tissuesim::mesh::{default_organ, lattice_box, TetMesh};
use tissuesim::{
    BodyOptions, ContactMode, Error, Material, Pose, Real, Settings, ToolOptions, ToolShape, Vec3,
    World,
};

/// Run `f` on its own thread; fail the test if it does not return within `secs` seconds.
fn within<T: Send + 'static>(secs: u64, what: &str, f: impl FnOnce() -> T + Send + 'static) -> T {
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        let _ = tx.send(f());
    });
    rx.recv_timeout(Duration::from_secs(secs))
        .unwrap_or_else(|_| panic!("{what} did not return within {secs} s"))
}

/// A 0.1 m cube of 4 × 4 × 4 cells (125 particles, cell 0.025 m).
fn cube() -> TetMesh {
    lattice_box(Vec3::repeat(-0.05), Vec3::repeat(0.05), [4, 4, 4])
}

fn invalid(r: Result<impl std::fmt::Debug, Error>, needle: &str) {
    match r {
        Err(Error::InvalidArgument(m)) => {
            assert!(
                m.contains(needle),
                "message `{m}` should mention `{needle}`"
            )
        }
        other => panic!("expected InvalidArgument mentioning `{needle}`, got {other:?}"),
    }
}

#[test]
fn tiny_and_huge_particle_radii_are_refused_with_a_message() {
    for r in [1e-9, 5e-324, 1e3] {
        let mut w = World::new(Settings::default()).unwrap();
        let options = BodyOptions {
            particle_radius: Some(r),
            ..BodyOptions::default()
        };
        invalid(w.add_body(&cube(), &options), "particle_radius");
    }
}

#[test]
fn support_radius_far_above_the_spacing_is_refused() {
    let mut w = World::new(Settings::default()).unwrap();
    let options = BodyOptions {
        support_radius: Some(1e3),
        ..BodyOptions::default()
    };
    invalid(w.add_body(&cube(), &options), "support_radius");
    let options = BodyOptions {
        support_radius: Some(1e-6),
        ..BodyOptions::default()
    };
    invalid(w.add_body(&cube(), &options), "support_radius");
}

#[test]
fn poisson_ratios_outside_the_supported_range_are_refused() {
    for nu in [-0.5, -0.999_999_99, -1e-3, 0.4999, 0.5, 0.7] {
        let mut w = World::new(Settings::default()).unwrap();
        let options = BodyOptions {
            material: Material {
                poisson_ratio: nu,
                ..Material::default()
            },
            ..BodyOptions::default()
        };
        invalid(w.add_body(&cube(), &options), "poisson_ratio");
    }
    for nu in [0.0, 0.3, 0.45, 0.49, 0.499] {
        let m = Material {
            poisson_ratio: nu,
            ..Material::default()
        };
        assert!(m.validate().is_ok(), "nu {nu} is supported");
    }
}

#[test]
fn degenerate_tool_meshes_are_refused() {
    let mut w = World::new(Settings::default()).unwrap();
    w.add_body(&cube(), &BodyOptions::default()).unwrap();
    let p = Vec3::new(0.3, 0.0, 0.0);
    // All vertices equal.
    let point = ToolShape::TriMesh {
        vertices: vec![p; 4],
        triangles: vec![[0, 1, 2], [0, 2, 3], [0, 3, 1], [1, 3, 2]],
    };
    invalid(
        w.add_tool(point, Pose::at(Vec3::zeros()), &ToolOptions::default()),
        "tool mesh",
    );
    // A tetrahedron surface plus one zero-area triangle (collinear vertices).
    let v = vec![
        Vec3::zeros(),
        Vec3::new(0.01, 0.0, 0.0),
        Vec3::new(0.0, 0.01, 0.0),
        Vec3::new(0.0, 0.0, 0.01),
        Vec3::new(0.02, 0.0, 0.0),
    ];
    let sliver = ToolShape::TriMesh {
        vertices: v.clone(),
        triangles: vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3], [0, 1, 4]],
    };
    invalid(
        w.add_tool(sliver, Pose::at(Vec3::zeros()), &ToolOptions::default()),
        "zero area",
    );
    // A flat mesh (two triangles in a plane): no volume.
    let flat = ToolShape::TriMesh {
        vertices: v[..3]
            .iter()
            .copied()
            .chain([Vec3::new(0.01, 0.01, 0.0)])
            .collect(),
        triangles: vec![[0, 1, 2], [1, 3, 2]],
    };
    invalid(
        w.add_tool(flat, Pose::at(Vec3::zeros()), &ToolOptions::default()),
        "flat",
    );
    // The world still steps.
    within(30, "step", move || w.step().map(|_| ())).unwrap();
}

#[test]
fn tool_sample_counts_are_bounded() {
    let settings = Settings {
        contact_mode: ContactMode::SampledPoints,
        ..Settings::default()
    };
    let r = within(30, "add_tool", move || {
        let mut w = World::new(settings).unwrap();
        w.add_body(&cube(), &BodyOptions::default()).unwrap();
        let absurd = ToolShape::Cuboid {
            half_extents: Vec3::repeat(1e300),
        };
        let too_big = w.add_tool(absurd, Pose::at(Vec3::zeros()), &ToolOptions::default());
        invalid(too_big.map(|_| ()), "half_extents");
        // 200 m across: a legal size, but ~10^9 samples at the default spacing.
        let huge = ToolShape::Cuboid {
            half_extents: Vec3::repeat(100.0),
        };
        let a = w.add_tool(huge, Pose::at(Vec3::zeros()), &ToolOptions::default());
        let options = ToolOptions {
            sample_spacing: Some(2e-6),
            ..ToolOptions::default()
        };
        let b = w.add_tool(
            ToolShape::Sphere { radius: 0.01 },
            Pose::at(Vec3::zeros()),
            &options,
        );
        (a.map(|_| ()), b.map(|_| ()))
    });
    invalid(r.0, "samples");
    invalid(r.1, "samples");
}

fn organ_world(settings: Settings) -> World {
    let mut w = World::new(settings).unwrap();
    let b = w
        .add_body(&default_organ(), &BodyOptions::default())
        .unwrap();
    w.fix_box(b, Vec3::new(-1.0, 0.04, -1.0), Vec3::repeat(1.0))
        .unwrap();
    w
}

#[test]
fn restore_refuses_far_positions_and_huge_velocities() {
    let mut w = World::new(Settings::default()).unwrap();
    w.add_body(&cube(), &BodyOptions::default()).unwrap();
    let mut good = Vec::new();
    w.save_state(&mut good);
    // Magic, version, counts, time; the substep hold; the first body's particle count.
    let hold = 8 + 4 + 4 + 4 + 8;
    let header = hold + 4 + 4 + 4;
    let n = w.body(tissuesim::BodyId(0)).unwrap().particle_count();
    let crafted = [
        (header, 1e300f64.to_le_bytes().to_vec(), "position"),
        (header + n * 24, 1e300f64.to_le_bytes().to_vec(), "velocity"),
        (hold + 4, 1000u32.to_le_bytes().to_vec(), "substep hold"),
    ];
    for (at, value, what) in crafted {
        let mut bad = good.clone();
        bad[at..at + value.len()].copy_from_slice(&value);
        // Re-seal the checksum: a crafted state, not a corrupt one.
        let body = bad.len() - 8;
        let sum = fnv1a(&bad[..body]);
        bad[body..].copy_from_slice(&sum.to_le_bytes());
        match w.restore_state(&bad) {
            Err(Error::BadState(m)) => assert!(m.contains(what), "{m}"),
            other => panic!("crafted {what} restored: {other:?}"),
        }
    }
    w.restore_state(&good).unwrap();
    within(30, "step", move || w.step().map(|_| ())).unwrap();
}

fn fnv1a(bytes: &[u8]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for &b in bytes {
        h ^= b as u64;
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}

#[test]
fn far_tool_poses_neither_hang_nor_poison() {
    let mut w = organ_world(Settings::default());
    let t = w
        .add_tool(
            ToolShape::Sphere { radius: 0.01 },
            Pose::at(Vec3::new(0.0, 0.0, 0.2)),
            &ToolOptions::default(),
        )
        .unwrap();
    let w = within(60, "steps with far poses", move || {
        for x in [1e300, -1e300, 1e12, 0.0] {
            let _ = w.set_tool_pose(t, Pose::at(Vec3::new(x, 0.0, 0.2)));
            let _ = w.step();
        }
        w
    });
    let _ = w;
}

/// The hanging organ in contact `mode` and a 1.5 cm sphere with friction 1, 0.3 m in front of
/// it (out of contact).
fn organ_and_sticky_probe(mode: ContactMode) -> (World, tissuesim::ToolId) {
    let mut w = organ_world(Settings {
        contact_mode: mode,
        ..Settings::default()
    });
    let options = ToolOptions {
        friction_static: 1.0,
        friction_kinetic: 1.0,
        ..ToolOptions::default()
    };
    let away = Pose::at(Vec3::new(0.0, 0.0, 0.3));
    let t = w
        .add_tool(ToolShape::Sphere { radius: 0.015 }, away, &options)
        .unwrap();
    (w, t)
}

/// Random tool motion inside the hanging organ, friction 1: with `walk` the tool moves by up to
/// `walk` (m) along each axis a step (swept across the substeps), without it it jumps to a
/// random point every step (10 cm a step: 100 m/s). Every step either succeeds with the organ
/// within the divergence limits or fails as `Diverged` and changes nothing; the world then
/// steps again from the state saved before the abuse. Returns the number of diverged steps and
/// the largest particle speed (m/s) after a successful step.
fn random_motion(mode: ContactMode, steps: usize, walk: Option<Real>) -> (u64, Real) {
    let (mut w, t) = organ_and_sticky_probe(mode);
    let limits = w.settings().divergence;
    let away = w.tool(t).unwrap().pose();
    let mut seed = 0x9e37_79b9_7f4a_7c15u64;
    let mut rnd = || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as Real / (1u64 << 53) as Real * 2.0 - 1.0
    };
    let b = tissuesim::BodyId(0);
    let (mut start, mut before, mut after) = (Vec::new(), Vec::new(), Vec::new());
    w.save_state(&mut start);
    let mut fastest: Real = 0.0;
    let mut at = Vec3::zeros();
    for _ in 0..steps {
        let random = Vec3::new(rnd(), rnd(), rnd());
        let p = match walk {
            Some(step) => at + random * step,
            None => random,
        };
        at = Vec3::new(
            p.x.clamp(-1.0, 1.0),
            p.y.clamp(-1.0, 1.0),
            p.z.clamp(-1.0, 1.0),
        );
        let p = at.component_mul(&Vec3::new(0.1, 0.05, 0.07));
        w.set_tool_pose(t, Pose::at(p)).unwrap();
        before.clear();
        w.save_state(&mut before);
        match w.step() {
            Ok(_) => {
                let body = w.body(b).unwrap();
                let r = body.volume_ratio();
                assert!(
                    (limits.volume_ratio.0..=limits.volume_ratio.1).contains(&r),
                    "{mode:?}: a step returned OK with a volume ratio of {r}"
                );
                let speed = body.velocities().iter().map(|v| v.norm());
                fastest = fastest.max(speed.fold(0.0, Real::max));
            }
            Err(Error::Diverged(_)) => {
                after.clear();
                w.save_state(&mut after);
                assert!(
                    before == after,
                    "{mode:?}: a diverged step changed the world"
                );
            }
            Err(e) => panic!("{mode:?}: {e}"),
        }
    }
    w.restore_state(&start).unwrap();
    assert_eq!(w.tool(t).unwrap().pose(), away);
    for k in 0..50 {
        if let Err(e) = w.step() {
            panic!("{mode:?}: step {k} after restoring the state: {e}");
        }
    }
    (w.diverged_steps(), fastest)
}

/// Random far jumps (100 m/s) are tracking glitches: the tool is placed, not swept, and the
/// tissue it lands in leaves it at `max_depenetration_speed`. No step diverges in either
/// contact mode. Before, tissue swept along at the tool's speed failed the speed bound on
/// 553 (exact shape) and 592 (sampled points) of 600 steps, and with the bound off the
/// sampled-points mode flew apart (11 times its size). Random swept motion at up to 12 m/s
/// (9, 4.5 and 6.3 mm a step along x, y, z; the jump speed is 17 m/s on this organ) never
/// diverges either.
#[test]
fn random_far_jumps_and_fast_sweeps_inside_the_organ_never_diverge() {
    for mode in [ContactMode::ExactShape, ContactMode::SampledPoints] {
        let (diverged, fastest) = random_motion(mode, 300, None);
        println!("{mode:?} jumps: {diverged} diverged, particles at up to {fastest:.2} m/s");
        assert_eq!(diverged, 0, "{mode:?}: random jumps");
        let (diverged, fastest) = random_motion(mode, 200, Some(0.09));
        println!("{mode:?} sweeps: {diverged} diverged, particles at up to {fastest:.2} m/s");
        assert_eq!(diverged, 0, "{mode:?}: random sweeps");
    }
}

/// A tool that jumps 30 cm into the middle of the organ in one 1 ms step (a tracking glitch,
/// 300 m/s) and stays there: no step diverges, the jump step's force is no kick (the
/// tissue is not swept along at 300 m/s), the tissue moves at a few m/s at most, and in the
/// sampled-points mode the particles the tool landed on are all out of it within 0.1 s.
#[test]
fn a_tool_jumping_into_the_organ_is_left_gently() {
    for mode in [ContactMode::ExactShape, ContactMode::SampledPoints] {
        let (mut w, t) = organ_and_sticky_probe(mode);
        w.set_tool_pose(t, Pose::at(Vec3::zeros())).unwrap();
        let b = tissuesim::BodyId(0);
        let inside = |w: &World| {
            let tool = w.tool(t).unwrap();
            let x = w.body(b).unwrap().positions();
            x.iter()
                .filter(|x| tool.signed_distance(&tool.pose(), x) < 0.0)
                .count()
        };
        let mut fastest: Real = 0.0;
        for k in 0..100 {
            w.step()
                .unwrap_or_else(|e| panic!("{mode:?}: step {k}: {e}"));
            let v = w.body(b).unwrap().velocities();
            fastest = fastest.max(v.iter().map(|v| v.norm()).fold(0.0, Real::max));
            if k == 0 {
                let force = w.tool(t).unwrap().wrench().force.norm();
                assert!(force < 10.0, "{mode:?}: the jump kicked with {force} N");
                assert!(inside(&w) > 0, "{mode:?}: the tool landed on no particle");
            }
        }
        // Measured: 0.5 m/s (exact shape), 2.1 m/s (sampled points); swept, 100+ m/s.
        assert!(fastest < 5.0, "{mode:?}: tissue at {fastest} m/s");
        if mode == ContactMode::SampledPoints {
            assert_eq!(inside(&w), 0, "particles left inside the tool");
        }
    }
}

/// Step a 0.1 m cube from the state (`x`, `v`) under `limits`: the step must fail as
/// `Diverged` with a message containing `why`, be counted and rolled back, and the world must
/// step on from a sane state afterwards.
fn explodes(limits: tissuesim::DivergenceLimits, x: &[Vec3], v: &[Vec3], why: &str) {
    explodes_with(Settings::default(), limits, x, v, why);
}

/// [`explodes`] with other settings than the default.
fn explodes_with(
    settings: Settings,
    limits: tissuesim::DivergenceLimits,
    x: &[Vec3],
    v: &[Vec3],
    why: &str,
) {
    let mut w = World::new(Settings {
        divergence: limits,
        ..settings
    })
    .unwrap();
    let b = w.add_body(&cube(), &BodyOptions::default()).unwrap();
    let rest = w.body(b).unwrap().positions().to_vec();
    w.set_body_state(b, x, v).unwrap();
    match w.step() {
        Err(Error::Diverged(m)) => assert!(m.contains(why), "{m}"),
        other => panic!("expected Diverged ({why}), got {other:?}"),
    }
    assert_eq!(w.diverged_steps(), 1);
    assert_eq!(w.body(b).unwrap().positions(), x, "rolled back");
    assert_eq!(w.body(b).unwrap().velocities(), v, "rolled back");
    w.set_body_state(b, &rest, &vec![Vec3::zeros(); rest.len()])
        .unwrap();
    w.step().unwrap();
}

/// A finite explosion (a particle too fast, a body flown apart) is reported as `Diverged` with
/// the reason, the step is rolled back, and the world steps on once the state is sane again.
#[test]
fn finite_explosions_are_rolled_back_and_reported() {
    use tissuesim::DivergenceLimits;
    // The body's rest positions, in its particle order.
    let rest = tissuesim::BodyModel::new(&cube(), &BodyOptions::default())
        .unwrap()
        .rest_positions()
        .to_vec();
    let size = 0.1 * 3.0f64.sqrt();
    let still = vec![Vec3::zeros(); rest.len()];
    // One particle at 500 body sizes per second (accepted as a state, beyond the step's 250).
    let mut fast = still.clone();
    fast[7] = Vec3::new(500.0 * size, 0.0, 0.0);
    explodes(DivergenceLimits::default(), &rest, &fast, "moves at");
    // Spread to 9.9 times its size and flying apart (the extent crosses 10 within the step);
    // the speed check off, or it would fire first.
    let spread: Vec<Vec3> = rest.iter().map(|x| x * 9.9).collect();
    let outwards: Vec<Vec3> = spread.iter().map(|x| x * 100.0).collect();
    let no_speed = DivergenceLimits {
        max_speed: Real::INFINITY,
        ..Default::default()
    };
    explodes(no_speed, &spread, &outwards, "spans");
    // Squashed to 12% of its height and still being squashed (the volume ratio crosses 0.1).
    // The default's crush guard holds every tetrahedron above a tenth of its rest volume, so
    // the squash runs on the paper's particles, which have none.
    let flat: Vec<Vec3> = rest
        .iter()
        .map(|x| Vec3::new(x.x, 0.12 * x.y, x.z))
        .collect();
    let squashing: Vec<Vec3> = flat
        .iter()
        .map(|x| Vec3::new(0.0, -400.0 * x.y, 0.0))
        .collect();
    let volume_only = DivergenceLimits {
        max_extent_ratio: Real::INFINITY,
        ..no_speed
    };
    let paper = Settings {
        elastic_scheme: tissuesim::ElasticScheme::PointBased,
        volume_scheme: tissuesim::VolumeScheme::Tetrahedra,
        ..Settings::default()
    };
    explodes_with(paper, volume_only, &flat, &squashing, "volume");
    // The default under the same squash: held, not diverged.
    let mut w = World::new(Settings {
        divergence: volume_only,
        ..Settings::default()
    })
    .unwrap();
    let b = w.add_body(&cube(), &BodyOptions::default()).unwrap();
    w.set_body_state(b, &flat, &squashing).unwrap();
    w.step().unwrap();
    assert!(w.body(b).unwrap().volume_ratio() >= 0.1);
    // A body set outside the bounds but recovering is not diverging:
    // A body squashed to 5% of its height (volume ratio 0.05) and at rest springs back.
    let mut w = World::new(Settings::default()).unwrap();
    let b = w.add_body(&cube(), &BodyOptions::default()).unwrap();
    let flatter: Vec<Vec3> = rest
        .iter()
        .map(|x| Vec3::new(x.x, 0.05 * x.y, x.z))
        .collect();
    w.set_body_state(b, &flatter, &still).unwrap();
    for _ in 0..10 {
        w.step().unwrap();
    }
    assert!(w.body(b).unwrap().volume_ratio() > 0.05);
    // Switched off, the same fast particle steps (and flies).
    let mut w = World::new(Settings {
        divergence: no_speed,
        ..Settings::default()
    })
    .unwrap();
    let b = w.add_body(&cube(), &BodyOptions::default()).unwrap();
    w.set_body_state(b, &rest, &fast).unwrap();
    w.step().unwrap();
    let nan = DivergenceLimits {
        max_speed: Real::NAN,
        ..Default::default()
    };
    invalid(
        World::new(Settings {
            divergence: nan,
            ..Settings::default()
        })
        .map(|_| ()),
        "divergence",
    );
}
