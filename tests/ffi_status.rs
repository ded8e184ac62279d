//! Every status path of the C API, exercised from Rust through the `extern "C"` functions:
//! NULL pointers, unknown ids, wrong sizes, NaN/Inf inputs (world unchanged), short buffers
//! (nothing written), mesh errors (message names the file), bad states (world unchanged),
//! `_free(NULL)`, status strings and the last error message.

use std::ffi::{c_char, CStr, CString};
use std::ptr::{null, null_mut};
use tissuesim::ffi::body::*;
use tissuesim::ffi::error::*;
use tissuesim::ffi::state::*;
use tissuesim::ffi::status::*;
use tissuesim::ffi::tool::*;
use tissuesim::ffi::world::*;

use ts_status as S;

const CELLS: usize = 3;
const SIZE: f64 = 0.06;

/// A cube lattice of SIZE m with CELLS cells per axis, six tets per cell (Kuhn subdivision),
/// centred on the origin: (nodes as xyz, tets as 4 indices each).
fn lattice() -> (Vec<f64>, Vec<u32>) {
    let n = CELLS + 1;
    let h = SIZE / CELLS as f64;
    let mut nodes = Vec::new();
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                nodes.extend([
                    i as f64 * h - SIZE / 2.0,
                    j as f64 * h - SIZE / 2.0,
                    k as f64 * h - SIZE / 2.0,
                ]);
            }
        }
    }
    let id = |i: usize, j: usize, k: usize| (i + n * (j + n * k)) as u32;
    let mut tets = Vec::new();
    for k in 0..CELLS {
        for j in 0..CELLS {
            for i in 0..CELLS {
                let corner = |d: [usize; 3]| id(i + d[0], j + d[1], k + d[2]);
                for perm in [
                    [0, 1, 2],
                    [0, 2, 1],
                    [1, 0, 2],
                    [1, 2, 0],
                    [2, 0, 1],
                    [2, 1, 0],
                ] {
                    let mut d = [0usize; 3];
                    let mut t = [corner(d); 4];
                    for (s, &axis) in perm.iter().enumerate() {
                        d[axis] = 1;
                        t[s + 1] = corner(d);
                    }
                    tets.extend(t);
                }
            }
        }
    }
    (nodes, tets)
}

fn settings() -> ts_settings {
    let mut s = std::mem::MaybeUninit::uninit();
    assert_eq!(unsafe { ts_settings_default(s.as_mut_ptr()) }, S::Ok);
    unsafe { s.assume_init() }
}

fn material() -> ts_material {
    let mut m = std::mem::MaybeUninit::uninit();
    assert_eq!(unsafe { ts_material_default(m.as_mut_ptr()) }, S::Ok);
    unsafe { m.assume_init() }
}

fn pose(x: f64, y: f64, z: f64) -> ts_pose {
    ts_pose {
        position: [x, y, z],
        orientation: [1.0, 0.0, 0.0, 0.0],
    }
}

/// A world holding the lattice (body 0, top face fixed) and a probe sphere above it (tool 0).
struct Scene {
    w: *mut ts_world,
}

impl Scene {
    fn new() -> Scene {
        let mut w = null_mut();
        assert_eq!(unsafe { ts_world_new(&settings(), &mut w) }, S::Ok);
        let (nodes, tets) = lattice();
        let mut body = u32::MAX;
        let st = unsafe {
            ts_world_add_body_from_arrays(
                w,
                nodes.as_ptr(),
                nodes.len() / 3,
                tets.as_ptr(),
                tets.len() / 4,
                &material(),
                null(),
                &mut body,
            )
        };
        assert_eq!(st, S::Ok, "{}", last_error());
        assert_eq!(body, 0);
        let (lo, hi) = ([-1.0, SIZE / 2.0 - 1e-6, -1.0], [1.0, 1.0, 1.0]);
        let mut fixed = 0usize;
        assert_eq!(
            unsafe { ts_body_fix_box(w, 0, lo.as_ptr(), hi.as_ptr(), &mut fixed) },
            S::Ok
        );
        assert_eq!(fixed, (CELLS + 1) * (CELLS + 1));
        let mut tool = u32::MAX;
        let p = pose(0.0, -SIZE / 2.0 - 0.011, 0.0);
        assert_eq!(
            unsafe { ts_world_add_tool_sphere(w, 0.01, &p, null(), &mut tool) },
            S::Ok
        );
        assert_eq!(tool, 0);
        Scene { w }
    }

    fn particles(&self) -> usize {
        let mut n = 0;
        assert_eq!(unsafe { ts_body_particle_count(self.w, 0, &mut n) }, S::Ok);
        n
    }

    fn positions(&self) -> Vec<f64> {
        let mut v = vec![0.0; 3 * self.particles()];
        assert_eq!(
            unsafe { ts_body_positions(self.w, 0, v.as_mut_ptr(), v.len()) },
            S::Ok
        );
        v
    }

    fn velocities(&self) -> Vec<f64> {
        let mut v = vec![0.0; 3 * self.particles()];
        assert_eq!(
            unsafe { ts_body_velocities(self.w, 0, v.as_mut_ptr(), v.len()) },
            S::Ok
        );
        v
    }

    fn volume(&self) -> f64 {
        let mut v = 0.0;
        assert_eq!(unsafe { ts_body_volume(self.w, 0, &mut v) }, S::Ok);
        v
    }

    fn tool_pose(&self) -> ts_pose {
        let mut p = pose(0.0, 0.0, 0.0);
        assert_eq!(unsafe { ts_tool_get_pose(self.w, 0, &mut p) }, S::Ok);
        p
    }

    fn time(&self) -> f64 {
        let mut t = -1.0;
        assert_eq!(unsafe { ts_world_time(self.w, &mut t) }, S::Ok);
        t
    }

    /// Everything observable that a failed call must leave alone, as bits.
    fn snapshot(&self) -> Vec<u64> {
        let mut s: Vec<u64> = self.positions().iter().map(|x| x.to_bits()).collect();
        s.extend(self.velocities().iter().map(|x| x.to_bits()));
        s.push(self.volume().to_bits());
        s.push(self.time().to_bits());
        let p = self.tool_pose();
        s.extend(p.position.iter().chain(&p.orientation).map(|x| x.to_bits()));
        let mut st = settings();
        assert_eq!(unsafe { ts_world_get_settings(self.w, &mut st) }, S::Ok);
        s.push(st.dt.to_bits());
        s.extend(st.gravity.iter().map(|x| x.to_bits()));
        s
    }

    fn step(&self, n: usize) {
        for _ in 0..n {
            let st = unsafe { ts_world_step(self.w, null_mut()) };
            assert_eq!(st, S::Ok, "{}", last_error());
        }
    }
}

impl Drop for Scene {
    fn drop(&mut self) {
        unsafe { ts_world_free(self.w) };
    }
}

