//! `World::settle`: the static equilibrium under gravity. With the particles carrying the
//! volumetric stiffness (volume constraints off) the step integrates exactly the energy that
//! settle minimises, so a settled body stays at rest. (With the XPBD volume constraints, one
//! projection pass per substep under-applies their stiffness by `1/(1 + w h²/α)`, and the
//! step's equilibrium differs slightly: docs/VALIDATION.md.)

mod common;

use tissuesim::{statics, Settings, Vec3, World};

#[test]
fn a_settled_body_matches_the_linear_sag_and_stays_at_rest() {
    let g = Vec3::new(0.0, -0.01, 0.0);
    let mut world = World::new(Settings {
        gravity: g,
        volume_constraints: false,
        ..Settings::default()
    })
    .unwrap();
    let id = world
        .add_body(&common::liver("liver_1k6.node"), &common::tissue())
        .unwrap();
    common::fix_top(&mut world, id, 0.1);
    let linear = statics::linear_gravity_sag(world.body(id).unwrap(), g).unwrap();
    let report = world.settle().unwrap();
    eprintln!("{report:?}");
    let b = world.body(id).unwrap();
    let (mut e, mut n) = (0.0, 0.0);
    for ((x, x0), lin) in b.positions().iter().zip(b.rest_positions()).zip(&linear) {
        e += (x - x0 - lin).norm_squared();
        n += lin.norm_squared();
    }
    eprintln!("settled vs linear: {:e}", (e / n).sqrt());
    assert!(report[0].converged, "{report:?}");
    // Small strain: the nonlinear equilibrium is the linear one to ~1e-3.
    assert!((e / n).sqrt() < 5e-3);
    let sag = linear.iter().map(|u| u.norm()).fold(0.0, f64::max);
    for _ in 0..20 {
        world.step().unwrap();
    }
    let b = world.body(id).unwrap();
    let v = b.velocities().iter().map(|v| v.norm()).fold(0.0, f64::max);
    eprintln!("after 20 steps: max speed {v:e} m/s (sag {sag:e} m)");
    // Moving less than a millionth of the sag per millisecond.
    assert!(v * 1e-3 < 1e-6 * sag, "speed {v} m/s");
}

#[test]
fn a_free_body_cannot_settle_and_is_left_unchanged() {
    let mut world = World::new(Settings::default()).unwrap();
    let id = world
        .add_body(&common::liver("liver_1k6.node"), &common::tissue())
        .unwrap();
    let before = world.body(id).unwrap().positions().to_vec();
    assert!(world.settle().is_err());
    assert_eq!(world.body(id).unwrap().positions(), &before[..]);
}
