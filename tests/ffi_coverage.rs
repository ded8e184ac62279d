//! The C API functions that cover the rest of the Rust API a trainer uses,
//! checked by their physical effect through the `extern "C"` functions: setting a body's
//! positions and velocities, reading its fixed flags and particle radius, removing a tool,
//! convex-hull and triangle-array tools, tool friction, body-pair friction. And the one
//! validation path: the C layer and the Rust API reject the same values with the same error
//! (a capsule of half-height 0 is a sphere in both).

use std::ffi::{c_char, CStr};
use std::ptr::{null, null_mut};
use tissuesim::ffi::body::*;
use tissuesim::ffi::error::*;
use tissuesim::ffi::state::*;
use tissuesim::ffi::status::*;
use tissuesim::ffi::tool::*;
use tissuesim::ffi::world::*;
use tissuesim::{mesh, Pose, ToolOptions, ToolShape, Vec3};

use ts_status as S;

/// Edge of the lattice cube (m).
const SIZE: f64 = 0.06;

fn last_error() -> String {
    let n = unsafe { ts_last_error_message(null_mut(), 0) };
    let mut buf = vec![0 as c_char; n + 1];
    unsafe { ts_last_error_message(buf.as_mut_ptr(), buf.len()) };
    unsafe { CStr::from_ptr(buf.as_ptr()) }
        .to_string_lossy()
        .into_owned()
}

#[track_caller]
fn ok(st: ts_status) {
    assert_eq!(st, S::Ok, "{}", last_error());
}

#[track_caller]
fn expect(st: ts_status, expected: ts_status, needle: &str) {
    let msg = last_error();
    assert_eq!(st, expected, "last error: {msg}");
    assert!(msg.contains(needle), "{msg:?} should mention {needle:?}");
}

fn settings() -> ts_settings {
    let mut s = std::mem::MaybeUninit::uninit();
    ok(unsafe { ts_settings_default(s.as_mut_ptr()) });
    unsafe { s.assume_init() }
}

fn material() -> ts_material {
    let mut m = std::mem::MaybeUninit::uninit();
    ok(unsafe { ts_material_default(m.as_mut_ptr()) });
    unsafe { m.assume_init() }
}

fn pose(x: f64, y: f64, z: f64) -> ts_pose {
    ts_pose {
        position: [x, y, z],
        orientation: [1.0, 0.0, 0.0, 0.0],
    }
}

/// A world owned by the test.
struct W(*mut ts_world);

impl Drop for W {
    fn drop(&mut self) {
        unsafe { ts_world_free(self.0) };
    }
}

impl W {
    fn new(s: &ts_settings) -> W {
        let mut w = null_mut();
        ok(unsafe { ts_world_new(s, &mut w) });
        W(w)
    }

    /// Add a 3 x 3 x 3-cell lattice cube of edge SIZE with its lowest corner at `corner`;
    /// `particle_radius` 0 is automatic.
    fn add_cube(&self, corner: [f64; 3], particle_radius: f64) -> u32 {
        let lo = Vec3::from(corner);
        let m = mesh::lattice_box(lo, lo.add_scalar(SIZE), [3, 3, 3]);
        let nodes: Vec<f64> = m.nodes.iter().flat_map(|p| [p.x, p.y, p.z]).collect();
        let tets: Vec<u32> = m.tets.iter().flatten().copied().collect();
        let mut o = std::mem::MaybeUninit::uninit();
        ok(unsafe { ts_body_options_default(o.as_mut_ptr()) });
        let mut o = unsafe { o.assume_init() };
        o.particle_radius = particle_radius;
        let mut id = u32::MAX;
        ok(unsafe {
            ts_world_add_body_from_arrays(
                self.0,
                nodes.as_ptr(),
                nodes.len() / 3,
                tets.as_ptr(),
                tets.len() / 4,
                &material(),
                &o,
                &mut id,
            )
        });
        id
    }

    /// Fix the particles of `body` in the box [lo, hi]; returns how many.
    fn fix_box(&self, body: u32, lo: [f64; 3], hi: [f64; 3]) -> usize {
        let mut n = 0;
        ok(unsafe { ts_body_fix_box(self.0, body, lo.as_ptr(), hi.as_ptr(), &mut n) });
        n
    }

    fn particles(&self, body: u32) -> usize {
        let mut n = 0;
        ok(unsafe { ts_body_particle_count(self.0, body, &mut n) });
        n
    }

    fn positions(&self, body: u32) -> Vec<f64> {
        let mut v = vec![0.0; 3 * self.particles(body)];
        ok(unsafe { ts_body_positions(self.0, body, v.as_mut_ptr(), v.len()) });
        v
    }