fn last_error() -> String {
    let n = unsafe { ts_last_error_message(null_mut(), 0) };
    let mut buf = vec![0 as c_char; n + 1];
    let m = unsafe { ts_last_error_message(buf.as_mut_ptr(), buf.len()) };
    assert_eq!(m, n);
    unsafe { CStr::from_ptr(buf.as_ptr()) }
        .to_string_lossy()
        .into_owned()
}

/// `status` is `expected` and the last error message mentions `needle`.
#[track_caller]
fn expect(status: ts_status, expected: ts_status, needle: &str) {
    let msg = last_error();
    assert_eq!(status, expected, "last error: {msg}");
    assert!(
        msg.contains(needle),
        "last error {msg:?} should mention {needle:?}"
    );
}

#[test]
fn free_null_is_a_no_op() {
    unsafe { ts_world_free(null_mut()) };
}

#[test]
fn status_strings_are_static_and_named() {
    for code in 0..=12 {
        let s = unsafe { CStr::from_ptr(ts_status_string(code)) }
            .to_str()
            .unwrap();
        assert!(s.starts_with("TS_STATUS_"), "{code}: {s}");
    }
    let ok = unsafe { CStr::from_ptr(ts_status_string(S::Ok as i32)) };
    assert!(ok.to_str().unwrap().starts_with("TS_STATUS_OK"));
    let np = unsafe { CStr::from_ptr(ts_status_string(S::NullParameter as i32)) };
    assert!(np.to_str().unwrap().starts_with("TS_STATUS_NULL_PARAMETER"));
    for bad in [-1, 14, 9999, i32::MIN, i32::MAX] {
        let s = unsafe { CStr::from_ptr(ts_status_string(bad)) };
        assert_eq!(s.to_str().unwrap(), "unknown ts_status value");
    }
}

#[test]
fn status_numbers_are_stable() {
    let expected = [
        (S::Ok, 0),
        (S::NullParameter, 1),
        (S::InvalidArgument, 2),
        (S::NonFinite, 3),
        (S::UnknownBody, 4),
        (S::UnknownTool, 5),
        (S::BufferTooSmall, 6),
        (S::MeshError, 7),
        (S::BadState, 8),
        (S::Diverged, 9),
        (S::IoError, 10),
        (S::Panic, 11),
        (S::Poisoned, 12),
        (S::UnknownRenderSurface, 13),
    ];
    for (s, n) in expected {
        assert_eq!(s as i32, n, "{s:?}");
    }
}

#[test]
fn last_error_message_truncates_and_reports_full_length() {
    let st = unsafe { ts_world_new(null(), null_mut()) };
    assert_eq!(st, S::NullParameter);
    let full = last_error();
    assert!(full.contains("settings"), "{full}");
    let n = full.len();
    assert_eq!(unsafe { ts_last_error_message(null_mut(), 0) }, n);
    assert_eq!(unsafe { ts_last_error_message(null_mut(), 100) }, n);
    // A buffer of 5 gets 4 bytes and a NUL; the bytes after are untouched.
    let mut buf = [b'#' as c_char; 8];
    assert_eq!(unsafe { ts_last_error_message(buf.as_mut_ptr(), 5) }, n);
    let got = unsafe { CStr::from_ptr(buf.as_ptr()) }.to_bytes();
    assert_eq!(got, &full.as_bytes()[..4]);
    assert_eq!(buf[5], b'#' as c_char);
    // A buffer of 1 gets just the NUL.
    let mut one = [b'#' as c_char; 2];
    assert_eq!(unsafe { ts_last_error_message(one.as_mut_ptr(), 1) }, n);
    assert_eq!(one, [0, b'#' as c_char]);
    // len 0 writes nothing.
    let mut zero = [b'#' as c_char; 1];
    assert_eq!(unsafe { ts_last_error_message(zero.as_mut_ptr(), 0) }, n);
    assert_eq!(zero[0], b'#' as c_char);
    // Cleared: empty string.
    ts_last_error_clear();
    assert_eq!(unsafe { ts_last_error_message(null_mut(), 0) }, 0);
    assert_eq!(last_error(), "");
}

#[test]
fn last_error_is_per_thread() {
    assert_eq!(unsafe { ts_settings_default(null_mut()) }, S::NullParameter);
    let here = last_error();
    let there = std::thread::spawn(|| {
        let empty = last_error();
        assert_eq!(unsafe { ts_material_default(null_mut()) }, S::NullParameter);
        (empty, last_error())
    })
    .join()
    .unwrap();
    assert_eq!(there.0, "");
    assert!(!there.1.is_empty());
    assert_eq!(last_error(), here);
}

