//! Elastic and volume forces are internal: a free body without gravity or ambient damping
//! conserves linear and angular momentum; the stiffness-proportional damping's edge dashpots,
//! central and opposite, keep linear momentum exact too.

mod common;

use common::{liver, tissue, Noise};
use tissuesim::{Settings, Vec3, World};

fn momenta(world: &World, id: tissuesim::BodyId) -> (Vec3, Vec3) {
    let b = world.body(id).unwrap();
    let m = b.inertial_masses();
    let mut p = Vec3::zeros();
    let mut l = Vec3::zeros();
    for ((x, v), mi) in b.positions().iter().zip(b.velocities()).zip(m) {
        let mv = v * *mi;
        p += mv;
        l += x.cross(&mv);
    }
    (p, l)
}

/// Run a free, deformed, spinning, drifting liver of the paper's particles for 300 steps;
/// return the momenta before and after. Without volume constraints the particles carry λ.
fn run(volume_constraints: bool) -> ((Vec3, Vec3), (Vec3, Vec3)) {
    run_with(Settings {
        volume_constraints,
        damping_stiffness: 0.0,
        ..common::paper(Settings::default())
    })
}

/// [`run`] under `settings` (gravity and ambient damping off).
fn run_with(settings: Settings) -> ((Vec3, Vec3), (Vec3, Vec3)) {
    let settings = Settings {
        gravity: Vec3::zeros(),
        damping_mass: 0.0,
        ..settings
    };
    let mut world = World::new(settings).unwrap();
    let id = world.add_body(&liver("liver_1k6.node"), &tissue()).unwrap();
    // Start from a deformed, spinning, drifting state.
    let mut noise = Noise::new(3);
    let b = world.body(id).unwrap();
    let (lo, hi) = common::bounds(b.rest_positions());
    let size = (hi - lo).max();
    let spin = Vec3::new(0.0, 0.0, 3.0);
    let x: Vec<Vec3> = b
        .rest_positions()
        .iter()
        .map(|p| p + noise.vec() * (0.01 * size))
        .collect();
    let v: Vec<Vec3> = x
        .iter()
        .map(|p| spin.cross(p) + noise.vec() * 0.05 + Vec3::new(0.1, 0.0, 0.0))
        .collect();
    world.set_body_state(id, &x, &v).unwrap();

    let before = momenta(&world, id);
    for _ in 0..300 {
        world.step().unwrap();
    }
    (before, momenta(&world, id))
}

#[test]
fn elastic_forces_conserve_linear_and_angular_momentum() {
    let ((p0, l0), (p1, l1)) = run(false);
    assert!(p0.norm() > 0.0 && l0.norm() > 0.0);
    assert!(
        (p1 - p0).norm() <= 1e-9 * p0.norm(),
        "linear momentum drifted from {p0} to {p1}"
    );
    assert!(
        (l1 - l0).norm() <= 1e-6 * l0.norm(),
        "angular momentum drifted from {l0} to {l1}"
    );
}

/// Linear momentum exact and angular momentum within 1% (the volume projections change it at
/// O(h)), from the momenta `before` and `after` a run of `what`, whose angular drift is reported.
fn linear_exact_angular_within_a_percent(
    ((p0, l0), (p1, l1)): ((Vec3, Vec3), (Vec3, Vec3)),
    what: &str,
) {
    assert!(
        (p1 - p0).norm() <= 1e-9 * p0.norm(),
        "{what}: linear momentum drifted from {p0} to {p1}"
    );
    eprintln!(
        "angular momentum drift, {what}: {:.3e} (relative)",
        (l1 - l0).norm() / l0.norm()
    );
    assert!((l1 - l0).norm() <= 1e-2 * l0.norm(), "{what}");
}

/// Volume projections move particles along constraint gradients that sum to zero (weighted by
/// mass), so linear momentum stays exact; angular momentum changes only at O(h) (a known
/// property of position projection), which is reported.
#[test]
fn volume_constraints_conserve_linear_momentum() {
    linear_exact_angular_within_a_percent(run(true), "the paper's method");
}

/// The default: the tetrahedra's corner forces sum to zero and their torque vanishes; with the
/// dual cells carrying the volume, linear momentum stays exact and angular momentum changes
/// only as the volume projections make it (O(h)).
#[test]
fn tetrahedra_conserve_momentum() {
    linear_exact_angular_within_a_percent(
        run_with(Settings::default()),
        "tetrahedra and dual cells",
    );
}

/// The default under a strong stiffness-proportional damping (β = 5 ms): the edge dashpots'
/// impulses are central and opposite, so linear momentum stays exact, and angular momentum
/// changes only as the volume projections make it (the kernel's own test checks both exactly
/// on one tetrahedron).
#[test]
fn stiffness_damping_conserves_momentum() {
    let settings = Settings {
        damping_stiffness: 5e-3,
        ..Settings::default()
    };
    linear_exact_angular_within_a_percent(run_with(settings), "β = 5 ms");
}