    fn velocities(&self, body: u32) -> Vec<f64> {
        let mut v = vec![0.0; 3 * self.particles(body)];
        ok(unsafe { ts_body_velocities(self.0, body, v.as_mut_ptr(), v.len()) });
        v
    }

    fn step(&self, n: usize) {
        for _ in 0..n {
            ok(unsafe { ts_world_step(self.0, null_mut()) });
        }
    }

    fn wrench(&self, tool: u32) -> ts_wrench {
        let mut w = ts_wrench::default();
        ok(unsafe { ts_tool_wrench(self.0, tool, &mut w) });
        w
    }

    fn tool_count(&self) -> u32 {
        let mut n = 0;
        ok(unsafe { ts_world_tool_count(self.0, &mut n) });
        n
    }

    /// Move `tool` from `from` to `to` (m) over `steps` steps, then hold it `hold` steps.
    fn drive(&self, tool: u32, from: [f64; 3], to: [f64; 3], steps: usize, hold: usize) {
        for k in 1..=steps + hold {
            let s = k.min(steps) as f64 / steps as f64;
            let p = pose(
                from[0] + s * (to[0] - from[0]),
                from[1] + s * (to[1] - from[1]),
                from[2] + s * (to[2] - from[2]),
            );
            ok(unsafe { ts_tool_set_pose(self.0, tool, &p) });
            self.step(1);
        }
    }
}

/// A cube centred on the origin with its top face fixed (body 0).
fn hanging_cube() -> W {
    let w = W::new(&settings());
    let b = w.add_cube([-SIZE / 2.0; 3], 0.0);
    assert_eq!(b, 0);
    let fixed = w.fix_box(0, [-1.0, SIZE / 2.0 - 1e-6, -1.0], [1.0; 3]);
    assert_eq!(fixed, 16);
    w
}

/// Below the cube's bottom face (y = -SIZE/2), 1 mm clear of it for a 1 cm sphere.
const BELOW: [f64; 3] = [0.0, -SIZE / 2.0 - 0.011, 0.0];
/// 4 mm into the bottom face for a 1 cm sphere.
const PRESSED: [f64; 3] = [0.0, -SIZE / 2.0 - 0.006, 0.0];

#[test]
fn set_state_then_read_it_back() {
    let w = hanging_cube();
    let n = w.particles(0);
    let mut flags = vec![9u8; n];
    ok(unsafe { ts_body_fixed_flags(w.0, 0, flags.as_mut_ptr(), n) });
    let x0 = w.positions(0);
    for i in 0..n {
        assert_eq!(
            flags[i] == 1,
            x0[3 * i + 1] > SIZE / 2.0 - 1e-6,
            "particle {i}"
        );
        assert!(flags[i] <= 1);
    }
    assert_eq!(flags.iter().filter(|&&f| f == 1).count(), 16);
    let x: Vec<f64> = (0..3 * n).map(|k| x0[k] + 1e-3 * (k % 7) as f64).collect();
    let v: Vec<f64> = (0..3 * n).map(|k| 0.01 * (k % 5) as f64 - 0.02).collect();
    ok(unsafe { ts_body_set_state(w.0, 0, x.as_ptr(), x.len(), v.as_ptr(), v.len()) });
    assert_eq!(w.positions(0), x, "positions read back exactly");
    let got = w.velocities(0);
    for i in 0..n {
        for a in 0..3 {
            let want = if flags[i] == 1 { 0.0 } else { v[3 * i + a] };
            assert_eq!(got[3 * i + a], want, "velocity {i}.{a}");
        }
    }
    // The velocities act: from the rest shape with 5 cm/s along z everywhere, a step later
    // the free particles moved by about v dt along z.
    let vz: Vec<f64> = (0..3 * n)
        .map(|k| if k % 3 == 2 { 0.05 } else { 0.0 })
        .collect();
    ok(unsafe { ts_body_set_state(w.0, 0, x0.as_ptr(), x0.len(), vz.as_ptr(), vz.len()) });
    w.step(1);
    let after = w.positions(0);
    let free: Vec<usize> = (0..n).filter(|&i| flags[i] == 0).collect();
    let dz = free
        .iter()
        .map(|&i| after[3 * i + 2] - x0[3 * i + 2])
        .sum::<f64>()
        / free.len() as f64;
    assert!((dz - 0.05e-3).abs() < 0.1 * 0.05e-3, "{dz}");
    ok(unsafe { ts_body_set_state(w.0, 0, x.as_ptr(), x.len(), v.as_ptr(), v.len()) });
    // Errors change nothing.
    let before = (w.positions(0), w.velocities(0));
    let mut nan = x.clone();
    nan[4] = f64::NAN;
    let sts = unsafe {
        [
            ts_body_set_state(null_mut(), 0, x.as_ptr(), x.len(), v.as_ptr(), v.len()),
            ts_body_set_state(w.0, 0, null(), x.len(), v.as_ptr(), v.len()),
            ts_body_set_state(w.0, 0, x.as_ptr(), x.len(), null(), v.len()),
            ts_body_set_state(w.0, 3, x.as_ptr(), x.len(), v.as_ptr(), v.len()),
            ts_body_set_state(w.0, 0, x.as_ptr(), x.len() - 3, v.as_ptr(), v.len()),
            ts_body_set_state(w.0, 0, x.as_ptr(), x.len(), v.as_ptr(), v.len() - 1),
            ts_body_set_state(w.0, 0, nan.as_ptr(), x.len(), v.as_ptr(), v.len()),
        ]
    };
    let expected = [
        S::NullParameter,
        S::NullParameter,
        S::NullParameter,
        S::UnknownBody,
        S::InvalidArgument,
        S::InvalidArgument,
        S::NonFinite,
    ];
    assert_eq!(sts, expected);
    assert_eq!((w.positions(0), w.velocities(0)), before);
    // Fixed flags and particle radius: short buffers, unknown bodies, NULL.
    let mut short = vec![7u8; n - 1];
    let st = unsafe { ts_body_fixed_flags(w.0, 0, short.as_mut_ptr(), short.len()) };
    expect(st, S::BufferTooSmall, &n.to_string());
    assert!(short.iter().all(|&f| f == 7));
    let st = unsafe { ts_body_fixed_flags(w.0, 1, flags.as_mut_ptr(), n) };
    assert_eq!(st, S::UnknownBody);
    let st = unsafe { ts_body_fixed_flags(w.0, 0, null_mut(), n) };
    assert_eq!(st, S::NullParameter);
    let mut r = 0.0;
    ok(unsafe { ts_body_particle_radius(w.0, 0, &mut r) });
    assert!(r > 0.0 && r < SIZE / 3.0, "{r}");
    assert_eq!(
        unsafe { ts_body_particle_radius(w.0, 1, &mut r) },
        S::UnknownBody
    );
    assert_eq!(
        unsafe { ts_body_particle_radius(w.0, 0, null_mut()) },
        S::NullParameter
    );
}