#[test]
fn null_parameters() {
    let sc = Scene::new();
    let w = sc.w;
    let s = settings();
    let m = material();
    let p = pose(0.0, 1.0, 0.0);
    let mut out_w = null_mut();
    let mut u = 0u32;
    let mut z = 0usize;
    let mut d = 0.0f64;
    let mut buf = vec![0.0f64; 3 * sc.particles()];
    let mut ibuf = vec![0u32; 100_000];
    let mut bytes = vec![0u8; 1 << 20];
    let (nodes, tets) = lattice();
    let path = CString::new("/nonexistent.msh").unwrap();
    let three = [0.01; 3];
    let idx = [0u32];
    let nw: *mut ts_world = null_mut();
    let nc: *const ts_world = null();
    let before = sc.snapshot();

    let cases: Vec<(&str, ts_status)> = unsafe {
        vec![
            ("settings_default", ts_settings_default(null_mut())),
            ("material_default", ts_material_default(null_mut())),
            ("body_options_default", ts_body_options_default(null_mut())),
            ("tool_options_default", ts_tool_options_default(null_mut())),
            ("world_new settings", ts_world_new(null(), &mut out_w)),
            ("world_new out", ts_world_new(&s, null_mut())),
            (
                "get_settings world",
                ts_world_get_settings(nc, &mut s.clone()),
            ),
            ("get_settings out", ts_world_get_settings(w, null_mut())),
            ("set_settings world", ts_world_set_settings(nw, &s)),
            ("set_settings settings", ts_world_set_settings(w, null())),
            ("step world", ts_world_step(nw, null_mut())),
            ("time world", ts_world_time(nc, &mut d)),
            ("time out", ts_world_time(w, null_mut())),
            (
                "tool_jump_speed world",
                ts_world_tool_jump_speed(nc, &mut d),
            ),
            (
                "tool_jump_speed out",
                ts_world_tool_jump_speed(w, null_mut()),
            ),
            ("body_count world", ts_world_body_count(nc, &mut u)),
            ("body_count out", ts_world_body_count(w, null_mut())),
            ("tool_count world", ts_world_tool_count(nc, &mut u)),
            ("tool_count out", ts_world_tool_count(w, null_mut())),
            ("diverged world", ts_world_diverged_steps(nc, &mut 0)),
            ("diverged out", ts_world_diverged_steps(w, null_mut())),
            (
                "add_file world",
                ts_world_add_body_from_file(nw, path.as_ptr(), 1.0, &m, null(), &mut u),
            ),
            (
                "add_file path",
                ts_world_add_body_from_file(w, null(), 1.0, &m, null(), &mut u),
            ),
            (
                "add_file material",
                ts_world_add_body_from_file(w, path.as_ptr(), 1.0, null(), null(), &mut u),
            ),
            (
                "add_file out",
                ts_world_add_body_from_file(w, path.as_ptr(), 1.0, &m, null(), null_mut()),
            ),
            (
                "add_arrays world",
                ts_world_add_body_from_arrays(
                    nw,
                    nodes.as_ptr(),
                    nodes.len() / 3,
                    tets.as_ptr(),
                    tets.len() / 4,
                    &m,
                    null(),
                    &mut u,
                ),
            ),
            (
                "add_arrays nodes",
                ts_world_add_body_from_arrays(
                    w,
                    null(),
                    nodes.len() / 3,
                    tets.as_ptr(),
                    tets.len() / 4,
                    &m,
                    null(),
                    &mut u,
                ),
            ),
            (
                "add_arrays tets",
                ts_world_add_body_from_arrays(
                    w,
                    nodes.as_ptr(),
                    nodes.len() / 3,
                    null(),
                    tets.len() / 4,
                    &m,
                    null(),
                    &mut u,
                ),
            ),
            (
                "add_arrays material",
                ts_world_add_body_from_arrays(
                    w,
                    nodes.as_ptr(),
                    nodes.len() / 3,
                    tets.as_ptr(),
                    tets.len() / 4,
                    null(),
                    null(),
                    &mut u,
                ),
            ),
            (
                "add_arrays out",
                ts_world_add_body_from_arrays(
                    w,
                    nodes.as_ptr(),
                    nodes.len() / 3,
                    tets.as_ptr(),
                    tets.len() / 4,
                    &m,
                    null(),
                    null_mut(),
                ),
            ),
            (
                "organ world",
                ts_world_add_default_organ(nw, &m, null(), &mut u),
            ),
            (
                "organ material",
                ts_world_add_default_organ(w, null(), null(), &mut u),
            ),
            (
                "organ out",
                ts_world_add_default_organ(w, &m, null(), null_mut()),
            ),
            (
                "fix_particles world",
                ts_body_fix_particles(nw, 0, idx.as_ptr(), 1),
            ),
            (
                "fix_particles indices",
                ts_body_fix_particles(w, 0, null(), 1),
            ),
            (
                "fix_particles indices 0",
                ts_body_fix_particles(w, 0, null(), 0),
            ),
            (
                "fix_box world",
                ts_body_fix_box(nw, 0, three.as_ptr(), three.as_ptr(), null_mut()),
            ),
            (
                "fix_box min",
                ts_body_fix_box(w, 0, null(), three.as_ptr(), null_mut()),
            ),
            (
                "fix_box max",
                ts_body_fix_box(w, 0, three.as_ptr(), null(), null_mut()),
            ),
            (
                "particle_count world",
                ts_body_particle_count(nc, 0, &mut z),
            ),
            (
                "particle_count out",
                ts_body_particle_count(w, 0, null_mut()),
            ),
            (
                "positions world",
                ts_body_positions(nc, 0, buf.as_mut_ptr(), buf.len()),
            ),
            (
                "positions out",
                ts_body_positions(w, 0, null_mut(), buf.len()),
            ),
            (
                "velocities world",
                ts_body_velocities(nc, 0, buf.as_mut_ptr(), buf.len()),
            ),
            (
                "velocities out",
                ts_body_velocities(w, 0, null_mut(), buf.len()),
            ),
            (
                "rest world",
                ts_body_rest_positions(nc, 0, buf.as_mut_ptr(), buf.len()),
            ),
            (
                "rest out",
                ts_body_rest_positions(w, 0, null_mut(), buf.len()),
            ),
            (
                "source world",
                ts_body_source_indices(nc, 0, ibuf.as_mut_ptr(), ibuf.len()),
            ),
            (
                "source out",
                ts_body_source_indices(w, 0, null_mut(), ibuf.len()),
            ),
            (
                "btri_count world",
                ts_body_boundary_triangle_count(nc, 0, &mut z),
            ),
            (
                "btri_count out",
                ts_body_boundary_triangle_count(w, 0, null_mut()),
            ),
            (
                "btri world",
                ts_body_boundary_triangles(nc, 0, ibuf.as_mut_ptr(), ibuf.len()),
            ),
            (
                "btri out",
                ts_body_boundary_triangles(w, 0, null_mut(), ibuf.len()),
            ),
            ("tet_count world", ts_body_tet_count(nc, 0, &mut z)),
            ("tet_count out", ts_body_tet_count(w, 0, null_mut())),
            (
                "tets world",
                ts_body_tets(nc, 0, ibuf.as_mut_ptr(), ibuf.len()),
            ),
            ("tets out", ts_body_tets(w, 0, null_mut(), ibuf.len())),
            ("volume world", ts_body_volume(nc, 0, &mut d)),
            ("volume out", ts_body_volume(w, 0, null_mut())),
            ("rest_volume world", ts_body_rest_volume(nc, 0, &mut d)),
            ("rest_volume out", ts_body_rest_volume(w, 0, null_mut())),
            ("max_disp world", ts_body_max_displacement(nc, 0, &mut d)),
            ("max_disp out", ts_body_max_displacement(w, 0, null_mut())),
            ("mass world", ts_body_mass(nc, 0, &mut d)),
            ("mass out", ts_body_mass(w, 0, null_mut())),
            ("added_mass world", ts_body_added_mass(nc, 0, &mut d)),
            ("added_mass out", ts_body_added_mass(w, 0, null_mut())),
            (
                "sphere world",
                ts_world_add_tool_sphere(nw, 0.01, &p, null(), &mut u),
            ),
            (
                "sphere pose",
                ts_world_add_tool_sphere(w, 0.01, null(), null(), &mut u),
            ),
            (
                "sphere out",
                ts_world_add_tool_sphere(w, 0.01, &p, null(), null_mut()),
            ),
            (
                "capsule world",
                ts_world_add_tool_capsule(nw, 0.01, 0.01, &p, null(), &mut u),
            ),
            (
                "capsule pose",
                ts_world_add_tool_capsule(w, 0.01, 0.01, null(), null(), &mut u),
            ),
            (
                "capsule out",
                ts_world_add_tool_capsule(w, 0.01, 0.01, &p, null(), null_mut()),
            ),
            (
                "cylinder world",
                ts_world_add_tool_cylinder(nw, 0.01, 0.01, &p, null(), &mut u),
            ),
            (
                "cylinder pose",
                ts_world_add_tool_cylinder(w, 0.01, 0.01, null(), null(), &mut u),
            ),
            (
                "cylinder out",
                ts_world_add_tool_cylinder(w, 0.01, 0.01, &p, null(), null_mut()),
            ),
            (
                "box world",
                ts_world_add_tool_box(nw, three.as_ptr(), &p, null(), &mut u),
            ),
            (
                "box extents",
                ts_world_add_tool_box(w, null(), &p, null(), &mut u),
            ),
            (
                "box pose",
                ts_world_add_tool_box(w, three.as_ptr(), null(), null(), &mut u),
            ),
            (
                "box out",
                ts_world_add_tool_box(w, three.as_ptr(), &p, null(), null_mut()),
            ),
            (
                "mesh world",
                ts_world_add_tool_mesh_file(nw, path.as_ptr(), 1.0, &p, null(), &mut u),
            ),
            (
                "mesh path",
                ts_world_add_tool_mesh_file(w, null(), 1.0, &p, null(), &mut u),
            ),
            (
                "mesh pose",
                ts_world_add_tool_mesh_file(w, path.as_ptr(), 1.0, null(), null(), &mut u),
            ),
            (
                "mesh out",
                ts_world_add_tool_mesh_file(w, path.as_ptr(), 1.0, &p, null(), null_mut()),
            ),
            ("set_pose world", ts_tool_set_pose(nw, 0, &p)),
            ("set_pose pose", ts_tool_set_pose(w, 0, null())),
            ("get_pose world", ts_tool_get_pose(nc, 0, &mut p.clone())),
            ("get_pose out", ts_tool_get_pose(w, 0, null_mut())),
            (
                "wrench world",
                ts_tool_wrench(nc, 0, &mut ts_wrench::default()),
            ),
            ("wrench out", ts_tool_wrench(w, 0, null_mut())),
            ("contacts world", ts_tool_contact_count(nc, 0, &mut u)),
            ("contacts out", ts_tool_contact_count(w, 0, null_mut())),
            ("state_size world", ts_world_state_size(nc, &mut z)),
            ("state_size out", ts_world_state_size(w, null_mut())),
            (
                "save world",
                ts_world_save_state(nw, bytes.as_mut_ptr(), bytes.len(), null_mut()),
            ),
            (
                "save buf",
                ts_world_save_state(w, null_mut(), bytes.len(), null_mut()),
            ),
            (
                "restore world",
                ts_world_restore_state(nw, bytes.as_ptr(), 1),
            ),
            ("restore buf", ts_world_restore_state(w, null(), 0)),
        ]
    };
    for (name, st) in cases {
        assert_eq!(st, S::NullParameter, "{name}: {}", last_error());
    }
    assert!(out_w.is_null(), "no world made");
    assert_eq!(sc.snapshot(), before, "the world is unchanged");
    let mut n = 0;
    assert_eq!(unsafe { ts_world_body_count(w, &mut n) }, S::Ok);
    assert_eq!(n, 1);
    assert_eq!(unsafe { ts_world_tool_count(w, &mut n) }, S::Ok);
    assert_eq!(n, 1);
}

