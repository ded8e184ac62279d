//! The world state as one value: `World::state` /
//! `World::set_state`, its byte form, the fixed flags in it, and the rollback of a diverged
//! step putting back all of it (particles, needle holds, grasps), not only the particles.

use tissuesim::mesh::lattice_box;
use tissuesim::{
    BodyId, BodyOptions, Error, GraspOptions, NeedleOptions, Pose, Quat, Real, Settings, ToolId,
    ToolOptions, ToolShape, Vec3, World, WorldState,
};

/// Edge of the block of tissue (m); its bottom face is fixed, its top at y = SIDE.
const SIDE: Real = 0.06;
/// Half length and radius of the needle (m).
const HALF: Real = 0.04;
const RADIUS: Real = 0.001;

/// A 6 cm block on a fixed base, a downward needle with its tip `depth` (m) into the top face
/// after a slow insertion (punctured, particles held on the shaft), and a grasping sphere at a
/// corner of the top face.
fn scene(depth: Real) -> (World, BodyId, ToolId) {
    scene_on(depth, 1)
}

/// The block alone on its fixed base, on `threads` threads.
fn block_on(threads: u32) -> (World, BodyId) {
    let settings = Settings {
        threads,
        ..Settings::default()
    };
    let mut w = World::new(settings).unwrap();
    let lo = Vec3::new(-SIDE / 2.0, 0.0, -SIDE / 2.0);
    let hi = Vec3::new(SIDE / 2.0, SIDE, SIDE / 2.0);
    let b = w
        .add_body(&lattice_box(lo, hi, [6, 6, 6]), &BodyOptions::default())
        .unwrap();
    w.fix_box(b, Vec3::repeat(-1.0), Vec3::new(1.0, 1e-6, 1.0))
        .unwrap();
    (w, b)
}

/// [`scene`] on `threads` threads.
fn scene_on(depth: Real, threads: u32) -> (World, BodyId, ToolId) {
    let (mut w, b) = block_on(threads);
    let shaft = ToolShape::Capsule {
        half_height: HALF,
        radius: RADIUS,
    };
    let needle = w
        .add_tool(shaft, tip_at(SIDE + 0.012), &ToolOptions::default())
        .unwrap();
    let options = NeedleOptions {
        puncture_force: 0.1,
        ..NeedleOptions::default()
    };
    w.make_needle(needle, &options).unwrap();
    let jaw = ToolShape::Sphere { radius: 0.005 };
    let corner = Pose::at(Vec3::new(0.02, SIDE + 0.004, 0.02));
    let grasper = w.add_tool(jaw, corner, &ToolOptions::default()).unwrap();
    assert!(w.grasp(grasper, &GraspOptions::default()).unwrap() > 0);
    let mut y = SIDE + 0.012;
    while y > SIDE - depth {
        y -= 0.05 * w.settings().dt;
        w.set_tool_pose(needle, tip_at(y)).unwrap();
        w.step().unwrap();
    }
    let state = w.needle_state(needle).unwrap();
    assert!(state.punctured && state.held > 0, "{state:?}");
    (w, b, needle)
}

/// The needle's pose with its tip at height `y` above the block's centre, pointing down.
fn tip_at(y: Real) -> Pose {
    Pose {
        position: Vec3::new(0.0, y + HALF + RADIUS, 0.0),
        orientation: Quat::from_axis_angle(&Vec3::x_axis(), std::f64::consts::PI),
    }
}

#[test]
fn the_state_round_trips_through_its_bytes_and_replays_bit_for_bit() {
    let (mut w, _, needle) = scene(0.01);
    let state = w.state();
    let mut bytes = Vec::new();
    w.save_state(&mut bytes);
    assert_eq!(bytes.len(), w.state_size());
    assert_eq!(bytes.len(), state.byte_size());
    assert_eq!(WorldState::from_bytes(&bytes).unwrap(), state);
    assert_eq!((state.body_count(), state.tool_count()), (1, 2));

    let run = |w: &mut World| {
        for k in 0..20 {
            w.set_tool_pose(needle, tip_at(SIDE - 0.01 - 0.0001 * k as Real))
                .unwrap();
            w.step().unwrap();
        }
        w.state()
    };
    let first = run(&mut w);
    assert_ne!(first, state, "the run changed nothing");
    w.set_state(&state).unwrap();
    assert_eq!(w.state(), state);
    assert_eq!(run(&mut w), first, "the replay differs");
}

