//! Substeps where the tissue at a tool is compressed. `Settings::crushed_substeps`: a step that
//! starts with a tetrahedron touching a tool compressed below half its rest volume takes at
//! least that many substeps. By default, whatever that setting: such a step takes twice the
//! substeps it would otherwise when the compressed tetrahedron is longer (its longest rest edge)
//! than the tool is wide. Otherwise the step substeps as before. The rules read the state at the
//! start of the step only (positions, the tools' poses). A count they raised is held for
//! `SUBSTEP_HOLD_STEPS` steps after they ask for less; the hold is part of the saved state, so
//! a restored state steps the same.

mod common;

use tissuesim::{
    mesh, BodyId, BodyOptions, Error, Pose, Real, Settings, ToolOptions, ToolShape, Vec3, World,
    SUBSTEP_HOLD_STEPS,
};

/// The radius (m) of the probe resting on the box.
const PROBE: Real = 0.005;

/// A weightless 6 cm lattice box flattened along y to `fraction` of its height about its
/// bottom (every tetrahedron at `fraction` of its rest volume), at rest, under `settings`.
fn flattened_box(settings: Settings, fraction: Real) -> (World, BodyId) {
    let mut world = World::new(settings).unwrap();
    let size = 0.06;
    let box_mesh = mesh::lattice_box(Vec3::zeros(), Vec3::repeat(size), [6, 6, 6]);
    let body = world.add_body(&box_mesh, &BodyOptions::default()).unwrap();
    let b = world.body(body).unwrap();
    let x: Vec<Vec3> = (b.rest_positions().iter())
        .map(|p| Vec3::new(p.x, p.y * fraction, p.z))
        .collect();
    let v = vec![Vec3::zeros(); x.len()];
    world.set_body_state(body, &x, &v).unwrap();
    (world, body)
}

/// The radius (m) of a probe wider than the box's tetrahedra (their longest edges are at most
/// the 1 cm cells' diagonal, 1.73 cm).
const WIDE_PROBE: Real = 0.01;

/// A sphere of `radius` (m) resting on the flattened top face of a box of 6 cm flattened to
/// `fraction`, or `away` from it (m, upwards).
fn sphere_on_top(world: &mut World, radius: Real, fraction: Real, away: Real) {
    let top = 0.06 * fraction;
    let centre = Vec3::new(0.03, top + radius + away, 0.03);
    let sphere = ToolShape::Sphere { radius };
    world
        .add_tool(sphere, Pose::at(centre), &ToolOptions::default())
        .unwrap();
}

/// [`sphere_on_top`] of [`WIDE_PROBE`] radius.
fn probe_on_top(world: &mut World, fraction: Real, away: Real) {
    sphere_on_top(world, WIDE_PROBE, fraction, away);
}

fn crushed(substeps: u32) -> Settings {
    Settings {
        crushed_substeps: substeps,
        ..common::weightless()
    }
}

#[test]
fn a_tool_on_tissue_below_half_its_volume_takes_the_crushed_substeps() {
    let (mut world, _) = flattened_box(crushed(2), 0.4);
    assert_eq!(
        world.substeps_needed(),
        (1, false),
        "no tool: no extra substep"
    );
    probe_on_top(&mut world, 0.4, 0.0);
    assert_eq!(world.substeps_needed(), (2, false));
    let report = world.step().unwrap();
    assert_eq!(report.substeps, 2);
}

/// The substeps the next step of [`flattened_box`] with a probe [`probe_on_top`] needs.
fn substeps_with_probe(settings: Settings, fraction: Real, away: Real) -> (u32, bool) {
    let (mut world, _) = flattened_box(settings, fraction);
    probe_on_top(&mut world, fraction, away);
    world.substeps_needed()
}

#[test]
fn tissue_above_half_its_volume_or_far_from_the_tool_takes_one_substep() {
    let one = (1, false);
    assert_eq!(
        substeps_with_probe(crushed(2), 0.6, 0.0),
        one,
        "compressed to 0.6 only"
    );
    assert_eq!(
        substeps_with_probe(crushed(2), 0.4, 0.02),
        one,
        "the probe 2 cm above"
    );
    assert_eq!(
        substeps_with_probe(crushed(1), 0.4, 0.0),
        one,
        "the default adds none for a probe wider than the tetrahedra"
    );
    let paper = common::paper(crushed(2));
    assert_eq!(
        substeps_with_probe(paper, 0.4, 0.0),
        one,
        "the paper's particles have no crush guard"
    );
}

