//! Volume conservation: liver_4k sagging under gravity (top 10% fixed).
//!
//! How much volume is kept is a property of the material, whichever part of the solver carries
//! the bulk stiffness: nearly incompressible tissue (ν = 0.49, volume constraints on) keeps it
//! within 1% under a sag of several centimetres; the DESIGN §7 material (ν = 0.45) with the
//! volume constraints carrying λ (the default) physically loses a little more, reported here
//! and bounded; the particles carrying λ instead (consistent gradients) give the same order.

mod common;

use common::{fix_top, liver, tissue};
use tissuesim::{BodyOptions, Real, Settings, VolumeScheme, World};

/// Largest |V/V0 - 1| over 1.5 s of sagging, of the paper's particles with per-tetrahedron
/// volume constraints, or without them (the particles carrying λ).
fn worst_volume_error(volume_constraints: bool, poisson_ratio: Real) -> Real {
    worst_volume_error_with(
        Settings {
            volume_constraints,
            ..common::paper(Settings::default())
        },
        poisson_ratio,
    )
}

/// Largest |V/V0 - 1| over 1.5 s of sagging under `settings`.
fn worst_volume_error_with(settings: Settings, poisson_ratio: Real) -> Real {
    let volume_constraints = settings.volume_constraints;
    let mut world = World::new(settings).unwrap();
    let mut options: BodyOptions = tissue();
    options.material.poisson_ratio = poisson_ratio;
    let id = world.add_body(&liver("liver_4k.node"), &options).unwrap();
    assert!(fix_top(&mut world, id, 0.1) > 0);
    let mut worst: Real = 0.0;
    let mut sag: Real = 0.0;
    for _ in 0..1500 {
        world.step().unwrap();
        let b = world.body(id).unwrap();
        worst = worst.max((b.volume_ratio() - 1.0).abs());
        sag = sag.max(b.max_displacement());
    }
    println!(
        "nu {poisson_ratio}, volume constraints {volume_constraints}: largest |V/V0 - 1| = {:.4}%, largest sag {:.1} mm",
        worst * 100.0,
        sag * 1e3
    );
    assert!(sag > 0.005, "the liver must sag visibly under gravity");
    worst
}

#[test]
fn sagging_liver_keeps_its_volume_within_one_percent() {
    let with = worst_volume_error(true, 0.49);
    assert!(
        with < 0.01,
        "volume error {:.3}% with constraints",
        with * 100.0
    );
}

/// At the largest accepted Poisson ratio (ν = 0.499, λ/μ = 499) the default solver steps an
/// organ stably and keeps its volume closer than at 0.49: the volume constraints carry λ
/// implicitly, so no explicit bulk stiffness limits the step.
#[test]
fn nearly_incompressible_0499_liver_sags_and_keeps_its_volume() {
    let at_0499 = worst_volume_error(true, tissuesim::MAX_POISSON_RATIO);
    let at_049 = worst_volume_error(true, 0.49);
    assert!(
        at_0499 < 0.005 && at_0499 < at_049,
        "volume error {:.3}% at nu 0.499 against {:.3}% at 0.49",
        at_0499 * 100.0,
        at_049 * 100.0
    );
}

/// The default's one volume constraint per particle (its dual cell) holds a nearly
/// incompressible organ's volume as the per-tetrahedron constraints do, with about a sixth of
/// the constraints.
#[test]
fn dual_cell_constraints_keep_a_nearly_incompressible_liver_volume() {
    let settings = Settings::default();
    assert_eq!(settings.volume_scheme, VolumeScheme::DualCells);
    let dual = worst_volume_error_with(settings, 0.499);
    assert!(
        dual < 0.005,
        "volume error {:.3}% at nu 0.499",
        dual * 100.0
    );
}

#[test]
fn default_particles_hold_the_volume_of_a_nu_045_organ_like_the_constraints() {
    let particles = worst_volume_error(false, 0.45);
    let constraints = worst_volume_error(true, 0.45);
    // Measured 1.0% and 1.8% (the constraints converge in one XPBD pass only); both are the
    // material's own compressibility under a ~8 cm sag.
    assert!(
        particles < 0.015,
        "{:.3}% with the particles",
        particles * 100.0
    );
    assert!(
        constraints < 0.025,
        "{:.3}% with the constraints",
        constraints * 100.0
    );
}

/// `Body::volume` (the volume the boundary surface encloses) is the sum of the signed volumes
/// of the tetrahedra at rest, deformed, and with tetrahedra inverted.
#[test]
fn the_body_volume_is_the_sum_of_its_tetrahedra() {
    let mut world = World::new(Settings::default()).unwrap();
    let id = world.add_body(&liver("liver_1k6.node"), &tissue()).unwrap();
    let b = world.body(id).unwrap();
    let (rest, tets) = (b.rest_positions().to_vec(), b.tets().to_vec());
    let sum = |x: &[tissuesim::Vec3]| common::tet_volumes(x, &tets).iter().sum::<Real>();
    let mut seed = 7u64;
    let mut noise = || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (seed >> 11) as Real / (1u64 << 53) as Real - 0.5
    };
    let scale = common::bounds(&rest).1 - common::bounds(&rest).0;
    for amplitude in [0.0, 0.01, 0.2] {
        let x: Vec<_> = rest
            .iter()
            .map(|p| p + scale.map(|s| s * amplitude * noise()))
            .collect();
        let v = vec![tissuesim::Vec3::zeros(); x.len()];
        world.set_body_state(id, &x, &v).unwrap();
        let (got, want) = (world.body(id).unwrap().volume(), sum(&x));
        assert!(
            (got - want).abs()
                <= 1e-12
                    * common::tet_volumes(&x, &tets)
                        .iter()
                        .map(|v| v.abs())
                        .sum::<Real>(),
            "amplitude {amplitude}: {got} against {want}"
        );
        if amplitude == 0.0 {
            assert!((got / world.body(id).unwrap().rest_volume() - 1.0).abs() < 1e-12);
        }
    }
}
