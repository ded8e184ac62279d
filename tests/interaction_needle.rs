//! Needle insertion: the axial force on a needle
//! pushed into tissue rises while the tip indents the surface, drops when it punctures at the
//! puncture force, then grows with the inserted length through the shaft's friction; pulling it
//! back out releases the tissue.

use tissuesim::mesh::lattice_box;
use tissuesim::{
    BodyOptions, Error, NeedleOptions, Pose, Quat, Real, Settings, ToolId, ToolOptions, ToolShape,
    Vec3, World,
};

/// Edge of the block of tissue (m); its bottom face is fixed, its top at y = SIDE.
const SIDE: Real = 0.06;
/// Half length of the needle's cylindrical part (m) and its radius (m).
const HALF: Real = 0.04;
const RADIUS: Real = 0.001;
/// Insertion speed (m/s).
const SPEED: Real = 0.05;

const OPTIONS: NeedleOptions = NeedleOptions {
    puncture_force: 0.1,
    friction_per_length: 2.0,
    reach: None,
};

/// Shaft axis (world): the needle points down.
fn axis() -> Vec3 {
    -Vec3::y()
}

/// A 6 cm block of liver-like tissue on a fixed base and a 1 mm capsule needle pointing down,
/// its tip 12 mm above the top face (clear of the particles' contact radius), over a column of particles.
fn scene() -> (World, ToolId) {
    let mut w = World::new(Settings::default()).unwrap();
    let mesh = lattice_box(
        Vec3::new(-0.03, 0.0, -0.03),
        Vec3::new(0.03, SIDE, 0.03),
        [6, 6, 6],
    );
    let b = w.add_body(&mesh, &BodyOptions::default()).unwrap();
    w.fix_box(b, Vec3::new(-1.0, -1.0, -1.0), Vec3::new(1.0, 1e-6, 1.0))
        .unwrap();
    let t = w
        .add_tool(
            ToolShape::Capsule {
                half_height: HALF,
                radius: RADIUS,
            },
            pose_with_tip_at(SIDE + 0.012),
            &ToolOptions::default(),
        )
        .unwrap();
    w.make_needle(t, &OPTIONS).unwrap();
    (w, t)
}

/// The needle's pose with its tip at height `y` above the block's centre.
fn pose_with_tip_at(y: Real) -> Pose {
    let down = Quat::from_axis_angle(&Vec3::x_axis(), std::f64::consts::PI);
    Pose {
        position: Vec3::new(0.0, y, 0.0) - axis() * (HALF + RADIUS),
        orientation: down,
    }
}

/// One step moving the tip to height `y`; returns the axial force (N) resisting insertion.
fn step_to(w: &mut World, t: ToolId, y: Real) -> Real {
    w.set_tool_pose(t, pose_with_tip_at(y)).unwrap();
    w.step().unwrap();
    -w.tool(t).unwrap().wrench().force.dot(&axis())
}

#[test]
fn the_force_rises_drops_at_puncture_and_grows_with_friction() {
    let (mut w, t) = scene();
    let dt = w.settings().dt;
    let mut y = SIDE + 0.012;
    let mut trace = Vec::new();
    let mut punctured_at = None;
    while y > SIDE - 0.04 {
        y -= SPEED * dt;
        let f = step_to(&mut w, t, y);
        let s = w.needle_state(t).unwrap();
        trace.push((SIDE - y, f, s.inserted_length, s.held));
        if s.punctured && punctured_at.is_none() {
            punctured_at = Some(trace.len() - 1);
        }
    }
    let k = punctured_at.expect("the needle punctures the block");
    let (depth, f, _, _) = trace[k];
    println!(
        "punctured at {:.2} mm of travel, axial force {f:.4} N",
        depth * 1e3
    );
    // Puncture happens at the threshold: the step that reached it, not before.
    assert!(f >= OPTIONS.puncture_force, "punctured at {f} N");
    assert!(trace[k - 1].1 < OPTIONS.puncture_force);
    assert!(
        trace[..k]
            .iter()
            .any(|r| r.1 > 0.2 * OPTIONS.puncture_force),
        "a rise first"
    );
    // The drop: shortly after puncture the shaft carries less than the puncture force.
    let after = trace[k + 20].1;
    println!("20 steps after puncture: {after:.4} N");
    assert!(
        after < 0.7 * OPTIONS.puncture_force,
        "drop after puncture: {after} N"
    );
    // Friction growth: force ≈ friction_per_length × inserted length once the shaft slides.
    let (_, f_end, inserted, held) = *trace.last().unwrap();
    let expected = OPTIONS.friction_per_length * inserted;
    println!(
        "inserted {:.1} mm, {held} particles held: axial force {f_end:.4} N, friction \
         × length {expected:.4} N",
        inserted * 1e3
    );
    assert!(held > 0);
    assert!(
        (f_end - expected).abs() < 0.25 * expected,
        "{f_end} vs {expected}"
    );
    let halfway = trace
        .iter()
        .find(|r| r.2 > 0.5 * inserted)
        .map(|r| r.1)
        .unwrap();
    assert!(
        f_end > 1.3 * halfway,
        "grows with depth: {halfway} -> {f_end}"
    );
}

