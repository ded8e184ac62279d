//! Cutting: a blade's swept edge removes the neighbour
//! pairs and tetrahedra it crosses. A piece cut free falls and keeps its volume; a partial cut
//! in the stretched side of a sagging cantilever opens; cuts are deterministic and survive
//! save/restore.

mod common;

use tissuesim::{Blade, BodyId, Error, Pose, Real, Settings, ToolOptions, ToolShape, Vec3, World};

/// A 12 × 3 × 3 cm bar of firm tissue (E = 100 kPa, ν = 0.45, ρ = 1060 kg/m³: it sags a few
/// millimetres) along x, cells of 1.5 cm, its end x = −6 cm fixed.
fn bar(threads: u32) -> (World, BodyId) {
    bar_with(Settings {
        threads,
        ..Settings::default()
    })
}

/// [`bar`] under `settings`.
fn bar_with(settings: Settings) -> (World, BodyId) {
    let mut w = World::new(settings).unwrap();
    let (mesh, options) = common::firm_bar();
    let b = w.add_body(&mesh, &options).unwrap();
    w.fix_box(b, Vec3::new(-1.0, -1.0, -1.0), Vec3::new(-0.0599, 1.0, 1.0))
        .unwrap();
    (w, b)
}

/// A blade in the plane x = `x` swept from y = `top` down to y = `bottom`, across all of z.
fn vertical_cut(x: Real, top: Real, bottom: Real) -> Blade {
    let edge = |y: Real| [Vec3::new(x, y, -0.05), Vec3::new(x, y, 0.05)];
    Blade {
        from: edge(top),
        to: edge(bottom),
    }
}

fn run(w: &mut World, seconds: Real) {
    for _ in 0..(seconds / w.settings().dt).round() as usize {
        w.step().unwrap();
    }
}

/// Mean y (m) of the particles whose rest x lies in `[lo, hi]`.
fn mean_y(w: &World, b: BodyId, lo: Real, hi: Real) -> Real {
    let body = w.body(b).unwrap();
    let (sum, n) = body
        .rest_positions()
        .iter()
        .zip(body.positions())
        .filter(|(r, _)| (lo..=hi).contains(&r.x))
        .fold((0.0, 0), |(s, n), (_, x)| (s + x.y, n + 1));
    sum / n as Real
}

/// Volume (m³) of the tetrahedra whose nodes all have rest x in `[lo, hi]`, now and at rest.
fn piece_volume(w: &World, b: BodyId, lo: Real, hi: Real) -> (Real, Real) {
    let body = w.body(b).unwrap();
    let (rest, x) = (body.rest_positions(), body.positions());
    let mut v = (0.0, 0.0);
    for t in body.tets() {
        let [a, b2, c, d] = t.map(|k| k as usize);
        if [a, b2, c, d]
            .iter()
            .all(|&k| (lo..=hi).contains(&rest[k].x))
        {
            v.0 += tissuesim::tet_volume(&x[a], &x[b2], &x[c], &x[d]);
            v.1 += tissuesim::tet_volume(&rest[a], &rest[b2], &rest[c], &rest[d]);
        }
    }
    v
}

#[test]
fn a_piece_cut_free_falls_and_keeps_its_volume() {
    let (mut w, b) = bar(1);
    run(&mut w, 0.5);
    let free_end = mean_y(&w, b, 0.014, 0.07);
    let report = w.cut(b, &vertical_cut(0.0075, 0.1, -0.1)).unwrap();
    println!("cut through: {report:?}");
    assert!(report.pairs > 0 && report.tets > 0);
    assert_eq!(w.body(b).unwrap().cut_counts(), (report.pairs, report.tets));
    run(&mut w, 0.2);
    let fall = free_end - mean_y(&w, b, 0.014, 0.07);
    let stub = mean_y(&w, b, -0.07, 0.0);
    println!(
        "0.2 s after the cut: the free piece fell {:.1} mm; the stub is at {:.1} mm",
        fall * 1e3,
        stub * 1e3
    );
    // Free fall over 0.2 s is 196 mm; ambient damping (2/s) takes some of it.
    assert!(fall > 0.12, "the piece cut free falls: {fall} m");
    assert!(stub > -0.02, "the fixed stub stays up: {stub} m");
    let (now, rest) = piece_volume(&w, b, 0.014, 0.07);
    println!("free piece volume ratio {:.4}", now / rest);
    assert!(
        (now / rest - 1.0).abs() < 0.02,
        "the falling piece keeps its volume"
    );
}