#[test]
fn optional_out_pointers_may_be_null() {
    let sc = Scene::new();
    assert_eq!(unsafe { ts_world_step(sc.w, null_mut()) }, S::Ok);
    let lo = [-1.0, -1.0, -1.0];
    let hi = [1.0, -SIZE / 2.0 + 1e-6, 1.0];
    assert_eq!(
        unsafe { ts_body_fix_box(sc.w, 0, lo.as_ptr(), hi.as_ptr(), null_mut()) },
        S::Ok
    );
    let mut size = 0;
    assert_eq!(unsafe { ts_world_state_size(sc.w, &mut size) }, S::Ok);
    let mut buf = vec![0u8; size];
    assert_eq!(
        unsafe { ts_world_save_state(sc.w, buf.as_mut_ptr(), size, null_mut()) },
        S::Ok
    );
    // Optional option structs: NULL means defaults.
    let mut t = 0;
    let p = pose(0.0, 0.5, 0.0);
    assert_eq!(
        unsafe { ts_world_add_tool_sphere(sc.w, 0.01, &p, null(), &mut t) },
        S::Ok
    );
    assert_eq!(t, 1);
}

#[test]
fn unknown_ids() {
    let sc = Scene::new();
    let w = sc.w;
    let before = sc.snapshot();
    let mut z = 0usize;
    let mut d = 0.0;
    let mut u = 0u32;
    let mut buf = vec![0.0; 3 * sc.particles()];
    let mut ibuf = vec![0u32; 100_000];
    let idx = [0u32];
    let (lo, hi) = ([-1.0; 3], [1.0; 3]);
    let p = pose(0.0, 0.0, 0.0);
    for bad in [1u32, 7, u32::MAX] {
        let bodies = unsafe {
            [
                ts_body_fix_particles(w, bad, idx.as_ptr(), 1),
                ts_body_fix_box(w, bad, lo.as_ptr(), hi.as_ptr(), &mut z),
                ts_body_particle_count(w, bad, &mut z),
                ts_body_positions(w, bad, buf.as_mut_ptr(), buf.len()),
                ts_body_velocities(w, bad, buf.as_mut_ptr(), buf.len()),
                ts_body_rest_positions(w, bad, buf.as_mut_ptr(), buf.len()),
                ts_body_source_indices(w, bad, ibuf.as_mut_ptr(), ibuf.len()),
                ts_body_boundary_triangle_count(w, bad, &mut z),
                ts_body_boundary_triangles(w, bad, ibuf.as_mut_ptr(), ibuf.len()),
                ts_body_tet_count(w, bad, &mut z),
                ts_body_tets(w, bad, ibuf.as_mut_ptr(), ibuf.len()),
                ts_body_volume(w, bad, &mut d),
                ts_body_rest_volume(w, bad, &mut d),
                ts_body_max_displacement(w, bad, &mut d),
                ts_body_mass(w, bad, &mut d),
                ts_body_added_mass(w, bad, &mut d),
            ]
        };
        for (i, st) in bodies.into_iter().enumerate() {
            expect(st, S::UnknownBody, &bad.to_string());
            assert_eq!(st, S::UnknownBody, "body call #{i}");
        }
        let tools = unsafe {
            [
                ts_tool_set_pose(w, bad, &p),
                ts_tool_get_pose(w, bad, &mut p.clone()),
                ts_tool_wrench(w, bad, &mut ts_wrench::default()),
                ts_tool_contact_count(w, bad, &mut u),
            ]
        };
        for (i, st) in tools.into_iter().enumerate() {
            expect(st, S::UnknownTool, &bad.to_string());
            assert_eq!(st, S::UnknownTool, "tool call #{i}");
        }
    }
    assert_eq!((z, d, u), (0, 0.0, 0), "no output written");
    assert_eq!(sc.snapshot(), before);
}