#[test]
fn a_removed_tool_stops_pushing_and_its_id_is_stale() {
    let w = hanging_cube();
    let mut probe = u32::MAX;
    ok(unsafe {
        ts_world_add_tool_sphere(
            w.0,
            0.01,
            &pose(BELOW[0], BELOW[1], BELOW[2]),
            null(),
            &mut probe,
        )
    });
    w.drive(probe, BELOW, PRESSED, 40, 20);
    assert!(
        w.wrench(probe).force[1] < -0.01,
        "the tissue pushes the probe down"
    );
    let mut size = 0;
    ok(unsafe { ts_world_state_size(w.0, &mut size) });
    let mut state = vec![0u8; size];
    ok(unsafe { ts_world_save_state(w.0, state.as_mut_ptr(), size, null_mut()) });

    // A twin without a tool, stepped alike, only sags under gravity.
    let twin = hanging_cube();
    twin.step(60);
    let apart = |a: &W, b: &W| {
        let (xa, xb) = (a.positions(0), b.positions(0));
        xa.iter()
            .zip(&xb)
            .map(|(p, q)| (p - q).abs())
            .fold(0.0, f64::max)
    };
    let dented = apart(&w, &twin);
    assert!(dented > 2e-3, "{dented}");
    ok(unsafe { ts_world_remove_tool(w.0, probe) });
    assert_eq!(w.tool_count(), 0);
    w.step(1000);
    twin.step(1000);
    let left = apart(&w, &twin);
    assert!(
        left < 0.5 * dented,
        "{left} m from the twin after release, {dented} m pressed"
    );
    // The id is stale for every tool call; a new tool gets a new id.
    let mut wr = ts_wrench::default();
    let mut p = pose(0.0, 0.0, 0.0);
    let mut o = std::mem::MaybeUninit::uninit();
    let mut c = 0;
    let sts = unsafe {
        [
            ts_world_remove_tool(w.0, probe),
            ts_tool_set_pose(w.0, probe, &p),
            ts_tool_get_pose(w.0, probe, &mut p),
            ts_tool_wrench(w.0, probe, &mut wr),
            ts_tool_contact_count(w.0, probe, &mut c),
            ts_tool_set_friction(w.0, probe, 0.5, 0.3),
            ts_tool_get_options(w.0, probe, o.as_mut_ptr()),
        ]
    };
    for st in sts {
        expect(st, S::UnknownTool, &probe.to_string());
    }
    assert_eq!(
        unsafe { ts_world_remove_tool(null_mut(), 0) },
        S::NullParameter
    );
    // A state saved with the tool does not restore into the world without it.
    let st = unsafe { ts_world_restore_state(w.0, state.as_ptr(), state.len()) };
    assert_eq!(st, S::BadState);
    let mut again = u32::MAX;
    ok(unsafe {
        ts_world_add_tool_sphere(
            w.0,
            0.01,
            &pose(BELOW[0], BELOW[1], BELOW[2]),
            null(),
            &mut again,
        )
    });
    assert_eq!(again, probe + 1, "ids are not reused");
    assert_eq!(w.tool_count(), 1);
    w.drive(again, BELOW, PRESSED, 40, 20);
    assert!(w.wrench(again).force[1] < -0.01);
}

