//! Stiffness-proportional damping (`Settings::damping_stiffness`, the edge dashpots filtered
//! implicitly): after a 1 cm probe jumps 10 cm into an organ held at its top, the organ comes
//! to rest sooner with the default β of 0.3 ms than without it and than with the paper's
//! method (which names no damping), also on an organ from another mesher; and the damping adds
//! no substep.

mod common;

use common::{bounds, fix_top, liver, tissue, weightless};
use tissuesim::{Pose, Real, Settings, ToolOptions, ToolShape, Vec3, World};

/// Below this speed (m/s) the organ is at rest.
const REST_SPEED: Real = 0.01;

/// What a jump did: the time (s) after which the organ's fastest particle stays below
/// [`REST_SPEED`] (the whole run if it never does), and the substeps of every step after it.
struct Ringing {
    rest_after: Real,
    substeps: Vec<u32>,
}

/// The jump of `contact_tools_and_organs`: `mesh` weightless, its top 10% fixed, a 1 cm sphere
/// 10 cm in front of its +z surface on the line through the centre of its bounding box, then
/// in one step at the surface, half in the tissue; `seconds` of steps after it.
fn jump(mesh: &str, settings: Settings, seconds: Real) -> Ringing {
    let mut world = World::new(settings).unwrap();
    let id = world.add_body(&liver(mesh), &tissue()).unwrap();
    fix_top(&mut world, id, 0.1);
    let rest = world.body(id).unwrap().rest_positions().to_vec();
    let (lo, hi) = bounds(&rest);
    let (cx, cy) = (
        0.5 * (lo.x + hi.x),
        0.5 * (lo.y + hi.y) - 0.1 * (hi.y - lo.y),
    );
    let probe = 0.01;
    let front = (rest.iter())
        .filter(|p| (p.x - cx).abs() < probe && (p.y - cy).abs() < probe)
        .map(|p| p.z)
        .fold(Real::NEG_INFINITY, Real::max);
    assert!(front.is_finite(), "{mesh}: no surface on the probe's line");
    let tool = world
        .add_tool(
            ToolShape::Sphere { radius: probe },
            Pose::at(Vec3::new(cx, cy, front + 0.1)),
            &ToolOptions::default(),
        )
        .unwrap();
    world.step().unwrap();
    world
        .set_tool_pose(tool, Pose::at(Vec3::new(cx, cy, front)))
        .unwrap();
    let dt = world.settings().dt;
    let steps = (seconds / dt).round() as usize;
    let mut last_moving = 0;
    let mut substeps = Vec::with_capacity(steps);
    for k in 1..=steps {
        substeps.push(world.step().unwrap().substeps);
        let b = world.body(id).unwrap();
        let fastest = b.velocities().iter().map(|v| v.norm()).fold(0.0, Real::max);
        if fastest > REST_SPEED {
            last_moving = k;
        }
    }
    Ringing {
        rest_after: last_moving as Real * dt,
        substeps,
    }
}

#[test]
fn the_default_damping_brings_an_organ_to_rest_sooner_at_no_substep() {
    let seconds = 3.5;
    let beta = weightless().damping_stiffness;
    assert!(
        beta > 0.0,
        "the default has no stiffness-proportional damping"
    );
    for mesh in ["liver_1k6.node", "kidney_gmsh"] {
        let damped = jump(mesh, weightless(), seconds);
        let undamped = jump(
            mesh,
            Settings {
                damping_stiffness: 0.0,
                ..weightless()
            },
            seconds,
        );
        let paper = jump(
            mesh,
            common::paper(Settings {
                damping_stiffness: 0.0,
                ..weightless()
            }),
            seconds,
        );
        println!(
            "{mesh}: at rest after {:.2} s (β {} ms), {:.2} s (β 0), {:.2} s (the paper's method)",
            damped.rest_after,
            1e3 * beta,
            undamped.rest_after,
            paper.rest_after
        );
        assert!(
            damped.rest_after < seconds,
            "{mesh}: still moving after {seconds} s"
        );
        assert!(
            damped.rest_after < undamped.rest_after && damped.rest_after < paper.rest_after,
            "{mesh}: at rest after {} s, {} s without damping, {} s with the paper's method",
            damped.rest_after,
            undamped.rest_after,
            paper.rest_after
        );
        assert_eq!(
            damped.substeps, undamped.substeps,
            "{mesh}: the damping changed the substeps"
        );
    }
}