#[test]
fn wrong_sizes_and_ranges() {
    let sc = Scene::new();
    let w = sc.w;
    sc.step(3);
    let before = sc.snapshot();
    let m = material();
    let (nodes, tets) = lattice();
    let mut u = 77u32;
    // A tet that names a node past the end of the nodes array.
    let mut bad_tets = tets.clone();
    bad_tets[5] = (nodes.len() / 3) as u32;
    let st = unsafe {
        ts_world_add_body_from_arrays(
            w,
            nodes.as_ptr(),
            nodes.len() / 3,
            bad_tets.as_ptr(),
            bad_tets.len() / 4,
            &m,
            null(),
            &mut u,
        )
    };
    assert_eq!(st, S::MeshError, "{}", last_error());
    // A node count that overflows when multiplied by 3.
    let st = unsafe {
        ts_world_add_body_from_arrays(
            w,
            nodes.as_ptr(),
            usize::MAX / 2,
            tets.as_ptr(),
            1,
            &m,
            null(),
            &mut u,
        )
    };
    expect(st, S::InvalidArgument, "node_count");
    // No tets at all.
    let st = unsafe {
        ts_world_add_body_from_arrays(
            w,
            nodes.as_ptr(),
            nodes.len() / 3,
            tets.as_ptr(),
            0,
            &m,
            null(),
            &mut u,
        )
    };
    assert_ne!(st, S::Ok);
    // A particle index out of range.
    let idx = [0u32, 10_000];
    let st = unsafe { ts_body_fix_particles(w, 0, idx.as_ptr(), 2) };
    expect(st, S::InvalidArgument, "10000");
    // Inverted box.
    let (lo, hi) = ([1.0, 0.0, 0.0], [0.0, 1.0, 1.0]);
    let st = unsafe { ts_body_fix_box(w, 0, lo.as_ptr(), hi.as_ptr(), null_mut()) };
    assert_eq!(st, S::InvalidArgument);
    // Bad materials and options.
    let bad_materials = [
        ts_material {
            youngs_modulus: -1.0,
            ..m
        },
        ts_material { density: 0.0, ..m },
        ts_material {
            poisson_ratio: 0.5,
            ..m
        },
        ts_material {
            poisson_ratio: -1.0,
            ..m
        },
    ];
    for bm in bad_materials {
        let st = unsafe { ts_world_add_default_organ(w, &bm, null(), &mut u) };
        assert_eq!(st, S::InvalidArgument, "{bm:?}");
    }
    let mut o = std::mem::MaybeUninit::uninit();
    assert_eq!(unsafe { ts_body_options_default(o.as_mut_ptr()) }, S::Ok);
    let o = unsafe { o.assume_init() };
    for bo in [
        ts_body_options {
            support_radius: -0.1,
            ..o
        },
        ts_body_options {
            particle_radius: -0.1,
            ..o
        },
        ts_body_options {
            target_neighbours: 0,
            ..o
        },
    ] {
        let st = unsafe { ts_world_add_default_organ(w, &m, &bo, &mut u) };
        assert_eq!(st, S::InvalidArgument, "{bo:?}");
    }
    // Bad tool shapes and options.
    let p = pose(0.0, 1.0, 0.0);
    let zero3 = [0.01, 0.0, 0.01];
    let sts = unsafe {
        [
            ts_world_add_tool_sphere(w, 0.0, &p, null(), &mut u),
            ts_world_add_tool_sphere(w, -0.01, &p, null(), &mut u),
            ts_world_add_tool_capsule(w, -0.01, 0.01, &p, null(), &mut u),
            ts_world_add_tool_capsule(w, 0.01, 0.0, &p, null(), &mut u),
            ts_world_add_tool_cylinder(w, 0.0, 0.01, &p, null(), &mut u),
            ts_world_add_tool_cylinder(w, 0.01, -1.0, &p, null(), &mut u),
            ts_world_add_tool_box(w, zero3.as_ptr(), &p, null(), &mut u),
        ]
    };
    for (i, st) in sts.into_iter().enumerate() {
        assert_eq!(st, S::InvalidArgument, "shape #{i}");
    }
    let mut to = std::mem::MaybeUninit::uninit();
    assert_eq!(unsafe { ts_tool_options_default(to.as_mut_ptr()) }, S::Ok);
    let to = unsafe { to.assume_init() };
    for bo in [
        ts_tool_options {
            friction_static: -1.0,
            ..to
        },
        ts_tool_options {
            friction_static: 0.2,
            friction_kinetic: 0.5,
            ..to
        },
        ts_tool_options {
            sample_spacing: -1.0,
            ..to
        },
    ] {
        let st = unsafe { ts_world_add_tool_sphere(w, 0.01, &p, &bo, &mut u) };
        assert_eq!(st, S::InvalidArgument, "{bo:?}");
    }
    // Zero quaternion.
    let zq = ts_pose {
        position: [0.0; 3],
        orientation: [0.0; 4],
    };
    expect(
        unsafe { ts_tool_set_pose(w, 0, &zq) },
        S::InvalidArgument,
        "quaternion",
    );
    expect(
        unsafe { ts_world_add_tool_sphere(w, 0.01, &zq, null(), &mut u) },
        S::InvalidArgument,
        "quaternion",
    );
    // Bad scale and empty path.
    let path = CString::new("/nonexistent.msh").unwrap();
    let empty = CString::new("").unwrap();
    for scale in [0.0, -1.0] {
        let st =
            unsafe { ts_world_add_body_from_file(w, path.as_ptr(), scale, &m, null(), &mut u) };
        assert!(st == S::InvalidArgument || st == S::MeshError, "{st:?}");
    }
    let st = unsafe { ts_world_add_body_from_file(w, empty.as_ptr(), 1.0, &m, null(), &mut u) };
    assert_eq!(st, S::InvalidArgument);
    // Bad settings values.
    let s = settings();
    for bad in [
        ts_settings { dt: 0.0, ..s },
        ts_settings { dt: -1e-3, ..s },
        ts_settings {
            min_substeps: 0,
            ..s
        },
        ts_settings {
            max_substeps: 0,
            ..s
        },
        ts_settings { iterations: 0, ..s },
        ts_settings {
            stability_margin: 1.5,
            ..s
        },
        ts_settings {
            damping_mass: -1.0,
            ..s
        },
        ts_settings {
            contact_mode: 2,
            ..s
        },
        ts_settings {
            max_depenetration_speed: 0.0,
            ..s
        },
    ] {
        let mut nw = null_mut();
        assert_eq!(unsafe { ts_world_new(&bad, &mut nw) }, S::InvalidArgument);
        assert!(nw.is_null());
        assert_eq!(
            unsafe { ts_world_set_settings(w, &bad) },
            S::InvalidArgument
        );
    }
    assert_eq!(u, 77, "no id written");
    assert_eq!(sc.snapshot(), before, "the world is unchanged");
    let mut n = 0;
    assert_eq!(unsafe { ts_world_body_count(w, &mut n) }, S::Ok);
    assert_eq!(n, 1);
    assert_eq!(unsafe { ts_world_tool_count(w, &mut n) }, S::Ok);
    assert_eq!(n, 1);
}