#[test]
fn withdrawal_drags_the_tissue_then_lets_it_go() {
    let (mut w, t) = scene();
    let dt = w.settings().dt;
    let mut y = SIDE + 0.012;
    while y > SIDE - 0.03 {
        y -= SPEED * dt;
        step_to(&mut w, t, y);
    }
    assert!(w.needle_state(t).unwrap().punctured);
    let mut pulled = Vec::new();
    while y < SIDE + 0.01 {
        y += SPEED * dt;
        pulled.push(step_to(&mut w, t, y));
    }
    // Friction now resists the withdrawal: the tissue pulls the needle in (negative force).
    let early = pulled[100];
    println!("withdrawing: axial force {early:.4} N");
    assert!(early < -0.01, "friction resists withdrawal: {early} N");
    let s = w.needle_state(t).unwrap();
    assert!(!s.punctured && s.held == 0 && s.inserted_length == 0.0);
    for _ in 0..50 {
        w.step().unwrap();
    }
    assert!(
        w.tool(t).unwrap().wrench().force.norm() < 1e-9,
        "out and free"
    );
}

#[test]
fn an_inserted_needle_is_saved_and_restored_bit_for_bit() {
    let (mut w, t) = scene();
    let dt = w.settings().dt;
    let mut y = SIDE + 0.012;
    while y > SIDE - 0.02 {
        y -= SPEED * dt;
        step_to(&mut w, t, y);
    }
    let mut saved = Vec::new();
    w.save_state(&mut saved);
    assert_eq!(saved.len(), w.state_size());
    let run = |w: &mut World| -> Vec<Real> {
        (1..=100)
            .map(|k| step_to(w, t, y - SPEED * dt * k as Real))
            .collect()
    };
    let first = run(&mut w);
    w.restore_state(&saved).unwrap();
    assert_eq!(run(&mut w), first);
}

#[test]
fn only_capsules_and_cylinders_become_needles_with_valid_options() {
    let (mut w, t) = scene();
    let ball = w
        .add_tool(
            ToolShape::Sphere { radius: 0.01 },
            Pose::at(Vec3::new(1.0, 1.0, 1.0)),
            &ToolOptions::default(),
        )
        .unwrap();
    assert!(matches!(
        w.make_needle(ball, &OPTIONS),
        Err(Error::InvalidArgument(_))
    ));
    assert!(matches!(
        w.needle_state(ball),
        Err(Error::InvalidArgument(_))
    ));
    for bad in [
        NeedleOptions {
            puncture_force: 0.0,
            ..OPTIONS
        },
        NeedleOptions {
            friction_per_length: -1.0,
            ..OPTIONS
        },
        NeedleOptions {
            reach: Some(0.0),
            ..OPTIONS
        },
    ] {
        assert!(matches!(
            w.make_needle(t, &bad),
            Err(Error::InvalidArgument(_))
        ));
    }
    let nan = NeedleOptions {
        puncture_force: Real::NAN,
        ..OPTIONS
    };
    assert!(matches!(w.make_needle(t, &nan), Err(Error::NonFinite(_))));
    assert_eq!(w.needle_state(t).unwrap().inserted_length, 0.0);
}
