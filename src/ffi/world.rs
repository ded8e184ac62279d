//! `ts_world`: the opaque world handle, its settings and its step.

use crate::error::Error;
use crate::ffi::args::{non_null, world_mut, world_ref, write};
use crate::ffi::error::{fail, FfiResult};
use crate::ffi::guard::guard;
use crate::ffi::status::ts_status;
use crate::kernels::math::Vec3;
use crate::scene::settings::{ContactMode, DivergenceLimits, Settings};
use crate::world::World;

/// How tool-tissue contact is detected (the values of ts_settings.contact_mode).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ts_contact_mode {
    /// The tool's exact shape against the body's deformed boundary triangles (the default):
    /// contact starts a skin of a tenth of the particle radius out from the surface, one-sided
    /// and swept, so tools thinner than the particle spacing do not slip in.
    ExactShape = 0,
    /// The paper's mode: the tool surface sampled into points, particles (spheres of the
    /// particle radius) pushed out of them; thin tools can slip between particles.
    SampledPoints = 1,
}

/// Parameters of the time integration and of the constraint projection (SI units). Fill it
/// with ts_settings_default, then change fields. Integer flags are 0 (off) or non-zero (on).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ts_settings {
    /// Time step of one ts_world_step call (s), > 0.
    pub dt: f64,
    /// Gravity acceleration (m/s^2), world frame, [x, y, z].
    pub gravity: [f64; 3],
    /// Smallest number of substeps per step (>= 1).
    pub min_substeps: u32,
    /// Largest number of substeps per step (>= min_substeps); the world substeps as stability
    /// requires up to this many and reports clamping in ts_step_report.substeps_clamped.
    pub max_substeps: u32,
    /// Fraction (0, 1] of the explicit stability limit that a substep may use.
    pub stability_margin: f64,
    /// Mass-proportional (ambient) damping rate (1/s), >= 0.
    pub damping_mass: f64,
    /// Stiffness-proportional damping time (s), >= 0.
    pub damping_stiffness: f64,
    /// Hourglass-control stiffness (dimensionless, times the shear modulus mu), >= 0.
    pub hourglass_stiffness: f64,
    /// Compliance (1/Pa, per unit volume, >= 0) of the volume constraints in addition to the
    /// material's 1/lambda under the volumetric split (the default: 0 keeps the material's own
    /// compressibility), or in total without the split (0 = hard constraints).
    pub volume_compliance: f64,
    /// Largest speed (m/s, > 0) at which tool contact pushes a particle out of a tool, so that
    /// a tool jumping into the tissue (a haptic glitch) does not fling particles out.
    pub max_depenetration_speed: f64,
    /// Constraint-projection iterations per substep (>= 1).
    pub iterations: u32,
    /// How tool-tissue contact is detected: a ts_contact_mode value.
    pub contact_mode: u32,
    /// Volume constraints, one per particle on its dual cell (the elasticity on corotated
    /// tetrahedra keeps the volumetric stiffness up to lambda = 1.5 mu, the constraints take
    /// the rest; ts_world_set_schemes selects others): 0 off, non-zero on (the default).
    pub volume_constraints: u8,
    /// Surface self-contact: each body's boundary vertices kept a skin of half a particle
    /// radius in front of its own boundary triangles, so that folds and the faces of a cut do
    /// not pass through each other: 0 off (the default), non-zero on.
    pub self_contact: u8,
    /// Selective mass scaling: 0 off, non-zero on (the default). Particles whose own stable
    /// time step is shorter than dt / min_substeps get extra inertial mass (not extra weight)
    /// so that the step needs no extra substeps; see ts_body_added_mass. Turn it off for
    /// dynamics comparisons against other solvers.
    pub mass_scaling: u8,
    /// With volume constraints on, the volumetric part of the stress is carried by the
    /// constraints (compliance 1/lambda + volume_compliance) instead of the particles: 0 off,
    /// non-zero on (the default). Off gives the paper's literal arrangement.
    pub volumetric_split: u8,
    /// Threads a step runs on (1..=64; default 1): the calling thread plus threads - 1
    /// workers owned by the world, sharing the force, volume, prediction and update passes.
    /// Results are bit-identical for any count.
    pub threads: u32,
    /// Divergence check: largest particle speed, in body sizes per second (1/s, > 0; default
    /// 250, i.e. 50 m/s for a 0.2 m organ). A step beyond it is rolled back and returns
    /// TS_STATUS_DIVERGED. +infinity switches the check off.
    pub divergence_max_speed: f64,
    /// Divergence check: largest extent of a body (deformed bounding-box diagonal) over its
    /// rest size (dimensionless, > 1; default 10). +infinity switches it off.
    pub divergence_max_extent_ratio: f64,
    /// Divergence check: smallest accepted body volume over rest volume (dimensionless, in
    /// [0, 1); default 0.1).
    pub divergence_min_volume_ratio: f64,
    /// Divergence check: largest accepted body volume over rest volume (dimensionless, > 1;
    /// default 10). +infinity switches it off.
    pub divergence_max_volume_ratio: f64,
}