#[test]
fn non_finite_inputs_leave_the_world_untouched() {
    let sc = Scene::new();
    let w = sc.w;
    let p = pose(0.0, -SIZE / 2.0 - 0.005, 0.0);
    assert_eq!(unsafe { ts_tool_set_pose(w, 0, &p) }, S::Ok);
    sc.step(5);
    let before = sc.snapshot();
    let m = material();
    let mut u = 99u32;
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        for k in 0..7 {
            let mut q = pose(0.0, 0.0, 0.0);
            if k < 3 {
                q.position[k] = bad;
            } else {
                q.orientation[k - 3] = bad;
            }
            expect(unsafe { ts_tool_set_pose(w, 0, &q) }, S::NonFinite, "pose");
            expect(
                unsafe { ts_world_add_tool_sphere(w, 0.01, &q, null(), &mut u) },
                S::NonFinite,
                "pose",
            );
        }
        let s = settings();
        let mut g = s;
        g.gravity[1] = bad;
        for b in [
            ts_settings { dt: bad, ..s },
            g,
            ts_settings {
                stability_margin: bad,
                ..s
            },
            ts_settings {
                damping_mass: bad,
                ..s
            },
            ts_settings {
                damping_stiffness: bad,
                ..s
            },
            ts_settings {
                hourglass_stiffness: bad,
                ..s
            },
            ts_settings {
                volume_compliance: bad,
                ..s
            },
            ts_settings {
                max_depenetration_speed: bad,
                ..s
            },
        ] {
            let mut nw = null_mut();
            expect(
                unsafe { ts_world_new(&b, &mut nw) },
                S::NonFinite,
                "settings.",
            );
            assert!(nw.is_null());
            expect(
                unsafe { ts_world_set_settings(w, &b) },
                S::NonFinite,
                "settings.",
            );
        }
        let sts = unsafe {
            [
                ts_world_add_tool_sphere(w, bad, &p, null(), &mut u),
                ts_world_add_tool_capsule(w, bad, 0.01, &p, null(), &mut u),
                ts_world_add_tool_capsule(w, 0.01, bad, &p, null(), &mut u),
                ts_world_add_tool_cylinder(w, 0.01, bad, &p, null(), &mut u),
                ts_world_add_tool_box(w, [0.01, bad, 0.01].as_ptr(), &p, null(), &mut u),
                ts_body_fix_box(
                    w,
                    0,
                    [bad, 0.0, 0.0].as_ptr(),
                    [1.0; 3].as_ptr(),
                    null_mut(),
                ),
                ts_body_fix_box(
                    w,
                    0,
                    [0.0; 3].as_ptr(),
                    [1.0, 1.0, bad].as_ptr(),
                    null_mut(),
                ),
                ts_world_add_default_organ(
                    w,
                    &ts_material {
                        youngs_modulus: bad,
                        ..m
                    },
                    null(),
                    &mut u,
                ),
                ts_world_add_default_organ(w, &ts_material { density: bad, ..m }, null(), &mut u),
            ]
        };
        for (i, st) in sts.into_iter().enumerate() {
            assert_eq!(st, S::NonFinite, "call #{i} with {bad}");
        }
        let (mut nodes, tets) = lattice();
        nodes[7] = bad;
        let st = unsafe {
            ts_world_add_body_from_arrays(
                w,
                nodes.as_ptr(),
                nodes.len() / 3,
                tets.as_ptr(),
                tets.len() / 4,
                &m,
                null(),
                &mut u,
            )
        };
        expect(st, S::NonFinite, "nodes[7]");
        let path = CString::new("/nonexistent.msh").unwrap();
        let st = unsafe { ts_world_add_body_from_file(w, path.as_ptr(), bad, &m, null(), &mut u) };
        expect(st, S::NonFinite, "scale");
    }
    assert_eq!(u, 99, "no id written");
    assert_eq!(sc.snapshot(), before, "the world is unchanged");
    // And it still steps exactly as before: compare with a twin that saw no bad calls.
    let twin = Scene::new();
    assert_eq!(unsafe { ts_tool_set_pose(twin.w, 0, &p) }, S::Ok);
    twin.step(5);
    assert_eq!(twin.snapshot(), before);
    sc.step(5);
    twin.step(5);
    assert_eq!(twin.snapshot(), sc.snapshot());
}

#[test]
fn quaternions_are_normalised() {
    let sc = Scene::new();
    let q = ts_pose {
        position: [0.0, -0.1, 0.0],
        orientation: [2.0, 0.0, 0.0, 0.0],
    };
    assert_eq!(unsafe { ts_tool_set_pose(sc.w, 0, &q) }, S::Ok);
    sc.step(1);
    let got = sc.tool_pose();
    assert!((got.orientation[0] - 1.0).abs() < 1e-12, "{got:?}");
    assert!((got.position[1] + 0.1).abs() < 1e-12, "{got:?}");
}

