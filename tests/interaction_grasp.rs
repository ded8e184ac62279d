//! Grasping: a tool attaches the tissue within its
//! jaws, lifts it with the reaction force on the tool equal to the weight of what it holds,
//! lets go on release, and lets the tissue slip beyond a holding force.

use tissuesim::mesh::{lattice_box, TetMesh};
use tissuesim::{
    BodyId, BodyOptions, Error, GraspOptions, Pose, Real, Settings, ToolId, ToolOptions, ToolShape,
    Vec3, World,
};

/// Edge of the cube of tissue (m).
const SIDE: Real = 0.04;
/// Radius of the grasping sphere (m).
const JAW: Real = 0.01;

fn cube() -> TetMesh {
    lattice_box(
        Vec3::repeat(-SIDE / 2.0),
        Vec3::repeat(SIDE / 2.0),
        [4, 4, 4],
    )
}

/// A free cube of liver-like tissue (no fixed particle) and a sphere just touching its top face
/// (its centre half a particle radius above contact distance), not yet grasping.
fn scene() -> (World, BodyId, ToolId) {
    let mut w = World::new(Settings::default()).unwrap();
    let b = w.add_body(&cube(), &BodyOptions::default()).unwrap();
    let r = w.body(b).unwrap().particle_radius();
    let top = Vec3::new(0.0, SIDE / 2.0 + JAW + 0.5 * r, 0.0);
    let t = w
        .add_tool(
            ToolShape::Sphere { radius: JAW },
            Pose::at(top),
            &ToolOptions::default(),
        )
        .unwrap();
    (w, b, t)
}

fn centre_of_mass(w: &World, b: BodyId) -> Vec3 {
    let body = w.body(b).unwrap();
    let m = body.masses();
    let sum: Vec3 = body
        .positions()
        .iter()
        .zip(m)
        .map(|(x, m)| x * *m)
        .fold(Vec3::zeros(), |a, b| a + b);
    sum / body.mass()
}

fn velocity_of_mass_centre(w: &World, b: BodyId) -> Vec3 {
    let body = w.body(b).unwrap();
    let sum: Vec3 = body
        .velocities()
        .iter()
        .zip(body.masses())
        .map(|(v, m)| v * *m)
        .fold(Vec3::zeros(), |a, b| a + b);
    sum / body.mass()
}

/// Step `seconds` and return the mean force on the tool (N) over the last quarter.
fn hold(w: &mut World, t: ToolId, seconds: Real) -> Vec3 {
    let steps = (seconds / w.settings().dt).round() as usize;
    let mut mean = Vec3::zeros();
    let tail = steps / 4;
    for k in 0..steps {
        w.step().unwrap();
        if k >= steps - tail {
            mean += w.tool(t).unwrap().wrench().force / tail as Real;
        }
    }
    mean
}

#[test]
fn a_held_cube_pulls_on_the_tool_with_its_weight() {
    let (mut w, b, t) = scene();
    let n = w.grasp(t, &GraspOptions::default()).unwrap();
    assert!(n >= 4, "the jaws hold {n} particles of the top face");
    let force = hold(&mut w, t, 3.0);
    let weight = w.body(b).unwrap().mass() * 9.81;
    println!("held: {n} particles, force {force:?} N, weight {weight:.4} N");
    assert!(
        (force.y + weight).abs() < 0.05 * weight,
        "vertical pull {} N against weight {weight} N",
        -force.y
    );
    assert!(force.xz().norm() < 0.05 * weight, "sideways {force:?}");
    assert_eq!(w.grasped_count(t).unwrap(), n, "nothing slipped");
}

#[test]
fn lifting_raises_the_tissue_and_release_lets_it_fall() {
    let (mut w, b, t) = scene();
    w.grasp(t, &GraspOptions::default()).unwrap();
    hold(&mut w, t, 1.0);
    let before = centre_of_mass(&w, b);
    // Lift 3 cm at 6 cm/s, then hold still.
    let dt = w.settings().dt;
    let start = w.tool(t).unwrap().pose().position;
    let lift_steps = (0.5 / dt).round() as usize;
    for k in 1..=lift_steps {
        let y = 0.03 * k as Real / lift_steps as Real;
        w.set_tool_pose(t, Pose::at(start + Vec3::new(0.0, y, 0.0)))
            .unwrap();
        w.step().unwrap();
    }
    let force = hold(&mut w, t, 1.5);
    let rise = centre_of_mass(&w, b).y - before.y;
    println!("lifted 30 mm: the tissue rose {:.2} mm", rise * 1e3);
    assert!(
        (rise - 0.03).abs() < 0.003,
        "rose {rise} m for a 0.03 m lift"
    );
    let weight = w.body(b).unwrap().mass() * 9.81;
    assert!((force.y + weight).abs() < 0.05 * weight, "{force:?}");

    w.release(t).unwrap();
    assert_eq!(w.grasped_count(t).unwrap(), 0);
    let fall = 0.1;
    for _ in 0..(fall / dt).round() as usize {
        w.step().unwrap();
    }
    let v = velocity_of_mass_centre(&w, b);
    println!("0.1 s after release: centre of mass at {:.3} m/s", v.y);
    // Free fall reaches -g t = -0.98 m/s; ambient damping (2/s) takes some of it.
    assert!(v.y < -0.7 * 9.81 * fall, "falls after release: {v:?}");
    assert!(
        w.tool(t).unwrap().wrench().force.norm() < 1e-9,
        "no pull once let go"
    );
}