/// The 8 corners of a box of half-extents `e` (m).
fn corners(e: [f64; 3]) -> Vec<f64> {
    let mut v = Vec::new();
    for k in 0..8 {
        for (a, ea) in e.iter().enumerate() {
            v.push(if k >> a & 1 == 1 { *ea } else { -ea });
        }
    }
    v
}

#[test]
fn a_convex_hull_of_box_corners_touches_like_the_box() {
    let e = [0.012, 0.008, 0.01];
    let run = |hull: bool| {
        let w = hanging_cube();
        let start = pose(0.0, -SIZE / 2.0 - e[1] - 0.001, 0.0);
        let mut t = u32::MAX;
        if hull {
            let pts = corners(e);
            ok(unsafe {
                ts_world_add_tool_convex_hull(w.0, pts.as_ptr(), 8, &start, null(), &mut t)
            });
        } else {
            ok(unsafe { ts_world_add_tool_box(w.0, e.as_ptr(), &start, null(), &mut t) });
        }
        let from = start.position;
        w.drive(t, from, [0.002, from[1] + 0.005, 0.001], 40, 10);
        (w.wrench(t), w.positions(0))
    };
    let (wb, xb) = run(false);
    let (wh, xh) = run(true);
    assert!(wb.contact_count > 0 && wb.force[1] < -0.01, "{wb:?}");
    assert_eq!(wb.contact_count, wh.contact_count);
    for a in 0..3 {
        assert!(
            (wb.force[a] - wh.force[a]).abs() < 1e-6 * wb.force[1].abs(),
            "{wb:?} {wh:?}"
        );
    }
    let dx = xb
        .iter()
        .zip(&xh)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(dx < 1e-9, "positions differ by {dx} m");
}

#[test]
fn convex_hull_and_triangle_tools_are_validated() {
    let w = hanging_cube();
    let p = pose(0.5, 0.5, 0.5);
    let mut t = 77;
    let cube = corners([0.01; 3]);
    let flat = [
        0.0, 0.0, 0.0, 0.01, 0.0, 0.0, 0.0, 0.01, 0.0, 0.01, 0.01, 0.0,
    ];
    let tetra = [
        0.0, 0.0, 0.0, 0.01, 0.0, 0.0, 0.0, 0.01, 0.0, 0.0, 0.0, 0.01,
    ];
    let mut nan = cube.clone();
    nan[10] = f64::NAN;
    let cases: [(&[f64], usize, ts_status, &str); 5] = [
        (&cube, 3, S::InvalidArgument, "at least 4"),
        (&flat, 4, S::InvalidArgument, "plane"),
        (&tetra, 4, S::Ok, ""),
        (&nan, 8, S::NonFinite, "points[3]"),
        (&cube, 8, S::Ok, ""),
    ];
    for (pts, n, want, needle) in cases {
        let st = unsafe { ts_world_add_tool_convex_hull(w.0, pts.as_ptr(), n, &p, null(), &mut t) };
        if want == S::Ok {
            assert_eq!(st, S::Ok, "{}", last_error());
        } else {
            expect(st, want, needle);
        }
    }
    assert_eq!(w.tool_count(), 2);
    let st = unsafe { ts_world_add_tool_convex_hull(w.0, null(), 8, &p, null(), &mut t) };
    assert_eq!(st, S::NullParameter);
    // Triangle meshes from arrays: a tetrahedron.
    let v = [
        0.0, 0.0, 0.0, 0.01, 0.0, 0.0, 0.0, 0.01, 0.0, 0.0, 0.0, 0.01,
    ];
    let tri = [0u32, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3];
    let bad = [0u32, 2, 1, 0, 1, 4];
    ok(unsafe { ts_world_add_tool_mesh(w.0, v.as_ptr(), 4, tri.as_ptr(), 4, &p, null(), &mut t) });
    assert_eq!(t, 2);
    let sts = unsafe {
        [
            ts_world_add_tool_mesh(w.0, v.as_ptr(), 4, bad.as_ptr(), 2, &p, null(), &mut t),
            ts_world_add_tool_mesh(w.0, v.as_ptr(), 4, tri.as_ptr(), 0, &p, null(), &mut t),
            ts_world_add_tool_mesh(w.0, null(), 4, tri.as_ptr(), 4, &p, null(), &mut t),
            ts_world_add_tool_mesh(w.0, v.as_ptr(), 4, null(), 4, &p, null(), &mut t),
            ts_world_add_tool_mesh(w.0, v.as_ptr(), 4, tri.as_ptr(), 4, null(), null(), &mut t),
            ts_world_add_tool_mesh(w.0, v.as_ptr(), 4, tri.as_ptr(), 4, &p, null(), null_mut()),
        ]
    };
    let expected = [
        S::InvalidArgument,
        S::InvalidArgument,
        S::NullParameter,
        S::NullParameter,
        S::NullParameter,
        S::NullParameter,
    ];
    assert_eq!(sts, expected);
    assert_eq!((t, w.tool_count()), (2, 3));
}

