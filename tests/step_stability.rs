//! No zero-energy mode grows: a small random perturbation of the rest state stays bounded
//! without damping and decays with it; a step never lets NaN or Inf through.

mod common;

use common::{bounds, fix_top, liver, tissue, Noise};
use tissuesim::{Error, Real, Settings, Vec3, World};

fn perturbed(settings: Settings) -> (World, tissuesim::BodyId, Real) {
    let mut world = World::new(settings).unwrap();
    let id = world.add_body(&liver("liver_1k6.node"), &tissue()).unwrap();
    fix_top(&mut world, id, 0.1);
    let b = world.body(id).unwrap();
    let (lo, hi) = bounds(b.rest_positions());
    let amplitude = 1e-3 * (hi - lo).max();
    let mut noise = Noise::new(11);
    let x: Vec<Vec3> = (0..b.particle_count())
        .map(|i| {
            let p = b.rest_positions()[i];
            if b.is_fixed(i) {
                p
            } else {
                p + noise.vec() * amplitude
            }
        })
        .collect();
    let v = vec![Vec3::zeros(); x.len()];
    world.set_body_state(id, &x, &v).unwrap();
    let initial = world.body(id).unwrap().max_displacement();
    (world, id, initial)
}

#[test]
fn random_perturbation_stays_bounded_without_damping() {
    let settings = Settings {
        gravity: Vec3::zeros(),
        damping_mass: 0.0,
        ..Settings::default()
    };
    let (mut world, id, initial) = perturbed(settings);
    let mut largest: Real = 0.0;
    for _ in 0..2000 {
        world.step().unwrap();
        largest = largest.max(world.body(id).unwrap().max_displacement());
    }
    assert!(
        largest < 3.0 * initial,
        "a mode grew: displacement reached {largest} m from {initial} m"
    );
}

#[test]
fn random_perturbation_decays_with_damping() {
    let settings = Settings {
        gravity: Vec3::zeros(),
        ..Settings::default()
    };
    let (mut world, id, initial) = perturbed(settings);
    for _ in 0..2000 {
        world.step().unwrap();
    }
    let last = world.body(id).unwrap().max_displacement();
    assert!(
        last < 0.1 * initial,
        "perturbation {initial} m decayed only to {last} m in 2 s"
    );
}

#[test]
fn a_diverging_step_is_rolled_back_and_reported() {
    // No mass scaling and a single forced substep far beyond the stability limit.
    let settings = Settings {
        dt: 0.02,
        mass_scaling: false,
        max_substeps: 1,
        ..Settings::default()
    };
    let mut world = World::new(settings).unwrap();
    let id = world.add_body(&liver("liver_1k6.node"), &tissue()).unwrap();
    fix_top(&mut world, id, 0.1);
    let mut diverged = 0;
    for _ in 0..200 {
        let before = world.body(id).unwrap().positions().to_vec();
        let t = world.time();
        match world.step() {
            Ok(report) => assert!(report.substeps_clamped),
            Err(Error::Diverged(_)) => {
                diverged += 1;
                assert_eq!(world.body(id).unwrap().positions(), &before[..]);
                assert_eq!(world.time(), t);
            }
            Err(e) => panic!("unexpected error {e}"),
        }
        let b = world.body(id).unwrap();
        assert!(b
            .positions()
            .iter()
            .chain(b.velocities())
            .all(|v| v.iter().all(|c| c.is_finite())));
    }
    assert!(diverged > 0, "this step size should diverge");
    assert_eq!(world.diverged_steps(), diverged);
}