#[test]
fn a_partial_cut_in_the_stretched_side_opens() {
    // The cantilever sags under gravity: its top near the root is stretched along x.
    let gap = |cut: bool| {
        let (mut w, b) = bar(1);
        if cut {
            // From above the top face down to the middle, between the cells at x = -4.5 and -3 cm.
            let r = w.cut(b, &vertical_cut(-0.0375, 0.1, 0.0)).unwrap();
            assert!(r.pairs > 0);
        }
        run(&mut w, 1.5);
        let body = w.body(b).unwrap();
        let top = |x0: Real| {
            let k = body
                .rest_positions()
                .iter()
                .position(|r| {
                    (r.x - x0).abs() < 1e-9 && (r.y - 0.015).abs() < 1e-9 && r.z.abs() < 1e-9
                })
                .unwrap();
            body.positions()[k]
        };
        let opening = (top(-0.03) - top(-0.045)).norm();
        (opening, mean_y(&w, b, 0.059, 0.07))
    };
    let (closed, tip_whole) = gap(false);
    let (open, tip_cut) = gap(true);
    println!(
        "top gap across the cut: {:.2} mm uncut, {:.2} mm cut; tip at {:.1} / {:.1} mm",
        closed * 1e3,
        open * 1e3,
        tip_whole * 1e3,
        tip_cut * 1e3
    );
    assert!(open > closed + 0.002, "the cut opens by more than 2 mm");
    assert!(tip_cut < tip_whole, "a notched cantilever sags more");
}

#[test]
fn cuts_are_deterministic_and_survive_save_and_restore() {
    let cut_and_run = |threads: u32| {
        let (mut w, b) = bar(threads);
        run(&mut w, 0.1);
        w.cut(b, &vertical_cut(0.0225, 0.1, -0.1)).unwrap();
        run(&mut w, 0.1);
        w.body(b).unwrap().positions().to_vec()
    };
    assert_eq!(cut_and_run(1), cut_and_run(1));
    assert_eq!(cut_and_run(1), cut_and_run(2));

    let (mut w, b) = bar(1);
    run(&mut w, 0.1);
    let mut uncut = Vec::new();
    w.save_state(&mut uncut);
    w.cut(b, &vertical_cut(0.0225, 0.1, -0.1)).unwrap();
    let mut cut = Vec::new();
    w.save_state(&mut cut);
    assert_eq!(cut.len(), w.state_size());
    run(&mut w, 0.1);
    let after_cut = w.body(b).unwrap().positions().to_vec();
    // Back to the uncut state: the topology comes back too, and the bar holds together.
    w.restore_state(&uncut).unwrap();
    assert_eq!(w.body(b).unwrap().cut_counts(), (0, 0));
    run(&mut w, 0.1);
    let (mut fresh, fb) = bar(1);
    run(&mut fresh, 0.2);
    assert_eq!(
        w.body(b).unwrap().positions(),
        fresh.body(fb).unwrap().positions(),
        "restoring the uncut state gives the uncut run"
    );
    // The cut state restores into a world built the same way, never cut.
    let (mut other, ob) = bar(1);
    other.restore_state(&cut).unwrap();
    run(&mut other, 0.1);
    assert_eq!(other.body(ob).unwrap().positions(), &after_cut[..]);
    // A corrupted cut list is refused and changes nothing.
    let mut bad = cut.clone();
    let n = bad.len();
    bad[n - 12] ^= 0x40;
    assert!(matches!(other.restore_state(&bad), Err(Error::BadState(_))));
}