#[test]
fn short_buffers_write_nothing() {
    let sc = Scene::new();
    let w = sc.w;
    sc.step(2);
    let n = sc.particles();
    let mut nt = 0;
    assert_eq!(
        unsafe { ts_body_boundary_triangle_count(w, 0, &mut nt) },
        S::Ok
    );
    let mut ntet = 0;
    assert_eq!(unsafe { ts_body_tet_count(w, 0, &mut ntet) }, S::Ok);
    assert!(nt > 0 && ntet > 0);
    const FILL: f64 = -12345.5;
    let doubles: [(
        &str,
        unsafe extern "C" fn(*const ts_world, u32, *mut f64, usize) -> ts_status,
    ); 3] = [
        ("positions", ts_body_positions),
        ("velocities", ts_body_velocities),
        ("rest positions", ts_body_rest_positions),
    ];
    for (name, f) in doubles {
        for len in [0, 1, 3 * n - 1] {
            let mut buf = vec![FILL; 3 * n + 4];
            expect(
                unsafe { f(w, 0, buf.as_mut_ptr(), len) },
                S::BufferTooSmall,
                &(3 * n).to_string(),
            );
            assert!(buf.iter().all(|&x| x.to_bits() == FILL.to_bits()), "{name}");
        }
        let mut buf = vec![FILL; 3 * n + 4];
        assert_eq!(unsafe { f(w, 0, buf.as_mut_ptr(), buf.len()) }, S::Ok);
        assert!(buf[..3 * n].iter().all(|x| x.is_finite() && *x != FILL));
        assert!(
            buf[3 * n..].iter().all(|&x| x == FILL),
            "{name}: wrote past 3n"
        );
    }
    const IFILL: u32 = 0xDEAD_BEEF;
    let ints: [(
        unsafe extern "C" fn(*const ts_world, u32, *mut u32, usize) -> ts_status,
        usize,
    ); 3] = [
        (ts_body_source_indices, n),
        (ts_body_boundary_triangles, 3 * nt),
        (ts_body_tets, 4 * ntet),
    ];
    for (f, needed) in ints {
        for len in [0, needed - 1] {
            let mut buf = vec![IFILL; needed + 2];
            expect(
                unsafe { f(w, 0, buf.as_mut_ptr(), len) },
                S::BufferTooSmall,
                &needed.to_string(),
            );
            assert!(buf.iter().all(|&x| x == IFILL));
        }
        let mut buf = vec![IFILL; needed + 2];
        assert_eq!(unsafe { f(w, 0, buf.as_mut_ptr(), buf.len()) }, S::Ok);
        assert!(buf[..needed].iter().all(|&x| (x as usize) < n));
        assert_eq!(&buf[needed..], &[IFILL, IFILL]);
    }
    let mut size = 0;
    assert_eq!(unsafe { ts_world_state_size(w, &mut size) }, S::Ok);
    assert!(size > 0);
    let mut buf = vec![0xA5u8; size + 8];
    let mut written = 4242usize;
    expect(
        unsafe { ts_world_save_state(w, buf.as_mut_ptr(), size - 1, &mut written) },
        S::BufferTooSmall,
        &size.to_string(),
    );
    assert!(buf.iter().all(|&b| b == 0xA5));
    assert_eq!(written, 4242);
    assert_eq!(
        unsafe { ts_world_save_state(w, buf.as_mut_ptr(), buf.len(), &mut written) },
        S::Ok
    );
    assert_eq!(written, size);
    assert!(buf[size..].iter().all(|&b| b == 0xA5));
}

