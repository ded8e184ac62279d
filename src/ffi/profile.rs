//! Where a step's time goes, from C: the wall time of each stage of the last step (see the Rust
//! `World::set_profiling` and `World::step_profile`).

use crate::ffi::args::world_mut;
use crate::ffi::guard::guard;
use crate::ffi::status::ts_status;
use crate::ffi::world::{ts_world, world_value};
use crate::solver::profile::StepProfile;

/// The wall time (s) of each stage of the last step, summed over its substeps and iterations:
/// the calling thread's time, waits for the world's other threads included.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ts_step_profile {
    /// 1 when the stages below were measured (profiling on and a step run since), else 0 and
    /// every time 0.
    pub measured: u32,
    /// The copy of the state a diverged step is rolled back to (s).
    pub state_copy: f64,
    /// Gravity and elastic forces, velocities and predicted positions (s).
    pub prediction: f64,
    /// The volume constraints (s).
    pub volume: f64,
    /// Organ–organ contact (s).
    pub organ_contact: f64,
    /// Surface self-contact (s).
    pub self_contact: f64,
    /// Tool–tissue contact (s).
    pub tool_contact: f64,
    /// Grasps and needle holds (s).
    pub grasp_and_needle: f64,
    /// The update of positions and velocities (s).
    pub update: f64,
    /// The divergence check, grasp slip, cuts, the tools' wrenches and poses, needle puncture
    /// (s).
    pub end_of_step: f64,
    /// The whole step (s).
    pub total: f64,
}

impl From<Option<StepProfile>> for ts_step_profile {
    fn from(p: Option<StepProfile>) -> ts_step_profile {
        let Some(p) = p else {
            return ts_step_profile::default();
        };
        ts_step_profile {
            measured: 1,
            state_copy: p.state_copy.as_secs_f64(),
            prediction: p.prediction.as_secs_f64(),
            volume: p.volume.as_secs_f64(),
            organ_contact: p.organ_contact.as_secs_f64(),
            self_contact: p.self_contact.as_secs_f64(),
            tool_contact: p.tool_contact.as_secs_f64(),
            grasp_and_needle: p.grasp_and_needle.as_secs_f64(),
            update: p.update.as_secs_f64(),
            end_of_step: p.end_of_step.as_secs_f64(),
            total: p.total.as_secs_f64(),
        }
    }
}

/// Measure the wall time of every stage of the steps from now on (`on` non-zero), or stop
/// (`on` 0, the default: a step then reads no clock). Profiling changes no result.
///
/// # Safety
///
/// `world` is NULL or a live handle.
#[no_mangle]
pub unsafe extern "C" fn ts_world_set_profiling(world: *mut ts_world, on: u32) -> ts_status {
    guard(|| {
        // SAFETY: contract of this function.
        let h = unsafe { world_mut(world)? };
        h.mutate(|w| {
            w.set_profiling(on != 0);
            Ok(())
        })
    })
}

/// Write where the last step's time went into *out_profile: its stages' wall times with
/// `measured` 1 while profiling is on (ts_world_set_profiling) and a step has run since; all 0
/// otherwise.
///
/// # Safety
///
/// `world` is NULL or a live handle; `out_profile` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn ts_world_step_profile(
    world: *const ts_world,
    out_profile: *mut ts_step_profile,
) -> ts_status {
    // SAFETY: contract of this function.
    unsafe {
        world_value(world, out_profile, "out_profile", |w| {
            ts_step_profile::from(w.step_profile())
        })
    }
}