/// The lateral force (N, along x) on a flat 2 × 2 cm pad pressed into the bottom face of the
/// hanging cube and dragged 3 mm sideways, with tool friction (mu_s, mu_k). Flat on a flat face,
/// the pad meets no sloped surface, so without friction there is next to no drag.
fn drag_force(friction: Option<(f64, f64)>) -> f64 {
    let w = hanging_cube();
    let mut t = u32::MAX;
    let half = [0.01, 0.005, 0.01];
    let below = [BELOW[0], BELOW[1] + 0.005, BELOW[2]];
    let pressed = [PRESSED[0], PRESSED[1] + 0.005, PRESSED[2]];
    ok(unsafe {
        ts_world_add_tool_box(
            w.0,
            half.as_ptr(),
            &pose(below[0], below[1], below[2]),
            null(),
            &mut t,
        )
    });
    if let Some((s, k)) = friction {
        ok(unsafe { ts_tool_set_friction(w.0, t, s, k) });
        let mut o = std::mem::MaybeUninit::uninit();
        ok(unsafe { ts_tool_get_options(w.0, t, o.as_mut_ptr()) });
        let o = unsafe { o.assume_init() };
        assert_eq!((o.friction_static, o.friction_kinetic), (s, k));
    }
    w.drive(t, below, pressed, 40, 10);
    let side = [pressed[0] + 0.003, pressed[1], pressed[2]];
    w.drive(t, pressed, side, 30, 0);
    w.wrench(t).force[0]
}

#[test]
fn tool_friction_drags_the_tissue() {
    let smooth = drag_force(None);
    let rough = drag_force(Some((1.0, 0.8)));
    // Friction adds a force against the drag (along -x on the tool) of more than 0.1 N.
    assert!(
        rough < smooth - 0.1,
        "{rough} N with friction, {smooth} N without"
    );
    let w = hanging_cube();
    let mut t = 0;
    ok(unsafe { ts_world_add_tool_sphere(w.0, 0.01, &pose(0.5, 0.5, 0.5), null(), &mut t) });
    let sts = unsafe {
        [
            ts_tool_set_friction(w.0, t, 0.2, 0.5),
            ts_tool_set_friction(w.0, t, -0.1, 0.0),
            ts_tool_set_friction(w.0, t, f64::NAN, 0.0),
            ts_tool_set_friction(w.0, t, 0.5, f64::INFINITY),
            ts_tool_set_friction(w.0, 9, 0.5, 0.3),
            ts_tool_set_friction(null_mut(), t, 0.5, 0.3),
            ts_tool_get_options(w.0, t, null_mut()),
        ]
    };
    let expected = [
        S::InvalidArgument,
        S::InvalidArgument,
        S::NonFinite,
        S::NonFinite,
        S::UnknownTool,
        S::NullParameter,
        S::NullParameter,
    ];
    assert_eq!(sts, expected);
    let mut o = std::mem::MaybeUninit::uninit();
    ok(unsafe { ts_tool_get_options(w.0, t, o.as_mut_ptr()) });
    let o = unsafe { o.assume_init() };
    assert_eq!(
        (o.friction_static, o.friction_kinetic),
        (0.0, 0.0),
        "unchanged"
    );
}

