//! The body model is immutable and shareable: worlds built on
//! one `Arc<BodyModel>` hold the same load-time data without copying it, step exactly as
//! worlds that loaded the mesh themselves, and a cut in one world leaves the others' model
//! untouched (copy-on-write).

mod common;

use std::sync::Arc;
use tissuesim::{Blade, BodyId, BodyModel, Pose, Settings, ToolOptions, ToolShape, Vec3, World};

/// A 12 × 3 × 3 cm bar of firm tissue, cells of 1.5 cm.
fn bar_model() -> Arc<BodyModel> {
    let (mesh, options) = common::firm_bar();
    BodyModel::new(&mesh, &options).unwrap()
}

/// A world without gravity holding `model`, its end x = −6 cm fixed, a sphere above the free
/// end.
fn scene(model: Arc<BodyModel>) -> (World, BodyId) {
    let settings = Settings {
        gravity: Vec3::zeros(),
        ..Settings::default()
    };
    let mut w = World::new(settings).unwrap();
    let b = w.add_body_model(model);
    w.fix_box(b, Vec3::new(-1.0, -1.0, -1.0), Vec3::new(-0.0599, 1.0, 1.0))
        .unwrap();
    w.add_tool(
        ToolShape::Sphere { radius: 0.008 },
        Pose::at(Vec3::new(0.05, 0.03, 0.0)),
        &ToolOptions::default(),
    )
    .unwrap();
    (w, b)
}

/// Press the free end down 2.5 cm over 200 steps of 1 ms.
fn press(w: &mut World) {
    let probe = tissuesim::ToolId(0);
    for k in 0..200 {
        let y = 0.03 - 0.025 * (k + 1) as f64 / 200.0;
        w.set_tool_pose(probe, Pose::at(Vec3::new(0.05, y, 0.0)))
            .unwrap();
        w.step().unwrap();
    }
}

fn vertical_cut(x: f64) -> Blade {
    let edge = |y: f64| [Vec3::new(x, y, -0.05), Vec3::new(x, y, 0.05)];
    Blade {
        from: edge(0.1),
        to: edge(-0.1),
    }
}

#[test]
fn worlds_on_one_model_share_it_and_step_like_worlds_that_loaded_their_own() {
    let model = bar_model();
    let (mut shared_a, a) = scene(Arc::clone(&model));
    let (mut shared_b, b) = scene(Arc::clone(&model));
    let (mut own, c) = scene(bar_model());
    // One model, three holders (this test and two worlds); the third world has its own copy.
    assert_eq!(Arc::strong_count(&model), 3);
    assert!(Arc::ptr_eq(shared_a.body(a).unwrap().model(), &model));
    assert!(!Arc::ptr_eq(own.body(c).unwrap().model(), &model));
    assert!(model.heap_bytes() > 100 * model.particle_count());
    for w in [&mut shared_a, &mut shared_b, &mut own] {
        press(w);
    }
    let x = |w: &World, id| w.body(id).unwrap().positions().to_vec();
    let force = shared_a.tool(tissuesim::ToolId(0)).unwrap().wrench().force;
    assert!(force.norm() > 0.1);
    assert_eq!(
        x(&shared_a, a),
        x(&own, c),
        "a shared model steps bit for bit alike"
    );
    assert_eq!(x(&shared_b, b), x(&own, c));
}

#[test]
fn a_cut_copies_the_model_and_leaves_the_other_holders_uncut() {
    let model = bar_model();
    let tets = model.tets().len();
    let (mut cut, a) = scene(Arc::clone(&model));
    let (mut kept, b) = scene(Arc::clone(&model));
    let (mut reference, c) = scene(bar_model());
    let report = cut.cut(a, &vertical_cut(0.0075)).unwrap();
    assert!(report.tets > 0 && report.pairs > 0);
    // The cut world now runs on its own copy; the shared model and its other holder are intact.
    assert!(!Arc::ptr_eq(cut.body(a).unwrap().model(), &model));
    assert_eq!(cut.body(a).unwrap().tets().len(), tets - report.tets);
    assert_eq!(model.tets().len(), tets);
    assert_eq!(
        Arc::strong_count(&model),
        2 + 1,
        "the cut's record keeps the original too"
    );
    assert!(Arc::ptr_eq(kept.body(b).unwrap().model(), &model));
    press(&mut kept);
    press(&mut reference);
    assert_eq!(
        kept.body(b).unwrap().positions(),
        reference.body(c).unwrap().positions(),
        "the uncut holder behaves as if no other world had cut"
    );
    // Restoring the uncut state gives the cut world the load-time topology back.
    let (fresh, _) = scene(Arc::clone(&model));
    let mut bytes = Vec::new();
    fresh.save_state(&mut bytes);
    cut.restore_state(&bytes).unwrap();
    assert_eq!(cut.body(a).unwrap().tets().len(), tets);
    assert_eq!(cut.body(a).unwrap().cut_counts(), (0, 0));
}