/// The default's force pass shares the tetrahedra among the threads by a layout made for the
/// current tetrahedra: after a cut, and after restoring a cut state into a world never cut,
/// one and two threads still give the same bits.
#[test]
fn cuts_on_tetrahedra_give_the_same_bits_on_one_and_two_threads() {
    let tetrahedra = |threads| {
        bar_with(Settings {
            threads,
            ..Settings::default()
        })
    };
    let cut_and_run = |threads: u32| {
        let (mut w, b) = tetrahedra(threads);
        run(&mut w, 0.05);
        w.cut(b, &vertical_cut(0.0225, 0.1, -0.1)).unwrap();
        assert!(w.body(b).unwrap().cut_counts().1 > 0, "tetrahedra removed");
        let mut cut = Vec::new();
        w.save_state(&mut cut);
        run(&mut w, 0.05);
        (w.body(b).unwrap().positions().to_vec(), cut)
    };
    let (one, cut) = cut_and_run(1);
    assert_eq!(one, cut_and_run(2).0);
    let (mut other, ob) = tetrahedra(2);
    other.restore_state(&cut).unwrap();
    run(&mut other, 0.05);
    assert_eq!(other.body(ob).unwrap().positions(), &one[..]);
}

#[test]
fn a_blade_tool_cuts_along_its_swept_edge() {
    let (mut w, b) = bar(1);
    let blade = w
        .add_tool(
            ToolShape::Capsule {
                half_height: 0.05,
                radius: 0.0005,
            },
            // Edge along z (local y turned onto z), above the bar at x = 1.5 cm.
            Pose {
                position: Vec3::new(0.0225, 0.05, 0.0),
                orientation: tissuesim::Quat::from_axis_angle(
                    &Vec3::x_axis(),
                    std::f64::consts::FRAC_PI_2,
                ),
            },
            &ToolOptions::default(),
        )
        .unwrap();
    w.make_blade(blade).unwrap();
    let mut cut = 0;
    for k in 1..=100 {
        let mut p = w.tool(blade).unwrap().pose();
        p.position.y = 0.05 - 0.001 * k as Real;
        w.set_tool_pose(blade, p).unwrap();
        cut += w.step().unwrap().cut.pairs;
    }
    let (pairs, tets) = w.body(b).unwrap().cut_counts();
    println!("blade stroke: {pairs} pairs and {tets} tetrahedra cut");
    assert_eq!(cut, pairs);
    assert!(pairs > 0 && tets > 0);
    let ball = w
        .add_tool(
            ToolShape::Sphere { radius: 0.01 },
            Pose::at(Vec3::new(1.0, 1.0, 1.0)),
            &ToolOptions::default(),
        )
        .unwrap();
    assert!(matches!(w.make_blade(ball), Err(Error::InvalidArgument(_))));
    // A blade faster than the jump speed (the whole stroke in one step) still cuts along its
    // whole path: only pushing tools are placed instead of swept.
    let (mut fast, fb) = bar(1);
    let start = w.tool(blade).unwrap().pose();
    let start = Pose {
        position: Vec3::new(start.position.x, 0.05, 0.0),
        ..start
    };
    let fast_blade = fast
        .add_tool(
            w.tool(blade).unwrap().shape().clone(),
            start,
            &ToolOptions::default(),
        )
        .unwrap();
    fast.make_blade(fast_blade).unwrap();
    let mut end = start;
    end.position.y = -0.05;
    assert!(0.1 > fast.tool_jump_speed() * fast.settings().dt, "a jump");
    fast.set_tool_pose(fast_blade, end).unwrap();
    let one_step = fast.step().unwrap().cut.pairs;
    assert_eq!(one_step, fast.body(fb).unwrap().cut_counts().0);
    assert!(one_step > 0, "a fast blade cut nothing");
    let nan = Blade {
        from: [Vec3::new(Real::NAN, 0.0, 0.0), Vec3::zeros()],
        to: [Vec3::zeros(), Vec3::x()],
    };
    assert!(matches!(w.cut(b, &nan), Err(Error::NonFinite(_))));
}