/// How far (m, along x) a free cube launched at 0.3 m/s along x slides over a fixed one in
/// 150 steps, with pair friction (mu_s, mu_k).
fn slide(friction: Option<(f64, f64)>) -> f64 {
    let mut s = settings();
    s.damping_mass = 0.0;
    let w = W::new(&s);
    let r = 0.004;
    let floor = w.add_cube([-SIZE / 2.0, -SIZE, -SIZE / 2.0], r);
    let block = w.add_cube([-SIZE / 2.0, 1.9 * r, -SIZE / 2.0], r);
    assert_eq!(w.fix_box(floor, [-1.0; 3], [1.0; 3]), 64);
    if let Some((ms, mk)) = friction {
        ok(unsafe { ts_world_set_body_pair_friction(w.0, block, floor, ms, mk) });
    }
    let x = w.positions(block);
    let v: Vec<f64> = (0..x.len())
        .map(|k| if k % 3 == 0 { 0.3 } else { 0.0 })
        .collect();
    ok(unsafe { ts_body_set_state(w.0, block, x.as_ptr(), x.len(), v.as_ptr(), v.len()) });
    w.step(150);
    let after = w.positions(block);
    let n = after.len() / 3;
    (0..n).map(|i| after[3 * i] - x[3 * i]).sum::<f64>() / n as f64
}

#[test]
fn body_pair_friction_slows_sliding() {
    let free = slide(None);
    let rough = slide(Some((0.8, 0.6)));
    assert!(
        free > 0.035,
        "frictionless: slid {free} m (launched for 0.045 m)"
    );
    assert!(
        rough < 0.7 * free,
        "with friction slid {rough} m, without {free} m"
    );
    let w = hanging_cube();
    let b = w.add_cube([0.2, 0.0, 0.0], 0.0);
    let sts = unsafe {
        [
            ts_world_set_body_pair_friction(w.0, 0, b, 0.3, 0.2),
            ts_world_set_body_pair_friction(w.0, b, b, 0.3, 0.2),
            ts_world_set_body_pair_friction(w.0, 0, 5, 0.3, 0.2),
            ts_world_set_body_pair_friction(w.0, 5, 0, 0.3, 0.2),
            ts_world_set_body_pair_friction(w.0, 0, b, 0.1, 0.2),
            ts_world_set_body_pair_friction(w.0, 0, b, f64::NAN, 0.2),
            ts_world_set_body_pair_friction(null_mut(), 0, b, 0.3, 0.2),
        ]
    };
    let expected = [
        S::Ok,
        S::Ok,
        S::UnknownBody,
        S::UnknownBody,
        S::InvalidArgument,
        S::NonFinite,
        S::NullParameter,
    ];
    assert_eq!(sts, expected);
}

/// A capsule of half-height 0 is legal in both APIs and is a sphere.
#[test]
fn a_capsule_of_half_height_zero_is_a_sphere() {
    let shape = ToolShape::Capsule {
        half_height: 0.0,
        radius: 0.01,
    };
    assert_eq!(shape.validate(), Ok(()));
    let mut world = tissuesim::World::new(tissuesim::Settings::default()).unwrap();
    let at = Pose::at(Vec3::new(0.1, 0.0, 0.0));
    let capsule = world.add_tool(shape, at, &ToolOptions::default()).unwrap();
    let sphere = world
        .add_tool(
            ToolShape::Sphere { radius: 0.01 },
            at,
            &ToolOptions::default(),
        )
        .unwrap();
    for q in [
        Vec3::new(0.1, 0.02, 0.0),
        Vec3::new(0.103, 0.0, 0.001),
        Vec3::new(0.09, -0.005, 0.004),
    ] {
        let dc = world.tool(capsule).unwrap().signed_distance(&at, &q);
        let ds = world.tool(sphere).unwrap().signed_distance(&at, &q);
        assert!((dc - ds).abs() < 1e-15, "{dc} vs {ds}");
    }
    // From C: same contact as the sphere.
    let press = |capsule: bool| {
        let w = hanging_cube();
        let mut t = 0;
        let p = pose(BELOW[0], BELOW[1], BELOW[2]);
        ok(unsafe {
            if capsule {
                ts_world_add_tool_capsule(w.0, 0.0, 0.01, &p, null(), &mut t)
            } else {
                ts_world_add_tool_sphere(w.0, 0.01, &p, null(), &mut t)
            }
        });
        w.drive(t, BELOW, PRESSED, 30, 5);
        w.wrench(t)
    };
    let (c, s) = (press(true), press(false));
    assert!(
        c.force[1] < -0.01 && c.contact_count == s.contact_count,
        "{c:?} {s:?}"
    );
    for a in 0..3 {
        assert!((c.force[a] - s.force[a]).abs() < 1e-9, "{c:?} {s:?}");
    }
    // Negative half-heights stay invalid; cylinders need a positive one.
    let w = hanging_cube();
    let p = pose(0.5, 0.5, 0.5);
    let mut t = 0;
    expect(
        unsafe { ts_world_add_tool_capsule(w.0, -1e-3, 0.01, &p, null(), &mut t) },
        S::InvalidArgument,
        "half_height",
    );
    expect(
        unsafe { ts_world_add_tool_cylinder(w.0, 0.0, 0.01, &p, null(), &mut t) },
        S::InvalidArgument,
        "half_height",
    );
}

