//! DESIGN §5: no heap allocation inside `ts_world_step` after the first step, nor in the getters
//! a haptic loop calls every step (pose in, wrench and positions out), nor in the render
//! surface update a render thread calls every frame. Counted with a global
//! allocator wrapper; this test binary runs its single test alone.

use std::alloc::{GlobalAlloc, Layout, System};
use std::ptr::{null, null_mut};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use tissuesim::ffi::body::*;
use tissuesim::ffi::render::*;
use tissuesim::ffi::status::ts_status;
use tissuesim::ffi::tool::*;
use tissuesim::ffi::world::*;

struct Counting;

static COUNTING: AtomicBool = AtomicBool::new(false);
static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if COUNTING.load(Ordering::Relaxed) {
            ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        }
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        if COUNTING.load(Ordering::Relaxed) {
            ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        }
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

#[test]
fn haptic_loop_calls_do_not_allocate_after_the_first_step() {
    let mut s = std::mem::MaybeUninit::uninit();
    assert_eq!(
        unsafe { ts_settings_default(s.as_mut_ptr()) },
        ts_status::Ok
    );
    let s = unsafe { s.assume_init() };
    let mut w = null_mut();
    assert_eq!(unsafe { ts_world_new(&s, &mut w) }, ts_status::Ok);
    let mut m = std::mem::MaybeUninit::uninit();
    assert_eq!(
        unsafe { ts_material_default(m.as_mut_ptr()) },
        ts_status::Ok
    );
    let m = unsafe { m.assume_init() };
    let mut organ = 0;
    assert_eq!(
        unsafe { ts_world_add_default_organ(w, &m, null(), &mut organ) },
        ts_status::Ok
    );
    let mut n = 0;
    assert_eq!(
        unsafe { ts_body_particle_count(w, organ, &mut n) },
        ts_status::Ok
    );
    let mut x = vec![0.0; 3 * n];
    assert_eq!(
        unsafe { ts_body_positions(w, organ, x.as_mut_ptr(), x.len()) },
        ts_status::Ok
    );
    let top = x.chunks(3).map(|p| p[1]).fold(f64::MIN, f64::max);
    let bottom = x.chunks(3).map(|p| p[1]).fold(f64::MAX, f64::min);
    let (lo, hi) = ([-1.0, bottom - 1.0, -1.0], [1.0, bottom + 0.01, 1.0]);
    assert_eq!(
        unsafe { ts_body_fix_box(w, organ, lo.as_ptr(), hi.as_ptr(), null_mut()) },
        ts_status::Ok
    );
    let mut pose = ts_pose {
        position: [0.0, top + 0.005, 0.0],
        orientation: [1.0, 0.0, 0.0, 0.0],
    };
    let mut probe = 0;
    assert_eq!(
        unsafe { ts_world_add_tool_sphere(w, 0.01, &pose, null(), &mut probe) },
        ts_status::Ok
    );
    let mut tris = vec![0u32; 1];
    let mut nt = 0;
    assert_eq!(
        unsafe { ts_body_boundary_triangle_count(w, organ, &mut nt) },
        ts_status::Ok
    );
    tris.resize(3 * nt, 0);
    let mut surface = 0;
    assert_eq!(
        unsafe { ts_world_add_render_surface_from_boundary(w, organ, &mut surface) },
        ts_status::Ok
    );
    let mut nv = 0;
    assert_eq!(
        unsafe { ts_render_surface_vertex_count(w, surface, &mut nv) },
        ts_status::Ok
    );
    let (mut sp, mut sn) = (vec![0.0; 3 * nv], vec![0.0; 3 * nv]);
    let mut wrench = ts_wrench::default();
    let mut frame = |k: usize, pose: &mut ts_pose| {
        // 0.1 mm a step: the probe reaches the organ whatever its sag under its own weight.
        pose.position[1] = top + 0.005 - 0.0001 * k as f64;
        assert_eq!(unsafe { ts_tool_set_pose(w, probe, pose) }, ts_status::Ok);
        assert_eq!(unsafe { ts_world_step(w, null_mut()) }, ts_status::Ok);
        assert_eq!(
            unsafe { ts_tool_wrench(w, probe, &mut wrench) },
            ts_status::Ok
        );
        assert_eq!(
            unsafe { ts_body_positions(w, organ, x.as_mut_ptr(), x.len()) },
            ts_status::Ok
        );
        assert_eq!(
            unsafe { ts_body_boundary_triangles(w, organ, tris.as_mut_ptr(), tris.len()) },
            ts_status::Ok
        );
        assert_eq!(
            unsafe {
                ts_render_surface_update(w, surface, sp.as_mut_ptr(), sn.as_mut_ptr(), sp.len())
            },
            ts_status::Ok
        );
    };
    frame(0, &mut pose);
    frame(1, &mut pose);
    COUNTING.store(true, Ordering::SeqCst);
    for k in 2..400 {
        frame(k, &mut pose);
    }
    COUNTING.store(false, Ordering::SeqCst);
    let allocations = ALLOCATIONS.load(Ordering::SeqCst);
    assert!(wrench.contact_count > 0, "the probe is pressing the organ");
    assert_eq!(allocations, 0, "heap allocations in 398 haptic frames");
    unsafe { ts_world_free(w) };
}