/// A probe narrower than the tetrahedra it crushes (a 5 mm sphere on 1 cm cells): by default
/// the step takes twice the substeps it would otherwise, before `crushed_substeps`; not where
/// the tissue is above half its volume, nor on the paper's particles (no crush guard).
#[test]
fn a_probe_narrower_than_the_crushed_tetrahedra_doubles_the_substeps() {
    let narrow = |settings: Settings, fraction: Real| {
        let (mut world, _) = flattened_box(settings, fraction);
        sphere_on_top(&mut world, PROBE, fraction, 0.0);
        world.substeps_needed()
    };
    assert_eq!(narrow(crushed(1), 0.4), (2, false));
    let at_least_three = Settings {
        min_substeps: 3,
        ..crushed(1)
    };
    assert_eq!(narrow(at_least_three, 0.4), (6, false));
    assert_eq!(
        narrow(crushed(5), 0.4),
        (5, false),
        "crushed_substeps above twice"
    );
    assert_eq!(
        narrow(crushed(1), 0.6),
        (1, false),
        "compressed to 0.6 only"
    );
    assert_eq!(
        narrow(common::paper(crushed(1)), 0.4),
        (1, false),
        "the paper's particles"
    );
    let (mut world, _) = flattened_box(crushed(1), 0.4);
    sphere_on_top(&mut world, PROBE, 0.4, 0.0);
    assert_eq!(world.step().unwrap().substeps, 2);
}

/// The narrow probe of the test above lifted off after one step: the rules ask for two
/// substeps on the step that lifts it (it starts on the box) and for one after, but the steps
/// take two for `SUBSTEP_HOLD_STEPS` steps more, then one. A state saved
/// inside the hold and restored into a world built the same way takes the same substeps and
/// ends at the same positions, bit for bit.
#[test]
fn a_raised_count_is_held_after_the_tool_leaves_and_saved_with_the_state() {
    let build = || {
        let (mut world, body) = flattened_box(crushed(1), 0.4);
        sphere_on_top(&mut world, PROBE, 0.4, 0.0);
        (world, body)
    };
    let (mut world, body) = build();
    assert_eq!(world.step().unwrap().substeps, 2);
    let probe = world.tool_ids().next().unwrap();
    let away = Pose::at(Vec3::new(0.03, 1.0, 0.03));
    world.set_tool_pose(probe, away).unwrap();
    let mut saved = Vec::new();
    world.save_state(&mut saved);
    let run = |w: &mut World| -> Vec<u32> {
        (0..SUBSTEP_HOLD_STEPS + 4)
            .map(|_| {
                let needed = w.substeps_needed().0;
                let taken = w.step().unwrap().substeps;
                assert_eq!(needed, taken, "substeps_needed and the step disagree");
                taken
            })
            .collect()
    };
    let taken = run(&mut world);
    let held = taken.iter().take_while(|&&n| n == 2).count();
    assert_eq!(held, 1 + SUBSTEP_HOLD_STEPS as usize, "{taken:?}");
    assert!(taken[held..].iter().all(|&n| n == 1), "{taken:?}");

    let (mut restored, _) = build();
    restored.restore_state(&saved).unwrap();
    assert_eq!(run(&mut restored), taken);
    let x = |w: &World| w.body(body).unwrap().positions().to_vec();
    assert_eq!(x(&restored), x(&world), "the restored run differs");
}

#[test]
fn crushed_substeps_outside_one_to_max_substeps_are_refused() {
    for (substeps, max_substeps) in [(0, 64), (9, 8)] {
        let settings = Settings {
            crushed_substeps: substeps,
            max_substeps,
            ..Settings::default()
        };
        match World::new(settings).err() {
            Some(Error::InvalidArgument(m)) => assert!(m.contains("crushed_substeps"), "{m}"),
            other => panic!("crushed_substeps {substeps} of {max_substeps}: {other:?}"),
        }
    }
}