impl From<&Settings> for ts_settings {
    fn from(s: &Settings) -> Self {
        ts_settings {
            dt: s.dt,
            gravity: [s.gravity.x, s.gravity.y, s.gravity.z],
            min_substeps: s.min_substeps,
            max_substeps: s.max_substeps,
            stability_margin: s.stability_margin,
            damping_mass: s.damping_mass,
            damping_stiffness: s.damping_stiffness,
            hourglass_stiffness: s.hourglass_stiffness,
            volume_compliance: s.volume_compliance,
            max_depenetration_speed: s.max_depenetration_speed,
            iterations: s.iterations,
            contact_mode: match s.contact_mode {
                ContactMode::ExactShape => ts_contact_mode::ExactShape as u32,
                ContactMode::SampledPoints => ts_contact_mode::SampledPoints as u32,
            },
            volume_constraints: s.volume_constraints as u8,
            self_contact: s.self_contact as u8,
            mass_scaling: s.mass_scaling as u8,
            volumetric_split: s.volumetric_split as u8,
            threads: s.threads,
            divergence_max_speed: s.divergence.max_speed,
            divergence_max_extent_ratio: s.divergence.max_extent_ratio,
            divergence_min_volume_ratio: s.divergence.volume_ratio.0,
            divergence_max_volume_ratio: s.divergence.volume_ratio.1,
        }
    }
}

impl ts_settings {
    /// The Rust settings, converted field by field (an unknown contact_mode value gives
    /// TS_STATUS_INVALID_ARGUMENT). Values are not checked here: [`Settings::validate`] does
    /// that in [`World::new`] and [`World::set_settings`].
    #[allow(clippy::needless_update)]
    pub fn to_settings(&self) -> FfiResult<Settings> {
        // Infinity switches a divergence check off; NaN is refused by Settings::validate.
        let divergence = DivergenceLimits {
            max_speed: self.divergence_max_speed,
            max_extent_ratio: self.divergence_max_extent_ratio,
            volume_ratio: (
                self.divergence_min_volume_ratio,
                self.divergence_max_volume_ratio,
            ),
        };
        let contact_mode = match self.contact_mode {
            0 => ContactMode::ExactShape,
            1 => ContactMode::SampledPoints,
            m => {
                return Err(fail(
                    ts_status::InvalidArgument,
                    format!("settings.contact_mode: {m} is not a ts_contact_mode"),
                ))
            }
        };
        // `..Settings::default()` keeps this compiling when the core adds a setting; such a
        // setting keeps its default until it is added to ts_settings.
        Ok(Settings {
            dt: self.dt,
            gravity: Vec3::new(self.gravity[0], self.gravity[1], self.gravity[2]),
            min_substeps: self.min_substeps,
            max_substeps: self.max_substeps,
            stability_margin: self.stability_margin,
            damping_mass: self.damping_mass,
            damping_stiffness: self.damping_stiffness,
            hourglass_stiffness: self.hourglass_stiffness,
            threads: self.threads,
            volume_constraints: self.volume_constraints != 0,
            volume_compliance: self.volume_compliance,
            iterations: self.iterations,
            contact_mode,
            self_contact: self.self_contact != 0,
            mass_scaling: self.mass_scaling != 0,
            volumetric_split: self.volumetric_split != 0,
            max_depenetration_speed: self.max_depenetration_speed,
            divergence,
            ..Settings::default()
        })
    }
}

