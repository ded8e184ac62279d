//! Surface self-contact, measured on the geometry: a slab folded onto itself by a press ends
//! with no crossing surface triangles, and the two faces of a cut squeezed together do not pass
//! through each other; with `Settings::self_contact` off both do (the scenes have teeth).
//! Crossings are counted by an exact triangle–triangle test written here
//! (`common/intersections.rs`), pairs sharing a vertex skipped.

mod common;
#[path = "common/intersections.rs"]
mod intersections;

use intersections::{crossing_pairs, triangles_cross};
use tissuesim::{
    mesh, Blade, BodyId, Pose, Quat, Real, Settings, ToolOptions, ToolShape, Vec3, World,
};

/// Crossing pairs of `body`'s boundary triangles now.
fn crossings(w: &World, body: BodyId) -> Vec<(usize, usize)> {
    let b = w.body(body).unwrap();
    crossing_pairs(b.positions(), b.boundary_triangles())
}

#[test]
fn the_triangle_test_tells_crossing_from_apart() {
    let t = [Vec3::zeros(), Vec3::x(), Vec3::y()];
    let through = [
        Vec3::new(0.2, 0.2, -1.0),
        Vec3::new(0.3, 0.2, 1.0),
        Vec3::new(0.2, 0.3, 1.0),
    ];
    assert!(triangles_cross(&t, &through));
    assert!(!triangles_cross(&t, &through.map(|p| p + Vec3::z() * 1.5)));
    assert!(!triangles_cross(&t, &through.map(|p| p + Vec3::x() * 2.0)));
}

/// Slab thickness (m): 12 × 1.2 × 4 cm along x, three layers of 4 mm cells across.
const THICKNESS: Real = 0.012;

/// The fold: a slab along x clamped for x < −3 cm, a plate under its part beyond x = 0 turned
/// by 180° about the z axis through (`HINGE_X`, `HINGE_Y`) over a second, like closing a
/// book, then held. The hinge sits 1.5 mm below the slab's top and the plate starts 1 mm under
/// the slab, so the turned plate ends 2 mm nearer the clamped part than two thicknesses: the
/// turned part is pressed onto the clamped part and the free part between them is bent into a
/// tight U. Returns the world and the slab after `seconds`.
const HINGE_X: Real = -0.005;
const HINGE_Y: Real = THICKNESS - 0.0015;

fn fold(self_contact: bool, seconds: Real) -> (World, BodyId) {
    let settings = Settings {
        self_contact,
        ..common::weightless()
    };
    let mut w = World::new(settings).unwrap();
    let slab = mesh::lattice_box(
        Vec3::new(-0.06, 0.0, -0.02),
        Vec3::new(0.06, THICKNESS, 0.02),
        [30, 3, 10],
    );
    let b = w.add_body(&slab, &common::tissue()).unwrap();
    w.fix_box(b, Vec3::new(-1.0, -1.0, -1.0), Vec3::new(-0.0301, 1.0, 1.0))
        .unwrap();
    // The plate: 7 × 0.8 × 6 cm, its top 1 mm under the slab from x = 0 on.
    let (half, gap) = (Vec3::new(0.035, 0.004, 0.03), 0.001);
    let plate_at = |angle: Real| {
        let hinge = Vec3::new(HINGE_X, HINGE_Y, 0.0);
        let rotation = Quat::from_scaled_axis(Vec3::z() * angle);
        let centre = Vec3::new(0.0 + half.x, -gap - half.y, 0.0);
        Pose {
            position: hinge + rotation * (centre - hinge),
            orientation: rotation,
        }
    };
    let grip = ToolOptions {
        friction_static: 0.6,
        friction_kinetic: 0.5,
        ..ToolOptions::default()
    };
    let t = w
        .add_tool(
            ToolShape::Cuboid { half_extents: half },
            plate_at(0.0),
            &grip,
        )
        .unwrap();
    let dt = w.settings().dt;
    let steps = (seconds / dt).round() as usize;
    for k in 1..=steps {
        let turn = (k as Real * dt).min(1.0);
        w.set_tool_pose(t, plate_at(std::f64::consts::PI * turn))
            .unwrap();
        w.step().unwrap();
    }
    (w, b)
}