#[test]
fn the_fixed_flags_are_part_of_the_state() {
    let (mut w, b, _) = scene(0.01);
    let before = w.state();
    let freed = w.body(b).unwrap().positions()[..]
        .iter()
        .position(|x| x.y > SIDE / 2.0 && x.x < -0.02)
        .unwrap();
    w.fix_particles(b, &[freed as u32]).unwrap();
    assert!(w.body(b).unwrap().is_fixed(freed));
    assert_ne!(w.state(), before);
    w.set_state(&before).unwrap();
    assert!(!w.body(b).unwrap().is_fixed(freed));
    // Free again: it moves under gravity with the rest of the block.
    let x0 = w.body(b).unwrap().positions()[freed];
    for _ in 0..5 {
        w.step().unwrap();
    }
    assert_ne!(w.body(b).unwrap().positions()[freed], x0);
}

/// A block with its bottom half fixed has inert particles (fixed, every neighbour fixed),
/// whose terms the force pass skips. A state that frees them makes them count again: after
/// it, the world steps with the bits of one that never fixed them.
#[test]
fn a_state_that_frees_inert_particles_computes_them_again() {
    let run = |w: &mut World, b: BodyId| {
        for _ in 0..20 {
            w.step().unwrap();
        }
        w.body(b).unwrap().positions().to_vec()
    };
    let (mut never, b) = block_on(1);
    let expected = run(&mut never, b);
    let (mut w, b) = block_on(1);
    let base_only = w.state();
    let half = w
        .fix_box(b, Vec3::repeat(-1.0), Vec3::new(1.0, SIDE / 2.0, 1.0))
        .unwrap();
    assert!(half > 100, "{half} fixed");
    run(&mut w, b);
    w.set_state(&base_only).unwrap();
    assert_eq!(run(&mut w, b), expected);
}

/// A step that diverges puts the whole state back: the needle's holds and the grasp as well as
/// the particles. The same step without the divergence changes the needle's holds, so the
/// comparison has something to catch.
#[test]
fn a_diverged_step_leaves_the_whole_state_as_it_was() {
    let deeper = tip_at(SIDE - 0.02);
    let (mut calm, _, needle) = scene(0.01);
    let held = calm.needle_state(needle).unwrap().held;
    calm.set_tool_pose(needle, deeper).unwrap();
    calm.step().unwrap();
    assert_ne!(calm.needle_state(needle).unwrap().held, held);

    // On two threads too: each step's copy of the state is then split over the threads.
    for threads in [1, 2] {
        let (mut w, b, needle) = scene_on(0.01, threads);
        let body = w.body(b).unwrap();
        let (x, mut v) = (body.positions().to_vec(), body.velocities().to_vec());
        let free = (0..x.len()).find(|&i| !body.is_fixed(i)).unwrap();
        // 500 body sizes per second: accepted as a state, beyond the step's limit of 250.
        v[free] = Vec3::new(500.0 * SIDE * 3f64.sqrt(), 0.0, 0.0);
        w.set_body_state(b, &x, &v).unwrap();
        w.set_tool_pose(needle, deeper).unwrap();
        let before = w.state();
        match w.step() {
            Err(Error::Diverged(m)) => assert!(m.contains("moves at"), "{m}"),
            other => panic!("the step did not diverge on {threads} threads: {other:?}"),
        }
        assert_eq!(w.state(), before, "{threads} threads");
        assert_eq!(w.diverged_steps(), 1);
    }
}

#[test]
fn a_state_that_does_not_fit_is_refused_and_changes_nothing() {
    let (mut w, _, _) = scene(0.01);
    let mut bytes = Vec::new();
    w.save_state(&mut bytes);
    let (other, _, _) = scene(0.01);
    let mut lone = World::new(Settings::default()).unwrap();
    lone.add_body(
        &lattice_box(Vec3::zeros(), Vec3::repeat(0.05), [3, 3, 3]),
        &BodyOptions::default(),
    )
    .unwrap();
    let before = w.state();
    for (bad, what) in [(lone.state(), "bodies"), (WorldState::default(), "bodies")] {
        match w.set_state(&bad) {
            Err(Error::BadState(m)) => assert!(m.contains(what), "{m}"),
            r => panic!("a state of another world was accepted: {r:?}"),
        }
    }
    assert_eq!(w.state(), before);
    // A state from a twin world fits.
    w.set_state(&other.state()).unwrap();
    assert_eq!(w.state(), other.state());
    // Every truncation is refused by the reader itself.
    for len in (0..bytes.len()).step_by(97) {
        assert!(matches!(
            WorldState::from_bytes(&bytes[..len]),
            Err(Error::BadState(_))
        ));
    }
}
