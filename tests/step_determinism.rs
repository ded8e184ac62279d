//! Same inputs, same bits: two runs of one scene (probe contact, friction, two bodies) agree
//! exactly, and save → step N → restore → step N reproduces the positions bit for bit; neither
//! the thread count nor profiling changes a bit.

mod common;

use common::{fix_top, two_bodies_stacked};
use tissuesim::{Pose, Settings, ToolOptions, ToolShape, Vec3, VolumeScheme, World};

fn scene() -> World {
    scene_with_threads(1)
}

fn scene_with_threads(threads: u32) -> World {
    scene_with(Settings {
        threads,
        ..Settings::default()
    })
}

/// The paper's method (point-based particles, per-tetrahedron volume constraints), on
/// `threads` threads.
fn paper_scene(threads: u32) -> World {
    scene_with(common::paper(Settings {
        threads,
        ..Settings::default()
    }))
}

fn scene_with(settings: Settings) -> World {
    let (mut world, a, b) = two_bodies_stacked(settings);
    fix_top(&mut world, b, 0.05);
    world.set_body_pair_friction(a, b, 0.4, 0.3).unwrap();
    let options = ToolOptions {
        friction_static: 0.5,
        friction_kinetic: 0.4,
        ..ToolOptions::default()
    };
    world
        .add_tool(
            ToolShape::Sphere { radius: 0.01 },
            Pose::at(Vec3::new(0.0, 0.0, 0.12)),
            &options,
        )
        .unwrap();
    world
}

fn drive(world: &mut World, from: usize, steps: usize) {
    let tool = tissuesim::ToolId(0);
    for k in from..from + steps {
        let s = k as f64 * 1e-3;
        let z = 0.12 - 0.08 * (s * 2.0).min(1.0);
        world
            .set_tool_pose(tool, Pose::at(Vec3::new(0.01 * (5.0 * s).sin(), 0.0, z)))
            .unwrap();
        world.step().unwrap();
    }
}

fn positions(world: &World) -> Vec<Vec3> {
    (0..world.body_count() as u32)
        .flat_map(|b| {
            world
                .body(tissuesim::BodyId(b))
                .unwrap()
                .positions()
                .to_vec()
        })
        .collect()
}

#[test]
fn two_runs_give_identical_bits() {
    let (mut w1, mut w2) = (scene(), scene());
    drive(&mut w1, 0, 400);
    drive(&mut w2, 0, 400);
    assert!(
        w1.tool(tissuesim::ToolId(0))
            .unwrap()
            .wrench()
            .contact_count
            > 0
    );
    assert_eq!(positions(&w1), positions(&w2));
    assert_eq!(
        w1.tool(tissuesim::ToolId(0)).unwrap().wrench(),
        w2.tool(tissuesim::ToolId(0)).unwrap().wrench()
    );
}

#[test]
fn thread_count_does_not_change_a_bit() {
    let mut one = scene_with_threads(1);
    let mut two = scene_with_threads(2);
    let mut three = scene_with_threads(3);
    for w in [&mut one, &mut two, &mut three] {
        drive(w, 0, 300);
    }
    assert_eq!(positions(&one), positions(&two));
    assert_eq!(positions(&one), positions(&three));
    let tool = tissuesim::ToolId(0);
    assert_eq!(
        one.tool(tool).unwrap().wrench(),
        three.tool(tool).unwrap().wrench()
    );
}

/// The dual cells' pass runs colour by colour on the pool (both bodies have enough cells to
/// be split over the threads): the same bits on one thread and on two, under the paper's
/// particles too.
#[test]
fn thread_count_does_not_change_a_bit_with_dual_cells() {
    let dual_cells = |threads| {
        scene_with(Settings {
            volume_scheme: VolumeScheme::DualCells,
            ..common::paper(Settings {
                threads,
                ..Settings::default()
            })
        })
    };
    let (mut one, mut two) = (dual_cells(1), dual_cells(2));
    for w in [&mut one, &mut two] {
        drive(w, 0, 300);
    }
    assert_eq!(positions(&one), positions(&two));
    let tool = tissuesim::ToolId(0);
    assert!(one.tool(tool).unwrap().wrench().contact_count > 0);
    assert_eq!(
        one.tool(tool).unwrap().wrench(),
        two.tool(tool).unwrap().wrench()
    );
}

