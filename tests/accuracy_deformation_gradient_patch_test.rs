//! Patch test of the MLS deformation gradient and zero force under rigid motion (eq. 1–4).

mod common;

use common::{liver, tissue, weightless, Noise};
use tissuesim::mesh::default_organ;
use tissuesim::{Mat3, Vec3, World};

fn body_world(mesh: &tissuesim::mesh::TetMesh) -> (World, tissuesim::BodyId) {
    let mut world = World::new(weightless()).unwrap();
    let id = world.add_body(mesh, &tissue()).unwrap();
    (world, id)
}

#[test]
fn affine_deformation_gives_exactly_that_gradient_at_every_particle() {
    for mesh in [liver("liver_1k6.node"), default_organ()] {
        let (world, id) = body_world(&mesh);
        let body = world.body(id).unwrap();
        let a = Mat3::new(1.10, 0.05, -0.02, -0.03, 0.92, 0.04, 0.01, 0.06, 1.05);
        let b = Vec3::new(0.01, -0.02, 0.03);
        let x: Vec<Vec3> = body.rest_positions().iter().map(|p| a * p + b).collect();
        for i in 0..body.particle_count() {
            let f = body.deformation_gradient_at(&x, i);
            assert!(
                (f - a).amax() < 1e-9,
                "particle {i}: F = {f} differs from the affine map {a}"
            );
        }
    }
}

#[test]
fn rigid_rotation_and_translation_give_zero_elastic_force() {
    let mesh = liver("liver_1k6.node");
    let (world, id) = body_world(&mesh);
    let body = world.body(id).unwrap();
    let rest = body.rest_positions();
    // Reference force scale: a 1% uniaxial stretch.
    let stretch: Vec<Vec3> = rest
        .iter()
        .map(|p| Vec3::new(1.01 * p.x, p.y, p.z))
        .collect();
    let scale = body
        .elastic_forces_at(&stretch)
        .iter()
        .map(|f| f.norm())
        .fold(0.0, f64::max);
    assert!(scale > 0.0, "a stretch must produce forces");
    let mut noise = Noise::new(7);
    for _ in 0..3 {
        let axis = nalgebra::Unit::new_normalize(noise.vec());
        let r = nalgebra::Rotation3::from_axis_angle(&axis, 2.0 * noise.next());
        let t = noise.vec() * 0.1;
        let moved: Vec<Vec3> = rest.iter().map(|p| r * p + t).collect();
        let worst = body
            .elastic_forces_at(&moved)
            .iter()
            .map(|f| f.norm())
            .fold(0.0, f64::max);
        assert!(
            worst < 1e-8 * scale,
            "rigid motion produced a force of {worst} N (1% stretch: {scale} N)"
        );
    }
}