/// The fold ends with no crossing surface triangles; without self-contact the turned part and
/// the U of the bend pass into the clamped part.
#[test]
fn a_slab_folded_onto_itself_by_a_press_does_not_pass_through_itself() {
    let (on, b) = fold(true, 1.3);
    let (off, b_off) = fold(false, 1.3);
    let (found_on, found_off) = (crossings(&on, b), crossings(&off, b_off));
    let top_of = |w: &World| {
        let body = w.body(b).unwrap();
        (body.rest_positions().iter().zip(body.positions()))
            .filter(|(r, _)| r.x > 0.059)
            .map(|(_, x)| x.y)
            .fold(Real::MIN, Real::max)
    };
    println!(
        "folded slab: {} crossing triangle pairs with self-contact, {} without; the free end \
         at y = {:.1} mm (folded over: above the slab's {:.0} mm)",
        found_on.len(),
        found_off.len(),
        top_of(&on) * 1e3,
        THICKNESS * 1e3
    );
    assert!(
        top_of(&on) > THICKNESS,
        "the slab is folded over onto itself"
    );
    assert!(
        found_off.len() > 10,
        "without self-contact the fold passes through itself: {} pairs",
        found_off.len()
    );
    assert!(
        found_on.is_empty(),
        "crossing pairs with self-contact: {found_on:?}"
    );
}

/// A 6 × 3 × 3 cm block, its bottom fixed, cut from the top down to 1 cm above its bottom in
/// the plane x = 2.5 mm (between two layers of its 5 mm cells), the halves above the uncut
/// centimetre squeezed together by two plates moving `squeeze` (m) each over 0.5 s, held
/// 0.2 s.
fn squeezed_cut(self_contact: bool, squeeze: Real, threads: u32) -> (World, BodyId) {
    let settings = Settings {
        self_contact,
        threads,
        ..Settings::default()
    };
    let mut w = World::new(settings).unwrap();
    let block = mesh::lattice_box(
        Vec3::new(-0.03, 0.0, -0.015),
        Vec3::new(0.03, 0.03, 0.015),
        [12, 6, 6],
    );
    let b = w.add_body(&block, &common::tissue()).unwrap();
    w.fix_box(b, Vec3::repeat(-1.0), Vec3::new(1.0, 0.001, 1.0))
        .unwrap();
    let edge = |y: Real| [Vec3::new(0.0025, y, -0.05), Vec3::new(0.0025, y, 0.05)];
    let report = w
        .cut(
            b,
            &Blade {
                from: edge(0.1),
                to: edge(0.01),
            },
        )
        .unwrap();
    assert!(report.tets > 0);
    let half = Vec3::new(0.005, 0.008, 0.025);
    let at = |side: Real, inward: Real| {
        Pose::at(Vec3::new(
            side * (0.03 + half.x + 0.0005 - inward),
            0.022,
            0.0,
        ))
    };
    let plates = [-1.0, 1.0].map(|side| {
        let shape = ToolShape::Cuboid { half_extents: half };
        w.add_tool(shape, at(side, 0.0), &ToolOptions::default())
            .unwrap()
    });
    let dt = w.settings().dt;
    for k in 1..=700 {
        let s = (k as Real * dt / 0.5).min(1.0);
        for (plate, side) in plates.iter().zip([-1.0, 1.0]) {
            w.set_tool_pose(*plate, at(side, squeeze * s)).unwrap();
        }
        w.step().unwrap();
    }
    (w, b)
}

/// The cut's two faces, squeezed 6 mm each way after a gap of one 5 mm cell, stay apart; without
/// self-contact they pass through each other.
#[test]
fn the_faces_of_a_cut_squeezed_together_do_not_pass_through_each_other() {
    let (on, b) = squeezed_cut(true, 0.006, 1);
    let (off, b_off) = squeezed_cut(false, 0.006, 1);
    let (found_on, found_off) = (crossings(&on, b), crossings(&off, b_off));
    println!(
        "squeezed cut: {} crossing triangle pairs with self-contact, {} without",
        found_on.len(),
        found_off.len()
    );
    assert!(
        found_off.len() > 10,
        "without self-contact the faces pass through each other: {} pairs",
        found_off.len()
    );
    assert!(
        found_on.is_empty(),
        "crossing pairs with self-contact: {found_on:?}"
    );
}

/// The squeezed cut with self-contact gives the same bits on one thread and on two.
#[test]
fn self_contact_gives_the_same_bits_on_any_thread_count() {
    let (one, b) = squeezed_cut(true, 0.006, 1);
    let (two, _) = squeezed_cut(true, 0.006, 2);
    let bits = |w: &World| -> Vec<u64> {
        let body = w.body(b).unwrap();
        body.positions()
            .iter()
            .flat_map(|p| p.iter().map(|c| c.to_bits()))
            .collect()
    };
    assert!(bits(&one) == bits(&two), "one and two threads differ");
}