/// The paper's method (the particles' force pass with its pair slots, the per-tetrahedron
/// constraints in colours) gives the same bits on any thread count, and a restored state
/// reproduces the run (the particles' rotations are part of the state).
#[test]
fn the_papers_method_is_deterministic() {
    let mut one = paper_scene(1);
    let mut two = paper_scene(2);
    let mut three = paper_scene(3);
    for w in [&mut one, &mut two, &mut three] {
        drive(w, 0, 300);
    }
    let tool = tissuesim::ToolId(0);
    assert_eq!(positions(&one), positions(&two));
    assert_eq!(positions(&one), positions(&three));
    assert_eq!(
        one.tool(tool).unwrap().wrench(),
        three.tool(tool).unwrap().wrench()
    );
    let mut state = Vec::new();
    one.save_state(&mut state);
    drive(&mut one, 300, 100);
    let first = positions(&one);
    one.restore_state(&state).unwrap();
    drive(&mut one, 300, 100);
    assert_eq!(positions(&one), first);
}

#[test]
fn save_step_restore_step_reproduces_the_run() {
    let mut world = scene();
    drive(&mut world, 0, 200);
    let mut state = Vec::new();
    world.save_state(&mut state);
    assert_eq!(state.len(), world.state_size());
    drive(&mut world, 200, 150);
    let first = positions(&world);
    let wrench = world.tool(tissuesim::ToolId(0)).unwrap().wrench();
    world.restore_state(&state).unwrap();
    drive(&mut world, 200, 150);
    assert_eq!(positions(&world), first);
    assert_eq!(world.tool(tissuesim::ToolId(0)).unwrap().wrench(), wrench);
}

#[test]
fn a_corrupted_state_is_refused_and_changes_nothing() {
    let mut world = scene();
    drive(&mut world, 0, 20);
    let mut state = Vec::new();
    world.save_state(&mut state);
    drive(&mut world, 20, 5);
    let before = positions(&world);
    let mut corrupt = state.clone();
    corrupt[100] ^= 0x40;
    assert!(world.restore_state(&corrupt).is_err());
    assert!(world.restore_state(&state[..state.len() - 1]).is_err());
    let mut wrong_version = state.clone();
    wrong_version[8] = 99;
    assert!(world.restore_state(&wrong_version).is_err());
    assert_eq!(positions(&world), before);
}

/// Profiling reads clocks and nothing else: a profiled run gives the same bits. Its profile
/// exists only while it is on, and the stages (contact with two bodies and a probe) lie within
/// the step's total.
#[test]
fn profiling_changes_no_bit_and_accounts_for_the_step() {
    let (mut plain, mut profiled) = (scene_with_threads(2), scene_with_threads(2));
    assert!(profiled.step_profile().is_none());
    profiled.set_profiling(true);
    drive(&mut plain, 0, 300);
    drive(&mut profiled, 0, 300);
    assert_eq!(positions(&plain), positions(&profiled));
    assert!(plain.step_profile().is_none());
    let p = profiled
        .step_profile()
        .expect("a profile while profiling is on");
    let stages = [
        p.state_copy,
        p.prediction,
        p.volume,
        p.organ_contact,
        p.self_contact,
        p.tool_contact,
        p.grasp_and_needle,
        p.update,
        p.end_of_step,
    ];
    let sum: std::time::Duration = stages.iter().sum();
    assert!(p.prediction > std::time::Duration::ZERO && p.tool_contact > std::time::Duration::ZERO);
    assert!(
        p.organ_contact > std::time::Duration::ZERO,
        "two bodies touch"
    );
    assert!(
        sum <= p.total,
        "stages {sum:?} beyond the step's {:?}",
        p.total
    );
    profiled.set_profiling(false);
    assert!(profiled.step_profile().is_none());
}