/// What one ts_world_step did.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct ts_step_report {
    /// Substeps taken by the step.
    pub substeps: u32,
    /// 1 when stability asked for more than ts_settings.max_substeps substeps (the step ran
    /// with max_substeps), else 0.
    pub substeps_clamped: u32,
}

/// A simulated scene: bodies, tools and settings. Opaque; made by ts_world_new, released by
/// ts_world_free. Used by one thread at a time; different worlds are independent.
pub struct ts_world {
    pub(crate) world: World,
    /// Set while a mutation runs; stays set when it panicked.
    poisoned: bool,
    /// For each body id, the index in the source (file order or caller array) of each particle.
    pub(crate) source_indices: Vec<Vec<u32>>,
    /// Scratch buffer for saving states without reallocating.
    pub(crate) scratch: Vec<u8>,
}

impl ts_world {
    /// `TS_STATUS_POISONED` when an earlier mutation panicked.
    pub(crate) fn check_poisoned(&self) -> FfiResult {
        if self.poisoned {
            Err(fail(
                ts_status::Poisoned,
                "the world is poisoned: an earlier call panicked while changing it; free it",
            ))
        } else {
            Ok(())
        }
    }

    /// Run a mutation of the world; if it panics the handle stays poisoned.
    pub(crate) fn mutate<T>(
        &mut self,
        f: impl FnOnce(&mut World) -> Result<T, Error>,
    ) -> FfiResult<T> {
        self.poisoned = true;
        let r = f(&mut self.world);
        self.poisoned = false;
        Ok(r?)
    }
}

/// Write the default settings (1 ms step, gravity -9.81 m/s^2 along y, ...) into *out.
///
/// # Safety
///
/// `out` is NULL or points to a writable ts_settings.
#[no_mangle]
pub unsafe extern "C" fn ts_settings_default(out: *mut ts_settings) -> ts_status {
    guard(|| {
        non_null(out, "out")?;
        let s = ts_settings::from(&Settings::default());
        // SAFETY: checked non-NULL; writable by contract.
        unsafe { write(out, s) };
        Ok(())
    })
}

/// Create an empty world with `settings` (validated by the core: NaN/Inf give
/// TS_STATUS_NON_FINITE, out of range values TS_STATUS_INVALID_ARGUMENT, the message names the
/// field) and store its handle in *out_world. Release it with
/// ts_world_free.
///
/// # Safety
///
/// `settings` is NULL or points to a readable ts_settings; `out_world` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn ts_world_new(
    settings: *const ts_settings,
    out_world: *mut *mut ts_world,
) -> ts_status {
    guard(|| {
        non_null(settings, "settings")?;
        non_null(out_world, "out_world")?;
        // SAFETY: checked non-NULL; readable by contract; every bit pattern is a valid value.
        let s = unsafe { *settings }.to_settings()?;
        let world = World::new(s)?;
        let handle = Box::new(ts_world {
            world,
            poisoned: false,
            source_indices: Vec::new(),
            scratch: Vec::new(),
        });
        // SAFETY: checked non-NULL; writable by contract.
        unsafe { write(out_world, Box::into_raw(handle)) };
        Ok(())
    })
}

/// Release a world and everything in it. NULL is a no-op. The handle is invalid afterwards.
///
/// # Safety
///
/// `world` is NULL or a live handle from ts_world_new, not used by another thread and not
/// freed before.
#[no_mangle]
pub unsafe extern "C" fn ts_world_free(world: *mut ts_world) {
    crate::ffi::guard::guard_value((), || {
        if !world.is_null() {
            // SAFETY: a live handle made by Box::into_raw in ts_world_new, freed once.
            drop(unsafe { Box::from_raw(world) });
        }
    })
}