/// The C functions reject exactly what the core validators reject, with the core's message.
#[test]
fn c_and_rust_share_one_validation() {
    let w = hanging_cube();
    let p = pose(0.5, 0.5, 0.5);
    let shapes: Vec<(ToolShape, ts_status, String)> = [
        (0.01, 0.0),
        (0.0, 0.01),
        (-0.01, 0.01),
        (0.01, -0.02),
        (f64::NAN, 0.01),
        (0.01, f64::INFINITY),
    ]
    .into_iter()
    .map(|(h, r)| {
        let mut t = 0;
        let st = unsafe { ts_world_add_tool_capsule(w.0, h, r, &p, null(), &mut t) };
        let shape = ToolShape::Capsule {
            half_height: h,
            radius: r,
        };
        (shape, st, last_error())
    })
    .collect();
    for (shape, st, msg) in shapes {
        match shape.validate() {
            Ok(()) => assert_eq!(st, S::Ok, "{shape:?}"),
            Err(e) => {
                assert_eq!(st, status_of(&e), "{shape:?}");
                assert_eq!(msg, e.to_string(), "{shape:?}");
            }
        }
    }
    let mut s = settings();
    s.stability_margin = f64::NAN;
    let mut nw = null_mut();
    let st = unsafe { ts_world_new(&s, &mut nw) };
    let rust = tissuesim::Settings {
        stability_margin: f64::NAN,
        ..tissuesim::Settings::default()
    }
    .validate()
    .unwrap_err();
    assert_eq!((st, last_error()), (status_of(&rust), rust.to_string()));
    let m = ts_material {
        poisson_ratio: 0.5,
        ..material()
    };
    let mut b = 0;
    let st = unsafe { ts_world_add_default_organ(w.0, &m, null(), &mut b) };
    let rust = tissuesim::Material {
        poisson_ratio: 0.5,
        ..tissuesim::Material::default()
    }
    .validate()
    .unwrap_err();
    assert_eq!((st, last_error()), (status_of(&rust), rust.to_string()));
    let zero = ts_pose {
        position: [0.0; 3],
        orientation: [1e-13, 0.0, 0.0, 0.0],
    };
    let st = unsafe { ts_tool_set_pose(w.0, 0, &zero) };
    let rust = Pose::from_components([0.0; 3], [1e-13, 0.0, 0.0, 0.0]).unwrap_err();
    assert_eq!(status_of(&rust), S::InvalidArgument);
    assert_eq!((st, last_error()), (status_of(&rust), rust.to_string()));
    let mut t = 0;
    let st = unsafe { ts_world_add_tool_sphere(w.0, 0.01, &zero, null(), &mut t) };
    assert_eq!((st, last_error()), (status_of(&rust), rust.to_string()));
}

/// `ts_world_add_body_shared` puts the same body into another world (or the same one) without
/// a mesh: same particles, same source indices, and bit-identical motion; bad handles and ids
/// are refused with their status.
#[test]
fn a_body_shared_from_another_world_moves_alike() {
    let a = hanging_cube();
    let b = W::new(&settings());
    let mut id = u32::MAX;
    ok(unsafe { ts_world_add_body_shared(b.0, a.0, 0, &mut id) });
    assert_eq!(id, 0);
    assert_eq!(b.particles(0), a.particles(0));
    let source = |w: &W| {
        let mut v = vec![u32::MAX; w.particles(0)];
        ok(unsafe { ts_body_source_indices(w.0, 0, v.as_mut_ptr(), v.len()) });
        v
    };
    assert_eq!(source(&b), source(&a));
    // The shared body is at rest and unfixed: fix the same face, then both hang alike.
    assert_eq!(b.fix_box(0, [-1.0, SIZE / 2.0 - 1e-6, -1.0], [1.0; 3]), 16);
    let rest = a.positions(0);
    a.step(30);
    b.step(30);
    assert_ne!(a.positions(0), rest, "the cube hangs");
    assert_eq!(a.positions(0), b.positions(0));
    // Into the same world: a second body on the same model.
    ok(unsafe { ts_world_add_body_shared(a.0, a.0, 0, &mut id) });
    assert_eq!((id, a.particles(1)), (1, a.particles(0)));
    expect(
        unsafe { ts_world_add_body_shared(b.0, a.0, 7, &mut id) },
        S::UnknownBody,
        "body id 7",
    );
    expect(
        unsafe { ts_world_add_body_shared(b.0, null(), 0, &mut id) },
        S::NullParameter,
        "world",
    );
    expect(
        unsafe { ts_world_add_body_shared(b.0, a.0, 0, null_mut()) },
        S::NullParameter,
        "out_body",
    );
    let mut count = 0;
    ok(unsafe { ts_world_body_count(b.0, &mut count) });
    assert_eq!(count, 1, "a refused call added nothing");
}

