//! No heap allocation inside a step after the first: two bodies in organ–organ contact, a probe
//! with friction pressing one of them, in both contact modes, on one and on two threads, and
//! with surface self-contact. Every
//! thread's allocations are counted (this file holds a single test, so nothing else runs).

mod common;

use common::two_bodies_stacked;
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use tissuesim::{
    ContactMode, ElasticScheme, Pose, Settings, ToolOptions, ToolShape, Vec3, VolumeScheme,
};

struct Counting;

static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);
static COUNTING: AtomicBool = AtomicBool::new(false);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if COUNTING.load(Ordering::SeqCst) {
            ALLOCATIONS.fetch_add(1, Ordering::SeqCst);
        }
        System.alloc(layout)
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        System.dealloc(ptr, layout)
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        if COUNTING.load(Ordering::SeqCst) {
            ALLOCATIONS.fetch_add(1, Ordering::SeqCst);
        }
        System.realloc(ptr, layout, new_size)
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

fn allocations_during(f: impl FnOnce()) -> usize {
    let before = ALLOCATIONS.load(Ordering::SeqCst);
    COUNTING.store(true, Ordering::SeqCst);
    f();
    COUNTING.store(false, Ordering::SeqCst);
    ALLOCATIONS.load(Ordering::SeqCst) - before
}

#[test]
fn steps_after_the_first_do_not_allocate() {
    // (contact mode, threads, volume scheme, elastic scheme, self-contact, crushed substeps)
    use ElasticScheme::{PointBased, Tetrahedra};
    use VolumeScheme::DualCells;
    let per_tet = VolumeScheme::Tetrahedra;
    let (exact, sampled) = (ContactMode::ExactShape, ContactMode::SampledPoints);
    for (mode, threads, volume_scheme, elastic_scheme, self_contact, crushed_substeps) in [
        (exact, 1, per_tet, PointBased, false, 1),
        (sampled, 1, per_tet, PointBased, false, 1),
        (exact, 2, per_tet, PointBased, false, 1),
        (exact, 1, DualCells, PointBased, false, 1),
        (exact, 2, DualCells, PointBased, false, 1),
        (exact, 1, DualCells, Tetrahedra, false, 1),
        (exact, 2, DualCells, Tetrahedra, false, 1),
        (exact, 1, DualCells, Tetrahedra, false, 2),
        (exact, 1, per_tet, PointBased, true, 1),
        (exact, 2, DualCells, Tetrahedra, true, 1),
    ] {
        let settings = Settings {
            contact_mode: mode,
            threads,
            volume_scheme,
            elastic_scheme,
            self_contact,
            crushed_substeps,
            ..Settings::default()
        };
        let (mut world, a, b) = two_bodies_stacked(settings);
        world.set_body_pair_friction(a, b, 0.3, 0.2).unwrap();
        let options = ToolOptions {
            friction_static: 0.5,
            friction_kinetic: 0.4,
            ..ToolOptions::default()
        };
        let tool = world
            .add_tool(
                ToolShape::Capsule {
                    half_height: 0.02,
                    radius: 0.008,
                },
                Pose::at(Vec3::new(0.0, 0.0, 0.1)),
                &options,
            )
            .unwrap();
        world.step().unwrap();
        let n = allocations_during(|| {
            for k in 0..100 {
                let z = 0.1 - 0.0005 * k as f64;
                world
                    .set_tool_pose(tool, Pose::at(Vec3::new(0.0, -0.02, z)))
                    .unwrap();
                world.step().unwrap();
            }
        });
        assert!(
            world.tool(tool).unwrap().wrench().contact_count > 0,
            "{mode:?}: no contact"
        );
        assert_eq!(n, 0, "{mode:?}: {n} allocations in 100 steps");
    }
}