/// Copy the settings in force into *out.
///
/// # Safety
///
/// `world` is NULL or a live handle; `out` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn ts_world_get_settings(
    world: *const ts_world,
    out: *mut ts_settings,
) -> ts_status {
    guard(|| {
        non_null(out, "out")?;
        // SAFETY: contract of this function.
        let h = unsafe { world_ref(world)? };
        let s = ts_settings::from(h.world.settings());
        // SAFETY: checked non-NULL.
        unsafe { write(out, s) };
        Ok(())
    })
}

/// Replace the settings (validated as in ts_world_new; the world is unchanged on error). The
/// world keeps its schemes (ts_world_set_schemes) and its crushed-step substeps
/// (ts_world_set_crushed_substeps), which ts_settings does not carry.
///
/// # Safety
///
/// `world` is NULL or a live handle; `settings` is NULL or readable.
#[no_mangle]
pub unsafe extern "C" fn ts_world_set_settings(
    world: *mut ts_world,
    settings: *const ts_settings,
) -> ts_status {
    guard(|| {
        non_null(settings, "settings")?;
        // SAFETY: contract of this function.
        let h = unsafe { world_mut(world)? };
        // SAFETY: checked non-NULL; readable by contract.
        let s = unsafe { *settings }.to_settings()?;
        // The schemes and the crushed-step substeps are not in ts_settings: the world keeps
        // its own (ts_world_set_schemes, ts_world_set_crushed_substeps).
        h.mutate(|w| {
            w.set_settings(Settings {
                elastic_scheme: w.settings().elastic_scheme,
                volume_scheme: w.settings().volume_scheme,
                crushed_substeps: w.settings().crushed_substeps,
                ..s
            })
        })
    })
}

/// Advance the world by settings.dt (substepping as stability requires). On
/// TS_STATUS_DIVERGED the step produced NaN/Inf or left the divergence limits of ts_settings
/// (particle speed, body extent, volume ratio) and the world was rolled back to its state
/// before the call (time not advanced; the message names the body and the reason).
/// `out_report` is optional (may be NULL); it is written on success only. Allocates nothing
/// after the first step, except in a step in which a blade tool cuts.
///
/// # Safety
///
/// `world` is NULL or a live handle; `out_report` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn ts_world_step(
    world: *mut ts_world,
    out_report: *mut ts_step_report,
) -> ts_status {
    guard(|| {
        // SAFETY: contract of this function.
        let h = unsafe { world_mut(world)? };
        let r = h.mutate(|w| w.step())?;
        if !out_report.is_null() {
            // SAFETY: non-NULL and writable by contract.
            unsafe {
                write(
                    out_report,
                    ts_step_report {
                        substeps: r.substeps,
                        substeps_clamped: r.substeps_clamped as u32,
                    },
                )
            };
        }
        Ok(())
    })
}

/// Bring the world to rest in its equilibrium under gravity, fixed particles held: a scene
/// started from ts_world_settle hangs still instead of swinging into place. A static solve
/// (Newton, corotated stiffness, sparse direct factorisation; kept if it converges), then
/// dynamic relaxation with the world's own step until no particle moves faster than 10 um/s.
/// Simulated time is not advanced; velocities end at zero. Fails with
/// TS_STATUS_INVALID_ARGUMENT and changes nothing when a body has no fixed particle.
/// Allocates and may take seconds: not for the haptic loop.
///
/// # Safety
///
/// `world` is NULL or a live handle.
#[no_mangle]
pub unsafe extern "C" fn ts_world_settle(world: *mut ts_world) -> ts_status {
    guard(|| {
        // SAFETY: contract of this function.
        let h = unsafe { world_mut(world)? };
        h.mutate(|w| w.settle())?;
        Ok(())
    })
}

/// Simulated time (s) since the world was created (or of the last restored state).
///
/// # Safety
///
/// `world` is NULL or a live handle; `out_time` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn ts_world_time(world: *const ts_world, out_time: *mut f64) -> ts_status {
    // SAFETY: contract of this function.
    unsafe { world_value(world, out_time, "out_time", |w| w.time()) }
}