#[test]
fn the_tissue_slips_beyond_the_holding_force() {
    let (mut w, b, t) = scene();
    let weight = w.body(b).unwrap().mass() * 9.81;
    let options = GraspOptions {
        max_force: 0.5 * weight,
        ..GraspOptions::default()
    };
    assert!(w.grasp(t, &options).unwrap() > 0);
    let mut slipped_at = None;
    for k in 0..1000 {
        w.step().unwrap();
        if w.grasped_count(t).unwrap() == 0 {
            slipped_at = Some(k);
            break;
        }
    }
    let k = slipped_at.expect("a grasp holding half the weight lets go");
    println!("slipped at step {k}");
    // A grasp that may hold twice the weight does not slip.
    let (mut w, _, t) = scene();
    let options = GraspOptions {
        max_force: 2.0 * weight,
        ..GraspOptions::default()
    };
    let n = w.grasp(t, &options).unwrap();
    hold(&mut w, t, 2.0);
    assert_eq!(w.grasped_count(t).unwrap(), n);
}

#[test]
fn a_saved_grasp_is_restored_bit_for_bit() {
    let (mut w, b, t) = scene();
    let mut free = Vec::new();
    w.save_state(&mut free);
    w.grasp(t, &GraspOptions::default()).unwrap();
    hold(&mut w, t, 0.2);
    let mut held = Vec::new();
    w.save_state(&mut held);
    assert_eq!(held.len(), w.state_size());
    let run = |w: &mut World| -> Vec<Vec3> {
        for k in 0..100 {
            let p = Pose::at(Vec3::new(0.0, 0.04 + 1e-4 * k as Real, 0.0));
            w.set_tool_pose(t, p).unwrap();
            w.step().unwrap();
        }
        w.body(b).unwrap().positions().to_vec()
    };
    let first = run(&mut w);
    // Release, then restore the grasping state: the grasp comes back with it.
    w.release(t).unwrap();
    w.restore_state(&held).unwrap();
    assert!(w.grasped_count(t).unwrap() > 0);
    assert_eq!(run(&mut w), first, "the same run after restore");
    // A state saved before the grasp restores a world that holds nothing.
    w.restore_state(&free).unwrap();
    assert_eq!(w.grasped_count(t).unwrap(), 0);
    // Corrupt attachment counts are refused and change nothing.
    let mut bad = held.clone();
    let end = bad.len() - 8;
    bad.truncate(end - 40);
    bad.extend_from_slice(&[0; 8]);
    assert!(matches!(w.restore_state(&bad), Err(Error::BadState(_))));
    assert_eq!(w.grasped_count(t).unwrap(), 0);
}

#[test]
fn bad_grasps_are_errors_and_an_empty_grasp_is_not() {
    let (mut w, _, t) = scene();
    let nan = GraspOptions {
        reach: Some(Real::NAN),
        ..GraspOptions::default()
    };
    assert!(matches!(w.grasp(t, &nan), Err(Error::NonFinite(_))));
    let zero = GraspOptions {
        max_force: 0.0,
        ..GraspOptions::default()
    };
    assert!(matches!(w.grasp(t, &zero), Err(Error::InvalidArgument(_))));
    assert!(matches!(
        w.grasp(ToolId(7), &GraspOptions::default()),
        Err(Error::UnknownTool(7))
    ));
    w.set_tool_pose(t, Pose::at(Vec3::new(0.0, 1.0, 0.0)))
        .unwrap();
    w.step().unwrap();
    assert_eq!(w.grasp(t, &GraspOptions::default()).unwrap(), 0);
    w.remove_tool(t).unwrap();
    assert!(matches!(w.release(t), Err(Error::UnknownTool(_))));
}

#[test]
fn grasping_is_bit_identical_for_any_thread_count() {
    let run = |threads: u32| -> (Vec<Vec3>, Vec3) {
        let (mut w, b, t) = scene();
        let mut s = w.settings().clone();
        s.threads = threads;
        w.set_settings(s).unwrap();
        w.grasp(t, &GraspOptions::default()).unwrap();
        let start = w.tool(t).unwrap().pose().position;
        for k in 0..300 {
            let lift = Vec3::new(0.0, 1e-4 * k as Real, 0.0);
            w.set_tool_pose(t, Pose::at(start + lift)).unwrap();
            w.step().unwrap();
        }
        let force = w.tool(t).unwrap().wrench().force;
        (w.body(b).unwrap().positions().to_vec(), force)
    };
    assert_eq!(run(1), run(2));
}