/// A scratch directory for this test process.
fn scratch(name: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("tissuesim-ffi-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

#[test]
fn missing_and_malformed_files_are_mesh_errors_naming_the_file() {
    let sc = Scene::new();
    let w = sc.w;
    let before = sc.snapshot();
    let m = material();
    let p = pose(0.0, 1.0, 0.0);
    let dir = scratch("meshes");
    let missing = dir.join("no_such_liver.msh");
    let malformed = dir.join("broken_liver.msh");
    std::fs::write(
        &malformed,
        "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n3\n1 0 0\n",
    )
    .unwrap();
    let garbage_vtk = dir.join("garbage.vtk");
    std::fs::write(&garbage_vtk, "this is not a VTK file\n").unwrap();
    let missing_obj = dir.join("no_such_probe.obj");
    let bad_obj = dir.join("bad_probe.obj");
    std::fs::write(&bad_obj, "v 0 0 0\nv 1 0 0\nf 1 2 9\n").unwrap();
    let mut u = 5u32;
    for path in [&missing, &malformed, &garbage_vtk] {
        let c = CString::new(path.to_str().unwrap()).unwrap();
        let st = unsafe { ts_world_add_body_from_file(w, c.as_ptr(), 1.0, &m, null(), &mut u) };
        let name = path.file_name().unwrap().to_str().unwrap();
        expect(st, S::MeshError, name);
    }
    for path in [&missing_obj, &bad_obj] {
        let c = CString::new(path.to_str().unwrap()).unwrap();
        let st = unsafe { ts_world_add_tool_mesh_file(w, c.as_ptr(), 1.0, &p, null(), &mut u) };
        let name = path.file_name().unwrap().to_str().unwrap();
        expect(st, S::MeshError, name);
    }
    assert_eq!(u, 5);
    assert_eq!(sc.snapshot(), before);
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn files_that_exist_load() {
    let sc = Scene::new();
    let dir = scratch("ok");
    // The lattice as a legacy VTK file (mesh units: the lattice's metres / 0.05).
    let (nodes, tets) = lattice();
    let vtk = dir.join("lattice.vtk");
    let mut text = format!(
        "# vtk DataFile Version 2.0\nlattice\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS {} double\n",
        nodes.len() / 3
    );
    for p in nodes.chunks(3) {
        text += &format!("{} {} {}\n", p[0] / 0.05, p[1] / 0.05, p[2] / 0.05);
    }
    text += &format!("CELLS {} {}\n", tets.len() / 4, tets.len() / 4 * 5);
    for t in tets.chunks(4) {
        text += &format!("4 {} {} {} {}\n", t[0], t[1], t[2], t[3]);
    }
    text += &format!("CELL_TYPES {}\n", tets.len() / 4);
    for _ in 0..tets.len() / 4 {
        text += "10\n";
    }
    std::fs::write(&vtk, text).unwrap();
    let obj = dir.join("probe.obj");
    std::fs::write(
        &obj,
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n",
    )
    .unwrap();
    let m = material();
    let mut b = 0;
    let c = CString::new(vtk.to_str().unwrap()).unwrap();
    let st = unsafe { ts_world_add_body_from_file(sc.w, c.as_ptr(), 0.05, &m, null(), &mut b) };
    assert_eq!(st, S::Ok, "{}", last_error());
    assert_eq!(b, 1);
    let mut v = 0.0;
    assert_eq!(unsafe { ts_body_rest_volume(sc.w, 1, &mut v) }, S::Ok);
    assert!((v - SIZE.powi(3)).abs() < 1e-12, "{v}");
    let mut t = 0;
    let c = CString::new(obj.to_str().unwrap()).unwrap();
    let p = pose(0.0, 1.0, 0.0);
    let st = unsafe { ts_world_add_tool_mesh_file(sc.w, c.as_ptr(), 0.02, &p, null(), &mut t) };
    assert_eq!(st, S::Ok, "{}", last_error());
    assert_eq!(t, 1);
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn bad_states_are_rejected_and_leave_the_world_untouched() {
    let sc = Scene::new();
    let w = sc.w;
    sc.step(3);
    let mut size = 0;
    assert_eq!(unsafe { ts_world_state_size(w, &mut size) }, S::Ok);
    let mut good = vec![0u8; size];
    assert_eq!(
        unsafe { ts_world_save_state(w, good.as_mut_ptr(), size, null_mut()) },
        S::Ok
    );
    sc.step(2);
    let before = sc.snapshot();
    let mut bad_inputs: Vec<(&str, Vec<u8>)> = vec![
        ("empty", Vec::new()),
        ("truncated by one", good[..size - 1].to_vec()),
        ("half", good[..size / 2].to_vec()),
        ("header only", good[..8.min(size)].to_vec()),
        ("garbage", (0..size).map(|i| (i * 131 + 7) as u8).collect()),
        ("zeros", vec![0u8; size]),
        ("one byte too long", [good.clone(), vec![0]].concat()),
    ];
    // Corrupt the version: flip every byte of the first 8 in turn (magic / version live there).
    for i in 0..8.min(size) {
        let mut v = good.clone();
        v[i] ^= 0xFF;
        bad_inputs.push(("header byte flipped", v));
    }
    for (name, bytes) in &bad_inputs {
        let st = unsafe { ts_world_restore_state(w, bytes.as_ptr(), bytes.len()) };
        assert_eq!(st, S::BadState, "{name}: {}", last_error());
        assert_eq!(sc.snapshot(), before, "{name}: world changed");
    }
    // A state of another scene (two tools) does not restore into this one.
    let other = Scene::new();
    let mut t = 0;
    let p = pose(0.5, 0.5, 0.5);
    assert_eq!(
        unsafe { ts_world_add_tool_sphere(other.w, 0.01, &p, null(), &mut t) },
        S::Ok
    );
    let mut osize = 0;
    assert_eq!(unsafe { ts_world_state_size(other.w, &mut osize) }, S::Ok);
    let mut obuf = vec![0u8; osize];
    assert_eq!(
        unsafe { ts_world_save_state(other.w, obuf.as_mut_ptr(), osize, null_mut()) },
        S::Ok
    );
    let st = unsafe { ts_world_restore_state(w, obuf.as_ptr(), obuf.len()) };
    assert_eq!(st, S::BadState, "{}", last_error());
    assert_eq!(sc.snapshot(), before);
    // The good one restores.
    assert_eq!(
        unsafe { ts_world_restore_state(w, good.as_ptr(), size) },
        S::Ok
    );
    assert_ne!(sc.snapshot(), before);
}

#[test]
fn save_step_restore_step_is_bit_identical() {
    let sc = Scene::new();
    let w = sc.w;
    // Press the probe into the block while stepping, so contact and friction are in the state.
    let press = |k: usize| {
        pose(
            0.002 * (k as f64 * 0.1).sin(),
            -SIZE / 2.0 - 0.011 + 0.0004 * k as f64,
            0.0,
        )
    };
    for k in 0..20 {
        assert_eq!(unsafe { ts_tool_set_pose(w, 0, &press(k)) }, S::Ok);
        sc.step(1);
    }
    let mut size = 0;
    assert_eq!(unsafe { ts_world_state_size(w, &mut size) }, S::Ok);
    let mut saved = vec![0u8; size];
    let mut written = 0;
    assert_eq!(
        unsafe { ts_world_save_state(w, saved.as_mut_ptr(), size, &mut written) },
        S::Ok
    );
    assert_eq!(written, size);
    let run = |sc: &Scene| -> (Vec<u64>, Vec<[u64; 3]>) {
        let mut forces = Vec::new();
        for k in 20..45 {
            assert_eq!(unsafe { ts_tool_set_pose(sc.w, 0, &press(k)) }, S::Ok);
            sc.step(1);
            let mut wr = ts_wrench::default();
            assert_eq!(unsafe { ts_tool_wrench(sc.w, 0, &mut wr) }, S::Ok);
            forces.push(wr.force.map(f64::to_bits));
        }
        (sc.snapshot(), forces)
    };
    let first = run(&sc);
    assert_eq!(
        unsafe { ts_world_restore_state(w, saved.as_ptr(), size) },
        S::Ok
    );
    let second = run(&sc);
    assert_eq!(
        first.0, second.0,
        "positions, velocities, volume, time, pose"
    );
    assert_eq!(first.1, second.1, "force trace");
    assert!(
        first
            .1
            .iter()
            .any(|f| f.iter().any(|&b| f64::from_bits(b) != 0.0)),
        "the probe touched the block"
    );
    // Into a fresh world with the same scene, too.
    let twin = Scene::new();
    assert_eq!(
        unsafe { ts_world_restore_state(twin.w, saved.as_ptr(), size) },
        S::Ok
    );
    let third = run(&twin);
    assert_eq!(first, third);
}

#[test]
fn outputs_are_sane() {
    let sc = Scene::new();
    let w = sc.w;
    let n = sc.particles();
    assert_eq!(n, (CELLS + 1).pow(3));
    let mut src = vec![0u32; n];
    assert_eq!(
        unsafe { ts_body_source_indices(w, 0, src.as_mut_ptr(), n) },
        S::Ok
    );
    assert!(src.iter().enumerate().all(|(i, &s)| s as usize == i));
    let (mut v, mut v0, mut mass) = (0.0, 0.0, 0.0);
    assert_eq!(unsafe { ts_body_volume(w, 0, &mut v) }, S::Ok);
    assert_eq!(unsafe { ts_body_rest_volume(w, 0, &mut v0) }, S::Ok);
    assert_eq!(unsafe { ts_body_mass(w, 0, &mut mass) }, S::Ok);
    assert!((v0 - SIZE.powi(3)).abs() < 1e-12, "{v0}");
    assert!((v - v0).abs() < 1e-12);
    assert!((mass - 1060.0 * SIZE.powi(3)).abs() < 1e-9, "{mass}");
    let mut report = ts_step_report {
        substeps: 0,
        substeps_clamped: 7,
    };
    assert_eq!(unsafe { ts_world_step(w, &mut report) }, S::Ok);
    assert!(
        report.substeps >= 1 && report.substeps_clamped <= 1,
        "{report:?}"
    );
    let mut t = 0.0;
    assert_eq!(unsafe { ts_world_time(w, &mut t) }, S::Ok);
    assert!((t - 1e-3).abs() < 1e-15);
    let mut d = -1.0;
    assert_eq!(unsafe { ts_body_max_displacement(w, 0, &mut d) }, S::Ok);
    assert!(d >= 0.0);
    let mut dv = 1;
    assert_eq!(unsafe { ts_world_diverged_steps(w, &mut dv) }, S::Ok);
    assert_eq!(dv, 0);
    let fixed = [0u32, 1, 2, 3];
    assert_eq!(
        unsafe { ts_body_fix_particles(w, 0, fixed.as_ptr(), 4) },
        S::Ok
    );
    assert_eq!(
        unsafe { ts_body_fix_particles(w, 0, fixed.as_ptr(), 0) },
        S::Ok
    );
    let mut s = settings();
    s.gravity = [0.0, 0.0, -1.0];
    assert_eq!(unsafe { ts_world_set_settings(w, &s) }, S::Ok);
    let mut got = settings();
    assert_eq!(unsafe { ts_world_get_settings(w, &mut got) }, S::Ok);
    assert_eq!(got, s);
}

#[test]
fn panics_become_status_panic() {
    use tissuesim::ffi::guard::{guard, guard_value};
    let st = guard(|| panic!("boom at the boundary"));
    expect(st, S::Panic, "boom at the boundary");
    let st = guard(|| std::panic::panic_any(42u8));
    expect(st, S::Panic, "internal panic");
    assert_eq!(guard_value(7, || -> i32 { panic!("value boom") }), 7);
    assert!(last_error().contains("value boom"));
}