/// The fastest (m/s) a tool may move and still be swept across the substeps: a faster pose
/// change (a tracking glitch) is a jump, and the tool is placed at its new pose at once, the
/// tissue it lands in leaving it at ts_settings.max_depenetration_speed. A quarter of the
/// divergence speed bound of the smallest body; infinite while the world has no body.
///
/// # Safety
///
/// `world` is NULL or a live handle; `out_speed` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn ts_world_tool_jump_speed(
    world: *const ts_world,
    out_speed: *mut f64,
) -> ts_status {
    // SAFETY: contract of this function.
    unsafe { world_value(world, out_speed, "out_speed", |w| w.tool_jump_speed()) }
}

/// Number of bodies in the world (their ids are 0 .. count-1).
///
/// # Safety
///
/// `world` is NULL or a live handle; `out_count` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn ts_world_body_count(
    world: *const ts_world,
    out_count: *mut u32,
) -> ts_status {
    // SAFETY: contract of this function.
    unsafe { world_value(world, out_count, "out_count", |w| w.body_count() as u32) }
}

/// Number of tools in the world, removed tools not counted (tool ids are 0, 1, 2, ... in
/// order of creation and never reused, so after ts_world_remove_tool they are not 0 .. count-1).
///
/// # Safety
///
/// `world` is NULL or a live handle; `out_count` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn ts_world_tool_count(
    world: *const ts_world,
    out_count: *mut u32,
) -> ts_status {
    // SAFETY: contract of this function.
    unsafe { world_value(world, out_count, "out_count", |w| w.tool_count() as u32) }
}

/// Number of steps so far that diverged (NaN/Inf or outside the divergence limits) and were
/// rolled back (TS_STATUS_DIVERGED).
///
/// # Safety
///
/// `world` is NULL or a live handle; `out_count` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn ts_world_diverged_steps(
    world: *const ts_world,
    out_count: *mut u64,
) -> ts_status {
    // SAFETY: contract of this function.
    unsafe { world_value(world, out_count, "out_count", |w| w.diverged_steps()) }
}

/// Write `get(world)` into `*out` (`out_name` names it in errors): the world-wide getters.
///
/// # Safety
///
/// `world` is NULL or a live handle; `out` is NULL or writable.
pub(crate) unsafe fn world_value<T>(
    world: *const ts_world,
    out: *mut T,
    out_name: &str,
    get: impl FnOnce(&World) -> T,
) -> ts_status {
    guard(|| {
        non_null(out, out_name)?;
        // SAFETY: contract of the caller.
        let h = unsafe { world_ref(world)? };
        let v = get(&h.world);
        // SAFETY: checked non-NULL.
        unsafe { write(out, v) };
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::ptr::null_mut;

    /// A panic inside a mutation becomes TS_STATUS_PANIC and poisons the world: every later
    /// call returns TS_STATUS_POISONED, and ts_world_free still releases it.
    #[test]
    fn a_panicking_mutation_poisons_the_world() {
        let mut s = ts_settings::from(&Settings::default());
        let mut w = null_mut();
        assert_eq!(unsafe { ts_world_new(&s, &mut w) }, ts_status::Ok);
        let st = guard(|| {
            // SAFETY: a live handle.
            let h = unsafe { world_mut(w)? };
            h.mutate(|_| -> Result<(), Error> { panic!("half-way through a change") })
        });
        assert_eq!(st, ts_status::Panic);
        assert!(crate::ffi::error::last_error().contains("half-way"));
        assert_eq!(unsafe { ts_world_step(w, null_mut()) }, ts_status::Poisoned);
        let mut t = 0.0;
        assert_eq!(unsafe { ts_world_time(w, &mut t) }, ts_status::Poisoned);
        assert_eq!(unsafe { ts_world_set_settings(w, &s) }, ts_status::Poisoned);
        assert_eq!(
            unsafe { ts_world_get_settings(w, &mut s) },
            ts_status::Poisoned
        );
        assert_eq!(
            unsafe { crate::ffi::state::ts_world_restore_state(w, [0u8].as_ptr(), 1) },
            ts_status::Poisoned
        );
        assert!(crate::ffi::error::last_error().contains("poisoned"));
        unsafe { ts_world_free(w) };
    }
}
