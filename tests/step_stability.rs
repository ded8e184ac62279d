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

/// A new time step (an FMU master varying its communication step) re-derives the mass
/// scaling and the stability limit exactly as a fresh world at that step would, whatever steps
/// came before; the estimate with the physical masses, kept across them, is the same number,
/// and a change of the elastic model estimates it anew.
#[test]
fn a_changed_time_step_gives_what_a_fresh_world_gives() {
    // The paper's particles: the time step and the hourglass term (which changes the elastic
    // model). The default's tetrahedra: the time step (down to 0.1 ms, where nothing is scaled).
    let paper = [
        (4e-3, 0.25),
        (0.4e-3, 0.25),
        (0.4e-3, 1.0),
        (8e-3, 1.0),
        (0.4e-3, 0.25),
    ];
    let default = [
        (4e-3, 0.25),
        (0.1e-3, 0.25),
        (1e-3, 0.25),
        (8e-3, 0.25),
        (0.1e-3, 0.25),
    ];
    changed_time_steps(common::paper(Settings::default()), &paper);
    changed_time_steps(Settings::default(), &default);
}

/// Step a liver under `start` with each (time step, hourglass stiffness) of `steps` in turn,
/// checking the stability limit and the added mass against a fresh world's.
fn changed_time_steps(start: Settings, steps: &[(Real, Real)]) {
    let mesh = liver("liver_1k6.node");
    let body_at = |settings: &Settings| {
        let mut w = World::new(settings.clone()).unwrap();
        let id = w.add_body(&mesh, &tissue()).unwrap();
        let b = w.body(id).unwrap();
        (b.max_angular_frequency(), b.added_mass())
    };
    let (mut world, id) = {
        let mut w = World::new(start).unwrap();
        let id = w.add_body(&mesh, &tissue()).unwrap();
        (w, id)
    };
    let (mut scaled, mut unscaled) = (0, 0);
    for &(dt, hourglass) in steps {
        let settings = Settings {
            dt,
            hourglass_stiffness: hourglass,
            ..world.settings().clone()
        };
        world.set_settings(settings.clone()).unwrap();
        world.step().unwrap();
        let b = world.body(id).unwrap();
        let (omega, added) = body_at(&settings);
        assert_eq!(
            b.max_angular_frequency().to_bits(),
            omega.to_bits(),
            "dt {dt}"
        );
        assert_eq!(b.added_mass().to_bits(), added.to_bits(), "dt {dt}");
        scaled += (added > 0.0) as usize;
        unscaled += (added == 0.0) as usize;
    }
    assert!(
        scaled >= 2 && unscaled >= 2,
        "steps with and without mass scaling"
    );
}