/// The C ABI speaks the mesh's node order, whatever order the solver keeps its particles in:
/// rest positions, tetrahedra and boundary triangles read back as given; fixing particle `k`
/// holds node `k`; a state set per node reads back per node.
#[test]
fn the_c_abi_reads_and_writes_in_the_mesh_node_order() {
    let w = W::new(&settings());
    let id = w.add_cube([-SIZE / 2.0; 3], 0.0);
    let m = mesh::lattice_box(
        Vec3::repeat(-SIZE / 2.0),
        Vec3::repeat(SIZE / 2.0),
        [3, 3, 3],
    );
    let n = m.nodes.len();
    // The solver's order (a function of the nodes alone) differs from the lattice's: the
    // mapping below is exercised.
    let model = tissuesim::BodyModel::new(&m, &tissuesim::BodyOptions::default()).unwrap();
    let order = model.particle_order();
    assert!((0..n).any(|i| order.mesh_index(i) != i), "identity order");
    let flat = |v: &[Vec3]| v.iter().flat_map(|p| [p.x, p.y, p.z]).collect::<Vec<f64>>();
    let mut rest = vec![0.0; 3 * n];
    ok(unsafe { ts_body_rest_positions(w.0, id, rest.as_mut_ptr(), rest.len()) });
    assert_eq!(rest, flat(&m.nodes));
    assert_eq!(w.positions(id), flat(&m.nodes));
    let mut tets = vec![0; 4 * m.tets.len()];
    ok(unsafe { ts_body_tets(w.0, id, tets.as_mut_ptr(), tets.len()) });
    assert_eq!(tets, m.tets.iter().flatten().copied().collect::<Vec<u32>>());
    let boundary = m.boundary_triangles();
    let mut tris = vec![0; 3 * boundary.len()];
    ok(unsafe { ts_body_boundary_triangles(w.0, id, tris.as_mut_ptr(), tris.len()) });
    assert_eq!(
        tris,
        boundary.iter().flatten().copied().collect::<Vec<u32>>()
    );
    // Fix the top face's nodes by index and a node of the bottom face: they stay put.
    let bottom = (0..n).find(|&k| m.nodes[k].y < -SIZE / 2.0 + 1e-9).unwrap();
    let mut fixed: Vec<u32> = (0..n as u32)
        .filter(|&k| m.nodes[k as usize].y > SIZE / 2.0 - 1e-9)
        .collect();
    fixed.push(bottom as u32);
    ok(unsafe { ts_body_fix_particles(w.0, id, fixed.as_ptr(), fixed.len()) });
    let mut flags = vec![9u8; n];
    ok(unsafe { ts_body_fixed_flags(w.0, id, flags.as_mut_ptr(), flags.len()) });
    for (k, f) in flags.iter().enumerate() {
        assert_eq!(*f == 1, fixed.contains(&(k as u32)), "node {k}");
    }
    w.step(20);
    let x = w.positions(id);
    for k in 0..n {
        let moved = (0..3).any(|c| x[3 * k + c] != m.nodes[k][c]);
        assert_eq!(moved, !fixed.contains(&(k as u32)), "node {k}");
    }
    // A state given per node reads back per node.
    let shifted: Vec<f64> = (0..n)
        .flat_map(|k| [m.nodes[k].x + 1e-5 * k as f64, m.nodes[k].y, m.nodes[k].z])
        .collect();
    let speeds: Vec<f64> = (0..n).flat_map(|k| [0.0, 1e-3 * k as f64, 0.0]).collect();
    ok(unsafe {
        ts_body_set_state(
            w.0,
            id,
            shifted.as_ptr(),
            shifted.len(),
            speeds.as_ptr(),
            speeds.len(),
        )
    });
    assert_eq!(w.positions(id), shifted);
    let v = w.velocities(id);
    for k in 0..n {
        let expected = if fixed.contains(&(k as u32)) {
            0.0
        } else {
            1e-3 * k as f64
        };
        assert_eq!(v[3 * k + 1], expected, "node {k}");
    }
}
