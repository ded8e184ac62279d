//! Contact against the organ's surface: instruments
//! thinner than the particle spacing press the deformed boundary triangles, not only the
//! particles, so that they never pass into the tissue. Scene: the default organ hanging from its
//! top 15%, settled at rest, a sphere pressed horizontally into it.

mod common;

use tissuesim::{
    mesh, BodyId, BodyOptions, Pose, Quat, Real, Settings, ToolOptions, ToolShape, Vec3, World,
};

/// How far the sphere is pressed past first contact (the contact skin over the surface, m).
const PRESS: Real = 0.03;

/// What a press measured.
struct Press {
    /// Steps on which the sphere's centre was inside the deformed surface.
    inside_steps: usize,
    /// Force on the sphere along the press direction reversed (N, > 0 pushes back), when its
    /// front was 1, 2 and 3 cm past first contact.
    push_back_at_cm: [Real; 3],
    /// The smallest push-back (N) over the steps from the first that pushed back.
    least_push_back: Real,
}

/// The default organ hanging from its top 15%, settled.
fn hanging_organ() -> (World, BodyId) {
    let organ = mesh::default_organ();
    let mut world = World::new(Settings::default()).unwrap();
    let body = world.add_body(&organ, &BodyOptions::default()).unwrap();
    common::fix_top(&mut world, body, 0.15);
    world.settle().unwrap();
    (world, body)
}

/// Press a sphere of `radius` (m) at `speed` (m/s) along the horizontal unit `direction`, on the
/// line through `through` (m), from 2 mm off the organ's contact skin until its front is
/// [`PRESS`] past it.
fn press(radius: Real, direction: Vec3, through: Vec3, speed: Real) -> Press {
    let (mut world, body) = hanging_organ();
    // Start 2 mm clear of the contact skin over the surface; depth counts from the skin.
    let gap = 0.002;
    let b = world.body(body).unwrap();
    let line = (through, direction);
    let start = common::press_start(b.positions(), b.contact_skin(), line, radius, gap);
    let tool = world
        .add_tool(
            ToolShape::Sphere { radius },
            Pose::at(start),
            &ToolOptions::default(),
        )
        .unwrap();
    let dt = world.settings().dt;
    let steps = ((gap + PRESS) / speed / dt).round() as usize;
    let mut touched = false;
    let mut result = Press {
        inside_steps: 0,
        push_back_at_cm: [Real::NAN; 3],
        least_push_back: Real::INFINITY,
    };
    for k in 1..=steps {
        let travel = speed * k as Real * dt;
        let centre = start + direction * travel;
        world.set_tool_pose(tool, Pose::at(centre)).unwrap();
        world.step().unwrap();
        let push_back = -world.tool(tool).unwrap().wrench().force.dot(&direction);
        result.inside_steps += world.body(body).unwrap().contains(&centre) as usize;
        let depth = travel - gap;
        touched |= push_back > 0.0;
        if touched {
            result.least_push_back = result.least_push_back.min(push_back);
        }
        for (cm, slot) in result.push_back_at_cm.iter_mut().enumerate() {
            if slot.is_nan() && depth >= 0.01 * (cm + 1) as Real - 1e-9 {
                *slot = push_back;
            }
        }
    }
    result
}

/// The facts of the issue for one press: the centre never inside, the force always pushing
/// back, and growing with depth.
fn assert_holds(what: &str, p: &Press) {
    let [f1, f2, f3] = p.push_back_at_cm;
    assert_eq!(
        p.inside_steps, 0,
        "{what}: centre inside the organ on {} steps",
        p.inside_steps
    );
    assert!(
        p.least_push_back > 0.0,
        "{what}: the force stopped pushing back ({} N)",
        p.least_push_back
    );
    assert!(
        f2 > 1.2 * f1 && f3 > 1.2 * f2,
        "{what}: force must grow with depth, got {f1:.3} / {f2:.3} / {f3:.3} N at 1 / 2 / 3 cm"
    );
}

#[test]
fn spheres_of_10_2_5_and_1_mm_pressed_3_cm_into_the_front_never_enter_the_organ() {
    for radius in [0.010, 0.0025, 0.001] {
        let p = press(radius, -Vec3::z(), Vec3::new(0.035, 0.0, 0.0), 0.05);
        assert_holds(&format!("front, r = {} mm", radius * 1e3), &p);
    }
}

#[test]
fn a_1_mm_sphere_pressed_into_the_side_never_enters_the_organ() {
    let (world, body) = hanging_organ();
    let (lo, hi) = common::bounds(world.body(body).unwrap().positions());
    let middle = (lo + hi) * 0.5;
    let through = Vec3::new(0.0, middle.y, middle.z);
    let p = press(0.001, Vec3::x(), through, 0.05);
    assert_holds("side, r = 1 mm", &p);
}

#[test]
fn a_1_mm_sphere_pushed_at_half_a_metre_per_second_does_not_tunnel() {
    let p = press(0.001, -Vec3::z(), Vec3::new(0.035, 0.0, 0.0), 0.5);
    assert_eq!(
        p.inside_steps, 0,
        "centre inside the organ on {} steps",
        p.inside_steps
    );
    assert!(
        p.least_push_back > 0.0,
        "the force stopped pushing back ({} N)",
        p.least_push_back
    );
}

#[test]
fn tools_driven_across_the_fixed_top_at_2_m_per_s_never_diverge() {
    // Where the tool touches a triangle next to its fixed corner, the point–triangle projection
    // moves the free corners by 1/b (b the contact point's small barycentric weight on them):
    // without a bound the soak run flung particles to 1e13 m/s, and every such step was rolled
    // back. Sphere, capsule and box driven 8 cm in along the boundary of the fixed top at 2 m/s,
    // wobbling across it and turning, then held for 0.1 s.
    let shapes = [
        ToolShape::Sphere { radius: 0.005 },
        ToolShape::Capsule {
            half_height: 0.02,
            radius: 0.003,
        },
        ToolShape::Cuboid {
            half_extents: Vec3::new(0.01, 0.004, 0.015),
        },
    ];
    let (mut world, body) = hanging_organ();
    let (lo, hi) = common::bounds(world.body(body).unwrap().positions());
    let fix_line = hi.y - 0.15 * (hi.y - lo.y);
    let start = Vec3::new(0.5 * (lo.x + hi.x), fix_line, lo.z - 0.02);
    let tools: Vec<_> = shapes
        .iter()
        .map(|s| {
            let options = ToolOptions::default();
            world
                .add_tool(s.clone(), Pose::at(start), &options)
                .unwrap()
        })
        .collect();
    let mut at_rest = Vec::new();
    world.save_state(&mut at_rest);
    let (dt, speed) = (world.settings().dt, 2.0);
    let steps = (0.08 / speed / dt).round() as usize;
    for (shape, &tool) in shapes.iter().zip(&tools) {
        world.restore_state(&at_rest).unwrap();
        let mut pose = Pose::at(start);
        for k in 1..=steps + 100 {
            let travel = speed * k.min(steps) as Real * dt;
            let wobble = 0.004 * (0.3 * k as Real).sin();
            pose.position = start + Vec3::new(0.0, wobble, travel);
            pose.orientation =
                Quat::from_scaled_axis(Vec3::new(0.01, 0.02, -0.015)) * pose.orientation;
            world.set_tool_pose(tool, pose).unwrap();
            if let Err(e) = world.step() {
                panic!("{shape:?}: step {k}: {e}");
            }
        }
    }
}
